// SPDX-License-Identifier: BSD-3-Clause
#include "ictkDynamicComplexSource.h"
#include "ictkRequest.h"

#include "Engine/CoherentDiscretizer.h"
#include "Engine/DynamicModel.h"
#include "FRep/Sampling.h"
#include "ictkComplexSource.h"

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
#include <functional>
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

/// t0, t0 + h, ... up to t1, with t1 itself as the last step when the spacing does not reach it
/// exactly (a step within h / 1000 of t1 is t1: the rounding of t0 + k h) - as `ictk run --time`.
std::vector<double> UniformSteps(double t0, double t1, double h)
{
  std::vector<double> steps;
  if (!(t1 > t0) || !(h > 0))
  {
    steps.push_back(t0);
    return steps;
  }
  const double count = std::floor((t1 - t0) / h + 1e-3);
  // A time step list is for people and pipelines to walk through; refuse absurd ones rather than
  // allocate them.
  const double limit = 1e6;
  const auto n = static_cast<long long>(std::min(count, limit));
  for (long long k = 0; k <= n; ++k)
  {
    steps.push_back(t0 + static_cast<double>(k) * h);
  }
  if (std::abs(t1 - steps.back()) < 1e-3 * h)
  {
    steps.back() = t1;
  }
  else if (count < limit)
  {
    steps.push_back(t1);
  }
  return steps;
}

} // namespace

struct ictkDynamicComplexSource::Internals
{
  std::unique_ptr<engine::DynamicModel> Model;
  std::unique_ptr<engine::CoherentDiscretizer> Mesher;
  /// The settings the model and the kept meshes were made under: when they change, both start
  /// again.
  std::string Configuration;
  std::vector<double> Steps; ///< advertised
  double EngineStep = 0;
  /// A run was cancelled between two advertised times: the next request starts again, so that
  /// what is computed does not depend on where the cancel fell.
  bool Interrupted = false;
  /// The engine stands at a time between the advertised ones: going on from there would give
  /// later frames one more stop than a run from the start, so the next later request restarts.
  bool OffGrid = false;
  /// The span of the progress range the engine's current advanceTo() fills.
  double ProgressLo = 0;
  double ProgressHi = 0.5;
  /// Reports the engine's progress into that span and passes AbortExecute back as a cancel.
  std::function<bool(double)> EngineProgress;

  /// The model (again) at its start.
  void Load(const std::string& file)
  {
    engine::RunOptions options;
    options.progress = this->EngineProgress;
    this->Model =
      std::make_unique<engine::DynamicModel>(engine::DynamicModel::load(file, std::move(options)));
    this->Model->start();
    this->Interrupted = false;
    this->OffGrid = false;
  }
};

ictkDynamicComplexSource::ictkDynamicComplexSource()
  : Internal(new Internals)
{
  this->SetNumberOfInputPorts(0);
  this->Internal->EngineProgress = [this](double fraction)
  {
    const Internals& s = *this->Internal;
    this->UpdateProgress(s.ProgressLo + (s.ProgressHi - s.ProgressLo) * fraction);
    return !this->GetAbortExecute();
  };
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
      vtkErrorMacro("no model: set FileName (a .icm file)");
      return 0;
    }
    std::ostringstream configuration;
    configuration << std::setprecision(17) << this->FileName << "|" << this->FeatureSize << "|"
                  << this->MaximumStep << "|" << this->TimeStepSize << "|" << this->Coherent << "|"
                  << this->NumberOfThreads;
    for (double t : this->TimeSteps)
    {
      configuration << "|" << t;
    }
    if (!in.Model || configuration.str() != in.Configuration)
    {
      in.Model.reset();
      in.Mesher.reset();
      in.Configuration.clear();
      in.Load(this->FileName);

      const auto [t0, t1] = in.Model->timeRange();
      if (!this->TimeSteps.empty())
      {
        in.Steps = this->TimeSteps;
      }
      else
      {
        const double h = this->TimeStepSize > 0 ? this->TimeStepSize : (t1 - t0) / 100;
        in.Steps = UniformSteps(t0, t1, h);
      }
      double spacing = 0;
      for (std::size_t i = 1; i < in.Steps.size(); ++i)
      {
        const double d = in.Steps[i] - in.Steps[i - 1];
        spacing = spacing > 0 ? std::min(spacing, d) : d;
      }
      in.EngineStep = this->MaximumStep > 0 ? this->MaximumStep
        : spacing > 0                       ? spacing
        : t1 > t0                           ? (t1 - t0) / 100
                                            : 1.0;

      engine::CoherenceOptions mesherOptions;
      mesherOptions.featureSize = this->FeatureSize;
      mesherOptions.coherent = this->Coherent != 0;
      mesherOptions.threads = this->NumberOfThreads;
      mesherOptions.progress = ictk::vtk::progressOf(this, 0.5, 1.0);
      in.Mesher = std::make_unique<engine::CoherentDiscretizer>(std::move(mesherOptions));
      if (!(this->FeatureSize > 0))
      {
        // Fixed from the model's start, whatever time is asked for first.
        in.Mesher->setFeatureSize(ictk::complex::defaultFeatureSize(in.Model->complex()));
      }
      in.Configuration = configuration.str();
    }
    vtkInformation* outInfo = outputVector->GetInformationObject(0);
    outInfo->Set(vtkStreamingDemandDrivenPipeline::TIME_STEPS(), in.Steps.data(),
      static_cast<int>(in.Steps.size()));
    const double range[2] = { in.Steps.front(), in.Steps.back() };
    outInfo->Set(vtkStreamingDemandDrivenPipeline::TIME_RANGE(), range, 2);
    outInfo->Set(CAN_HANDLE_PIECE_REQUEST(), 1);
    return 1;
  }
  catch (const engine::ModelError& e)
  {
    vtkErrorMacro("" << Describe(e));
  }
  catch (const std::exception& e)
  {
    vtkErrorMacro("" << e.what());
  }
  in.Model.reset();
  in.Mesher.reset();
  in.Configuration.clear();
  return 0;
}

