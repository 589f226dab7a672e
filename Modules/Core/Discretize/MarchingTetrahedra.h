// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The surface {f = 0} of a field by marching tetrahedra: the Kuhn split of the grid cubes has no
// ambiguous cases, so the result is a 2-manifold, oriented outwards (towards f < 0). Only the
// blocks that interval arithmetic cannot prove empty are visited, each with its tape pruned to
// the block; vertices are refined onto f = 0 along their grid edge. Used for the carrier
// surfaces of 2D cells (whose vertices must lie on the surface before trimming) and for solids.
// Deterministic for any thread count.

#include "Discretize/Mesh.h"
#include "FRep/Progress.h"

#include <functional>

namespace ictk::discretize
{

struct ContourOptions
{
  /// Grid cell edge (required > 0).
  double featureSize = 0;
  /// 0 = TBB's default.
  int threads = 0;
  /// Treat the outside of the box as outside the solid, so that a solid cut by the box is closed.
  /// Off for carrier surfaces, which trimming cuts.
  bool closeAtBox = true;
  /// Refuse grids with more cells (std::invalid_argument with the estimate).
  double maxCells = 4e9;
  /// Called with the completed fraction; return false to cancel (throws frep::Cancelled).
  Progress progress;
};

SurfaceMesh marchingTetrahedra(
  const frep::Field& field, const Box3& box, const ContourOptions& options);

} // namespace ictk::discretize
