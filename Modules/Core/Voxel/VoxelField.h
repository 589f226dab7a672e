// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// A voxel grid as an FRep field (a voxel cell): f >= 0 inside, f = 0 on the surface.
//
// Inside the grid's box G, with v the trilinear interpolant of the grid values and s = +1 when
// the inside is above the iso-value (s = -1 when it is below):
//     F(p) = s * (v(p) - iso)
// Everywhere, with clamp(p) the nearest point of G and d_G the signed distance to G (positive
// inside, the Euclidean distance to the box negated outside):
//     f(p) = min(F(clamp(p)), L * d_G(p))
// where L is a Lipschitz bound of F (the largest edge difference of the grid divided by the
// spacing, per axis, combined as a Euclidean norm; for a constant grid L = max(|F|, 1) divided by
// the smallest spacing). So:
// - f < 0 strictly outside G: the cell is the part of {F >= 0} inside G, closed by G's faces where
//   the material touches them (a CT scan cut by its field of view is a closed solid);
// - f is continuous and L-Lipschitz everywhere (F o clamp is, and so is L * d_G);
// - f = F exactly inside G wherever F <= L * d_G; in particular everywhere inside G when F <= 0
//   on G's boundary (the object lies inside the grid). Where the material touches a face, only
//   positive values within about F / L of that face are lowered (never their sign, except on the
//   face itself, where f = 0);
// - the zero set inside the open box G is exactly the iso-surface of the trilinear interpolant.
//
// bound(box) encloses f over the box with no rounding slack needed: the values of f come from a
// convex combination of the vertex values of the cells the (clamped) box touches, and min/max of
// those values come from a min/max pyramid (blocks of 8^3 cells, then 8^3 blocks, ...) built once
// when the field is created. For boxes touching at most 64^3 vertices the min/max is exact (the
// values of those cells: the blocks the box covers in part are scanned, unless their own min/max
// already lies within the range found, which is the common case for smooth data); for larger
// boxes the partly covered 8^3 blocks count whole (still an enclosure, looser by the values
// within 8 cells of the box), so a query costs about the number of blocks touched rather than
// the box's surface in voxels. Combined with the exact range of
// L * d_G over the box, bound() is tight for a constant grid.
//
// gradient() is the gradient of the piece that gives the value (the trilinear interpolant's
// within the cell holding the clamped point, zero along clamped axes; or L times d_G's). On a
// cell face the cell with the larger index is used, except at the grid's last point.
//
// Evaluators hold no mutable state beyond scratch space; the field keeps the grid alive.

#include "Voxel/VoxelGrid.h"

#include <memory>

namespace ictk::voxel
{

/// The voxel cell of `grid` at `isoValue` (see the file comment). Validates the grid (throws
/// std::invalid_argument as validate() does) and a finite iso-value.
frep::FieldPtr voxelField(
  std::shared_ptr<const VoxelGrid> grid, double isoValue, bool insideAbove = true);

/// The Lipschitz bound L used by voxelField(grid, isoValue, ...) for the box distance term (the
/// largest gradient norm the trilinear interpolant of the grid can have).
double lipschitzBound(const VoxelGrid& grid, double isoValue);

} // namespace ictk::voxel
