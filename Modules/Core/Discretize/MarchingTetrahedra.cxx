// SPDX-License-Identifier: BSD-3-Clause
#include "Discretize/Contour.h"

#include "FRep/Sampling.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <map>
#include <mutex>
#include <stdexcept>
#include <unordered_map>

namespace ictk::discretize
{
namespace
{

using frep::FieldEvaluator;

Point3 sub(const Point3& a, const Point3& b)
{
  return { a[0] - b[0], a[1] - b[1], a[2] - b[2] };
}
Point3 cross(const Point3& a, const Point3& b)
{
  return { a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0] };
}
double dot(const Point3& a, const Point3& b)
{
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
Point3 lerp(const Point3& a, const Point3& b, double t)
{
  return { a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), a[2] + t * (b[2] - a[2]) };
}

void checkBox(const Box3& box, double size, const char* what)
{
  for (int a = 0; a < 3; ++a)
  {
    if (!std::isfinite(box.lo[a]) || !std::isfinite(box.hi[a]) || box.lo[a] > box.hi[a])
    {
      throw std::invalid_argument(std::string(what) + ": the box must be finite with lo <= hi");
    }
  }
  if (!(size > 0) || !std::isfinite(size))
  {
    throw std::invalid_argument(std::string(what) + ": the feature size must be positive");
  }
}

/// Finds the zero of f on the segment [a, b] (f(a) >= 0 > f(b) or the reverse) by regula falsi
/// with the Illinois modification, starting from the linear estimate.
Point3 edgeRoot(FieldEvaluator& f, Point3 a, double fa, Point3 b, double fb, int iterations = 8)
{
  Point3 p = lerp(a, b, fa / (fa - fb));
  int side = 0;
  for (int i = 0; i < iterations; ++i)
  {
    const double t = fa / (fa - fb);
    p = lerp(a, b, t);
    const double fp = f.value(p);
    if (fp == 0 || !std::isfinite(fp))
    {
      break;
    }
    if ((fp >= 0) == (fa >= 0))
    {
      a = p;
      fa = fp;
      if (side == -1)
      {
        fb *= 0.5;
      }
      side = -1;
    }
    else
    {
      b = p;
      fb = fp;
      if (side == 1)
      {
        fa *= 0.5;
      }
      side = 1;
    }
  }
  return p;
}

// The six tetrahedra of the Kuhn split of a cube (corners by bits x = 1, y = 2, z = 4): every
// cube is split the same way, so faces match and there is no ambiguity.
constexpr int kTets[6][4] = { { 0, 1, 3, 7 }, { 0, 1, 5, 7 }, { 0, 2, 3, 7 }, { 0, 2, 6, 7 },
  { 0, 4, 5, 7 }, { 0, 4, 6, 7 } };

struct BlockResult
{
  // Each triangle vertex is an edge key; positions are found after the merge.
  std::vector<std::array<std::uint64_t, 3>> triangles;
};

} // namespace

