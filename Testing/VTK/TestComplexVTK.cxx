// SPDX-License-Identifier: BSD-3-Clause
// Complexes through VTK: a voxel cell read from a .vti image, an explicit cell read from an .stl
// file, the containment of an FRep ball in the voxel cell proved by validation, and the
// partitioned dataset collection ictkComplexSource makes of them.

#include "Complex/Discretization.h"
#include "Complex/Validation.h"
#include "ictkComplexSource.h"
#include "ictkComplexValidator.h"
#include "ictkTetrahedralize.h"

#include <vtkCellData.h>
#include <vtkCubeSource.h>
#include <vtkDataAssembly.h>
#include <vtkDoubleArray.h>
#include <vtkFieldData.h>
#include <vtkFloatArray.h>
#include <vtkIdList.h>
#include <vtkImageData.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkPartitionedDataSet.h>
#include <vtkPartitionedDataSetCollection.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkSTLWriter.h>
#include <vtkStringArray.h>
#include <vtkTable.h>
#include <vtkTetra.h>
#include <vtkTriangleFilter.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLImageDataWriter.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

namespace
{

struct Files
{
  std::filesystem::path dir;
  Files()
  {
    dir =
      std::filesystem::temp_directory_path() / ("ictk-complex-vtk-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
  }
  ~Files() { std::filesystem::remove_all(dir); }
  std::string path(const std::string& name) const { return (dir / name).string(); }
};

/// A 64^3 image of 0.8 - |p| over [-1, 1]^3: a ball of radius 0.8 sampled on voxels of 2/63.
void writeSphereImage(const std::string& path)
{
  vtkNew<vtkImageData> image;
  image->SetDimensions(64, 64, 64);
  image->SetOrigin(-1, -1, -1);
  const double h = 2.0 / 63;
  image->SetSpacing(h, h, h);
  vtkNew<vtkFloatArray> values;
  values->SetName("density");
  values->SetNumberOfTuples(64 * 64 * 64);
  for (int k = 0; k < 64; ++k)
  {
    for (int j = 0; j < 64; ++j)
    {
      for (int i = 0; i < 64; ++i)
      {
        const double x = -1 + i * h, y = -1 + j * h, z = -1 + k * h;
        values->SetValue(
          (k * 64 + j) * 64 + i, static_cast<float>(0.8 - std::sqrt(x * x + y * y + z * z)));
      }
    }
  }
  image->GetPointData()->SetScalars(values);
  vtkNew<vtkXMLImageDataWriter> writer;
  writer->SetInputData(image);
  writer->SetFileName(path.c_str());
  ASSERT_EQ(writer->Write(), 1);
}

void writeCube(const std::string& path)
{
  vtkNew<vtkCubeSource> cube;
  cube->SetCenter(3, 0, 0);
  vtkNew<vtkTriangleFilter> triangles;
  triangles->SetInputConnection(cube->GetOutputPort());
  vtkNew<vtkSTLWriter> writer;
  writer->SetInputConnection(triangles->GetOutputPort());
  writer->SetFileName(path.c_str());
  ASSERT_EQ(writer->Write(), 1);
}

vtkPolyData* partition(vtkPartitionedDataSetCollection* pdc, const std::string& name)
{
  for (unsigned int i = 0; i < pdc->GetNumberOfPartitionedDataSets(); ++i)
  {
    auto* leaf = vtkPolyData::SafeDownCast(pdc->GetPartitionedDataSet(i)->GetPartition(0));
    auto* names = vtkStringArray::SafeDownCast(leaf->GetFieldData()->GetAbstractArray("CellName"));
    if (names && names->GetValue(0) == name)
    {
      return leaf;
    }
  }
  return nullptr;
}

} // namespace

TEST(ComplexVTK, VoxelAndMeshCellsFromFiles)
{
  Files files;
  writeSphereImage(files.path("sphere.vti"));
  writeCube(files.path("cube.stl"));
  std::ofstream(files.path("scene.json")) << R"({
  "name": "scene",
  "cells": [
    { "name": "scan", "kind": "V", "dimension": 3, "file": "sphere.vti", "array": "density",
      "iso": 0, "inside": "above" },
    { "name": "implant", "kind": "F", "dimension": 3, "inside": ["0.25 - x[1]^2 - x[2]^2 - x[3]^2"],
      "bounds": [[-0.5, -0.5, -0.5], [0.5, 0.5, 0.5]] },
    { "name": "box", "kind": "B", "dimension": 2, "file": "cube.stl" }
  ],
  "relations": { "containment": [["scan", "implant"]] }
})";
  const ictk::complex::Complex k = ictkComplexSource::ReadComplexFile(files.path("scene.json"));
  ASSERT_EQ(k.cellCount(), 3u);
  EXPECT_EQ(k.cell(k.idOf("scan")).kind, ictk::complex::CellKind::Voxel);

  const double h = 2.0 / 63;
  ictk::complex::DiscretizationOptions o;
  o.featureSize = h;
  const ictk::complex::ComplexMesh mesh = ictk::complex::discretizeComplex(k, o);
  // The voxel cell's surface lies within half a voxel of the analytic sphere of radius 0.8.
  const auto& scan = mesh.of(k.idOf("scan")).surface;
  ASSERT_GT(scan.triangles.size(), 1000u);
  double worst = 0;
  for (const auto& p : scan.points)
  {
    worst = std::max(worst, std::abs(std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) - 0.8));
  }
  EXPECT_LT(worst, 0.5 * h);
  // The explicit cube: 12 triangles, closed.
  const auto& box = mesh.of(k.idOf("box")).surface;
  EXPECT_EQ(box.triangles.size(), 12u);
  EXPECT_TRUE(ictk::discretize::analyzeTopology(box).closed());
  // Rc^{33} (scan, implant) holds, proved by interval arithmetic on the voxel field.
  const ictk::complex::ValidationReport report = ictk::complex::validateComplex(k, mesh);
  EXPECT_TRUE(report.ok()) << report.text(k);
  ASSERT_EQ(report.satisfied.size(), 1u);

  // A ball that pokes out of the scan: the containment is violated, with a witness outside.
  std::ofstream(files.path("bad.json")) << R"({
  "cells": [
    { "name": "scan", "kind": "V", "dimension": 3, "file": "sphere.vti", "iso": 0 },
    { "name": "implant", "kind": "F", "dimension": 3,
      "inside": ["0.25 - (x[1] - 0.5)^2 - x[2]^2 - x[3]^2"], "bounds": [[0, -0.5, -0.5], [1, 0.5, 0.5]] }
  ],
  "relations": { "containment": [["scan", "implant"]] }
})";
  const ictk::complex::Complex bad = ictkComplexSource::ReadComplexFile(files.path("bad.json"));
  const ictk::complex::ValidationReport badReport =
    ictk::complex::validateComplex(bad, ictk::complex::discretizeComplex(bad, o));
  ASSERT_EQ(badReport.violated.size(), 1u);
  const auto& w = badReport.violated[0].witness;
  EXPECT_GT(std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]), 0.8);

  // The VTK form: one partitioned dataset per cell with its field data.
  vtkNew<ictkComplexSource> source;
  source->SetFileName(files.path("scene.json").c_str());
  source->SetFeatureSize(h);
  source->SetVolumeResolution(17);
  source->Update();
  vtkPartitionedDataSetCollection* pdc = source->GetOutput();
  ASSERT_EQ(pdc->GetNumberOfPartitionedDataSets(), 3u);
  vtkPolyData* scanData = partition(pdc, "scan");
  ASSERT_NE(scanData, nullptr);
  EXPECT_EQ(scanData->GetNumberOfPolys(), static_cast<vtkIdType>(scan.triangles.size()));
  auto* kind = vtkStringArray::SafeDownCast(scanData->GetFieldData()->GetAbstractArray("CellKind"));
  ASSERT_NE(kind, nullptr);
  EXPECT_EQ(kind->GetValue(0), "V");
  // The optional volume of the FRep implicant: 17^3 samples of 0.25 - |p|^2 over [-0.5, 0.5]^3.
  vtkPartitionedDataSet* implant = nullptr;
  for (unsigned int i = 0; i < pdc->GetNumberOfPartitionedDataSets(); ++i)
  {
    if (vtkPolyData::SafeDownCast(pdc->GetPartitionedDataSet(i)->GetPartition(0)) ==
      partition(pdc, "implant"))
    {
      implant = pdc->GetPartitionedDataSet(i);
    }
  }
  ASSERT_NE(implant, nullptr);
  auto* volume = vtkImageData::SafeDownCast(implant->GetPartition(1));
  ASSERT_NE(volume, nullptr);
  EXPECT_EQ(volume->GetNumberOfPoints(), 17 * 17 * 17);
  // The centre sample (8, 8, 8) is at the origin: f = 0.25.
  EXPECT_NEAR(volume->GetPointData()->GetArray("f")->GetTuple1((8 * 17 + 8) * 17 + 8), 0.25, 1e-6);
}

