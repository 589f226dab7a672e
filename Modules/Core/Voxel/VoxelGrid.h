// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// A dense regular grid of scalar samples (a CT scan, a sampled FRep, a densified OpenVDB grid),
// the data of a voxel cell. Values sit at the grid points; a voxel cell interpolates them
// trilinearly (VoxelField.h).

#include "FRep/Field.h"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace ictk::voxel
{

using frep::Point3;

struct VoxelGrid
{
  /// Points per axis (at least 2 each: a cell needs two points along every axis).
  std::array<std::int64_t, 3> dimensions{ 0, 0, 0 };
  /// Position of the point (0, 0, 0).
  Point3 origin{ 0, 0, 0 };
  /// Distance between neighbouring points along each axis (finite, > 0).
  Point3 spacing{ 1, 1, 1 };
  /// pointCount() values, x varying fastest, then y, then z (VTK's point order).
  std::vector<float> values;

  std::int64_t pointCount() const { return dimensions[0] * dimensions[1] * dimensions[2]; }
  std::int64_t index(std::int64_t i, std::int64_t j, std::int64_t k) const
  {
    return i + dimensions[0] * (j + dimensions[1] * k);
  }
  float at(std::int64_t i, std::int64_t j, std::int64_t k) const
  {
    return values[static_cast<std::size_t>(index(i, j, k))];
  }
  Point3 point(std::int64_t i, std::int64_t j, std::int64_t k) const
  {
    return { origin[0] + static_cast<double>(i) * spacing[0],
      origin[1] + static_cast<double>(j) * spacing[1],
      origin[2] + static_cast<double>(k) * spacing[2] };
  }
  /// The box spanned by the grid points.
  frep::Box3 bounds() const;
};

/// Throws std::invalid_argument, with `what` leading the message, when a dimension is below 2,
/// the point count overflows, values.size() differs from pointCount(), the origin is not
/// finite, a spacing is not finite and positive, the far corner is not finite, or a value is NaN
/// or infinite (the message names the first bad point by (i, j, k) and linear index, and how many
/// bad values there are).
void validate(const VoxelGrid& grid, const std::string& what = "voxel grid");

/// Samples `field` at resolution[0] x resolution[1] x resolution[2] points spanning `box`
/// (corners included; each resolution at least 2), in parallel. The grid's values are the
/// field's values rounded to float (magnitudes beyond the float range are clamped to +-FLT_MAX).
/// Throws std::invalid_argument for a bad box or resolution, or a grid over the memory budget of
/// frep::checkGrid, and std::runtime_error when the field is NaN at a point (named in the
/// message).
VoxelGrid sampleToGrid(
  const frep::Field& field, const frep::Box3& box, std::array<std::int64_t, 3> resolution);

/// Stamps a solid into the grid (an implant into a scan, issue 15): every grid point where
/// `region` >= 0 takes `value` (e.g. titanium's Hounsfield units), the others keep theirs, so
/// the scan's materials and iso-surface see the implant. Returns how many points were stamped.
/// Rows of points whose interval bound is negative are skipped unevaluated. Throws
/// std::invalid_argument for a non-finite value.
std::int64_t stamp(VoxelGrid& grid, const frep::Field& region, double value);

} // namespace ictk::voxel
