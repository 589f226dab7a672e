// SPDX-License-Identifier: BSD-3-Clause
#include "ictkFRepSampler.h"
#include "ictkFRepModel.h"
#include "ictkRequest.h"

#include "FRep/Hypervolume.h"
#include "FRep/ModelRegistry.h"
#include "FRep/Sampling.h"
#include "Lang/ModelFile.h"

#include "vtkAOSDataArrayTemplate.h"
#include "vtkExtentTranslator.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationIntegerRequestKey.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkSmartPointer.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <new>
#include <stdexcept>
#include <string>

namespace frep = ictk::frep;

vtkStandardNewMacro(ictkFRepSampler);

namespace
{
/// Everything RequestInformation and RequestData both need.
struct Plan
{
  const frep::Hypervolume* hv = nullptr;
  frep::Grid grid;
  std::size_t bytesPerPoint = 0;
  bool timeDependent = false;
};
} // namespace

struct ictkFRepSampler::Internals
{
  ictkFRepModel Model;
  /// SetHypervolumeOfTime(): in use while Model.Explicit is its instance at InstanceTime
  /// (setting a name, file or hypervolume clears Explicit or this).
  std::function<frep::Hypervolume(double)> OfTime;
  double InstanceTime = 0;
  bool OfTimeInUse() const { return this->OfTime && this->Model.Explicit; }
  /// Model.Explicit made the instance at t.
  void Instantiate(double t)
  {
    if (this->InstanceTime != t)
    {
      this->Model.Explicit = std::make_unique<frep::Hypervolume>(this->OfTime(t));
      this->InstanceTime = t;
    }
  }

  bool MakePlan(ictkFRepSampler* self, Plan& plan, std::string& error);
};

namespace
{
bool BoundsAreSet(const double b[6])
{
  return b[0] <= b[1] && b[2] <= b[3] && b[4] <= b[5];
}

template <typename T>
vtkSmartPointer<vtkAOSDataArrayTemplate<T>> NewArray(
  const std::string& name, int components, std::int64_t tuples)
{
  auto array = vtkSmartPointer<vtkAOSDataArrayTemplate<T>>::New();
  array->SetName(name.c_str());
  array->SetNumberOfComponents(components);
  if (!array->Allocate(tuples * components))
  {
    throw std::bad_alloc();
  }
  array->SetNumberOfTuples(tuples);
  return array;
}
} // namespace

ictkFRepSampler::ictkFRepSampler()
  : Internal(new Internals)
{
  this->SetNumberOfInputPorts(0);
  this->SetNumberOfOutputPorts(1);
}

ictkFRepSampler::~ictkFRepSampler()
{
  delete[] this->ModelName;
  this->ModelName = nullptr;
  delete[] this->FileName;
  this->FileName = nullptr;
}

namespace
{
std::string LowerExtension(const std::string& path)
{
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext)
  {
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  return ext;
}
} // namespace

void ictkFRepSampler::SetFileName(const char* name)
{
  if (this->Internal->Model.SelectFileName(this->ModelName, this->FileName, name))
  {
    this->Modified();
  }
}

