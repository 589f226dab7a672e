// SPDX-License-Identifier: BSD-3-Clause
#include "Mesh/TetGen/MeshTetGen.h"

#include "Complex/Discretization.h"
#include "FRep/Expr.h"
#include "FRep/Sampling.h"
#include "FRep/Tape.h"

#include <tetgen.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <new>
#include <sstream>
#include <stdexcept>
#include <variant>

namespace ictk::mesh
{
namespace
{

using Clock = std::chrono::steady_clock;

double seconds(Clock::time_point since)
{
  return std::chrono::duration<double>(Clock::now() - since).count();
}

std::string number(double v)
{
  char text[64];
  std::snprintf(text, sizeof text, "%.6g", v);
  return text;
}

std::string point(const Point3& p)
{
  return "(" + number(p[0]) + ", " + number(p[1]) + ", " + number(p[2]) + ")";
}

/// The box [lo, hi] as a field (min of six half-spaces).
frep::FieldPtr boundsField(const frep::Box3& b)
{
  using frep::Expr;
  auto c = [](double v)
  {
    return Expr::constant(v);
  };
  const Expr x = Expr::x(), y = Expr::y(), z = Expr::z();
  const Expr f = min(min(min(x - c(b.lo[0]), c(b.hi[0]) - x), min(y - c(b.lo[1]), c(b.hi[1]) - y)),
    min(z - c(b.lo[2]), c(b.hi[2]) - z));
  return frep::tapeField(frep::Tape::compile(f));
}

std::string tetgenError(int code)
{
  switch (code)
  {
    case 1:
      return "out of memory";
    case 2:
      return "internal error";
    case 3:
      return "the input surfaces intersect each other (self-intersection)";
    case 4:
      return "a very small input feature was found (input points or edges too close for its "
             "tolerance)";
    case 5:
      return "two very close input facets were found";
    case 10:
      return "invalid input";
    default:
      return "unknown error";
  }
}

bool finiteBox(const frep::Box3& b)
{
  for (int a = 0; a < 3; ++a)
  {
    if (!std::isfinite(b.lo[a]) || !std::isfinite(b.hi[a]) || !(b.lo[a] < b.hi[a]))
    {
      return false;
    }
  }
  return true;
}

double orient(const std::vector<Point3>& p, const std::array<std::uint32_t, 4>& t)
{
  const Point3& a = p[t[0]];
  double e[3][3];
  for (int k = 0; k < 3; ++k)
  {
    for (int c = 0; c < 3; ++c)
    {
      e[k][c] = p[t[k + 1]][c] - a[c];
    }
  }
  return e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) -
    e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
    e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0]);
}

void checkSize(const TetraOptions& o)
{
  if (!(o.size > 0) || !std::isfinite(o.size))
  {
    throw std::invalid_argument("TetGen backend: the mesh size must be a positive number");
  }
}

double labelledVolume(const discretize::MaterialSurface& s, int materials)
{
  double volume = 0;
  for (int m = 1; m <= materials; ++m)
  {
    volume += discretize::materialVolume(s, m);
  }
  return volume;
}

void checkBudget(double estimate, const TetraOptions& o)
{
  if (estimate > o.maxTetrahedra)
  {
    throw std::invalid_argument("TetGen backend: size " + number(o.size) + " gives about " +
      number(estimate) + " tetrahedra, more than the limit of " + number(o.maxTetrahedra) +
      " (raise maxTetrahedra or the size)");
  }
}

/// The label of the multi-material surface at a point (the solid of highest priority whose
/// field is >= 0, ties to the lower index), evaluated directly on the fields.
class Labels
{
public:
  Labels(const std::vector<frep::FieldPtr>& fields, const std::vector<double>& priorities)
    : priorities_(priorities)
  {
    for (const auto& f : fields)
    {
      evaluators_.push_back(f->evaluator());
    }
  }

  int operator()(const Point3& p)
  {
    int best = 0;
    for (std::size_t i = 0; i < evaluators_.size(); ++i)
    {
      if (evaluators_[i]->value(p) >= 0 &&
        (best == 0 || priorities_[i] > priorities_[std::size_t(best - 1)]))
      {
        best = static_cast<int>(i) + 1;
      }
    }
    return best;
  }

private:
  std::vector<std::unique_ptr<frep::FieldEvaluator>> evaluators_;
  std::vector<double> priorities_;
};

