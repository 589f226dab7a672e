// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Discretisation of 0D implicit cells (points) of E^3 (seed 001 1.4: "the intersection of three
// surfaces, the intersection of a curve and a surface"):
//  - solvePoints: where three fields vanish, by interval subdivision and Newton;
//  - curveCrossings: where a discretised curve crosses a surface g = 0.
// Both are deterministic for any thread count; bad input raises std::invalid_argument.

#include "Discretize/Mesh.h"

namespace ictk::discretize
{

struct PointOptions
{
  /// Edge of the subdivision's smallest boxes (0 = the box diagonal / 64). Roots closer than
  /// about this may be reported once.
  double size = 0;
  /// Points satisfy |g_i| <= tolerance * |grad g_i| (about a distance).
  double tolerance = 1e-10;
  int maxIterations = 30;
  /// Points closer than this are one point (0 = max(1e-7 * box diagonal, 100 * tolerance)).
  double mergeDistance = 0;
  /// Throw std::invalid_argument beyond this many candidate boxes (the fields then vanish on a
  /// curve or a surface, not at isolated points) or beyond 2^20 boxes along an axis.
  double maxBoxes = 1e6;
  int threads = 0;
};

/// The points of `box` where g1, g2 and g3 all vanish: the boxes of a subdivision where interval
/// arithmetic says all three may vanish are refined to options.size, then Gauss-Newton from
/// each box's centre (and its octant centres) keeps the roots found inside the box; roots are
/// merged within options.mergeDistance and returned in lexicographic (x, y, z) order. A point
/// array "sine" holds |det J| / (|grad g1| |grad g2| |grad g3|) at each point (near 0: the
/// surfaces meet tangentially there and the point is ill-conditioned).
PointSet solvePoints(const frep::Field& g1, const frep::Field& g2, const frep::Field& g3,
  const Box3& box, const PointOptions& options = {});

struct CrossingOptions
{
  /// The fields the curve lies on (0 to 2; e.g. traceCurve's g1, g2). When given, every
  /// crossing is projected onto {carriers = 0, g = 0}; otherwise it stays on the polyline.
  std::vector<frep::FieldPtr> carriers;
  double tolerance = 1e-10;
  int maxIterations = 30;
};

/// The points where the polylines of `curves` cross g = 0: a segment whose ends lie on
/// different sides (g >= 0 against g < 0, so a vertex where g is exactly 0 is counted once) is
/// bisected to the crossing, which is then projected as CrossingOptions says. Point arrays
/// "line" and "segment" hold the polyline index and the segment index within it; points are in
/// polyline then segment order.
PointSet curveCrossings(
  const CurveSet& curves, const frep::Field& g, const CrossingOptions& options = {});

} // namespace ictk::discretize
