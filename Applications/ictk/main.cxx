// SPDX-License-Identifier: BSD-3-Clause
// ictk: the command-line face of ICTK.
//
//   ictk models                         list the registered models
//   ictk eval MODEL --at x,y,z[,t]      value (and with --json gradient, normal, membership,
//                                       attributes) at a point
//   ictk sample MODEL -o out.vti        sample on a grid (.vti), optionally extract the surface
//   ictk run MODEL.icm --time T0:T1:DT -o out.pvd
//                                       run a dynamic complex, one .vtpc per frame (RunCommand.cxx)
//
// Every user error ends in one line "ictk: error: ..." on stderr and exit code 2; nothing is
// left half-written (outputs go to a temporary file in the target folder, renamed on success).

#include "ComplexCommands.h"
#include "FRep/Bounds.h"
#include "FRep/Evaluators.h"
#include "FRep/Hypervolume.h"
#include "FRep/ModelRegistry.h"
#include "FRep/Sampling.h"
#include "Lang/ModelFile.h"
#include "RunCommand.h"
#include "TetraCommand.h"

#include "Bench.h"
#include "ictkFRepSampler.h"

#include <vtkCallbackCommand.h>
#include <vtkCommand.h>
#include <vtkDataObject.h>
#include <vtkFloatArray.h>
#include <vtkFlyingEdges3D.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkOBJWriter.h>
#include <vtkObjectFactory.h>
#include <vtkOutputWindow.h>
#include <vtkPLYWriter.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkSMPTools.h>
#include <vtkSTLWriter.h>
#include <vtkSmartPointer.h>
#include <vtkXMLImageDataWriter.h>
#include <vtkXMLPolyDataWriter.h>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <climits>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace frep = ictk::frep;
namespace lang = ictk::lang;
namespace fs = std::filesystem;

namespace
{

/// A user error: reported as one line, exit code 2.
class UserError : public std::runtime_error
{
public:
  using std::runtime_error::runtime_error;
};

/// A model file's diagnostics: already "file:line:col: error: ..." lines, printed as they are.
class ModelFileError : public UserError
{
public:
  using UserError::UserError;
};

constexpr int ExitUserError = 2;
constexpr int ExitInterrupted = 130;

// --- parsing ------------------------------------------------------------------------------------

std::string Trim(const std::string& s)
{
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos)
  {
    return {};
  }
  const auto e = s.find_last_not_of(" \t");
  return s.substr(b, e - b + 1);
}

std::vector<std::string> SplitCommas(const std::string& text)
{
  std::vector<std::string> fields;
  std::string::size_type start = 0;
  while (true)
  {
    const auto comma = text.find(',', start);
    fields.push_back(Trim(text.substr(start, comma == std::string::npos ? comma : comma - start)));
    if (comma == std::string::npos)
    {
      return fields;
    }
    start = comma + 1;
  }
}

/// Parses a comma-separated list of finite numbers. `names` names the fields for messages (e.g.
/// x, y, z); fields beyond it are called "value N".
std::vector<double> ParseNumbers(const std::string& text, const std::string& option,
  const std::vector<std::string>& names, std::size_t minCount, std::size_t maxCount,
  const std::string& expected)
{
  const std::vector<std::string> fields = SplitCommas(text);
  if (fields.size() < minCount || fields.size() > maxCount)
  {
    throw UserError(option + ": expected " + expected + ", got " + std::to_string(fields.size()) +
      " value(s) in '" + text + "'");
  }
  std::vector<double> values;
  for (std::size_t i = 0; i < fields.size(); ++i)
  {
    const std::string name =
      i < names.size() ? "field '" + names[i] + "'" : "value " + std::to_string(i + 1);
    const std::string& field = fields[i];
    if (field.empty())
    {
      throw UserError(option + ": " + name + " is empty in '" + text + "'");
    }
    errno = 0;
    char* end = nullptr;
    const double v = std::strtod(field.c_str(), &end);
    if (end == field.c_str() || *end != '\0')
    {
      throw UserError(option + ": " + name + " is not a number: '" + field + "'");
    }
    if (!std::isfinite(v) || errno == ERANGE)
    {
      throw UserError(option + ": " + name + " must be a finite number, got '" + field + "'");
    }
    values.push_back(v);
  }
  return values;
}

std::vector<double> ParseParameters(const std::string& text)
{
  if (text.empty())
  {
    return {};
  }
  return ParseNumbers(text, "--params", {}, 1, 1024, "p1,p2,...");
}