SurfaceMesh contourSurface(const frep::Field& field, const Box3& box, const ContourOptions& o)
{
  checkBox(box, o.featureSize, "contourSurface");
  const double h = o.featureSize;
  std::array<std::int64_t, 3> cells;
  double total = 1;
  for (int a = 0; a < 3; ++a)
  {
    cells[a] =
      std::max<std::int64_t>(1, static_cast<std::int64_t>(std::ceil((box.hi[a] - box.lo[a]) / h)));
    total *= static_cast<double>(cells[a]);
  }
  if (total > o.maxCells)
  {
    throw std::invalid_argument("contourSurface: feature size " + std::to_string(h) +
      " over this box needs " + std::to_string(total) + " grid cells, more than the limit of " +
      std::to_string(o.maxCells));
  }
  // With closeAtBox, one layer of outside cells surrounds the box.
  const std::int64_t pad = o.closeAtBox ? 1 : 0;
  std::array<std::int64_t, 3> n; // grid points per axis
  Point3 origin;
  for (int a = 0; a < 3; ++a)
  {
    n[a] = cells[a] + 1 + 2 * pad;
    origin[a] = box.lo[a] - pad * h;
  }
  auto pointIndex = [&](std::int64_t i, std::int64_t j, std::int64_t k)
  {
    return static_cast<std::uint64_t>((k * n[1] + j) * n[0] + i);
  };
  constexpr std::int64_t B = 8; // cells per block edge
  std::array<std::int64_t, 3> blocks;
  for (int a = 0; a < 3; ++a)
  {
    blocks[a] = (n[a] - 1 + B - 1) / B;
  }
  const std::int64_t blockCount = blocks[0] * blocks[1] * blocks[2];
  std::vector<BlockResult> results(static_cast<std::size_t>(blockCount));
  std::atomic<std::int64_t> done{ 0 };
  std::atomic<bool> cancelled{ false };

  auto runBlock = [&](std::int64_t b, FieldEvaluator& root, std::vector<double>& xs,
                    std::vector<double>& ys, std::vector<double>& zs, std::vector<double>& vs)
  {
    const std::int64_t bi = b % blocks[0];
    const std::int64_t bj = (b / blocks[0]) % blocks[1];
    const std::int64_t bk = b / (blocks[0] * blocks[1]);
    const std::int64_t i0 = bi * B, j0 = bj * B, k0 = bk * B;
    const std::int64_t ni = std::min(B, n[0] - 1 - i0), nj = std::min(B, n[1] - 1 - j0),
                       nk = std::min(B, n[2] - 1 - k0);
    Box3 blockBox;
    blockBox.lo = { origin[0] + i0 * h, origin[1] + j0 * h, origin[2] + k0 * h };
    blockBox.hi = { origin[0] + (i0 + ni) * h, origin[1] + (j0 + nj) * h,
      origin[2] + (k0 + nk) * h };
    const frep::Interval bound = root.bound(blockBox);
    const bool touchesPad = pad &&
      (i0 == 0 || j0 == 0 || k0 == 0 || i0 + ni == n[0] - 1 || j0 + nj == n[1] - 1 ||
        k0 + nk == n[2] - 1);
    if (!bound.maybeNaN && (bound.negative() || (bound.positive() && !touchesPad)))
    {
      return;
    }
    std::unique_ptr<FieldEvaluator> narrowed = root.narrowed(blockBox);
    FieldEvaluator& f = narrowed ? *narrowed : root;
    const std::int64_t pi = ni + 1, pj = nj + 1, pk = nk + 1;
    const auto count = static_cast<std::size_t>(pi * pj * pk);
    xs.resize(count);
    ys.resize(count);
    zs.resize(count);
    vs.resize(count);
    std::size_t c = 0;
    for (std::int64_t k = 0; k < pk; ++k)
    {
      for (std::int64_t j = 0; j < pj; ++j)
      {
        for (std::int64_t i = 0; i < pi; ++i, ++c)
        {
          xs[c] = origin[0] + (i0 + i) * h;
          ys[c] = origin[1] + (j0 + j) * h;
          zs[c] = origin[2] + (k0 + k) * h;
        }
      }
    }
    f.values(xs.data(), ys.data(), zs.data(), vs.data(), count);
    if (pad)
    {
      c = 0;
      for (std::int64_t k = 0; k < pk; ++k)
      {
        for (std::int64_t j = 0; j < pj; ++j)
        {
          for (std::int64_t i = 0; i < pi; ++i, ++c)
          {
            const std::int64_t gi = i0 + i, gj = j0 + j, gk = k0 + k;
            if (gi == 0 || gj == 0 || gk == 0 || gi == n[0] - 1 || gj == n[1] - 1 || gk == n[2] - 1)
            {
              vs[c] = -h; // outside the box
            }
          }
        }
      }
    }
    auto local = [&](std::int64_t i, std::int64_t j, std::int64_t k)
    {
      return static_cast<std::size_t>((k * pj + j) * pi + i);
    };
    BlockResult& out = results[static_cast<std::size_t>(b)];
    for (std::int64_t k = 0; k < nk; ++k)
    {
      for (std::int64_t j = 0; j < nj; ++j)
      {
        for (std::int64_t i = 0; i < ni; ++i)
        {
          double v[8];
          bool anyIn = false, anyOut = false;
          for (int corner = 0; corner < 8; ++corner)
          {
            v[corner] = vs[local(i + (corner & 1), j + ((corner >> 1) & 1), k + (corner >> 2))];
            if (!(v[corner] >= 0))
            {
              v[corner] = std::isnan(v[corner]) ? -h : v[corner]; // NaN counts as outside
            }
            (v[corner] >= 0 ? anyIn : anyOut) = true;
          }
          if (!anyIn || !anyOut)
          {
            continue;
          }
          const std::int64_t gi = i0 + i, gj = j0 + j, gk = k0 + k;
          auto key = [&](int a, int bCorner)
          {
            const int lo = std::min(a, bCorner), hi = std::max(a, bCorner);
            const std::uint64_t p = pointIndex(gi + (lo & 1), gj + ((lo >> 1) & 1), gk + (lo >> 2));
            return p * 8 + static_cast<std::uint64_t>(lo ^ hi);
          };
          for (const auto& tet : kTets)
          {
            int in[4], out4[4], nin = 0, nout = 0;
            for (int t = 0; t < 4; ++t)
            {
              (v[tet[t]] >= 0 ? in[nin++] : out4[nout++]) = tet[t];
            }
            if (nin == 0 || nout == 0)
            {
              continue;
            }
            // Orient each triangle so that its normal points from inside to outside, computed
            // on the midpoints of its edges: those never degenerate, unlike the final vertices,
            // which may coincide when a corner value is zero.
            auto emit = [&](int a, int b, int c1, int c2, int d1, int d2)
            {
              auto mid = [](int p, int q)
              {
                return Point3{ 0.5 * ((p & 1) + (q & 1)), 0.5 * (((p >> 1) & 1) + ((q >> 1) & 1)),
                  0.5 * ((p >> 2) + (q >> 2)) };
              };
              const Point3 m0 = mid(a, b), m1 = mid(c1, c2), m2 = mid(d1, d2);
              const Point3 normal = cross(sub(m1, m0), sub(m2, m0));
              const int inCorner = v[a] >= 0 ? a : b, outCorner = v[a] >= 0 ? b : a;
              const Point3 outward{ double((outCorner & 1) - (inCorner & 1)),
                double(((outCorner >> 1) & 1) - ((inCorner >> 1) & 1)),
                double((outCorner >> 2) - (inCorner >> 2)) };
              if (dot(normal, outward) >= 0)
              {
                out.triangles.push_back({ key(a, b), key(c1, c2), key(d1, d2) });
              }
              else
              {
                out.triangles.push_back({ key(a, b), key(d1, d2), key(c1, c2) });
              }
            };
            if (nin == 1 || nout == 1)
            {
              const int apex = nin == 1 ? in[0] : out4[0];
              const int* others = nin == 1 ? out4 : in;
              emit(apex, others[0], apex, others[1], apex, others[2]);
            }
            else
            {
              emit(in[0], out4[0], in[0], out4[1], in[1], out4[1]);
              emit(in[0], out4[0], in[1], out4[1], in[1], out4[0]);
            }
          }
        }
      }
    }
  };

  tbb::task_arena arena(o.threads > 0 ? o.threads : tbb::task_arena::automatic);
  arena.execute(
    [&]
    {
      tbb::parallel_for(tbb::blocked_range<std::int64_t>(0, blockCount, 1),
        [&](const tbb::blocked_range<std::int64_t>& range)
        {
          auto root = field.evaluator();
          std::vector<double> xs, ys, zs, vs;
          for (std::int64_t b = range.begin(); b != range.end(); ++b)
          {
            if (cancelled.load())
            {
              return;
            }
            runBlock(b, *root, xs, ys, zs, vs);
            const std::int64_t finished = ++done;
            if (o.progress && (finished % 64 == 0 || finished == blockCount))
            {
              static std::mutex progressMutex;
              std::lock_guard<std::mutex> lock(progressMutex);
              if (!cancelled.load() && !o.progress(0.9 * double(finished) / double(blockCount)))
              {
                cancelled = true;
              }
            }
          }
        });
    });
  if (cancelled)
  {
    throw frep::Cancelled();
  }

  // Merge in block order: vertex ids by ascending edge key, so the output does not depend on
  // the thread schedule.
  std::vector<std::uint64_t> keys;
  for (const auto& r : results)
  {
    for (const auto& t : r.triangles)
    {
      keys.insert(keys.end(), t.begin(), t.end());
    }
  }
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  SurfaceMesh mesh;
  mesh.points.resize(keys.size());
  auto corner = [&](std::uint64_t p, int offset)
  {
    const std::int64_t pi64 = static_cast<std::int64_t>(p);
    const std::int64_t i = pi64 % n[0] + (offset & 1);
    const std::int64_t j = (pi64 / n[0]) % n[1] + ((offset >> 1) & 1);
    const std::int64_t k = pi64 / (n[0] * n[1]) + (offset >> 2);
    return Point3{ origin[0] + i * h, origin[1] + j * h, origin[2] + k * h };
  };
  auto padded = [&](const Point3& p)
  {
    for (int a = 0; a < 3; ++a)
    {
      if (p[a] < box.lo[a] - 0.5 * h || p[a] > box.hi[a] + 0.5 * h)
      {
        return true;
      }
    }
    return false;
  };
  arena.execute(
    [&]
    {
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, keys.size(), 256),
        [&](const tbb::blocked_range<std::size_t>& range)
        {
          auto f = field.evaluator();
          for (std::size_t v = range.begin(); v != range.end(); ++v)
          {
            const Point3 a = corner(keys[v] / 8, 0);
            const Point3 b = corner(keys[v] / 8, static_cast<int>(keys[v] % 8));
            double fa = padded(a) ? -h : f->value(a);
            double fb = padded(b) ? -h : f->value(b);
            fa = std::isnan(fa) ? -h : fa;
            fb = std::isnan(fb) ? -h : fb;
            if ((fa >= 0) == (fb >= 0))
            {
              mesh.points[v] = lerp(a, b, 0.5);
            }
            else if (padded(a) || padded(b))
            {
              // The cut by the box: the vertex stays on the box face.
              const Point3& inside = fa >= 0 ? a : b;
              const Point3& outside = fa >= 0 ? b : a;
              Point3 p = inside;
              for (int ax = 0; ax < 3; ++ax)
              {
                if (outside[ax] != inside[ax])
                {
                  p[ax] = std::clamp(outside[ax], box.lo[ax], box.hi[ax]);
                }
              }
              mesh.points[v] = p;
            }
            else
            {
              mesh.points[v] = edgeRoot(*f, a, fa, b, fb);
            }
          }
        });
    });
  auto indexOf = [&](std::uint64_t key)
  {
    return static_cast<std::uint32_t>(
      std::lower_bound(keys.begin(), keys.end(), key) - keys.begin());
  };
  for (const auto& r : results)
  {
    for (const auto& t : r.triangles)
    {
      const std::array<std::uint32_t, 3> tri = { indexOf(t[0]), indexOf(t[1]), indexOf(t[2]) };
      mesh.triangles.push_back(tri);
    }
  }
  if (o.progress && !o.progress(1.0))
  {
    throw frep::Cancelled();
  }
  return mesh;
}

