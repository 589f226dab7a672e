// SPDX-License-Identifier: BSD-3-Clause
// `ictk sample MODEL.icm` (DynamicSampling.h): the engine run to --time, then the active
// instance's cells sampled through their world fields (geometry::worldField, the field the
// discretisers mesh); with --space-time one 2D cell at every t of the time range, z = t.
#include "DynamicSampling.h"

#include "Command.h"
#include "Models.h"
#include "Options.h"
#include "Output.h"
#include "ProgressDisplay.h"
#include "VtkMessages.h"

#include "Engine/DynamicModel.h"
#include "FRep/Progress.h"
#include "FRep/Sampling.h"
#include "Geometry/Queries.h"

#include "ictkTimeSeriesWriter.h"

#include <vtkDataArray.h>
#include <vtkDoubleArray.h>
#include <vtkFieldData.h>
#include <vtkFloatArray.h>
#include <vtkImageAlgorithm.h>
#include <vtkImageData.h>
#include <vtkInformation.h>
#include <vtkInformationVector.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkPointData.h>
#include <vtkSmartPointer.h>
#include <vtkStreamingDemandDrivenPipeline.h>
#include <vtkStringArray.h>
#include <vtkXMLImageDataWriter.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <limits>
#include <memory>
#include <sstream>
#include <thread>
#include <tuple>
#include <vector>

