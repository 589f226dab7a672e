// SPDX-License-Identifier: BSD-3-Clause
// ictkTimeSeriesWriter from plain pipelines: the dynamic complex source (thesis 5.1, a disk moving
// towards a rectangle, Data/Models/icm/ch5_1_disk_rectangle.icm) and a space-time FRep model
// contoured by VTK's own filter (Data/Models/growing_ball.hf). The series is read back: as many
// frames as time steps chosen, their times in the .pvd, and each frame what its input gives at
// that time. A cancelled or failed write leaves an earlier series of the same name as it was.

#include "ictkDynamicComplexSource.h"
#include "ictkFRepSampler.h"
#include "ictkTimeSeriesWriter.h"

#include <vtkCallbackCommand.h>
#include <vtkCommand.h>
#include <vtkContourFilter.h>
#include <vtkDataObjectTreeIterator.h>
#include <vtkDataSet.h>
#include <vtkInformation.h>
#include <vtkInformationVector.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkPartitionedDataSetCollection.h>
#include <vtkPassInputTypeAlgorithm.h>
#include <vtkPolyData.h>
#include <vtkStreamingDemandDrivenPipeline.h>
#include <vtkXMLPartitionedDataSetCollectionReader.h>
#include <vtkXMLPolyDataReader.h>

