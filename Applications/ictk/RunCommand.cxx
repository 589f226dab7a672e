// SPDX-License-Identifier: BSD-3-Clause
// `ictk run`: runs a dynamic implicit complex (.icm) over a range of times (by default its time
// spans' range in 100 steps) and writes a .pvd time series of its discretised complexes (one
// .vtpc per frame), optionally with a JSON-lines trace of every evaluated time. The run is the
// dynamic complex source written by the time series writer (Engine/FrameSequence.h is their one
// frame loop); this file adds the trace, the progress display, Ctrl-C and the summary.
#include "Command.h"
#include "Models.h"
#include "Options.h"
#include "ProgressDisplay.h"
#include "VtkMessages.h"

#include "Engine/DynamicModel.h"
#include "Engine/FrameSequence.h"
#include "Lang/Diagnostics.h"
#include "ictkDynamicComplexSource.h"
#include "ictkTimeSeriesWriter.h"

#include <vtkCallbackCommand.h>
#include <vtkCommand.h>
#include <vtkExecutive.h>
#include <vtkInformation.h>
#include <vtkNew.h>
#include <vtkStreamingDemandDrivenPipeline.h>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>
#include <stdexcept>

namespace ictk::cli
{
namespace
{

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

struct RunModelOptions
{
  std::string Model;
  std::string Frames;                    ///< T0:T1:DT
  std::string FramesOption = "--frames"; ///< the name it was given under, for messages
  std::string Output;
  std::string Trace;
  double FeatureSize = 0;
  double MaxStep = 0;
  bool NoCoherence = false;
  bool Json = false;
  int Threads = 0;
};

std::string TraceLine(const engine::FrameRecord& r)
{
  std::string line = "{\"time\":" + nlohmann::json(r.time).dump() +
    ",\"instance\":" + nlohmann::json(r.instance).dump() +
    ",\"transition\":" + (r.transition ? "true" : "false") +
    ",\"events\":" + nlohmann::json(r.events).dump() + ",\"state\":{";
  for (std::size_t i = 0; i < r.state.size(); ++i)
  {
    line +=
      (i ? "," : "") + nlohmann::json(r.state[i].first).dump() + ":" + r.state[i].second.toJson();
  }
  return line + "}}";
}

/// The trace's destination, checked before any work, and the temporary file beside it that it is
/// written to; moved into place only once the series is written, removed otherwise.
struct TraceFile
{
  fs::path Trace;
  fs::path Temporary;
  std::ofstream Stream;
  bool Committed = false;

