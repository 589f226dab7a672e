// SPDX-License-Identifier: BSD-3-Clause
#include "Mesh/Quality.h"

#include "FRep/Vector.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <variant>

namespace ictk::mesh
{

namespace
{

constexpr double pi = 3.14159265358979323846;
constexpr double nan = std::numeric_limits<double>::quiet_NaN();

using frep::cross;
using frep::dot;
using frep::sub;

double degrees(double radians)
{
  return radians * 180 / pi;
}

double boxVolume(const frep::Box3& b)
{
  return (b.hi[0] - b.lo[0]) * (b.hi[1] - b.lo[1]) * (b.hi[2] - b.lo[2]);
}

/// Bisects the longest edge.
std::pair<frep::Box3, frep::Box3> bisect(const frep::Box3& b)
{
  int axis = 0;
  for (int a = 1; a < 3; ++a)
  {
    if (b.hi[a] - b.lo[a] > b.hi[axis] - b.lo[axis])
    {
      axis = a;
    }
  }
  const double mid = 0.5 * (b.lo[axis] + b.hi[axis]);
  frep::Box3 first = b, second = b;
  first.hi[axis] = mid;
  second.lo[axis] = mid;
  return { first, second };
}

double longestEdge(const frep::Box3& b)
{
  return std::max({ b.hi[0] - b.lo[0], b.hi[1] - b.lo[1], b.hi[2] - b.lo[2] });
}

enum class Verdict
{
  Inside,
  Outside,
  Undecided
};

Verdict classify(frep::FieldEvaluator& ev, const frep::Box3& box)
{
  const frep::Interval i = ev.bound(box);
  if (i.maybeNaN)
  {
    // NaN nowhere counts as inside; a box that is NaN everywhere is outside.
    return i.empty() ? Verdict::Outside : Verdict::Undecided;
  }
  // The zero set of a field is taken to have no volume: a box where f <= 0 (touching the solid
  // only on its boundary, as the boxes next to a face on a bisection plane) adds nothing.
  if (i.lo >= 0)
  {
    return Verdict::Inside;
  }
  if (i.hi <= 0)
  {
    return Verdict::Outside;
  }
  return Verdict::Undecided;
}

/// Accumulates the volume of one top-level box, depth first.
class Integrator
{
public:
  explicit Integrator(double tolerance)
    : tolerance_(tolerance)
  {
  }

  void run(frep::FieldEvaluator& ev, const frep::Box3& box, int depth)
  {
    switch (classify(ev, box))
    {
      case Verdict::Inside:
        result.provenInside += boxVolume(box);
        return;
      case Verdict::Outside:
        return;
      case Verdict::Undecided:
        break;
    }
    if (longestEdge(box) <= tolerance_)
    {
      sample(ev, box);
      return;
    }
    // Every third level (a full octree step), a tape pruned to this box may be cheaper.
    std::unique_ptr<frep::FieldEvaluator> narrowed;
    if (depth % 3 == 2)
    {
      narrowed = ev.narrowed(box);
    }
    frep::FieldEvaluator& next = narrowed ? *narrowed : ev;
    const auto halves = bisect(box);
    run(next, halves.first, depth + 1);
    run(next, halves.second, depth + 1);
  }

  VolumeEstimate result;

private:
  static constexpr int n = 4;

  void sample(frep::FieldEvaluator& ev, const frep::Box3& box)
  {
    double x[n * n * n], y[n * n * n], z[n * n * n], f[n * n * n];
    int k = 0;
    for (int i = 0; i < n; ++i)
    {
      for (int j = 0; j < n; ++j)
      {
        for (int l = 0; l < n; ++l, ++k)
        {
          x[k] = box.lo[0] + (i + 0.5) / n * (box.hi[0] - box.lo[0]);
          y[k] = box.lo[1] + (j + 0.5) / n * (box.hi[1] - box.lo[1]);
          z[k] = box.lo[2] + (l + 0.5) / n * (box.hi[2] - box.lo[2]);
        }
      }
    }
    ev.values(x, y, z, f, n * n * n);
    int inside = 0;
    for (double v : f)
    {
      inside += v >= 0 ? 1 : 0;
    }
    const double fraction = static_cast<double>(inside) / (n * n * n);
    const double volume = boxVolume(box);
    result.volume += fraction * volume;
    result.undecided += volume;
    result.errorBound += std::max(fraction, 1 - fraction) * volume;
    ++result.sampledBoxes;
  }

