// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The volume files the core reads without VTK (issue 15): OpenVDB (.vdb, VdbIO.h) and
// InVesalius projects (.inv3), behind one entry point so every front end that loads voxel cells
// (complex JSON in the core, ictkComplexSource in the VTK layer) reads them the same way.
//
// An .inv3 file is a gzip-compressed tar archive written by InVesalius 3: `main.plist` (an Apple
// XML property list) names the scan's raw array under "matrix" (its "filename", its numpy "dtype"
// and its "shape" as [nz, ny, nx]) and gives "spacing" as [sx, sy, sz] in mm; the array is raw,
// little-endian, x varying fastest. InVesalius places the first voxel at the origin, so the grid's
// origin is (0, 0, 0) and its point (i, j, k) is at (i sx, j sy, k sz) (the issue-15 specimen's
// coordinates are in this frame; Data/Studies/ct-implant/README.md shows the check).

#include "Voxel/VoxelGrid.h"

#include <cstdint>
#include <memory>
#include <string>

namespace ictk::voxel
{

/// Whether `path` names a volume the core reads itself (.vdb, .inv3), by its extension.
bool isCoreVolume(const std::string& path);

/// Reads a .vdb (readVdb, `array` the grid name) or .inv3 (readInv3) volume; throws
/// std::invalid_argument for another extension.
std::shared_ptr<VoxelGrid> readCoreVolume(const std::string& path, const std::string& array = "");

/// The most an .inv3 archive may inflate to: 8 GiB, four times a 1024 x 1024 x 1024 scan of
/// 16-bit values, far above any clinical CT or MRI.
constexpr std::uint64_t MaxInv3Bytes = std::uint64_t{ 8 } << 30;

/// Reads the scan of an InVesalius project. `array` is "" or "matrix" (the scan; InVesalius's
/// masks and surfaces are not read). dtypes int16, uint16, int8, uint8 and float32 are converted
/// to float. Throws std::runtime_error naming the file for a missing or unreadable file, data
/// that is not gzip or is cut short, a tar without main.plist or without the matrix file, a plist
/// without a valid "matrix" (dtype, filename, shape) or "spacing", an unsupported dtype, and a
/// matrix whose byte count differs from what its shape and dtype need (both counts in the
/// message), and an archive that inflates to more than `maxInflatedBytes` (a damaged file or a
/// gzip bomb: it is refused before it fills the memory).
std::shared_ptr<VoxelGrid> readInv3(const std::string& path, const std::string& array = "",
  std::uint64_t maxInflatedBytes = MaxInv3Bytes);

} // namespace ictk::voxel
