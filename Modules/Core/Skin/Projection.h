// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The projection of a skinned mesh onto its implicit stand-in (issue 17; thesis 5.5, L3409-3422):
// the first and last steps of a controlled metamorphosis between animated meshes. Every vertex
// gets an offset dp_i in the bind pose that takes it onto the stand-in's surface and the stand-in's
// outward normal there, ñ_i = -grad F / |grad F| (F >= 0 inside); the mesh is then posed by
// skinning the moved vertices and normals (L3416, L3418):
//
//   p'_i(t) = sum_j w_ij M_j(t) f_alpha(p_i, p_i + dp_i) + alpha_i c_i(t)
//   n'_i(t) = slerp(normalize(A_i^-T g_alpha(n_i, ñ_i)), ñ'_i(t), alpha_i)
//
// - f_alpha is the straight line (1 - alpha_i) p_i + alpha_i (p_i + dp_i), g_alpha the spherical
//   interpolation of the unit normals (slerp: it stays unit and turns at an even rate, where the
//   normalised straight line would pass through 0 for opposite normals).
// - Normals are skinned by the inverse transpose of the blended linear part A_i = sum_j w_ij
//   M_j's: the thesis prints M_j^-1 (an erratum; SkinnedMesh.h).
// - c_i(t), the posed remainder (ours): skinning the bind-pose projection does not put a vertex on
//   the posed stand-in, since linear blend skinning blends a vertex weighed by several joints
//   while every convolution segment moves rigidly with its two joints (and keeps its round
//   section under a non-uniform scale). Measured on huesitos.fbx (9 bones) |F| reaches 1.28 along
//   its animation at alpha = 1, on skinned_tube.gltf 0.49: the thesis' switch "when the positions
//   and normals of all the vertices are aligned with the stand-in" (L3420) would never come. So
//   the skinned projection q0_i = sum_j w_ij M_j (p_i + dp_i) is projected again onto the posed
//   stand-in (the same Newton's method, from q0_i), c_i = that point - q0_i, and ñ'_i(t) is the
//   posed stand-in's outward normal there. c_i vanishes in the bind pose and wherever skinning
//   carries the stand-in exactly; alpha_i = 0 is the plain skinned mesh, bit for bit, and alpha_i
//   = 1 puts every vertex on the posed stand-in with its normal.
// - alpha_i: the model's alpha, or delayed per vertex by a weight map (L3435: "which parts of the
//   mesh have to be projected / unprojected first"): see delayedAlpha.
//
// The projection is Newton's along the gradient, p <- p - F(p) grad F / |grad F|^2, each step
// halved while it does not lower |F|, until |F| < epsilon (the stand-in's F is dimensionless: 0 on
// the surface, -1 far away).

#include "FRep/Field.h"
#include "Skin/StandIn.h"

#include <cstddef>
#include <vector>

namespace ictk::skin
{

struct ProjectionOptions
{
  double epsilon = 1e-9; ///< |F| below which a vertex is on the stand-in
  int maxIterations = 100;
};

struct Projection
{
  std::vector<Vec3> offsets;        ///< dp_i, in the bind pose
  std::vector<Vec3> standInNormals; ///< ñ_i at p_i + dp_i, unit, outward
  double maxResidual = 0;           ///< max |F(p_i + dp_i)|
  int iterations = 0;               ///< the most any vertex took
  int failures = 0;                 ///< vertices left with |F| >= epsilon
  std::size_t firstFailure = 0;     ///< the first of them (when failures > 0)
};

/// Projects the rest mesh's vertices onto `standIn` (in the rest frame).
Projection projectOntoStandIn(
  const SkinnedMesh& mesh, const StandIn& standIn, const ProjectionOptions& options = {});

/// The rest points moved a fraction alpha (clamped to [0, 1]) of the way to their projections.
std::vector<Vec3> projectedRestPoints(
  const SkinnedMesh& mesh, const Projection& projection, double alpha);

/// The rest mesh's unit normals: the file's, or (when it has none) the area-weighted normals of
/// its triangles (outward for triangles counter-clockwise seen from outside).
std::vector<Vec3> restNormalsOf(const SkinnedMesh& mesh);

/// The unit vector a fraction s of the way from a to b along the great circle (a, b unit); for
/// opposite vectors the turn is about an axis normal to a.
Vec3 slerpDirection(const Vec3& a, const Vec3& b, double s);

// ---- per-vertex delays from a weight map (thesis L3435) ----------------------------------------
//
// A weight map gives every vertex a priority w_i (any finite numbers; only their order and spacing
// count: they are scaled to u_i = (w_i - min w) / (max w - min w) in [0, 1], all 1 when equal).
// Vertex i moves over a window of the model's alpha of length 1 - spread, starting at
// s_i = spread (1 - u_i):
//
//   alpha_i = clamp((alpha - s_i) / (1 - spread), 0, 1)
//
// so alpha_i(0) = 0 and alpha_i(1) = 1 for every vertex, alpha_i is non-decreasing in alpha, and
// alpha_i >= alpha_j whenever w_i >= w_j: as alpha rises the vertices of the highest weight reach
// the stand-in first (at alpha = 1 - spread), those of the lowest last (at alpha = 1); as it falls
// they leave it first. spread = 0 is no delay.

/// The window starts s_i of the weights; throws std::invalid_argument when spread is not in
/// [0, 1) or a weight is not finite (naming the vertex).
std::vector<double> projectionDelays(const std::vector<double>& weights, double spread);
/// alpha_i of the model's alpha (clamped to [0, 1]) for a vertex whose window starts at `delay`.
double delayedAlpha(double alpha, double delay, double spread);

// ---- posing ------------------------------------------------------------------------------------

struct ProjectedPose
{
  Posed posed;      ///< points and unit normals (always: restNormalsOf)
  int failures = 0; ///< vertices whose posed remainder did not converge
  std::size_t firstFailure = 0;
};

/// The thesis' formulas alone (L3416, L3418 with the inverse transpose): the rest points moved
/// alpha_i of the way to their projections, the rest normals turned alpha_i of the way to ñ_i
/// (g_alpha), both skinned by `jointMatrices`. `alphas`: one per vertex.
Posed skinProjected(const SkinnedMesh& mesh, const Projection& projection,
  const std::vector<Affine>& jointMatrices, const std::vector<double>& alphas);

/// The pose above with the posed remainder (see the top of the file): `posedStandIn` is the
/// stand-in's field posed by the same matrices (poseStandIn), in the frame of the posed mesh.
/// Vertices with alpha_i = 0 are the plain skinned ones (no projection is made for them).
ProjectedPose poseOnStandIn(const SkinnedMesh& mesh, const Projection& projection,
  const std::vector<Affine>& jointMatrices, const std::vector<double>& alphas,
  const frep::Field& posedStandIn, const ProjectionOptions& options = {});

/// How far a posed mesh is from its posed stand-in (the switch of L3420): the largest
/// first-order distance |F(p)| / |grad F(p)| of a vertex to the surface and the largest angle
/// between a vertex normal and the stand-in's outward normal there, both measured after `place`
/// (the cell's placement: F(place^-1 x) has the gradient place^-T grad F). A vertex where the
/// gradient vanishes counts as infinitely far.
struct ProjectionResidual
{
  double distance = 0;
  double degrees = 0;
  std::size_t farthest = 0; ///< the vertex of the largest distance
};
ProjectionResidual projectionResidual(
  const Posed& posed, const frep::Field& posedStandIn, const Affine& place = {});

} // namespace ictk::skin
