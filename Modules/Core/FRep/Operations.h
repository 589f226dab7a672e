// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// FRep operations (f >= 0 inside). Set operations check that their operands share a modelling
// domain (thesis L1118) and throw DomainError otherwise.

#include "FRep/Domain.h"
#include "FRep/Primitives.h"

namespace ictk::frep
{

// --- set-theoretic operations ------------------------------------------------------------------
/// R-functions of the alpha-system (thesis_ch2_3.md 1.7 [EXT]); alpha = 0 is the thesis pair
/// (L620-L622): f1 + f2 +- sqrt(f1^2 + f2^2); alpha = 1 gives max / min (L614-L616).
Shape unite(const Shape& a, const Shape& b, double alpha = 0.0);
Shape intersect(const Shape& a, const Shape& b, double alpha = 0.0);
Shape subtract(const Shape& a, const Shape& b, double alpha = 0.0);
/// min/max forms (Ricci, L612-L618).
Shape uniteMinMax(const Shape& a, const Shape& b);
Shape intersectMinMax(const Shape& a, const Shape& b);
Shape subtractMinMax(const Shape& a, const Shape& b);
Shape negate(const Shape& a);
/// Blending union / intersection (L643-L645; intersection [EXT] as hfBlendInt).
Shape blendUnion(const Shape& a, const Shape& b, double a0, double a1, double a2);
Shape blendIntersection(const Shape& a, const Shape& b, double a0, double a1, double a2);
/// Bounded blending (L651-L659) with an amplitude a0 (a0 = 1 is the thesis formula).
Shape boundedBlend(const Shape& a, const Shape& b, const Shape& bound, double a1, double a2,
  double a3, double a0 = 1.0);
/// f + d.
Shape offset(const Shape& a, double d);

// --- space mappings (the query point is inverse-mapped: f'(p) = f(M^-1 p)) -----------------------
Shape shift(const Shape& a, const Vec3& v);                 // hfShift3D
Shape scale(const Shape& a, const Vec3& s);                 // hfScale3D
Shape rotate(const Shape& a, Axis axis, double angleRadians); // hfRotate3DX/Y/Z
/// General affine map p' = A p + b given row-major (3x4); throws if A is singular.
Shape affine(const Shape& a, const std::array<double, 12>& matrix);
Shape twist(const Shape& a, Axis axis, double z1, double z2, double theta1, double theta2); // hfTwistX/Y/Z
Shape taper(const Shape& a, Axis axis, double z1, double z2, double s1, double s2);         // hfTaperX/Y/Z
/// Barr bend about `axis`.
Shape bend(const Shape& a, Axis axis, double curvature);
Shape stretch(const Shape& a, const Vec3& center, const Vec3& factors); // hfStretch3D

// --- dimension and time --------------------------------------------------------------------------
/// Cartesian product of shapes on disjoint coordinate sets (L1139-L1141): the R-intersection of
/// both, on the domain formed by the union of their coordinates (must be one of Table 1).
Shape cartesianProduct(const Shape& a, const Shape& b);
/// Projection along `axis` (existential: max over the axis), sampled at `samples` points on
/// [lo, hi]; the result's domain drops the axis.
Shape project(const Shape& a, Axis axis, double lo, double hi, int samples = 64);
/// Linear metamorphosis (1 - s) f1 + s f2 (Pasko et al. 1995); s in [0, 1].
Shape metamorphosis(const Shape& a, const Shape& b, double s);
/// Space-time blending (thesis 5.3): two shapes of one domain blended over t in [t0, t1] by bounded
/// blending in the domain extended with t.
Shape spaceTimeBlend(const Shape& a, const Shape& b, double t0, double t1, double a0, double a1,
  double a2, double a3);

} // namespace ictk::frep
