// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Discretisation of 2D implicit cells (surface patches).
//
// A 2D cell of E^3 is kept as its parts, never as the seed's -(G)^2 AND H >= 0 (a set without an
// inside, which sign-change contouring cannot see): a carrier field G (the patch lies on G = 0)
// and trim fields H_k (the patch is where every H_k >= 0). A mapped cell (MappedFCell) is a 2D
// FRep F(u, v) >= 0 of the (u, v) = (x, y) plane (z ignored) pushed to E^3 by h = (hx, hy, hz).
//
//  - trimSurface: the part of a triangulated carrier surface where all trims are >= 0; crossing
//    triangles are split and the new vertices projected onto {G = 0, H = 0} exactly;
//  - triangulateRegion2D: {F >= 0} in a (u, v) rectangle (holes kept), boundary vertices on F = 0;
//  - mapToSpace: (u, v) meshes and curves pushed through h.
//
// Everything is deterministic for any thread count. Bad input (empty box, non-positive size,
// absurd resolution, malformed mesh) raises std::invalid_argument with a message naming the
// function.

#include "Discretize/Mesh.h"

namespace ictk::discretize
{

struct TrimOptions
{
  /// Projected points satisfy |f| <= tolerance * |grad f| for every field (about a distance).
  double tolerance = 1e-10;
  /// Gauss-Newton iterations per projected point.
  int maxIterations = 30;
  /// Threads (0 = TBB's default). The result does not depend on it.
  int threads = 0;
};

/// The part of `carrierMesh` (a triangulation of {carrier = 0}) where every trim is >= 0.
/// Triangles that cross a trim's zero set are split (polygon clipping of each triangle, the cut
/// point of an edge shared by both neighbours so the result stays conforming); the cut point is
/// located by bisection along the edge, then moved onto the exact curve {carrier = 0, trim = 0}
/// by Gauss-Newton (onto the corner {carrier = 0, trim_j = 0, trim_k = 0} when the edge already
/// lies on trim_j's curve). Where a projection fails (e.g. a tangency), the bisection point is
/// kept. Vertices of the carrier mesh are not moved; a vertex where a trim is exactly 0 counts as
/// inside. Point arrays of the carrier mesh are interpolated linearly to the new vertices; unused
/// vertices are dropped. At most 32 trims; a null trim throws std::invalid_argument.
SurfaceMesh trimSurface(const SurfaceMesh& carrierMesh, const frep::Field& carrier,
  const std::vector<frep::FieldPtr>& trims, const TrimOptions& options);

struct Region2DOptions
{
  /// Edge of the grid squares (required > 0); each square is split into two triangles.
  double size = 0;
  /// Grid vertices closer to f = 0 than snap * size (by |f| / |grad f|) are moved onto f = 0
  /// first, which avoids sliver triangles at the boundary (0 = no snapping; at most 0.3).
  double snap = 0.25;
  /// As TrimOptions.
  double tolerance = 1e-10;
  int maxIterations = 30;
  /// Refuse grids with more squares than this (std::invalid_argument).
  double maxCells = 5e7;
  int threads = 0;
};

/// A triangulation of {f(u, v) >= 0} in the (u, v) = (x, y) rectangle of `box` (box.z ignored,
/// the field evaluated and the mesh placed at z = 0). A uniform grid of squares of edge about
/// options.size (the rectangle is divided exactly) is clipped by f >= 0 as trimSurface does, in
/// the plane; every boundary vertex inside the rectangle lies on f = 0 (to options.tolerance).
/// Holes are kept; where {f >= 0} reaches the rectangle, the rectangle's edge bounds the mesh.
/// Triangles are counter-clockwise in (u, v) (normal +z).
SurfaceMesh triangulateRegion2D(
  const frep::Field& f, const Box3& box, const Region2DOptions& options);

/// Pushes every point (u, v, .) = (x, y, .) through h: the point becomes
/// (hx(u, v), hy(u, v), hz(u, v)) (the fields evaluated at (u, v, 0)). The (u, v) coordinates
/// are kept as a 2-component point array named "uv" (replacing one of that name).
void mapToSpace(
  SurfaceMesh& mesh, const frep::Field& hx, const frep::Field& hy, const frep::Field& hz);
void mapToSpace(
  CurveSet& curves, const frep::Field& hx, const frep::Field& hy, const frep::Field& hz);
void mapToSpace(
  PointSet& points, const frep::Field& hx, const frep::Field& hy, const frep::Field& hz);

} // namespace ictk::discretize
