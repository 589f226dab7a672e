// SPDX-License-Identifier: BSD-3-Clause
#include "Mesh/Validity.h"

#include "FRep/Vector.h"

#include <tbb/parallel_sort.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <unordered_map>
#include <variant>

namespace ictk::mesh
{
namespace
{

constexpr double kInf = std::numeric_limits<double>::infinity();

/// Unit vectors: the 6 axes and the 8 diagonals.
constexpr double kD = 0.57735026918962576;
constexpr Point3 kDirections[14] = { { 1, 0, 0 }, { -1, 0, 0 }, { 0, 1, 0 }, { 0, -1, 0 },
  { 0, 0, 1 }, { 0, 0, -1 }, { kD, kD, kD }, { kD, kD, -kD }, { kD, -kD, kD }, { kD, -kD, -kD },
  { -kD, kD, kD }, { -kD, kD, -kD }, { -kD, -kD, kD }, { -kD, -kD, -kD } };

using frep::cross;
using frep::distance;
using frep::dot;
using frep::sub;

std::string number(double v)
{
  std::ostringstream s;
  s.precision(4);
  s << v;
  return s.str();
}

std::string pointText(const Point3& p)
{
  std::ostringstream s;
  s.precision(7);
  s << "(" << p[0] << ", " << p[1] << ", " << p[2] << ")";
  return s.str();
}

Point3 centroid(const TetMesh& mesh, const std::uint32_t* v, int n)
{
  Point3 c{ 0, 0, 0 };
  for (int k = 0; k < n; ++k)
  {
    for (int a = 0; a < 3; ++a)
    {
      c[a] += mesh.points[v[k]][a] / n;
    }
  }
  return c;
}

std::string cellText(const TetMesh& mesh, std::size_t tet)
{
  const std::int32_t m = mesh.materials[tet];
  return "tetrahedron " + std::to_string(tet) + " of '" +
    mesh.materialNames[static_cast<std::size_t>(m - 1)] + "'";
}

/// Points with another point within `tolerance`: a hash grid of that cell size, 27 neighbours.
std::size_t duplicatePoints(const TetMesh& mesh, double tolerance, std::size_t& first)
{
  struct KeyHash
  {
    std::size_t operator()(const std::array<std::int64_t, 3>& k) const
    {
      return static_cast<std::size_t>(k[0] * 73856093 ^ k[1] * 19349663 ^ k[2] * 83492791);
    }
  };
  std::unordered_map<std::array<std::int64_t, 3>, std::vector<std::uint32_t>, KeyHash> grid;
  auto keyOf = [&](const Point3& p)
  {
    return std::array<std::int64_t, 3>{ static_cast<std::int64_t>(std::floor(p[0] / tolerance)),
      static_cast<std::int64_t>(std::floor(p[1] / tolerance)),
      static_cast<std::int64_t>(std::floor(p[2] / tolerance)) };
  };
  for (std::uint32_t i = 0; i < mesh.points.size(); ++i)
  {
    grid[keyOf(mesh.points[i])].push_back(i);
  }
  std::size_t count = 0;
  first = mesh.points.size();
  for (std::uint32_t i = 0; i < mesh.points.size(); ++i)
  {
    const auto k = keyOf(mesh.points[i]);
    bool duplicate = false;
    for (int dx = -1; dx <= 1 && !duplicate; ++dx)
    {
      for (int dy = -1; dy <= 1 && !duplicate; ++dy)
      {
        for (int dz = -1; dz <= 1 && !duplicate; ++dz)
        {
          const auto it = grid.find({ k[0] + dx, k[1] + dy, k[2] + dz });
          if (it == grid.end())
          {
            continue;
          }
          for (const std::uint32_t j : it->second)
          {
            if (j != i && distance(mesh.points[i], mesh.points[j]) <= tolerance)
            {
              duplicate = true;
              break;
            }
          }
        }
      }
    }
    if (duplicate)
    {
      first = std::min<std::size_t>(first, i);
      ++count;
    }
  }
  return count;
}

/// Which points lie in some 3D cell of the complex (implicit cells: inside their bounds with every
/// inside field >= 0).
class CellMembership
{
public:
  explicit CellMembership(const complex::Complex& complex)
  {
    for (const complex::CellId id : complex.cellsOfDimension(3))
    {
      const auto* g = std::get_if<complex::ImplicitGeometry>(&complex.cell(id).geometry);
      Cell c;
      if (g && g->carriers.empty() && !g->inside.empty())
      {
        c.bounds = g->bounds;
        for (const auto& f : g->inside)
        {
          c.inside.push_back(f->evaluator());
        }
      }
      else
      {
        c.evaluable = false;
        c.bounds = complex.cell(id).bounds();
      }
      cells_.push_back(std::move(c));
    }
  }