bool projectOntoSet(
  const std::vector<frep::FieldEvaluator*>& fields, Point3& p, const ProjectionOptions& o)
{
  const std::size_t m = fields.size();
  if (m == 0 || m > 3)
  {
    throw std::invalid_argument("projectOntoSet: between one and three fields");
  }
  for (int iteration = 0; iteration < o.maxIterations; ++iteration)
  {
    double f[3];
    Point3 g[3];
    bool converged = true;
    for (std::size_t i = 0; i < m; ++i)
    {
      f[i] = fields[i]->gradient(p, g[i]);
      if (!std::isfinite(f[i]))
      {
        return false;
      }
      converged = converged && std::abs(f[i]) <= o.tolerance * std::sqrt(dot(g[i], g[i]));
    }
    if (converged)
    {
      return true;
    }
    // Minimum-norm step: dx = -J^T (J J^T)^-1 f, with J the m x 3 Jacobian.
    double a[3][3];
    for (std::size_t i = 0; i < m; ++i)
    {
      for (std::size_t j = 0; j < m; ++j)
      {
        a[i][j] = dot(g[i], g[j]);
      }
    }
    double y[3] = { f[0], m > 1 ? f[1] : 0, m > 2 ? f[2] : 0 };
    // Gaussian elimination with partial pivoting on the small system a y = f.
    for (std::size_t c = 0; c < m; ++c)
    {
      std::size_t pivot = c;
      for (std::size_t r = c + 1; r < m; ++r)
      {
        if (std::abs(a[r][c]) > std::abs(a[pivot][c]))
        {
          pivot = r;
        }
      }
      if (std::abs(a[pivot][c]) < 1e-300)
      {
        return false; // the gradients are dependent: the sets are tangent here
      }
      std::swap(a[c], a[pivot]);
      std::swap(y[c], y[pivot]);
      for (std::size_t r = c + 1; r < m; ++r)
      {
        const double factor = a[r][c] / a[c][c];
        for (std::size_t k = c; k < m; ++k)
        {
          a[r][k] -= factor * a[c][k];
        }
        y[r] -= factor * y[c];
      }
    }
    for (std::size_t c = m; c-- > 0;)
    {
      for (std::size_t k = c + 1; k < m; ++k)
      {
        y[c] -= a[c][k] * y[k];
      }
      y[c] /= a[c][c];
    }
    for (std::size_t i = 0; i < m; ++i)
    {
      for (int ax = 0; ax < 3; ++ax)
      {
        p[ax] -= y[i] * g[i][ax];
      }
    }
  }
  return false;
}

