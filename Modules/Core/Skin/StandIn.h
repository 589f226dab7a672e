// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Implicit stand-ins of skinned meshes (issue 17; thesis 5.4, L3239-3270): a convolution surface
// whose skeleton is the mesh's rigging skeleton, embedded in the mesh, that moves with it and can
// be blended with FRep objects (a liquid) or metamorphosed where the mesh cannot.
//
// - The initial approximation (L3254): one line segment per bone, between the markers of its two
//   joints (a joint and its parent joint, at their origins in the rest mesh's frame: the inverse
//   of the joint's offset matrix applied to the origin); its radius is the minimal distance from
//   the segment to the mesh, here to the mesh's vertices (within the sagitta of its triangles).
// - The field: F(p) = sum_i f_i(p) / f_i(r_i) - 1, f_i the Cauchy convolution field of segment i
//   (FRep's cauchySegmentField, kernel width s_i = 1 / r_i of the initial approximation, fixed)
//   and f_i(r) its value at distance r from the segment's middle: a segment alone is zero at
//   distance r_i from its middle, and >= 0 inside.
// - The fit (L3256): the radii minimising the algebraic distance of the mesh vertices from the
//   surface, 1/2 sum_v F(v)^2, with bounds on every radius, by a projected Levenberg-Marquardt
//   method (the constrained variant of Kanzow, Yamashita and Fukushima 2005 the thesis cites:
//   each damped Gauss-Newton step is projected onto the bounds and accepted when it lowers the
//   cost; the damping falls after a success and grows after a failure).
// - Posing: a segment's ends are its joints' origins carried by their skinning matrices, so the
//   stand-in follows the skeleton exactly (L3266).

#include "FRep/Domain.h"
#include "Skin/SkinnedMesh.h"

#include <vector>

namespace ictk::skin
{

struct StandInSegment
{
  int joint = -1;                  ///< the bone's end (an index into SkinnedMesh::joints)
  int parentJoint = -1;            ///< its start: the joint of the node's nearest joint ancestor
  Vec3 a{ 0, 0, 0 }, b{ 0, 0, 0 }; ///< the ends, in the rest mesh's frame
  double s = 1;                    ///< the kernel width (1 / the initial radius)
  double radius = 0;
};

struct StandIn
{
  std::vector<StandInSegment> segments;
};

/// The initial approximation of `mesh` (see above). Bones of zero length are skipped; throws
/// std::invalid_argument naming the file when no bone is left or a segment touches the mesh
/// (radius 0).
StandIn initialStandIn(const SkinnedMesh& mesh);

/// The stand-in's field as an FRep shape (domain XYZ), in the frame of its segments' ends.
frep::Shape standInShape(const StandIn& standIn);

/// A box that holds the stand-in's surface: its segments' box grown by twice the largest radius
/// (a segment alone is zero at its radius; where k segments meet their sum reaches further,
/// each term falling at least as 1 / distance^3 beyond it).
frep::Box3 standInBounds(const StandIn& standIn);

/// The stand-in posed by the mesh's skinning matrices (jointMatrices): every segment's ends
/// moved by their joints' matrices, its radius multiplied and its kernel width divided by their
/// scale (the cube root of the determinant of their linear parts, the mean of its two ends), so
/// that a skeleton scaled uniformly scales its stand-in (FBX files pose their meshes so).
StandIn poseStandIn(const StandIn& standIn, const std::vector<Affine>& jointMatrices);

struct StandInFitOptions
{
  /// Every radius stays in [minFactor, maxFactor] x its initial value.
  double minFactor = 0.25;
  double maxFactor = 4.0;
  int maxIterations = 100;
  /// Stop when a step changes the cost by less than this fraction of it.
  double relativeTolerance = 1e-12;
};

struct StandInFitReport
{
  double initialCost = 0; ///< 1/2 sum F(v)^2 before the fit
  double finalCost = 0;
  double initialMeanDistance = 0; ///< mean |F(v)| over the points
  double finalMeanDistance = 0;
  int iterations = 0;
  double seconds = 0; ///< wall time of the fit
};

/// Fits the radii of `standIn` to `points` (the rest mesh's vertices) as described above.
StandInFitReport fitStandIn(
  StandIn& standIn, const std::vector<Vec3>& points, const StandInFitOptions& options = {});

} // namespace ictk::skin
