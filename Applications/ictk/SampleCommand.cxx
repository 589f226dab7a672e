// SPDX-License-Identifier: BSD-3-Clause
// `ictk sample`: a model sampled on a regular grid into a .vti (f and the attributes), optionally
// with its surface f = 0; or, with -o name.vdb, only the narrow band |f| <= band into a sparse
// OpenVDB grid (voxel::sampleNarrowBand), whose memory follows the surface. A dynamic model (.icm)
// is sampled by DynamicSampling.h.
#include "Command.h"
#include "DynamicSampling.h"
#include "GridSampling.h"
#include "Options.h"
#include "Output.h"
#include "ProgressDisplay.h"
#include "VtkMessages.h"

#include "FRep/Field.h"
#include "Voxel/NarrowBand.h"

#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkXMLImageDataWriter.h>

#include <CLI/CLI.hpp>

#include <chrono>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>

namespace ictk::cli
{
namespace
{

struct SampleCommandOptions : GridCommandOptions
{
  bool Double = false;
  std::string Surface;
  std::string Frames;
  double Band = 0;
  std::string Cell;
  double MaxStep = 0;
};

class SampleCommand final : public Command
{
public:
  CLI::App* add(CLI::App& app) override
  {
    CLI::App* sample = app.add_subcommand("sample",
      "Sample a model on a regular grid (.vti), or its narrow band (.vdb). A dynamic model "
      "(.icm) is run by the engine to --time (default: its start) and the active instance's "
      "cells with a field (2D or 3D, not meshes; a space-time cell at its cross-section) are "
      "sampled, one array per cell and f, their largest (the union); with --space-time, one 2D "
      "cell (--cell) at every time of the model's time range (or --bounds' z0,z1) as a 3D volume "
      "whose z is t");
    o.AddTo(sample, 64,
      "Model name (see `ictk models`), a .hf / .xml / .vm / .blob file, or a dynamic model "
      "(.icm)");
    AddOutput(sample, o.Output,
      "Output image (.vti), or a sparse OpenVDB grid of the narrow band (.vdb, see --band)");
    sample->add_flag("--double", o.Double, "Write double-precision arrays (default float)");
    CLI::Option* surface = sample->add_option("--surface", o.Surface,
      "Also extract the surface f = 0 (Flying Edges) into this .vtp, .stl, .ply or .obj");
    CLI::Option* frames = AddFrames(sample, o.Frames,
      "a space-time model (XYZT, XYT), an animated .blob or a .icm model (its cells, as at "
      "--time) at every time, as a .pvd series of .vti frames (-o name.pvd; the frames go into a "
      "folder named after it)");
    CLI::Option* band = sample->add_option("--band", o.Band,
      "With -o name.vdb: keep the points where |f| <= W (in f's units; a distance for a distance "
      "field); default 3 grid spacings");
    band->check(CLI::PositiveNumber);
    sample->add_option("--cell", o.Cell,
      "A .icm model: sample only this cell (with --space-time: the 2D cell whose space-time is "
      "sampled; default the model's one space-time 2D cell)");
    sample->add_option("--max-step", o.MaxStep,
      "A .icm model: the engine's largest step on the way to --time (default: 1/100 of the "
      "model's time range, as `ictk run`; with --space-time the spacing of the times)");
    frames->excludes(surface);
    frames->excludes(band);
    frames->excludes(sample->get_option("--time"));
    frames->excludes(sample->get_option("--space-time"));
    return sample;
  }

