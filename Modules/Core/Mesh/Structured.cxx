// SPDX-License-Identifier: BSD-3-Clause
#include "Mesh/Structured.h"

#include "Mesh/Quality.h"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <variant>

namespace ictk::mesh
{

TetMesh kuhnTetMesh(const frep::Box3& box, const std::array<int, 3>& divisions)
{
  for (int a = 0; a < 3; ++a)
  {
    if (divisions[a] < 1 || !(box.hi[a] > box.lo[a]))
    {
      throw std::invalid_argument(
        "kuhnTetMesh: every division must be at least 1 and the box must not be flat");
    }
  }
  const std::size_t nx = static_cast<std::size_t>(divisions[0]) + 1;
  const std::size_t ny = static_cast<std::size_t>(divisions[1]) + 1;
  const std::size_t nz = static_cast<std::size_t>(divisions[2]) + 1;
  if (static_cast<double>(nx) * static_cast<double>(ny) * static_cast<double>(nz) > 4e9)
  {
    throw std::invalid_argument("kuhnTetMesh: too many points");
  }
  TetMesh mesh;
  mesh.points.reserve(nx * ny * nz);
  for (std::size_t k = 0; k < nz; ++k)
  {
    for (std::size_t j = 0; j < ny; ++j)
    {
      for (std::size_t i = 0; i < nx; ++i)
      {
        const std::size_t idx[3] = { i, j, k };
        Point3 p;
        for (int a = 0; a < 3; ++a)
        {
          const double s = static_cast<double>(idx[a]) / divisions[a];
          p[a] = idx[a] == static_cast<std::size_t>(divisions[a])
            ? box.hi[a]
            : box.lo[a] + s * (box.hi[a] - box.lo[a]);
        }
        mesh.points.push_back(p);
      }
    }
  }
  auto index = [&](std::size_t i, std::size_t j, std::size_t k)
  {
    return static_cast<std::uint32_t>(i + nx * (j + ny * k));
  };
  // The six monotone paths from corner (0,0,0) to (1,1,1), one per axis order.
  static const int orders[6][3] = { { 0, 1, 2 }, { 0, 2, 1 }, { 1, 0, 2 }, { 1, 2, 0 }, { 2, 0, 1 },
    { 2, 1, 0 } };
  mesh.tetrahedra.reserve(6 * (nx - 1) * (ny - 1) * (nz - 1));
  for (std::size_t k = 0; k + 1 < nz; ++k)
  {
    for (std::size_t j = 0; j + 1 < ny; ++j)
    {
      for (std::size_t i = 0; i + 1 < nx; ++i)
      {
        for (const auto& order : orders)
        {
          std::size_t c[3] = { i, j, k };
          std::array<std::uint32_t, 4> tet;
          tet[0] = index(c[0], c[1], c[2]);
          for (int s = 0; s < 3; ++s)
          {
            ++c[order[s]];
            tet[static_cast<std::size_t>(s + 1)] = index(c[0], c[1], c[2]);
          }
          const auto& P = mesh.points;
          if (tetShape(P[tet[0]], P[tet[1]], P[tet[2]], P[tet[3]]).volume < 0)
          {
            std::swap(tet[2], tet[3]);
          }
          mesh.tetrahedra.push_back(tet);
        }
      }
    }
  }
  return mesh;
}

void labelByCentroid(TetMesh& mesh, const complex::Complex& complex)
{
  struct Solid
  {
    complex::CellId id;
    double priority;
    std::unique_ptr<frep::FieldEvaluator> ev;
  };
  const auto ids = complex.cellsOfDimension(3);
  std::vector<Solid> solids;
  for (auto id : ids)
  {
    const auto& cell = complex.cell(id);
    const auto* g = std::get_if<complex::ImplicitGeometry>(&cell.geometry);
    if (!g || !g->carriers.empty() || g->inside.empty())
    {
      continue;
    }
    const auto field = g->inside.size() == 1 ? g->inside[0] : frep::minField(g->inside);
    solids.push_back({ id, cell.priority, field->evaluator() });
  }
  std::vector<std::size_t> materialOf(ids.empty() ? 0 : ids.back() + 1, 0);
  mesh.materialNames.clear();
  for (std::size_t m = 0; m < ids.size(); ++m)
  {
    materialOf[ids[m]] = m + 1;
    mesh.materialNames.push_back(complex.cell(ids[m]).name);
  }
  const std::size_t n = mesh.tetrahedra.size();
  std::vector<double> x(n), y(n), z(n), f(n);
  for (std::size_t t = 0; t < n; ++t)
  {
    Point3 c{ 0, 0, 0 };
    for (auto i : mesh.tetrahedra[t])
    {
      for (int a = 0; a < 3; ++a)
      {
        c[a] += 0.25 * mesh.points.at(i)[a];
      }
    }
    x[t] = c[0];
    y[t] = c[1];
    z[t] = c[2];
  }
  constexpr auto none = std::numeric_limits<std::size_t>::max();
  std::vector<std::size_t> best(n, none);
  for (std::size_t s = 0; s < solids.size(); ++s)
  {
    if (n > 0)
    {
      solids[s].ev->values(x.data(), y.data(), z.data(), f.data(), n);
    }
    for (std::size_t t = 0; t < n; ++t)
    {
      if (f[t] >= 0 && (best[t] == none || solids[s].priority > solids[best[t]].priority))
      {
        best[t] = s;
      }
    }
  }
  TetMesh out;
  out.materialNames = std::move(mesh.materialNames);
  std::vector<std::uint32_t> remap(mesh.points.size(), std::numeric_limits<std::uint32_t>::max());
  for (std::size_t t = 0; t < n; ++t)
  {
    if (best[t] == none)
    {
      continue;
    }
    auto tet = mesh.tetrahedra[t];
    for (auto& i : tet)
    {
      if (remap[i] == std::numeric_limits<std::uint32_t>::max())
      {
        remap[i] = static_cast<std::uint32_t>(out.points.size());
        out.points.push_back(mesh.points[i]);
      }
      i = remap[i];
    }
    out.tetrahedra.push_back(tet);
    const auto id = solids[best[t]].id;
    out.cells.push_back(id);
    out.materials.push_back(static_cast<std::int32_t>(materialOf[id]));
  }
  mesh = std::move(out);
}

} // namespace ictk::mesh
