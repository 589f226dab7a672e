// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class ictkFRepSampler
 * @brief Samples an FRep hypervolume (geometry and attributes) on a vtkImageData.
 *
 * A source (no input), and the reader of model files. The model is a registered model, chosen by
 * name with SetModelName() (the bundled models are registered on first use), a model file given
 * with SetFileName() (.hf HyperFun, .xml FRep XML, .vm Fidget SSA), or a hypervolume given through
 * the C++ setter SetHypervolume(); whichever was set last is sampled. A file without bounds is
 * bounded by interval arithmetic over [-10, 10]^3 (ictk::lang::modelFileBounds).
 *
 * Output point data:
 * - "f": the defining function (f >= 0 inside, the FRep convention), the active scalars;
 * - one array per attribute, named after it, with the attribute's component count; the value
 *   follows the hypervolume default rule (the attribute function where its partition is >= 0,
 *   else the inside or outside default).
 *
 * The grid covers ModelBounds with SampleDimensions points (corners included). An axis whose
 * bounds have zero extent (e.g. z of a 2D model) is sampled once, whatever SampleDimensions says.
 * A ModelBounds box with xmin > xmax (the default) means "the registered model's own bounds";
 * a hypervolume set through SetHypervolume() has none, so ModelBounds must then be set.
 *
 * Time: a model whose domain has the t axis (XYZT, XYT, ...) is time-dependent. The output then
 * advertises TIME_RANGE (TimeRange) and TIME_STEPS (NumberOfTimeSteps evenly over it, or the
 * times SetTimeSteps() gave, whose first and last are then the range) and is
 * sampled at the pipeline's UPDATE_TIME_STEP when there is one (DATA_TIME_STEP says which), else
 * at Time. A model without t advertises no time.
 *
 * Pieces: the source produces any sub-extent of its whole extent (CAN_PRODUCE_SUB_EXTENT), so
 * VTK's streaming and ParaView's ranks under MPI each sample their own slab (with the ghost
 * levels the pipeline asks for, so contours of pieces stitch). A point's coordinates are computed
 * from its index in the whole grid, so in double precision a piece equals the whole bit for bit.
 *
 * Sampling is multithreaded (TBB) and gives identical values for any NumberOfThreads. Progress is
 * reported through UpdateProgress(); setting AbortExecute stops the sampling and leaves an empty
 * output. Bad input (unknown model, empty or too large grid, missing parameters) is reported with
 * vtkErrorMacro and the request fails.
 */
#pragma once

#include "ictkFiltersFRepModule.h" // export macro
#include "vtkImageAlgorithm.h"

#include <functional> // for std::function
#include <memory>     // for std::unique_ptr
#include <vector>     // for std::vector

#ifndef __VTK_WRAP__
namespace ictk
{
namespace frep
{
class Hypervolume;
}
} // namespace ictk
#endif

