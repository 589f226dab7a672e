// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Direct ray casting of an FRep solid (f >= 0 inside): for the ray through each pixel's centre,
// the first point where f >= 0, found with the kernel's interval arithmetic rather than by sphere
// tracing, which needs f to be a distance (an FRep is not one: a HyperFun model's f = r^2 - |p|^2,
// a blend or a scaled field steps past thin parts or crawls). Colour and depth buffers come out;
// writing them (PNG, .vti) is the application's job, so the core stays VTK-free.
//
// The search is seed 003's recursive multilevel ray casting as papers.md 2.4 reconstructs it
// (the paper names the levels, "quatro" and "binary", and nothing more):
//   1. The image is cut into square tiles (the unit of parallel work). A node is a rectangle of
//      pixels and a depth range [s0, s1] along the viewing axis; the piece of the view it stands
//      for (every point of the rectangle's pixel-centre rays between the two depths) is a convex
//      frustum (a box for an orthographic camera) whose eight corners bound it (Camera.h). Its
//      axis-aligned bounding box, clipped to the model's box, is handed to the interval evaluator.
//   2. A node whose interval excludes 0 from above (f < 0 on the whole piece, or NaN) holds no
//      point of the solid and is dropped. Otherwise the tape is simplified for the piece (min,
//      max and select whose operand is decided there are cut: IntervalEvaluator::simplified,
//      the same pruning as FRep/Render.h; not for a node whose children are single pixels,
//      where building the tape costs more than it saves), and the node is split with the
//      shorter tape: in depth (front half first) while the piece is deeper than it is wide,
//      else as a quadtree over the rectangle. Pixels that found their surface are skipped by
//      the nodes behind them.
//   3. At one pixel the ray, clipped to the model's box, is cut in halves in depth, each checked
//      by intervals (with the tape of the last node: simplifying per piece of one ray costs more
//      than it saves; a piece of at most two leaves is not checked whole, only its halves),
//      front first, down to a leaf no longer than the pixel's footprint at that depth. In a
//      leaf f is evaluated at both ends first (an end inside settles the leaf, and its interval
//      could only have confirmed that): a sign change is refined by Illinois
//      (FRep/RootFinding.h refineRoot) to the depth tolerance; two negative ends are checked by
//      the leaf's interval, and one that does not exclude 0 means a feature may hide inside, so
//      the leaf is halved again (samples and intervals) down to the depth tolerance. The
//      evaluators are incremental (FRep/Evaluators.h): successive pieces of one ray differ in z
//      alone when the rays are parallel to z (an orthographic view along it), and then only the
//      instructions that depend on z run again; the values are those of a full evaluation, bit
//      for bit.
//   4. The hit is shaded from the analytic gradient (Lambert with an ambient term, lit by a
//      headlight, both faces lit) in the model's colour (see RayCastOptions).
//
// What is guaranteed for the ray through a pixel's centre (inside the model's box, with the
// interval evaluator's enclosures, which are conservative):
//   * No miss. A pixel is empty only when every piece of its ray was excluded by an interval
//     bound, and a bound that excludes 0 proves f < 0 on the whole piece. So if any point of
//     the centre ray has f >= 0, however thin the feature there (a slab far thinner than any
//     uniform marching step, a tangency), the pixel is covered: finer uniform sampling of the
//     ray cannot find anything this render misses.
//   * The price of no miss: a piece no longer than the depth tolerance that intervals cannot
//     exclude and whose sample ends are both outside may hold a feature thinner than the
//     tolerance. The search goes on behind it; a crossing found within one leaf behind it is
//     taken (the piece was the intervals' overestimate just in front of that surface), else the
//     pixel is covered at that piece, "unresolved" (drawn in neutral grey, counted in
//     RayCastResult). Such pixels are rays that pass within about the interval arithmetic's
//     overestimate over a tolerance-long piece of the surface without meeting it (for
//     r^2 - |p|^2, within about twice the tolerance of the silhouette).
//   * Depth. The reported depth is never behind the first point of the ray with f >= 0 by more
//     than one leaf (the pixel's footprint at that depth), and it is that point to the depth
//     tolerance whenever the leaf that holds it holds only that crossing (every leaf in front
//     was excluded or searched down to the tolerance). A feature thinner than a leaf that lies
//     in front of a second crossing in the same leaf (a slab a fraction of a pixel in front of
//     a wall) may be passed in depth: the pixel is still covered, by the wall behind.
// What is not guaranteed:
//   * Anything between pixel centres: a feature thinner than a pixel that no centre ray meets
//     is not drawn (the picture samples the image plane at pixel centres; no antialiasing).
//   * Exactness beyond the kernel's arithmetic: point values are double-precision floating
//     point, so a ray that meets the surface within rounding of f = 0 may go either way.
// The result does not depend on the number of threads: each pixel is computed inside its own
// tile, by the same sequence of evaluations whichever thread runs it.

#include "FRep/Field.h"
#include "FRep/Hypervolume.h"
#include "FRep/Progress.h"
#include "FRep/Tape.h"
#include "Render/Camera.h"
#include "Render/Canvas.h"
#include "Render/ComplexRender.h"