namespace ictk::cli
{
namespace
{

/// What a cell's array holds where the cell is not in the active instance (a space-time volume's
/// slices before it appears or after an instance dropped it): outside, far below any field value
/// near a surface.
constexpr double kAbsent = -1e30;

std::string Number(double x)
{
  std::ostringstream os;
  os << x;
  return os.str();
}

/// The engine's largest step: --max-step, else the rule of `ictk run` (FrameSequence): the
/// spacing of the requested times, or 1/100 of the model's time range for one time. The steps
/// from the model's time to `end`, the last time `option` asks for, are checked against the
/// engine's limit (a --time of 1e300 would otherwise step for ever).
double EngineStep(const DynamicSampleOptions& o, const engine::DynamicModel& m, double spacing,
  double end, const std::string& option)
{
  double step = 1.0;
  if (o.MaxStep > 0)
  {
    step = o.MaxStep;
  }
  else if (spacing > 0)
  {
    step = spacing;
  }
  else
  {
    const auto [t0, t1] = m.timeRange();
    const double range = t1 - t0;
    step = std::isfinite(range) && range > 0 ? range / 100 : 1.0;
  }
  if (o.MaxStep > 0)
  {
    CheckEngineSteps(m.time(), end, step, "--max-step", "a larger --max-step?");
  }
  else
  {
    CheckEngineSteps(m.time(), end, step, option, "an earlier time, or a larger --max-step?");
  }
  return step;
}

/// The names of the cells, for messages.
std::string Names(const std::vector<engine::CellState>& cells)
{
  std::string out;
  for (const engine::CellState& c : cells)
  {
    out += (out.empty() ? "" : ", ") + c.name;
  }
  return out.empty() ? "none" : out;
}

/// Whether a cell has a field to sample: a 2D or 3D shape that is not an explicit mesh.
bool HasField(const engine::CellState& c)
{
  if (c.dimension < 2 || !c.shape)
  {
    return false;
  }
  for (const geometry::ShapePart& p : c.shape->parts)
  {
    if (p.kind == geometry::ShapePart::Kind::Mesh)
    {
      return false;
    }
  }
  return true;
}

void Grow(frep::Box3& box, const frep::Box3& b)
{
  for (int a = 0; a < 3; ++a)
  {
    box.lo[a] = std::min(box.lo[a], b.lo[a]);
    box.hi[a] = std::max(box.hi[a], b.hi[a]);
  }
}

frep::Box3 EmptyBox()
{
  constexpr double inf = std::numeric_limits<double>::infinity();
  return { { inf, inf, inf }, { -inf, -inf, -inf } };
}

/// The grid: --bounds, else `box`; --dims, else --resolution on every axis the box is not flat
/// along. Checked against the memory it needs (`arrays` values a point).
frep::Grid PlanDynamicGrid(
  const DynamicSampleOptions& o, frep::Box3 box, std::size_t arrays, std::size_t bytesPerValue)
{
  if (!o.Bounds.empty())
  {
    ParseBounds(o.Bounds, box.lo, box.hi);
  }
  std::array<std::int64_t, 3> dims{ o.Resolution, o.Resolution, o.Resolution };
  if (!o.Dims.empty())
  {
    dims = ParseDims(o.Dims);
  }
  else if (o.Resolution < 2)
  {
    throw UserError("--resolution must be at least 2, got " + std::to_string(o.Resolution));
  }
  for (int a = 0; a < 3; ++a)
  {
    if (!(box.hi[a] > box.lo[a]))
    {
      dims[a] = 1;
    }
    if (dims[a] > INT_MAX)
    {
      throw UserError("cannot sample: " + std::to_string(dims[a]) +
        " points along one axis is more than VTK's limit");
    }
  }
  const frep::Grid grid = frep::gridOverBox(box.lo, box.hi, dims);
  try
  {
    frep::checkGrid(grid, arrays * bytesPerValue);
  }
  catch (const std::invalid_argument& e)
  {
    throw UserError(std::string("cannot sample: ") + e.what());
  }
  return grid;
}

vtkSmartPointer<vtkImageData> MakeImage(const frep::Grid& grid)
{
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->SetDimensions(static_cast<int>(grid.dimensions[0]), static_cast<int>(grid.dimensions[1]),
    static_cast<int>(grid.dimensions[2]));
  image->SetOrigin(grid.origin[0], grid.origin[1], grid.origin[2]);
  image->SetSpacing(grid.spacing[0] > 0 ? grid.spacing[0] : 1,
    grid.spacing[1] > 0 ? grid.spacing[1] : 1, grid.spacing[2] > 0 ? grid.spacing[2] : 1);
  return image;
}

vtkSmartPointer<vtkDataArray> MakeArray(const std::string& name, vtkIdType n, bool asDouble)
{
  vtkSmartPointer<vtkDataArray> a;
  if (asDouble)
  {
    a = vtkSmartPointer<vtkDoubleArray>::New();
  }
  else
  {
    a = vtkSmartPointer<vtkFloatArray>::New();
  }
  a->SetName(name.c_str());
  a->SetNumberOfTuples(n);
  return a;
}

/// Layers [k0, k1) of the grid of a field into `out` (nx values a row, row k * ny + j at
/// (k * ny + j) * nx), at the grid's z, or at z = 0 for every layer when `flat` (a space-time
/// volume, whose z is t). The rows are shared by `threads` threads (0: the machine's), each with
/// its own evaluator: an evaluator keeps scratch space.
void SampleLayers(const frep::Grid& grid, const frep::Field& field, std::int64_t k0,
  std::int64_t k1, bool flat, int threads, std::vector<double>& out)
{
  const std::int64_t nx = grid.dimensions[0], ny = grid.dimensions[1];
  const std::int64_t first = k0 * ny, rows = (k1 - k0) * ny;
  const unsigned machine = std::max(1u, std::thread::hardware_concurrency());
  const std::int64_t workers =
    std::max<std::int64_t>(1, std::min<std::int64_t>(threads > 0 ? threads : machine, rows));
  std::vector<std::exception_ptr> errors(static_cast<std::size_t>(workers));
  auto work = [&](std::int64_t w)
  {
    try
    {
      const auto evaluator = field.evaluator();
      std::vector<double> x(static_cast<std::size_t>(nx)), y(x.size()), z(x.size());
      for (std::int64_t i = 0; i < nx; ++i)
      {
        x[static_cast<std::size_t>(i)] = grid.origin[0] + static_cast<double>(i) * grid.spacing[0];
      }
      for (std::int64_t r = first + w; r < first + rows && !Interrupted(); r += workers)
      {
        const std::int64_t k = r / ny, j = r % ny;
        std::fill(y.begin(), y.end(), grid.origin[1] + static_cast<double>(j) * grid.spacing[1]);
        std::fill(z.begin(), z.end(),
          flat ? 0.0 : grid.origin[2] + static_cast<double>(k) * grid.spacing[2]);
        evaluator->values(
          x.data(), y.data(), z.data(), out.data() + r * nx, static_cast<std::size_t>(nx));
      }
    }
    catch (...)
    {
      errors[static_cast<std::size_t>(w)] = std::current_exception();
    }
  };
  std::vector<std::thread> pool;
  for (std::int64_t w = 1; w < workers; ++w)
  {
    pool.emplace_back(work, w);
  }
  work(0);
  for (std::thread& t : pool)
  {
    t.join();
  }
  for (const std::exception_ptr& e : errors)
  {
    if (e)
    {
      std::rethrow_exception(e);
    }
  }
  if (Interrupted())
  {
    throw Cancelled();
  }
}

void Write(vtkImageData* image, const std::string& output)
{
  AtomicOutput file(output);
  ictkCaptureOutputWindow* messages = CaptureVtkMessages();
  vtkNew<vtkXMLImageDataWriter> writer;
  writer->SetDataModeToAppended();
  writer->EncodeAppendedDataOff();
  const std::size_t errorsBefore = messages->Errors.size();
  WriteXml(writer, image, file);
  ThrowIfVtkFailed(messages, errorsBefore, "cannot write '" + output + "'");
  file.Commit();
}

void AddFieldData(vtkImageData* image, const char* name, const std::string& value)
{
  vtkNew<vtkStringArray> a;
  a->SetName(name);
  a->InsertNextValue(value);
  image->GetFieldData()->AddArray(a);
}

/// The cells sampled now: --cell, or every cell with a field (2D or 3D, not a mesh) of the
/// largest dimension among them (a 2D cell's field does not depend on z: among 3D cells it would
/// be a cylinder).
std::vector<engine::CellState> CellsToSample(
  const DynamicSampleOptions& o, const engine::DynamicModel& model)
{
  const double t = model.time();
  const std::vector<engine::CellState> all = model.cells();
  std::vector<engine::CellState> cells;
  if (!o.Cell.empty())
  {
    for (const engine::CellState& c : all)
    {
      if (c.name == o.Cell)
      {
        cells.push_back(c);
      }
    }
    if (cells.empty())
    {
      throw UserError("--cell: no cell '" + o.Cell + "' in the instance " + model.activeInstance() +
        " at t = " + Number(t) + " (its cells: " + Names(all) + ")");
    }
    if (!HasField(cells[0]))
    {
      throw UserError("--cell: " + o.Cell + " is a " + std::to_string(cells[0].dimension) +
        "D cell" + (cells[0].dimension >= 2 ? " with an explicit mesh" : "") +
        ", which has no field to sample; `ictk run` writes its discretisation");
    }
    return cells;
  }
  int dimension = 0;
  for (const engine::CellState& c : all)
  {
    if (HasField(c))
    {
      dimension = std::max(dimension, c.dimension);
    }
  }
  for (const engine::CellState& c : all)
  {
    if (HasField(c) && c.dimension == dimension)
    {
      cells.push_back(c);
    }
  }
  if (cells.empty())
  {
    throw UserError("no cell of the instance " + model.activeInstance() + " at t = " + Number(t) +
      " has a field to sample (2D or 3D, not a mesh; its cells: " + Names(all) +
      "); `ictk run` writes their discretisation");
  }
  return cells;
}

/// The box of the cells as placed now; 2D cells lie in z = 0 (their bounds may be padded along z,
/// as a blend's are).
frep::Box3 BoxOf(const std::vector<engine::CellState>& cells)
{
  frep::Box3 box = EmptyBox();
  for (const engine::CellState& c : cells)
  {
    Grow(box, c.shape->worldBounds());
  }
  if (cells[0].dimension == 2)
  {
    box.lo[2] = box.hi[2] = 0;
  }
  return box;
}

/// The cells on the grid: one array each, named after it, and f, the largest of them (the union
/// of their solids); field data Time and Instance.
vtkSmartPointer<vtkImageData> SampleCells(const std::vector<engine::CellState>& cells,
  const frep::Grid& grid, bool asDouble, int threads, double t, const std::string& instance)
{
  vtkSmartPointer<vtkImageData> image = MakeImage(grid);
  const std::int64_t layer = grid.dimensions[0] * grid.dimensions[1];
  const vtkIdType n = static_cast<vtkIdType>(layer * grid.dimensions[2]);
  std::vector<double> values(static_cast<std::size_t>(n)), f(values.size(), kAbsent);
  std::vector<vtkSmartPointer<vtkDataArray>> arrays;
  for (const engine::CellState& c : cells)
  {
    SampleLayers(
      grid, *geometry::worldField(*c.shape), 0, grid.dimensions[2], false, threads, values);
    vtkSmartPointer<vtkDataArray> a = MakeArray(c.name, n, asDouble);
    for (vtkIdType i = 0; i < n; ++i)
    {
      const auto u = static_cast<std::size_t>(i);
      a->SetComponent(i, 0, values[u]);
      f[u] = std::max(f[u], values[u]);
    }
    arrays.push_back(a);
  }
  vtkSmartPointer<vtkDataArray> union_ = MakeArray("f", n, asDouble);
  for (vtkIdType i = 0; i < n; ++i)
  {
    union_->SetComponent(i, 0, f[static_cast<std::size_t>(i)]);
  }
  image->GetPointData()->AddArray(union_);
  image->GetPointData()->SetActiveScalars("f");
  for (const auto& a : arrays)
  {
    image->GetPointData()->AddArray(a);
  }
  vtkNew<vtkDoubleArray> time;
  time->SetName("Time");
  time->InsertNextValue(t);
  image->GetFieldData()->AddArray(time);
  AddFieldData(image, "Instance", instance);
  return image;
}

/// The model at --time.
int SampleAtTime(const DynamicSampleOptions& o, engine::DynamicModel& model)
{
  const double t = o.TimeGiven ? o.Time : model.timeRange().first;
  if (t < model.time())
  {
    throw UserError(
      "--time: t = " + Number(t) + " is before the model's start (" + Number(model.time()) + ")");
  }
  model.advanceTo(t, EngineStep(o, model, 0, t, "--time"));
  const std::vector<engine::CellState> cells = CellsToSample(o, model);
  const std::size_t bytes = o.Double ? sizeof(double) : sizeof(float);
  const frep::Grid grid = PlanDynamicGrid(o, BoxOf(cells), cells.size() + 2, bytes);
  vtkSmartPointer<vtkImageData> image =
    SampleCells(cells, grid, o.Double, o.Threads, t, model.activeInstance());
  Write(image, o.Output);
  std::cout << "wrote " << o.Output << " (" << grid.dimensions[0] << " x " << grid.dimensions[1]
            << " x " << grid.dimensions[2] << " points; " << model.name() << " at t = " << t
            << ", instance " << model.activeInstance() << "; arrays: f";
  for (const engine::CellState& c : cells)
  {
    std::cout << ", " << c.name;
  }
  std::cout << ")\n";
  return 0;
}

/// --frames: the source of ictkTimeSeriesWriter, one image a requested time. The engine runs
/// forward through the times as the writer asks for them (a time before the engine's restarts
/// the model), every frame on the one grid planned for all of them.
class IcmFrameSource : public vtkImageAlgorithm
{
public:
  static IcmFrameSource* New();
  vtkTypeMacro(IcmFrameSource, vtkImageAlgorithm);