namespace
{

std::vector<std::unique_ptr<FieldEvaluator>> evaluators(const std::vector<frep::FieldPtr>& fields)
{
  std::vector<std::unique_ptr<FieldEvaluator>> out;
  for (const auto& f : fields)
  {
    if (!f)
    {
      throw std::invalid_argument("a trim field is missing");
    }
    out.push_back(f->evaluator());
  }
  return out;
}

/// Clips a polygon (vertex ids) against {h >= 0}: vertices with h >= 0 are kept; a crossing edge
/// gets a vertex from `cut(a, b)`, shared between the two polygons of the edge.
std::vector<std::uint32_t> clipPolygon(const std::vector<std::uint32_t>& polygon,
  const std::vector<double>& h,
  const std::function<std::uint32_t(std::uint32_t, std::uint32_t)>& cut)
{
  std::vector<std::uint32_t> out;
  for (std::size_t i = 0; i < polygon.size(); ++i)
  {
    const std::uint32_t a = polygon[i], b = polygon[(i + 1) % polygon.size()];
    const bool ina = h[a] >= 0, inb = h[b] >= 0;
    if (ina)
    {
      out.push_back(a);
    }
    if (ina != inb)
    {
      out.push_back(cut(a, b));
    }
  }
  return out;
}

/// Cuts the mesh by every trim; new vertices are placed by `place(a, b, trim)`.
SurfaceMesh clipByTrims(SurfaceMesh mesh, std::vector<std::unique_ptr<FieldEvaluator>>& trims,
  const std::function<Point3(const Point3&, const Point3&, FieldEvaluator&)>& place)
{
  for (auto& trim : trims)
  {
    std::vector<double> h(mesh.points.size());
    for (std::size_t i = 0; i < mesh.points.size(); ++i)
    {
      const double v = trim->value(mesh.points[i]);
      h[i] = std::isnan(v) ? -1 : v;
    }
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> cuts;
    auto cut = [&](std::uint32_t a, std::uint32_t b)
    {
      const auto key = std::make_pair(std::min(a, b), std::max(a, b));
      auto it = cuts.find(key);
      if (it != cuts.end())
      {
        return it->second;
      }
      const std::uint32_t id = static_cast<std::uint32_t>(mesh.points.size());
      const Point3& in = h[a] >= 0 ? mesh.points[a] : mesh.points[b];
      const Point3& out = h[a] >= 0 ? mesh.points[b] : mesh.points[a];
      mesh.points.push_back(place(in, out, *trim));
      h.push_back(0);
      cuts.emplace(key, id);
      return id;
    };
    std::vector<std::array<std::uint32_t, 3>> kept;
    for (const auto& t : mesh.triangles)
    {
      const std::vector<std::uint32_t> polygon = clipPolygon({ t[0], t[1], t[2] }, h, cut);
      for (std::size_t k = 1; k + 1 < polygon.size(); ++k)
      {
        kept.push_back({ polygon[0], polygon[k], polygon[k + 1] });
      }
    }
    mesh.triangles = std::move(kept);
  }
  // Drop the vertices no triangle uses any more.
  std::vector<std::uint32_t> remap(mesh.points.size(), UINT32_MAX);
  SurfaceMesh out;
  for (const auto& t : mesh.triangles)
  {
    std::array<std::uint32_t, 3> tri;
    for (int k = 0; k < 3; ++k)
    {
      if (remap[t[k]] == UINT32_MAX)
      {
        remap[t[k]] = static_cast<std::uint32_t>(out.points.size());
        out.points.push_back(mesh.points[t[k]]);
      }
      tri[k] = remap[t[k]];
    }
    out.triangles.push_back(tri);
  }
  return out;
}

/// The zero of h between `in` (h >= 0) and `out` (h < 0) by bisection.
Point3 bisect(FieldEvaluator& h, Point3 in, Point3 out, int steps = 40)
{
  for (int i = 0; i < steps; ++i)
  {
    const Point3 m = lerp(in, out, 0.5);
    (h.value(m) >= 0 ? in : out) = m;
  }
  return lerp(in, out, 0.5);
}

/// Chains segments (pairs of vertex ids) into polylines; closed loops repeat their first id.
std::vector<std::vector<std::uint32_t>> chain(
  const std::vector<std::array<std::uint32_t, 2>>& segments, std::size_t vertexCount)
{
  std::vector<std::vector<std::uint32_t>> adjacent(vertexCount);
  for (std::uint32_t s = 0; s < segments.size(); ++s)
  {
    adjacent[segments[s][0]].push_back(s);
    adjacent[segments[s][1]].push_back(s);
  }
  std::vector<char> used(segments.size(), 0);
  std::vector<std::vector<std::uint32_t>> lines;
  auto walk = [&](std::uint32_t start)
  {
    std::vector<std::uint32_t> line{ start };
    std::uint32_t at = start;
    for (;;)
    {
      std::uint32_t next = UINT32_MAX;
      for (std::uint32_t s : adjacent[at])
      {
        if (!used[s])
        {
          used[s] = 1;
          next = segments[s][0] == at ? segments[s][1] : segments[s][0];
          break;
        }
      }
      if (next == UINT32_MAX)
      {
        break;
      }
      line.push_back(next);
      at = next;
      if (at == start)
      {
        break;
      }
    }
    if (line.size() > 1)
    {
      lines.push_back(std::move(line));
    }
  };
  // Open chains first, from their ends (vertices of odd degree), then the loops.
  for (std::uint32_t v = 0; v < vertexCount; ++v)
  {
    if (adjacent[v].size() % 2 == 1)
    {
      walk(v);
    }
  }
  for (std::uint32_t v = 0; v < vertexCount; ++v)
  {
    walk(v);
  }
  return lines;
}

/// Keeps the parts of the polylines where every trim is >= 0, ending exactly on the trims'
/// zero sets (cut points placed by `place`).
CurveSet trimCurves(const CurveSet& in, std::vector<std::unique_ptr<FieldEvaluator>>& trims,
  const std::function<Point3(const Point3&, const Point3&, FieldEvaluator&)>& place)
{
  CurveSet curves = in;
  for (auto& trim : trims)
  {
    std::vector<double> h(curves.points.size());
    for (std::size_t i = 0; i < h.size(); ++i)
    {
      const double v = trim->value(curves.points[i]);
      h[i] = std::isnan(v) ? -1 : v;
    }
    std::vector<std::array<std::uint32_t, 2>> segments;
    for (const auto& line : curves.lines)
    {
      for (std::size_t i = 0; i + 1 < line.size(); ++i)
      {
        const std::uint32_t a = line[i], b = line[i + 1];
        const bool ina = h[a] >= 0, inb = h[b] >= 0;
        if (ina && inb)
        {
          segments.push_back({ a, b });
        }
        else if (ina != inb)
        {
          const std::uint32_t id = static_cast<std::uint32_t>(curves.points.size());
          curves.points.push_back(
            place(curves.points[ina ? a : b], curves.points[ina ? b : a], *trim));
          h.push_back(0);
          segments.push_back({ ina ? a : id, ina ? id : b });
        }
      }
    }
    curves.lines = chain(segments, curves.points.size());
  }
  // Drop the points no line uses any more.
  std::vector<std::uint32_t> remap(curves.points.size(), UINT32_MAX);
  CurveSet out;
  for (auto& line : curves.lines)
  {
    for (auto& id : line)
    {
      if (remap[id] == UINT32_MAX)
      {
        remap[id] = static_cast<std::uint32_t>(out.points.size());
        out.points.push_back(curves.points[id]);
      }
      id = remap[id];
    }
    out.lines.push_back(std::move(line));
  }
  return out;
}

} // namespace