#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace
{
namespace fs = std::filesystem;

const std::string Data = ICTK_DATA_DIR;

/// A fresh folder for one test.
fs::path WorkFolder(const std::string& name)
{
  const fs::path dir =
    fs::temp_directory_path() / ("ictk-series-" + name + "-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

/// The .pvd's data sets: (timestep, file) in order.
std::vector<std::pair<double, std::string>> ReadPvd(const fs::path& pvd)
{
  std::ifstream in(pvd);
  std::stringstream text;
  text << in.rdbuf();
  const std::string s = text.str();
  const std::regex dataset("<DataSet timestep=\"([^\"]+)\" file=\"([^\"]+)\"/>");
  std::vector<std::pair<double, std::string>> out;
  for (auto it = std::sregex_iterator(s.begin(), s.end(), dataset); it != std::sregex_iterator();
       ++it)
  {
    out.emplace_back(std::stod((*it)[1]), (*it)[2]);
  }
  return out;
}

/// Every file under a folder (its dot files too) with its bytes, to tell that nothing changed.
std::map<std::string, std::string> Snapshot(const fs::path& dir)
{
  std::map<std::string, std::string> files;
  for (const auto& entry : fs::recursive_directory_iterator(dir))
  {
    std::string bytes;
    if (entry.is_regular_file())
    {
      std::ifstream in(entry.path(), std::ios::binary);
      std::stringstream s;
      s << in.rdbuf();
      bytes = s.str();
    }
    files[fs::relative(entry.path(), dir).string()] = bytes;
  }
  return files;
}

vtkIdType PointsOf(vtkDataObject* data)
{
  if (auto* set = vtkDataSet::SafeDownCast(data))
  {
    return set->GetNumberOfPoints();
  }
  vtkIdType n = 0;
  if (auto* tree = vtkDataObjectTree::SafeDownCast(data))
  {
    vtkSmartPointer<vtkDataObjectTreeIterator> it;
    it.TakeReference(tree->NewTreeIterator());
    for (it->InitTraversal(); !it->IsDoneWithTraversal(); it->GoToNextItem())
    {
      n += PointsOf(it->GetCurrentDataObject());
    }
  }
  return n;
}

/// Collects a VTK object's error messages instead of printing them.
struct Errors
{
  std::vector<std::string> messages;
  vtkNew<vtkCallbackCommand> command;
  explicit Errors(vtkObject* object)
  {
    command->SetClientData(&messages);
    command->SetCallback(
      [](vtkObject*, unsigned long, void* clientData, void* callData)
      {
        static_cast<std::vector<std::string>*>(clientData)
          ->push_back(callData ? static_cast<const char*>(callData) : "");
      });
    object->AddObserver(vtkCommand::ErrorEvent, command);
  }
};

/// Passes its input through, and fails from a time on: an input that breaks part-way.
class FailFrom : public vtkPassInputTypeAlgorithm
{
public:
  static FailFrom* New();
  vtkTypeMacro(FailFrom, vtkPassInputTypeAlgorithm);
  double Time = 0;

protected:
  int RequestData(vtkInformation*, vtkInformationVector** in, vtkInformationVector* out) override
  {
    vtkInformation* info = out->GetInformationObject(0);
    if (info->Has(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP()) &&
      info->Get(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP()) >= this->Time)
    {
      vtkErrorMacro("broken from t = " << this->Time);
      return 0;
    }
    vtkDataObject::GetData(out)->ShallowCopy(vtkDataObject::GetData(in[0]));
    return 1;
  }
};
vtkStandardNewMacro(FailFrom);

/// growing_ball.hf sampled at 5 times in [0, 1] and contoured at f = 0 by VTK.
struct BallPipeline
{
  vtkNew<ictkFRepSampler> sampler;
  vtkNew<vtkContourFilter> contour;
  BallPipeline()
  {
    sampler->SetFileName((Data + "/Models/growing_ball.hf").c_str());
    sampler->SetModelBounds(-1, 2.5, -1.5, 1.5, -1.5, 1.5);
    sampler->SetSampleDimensions(24, 20, 20);
    sampler->SetTimeRange(0, 1);
    sampler->SetNumberOfTimeSteps(5);
    contour->SetInputConnection(sampler->GetOutputPort());
    contour->SetValue(0, 0.0);
  }
};

} // namespace

TEST(TimeSeriesWriter, WritesEveryFrameOfTheDynamicSource)
{
  const fs::path dir = WorkFolder("disk");
  vtkNew<ictkDynamicComplexSource> source;
  source->SetFileName((Data + "/Models/icm/ch5_1_disk_rectangle.icm").c_str());
  source->SetTimeStepSize(1.0);
  source->SetFeatureSize(0.1);
  vtkNew<ictkTimeSeriesWriter> writer;
  writer->SetInputConnection(source->GetOutputPort());
  writer->SetFileName((dir / "disk.pvd").string().c_str());
  ASSERT_EQ(writer->Write(), 1);

  // TIMESPAN(0, 10) at 1: 11 frames, t = 0, 1, ..., 10, in disk/.
  EXPECT_EQ(writer->GetNumberOfFramesWritten(), 11);
  const auto datasets = ReadPvd(dir / "disk.pvd");
  ASSERT_EQ(datasets.size(), 11u);
  for (std::size_t k = 0; k < datasets.size(); ++k)
  {
    EXPECT_EQ(datasets[k].first, static_cast<double>(k));
    // The frame number padded to four digits, as the writer names its files.
    std::ostringstream name;
    name << "disk/disk_" << std::setw(4) << std::setfill('0') << k << ".vtpc";
    EXPECT_EQ(datasets[k].second, name.str());
  }
  // Frame 5 (t = 5, instance K3: 7 cells) read back is what the source gives at t = 5.
  vtkNew<vtkXMLPartitionedDataSetCollectionReader> reader;
  reader->SetFileName((dir / datasets[5].second).string().c_str());
  reader->Update();
  vtkNew<ictkDynamicComplexSource> alone;
  alone->SetFileName(source->GetFileName());
  alone->SetTimeStepSize(1.0);
  alone->SetFeatureSize(0.1);
  ASSERT_EQ(alone->UpdateTimeStep(5.0), 1);
  auto* expected = vtkPartitionedDataSetCollection::SafeDownCast(alone->GetOutputDataObject(0));
  auto* read = vtkPartitionedDataSetCollection::SafeDownCast(reader->GetOutput());
  ASSERT_NE(read, nullptr);
  EXPECT_EQ(read->GetNumberOfPartitionedDataSets(), expected->GetNumberOfPartitionedDataSets());
  EXPECT_EQ(expected->GetNumberOfPartitionedDataSets(), 7u);
  EXPECT_GT(PointsOf(expected), 0);
  EXPECT_EQ(PointsOf(read), PointsOf(expected));
  // Only the series is left: no staging folder.
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir))
  {
    names.push_back(entry.path().filename().string());
  }
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{ "disk", "disk.pvd" }));
  fs::remove_all(dir);
}

