// SPDX-License-Identifier: BSD-3-Clause
#include "Complex/Cell.h"

#include "Discretize/Mesh.h"
#include "FRep/Tape.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace ictk::complex
{
namespace
{

struct KindCode
{
  CellKind kind;
  const char* code;
};
constexpr KindCode kKindCodes[] = {
  { CellKind::Point, "P" },
  { CellKind::BRep, "B" },
  { CellKind::FRep, "F" },
  { CellKind::MappedFRep, "MF" },
  { CellKind::Voxel, "V" },
  { CellKind::Composite, "C" },
  { CellKind::Computed, "T" },
};

[[noreturn]] void fail(const Cell& cell, const std::string& what)
{
  throw std::invalid_argument("cell '" + cell.name + "' (" + kindCode(cell.kind) + ", " +
    std::to_string(cell.dimension) + "D): " + what);
}

bool finiteBox(const Box3& b)
{
  for (int a = 0; a < 3; ++a)
  {
    if (!std::isfinite(b.lo[a]) || !std::isfinite(b.hi[a]) || b.lo[a] > b.hi[a])
    {
      return false;
    }
  }
  return true;
}

void checkFields(const Cell& cell, const std::vector<FieldPtr>& fields, const char* role)
{
  for (std::size_t i = 0; i < fields.size(); ++i)
  {
    if (!fields[i])
    {
      fail(cell, std::string(role) + " field " + std::to_string(i) + " is missing");
    }
  }
}

void checkExplicit(const Cell& cell, const ExplicitGeometry& g)
{
  if (g.points.empty())
  {
    fail(cell, "has no points (an empty cell)");
  }
  for (std::size_t i = 0; i < g.points.size(); ++i)
  {
    for (double c : g.points[i])
    {
      if (!std::isfinite(c))
      {
        fail(cell, "point " + std::to_string(i) + " has a non-finite coordinate");
      }
    }
  }
  for (const discretize::PointArray& a : g.pointData)
  {
    if (a.components < 1 || a.values.size() != g.points.size() * std::size_t(a.components))
    {
      fail(cell,
        "point array '" + a.name + "' is not " + std::to_string(a.components) +
          " value(s) per point");
    }
  }
  const auto n = static_cast<std::uint32_t>(g.points.size());
  auto checkIndex = [&](std::uint32_t index, const char* what, std::size_t element)
  {
    if (index >= n)
    {
      fail(cell,
        std::string(what) + " " + std::to_string(element) + " uses point " + std::to_string(index) +
          " of " + std::to_string(n));
    }
  };
  for (std::size_t l = 0; l < g.polylines.size(); ++l)
  {
    if (g.polylines[l].size() < 2)
    {
      fail(cell, "polyline " + std::to_string(l) + " has fewer than two points");
    }
    for (auto i : g.polylines[l])
    {
      checkIndex(i, "polyline", l);
    }
  }
  for (std::size_t t = 0; t < g.triangles.size(); ++t)
  {
    for (auto i : g.triangles[t])
    {
      checkIndex(i, "triangle", t);
    }
  }
  for (std::size_t t = 0; t < g.tetrahedra.size(); ++t)
  {
    for (auto i : g.tetrahedra[t])
    {
      checkIndex(i, "tetrahedron", t);
    }
  }
  const bool curves = !g.polylines.empty();
  const bool surface = !g.triangles.empty();
  const bool solid = !g.tetrahedra.empty();
  const int expected = solid ? 3 : surface ? 2 : curves ? 1 : 0;
  if (int(curves) + int(surface) + int(solid) > 1)
  {
    fail(cell, "mixes polylines, triangles and tetrahedra; make one cell per dimension");
  }
  if (expected != cell.dimension)
  {
    fail(cell,
      "its explicit geometry is " + std::to_string(expected) + "-dimensional, not " +
        std::to_string(cell.dimension) + "-dimensional");
  }
  if (surface)
  {
    discretize::SurfaceMesh mesh;
    mesh.points = g.points;
    mesh.triangles = g.triangles;
    const discretize::MeshTopology topology = discretize::analyzeTopology(mesh);
    if (topology.degenerateTriangles > 0)
    {
      fail(cell, std::to_string(topology.degenerateTriangles) + " triangle(s) repeat a vertex");
    }
    if (topology.nonManifoldEdges > 0 || topology.nonManifoldVertices > 0)
    {
      fail(cell,
        "its surface is not a manifold (" + std::to_string(topology.nonManifoldEdges) +
          " edge(s) shared by more than two triangles, " +
          std::to_string(topology.nonManifoldVertices) + " vertex(es) joining separate fans)");
    }
  }
}

} // namespace

const char* kindCode(CellKind kind)
{
  for (const auto& k : kKindCodes)
  {
    if (k.kind == kind)
    {
      return k.code;
    }
  }
  return "?";
}

CellKind kindFromCode(const std::string& code)
{
  for (const auto& k : kKindCodes)
  {
    if (code == k.code)
    {
      return k.kind;
    }
  }
  throw std::invalid_argument(
    "unknown cell kind '" + code + "' (expected one of P, B, F, MF, V, C, T)");
}

Box3 Cell::bounds() const
{
  if (const auto* g = std::get_if<ImplicitGeometry>(&geometry))
  {
    return g->bounds;
  }
  const std::vector<Point3>* points = nullptr;
  if (const auto* e = std::get_if<ExplicitGeometry>(&geometry))
  {
    points = &e->points;
  }
  Box3 box;
  if (!points || points->empty())
  {
    // A mapped cell's box in E^3 is known only after discretisation.
    const double inf = std::numeric_limits<double>::infinity();
    box.lo = { inf, inf, inf };
    box.hi = { -inf, -inf, -inf };
    return box;
  }
  box.lo = box.hi = points->front();
  for (const auto& p : *points)
  {
    for (int a = 0; a < 3; ++a)
    {
      box.lo[a] = std::min(box.lo[a], p[a]);
      box.hi[a] = std::max(box.hi[a], p[a]);
    }
  }
  return box;
}

Cell frepCell(const std::string& name, const std::vector<frep::Expr>& carriers,
  const std::vector<frep::Expr>& inside, const Box3& bounds, double time)
{
  Cell c;
  c.name = name;
  c.kind = CellKind::FRep;
  c.dimension = 3 - static_cast<int>(carriers.size());
  ImplicitGeometry g;
  for (const auto& e : carriers)
  {
    g.carriers.push_back(frep::tapeField(frep::Tape::compile(e), time));
  }
  for (const auto& e : inside)
  {
    g.inside.push_back(frep::tapeField(frep::Tape::compile(e), time));
  }
  g.bounds = bounds;
  c.geometry = std::move(g);
  return c;
}

Cell explicitCell(const std::string& name, int dimension, ExplicitGeometry geometry)
{
  Cell c;
  c.name = name;
  c.kind = dimension == 0 ? CellKind::Point : CellKind::BRep;
  c.dimension = dimension;
  c.geometry = std::move(geometry);
  return c;
}

void checkCell(const Cell& cell)
{
  if (cell.name.empty())
  {
    throw std::invalid_argument("a cell needs a name");
  }
  if (cell.dimension < 0 || cell.dimension > 3)
  {
    fail(cell, "the dimension must be 0, 1, 2 or 3");
  }
  if (const auto* g = std::get_if<ImplicitGeometry>(&cell.geometry))
  {
    if (cell.kind == CellKind::Point || cell.kind == CellKind::BRep ||
      cell.kind == CellKind::MappedFRep)
    {
      fail(cell, "an implicit geometry needs kind F, V, C or T");
    }
    checkFields(cell, g->carriers, "carrier");
    checkFields(cell, g->inside, "inside");
    const int dimension = 3 - static_cast<int>(g->carriers.size());
    if (dimension != cell.dimension)
    {
      fail(cell,
        std::to_string(g->carriers.size()) + " carrier field(s) define a " +
          std::to_string(dimension) + "-dimensional set in E^3");
    }
    if (g->carriers.empty() && g->inside.empty())
    {
      fail(cell, "has neither carrier nor inside fields (it would be all of space)");
    }
    if (!finiteBox(g->bounds))
    {
      fail(cell, "needs a finite bounding box");
    }
  }
  else if (const auto* m = std::get_if<MappedGeometry>(&cell.geometry))
  {
    if (cell.kind != CellKind::MappedFRep)
    {
      fail(cell, "a mapped geometry needs kind MF");
    }
    checkFields(cell, m->carriers, "carrier");
    checkFields(cell, m->inside, "inside");
    for (int a = 0; a < 3; ++a)
    {
      if (!m->map[a])
      {
        fail(cell, "its map h is missing component " + std::to_string(a));
      }
    }
    const int dimension = 2 - static_cast<int>(m->carriers.size());
    if (dimension != cell.dimension)
    {
      fail(cell,
        std::to_string(m->carriers.size()) + " carrier field(s) in the (u, v) plane define a " +
          std::to_string(dimension) + "-dimensional set");
    }
    if (m->inside.empty() && m->carriers.empty())
    {
      fail(cell, "has neither carrier nor inside fields in the (u, v) plane");
    }
    if (!finiteBox(m->uvBounds))
    {
      fail(cell, "needs a finite (u, v) rectangle");
    }
  }
  else
  {
    if (cell.kind != CellKind::Point && cell.kind != CellKind::BRep)
    {
      fail(cell, "an explicit geometry needs kind P or B");
    }
    checkExplicit(cell, std::get<ExplicitGeometry>(cell.geometry));
  }
  for (const auto& b : cell.attributes)
  {
    if (!b.function || b.function->components.empty())
    {
      fail(cell, "attribute '" + b.attribute + "' has no function");
    }
    checkFields(cell, b.function->components, ("attribute " + b.attribute).c_str());
    if (!std::isfinite(b.priority))
    {
      fail(cell, "attribute '" + b.attribute + "' has a non-finite priority");
    }
  }
}

} // namespace ictk::complex
