// SPDX-License-Identifier: BSD-3-Clause
#include "Mesh/TetAttributes.h"

#include <algorithm>
#include <map>
#include <stdexcept>

namespace ictk::mesh
{

const TetArray* findArray(const TetMesh& mesh, const std::string& name)
{
  for (const auto& a : mesh.cellData)
  {
    if (a.name == name)
    {
      return &a;
    }
  }
  return nullptr;
}

void assignAttributes(TetMesh& mesh, const complex::Complex& complex)
{
  const std::size_t n = mesh.tetrahedra.size();
  if (mesh.cells.size() != n)
  {
    throw std::invalid_argument("assignAttributes: the mesh needs one cell id per tetrahedron");
  }
  // Centroids, and the tetrahedra of each cell.
  std::vector<double> x(n), y(n), z(n);
  std::map<complex::CellId, std::vector<std::size_t>> byCell;
  for (std::size_t t = 0; t < n; ++t)
  {
    double c[3] = { 0, 0, 0 };
    for (auto i : mesh.tetrahedra[t])
    {
      if (i >= mesh.points.size())
      {
        throw std::invalid_argument("assignAttributes: tetrahedron " + std::to_string(t) +
          " uses point " + std::to_string(i) + " of " + std::to_string(mesh.points.size()));
      }
      for (int a = 0; a < 3; ++a)
      {
        c[a] += 0.25 * mesh.points[i][a];
      }
    }
    x[t] = c[0];
    y[t] = c[1];
    z[t] = c[2];
    byCell[mesh.cells[t]].push_back(t);
  }
  for (const auto& [id, tets] : byCell)
  {
    if (!complex.hasCell(id))
    {
      throw std::invalid_argument("assignAttributes: tetrahedron " + std::to_string(tets.front()) +
        " belongs to cell " + std::to_string(id) + ", which the complex does not have");
    }
  }

  for (const auto& [name, defaults] : complex.attributes())
  {
    const auto components = static_cast<std::size_t>(defaults.components);
    TetArray array;
    array.name = name;
    array.components = defaults.components;
    array.values.resize(n * components);
    std::vector<double> px, py, pz, v;
    for (const auto& [id, tets] : byCell)
    {
      const complex::Cell& cell = complex.cell(id);
      const complex::AttributeBinding* binding = nullptr;
      for (const auto& b : cell.attributes)
      {
        if (b.attribute == name && (!binding || b.priority > binding->priority))
        {
          binding = &b;
        }
      }
      if (!binding)
      {
        for (auto t : tets)
        {
          std::copy(defaults.inside.begin(), defaults.inside.end(),
            array.values.begin() + static_cast<std::ptrdiff_t>(t * components));
        }
        continue;
      }
      if (binding->function->components.size() != components)
      {
        throw std::invalid_argument("cell '" + cell.name + "': attribute '" + name + "' has " +
          std::to_string(binding->function->components.size()) + " components, declared " +
          std::to_string(components));
      }
      px.resize(tets.size());
      py.resize(tets.size());
      pz.resize(tets.size());
      v.resize(tets.size());
      for (std::size_t k = 0; k < tets.size(); ++k)
      {
        px[k] = x[tets[k]];
        py[k] = y[tets[k]];
        pz[k] = z[tets[k]];
      }
      for (std::size_t c = 0; c < components; ++c)
      {
        binding->function->components[c]->evaluator()->values(
          px.data(), py.data(), pz.data(), v.data(), tets.size());
        for (std::size_t k = 0; k < tets.size(); ++k)
        {
          array.values[tets[k] * components + c] = v[k];
        }
      }
    }
    auto existing = std::find_if(mesh.cellData.begin(), mesh.cellData.end(),
      [&](const TetArray& a) { return a.name == name; });
    if (existing != mesh.cellData.end())
    {
      *existing = std::move(array);
    }
    else
    {
      mesh.cellData.push_back(std::move(array));
    }
  }
}

} // namespace ictk::mesh
