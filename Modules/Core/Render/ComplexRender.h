// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// A picture of an implicit complex, its cells of every dimension composed through one depth
// buffer as seed 001 renders them (papers.md 1.9, its erratum E5 read as there):
//   pass A, the cells drawn from their discretisation (ComplexMesh), by the exact rasteriser
//   (Rasterize.h): 0D cells as small spheres, 1D cells (explicit polylines, traced implicit and
//   mapped curves) as thin tubes, 2D cells (trimmed FRep patches, mapped patches, explicit
//   triangles) as their triangles, and 3D cells that cannot be ray cast (explicit tetrahedra) as
//   their boundary triangles;
//   pass B, every 3D cell given by fields (FRep, voxel, composite: carriers none, inside fields
//   min-ed), ray cast directly (RayCast.h, the same no-miss search) against the depth the canvas
//   holds, in the cell's box.
// 2D cells are rasterised rather than ray cast against their carrier and trimmed: their
// discretisation exists for every kind (mapped patches have no carrier in E^3 to ray cast), is
// what `ictk mesh` writes, and the paper's flower was drawn that way. Where a 2D cell lies on a
// 3D cell's boundary, the nearer of the triangle and the solid's surface shows at each pixel, so
// the two speckle to the discretisation's accuracy.
//
// Colours come from one attribute (ColourOptions): a 3-component colour (the flower's colour)
// or a scalar through a colour map. A meshed cell takes it from its discretisation's point
// array of that name (interpolated over triangles and along tubes), else from its own binding,
// else the attribute's inside default; a ray-cast cell evaluates its own binding at the first
// point found inside, else takes the inside default. The result says how many pixels show
// cells of each dimension.

#include "Complex/Complex.h"
#include "Complex/Discretization.h"
#include "FRep/Progress.h"
#include "Render/Camera.h"
#include "Render/Canvas.h"
#include "Render/Rasterize.h"

#include <array>
#include <cstdint>
#include <vector>

namespace ictk::render
{

struct ComplexRenderOptions
{
  /// Threads to use; 0 = TBB's default.
  int threads = 0;
  /// Radius of the tubes of 1D cells; 0: 1/200 of the half-diagonal of the complex's box.
  double tubeRadius = 0;
  /// Radius of the spheres of 0D cells; 0: 2.5 tube radii.
  double pointRadius = 0;
  ColourOptions colours;
  /// The ray caster's depth tolerance (RayCastOptions::depthTolerance).
  double depthTolerance = 0;
  /// Progress and cancellation: pass A in [0, 0.1], the ray-cast cells in equal shares after.
  Progress progress;
};

struct ComplexRenderResult
{
  Canvas canvas;
  /// Pixels that show a cell of dimension 0, 1, 2, 3.
  std::array<std::int64_t, 4> pixelsByDimension{ 0, 0, 0, 0 };
  /// Of the ray-cast cells (RayCastResult's counts, summed).
  std::int64_t unresolvedPixels = 0;
  /// Rays that start inside a solid where they enter its cell's box (the box is part of the
  /// cell's definition: this is the cell's face).
  std::int64_t cutPixels = 0;
  /// Of those, the rays that start inside a solid at the camera: it is inside the cell.
  std::int64_t eyeInsidePixels = 0;
  std::int64_t intervalEvaluations = 0;
  /// The radii used.
  double tubeRadius = 0;
  double pointRadius = 0;
  /// Coloured by a scalar: the values at the colour map's ends (else NaN).
  std::array<double, 2> scalarRange{ std::numeric_limits<double>::quiet_NaN(),
    std::numeric_limits<double>::quiet_NaN() };
};

/// True for a cell drawn by ray casting: 3D and given by fields (no carriers, inside fields).
bool isRayCast(const complex::Cell& cell);

/// The cells whose discretisation renderComplex needs: every cell that is not ray cast.
std::vector<complex::CellId> meshedCells(const complex::Complex& complex);

/// Throws std::invalid_argument unless the options colour the complex: an attribute it declares
/// with 1, 3 or 4 components (or none named), a known colour map. renderComplex checks the
/// same; this is for checking before the discretisation it needs.
void checkColours(const complex::Complex& complex, const ColourOptions& colours);

/// What pass A draws: the meshed cells as primitives (owner: the cell id) with their paints, the
/// radii used, and the cells pass B ray casts.
struct ScenePrimitives
{
  std::vector<Primitives> meshed;
  std::vector<complex::CellId> rayCast;
  bool scalar = false; ///< the paints are scalars (else colours)
  double tubeRadius = 0;
  double pointRadius = 0;
};

/// The primitives of renderComplex's pass A; `everyCell`: every cell from its discretisation (3D
/// field cells by their boundary too), the polygonal scene of `ictk render --mode mesh`. Throws
/// as renderComplex does.
ScenePrimitives scenePrimitives(const complex::Complex& complex, const complex::ComplexMesh& mesh,
  const ComplexRenderOptions& options, bool everyCell);

/// The complex seen by `camera` (see the file comment). `mesh` holds the discretisation of every
/// cell of meshedCells() (more is fine). Throws std::invalid_argument for a missing
/// discretisation, an attribute the complex does not declare or that is neither a colour nor a
/// scalar, a radius that is not positive and finite (or 0), an unknown colour map; Cancelled.
ComplexRenderResult renderComplex(const complex::Complex& complex, const complex::ComplexMesh& mesh,
  const Camera& camera, const ComplexRenderOptions& options = {});

} // namespace ictk::render
