// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The CSG recipes behind the bundled models `csg3` and `random1000`. They are exposed so that the
// benchmark can build the very same trees out of VTK implicit functions (vtkSphere, vtkBox,
// vtkCylinder, vtkImplicitBoolean) and compare fields and speed apples to apples.

#include "FRep/Expr.h"
#include "FRep/ModelRegistry.h"

#include <array>
#include <cstdint>
#include <vector>

namespace ictk::frep::bundled
{

/// One node of a CSG tree. Leaves use `p`; operations use the children `a` and `b` (indices into
/// CsgRecipe::nodes).
struct CsgNode
{
  enum class Kind : std::uint8_t
  {
    Sphere,       ///< p = (cx, cy, cz, r)
    Box,          ///< p = (xmin, ymin, zmin, xmax, ymax, zmax), every side > 0
    CylinderY,    ///< infinite, along y: p = (cx, cy, cz, r)
    Union,        ///< VTK: min; ICTK: max
    Intersection, ///< VTK: max; ICTK: min
    Difference    ///< a \ b. VTK: max(a, -b); ICTK: min(a, -b)
  };
  Kind kind = Kind::Sphere;
  std::array<double, 6> p{};
  int a = -1;
  int b = -1;
};

struct CsgRecipe
{
  std::vector<CsgNode> nodes;
  int root = -1;
};

/// (sphere r = 1 ∩ box [-0.8, 0.8]^3) \ cylinder along y, r = 0.4, all centred at the origin.
CsgRecipe csg3Recipe();
/// The unit sphere at the origin (the `sphere` model), as a one-node recipe.
CsgRecipe sphereRecipe();
/// The random CSG of spheres and boxes behind `random1000` (fixed seed, portable).
CsgRecipe random1000Recipe();
/// The same family with `primitives` spheres and boxes (at least 1) and any seed: a random walk
/// of centres in [-0.75, 0.75]^3, combined by a balanced tree of min/max (13 to 16 tape
/// instructions per primitive: 62 give 1016, 628 give 10019, 7940 give 100161). random1000Recipe()
/// is randomCsgRecipe(48, 20240611). Used by the scaling benchmark (`ictk bench --scaling`,
/// docs/performance.md).
CsgRecipe randomCsgRecipe(int primitives, std::uint32_t seed);

/// The ICTK field (f >= 0 inside) of a recipe: exactly minus the field of the equivalent
/// vtkImplicitBoolean tree, operation for operation (up to the rounding of vtkCylinder's
/// projection on its axis).
Expr csgField(const CsgRecipe& recipe);

/// Minus vtkBox::EvaluateFunction for the box [lo, hi]: -max_i d_i inside and -|distance| outside,
/// d_i = max(lo_i - p_i, p_i - hi_i). Every side must be longer than 0.
Expr vtkBoxField(const std::array<double, 3>& lo, const std::array<double, 3>& hi);

/// Every bundled model (the registry starts with these).
/// libfive's mesh benchmark "sphereGyroid" (libfive test/util/shapes.cpp; the formulas of
/// shared/bench/README.md), negated to FRep's convention (f >= 0 inside):
///   g = sin(x/s)cos(y/s) + sin(y/s)cos(z/s) + sin(z/s)cos(x/s), s = 0.5; gyroid = max(g, g - 0.5)
///   sphere = |p| - 3; sg = max(sphere, gyroid); f = -min(sg, min(sg, 2 sqrt(|sg|) - 0.5)).
Expr sphereGyroidField();

std::vector<ModelInfo> modelInfos();

} // namespace ictk::frep::bundled
