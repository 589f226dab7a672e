// SPDX-License-Identifier: BSD-3-Clause
// A dynamic complex in VTK's temporal pipeline (ictkDynamicComplexSource) on the thesis 5.1 model
// (Data/Models/icm/ch5_1_disk_rectangle.icm): a disk of radius 1 whose centre moves from (-2, 0)
// at velocity (1, 0) towards a 2 x 2 rectangle centred at (3, 0). The disk's centre is at x =
// -2 + t and touches the rectangle's left side x = 2 at t = 3: instance K1 (2 cells) before, K3
// (the rectangle, the disk, the half-disk, the arc, the chord and its end points) after.

#include "Complex/Complex.h"
#include "ictkComplexSource.h"
#include "ictkDynamicComplexSource.h"

#include <vtkCallbackCommand.h>
#include <vtkCommand.h>
#include <vtkDataAssembly.h>
#include <vtkDoubleArray.h>
#include <vtkFieldData.h>
#include <vtkInformation.h>
#include <vtkNew.h>
#include <vtkPartitionedDataSet.h>
#include <vtkPartitionedDataSetCollection.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkStreamingDemandDrivenPipeline.h>
#include <vtkStringArray.h>

#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace
{

std::string DiskRectangle()
{
  return std::string(ICTK_DATA_DIR) + "/Models/icm/ch5_1_disk_rectangle.icm";
}

std::vector<double> AdvertisedSteps(ictkDynamicComplexSource* source)
{
  vtkInformation* info = source->GetOutputInformation(0);
  const int n = info->Length(vtkStreamingDemandDrivenPipeline::TIME_STEPS());
  const double* steps = info->Get(vtkStreamingDemandDrivenPipeline::TIME_STEPS());
  return std::vector<double>(steps, steps + n);
}

std::string Instance(vtkPartitionedDataSetCollection* output)
{
  auto* names = vtkStringArray::SafeDownCast(output->GetFieldData()->GetAbstractArray("Instance"));
  return names && names->GetNumberOfValues() == 1 ? names->GetValue(0) : std::string("<none>");
}

vtkPolyData* Cell(vtkPartitionedDataSetCollection* output, const std::string& name)
{
  for (unsigned int i = 0; i < output->GetNumberOfPartitionedDataSets(); ++i)
  {
    auto* leaf = vtkPolyData::SafeDownCast(output->GetPartitionedDataSet(i)->GetPartition(0));
    auto* names = vtkStringArray::SafeDownCast(leaf->GetFieldData()->GetAbstractArray("CellName"));
    if (names && names->GetValue(0) == name)
    {
      return leaf;
    }
  }
  return nullptr;
}

/// The number of cells the assembly lists under /dimension_<p>.
int CellsOfDimension(vtkPartitionedDataSetCollection* output, int p)
{
  vtkDataAssembly* assembly = output->GetDataAssembly();
  const int node = assembly->FindFirstNodeWithName(("dimension_" + std::to_string(p)).c_str());
  return node < 0 ? -1 : static_cast<int>(assembly->GetChildNodes(node).size());
}

struct Frame
{
  std::string instance;
  double dataTime = NAN;
  unsigned int cells = 0;
  double diskCentreX = NAN;
  vtkIdType diskPoints = 0;
  double diskBounds[6] = { 0, 0, 0, 0, 0, 0 };
  int oneDimensional = 0;
};

Frame Update(ictkDynamicComplexSource* source, double t)
{
  EXPECT_EQ(source->UpdateTimeStep(t), 1) << "t = " << t;
  vtkPartitionedDataSetCollection* output =
    vtkPartitionedDataSetCollection::SafeDownCast(source->GetOutputDataObject(0));
  Frame f;
  f.instance = Instance(output);
  if (output->GetInformation()->Has(vtkDataObject::DATA_TIME_STEP()))
  {
    f.dataTime = output->GetInformation()->Get(vtkDataObject::DATA_TIME_STEP());
  }
  f.cells = output->GetNumberOfPartitionedDataSets();
  if (vtkPolyData* disk = Cell(output, "LHKF"))
  {
    disk->GetBounds(f.diskBounds);
    f.diskCentreX = 0.5 * (f.diskBounds[0] + f.diskBounds[1]);
    f.diskPoints = disk->GetNumberOfPoints();
  }
  f.oneDimensional = CellsOfDimension(output, 1);
  // The complex itself rides along for downstream filters.
  const auto k = ictkComplexSource::GetComplex(output);
  EXPECT_TRUE(k != nullptr);
  if (k)
  {
    EXPECT_EQ(k->cellCount(), f.cells);
  }
  return f;
}

TEST(DynamicsVTK, AdvertisesTheModelsTimeSteps)
{
  vtkNew<ictkDynamicComplexSource> source;
  source->SetFileName(DiskRectangle().c_str());
  source->SetTimeStepSize(0.5);
  source->UpdateInformation();
  // TIMESPAN(0, 10) at 0.5: 0, 0.5, ..., 10.
  const std::vector<double> steps = AdvertisedSteps(source);
  ASSERT_EQ(steps.size(), 21u);
  for (std::size_t k = 0; k < steps.size(); ++k)
  {
    EXPECT_DOUBLE_EQ(steps[k], 0.5 * static_cast<double>(k));
  }
  vtkInformation* info = source->GetOutputInformation(0);
  ASSERT_TRUE(info->Has(vtkStreamingDemandDrivenPipeline::TIME_RANGE()));
  const double* range = info->Get(vtkStreamingDemandDrivenPipeline::TIME_RANGE());
  EXPECT_EQ(range[0], 0.0);
  EXPECT_EQ(range[1], 10.0);

  // 0.3 does not divide 10: 0, 0.3, ..., 9.9 and then 10 itself.
  source->SetTimeStepSize(0.3);
  source->UpdateInformation();
  const std::vector<double> uneven = AdvertisedSteps(source);
  ASSERT_EQ(uneven.size(), 35u);
  EXPECT_NEAR(uneven[33], 9.9, 1e-12);
  EXPECT_EQ(uneven[34], 10.0);

  // The default: 1/100 of the range.
  source->SetTimeStepSize(0);
  source->UpdateInformation();
  EXPECT_EQ(AdvertisedSteps(source).size(), 101u);

  // An explicit list, sorted and without duplicates.
  const double times[] = { 4.0, 1.0, 2.5, 1.0 };
  source->SetTimeSteps(times, 4);
  source->UpdateInformation();
  EXPECT_EQ(AdvertisedSteps(source), (std::vector<double>{ 1.0, 2.5, 4.0 }));
}

TEST(DynamicsVTK, UpdateTimeStepGivesTheInstanceOfThatTime)
{
  vtkNew<ictkDynamicComplexSource> source;
  source->SetFileName(DiskRectangle().c_str());
  source->SetTimeStepSize(0.5);
  source->SetFeatureSize(0.05);

  const Frame early = Update(source, 2.0);
  EXPECT_EQ(early.instance, "K1");
  EXPECT_EQ(early.dataTime, 2.0);
  EXPECT_EQ(early.cells, 2u); // DEQS and LHKF
  EXPECT_EQ(early.oneDimensional, 0);
  EXPECT_NEAR(early.diskCentreX, -2.0 + 2.0, 0.01);
  EXPECT_NEAR(early.diskBounds[1] - early.diskBounds[0], 2.0, 0.02); // the diameter
  EXPECT_STREQ(source->GetInstanceName(), "K1");

  const Frame late = Update(source, 4.5);
  EXPECT_EQ(late.instance, "K3");
  EXPECT_EQ(late.dataTime, 4.5);
  EXPECT_EQ(late.cells, 7u);
  EXPECT_EQ(late.oneDimensional, 2); // the arc KFL and the chord KL
  EXPECT_NEAR(late.diskCentreX, -2.0 + 4.5, 0.01);
  // The disk only moved between the two requests: the same mesh, shifted by 2.5.
  EXPECT_EQ(late.diskPoints, early.diskPoints);
  EXPECT_NEAR(late.diskBounds[0] - early.diskBounds[0], 2.5, 1e-9);
  EXPECT_GE(source->GetCellsReused(), 1); // the rectangle

  // Back in time: the model runs again from its start and gives the same frame.
  const Frame again = Update(source, 2.0);
  EXPECT_EQ(again.instance, "K1");
  EXPECT_EQ(again.dataTime, 2.0);
  EXPECT_EQ(again.cells, early.cells);
  EXPECT_EQ(again.diskPoints, early.diskPoints);
  for (int k = 0; k < 6; ++k)
  {
    EXPECT_NEAR(again.diskBounds[k], early.diskBounds[k], 1e-12);
  }

  // A time between the advertised ones is evaluated as asked, and stamped so.
  const Frame between = Update(source, 2.75);
  EXPECT_EQ(between.instance, "K1");
  EXPECT_EQ(between.dataTime, 2.75);
  EXPECT_NEAR(between.diskCentreX, 0.75, 0.01);
}

TEST(DynamicsVTK, CoherenceOffGivesTheSameFrames)
{
  vtkNew<ictkDynamicComplexSource> coherent;
  vtkNew<ictkDynamicComplexSource> full;
  for (ictkDynamicComplexSource* s : { coherent.Get(), full.Get() })
  {
    s->SetFileName(DiskRectangle().c_str());
    s->SetTimeStepSize(0.5);
    s->SetFeatureSize(0.05);
  }
  full->CoherentOff();
  for (double t : { 1.0, 2.0, 3.5, 4.0, 5.0 })
  {
    const Frame a = Update(coherent, t);
    const Frame b = Update(full, t);
    EXPECT_EQ(a.instance, b.instance);
    EXPECT_EQ(a.cells, b.cells);
    EXPECT_EQ(a.diskPoints, b.diskPoints);
    for (int k = 0; k < 6; ++k)
    {
      EXPECT_NEAR(a.diskBounds[k], b.diskBounds[k], 1e-9);
    }
  }
  EXPECT_GT(coherent->GetTotalCellsReused() + coherent->GetTotalCellsMoved(), 0);
  EXPECT_EQ(full->GetTotalCellsReused() + full->GetTotalCellsMoved(), 0);
}

TEST(DynamicsVTK, ReportsProgressAndHonoursAbort)
{
  vtkNew<ictkDynamicComplexSource> source;
  source->SetFileName(DiskRectangle().c_str());
  source->SetTimeStepSize(0.5);
  source->SetFeatureSize(0.1);
  struct Seen
  {
    std::vector<double> progress;
    bool abort = false;
  } seen;
  vtkNew<vtkCallbackCommand> onProgress;
  onProgress->SetClientData(&seen);
  onProgress->SetCallback(
    [](vtkObject* caller, unsigned long, void* clientData, void* callData)
    {
      auto* s = static_cast<Seen*>(clientData);
      s->progress.push_back(*static_cast<double*>(callData));
      if (s->abort && s->progress.back() > 0.25)
      {
        static_cast<vtkAlgorithm*>(caller)->SetAbortExecute(1);
      }
    });
  source->AddObserver(vtkCommand::ProgressEvent, onProgress);
  ASSERT_EQ(source->UpdateTimeStep(4.5), 1);
  ASSERT_GE(seen.progress.size(), 3u);
  EXPECT_TRUE(std::is_sorted(seen.progress.begin(), seen.progress.end()));
  EXPECT_EQ(seen.progress.back(), 1.0);

  // Cancelled in the middle of the engine's run: an empty output, and the next request starts
  // again from the model's start and gives the frame as if nothing happened.
  seen.abort = true;
  seen.progress.clear();
  source->UpdateTimeStep(5.5);
  auto* output = vtkPartitionedDataSetCollection::SafeDownCast(source->GetOutputDataObject(0));
  EXPECT_EQ(output->GetNumberOfPartitionedDataSets(), 0u);
  seen.abort = false;
  source->SetAbortExecute(0);
  source->Modified();
  const Frame f = Update(source, 5.5);
  EXPECT_EQ(f.instance, "K3");
  EXPECT_EQ(f.cells, 7u);
  EXPECT_NEAR(f.diskCentreX, -2.0 + 5.5, 0.01);
}

TEST(DynamicsVTK, ReportsModelErrorsWithTheirPlace)
{
  const std::filesystem::path bad = std::filesystem::temp_directory_path() /
    ("ictk-dynamics-bad-" + std::to_string(::getpid()) + ".icm");
  {
    std::ofstream out(bad);
    out << "name = BROKEN;\nCELLS {\n  A { type = F-CELL; shape = ; }\n}\n";
  }
  vtkNew<ictkDynamicComplexSource> source;
  source->SetFileName(bad.string().c_str());
  std::string message;
  vtkNew<vtkCallbackCommand> onError;
  onError->SetClientData(&message);
  onError->SetCallback([](vtkObject*, unsigned long, void* clientData, void* callData)
    { *static_cast<std::string*>(clientData) = static_cast<const char*>(callData); });
  source->AddObserver(vtkCommand::ErrorEvent, onError);
  source->UpdateInformation();
  std::filesystem::remove(bad);
  EXPECT_NE(message.find(bad.string() + ":3:"), std::string::npos) << message;
  EXPECT_NE(message.find("error"), std::string::npos) << message;
}

#ifdef ICTK_WITH_ASSIMP
// Issue 17: a skinned mesh (glTF2/simple_skin of Debian's assimp-testmodels: a strip of 10
// vertices on two joints, its upper joint turning about z) as a B-cell: its polydata per frame
// moves with the animation and carries, per vertex, the joint that weighs most on it and that
// weight (row k of the strip weighs (1 - k/4, k/4); the first joint wins the tie of row 2).
TEST(DynamicsVTK, SkinnedMeshFramesCarryTheirDominantJoint)
{
  const std::filesystem::path model = std::filesystem::temp_directory_path() /
    ("ictk-dynamics-skin-" + std::to_string(::getpid()) + ".icm");
  {
    std::ofstream out(model);
    out << "name = STRIP;\nTIMESPANS { film : TIMESPAN(0, 5.5); }\n"
           "CELLS { Strip { type = B-CELL; shape = loadMesh(\""
        << ICTK_ASSIMP_MODELS
        << "/glTF2/simple_skin/simple_skin.gltf\", \"\"); dim = 2D; } }\n"
           "K { CELLS { Strip; } }\n";
  }
  vtkNew<ictkDynamicComplexSource> source;
  source->SetFileName(model.string().c_str());
  source->SetTimeStepSize(0.5);
  std::vector<double> minX;
  for (double t : { 0.0, 0.5, 1.0 })
  {
    ASSERT_EQ(source->UpdateTimeStep(t), 1);
    auto* output = vtkPartitionedDataSetCollection::SafeDownCast(source->GetOutputDataObject(0));
    vtkPolyData* strip = Cell(output, "Strip");
    ASSERT_NE(strip, nullptr);
    ASSERT_EQ(strip->GetNumberOfPoints(), 10);
    EXPECT_EQ(strip->GetNumberOfPolys(), 8);
    auto* joint = vtkDoubleArray::SafeDownCast(strip->GetPointData()->GetArray("DominantJoint"));
    auto* weight =
      vtkDoubleArray::SafeDownCast(strip->GetPointData()->GetArray("DominantJointWeight"));
    ASSERT_NE(joint, nullptr);
    ASSERT_NE(weight, nullptr);
    const double joints[10] = { 0, 0, 0, 0, 0, 0, 1, 1, 1, 1 };
    const double weights[10] = { 1, 1, 0.75, 0.75, 0.5, 0.5, 0.75, 0.75, 1, 1 };
    for (vtkIdType i = 0; i < 10; ++i)
    {
      EXPECT_EQ(joint->GetValue(i), joints[i]) << "vertex " << i;
      EXPECT_EQ(weight->GetValue(i), weights[i]) << "vertex " << i;
    }
    // The skinned vertex normals are the polydata's normals: the strip lies in z = 0 and turns
    // about z, so they stay along z.
    vtkDataArray* normals = strip->GetPointData()->GetNormals();
    ASSERT_NE(normals, nullptr);
    ASSERT_EQ(normals->GetNumberOfTuples(), 10);
    for (vtkIdType i = 0; i < 10; ++i)
      EXPECT_NEAR(std::abs(normals->GetComponent(i, 2)), 1, 1e-12) << "vertex " << i;
    double bounds[6];
    strip->GetBounds(bounds);
    minX.push_back(bounds[0]);
  }
  std::filesystem::remove(model);
  // The rest pose spans x in [-0.5, 0.5]; at 1 s the top row has swung to x = -1.
  EXPECT_NEAR(minX[0], -0.5, 1e-6);
  EXPECT_LT(minX[1], -0.5 - 0.1);
  EXPECT_NEAR(minX[2], -1, 1e-6);
}
#endif

} // namespace
