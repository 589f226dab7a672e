// SPDX-License-Identifier: BSD-3-Clause
#include "Options.h"

#include "Command.h"

#include "Engine/FrameSequence.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <iomanip>
#include <sstream>

namespace ictk::cli
{
namespace
{

/// Parses one number; `what` names it in the messages ("--at: field 'x'", "--frames: T0") and
/// `context` is added to the "not a number" one (the whole value, where the field alone is not
/// enough to find it).
double ParseFinite(const std::string& field, const std::string& what, const std::string& context)
{
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(field.c_str(), &end);
  if (field.empty() || end == field.c_str() || *end != '\0')
  {
    throw UserError(what + " is not a number: '" + field + "'" + context);
  }
  if (!std::isfinite(v) || errno == ERANGE)
  {
    throw UserError(what + " must be a finite number, got '" + field + "'");
  }
  return v;
}

} // namespace

CLI::Option* AddModel(CLI::App* command, std::string& model, const std::string& help)
{
  return command->add_option("model", model, help)->required();
}

CLI::Option* AddOutput(CLI::App* command, std::string& output, const std::string& help)
{
  return command->add_option("-o,--output", output, help)->required();
}

CLI::Option* AddSize(CLI::App* command, double& size, const std::string& help)
{
  return command->add_option("--size,--feature-size", size, help);
}

CLI::Option* AddThreads(CLI::App* command, int& threads, const std::string& help)
{
  return command->add_option("--threads", threads, help);
}

CLI::Option* AddJson(CLI::App* command, bool& json, const std::string& help)
{
  return command->add_flag("--json", json, help);
}

CLI::Option* AddParams(CLI::App* command, std::string& params)
{
  return command->add_option("--params", params, "Model parameters: p1,p2,...");
}

CLI::Option* AddTime(CLI::App* command, double& time)
{
  return command->add_option("--time", time,
    "Time t (default 0; a .icm model's default is its start, and an animated .blob has no "
    "default and needs it)");
}

CLI::Option* AddFrames(CLI::App* command, std::string& frames, const std::string& help)
{
  return command->add_option("--frames", frames, help);
}

void CheckThreads(int threads)
{
  if (threads < 0)
  {
    throw UserError("--threads must be 0 (automatic) or more, got " + std::to_string(threads));
  }
}

void CheckSize(double size)
{
  if (!std::isfinite(size) || size < 0)
  {
    throw UserError("--size must be a finite number >= 0");
  }
}

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

std::vector<std::string> Split(const std::string& text, char separator)
{
  std::vector<std::string> fields;
  std::string::size_type start = 0;
  while (true)
  {
    const auto at = text.find(separator, start);
    fields.push_back(Trim(text.substr(start, at == std::string::npos ? at : at - start)));
    if (at == std::string::npos)
    {
      return fields;
    }
    start = at + 1;
  }
}

std::vector<double> ParseNumbers(const std::string& text, const std::string& option,
  const std::vector<std::string>& names, std::size_t minCount, std::size_t maxCount,
  const std::string& expected)
{
  const std::vector<std::string> fields = Split(text, ',');
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
    if (fields[i].empty())
    {
      throw UserError(option + ": " + name + " is empty in '" + text + "'");
    }
    values.push_back(ParseFinite(fields[i], option + ": " + name, ""));
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

std::vector<std::int64_t> ParseIntegers(const std::string& text, const std::string& option,
  const std::vector<std::string>& names, const std::string& expected)
{
  const std::vector<std::string> fields = Split(text, ',');
  if (fields.size() != names.size())
  {
    throw UserError(option + ": expected " + expected + ", got " + std::to_string(fields.size()) +
      " value(s) in '" + text + "'");
  }
  std::vector<std::int64_t> values;
  for (std::size_t a = 0; a < fields.size(); ++a)
  {
    errno = 0;
    char* end = nullptr;
    const long long v = std::strtoll(fields[a].c_str(), &end, 10);
    if (fields[a].empty() || end == fields[a].c_str() || *end != '\0' || errno == ERANGE)
    {
      throw UserError(option + ": field '" + names[a] + "' is not an integer: '" + fields[a] + "'");
    }
    values.push_back(v);
  }
  return values;
}

std::array<std::int64_t, 3> ParseDims(const std::string& text)
{
  const std::vector<std::int64_t> v =
    ParseIntegers(text, "--dims", { "NX", "NY", "NZ" }, "NX,NY,NZ");
  static const char* names[] = { "NX", "NY", "NZ" };
  for (int a = 0; a < 3; ++a)
  {
    if (v[a] < 1)
    {
      throw UserError(
        std::string("--dims: ") + names[a] + " must be at least 1, got " + std::to_string(v[a]));
    }
  }
  return { v[0], v[1], v[2] };
}

void ParseBounds(const std::string& text, std::array<double, 3>& lo, std::array<double, 3>& hi)
{
  const std::vector<double> b = ParseNumbers(
    text, "--bounds", { "x0", "x1", "y0", "y1", "z0", "z1" }, 6, 6, "x0,x1,y0,y1,z0,z1");
  static const char* axes[] = { "x", "y", "z" };
  for (int a = 0; a < 3; ++a)
  {
    lo[a] = b[2 * a];
    hi[a] = b[2 * a + 1];
    if (lo[a] > hi[a])
    {
      std::ostringstream os;
      os << "--bounds: " << axes[a] << "0 > " << axes[a] << "1 (" << lo[a] << " > " << hi[a] << ")";
      throw UserError(os.str());
    }
  }
}

std::vector<double> ParseFrames(const std::string& spec, const std::string& option)
{
  const std::vector<std::string> fields = Split(spec, ':');
  if (fields.size() != 3)
  {
    throw UserError(option + ": expected T0:T1:DT (e.g. 0:10:0.1), got '" + spec + "'");
  }
  static const char* const names[3] = { "T0", "T1", "DT" };
  double v[3];
  for (int i = 0; i < 3; ++i)
  {
    v[i] = ParseFinite(fields[i], option + ": " + names[i], " in '" + spec + "'");
  }
  const double t0 = v[0], t1 = v[1], dt = v[2];
  if (t1 < t0)
  {
    throw UserError(option + ": T1 < T0 in '" + spec + "' (time runs forwards)");
  }
  if (!(dt > 0))
  {
    throw UserError(option + ": DT must be positive, got '" + fields[2] + "'");
  }
  const double count = engine::frameCount(t0, t1, dt);
  if (!(count <= engine::MaxFrames))
  {
    std::ostringstream os;
    os << option << ": '" << spec << "' gives " << std::setprecision(3) << count
       << " frames, more than the limit of 1000000 (a larger DT?)";
    throw UserError(os.str());
  }
  return engine::frameTimes(t0, t1, dt);
}

void CheckEngineSteps(
  double start, double end, double step, const std::string& option, const std::string& hint)
{
  const double steps = (end - start) / step;
  if (steps > engine::MaxEngineSteps)
  {
    std::ostringstream os;
    os << option << ": " << step << " from the model's start " << start << " to " << end
       << " gives " << steps << " engine steps, more than the limit of "
       << static_cast<long long>(engine::MaxEngineSteps) << " (" << hint << ")";
    throw UserError(os.str());
  }
}

bool HasExtension(const std::string& path, const std::string& extension)
{
  if (path.size() < extension.size())
  {
    return false;
  }
  return std::equal(extension.begin(), extension.end(), path.end() - extension.size(),
    [](char e, char p)
    {
      return std::tolower(static_cast<unsigned char>(e)) ==
        std::tolower(static_cast<unsigned char>(p));
    });
}

} // namespace ictk::cli