std::array<std::int64_t, 3> ParseDims(const std::string& text)
{
  static const std::vector<std::string> names{ "NX", "NY", "NZ" };
  const std::vector<std::string> fields = SplitCommas(text);
  if (fields.size() != 3)
  {
    throw UserError("--dims: expected NX,NY,NZ, got " + std::to_string(fields.size()) +
      " value(s) in '" + text + "'");
  }
  std::array<std::int64_t, 3> dims{};
  for (int a = 0; a < 3; ++a)
  {
    errno = 0;
    char* end = nullptr;
    const long long v = std::strtoll(fields[a].c_str(), &end, 10);
    if (fields[a].empty() || end == fields[a].c_str() || *end != '\0' || errno == ERANGE)
    {
      throw UserError("--dims: field '" + names[a] + "' is not an integer: '" + fields[a] + "'");
    }
    dims[a] = v;
  }
  return dims;
}

const frep::ModelInfo& FindModel(const std::string& name)
{
  try
  {
    return frep::findModel(name);
  }
  catch (const std::invalid_argument& e)
  {
    throw UserError(e.what());
  }
}

std::string FormatBounds(const std::array<double, 3>& lo, const std::array<double, 3>& hi)
{
  std::ostringstream os;
  os << "[" << lo[0] << "," << hi[0] << "]x[" << lo[1] << "," << hi[1] << "]x[" << lo[2] << ","
     << hi[2] << "]";
  return os.str();
}

// --- VTK messages
// ---------------------------------------------------------------------------------

/// Collects VTK's error and warning texts instead of printing them, so that a failure becomes one
/// "ictk: error:" line rather than VTK's multi-line reports (and the executive's follow-ups).
class ictkCaptureOutputWindow : public vtkOutputWindow
{
public:
  static ictkCaptureOutputWindow* New();
  vtkTypeMacro(ictkCaptureOutputWindow, vtkOutputWindow);

  void DisplayErrorText(const char* text) override { this->Errors.push_back(Message(text)); }
  void DisplayWarningText(const char* text) override { this->Warnings.push_back(Message(text)); }
  void DisplayGenericWarningText(const char* text) override
  {
    this->Warnings.push_back(Message(text));
  }
  void DisplayText(const char*) override {}

  std::vector<std::string> Errors;
  std::vector<std::string> Warnings;

private:
  /// "ERROR: In file, line N\nClass (0x...): message\n\n" -> "message".
  static std::string Message(const char* text)
  {
    std::string s = text ? text : "";
    const auto header = s.find('\n');
    if (s.rfind("ERROR: In ", 0) == 0 || s.rfind("Warning: In ", 0) == 0)
    {
      s = header == std::string::npos ? s : s.substr(header + 1);
    }
    const auto object = s.find("): ");
    if (object != std::string::npos && s.find(" (") < object)
    {
      s = s.substr(object + 3);
    }
    while (!s.empty() && (s.back() == '\n' || s.back() == ' '))
    {
      s.pop_back();
    }
    return s;
  }
};
vtkStandardNewMacro(ictkCaptureOutputWindow);

ictkCaptureOutputWindow* CaptureVtkMessages()
{
  static vtkSmartPointer<ictkCaptureOutputWindow> window;
  if (!window)
  {
    window = vtkSmartPointer<ictkCaptureOutputWindow>::New();
    vtkOutputWindow::SetInstance(window);
  }
  return window;
}

/// Throws the first VTK error recorded since `before`, prefixed by `what`.
void ThrowIfVtkFailed(
  const ictkCaptureOutputWindow* window, std::size_t before, const std::string& what)
{
  if (window->Errors.size() > before)
  {
    throw UserError(what + ": " + window->Errors[before]);
  }
}

// --- output files
// ---------------------------------------------------------------------------------

