// SPDX-License-Identifier: BSD-3-Clause
#include "Complex/Discretization.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace ictk::complex
{

const std::vector<Point3>& CellMesh::vertices() const
{
  switch (dimension)
  {
    case 0:
      return points.points;
    case 1:
      return curves.points;
    default:
      return surface.points;
  }
}

std::vector<discretize::PointArray>& CellMesh::pointData()
{
  switch (dimension)
  {
    case 0:
      return points.pointData;
    case 1:
      return curves.pointData;
    default:
      return surface.pointData;
  }
}

const std::vector<discretize::PointArray>& CellMesh::pointData() const
{
  return const_cast<CellMesh*>(this)->pointData();
}

const CellMesh& ComplexMesh::of(CellId id) const
{
  auto it = std::lower_bound(
    cells.begin(), cells.end(), id, [](const CellMesh& m, CellId value) { return m.cell < value; });
  if (it == cells.end() || it->cell != id)
  {
    throw ComplexError("the discretisation has no cell with id " + std::to_string(id));
  }
  return *it;
}

Box3 complexBounds(const Complex& complex)
{
  const double inf = std::numeric_limits<double>::infinity();
  Box3 box{ { inf, inf, inf }, { -inf, -inf, -inf } };
  auto grow = [&](const Point3& p)
  {
    for (int a = 0; a < 3; ++a)
    {
      if (std::isfinite(p[a]))
      {
        box.lo[a] = std::min(box.lo[a], p[a]);
        box.hi[a] = std::max(box.hi[a], p[a]);
      }
    }
  };
  for (CellId id : complex.cellIds())
  {
    const Cell& c = complex.cell(id);
    if (const auto* m = std::get_if<MappedGeometry>(&c.geometry))
    {
      std::array<std::unique_ptr<frep::FieldEvaluator>, 3> h = { m->map[0]->evaluator(),
        m->map[1]->evaluator(), m->map[2]->evaluator() };
      const int n = 8;
      for (int i = 0; i <= n; ++i)
      {
        for (int j = 0; j <= n; ++j)
        {
          const Point3 uv{ m->uvBounds.lo[0] + (m->uvBounds.hi[0] - m->uvBounds.lo[0]) * i / n,
            m->uvBounds.lo[1] + (m->uvBounds.hi[1] - m->uvBounds.lo[1]) * j / n, 0 };
          grow({ h[0]->value(uv), h[1]->value(uv), h[2]->value(uv) });
        }
      }
      continue;
    }
    const Box3 b = c.bounds();
    grow(b.lo);
    grow(b.hi);
  }
  return box;
}

} // namespace ictk::complex