  const DynamicSampleOptions* Options = nullptr;
  frep::Grid Grid;
  std::vector<double> Times;
  double Step = 1;
  /// What stopped a frame (a ModelError, a UserError), rethrown once the writer returns.
  std::exception_ptr Error;

protected:
  IcmFrameSource() { this->SetNumberOfInputPorts(0); }

  int RequestInformation(
    vtkInformation*, vtkInformationVector**, vtkInformationVector* out) override
  {
    vtkInformation* info = out->GetInformationObject(0);
    const int extent[6] = { 0, static_cast<int>(this->Grid.dimensions[0]) - 1, 0,
      static_cast<int>(this->Grid.dimensions[1]) - 1, 0,
      static_cast<int>(this->Grid.dimensions[2]) - 1 };
    info->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), extent, 6);
    info->Set(vtkStreamingDemandDrivenPipeline::TIME_STEPS(), this->Times.data(),
      static_cast<int>(this->Times.size()));
    const double range[2] = { this->Times.front(), this->Times.back() };
    info->Set(vtkStreamingDemandDrivenPipeline::TIME_RANGE(), range, 2);
    return 1;
  }

  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector* out) override
  {
    vtkInformation* info = out->GetInformationObject(0);
    double t = this->Times.front();
    if (info->Has(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP()))
    {
      t = info->Get(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP());
    }
    try
    {
      if (Interrupted())
      {
        this->SetAbortExecute(1);
        return 1;
      }
      if (!this->Model || t < this->Model->time())
      {
        this->Model =
          std::make_unique<engine::DynamicModel>(engine::DynamicModel::load(this->Options->Model));
        this->Model->start();
      }
      this->Model->advanceTo(std::max(t, this->Model->time()), this->Step);
      vtkSmartPointer<vtkImageData> image =
        SampleCells(CellsToSample(*this->Options, *this->Model), this->Grid, this->Options->Double,
          this->Options->Threads, t, this->Model->activeInstance());
      vtkImageData* output = vtkImageData::GetData(out);
      output->ShallowCopy(image);
      output->GetInformation()->Set(vtkDataObject::DATA_TIME_STEP(), t);
      return 1;
    }
    catch (const Cancelled&)
    {
      this->SetAbortExecute(1);
      return 1;
    }
    catch (...)
    {
      this->Error = std::current_exception();
      vtkErrorMacro(<< "the frame at t = " << t << " failed");
      return 0;
    }
  }