int ictkFRepSampler::CanReadFile(const char* name)
{
  if (!name || !ictk::lang::isModelFile(name))
  {
    return 0;
  }
  if (LowerExtension(name) != ".xml")
  {
    return 1;
  }
  // An XML file is an FRep model when its root element is <frep>: skip the declaration,
  // comments and whitespace before it.
  std::ifstream in(name, std::ios::binary);
  std::string head(4096, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  std::size_t at = 0;
  while (true)
  {
    at = head.find('<', at);
    if (at == std::string::npos || at + 1 >= head.size())
    {
      return 0;
    }
    if (head[at + 1] == '?' || head[at + 1] == '!')
    {
      ++at;
      continue;
    }
    return head.compare(at + 1, 4, "frep") == 0 ? 1 : 0;
  }
}

void ictkFRepSampler::SetModelName(const char* name)
{
  if (this->Internal->Model.SelectModelName(this->ModelName, this->FileName, name))
  {
    this->Modified();
  }
}

void ictkFRepSampler::SetHypervolume(const frep::Hypervolume& hv)
{
  this->Internal->Model.Explicit = std::make_unique<frep::Hypervolume>(hv);
  this->Internal->OfTime = nullptr;
  this->Modified();
}

void ictkFRepSampler::SetHypervolumeOfTime(std::function<frep::Hypervolume(double)> model)
{
  Internals& in = *this->Internal;
  in.OfTime = std::move(model);
  in.Model.Explicit = std::make_unique<frep::Hypervolume>(in.OfTime(this->Time));
  in.InstanceTime = this->Time;
  this->Modified();
}

void ictkFRepSampler::SetParameters(const std::vector<double>& parameters)
{
  if (parameters != this->Internal->Model.Parameters)
  {
    this->Internal->Model.Parameters = parameters;
    // A HyperFun file is specialised to its parameter values when read: read it again.
    this->Internal->Model.ReadPath.clear();
    this->Modified();
  }
}

void ictkFRepSampler::AddParameter(double value)
{
  std::vector<double> parameters = this->Internal->Model.Parameters;
  parameters.push_back(value);
  this->SetParameters(parameters);
}

void ictkFRepSampler::ClearParameters()
{
  this->SetParameters({});
}

const std::vector<double>& ictkFRepSampler::GetParameters() const
{
  return this->Internal->Model.Parameters;
}

void ictkFRepSampler::SetTimeSteps(const double* times, int count)
{
  std::vector<double> steps(times, times + std::max(count, 0));
  for (std::size_t i = 0; i < steps.size(); ++i)
  {
    if (!std::isfinite(steps[i]) || (i > 0 && !(steps[i] > steps[i - 1])))
    {
      vtkErrorMacro(<< "SetTimeSteps: the times must be finite and increasing (time " << i << ")");
      return;
    }
  }
  if (steps != this->TimeSteps)
  {
    this->TimeSteps = std::move(steps);
    this->Modified();
  }
}

bool ictkFRepSampler::IsTimeDependent()
{
  Plan plan;
  std::string error;
  return this->Internal->MakePlan(this, plan, error) && plan.timeDependent;
}

int ictkFRepSampler::GetBytesPerPoint()
{
  Plan plan;
  std::string error;
  return this->Internal->MakePlan(this, plan, error) ? static_cast<int>(plan.bytesPerPoint) : 0;
}

bool ictkFRepSampler::Internals::MakePlan(ictkFRepSampler* self, Plan& plan, std::string& error)
{
  Internals& internal = *this;
  plan.hv = internal.Model.Resolve(self->GetModelName(), self->GetFileName(), error);
  if (!plan.hv)
  {
    return false;
  }
  const double* b = self->GetModelBounds();
  std::array<double, 3> lo, hi;
  if (BoundsAreSet(b))
  {
    lo = { b[0], b[2], b[4] };
    hi = { b[1], b[3], b[5] };
  }
  else if (!internal.Model.Explicit)
  {
    lo = internal.Model.ResolvedLo;
    hi = internal.Model.ResolvedHi;
  }
  else
  {
    error = "ModelBounds must be set (xmin <= xmax, ...) to sample a hypervolume given with "
            "SetHypervolume()";
    return false;
  }
  for (int a = 0; a < 3; ++a)
  {
    if (!std::isfinite(lo[a]) || !std::isfinite(hi[a]))
    {
      error = "ModelBounds must be finite";
      return false;
    }
  }
  const int* dims = self->GetSampleDimensions();
  std::array<std::int64_t, 3> resolution;
  for (int a = 0; a < 3; ++a)
  {
    // A flat axis (a 2D model, or a slice) has a single sample: more would all coincide.
    resolution[a] = hi[a] > lo[a] ? dims[a] : std::min(dims[a], 1);
  }
  plan.grid = frep::gridOverBox(lo, hi, resolution, self->GetTime());
  plan.timeDependent = internal.OfTimeInUse() ||
    (frep::domainAxes(plan.hv->geometry().domain()) & (1u << static_cast<int>(frep::Axis::T))) != 0;

  const int type = self->GetOutputScalarType();
  if (type != VTK_FLOAT && type != VTK_DOUBLE)
  {
    error = "OutputScalarType must be VTK_FLOAT or VTK_DOUBLE";
    return false;
  }
  const std::size_t valueSize = type == VTK_FLOAT ? sizeof(float) : sizeof(double);
  std::size_t values = 1;
  if (self->GetComputeAttributes())
  {
    values += plan.hv->attributeComponentCount();
  }
  plan.bytesPerPoint = values * valueSize;
  try
  {
    frep::checkGrid(plan.grid, plan.bytesPerPoint);
  }
  catch (const std::exception& e)
  {
    error = e.what();
    return false;
  }
  return true;
}

int ictkFRepSampler::RequestInformation(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  Plan plan;
  std::string error;
  if (!this->Internal->MakePlan(this, plan, error))
  {
    vtkErrorMacro(<< error);
    return 0;
  }
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  const auto& d = plan.grid.dimensions;
  const int extent[6] = { 0, static_cast<int>(d[0] - 1), 0, static_cast<int>(d[1] - 1), 0,
    static_cast<int>(d[2] - 1) };
  outInfo->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), extent, 6);
  outInfo->Set(vtkDataObject::SPACING(), plan.grid.spacing.data(), 3);
  outInfo->Set(vtkDataObject::ORIGIN(), plan.grid.origin.data(), 3);
  vtkDataObject::SetPointDataActiveScalarInfo(outInfo, this->OutputScalarType, 1);
  outInfo->Set(vtkAlgorithm::CAN_PRODUCE_SUB_EXTENT(), 1);
  outInfo->Remove(vtkStreamingDemandDrivenPipeline::TIME_STEPS());
  outInfo->Remove(vtkStreamingDemandDrivenPipeline::TIME_RANGE());
  if (plan.timeDependent && !this->TimeSteps.empty())
  {
    const double range[2] = { this->TimeSteps.front(), this->TimeSteps.back() };
    outInfo->Set(vtkStreamingDemandDrivenPipeline::TIME_RANGE(), range, 2);
    outInfo->Set(vtkStreamingDemandDrivenPipeline::TIME_STEPS(), this->TimeSteps.data(),
      static_cast<int>(this->TimeSteps.size()));
  }
  else if (plan.timeDependent)
  {
    const double t0 = this->TimeRange[0], t1 = this->TimeRange[1];
    if (!std::isfinite(t0) || !std::isfinite(t1) || t1 < t0)
    {
      vtkErrorMacro(<< "TimeRange must be finite with t0 <= t1, got " << t0 << ", " << t1);
      return 0;
    }
    outInfo->Set(vtkStreamingDemandDrivenPipeline::TIME_RANGE(), this->TimeRange, 2);
    const int n = this->NumberOfTimeSteps;
    if (n > 0)
    {
      std::vector<double> steps(static_cast<std::size_t>(n));
      for (int i = 0; i < n; ++i)
      {
        steps[static_cast<std::size_t>(i)] =
          n == 1 ? t0 : (i == n - 1 ? t1 : t0 + (t1 - t0) * i / static_cast<double>(n - 1));
      }
      outInfo->Set(vtkStreamingDemandDrivenPipeline::TIME_STEPS(), steps.data(), n);
    }
  }
  return 1;
}

