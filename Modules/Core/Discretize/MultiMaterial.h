// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Conforming boundary surfaces of a label field (issue 6): the input of constrained tetrahedral
// meshers (TetGen's piecewise linear complexes).
//
// The label of a point is the solid of highest priority among those whose field is >= 0 there
// (ties go to the lower index), 0 where no field is >= 0. The surfaces between the labels are
// extracted by multi-material marching tetrahedra on the Kuhn split of a grid:
// - a vertex on every grid edge whose end labels differ, found by bisection on the field of the
//   winning label of the two (to ~1e-13 of the edge; planar interfaces come out exact), but
//   kept 0.1 of the edge away from its ends: where a surface passes closer than that to a grid
//   point it is moved by up to 0.1 cell, in exchange for no tiny triangles (which make
//   tetrahedral meshers refine far below the requested size);
// - a vertex on every tetrahedron face with three labels, on the triple line, and one inside
//   every tetrahedron with three or four labels: the triangles of such a tetrahedron are cones
//   from that inner vertex over segments on its faces, so they cannot intersect;
// - the grid samples the box at cell centres shifted by different fractions per axis (0.5, 0.4,
//   0.6), so box faces and planes at multiples of the cell size never pass through grid points,
//   and points outside the box count as outside (label 0): solids cut by the box are closed by it
//   with sharp box edges.
// Vertices are welded by key (the grid points of their edge, face or tetrahedron), so the union
// of the triangles is a valid PLC: no T-junctions, no intersections, every label's boundary
// closed. Only blocks of 8^3 cells whose interval bounds allow more than one label are sampled.
// The output is identical for any thread count.

#include "Discretize/Mesh.h"
#include "FRep/Progress.h"

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

namespace ictk::discretize
{

struct MultiMaterialOptions
{
  /// 0 = TBB's default.
  int threads = 0;
  /// Refuse grids with more cells (std::invalid_argument with the count). The label grid takes
  /// 2 bytes per grid point.
  double maxCells = 2.5e8;
  /// Called with the completed fraction; return false to cancel (throws frep::Cancelled).
  Progress progress;
};

/// A point strictly inside one connected region of one label (for region attributes and holes).
struct MaterialRegion
{
  Point3 point{ 0, 0, 0 };
  /// 0 (a void: outside every solid but enclosed by them) or 1 + the solid's index.
  int label = 0;
};

/// Two solids of equal priority both strictly inside (field > 0) at `point`.
struct MaterialOverlap
{
  int first = 0; ///< solid indices, first < second
  int second = 0;
  Point3 point{ 0, 0, 0 };
};

struct MaterialSurface
{
  std::vector<Point3> points;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  /// Per triangle: the labels it separates (0 = outside, i + 1 = solids[i]), first < second;
  /// the triangle's normal points from `first` into `second`.
  std::vector<std::array<std::int32_t, 2>> labels;
  /// One point per connected region of every label, except the outside region that reaches the
  /// box (enclosed voids of label 0 are listed), in ascending grid order.
  std::vector<MaterialRegion> regions;
  /// Equal-priority solids that overlap (one entry per pair, the first grid point found).
  std::vector<MaterialOverlap> overlaps;
  /// The grid cell edge per axis that was used.
  Point3 spacing{ 0, 0, 0 };
};

/// The conforming surfaces between the labels of `solids` (f >= 0 inside) inside `box`, on a
/// grid of cell edge about `size`. `priorities` has one entry per solid (empty = all 0). Throws
/// std::invalid_argument for a box that is not finite with lo < hi, a size that is not positive,
/// null fields, more than 32766 solids or a grid above options.maxCells.
MaterialSurface multiMaterialSurface(const std::vector<frep::FieldPtr>& solids,
  const std::vector<double>& priorities, const Box3& box, double size,
  const MultiMaterialOptions& options = {});

/// The volume of label `label` (>= 1) enclosed by its oriented triangles.
double materialVolume(const MaterialSurface& surface, int label);

} // namespace ictk::discretize
