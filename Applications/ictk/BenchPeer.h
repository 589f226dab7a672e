// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// `ictk bench --peer-libfive PATH` (issue 20): ICTK's workloads timed side by side with a peer,
// libfive through its `l5bench` harness (../shared/bench/peers/libfive, run as a subprocess) or
// VTK in this process. A figure of another tool quoted from elsewhere does not reproduce on a
// shared machine; timing both sides in alternating rounds of the same run exposes them to the
// same load, so their ratio holds even when the absolute times do not. See docs/performance.md.

#include <nlohmann/json.hpp>

#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace ictk::cli
{

/// One side's measurement in one round: the median wall and CPU seconds of its timed runs, and
/// what it reports besides (pixels inside, triangles).
struct PeerRound
{
  double seconds = 0;
  double cpuSeconds = 0;
  nlohmann::json details = nlohmann::json::object();
};

/// One side of a side-by-side workload: `round` makes one warm-up run and its timed runs.
struct PeerSide
{
  std::string tool;  // ICTK, libfive, VTK
  std::string label; // what of the tool is timed (JIT, Heightmap, ...)
  std::function<PeerRound()> round;
  std::optional<double> goalSeconds; // an absolute goal of an ICTK side
};

/// A ratio to report: the peer side's time over the ICTK side's (above 1: ICTK is faster).
struct PeerRatio
{
  std::size_t ictk = 0;
  std::size_t peer = 0;
  std::optional<double> goal; // the ratio to reach
};

struct PeerCase
{
  std::string workload;
  std::string what;
  int threads = 1;
  std::vector<PeerSide> sides; // timed in this order in even rounds, reversed in odd ones
  std::vector<PeerRatio> ratios;
};

/// A side timed in this process: one warm-up run of `run`, then `runs` timed ones; `details`
/// (optional) is asked after each round.
PeerSide InProcessSide(std::string tool, std::string label, int runs, std::function<void()> run,
  std::function<nlohmann::json()> details = {});

/// A side timed by l5bench: `l5bench args...`, whose first JSON line holding "seconds" gives the
/// round's times (l5bench makes its own warm-up run) and whose other JSON lines the details.
PeerSide LibfiveSide(std::string label, std::string l5bench, std::vector<std::string> args);

/// Whether `l5bench args...` runs and exits with 0 (its output discarded): which commands a
/// harness has (the copy for N x N x N heightmaps adds `heightmap`).
bool PeerHasCommand(const std::string& l5bench, const std::vector<std::string>& args);
/// Throws std::invalid_argument unless `path` is an executable file.
void CheckPeerExecutable(const std::string& path);

/// Times every case over `rounds` alternating rounds and prints the sides and ratios as Markdown
/// tables (or one JSON object); the value of a side is the median of its round medians, a ratio
/// is the quotient of those medians (its range over the rounds beside it).
void RunPeerBench(
  const std::vector<PeerCase>& cases, int rounds, bool json, const std::string& peerPath);

} // namespace ictk::cli