TEST(ComplexVTK, UnreadableFilesNameTheCellAndFile)
{
  Files files;
  std::ofstream(files.path("missing.json")) << R"({
  "cells": [ { "name": "scan", "kind": "V", "dimension": 3, "file": "nowhere.vti" },
             { "name": "part", "kind": "B", "dimension": 2, "file": "nowhere.stl" } ]
})";
  try
  {
    ictkComplexSource::ReadComplexFile(files.path("missing.json"));
    FAIL();
  }
  catch (const std::exception& e)
  {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("cell 'scan': cannot open '"));
    EXPECT_THAT(e.what(), ::testing::HasSubstr("nowhere.vti'"));
    EXPECT_THAT(e.what(), ::testing::HasSubstr("cell 'part': cannot open '"));
  }
  // A source with a bad file fails the request with an error, and leaves an empty output.
  vtkNew<ictkComplexSource> source;
  source->SetFileName(files.path("missing.json").c_str());
  source->SetGlobalWarningDisplay(0);
  source->Update();
  EXPECT_EQ(source->GetOutput()->GetNumberOfPartitionedDataSets(), 0u);
}

TEST(ComplexVTK, TetrahedralizeFilterLabelsEveryTetrahedron)
{
  if (!ictkTetrahedralize::HasBackend(ictkTetrahedralize::TETGEN))
  {
    GTEST_SKIP() << "the TetGen backend was not built";
  }
  Files files;
  std::ofstream(files.path("bar.json")) << R"json({
  "cells": [
    { "name": "left", "kind": "F", "dimension": 3, "bounds": [[0, 0, 0], [1, 0.2, 0.2]],
      "inside": ["min(min(min(x[1], 1 - x[1]), min(x[2], 0.2 - x[2])), min(x[3], 0.2 - x[3]))"]
},
    { "name": "right", "kind": "F", "dimension": 3, "bounds": [[1, 0, 0], [2, 0.2, 0.2]],
      "inside": ["min(min(min(x[1] - 1, 2 - x[1]), min(x[2], 0.2 - x[2])), min(x[3], 0.2 - x[3]))"] }
  ]
})json";
  vtkNew<ictkComplexSource> source;
  source->SetFileName(files.path("bar.json").c_str());
  source->SetFeatureSize(0.05);
  vtkNew<ictkTetrahedralize> tetra;
  tetra->SetInputConnection(source->GetOutputPort());
  tetra->SetBackendToTetGen();
  tetra->SetSize(0.05);
  tetra->Update();
  vtkUnstructuredGrid* grid = tetra->GetOutput();
  ASSERT_GT(grid->GetNumberOfCells(), 100);
  auto* material = vtkIntArray::SafeDownCast(grid->GetCellData()->GetArray("MaterialId"));
  ASSERT_NE(material, nullptr);
  // Both materials present, each of volume 0.04, and no tetrahedron straddles x = 1.
  double volume[3] = { 0, 0, 0 };
  for (vtkIdType c = 0; c < grid->GetNumberOfCells(); ++c)
  {
    double p[4][3];
    vtkIdList* ids = grid->GetCell(c)->GetPointIds();
    for (int k = 0; k < 4; ++k)
    {
      grid->GetPoint(ids->GetId(k), p[k]);
    }
    const int m = material->GetValue(c);
    ASSERT_TRUE(m == 1 || m == 2);
    volume[m] += vtkTetra::ComputeVolume(p[0], p[1], p[2], p[3]);
    for (const auto& q : p)
    {
      EXPECT_TRUE(m == 1 ? q[0] <= 1 + 1e-9 : q[0] >= 1 - 1e-9);
    }
  }
  EXPECT_NEAR(volume[1], 0.04, 1e-9);
  EXPECT_NEAR(volume[2], 0.04, 1e-9);
  // The validity check's figures (issue 21) as field data: the shortest edge of the bar's mesh
  // is 0.213 x size, nothing duplicated, stray or non-conforming.
  vtkFieldData* fd = grid->GetFieldData();
  for (const char* name : { "MinEdgeLength", "MinEdgeLengthRelative", "MinTetrahedronVolume",
         "MinTetrahedronVolumeRelative", "DuplicatePoints", "NonConformingFaces",
         "StrayBoundaryFaces" })
  {
    ASSERT_NE(fd->GetArray(name), nullptr) << name;
  }
  EXPECT_GT(fd->GetArray("MinEdgeLengthRelative")->GetTuple1(0), 0.1);
  EXPECT_NEAR(fd->GetArray("MinEdgeLength")->GetTuple1(0),
    0.05 * fd->GetArray("MinEdgeLengthRelative")->GetTuple1(0), 1e-15);
  EXPECT_GT(fd->GetArray("MinTetrahedronVolume")->GetTuple1(0), 0);
  EXPECT_EQ(fd->GetArray("DuplicatePoints")->GetTuple1(0), 0);
  EXPECT_EQ(fd->GetArray("NonConformingFaces")->GetTuple1(0), 0);
  EXPECT_EQ(fd->GetArray("StrayBoundaryFaces")->GetTuple1(0), 0);
  // Without a complex on the input the filter fails with an error.
  vtkNew<ictkTetrahedralize> orphan;
  vtkNew<vtkPartitionedDataSetCollection> empty;
  orphan->SetInputData(empty);
  orphan->SetSize(0.05);
  orphan->SetGlobalWarningDisplay(0);
  orphan->Update();
  EXPECT_EQ(orphan->GetOutput()->GetNumberOfCells(), 0);
}