/// A temporary file next to the destination, renamed onto it by Commit() and removed otherwise.
class AtomicOutput
{
public:
  explicit AtomicOutput(const std::string& destination)
    : Destination(destination)
  {
    if (destination.empty())
    {
      throw UserError("the output path is empty");
    }
    const fs::path path(destination);
    std::error_code ec;
    if (fs::is_directory(path, ec))
    {
      throw UserError("cannot write '" + destination + "': it is a directory");
    }
    const fs::path folder = path.has_parent_path() ? path.parent_path() : fs::path(".");
    if (!fs::is_directory(folder, ec))
    {
      throw UserError(
        "cannot write '" + destination + "': folder '" + folder.string() + "' does not exist");
    }
    // The temporary name keeps the extension: some writers (vtkPLYWriter) append theirs
    // to a file name that does not end with it.
    const std::string extension = path.extension().string();
    std::string pattern =
      (folder / ("." + path.stem().string() + ".tmp-XXXXXX" + extension)).string();
    const int fd = mkstemps(pattern.data(), static_cast<int>(extension.size()));
    if (fd < 0)
    {
      throw UserError("cannot write '" + destination + "': " + std::strerror(errno));
    }
    // mkstemp creates the file 0600; give the result the permissions a plain create would.
    const mode_t mask = umask(0);
    umask(mask);
    fchmod(fd, 0666 & ~mask);
    close(fd);
    this->Temporary = pattern;
  }
  AtomicOutput(const AtomicOutput&) = delete;
  AtomicOutput& operator=(const AtomicOutput&) = delete;
  ~AtomicOutput()
  {
    if (!this->Temporary.empty())
    {
      std::remove(this->Temporary.c_str());
    }
  }

  const std::string& Path() const { return this->Temporary; }

  void Commit()
  {
    if (std::rename(this->Temporary.c_str(), this->Destination.c_str()) != 0)
    {
      throw UserError("cannot write '" + this->Destination + "': " + std::strerror(errno));
    }
    this->Temporary.clear();
  }

private:
  std::string Destination;
  std::string Temporary;
};

// --- progress
// -------------------------------------------------------------------------------------

std::atomic<bool> Interrupted{ false };

extern "C" void OnInterrupt(int)
{
  Interrupted = true;
}

/// A progress bar on a terminal, a few percentage lines otherwise (logs stay readable).
struct ProgressReporter
{
  std::string Label;
  bool Terminal = isatty(STDERR_FILENO) != 0;
  int LastShown = -1;
  bool Finished = false;

  void Show(double fraction)
  {
    const int percent = static_cast<int>(std::floor(std::min(1.0, std::max(0.0, fraction)) * 100));
    if (this->Finished || percent == this->LastShown)
    {
      return;
    }
    if (this->Terminal)
    {
      constexpr int Width = 40;
      const int filled = percent * Width / 100;
      std::cerr << "\r" << this->Label << " [" << std::string(filled, '#')
                << std::string(Width - filled, ' ') << "] " << std::setw(3) << percent << "%"
                << std::flush;
      if (percent == 100)
      {
        std::cerr << "\n";
        this->Finished = true;
      }
    }
    else if (percent / 25 != this->LastShown / 25 || this->LastShown < 0)
    {
      std::cerr << this->Label << ": " << percent << "%\n";
      this->Finished = percent == 100;
    }
    this->LastShown = percent;
  }

  void End()
  {
    if (this->Terminal && !this->Finished && this->LastShown >= 0)
    {
      std::cerr << "\n";
    }
    this->Finished = true;
  }
};

void OnProgress(vtkObject* caller, unsigned long, void* clientData, void* callData)
{
  auto* reporter = static_cast<ProgressReporter*>(clientData);
  reporter->Show(*static_cast<double*>(callData));
  if (Interrupted)
  {
    static_cast<vtkAlgorithm*>(caller)->SetAbortExecute(1);
  }
}

double Seconds(std::chrono::steady_clock::time_point since)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

// --- commands
// -------------------------------------------------------------------------------------

int RunModels(bool json)
{
  nlohmann::ordered_json list = nlohmann::ordered_json::array();
  std::size_t width = 4;
  for (const std::string& name : frep::modelNames())
  {
    width = std::max(width, name.size());
  }
  for (const std::string& name : frep::modelNames())
  {
    const frep::ModelInfo& info = frep::findModel(name);
    if (json)
    {
      list.push_back({ { "name", info.name }, { "description", info.description },
        { "bounds",
          { info.boundsLo[0], info.boundsHi[0], info.boundsLo[1], info.boundsHi[1],
            info.boundsLo[2], info.boundsHi[2] } } });
    }
    else
    {
      std::cout << std::left << std::setw(static_cast<int>(width)) << info.name << "  "
                << FormatBounds(info.boundsLo, info.boundsHi) << "\n"
                << std::string(width + 2, ' ') << info.description << "\n";
    }
  }
  if (json)
  {
    std::cout << list.dump(2) << "\n";
  }
  return 0;
}

/// A model ready to sample: its hypervolume and a box that holds it.
struct ResolvedModel
{
  std::string Name;
  frep::Hypervolume Model;
  std::array<double, 3> Lo;
  std::array<double, 3> Hi;
};

