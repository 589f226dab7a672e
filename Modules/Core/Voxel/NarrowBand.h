// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Sparse sampling of a field into an OpenVDB grid that holds only a narrow band around the
// surface f = 0: memory and time follow the surface (r^2 voxels at resolution r), not the volume
// (r^3). OpenVDB stays a private dependency: the grid is reached through NarrowBandGrid.
//
// The descent (sampleNarrowBand): the grid's points are cut into blocks of 64^3, each the root
// of an octree down to OpenVDB's 8^3 leaf nodes (aligned with them, so a leaf of the octree is a
// leaf node of the grid). At every node the interval bound of f over the node's points decides:
// a node whose bound lies entirely beyond the band (f > band or f < -band everywhere) is dropped
// with everything under it; otherwise the tape is simplified for the node (interval pruning of
// min/max, as frep::sampleGrid does per brick) and its children are visited with the shorter tape.
// A leaf is sampled with the tape of its parent, at the points sampleGrid would compute (the same
// coordinates, the same float row evaluation), and becomes a leaf node of the grid when at least
// one of its points lies in the band. So a point's value is exactly sampleGrid's value there,
// and the grid is the same for any thread count (each block writes its own leaves; they are
// inserted in block order).

#include "FRep/Progress.h"
#include "FRep/Sampling.h"
#include "FRep/Tape.h"

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace ictk::voxel
{

struct NarrowBandOptions
{
  /// Half-width of the band in the field's units: a point is active when |f| <= band. For a
  /// distance field it is a distance. 0: three times the largest grid spacing.
  double band = 0;
  /// Threads to use; 0 = TBB's default.
  int threads = 0;
  std::vector<double> parameters;
  /// Called with the completed fraction; return false to cancel (sampleNarrowBand then throws
  /// Cancelled).
  Progress progress;
};

/// Counts of what a narrow-band sampling did.
struct NarrowBandStats
{
  std::int64_t intervalEvaluations = 0; ///< octree nodes bounded (blocks, inner nodes, leaves)
  std::int64_t leavesSampled = 0;       ///< 8^3 leaves whose points were evaluated
  std::int64_t leavesKept = 0;          ///< of those, the leaves with a point in the band
  std::int64_t pointsEvaluated = 0;     ///< grid points inside the sampled leaves
};

/// A narrow band sampled by sampleNarrowBand: an openvdb::FloatGrid whose index (i, j, k) is the
/// point (i, j, k) of the sampled frep::Grid. Active voxels hold f where |f| <= band; every other
/// voxel reads +band inside the solid (f > 0) and -band outside (the background), as OpenVDB's
/// signed flood fill sets them.
class NarrowBandGrid
{
public:
  std::int64_t activeVoxelCount() const;
  /// The grid's memory in bytes (OpenVDB's memUsage(): nodes, masks and values).
  std::size_t memoryBytes() const;
  double band() const;
  const frep::Grid& grid() const;
  const NarrowBandStats& stats() const;
  /// The value at grid point (i, j, k); `active` (optional) receives whether it is in the band.
  float value(const std::array<std::int64_t, 3>& ijk, bool* active = nullptr) const;
  /// Calls visit(ijk, value) for every active voxel, in OpenVDB's (deterministic) order.
  void forEachActive(
    const std::function<void(const std::array<std::int64_t, 3>&, float)>& visit) const;
  /// Writes the grid, named `gridName`, as a new OpenVDB file at `path` (atomically: written
  /// under a temporary name and renamed). The file's metadata holds the band ("ictk_band").
  /// std::runtime_error naming the file when writing fails.
  void write(const std::string& path, const std::string& gridName = "f") const;

private:
  NarrowBandGrid() = default; // only sampleNarrowBand makes one
  struct Impl;
  std::shared_ptr<const Impl> impl_;
  friend NarrowBandGrid sampleNarrowBand(
    const frep::TapePtr& tape, const frep::Grid& grid, const NarrowBandOptions& options);
};

/// Samples the tape's first output on the points of `grid` that lie within the band of the
/// surface (see the file comment). Throws std::invalid_argument for a bad grid (frep::checkGrid's
/// rules without the dense memory budget; at most 2^30 points per axis), a band that is not
/// finite and positive or missing parameters, and Cancelled when the progress callback says so.
NarrowBandGrid sampleNarrowBand(
  const frep::TapePtr& tape, const frep::Grid& grid, const NarrowBandOptions& options = {});

} // namespace ictk::voxel
