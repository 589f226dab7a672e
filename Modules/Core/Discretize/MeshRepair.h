// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Repairs of triangle meshes read from files (issue 17: the characters of assimp-testmodels).
// Implemented in Mesh.cxx beside analyzeTopology, whose test of a vertex's fans it shares; a
// header of its own so that Mesh.h, which most of the toolkit includes, does not change with it.

#include "Discretize/Mesh.h"

#include <cstdint>
#include <vector>

namespace ictk::discretize
{

/// Repairs the vertices that join separate fans of triangles (MeshTopology::nonManifoldVertices:
/// patches touching at a corner, as the texture seams of a character leave them): every fan after
/// the first gets its own copy of the vertex, appended to `points` (and to every point array), so
/// that each vertex has one fan. The surface does not move. Returns, for each appended point, the
/// vertex it copies. Edges of three or more triangles are left as they are (no vertex split
/// separates them).
std::vector<std::uint32_t> splitNonManifoldVertices(SurfaceMesh& mesh);

} // namespace ictk::discretize