  double tolerance_;
};

} // namespace

TetShape tetShape(const Point3& a, const Point3& b, const Point3& c, const Point3& d)
{
  const Point3 p[4] = { a, b, c, d };
  TetShape s;
  const Point3 e1 = sub(b, a), e2 = sub(c, a), e3 = sub(d, a);
  const double det = orientation(a, b, c, d);
  s.volume = det / 6;

  // Outward unit normals of the faces opposite each vertex.
  Point3 normal[4];
  bool degenerate = false;
  for (int k = 0; k < 4; ++k)
  {
    const Point3& q0 = p[(k + 1) % 4];
    const Point3& q1 = p[(k + 2) % 4];
    const Point3& q2 = p[(k + 3) % 4];
    Point3 nk = cross(sub(q1, q0), sub(q2, q0));
    if (dot(nk, sub(p[k], q0)) > 0)
    {
      nk = { -nk[0], -nk[1], -nk[2] };
    }
    const double len = std::sqrt(dot(nk, nk));
    if (!(len > 0))
    {
      degenerate = true;
      normal[k] = { 0, 0, 0 };
      continue;
    }
    normal[k] = { nk[0] / len, nk[1] / len, nk[2] / len };
  }
  if (degenerate || det == 0)
  {
    s.minDihedralDegrees = 0;
    s.maxDihedralDegrees = 180;
    s.radiusEdgeRatio = std::numeric_limits<double>::infinity();
    return s;
  }
  double lo = 180, hi = 0;
  for (int k = 0; k < 4; ++k)
  {
    for (int l = k + 1; l < 4; ++l)
    {
      const double cosine = std::clamp(dot(normal[k], normal[l]), -1.0, 1.0);
      const double angle = degrees(pi - std::acos(cosine));
      lo = std::min(lo, angle);
      hi = std::max(hi, angle);
    }
  }
  s.minDihedralDegrees = lo;
  s.maxDihedralDegrees = hi;

  // Circumcentre relative to a: (|e1|^2 e2 x e3 + |e2|^2 e3 x e1 + |e3|^2 e1 x e2) / (2 det).
  const Point3 c23 = cross(e2, e3), c31 = cross(e3, e1), c12 = cross(e1, e2);
  const double l1 = dot(e1, e1), l2 = dot(e2, e2), l3 = dot(e3, e3);
  Point3 centre;
  for (int i = 0; i < 3; ++i)
  {
    centre[i] = (l1 * c23[i] + l2 * c31[i] + l3 * c12[i]) / (2 * det);
  }
  const double radius = std::sqrt(dot(centre, centre));
  double shortest = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 4; ++i)
  {
    for (int j = i + 1; j < 4; ++j)
    {
      const Point3 e = sub(p[j], p[i]);
      shortest = std::min(shortest, std::sqrt(dot(e, e)));
    }
  }
  s.radiusEdgeRatio = radius / shortest;
  return s;
}