  /// true: p is in some cell; false: in none; nullopt: in no cell that can be evaluated, but in
  /// the bounds of one that cannot.
  std::optional<bool> inside(const Point3& p)
  {
    bool unknown = false;
    for (Cell& c : cells_)
    {
      bool in = true;
      for (int a = 0; a < 3; ++a)
      {
        in = in && p[a] >= c.bounds.lo[a] && p[a] <= c.bounds.hi[a];
      }
      if (!in)
      {
        continue;
      }
      if (!c.evaluable)
      {
        unknown = true;
        continue;
      }
      for (auto& e : c.inside)
      {
        in = in && e->value(p) >= 0;
      }
      if (in)
      {
        return true;
      }
    }
    return unknown ? std::nullopt : std::optional<bool>(false);
  }

private:
  struct Cell
  {
    bool evaluable = true;
    frep::Box3 bounds;
    std::vector<std::unique_ptr<frep::FieldEvaluator>> inside;
  };
  std::vector<Cell> cells_;
};

} // namespace

ValidityReport checkValidity(
  const TetMesh& mesh, double size, const complex::Complex* complex, const ValidityLimits& limits)
{
  validateStructure(mesh);
  ValidityReport r;
  r.points = mesh.points.size();
  r.tetrahedra = mesh.tetrahedra.size();
  static constexpr int edges[6][2] = { { 0, 1 }, { 0, 2 }, { 0, 3 }, { 1, 2 }, { 1, 3 }, { 2, 3 } };
  if (!(size > 0) || !std::isfinite(size))
  {
    double sum = 0;
    for (const auto& t : mesh.tetrahedra)
    {
      for (const auto& e : edges)
      {
        sum += distance(mesh.points[t[e[0]]], mesh.points[t[e[1]]]);
      }
    }
    size = mesh.tetrahedra.empty() ? 1 : sum / (6.0 * double(mesh.tetrahedra.size()));
  }
  r.size = size;
  const double regular = size * size * size / (6 * std::sqrt(2.0));

  // Edges, volumes, orientation.
  r.minEdge = kInf;
  r.minVolume = kInf;
  std::size_t shortestAt = 0, smallestAt = 0, firstInverted = mesh.tetrahedra.size();
  for (std::size_t t = 0; t < mesh.tetrahedra.size(); ++t)
  {
    const auto& tet = mesh.tetrahedra[t];
    double shortest = kInf;
    for (const auto& e : edges)
    {
      shortest = std::min(shortest, distance(mesh.points[tet[e[0]]], mesh.points[tet[e[1]]]));
    }
    const double volume = orientation(mesh.points[tet[0]], mesh.points[tet[1]], mesh.points[tet[2]],
                            mesh.points[tet[3]]) /
      6;
    if (shortest < r.minEdge)
    {
      r.minEdge = shortest;
      shortestAt = t;
    }
    if (volume < r.minVolume)
    {
      r.minVolume = volume;
      smallestAt = t;
    }
    r.shortEdges += shortest < limits.minEdge * size ? 1 : 0;
    r.smallVolumes += volume < limits.minVolume * regular ? 1 : 0;
    if (!(volume > 0))
    {
      ++r.nonPositive;
      firstInverted = std::min(firstInverted, t);
    }
  }
  if (mesh.tetrahedra.empty())
  {
    r.minEdge = r.minVolume = std::numeric_limits<double>::quiet_NaN();
  }
  r.minEdgeRelative = r.minEdge / size;
  r.minVolumeRelative = r.minVolume / regular;
  if (r.nonPositive > 0)
  {
    const auto& tet = mesh.tetrahedra[firstInverted];
    r.problems.push_back(std::to_string(r.nonPositive) +
      " tetrahedra are not positively oriented (the first, " + cellText(mesh, firstInverted) +
      ", at " + pointText(centroid(mesh, tet.data(), 4)) + ")");
  }
  if (r.shortEdges > 0)
  {
    r.problems.push_back(std::to_string(r.shortEdges) + " tetrahedra have an edge shorter than " +
      number(limits.minEdge) + " x size " + number(size) + " (the shortest, " + number(r.minEdge) +
      ", in " + cellText(mesh, shortestAt) + " at " +
      pointText(centroid(mesh, mesh.tetrahedra[shortestAt].data(), 4)) + ")");
  }
  if (r.smallVolumes > r.nonPositive)
  {
    r.problems.push_back(std::to_string(r.smallVolumes) + " tetrahedra have a volume below " +
      number(limits.minVolume) + " of a regular tetrahedron of edge " + number(size) +
      " (the smallest, " + number(r.minVolume) + ", " + cellText(mesh, smallestAt) + " at " +
      pointText(centroid(mesh, mesh.tetrahedra[smallestAt].data(), 4)) + ")");
  }

  // Coincident vertices.
  std::size_t firstDuplicate = 0;
  r.duplicatePoints = duplicatePoints(mesh, limits.duplicateDistance * size, firstDuplicate);
  if (r.duplicatePoints > 0)
  {
    r.problems.push_back(std::to_string(r.duplicatePoints) + " points lie within " +
      number(limits.duplicateDistance * size) + " of another point (the first at " +
      pointText(mesh.points[firstDuplicate]) + ")");
  }

  // Conformity: faces sorted by their vertices.
  struct Face
  {
    std::array<std::uint32_t, 3> v;
    std::uint32_t tet;
    std::uint8_t opposite;
  };
  std::vector<Face> faces;
  faces.reserve(4 * mesh.tetrahedra.size());
  for (std::size_t t = 0; t < mesh.tetrahedra.size(); ++t)
  {
    const auto& tet = mesh.tetrahedra[t];
    for (std::uint8_t k = 0; k < 4; ++k)
    {
      std::array<std::uint32_t, 3> v{ tet[(k + 1) % 4], tet[(k + 2) % 4], tet[(k + 3) % 4] };
      std::sort(v.begin(), v.end());
      faces.push_back({ v, static_cast<std::uint32_t>(t), k });
    }
  }
  // The sort is most of the check's time (6 M faces at 1.5 M tetrahedra); the keys are unique
  // (face, tetrahedron), so the parallel sort's order is the sequential one.
  tbb::parallel_sort(faces.begin(), faces.end(),
    [](const Face& a, const Face& b) { return a.v != b.v ? a.v < b.v : a.tet < b.tet; });
  std::optional<CellMembership> membership;
  if (complex)
  {
    membership.emplace(*complex);
  }
  std::size_t firstNonConforming = faces.size(), firstStray = faces.size();
  for (std::size_t i = 0; i < faces.size();)
  {
    std::size_t j = i + 1;
    while (j < faces.size() && faces[j].v == faces[i].v)
    {
      ++j;
    }
    const Face& f = faces[i];
    if (j - i == 2)
    {
      ++r.interiorFaces;
      const Point3& a = mesh.points[f.v[0]];
      const Point3& b = mesh.points[f.v[1]];
      const Point3& c = mesh.points[f.v[2]];
      const double s0 = orientation(a, b, c, mesh.points[mesh.tetrahedra[f.tet][f.opposite]]);
      const double s1 =
        orientation(a, b, c, mesh.points[mesh.tetrahedra[faces[i + 1].tet][faces[i + 1].opposite]]);
      if (!(s0 * s1 < 0))
      {
        ++r.nonConformingFaces;
        firstNonConforming = std::min(firstNonConforming, i);
      }
    }
    else if (j - i > 2)
    {
      r.nonConformingFaces += 1;
      firstNonConforming = std::min(firstNonConforming, i);
    }
    else
    {
      // A face of one tetrahedron is on the boundary of the complex's solids when some point
      // within one probe length of it lies in no cell: along its outward normal first (steps
      // from 1 % of the probe, so that a gap between two parts of a solid narrower than a step
      // does not hide it), then along the 14 directions (a thin rim a backend cut shorter lies
      // beside the face, not ahead of it).
      ++r.boundaryFaces;
      if (!membership)
      {
        ++r.uncheckedBoundaryFaces;
      }
      else
      {
        const Point3& a = mesh.points[f.v[0]];
        const Point3 c = centroid(mesh, f.v.data(), 3);
        Point3 n = cross(sub(mesh.points[f.v[1]], a), sub(mesh.points[f.v[2]], a));
        const Point3& d = mesh.points[mesh.tetrahedra[f.tet][f.opposite]];
        const double length = std::sqrt(dot(n, n));
        const double sign = dot(n, sub(d, a)) > 0 ? -1 : 1;
        n = { sign * n[0] / length, sign * n[1] / length, sign * n[2] / length };
        bool outside = false, unknown = false;
        for (int k = -1; k < 14 && !outside; ++k)
        {
          const Point3 u = k < 0 ? n : kDirections[k];
          for (const double step : { 0.01, 0.03, 0.1, 0.3, 1.0 })
          {
            const double t = limits.boundaryProbe * step * size;
            const std::optional<bool> in =
              membership->inside({ c[0] + t * u[0], c[1] + t * u[1], c[2] + t * u[2] });
            unknown = unknown || !in;
            if (in && !*in)
            {
              outside = true;
              break;
            }
          }
        }
        if (outside)
        {
          // on the boundary
        }
        else if (unknown)
        {
          ++r.uncheckedBoundaryFaces;
        }
        else
        {
          ++r.strayBoundaryFaces;
          firstStray = std::min(firstStray, i);
        }
      }
    }
    i = j;
  }
  if (r.nonConformingFaces > 0)
  {
    const Face& f = faces[firstNonConforming];
    r.problems.push_back(std::to_string(r.nonConformingFaces) +
      " faces are shared by more than two tetrahedra or by two on the same side (the first at " +
      pointText(centroid(mesh, f.v.data(), 3)) + ", of " + cellText(mesh, f.tet) + ")");
  }
  if (r.strayBoundaryFaces > 0)
  {
    const Face& f = faces[firstStray];
    r.problems.push_back(std::to_string(r.strayBoundaryFaces) +
      " faces of one tetrahedron have cells all around them, as far as " +
      number(limits.boundaryProbe) + " x size: a hole or a gap between cells (the first at " +
      pointText(centroid(mesh, f.v.data(), 3)) + ", of " + cellText(mesh, f.tet) + ")");
  }
  return r;
}

std::size_t removeFlatBoundaryTetrahedra(TetMesh& mesh, double size, const ValidityLimits& limits)
{
  validateStructure(mesh);
  if (!(size > 0) || !std::isfinite(size))
  {
    return 0;
  }
  const double threshold = limits.minVolume * size * size * size / (6 * std::sqrt(2.0));
  const auto volumeOf = [&](const std::array<std::uint32_t, 4>& t)
  {
    return orientation(mesh.points[t[0]], mesh.points[t[1]], mesh.points[t[2]], mesh.points[t[3]]) /
      6;
  };
  std::vector<std::size_t> flat;
  for (std::size_t t = 0; t < mesh.tetrahedra.size(); ++t)
  {
    if (std::abs(volumeOf(mesh.tetrahedra[t])) < threshold)
    {
      flat.push_back(t);
    }
  }
  if (flat.empty())
  {
    return 0;
  }
  // The faces of a positively oriented (v0, v1, v2, v3) with outward orientation; this holds by
  // the vertices' order alone, so it still tells a flat tetrahedron's two sides apart.
  static constexpr int faces[4][3] = { { 1, 2, 3 }, { 0, 3, 2 }, { 0, 1, 3 }, { 0, 2, 1 } };
  const auto sorted = [](std::uint32_t a, std::uint32_t b, std::uint32_t c)
  {
    std::array<std::uint32_t, 3> k{ a, b, c };
    std::sort(k.begin(), k.end());
    return k;
  };
  // How many tetrahedra hold each face of a flat one (a few faces: one pass over the mesh).
  std::map<std::array<std::uint32_t, 3>, int> holders;
  for (const std::size_t t : flat)
  {
    for (const auto& f : faces)
    {
      const auto& tet = mesh.tetrahedra[t];
      holders[sorted(tet[f[0]], tet[f[1]], tet[f[2]])] = 0;
    }
  }
  for (const auto& t : mesh.tetrahedra)
  {
    for (const auto& f : faces)
    {
      const auto it = holders.find(sorted(t[f[0]], t[f[1]], t[f[2]]));
      if (it != holders.end())
      {
        ++it->second;
      }
    }
  }
  const auto count = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) -> int&
  {
    return holders.at(sorted(a, b, c));
  };
  std::vector<char> removed(mesh.tetrahedra.size(), 0);
  std::size_t removedCount = 0;
  // Removing one flat tetrahedron can expose another behind it: repeat until nothing changes.
  for (bool changed = true; changed;)
  {
    changed = false;
    for (const std::size_t t : flat)
    {
      if (removed[t])
      {
        continue;
      }
      const auto& tet = mesh.tetrahedra[t];
      std::array<Point3, 4> area{};
      std::size_t largest = 0;
      for (int f = 0; f < 4; ++f)
      {
        const Point3& a = mesh.points[tet[faces[f][0]]];
        area[f] =
          cross(sub(mesh.points[tet[faces[f][1]]], a), sub(mesh.points[tet[faces[f][2]]], a));
        largest = dot(area[f], area[f]) > dot(area[largest], area[largest]) ? f : largest;
      }
      const Point3 normal = area[largest];
      const double scale = dot(normal, normal);
      if (!(scale > 0))
      {
        continue; // four points on a line: no side to tell
      }
      bool upBoundary = true, downBoundary = true, decided = true;
      for (int f = 0; f < 4; ++f)
      {
        const double side = dot(area[f], normal);
        const bool boundary = count(tet[faces[f][0]], tet[faces[f][1]], tet[faces[f][2]]) == 1;
        if (std::abs(side) <= 1e-9 * scale)
        {
          // A face of no area belongs to neither side; it must not hide a neighbour.
          decided = decided && boundary;
        }
        else if (side > 0)
        {
          upBoundary = upBoundary && boundary;
        }
        else
        {
          downBoundary = downBoundary && boundary;
        }
      }
      if (!decided || !(upBoundary || downBoundary))
      {
        continue;
      }
      removed[t] = 1;
      ++removedCount;
      changed = true;
      for (const auto& f : faces)
      {
        --count(tet[f[0]], tet[f[1]], tet[f[2]]);
      }
    }
  }
  if (removedCount == 0)
  {
    return 0;
  }
  // Compact the tetrahedra and their arrays, then the points the rest still use.
  const bool perTet = !mesh.cellData.empty();
  std::size_t kept = 0;
  for (std::size_t t = 0; t < mesh.tetrahedra.size(); ++t)
  {
    if (removed[t])
    {
      continue;
    }
    mesh.tetrahedra[kept] = mesh.tetrahedra[t];
    mesh.cells[kept] = mesh.cells[t];
    mesh.materials[kept] = mesh.materials[t];
    ++kept;
  }
  mesh.tetrahedra.resize(kept);
  mesh.cells.resize(kept);
  mesh.materials.resize(kept);
  if (perTet)
  {
    for (TetArray& array : mesh.cellData)
    {
      const auto n = static_cast<std::size_t>(array.components);
      std::size_t k = 0;
      for (std::size_t t = 0; t < removed.size(); ++t)
      {
        if (!removed[t])
        {
          std::copy_n(array.values.begin() + std::ptrdiff_t(t * n), n,
            array.values.begin() + std::ptrdiff_t(k * n));
          ++k;
        }
      }
      array.values.resize(k * n);
    }
  }
  constexpr std::uint32_t unused = std::numeric_limits<std::uint32_t>::max();
  std::vector<std::uint32_t> index(mesh.points.size(), unused);
  for (const auto& t : mesh.tetrahedra)
  {
    for (const std::uint32_t v : t)
    {
      index[v] = 0;
    }
  }
  std::uint32_t next = 0;
  for (std::size_t v = 0; v < mesh.points.size(); ++v)
  {
    if (index[v] != unused)
    {
      index[v] = next;
      mesh.points[next++] = mesh.points[v];
    }
  }
  mesh.points.resize(next);
  for (auto& t : mesh.tetrahedra)
  {
    for (std::uint32_t& v : t)
    {
      v = index[v];
    }
  }
  return removedCount;
}

void requireValid(const ValidityReport& report, const std::string& what)
{
  if (report.valid())
  {
    return;
  }
  std::string text = what + " is not a valid tetrahedral mesh: ";
  for (std::size_t i = 0; i < report.problems.size(); ++i)
  {
    text += (i ? "; " : "") + report.problems[i];
  }
  throw std::invalid_argument(text);
}

std::string formatValidityReport(const ValidityReport& r)
{
  std::ostringstream s;
  s.precision(4);
  s << "validity: shortest edge " << r.minEdge << " (" << r.minEdgeRelative
    << " x size), smallest volume " << r.minVolume << " (" << r.minVolumeRelative
    << " of a regular tetrahedron), " << r.nonPositive << " inverted, " << r.duplicatePoints
    << " duplicate points\n"
    << "faces: " << r.interiorFaces << " interior, " << r.boundaryFaces << " boundary ("
    << r.uncheckedBoundaryFaces << " not checked), " << r.nonConformingFaces << " non-conforming, "
    << r.strayBoundaryFaces << " stray\n";
  for (const auto& p : r.problems)
  {
    s << "invalid: " << p << "\n";
  }
  return s.str();
}

} // namespace ictk::mesh
