// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// How long work shows itself while it runs and is timed: the progress bar every long command
// draws, Ctrl-C turned into a flag that the work polls (so that it can stop and leave nothing
// written), and the clocks of the timings the commands print.

#include <chrono>
#include <string>
#include <vector>

namespace ictk::cli
{

/// A bar redrawn in place on a terminal ("label [####    ]  42% suffix"). Elsewhere, with
/// `lines`, a line "label: N%" at every quarter (logs stay readable), otherwise nothing (logs and
/// pipes get the command's summary only). Disabled, it shows nothing anywhere (e.g. with --json).
class ProgressBar
{
public:
  explicit ProgressBar(std::string label, bool lines = false, bool enabled = true);
  /// `fraction` of the work is done; `suffix` follows the percentage on a terminal.
  void Show(double fraction, const std::string& suffix = {});
  /// Ends the bar's line (call it when the work stops, done or not).
  void End();

private:
  std::string Label;
  bool Terminal;
  bool Lines;
  bool Enabled;
  int LastShown = -1;
  std::string LastSuffix;
  bool Finished = false;
};

/// For its lifetime, Ctrl-C (SIGINT) and SIGTERM set Interrupted() instead of ending the process;
/// the previous handlers come back at its end.
class InterruptScope
{
public:
  InterruptScope();
  ~InterruptScope();
  InterruptScope(const InterruptScope&) = delete;
  InterruptScope& operator=(const InterruptScope&) = delete;

private:
  void (*PreviousInt)(int);
  void (*PreviousTerm)(int);
};

/// True once Ctrl-C was pressed inside an InterruptScope.
bool Interrupted();

/// Wall-clock seconds since `since`.
double Seconds(std::chrono::steady_clock::time_point since);
/// The process's CPU seconds so far (all threads): on a shared machine, CPU time / threads is
/// what a run would take with the cores to itself.
double CpuSeconds();
/// The median of `values` (not empty).
double Median(std::vector<double> values);

} // namespace ictk::cli
