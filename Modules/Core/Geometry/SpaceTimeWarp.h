// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Time-dependent deformations for space-time blending (thesis 5.3.3, L3112-L3124): a warp of the
// two operands controlled by point pairs (source feature of cellA -> destination feature of
// cellB), and the automatic control points of eq. (4), the "thick features" of a shape.
//
// The warp. With u = (t - t0) / (t1 - t0) clamped to [0, 1] and the pairs (s_i, d_i), the i-th
// feature is at m_i = s_i + u (d_i - s_i) at time t. Each operand is evaluated through a
// backward displacement: cellA at p + D_A(p), cellB at p + D_B(p), where D_A takes m_i to s_i
// (D_A(m_i) = s_i - m_i = -u (d_i - s_i)) and D_B takes m_i to d_i (D_B(m_i) = (1 - u)(d_i - s_i)).
// Between the nodes the displacements are Shepard's interpolation with weights 1 / |p - m_i|^2:
// D(p) = sum w_i D_i / sum w_i, a rational function of p, smooth, exact at the nodes with a
// zero derivative there (so each feature moves rigidly), bounded by the node values (a convex
// combination), and the mean of the node values far away. So cellA's source features travel to
// the destinations while cellB's destination features come from the sources, both sit on the
// same moving nodes, and the blend of the two stays in one piece where their features overlap.
// At u = 0 cellA is unwarped (the slice before t0 is cellA), at u = 1 cellB is.
//
// The automatic control points (eq. 4): strict local maxima of the Euclidean distance transform
// (EDT) inside the shape, which lie on its medial surface. The shape is sampled on a grid of
// cells of side h over its world box (128 cells along the longest side in 2D, 64 in 3D); the EDT
// of an inside cell is the distance from its centre to the nearest outside cell's centre minus
// h / 2 (the boundary lies between the two), exact on the grid (separable squared EDT). On a
// grid a ridge of the medial surface is flat (a rectangle's axis), so a cell counts as a maximum
// when no neighbour (8 in 2D, 26 in 3D) is larger; the maxima are taken in decreasing distance
// (ties in grid order), each at least `separation` from those already taken, up to `count`.
//
// Pairing (pairControlPoints): a source and a destination set of n and m points. The
// min(n, m) points of the smaller set are matched one to one with points of the larger set so
// that the total distance is least (every assignment is tried, the first least in lexicographic
// order wins: deterministic); each point of the larger set left over is paired with its nearest
// point of the smaller set (the first on a tie). So a disk (one maximum, its centre) to two
// disks gives the pairs centre -> each disk's centre: the disk is stretched into both.

#include "FRep/Vector.h"

#include <vector>

namespace ictk::geometry
{

using Vec3 = frep::Point3;
struct PlacedShape;

/// One control pair of a space-time warp: a feature of cellA at `source` becomes one of cellB
/// at `destination` (world coordinates).
struct ControlPair
{
  Vec3 source{ 0, 0, 0 };
  Vec3 destination{ 0, 0, 0 };
};

/// The most control points pairControlPoints takes per set (it tries every assignment).
constexpr int kMaxControlPoints = 8;

/// The thick features of a 2D or 3D placed shape (eq. 4; see above): up to `count` local maxima
/// of its EDT, at least `separation` apart, in decreasing distance to the boundary. `depths`,
/// when given, receives each point's EDT value. Throws std::invalid_argument for a 0D/1D shape,
/// count < 1 or a negative separation.
std::vector<Vec3> thickFeatures(
  const PlacedShape& shape, int count, double separation, std::vector<double>* depths = nullptr);

/// Pairs sources with destinations (see above). Empty when either set is; throws
/// std::invalid_argument when either has more than kMaxControlPoints points.
std::vector<ControlPair> pairControlPoints(
  const std::vector<Vec3>& sources, const std::vector<Vec3>& destinations);

/// The warp of a space-time blend at transition progress u in [0, 1] (see above): the moving
/// nodes m_i and the backward displacements of cellA and cellB there.
struct SpaceTimeWarp
{
  std::vector<Vec3> nodes;
  std::vector<Vec3> shiftA, shiftB;

  static SpaceTimeWarp at(const std::vector<ControlPair>& pairs, double u);
  bool empty() const { return nodes.empty(); }
  /// Shepard's interpolation of `shifts` (shiftA or shiftB) at p; with `jacobian` (row-major
  /// 3 x 3), its derivative there.
  Vec3 shift(const std::vector<Vec3>& shifts, const Vec3& p, double* jacobian = nullptr) const;
};

} // namespace ictk::geometry
