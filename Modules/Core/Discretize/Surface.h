// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Adaptive, interval-pruned dual contouring of the surface f = 0 of a field (f >= 0 inside).
//
// The box is covered by a grid of cubic cells of edge `featureSize`, aligned to box.lo. An octree
// over the grid visits only the regions whose interval bound (FieldEvaluator::bound) may contain
// the surface, carrying pruned evaluators (FieldEvaluator::narrowed) down the recursion; small
// blocks of cells are sampled in one batch. At each sign-changing grid edge the crossing is found
// by false position on the field and its normal by the gradient (Hermite data); each cell gets
// one vertex per connected component of its marching-cubes patch (manifold dual contouring),
// placed by a quadric error function (sharp edges and corners are kept), and each
// sign-changing edge gives one quad, split into two triangles.
//
// Guarantees:
// - The mesh is a 2-manifold, consistently oriented with outward normals (towards f < 0), and
//   closed: points outside the box count as outside, so a solid cut by the box is closed by the
//   box faces. Ambiguous cell faces are resolved by the asymptotic decider, which sees the same
//   four values from both cells; where one vertex per patch component cannot be manifold (a
//   tunnel through two cells), the two vertices are split and the tunnel, narrower than a cell,
//   is closed off.
// - The output is identical, byte for byte, for any thread count.
// - Points are in world coordinates and each is used by at least one triangle.
// Not guaranteed: freedom from self-intersections (dual contouring may fold where the surface
// has features of about a cell: CGAL finds none on libfive's sphere-gyroid for featureSize up to
// 0.31, i.e. 5 cells per half-period of the gyroid, but 12-24 pairs at 0.4-0.5), and features
// thinner than a cell may be missed.

#include "Discretize/Mesh.h"
#include "FRep/Progress.h"

#include <cstddef>
#include <functional>
#include <memory>

namespace ictk::discretize
{

/// What contourSurface did with a SurfaceMemory (SurfaceOptions::memory) in its last call.
struct SurfaceReuse
{
  /// Blocks of BlockCells^3 grid cells (8^3) contoured from the field, and taken from the
  /// previous call instead; together, every block the octree visited (blocks with no surface
  /// included).
  std::size_t blocksContoured = 0;
  std::size_t blocksReused = 0;
  /// Octree nodes of 32^3 cells (the threads' tasks) whose whole subtree was taken from the
  /// previous call without descending into it; their blocks count as reused.
  std::size_t tasksReused = 0;
  std::size_t tasks = 0;
};

/// Work kept between calls of contourSurface on a field that changes in some regions only (a
/// cell whose shape parameters change from frame to frame: time-coherent re-meshing, thesis
/// 4.6.8). Each call contours the regions whose field may have changed and takes the others
/// from the previous call.
///
/// Why it is exact: the octree hands every node (a task of 32^3 cells, and each block of 8^3
/// cells) an evaluator narrowed to the node's box, and what the node yields (its blocks: signs,
/// Hermite data, vertices) is a function of that evaluator's results, the node's place in the
/// grid and whether it is known to be inside. The memory keeps, per node, the evaluator's
/// fingerprint (FieldEvaluator::fingerprint: its pruned tape, the parameter values and time that
/// tape reads, placements...) and what the node yielded; a node whose evaluator has the same
/// fingerprint as in the previous call yields the same again, bit for bit, so it is copied
/// instead. A changed parameter therefore costs only the nodes where the pruned tape still
/// reads it (where its term can reach the surface); the rest of the assembly (vertex numbering,
/// quads, repairs) runs every call. A node whose evaluator cannot give a fingerprint is always
/// contoured, and a different grid (box, feature size, sharp features) forgets everything.
/// The result is the same mesh as without a memory, for any thread count.
///
/// One memory serves one surface (one cell); it is not thread safe: one call at a time.
class SurfaceMemory
{
public:
  SurfaceMemory();
  ~SurfaceMemory();
  SurfaceMemory(const SurfaceMemory&) = delete;
  SurfaceMemory& operator=(const SurfaceMemory&) = delete;
  /// The counts of the last call made with this memory.
  const SurfaceReuse& lastCall() const { return last_; }
  /// Forgets what was kept.
  void clear();

  struct State; // SurfaceDetail.h
  State& state() { return *state_; }
  void setLastCall(const SurfaceReuse& r) { last_ = r; }

private:
  std::unique_ptr<State> state_;
  SurfaceReuse last_;
};

struct SurfaceOptions
{
  /// Edge of the cubic cells (required, > 0). The grid is aligned to box.lo.
  double featureSize = 0;
  /// Threads to use; 0 = TBB's default.
  int threads = 0;
  /// true: vertices minimise the quadric error of the crossings' tangent planes (sharp edges and
  /// corners); false: vertices at the mass point of the crossings (smoother, cheaper: no
  /// gradients).
  bool sharpFeatures = true;
  /// Called from the calling thread with the completed fraction; return false to cancel
  /// (contourSurface then throws frep::Cancelled).
  Progress progress;
  /// Largest accepted number of grid cells (the dense count over the box, although only cells
  /// near the surface are visited): a guard against absurd resolutions.
  std::size_t maxCells = std::size_t(1) << 36;
  /// When set: the work of the previous call made with this memory is reused where the field
  /// did not change, and this call's is kept for the next (SurfaceMemory). The mesh is the same.
  SurfaceMemory* memory = nullptr;
};

/// The surface f = 0 of `field` inside `box`. Throws std::invalid_argument for a box that is not
/// finite with lo < hi on every axis, a featureSize that is not positive and finite, or a grid of
/// more than options.maxCells cells (the message gives the estimate); frep::Cancelled when the
/// progress callback returns false.
SurfaceMesh contourSurface(
  const frep::Field& field, const frep::Box3& box, const SurfaceOptions& options);

} // namespace ictk::discretize
