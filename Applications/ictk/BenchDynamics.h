// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The dynamic workload of `ictk bench` (issue 7, `andyhausen-100`): an .icm model run over a time
// range with its complex discretised at every step, with and without time coherence.

#include <cstddef>
#include <string>
#include <vector>

namespace ictk::cli
{

struct DynamicRunTiming
{
  std::vector<double> seconds;    ///< wall-clock seconds of each run (load, engine, meshing)
  std::vector<double> cpuSeconds; ///< process CPU seconds of each run
  double engineSeconds = 0;       ///< of the last run: the engine alone
  double meshSeconds = 0;         ///< of the last run: the discretisation alone
  std::size_t frames = 0;
  std::size_t points = 0; ///< mesh points over all frames of a run
  std::size_t computed = 0, moved = 0, reused = 0;
  /// Blocks (8^3 grid cells) of the computed cells' surfaces contoured and copied from the
  /// cell's previous meshing (CoherenceStats).
  std::size_t blocksContoured = 0, blocksReused = 0;
  double featureSize = 0;
  std::vector<std::string> instances; ///< the instances met, in order
};

/// Runs `path` from its start to t1 in `steps` equal steps (steps + 1 frames, the start included),
/// discretising the complex at every frame at 1/`divisions` of the largest side of the complex at
/// the model's start, `runs` times. Each run loads the model afresh, so runs are alike.
DynamicRunTiming TimeDynamicRun(const std::string& path, double t1, int steps, int divisions,
  bool coherent, int runs, int threads);

} // namespace ictk::cli
