// SPDX-License-Identifier: BSD-3-Clause
// Issue 15: a solved mesh in VTK (ictkSolverResults.h): the results as point arrays and the deck's
// binned moduli as cell arrays; a grid of tetrahedra back into the core's TetMesh, and refused
// when it holds another cell type.

#include "Mesh/Structured.h"
#include "Mesh/Writers.h"
#include "ictkSolverResults.h"

#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkHexahedron.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkUnstructuredGrid.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

using namespace ictk;

namespace
{

/// The unit cube's 6 Kuhn tetrahedra in two cells, E = 100 (t < 3) or 100 e^0.5.
mesh::TetMesh cube()
{
  mesh::TetMesh m = mesh::kuhnTetMesh({ { 0, 0, 0 }, { 1, 1, 1 } }, { 1, 1, 1 });
  m.cells = { 3, 3, 3, 3, 7, 7 };
  m.materials = { 1, 1, 1, 1, 2, 2 };
  m.materialNames = { "bone", "pin" };
  mesh::TetArray e{ "youngs_modulus", 1, {} };
  for (std::size_t t = 0; t < 6; ++t)
  {
    e.values.push_back(t < 2 ? 100 : t < 4 ? 100 * std::exp(0.5) : 110000);
  }
  m.cellData = { e, { "label", 1, { 1, 1, 1, 1, 2, 2 } } };
  return m;
}

} // namespace

TEST(SolverResultsVTK, ResultsAndDeckOnTheGrid)
{
  const mesh::TetMesh m = cube();
  mesh::PointResults r;
  for (std::size_t i = 0; i < m.points.size(); ++i)
  {
    r.displacement.push_back({ 0, 0, -0.01 * m.points[i][2] });
    r.stress.push_back({ 0, 0, -double(i), 0, 0, 0 });
    r.vonMises.push_back(double(i));
    r.force.push_back({ 0, 0, 0 });
  }
  const auto deck = mesh::deckMaterials(m, 0.01);
  ASSERT_EQ(deck.size(), 3u); // bone in two bins, the pin one material
  vtkNew<vtkUnstructuredGrid> grid;
  ictk::vtk::solverResultsToVTK(m, r, deck, grid);
  ASSERT_EQ(grid->GetNumberOfPoints(), 8);
  ASSERT_EQ(grid->GetNumberOfCells(), 6);
  vtkDataArray* u = grid->GetPointData()->GetArray("displacement");
  vtkDataArray* s = grid->GetPointData()->GetArray("stress");
  ASSERT_TRUE(u && s && grid->GetPointData()->GetArray("von_mises") &&
    grid->GetPointData()->GetArray("reaction_force"));
  EXPECT_EQ(s->GetNumberOfComponents(), 6);
  EXPECT_STREQ(s->GetComponentName(5), "XZ");
  for (vtkIdType i = 0; i < 8; ++i)
  {
    EXPECT_EQ(u->GetComponent(i, 2), -0.01 * grid->GetPoint(i)[2]);
    EXPECT_EQ(s->GetComponent(i, 2), -double(i));
  }
  EXPECT_STREQ(grid->GetPointData()->GetScalars()->GetName(), "von_mises");
  vtkDataArray* written = grid->GetCellData()->GetArray("deck_youngs_modulus");
  vtkDataArray* index = grid->GetCellData()->GetArray("deck_material");
  ASSERT_TRUE(written && index && grid->GetCellData()->GetArray("label"));
  for (vtkIdType t = 0; t < 6; ++t)
  {
    const double e = m.cellData[0].values[std::size_t(t)];
    EXPECT_NEAR(written->GetTuple1(t), e, 1e-9 * e) << t; // each bin holds one value here
    EXPECT_EQ(index->GetTuple1(t), t < 2 ? 1 : t < 4 ? 2 : 3);
  }
  mesh::PointResults wrong = r;
  wrong.vonMises.pop_back();
  EXPECT_THROW(ictk::vtk::solverResultsToVTK(m, wrong, deck, grid), std::invalid_argument);
}

TEST(SolverResultsVTK, GridBackIntoATetMesh)
{
  const mesh::TetMesh m = cube();
  vtkNew<vtkUnstructuredGrid> grid;
  ictk::vtk::solverResultsToVTK(m, {}, mesh::deckMaterials(m), grid);
  const mesh::TetMesh back = ictk::vtk::tetMeshFromVTK(grid, "cube.vtu");
  EXPECT_EQ(back.points, m.points);
  EXPECT_EQ(back.tetrahedra, m.tetrahedra);
  EXPECT_EQ(back.cells, m.cells);
  EXPECT_EQ(back.materials, m.materials);
  EXPECT_EQ(back.materialNames, m.materialNames);
  ASSERT_EQ(back.cellData.size(), 2u); // the deck's arrays are not attributes
  EXPECT_EQ(back.cellData[0].name, "youngs_modulus");
  EXPECT_EQ(back.cellData[0].values, m.cellData[0].values);
  EXPECT_EQ(back.cellData[1].name, "label");

  // A hexahedron is refused, naming the file and the cell.
  vtkNew<vtkUnstructuredGrid> hex;
  vtkNew<vtkPoints> points;
  for (int i = 0; i < 8; ++i)
  {
    points->InsertNextPoint(i & 1, (i >> 1) & 1, (i >> 2) & 1);
  }
  hex->SetPoints(points);
  const vtkIdType ids[8] = { 0, 1, 3, 2, 4, 5, 7, 6 };
  hex->InsertNextCell(VTK_HEXAHEDRON, 8, ids);
  try
  {
    ictk::vtk::tetMeshFromVTK(hex, "hex.vtu");
    FAIL() << "no error";
  }
  catch (const std::invalid_argument& e)
  {
    EXPECT_THAT(
      e.what(), ::testing::HasSubstr("'hex.vtu': cell 0 is a vtkHexahedron, not a tetrahedron"));
  }
  vtkNew<vtkUnstructuredGrid> empty;
  EXPECT_THROW(ictk::vtk::tetMeshFromVTK(empty, "empty.vtu"), std::invalid_argument);
}