SurfaceMesh trimSurface(const SurfaceMesh& carrierMesh, const frep::Field& carrier,
  const std::vector<frep::FieldPtr>& trims, const ProjectionOptions& options)
{
  auto g = carrier.evaluator();
  auto hs = evaluators(trims);
  return clipByTrims(carrierMesh, hs,
    [&](const Point3& in, const Point3& out, FieldEvaluator& h)
    {
      Point3 p = bisect(h, in, out);
      Point3 q = p;
      if (projectOntoSet({ g.get(), &h }, q, options))
      {
        p = q;
      }
      return p;
    });
}

CurveSet curvesOnSurface(const SurfaceMesh& mesh, const frep::Field& g1, const frep::Field& g2,
  const std::vector<frep::FieldPtr>& trims, const ProjectionOptions& options)
{
  auto e1 = g1.evaluator();
  auto e2 = g2.evaluator();
  std::vector<double> v(mesh.points.size());
  for (std::size_t i = 0; i < v.size(); ++i)
  {
    const double x = e2->value(mesh.points[i]);
    v[i] = std::isnan(x) ? -1 : x;
  }
  CurveSet curves;
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> cuts;
  auto cut = [&](std::uint32_t a, std::uint32_t b)
  {
    const auto key = std::make_pair(std::min(a, b), std::max(a, b));
    auto it = cuts.find(key);
    if (it != cuts.end())
    {
      return it->second;
    }
    const Point3& in = v[a] >= 0 ? mesh.points[a] : mesh.points[b];
    const Point3& out = v[a] >= 0 ? mesh.points[b] : mesh.points[a];
    Point3 p = bisect(*e2, in, out);
    Point3 q = p;
    if (projectOntoSet({ e1.get(), e2.get() }, q, options))
    {
      p = q;
    }
    const std::uint32_t id = static_cast<std::uint32_t>(curves.points.size());
    curves.points.push_back(p);
    cuts.emplace(key, id);
    return id;
  };
  std::vector<std::array<std::uint32_t, 2>> segments;
  for (const auto& t : mesh.triangles)
  {
    std::vector<std::uint32_t> ends;
    for (int k = 0; k < 3; ++k)
    {
      const std::uint32_t a = t[k], b = t[(k + 1) % 3];
      if ((v[a] >= 0) != (v[b] >= 0))
      {
        ends.push_back(cut(a, b));
      }
    }
    if (ends.size() == 2 && ends[0] != ends[1])
    {
      segments.push_back({ ends[0], ends[1] });
    }
  }
  curves.lines = chain(segments, curves.points.size());
  auto hs = evaluators(trims);
  return trimCurves(curves, hs,
    [&](const Point3& in, const Point3& out, FieldEvaluator& h)
    {
      Point3 p = bisect(h, in, out);
      Point3 q = p;
      if (projectOntoSet({ e1.get(), e2.get(), &h }, q, options))
      {
        p = q;
      }
      return p;
    });
}