QualityReport measureQuality(const TetMesh& mesh)
{
  QualityReport r;
  r.points = mesh.points.size();
  r.tetrahedra = mesh.tetrahedra.size();
  r.materials.resize(mesh.materialNames.size());
  for (std::size_t m = 0; m < mesh.materialNames.size(); ++m)
  {
    r.materials[m].material = static_cast<std::int32_t>(m + 1);
    r.materials[m].name = mesh.materialNames[m];
    r.materials[m].minDihedralDegrees = nan;
  }
  if (mesh.tetrahedra.empty())
  {
    r.minDihedralDegrees = r.maxDihedralDegrees = r.minDihedralPercentile1Degrees = nan;
    r.maxRadiusEdgeRatio = r.meanRadiusEdgeRatio = nan;
    return r;
  }
  std::vector<double> minima(mesh.tetrahedra.size());
  r.minDihedralDegrees = 180;
  r.maxDihedralDegrees = 0;
  r.maxRadiusEdgeRatio = 0;
  double ratioSum = 0;
  for (std::size_t t = 0; t < mesh.tetrahedra.size(); ++t)
  {
    const auto& tet = mesh.tetrahedra[t];
    for (auto i : tet)
    {
      if (i >= mesh.points.size())
      {
        throw std::invalid_argument("tetrahedral mesh: tetrahedron " + std::to_string(t) +
          " uses point " + std::to_string(i) + " of " + std::to_string(mesh.points.size()));
      }
    }
    const TetShape s =
      tetShape(mesh.points[tet[0]], mesh.points[tet[1]], mesh.points[tet[2]], mesh.points[tet[3]]);
    minima[t] = s.minDihedralDegrees;
    r.volume += s.volume;
    r.minDihedralDegrees = std::min(r.minDihedralDegrees, s.minDihedralDegrees);
    r.maxDihedralDegrees = std::max(r.maxDihedralDegrees, s.maxDihedralDegrees);
    r.maxRadiusEdgeRatio = std::max(r.maxRadiusEdgeRatio, s.radiusEdgeRatio);
    ratioSum += s.radiusEdgeRatio;
    r.nonPositive += s.volume > 0 ? 0 : 1;
    if (t < mesh.materials.size() && mesh.materials[t] >= 1 &&
      static_cast<std::size_t>(mesh.materials[t]) <= r.materials.size())
    {
      auto& m = r.materials[static_cast<std::size_t>(mesh.materials[t] - 1)];
      ++m.tetrahedra;
      m.volume += s.volume;
      m.minDihedralDegrees = std::isnan(m.minDihedralDegrees)
        ? s.minDihedralDegrees
        : std::min(m.minDihedralDegrees, s.minDihedralDegrees);
    }
  }
  r.meanRadiusEdgeRatio = ratioSum / static_cast<double>(mesh.tetrahedra.size());
  const auto rank = static_cast<std::size_t>(0.01 * static_cast<double>(minima.size() - 1));
  std::nth_element(
    minima.begin(), minima.begin() + static_cast<std::ptrdiff_t>(rank), minima.end());
  r.minDihedralPercentile1Degrees = minima[rank];
  return r;
}

std::string formatQualityReport(const QualityReport& r)
{
  std::string out;
  char line[512];
  std::snprintf(line, sizeof line, "points %zu, tetrahedra %zu, volume %.9g\n", r.points,
    r.tetrahedra, r.volume);
  out += line;
  std::snprintf(line, sizeof line,
    "dihedral angles: min %.4g deg (1st percentile %.4g deg), max %.4g deg\n", r.minDihedralDegrees,
    r.minDihedralPercentile1Degrees, r.maxDihedralDegrees);
  out += line;
  std::snprintf(line, sizeof line, "radius-edge ratio: max %.4g, mean %.4g (regular: 0.6124)\n",
    r.maxRadiusEdgeRatio, r.meanRadiusEdgeRatio);
  out += line;
  if (r.nonPositive > 0)
  {
    std::snprintf(line, sizeof line, "non-positive tetrahedra: %zu\n", r.nonPositive);
    out += line;
  }
  for (const auto& m : r.materials)
  {
    std::snprintf(line, sizeof line,
      "material %d '%s': %zu tetrahedra, volume %.9g, min dihedral %.4g deg\n", m.material,
      m.name.c_str(), m.tetrahedra, m.volume, m.minDihedralDegrees);
    out += line;
  }
  return out;
}

VolumeEstimate integrateVolume(const frep::Field& solid, const frep::Box3& bounds, double tolerance)
{
  for (int a = 0; a < 3; ++a)
  {
    if (!std::isfinite(bounds.lo[a]) || !std::isfinite(bounds.hi[a]) || bounds.lo[a] > bounds.hi[a])
    {
      throw std::invalid_argument("volume integration: the bounds must be a finite box");
    }
  }
  const double longest = longestEdge(bounds);
  if (!(tolerance > 0) || !std::isfinite(tolerance))
  {
    throw std::invalid_argument("volume integration: the tolerance must be a positive number");
  }
  if (longest / tolerance > 4096)
  {
    throw std::invalid_argument("volume integration: tolerance " + std::to_string(tolerance) +
      " is below 1/4096 of the box's longest edge " + std::to_string(longest));
  }
  if (boxVolume(bounds) == 0)
  {
    return {};
  }
  // Breadth first until there is work for every thread; then the boxes in parallel, each with
  // its own evaluator, summed in a fixed order (the result does not depend on the threads).
  VolumeEstimate total;
  std::vector<frep::Box3> boxes{ bounds }, next;
  auto ev = solid.evaluator();
  int depth = 0;
  while (!boxes.empty() && boxes.size() < 256 && depth < 12)
  {
    next.clear();
    for (const auto& b : boxes)
    {
      const Verdict v = classify(*ev, b);
      if (v == Verdict::Inside)
      {
        total.provenInside += boxVolume(b);
      }
      else if (v == Verdict::Undecided)
      {
        if (longestEdge(b) <= tolerance)
        {
          Integrator leaf(tolerance);
          leaf.run(*ev, b, 0);
          total.provenInside += leaf.result.provenInside;
          total.volume += leaf.result.volume;
          total.undecided += leaf.result.undecided;
          total.errorBound += leaf.result.errorBound;
          total.sampledBoxes += leaf.result.sampledBoxes;
        }
        else
        {
          const auto halves = bisect(b);
          next.push_back(halves.first);
          next.push_back(halves.second);
        }
      }
    }
    boxes.swap(next);
    ++depth;
  }
  std::vector<VolumeEstimate> parts(boxes.size());
  tbb::parallel_for(std::size_t(0), boxes.size(),
    [&](std::size_t i)
    {
      auto local = solid.evaluator();
      auto narrowed = local->narrowed(boxes[i]);
      Integrator integrator(tolerance);
      integrator.run(narrowed ? *narrowed : *local, boxes[i], 0);
      parts[i] = integrator.result;
    });
  for (const auto& p : parts)
  {
    total.provenInside += p.provenInside;
    total.volume += p.volume;
    total.undecided += p.undecided;
    total.errorBound += p.errorBound;
    total.sampledBoxes += p.sampledBoxes;
  }
  total.volume += total.provenInside;
  return total;
}

