// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Whether a tetrahedral mesh is one that every solver accepts (issue 21). Shape measures
// (Quality.h) do not see it: the CGAL backend once wrote clusters of well-shaped tetrahedra 1e-8
// across that CalculiX refused ("nonpositive jacobian determinant"). The check measures what a
// solver's acceptance depends on, relative to the requested element size: the shortest edge, the
// smallest volume, orientation, conformity (each face of at most two tetrahedra, on opposite sides
// of it; each face of one tetrahedron on its cell's boundary) and vertices that coincide. The
// backends (Backends.h) and the writers run it on every mesh; a mesh that fails is not written.

#include "Complex/Complex.h"
#include "Mesh/TetMesh.h"

#include <cstddef>
#include <string>
#include <vector>

namespace ictk::mesh
{

/// Below these (relative to the size) a mesh is refused. A sound mesh of either backend has its
/// shortest edge near 0.1 x size and its smallest tetrahedron near 1e-3 of a regular one's volume
/// (docs/tet-mesh-files.md has the figures of every model in Data/).
struct ValidityLimits
{
  /// Shortest edge / size.
  double minEdge = 1e-3;
  /// Smallest volume / the volume of a regular tetrahedron of edge `size`.
  double minVolume = 1e-7;
  /// Two vertices closer than this x size are one vertex given twice.
  double duplicateDistance = 1e-6;
  /// Within this x size of a face of a single tetrahedron must lie a point of no cell: a hole or
  /// a gap between cells has cells all around. As far as one element, because a backend may cut a
  /// sharp corner or a thin rim by about that much (TetGen's boundary is a surface mesh of the
  /// cells); a hole or gap is found wherever it is farther than that from the boundary.
  double boundaryProbe = 1;
};

struct ValidityReport
{
  /// What the figures are relative to: the requested size, or the mean edge length when the mesh
  /// was given none.
  double size = 0;
  std::size_t points = 0;
  std::size_t tetrahedra = 0;
  double minEdge = 0;
  double minEdgeRelative = 0;
  /// The smallest signed volume, and it over a regular tetrahedron's of edge `size`.
  double minVolume = 0;
  double minVolumeRelative = 0;
  /// Tetrahedra with an edge / a volume below the limits.
  std::size_t shortEdges = 0;
  std::size_t smallVolumes = 0;
  /// Tetrahedra with volume <= 0.
  std::size_t nonPositive = 0;
  /// Points with another point closer than the duplicate distance.
  std::size_t duplicatePoints = 0;
  std::size_t interiorFaces = 0;
  std::size_t boundaryFaces = 0;
  /// Faces of more than two tetrahedra, or of two on the same side of the face (overlapping).
  std::size_t nonConformingFaces = 0;
  /// Boundary faces with cells all around (holes, gaps between cells).
  std::size_t strayBoundaryFaces = 0;
  /// Boundary faces the check cannot decide: no complex given, or around them only cells it
  /// cannot evaluate (explicit solids).
  std::size_t uncheckedBoundaryFaces = 0;
  /// One sentence per failed check, naming the worst place; empty when the mesh is valid.
  std::vector<std::string> problems;

  bool valid() const { return problems.empty(); }
};

/// Checks the mesh. `size` <= 0 takes the mean edge length. With a complex, each boundary face is
/// checked to have a point of no 3D cell of the complex near it (implicit cells: inside their
/// bounds with every inside field >= 0). Throws std::invalid_argument for indices out of range or
/// arrays of the wrong length (validateStructure()).
ValidityReport checkValidity(const TetMesh& mesh, double size = 0,
  const complex::Complex* complex = nullptr, const ValidityLimits& limits = {});

/// Removes the flat tetrahedra (volume below limits.minVolume of a regular one of edge `size`)
/// that lie on the mesh's boundary, and the points only they used; returns how many went. CGAL's
/// refinement leaves such tetrahedra where a solid is about one element thick (the two-material
/// bar at size 0.15-0.25): four points of one planar face joined across it. A flat tetrahedron's
/// faces, by their outward area vectors, form two groups that cover the same polygon from its two
/// sides; when every face of one group is a boundary face, the faces of the other group become
/// the boundary instead, over the same polygon, so the cells' volumes (to the flat one's volume)
/// and the surface's conformity are unchanged. A flat tetrahedron with neighbours on both sides
/// (inside a cell or on an interface) is kept, and checkValidity refuses the mesh as before.
std::size_t removeFlatBoundaryTetrahedra(
  TetMesh& mesh, double size, const ValidityLimits& limits = {});

/// Throws std::invalid_argument "<what> is not a valid tetrahedral mesh: <problems>" unless the
/// report is valid.
void requireValid(const ValidityReport& report, const std::string& what);

/// A few lines of text: the figures and the problems.
std::string formatValidityReport(const ValidityReport& report);

} // namespace ictk::mesh