TEST(TimeSeriesWriter, WritesAChosenRangeOfAPlainPipeline)
{
  const fs::path dir = WorkFolder("ball");
  BallPipeline ball;
  vtkNew<ictkTimeSeriesWriter> writer;
  writer->SetInputConnection(ball.contour->GetOutputPort());
  writer->SetFileName((dir / "ball.pvd").string().c_str());
  // Steps 1 and 3 of 0, 0.25, 0.5, 0.75, 1.
  writer->SetFirstTimeStep(1);
  writer->SetLastTimeStep(3);
  writer->SetTimeStepStride(2);
  ASSERT_EQ(writer->Write(), 1);
  EXPECT_EQ(writer->GetNumberOfFramesWritten(), 2);
  const auto datasets = ReadPvd(dir / "ball.pvd");
  ASSERT_EQ(datasets.size(), 2u);
  EXPECT_EQ(datasets[0].first, 0.25);
  EXPECT_EQ(datasets[1].first, 0.75);
  EXPECT_EQ(datasets[0].second, "ball/ball_0000.vtp");
  EXPECT_EQ(datasets[1].second, "ball/ball_0001.vtp");

  BallPipeline alone;
  alone.contour->UpdateTimeStep(0.75);
  const vtkIdType expected = alone.contour->GetOutput()->GetNumberOfPoints();
  EXPECT_GT(expected, 100);
  vtkNew<vtkXMLPolyDataReader> reader;
  reader->SetFileName((dir / datasets[1].second).string().c_str());
  reader->Update();
  EXPECT_EQ(reader->GetOutput()->GetNumberOfPoints(), expected);
  // The ball grows: fewer points at t = 0.25 than at 0.75.
  reader->SetFileName((dir / datasets[0].second).string().c_str());
  reader->Update();
  EXPECT_LT(reader->GetOutput()->GetNumberOfPoints(), expected);
  fs::remove_all(dir);
}

TEST(TimeSeriesWriter, ACancelledOrFailedWriteKeepsTheEarlierSeries)
{
  const fs::path dir = WorkFolder("keep");
  const std::string pvd = (dir / "ball.pvd").string();
  {
    BallPipeline ball;
    vtkNew<ictkTimeSeriesWriter> writer;
    writer->SetInputConnection(ball.contour->GetOutputPort());
    writer->SetFileName(pvd.c_str());
    ASSERT_EQ(writer->Write(), 1);
    ASSERT_EQ(writer->GetNumberOfFramesWritten(), 5);
  }
  const auto before = Snapshot(dir);
  ASSERT_EQ(before.count("ball.pvd"), 1u);
  ASSERT_EQ(before.count("ball/ball_0004.vtp"), 1u);

  // Cancelled after its first frame (AbortExecute, as ParaView's abort or Ctrl-C set it).
  {
    BallPipeline ball;
    vtkNew<ictkTimeSeriesWriter> writer;
    writer->SetInputConnection(ball.contour->GetOutputPort());
    writer->SetFileName(pvd.c_str());
    vtkNew<vtkCallbackCommand> abort;
    abort->SetCallback(
      [](vtkObject* caller, unsigned long, void*, void* callData)
      {
        if (*static_cast<double*>(callData) > 0)
        {
          static_cast<vtkAlgorithm*>(caller)->SetAbortExecute(1);
        }
      });
    writer->AddObserver(vtkCommand::ProgressEvent, abort);
    Errors errors(writer);
    EXPECT_EQ(writer->Write(), 0);
    EXPECT_EQ(writer->GetNumberOfFramesWritten(), 0);
    EXPECT_TRUE(errors.messages.empty()) << errors.messages.front();
  }
  EXPECT_EQ(Snapshot(dir), before);

  // The input fails at its fourth time step (t = 0.75), after three frames were written.
  {
    BallPipeline ball;
    vtkNew<FailFrom> broken;
    broken->Time = 0.75;
    broken->SetInputConnection(ball.contour->GetOutputPort());
    vtkNew<ictkTimeSeriesWriter> writer;
    writer->SetInputConnection(broken->GetOutputPort());
    writer->SetFileName(pvd.c_str());
    Errors quiet(broken);
    Errors quietExecutive(broken->GetExecutive());
    Errors errors(writer);
    EXPECT_EQ(writer->Write(), 0);
    ASSERT_EQ(errors.messages.size(), 1u);
    EXPECT_NE(errors.messages[0].find("cannot write frame 3 of '" + pvd + "': the input failed"),
      std::string::npos)
      << errors.messages[0];
    EXPECT_EQ(quiet.messages.size(), 1u);
  }
  EXPECT_EQ(Snapshot(dir), before);
  fs::remove_all(dir);
}