namespace
{

/// A triangulated grid over the (u, v) rectangle of the box, z = 0.
SurfaceMesh planarGrid(const Box3& box, double size, const char* what)
{
  Box3 flat = box;
  flat.lo[2] = flat.hi[2] = 0;
  checkBox(flat, size, what);
  const auto nu =
    std::max<std::int64_t>(1, std::llround(std::ceil((box.hi[0] - box.lo[0]) / size)));
  const auto nv =
    std::max<std::int64_t>(1, std::llround(std::ceil((box.hi[1] - box.lo[1]) / size)));
  if (double(nu) * double(nv) > 5e7)
  {
    throw std::invalid_argument(std::string(what) + ": the step " + std::to_string(size) +
      " needs " + std::to_string(double(nu) * double(nv)) + " grid cells, more than 5e7");
  }
  SurfaceMesh grid;
  const double du = (box.hi[0] - box.lo[0]) / double(nu), dv = (box.hi[1] - box.lo[1]) / double(nv);
  for (std::int64_t j = 0; j <= nv; ++j)
  {
    for (std::int64_t i = 0; i <= nu; ++i)
    {
      grid.points.push_back({ box.lo[0] + double(i) * du, box.lo[1] + double(j) * dv, 0 });
    }
  }
  auto id = [&](std::int64_t i, std::int64_t j)
  {
    return static_cast<std::uint32_t>(j * (nu + 1) + i);
  };
  for (std::int64_t j = 0; j < nv; ++j)
  {
    for (std::int64_t i = 0; i < nu; ++i)
    {
      grid.triangles.push_back({ id(i, j), id(i + 1, j), id(i + 1, j + 1) });
      grid.triangles.push_back({ id(i, j), id(i + 1, j + 1), id(i, j + 1) });
    }
  }
  return grid;
}

/// Fields of (u, v) ignore z; the plane z = 0 as a carrier keeps projections in the plane.
const frep::FieldPtr& planeZ()
{
  static const frep::FieldPtr z = frep::tapeField(frep::Tape::compile(frep::Expr::z()));
  return z;
}

} // namespace