VolumeEstimate cellVolumeEstimate(const complex::Cell& cell, double tolerance)
{
  if (cell.dimension != 3)
  {
    throw std::invalid_argument("cell '" + cell.name + "' is " + std::to_string(cell.dimension) +
      "D: only 3D cells have a volume");
  }
  if (const auto* e = std::get_if<complex::ExplicitGeometry>(&cell.geometry))
  {
    VolumeEstimate r;
    for (const auto& t : e->tetrahedra)
    {
      r.volume += std::abs(
        tetShape(e->points.at(t[0]), e->points.at(t[1]), e->points.at(t[2]), e->points.at(t[3]))
          .volume);
    }
    r.provenInside = r.volume;
    return r;
  }
  const auto* g = std::get_if<complex::ImplicitGeometry>(&cell.geometry);
  if (!g || !g->carriers.empty() || g->inside.empty())
  {
    throw std::invalid_argument(
      "cell '" + cell.name + "': only implicit solids and explicit tetrahedra have a volume here");
  }
  const frep::FieldPtr solid = g->inside.size() == 1 ? g->inside[0] : frep::minField(g->inside);
  try
  {
    return integrateVolume(*solid, g->bounds, tolerance);
  }
  catch (const std::invalid_argument& e)
  {
    throw std::invalid_argument("cell '" + cell.name + "': " + e.what());
  }
}

double cellVolume(const complex::Cell& cell, double tolerance)
{
  return cellVolumeEstimate(cell, tolerance).volume;
}

std::vector<VolumeComparison> compareVolumes(
  const TetMesh& mesh, const complex::Complex& complex, double tolerance)
{
  const QualityReport q = measureQuality(mesh);
  std::vector<VolumeComparison> out;
  for (const auto& m : q.materials)
  {
    const complex::Cell* cell = complex.findCell(m.name);
    if (!cell)
    {
      throw std::invalid_argument("material " + std::to_string(m.material) + " '" + m.name +
        "' names no cell of the complex");
    }
    const VolumeEstimate exact = cellVolumeEstimate(*cell, tolerance);
    VolumeComparison c;
    c.material = m.material;
    c.name = m.name;
    c.cell = cell->id;
    c.meshVolume = m.volume;
    c.cellVolume = exact.volume;
    c.cellErrorBound = exact.errorBound;
    c.relativeDifference = exact.volume != 0 ? (m.volume - exact.volume) / exact.volume : nan;
    out.push_back(c);
  }
  return out;
}

std::string formatVolumeComparison(const std::vector<VolumeComparison>& comparison)
{
  std::string out;
  char line[512];
  for (const auto& c : comparison)
  {
    std::snprintf(line, sizeof line,
      "material %d '%s': mesh volume %.9g, cell volume %.9g (+- %.3g), difference %+.3f%%\n",
      c.material, c.name.c_str(), c.meshVolume, c.cellVolume, c.cellErrorBound,
      100 * c.relativeDifference);
    out += line;
  }
  return out;
}

} // namespace ictk::mesh
