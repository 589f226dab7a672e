// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Dense sampling of a tape on a regular grid, multithreaded with TBB. The result is identical for
// any thread count: every point is computed by the same arithmetic on the same (or a provably
// equivalent, pruned) tape, whatever thread runs it.

#include "FRep/Evaluators.h"
#include "FRep/Hypervolume.h"
#include "FRep/Progress.h"

#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <stdexcept>

namespace ictk::frep
{

/// A regular grid of the modelling space; x varies fastest (VTK's point order).
struct Grid
{
  std::array<double, 3> origin{ 0, 0, 0 };
  std::array<double, 3> spacing{ 1, 1, 1 };
  std::array<std::int64_t, 3> dimensions{ 0, 0, 0 };
  double time = 0;
  /// Where this grid starts in a larger one it is a piece of (an update extent, an MPI rank's
  /// slab): point (i, j, k) is at origin + (first + (i, j, k)) * spacing, computed exactly as the
  /// whole grid computes it, so pieces of a double-precision sampling equal the whole bit for bit.
  std::array<std::int64_t, 3> first{ 0, 0, 0 };
  std::int64_t pointCount() const { return dimensions[0] * dimensions[1] * dimensions[2]; }
};

/// A grid that covers [lo, hi] with `resolution` points per axis (corners included).
Grid gridOverBox(const std::array<double, 3>& lo, const std::array<double, 3>& hi,
  const std::array<std::int64_t, 3>& resolution, double time = 0);

/// Throws std::invalid_argument when the grid is empty, has a non-finite or non-positive spacing,
/// or would need more than `maxBytes` for `bytesPerPoint` values per point (default: 80 % of the
/// physical memory).
void checkGrid(const Grid& grid, std::size_t bytesPerPoint, std::size_t maxBytes = 0);

/// Counts of what a sampling did (for benchmarks: `ictk bench --scaling`).
struct SampleStats
{
  std::int64_t bricks = 0;
  std::int64_t pointsEvaluated = 0;
  /// Sum over the bricks of points x the length of the tape they were evaluated with (the pruned
  /// tape when pruning): instruction evaluations, before row hoisting.
  std::int64_t instructionEvaluations = 0;
};

struct SampleOptions
{
  /// Threads to use; 0 = TBB's default.
  int threads = 0;
  /// Simplify the tape per brick by interval arithmetic (same values, fewer instructions).
  bool prune = true;
  /// Edge of the cubic bricks the grid is split into.
  int brickSize = 16;
  /// Called with the completed fraction; return false to cancel (sampleGrid then throws Cancelled).
  Progress progress;
  std::vector<double> parameters;
  /// When set, receives the counts of the sampling.
  SampleStats* stats = nullptr;
};

/// Fills `out` (grid.pointCount() values) with the tape's first output.
void sampleGrid(
  const TapePtr& tape, const Grid& grid, float* out, const SampleOptions& options = {});
void sampleGrid(
  const TapePtr& tape, const Grid& grid, double* out, const SampleOptions& options = {});

/// Samples a hypervolume in one pass: f into `value` (grid.pointCount() values) and attribute i
/// into attributes[i] (grid.pointCount() tuples of its component count, interleaved), by the
/// default rule of HypervolumeEvaluator applied to the values in T.
void sampleGrid(const Hypervolume& hv, const Grid& grid, float* value,
  const std::vector<float*>& attributes, const SampleOptions& options = {});
void sampleGrid(const Hypervolume& hv, const Grid& grid, double* value,
  const std::vector<double*>& attributes, const SampleOptions& options = {});

} // namespace ictk::frep