  int run() override
  {
    if (HasExtension(o.Model, ".icm"))
    {
      return runDynamic();
    }
    if (!o.Cell.empty() || o.MaxStep != 0)
    {
      throw UserError(std::string(!o.Cell.empty() ? "--cell" : "--max-step") +
        " is for a dynamic model (.icm); '" + o.Model + "' is not one");
    }
    if (!o.Surface.empty() && !IsSurfaceFormat(o.Surface))
    {
      throw UserError("--surface: '" + o.Surface + "' is not a " + SurfaceFormats + " file");
    }
    if (HasExtension(o.Output, ".vdb"))
    {
      return runNarrowBand();
    }
    if (o.Band > 0)
    {
      throw UserError(
        "--band: the narrow band is written to a .vdb (-o name.vdb), not '" + o.Output + "'");
    }
    const std::vector<double> times =
      o.Frames.empty() ? std::vector<double>{} : ParseFrames(o.Frames);
    const GridPlan plan = PlanGrid(o, o.Double ? sizeof(double) : sizeof(float), times);
    if (!o.Frames.empty())
    {
      return runFrames(plan, times);
    }
    if (!o.Surface.empty())
    {
      CheckSurfaceGrid(plan, o.Surface, "--surface");
    }
    // Fail on an unwritable destination before spending time on sampling.
    InterruptScope interrupts;
    AtomicOutput volumeFile(o.Output);
    std::unique_ptr<AtomicOutput> surfaceFile;
    if (!o.Surface.empty())
    {
      surfaceFile = std::make_unique<AtomicOutput>(o.Surface);
    }
    ictkCaptureOutputWindow* messages = CaptureVtkMessages();

    const auto t0 = std::chrono::steady_clock::now();
    vtkSmartPointer<vtkImageData> image = SampleImage(plan, o.Threads, o.Double, true, messages);
    if (!image)
    {
      std::cerr << "ictk: interrupted; nothing written\n";
      return ExitInterrupted;
    }
    const double sampleSeconds = Seconds(t0);

    const auto t1 = std::chrono::steady_clock::now();
    vtkNew<vtkXMLImageDataWriter> writer;
    writer->SetDataModeToAppended();
    writer->EncodeAppendedDataOff();
    const std::size_t errorsBefore = messages->Errors.size();
    WriteXml(writer, image, volumeFile);
    ThrowIfVtkFailed(messages, errorsBefore, "cannot write '" + o.Output + "'");
    volumeFile.Commit();
    const double writeSeconds = Seconds(t1);

    std::cout << "wrote " << o.Output << " (" << plan.Dims[0] << " x " << plan.Dims[1] << " x "
              << plan.Dims[2] << " points; arrays:";
    vtkPointData* pd = image->GetPointData();
    for (int i = 0; i < pd->GetNumberOfArrays(); ++i)
    {
      std::cout << (i ? ", " : " ") << pd->GetArrayName(i);
    }
    std::cout << ") in " << std::fixed << std::setprecision(3) << sampleSeconds + writeSeconds
              << " s (sampling " << sampleSeconds << " s, writing " << writeSeconds << " s)\n";

    if (surfaceFile)
    {
      const auto t2 = std::chrono::steady_clock::now();
      vtkSmartPointer<vtkPolyData> surface = ExtractSurface(image, plan, messages);
      WriteSurface(surface, *surfaceFile, o.Surface, messages);
      std::cout << "wrote " << o.Surface << " (" << SurfaceSummary(surface) << ") in "
                << Seconds(t2) << " s\n";
    }
    return 0;
  }

private:
  /// A .icm model (DynamicSampling.h): its cells at --time, or one 2D cell's space-time.
  int runDynamic()
  {
    const char* refused = !o.Surface.empty() ? "--surface"
      : o.Band > 0                           ? "--band"
      : !o.Params.empty()                    ? "--params"
                                             : nullptr;
    if (refused)
    {
      throw UserError(std::string(refused) + " is not for a dynamic model (.icm): it is sampled " +
        "at --time into a .vti, at every time of --frames into a .pvd, or over its time range " +
        "with --space-time; `ictk run` writes its frames' meshes");
    }
    CheckThreads(o.Threads);
    DynamicSampleOptions d;
    d.Model = o.Model;
    d.Output = o.Output;
    d.Cell = o.Cell;
    d.Bounds = o.Bounds;
    d.Dims = o.Dims;
    d.Frames = o.Frames;
    d.Resolution = o.Resolution;
    d.Time = o.Time;
    d.TimeGiven = o.TimeOption && o.TimeOption->count() > 0;
    d.SpaceTime = o.SpaceTime;
    d.Double = o.Double;
    d.MaxStep = o.MaxStep;
    d.Threads = o.Threads;
    return SampleDynamicModel(d);
  }