/// The parts of the complex's 2D cells that lie inside the solids, as triangles TetGen must keep
/// as faces. The multi-material surface is only known to lie within a fraction of a grid cell of
/// the exact interfaces, and a facet that crossed or touched it would make the PLC
/// self-intersecting (TetGen error 3): so only triangles whose corners keep the same label at
/// `margin` in 14 directions are kept, and a 2D cell that reaches a solid's boundary stops about
/// `margin` short of it. 2D cells on a boundary or interface give nothing.
discretize::SurfaceMesh internalSurfaces(const complex::Complex& complex, Labels& labels,
  double size, double margin, int threads, std::size_t& cellsUsed)
{
  static const int directions[14][3] = { { 1, 0, 0 }, { -1, 0, 0 }, { 0, 1, 0 }, { 0, -1, 0 },
    { 0, 0, 1 }, { 0, 0, -1 }, { 1, 1, 1 }, { 1, 1, -1 }, { 1, -1, 1 }, { 1, -1, -1 }, { -1, 1, 1 },
    { -1, 1, -1 }, { -1, -1, 1 }, { -1, -1, -1 } };
  discretize::SurfaceMesh out;
  cellsUsed = 0;
  for (const complex::CellId id : complex.cellsOfDimension(2))
  {
    complex::DiscretizationOptions d;
    // Half the size: the kept triangles' corners then hold every point of them within the
    // margin's reach.
    d.featureSize = size / 2;
    d.threads = threads;
    const discretize::SurfaceMesh patch = complex::discretizeCell(complex, id, d).surface;
    std::vector<int> safe(patch.points.size(), -1); // -1 unknown, 0 no, 1 yes
    auto isSafe = [&](std::uint32_t v)
    {
      if (safe[v] < 0)
      {
        const Point3& p = patch.points[v];
        const int label = labels(p);
        bool ok = label > 0;
        for (int k = 0; k < 14 && ok; ++k)
        {
          const double scale = k < 6 ? margin : margin / std::sqrt(3.0);
          const Point3 q{ p[0] + scale * directions[k][0], p[1] + scale * directions[k][1],
            p[2] + scale * directions[k][2] };
          ok = labels(q) == label;
        }
        safe[v] = ok ? 1 : 0;
      }
      return safe[v] == 1;
    };
    std::vector<std::int64_t> index(patch.points.size(), -1);
    const std::size_t before = out.triangles.size();
    for (const auto& t : patch.triangles)
    {
      if (!isSafe(t[0]) || !isSafe(t[1]) || !isSafe(t[2]))
      {
        continue;
      }
      std::array<std::uint32_t, 3> n{};
      for (int c = 0; c < 3; ++c)
      {
        const std::uint32_t v = t[std::size_t(c)];
        if (index[v] < 0)
        {
          index[v] = static_cast<std::int64_t>(out.points.size());
          out.points.push_back(patch.points[v]);
        }
        n[std::size_t(c)] = static_cast<std::uint32_t>(index[v]);
      }
      out.triangles.push_back(n);
    }
    cellsUsed += out.triangles.size() > before ? 1 : 0;
  }
  return out;
}

