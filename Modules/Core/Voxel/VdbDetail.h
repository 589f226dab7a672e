// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// What the OpenVDB writers of this module share (VdbIO.cxx, NarrowBand.cxx). It includes OpenVDB,
// which is a private dependency: only .cxx files of the Voxel module include this header.

#include <openvdb/openvdb.h>

#include <array>
#include <string>

namespace ictk::voxel::detail
{

/// openvdb::initialize(), once per process.
void initialiseOpenVdb();

/// Index (i, j, k) -> origin + (i, j, k) * spacing: a uniform linear transform when the spacing
/// is the same on every axis, else a scale-and-translate map.
openvdb::math::Transform::Ptr gridTransform(
  const std::array<double, 3>& origin, const std::array<double, 3>& spacing);

/// Writes `vdb` as the only grid of a new file at `path`: under a temporary name in the same
/// folder, renamed over `path` when complete, so a failure never leaves a truncated file.
/// std::runtime_error starting with `where` when the folder is missing or writing fails.
void writeAtomically(
  const openvdb::GridBase::Ptr& vdb, const std::string& path, const std::string& where);

} // namespace ictk::voxel::detail
