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
#include "FRep/Tape.h"
#include "Skin/SkinnedMesh.h"

#include <array>
#include <functional>
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

/// The stand-in's field compiled once for a number of segments, each segment's ends, kernel width
/// and weight 1 / f_i(r_i) being parameters of the tape (ParametersPerSegment a segment: a, b,
/// s, weight): a stand-in posed or refitted (the same segments, other ends and radii) only binds
/// its values (parameters()), one tape for every frame as libfive's free variables are. Bound to
/// a stand-in, the tape gives in double precision what standInShape(that stand-in) compiled
/// gives, bit for bit: both are one expression, over constants there and parameters here.
class StandInField
{
public:
  static constexpr std::size_t ParametersPerSegment = 8;
  explicit StandInField(std::size_t segmentCount);
  const frep::TapePtr& tape() const { return tape_; }
  std::size_t segmentCount() const { return segmentCount_; }
  /// The tape's parameters for `standIn`; throws std::invalid_argument when its number of
  /// segments is not segmentCount().
  std::vector<double> parameters(const StandIn& standIn) const;

private:
  std::size_t segmentCount_ = 0;
  frep::TapePtr tape_;
};

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
  /// fitEmbeddedStandIn: F <= -margin at the constraint points (a stand-in kept this far under
  /// the mesh, in F's units: F is -1 far away).
  double margin = 0;
};

struct StandInFitReport
{
  double initialCost = 0; ///< 1/2 sum F(v)^2 before the fit
  double finalCost = 0;
  double initialMeanDistance = 0; ///< mean |F(v)| over the points
  double finalMeanDistance = 0;
  int iterations = 0;
  double seconds = 0;         ///< wall time of the fit
  std::size_t violations = 0; ///< fitEmbeddedStandIn: constraint points left with F > 0
};

/// Fits the radii of `standIn` to `points` (the rest mesh's vertices) as described above.
StandInFitReport fitStandIn(
  StandIn& standIn, const std::vector<Vec3>& points, const StandInFitOptions& options = {});

/// The same least-squares fit kept inside the mesh (thesis L3276: the stand-in must be "fully
/// embedded" in the mesh for the blend not to show it through): minimise 1/2 sum_v F(v)^2 over
/// the vertices subject to F(q) <= 0 at every vertex, edge middle and triangle centroid q (a
/// stand-in touching the vertices alone would bulge through the flat triangles between them).
/// F = A k - 1 is linear in the weights k_i = 1 / f_i(r_i), so this is a convex quadratic
/// programme; it is solved by the barrier method (Newton steps on the cost plus the logarithms of
/// the constraints' slacks, their weight falling twentyfold per round; `iterations` counts the
/// Newton steps), from near every radius 0. The radii range over [0, maxFactor x the initial one]
/// (minFactor is not used); a radius is recovered from k_i by inverting f_i (bisection). A point
/// where the stand-in is positive even with every radius 0 (where many short bones meet) is left
/// out of the constraints and counted in `violations`.
StandInFitReport fitEmbeddedStandIn(StandIn& standIn, const std::vector<Vec3>& points,
  const std::vector<std::array<int, 3>>& triangles, const StandInFitOptions& options = {});

/// The stand-in of a mesh as models use it (the engine's standIn(cell)): the initial
/// approximation fitted embedded in the rest mesh (fitEmbeddedStandIn) with a margin of 0.05.
StandIn fittedStandIn(const SkinnedMesh& mesh, StandInFitReport* report = nullptr);

// ---- how well the stand-in sits in its mesh (thesis L3276: "fully embed the convolution surface
// into the mesh when no deformation is applied") --------------------------------------------------

/// Points on the stand-in's surface (F = 0): from `along` points spaced evenly on each segment
/// (its ends included), along `directions` unit vectors spread over the sphere (a Fibonacci
/// lattice), the first place where F falls to 0 (marched in steps of a quarter of the segment's
/// radius, then refined by frep::refineRoot). A start where F <= 0 gives no sample.
std::vector<Vec3> standInSurfaceSamples(const StandIn& standIn, int along = 3, int directions = 32);