private:
  std::unique_ptr<engine::DynamicModel> Model;
};

vtkStandardNewMacro(IcmFrameSource);

/// --frames T0:T1:DT: the cells at every time as a .pvd series of .vti frames, one grid for all
/// (--bounds, or the box of the sampled cells at every frame).
int SampleFrames(const DynamicSampleOptions& o, engine::DynamicModel& model)
{
  if (!HasExtension(o.Output, ".pvd"))
  {
    throw UserError("-o: with --frames the output is a .pvd series, not '" + o.Output + "'");
  }
  const std::vector<double> times = ParseFrames(o.Frames);
  if (times.front() < model.time())
  {
    throw UserError("--frames: T0 = " + Number(times.front()) + " is before the model's start (" +
      Number(model.time()) + ")");
  }
  double spacing = 0;
  for (std::size_t k = 1; k < times.size(); ++k)
  {
    const double d = times[k] - times[k - 1];
    spacing = spacing > 0 ? std::min(spacing, d) : d;
  }
  const double step = EngineStep(o, model, spacing, times.back(), "--frames");
  // The engine alone through the frames first (cheap beside the sampling): the box of every
  // frame's cells, and their largest count for the memory check.
  frep::Box3 box = EmptyBox();
  std::size_t arrays = 0;
  for (double t : times)
  {
    if (Interrupted())
    {
      throw Cancelled();
    }
    model.advanceTo(std::max(t, model.time()), step);
    const std::vector<engine::CellState> cells = CellsToSample(o, model);
    Grow(box, BoxOf(cells));
    arrays = std::max(arrays, cells.size() + 2);
  }
  const std::size_t bytes = o.Double ? sizeof(double) : sizeof(float);
  vtkNew<IcmFrameSource> source;
  source->Options = &o;
  source->Grid = PlanDynamicGrid(o, box, arrays, bytes);
  source->Times = times;
  source->Step = step;
  vtkNew<ictkTimeSeriesWriter> writer;
  writer->SetInputConnection(source->GetOutputPort());
  writer->SetFileName(o.Output.c_str());
  ictkCaptureOutputWindow* messages = CaptureVtkMessages();
  const std::size_t errorsBefore = messages->Errors.size();
  const int written = writer->Write();
  if (source->Error)
  {
    std::rethrow_exception(source->Error);
  }
  if (Interrupted())
  {
    throw Cancelled();
  }
  if (!written || messages->Errors.size() > errorsBefore)
  {
    throw UserError(messages->Errors.size() > errorsBefore
        ? messages->FirstCause(errorsBefore)
        : "cannot sample the frames into '" + o.Output + "'");
  }
  const frep::Grid& grid = source->Grid;
  std::cout << "wrote " << o.Output << " (" << times.size() << " frames of " << grid.dimensions[0]
            << " x " << grid.dimensions[1] << " x " << grid.dimensions[2]
            << " points, t = " << times.front() << " .. " << times.back() << ")\n";
  return 0;
}

