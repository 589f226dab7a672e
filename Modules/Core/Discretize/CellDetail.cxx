// SPDX-License-Identifier: BSD-3-Clause
#include "Discretize/CellDetail.h"

#include "FRep/Threads.h"

#include <Eigen/Dense>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <stdexcept>

namespace ictk::discretize::detail
{

double pointSegmentDistance(const Point3& p, const Point3& a, const Point3& b)
{
  const Point3 ab = sub(b, a);
  const double len2 = dot(ab, ab);
  double t = len2 > 0 ? dot(sub(p, a), ab) / len2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  return distance(p, lerp(a, b, t));
}

double Constraint::eval(const Point3& p, Point3& grad) const
{
  if (field)
  {
    return field->gradient(p, grad);
  }
  grad = { 0, 0, 0 };
  grad[axis] = 1;
  return p[axis] - value;
}

bool projectOnto(const Constraint* constraints, int count, Point3& p, const NewtonSettings& s)
{
  using Jacobian = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor, 3, 3>;
  using Values = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 3, 1>;
  if (count < 1 || count > 3)
  {
    throw std::logic_error("projectOnto: 1 to 3 constraints");
  }
  const Point3 start = p;
  Jacobian J(count, 3);
  Values f(count);
  for (int iteration = 0;; ++iteration)
  {
    bool converged = true;
    bool nearlyConverged = true;
    for (int i = 0; i < count; ++i)
    {
      Point3 g{ 0, 0, 0 };
      const double v = constraints[i].eval(p, g);
      if (!std::isfinite(v) || !finite(g))
      {
        return false;
      }
      f(i) = v;
      J(i, 0) = g[0];
      J(i, 1) = g[1];
      J(i, 2) = g[2];
      const double gn = norm(g);
      converged = converged && std::abs(v) <= s.tolerance * gn;
      nearlyConverged = nearlyConverged && std::abs(v) <= 1e3 * s.tolerance * gn;
    }
    if (converged)
    {
      return true;
    }
    if (iteration >= s.maxIterations)
    {
      return false;
    }
    // Singular values below 1e-9 of the largest count as zero: nearly parallel gradients
    // (tangent constraints) then give the least-squares step instead of a huge one.
    Eigen::CompleteOrthogonalDecomposition<Jacobian> cod(J.rows(), J.cols());
    cod.setThreshold(1e-9);
    cod.compute(J);
    Eigen::Vector3d d = -cod.solve(f);
    double len = d.norm();
    if (!std::isfinite(len) || len == 0)
    {
      return false;
    }
    if (len < 1e-2 * s.tolerance && nearlyConverged)
    {
      return true; // stagnating at round-off level
    }
    if (s.maxStep > 0 && len > s.maxStep)
    {
      d *= s.maxStep / len;
    }
    p = { p[0] + d(0), p[1] + d(1), p[2] + d(2) };
    if (s.maxDistance > 0 && distance(p, start) > s.maxDistance)
    {
      return false;
    }
  }
}

void forChunks(std::size_t n, std::size_t grain, int threads,
  const std::function<void(std::size_t, std::size_t)>& fn)
{
  if (n == 0)
  {
    return;
  }
  grain = std::max<std::size_t>(grain, 1);
  const std::size_t chunks = (n + grain - 1) / grain;
  auto body = [&](const tbb::blocked_range<std::size_t>& r)
  {
    for (std::size_t c = r.begin(); c != r.end(); ++c)
    {
      fn(c * grain, std::min(n, (c + 1) * grain));
    }
  };
  if (threads == 1 || chunks == 1)
  {
    body(tbb::blocked_range<std::size_t>(0, chunks));
    return;
  }
  runOnThreads(
    threads, [&] { tbb::parallel_for(tbb::blocked_range<std::size_t>(0, chunks, 1), body); });
}

void checkBox(const Box3& box, unsigned flatAxes, const char* what)
{
  for (int a = 0; a < 3; ++a)
  {
    if (!std::isfinite(box.lo[a]) || !std::isfinite(box.hi[a]))
    {
      throw std::invalid_argument(std::string(what) + ": the box must be finite");
    }
    const bool flat = (flatAxes >> a) & 1u;
    if (flat ? !(box.hi[a] >= box.lo[a]) : !(box.hi[a] > box.lo[a]))
    {
      throw std::invalid_argument(std::string(what) + ": the box is empty (lo >= hi on axis " +
        std::string(1, static_cast<char>('x' + a)) + ")");
    }
  }
}

void checkFields(const std::vector<frep::FieldPtr>& fields, const char* what)
{
  for (const auto& f : fields)
  {
    if (!f)
    {
      throw std::invalid_argument(std::string(what) + ": null field");
    }
  }
}

std::vector<std::unique_ptr<frep::FieldEvaluator>> evaluatorsOf(
  const std::vector<frep::FieldPtr>& fields)
{
  std::vector<std::unique_ptr<frep::FieldEvaluator>> out;
  out.reserve(fields.size());
  for (const auto& f : fields)
  {
    out.push_back(f->evaluator());
  }
  return out;
}

void evaluateAt(const frep::Field& field, const std::vector<Point3>& points,
  std::vector<double>& out, int threads)
{
  out.assign(points.size(), 0.0);
  forChunks(points.size(), 4096, threads,
    [&](std::size_t b, std::size_t e)
    {
      auto ev = field.evaluator();
      std::vector<double> x(e - b), y(e - b), z(e - b);
      for (std::size_t i = b; i < e; ++i)
      {
        x[i - b] = points[i][0];
        y[i - b] = points[i][1];
        z[i - b] = points[i][2];
      }
      ev->values(x.data(), y.data(), z.data(), out.data() + b, e - b);
    });
}

namespace
{

std::uint64_t edgeKey(std::uint32_t a, std::uint32_t b)
{
  if (a > b)
  {
    std::swap(a, b);
  }
  return (static_cast<std::uint64_t>(a) << 32) | b;
}

constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

struct Cut
{
  Point3 p{ 0, 0, 0 };
  double t = 0; ///< position along the edge from its lower vertex index to its higher
  std::uint32_t reuse = kNone;
  unsigned on = 0;
};

void compact(SurfaceMesh& mesh, std::vector<unsigned>& onTrim)
{
  std::vector<std::uint32_t> remap(mesh.points.size(), kNone);
  std::uint32_t next = 0;
  for (auto& t : mesh.triangles)
  {
    for (auto& v : t)
    {
      if (remap[v] == kNone)
      {
        remap[v] = next++;
      }
      v = remap[v];
    }
  }
  std::vector<Point3> points(next);
  std::vector<unsigned> on(next);
  for (std::size_t v = 0; v < remap.size(); ++v)
  {
    if (remap[v] != kNone)
    {
      points[remap[v]] = mesh.points[v];
      on[remap[v]] = onTrim[v];
    }
  }
  for (auto& array : mesh.pointData)
  {
    const auto c = static_cast<std::size_t>(array.components);
    std::vector<double> values(next * c);
    for (std::size_t v = 0; v < remap.size(); ++v)
    {
      if (remap[v] != kNone)
      {
        std::copy_n(array.values.begin() + v * c, c, values.begin() + remap[v] * c);
      }
    }
    array.values = std::move(values);
  }
  mesh.points = std::move(points);
  onTrim = std::move(on);
}

} // namespace

SurfaceMesh clipMesh(SurfaceMesh mesh, std::vector<unsigned>& onTrim,
  const std::vector<frep::FieldPtr>& trims, const ClipSettings& settings)
{
  if (trims.size() > 32)
  {
    throw std::invalid_argument("trimming: at most 32 trim fields");
  }
  onTrim.resize(mesh.points.size(), 0u);
  for (std::size_t k = 0; k < trims.size(); ++k)
  {
    const unsigned bit = 1u << k;
    const std::size_t nv = mesh.points.size();
    std::vector<double> value;
    evaluateAt(*trims[k], mesh.points, value, settings.threads);
    std::vector<char> in(nv);
    for (std::size_t v = 0; v < nv; ++v)
    {
      if (onTrim[v] & bit)
      {
        value[v] = 0;
      }
      in[v] = value[v] >= 0;
    }

    std::vector<std::uint64_t> keys;
    for (const auto& t : mesh.triangles)
    {
      for (int e = 0; e < 3; ++e)
      {
        const std::uint32_t a = t[e], b = t[(e + 1) % 3];
        if (in[a] != in[b])
        {
          keys.push_back(edgeKey(a, b));
        }
      }
    }
    std::sort(keys.begin(), keys.end());
    keys.erase(std::unique(keys.begin(), keys.end()), keys.end());

    std::vector<Cut> cuts(keys.size());
    forChunks(keys.size(), 64, settings.threads,
      [&](std::size_t b, std::size_t e)
      {
        auto h = trims[k]->evaluator();
        std::unique_ptr<frep::FieldEvaluator> g =
          settings.carrier ? settings.carrier->evaluator() : nullptr;
        std::vector<std::unique_ptr<frep::FieldEvaluator>> others(k);
        for (std::size_t i = b; i < e; ++i)
        {
          const auto lo = static_cast<std::uint32_t>(keys[i] >> 32);
          const auto hi = static_cast<std::uint32_t>(keys[i] & 0xffffffffu);
          const std::uint32_t vin = in[lo] ? lo : hi;
          const std::uint32_t vout = in[lo] ? hi : lo;
          Cut& cut = cuts[i];
          if (value[vin] == 0)
          {
            cut.reuse = vin;
            continue;
          }
          const Point3 A = mesh.points[vin], B = mesh.points[vout];
          double ta = 0, tb = 1;
          for (int it = 0; it < 64 && tb - ta > 1e-15; ++it)
          {
            const double tm = 0.5 * (ta + tb);
            if (h->value(lerp(A, B, tm)) >= 0)
            {
              ta = tm;
            }
            else
            {
              tb = tm;
            }
          }
          const double t = 0.5 * (ta + tb);
          const Point3 x0 = lerp(A, B, t);
          Constraint cs[3];
          int n = 0;
          cs[n++] = g ? Constraint::of(*g) : Constraint::plane(2, settings.planeZ);
          cs[n++] = Constraint::of(*h);
          const unsigned common = onTrim[vin] & onTrim[vout] & ~bit;
          unsigned used = 0;
          for (std::size_t j = 0; j < k && n < 3; ++j)
          {
            if (common & (1u << j))
            {
              if (!others[j])
              {
                others[j] = trims[j]->evaluator();
              }
              cs[n++] = Constraint::of(*others[j]);
              used |= 1u << j;
            }
          }
          const double len = distance(A, B);
          NewtonSettings ns = settings.newton;
          ns.maxStep = len;
          ns.maxDistance = 2 * len;
          Point3 x = x0;
          const bool ok = projectOnto(cs, n, x, ns);
          cut.p = ok ? x : x0;
          cut.on = bit | (ok ? used : 0u);
          cut.t = vin < vout ? t : 1 - t;
        }
      });

    std::vector<std::uint32_t> cutIndex(keys.size());
    for (std::size_t i = 0; i < keys.size(); ++i)
    {
      const Cut& cut = cuts[i];
      if (cut.reuse != kNone)
      {
        cutIndex[i] = cut.reuse;
        onTrim[cut.reuse] |= bit;
        continue;
      }
      const auto lo = static_cast<std::uint32_t>(keys[i] >> 32);
      const auto hi = static_cast<std::uint32_t>(keys[i] & 0xffffffffu);
      cutIndex[i] = static_cast<std::uint32_t>(mesh.points.size());
      mesh.points.push_back(cut.p);
      onTrim.push_back(cut.on);
      for (auto& array : mesh.pointData)
      {
        const auto c = static_cast<std::size_t>(array.components);
        for (std::size_t j = 0; j < c; ++j)
        {
          const double a = array.values[lo * c + j], bv = array.values[hi * c + j];
          array.values.push_back(a + cut.t * (bv - a));
        }
      }
    }
    if (mesh.points.size() >= kNone)
    {
      throw std::length_error("trimming: too many vertices for 32-bit indices");
    }
    auto cutOf = [&](std::uint32_t a, std::uint32_t b)
    {
      const auto it = std::lower_bound(keys.begin(), keys.end(), edgeKey(a, b));
      return cutIndex[static_cast<std::size_t>(it - keys.begin())];
    };

    std::vector<std::array<std::uint32_t, 3>> triangles;
    triangles.reserve(mesh.triangles.size());
    auto emit = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c)
    {
      if (a != b && b != c && a != c)
      {
        triangles.push_back({ a, b, c });
      }
    };
    auto centre = trims[k]->evaluator();
    for (const auto& t : mesh.triangles)
    {
      const int inside = in[t[0]] + in[t[1]] + in[t[2]];
      if (inside == 3)
      {
        // A triangle whose corners all lie on the trim's curve may span an outside region (a
        // chord across a hole): keep it only when its centroid is inside.
        if ((onTrim[t[0]] & onTrim[t[1]] & onTrim[t[2]] & bit) != 0)
        {
          const Point3 c =
            scale(add(add(mesh.points[t[0]], mesh.points[t[1]]), mesh.points[t[2]]), 1.0 / 3.0);
          if (!(centre->value(c) >= 0))
          {
            continue;
          }
        }
        triangles.push_back(t);
        continue;
      }
      if (inside == 0)
      {
        continue;
      }
      std::uint32_t poly[4];
      int m = 0;
      for (int e = 0; e < 3; ++e)
      {
        const std::uint32_t a = t[e], b = t[(e + 1) % 3];
        if (in[a])
        {
          poly[m++] = a;
        }
        if (in[a] != in[b])
        {
          poly[m++] = cutOf(a, b);
        }
      }
      if (m == 3)
      {
        emit(poly[0], poly[1], poly[2]);
      }
      else
      {
        const auto& P = mesh.points;
        if (distance(P[poly[0]], P[poly[2]]) <= distance(P[poly[1]], P[poly[3]]))
        {
          emit(poly[0], poly[1], poly[2]);
          emit(poly[0], poly[2], poly[3]);
        }
        else
        {
          emit(poly[1], poly[2], poly[3]);
          emit(poly[1], poly[3], poly[0]);
        }
      }
    }
    mesh.triangles = std::move(triangles);
  }
  compact(mesh, onTrim);
  return mesh;
}

} // namespace ictk::discretize::detail
