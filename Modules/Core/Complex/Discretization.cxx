// SPDX-License-Identifier: BSD-3-Clause
#include "Complex/Discretization.h"

#include "Complex/Attributes.h"
#include "Discretize/Curves.h"
#include "Discretize/MarchingTetrahedra.h"
#include "Discretize/Patches.h"
#include "Discretize/Points.h"
#include "Discretize/Surface.h"
#include "FRep/Sampling.h"

#include <algorithm>
#include <cmath>
#include <map>

namespace ictk::complex
{
namespace
{

using discretize::CurveSet;
using discretize::PointSet;
using discretize::SurfaceMesh;

Box3 padded(const Box3& b, double margin)
{
  Box3 out = b;
  for (int a = 0; a < 3; ++a)
  {
    out.lo[a] -= margin;
    out.hi[a] += margin;
  }
  return out;
}

frep::FieldPtr intersection(const std::vector<frep::FieldPtr>& fields)
{
  return fields.size() == 1 ? fields[0] : frep::minField(fields);
}

const frep::FieldPtr& zField()
{
  static const frep::FieldPtr z = frep::tapeField(frep::Tape::compile(frep::Expr::z()));
  return z;
}

/// The boundary faces of a tetrahedral solid, oriented away from their tetrahedron.
SurfaceMesh tetrahedraBoundary(const ExplicitGeometry& g)
{
  std::map<std::array<std::uint32_t, 3>, std::pair<int, std::array<std::uint32_t, 3>>> faces;
  for (const auto& t : g.tetrahedra)
  {
    const std::array<std::array<int, 4>, 4> local = { { { 0, 1, 2, 3 }, { 0, 1, 3, 2 },
      { 0, 2, 3, 1 }, { 1, 2, 3, 0 } } };
    for (const auto& f : local)
    {
      std::array<std::uint32_t, 3> face = { t[f[0]], t[f[1]], t[f[2]] };
      // Orient the face so that the opposite vertex is behind it.
      const Point3& a = g.points[face[0]];
      const Point3& b = g.points[face[1]];
      const Point3& c = g.points[face[2]];
      const Point3& d = g.points[t[f[3]]];
      const Point3 ab{ b[0] - a[0], b[1] - a[1], b[2] - a[2] };
      const Point3 ac{ c[0] - a[0], c[1] - a[1], c[2] - a[2] };
      const Point3 ad{ d[0] - a[0], d[1] - a[1], d[2] - a[2] };
      const double volume = ab[0] * (ac[1] * ad[2] - ac[2] * ad[1]) -
        ab[1] * (ac[0] * ad[2] - ac[2] * ad[0]) + ab[2] * (ac[0] * ad[1] - ac[1] * ad[0]);
      if (volume > 0)
      {
        std::swap(face[1], face[2]);
      }
      std::array<std::uint32_t, 3> key = face;
      std::sort(key.begin(), key.end());
      auto& entry = faces[key];
      ++entry.first;
      entry.second = face;
    }
  }
  SurfaceMesh mesh;
  mesh.points = g.points;
  for (const auto& [key, entry] : faces)
  {
    (void)key;
    if (entry.first == 1)
    {
      mesh.triangles.push_back(entry.second);
    }
  }
  return mesh;
}

void discretizeExplicit(const Cell& c, const ExplicitGeometry& g, CellMesh& out)
{
  switch (c.dimension)
  {
    case 0:
      out.points.points = g.points;
      out.points.pointData = g.pointData;
      break;
    case 1:
      out.curves.points = g.points;
      out.curves.lines = g.polylines;
      out.curves.pointData = g.pointData;
      break;
    case 2:
      out.surface.points = g.points;
      out.surface.triangles = g.triangles;
      out.surface.pointData = g.pointData;
      break;
    default:
      out.surface = tetrahedraBoundary(g);
  }
}

discretize::ContourOptions contourOptions(const DiscretizationOptions& o, bool solid)
{
  discretize::ContourOptions c;
  c.featureSize = o.featureSize;
  c.threads = o.threads;
  c.closeAtBox = solid;
  return c;
}

discretize::CurveOptions curveOptions(const DiscretizationOptions& o, double step)
{
  discretize::CurveOptions c;
  c.step = step;
  c.tolerance = o.tolerance;
  c.threads = o.threads;
  return c;
}

discretize::PointOptions pointOptions(const DiscretizationOptions& o, double size)
{
  discretize::PointOptions p;
  p.size = size;
  p.tolerance = o.tolerance;
  p.threads = o.threads;
  return p;
}

/// Keeps the points where every inside field is >= 0 (to the projection tolerance, scaled).
PointSet keepInside(
  const PointSet& points, const std::vector<frep::FieldPtr>& inside, double tolerance)
{
  std::vector<std::unique_ptr<frep::FieldEvaluator>> fields;
  for (const auto& f : inside)
  {
    fields.push_back(f->evaluator());
  }
  PointSet out;
  for (std::size_t i = 0; i < points.points.size(); ++i)
  {
    bool keep = true;
    for (auto& f : fields)
    {
      keep = keep && f->value(points.points[i]) >= -tolerance;
    }
    if (keep)
    {
      out.points.push_back(points.points[i]);
    }
  }
  return out;
}

void discretizeImplicit(
  const Cell& c, const ImplicitGeometry& g, const DiscretizationOptions& o, CellMesh& out)
{
  // Carriers are meshed a little beyond the cell's box, so that trimming, not the box, makes
  // the cell's edges.
  const Box3 box = padded(g.bounds, 2 * o.featureSize);
  switch (c.dimension)
  {
    case 3:
    {
      // Solids by dual contouring: vertices placed by the QEF of the surface's tangent planes
      // keep edges and corners sharp (CSG of solids, the cut by the box).
      discretize::SurfaceOptions surface;
      surface.featureSize = o.featureSize;
      surface.threads = o.threads;
      surface.memory = o.surfaceMemory;
      out.surface = discretize::contourSurface(*intersection(g.inside), g.bounds, surface);
      break;
    }
    case 2:
    {
      SurfaceMesh carrier =
        discretize::marchingTetrahedra(*g.carriers[0], box, contourOptions(o, false));
      if (g.inside.empty())
      {
        out.surface = std::move(carrier);
      }
      else
      {
        discretize::TrimOptions trim;
        trim.tolerance = o.tolerance;
        trim.threads = o.threads;
        out.surface = discretize::trimSurface(carrier, *g.carriers[0], g.inside, trim);
      }
      break;
    }
    case 1:
      out.curves = discretize::traceCurve(
        *g.carriers[0], *g.carriers[1], g.inside, g.bounds, curveOptions(o, o.featureSize));
      break;
    default:
      out.points = keepInside(discretize::solvePoints(*g.carriers[0], *g.carriers[1],
                                *g.carriers[2], g.bounds, pointOptions(o, o.featureSize / 4)),
        g.inside, 1e3 * o.tolerance);
  }
}

void discretizeMapped(
  const Cell& c, const MappedGeometry& g, const DiscretizationOptions& o, CellMesh& out)
{
  Box3 uv = g.uvBounds;
  uv.lo[2] = -1;
  uv.hi[2] = 1;
  // The (u, v) step: h stretches the plane, so half the feature size keeps the mapped mesh fine
  // enough for maps that stretch up to twice (those of the models in Data/).
  const double step = o.featureSize / 2;
  switch (c.dimension)
  {
    case 2:
    {
      discretize::Region2DOptions region;
      region.size = step;
      region.tolerance = o.tolerance;
      region.threads = o.threads;
      out.surface = discretize::triangulateRegion2D(*intersection(g.inside), uv, region);
      discretize::mapToSpace(out.surface, *g.map[0], *g.map[1], *g.map[2]);
      break;
    }
    case 1:
      out.curves = discretize::traceCurve2D(*g.carriers[0], g.inside, uv, curveOptions(o, step));
      discretize::mapToSpace(out.curves, *g.map[0], *g.map[1], *g.map[2]);
      break;
    default:
      out.points = keepInside(discretize::solvePoints(*g.carriers[0], *g.carriers[1], *zField(), uv,
                                pointOptions(o, step / 4)),
        g.inside, 1e3 * o.tolerance);
      discretize::mapToSpace(out.points, *g.map[0], *g.map[1], *g.map[2]);
  }
}

} // namespace

double defaultFeatureSize(const Complex& complex)
{
  const Box3 b = complexBounds(complex);
  double side = 0;
  for (int a = 0; a < 3; ++a)
  {
    side = std::max(side, b.hi[a] - b.lo[a]);
  }
  return side > 0 && std::isfinite(side) ? side / 64 : 1.0 / 64;
}

CellMesh discretizeCell(const Complex& complex, CellId id, const DiscretizationOptions& options)
{
  const Cell& c = complex.cell(id);
  DiscretizationOptions o = options;
  if (!(o.featureSize > 0))
  {
    o.featureSize = defaultFeatureSize(complex);
  }
  CellMesh out;
  out.cell = id;
  out.dimension = c.dimension;
  try
  {
    if (const auto* g = std::get_if<ExplicitGeometry>(&c.geometry))
    {
      discretizeExplicit(c, *g, out);
    }
    else if (const auto* m = std::get_if<MappedGeometry>(&c.geometry))
    {
      discretizeMapped(c, *m, o, out);
    }
    else
    {
      discretizeImplicit(c, std::get<ImplicitGeometry>(c.geometry), o, out);
    }
  }
  catch (const frep::Cancelled&)
  {
    throw;
  }
  catch (const ComplexError&)
  {
    throw;
  }
  catch (const std::exception& e)
  {
    throw ComplexError("cell '" + c.name + "' cannot be discretised: " + e.what());
  }
  if (out.vertices().empty())
  {
    // An empty cell is a modelling error (seed 001 L93: every cell must be discretisable).
    throw ComplexError("cell '" + c.name + "' (" + kindCode(c.kind) + ", " +
      std::to_string(c.dimension) +
      "D) is empty: no point of its bounds satisfies its carriers and inside fields at feature "
      "size " +
      std::to_string(o.featureSize));
  }
  for (const auto& binding : c.attributes)
  {
    appendAttribute(binding, out.vertices(), out.pointData());
  }
  return out;
}

ComplexMesh discretizeComplex(const Complex& complex, const DiscretizationOptions& options)
{
  ComplexMesh mesh;
  DiscretizationOptions o = options;
  o.surfaceMemory = nullptr;
  if (!(o.featureSize > 0))
  {
    o.featureSize = defaultFeatureSize(complex);
  }
  mesh.featureSize = o.featureSize;
  const double attributeTolerance = 0.25 * o.featureSize;
  std::vector<CellId> ids = complex.cellIds();
  std::vector<CellId> targets;
  if (!o.cells.empty())
  {
    // A part of the complex: its cells, and the cells its unbound attributes are looked up in.
    targets = o.cells;
    std::sort(targets.begin(), targets.end());
    targets.erase(std::unique(targets.begin(), targets.end()), targets.end());
    for (CellId id : targets)
    {
      complex.cell(id); // throws ComplexError naming an unknown id
    }
    ids = targets;
    for (CellId id : attributeSupport(complex, targets, attributeTolerance))
    {
      ids.push_back(id);
    }
    std::sort(ids.begin(), ids.end());
  }
  ProgressScope progress(o.progress);
  std::size_t done = 0;
  for (CellId id : ids)
  {
    mesh.cells.push_back(discretizeCell(complex, id, o));
    ++done;
    progress.report(0.9 * double(done) / double(ids.size()));
  }
  appendUnboundAttributes(complex, mesh, attributeTolerance, targets);
  if (!targets.empty())
  {
    mesh.cells.erase(std::remove_if(mesh.cells.begin(), mesh.cells.end(),
                       [&](const CellMesh& m)
                       { return !std::binary_search(targets.begin(), targets.end(), m.cell); }),
      mesh.cells.end());
  }
  progress.report(1.0);
  return mesh;
}

} // namespace ictk::complex
