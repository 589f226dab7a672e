// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Reading and writing voxel grids as OpenVDB files (.vdb). OpenVDB is a private dependency: its
// headers are included by VdbIO.cxx only.

#include "Voxel/VoxelGrid.h"

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

namespace ictk::voxel
{

/// readVdb's default voxel budget: 2^30 voxels (4 GiB of floats).
inline constexpr std::int64_t kDefaultVdbVoxelBudget = std::int64_t(1) << 30;

/// Reads one scalar grid of an OpenVDB file as a dense VoxelGrid.
///
/// - gridName empty: the first float grid (in the order of the file's grid index, which OpenVDB
///   sorts by name), or failing that the first double grid (converted to float).
/// - The grid is densified over the bounding box of its active voxels plus a one-voxel margin;
///   every voxel takes the grid's value there (inactive voxels: the background value, or a tile's
///   value, e.g. the negated background inside a level set). The VoxelGrid's points are the
///   voxel centres (OpenVDB's index coordinates), as OpenVDB's own trilinear sampler uses them.
/// - The transform must be linear with an axis-aligned positive scale (uniform or per axis) plus
///   a translation; rotations, shears, reflections and frustum transforms are refused.
/// - Refuses a dense grid of more than `maxVoxels` voxels (or over frep::checkGrid's memory
///   budget) before allocating it.
/// Errors name the file and the grid: std::runtime_error for a missing file, a file that is not a
/// readable VDB, no float/double grid, an absent grid name (the message lists the grids), a
/// non-scalar grid, an empty grid, an unsupported transform or a grid over the budget;
/// std::invalid_argument (from validate()) for NaN or infinite values.
std::shared_ptr<VoxelGrid> readVdb(const std::string& path, const std::string& gridName = "",
  std::int64_t maxVoxels = kDefaultVdbVoxelBudget);

/// Writes `grid` (validated first) as a float grid named `gridName` of a new OpenVDB file at
/// `path`, replacing any existing file. Every grid point becomes an active voxel, so readVdb gives
/// back the same values on the same points (plus its one-voxel margin of background). The
/// background value (the value OpenVDB reports outside the grid) is `background`, by default the
/// grid's value at its first point (a corner: air in a scan, the outside of a sampled solid).
/// The file is written under a temporary name in the same folder and renamed over `path` when
/// complete, so a failure never leaves a truncated file at `path`.
/// Throws std::invalid_argument for a bad grid, name or background, and std::runtime_error,
/// naming the file, when writing fails.
void writeVdb(const VoxelGrid& grid, const std::string& path,
  const std::string& gridName = "density", std::optional<float> background = std::nullopt);

} // namespace ictk::voxel
