// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The CGAL Mesh_3 backend (issue 6). This header includes no CGAL; the library that implements it
// links CGAL Mesh_3 (GPL-3.0-or-later) and is built only with ICTK_ENABLE_GPL_BACKENDS.
//
// The complex's 3D cells become one labelled domain: the label of a point is the 1-based index
// (among the 3D cells, ascending id) of the cell that holds it (bounds and every inside field
// >= 0), the highest Cell::priority winning where cells overlap. Curves are protected as mesh
// edges: the 1D cells, the creases of each solid (where two of its inside fields vanish) and the
// curves where two solids' boundaries meet. Explicit (B) 3D cells are refused.
//
// 2D implicit cells {G = 0, H >= 0} that pass through a solid become internal surfaces: a
// labelled domain only has surfaces where the label changes, so the solid's points with G < 0
// and every H >= 0 (within the 2D cell's bounds, padded by size, unbounded along axes the cell
// is flat in) get a sub-label that is mapped back to the solid's cell and material in the
// output. Mesh_3 then meshes {G = 0, H >= 0} (tetrahedra on both sides share faces on it), and
// also the walls {H = 0, G < 0} from its rim to the solid's boundary (extra faces inside the
// solid, with the solid's label on both sides); the rim and the walls' edges are protected. At
// most 16 such cells; mapped and explicit 2D cells are not inserted (use the TetGen backend).

#include "Mesh/TetMesh.h"

#include <vector>

namespace ictk::mesh
{

/// A tetrahedral mesh of the complex's 3D cells (implicit cells only; cellData is left empty).
/// options.size is met on average: the mean tetrahedron has the volume of a regular one of edge
/// `size` (so estimateTetrahedra predicts the count) and protected curves get edges of at most
/// `size`. In the default mode on more than one thread (options.threads, 0: every core),
/// refinement, perturbation and exudation run on CGAL's parallel code (Parallel_tag, TBB; see
/// cgalMeshesInParallel); the deterministic mode is always sequential. Sliver exudation
/// (deterministic: no random choice, no time limit) aims at options.minDihedralDegrees in both
/// modes; the default mode perturbs vertices first (random).
/// options.deterministic: no perturbation and fixed seeds, identical output run to run and
/// thread count to thread count (the flower: min dihedral 6.3 deg instead of 0.3 without
/// exudation, 9.5 deg with perturbation).
/// Throws std::invalid_argument for a 3D cell that is not implicit or not bounded, one the mesh
/// has no tetrahedron of (no volume; naming it), more than 16 2D cells inside solids, for
/// overlapping cells of equal priority (naming both and the point), or for an estimate above
/// options.maxTetrahedra (giving the estimate); frep::Cancelled when options.progress asks to
/// stop.
TetMesh tetrahedralizeCgal(const complex::Complex& complex, const TetraOptions& options);

/// Whether tetrahedralizeCgal refines with CGAL's Parallel_tag for these options: not in the
/// deterministic mode (the parallel result depends on the threads' timing), not on one thread,
/// and only when the library was built with CGAL's TBB support.
bool cgalMeshesInParallel(const TetraOptions& options);

/// The polylines the backend protects (after merging duplicates, snapping end points and
/// splitting at junctions), for tests and viewers.
std::vector<std::vector<frep::Point3>> cgalFeatureCurves(
  const complex::Complex& complex, const TetraOptions& options);

} // namespace ictk::mesh
