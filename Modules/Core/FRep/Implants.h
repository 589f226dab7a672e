// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Parametric implants for medical studies (issue 15, docs/medical.md): a pin, a threaded screw,
// a plate with holes and a graded gyroid scaffold, each built in its own frame and placed in the
// patient's by a rigid transform, and the interface shell around any implant. They are ordinary
// kernel shapes (Exprs on XYZ, f >= 0 inside), so every evaluator, interval bound and mesher
// takes them, and HyperFun reaches them as hfPin, hfScrew, hfPlate and hfGyroid
// (Lang/HyperFunLibrary.cxx), which is how a study file places them.
//
// The fields are distances, or close to them (|grad f| = 1 on the pin's and the plate's faces,
// sqrt(1 + (2 depth / pitch)^2) on the screw's thread flanks, about 1 on the scaffold's walls):
// the CGAL backend's surface criteria and an offset by a thickness then mean millimetres.
//
// Errors: a size that must be positive, a NaN or infinite parameter, a hole outside the plate or
// a degenerate placement raise std::invalid_argument naming the implant and the parameter, e.g.
// "screw: pitch must be positive (got nan)".

#include "FRep/Domain.h"
#include "FRep/Primitives.h"

#include <vector>

namespace ictk::frep
{

/// Where an implant's own frame sits in the patient's: its local z axis runs along `axis` from
/// `origin`, and its local x axis is `reference` made orthogonal to `axis` (the plate, the
/// scaffold and the screw's thread phase are not symmetric about the axis). A zero `reference`
/// (the default) takes the patient's x, y or z axis least aligned with `axis`; a given one must
/// not be parallel to `axis`. Neither vector need be unit.
struct Placement
{
  Vec3 origin{ 0, 0, 0 };
  Vec3 axis{ 0, 0, 1 };
  Vec3 reference{ 0, 0, 0 };
};

/// `local`, built in an implant's frame, moved into the patient's: f(p) = local(R^T (p - o)),
/// with R's columns the placement's unit x, y, z axes. Needs an XYZ shape.
Shape place(const Shape& local, const Placement& where);

/// A cylindrical pin of `radius` from z = 0 to z = length in its frame:
/// min(radius - rho, min(z, length - z)), rho the distance to the z axis.
Shape pin(double radius, double length, const Placement& where = {});

/// A screw with a single-start V thread, along its z axis from the tip z = 0 to z = length.
struct ScrewThread
{
  /// The root radius (the core) and the crest radius (the thread's outside); core < major.
  double coreRadius = 1.5;
  double majorRadius = 2;
  /// The thread's advance per turn.
  double pitch = 1;
  double length = 10;
};
/// The thread's radius at height z and angle theta = atan2(y, x) is
///   r(z, theta) = core + (major - core) (1 - |2 u - 1|),  u = frac(z / pitch - theta / (2 pi)),
/// a symmetric V whose crest (u = 1/2) winds right-handed; the field is
/// min(r(z, theta) - rho, min(z, length - z)). A turn of theta changes u by exactly 1, so the
/// field is continuous across atan2's cut.
Shape screw(const ScrewThread& thread, const Placement& where = {});

/// A flat plate in its frame's x, y plane: [0, length] x [0, width] x [0, thickness], pierced
/// along z by round holes of `holeRadius` centred at `holes` (x, y in the plate's frame).
struct PlateShape
{
  double length = 20;
  double width = 8;
  double thickness = 2;
  double holeRadius = 1.5;
  std::vector<Vec2> holes;
};
/// min(box, min_i(|(x, y) - hole_i| - holeRadius)), the box as the min of its six face distances.
/// Every hole must lie inside the plate's outline with a rim left (its disk strictly within
/// [0, length] x [0, width]); holes may not overlap (each one then adds exactly one handle, so a
/// plate with n holes bounds a surface of genus n).
Shape plate(const PlateShape& p, const Placement& where = {});

/// The gyroid sheet of a TPMS scaffold, graded by a field: the solid within wallThickness(p) / 2
/// of the gyroid's nodal surface g = 0,
///   g(p) = sin(k x) cos(k y) + sin(k y) cos(k z) + sin(k z) cos(k x),  k = 2 pi / cellSize,
///   f(p) = wallThickness(p) / 2 - |g(p)| / |grad g(p)|
/// (|g| / |grad g| is the distance to g = 0 to first order, so the wall is about wallThickness
/// thick in mm wherever it is thin against the cell). `wallThickness` is any field of x, y, z in
/// the scaffold's frame (a constant, or a gradient along the implant, e.g. the HyperFun text
/// a study gives); it is not checked for sign (a wall of thickness <= 0 is simply absent). The
/// sheet fills all space: intersect it with the region it should fill. A true parallel shell of
/// small constant thickness w has the volume fraction (A / V) w - (4 pi / 3) (w / a)^3, A / V the
/// gyroid's area per volume, 3.0915 / a (Schoen), the cubic term Gauss-Bonnet's (integral of K
/// over one cell = 2 pi chi = -16 pi); this first-order wall holds 0.7 % less at w = a / 20,
/// 3.6 % less at a / 10 and 7 % less at 0.15 a (measured, TestImplants.cxx).
Shape gyroidSheet(double cellSize, const Expr& wallThickness, const Placement& where = {});
/// |g| / |grad g| of the gyroid of `cellSize` in its own frame (no placement): the part of
/// gyroidSheet that does not depend on the wall, for front ends that combine it with a wall
/// field of their own coordinates (HyperFun's hfGyroid).
Expr gyroidDistance(double cellSize);

/// The interface layer of `thickness` around an implant (offset minus implant, by min/max):
/// min(f + thickness, -f). A metric layer when f is a distance, as the implants above are.
Shape interfaceShell(const Shape& implant, double thickness);

} // namespace ictk::frep