namespace
{
std::string FlowerPath()
{
  return std::string(ICTK_DATA_DIR) + "/Models/flower/flower.json";
}

/// Points of each partitioned dataset of a collection (0 for an empty one).
std::vector<vtkIdType> PointsPerCell(vtkPartitionedDataSetCollection* pdc)
{
  std::vector<vtkIdType> points;
  for (unsigned int i = 0; i < pdc->GetNumberOfPartitionedDataSets(); ++i)
  {
    points.push_back(pdc->GetPartitionedDataSet(i)->GetNumberOfPoints());
  }
  return points;
}

/// The points of cell i's surface/curve/point partition, flattened.
std::vector<double> Coordinates(vtkPartitionedDataSetCollection* pdc, unsigned int i)
{
  std::vector<double> xyz;
  vtkPartitionedDataSet* part = pdc->GetPartitionedDataSet(i);
  auto* leaf =
    part->GetNumberOfPartitions() ? vtkPolyData::SafeDownCast(part->GetPartition(0)) : nullptr;
  for (vtkIdType p = 0; leaf && p < leaf->GetNumberOfPoints(); ++p)
  {
    const double* q = leaf->GetPoint(p);
    xyz.insert(xyz.end(), q, q + 3);
  }
  return xyz;
}
} // namespace