/// TetGen on the surface, with `internal` triangles as extra facets. A region no region point
/// reaches (closed off by internal facets) takes the label `labelAt` gives most of its volume.
/// Reports from 0.35 of the operation's progress on.
TetMesh runTetGen(const discretize::MaterialSurface& surface, int materials,
  const discretize::SurfaceMesh* internal, const std::function<int(const Point3&)>& labelAt,
  const TetraOptions& o, ProgressScope& progress, TetGenReport* report)
{
  checkSize(o);
  if (surface.triangles.empty())
  {
    throw std::invalid_argument("TetGen backend: the surface is empty (no cell has volume)");
  }
  const double estimate = estimateTetrahedra(labelledVolume(surface, materials), o.size);
  checkBudget(estimate, o);

  const std::size_t surfacePoints = surface.points.size();
  const std::size_t surfaceTriangles = surface.triangles.size();
  const std::size_t points = surfacePoints + (internal ? internal->points.size() : 0);
  const std::size_t facets = surfaceTriangles + (internal ? internal->triangles.size() : 0);
  tetgenio in, out;
  in.firstnumber = 0;
  in.numberofpoints = static_cast<int>(points);
  in.pointlist = new REAL[points * 3];
  for (std::size_t i = 0; i < points; ++i)
  {
    const Point3& p = i < surfacePoints ? surface.points[i] : internal->points[i - surfacePoints];
    for (int c = 0; c < 3; ++c)
    {
      in.pointlist[3 * i + std::size_t(c)] = p[std::size_t(c)];
    }
  }
  in.numberoffacets = static_cast<int>(facets);
  in.facetlist = new tetgenio::facet[facets];
  in.facetmarkerlist = new int[facets];
  for (std::size_t t = 0; t < facets; ++t)
  {
    tetgenio::facet& f = in.facetlist[t];
    tetgenio::init(&f);
    f.numberofpolygons = 1;
    f.polygonlist = new tetgenio::polygon[1];
    tetgenio::init(&f.polygonlist[0]);
    f.polygonlist[0].numberofvertices = 3;
    f.polygonlist[0].vertexlist = new int[3];
    const bool inner = t >= surfaceTriangles;
    for (int c = 0; c < 3; ++c)
    {
      f.polygonlist[0].vertexlist[c] = inner
        ? static_cast<int>(
            surfacePoints + internal->triangles[t - surfaceTriangles][std::size_t(c)])
        : static_cast<int>(surface.triangles[t][std::size_t(c)]);
    }
    // The pair of labels, for TetGen's boundary markers (internal facets: one past them all).
    in.facetmarkerlist[t] = inner ? (materials + 1) * (materials + 1)
                                  : surface.labels[t][0] * (materials + 1) + surface.labels[t][1];
  }
  int regions = 0, holes = 0;
  for (const auto& r : surface.regions)
  {
    (r.label == 0 ? holes : regions) += 1;
  }
  in.numberofregions = regions;
  in.regionlist = regions ? new REAL[std::size_t(regions) * 5] : nullptr;
  in.numberofholes = holes;
  in.holelist = holes ? new REAL[std::size_t(holes) * 3] : nullptr;
  int ri = 0, hi = 0;
  for (const auto& r : surface.regions)
  {
    if (r.label == 0)
    {
      std::copy(r.point.begin(), r.point.end(), in.holelist + 3 * hi++);
    }
    else
    {
      REAL* e = in.regionlist + 5 * ri++;
      std::copy(r.point.begin(), r.point.end(), e);
      e[3] = r.label;
      e[4] = -1; // no regional volume bound: the global one applies
    }
  }

  // -Y keeps the conforming surface as it is (TetGen's quality refinement would otherwise split
  // the small marching-tetrahedra triangles again and again: 5-10 times the tetrahedra); the
  // volume bound is 3 regular tetrahedra of edge `size`, since refinement ends well below it.
  const double maxVolume = 3 * o.size * o.size * o.size / (6 * std::sqrt(2.0));
  std::ostringstream sw;
  sw.precision(6);
  sw << "pYq1.414/" << o.minDihedralDegrees << "a" << maxVolume << "AQ";
  std::string switches = sw.str();
  if (report)
  {
    report->switches = switches;
    report->estimate = estimate;
    report->surfacePoints = surface.points.size();
    report->surfaceTriangles = surface.triangles.size();
    report->internalTriangles = internal ? internal->triangles.size() : 0;
  }
  progress.report(0.35);
  const auto start = Clock::now();
  try
  {
    tetrahedralize(switches.data(), &in, &out);
  }
  catch (int code)
  {
    throw std::runtime_error("TetGen failed (error " + std::to_string(code) + ": " +
      tetgenError(code) + ") on a surface of " + std::to_string(surface.points.size()) +
      " points and " + std::to_string(surface.triangles.size()) + " triangles with switches -" +
      switches);
  }
  if (report)
  {
    report->tetgenSeconds = seconds(start);
  }

  TetMesh mesh;
  const int base = out.firstnumber;
  mesh.points.resize(std::size_t(out.numberofpoints));
  for (int i = 0; i < out.numberofpoints; ++i)
  {
    for (int c = 0; c < 3; ++c)
    {
      mesh.points[std::size_t(i)][std::size_t(c)] = out.pointlist[3 * i + c];
    }
  }
  const auto tets = std::size_t(out.numberoftetrahedra);
  mesh.tetrahedra.resize(tets);
  mesh.materials.resize(tets);
  mesh.cells.resize(tets);
  for (std::size_t t = 0; t < tets; ++t)
  {
    std::array<std::uint32_t, 4> tet;
    for (std::size_t c = 0; c < 4; ++c)
    {
      tet[c] = static_cast<std::uint32_t>(
        out.tetrahedronlist[t * std::size_t(out.numberofcorners) + c] - base);
    }
    if (orient(mesh.points, tet) < 0)
    {
      std::swap(tet[1], tet[2]);
    }
    mesh.tetrahedra[t] = tet;
    const double attribute = out.numberoftetrahedronattributes > 0
      ? out.tetrahedronattributelist[t * std::size_t(out.numberoftetrahedronattributes)]
      : 0;
    const auto m = static_cast<std::int32_t>(std::lround(attribute));
    if ((m < 1 || m > materials) && !labelAt)
    {
      throw std::runtime_error("TetGen backend: tetrahedron " + std::to_string(t) +
        " has region attribute " + number(attribute) + ", not a material");
    }
    mesh.materials[t] = m;
  }
  // TetGen numbers the regions no region point reaches (those closed off by internal surfaces)
  // itself, past the given attributes: each such region takes the label that holds most of its
  // volume, sampled at the centroids.
  std::map<std::int32_t, std::map<int, double>> votes;
  for (std::size_t t = 0; t < tets; ++t)
  {
    const std::int32_t m = mesh.materials[t];
    if (m >= 1 && m <= materials)
    {
      continue;
    }
    const auto& tet = mesh.tetrahedra[t];
    Point3 centroid{ 0, 0, 0 };
    for (const auto v : tet)
    {
      for (int c = 0; c < 3; ++c)
      {
        centroid[std::size_t(c)] += mesh.points[v][std::size_t(c)] / 4;
      }
    }
    votes[m][labelAt(centroid)] += orient(mesh.points, tet);
  }
  std::map<std::int32_t, std::int32_t> relabel;
  for (const auto& [region, byLabel] : votes)
  {
    const auto best = std::max_element(byLabel.begin(), byLabel.end(),
      [](const auto& a, const auto& b) { return a.second < b.second; });
    if (best->first < 1 || best->first > materials)
    {
      throw std::runtime_error("TetGen backend: a region closed off by internal surfaces lies "
                               "outside every solid");
    }
    relabel[region] = best->first;
  }
  for (std::size_t t = 0; t < tets; ++t)
  {
    const auto r = relabel.find(mesh.materials[t]);
    if (r != relabel.end())
    {
      mesh.materials[t] = r->second;
    }
    mesh.cells[t] = static_cast<complex::CellId>(mesh.materials[t] - 1);
  }
  for (int m = 1; m <= materials; ++m)
  {
    mesh.materialNames.push_back("material " + std::to_string(m));
  }
  progress.report(1.0);
  return mesh;
}

} // namespace

