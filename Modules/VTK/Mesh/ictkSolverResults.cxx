// SPDX-License-Identifier: BSD-3-Clause
#include "ictkSolverResults.h"

#include "ictkTetrahedralize.h"

#include <vtkCellData.h>
#include <vtkCellTypes.h>
#include <vtkDataArray.h>
#include <vtkDoubleArray.h>
#include <vtkFieldData.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkStringArray.h>
#include <vtkUnstructuredGrid.h>

#include <stdexcept>
#include <string>

namespace ictk::vtk
{

namespace
{

template <std::size_t N>
void addPointArray(vtkUnstructuredGrid* grid, const char* name,
  const std::vector<std::array<double, N>>& values, const char* const* componentNames = nullptr)
{
  if (values.empty())
  {
    return;
  }
  vtkNew<vtkDoubleArray> a;
  a->SetName(name);
  a->SetNumberOfComponents(static_cast<int>(N));
  a->SetNumberOfTuples(static_cast<vtkIdType>(values.size()));
  for (std::size_t i = 0; i < values.size(); ++i)
  {
    a->SetTypedTuple(static_cast<vtkIdType>(i), values[i].data());
  }
  for (int c = 0; componentNames && c < static_cast<int>(N); ++c)
  {
    a->SetComponentName(c, componentNames[c]);
  }
  grid->GetPointData()->AddArray(a);
}

} // namespace

void solverResultsToVTK(const mesh::TetMesh& mesh, const mesh::PointResults& results,
  const std::vector<mesh::DeckMaterial>& materials, vtkUnstructuredGrid* output)
{
  const std::size_t n = mesh.points.size();
  for (const std::size_t size : { results.displacement.size(), results.stress.size(),
         results.vonMises.size(), results.force.size() })
  {
    if (size != 0 && size != n)
    {
      throw std::invalid_argument(
        "solver results for " + std::to_string(size) + " points on a mesh of " + std::to_string(n));
    }
  }
  ictkTetrahedralize::Convert(mesh, output);
  addPointArray<3>(output, "displacement", results.displacement);
  static const char* const tensor[6] = { "XX", "YY", "ZZ", "XY", "YZ", "XZ" };
  addPointArray<6>(output, "stress", results.stress, tensor);
  if (!results.vonMises.empty())
  {
    vtkNew<vtkDoubleArray> a;
    a->SetName("von_mises");
    a->SetNumberOfTuples(static_cast<vtkIdType>(n));
    std::copy(results.vonMises.begin(), results.vonMises.end(), a->GetPointer(0));
    output->GetPointData()->AddArray(a);
    output->GetPointData()->SetActiveScalars("von_mises");
  }
  addPointArray<3>(output, "reaction_force", results.force);
  if (!results.displacement.empty())
  {
    output->GetPointData()->SetActiveVectors("displacement");
  }
  if (materials.empty())
  {
    return;
  }
  const auto tets = static_cast<vtkIdType>(mesh.tetrahedra.size());
  vtkNew<vtkIntArray> index;
  index->SetName("deck_material");
  index->SetNumberOfTuples(tets);
  index->FillValue(0);
  vtkNew<vtkDoubleArray> modulus;
  modulus->SetName("deck_youngs_modulus");
  modulus->SetNumberOfTuples(tets);
  modulus->FillValue(0);
  for (std::size_t m = 0; m < materials.size(); ++m)
  {
    for (const std::size_t t : materials[m].tetrahedra)
    {
      if (t >= mesh.tetrahedra.size())
      {
        throw std::invalid_argument("deck material '" + materials[m].setName +
          "' names tetrahedron " + std::to_string(t) + " of a mesh of " +
          std::to_string(mesh.tetrahedra.size()));
      }
      index->SetValue(static_cast<vtkIdType>(t), static_cast<int>(m + 1));
      modulus->SetValue(static_cast<vtkIdType>(t), materials[m].youngsModulus);
    }
  }
  output->GetCellData()->AddArray(index);
  output->GetCellData()->AddArray(modulus);
}

mesh::TetMesh tetMeshFromVTK(vtkUnstructuredGrid* grid, const std::string& where)
{
  if (!grid || grid->GetNumberOfCells() == 0 || !grid->GetPoints())
  {
    throw std::invalid_argument("'" + where + "' has no cells");
  }
  mesh::TetMesh m;
  const vtkIdType points = grid->GetNumberOfPoints();
  m.points.resize(static_cast<std::size_t>(points));
  for (vtkIdType i = 0; i < points; ++i)
  {
    grid->GetPoint(i, m.points[static_cast<std::size_t>(i)].data());
  }
  const vtkIdType cells = grid->GetNumberOfCells();
  m.tetrahedra.resize(static_cast<std::size_t>(cells));
  vtkNew<vtkIdList> ids;
  for (vtkIdType c = 0; c < cells; ++c)
  {
    if (grid->GetCellType(c) != VTK_TETRA)
    {
      throw std::invalid_argument("'" + where + "': cell " + std::to_string(c) + " is a " +
        vtkCellTypes::GetClassNameFromTypeId(grid->GetCellType(c)) + ", not a tetrahedron");
    }
    grid->GetCellPoints(c, ids);
    for (int k = 0; k < 4; ++k)
    {
      m.tetrahedra[static_cast<std::size_t>(c)][std::size_t(k)] =
        static_cast<std::uint32_t>(ids->GetId(k));
    }
  }
  vtkCellData* cd = grid->GetCellData();
  m.materials.assign(static_cast<std::size_t>(cells), 1);
  m.cells.assign(static_cast<std::size_t>(cells), 0);
  if (vtkDataArray* a = cd->GetArray("MaterialId"))
  {
    for (vtkIdType c = 0; c < cells; ++c)
    {
      m.materials[static_cast<std::size_t>(c)] = static_cast<std::int32_t>(a->GetTuple1(c));
    }
  }
  if (vtkDataArray* a = cd->GetArray("CellId"))
  {
    for (vtkIdType c = 0; c < cells; ++c)
    {
      m.cells[static_cast<std::size_t>(c)] = static_cast<complex::CellId>(a->GetTuple1(c));
    }
  }
  std::int32_t largest = 0;
  for (const auto id : m.materials)
  {
    largest = std::max(largest, id);
  }
  auto* names =
    vtkStringArray::SafeDownCast(grid->GetFieldData()->GetAbstractArray("MaterialNames"));
  for (std::int32_t id = 1; id <= largest; ++id)
  {
    m.materialNames.push_back(names && id <= names->GetNumberOfValues()
        ? names->GetValue(id - 1)
        : "material_" + std::to_string(id));
  }
  for (int i = 0; i < cd->GetNumberOfArrays(); ++i)
  {
    vtkDataArray* a = cd->GetArray(i);
    if (!a || !a->GetName())
    {
      continue;
    }
    const std::string name = a->GetName();
    if (name == "MaterialId" || name == "CellId" || name.rfind("deck_", 0) == 0)
    {
      continue;
    }
    mesh::TetArray t{ name, a->GetNumberOfComponents(), {} };
    t.values.resize(static_cast<std::size_t>(cells) * std::size_t(t.components));
    for (vtkIdType c = 0; c < cells; ++c)
    {
      for (int k = 0; k < t.components; ++k)
      {
        t.values[static_cast<std::size_t>(c) * std::size_t(t.components) + std::size_t(k)] =
          a->GetComponent(c, k);
      }
    }
    m.cellData.push_back(std::move(t));
  }
  try
  {
    mesh::validate(m);
  }
  catch (const std::invalid_argument& e)
  {
    throw std::invalid_argument("'" + where + "': " + e.what());
  }
  return m;
}

} // namespace ictk::vtk
