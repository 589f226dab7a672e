// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Time-coherent discretisation of a running model (thesis 4.6.8: "re-meshing across time steps
// reuses work where the model did not change").
//
// A cell's shape is given in its local frame and placed by an affine map; between frames most
// cells only move. So each cell is discretised once in its local frame, the mesh is kept under
// the cell's name and shape version (CellState::shapeVersion, which changes when the shape's parts
// change but not when only the placement does), and every frame just maps the kept points by the
// current placement. Shapes whose parts live in world coordinates (blends and unions of other
// cells) change version when their operands move, and a kept mesh of theirs is only reused under
// the very same placement, so reuse never gives a stale mesh.
//
// Meshing in the local frame also makes the result independent of where the cell is: a moving
// cell keeps the same triangles instead of being re-sampled on a grid it slides through. The
// coherent and the full (coherent = false) discretisations are therefore the same meshes; the
// full one only does all the work again, for comparison.
//
// Below the cell: a cell whose shape changes (a parameter set every frame, blend operands that
// move) is re-meshed, but a 3D implicit one keeps a discretize::SurfaceMemory from its second
// meshing on, so that the regions of its surface where its field did not change (the octree's
// blocks whose pruned evaluator has the same fingerprint, e.g. the walls of a liquid whose noise
// is only on its top) are copied from the previous meshing instead of contoured again. That is
// exact too: the mesh is the one a meshing from scratch gives (Discretize/Surface.h says why).
//
// The feature size must be the same in every frame, or a kept mesh would not be what a fresh one
// is: it is CoherenceOptions::featureSize, or, when 0, 1/64 of the largest side of the first
// complex discretised (as complex::discretizeComplex chooses it), kept until reset().

#include "Complex/Discretization.h"
#include "Engine/DynamicModel.h"
#include "FRep/Progress.h"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace ictk::engine
{

struct CoherenceOptions
{
  /// Mesh edge length and curve step (model units), the same in every frame; 0 = from the first
  /// complex discretised (1/64 of its largest side).
  double featureSize = 0;
  /// false: discretise every cell in every frame (the reference for the coherent result).
  bool coherent = true;
  /// Tolerance of point projections (complex::DiscretizationOptions::tolerance).
  double tolerance = 1e-7;
  /// Threads of the discretisers; 0 = TBB's default. The result does not depend on it.
  int threads = 0;
  /// How circular parts become explicit cells (toComplexCell).
  geometry::QueryOptions geometry;
  /// Called with the completed fraction of a frame; return false to cancel (frep::Cancelled).
  Progress progress;
};

/// Work done for the cells of one frame, or summed over frames.
struct CoherenceStats
{
  std::size_t frames = 0;
  std::size_t computed = 0; ///< discretised in their local frame
  std::size_t moved = 0;    ///< a kept mesh mapped by a placement that changed
  std::size_t reused = 0;   ///< a kept mesh under the same placement as before
  /// Blocks (8^3 grid cells) of the computed 3D cells' surfaces: contoured from the field, or
  /// copied from the cell's previous meshing where its field did not change there.
  std::size_t blocksContoured = 0;
  std::size_t blocksReused = 0;
  double seconds = 0; ///< wall-clock time of discretize()
  std::size_t cells() const { return computed + moved + reused; }
  CoherenceStats& operator+=(const CoherenceStats& o);
};

/// What became of one cell's mesh in a frame.
enum class CellWork
{
  Computed,
  Moved,
  Reused
};

class CoherentDiscretizer
{
public:
  explicit CoherentDiscretizer(CoherenceOptions options = {});

  /// The discretisation of model.complex() now: one CellMesh per cell, ids following
  /// model.cells(), with the attributes of the complex at every point (the cell's own bindings,
  /// then the declared defaults by priority, as complex::discretizeComplex gives them).
  complex::ComplexMesh discretize(const DynamicModel& model);
  /// The same for cells and the complex made from them (complex.cell(i) stands for cells[i]).
  /// `only`: discretise just these cells (an MPI rank's share; empty = all), each as in a whole
  /// frame; the cells their unbound attributes are looked up in are meshed too, then dropped.
  complex::ComplexMesh discretize(const std::vector<CellState>& cells,
    const complex::Complex& complex, const std::vector<complex::CellId>& only = {});

  /// The feature size in use (0 before the first frame when none was given).
  double featureSize() const { return featureSize_; }
  /// Fixes the feature size from now on (0 = again from the next complex discretised).
  void setFeatureSize(double h) { featureSize_ = h; }
  const CoherenceStats& lastFrame() const { return last_; }
  const CoherenceStats& total() const { return total_; }
  /// Per cell of the last frame (by cell id): its name and what was done.
  const std::vector<std::pair<std::string, CellWork>>& lastCells() const { return lastCells_; }
  const CoherenceOptions& options() const { return options_; }

  /// Forgets every kept mesh and the statistics; the feature size stays. Call it when the
  /// model is reloaded: shape versions are only meaningful within one run.
  void reset();

private:
  struct Kept
  {
    std::uint64_t version = 0;
    /// The local mesh, without attributes.
    complex::CellMesh local;
    /// Shapes with world-space parts: their mesh is only valid under this placement.
    bool worldParts = false;
    geometry::Affine madeUnder;
    /// The placement of the previous frame, to tell a moved cell from a resting one.
    geometry::Affine lastPlace;
    /// From the cell's second meshing on (its shape changed once, so it may again): the work of
    /// its last meshing, for the next one. Cells that never change do not pay for it.
    std::shared_ptr<discretize::SurfaceMemory> surface;
    /// Keeping blocks costs a copy of each (about 5% of a meshing): after a meshing with a
    /// memory that reused nothing (a field that changes everywhere), the next 2^misses - 1
    /// meshings go without one, then it is tried again. Only the work done changes, never the
    /// mesh.
    std::uint32_t misses = 0;
    std::uint32_t skip = 0;
  };
  CoherenceOptions options_;
  double featureSize_ = 0;
  std::map<std::string, Kept> kept_;
  CoherenceStats last_;
  CoherenceStats total_;
  std::vector<std::pair<std::string, CellWork>> lastCells_;
};

} // namespace ictk::engine