/// Opens a model file, turning its diagnostics into the user error (they name file, line and
/// column already).
lang::ModelFile OpenModelFile(const std::string& path, const std::vector<double>& params = {})
{
  try
  {
    return lang::loadModelFile(path, {}, params);
  }
  catch (const lang::ParseError& e)
  {
    // Every diagnostic, each "file:line:col: error: ..." with its source line and caret.
    std::string text = e.what();
    while (!text.empty() && text.back() == '\n')
    {
      text.pop_back();
    }
    throw ModelFileError(text);
  }
  catch (const std::invalid_argument& e)
  {
    throw UserError(e.what());
  }
}

/// A registered model's name or a model file (.hf, .xml). A HyperFun file is specialised to the
/// parameter values given (--params), so they may stand where its library needs numbers.
ResolvedModel ResolveModel(const std::string& nameOrPath, const std::vector<double>& params)
{
  if (!lang::isModelFile(nameOrPath))
  {
    const frep::ModelInfo& info = FindModel(nameOrPath);
    return { info.name, info.build(), info.boundsLo, info.boundsHi };
  }
  lang::ModelFile file = OpenModelFile(nameOrPath, params);
  const std::array<double, 6> b = lang::modelFileBounds(file, params);
  return { file.name, std::move(file.model), { b[0], b[2], b[4] }, { b[1], b[3], b[5] } };
}

struct EvalOptions
{
  std::string Model;
  std::string At;
  std::string Params;
  bool Json = false;
};

int RunEval(const EvalOptions& o)
{
  const std::vector<double> at =
    ParseNumbers(o.At, "--at", { "x", "y", "z", "t" }, 3, 4, "x,y,z or x,y,z,t");
  const std::array<double, 4> p{ at[0], at[1], at[2], at.size() > 3 ? at[3] : 0.0 };
  const std::vector<double> params = ParseParameters(o.Params);
  const ResolvedModel model = ResolveModel(o.Model, params);

  const frep::Hypervolume& hv = model.Model;
  std::vector<double> attributes(hv.attributeComponentCount());
  double value = 0;
  std::unique_ptr<frep::HypervolumeEvaluator> evaluator;
  try
  {
    evaluator = std::make_unique<frep::HypervolumeEvaluator>(hv, params);
  }
  catch (const std::invalid_argument& e)
  {
    throw UserError(std::string("--params: ") + e.what());
  }
  evaluator->eval(p, value, attributes.data());
  if (!o.Json)
  {
    std::cout << std::setprecision(17) << value << "\n";
    return 0;
  }

  frep::GradientEvaluator gradient(frep::Tape::compile(hv.geometry().function()), params);
  const frep::ValueGradient vg = gradient.eval(p[0], p[1], p[2], p[3]);
  const std::array<double, 3> normal = frep::outwardNormal(vg);

  nlohmann::ordered_json out;
  out["model"] = model.Name;
  out["point"] = p;
  out["value"] = value;
  out["gradient"] = vg.gradient;
  out["normal"] = normal;
  out["membership"] = evaluator->membership(p);
  nlohmann::ordered_json attributeValues = nlohmann::ordered_json::object();
  std::size_t k = 0;
  for (const frep::Attribute& a : hv.attributes())
  {
    if (a.components.size() == 1)
    {
      attributeValues[a.name] = attributes[k++];
    }
    else
    {
      nlohmann::ordered_json values = nlohmann::ordered_json::array();
      for (std::size_t c = 0; c < a.components.size(); ++c)
      {
        values.push_back(attributes[k++]);
      }
      attributeValues[a.name] = values;
    }
  }
  out["attributes"] = attributeValues;
  // NaN and infinities have no JSON spelling: nlohmann writes them as null.
  std::cout << out.dump(2) << "\n";
  return 0;
}

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

/// Options shared by the commands that sample a model on a grid (sample, mesh).
struct GridCommandOptions
{
  std::string Model;
  std::string Output;
  std::int64_t Resolution = 64;
  std::string Dims;
  std::string Bounds;
  double Time = 0;
  int Threads = 0;
  std::string Params;