namespace
{
/// The piece of `whole` inside `extent` (VTK's inclusive point extent).
frep::Grid PieceOf(const frep::Grid& whole, const int extent[6])
{
  frep::Grid piece = whole;
  for (int a = 0; a < 3; ++a)
  {
    piece.first[a] = extent[2 * a];
    piece.dimensions[a] = extent[2 * a + 1] - extent[2 * a] + 1;
  }
  return piece;
}

template <typename T>
void Sample(ictkFRepSampler* self, const Plan& plan, const int extent[6],
  const std::vector<double>& parameters, int threads, vtkImageData* output)
{
  const frep::Grid grid = PieceOf(plan.grid, extent);
  const std::int64_t n = grid.pointCount();
  // Without attributes, sample the geometry alone (a hypervolume with no attribute).
  const frep::Hypervolume hv = self->GetComputeAttributes()
    ? *plan.hv
    : frep::Hypervolume(plan.hv->geometry(), plan.hv->threshold());

  auto f = NewArray<T>("f", 1, n);
  std::vector<vtkSmartPointer<vtkAOSDataArrayTemplate<T>>> attributeArrays;
  std::vector<T*> attributePointers;
  for (const frep::Attribute& a : hv.attributes())
  {
    // "f" is the field; an attribute of that name must not hide it.
    const std::string name = a.name == "f" ? "attribute_f" : a.name;
    attributeArrays.push_back(NewArray<T>(name, static_cast<int>(a.components.size()), n));
    attributePointers.push_back(attributeArrays.back()->GetPointer(0));
  }

  frep::SampleOptions options;
  options.threads = threads;
  options.parameters = parameters;
  options.progress = ictk::vtk::progressOf(self);
  if (self->GetAbortExecute())
  {
    throw frep::Cancelled();
  }
  // Geometry and attributes in one pass over one tape (shared sub-expressions computed once).
  frep::sampleGrid(hv, grid, f->GetPointer(0), attributePointers, options);

  output->SetExtent(const_cast<int*>(extent));
  output->SetOrigin(plan.grid.origin.data());
  output->SetSpacing(plan.grid.spacing.data());
  vtkPointData* pd = output->GetPointData();
  pd->Initialize();
  pd->SetScalars(f);
  for (auto& array : attributeArrays)
  {
    pd->AddArray(array);
  }
}
} // namespace