TetMesh tetrahedralizeSurfaceTetGen(const discretize::MaterialSurface& surface, int materials,
  const TetraOptions& o, TetGenReport* report)
{
  ProgressScope progress(o.progress);
  return runTetGen(surface, materials, nullptr, {}, o, progress, report);
}

TetMesh tetrahedralizeTetGen(
  const complex::Complex& complex, const TetraOptions& o, TetGenReport* report)
{
  checkSize(o);
  const std::vector<complex::CellId> ids = complex.cellsOfDimension(3);
  if (ids.empty())
  {
    throw std::invalid_argument("TetGen backend: the complex has no 3D cell");
  }
  std::vector<frep::FieldPtr> fields;
  std::vector<double> priorities;
  frep::Box3 box;
  for (std::size_t i = 0; i < ids.size(); ++i)
  {
    const complex::Cell& cell = complex.cell(ids[i]);
    const auto* g = std::get_if<complex::ImplicitGeometry>(&cell.geometry);
    if (!g || !g->carriers.empty())
    {
      throw std::invalid_argument("TetGen backend: 3D cell '" + cell.name +
        "' is not an implicit solid (only F and V cells without carriers can be meshed)");
    }
    if (!finiteBox(g->bounds))
    {
      throw std::invalid_argument(
        "TetGen backend: 3D cell '" + cell.name + "' has no finite bounds with lo < hi");
    }
    std::vector<frep::FieldPtr> parts = g->inside;
    parts.push_back(boundsField(g->bounds)); // the cell lies inside its bounds
    fields.push_back(parts.size() == 1 ? parts[0] : frep::minField(parts));
    priorities.push_back(cell.priority);
    for (int a = 0; a < 3; ++a)
    {
      box.lo[a] = i == 0 ? g->bounds.lo[a] : std::min(box.lo[a], g->bounds.lo[a]);
      box.hi[a] = i == 0 ? g->bounds.hi[a] : std::max(box.hi[a], g->bounds.hi[a]);
    }
  }
  const int materials = static_cast<int>(ids.size());
  discretize::MultiMaterialOptions mo;
  mo.threads = o.threads;

  // A coarse pass first, so that an absurd size is refused before the fine grid is built.
  double side = 0;
  for (int a = 0; a < 3; ++a)
  {
    side = std::max(side, box.hi[a] - box.lo[a]);
  }
  const double coarse = side / 24;
  if (coarse > 2 * o.size)
  {
    const auto rough = discretize::multiMaterialSurface(fields, priorities, box, coarse, mo);
    checkBudget(estimateTetrahedra(labelledVolume(rough, materials), o.size), o);
  }

  ProgressScope progress(o.progress);
  mo.progress = progress.range(0, 0.3);
  const auto start = Clock::now();
  const discretize::MaterialSurface surface =
    discretize::multiMaterialSurface(fields, priorities, box, o.size, mo);
  const double surfaceSeconds = seconds(start);
  if (!surface.overlaps.empty())
  {
    const auto& v = surface.overlaps.front();
    const complex::Cell& a = complex.cell(ids[std::size_t(v.first)]);
    const complex::Cell& b = complex.cell(ids[std::size_t(v.second)]);
    throw std::invalid_argument("TetGen backend: 3D cells '" + a.name + "' and '" + b.name +
      "' overlap (both hold " + point(v.point) + ") and have the same priority " +
      number(a.priority) + ": give one of them a higher priority");
  }
  // A solid the grid finds no point of would silently be missing from the mesh (and from a
  // solver's element sets): refuse it by name.
  for (int m = 1; m <= materials; ++m)
  {
    const bool found = std::any_of(surface.regions.begin(), surface.regions.end(),
      [&](const discretize::MaterialRegion& r) { return r.label == m; });
    if (!found || !(discretize::materialVolume(surface, m) > 0))
    {
      const complex::Cell& c = complex.cell(ids[std::size_t(m - 1)]);
      throw std::invalid_argument("TetGen backend: 3D cell '" + c.name +
        "' has no volume: no point of its bounds is inside it" +
        (priorities.size() > 1 ? " (or cells of higher priority cover it)" : std::string()) +
        " at size " + number(o.size));
    }
  }
  Labels labels(fields, priorities);
  std::size_t internalCells = 0;
  const discretize::SurfaceMesh internal =
    internalSurfaces(complex, labels, o.size, 0.75 * o.size, o.threads, internalCells);
  TetMesh mesh = runTetGen(
    surface, materials, internal.triangles.empty() ? nullptr : &internal,
    [&](const Point3& p) { return labels(p); }, o, progress, report);
  if (report)
  {
    report->surfaceSeconds = surfaceSeconds;
    report->internalCells = internalCells;
  }
  mesh.materialNames.clear();
  for (const auto id : ids)
  {
    mesh.materialNames.push_back(complex.cell(id).name);
  }
  for (std::size_t t = 0; t < mesh.cells.size(); ++t)
  {
    mesh.cells[t] = ids[std::size_t(mesh.materials[t] - 1)];
  }
  return mesh;
}

} // namespace ictk::mesh
