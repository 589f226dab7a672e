// SPDX-License-Identifier: BSD-3-Clause
#include "Mesh/TetMesh.h"

#include "FRep/Vector.h"

#include <cmath>
#include <stdexcept>

namespace ictk::mesh
{

double estimateTetrahedra(double volume, double size)
{
  if (!(size > 0) || !std::isfinite(size))
  {
    throw std::invalid_argument("the mesh size must be a positive number");
  }
  return volume / (size * size * size / (6 * std::sqrt(2.0)));
}

double orientation(const Point3& a, const Point3& b, const Point3& c, const Point3& d)
{
  return frep::dot(frep::sub(b, a), frep::cross(frep::sub(c, a), frep::sub(d, a)));
}

void validateStructure(const TetMesh& mesh)
{
  const auto n = mesh.tetrahedra.size();
  if (mesh.cells.size() != n || mesh.materials.size() != n)
  {
    throw std::invalid_argument("tetrahedral mesh: cells and materials need one entry per "
                                "tetrahedron");
  }
  for (const auto& a : mesh.cellData)
  {
    if (a.components < 1 || a.values.size() != n * static_cast<std::size_t>(a.components))
    {
      throw std::invalid_argument("tetrahedral mesh: array '" + a.name + "' has " +
        std::to_string(a.values.size()) + " values, not " + std::to_string(a.components) +
        " per tetrahedron");
    }
  }
  for (std::size_t t = 0; t < n; ++t)
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
    if (mesh.materials[t] < 1 ||
      static_cast<std::size_t>(mesh.materials[t]) > mesh.materialNames.size())
    {
      throw std::invalid_argument("tetrahedral mesh: tetrahedron " + std::to_string(t) +
        " has material " + std::to_string(mesh.materials[t]) + " of " +
        std::to_string(mesh.materialNames.size()));
    }
  }
}

void validate(const TetMesh& mesh)
{
  validateStructure(mesh);
  for (std::size_t t = 0; t < mesh.tetrahedra.size(); ++t)
  {
    const auto& tet = mesh.tetrahedra[t];
    const double volume = orientation(
      mesh.points[tet[0]], mesh.points[tet[1]], mesh.points[tet[2]], mesh.points[tet[3]]);
    if (!(volume > 0))
    {
      throw std::invalid_argument("tetrahedral mesh: tetrahedron " + std::to_string(t) +
        " is not positively oriented (6 x volume = " + std::to_string(volume) + ")");
    }
  }
}

} // namespace ictk::mesh
