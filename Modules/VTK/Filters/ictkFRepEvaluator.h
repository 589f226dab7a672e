// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class ictkFRepEvaluator
 * @brief Evaluates an FRep model at a list of points: values, gradients and attributes.
 *
 * The model is resolved as in ictkFRepSampler (SetModelName, SetFileName, or SetHypervolume in
 * C++). The Evaluate* methods take the points as a vtkDataArray of N tuples with 3 (x, y, z)
 * or 4 (x, y, z, t) components, and write into a caller-given vtkDataArray of N tuples, so that
 * NumPy arrays wrapped without a copy (vtkmodules.util.numpy_support.numpy_to_vtk(a,
 * deep=False)) are read and written in place; the Python package's ictk.Model does that.
 * Points with 3 components are evaluated at Time.
 *
 * Values come from the same batch evaluator as grid sampling (so they equal the sampler's at
 * the same points), in parallel over chunks; the result does not depend on the thread count.
 * Each method returns 1 on success, 0 with vtkErrorMacro on bad input (unresolvable model,
 * wrong component or tuple counts, non-finite coordinates are evaluated as given).
 */
#pragma once

#include "ictkFiltersFRepModule.h" // export macro
#include "vtkObject.h"

#include <memory> // for std::unique_ptr
#include <string> // for std::string
#include <vector> // for std::vector

class vtkDataArray;

#ifndef __VTK_WRAP__
namespace ictk
{
namespace frep
{
class Hypervolume;
}
} // namespace ictk
#endif

class ICTKFILTERSFREP_EXPORT ictkFRepEvaluator : public vtkObject
{
public:
  static ictkFRepEvaluator* New();
  vtkTypeMacro(ictkFRepEvaluator, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// A registered model (`ictk models`); replaces a file or hypervolume.
  void SetModelName(const char* name);
  vtkGetStringMacro(ModelName);
  /// A model file (.hf, .xml, .vm); replaces a name or hypervolume.
  void SetFileName(const char* name);
  vtkGetStringMacro(FileName);
#ifndef __VTK_WRAP__
  void SetHypervolume(const ictk::frep::Hypervolume& hv);
  const ictk::frep::Hypervolume* GetHypervolume();
#endif
  /// Values of the model's parameters (a HyperFun file is read again with them).
  void SetParameters(const double* values, int count);
  int GetNumberOfParameters();

  /// The time of points given with 3 components (default 0).
  vtkSetMacro(Time, double);
  vtkGetMacro(Time, double);

  /// Threads (0: TBB's default); results do not depend on it.
  vtkSetClampMacro(NumberOfThreads, int, 0, VTK_INT_MAX);
  vtkGetMacro(NumberOfThreads, int);

  /// Resolves the model now; 0 (with the error in GetLastError()) when it cannot be.
  int Load();
  /// The last error, empty when the last call succeeded.
  const char* GetLastError() const
  {
    return this->LastError.c_str();
  }

  ///@{
  /// About the model (after Load()).
  const char* GetName();
  bool IsTimeDependent();
  /// A box that holds the model (xmin, xmax, ymin, ymax, zmin, zmax); a hypervolume given in
  /// C++ has none (an empty box).
  void GetBounds(double bounds[6]);
  int GetNumberOfAttributes();
  const char* GetAttributeName(int i);
  int GetAttributeNumberOfComponents(int i);
  /// Components of all attributes together (the width of EvaluateAttributes' output).
  int GetAttributeComponentCount();
  ///@}

  /// values (N x 1) = f at the points.
  int EvaluateValues(vtkDataArray* points, vtkDataArray* values);
  /// gradients (N x 4) = (df/dx, df/dy, df/dz, df/dt); values (N x 1) may be null.
  int EvaluateGradients(vtkDataArray* points, vtkDataArray* gradients, vtkDataArray* values);
  /// attributes (N x GetAttributeComponentCount()) = every attribute's components in order, by
  /// the hypervolume default rule (the attribute where its partition is >= 0, else the inside or
  /// outside default).
  int EvaluateAttributes(vtkDataArray* points, vtkDataArray* attributes);

protected:
  ictkFRepEvaluator();
  ~ictkFRepEvaluator() override;

  char* ModelName = nullptr;
  char* FileName = nullptr;
  double Time = 0.0;
  int NumberOfThreads = 0;
  std::string LastError;

private:
  ictkFRepEvaluator(const ictkFRepEvaluator&) = delete;
  void operator=(const ictkFRepEvaluator&) = delete;

  struct Internals;
  std::unique_ptr<Internals> Internal;
};
