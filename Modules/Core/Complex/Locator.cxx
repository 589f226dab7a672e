// SPDX-License-Identifier: BSD-3-Clause
#include "Complex/Locator.h"

#include "FRep/Vector.h"

#include <algorithm>
#include <cmath>
#include <map>

namespace ictk::complex
{
namespace
{

constexpr double kInf = std::numeric_limits<double>::infinity();

using frep::distance;
using frep::dot;
using frep::norm;
using frep::sub;

/// |f| / |grad f|: the distance to {f = 0} to first order. A vanishing gradient gives |f|
/// itself, which is large where f is, and so never claims a far point is near.
double levelDistance(frep::FieldEvaluator& f, const Point3& p, double* value = nullptr)
{
  Point3 g;
  const double v = f.gradient(p, g);
  if (value)
  {
    *value = v;
  }
  if (!std::isfinite(v))
  {
    return kInf;
  }
  const double n = norm(g);
  return n > 1e-12 ? std::abs(v) / n : std::abs(v);
}

/// Primitives of a discretisation, with a box for early rejection.
struct Elements
{
  std::vector<Point3> points;
  std::vector<std::array<Point3, 2>> segments;
  std::vector<std::array<Point3, 3>> triangles;
  Box3 box{ { kInf, kInf, kInf }, { -kInf, -kInf, -kInf } };