// Selectors choose cells by the assembly; the collection keeps every cell's dataset, empty for
// the others, and the chosen cells' meshes (attributes included) equal the whole discretisation.
TEST(ComplexVTK, SelectorsDiscretiseOnlyTheChosenCells)
{
  vtkNew<ictkComplexSource> whole;
  whole->SetFileName(FlowerPath().c_str());
  whole->Update();
  vtkPartitionedDataSetCollection* all = whole->GetOutput();
  ASSERT_EQ(all->GetNumberOfPartitionedDataSets(), 12u);
  ASSERT_NE(whole->GetAssembly(), nullptr);

  vtkNew<ictkComplexSource> source;
  source->SetFileName(FlowerPath().c_str());
  source->AddSelector("//dimension_2");
  source->AddSelector("//t_0^0"); // a node name made valid, as MakeValidNodeName does
  source->UpdateInformation();
  // The assembly is known before any discretisation.
  vtkDataAssembly* assembly = source->GetAssembly();
  ASSERT_NE(assembly, nullptr);
  EXPECT_EQ(assembly->GetDataSetIndices(assembly->FindFirstNodeWithName("dimension_2")).size(), 2u);
  source->ClearSelectors();
  source->AddSelector("//dimension_2");
  source->Update();
  vtkPartitionedDataSetCollection* some = source->GetOutput();
  ASSERT_EQ(some->GetNumberOfPartitionedDataSets(), 12u);
  int chosen = 0;
  for (unsigned int i = 0; i < 12; ++i)
  {
    auto* dim = vtkIntArray::SafeDownCast(
      some->GetPartitionedDataSet(i)->GetFieldData()->GetArray("CellDimension"));
    ASSERT_NE(dim, nullptr) << "every dataset keeps its cell's field data";
    if (dim->GetValue(0) == 2)
    {
      ++chosen;
      EXPECT_EQ(Coordinates(some, i), Coordinates(all, i)) << "cell " << i;
      auto* leaf = vtkPolyData::SafeDownCast(some->GetPartitionedDataSet(i)->GetPartition(0));
      auto* reference = vtkPolyData::SafeDownCast(all->GetPartitionedDataSet(i)->GetPartition(0));
      ASSERT_EQ(
        leaf->GetPointData()->GetNumberOfArrays(), reference->GetPointData()->GetNumberOfArrays());
      for (int a = 0; a < reference->GetPointData()->GetNumberOfArrays(); ++a)
      {
        vtkDataArray* x = reference->GetPointData()->GetArray(a);
        vtkDataArray* y = leaf->GetPointData()->GetArray(x->GetName());
        ASSERT_NE(y, nullptr) << x->GetName();
        for (vtkIdType t = 0; t < x->GetNumberOfTuples(); ++t)
        {
          for (int c = 0; c < x->GetNumberOfComponents(); ++c)
          {
            ASSERT_EQ(x->GetComponent(t, c), y->GetComponent(t, c)) << x->GetName();
          }
        }
      }
    }
    else
    {
      EXPECT_EQ(some->GetPartitionedDataSet(i)->GetNumberOfPoints(), 0) << "cell " << i;
    }
  }
  EXPECT_EQ(chosen, 2);
}