int ictkFRepSampler::RequestData(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  vtkImageData* output = vtkImageData::GetData(outputVector, 0);
  if (!output)
  {
    vtkErrorMacro(<< "the output is not a vtkImageData");
    return 0;
  }
  output->Initialize();
  Plan plan;
  std::string error;
  if (!this->Internal->MakePlan(this, plan, error))
  {
    vtkErrorMacro(<< error);
    return 0;
  }
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  using SDDP = vtkStreamingDemandDrivenPipeline;
  if (plan.timeDependent && outInfo->Has(SDDP::UPDATE_TIME_STEP()))
  {
    plan.grid.time = outInfo->Get(SDDP::UPDATE_TIME_STEP());
    if (!std::isfinite(plan.grid.time))
    {
      vtkErrorMacro(<< "the requested time is not a finite number");
      return 0;
    }
  }
  if (this->Internal->OfTimeInUse())
  {
    this->Internal->Instantiate(plan.grid.time);
    plan.hv = this->Internal->Model.Explicit.get();
  }
  if (plan.timeDependent)
  {
    output->GetInformation()->Set(vtkDataObject::DATA_TIME_STEP(), plan.grid.time);
  }
  else
  {
    output->GetInformation()->Remove(vtkDataObject::DATA_TIME_STEP());
  }
  // The piece the pipeline asks for (the whole grid when it asks for nothing in particular).
  const auto& d = plan.grid.dimensions;
  const int whole[6] = { 0, static_cast<int>(d[0] - 1), 0, static_cast<int>(d[1] - 1), 0,
    static_cast<int>(d[2] - 1) };
  int extent[6];
  std::copy(whole, whole + 6, extent);
  if (outInfo->Has(SDDP::UPDATE_EXTENT()))
  {
    outInfo->Get(SDDP::UPDATE_EXTENT(), extent);
    for (int a = 0; a < 3; ++a)
    {
      extent[2 * a] = std::max(extent[2 * a], whole[2 * a]);
      extent[2 * a + 1] = std::min(extent[2 * a + 1], whole[2 * a + 1]);
    }
  }
  if (extent[0] > extent[1] || extent[2] > extent[3] || extent[4] > extent[5])
  {
    return 1; // an empty piece (more ranks than slabs): nothing to sample
  }
  this->UpdateProgress(0.0);
  const int ok = ictk::vtk::runRequest(this, output,
    [&]
    {
      try
      {
        if (this->OutputScalarType == VTK_FLOAT)
        {
          Sample<float>(
            this, plan, extent, this->Internal->Model.Parameters, this->NumberOfThreads, output);
        }
        else
        {
          Sample<double>(
            this, plan, extent, this->Internal->Model.Parameters, this->NumberOfThreads, output);
        }
      }
      catch (const std::bad_alloc&)
      {
        throw std::runtime_error("out of memory sampling " +
          std::to_string(plan.grid.dimensions[0]) + " x " +
          std::to_string(plan.grid.dimensions[1]) + " x " +
          std::to_string(plan.grid.dimensions[2]) + " points");
      }
      // Ghost levels: the points beyond the piece proper are marked, so that downstream filters
      // and ParaView count every point and cell once over all pieces.
      const int ghostLevels = outInfo->Get(SDDP::UPDATE_NUMBER_OF_GHOST_LEVELS());
      const int pieces = outInfo->Get(SDDP::UPDATE_NUMBER_OF_PIECES());
      if (ghostLevels > 0 && pieces > 1)
      {
        int proper[6];
        vtkNew<vtkExtentTranslator> translator;
        const int splitMode = outInfo->Has(vtkExtentTranslator::UPDATE_SPLIT_MODE())
          ? outInfo->Get(vtkExtentTranslator::UPDATE_SPLIT_MODE())
          : vtkExtentTranslator::BLOCK_MODE;
        translator->PieceToExtentThreadSafe(outInfo->Get(SDDP::UPDATE_PIECE_NUMBER()), pieces, 0,
          const_cast<int*>(whole), proper, splitMode, 0);
        output->GenerateGhostArray(proper);
      }
      return 1;
    });
  if (!ok || output->GetNumberOfPoints() == 0)
  {
    return ok;
  }
  this->UpdateProgress(1.0);
  return 1;
}

