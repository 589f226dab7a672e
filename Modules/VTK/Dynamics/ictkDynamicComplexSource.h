// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class ictkDynamicComplexSource
 * @brief Runs a dynamic implicit complex (.icm model) and outputs, at the time the pipeline asks
 * for, the complex of the model's active instance as a vtkPartitionedDataSetCollection.
 *
 * The frames are those of ictk::engine::FrameSequence (Modules/Core/Engine/FrameSequence.h),
 * ICTK's one frame loop. RequestInformation advertises TIME_STEPS and TIME_RANGE: the times in
 * SetTimeSteps() when given, otherwise the model's time range (the union of its time spans) from
 * its start at every TimeStepSize, its end included (ictk::engine::frameTimes). RequestData
 * honours UPDATE_TIME_STEP (clamped to that range): the engine is advanced to the requested time
 * through every advertised time step before it, in steps of at most MaximumStep (transitions
 * between instances are located on the way), so the output at a time does not depend on the
 * order in which times were requested; a time earlier than the engine's restarts the model from
 * its start. The output carries DATA_TIME_STEP, the complex itself (ictkComplexSource::COMPLEX()),
 * and the field data "Instance" (the active instance's name) and "Time". Its cells and
 * vtkDataAssembly are the VTK form of a complex (ictkComplexToVTK.h), as ictkComplexSource's, so
 * they change when the instance changes. In C++, GetFrameRecords() gives the engine's records on
 * the way to the last frame (what `ictk run --trace` writes).
 *
 * Written as a time series (.pvd and one .vtpc per frame) by ictkTimeSeriesWriter.
 *
 * Frames are discretised with time coherence (ictk::engine::CoherentDiscretizer): a cell whose
 * shape did not change since it was last meshed is moved, not re-meshed. FeatureSize is the same
 * for every frame (0: 1/64 of the complex's size at the model's start).
 *
 * Pieces: under MPI every rank runs the engine (it is cheap and deterministic) and discretises
 * its share of the active instance's cells (cell i to piece i mod N), as ictkComplexSource does.
 *
 * Progress is reported over the engine's run (first half) and the discretisation (second half);
 * AbortExecute cancels and leaves an empty output. A model that does not read or run is reported
 * with vtkErrorMacro ("file:line:col: error: ...") and the request fails.
 */
#pragma once

#include "ictkFiltersDynamicsModule.h" // export macro
#include "vtkPartitionedDataSetCollectionAlgorithm.h"

#include <exception> // for std::exception_ptr
#include <memory>    // for std::unique_ptr
#include <string>    // for std::string
#include <vector>    // for std::vector

class vtkPartitionedDataSetCollection;

#ifndef __VTK_WRAP__
namespace ictk
{
namespace engine
{
struct FrameRecord;
} // namespace engine
} // namespace ictk
#endif

class ICTKFILTERSDYNAMICS_EXPORT ictkDynamicComplexSource
  : public vtkPartitionedDataSetCollectionAlgorithm
{
public:
  static ictkDynamicComplexSource* New();
  vtkTypeMacro(ictkDynamicComplexSource, vtkPartitionedDataSetCollectionAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// The .icm model.
  vtkSetStdStringFromCharMacro(FileName);
  vtkGetCharFromStdStringMacro(FileName);

  /// Mesh edge length and curve step in model units, fixed for every frame; 0 (default) = 1/64
  /// of the largest side of the complex at the model's start.
  vtkSetClampMacro(FeatureSize, double, 0.0, VTK_DOUBLE_MAX);
  vtkGetMacro(FeatureSize, double);

  /// The engine's largest time step; 0 (default) = the spacing of the time steps.
  vtkSetClampMacro(MaximumStep, double, 0.0, VTK_DOUBLE_MAX);
  vtkGetMacro(MaximumStep, double);

  /// The spacing of the advertised time steps when no list is given; 0 (default) = 1/100 of the
  /// model's time range.
  vtkSetClampMacro(TimeStepSize, double, 0.0, VTK_DOUBLE_MAX);
  vtkGetMacro(TimeStepSize, double);

  /// An explicit list of time steps (sorted, duplicates dropped), used instead of TimeStepSize.
  void SetTimeSteps(const double* times, int count);
  void AddTimeStep(double time);
  void RemoveAllTimeSteps();
  int GetNumberOfTimeSteps() const { return static_cast<int>(this->TimeSteps.size()); }
  double GetTimeStep(int i) const { return this->TimeSteps.at(static_cast<std::size_t>(i)); }

  /// Reuse the meshes of unchanged cells across frames (default on); off re-meshes every cell
  /// of every frame, for comparison.
  vtkSetMacro(Coherent, vtkTypeBool);
  vtkGetMacro(Coherent, vtkTypeBool);
  vtkBooleanMacro(Coherent, vtkTypeBool);

  /// Threads for the discretisers; 0 = TBB's default. Results do not depend on it.
  vtkSetClampMacro(NumberOfThreads, int, 0, 1024);
  vtkGetMacro(NumberOfThreads, int);

  /// After an update: the active instance, the engine's time, and the work of the last frame's
  /// discretisation (cells meshed, moved, reused as they were) and of all frames so far.
  const char* GetInstanceName() const { return this->InstanceName.c_str(); }
  double GetModelTime() const { return this->ModelTime; }
  int GetCellsComputed() const { return this->Stats[0]; }
  int GetCellsMoved() const { return this->Stats[1]; }
  int GetCellsReused() const { return this->Stats[2]; }
  int GetTotalCellsComputed() const { return this->TotalStats[0]; }
  int GetTotalCellsMoved() const { return this->TotalStats[1]; }
  int GetTotalCellsReused() const { return this->TotalStats[2]; }

  /// The model's time at its start and the feature size the frames are discretised at
  /// (FeatureSize, or the one chosen at the model's start when that is 0); known after
  /// UpdateInformation().
  double GetStartTime() const;
  double GetFeatureSizeInUse() const;

#ifndef __VTK_WRAP__
  /// The engine's records on the way to the last frame output, since the frame before it (from
  /// the model's start, its start record first, when the model was started for it): one per
  /// evaluated time, requested or a located transition. Empty after a failed or cancelled frame.
  const std::vector<ictk::engine::FrameRecord>& GetFrameRecords() const;
  /// The exception behind the last failed request (lang::ParseError, engine::ModelError, ...),
  /// or null: for C++ front ends that report errors in their own form (the request itself reports
  /// it with vtkErrorMacro, "file:line:col: error: ..." for a model's errors).
  std::exception_ptr GetLastError() const;
#endif

  /// Stamps a frame: the field data "Instance" (the active instance's name) and "Time" on the
  /// collection and on every leaf (the XML writers keep only the leaves' field data).
  static void AddFrameFields(
    vtkPartitionedDataSetCollection* frame, const char* instance, double time);

protected:
  ictkDynamicComplexSource();
  ~ictkDynamicComplexSource() override;

  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  std::string FileName;
  double FeatureSize = 0;
  double MaximumStep = 0;
  double TimeStepSize = 0;
  std::vector<double> TimeSteps;
  vtkTypeBool Coherent = 1;
  int NumberOfThreads = 0;

  std::string InstanceName;
  double ModelTime = 0;
  int Stats[3] = { 0, 0, 0 };
  int TotalStats[3] = { 0, 0, 0 };

private:
  ictkDynamicComplexSource(const ictkDynamicComplexSource&) = delete;
  void operator=(const ictkDynamicComplexSource&) = delete;

  struct Internals;
  std::unique_ptr<Internals> Internal;
  /// vtkErrorMacro with a model's errors in the front ends' form.
  void ReportError(const std::exception& e);
};
