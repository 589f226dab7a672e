// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The explicit primitives of a picture, drawn into the common z-buffer (Canvas.h) exactly: the
// triangles of discretised surfaces, the tubes that stand for curves and the spheres that stand
// for points (seed 001, papers.md 1.9: "we replace 1D cells with thin cylinders to be able to
// shade them"). Every primitive is bounded on the screen by the projection of its box; the ray
// through each pixel centre in that rectangle is intersected with it analytically (a triangle by
// its plane and edges, a tube as the union of a cylinder and two balls, a sphere as a ball), so
// silhouettes and depths are those of the primitives themselves to rounding, on the same rays as
// the ray caster's (Camera.h), and a ray-cast solid composes with them pixel by pixel.
//
// Shading is the ray caster's headlight: triangles take the normal interpolated from their
// vertices' (or their own where there is none), tubes and spheres their analytic normal. Paint
// is interpolated linearly from the vertices (along a tube's axis for a tube). The picture does
// not depend on the number of threads: rows are split in bands and each band draws every
// primitive in order.

#include "FRep/Progress.h"
#include "FRep/Vector.h"
#include "Render/Camera.h"
#include "Render/Canvas.h"

#include <array>
#include <cstdint>
#include <vector>

namespace ictk::render
{

/// Primitives over one point list, drawn as one owner's (Canvas::owner).
struct Primitives
{
  std::vector<frep::Point3> points;
  /// Per point, the surface's normal for shading triangles (any length; zero: the triangle's
  /// own). Empty: every triangle's own.
  std::vector<frep::Point3> normals;
  /// Per point; empty: neutral grey everywhere.
  std::vector<Paint> paints;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  /// Tubes: a cylinder of tubeRadius about each segment, closed by balls at its ends.
  std::vector<std::array<std::uint32_t, 2>> segments;
  /// Balls of sphereRadius about these points.
  std::vector<std::uint32_t> spheres;
  double tubeRadius = 0;
  double sphereRadius = 0;
  std::int32_t owner = 0;
};

struct RasterOptions
{
  /// Threads to use; 0 = TBB's default.
  int threads = 0;
  /// Progress and cancellation, counted per band of rows.
  Progress progress;
};

/// Draws the primitives into the canvas (the camera's size) where they are nearer than what it
/// holds; returns the number of pixels written (a pixel written twice counts twice). Throws
/// std::invalid_argument for an index out of range, a point that is not finite, a radius that is
/// not positive where tubes or spheres are drawn, or per-point arrays of the wrong size;
/// Cancelled from the progress callback.
std::int64_t rasterize(Canvas& canvas, const Camera& camera, const Primitives& primitives,
  const RasterOptions& options = {});

/// The normals of a triangle mesh at its vertices: the area-weighted sum of the normals of the
/// triangles around each (zero at a vertex no triangle uses).
std::vector<frep::Point3> vertexNormals(const std::vector<frep::Point3>& points,
  const std::vector<std::array<std::uint32_t, 3>>& triangles);

} // namespace ictk::render