// Pieces (MPI ranks) share the cells out: every cell is discretised by exactly one piece, as the
// whole run discretises it, and every piece has the whole structure.
TEST(ComplexVTK, PiecesShareTheCellsOut)
{
  vtkNew<ictkComplexSource> whole;
  whole->SetFileName(FlowerPath().c_str());
  whole->Update();
  const std::vector<vtkIdType> reference = PointsPerCell(whole->GetOutput());
  std::vector<vtkIdType> merged(reference.size(), 0);
  for (int piece = 0; piece < 3; ++piece)
  {
    vtkNew<ictkComplexSource> source;
    source->SetFileName(FlowerPath().c_str());
    source->UpdatePiece(piece, 3, 0);
    vtkPartitionedDataSetCollection* part = source->GetOutput();
    ASSERT_EQ(part->GetNumberOfPartitionedDataSets(), reference.size());
    EXPECT_EQ(part->GetDataAssembly()->GetNumberOfChildren(0),
      whole->GetOutput()->GetDataAssembly()->GetNumberOfChildren(0));
    const std::vector<vtkIdType> points = PointsPerCell(part);
    for (std::size_t i = 0; i < points.size(); ++i)
    {
      if (points[i] > 0)
      {
        EXPECT_EQ(i % 3, static_cast<std::size_t>(piece)) << "cell " << i;
        EXPECT_EQ(merged[i], 0) << "cell " << i << " discretised twice";
        merged[i] = points[i];
        EXPECT_EQ(Coordinates(part, static_cast<unsigned int>(i)),
          Coordinates(whole->GetOutput(), static_cast<unsigned int>(i)));
      }
    }
  }
  EXPECT_EQ(merged, reference);
}

