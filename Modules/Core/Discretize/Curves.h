// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Discretisation of 1D implicit cells (curves) by predictor-corrector tracing (not marching
// cubes).
//
// A 1D cell of E^3 is kept as two carrier fields g1, g2 (the curve lies on g1 = 0 and g2 = 0)
// and trim fields H_k (the cell is where every H_k >= 0); seed 001's -(G)^2 form has no inside
// and is never contoured. A 1D mapped cell is {g(u, v) = 0, trims >= 0} in the (u, v) = (x, y)
// plane, pushed to E^3 afterwards with mapToSpace (Patches.h).
//
// The tracer:
//  1. seeds: the box is divided into a grid of seed boxes of edge about options.seedSize; an
//     octree-like subdivision visits only the boxes where interval arithmetic says both carriers
//     may vanish and no trim is certainly negative; in each, Gauss-Newton from the centre (then
//     from the octant centres) looks for a point of the curve inside the box;
//  2. tracing, from each seed not already on a traced curve: Euler predictor along
//     t = grad g1 x grad g2 (g2 = the plane's normal in 2D), Gauss-Newton corrector, step halved
//     until the corrector converges and the tangent turns by at most options.maxTurn, then grown
//     again up to options.step; the trace closes a loop when it comes back to its seed, and stops
//     exactly (Newton on {g1, g2, H_k} or {g1, g2, face}, bisection as a fallback) where it
//     leaves the trims or the box; an open curve is traced both ways from its seed;
//  3. no duplicates: the seed boxes a traced curve passes through are marked visited, and a seed
//     closer than a quarter step to a traced curve is dropped.
//
// Each polyline runs along grad g1 x grad g2 (in 2D along grad g x e_z: outer boundaries of
// {g >= 0} counter-clockwise); a closed curve repeats its first index at the end. The output is
// deterministic for any thread count (seeds are found in parallel, traced in a fixed order).
//
// Limits (documented, not detected): components closer to each other than a quarter step may be
// merged or missed, trim regions thinner than a step along the curve may be stepped over, and
// a trace stops (the polyline ends) at a singular point met along the way (carriers tangent
// there, e.g. a self-crossing curve).

#include "Discretize/Mesh.h"

#include <stdexcept>

namespace ictk::discretize
{

/// Raised when the carriers are tangent (grad g1 x grad g2 vanishes, or a gradient vanishes) at
/// a point of their common zero set where tracing would start: the set is not a regular curve
/// there (tangent surfaces, coincident carriers, seed 001's literal -(G)^2 carriers).
class DegenerateCurve : public std::runtime_error
{
public:
  using std::runtime_error::runtime_error;
};

struct CurveOptions
{
  /// Longest segment (required > 0).
  double step = 0;
  /// Edge of the seed boxes (0 = step). Smaller finds smaller components.
  double seedSize = 0;
  /// Largest angle (radians) between the tangents at consecutive points (curvature control).
  double maxTurn = 0.2;
  /// Points satisfy |g| <= tolerance * |grad g| for every carrier (about a distance).
  double tolerance = 1e-10;
  int maxIterations = 30;
  /// Throw std::runtime_error beyond this many output points.
  double maxPoints = 1e7;
  /// Throw std::invalid_argument beyond this many candidate seed boxes (the carriers may then
  /// vanish on a surface: see DegenerateCurve) or beyond 2^20 seed boxes along an axis.
  double maxSeedBoxes = 4e6;
  /// |grad g1 x grad g2| / (|grad g1| |grad g2|) below this at a seed raises DegenerateCurve
  /// (and ends a trace that meets it). 0 = sqrt(tolerance / min(step, seedSize)): two surfaces
  /// that touch, each known to `tolerance`, look like a loop of radius about
  /// sqrt(tolerance / curvature) along which the sine is about that small, so such sub-resolution
  /// loops are reported as tangencies rather than traced.
  double degenerateSine = 0;
  /// Threads for seeding (0 = TBB's default). The result does not depend on it.
  int threads = 0;
};

/// {g1 = 0, g2 = 0, every trim >= 0} inside `box` as polylines (see the file comment).
CurveSet traceCurve(const frep::Field& g1, const frep::Field& g2,
  const std::vector<frep::FieldPtr>& trims, const Box3& box, const CurveOptions& options);

/// {g(u, v) = 0, every trim >= 0} in the (u, v) = (x, y) rectangle of `box` (box.z ignored; the
/// fields are evaluated and the points placed at z = 0) as polylines.
CurveSet traceCurve2D(const frep::Field& g, const std::vector<frep::FieldPtr>& trims,
  const Box3& box, const CurveOptions& options);

} // namespace ictk::discretize