/// --space-time: one 2D cell at every t of the time range as a 3D volume, z = t.
int SampleSpaceTime(const DynamicSampleOptions& o, engine::DynamicModel& model)
{
  if (o.TimeGiven)
  {
    throw UserError("--space-time samples the cell at every time of --bounds' z0,z1 (default the "
                    "model's time range); --time is one cross-section, without --space-time");
  }
  std::vector<engine::CellState> start = model.cells();
  std::string cell = o.Cell;
  if (cell.empty())
  {
    // The model's one space-time cell, when it has one.
    std::vector<std::string> spaceTime;
    for (const engine::CellState& c : start)
    {
      if (c.spaceTime && c.dimension == 2)
      {
        spaceTime.push_back(c.name);
      }
    }
    if (spaceTime.size() != 1)
    {
      throw UserError("--space-time samples one 2D cell over time: name it with --cell (the "
                      "cells at the start: " +
        Names(start) + ")");
    }
    cell = spaceTime[0];
  }
  // The time range: --bounds' z0,z1, else the model's.
  double t0 = 0, t1 = 0;
  if (!o.Bounds.empty())
  {
    std::array<double, 3> lo{}, hi{};
    ParseBounds(o.Bounds, lo, hi);
    t0 = lo[2];
    t1 = hi[2];
  }
  else
  {
    std::tie(t0, t1) = model.timeRange();
    if (!std::isfinite(t0) || !std::isfinite(t1))
    {
      throw UserError("--space-time: the model's time spans have no finite start and end; give "
                      "the time range as --bounds x0,x1,y0,y1,t0,t1");
    }
  }
  if (t0 < model.time())
  {
    throw UserError("--space-time: t0 = " + Number(t0) + " is before the model's start (" +
      Number(model.time()) + ")");
  }
  std::int64_t nt = o.Resolution;
  if (!o.Dims.empty())
  {
    nt = ParseDims(o.Dims)[2];
  }
  if (!(t1 > t0))
  {
    nt = 1;
  }
  if (nt < 1)
  {
    throw UserError(
      "--dims: NZ (the number of times) must be at least 1, got " + std::to_string(nt));
  }
  if (nt > 100000)
  {
    throw UserError("--space-time: " + std::to_string(nt) + " times is more than 100000");
  }
  const double dt = nt > 1 ? (t1 - t0) / static_cast<double>(nt - 1) : 0;
  const double step = EngineStep(o, model, dt, t1, "--space-time");
  // The cell's cross-section at every time, as the engine has it (its operands moved, its
  // numbers evaluated), kept to sample once the box holding all of them is known.
  std::vector<geometry::PlacedShapePtr> shapes(static_cast<std::size_t>(nt));
  frep::Box3 box = EmptyBox();
  bool seen = false;
  for (std::int64_t k = 0; k < nt; ++k)
  {
    if (Interrupted())
    {
      throw Cancelled();
    }
    const double t = k + 1 == nt ? t1 : t0 + static_cast<double>(k) * dt;
    model.advanceTo(std::max(t, model.time()), step);
    for (const engine::CellState& c : model.cells())
    {
      if (c.name != cell)
      {
        continue;
      }
      if (c.dimension != 2 || !HasField(c))
      {
        throw UserError("--space-time: " + cell + " is a " + std::to_string(c.dimension) +
          "D cell" +
          (c.dimension == 3 ? " (its space-time is 4D: sample its cross-sections "
                              "with --time t, or a series of them with --frames T0:T1:DT)"
                            : ", which has no 2D field") +
          "; --space-time takes a 2D cell, whose space-time is a 3D volume");
      }
      shapes[static_cast<std::size_t>(k)] = c.shape;
      Grow(box, c.shape->worldBounds());
      seen = true;
    }
  }
  if (!seen)
  {
    throw UserError("--cell: no cell '" + cell + "' in the model between t = " + Number(t0) +
      " and " + Number(t1) + " (the cells at the start: " + Names(start) + ")");
  }
  box.lo[2] = t0;
  box.hi[2] = t1;
  DynamicSampleOptions planned = o;
  if (!o.Bounds.empty())
  {
    planned.Bounds.clear();
    ParseBounds(o.Bounds, box.lo, box.hi);
  }
  const std::size_t bytes = o.Double ? sizeof(double) : sizeof(float);
  // One layer a time: PlanDynamicGrid gives the z axis nt points over [t0, t1] as planned above.
  const frep::Grid grid = PlanDynamicGrid(planned, box, 2, bytes);
  vtkSmartPointer<vtkImageData> image = MakeImage(grid);
  const vtkIdType n = static_cast<vtkIdType>(grid.dimensions[0] * grid.dimensions[1] * nt);
  std::vector<double> values(static_cast<std::size_t>(n), kAbsent);
  for (std::int64_t k = 0; k < nt; ++k)
  {
    if (Interrupted())
    {
      throw Cancelled();
    }
    if (const geometry::PlacedShapePtr& s = shapes[static_cast<std::size_t>(k)])
    {
      SampleLayers(grid, *geometry::worldField(*s), k, k + 1, true, o.Threads, values);
    }
  }
  vtkSmartPointer<vtkDataArray> f = MakeArray("f", n, o.Double);
  for (vtkIdType i = 0; i < n; ++i)
  {
    f->SetComponent(i, 0, values[static_cast<std::size_t>(i)]);
  }
  image->GetPointData()->AddArray(f);
  image->GetPointData()->SetActiveScalars("f");
  AddFieldData(image, "Cell", cell);
  AddFieldData(image, "ZAxis", "t");
  Write(image, o.Output);
  std::cout << "wrote " << o.Output << " (" << grid.dimensions[0] << " x " << grid.dimensions[1]
            << " x " << nt << " points; the space-time of " << cell << ", z = t from " << t0
            << " to " << t1 << ")\n";
  return 0;
}

} // namespace

int SampleDynamicModel(const DynamicSampleOptions& o)
{
  if (o.Frames.empty() && !HasExtension(o.Output, ".vti"))
  {
    throw UserError("-o: a .icm model is sampled into a .vti image, not '" + o.Output + "'");
  }
  if (!std::isfinite(o.Time))
  {
    throw UserError("--time must be a finite number");
  }
  if (!std::isfinite(o.MaxStep) || o.MaxStep < 0)
  {
    throw UserError("--max-step must be a finite number >= 0");
  }
  InterruptScope interrupts;
  try
  {
    engine::DynamicModel model = engine::DynamicModel::load(o.Model);
    model.start();
    return o.SpaceTime    ? SampleSpaceTime(o, model)
      : !o.Frames.empty() ? SampleFrames(o, model)
                          : SampleAtTime(o, model);
  }
  catch (const engine::ModelError& e)
  {
    throw AsParseError(e);
  }
  catch (const Cancelled&)
  {
    std::cerr << "ictk: interrupted; nothing written\n";
    return ExitInterrupted;
  }
}

} // namespace ictk::cli
