// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The TetGen backend (issue 6). This header includes no TetGen; the library that implements it
// links TetGen 1.5 (AGPL-3.0-or-later) and is built only with ICTK_ENABLE_GPL_BACKENDS.
//
// The complex's 3D cells become one label field (discretize::multiMaterialSurface): the label
// of a point is the 1-based index (among the 3D cells, ascending id) of the cell that holds it
// (bounds and every inside field >= 0), the highest Cell::priority winning where cells overlap.
// The conforming surfaces between the labels, extracted on a grid of cell edge options.size,
// are TetGen's piecewise linear complex; every connected region gets a region point whose
// attribute is its material (TetGen -A), enclosed voids a hole point. TetGen then refines for
// quality inside, keeping the surface triangles (-Y): -pYq1.414/<minDihedralDegrees>a<volume of
// three regular tetrahedra of edge size>A. The tetrahedra next to the surface are as good as
// its triangles allow (marching tetrahedra: some small angles).
// 2D cells (implicit, mapped or explicit) that pass through a solid become internal faces of
// the mesh: their triangulation (edge about size / 2) is added to the PLC as facets, so the
// tetrahedra on both sides share faces on it and keep the solid's label. Only the part at least
// 0.75 size away from every label change is added (a facet crossing or touching the
// grid-extracted interfaces would make the PLC self-intersecting): a 2D cell that reaches a
// solid's boundary stops short of it, one on a boundary or interface adds nothing.
// TetGen is deterministic: the same complex and options give the same mesh.

#include "Discretize/MultiMaterial.h"
#include "Mesh/TetMesh.h"

#include <string>

namespace ictk::mesh
{

/// Figures of the last run, for reports and benchmarks.
struct TetGenReport
{
  double surfaceSeconds = 0;
  double tetgenSeconds = 0;
  std::size_t surfacePoints = 0;
  std::size_t surfaceTriangles = 0;
  double estimate = 0; ///< estimateTetrahedra of the labelled volume
  /// Triangles of 2D cells inside the solids kept as internal faces, and how many 2D cells
  /// gave some.
  std::size_t internalTriangles = 0;
  std::size_t internalCells = 0;
  std::string switches;
};

/// A tetrahedral mesh of the complex's 3D cells (implicit cells only; cellData is left empty).
/// Throws std::invalid_argument for no 3D cell, a 3D cell that is not implicit or not bounded,
/// a 3D cell with no volume (naming it),
/// overlapping cells of equal priority (naming both and a point), or an estimate above
/// options.maxTetrahedra (giving the estimate); std::runtime_error when TetGen fails (its error
/// code explained); frep::Cancelled when options.progress asks to stop.
TetMesh tetrahedralizeTetGen(
  const complex::Complex& complex, const TetraOptions& options, TetGenReport* report = nullptr);

/// TetGen on a given multi-material surface: material m = label m (1..materials), region
/// points and holes from surface.regions. The complex-free half of tetrahedralizeTetGen (cells
/// are left empty), for benchmarks and tests.
TetMesh tetrahedralizeSurfaceTetGen(const discretize::MaterialSurface& surface, int materials,
  const TetraOptions& options, TetGenReport* report = nullptr);

} // namespace ictk::mesh
