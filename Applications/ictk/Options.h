// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The options that several `ictk` commands share, added by one function each so that the same
// thing has the same name (and help) in every command, and the parsing of their values: number
// lists (--at, --bounds, --params), integer lists (--dims, render's --size), frame ranges (--frames
// T0:T1:DT) and file extensions. Every parse error is a UserError whose message starts with the
// option's name.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace CLI
{
class App;
class Option;
} // namespace CLI

namespace ictk::cli
{

// --- shared options ------------------------------------------------------------------------------

/// The positional `model`: what the command reads (a registered model, a model file, a complex).
CLI::Option* AddModel(CLI::App* command, std::string& model, const std::string& help);
/// -o,--output (required).
CLI::Option* AddOutput(CLI::App* command, std::string& output, const std::string& help);
/// --size (and --feature-size, its older spelling): the edge length of meshes, the step of curves.
CLI::Option* AddSize(CLI::App* command, double& size, const std::string& help);
/// --threads: 0 (the default) means all cores.
CLI::Option* AddThreads(
  CLI::App* command, int& threads, const std::string& help = "Threads (default: all cores)");
/// --json: print the result as JSON instead of text.
CLI::Option* AddJson(CLI::App* command, bool& json, const std::string& help);
/// --params p1,p2,...: the model's parameters (ParseParameters).
CLI::Option* AddParams(CLI::App* command, std::string& params);
/// --time T: the instant at which a model is evaluated (a frame range is --frames).
CLI::Option* AddTime(CLI::App* command, double& time);
/// --frames T0:T1:DT (ParseFrames); `help` says what the frames are of.
CLI::Option* AddFrames(CLI::App* command, std::string& frames, const std::string& help);

/// Throws unless `threads` >= 0.
void CheckThreads(int threads);
/// Throws unless `size` is finite and >= 0 (0: the command's default).
void CheckSize(double size);

// --- values --------------------------------------------------------------------------------------

std::string Trim(const std::string& s);
/// The fields of `text` between `separator`s, each trimmed of blanks; one field when there is none.
std::vector<std::string> Split(const std::string& text, char separator);

/// Parses a comma-separated list of finite numbers. `names` names the fields for messages (e.g.
/// x, y, z); fields beyond it are called "value N". `expected` spells the form for the count's
/// message (e.g. "x,y,z or x,y,z,t").
std::vector<double> ParseNumbers(const std::string& text, const std::string& option,
  const std::vector<std::string>& names, std::size_t minCount, std::size_t maxCount,
  const std::string& expected);
/// --params: p1,p2,... (empty: none).
std::vector<double> ParseParameters(const std::string& text);
/// A comma-separated list of exactly names.size() integers (their range is checked by the
/// caller); `expected` spells the form for the count's message (e.g. "NX,NY,NZ").
std::vector<std::int64_t> ParseIntegers(const std::string& text, const std::string& option,
  const std::vector<std::string>& names, const std::string& expected);
/// --bounds: x0,x1,y0,y1,z0,z1 into lo and hi (a UserError for x0 > x1 and the like).
void ParseBounds(const std::string& text, std::array<double, 3>& lo, std::array<double, 3>& hi);
/// --dims: NX,NY,NZ, integers of at least 1 (their upper bounds are the caller's).
std::array<std::int64_t, 3> ParseDims(const std::string& text);

/// The frame times of "T0:T1:DT": T0, T0 + DT, ... while <= T1 (with DT / 1000 of slack for
/// rounding), and T1 itself when DT does not divide the range. A malformed or unreasonable spec
/// (T1 < T0, DT <= 0, a value that is not finite, more than a million frames) is a UserError whose
/// message starts with `option`, the name the range was given under (--frames, or `run`'s --time).
std::vector<double> ParseFrames(const std::string& spec, const std::string& option = "--frames");

/// The engine's steps from the model's `start` to `end`, at most `step` apart, checked against
/// engine::MaxEngineSteps: above it a UserError "<option>: <step> from the model's start <start>
/// to <end> gives <n> engine steps, more than the limit of 10000000 (<hint>)".
void CheckEngineSteps(
  double start, double end, double step, const std::string& option, const std::string& hint);

/// True when `path` ends with `extension` (".vtp"), whatever the letters' case.
bool HasExtension(const std::string& path, const std::string& extension);

} // namespace ictk::cli
