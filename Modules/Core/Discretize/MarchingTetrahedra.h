// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Discretisers of implicit sets of every dimension, over frep::Field (OpenVDB tools style: small
// functions over plain data):
//  - contourSurface: the surface {f = 0} by marching tetrahedra (Kuhn split of the cubes, so
//    there are no ambiguous cases and the result is a manifold), visiting only the blocks that
//    interval arithmetic cannot prove empty, vertices refined onto f = 0 along their edge;
//  - trimSurface: the part of a carrier mesh where trim fields are >= 0, the cut edges projected
//    onto {carrier = 0, trim = 0};
//  - curvesOnSurface: {g1 = 0, g2 = 0} as polylines, contoured on a mesh of g1 = 0 and projected
//    onto both surfaces by Gauss-Newton (sign-change contouring of -(g1^2 + g2^2) would see
//    nothing: that set has no inside);
//  - triangulateRegion2D / curves2D: the same in the (u, v) plane for mapped cells;
//  - solvePoints: where three fields vanish, by interval subdivision and Newton.
// All are deterministic for any thread count.

#include "Discretize/Mesh.h"

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
  bool closeAtBox = true;
  /// Refuse grids with more cells (std::invalid_argument with the estimate).
  double maxCells = 4e9;
  /// Called with the completed fraction; return false to cancel (throws frep::Cancelled).
  std::function<bool(double)> progress;
};

SurfaceMesh contourSurface(
  const frep::Field& field, const Box3& box, const ContourOptions& options);

struct ProjectionOptions
{
  /// Stop when every |f_i| <= tolerance * |grad f_i|, i.e. within `tolerance` in distance.
  double tolerance = 1e-9;
  int maxIterations = 20;
};

/// Moves p onto {f_i = 0 for all i} (1 to 3 fields) by Gauss-Newton with the minimum-norm step.
/// Returns false when it did not converge (p is then the last iterate).
bool projectOntoSet(const std::vector<frep::FieldEvaluator*>& fields, Point3& p,
  const ProjectionOptions& options = {});

/// The part of `carrierMesh` (a mesh of {carrier = 0}) where every trim is >= 0.
SurfaceMesh trimSurface(const SurfaceMesh& carrierMesh, const frep::Field& carrier,
  const std::vector<frep::FieldPtr>& trims, const ProjectionOptions& options = {});

/// {g1 = 0, g2 = 0, trims >= 0} as polylines, contoured on `g1Mesh` (a mesh of {g1 = 0}).
CurveSet curvesOnSurface(const SurfaceMesh& g1Mesh, const frep::Field& g1, const frep::Field& g2,
  const std::vector<frep::FieldPtr>& trims, const ProjectionOptions& options = {});

/// {f >= 0} in the (u, v) = (x, y) rectangle of `box` (z ignored), triangulated on a grid of
/// edge `size`; boundary vertices lie on f = 0.
SurfaceMesh triangulateRegion2D(const frep::Field& f, const Box3& box, double size);

/// {g = 0, trims >= 0} in the (u, v) rectangle as polylines (z = 0).
CurveSet curves2D(const frep::Field& g, const std::vector<frep::FieldPtr>& trims, const Box3& box,
  double size, const ProjectionOptions& options = {});

/// Points where the three fields vanish inside the box, found to `options.tolerance`, merged
/// when closer than `mergeDistance`, in lexicographic order.
PointSet solvePoints(const frep::Field& f1, const frep::Field& f2, const frep::Field& f3,
  const Box3& box, double mergeDistance, const ProjectionOptions& options = {});

/// Keeps the points where every field is >= -tolerance.
PointSet keepInside(
  const PointSet& points, const std::vector<frep::FieldPtr>& fields, double tolerance);

/// Pushes (u, v) points through h = (hx, hy, hz); the (u, v) coordinates are kept as a point
/// array named "uv".
void mapToSpace(std::vector<Point3>& points, std::vector<PointArray>& pointData,
  const frep::Field& hx, const frep::Field& hy, const frep::Field& hz);

} // namespace ictk::discretize
