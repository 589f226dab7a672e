// SPDX-License-Identifier: BSD-3-Clause
// Placed shapes as complex cells (ShapeCells.h): explicit geometry where the parts are
// polygonal, the shape's world field (worldField) as implicit geometry otherwise.
#include "Geometry/ShapeCells.h"

#include "Geometry/Prepared.h"

#include "FRep/Expr.h"
#include "FRep/Tape.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace ictk::geometry
{
using namespace detail;

namespace
{

/// Vertex normals ("Normals", 3 components: a skinned mesh's) are covectors: placed by the
/// inverse transpose of the placement's linear part, then made unit again.
void placeNormals(std::vector<discretize::PointArray>& arrays, const Affine& place)
{
  if (place.isIdentity())
  {
    return;
  }
  const Affine inverse = place.inverse();
  Affine normalMap;
  for (int r = 0; r < 3; ++r)
  {
    for (int c = 0; c < 3; ++c)
    {
      normalMap.a[static_cast<std::size_t>(3 * r + c)] =
        inverse.a[static_cast<std::size_t>(3 * c + r)];
    }
  }
  normalMap.b = { 0, 0, 0 };
  for (discretize::PointArray& array : arrays)
  {
    if (array.name != "Normals" || array.components != 3)
    {
      continue;
    }
    for (std::size_t i = 0; i + 2 < array.values.size(); i += 3)
    {
      const Vec3 n =
        normalMap.applyLinear({ array.values[i], array.values[i + 1], array.values[i + 2] });
      const double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      for (std::size_t k = 0; k < 3; ++k)
      {
        array.values[i + k] = length > 0 ? n[k] / length : n[k];
      }
    }
  }
}

/// A shape of mesh parts (.obj/.off files) as the explicit surface it is: its triangles placed.
complex::Cell meshCell(const PlacedShape& s)
{
  complex::ExplicitGeometry g;
  for (const ShapePart& part : s.parts)
  {
    if (part.kind != ShapePart::Kind::Mesh)
    {
      fail(s, "a mesh is a shape of its own: it does not combine with other parts");
    }
    const auto offset = static_cast<std::uint32_t>(g.points.size());
    for (const Vec3& q : part.points)
    {
      g.points.push_back(s.place.apply(q));
    }
    for (const auto& t : part.triangles)
    {
      g.triangles.push_back({ t[0] + offset, t[1] + offset, t[2] + offset });
    }
  }
  // Point arrays go with a shape of one mesh (several meshes need not share their arrays).
  if (s.parts.size() == 1)
  {
    g.pointData = s.parts[0].pointData;
    placeNormals(g.pointData, s.place);
  }
  complex::Cell cell = complex::explicitCell(s.cell, 2, std::move(g));
  return cell;
}

} // namespace

complex::Cell toComplexCell(const PlacedShape& s, complex::CellKind kind, const QueryOptions& o)
{
  validate(s);
  if (std::any_of(s.parts.begin(), s.parts.end(),
        [](const ShapePart& part) { return part.kind == ShapePart::Kind::Mesh; }))
  {
    return meshCell(s);
  }
  const Prepared p(s);
  complex::Cell cell;
  cell.name = s.cell;
  cell.dimension = p.dim;
  cell.kind = kind;
  bool explicitOnly = true;
  for (const auto& pp : p.parts)
  {
    const auto k = pp.part->kind;
    explicitOnly = explicitOnly &&
      (k == ShapePart::Kind::Point || k == ShapePart::Kind::Segment ||
        k == ShapePart::Kind::Polyline || k == ShapePart::Kind::Arc ||
        k == ShapePart::Kind::Rectangle || k == ShapePart::Kind::Box) &&
      pp.dim == p.dim;
  }
  if (explicitOnly)
  {
    complex::ExplicitGeometry g;
    auto add = [&](const Vec3& local)
    {
      g.points.push_back(s.place.apply(local));
      return static_cast<std::uint32_t>(g.points.size() - 1);
    };
    for (const auto& pp : p.parts)
    {
      const ShapePart& part = *pp.part;
      switch (part.kind)
      {
        case ShapePart::Kind::Point:
          for (const auto& q : part.points)
          {
            add(q);
          }
          break;
        case ShapePart::Kind::Segment:
        case ShapePart::Kind::Polyline:
        {
          std::vector<std::uint32_t> line;
          for (const auto& q : part.points)
          {
            line.push_back(add(q));
          }
          g.polylines.push_back(line);
          break;
        }
        case ShapePart::Kind::Arc:
        {
          const double t0 = std::atan2(part.points[0][1], part.points[0][0]);
          double t1 = std::atan2(part.points[1][1], part.points[1][0]);
          while (t1 <= t0)
          {
            t1 += 2 * Pi;
          }
          const int n =
            std::max(2, static_cast<int>(std::ceil(o.arcSegments * (t1 - t0) / (2 * Pi))));
          std::vector<std::uint32_t> line;
          for (int i = 0; i <= n; ++i)
          {
            const double t = t0 + (t1 - t0) * i / n;
            line.push_back(add({ part.radius * std::cos(t), part.radius * std::sin(t), 0 }));
          }
          g.polylines.push_back(line);
          break;
        }
        case ShapePart::Kind::Rectangle:
        {
          const double w = 0.5 * part.size[0], h = 0.5 * part.size[1];
          const auto c0 = add({ -w, -h, 0 }), c1 = add({ w, -h, 0 }), c2 = add({ w, h, 0 }),
                     c3 = add({ -w, h, 0 });
          g.triangles.push_back({ c0, c1, c2 });
          g.triangles.push_back({ c0, c2, c3 });
          break;
        }
        case ShapePart::Kind::Box:
        {
          std::uint32_t c[8];
          for (int k = 0; k < 8; ++k)
          {
            c[k] = add({ (k & 1 ? 0.5 : -0.5) * part.size[0], (k & 2 ? 0.5 : -0.5) * part.size[1],
              (k & 4 ? 0.5 : -0.5) * part.size[2] });
          }
          // Six tetrahedra around the diagonal 0-7 (the Kuhn split of the cube).
          const int paths[6][2] = { { 1, 3 }, { 1, 5 }, { 2, 3 }, { 2, 6 }, { 4, 5 }, { 4, 6 } };
          for (const auto& q : paths)
          {
            g.tetrahedra.push_back({ c[0], c[q[0]], c[q[1]], c[7] });
          }
          break;
        }
        default:
          break;
      }
    }
    if (cell.kind != complex::CellKind::Point && cell.kind != complex::CellKind::BRep)
    {
      // An explicit geometry is a P or B cell whatever the model called it.
      cell.kind = p.dim == 0 ? complex::CellKind::Point : complex::CellKind::BRep;
    }
    cell.geometry = std::move(g);
    return cell;
  }
  if (p.dim < 2)
  {
    fail(s, "mixes points and curves of different dimensions; no single complex cell holds it");
  }
  complex::ImplicitGeometry g;
  g.inside.push_back(worldField(s));
  g.insideText.push_back("shape of " + s.cell);
  g.bounds = p.bounds;
  if (p.flat)
  {
    g.carriers.push_back(frep::tapeField(frep::Tape::compile(frep::Expr::z())));
    g.carrierText.push_back("z");
    // A thin slab about z = 0, so that the box has a thickness for discretisers.
    const double pad = 1e-3 * p.scale;
    g.bounds.lo[2] = -pad;
    g.bounds.hi[2] = pad;
  }
  if (cell.kind == complex::CellKind::Point || cell.kind == complex::CellKind::BRep ||
    cell.kind == complex::CellKind::MappedFRep)
  {
    cell.kind = complex::CellKind::FRep;
  }
  cell.geometry = std::move(g);
  return cell;
}

} // namespace ictk::geometry