class ICTKFILTERSFREP_EXPORT ictkFRepSampler : public vtkImageAlgorithm
{
public:
  static ictkFRepSampler* New();
  vtkTypeMacro(ictkFRepSampler, vtkImageAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * Name of a registered model (see `ictk models`). Setting a name replaces a hypervolume given
   * with SetHypervolume().
   */
  virtual void SetModelName(const char* name);
  vtkGetStringMacro(ModelName);
  ///@}

  ///@{
  /**
   * The model's parameter values one at a time (Python, ParaView's Parameters property): a
   * HyperFun file is specialised to them (`ictk eval --params`); a model that declares more
   * parameters than are given is an error that says how many it needs.
   */
  void AddParameter(double value);
  void ClearParameters();
  ///@}

#ifndef __VTK_WRAP__
  /**
   * Samples `hv` (copied) instead of a registered model. ModelBounds must be set.
   */
  void SetHypervolume(const ictk::frep::Hypervolume& hv);
  /**
   * A model that changes with time outside its domain (an animated BlobTree, whose instance at t
   * is an XYZ model): `model(t)` is sampled at the time of each request, and the output is
   * time-dependent as for an XYZT model. Replaces a model name, file or hypervolume (until one of
   * them is set again). ModelBounds must be set.
   */
  void SetHypervolumeOfTime(std::function<ictk::frep::Hypervolume(double)> model);
  /**
   * Values of the model's parameters (Expr::parameter slots), default none.
   */
  void SetParameters(const std::vector<double>& parameters);
  const std::vector<double>& GetParameters() const;
#endif

  ///@{
  /**
   * A model file (.hf, .xml, .vm). Setting a file name replaces a model name or a hypervolume;
   * an empty name clears it. Syntax errors are reported as "file:line:col: error: ...".
   */
  virtual void SetFileName(const char* name);
  vtkGetStringMacro(FileName);
  ///@}

  /**
   * 1 when `name` looks like a model file this reader opens: a .hf or .vm file, or a .xml file
   * whose root element is <frep> (other XML files are left to other readers).
   */
  static int CanReadFile(const char* name);

  ///@{
  /**
   * Number of grid points along x, y, z (default 50, 50, 50).
   */
  vtkSetVector3Macro(SampleDimensions, int);
  vtkGetVector3Macro(SampleDimensions, int);
  ///@}

  ///@{
  /**
   * The sampled box (xmin, xmax, ymin, ymax, zmin, zmax). Default: an empty box (xmin > xmax),
   * meaning the registered model's own bounds.
   */
  vtkSetVector6Macro(ModelBounds, double);
  vtkGetVector6Macro(ModelBounds, double);
  ///@}

  ///@{
  /**
   * The time t at which time-dependent models are sampled (default 0).
   */
  vtkSetMacro(Time, double);
  vtkGetMacro(Time, double);
  ///@}

  ///@{
  /**
   * The time range advertised for a time-dependent model (default 0..1), and how many evenly
   * spaced time steps are advertised over it (default 11; 0 advertises the range alone).
   */
  vtkSetVector2Macro(TimeRange, double);
  vtkGetVector2Macro(TimeRange, double);
  vtkSetClampMacro(NumberOfTimeSteps, int, 0, 100000);
  vtkGetMacro(NumberOfTimeSteps, int);
  ///@}

  /**
   * Advertises exactly these times (increasing, finite) instead of NumberOfTimeSteps over
   * TimeRange; an empty list (count 0) goes back to those. `ictk sample --frames` sets them.
   */
  void SetTimeSteps(const double* times, int count);

  /**
   * True when the model (resolved from the current settings) depends on t.
   */
  bool IsTimeDependent();

  ///@{
  /**
   * VTK_FLOAT (default) or VTK_DOUBLE for every output array.
   */
  vtkSetMacro(OutputScalarType, int);
  vtkGetMacro(OutputScalarType, int);
  void SetOutputScalarTypeToFloat()
  {
    this->SetOutputScalarType(VTK_FLOAT);
  }
  void SetOutputScalarTypeToDouble()
  {
    this->SetOutputScalarType(VTK_DOUBLE);
  }
  ///@}

  ///@{
  /**
   * Whether to produce the attribute arrays (default on).
   */
  vtkSetMacro(ComputeAttributes, bool);
  vtkGetMacro(ComputeAttributes, bool);
  vtkBooleanMacro(ComputeAttributes, bool);
  ///@}

  ///@{
  /**
   * Threads used for sampling; 0 (default) lets TBB decide.
   */
  vtkSetClampMacro(NumberOfThreads, int, 0, VTK_INT_MAX);
  vtkGetMacro(NumberOfThreads, int);
  ///@}

  /**
   * Bytes per grid point the output will need with the current settings (0 when the model cannot
   * be resolved). Lets callers check the grid size before Update().
   */
  int GetBytesPerPoint();

protected:
  ictkFRepSampler();
  ~ictkFRepSampler() override;

  int RequestInformation(vtkInformation* request, vtkInformationVector** inputVector,
    vtkInformationVector* outputVector) override;
  int RequestData(vtkInformation* request, vtkInformationVector** inputVector,
    vtkInformationVector* outputVector) override;

  char* ModelName = nullptr;
  char* FileName = nullptr;
  int SampleDimensions[3] = { 50, 50, 50 };
  double ModelBounds[6] = { 1, -1, 1, -1, 1, -1 };
  double Time = 0.0;
  double TimeRange[2] = { 0.0, 1.0 };
  int NumberOfTimeSteps = 11;
  std::vector<double> TimeSteps;
  int OutputScalarType = VTK_FLOAT;
  bool ComputeAttributes = true;
  int NumberOfThreads = 0;

private:
  ictkFRepSampler(const ictkFRepSampler&) = delete;
  void operator=(const ictkFRepSampler&) = delete;

  struct Internals;
  std::unique_ptr<Internals> Internal;
};
