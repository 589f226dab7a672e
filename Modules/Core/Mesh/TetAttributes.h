// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Attribute values on the tetrahedra of a mesh (issue 6): each tetrahedron takes the value of
// its own cell's binding at its centroid, or the complex's inside default theta1.

#include "Mesh/TetMesh.h"

#include <string>

namespace ictk::mesh
{

/// For every attribute the complex declares, a TetArray named after it (replacing an array of
/// that name): the value of the binding of the tetrahedron's cell (TetMesh::cells) at the
/// tetrahedron's centroid, else the declared inside default theta1. Values that are not finite
/// are kept (NaN marks "undefined here"). Throws std::invalid_argument when a tetrahedron's cell
/// is not in the complex or a point index is out of range.
void assignAttributes(TetMesh& mesh, const complex::Complex& complex);

/// The array named `name`, or nullptr.
const TetArray* findArray(const TetMesh& mesh, const std::string& name);

} // namespace ictk::mesh