  /// -o name.vdb: the narrow band into a sparse OpenVDB grid (f only; no attributes, no dense
  /// memory budget: memory follows the band).
  int runNarrowBand()
  {
    if (!o.Frames.empty() || !o.Surface.empty() || o.Double)
    {
      throw UserError(std::string("-o: a .vdb holds the narrow band of f in float; ") +
        (!o.Frames.empty()       ? "--frames"
            : !o.Surface.empty() ? "--surface"
                                 : "--double") +
        " needs a .vti (or .pvd) output");
    }
    const GridPlan plan = PlanGrid(o, 0);
    InterruptScope interrupts;
    AtomicOutput file(o.Output);
    const auto t0 = std::chrono::steady_clock::now();
    voxel::NarrowBandOptions options;
    options.band = o.Band;
    options.threads = o.Threads;
    options.parameters = plan.Params;
    ProgressBar bar("sampling the band of " + plan.Model.Name, true);
    options.progress = [&](double fraction)
    {
      bar.Show(fraction);
      return !Interrupted();
    };
    std::optional<voxel::NarrowBandGrid> band;
    try
    {
      band = voxel::sampleNarrowBand(
        frep::Tape::compile(plan.Model.Model.geometry().function()), plan.Grid, options);
    }
    catch (const Cancelled&)
    {
      bar.End();
      std::cerr << "ictk: interrupted; nothing written\n";
      return ExitInterrupted;
    }
    catch (const std::invalid_argument& e)
    {
      bar.End();
      throw UserError(std::string("cannot sample: ") + e.what());
    }
    bar.End();
    const double sampleSeconds = Seconds(t0);
    const auto t1 = std::chrono::steady_clock::now();
    try
    {
      band->write(file.Path(), "f");
    }
    catch (const std::runtime_error& e)
    {
      file.Fail(e.what());
    }
    file.Commit();
    std::cout << "wrote " << o.Output << " (narrow band |f| <= " << band->band() << " of "
              << plan.Dims[0] << " x " << plan.Dims[1] << " x " << plan.Dims[2]
              << " points: " << band->activeVoxelCount() << " active voxels, " << std::fixed
              << std::setprecision(1) << static_cast<double>(band->memoryBytes()) / 1e6
              << " MB in memory) in " << std::setprecision(3) << sampleSeconds + Seconds(t1)
              << " s (sampling " << sampleSeconds << " s, writing " << Seconds(t1) << " s)\n";
    return 0;
  }

  /// --frames: the grid at every time, written as a .pvd series (issue 16: a 4D field sampled
  /// as a whole, a series of 3D frames).
  int runFrames(const GridPlan& plan, const std::vector<double>& times)
  {
    if (!HasExtension(o.Output, ".pvd"))
    {
      throw UserError("-o: with --frames the output is a .pvd series, not '" + o.Output + "'");
    }
    InterruptScope interrupts;
    ictkCaptureOutputWindow* messages = CaptureVtkMessages();
    const auto t0 = std::chrono::steady_clock::now();
    if (!SampleSeries(plan, o.Threads, o.Double, times, o.Output, messages))
    {
      std::cerr << "ictk: interrupted; nothing written\n";
      return ExitInterrupted;
    }
    std::cout << "wrote " << o.Output << " (" << times.size() << " frames of " << plan.Dims[0]
              << " x " << plan.Dims[1] << " x " << plan.Dims[2] << " points, t = " << times.front()
              << " .. " << times.back() << ") in " << std::fixed << std::setprecision(3)
              << Seconds(t0) << " s\n";
    return 0;
  }

  SampleCommandOptions o;
};

} // namespace

std::unique_ptr<Command> sampleCommand()
{
  return std::make_unique<SampleCommand>();
}

} // namespace ictk::cli