TEST(ComplexVTK, ValidatorTableMatchesTheCoreReport)
{
  vtkNew<ictkComplexSource> source;
  source->SetFileName(FlowerPath().c_str());
  vtkNew<ictkComplexValidator> validator;
  validator->SetInputConnection(source->GetOutputPort());
  validator->Update();
  vtkTable* table = validator->GetOutput();

  const ictk::complex::Complex k = ictkComplexSource::ReadComplexFile(FlowerPath());
  const ictk::complex::ComplexMesh mesh = ictk::complex::discretizeComplex(k);
  const ictk::complex::ValidationReport report = ictk::complex::validateComplex(k, mesh);
  const std::size_t rows =
    report.satisfied.size() + report.violated.size() + report.undeclared.size();
  ASSERT_EQ(table->GetNumberOfRows(), static_cast<vtkIdType>(rows));
  ASSERT_GT(rows, 10u);
  auto* status = vtkStringArray::SafeDownCast(table->GetColumnByName("Status"));
  auto* deviation = vtkDoubleArray::SafeDownCast(table->GetColumnByName("Deviation"));
  ASSERT_NE(status, nullptr);
  ASSERT_NE(deviation, nullptr);
  // Violated first, then undeclared, then satisfied, each in the report's order.
  vtkIdType r = static_cast<vtkIdType>(report.violated.size() + report.undeclared.size());
  for (const auto& f : report.satisfied)
  {
    EXPECT_EQ(status->GetValue(r), "satisfied");
    EXPECT_EQ(deviation->GetValue(r), f.deviation);
    ++r;
  }
  EXPECT_EQ(table->GetFieldData()->GetArray("Valid")->GetTuple1(0), report.ok() ? 1 : 0);
  EXPECT_EQ(table->GetFieldData()->GetArray("Tolerance")->GetTuple1(0), report.tolerance);
}

// The complex survives a shallow copy (ParaView's vtkPVPostFilter makes one after every output).
TEST(ComplexVTK, ComplexSurvivesAShallowCopy)
{
  vtkNew<ictkComplexSource> source;
  source->SetFileName(FlowerPath().c_str());
  source->SetFeatureSize(0.1);
  source->Update();
  vtkNew<vtkPartitionedDataSetCollection> copy;
  copy->ShallowCopy(source->GetOutput());
  const auto k = ictkComplexSource::GetComplex(copy);
  ASSERT_NE(k, nullptr);
  EXPECT_EQ(k, ictkComplexSource::GetComplex(source->GetOutput()));
  EXPECT_EQ(k->cellIds().size(), 12u);
}
