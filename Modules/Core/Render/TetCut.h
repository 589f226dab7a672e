// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// A tetrahedral mesh cut open for a picture (`ictk render MESH.vtu --cut nx,ny,nz,d`): the
// tetrahedra on one side of a plane are kept whole (none is split, so what shows is the mesh's
// own elements, as a finite-element user expects to inspect them), and what one sees of them is
// their faces that no other kept tetrahedron shares: the mesh's outer boundary on the kept side
// and, along the cut, the faces of the first layer of elements. Those faces are drawn by the
// exact rasteriser (Rasterize.h) into the common depth buffer, each flat-shaded, coloured by a
// value per tetrahedron (a material, a modulus: constant over each face) or per point
// (a stress: interpolated over each face).

#include "FRep/Vector.h"
#include "Render/Rasterize.h"

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

namespace ictk::render
{

/// The half-space n . x > d is removed: a tetrahedron is kept when its centroid c has
/// n . c <= d. n need not be unit length.
struct CutPlane
{
  frep::Point3 normal{ 0, 0, 1 };
  double offset = 0;
};

/// The faces seen of the kept tetrahedra.
struct TetFaces
{
  /// Each face's vertices (indices into the mesh's points).
  std::vector<std::array<std::uint32_t, 3>> triangles;
  /// Each face's tetrahedron.
  std::vector<std::uint32_t> tetrahedron;
  std::int64_t keptTetrahedra = 0;
};

/// The faces of the tetrahedra kept by `cut` (every one without a cut) that no other kept
/// tetrahedron shares, in the order of the tetrahedra and their faces (opposite vertex 0, 1, 2,
/// 3). Throws std::invalid_argument for an index out of range, a point or a plane that is not
/// finite, or a zero normal.
TetFaces tetrahedronFaces(const std::vector<frep::Point3>& points,
  const std::vector<std::array<std::uint32_t, 4>>& tetrahedra, const std::optional<CutPlane>& cut);

/// How the faces are painted: by one scalar per tetrahedron (flat over each face), one per point
/// (interpolated), or neither (neutral grey). NaN values are undefined (neutral grey).
struct TetPaint
{
  std::vector<double> perTetrahedron;
  std::vector<double> perPoint;
};

/// The faces as primitives for rasterize(), each face with points of its own so that a value per
/// tetrahedron stays flat, and no vertex normals (every face lit by its own normal). Throws
/// std::invalid_argument when a paint array does not have one value per tetrahedron or point.
Primitives tetrahedronFacePrimitives(
  const std::vector<frep::Point3>& points, const TetFaces& faces, const TetPaint& paint);

} // namespace ictk::render