int ictkDynamicComplexSource::RequestData(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  Internals& in = *this->Internal;
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  vtkPartitionedDataSetCollection* output = vtkPartitionedDataSetCollection::GetData(outputVector);
  if (!in.Model || in.Steps.empty())
  {
    vtkErrorMacro("no model loaded");
    return 0;
  }
  double t = in.Steps.front();
  if (outInfo->Has(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP()))
  {
    t = outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP());
  }
  t = std::clamp(t, in.Steps.front(), in.Steps.back());
  try
  {
    if (in.Interrupted || t < in.Model->time() || (in.OffGrid && t != in.Model->time()))
    {
      // The engine only runs forwards: start again from the model's start (the kept meshes go
      // too, since shape versions count within one run).
      in.Load(this->FileName);
      in.Mesher->reset();
    }
    // Every advertised time on the way is a stop, so that a frame is computed by the same steps
    // whichever frames were asked for before it.
    std::vector<double> stops;
    for (double s : in.Steps)
    {
      if (s > in.Model->time() && s < t)
      {
        stops.push_back(s);
      }
    }
    if (t > in.Model->time())
    {
      stops.push_back(t);
    }
    for (std::size_t i = 0; i < stops.size(); ++i)
    {
      in.ProgressLo = 0.5 * double(i) / double(stops.size());
      in.ProgressHi = 0.5 * double(i + 1) / double(stops.size());
      in.Model->advanceTo(stops[i], in.EngineStep);
    }
    this->UpdateProgress(0.5);
    in.OffGrid = !std::binary_search(in.Steps.begin(), in.Steps.end(), t);

    const std::vector<engine::CellState> cells = in.Model->cells();
    auto k = std::make_shared<const ictk::complex::Complex>(in.Model->complex());
    // Under MPI every rank runs the engine (cheap, deterministic) and discretises its share of
    // the cells (cell i to piece i mod N); every piece has the whole collection's structure.
    const int pieces =
      std::max(1, outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES()));
    const int piece = outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER());
    const std::vector<ictk::complex::CellId> all = k->cellIds();
    std::vector<ictk::complex::CellId> share;
    for (std::size_t i = 0; i < all.size(); ++i)
    {
      if (static_cast<int>(i % static_cast<std::size_t>(pieces)) == piece)
      {
        share.push_back(all[i]);
      }
    }
    ictk::complex::ComplexMesh mesh;
    if (pieces == 1)
    {
      mesh = in.Mesher->discretize(cells, *k);
    }
    else if (!share.empty())
    {
      mesh = in.Mesher->discretize(cells, *k, share);
    }
    const std::vector<unsigned int> layout(all.begin(), all.end());
    ictkComplexSource::Convert(*k, mesh, output, 0, &layout);
    ictkComplexSource::AttachComplex(output, k);

    this->InstanceName = in.Model->activeInstance();
    this->ModelTime = in.Model->time();
    AddFrameFields(output, this->InstanceName.c_str(), t);
    output->GetInformation()->Set(vtkDataObject::DATA_TIME_STEP(), t);

    const engine::CoherenceStats& last = in.Mesher->lastFrame();
    const engine::CoherenceStats& total = in.Mesher->total();
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
    // Cancelled in the engine's run or in the meshing: start again from the model's start next
    // time, so that no frame depends on where a cancellation fell.
    in.Interrupted = true;
    output->Initialize();
    return 1;
  }
  catch (const engine::ModelError& e)
  {
    vtkErrorMacro("" << Describe(e));
  }
  catch (const std::exception& e)
  {
    vtkErrorMacro("" << e.what());
  }
  // A failure may leave the engine between frames: start again next time.
  in.Interrupted = true;
  output->Initialize();
  return 0;
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