void ictkFRepSampler::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "ModelName: " << (this->ModelName ? this->ModelName : "(none)") << "\n";
  os << indent << "FileName: " << (this->FileName ? this->FileName : "(none)") << "\n";
  os << indent << "Hypervolume: " << (this->Internal->Model.Explicit ? "set" : "(none)") << "\n";
  os << indent << "SampleDimensions: (" << this->SampleDimensions[0] << ", "
     << this->SampleDimensions[1] << ", " << this->SampleDimensions[2] << ")\n";
  os << indent << "ModelBounds: (" << this->ModelBounds[0] << ", " << this->ModelBounds[1] << ", "
     << this->ModelBounds[2] << ", " << this->ModelBounds[3] << ", " << this->ModelBounds[4] << ", "
     << this->ModelBounds[5] << ")" << (BoundsAreSet(this->ModelBounds) ? "" : " (model's own)")
     << "\n";
  os << indent << "Time: " << this->Time << "\n";
  os << indent << "TimeRange: (" << this->TimeRange[0] << ", " << this->TimeRange[1] << ")\n";
  os << indent << "NumberOfTimeSteps: " << this->NumberOfTimeSteps << "\n";
  os << indent << "OutputScalarType: "
     << (this->OutputScalarType == VTK_DOUBLE
            ? "double"
            : (this->OutputScalarType == VTK_FLOAT ? "float" : "invalid"))
     << "\n";
  os << indent << "ComputeAttributes: " << (this->ComputeAttributes ? "on" : "off") << "\n";
  os << indent << "NumberOfThreads: " << this->NumberOfThreads << "\n";
  os << indent << "Parameters:";
  for (double p : this->Internal->Model.Parameters)
  {
    os << " " << p;
  }
  os << "\n";
}
