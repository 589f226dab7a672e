// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The tetrahedral meshing backends, chosen in one place. Each backend is an optional library
// (CGAL Mesh_3: GPL-3+, TetGen: AGPL-3+, built with ICTK_ENABLE_GPL_BACKENDS); this library knows
// which were built, and every front end (ictk tetra, ictkTetrahedralize, Python) asks it.

#include "Complex/Complex.h"
#include "Mesh/TetMesh.h"
#include "Mesh/Validity.h"

#include <optional>
#include <string>
#include <vector>

namespace ictk::mesh
{

enum class Backend
{
  Cgal,
  TetGen
};

/// "cgal" or "tetgen": the names the front ends use.
const char* backendName(Backend backend);
/// The backend of a name (case-insensitive), or nullopt.
std::optional<Backend> backendFromName(const std::string& name);
/// The backends built into this ICTK, in order of preference (CGAL first: it meshes every cell
/// kind; TetGen needs conforming surfaces).
std::vector<Backend> availableBackends();
bool hasBackend(Backend backend);
/// The first of availableBackends(); nullopt when none was built.
std::optional<Backend> defaultBackend();

/// Meshes the complex with the backend and checks the mesh (checkValidity with the complex, into
/// `validity` when given). Throws std::invalid_argument when the backend was not built (saying
/// how to build it) or its mesh is not valid (saying what failed and where), and whatever the
/// backend throws.
TetMesh tetrahedralize(const complex::Complex& complex, Backend backend,
  const TetraOptions& options, ValidityReport* validity = nullptr);

} // namespace ictk::mesh
