// SPDX-License-Identifier: BSD-3-Clause
// `ictk run`: runs a dynamic implicit complex (.icm) over a range of times and writes a .pvd time
// series of its discretised complexes (one .vtpc per frame), optionally with a JSON-lines trace
// of every evaluated time.
#include "Command.h"
#include "Options.h"
#include "Progress.h"

#include "Engine/CoherentDiscretizer.h"
#include "Engine/DynamicModel.h"
#include "FRep/Sampling.h"
#include "Lang/Diagnostics.h"
#include "ictkComplexSource.h"
#include "ictkDynamicComplexSource.h"

#include <vtkNew.h>
#include <vtkPartitionedDataSetCollection.h>
#include <vtkXMLPartitionedDataSetCollectionWriter.h>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
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

/// The engine's errors in the front ends' form (file:line:col, the source line and a caret), so
/// that a model that reads but does not build reports like one that does not read.
lang::ParseError AsParseError(const engine::ModelError& e)
{
  lang::Diagnostic d;
  d.where.file = e.file;
  d.where.line = e.pos.line;
  d.where.column = e.pos.column;
  d.message = e.message;
  std::ifstream in(e.file);
  std::string line;
  for (int i = 0; i < e.pos.line && std::getline(in, line); ++i)
  {
  }
  if (e.pos.line > 0 && in)
  {
    d.sourceLine = line;
  }
  return lang::ParseError({ d });
}

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

/// The frames folder's entries this command writes: <stem>_<digits>.vtpc and their pieces
/// folders <stem>_<digits>.
bool IsFrameEntry(const fs::directory_entry& entry, const std::string& stem)
{
  std::string name = entry.path().filename().string();
  const std::string prefix = stem + "_";
  if (name.rfind(prefix, 0) != 0)
  {
    return false;
  }
  name = name.substr(prefix.size());
  if (entry.is_regular_file() && HasExtension(name, ".vtpc"))
  {
    name = name.substr(0, name.size() - 5);
  }
  else if (!entry.is_directory())
  {
    return false;
  }
  return !name.empty() &&
    std::all_of(name.begin(), name.end(), [](unsigned char c) { return std::isdigit(c); });
}

/// Where the outputs go, checked before any work: the .pvd, its frames folder (named after its
/// stem, beside it) and the trace. Everything is written into a staging folder beside the .pvd
/// and moved into place at the end, so that an error or Ctrl-C leaves what was there untouched.
struct Outputs
{
  fs::path Pvd;
  fs::path Frames; ///< the frames folder
  std::string Stem;
  fs::path Staging;
  fs::path Trace;
  fs::path TraceTemporary;
  bool Committed = false;

  Outputs(const std::string& output, const std::string& trace)
  {
    if (!HasExtension(output, ".pvd"))
    {
      throw std::invalid_argument("-o: '" + output + "' is not a .pvd file");
    }
    Pvd = fs::absolute(output);
    Stem = Pvd.stem().string();
    Frames = Pvd.parent_path() / Stem;
    std::error_code ec;
    if (!fs::is_directory(Pvd.parent_path(), ec))
    {
      throw std::invalid_argument("cannot write '" + output + "': folder '" +
        Pvd.parent_path().string() + "' does not exist");
    }
    if (fs::is_directory(Pvd, ec))
    {
      throw std::invalid_argument("cannot write '" + output + "': it is a directory");
    }
    if (fs::exists(Frames, ec))
    {
      if (!fs::is_directory(Frames, ec))
      {
        throw std::invalid_argument("cannot write the frames of '" + output + "': '" +
          Frames.string() + "' is a file; move it or choose another name");
      }
      // Replace an earlier run's frames, never anything else.
      for (const auto& entry : fs::directory_iterator(Frames))
      {
        if (!IsFrameEntry(entry, Stem))
        {
          throw std::invalid_argument("cannot write the frames of '" + output + "': the folder '" +
            Frames.string() + "' holds other files ('" + entry.path().filename().string() +
            "'); move them or choose another name");
        }
      }
    }
    if (!trace.empty())
    {
      Trace = fs::absolute(trace);
      if (fs::is_directory(Trace, ec))
      {
        throw std::invalid_argument("--trace: cannot write '" + trace + "': it is a directory");
      }
      if (!fs::is_directory(Trace.parent_path(), ec))
      {
        throw std::invalid_argument("--trace: cannot write '" + trace + "': folder '" +
          Trace.parent_path().string() + "' does not exist");
      }
      TraceTemporary = Trace.parent_path() /
        ("." + Trace.filename().string() + ".ictk-" + std::to_string(::getpid()));
    }
    Staging = Pvd.parent_path() / (".ictk-run-" + Stem + "-" + std::to_string(::getpid()));
    fs::remove_all(Staging, ec);
    if (!fs::create_directory(Staging, ec) || !fs::create_directory(Staging / Stem, ec))
    {
      const std::string why = ec.message();
      fs::remove_all(Staging, ec);
      throw std::invalid_argument("cannot write '" + output + "': " + why);
    }
  }
  Outputs(const Outputs&) = delete;
  Outputs& operator=(const Outputs&) = delete;
  ~Outputs()
  {
    std::error_code ec;
    fs::remove_all(Staging, ec);
    if (!Committed && !TraceTemporary.empty())
    {
      fs::remove(TraceTemporary, ec);
    }
  }

