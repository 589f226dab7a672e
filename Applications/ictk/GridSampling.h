// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// What `ictk sample` and `ictk mesh` (for a model) share: their grid options, the grid planned and
// checked before anything is allocated or written, the sampling with a progress bar and Ctrl-C,
// and the surface f = 0 (Flying Edges, attributes evaluated just inside the solid) with its
// writers (.vtp, .stl, .ply, .obj).

#include "FRep/Sampling.h"
#include "Models.h"

#include <vtkSmartPointer.h>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace CLI
{
class App;
class Option;
} // namespace CLI
class vtkImageData;
class vtkPolyData;

namespace ictk::cli
{

class AtomicOutput;
class ictkCaptureOutputWindow;

/// The options of the commands that sample a model on a grid.
struct GridCommandOptions
{
  std::string Model;
  std::string Output;
  std::int64_t Resolution = 64;
  std::string Dims;
  std::string Bounds;
  double Time = 0;
  CLI::Option* TimeOption = nullptr; ///< whether --time was given (an animated .blob needs it)
  int Threads = 0;
  std::string Params;
  /// An XYT model (2D over time) sampled as the 3D solid of its space-time, z standing for t
  /// (frep::spaceTimeSolid).
  bool SpaceTime = false;

  /// Adds the model argument and the grid options (not -o, whose help differs per command).
  void AddTo(CLI::App* command, std::int64_t defaultResolution,
    const std::string& modelHelp =
      "Model name (see `ictk models`) or a .hf / .xml / .vm / .blob file");
};

/// The grid a command samples, checked before anything is allocated or written.
struct GridPlan
{
  ResolvedModel Model;
  std::vector<double> Params;
  std::array<std::int64_t, 3> Dims;
  frep::Grid Grid;
};

/// Resolves the model and checks the grid (bounds, dimensions, the memory it needs at
/// `bytesPerValue` per value of f and of every attribute component). `frames`: the times of a
/// series (sample --frames), at the first of which an animated .blob is resolved, its bounds
/// then the union of its boxes at every frame; else an animated .blob is resolved at --time and
/// refused without it.
GridPlan PlanGrid(
  const GridCommandOptions& o, std::size_t bytesPerValue, const std::vector<double>& frames = {});

/// Samples the planned grid with a progress display; null when interrupted (Ctrl-C, inside the
/// caller's InterruptScope).
vtkSmartPointer<vtkImageData> SampleImage(const GridPlan& plan, int threads, bool asDouble,
  bool attributes, ictkCaptureOutputWindow* messages);

/// Samples the planned grid of a time-dependent model at every time into the ParaView time series
/// `pvd` (ictkTimeSeriesWriter: one .vti a frame, written atomically), with a progress display;
/// false when interrupted (nothing written). A model without time is a UserError; an animated
/// .blob is instantiated at every time.
bool SampleSeries(const GridPlan& plan, int threads, bool asDouble,
  const std::vector<double>& times, const std::string& pvd, ictkCaptureOutputWindow* messages);

/// Checks, before any work, that the planned grid has a surface to write to `path` (given as
/// `option`): a grid flat along one axis (a 2D model) has a boundary curve, written as .vtp or
/// .obj (line segments); a flatter one has none.
void CheckSurfaceGrid(const GridPlan& plan, const std::string& path, const std::string& option);
/// "P points, T triangles", or "P points, L line segments" for a 2D model's boundary curve.
std::string SurfaceSummary(vtkPolyData* surface);

/// The surface f = 0 of a sampled image (the curve f = 0 of a flat one, CheckSurfaceGrid), with
/// outward normals and the model's attributes evaluated at its vertices.
vtkSmartPointer<vtkPolyData> ExtractSurface(
  vtkImageData* image, const GridPlan& plan, ictkCaptureOutputWindow* messages);

/// The surface formats, for messages.
extern const char* const SurfaceFormats;
bool IsSurfaceFormat(const std::string& path);
/// Writes a surface in the format its path names (checked by IsSurfaceFormat) and commits `file`.
void WriteSurface(vtkPolyData* surface, AtomicOutput& file, const std::string& path,
  ictkCaptureOutputWindow* messages);

} // namespace ictk::cli