  void AddTo(CLI::App* command, std::int64_t defaultResolution)
  {
    this->Resolution = defaultResolution;
    command->add_option("model", this->Model, "Model name (see `ictk models`) or a .hf / .xml file")
      ->required();
    CLI::Option* resolution = command->add_option("--resolution", this->Resolution,
      "Points per axis (default " + std::to_string(defaultResolution) + ")");
    CLI::Option* dims = command->add_option("--dims", this->Dims, "Points per axis: NX,NY,NZ");
    resolution->excludes(dims);
    command->add_option(
      "--bounds", this->Bounds, "Sampled box x0,x1,y0,y1,z0,z1 (default: the model's bounds)");
    command->add_option("--time", this->Time, "Time t (default 0)");
    command->add_option("--threads", this->Threads, "Threads (default: all cores)");
    command->add_option("--params", this->Params, "Model parameters: p1,p2,...");
  }
};

/// The grid a command samples, checked before anything is allocated or written.
struct GridPlan
{
  ResolvedModel Model;
  std::vector<double> Params;
  std::array<std::int64_t, 3> Dims;
  frep::Grid Grid;
};

GridPlan PlanGrid(const GridCommandOptions& o, std::size_t bytesPerValue)
{
  const std::vector<double> params = ParseParameters(o.Params);
  GridPlan plan{ ResolveModel(o.Model, params), params, {}, {} };
  if (!std::isfinite(o.Time))
  {
    throw UserError("--time must be a finite number");
  }
  if (o.Threads < 0)
  {
    throw UserError("--threads must be 0 (automatic) or more, got " + std::to_string(o.Threads));
  }
  std::array<double, 3>& lo = plan.Model.Lo;
  std::array<double, 3>& hi = plan.Model.Hi;
  if (!o.Bounds.empty())
  {
    const std::vector<double> b = ParseNumbers(
      o.Bounds, "--bounds", { "x0", "x1", "y0", "y1", "z0", "z1" }, 6, 6, "x0,x1,y0,y1,z0,z1");
    static const char* axes[] = { "x", "y", "z" };
    for (int a = 0; a < 3; ++a)
    {
      lo[a] = b[2 * a];
      hi[a] = b[2 * a + 1];
      if (lo[a] > hi[a])
      {
        std::ostringstream os;
        os << "--bounds: " << axes[a] << "0 > " << axes[a] << "1 (" << lo[a] << " > " << hi[a]
           << ")";
        throw UserError(os.str());
      }
    }
  }
  std::array<std::int64_t, 3>& dims = plan.Dims;
  if (!o.Dims.empty())
  {
    dims = ParseDims(o.Dims);
    static const char* names[] = { "NX", "NY", "NZ" };
    for (int a = 0; a < 3; ++a)
    {
      if (dims[a] < 1)
      {
        throw UserError(std::string("--dims: ") + names[a] + " must be at least 1, got " +
          std::to_string(dims[a]));
      }
    }
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

/// Samples the planned grid with a progress display; null when interrupted (Ctrl-C).
vtkSmartPointer<vtkImageData> SampleImage(const GridPlan& plan, int threads, bool asDouble,
  bool attributes, ictkCaptureOutputWindow* messages)
{
  vtkNew<ictkFRepSampler> sampler;
  sampler->SetHypervolume(plan.Model.Model);
  sampler->SetParameters(plan.Params);
  const auto& lo = plan.Model.Lo;
  const auto& hi = plan.Model.Hi;
  sampler->SetModelBounds(lo[0], hi[0], lo[1], hi[1], lo[2], hi[2]);
  sampler->SetSampleDimensions(
    static_cast<int>(plan.Dims[0]), static_cast<int>(plan.Dims[1]), static_cast<int>(plan.Dims[2]));
  sampler->SetTime(plan.Grid.time);
  sampler->SetNumberOfThreads(threads);
  sampler->SetOutputScalarType(asDouble ? VTK_DOUBLE : VTK_FLOAT);
  sampler->SetComputeAttributes(attributes);

  ProgressReporter progress;
  progress.Label = "sampling " + plan.Model.Name;
  vtkNew<vtkCallbackCommand> onProgress;
  onProgress->SetCallback(OnProgress);
  onProgress->SetClientData(&progress);
  sampler->AddObserver(vtkCommand::ProgressEvent, onProgress);

  std::signal(SIGINT, OnInterrupt);
  std::signal(SIGTERM, OnInterrupt);
  const std::size_t errorsBefore = messages->Errors.size();
  sampler->Update();
  progress.End();
  if (Interrupted)
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

/// The surface f = 0 of a sampled image (Flying Edges), with outward normals and the model's
/// attributes evaluated at its vertices.
vtkSmartPointer<vtkPolyData> ExtractSurface(
  vtkImageData* image, const GridPlan& plan, ictkCaptureOutputWindow* messages)
{
  vtkNew<vtkFlyingEdges3D> contour;
  contour->SetInputData(image);
  contour->SetInputArrayToProcess(0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, "f");
  contour->SetValue(0, 0.0);
  // f grows inwards, so the negated gradient Flying Edges uses for normals points outwards.
  contour->ComputeNormalsOn();
  contour->ComputeScalarsOff();
  contour->InterpolateAttributesOff();
  const std::size_t errorsBefore = messages->Errors.size();
  contour->Update();
  ThrowIfVtkFailed(messages, errorsBefore, "surface extraction failed");
  vtkSmartPointer<vtkPolyData> surface = contour->GetOutput();
  // Interpolating the grid's attribute arrays would mix the values on both sides of the
  // boundary (an attribute usually jumps there); evaluate them instead just inside the solid,
  // a thousandth of a grid step from each vertex against its outward normal.
  const auto& spacing = plan.Grid.spacing;
  const double step = std::min({ spacing[0], spacing[1], spacing[2] });
  AttachBoundaryAttributes(surface, plan.Model.Model, plan.Params, plan.Grid.time, 1e-3 * step);
  return surface;
}

std::string LowerExtension(const std::string& path)
{
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
    [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

const char* const SurfaceFormats = ".vtp, .stl, .ply or .obj";

bool IsSurfaceFormat(const std::string& path)
{
  const std::string ext = LowerExtension(path);
  return ext == ".vtp" || ext == ".stl" || ext == ".ply" || ext == ".obj";
}

/// Writes a surface in the format its path names (checked by IsSurfaceFormat).
void WriteSurface(vtkPolyData* surface, AtomicOutput& file, const std::string& path,
  ictkCaptureOutputWindow* messages)
{
  const std::string ext = LowerExtension(path);
  // Every writer is given the temporary path, and reports failure through Write() and its error
  // code (vtkXMLWriter is not a vtkWriter, so each kind is driven on its own).
  auto run = [&](auto* writer)
  {
    writer->SetInputData(surface);
    writer->SetFileName(file.Path().c_str());
    return writer->Write() == 1 && writer->GetErrorCode() == 0;
  };
  const std::size_t errorsBefore = messages->Errors.size();
  bool written = false;
  if (ext == ".vtp")
  {
    vtkNew<vtkXMLPolyDataWriter> xml;
    xml->SetDataModeToAppended();
    xml->EncodeAppendedDataOff();
    written = run(xml.Get());
  }
  else if (ext == ".stl")
  {
    vtkNew<vtkSTLWriter> stl;
    stl->SetFileTypeToBinary();
    written = run(stl.Get());
  }
  else if (ext == ".ply")
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

struct SampleCommandOptions : GridCommandOptions
{
  bool Double = false;
  std::string Surface;
};

int RunSample(const SampleCommandOptions& o)
{
  if (!o.Surface.empty() && !IsSurfaceFormat(o.Surface))
  {
    throw UserError("--surface: '" + o.Surface + "' is not a " + SurfaceFormats + " file");
  }
  const GridPlan plan = PlanGrid(o, o.Double ? sizeof(double) : sizeof(float));
  // Fail on an unwritable destination before spending time on sampling.
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
  writer->SetInputData(image);
  writer->SetFileName(volumeFile.Path().c_str());
  writer->SetDataModeToAppended();
  writer->EncodeAppendedDataOff();
  std::size_t errorsBefore = messages->Errors.size();
  if (writer->Write() != 1 || writer->GetErrorCode() != 0)
  {
    ThrowIfVtkFailed(messages, errorsBefore, "cannot write '" + o.Output + "'");
    throw UserError("cannot write '" + o.Output + "'");
  }
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
    std::cout << "wrote " << o.Surface << " (" << surface->GetNumberOfPoints() << " points, "
              << surface->GetNumberOfPolys() << " triangles) in " << Seconds(t2) << " s\n";
  }
  return 0;
}

int RunMesh(const GridCommandOptions& o)
{
  if (!IsSurfaceFormat(o.Output))
  {
    throw UserError("-o: '" + o.Output + "' is not a " + SurfaceFormats + " file");
  }
  const GridPlan plan = PlanGrid(o, sizeof(float));
  AtomicOutput file(o.Output);
  ictkCaptureOutputWindow* messages = CaptureVtkMessages();
  const auto t0 = std::chrono::steady_clock::now();
  // The attributes are evaluated on the surface itself; the grid needs only f.
  vtkSmartPointer<vtkImageData> image = SampleImage(plan, o.Threads, false, false, messages);
  if (!image)
  {
    std::cerr << "ictk: interrupted; nothing written\n";
    return ExitInterrupted;
  }
  vtkSmartPointer<vtkPolyData> surface = ExtractSurface(image, plan, messages);
  WriteSurface(surface, file, o.Output, messages);
  std::cout << "wrote " << o.Output << " (" << surface->GetNumberOfPoints() << " points, "
            << surface->GetNumberOfPolys() << " triangles from a " << plan.Dims[0] << " x "
            << plan.Dims[1] << " x " << plan.Dims[2] << " grid) in " << std::fixed
            << std::setprecision(3) << Seconds(t0) << " s\n";
  return 0;
}

struct ConvertOptions
{
  std::string Input;
  std::string Output;
};

/// Translates between model files (.hf, .xml); a registered model can be exported too.
int RunConvert(const ConvertOptions& o)
{
  if (!lang::isModelFile(o.Output))
  {
    throw UserError("convert: '" + o.Output + "' is not a .hf or .xml file");
  }
  auto open = [&]() -> lang::ModelFile
  {
    if (lang::isModelFile(o.Input))
    {
      return OpenModelFile(o.Input);
    }
    const frep::ModelInfo& info = FindModel(o.Input);
    return { info.name, 0, info.build(),
      std::array<double, 6>{ info.boundsLo[0], info.boundsHi[0], info.boundsLo[1], info.boundsHi[1],
        info.boundsLo[2], info.boundsHi[2] } };
  };
  const lang::ModelFile model = open();
  try
  {
    lang::saveModelFile(model, o.Output);
  }
  catch (const std::exception& e)
  {
    throw UserError(e.what());
  }
  std::cout << "wrote " << o.Output << " (model '" << model.name << "')\n";
  return 0;
}

int Run(int argc, char** argv)
{
  CLI::App app{ "ICTK: Implicit Complex ToolKit command-line tool", "ictk" };
  app.set_version_flag("--version", "ictk 0.1.0");
  app.require_subcommand(1);

  bool modelsJson = false;
  CLI::App* models =
    app.add_subcommand("models", "List the registered models (name, bounds, description)");
  models->add_flag("--json", modelsJson, "Print a JSON array");

  EvalOptions evalOptions;
  CLI::App* eval = app.add_subcommand("eval", "Evaluate a model at a point");
  eval
    ->add_option("model", evalOptions.Model, "Model name (see `ictk models`) or a .hf / .xml file")
    ->required();
  eval->add_option("--at", evalOptions.At, "The point: x,y,z or x,y,z,t")->required();
  eval->add_option("--params", evalOptions.Params, "Model parameters: p1,p2,...");
  eval->add_flag("--json", evalOptions.Json,
    "Print a JSON object with value, gradient, normal, membership and attributes");

  SampleCommandOptions sampleOptions;
  CLI::App* sample = app.add_subcommand("sample", "Sample a model on a regular grid (.vti)");
  sampleOptions.AddTo(sample, 64);
  sample->add_option("-o,--output", sampleOptions.Output, "Output image (.vti)")->required();
  sample->add_flag(
    "--double", sampleOptions.Double, "Write double-precision arrays (default float)");
  sample->add_option("--surface", sampleOptions.Surface,
    "Also extract the surface f = 0 (Flying Edges) into this .vtp, .stl, .ply or .obj");

  ConvertOptions convertOptions;
  CLI::App* convert =
    app.add_subcommand("convert", "Translate a model between HyperFun (.hf) and FRep XML (.xml)");
  convert->add_option("input", convertOptions.Input, "A .hf or .xml file, or a registered model")
    ->required();
  convert->add_option("output", convertOptions.Output, "The .hf or .xml file to write")->required();

  CLI::App* bench = ictk::app::AddBenchCommand(app);

  GridCommandOptions meshOptions;
  double meshFeatureSize = 0;
  CLI::App* mesh = app.add_subcommand("mesh",
    "Extract the surface f = 0 on a uniform grid (Flying Edges) as .vtp, .stl, .ply or .obj, "
    "or discretise a complex (.json) by cell dimension into .vtpc or .vtm");
  meshOptions.AddTo(mesh, 128);
  mesh
    ->add_option("-o,--output", meshOptions.Output,
      "Output surface (.vtp, .stl, .ply, .obj) or complex (.vtpc, .vtm)")
    ->required();
  mesh->add_option("--size,--feature-size", meshFeatureSize,
    "Complexes: mesh edge length and curve step (default: 1/64 of the complex's size)");
  int meshVolumeResolution = 0;
  mesh->add_option("--volume-resolution", meshVolumeResolution,
    "Complexes: also sample each implicit 3D cell's field on N^3 points (vtkImageData)");

  ictk::cli::TetraOptions tetraOptions;
  CLI::App* tetra = ictk::cli::AddTetraCommand(app, tetraOptions);

  ictk::cli::RunModelOptions runOptions;
  CLI::App* run = ictk::cli::AddRunCommand(app, runOptions);

  ictk::cli::ComplexOptions infoOptions;
  CLI::App* info = app.add_subcommand(
    "info", "List the cells, relations and attributes of a complex (.json) or model");
  info->add_option("model", infoOptions.Model, "A .json complex or a .hf / .xml model")->required();
  info->add_flag("--json", infoOptions.Json, "Print a JSON object");

  ictk::cli::ComplexOptions validateOptions;
  CLI::App* validate = app.add_subcommand("validate",
    "Check every declared boundary and containment pair against the geometry; exit 1 when one "
    "is violated");
  validate->add_option("model", validateOptions.Model, "A .json complex")->required();
  validate->add_option("--size,--feature-size", validateOptions.FeatureSize,
    "Discretisation step (default: 1/64 of the complex's size)");
  validate->add_option("--tolerance", validateOptions.Tolerance,
    "Distance within which a point counts as on a set (default: a quarter of the step)");
  validate->add_option("--threads", validateOptions.Threads, "Threads (default: all cores)");
  validate->add_flag("--json", validateOptions.Json, "Print a JSON report");

  try
  {
    app.parse(argc, argv);
  }
  catch (const CLI::CallForHelp& e)
  {
    return app.exit(e);
  }
  catch (const CLI::CallForAllHelp& e)
  {
    return app.exit(e);
  }
  catch (const CLI::CallForVersion& e)
  {
    return app.exit(e);
  }
  catch (const CLI::ParseError& e)
  {
    throw UserError(std::string(e.what()) + " (see ictk --help)");
  }

  if (*bench)
  {
    return ictk::app::RunBenchCommand();
  }
  if (*models)
  {
    return RunModels(modelsJson);
  }
  if (*eval)
  {
    return RunEval(evalOptions);
  }
  if (*tetra)
  {
    return ictk::cli::RunTetra(tetraOptions);
  }
  if (*run)
  {
    return ictk::cli::RunModel(runOptions);
  }
  if (*info)
  {
    return ictk::cli::RunInfo(infoOptions);
  }
  if (*validate)
  {
    return ictk::cli::RunValidate(validateOptions);
  }
  if (*mesh)
  {
    if (ictk::cli::IsComplexInput(meshOptions.Model) ||
      ictk::cli::IsComplexOutput(meshOptions.Output))
    {
      ictk::cli::ComplexOptions o;
      o.Model = meshOptions.Model;
      o.Output = meshOptions.Output;
      o.FeatureSize = meshFeatureSize;
      o.VolumeResolution = meshVolumeResolution;
      o.Threads = meshOptions.Threads;
      return ictk::cli::RunComplexMesh(o);
    }
    return RunMesh(meshOptions);
  }
  if (*convert)
  {
    return RunConvert(convertOptions);
  }
  return RunSample(sampleOptions);
}

} // namespace

int main(int argc, char** argv)
{
  // VTK's filters (Flying Edges, and vtkSampleFunction in `ictk bench`) on as many threads as
  // ICTK's own: ParaView's VTK has no TBB backend and starts Sequential unless
  // VTK_SMP_BACKEND_IN_USE names another.
  if (std::string(vtkSMPTools::GetBackend()) == "Sequential" &&
    !std::getenv("VTK_SMP_BACKEND_IN_USE"))
  {
    vtkSMPTools::SetBackend("STDThread");
  }
  try
  {
    return Run(argc, argv);
  }
  catch (const ModelFileError& e)
  {
    std::cerr << e.what() << "\n";
  }
  catch (const ictk::lang::ParseError& e)
  {
    // Diagnostics carry their own "file:line:col: error:" prefix, source line and caret.
    std::cerr << e.what() << "\n";
  }
  catch (const std::bad_alloc&)
  {
    std::cerr << "ictk: error: out of memory\n";
  }
  catch (const std::exception& e)
  {
    std::cerr << "ictk: error: " << e.what() << "\n";
  }
  catch (...)
  {
    std::cerr << "ictk: error: unexpected failure\n";
  }
  return ExitUserError;
}
