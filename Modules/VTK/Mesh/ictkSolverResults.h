// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// A solved tetrahedral mesh in VTK (issue 15; not wrapped: it takes core types): the core reads
// CalculiX's results (Mesh/Frd.h) and this puts them on the mesh's vtkUnstructuredGrid, and a
// grid of labelled tetrahedra (a .vtu of `ictk tetra` or ictkTetrahedralize) back into the
// core's TetMesh, so a mesh written once can be solved later (`ictk solve`).
//
// The grid is ictkTetrahedralize::Convert's (cell data MaterialId, CellId and one double array
// per attribute: youngs_modulus, poisson_ratio, density, label...; field data MaterialNames)
// with, as point data, displacement (3 components), stress (6: xx, yy, zz, xy, yz, zx, VTK's
// order for symmetric tensors), von_mises and reaction_force (3; zero where nothing is held), and
// as cell data the deck's view of each tetrahedron: deck_material (1-based index into the deck's
// materials) and deck_youngs_modulus (the binned modulus the solver used).

#include "ictkFiltersMeshModule.h" // export macro

#include "Mesh/Frd.h"
#include "Mesh/TetMesh.h"
#include "Mesh/Writers.h"

#include <vector>

class vtkUnstructuredGrid;

namespace ictk::vtk
{

/// The results of a solve on the mesh's grid (above). `materials` (deckMaterials, or
/// CompressionCase::materials) may be empty: no deck arrays then. Throws std::invalid_argument
/// when the results are not of this mesh's size.
ICTKFILTERSMESH_EXPORT void solverResultsToVTK(const mesh::TetMesh& mesh,
  const mesh::PointResults& results, const std::vector<mesh::DeckMaterial>& materials,
  vtkUnstructuredGrid* output);

/// The TetMesh of a grid of tetrahedra: MaterialId (default 1 for every tetrahedron), CellId
/// (default 0), MaterialNames (default "material_<id>"), every other one-or-more-component
/// numeric cell array as a per-tetrahedron array; size 0 (unknown). Throws std::invalid_argument
/// naming `where` (the file) for a cell that is not a tetrahedron or an empty grid; the mesh is
/// checked by mesh::validate (a negatively oriented tetrahedron is an error, not flipped).
ICTKFILTERSMESH_EXPORT mesh::TetMesh tetMeshFromVTK(
  vtkUnstructuredGrid* grid, const std::string& where);

} // namespace ictk::vtk