  bool empty() const { return points.empty() && segments.empty() && triangles.empty(); }
  void grow(const Point3& p)
  {
    for (int a = 0; a < 3; ++a)
    {
      box.lo[a] = std::min(box.lo[a], p[a]);
      box.hi[a] = std::max(box.hi[a], p[a]);
    }
  }
  void finish()
  {
    for (const auto& p : points)
    {
      grow(p);
    }
    for (const auto& s : segments)
    {
      grow(s[0]);
      grow(s[1]);
    }
    for (const auto& t : triangles)
    {
      grow(t[0]);
      grow(t[1]);
      grow(t[2]);
    }
  }
  double distance(const Point3& p) const
  {
    if (empty())
    {
      return kInf;
    }
    double best = kInf;
    for (const auto& q : points)
    {
      best = std::min(best, norm(sub(p, q)));
    }
    for (const auto& s : segments)
    {
      best = std::min(best, segmentDistance(p, s[0], s[1]));
    }
    for (const auto& t : triangles)
    {
      best = std::min(best, triangleDistance(p, t[0], t[1], t[2]));
    }
    return best;
  }
};

} // namespace

double segmentDistance(const Point3& p, const Point3& a, const Point3& b)
{
  const Point3 ab = sub(b, a);
  const double len2 = dot(ab, ab);
  double t = len2 > 0 ? dot(sub(p, a), ab) / len2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  const Point3 q{ a[0] + t * ab[0], a[1] + t * ab[1], a[2] + t * ab[2] };
  return norm(sub(p, q));
}

double triangleDistance(const Point3& p, const Point3& a, const Point3& b, const Point3& c)
{
  // Project onto the plane; inside the triangle the plane distance is the answer, otherwise the
  // nearest point lies on an edge.
  const Point3 ab = sub(b, a), ac = sub(c, a), ap = sub(p, a);
  const Point3 n{ ab[1] * ac[2] - ab[2] * ac[1], ab[2] * ac[0] - ab[0] * ac[2],
    ab[0] * ac[1] - ab[1] * ac[0] };
  const double n2 = dot(n, n);
  if (n2 > 0)
  {
    const double d00 = dot(ab, ab), d01 = dot(ab, ac), d11 = dot(ac, ac);
    const double d20 = dot(ap, ab), d21 = dot(ap, ac);
    const double denom = d00 * d11 - d01 * d01;
    const double v = (d11 * d20 - d01 * d21) / denom;
    const double w = (d00 * d21 - d01 * d20) / denom;
    if (v >= 0 && w >= 0 && v + w <= 1)
    {
      return std::abs(dot(ap, n)) / std::sqrt(n2);
    }
  }
  return std::min({ segmentDistance(p, a, b), segmentDistance(p, b, c), segmentDistance(p, c, a) });
}

struct CellLocator::Impl
{
  const CellMesh* mesh = nullptr;
  // Implicit cells: evaluators of carriers and of the intersection of the inside fields.
  std::vector<std::unique_ptr<frep::FieldEvaluator>> carriers;
  std::unique_ptr<frep::FieldEvaluator> inside;
  bool implicit = false;
  Elements cellElements;
  Elements boundaryElements;
  bool boundaryIsCell = false; ///< closed curves: every point may be the attaching vertex
};

CellLocator::CellLocator(const Cell& cell, const CellMesh& mesh)
  : cell_(&cell)
  , impl_(std::make_unique<Impl>())
{
  Impl& m = *impl_;
  m.mesh = &mesh;
  if (const auto* g = std::get_if<ImplicitGeometry>(&cell.geometry))
  {
    m.implicit = true;
    for (const auto& c : g->carriers)
    {
      m.carriers.push_back(c->evaluator());
    }
    if (!g->inside.empty())
    {
      m.inside = (g->inside.size() == 1 ? g->inside[0] : frep::minField(g->inside))->evaluator();
    }
  }
  // Elements of the discretisation and of its boundary.
  Elements& e = m.cellElements;
  Elements& b = m.boundaryElements;
  switch (cell.dimension)
  {
    case 0:
      e.points = mesh.points.points;
      break;
    case 1:
    {
      const auto& curves = mesh.curves;
      bool anyOpen = false;
      for (const auto& line : curves.lines)
      {
        for (std::size_t i = 0; i + 1 < line.size(); ++i)
        {
          e.segments.push_back({ curves.points[line[i]], curves.points[line[i + 1]] });
        }
        const bool closed = line.size() > 2 && line.front() == line.back();
        if (!closed && !line.empty())
        {
          anyOpen = true;
          b.points.push_back(curves.points[line.front()]);
          b.points.push_back(curves.points[line.back()]);
        }
      }
      m.boundaryIsCell = !anyOpen;
      break;
    }
    default:
    {
      const auto& s = mesh.surface;
      for (const auto& t : s.triangles)
      {
        e.triangles.push_back({ s.points[t[0]], s.points[t[1]], s.points[t[2]] });
      }
      if (cell.dimension == 2)
      {
        // The boundary of a patch: edges used by one triangle.
        std::map<std::pair<std::uint32_t, std::uint32_t>, int> uses;
        for (const auto& t : s.triangles)
        {
          for (int k = 0; k < 3; ++k)
          {
            const auto a = t[k], c = t[(k + 1) % 3];
            ++uses[{ std::min(a, c), std::max(a, c) }];
          }
        }
        for (const auto& [edge, count] : uses)
        {
          if (count == 1)
          {
            b.segments.push_back({ s.points[edge.first], s.points[edge.second] });
          }
        }
      }
      else
      {
        // A solid's boundary is its surface mesh; its inside is decided by the fields, or for an
        // explicit solid by the mesh.
        b.triangles = e.triangles;
      }
    }
  }
  e.finish();
  b.finish();
}

CellLocator::~CellLocator() = default;
CellLocator::CellLocator(CellLocator&&) noexcept = default;

double CellLocator::distance(const Point3& p)
{
  Impl& m = *impl_;
  if (m.implicit)
  {
    double d = 0;
    for (auto& c : m.carriers)
    {
      d = std::max(d, levelDistance(*c, p));
    }
    if (m.inside)
    {
      double v = 0;
      const double dl = levelDistance(*m.inside, p, &v);
      if (!(v >= 0))
      {
        d = std::max(d, dl);
      }
    }
    return d;
  }
  if (cell_->dimension == 3)
  {
    // An explicit solid contains p when the winding number of its boundary around p is non-zero
    // (the sum of the solid angles of its triangles, robust on closed meshes).
    const Elements& e = m.cellElements;
    double omega = 0;
    for (const auto& t : e.triangles)
    {
      const Point3 a = sub(t[0], p), b = sub(t[1], p), c = sub(t[2], p);
      const double la = norm(a), lb = norm(b), lc = norm(c);
      const double det = a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
        a[2] * (b[0] * c[1] - b[1] * c[0]);
      const double den = la * lb * lc + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb;
      omega += 2 * std::atan2(det, den);
    }
    if (std::abs(omega) > 2 * M_PI)
    {
      return 0;
    }
  }
  return m.cellElements.distance(p);
}

double CellLocator::boundaryDistance(const Point3& p)
{
  Impl& m = *impl_;
  if (cell_->dimension == 0)
  {
    return kInf;
  }
  if (m.implicit && cell_->dimension >= 2)
  {
    // Solid: on {min H = 0}. Patch: on its carrier and on {min H = 0}.
    double d = 0;
    for (auto& c : m.carriers)
    {
      d = std::max(d, levelDistance(*c, p));
    }
    return m.inside ? std::max(d, levelDistance(*m.inside, p)) : kInf;
  }
  if (m.boundaryIsCell)
  {
    return distance(p);
  }
  return m.boundaryElements.distance(p);
}

std::vector<Point3> CellLocator::samples(std::size_t maxCount) const
{
  const std::vector<Point3>& all = impl_->mesh->vertices();
  if (all.size() <= maxCount || maxCount == 0)
  {
    return all;
  }
  std::vector<Point3> out;
  out.reserve(maxCount);
  for (std::size_t i = 0; i < maxCount; ++i)
  {
    out.push_back(all[i * all.size() / maxCount]);
  }
  return out;
}

} // namespace ictk::complex
