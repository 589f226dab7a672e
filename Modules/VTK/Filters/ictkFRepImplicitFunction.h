// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class ictkFRepImplicitFunction
 * @brief An ICTK FRep model as a vtkImplicitFunction (vtkClipPolyData, vtkCutter,
 * vtkSampleFunction, vtkExtractGeometry, ...).
 *
 * VTK's convention is negative inside and FRep's is f >= 0 inside, so EvaluateFunction returns
 * -f(x, y, z, Time) and EvaluateGradient returns -grad f (by forward-mode differentiation, exact
 * up to rounding). Only the geometry of a hypervolume is used.
 *
 * Thread safety: VTK filters (vtkSampleFunction, vtkCutter through vtkSMPTools) call
 * EvaluateFunction from several threads at once. The compiled tape is immutable and shared; each
 * thread gets its own evaluators from a tbb::enumerable_thread_specific cache owned by this
 * object, so evaluation takes no lock and threads never share scratch memory. The cache is
 * dropped when the model, parameters or time change; changing them while another thread is
 * evaluating is not supported (as for every VTK object).
 *
 * Without a model (or after an error such as an unknown name) EvaluateFunction returns +1
 * everywhere (empty: all outside) and the error is reported once by vtkErrorMacro when the model
 * is set.
 */
#pragma once

#include "ictkFiltersFRepModule.h" // export macro
#include "vtkImplicitFunction.h"

#include <memory> // for std::unique_ptr
#include <vector> // for std::vector

#ifndef __VTK_WRAP__
namespace ictk
{
namespace frep
{
class Hypervolume;
}
} // namespace ictk
#endif

class ICTKFILTERSFREP_EXPORT ictkFRepImplicitFunction : public vtkImplicitFunction
{
public:
  static ictkFRepImplicitFunction* New();
  vtkTypeMacro(ictkFRepImplicitFunction, vtkImplicitFunction);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * A registered model by name (the bundled models are registered on first use). Replaces a
   * hypervolume given with SetHypervolume(). An unknown name is an error and leaves no model.
   */
  virtual void SetModelName(const char* name);
  vtkGetStringMacro(ModelName);
  ///@}

#ifndef __VTK_WRAP__
  /**
   * Uses the geometry of `hv` (copied).
   */
  void SetHypervolume(const ictk::frep::Hypervolume& hv);
  /**
   * Values of the model's parameters. Too few values is reported as an error and leaves no
   * model.
   */
  void SetParameters(const std::vector<double>& parameters);
  const std::vector<double>& GetParameters() const;
#endif

  ///@{
  /**
   * The time t at which the model is evaluated (default 0).
   */
  virtual void SetTime(double t);
  vtkGetMacro(Time, double);
  ///@}

  /**
   * True when a model is set and compiled.
   */
  bool HasModel() const;

  using vtkImplicitFunction::EvaluateFunction;
  /**
   * -f(x, y, z, Time).
   */
  double EvaluateFunction(double x[3]) override;
  /**
   * -grad f at (x, y, z, Time), spatial part.
   */
  void EvaluateGradient(double x[3], double g[3]) override;

protected:
  ictkFRepImplicitFunction();
  ~ictkFRepImplicitFunction() override;

  char* ModelName = nullptr;
  double Time = 0.0;

private:
  ictkFRepImplicitFunction(const ictkFRepImplicitFunction&) = delete;
  void operator=(const ictkFRepImplicitFunction&) = delete;

  void Rebuild();

  struct Internals;
  std::unique_ptr<Internals> Internal;
};
