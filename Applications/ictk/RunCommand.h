// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// `ictk run`: runs a dynamic implicit complex (.icm) over a range of times and writes a .pvd time
// series of its discretised complexes (one .vtpc per frame), optionally with a JSON-lines trace
// of every evaluated time.

#include <string>
#include <vector>

namespace CLI
{
class App;
}

namespace ictk::cli
{

struct RunModelOptions
{
  std::string Model;
  std::string Time; ///< T0:T1:DT
  std::string Output;
  std::string Trace;
  double FeatureSize = 0;
  double MaxStep = 0;
  bool NoCoherence = false;
  bool Json = false;
  int Threads = 0;
};

CLI::App* AddRunCommand(CLI::App& app, RunModelOptions& options);
/// Returns the exit code (0, or 130 when interrupted); throws std::exception on a user error and
/// lang::ParseError for a model's diagnostics.
int RunModel(const RunModelOptions& options);

/// The frame times of "T0:T1:DT": T0, T0 + DT, ... while <= T1 (with DT / 1000 of slack for
/// rounding), and T1 itself when DT does not divide the range. Throws std::invalid_argument with
/// the message the user sees for a malformed or unreasonable spec (T1 < T0, DT <= 0, a value
/// that is not finite, more than a million frames).
std::vector<double> ParseTimeSpec(const std::string& spec);

} // namespace ictk::cli