  explicit TraceFile(const std::string& trace)
  {
    if (trace.empty())
    {
      return;
    }
    Trace = fs::absolute(trace);
    std::error_code ec;
    if (fs::is_directory(Trace, ec))
    {
      throw std::invalid_argument("--trace: cannot write '" + trace + "': it is a directory");
    }
    if (!fs::is_directory(Trace.parent_path(), ec))
    {
      throw std::invalid_argument("--trace: cannot write '" + trace + "': folder '" +
        Trace.parent_path().string() + "' does not exist");
    }
    Temporary = Trace.parent_path() /
      ("." + Trace.filename().string() + ".ictk-" + std::to_string(::getpid()));
  }
  TraceFile(const TraceFile&) = delete;
  TraceFile& operator=(const TraceFile&) = delete;
  ~TraceFile()
  {
    if (!Committed && !Temporary.empty())
    {
      Stream.close();
      std::error_code ec;
      fs::remove(Temporary, ec);
    }
  }
  bool enabled() const { return !Temporary.empty(); }
};

/// Calls `f(event, callData)` on events of a VTK object for as long as it lives.
class Observer
{
public:
  using Function = std::function<void(unsigned long, void*)>;
  Observer(vtkObject* object, std::initializer_list<unsigned long> events, Function f)
    : object_(object)
    , f_(std::make_unique<Function>(std::move(f)))
  {
    command_->SetClientData(f_.get());
    command_->SetCallback([](vtkObject*, unsigned long event, void* clientData, void* callData)
      { (*static_cast<Function*>(clientData))(event, callData); });
    for (unsigned long event : events)
    {
      tags_.push_back(object->AddObserver(event, command_));
    }
  }
  ~Observer()
  {
    for (unsigned long tag : tags_)
    {
      object_->RemoveObserver(tag);
    }
  }
  Observer(const Observer&) = delete;
  Observer& operator=(const Observer&) = delete;

private:
  vtkObject* object_;
  std::unique_ptr<Function> f_;
  vtkNew<vtkCallbackCommand> command_;
  std::vector<unsigned long> tags_;
};

struct Transition
{
  double time;
  std::string from;
  std::string to;
};

} // namespace

int RunModel(const RunModelOptions& o)
{
  // Without --frames, the source's default: the model's time range in 100 steps.
  std::vector<double> times;
  if (!o.Frames.empty())
  {
    times = ParseFrames(o.Frames, o.FramesOption);
  }
  CheckSize(o.FeatureSize);
  if (!std::isfinite(o.MaxStep) || o.MaxStep < 0)
  {
    throw std::invalid_argument("--max-step must be a finite number >= 0");
  }
  CheckThreads(o.Threads);
  if (!HasExtension(o.Model, ".icm"))
  {
    throw std::invalid_argument("'" + o.Model + "' is not a .icm model");
  }
  if (!HasExtension(o.Output, ".pvd"))
  {
    throw std::invalid_argument("-o: '" + o.Output + "' is not a .pvd file");
  }
  TraceFile trace(o.Trace);
  const auto started = Clock::now();
  double maxStep = o.MaxStep > 0 ? o.MaxStep : times.size() > 1 ? times[1] - times[0] : 0.0;

  // The run is the dynamic complex source (the engine's frames) written by the time series
  // writer; this command adds the trace, the progress display, Ctrl-C and the summary.
  vtkNew<ictkDynamicComplexSource> source;
  source->SetFileName(o.Model.c_str());
  if (!times.empty())
  {
    source->SetTimeSteps(times.data(), static_cast<int>(times.size()));
  }
  source->SetMaximumStep(maxStep);
  source->SetFeatureSize(o.FeatureSize);
  source->SetCoherent(!o.NoCoherence);
  source->SetNumberOfThreads(o.Threads);
  vtkNew<ictkTimeSeriesWriter> writer;
  writer->SetInputConnection(source->GetOutputPort());
  writer->SetFileName(o.Output.c_str());

  // VTK's errors become this command's (the first one, kept rather than printed).
  ictkCaptureOutputWindow* messages = CaptureVtkMessages();
  const std::size_t errorsBefore = messages->Errors.size();
  auto failure = [&]
  {
    return messages->FirstCause(errorsBefore);
  };
  // A model error in the front ends' form, with the source line and a caret.
  auto rethrowModelError = [&]
  {
    if (const std::exception_ptr e = source->GetLastError())
    {
      try
      {
        std::rethrow_exception(e);
      }
      catch (const engine::ModelError& m)
      {
        throw AsParseError(m);
      }
    }
  };

  InterruptScope interrupts;
  const auto loadStart = Clock::now();
  source->UpdateInformation();
  rethrowModelError();
  if (!failure().empty())
  {
    throw std::runtime_error(failure());
  }
  if (times.empty())
  {
    vtkInformation* info = source->GetOutputInformation(0);
    const double* steps = info->Get(vtkStreamingDemandDrivenPipeline::TIME_STEPS());
    times.assign(steps, steps + info->Length(vtkStreamingDemandDrivenPipeline::TIME_STEPS()));
    if (times.size() < 2)
    {
      throw std::invalid_argument("the model's time spans give no time range to run (no "
                                  "TIMESPAN with a finite start and end): give --frames T0:T1:DT");
    }
    // The engine's largest step is then the frames' spacing (FrameSequence's default).
    for (std::size_t i = 1; o.MaxStep <= 0 && i < times.size(); ++i)
    {
      maxStep = i == 1 ? times[1] - times[0] : std::min(maxStep, times[i] - times[i - 1]);
    }
  }
  if (times.front() < source->GetStartTime())
  {
    std::ostringstream os;
    os << o.FramesOption << ": T0 = " << times.front() << " is before the model's start ("
       << source->GetStartTime() << ")";
    throw std::invalid_argument(os.str());
  }
  // The engine's steps are set by --max-step, else by the frames' spacing: bounded as the frames
  // are (ParseFrames).
  if (o.MaxStep > 0)
  {
    CheckEngineSteps(
      source->GetStartTime(), times.back(), o.MaxStep, "--max-step", "a larger --max-step?");
  }
  double engineSeconds = Seconds(loadStart), meshSeconds = 0;

  // Every frame the source computes: its share of the progress (engine, then meshing, as the
  // source reports them), its timing, and its records for the trace and the summary.
  ProgressBar bar("run", false, !o.Json);
  struct Run
  {
    std::size_t frame = 0;
    Clock::time_point start;
    Clock::time_point meshStart;
    bool meshing = false;
    std::size_t records = 0;
    std::vector<Transition> transitions;
    std::string instance;
    std::string traceError;
  } run;
  if (trace.enabled())
  {
    trace.Stream.open(trace.Temporary, std::ios::binary);
    if (!trace.Stream)
    {
      throw std::invalid_argument("--trace: cannot write '" + o.Trace + "'");
    }
  }
  auto cancelIfInterrupted = [&]
  {
    if (Interrupted() || !run.traceError.empty())
    {
      source->SetAbortExecute(1);
      writer->SetAbortExecute(1);
    }
  };
  auto onStart = [&]
  {
    run.start = Clock::now();
    run.meshing = false;
  };
  auto onProgress = [&](double fraction)
  {
    if (!run.meshing && fraction >= 0.5)
    {
      run.meshStart = Clock::now();
      run.meshing = true;
    }
    bar.Show((double(run.frame) + fraction) / double(times.size()),
      "frame " + std::to_string(run.frame + 1) + "/" + std::to_string(times.size()));
    cancelIfInterrupted();
  };
  auto onEnd = [&]
  {
    const auto now = Clock::now();
    engineSeconds +=
      std::chrono::duration<double>((run.meshing ? run.meshStart : now) - run.start).count();
    meshSeconds += run.meshing ? std::chrono::duration<double>(now - run.meshStart).count() : 0;
    for (const engine::FrameRecord& r : source->GetFrameRecords())
    {
      if (trace.Stream.is_open())
      {
        trace.Stream << TraceLine(r) << "\n";
      }
      ++run.records;
      if (!run.instance.empty() && r.instance != run.instance)
      {
        run.transitions.push_back({ r.time, run.instance, r.instance });
      }
      run.instance = r.instance;
    }
    ++run.frame;
    if (trace.Stream.is_open() && run.frame == times.size())
    {
      trace.Stream.close();
    }
    if (trace.enabled() && !trace.Stream)
    {
      run.traceError = "--trace: cannot write '" + o.Trace + "'";
    }
    cancelIfInterrupted();
  };
  const Observer sourceEvents(source,
    { vtkCommand::StartEvent, vtkCommand::ProgressEvent, vtkCommand::EndEvent },
    [&](unsigned long event, void* callData)
    {
      if (event == vtkCommand::StartEvent)
      {
        onStart();
      }
      else if (event == vtkCommand::ProgressEvent)
      {
        onProgress(*static_cast<double*>(callData));
      }
      else
      {
        onEnd();
      }
    });
  const Observer writerEvents(
    writer, { vtkCommand::ProgressEvent }, [&](unsigned long, void*) { cancelIfInterrupted(); });

  const auto writeStart = Clock::now();
  const double computedBefore = engineSeconds + meshSeconds;
  const int written = writer->Write();
  bar.End();
  const double writeSeconds =
    std::max(0.0, Seconds(writeStart) - (engineSeconds + meshSeconds - computedBefore));
  if (!written)
  {
    if (!run.traceError.empty())
    {
      throw std::runtime_error(run.traceError);
    }
    if (Interrupted())
    {
      std::cerr << "ictk: interrupted; nothing written\n";
      return ExitInterrupted;
    }
    rethrowModelError();
    throw std::runtime_error(failure().empty() ? "cannot write '" + o.Output + "'" : failure());
  }
  if (trace.enabled())
  {
    fs::rename(trace.Temporary, trace.Trace);
    trace.Committed = true;
  }
  const double seconds = Seconds(started);
  const fs::path frames = fs::absolute(o.Output).parent_path() / fs::path(o.Output).stem();
  const std::size_t records = run.records;
  const std::vector<Transition>& transitions = run.transitions;
  const bool coherent = !o.NoCoherence;
  const std::size_t computed = static_cast<std::size_t>(source->GetTotalCellsComputed());
  const std::size_t moved = static_cast<std::size_t>(source->GetTotalCellsMoved());
  const std::size_t reused = static_cast<std::size_t>(source->GetTotalCellsReused());
  if (o.Json)
  {
    nlohmann::ordered_json j;
    j["output"] = o.Output;
    j["frames_folder"] = frames.string();
    j["frames"] = times.size();
    j["t0"] = times.front();
    j["t1"] = times.back();
    j["records"] = records;
    if (!o.Trace.empty())
    {
      j["trace"] = o.Trace;
    }
    j["transitions"] = nlohmann::ordered_json::array();
    for (const Transition& tr : transitions)
    {
      j["transitions"].push_back({ { "time", tr.time }, { "from", tr.from }, { "to", tr.to } });
    }
    j["final_instance"] = source->GetInstanceName();
    j["seconds"] = seconds;
    j["engine_seconds"] = engineSeconds;
    j["mesh_seconds"] = meshSeconds;
    j["write_seconds"] = writeSeconds;
    j["feature_size"] = source->GetFeatureSizeInUse();
    j["max_step"] = maxStep;
    j["coherence"] = { { "enabled", coherent }, { "computed", computed }, { "moved", moved },
      { "reused", reused } };
    std::cout << j.dump(2) << "\n";
    return 0;
  }
  std::cout << "wrote " << o.Output << " (" << times.size() << " frames, t = " << times.front()
            << " .. " << times.back() << ", in " << frames.filename().string() << "/)";
  if (!o.Trace.empty())
  {
    std::cout << " and " << o.Trace << " (" << records << " records)";
  }
  std::cout << std::fixed << std::setprecision(3) << " in " << seconds << " s (engine "
            << engineSeconds << " s, meshing " << meshSeconds << " s, writing " << writeSeconds
            << " s)\n";
  std::cout << std::defaultfloat << std::setprecision(10) << transitions.size() << " transition"
            << (transitions.size() == 1 ? "" : "s");
  // The first few: a model that switches instances often would bury the rest of the summary
  // (the trace and --json have them all).
  const std::size_t shown = std::min<std::size_t>(transitions.size(), 8);
  for (std::size_t i = 0; i < shown; ++i)
  {
    std::cout << (i ? ", " : ": ") << transitions[i].from << " -> " << transitions[i].to
              << " at t = " << transitions[i].time;
  }
  if (shown < transitions.size())
  {
    std::cout << ", ... (" << transitions.size() - shown << " more)";
  }
  std::cout << "\n"
            << "cells meshed " << computed << ", moved " << moved << ", reused " << reused
            << " (time coherence " << (o.NoCoherence ? "off" : "on") << ", feature size "
            << std::setprecision(6) << source->GetFeatureSizeInUse() << ")\n";
  return 0;
}

namespace
{

class RunCommand final : public Command
{
public:
  CLI::App* add(CLI::App& app) override
  {
    CLI::App* run = app.add_subcommand("run",
      "Run a dynamic implicit complex (.icm) and write its discretised complex at every frame as a "
      ".pvd time series (one .vtpc per frame)");
    AddModel(run, o.Model, "The .icm model");
    this->FramesOption = AddFrames(run, o.Frames,
      "Frames T0:T1:DT, e.g. 0:10:0.1 (T1 included); default: the model's time range (the "
      "union of its time spans) in 100 steps");
    // The older spelling, from before --time meant an instant in every command.
    this->TimeOption = run->add_option("--time", o.Frames, "The same as --frames (older spelling)");
    this->FramesOption->excludes(this->TimeOption);
    AddOutput(
      run, o.Output, "The .pvd file; the frames go into a folder named after it, beside it");
    run->add_option("--trace", o.Trace,
      "Also write a JSON-lines trace: one object per evaluated time (frames and located "
      "transitions) with time, instance, transition, events and state");
    AddSize(run, o.FeatureSize,
      "Mesh edge length and curve step, the same for every frame (default: 1/64 of the "
      "complex's size at the model's start)");
    run->add_option("--max-step", o.MaxStep, "The engine's largest time step (default: DT)");
    run->add_flag("--no-coherence", o.NoCoherence,
      "Re-mesh every cell of every frame instead of moving the meshes of unchanged cells");
    AddThreads(run, o.Threads, "Threads for the discretisers (default: all cores)");
    AddJson(run, o.Json, "Print the summary as JSON");
    return run;
  }

  int run() override
  {
    o.FramesOption = this->TimeOption->count() > 0 ? "--time" : "--frames";
    return RunModel(o);
  }

private:
  RunModelOptions o;
  CLI::Option* FramesOption = nullptr;
  CLI::Option* TimeOption = nullptr;
};

} // namespace

std::unique_ptr<Command> runCommand()
{
  return std::make_unique<RunCommand>();
}

} // namespace ictk::cli
