// SPDX-License-Identifier: BSD-3-Clause
#include "ictkDynamicComplexSource.h"
#include "ictkRequest.h"

#include "Engine/FrameSequence.h"
#include "ictkComplexSource.h"
#include "ictkComplexToVTK.h"

#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPartitionedDataSet.h"
#include "vtkPartitionedDataSetCollection.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkStringArray.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

vtkStandardNewMacro(ictkDynamicComplexSource);

namespace
{
namespace engine = ictk::engine;

/// A model error in the front ends' form, "file:line:col: error: message".
std::string Describe(const engine::ModelError& e)
{
  std::ostringstream os;
  os << e.file << ":" << e.pos.line << ":" << e.pos.column << ": error: " << e.message;
  return os.str();
}

} // namespace

struct ictkDynamicComplexSource::Internals
{
  std::unique_ptr<engine::FrameSequence> Frames;
  /// The settings the frames were made under: when they change, the model starts again.
  std::string Configuration;
  /// The records of the last frame output.
  std::vector<engine::FrameRecord> Records;
  std::exception_ptr LastError;
};

ictkDynamicComplexSource::ictkDynamicComplexSource()
  : Internal(new Internals)
{
  this->SetNumberOfInputPorts(0);
}

ictkDynamicComplexSource::~ictkDynamicComplexSource() = default;

void ictkDynamicComplexSource::SetTimeSteps(const double* times, int count)
{
  std::vector<double> steps(times, times + std::max(count, 0));
  steps.erase(
    std::remove_if(steps.begin(), steps.end(), [](double t) { return !std::isfinite(t); }),
    steps.end());
  std::sort(steps.begin(), steps.end());
  steps.erase(std::unique(steps.begin(), steps.end()), steps.end());
  if (steps != this->TimeSteps)
  {
    this->TimeSteps = std::move(steps);
    this->Modified();
  }
}

void ictkDynamicComplexSource::AddTimeStep(double time)
{
  std::vector<double> steps = this->TimeSteps;
  steps.push_back(time);
  this->SetTimeSteps(steps.data(), static_cast<int>(steps.size()));
}

void ictkDynamicComplexSource::RemoveAllTimeSteps()
{
  if (!this->TimeSteps.empty())
  {
    this->TimeSteps.clear();
    this->Modified();
  }
}

int ictkDynamicComplexSource::RequestInformation(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  Internals& in = *this->Internal;
  try
  {
    if (this->FileName.empty())
    {
      throw std::invalid_argument("no model: set FileName (a .icm file)");
    }
    std::ostringstream configuration;
    configuration << std::setprecision(17) << this->FileName << "|" << this->FeatureSize << "|"
                  << this->MaximumStep << "|" << this->TimeStepSize << "|" << this->Coherent << "|"
                  << this->NumberOfThreads;
    for (double t : this->TimeSteps)
    {
      configuration << "|" << t;
    }
    if (!in.Frames || configuration.str() != in.Configuration)
    {
      in.Frames.reset();
      in.Configuration.clear();
      engine::FrameSequenceOptions options;
      options.times = this->TimeSteps;
      options.timeStep = this->TimeStepSize;
      options.maxStep = this->MaximumStep;
      options.discretization.featureSize = this->FeatureSize;
      options.discretization.coherent = this->Coherent != 0;
      options.discretization.threads = this->NumberOfThreads;
      options.progress = ictk::vtk::progressOf(this);
      in.Frames = std::make_unique<engine::FrameSequence>(this->FileName, std::move(options));
      in.Configuration = configuration.str();
    }
    const std::vector<double>& steps = in.Frames->times();
    vtkInformation* outInfo = outputVector->GetInformationObject(0);
    outInfo->Set(
      vtkStreamingDemandDrivenPipeline::TIME_STEPS(), steps.data(), static_cast<int>(steps.size()));
    const double range[2] = { steps.front(), steps.back() };
    outInfo->Set(vtkStreamingDemandDrivenPipeline::TIME_RANGE(), range, 2);
    outInfo->Set(CAN_HANDLE_PIECE_REQUEST(), 1);
    in.LastError = nullptr;
    return 1;
  }
  catch (const std::exception& e)
  {
    in.LastError = std::current_exception();
    this->ReportError(e);
  }
  in.Frames.reset();
  in.Configuration.clear();
  return 0;
}

void ictkDynamicComplexSource::ReportError(const std::exception& e)
{
  if (const auto* m = dynamic_cast<const engine::ModelError*>(&e))
  {
    vtkErrorMacro("" << Describe(*m));
  }
  else
  {
    vtkErrorMacro("" << e.what());
  }
}