SurfaceMesh triangulateRegion2D(const frep::Field& f, const Box3& box, double size)
{
  SurfaceMesh grid = planarGrid(box, size, "triangulateRegion2D");
  std::vector<std::unique_ptr<FieldEvaluator>> fs;
  fs.push_back(f.evaluator());
  return clipByTrims(std::move(grid), fs,
    [](const Point3& in, const Point3& out, FieldEvaluator& h) { return bisect(h, in, out); });
}

CurveSet curves2D(const frep::Field& g, const std::vector<frep::FieldPtr>& trims, const Box3& box,
  double size, const ProjectionOptions& options)
{
  const SurfaceMesh grid = planarGrid(box, size, "curves2D");
  return curvesOnSurface(grid, *planeZ(), g, trims, options);
}

PointSet solvePoints(const frep::Field& f1, const frep::Field& f2, const frep::Field& f3,
  const Box3& box, double mergeDistance, const ProjectionOptions& options)
{
  checkBox(box, mergeDistance, "solvePoints");
  auto e1 = f1.evaluator(), e2 = f2.evaluator(), e3 = f3.evaluator();
  std::vector<Point3> found;
  std::vector<Box3> stack{ box };
  double side = 0;
  for (int a = 0; a < 3; ++a)
  {
    side = std::max(side, box.hi[a] - box.lo[a]);
  }
  const double leaf = std::max(mergeDistance, side * 1e-6);
  std::size_t visited = 0;
  while (!stack.empty())
  {
    if (++visited > 2000000)
    {
      throw std::invalid_argument("solvePoints: too many candidate boxes; the fields may vanish "
                                  "on a curve or surface rather than at isolated points");
    }
    const Box3 b = stack.back();
    stack.pop_back();
    bool possible = true;
    for (FieldEvaluator* e : { e1.get(), e2.get(), e3.get() })
    {
      const frep::Interval i = e->bound(b);
      possible = possible && (i.maybeNaN || (i.lo <= 0 && i.hi >= 0));
    }
    if (!possible)
    {
      continue;
    }
    double extent = 0;
    int axis = 0;
    for (int a = 0; a < 3; ++a)
    {
      if (b.hi[a] - b.lo[a] > extent)
      {
        extent = b.hi[a] - b.lo[a];
        axis = a;
      }
    }
    if (extent <= leaf)
    {
      Point3 p = b.centre();
      if (projectOntoSet({ e1.get(), e2.get(), e3.get() }, p, options))
      {
        bool inside = true;
        for (int a = 0; a < 3; ++a)
        {
          inside = inside && p[a] >= box.lo[a] && p[a] <= box.hi[a];
        }
        if (inside)
        {
          found.push_back(p);
        }
      }
      continue;
    }
    Box3 lo = b, hi = b;
    lo.hi[axis] = hi.lo[axis] = 0.5 * (b.lo[axis] + b.hi[axis]);
    stack.push_back(hi);
    stack.push_back(lo);
  }
  std::sort(found.begin(), found.end());
  PointSet out;
  for (const Point3& p : found)
  {
    bool duplicate = false;
    for (const Point3& q : out.points)
    {
      const Point3 d = sub(p, q);
      duplicate = duplicate || dot(d, d) <= mergeDistance * mergeDistance;
    }
    if (!duplicate)
    {
      out.points.push_back(p);
    }
  }
  return out;
}

PointSet keepInside(
  const PointSet& points, const std::vector<frep::FieldPtr>& fields, double tolerance)
{
  auto es = evaluators(fields);
  PointSet out;
  for (const Point3& p : points.points)
  {
    bool keep = true;
    for (auto& e : es)
    {
      keep = keep && e->value(p) >= -tolerance;
    }
    if (keep)
    {
      out.points.push_back(p);
    }
  }
  return out;
}

void mapToSpace(std::vector<Point3>& points, std::vector<PointArray>& pointData,
  const frep::Field& hx, const frep::Field& hy, const frep::Field& hz)
{
  PointArray uv;
  uv.name = "uv";
  uv.components = 2;
  auto ex = hx.evaluator(), ey = hy.evaluator(), ez = hz.evaluator();
  for (Point3& p : points)
  {
    uv.values.push_back(p[0]);
    uv.values.push_back(p[1]);
    p = { ex->value(p), ey->value(p), ez->value(p) };
  }
  pointData.push_back(std::move(uv));
}

} // namespace ictk::discretize