  /// Moves everything into place; an earlier run's frames are replaced only once the new ones
  /// are there to take their place.
  void commit()
  {
    const fs::path old = Staging / ".previous";
    const bool hadFrames = fs::exists(Frames);
    if (hadFrames)
    {
      fs::rename(Frames, old);
    }
    try
    {
      fs::rename(Staging / Stem, Frames);
    }
    catch (...)
    {
      if (hadFrames)
      {
        std::error_code ec;
        fs::rename(old, Frames, ec);
      }
      throw;
    }
    fs::rename(Staging / (Stem + ".pvd"), Pvd);
    if (!TraceTemporary.empty())
    {
      fs::rename(TraceTemporary, Trace);
    }
    Committed = true;
  }
};

std::string XmlAttribute(const std::string& s)
{
  std::string out;
  for (char c : s)
  {
    switch (c)
    {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

struct Transition
{
  double time;
  std::string from;
  std::string to;
};

} // namespace

int RunModel(const RunModelOptions& o)
{
  const std::vector<double> times = ParseFrames(o.Frames, o.FramesOption);
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
  // Fail on an unwritable destination before spending time on the run.
  Outputs out(o.Output, o.Trace);
  const auto started = Clock::now();

  ProgressBar bar("run", false, !o.Json);
  std::size_t frame = 0;
  auto frameOf = [&]
  {
    return "frame " + std::to_string(frame + 1) + "/" + std::to_string(times.size());
  };
  engine::RunOptions runOptions;
  runOptions.progress = [&](double fraction)
  {
    bar.Show((double(frame) + 0.5 * fraction) / double(times.size()), frameOf());
    return !Interrupted();
  };
  engine::CoherenceOptions meshOptions;
  meshOptions.featureSize = o.FeatureSize;
  meshOptions.coherent = !o.NoCoherence;
  meshOptions.threads = o.Threads;
  meshOptions.progress = [&](double fraction)
  {
    bar.Show((double(frame) + 0.5 + 0.5 * fraction) / double(times.size()), frameOf());
    return !Interrupted();
  };

  InterruptScope interrupts;
  try
  {
    auto loadStart = Clock::now();
    engine::DynamicModel model = [&]
    {
      try
      {
        return engine::DynamicModel::load(o.Model, runOptions);
      }
      catch (const engine::ModelError& e)
      {
        throw AsParseError(e);
      }
    }();
    const double maxStep = o.MaxStep > 0 ? o.MaxStep : times.size() > 1 ? times[1] - times[0] : 1.0;
    std::ofstream trace;
    if (!out.TraceTemporary.empty())
    {
      trace.open(out.TraceTemporary, std::ios::binary);
      if (!trace)
      {
        throw std::invalid_argument("--trace: cannot write '" + o.Trace + "'");
      }
    }
    std::size_t records = 0;
    std::vector<Transition> transitions;
    std::string instance;
    auto record = [&](const engine::FrameRecord& r)
    {
      if (trace.is_open())
      {
        trace << TraceLine(r) << "\n";
      }
      ++records;
      if (!instance.empty() && r.instance != instance)
      {
        transitions.push_back({ r.time, instance, r.instance });
      }
      instance = r.instance;
    };
    double engineSeconds = 0, meshSeconds = 0, writeSeconds = 0;
    engine::CoherentDiscretizer mesher(meshOptions);
    try
    {
      record(model.start());
      if (times.front() < model.time())
      {
        std::ostringstream os;
        os << o.FramesOption << ": T0 = " << times.front() << " is before the model's start ("
           << model.time() << ")";
        throw std::invalid_argument(os.str());
      }
      if (!(o.FeatureSize > 0))
      {
        // From the model's start, so that the same model gives the same meshes whatever T0.
        mesher.setFeatureSize(complex::defaultFeatureSize(model.complex()));
      }
    }
    catch (const engine::ModelError& e)
    {
      throw AsParseError(e);
    }
    engineSeconds += Seconds(loadStart);

    const std::size_t digits = std::max<std::size_t>(4, std::to_string(times.size() - 1).size());
    std::ostringstream pvd;
    pvd << "<?xml version=\"1.0\"?>\n"
        << "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
        << "  <Collection>\n";
    vtkNew<vtkXMLPartitionedDataSetCollectionWriter> writer;
    // Raw appended data with LZ4: writing a frame should not cost more than computing it.
    writer->SetDataModeToAppended();
    writer->EncodeAppendedDataOff();
    writer->SetCompressorTypeToLZ4();
    for (frame = 0; frame < times.size(); ++frame)
    {
      const double t = times[frame];
      auto t0 = Clock::now();
      try
      {
        if (t > model.time())
        {
          for (const engine::FrameRecord& r : model.advanceTo(t, maxStep))
          {
            record(r);
          }
        }
        engineSeconds += Seconds(t0);
        t0 = Clock::now();
        const std::vector<engine::CellState> cells = model.cells();
        const ictk::complex::Complex k = model.complex();
        const ictk::complex::ComplexMesh mesh = mesher.discretize(cells, k);
        vtkNew<vtkPartitionedDataSetCollection> collection;
        ictkComplexSource::Convert(k, mesh, collection);
        ictkDynamicComplexSource::AddFrameFields(collection, model.activeInstance().c_str(), t);
        meshSeconds += Seconds(t0);

        t0 = Clock::now();
        std::ostringstream name;
        name << out.Stem << "_" << std::setw(static_cast<int>(digits)) << std::setfill('0') << frame
             << ".vtpc";
        writer->SetInputDataObject(collection);
        writer->SetFileName((out.Staging / out.Stem / name.str()).string().c_str());
        if (writer->Write() != 1 || writer->GetErrorCode() != 0)
        {
          throw std::runtime_error(
            "cannot write frame " + std::to_string(frame) + " of '" + o.Output + "'");
        }
        writeSeconds += Seconds(t0);
        pvd << "    <DataSet timestep=\"" << nlohmann::json(t).dump() << "\" file=\""
            << XmlAttribute(out.Stem + "/" + name.str()) << "\"/>\n";
      }
      catch (const engine::ModelError& e)
      {
        throw AsParseError(e);
      }
    }
    bar.End();
    pvd << "  </Collection>\n</VTKFile>\n";
    {
      std::ofstream file(out.Staging / (out.Stem + ".pvd"), std::ios::binary);
      file << pvd.str();
      if (!file.flush())
      {
        throw std::runtime_error("cannot write '" + o.Output + "'");
      }
    }
    if (trace.is_open())
    {
      trace.close();
      if (!trace)
      {
        throw std::runtime_error("--trace: cannot write '" + o.Trace + "'");
      }
    }
    out.commit();
    const double seconds = Seconds(started);

    const engine::CoherenceStats& stats = mesher.total();
    if (o.Json)
    {
      nlohmann::ordered_json j;
      j["output"] = o.Output;
      j["frames_folder"] = out.Frames.string();
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
      j["final_instance"] = model.activeInstance();
      j["seconds"] = seconds;
      j["engine_seconds"] = engineSeconds;
      j["mesh_seconds"] = meshSeconds;
      j["write_seconds"] = writeSeconds;
      j["feature_size"] = mesher.featureSize();
      j["max_step"] = maxStep;
      j["coherence"] = { { "enabled", !o.NoCoherence }, { "computed", stats.computed },
        { "moved", stats.moved }, { "reused", stats.reused } };
      std::cout << j.dump(2) << "\n";
      return 0;
    }
    std::cout << "wrote " << o.Output << " (" << times.size() << " frames, t = " << times.front()
              << " .. " << times.back() << ", in " << out.Frames.filename().string() << "/)";
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
              << "cells meshed " << stats.computed << ", moved " << stats.moved << ", reused "
              << stats.reused << " (time coherence " << (o.NoCoherence ? "off" : "on")
              << ", feature size " << std::setprecision(6) << mesher.featureSize() << ")\n";
    return 0;
  }
  catch (const Cancelled&)
  {
    bar.End();
    std::cerr << "ictk: interrupted; nothing written\n";
    return ExitInterrupted;
  }
  catch (...)
  {
    bar.End();
    throw;
  }
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
    this->FramesOption =
      AddFrames(run, o.Frames, "Frames T0:T1:DT, e.g. 0:10:0.1 (T1 included); required");
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
    if (this->FramesOption->count() == 0 && this->TimeOption->count() == 0)
    {
      throw UserError("--frames is required (see ictk --help)");
    }
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
