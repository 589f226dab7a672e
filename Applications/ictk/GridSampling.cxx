// SPDX-License-Identifier: BSD-3-Clause
#include "GridSampling.h"

#include "Command.h"
#include "Options.h"
#include "Output.h"
#include "ProgressDisplay.h"
#include "VtkMessages.h"

#include "FRep/Evaluators.h"
#include "ictkFRepSampler.h"
#include "ictkTimeSeriesWriter.h"

#include <vtkCallbackCommand.h>
#include <vtkCommand.h>
#include <vtkDataObject.h>
#include <vtkFloatArray.h>
#include <vtkFlyingEdges2D.h>
#include <vtkFlyingEdges3D.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkOBJWriter.h>
#include <vtkPLYWriter.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkSMPTools.h>
#include <vtkSTLWriter.h>
#include <vtkXMLPolyDataWriter.h>

#include <CLI/CLI.hpp>

#include <algorithm>
#include <climits>
#include <cmath>
#include <optional>
#include <sstream>

namespace ictk::cli
{
namespace
{

// Evaluates the hypervolume's attributes at every vertex of a boundary surface, taken from the
// inside of the solid: each vertex (on f = 0 only up to Flying Edges' linear interpolation) is
// moved by a few Newton steps along the gradient to where f is just positive, about `inset` inside.
// Arrays are named as the attributes, with their component counts.
void AttachBoundaryAttributes(vtkPolyData* surface, const frep::Hypervolume& hv,
  const std::vector<double>& params, double time, double inset)
{
  if (hv.attributes().empty() || surface->GetNumberOfPoints() == 0)
  {
    return;
  }
  frep::HypervolumeEvaluator evaluator(hv, params);
  frep::GradientEvaluator gradient(frep::Tape::compile(hv.geometry().function()), params);
  std::vector<vtkSmartPointer<vtkFloatArray>> arrays;
  for (const frep::Attribute& a : hv.attributes())
  {
    auto array = vtkSmartPointer<vtkFloatArray>::New();
    array->SetName(a.name.c_str());
    array->SetNumberOfComponents(static_cast<int>(a.components.size()));
    array->SetNumberOfTuples(surface->GetNumberOfPoints());
    arrays.push_back(array);
  }
  std::vector<double> values(hv.attributeComponentCount());
  for (vtkIdType i = 0; i < surface->GetNumberOfPoints(); ++i)
  {
    double p[3];
    surface->GetPoint(i, p);
    for (int iteration = 0; iteration < 4; ++iteration)
    {
      const frep::ValueGradient g = gradient.eval(p[0], p[1], p[2], time);
      const double g2 = g.gradient[0] * g.gradient[0] + g.gradient[1] * g.gradient[1] +
        g.gradient[2] * g.gradient[2];
      const double target = hv.threshold() + inset * std::sqrt(g2);
      if (!(g2 > 0) || !std::isfinite(g.value) || g.value >= target)
      {
        break;
      }
      for (int k = 0; k < 3; ++k)
      {
        p[k] += (target - g.value) * g.gradient[k] / g2;
      }
    }
    double f;
    evaluator.eval({ p[0], p[1], p[2], time }, f, values.data());
    std::size_t k = 0;
    for (auto& array : arrays)
    {
      for (int c = 0; c < array->GetNumberOfComponents(); ++c)
      {
        array->SetTypedComponent(i, c, static_cast<float>(values[k++]));
      }
    }
  }
  for (auto& array : arrays)
  {
    surface->GetPointData()->AddArray(array);
  }
}

void OnProgress(vtkObject* caller, unsigned long, void* clientData, void* callData)
{
  static_cast<ProgressBar*>(clientData)->Show(*static_cast<double*>(callData));
  if (Interrupted())
  {
    static_cast<vtkAlgorithm*>(caller)->SetAbortExecute(1);
  }
}

} // namespace

void GridCommandOptions::AddTo(
  CLI::App* command, std::int64_t defaultResolution, const std::string& modelHelp)
{
  this->Resolution = defaultResolution;
  AddModel(command, this->Model, modelHelp);
  CLI::Option* resolution = command->add_option("--resolution", this->Resolution,
    "Points per axis (default " + std::to_string(defaultResolution) + ")");
  CLI::Option* dims = command->add_option("--dims", this->Dims, "Points per axis: NX,NY,NZ");
  resolution->excludes(dims);
  command->add_option(
    "--bounds", this->Bounds, "Sampled box x0,x1,y0,y1,z0,z1 (default: the model's bounds)");
  this->TimeOption = AddTime(command, this->Time);
  AddThreads(command, this->Threads);
  AddParams(command, this->Params);
  command->add_flag("--space-time", this->SpaceTime,
    "An XYT model (2D over time) as the 3D solid of its space-time, z standing for t (the "
    "thesis's figures of space-time blending); --bounds' z0,z1 are then the time range");
}

GridPlan PlanGrid(
  const GridCommandOptions& o, std::size_t bytesPerValue, const std::vector<double>& frames)
{
  const std::vector<double> params = ParseParameters(o.Params);
  if (!std::isfinite(o.Time))
  {
    throw UserError("--time must be a finite number");
  }
  std::optional<double> time;
  if (!frames.empty())
  {
    time = frames.front();
  }
  else if (o.TimeOption && o.TimeOption->count() > 0)
  {
    time = o.Time;
  }
  GridPlan plan{ ResolveModel(o.Model, params, time), params, {}, {} };
  if (plan.Model.Animated)
  {
    // One grid for the whole series: it holds the model at every frame.
    for (std::size_t k = 1; k < frames.size(); ++k)
    {
      const ResolvedModel at = plan.Model.At(frames[k]);
      for (int a = 0; a < 3; ++a)
      {
        plan.Model.Lo[a] = std::min(plan.Model.Lo[a], at.Lo[a]);
        plan.Model.Hi[a] = std::max(plan.Model.Hi[a], at.Hi[a]);
      }
    }
  }
  CheckThreads(o.Threads);
  if (o.SpaceTime)
  {
    try
    {
      plan.Model.Model = frep::spaceTimeSolid(plan.Model.Model);
    }
    catch (const std::invalid_argument& e)
    {
      throw UserError("--space-time: '" + o.Model + "': " + e.what());
    }
    if (o.Bounds.empty())
    {
      throw UserError("--space-time needs --bounds x0,x1,y0,y1,t0,t1: z is the time axis, and a "
                      "model's bounds have no time range");
    }
  }
  std::array<double, 3>& lo = plan.Model.Lo;
  std::array<double, 3>& hi = plan.Model.Hi;
  if (!o.Bounds.empty())
  {
    ParseBounds(o.Bounds, lo, hi);
  }
  std::array<std::int64_t, 3>& dims = plan.Dims;
  if (!o.Dims.empty())
  {
    dims = ParseDims(o.Dims);
  }
  else
  {
    if (o.Resolution < 2)
    {
      throw UserError("--resolution must be at least 2, got " + std::to_string(o.Resolution));
    }
    dims = { o.Resolution, o.Resolution, o.Resolution };
  }
  for (int a = 0; a < 3; ++a)
  {
    // A flat axis of the box (a 2D model) is sampled once, as ictkFRepSampler does.
    if (!(hi[a] > lo[a]))
    {
      dims[a] = 1;
    }
  }
  plan.Grid = frep::gridOverBox(lo, hi, dims, o.Time);
  try
  {
    frep::checkGrid(plan.Grid, (1 + plan.Model.Model.attributeComponentCount()) * bytesPerValue);
  }
  catch (const std::invalid_argument& e)
  {
    throw UserError(std::string("cannot sample: ") + e.what());
  }
  for (int a = 0; a < 3; ++a)
  {
    // VTK extents are int.
    if (dims[a] > INT_MAX)
    {
      throw UserError("cannot sample: " + std::to_string(dims[a]) +
        " points along one axis is more than VTK's limit of " + std::to_string(INT_MAX));
    }
  }
  if (o.Threads > 0)
  {
    vtkSMPTools::Initialize(o.Threads);
  }
  return plan;
}

namespace
{
/// The sampler of a planned grid, the one configuration of SampleImage and SampleSeries.
vtkSmartPointer<ictkFRepSampler> PlannedSampler(
  const GridPlan& plan, int threads, bool asDouble, bool attributes)
{
  vtkNew<ictkFRepSampler> sampler;
  sampler->SetTime(plan.Grid.time);
  if (plan.Model.Animated)
  {
    // An animated .blob changes outside its domain: its instance at each frame's time.
    sampler->SetHypervolumeOfTime([model = plan.Model](double t) { return model.At(t).Model; });
  }
  else
  {
    sampler->SetHypervolume(plan.Model.Model);
  }
  sampler->SetParameters(plan.Params);
  const auto& lo = plan.Model.Lo;
  const auto& hi = plan.Model.Hi;
  sampler->SetModelBounds(lo[0], hi[0], lo[1], hi[1], lo[2], hi[2]);
  sampler->SetSampleDimensions(
    static_cast<int>(plan.Dims[0]), static_cast<int>(plan.Dims[1]), static_cast<int>(plan.Dims[2]));
  sampler->SetNumberOfThreads(threads);
  sampler->SetOutputScalarType(asDouble ? VTK_DOUBLE : VTK_FLOAT);
  sampler->SetComputeAttributes(attributes);
  return sampler;
}
} // namespace

vtkSmartPointer<vtkImageData> SampleImage(const GridPlan& plan, int threads, bool asDouble,
  bool attributes, ictkCaptureOutputWindow* messages)
{
  vtkSmartPointer<ictkFRepSampler> sampler = PlannedSampler(plan, threads, asDouble, attributes);
  ProgressBar progress("sampling " + plan.Model.Name, true);
  vtkNew<vtkCallbackCommand> onProgress;
  onProgress->SetCallback(OnProgress);
  onProgress->SetClientData(&progress);
  sampler->AddObserver(vtkCommand::ProgressEvent, onProgress);

  const std::size_t errorsBefore = messages->Errors.size();
  sampler->Update();
  progress.End();
  if (Interrupted())
  {
    return nullptr;
  }
  ThrowIfVtkFailed(messages, errorsBefore, "sampling failed");
  vtkSmartPointer<vtkImageData> image = sampler->GetOutput();
  if (image->GetNumberOfPoints() != plan.Grid.pointCount())
  {
    throw UserError("sampling failed: the output has " +
      std::to_string(image->GetNumberOfPoints()) + " points instead of " +
      std::to_string(plan.Grid.pointCount()));
  }
  return image;
}

bool SampleSeries(const GridPlan& plan, int threads, bool asDouble,
  const std::vector<double>& times, const std::string& pvd, ictkCaptureOutputWindow* messages)
{
  vtkSmartPointer<ictkFRepSampler> sampler = PlannedSampler(plan, threads, asDouble, true);
  if (!sampler->IsTimeDependent())
  {
    throw UserError("--frames: " + plan.Model.Name +
      " does not depend on time (its domain has no t axis): sample it once, without --frames");
  }
  sampler->SetTimeSteps(times.data(), static_cast<int>(times.size()));
  vtkNew<ictkTimeSeriesWriter> writer;
  writer->SetInputConnection(sampler->GetOutputPort());
  writer->SetFileName(pvd.c_str());
  ProgressBar progress(
    "sampling " + plan.Model.Name + " over " + std::to_string(times.size()) + " frames", true);
  vtkNew<vtkCallbackCommand> onProgress;
  onProgress->SetCallback(OnProgress);
  onProgress->SetClientData(&progress);
  writer->AddObserver(vtkCommand::ProgressEvent, onProgress);
  const std::size_t errorsBefore = messages->Errors.size();
  const int written = writer->Write();
  progress.End();
  if (Interrupted())
  {
    return false;
  }
  // The writer's own errors name the series, the frame and its file: given as they are.
  if (messages->Errors.size() > errorsBefore)
  {
    const std::string cause = messages->FirstCause(errorsBefore);
    throw UserError(cause.rfind("cannot write", 0) == 0
        ? cause
        : "cannot sample the frames into '" + pvd + "': " + cause);
  }
  if (!written)
  {
    throw UserError("cannot sample the frames into '" + pvd + "'");
  }
  return true;
}

namespace
{
/// The number of axes of the planned grid that have a single point.
int FlatAxes(const GridPlan& plan)
{
  return static_cast<int>(std::count(plan.Dims.begin(), plan.Dims.end(), std::int64_t{ 1 }));
}

std::string GridText(const GridPlan& plan)
{
  return std::to_string(plan.Dims[0]) + " x " + std::to_string(plan.Dims[1]) + " x " +
    std::to_string(plan.Dims[2]);
}
} // namespace

void CheckSurfaceGrid(const GridPlan& plan, const std::string& path, const std::string& option)
{
  const int flat = FlatAxes(plan);
  if (flat >= 2)
  {
    throw UserError(option + ": a " + GridText(plan) +
      " grid has no surface f = 0 to extract; give two or three axes at least 2 points (--dims, "
      "--bounds)");
  }
  if (flat == 1 && !HasExtension(path, ".vtp") && !HasExtension(path, ".obj"))
  {
    throw UserError(option + ": '" + plan.Model.Name + "' is sampled on a flat " + GridText(plan) +
      " grid (a 2D model): its boundary f = 0 is a curve, written as .vtp or .obj, not '" + path +
      "'");
  }
}

std::string SurfaceSummary(vtkPolyData* surface)
{
  const vtkIdType lines = surface->GetNumberOfLines();
  return std::to_string(surface->GetNumberOfPoints()) + " points, " +
    (lines > 0 && surface->GetNumberOfPolys() == 0
        ? std::to_string(lines) + " line segments"
        : std::to_string(surface->GetNumberOfPolys()) + " triangles");
}

vtkSmartPointer<vtkPolyData> ExtractSurface(
  vtkImageData* image, const GridPlan& plan, ictkCaptureOutputWindow* messages)
{
  vtkSmartPointer<vtkPolyData> surface;
  const std::size_t errorsBefore = messages->Errors.size();
  if (FlatAxes(plan) == 1)
  {
    // A 2D model's boundary: the curve f = 0 in its plane, as line segments (Flying Edges 3D
    // refuses a flat grid).
    // Flying Edges 2D contours the XY plane only; a grid flat along x or y has the same point
    // order as the XY image of its two other axes, so it is contoured as that and mapped back.
    const int flat = static_cast<int>(
      std::find(plan.Dims.begin(), plan.Dims.end(), std::int64_t{ 1 }) - plan.Dims.begin());
    const int u = flat == 0 ? 1 : 0;
    const int v = flat == 2 ? 1 : 2;
    vtkNew<vtkImageData> plane;
    plane->SetDimensions(image->GetDimensions()[u], image->GetDimensions()[v], 1);
    plane->SetOrigin(image->GetOrigin()[u], image->GetOrigin()[v], 0);
    plane->SetSpacing(image->GetSpacing()[u], image->GetSpacing()[v], 1);
    plane->GetPointData()->SetScalars(image->GetPointData()->GetArray("f"));
    vtkNew<vtkFlyingEdges2D> contour;
    contour->SetInputData(plane);
    contour->SetInputArrayToProcess(0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, "f");
    contour->SetValue(0, 0.0);
    contour->ComputeScalarsOff();
    contour->Update();
    ThrowIfVtkFailed(messages, errorsBefore, "curve extraction failed");
    surface = contour->GetOutput();
    vtkPoints* points = surface->GetPoints();
    const double level = image->GetOrigin()[flat];
    for (vtkIdType i = 0; points && i < points->GetNumberOfPoints(); ++i)
    {
      double p[3];
      double q[3];
      points->GetPoint(i, p);
      q[u] = p[0];
      q[v] = p[1];
      q[flat] = level;
      points->SetPoint(i, q);
    }
  }
  else
  {
    vtkNew<vtkFlyingEdges3D> contour;
    contour->SetInputData(image);
    contour->SetInputArrayToProcess(0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, "f");
    contour->SetValue(0, 0.0);
    // f grows inwards, so the negated gradient Flying Edges uses for normals points outwards.
    contour->ComputeNormalsOn();
    contour->ComputeScalarsOff();
    contour->InterpolateAttributesOff();
    contour->Update();
    ThrowIfVtkFailed(messages, errorsBefore, "surface extraction failed");
    surface = contour->GetOutput();
  }
  // Interpolating the grid's attribute arrays would mix the values on both sides of the
  // boundary (an attribute usually jumps there); evaluate them instead just inside the solid,
  // a thousandth of a grid step from each vertex against its outward normal.
  const auto& spacing = plan.Grid.spacing;
  double step = 0;
  for (int a = 0; a < 3; ++a)
  {
    if (plan.Dims[a] > 1 && (step == 0 || spacing[a] < step))
    {
      step = spacing[a];
    }
  }
  AttachBoundaryAttributes(surface, plan.Model.Model, plan.Params, plan.Grid.time, 1e-3 * step);
  return surface;
}

const char* const SurfaceFormats = ".vtp, .stl, .ply or .obj";

bool IsSurfaceFormat(const std::string& path)
{
  return HasExtension(path, ".vtp") || HasExtension(path, ".stl") || HasExtension(path, ".ply") ||
    HasExtension(path, ".obj");
}

void WriteSurface(vtkPolyData* surface, AtomicOutput& file, const std::string& path,
  ictkCaptureOutputWindow* messages)
{
  // Every writer is given the temporary path, and reports failure through Write() and its error
  // code (vtkXMLWriter is not a vtkWriter, so each kind is driven on its own); the .vtp is made in
  // memory (WriteXml). vtkPLYWriter and vtkOBJWriter ignore their stream's errors: Commit checks
  // that the file was not cut short.
  auto run = [&](auto* writer)
  {
    writer->SetInputData(surface);
    writer->SetFileName(file.Path().c_str());
    return writer->Write() == 1 && writer->GetErrorCode() == 0;
  };
  const std::size_t errorsBefore = messages->Errors.size();
  bool written = false;
  if (HasExtension(path, ".vtp"))
  {
    vtkNew<vtkXMLPolyDataWriter> xml;
    xml->SetDataModeToAppended();
    xml->EncodeAppendedDataOff();
    WriteXml(xml, surface, file);
    written = true;
  }
  else if (HasExtension(path, ".stl"))
  {
    vtkNew<vtkSTLWriter> stl;
    stl->SetFileTypeToBinary();
    written = run(stl.Get());
  }
  else if (HasExtension(path, ".ply"))
  {
    vtkNew<vtkPLYWriter> ply;
    ply->SetFileTypeToBinary();
    written = run(ply.Get());
  }
  else
  {
    vtkNew<vtkOBJWriter> obj;
    written = run(obj.Get());
  }
  ThrowIfVtkFailed(messages, errorsBefore, "cannot write '" + path + "'");
  if (!written)
  {
    throw UserError("cannot write '" + path + "'");
  }
  file.Commit();
}

} // namespace ictk::cli