/// The generalised winding number of a triangle mesh at p (Jacobson, Kavan and Sorkine-Hornung
/// 2013): the solid angles its triangles subtend at p (Van Oosterom and Strackee's formula),
/// summed and divided by 4 pi. 1 inside and 0 outside a closed mesh whose triangles turn
/// counter-clockwise seen from outside (-1 inside with the other orientation); a mesh with holes
/// (BCN_Epileptic's patches are not sewn at its seams) keeps values near 1 inside and near 0
/// outside away from its holes, so |w| > 1/2 is its inside test.
double windingNumber(
  const std::vector<Vec3>& points, const std::vector<std::array<int, 3>>& triangles, const Vec3& p);

struct StandInEmbedding
{
  std::size_t samples = 0; ///< the stand-in's surface samples (standInSurfaceSamples)
  std::size_t inside = 0;  ///< those inside the mesh: |winding number| > 1/2
  double fraction() const { return samples ? double(inside) / double(samples) : 0.0; }
};

/// How much of the stand-in's surface lies inside the rest mesh (the bind pose).
StandInEmbedding standInEmbedding(const SkinnedMesh& mesh, const StandIn& standIn);

// ---- refits at key frames (thesis L3268-3270) -------------------------------------------------

/// For every segment of a posed stand-in: the stand-in-to-bone distance (how far its surface
/// reaches from the bone: the largest distance to F = 0 from the bone's middle and quarter points
/// in eight directions normal to it) and the bone-to-mesh distance (the smallest distance from
/// the bone to a vertex of the posed mesh). The thesis refits "when the distance between the
/// convolution surface and the bone exceeds the distance between the bone and the mesh": the
/// surface then passes out through the mesh near that bone.
struct BoneClearance
{
  double standInToBone = 0;
  double boneToMesh = 0;
  bool exceeds() const { return standInToBone > boneToMesh; }
};
std::vector<BoneClearance> boneClearances(
  const StandIn& posed, const std::vector<Vec3>& posedPoints);

/// Radii fitted at key frames and interpolated between them (thesis L3268: "the re-estimated
/// parameters are updated at the key-frames ... and then they are interpolated during the
/// playback"): linear in time between the two keys around t, the first or last key's before or
/// after them. The stand-in's segments are its rest ones; the radii are those of the key frame's
/// pose (poseStandIn scales them further by the joints' scale).
struct StandInKeys
{
  std::vector<double> times; ///< increasing
  std::vector<std::vector<double>> radii;
  /// The stand-in with the radii at t (kernel widths kept).
  StandIn at(const StandIn& rest, double t) const;
};

/// Refits the radii of `rest` at a key frame: the stand-in posed by `jointMatrices`, fitted
/// embedded (fitEmbeddedStandIn) to the mesh posed by them, its radii brought back to the rest
/// frame (divided by the joints' scale that poseStandIn multiplies them by). The kernel widths
/// stay. Returns the fit's report.
StandInFitReport refitStandIn(StandIn& rest, const SkinnedMesh& mesh,
  const std::vector<Affine>& jointMatrices, const StandInFitOptions& options = {});

/// Key frames where the stand-in needs a refit: the user's `times`, and every time of
/// `candidates` (e.g. the animation's frames) where a bone's clearance is exceeded
/// (boneClearances) with the radii interpolated from the keys made so far. Each key is refitted
/// (refitStandIn) in time order. `matricesAt(t)` gives the joints' skinning matrices.
StandInKeys refitAtKeyFrames(const StandIn& rest, const SkinnedMesh& mesh,
  const std::function<std::vector<Affine>(double)>& matricesAt, const std::vector<double>& times,
  const std::vector<double>& candidates, const StandInFitOptions& options = {});

} // namespace ictk::skin
