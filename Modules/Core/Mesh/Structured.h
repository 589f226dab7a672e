// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// A structured tetrahedral mesh of a box (issue 6): the reference mesh of tests and solver checks,
// and a backend-free way to label a grid with the cells of a complex (boundaries are staircased,
// not fitted: use the CGAL or TetGen backends for meshes that follow curved cells).

#include "Mesh/TetMesh.h"

namespace ictk::mesh
{

/// The box split into nx x ny x nz blocks, each block into the 6 tetrahedra around its diagonal
/// from lo to hi (the Kuhn / Freudenthal split): conforming, positively oriented, every
/// tetrahedron of volume block / 6. Cells, materials and names are left empty.
TetMesh kuhnTetMesh(const frep::Box3& box, const std::array<int, 3>& divisions);

/// Gives each tetrahedron the 3D implicit cell that holds its centroid (solid field >= 0; where
/// cells overlap the highest priority, then the lowest id), one material per 3D cell of the
/// complex in ascending id; drops the tetrahedra in no cell and the points no tetrahedron uses.
/// Per-tetrahedron arrays are dropped (assignAttributes fills them).
void labelByCentroid(TetMesh& mesh, const complex::Complex& complex);

} // namespace ictk::mesh