#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace ictk::render
{

struct RayCastOptions
{
  /// Threads to use; 0 = TBB's default.
  int threads = 0;
  /// The time t at which an XYZT model is evaluated.
  double time = 0;
  /// The model's parameter values.
  std::vector<double> parameters;
  /// The depth tolerance, in model units along the ray; 0: 1e-6 times the box's half-diagonal.
  double depthTolerance = 0;
  /// The side of the image tiles (the quadtree's roots and the unit of parallel work).
  int tileSize = 16;
  /// Progress and cancellation (FRep/Progress.h): counted per finished tile.
  Progress progress;
  /// How the model's attributes colour it (Canvas.h).
  ColourOptions colours;
};

/// The pictures a ray cast gives, pixel (i, j) at index j * width + i, row 0 at the bottom.
struct RayCastResult
{
  int width = 0;
  int height = 0;
  /// RGBA, 8 bits each, 4 values per pixel; the background is transparent white (255, 255, 255, 0).
  std::vector<std::uint8_t> colour;
  /// Distance along the pixel's ray from the camera's eye (perspective) or image plane
  /// (orthographic) to the surface; +infinity where nothing is hit.
  std::vector<double> depth;
  /// The surface's unit normal turned to face the camera, 3 values a pixel (Canvas::normal).
  std::vector<float> normal;
  std::int64_t coveredPixels = 0;
  /// Covered because a piece no longer than the depth tolerance could not be excluded (see the
  /// file comment); a subset of coveredPixels.
  std::int64_t unresolvedPixels = 0;
  /// Covered where the ray enters the solid's box or starts (the near end) already inside the
  /// solid: the picture shows the solid cut there (a camera inside the solid, a box that cuts
  /// it). A subset of coveredPixels.
  std::int64_t cutPixels = 0;
  /// Interval evaluations of the tape (any length), and point evaluations of f.
  std::int64_t intervalEvaluations = 0;
  std::int64_t pointEvaluations = 0;
  /// Coloured by a scalar attribute: the values at the colour map's ends (else NaN).
  std::array<double, 2> scalarRange{ std::numeric_limits<double>::quiet_NaN(),
    std::numeric_limits<double>::quiet_NaN() };
};

/// The solid f >= 0 of `field` (the tape's first output) inside `box`, seen by `camera`, in a
/// neutral grey. Throws std::invalid_argument on a null tape, a bad box, missing parameter values
/// or a bad tolerance or tile size; Cancelled when the progress callback asks to stop.
RayCastResult rayCast(const frep::TapePtr& field, const frep::Box3& box, const Camera& camera,
  const RayCastOptions& options = {});

/// The same for a hypervolume's geometry, coloured by the attribute options.colours names (by
/// default its attribute named "colour" (or "color") with 3 or 4 components in [0, 1], the last
/// ignored; neutral grey when it has none), evaluated at the first point found inside the solid
/// on the ray; a scalar attribute through the colour map. Also throws std::invalid_argument for
/// an attribute the model does not have or that is neither a colour nor a scalar, an unknown
/// colour map or a reversed range.
RayCastResult rayCast(const frep::Hypervolume& model, const frep::Box3& box, const Camera& camera,
  const RayCastOptions& options = {});

/// A lone model as the polygonal scene of `ictk render --mode mesh` (the reference the exact
/// ray cast is compared with): its surface in `box` by dual contouring (Discretize/Surface.h,
/// the surface `ictk mesh` makes) with edges of `featureSize` (0: 1/64 of the box's largest
/// side), at options.time with options.parameters, shaded with vertex normals and painted by the
/// attribute options.colours names (as rayCast) evaluated at each vertex. Throws as rayCast and
/// contourSurface do.
ScenePrimitives modelScene(const frep::Hypervolume& model, const frep::Box3& box,
  double featureSize, const RayCastOptions& options = {});

/// What a picture shows at one pixel (picking, seed 003 item 38).
struct Pick
{
  bool hit = false;
  /// Distance along the pixel's ray to the surface, as RayCastResult::depth (+infinity: none).
  double depth = std::numeric_limits<double>::infinity();
  /// The surface point found on the pixel's ray.
  frep::Point3 point{ 0, 0, 0 };
  /// The components of the attribute asked for at that point (empty when nothing is hit).
  std::vector<double> values;
};

/// The frontmost surface of the model on the ray through pixel (i, j) (row 0 at the bottom, as
/// in RayCastResult), found by the same ray cast as the picture's (a one-pixel camera on that
/// ray), and the model's attribute `attribute` there: for a scene (Lang/Scene.h) the attribute
/// "object" is the id of the frontmost object; an empty name asks for no attribute. Throws
/// std::invalid_argument for a pixel outside the camera's picture, an attribute the model does not
/// have, and what rayCast throws for.
Pick pick(const frep::Hypervolume& model, const frep::Box3& box, const Camera& camera, int i, int j,
  const std::string& attribute = "object", const RayCastOptions& options = {});

} // namespace ictk::render