int ictkDynamicComplexSource::RequestData(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  Internals& in = *this->Internal;
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  vtkPartitionedDataSetCollection* output = vtkPartitionedDataSetCollection::GetData(outputVector);
  in.Records.clear();
  if (!in.Frames)
  {
    vtkErrorMacro("no model loaded");
    return 0;
  }
  const std::vector<double>& steps = in.Frames->times();
  double t = steps.front();
  if (outInfo->Has(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP()))
  {
    t = outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP());
  }
  try
  {
    // Under MPI every rank runs the engine (cheap, deterministic) and discretises its share of
    // the cells; every piece has the whole collection's structure.
    engine::CellShare share;
    share.pieces =
      std::max(1, outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES()));
    share.piece = outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER());
    engine::Frame frame = in.Frames->at(t, share);
    in.LastError = nullptr;
    const std::vector<ictk::complex::CellId> all = frame.complex->cellIds();
    ictk::vtk::complexToVTK(*frame.complex, frame.mesh, output, 0, &all);
    ictkComplexSource::AttachComplex(output, frame.complex);

    this->InstanceName = frame.instance;
    this->ModelTime = in.Frames->model().time();
    in.Records = std::move(frame.records);
    AddFrameFields(output, this->InstanceName.c_str(), frame.time);
    output->GetInformation()->Set(vtkDataObject::DATA_TIME_STEP(), frame.time);

    const engine::CoherenceStats& last = in.Frames->discretizer().lastFrame();
    const engine::CoherenceStats& total = in.Frames->discretizer().total();
    this->Stats[0] = static_cast<int>(last.computed);
    this->Stats[1] = static_cast<int>(last.moved);
    this->Stats[2] = static_cast<int>(last.reused);
    this->TotalStats[0] = static_cast<int>(total.computed);
    this->TotalStats[1] = static_cast<int>(total.moved);
    this->TotalStats[2] = static_cast<int>(total.reused);
    this->UpdateProgress(1.0);
    return 1;
  }
  catch (const ictk::Cancelled&)
  {
    // The sequence starts the model again next time, so that no frame depends on where a
    // cancellation fell.
    output->Initialize();
    return 1;
  }
  catch (const std::exception& e)
  {
    in.LastError = std::current_exception();
    this->ReportError(e);
  }
  output->Initialize();
  return 0;
}

double ictkDynamicComplexSource::GetStartTime() const
{
  return this->Internal->Frames ? this->Internal->Frames->startTime() : 0.0;
}

double ictkDynamicComplexSource::GetFeatureSizeInUse() const
{
  return this->Internal->Frames ? this->Internal->Frames->discretizer().featureSize() : 0.0;
}

const std::vector<ictk::engine::FrameRecord>& ictkDynamicComplexSource::GetFrameRecords() const
{
  return this->Internal->Records;
}

std::exception_ptr ictkDynamicComplexSource::GetLastError() const
{
  return this->Internal->LastError;
}

void ictkDynamicComplexSource::AddFrameFields(
  vtkPartitionedDataSetCollection* frame, const char* instance, double time)
{
  if (!frame)
  {
    return;
  }
  auto stamp = [&](vtkFieldData* fd)
  {
    vtkNew<vtkStringArray> name;
    name->SetName("Instance");
    name->InsertNextValue(instance ? instance : "");
    fd->AddArray(name);
    vtkNew<vtkDoubleArray> t;
    t->SetName("Time");
    t->InsertNextValue(time);
    fd->AddArray(t);
  };
  stamp(frame->GetFieldData());
  for (unsigned int i = 0; i < frame->GetNumberOfPartitionedDataSets(); ++i)
  {
    vtkPartitionedDataSet* part = frame->GetPartitionedDataSet(i);
    for (unsigned int j = 0; part && j < part->GetNumberOfPartitions(); ++j)
    {
      if (vtkDataObject* leaf = part->GetPartitionAsDataObject(j))
      {
        stamp(leaf->GetFieldData());
      }
    }
  }
}

void ictkDynamicComplexSource::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FileName: " << this->FileName << "\n";
  os << indent << "FeatureSize: " << this->FeatureSize << "\n";
  os << indent << "MaximumStep: " << this->MaximumStep << "\n";
  os << indent << "TimeStepSize: " << this->TimeStepSize << "\n";
  os << indent << "TimeSteps: " << this->TimeSteps.size() << "\n";
  os << indent << "Coherent: " << this->Coherent << "\n";
  os << indent << "NumberOfThreads: " << this->NumberOfThreads << "\n";
  os << indent << "InstanceName: " << this->InstanceName << "\n";
}
