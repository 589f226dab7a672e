// SPDX-License-Identifier: BSD-3-Clause
#include "ictkFRepSampler.h"

#include "FRep/Hypervolume.h"
#include "FRep/ModelRegistry.h"
#include "FRep/Sampling.h"

#include "vtkAOSDataArrayTemplate.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkSmartPointer.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
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
};
} // namespace

struct ictkFRepSampler::Internals
{
  /// Set by SetHypervolume(); wins over ModelName while set.
  std::unique_ptr<frep::Hypervolume> Explicit;
  /// The registered model last resolved from ModelName (built once per name, since building a
  /// large model costs more than looking it up).
  std::string ResolvedName;
  std::unique_ptr<frep::Hypervolume> Resolved;
  std::array<double, 3> ResolvedLo{ 0, 0, 0 };
  std::array<double, 3> ResolvedHi{ 0, 0, 0 };
  std::vector<double> Parameters;

  /// The hypervolume to sample, or null with `error` set.
  const frep::Hypervolume* Resolve(const char* modelName, std::string& error)
  {
    if (this->Explicit)
    {
      return this->Explicit.get();
    }
    if (!modelName || !*modelName)
    {
      error = "no model: set ModelName or call SetHypervolume()";
      return nullptr;
    }
    if (this->Resolved && this->ResolvedName == modelName)
    {
      return this->Resolved.get();
    }
    this->Resolved.reset();
    try
    {
      const frep::ModelInfo& info = frep::findModel(modelName);
      this->Resolved = std::make_unique<frep::Hypervolume>(info.build());
      this->ResolvedName = modelName;
      this->ResolvedLo = info.boundsLo;
      this->ResolvedHi = info.boundsHi;
      return this->Resolved.get();
    }
    catch (const std::exception& e)
    {
      error = e.what();
      return nullptr;
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
}

void ictkFRepSampler::SetModelName(const char* name)
{
  const bool same = (!name && !this->ModelName) ||
    (name && this->ModelName && std::strcmp(name, this->ModelName) == 0);
  if (same && !this->Internal->Explicit)
  {
    return;
  }
  delete[] this->ModelName;
  this->ModelName = nullptr;
  if (name)
  {
    this->ModelName = new char[std::strlen(name) + 1];
    std::strcpy(this->ModelName, name);
  }
  this->Internal->Explicit.reset();
  this->Modified();
}

void ictkFRepSampler::SetHypervolume(const frep::Hypervolume& hv)
{
  this->Internal->Explicit = std::make_unique<frep::Hypervolume>(hv);
  this->Modified();
}

void ictkFRepSampler::SetParameters(const std::vector<double>& parameters)
{
  if (parameters != this->Internal->Parameters)
  {
    this->Internal->Parameters = parameters;
    this->Modified();
  }
}

const std::vector<double>& ictkFRepSampler::GetParameters() const
{
  return this->Internal->Parameters;
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
  plan.hv = internal.Resolve(self->GetModelName(), error);
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
  else if (!internal.Explicit)
  {
    lo = internal.ResolvedLo;
    hi = internal.ResolvedHi;
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
  return 1;
}

namespace
{
template <typename T>
void Sample(ictkFRepSampler* self, const Plan& plan, const std::vector<double>& parameters,
  int threads, vtkImageData* output)
{
  const std::int64_t n = plan.grid.pointCount();
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
  options.progress = [self](double fraction)
  {
    self->UpdateProgress(fraction);
    return !self->GetAbortExecute();
  };
  if (self->GetAbortExecute())
  {
    throw frep::Cancelled();
  }
  // Geometry and attributes in one pass over one tape (shared sub-expressions computed once).
  frep::sampleGrid(hv, plan.grid, f->GetPointer(0), attributePointers, options);

  const auto& d = plan.grid.dimensions;
  output->SetExtent(
    0, static_cast<int>(d[0] - 1), 0, static_cast<int>(d[1] - 1), 0, static_cast<int>(d[2] - 1));
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
  this->UpdateProgress(0.0);
  try
  {
    if (this->OutputScalarType == VTK_FLOAT)
    {
      Sample<float>(this, plan, this->Internal->Parameters, this->NumberOfThreads, output);
    }
    else
    {
      Sample<double>(this, plan, this->Internal->Parameters, this->NumberOfThreads, output);
    }
  }
  catch (const frep::Cancelled&)
  {
    // Aborting is a request, not a failure: leave an empty output, as VTK algorithms do.
    output->Initialize();
    return 1;
  }
  catch (const std::bad_alloc&)
  {
    output->Initialize();
    vtkErrorMacro(<< "out of memory sampling " << plan.grid.dimensions[0] << " x "
                  << plan.grid.dimensions[1] << " x " << plan.grid.dimensions[2] << " points");
    return 0;
  }
  catch (const std::exception& e)
  {
    output->Initialize();
    vtkErrorMacro(<< e.what());
    return 0;
  }
  this->UpdateProgress(1.0);
  return 1;
}

void ictkFRepSampler::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "ModelName: " << (this->ModelName ? this->ModelName : "(none)") << "\n";
  os << indent << "Hypervolume: " << (this->Internal->Explicit ? "set" : "(none)") << "\n";
  os << indent << "SampleDimensions: (" << this->SampleDimensions[0] << ", "
     << this->SampleDimensions[1] << ", " << this->SampleDimensions[2] << ")\n";
  os << indent << "ModelBounds: (" << this->ModelBounds[0] << ", " << this->ModelBounds[1] << ", "
     << this->ModelBounds[2] << ", " << this->ModelBounds[3] << ", " << this->ModelBounds[4] << ", "
     << this->ModelBounds[5] << ")" << (BoundsAreSet(this->ModelBounds) ? "" : " (model's own)")
     << "\n";
  os << indent << "Time: " << this->Time << "\n";
  os << indent << "OutputScalarType: "
     << (this->OutputScalarType == VTK_DOUBLE
            ? "double"
            : (this->OutputScalarType == VTK_FLOAT ? "float" : "invalid"))
     << "\n";
  os << indent << "ComputeAttributes: " << (this->ComputeAttributes ? "on" : "off") << "\n";
  os << indent << "NumberOfThreads: " << this->NumberOfThreads << "\n";
  os << indent << "Parameters:";
  for (double p : this->Internal->Parameters)
  {
    os << " " << p;
  }
  os << "\n";
}
