// SPDX-License-Identifier: BSD-3-Clause
#include "ictkFRepImplicitFunction.h"

#include "FRep/Evaluators.h"
#include "FRep/Hypervolume.h"
#include "FRep/ModelRegistry.h"

#include "vtkObjectFactory.h"

#include <tbb/enumerable_thread_specific.h>

#include <cstring>
#include <optional>
#include <stdexcept>
#include <string>

namespace frep = ictk::frep;

vtkStandardNewMacro(ictkFRepImplicitFunction);

namespace
{
/// One thread's evaluators. Built on the thread's first call, since most threads of a VTK filter
/// only ever need the value, a few also the gradient.
struct ThreadEvaluators
{
  std::optional<frep::PointEvaluator> Value;
  std::optional<frep::GradientEvaluator> Gradient;
};
} // namespace

struct ictkFRepImplicitFunction::Internals
{
  std::unique_ptr<frep::Hypervolume> Explicit;
  std::vector<double> Parameters;
  /// The compiled geometry (immutable, shared by every thread); null when there is no model.
  frep::TapePtr Tape;
  tbb::enumerable_thread_specific<ThreadEvaluators> PerThread;

  ThreadEvaluators& Local()
  {
    ThreadEvaluators& local = this->PerThread.local();
    if (!local.Value)
    {
      local.Value.emplace(this->Tape, this->Parameters);
    }
    return local;
  }
};

ictkFRepImplicitFunction::ictkFRepImplicitFunction()
  : Internal(new Internals)
{
}

ictkFRepImplicitFunction::~ictkFRepImplicitFunction()
{
  delete[] this->ModelName;
  this->ModelName = nullptr;
}

void ictkFRepImplicitFunction::SetModelName(const char* name)
{
  delete[] this->ModelName;
  this->ModelName = nullptr;
  if (name)
  {
    this->ModelName = new char[std::strlen(name) + 1];
    std::strcpy(this->ModelName, name);
  }
  this->Internal->Explicit.reset();
  this->Rebuild();
}

void ictkFRepImplicitFunction::SetHypervolume(const frep::Hypervolume& hv)
{
  this->Internal->Explicit = std::make_unique<frep::Hypervolume>(hv);
  this->Rebuild();
}

void ictkFRepImplicitFunction::SetParameters(const std::vector<double>& parameters)
{
  this->Internal->Parameters = parameters;
  this->Rebuild();
}

const std::vector<double>& ictkFRepImplicitFunction::GetParameters() const
{
  return this->Internal->Parameters;
}

void ictkFRepImplicitFunction::SetTime(double t)
{
  if (t != this->Time)
  {
    this->Time = t;
    this->Modified();
  }
}

bool ictkFRepImplicitFunction::HasModel() const
{
  return this->Internal->Tape != nullptr;
}

void ictkFRepImplicitFunction::Rebuild()
{
  Internals& in = *this->Internal;
  // Evaluators hold the old tape and parameters: drop them all (no thread may be evaluating now).
  in.PerThread.clear();
  in.Tape.reset();
  this->Modified();
  try
  {
    frep::TapePtr tape;
    if (in.Explicit)
    {
      tape = frep::Tape::compile(in.Explicit->geometry().function());
    }
    else if (this->ModelName && *this->ModelName)
    {
      const frep::Hypervolume hv = frep::findModel(this->ModelName).build();
      tape = frep::Tape::compile(hv.geometry().function());
    }
    else
    {
      return;
    }
    // Fails here, once, rather than in every thread's first evaluation.
    frep::PointEvaluator check(tape, in.Parameters);
    in.Tape = std::move(tape);
  }
  catch (const std::exception& e)
  {
    vtkErrorMacro(<< e.what());
  }
}

double ictkFRepImplicitFunction::EvaluateFunction(double x[3])
{
  if (!this->Internal->Tape)
  {
    return 1.0;
  }
  return -this->Internal->Local().Value->eval(x[0], x[1], x[2], this->Time);
}

void ictkFRepImplicitFunction::EvaluateGradient(double x[3], double g[3])
{
  if (!this->Internal->Tape)
  {
    g[0] = g[1] = g[2] = 0.0;
    return;
  }
  ThreadEvaluators& local = this->Internal->Local();
  if (!local.Gradient)
  {
    local.Gradient.emplace(this->Internal->Tape, this->Internal->Parameters);
  }
  const frep::ValueGradient vg = local.Gradient->eval(x[0], x[1], x[2], this->Time);
  for (int i = 0; i < 3; ++i)
  {
    g[i] = -vg.gradient[i];
  }
}

void ictkFRepImplicitFunction::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "ModelName: " << (this->ModelName ? this->ModelName : "(none)") << "\n";
  os << indent << "Hypervolume: " << (this->Internal->Explicit ? "set" : "(none)") << "\n";
  os << indent << "Time: " << this->Time << "\n";
  os << indent << "Parameters:";
  for (double p : this->Internal->Parameters)
  {
    os << " " << p;
  }
  os << "\n";
  os << indent << "Compiled: " << (this->HasModel() ? "yes" : "no") << "\n";
}
