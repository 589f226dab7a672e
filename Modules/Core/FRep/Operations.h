// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// FRep operations (f >= 0 inside). Set operations check that their operands share a modelling
// domain (thesis L1118) and throw DomainError otherwise. Every operation is built as an Expr, so
// all evaluators (point, batch, interval, gradient) support the result.
//
// Errors: an operand on the wrong domain raises DomainError; an invalid parameter (NaN, zero
// scale, singular matrix, alpha out of range, ...) raises std::invalid_argument whose message
// names the operation and the parameter.

#include "FRep/Domain.h"
#include "FRep/Primitives.h"

#include <array>
#include <vector>

namespace ictk::frep
{

// --- set-theoretic operations ------------------------------------------------------------------
/// R-functions of the alpha-system (thesis_ch2_3.md 1.7 [EXT]):
///   f1 |_a f2 = (f1 + f2 + sqrt(f1^2 + f2^2 - 2 a f1 f2)) / (1 + a), intersection with "-".
/// alpha must lie in (-1, 1]. alpha = 0 is exactly the thesis pair (L620-L622)
/// f1 + f2 +- sqrt(f1^2 + f2^2); alpha = 1 is exactly max / min (L614-L616).
Shape unite(const Shape& a, const Shape& b, double alpha = 0.0);
Shape intersect(const Shape& a, const Shape& b, double alpha = 0.0);
/// The R-functions themselves on fields' values, what unite and intersect build (and the
/// HyperFun and BlobTree front ends), alpha in (-1, 1], as Exprs or doubles (one formula). They
/// are computed without the cancellation of f1 + f2 + r (r the square root) where f1 + f2 < 0:
/// there the union is the same number as -2 (1 + alpha) f1 f2 / (r - f1 - f2) / (1 + alpha),
/// which keeps the nearer operand next to a far one (f1 = -1e8, f2 = 1e-9: about 1e-9, where the
/// sum gives 0); the intersection likewise where f1 + f2 > 0.
Expr rUnion(const Expr& f1, const Expr& f2, double alpha = 0.0);
Expr rIntersection(const Expr& f1, const Expr& f2, double alpha = 0.0);
double rUnion(double f1, double f2, double alpha = 0.0);
double rIntersection(double f1, double f2, double alpha = 0.0);
/// hfBlock.c's unnormalised R-intersection f1 + f2 - sqrt(f1^2 + f2^2 - 2 alpha f1 f2), that is
/// (1 + alpha) rIntersection(f1, f2, alpha) for alpha != 1, computed the same way.
Expr hyperFunIntersection(const Expr& f1, const Expr& f2, double alpha);
/// a \ b = a intersect_alpha (-b) (thesis_ch2_3.md 1.7 [EXT]).
Shape subtract(const Shape& a, const Shape& b, double alpha = 0.0);
/// C^m R-functions (Pasko & Savchenko 1994; thesis_ch2_3.md 1.7 [EXT]; replaces the garbled
/// L633-L635 form): (f1 + f2 +- sqrt(f1^2 + f2^2)) (f1^2 + f2^2)^(m/2), m >= 0 (m = 0 is unite /
/// intersect). Subtraction uses -f2.
Shape uniteCm(const Shape& a, const Shape& b, int m);
Shape intersectCm(const Shape& a, const Shape& b, int m);
Shape subtractCm(const Shape& a, const Shape& b, int m);
/// min/max forms (Ricci, L612-L618).
Shape uniteMinMax(const Shape& a, const Shape& b);
Shape intersectMinMax(const Shape& a, const Shape& b);
Shape subtractMinMax(const Shape& a, const Shape& b);
/// Complement: -f.
Shape negate(const Shape& a);
/// Blending union (L643-L645):
///   f1 + f2 + sqrt(f1^2 + f2^2) + a0 / (1 + (f1/a1)^2 + (f2/a2)^2).
/// Blending intersection [EXT] as HyperFun hfBlendInt: the same displacement added to the
/// R-intersection f1 + f2 - sqrt(f1^2 + f2^2). a1, a2 must be finite and non-zero.
Shape blendUnion(const Shape& a, const Shape& b, double a0, double a1, double a2);
Shape blendIntersection(const Shape& a, const Shape& b, double a0, double a1, double a2);
/// Bounded blending (L651-L659) with an amplitude a0 on the displacement (a0 = 1 is the thesis
/// formula literally):
///   F = f1 + f2 + sqrt(f1^2 + f2^2) + a0 disp(r),
///   disp = (1 - r^2)^3 / (1 + r^2) for r < 1, else 0,
///   r = r1^2 / (r1^2 + r2^2) if r2 > 0, else 1,
///   r1^2 = (f1/a1)^2 + (f2/a2)^2,  r2^2 = (f3/a3)^2 if f3 > 0, else 0.
/// Blending is confined to the bounding solid f3 > 0; elsewhere F is exactly the R-union.
/// All three shapes must share one domain; a1, a2, a3 must be finite and non-zero.
Shape boundedBlend(const Shape& a, const Shape& b, const Shape& bound, double a1, double a2,
  double a3, double a0 = 1.0);
/// f + d (d > 0 grows the solid; a metric offset only when f is a signed distance).
Shape offset(const Shape& a, double d);

// --- space mappings (the query point is inverse-mapped: f'(p) = f(M^-1 p)) -----------------------
// The mappings act on x, y, z (t is never touched). A shape whose domain lacks one of x, y, z can
// be mapped as long as the mapping leaves that axis alone (zero shift, unit scale, no coupling);
// otherwise DomainError.
/// Translation by v [hfShift3D: x' = x - dx].
Shape shift(const Shape& a, const Vec3& v);
/// Scaling about the origin [hfScale3D: x' = x / sx]; factors must be non-zero.
Shape scale(const Shape& a, const Vec3& s);
/// Rotation of the object by angle (right-handed) about X, Y or Z [hfRotate3DX/Y/Z]; needs the two
/// coordinates of the rotation plane. Axis::T is invalid.
Shape rotate(const Shape& a, Axis axis, double angleRadians);
/// General affine map p' = A p + b given row-major (3x4: rows [A | b]); the shape is inverse-mapped
/// with A^-1 (p - b). Throws std::invalid_argument if A is singular or non-finite.
Shape affine(const Shape& a, const std::array<double, 12>& matrix);
/// Twist about `axis` [hfTwistX/Y/Z]: with u the coordinate along the axis,
/// t = (u - z1) / (z2 - z1), theta = (1 - t) theta1 + t theta2 (not clamped, as HyperFun), and the
/// plane orthogonal to the axis is inverse-rotated by theta. Needs x, y, z; z1 != z2.
Shape twist(const Shape& a, Axis axis, double z1, double z2, double theta1, double theta2);
/// Taper along `axis` [hfTaperX/Y/Z]: scale = s1 for u < z1, s2 for u > z2, linear in between; the
/// two other coordinates are divided by scale. Needs x, y, z; z1 < z2; s1, s2 > 0.
Shape taper(const Shape& a, Axis axis, double z1, double z2, double s1, double s2);
/// Barr (1984) bend about `axis` with curvature k (bend radius 1/k), unbounded region, centre at
/// the origin. For axis X the object's Y direction is wrapped onto the circle of radius 1/k centred
/// at z = 1/k (bending towards +z); axes cycle (Y: Z bends towards +X; Z: X bends towards +Y).
/// Needs only the two coordinates of the bending plane. k = 0 is the identity.
Shape bend(const Shape& a, Axis axis, double curvature);
/// Stretch about a centre [hfStretch3D: x' = x0 + (x - x0) / sx]; factors must be non-zero.
Shape stretch(const Shape& a, const Vec3& center, const Vec3& factors);
/// Local warps by control points [hfSpaceMapCubic, hfSpaceMapExp]: the material at source[i] is
/// carried to target[i], space near target[i] following. The query point p is inverse-mapped one
/// control point after the other (i = 0, 1, ...), each step using the point left by the previous
/// one, as HyperFun updates its coordinate array in place:
///   d = target[i] - source[i],  u_k = (p_k - target[i]_k) / (b[i]_k (1 + |d_k|))  (k = x, y, z),
///   r^2 = u_x^2 + u_y^2 + u_z^2,  p <- p - w(r) d,
/// with w = (1 - r)^3 / (1 + r) for r <= 1 and 0 beyond (cubic; zero outside the ellipsoid of
/// half-axes b_k (1 + |d_k|) about the target), or w = exp(-r^2) (exp; everywhere). `influence`
/// holds b[i] per control point. The three lists must have one length (empty: the identity);
/// every value must be finite and each b component non-zero. Needs x, y, z.
Shape spaceMapCubic(const Shape& a, const std::vector<Vec3>& source,
  const std::vector<Vec3>& target, const std::vector<Vec3>& influence);
Shape spaceMapExp(const Shape& a, const std::vector<Vec3>& source, const std::vector<Vec3>& target,
  const std::vector<Vec3>& influence);

// --- dimension and time --------------------------------------------------------------------------
/// Cartesian product of shapes on disjoint coordinate sets (L1139-L1141): the R-intersection of
/// both, on the domain formed by the union of their coordinates (must be one of Table 1), e.g.
/// an XY disk x a T interval -> XYT.
Shape cartesianProduct(const Shape& a, const Shape& b);
/// Cartesian product with placement (L1139): coordinate i of a's domain is placed on axis
/// aAxes[i] (likewise for b), as reproject() does; the target domain is the union of the placed
/// axes. The L1139 example (XY disk on the XZ plane x X segment on the Y axis) is
/// cartesianProduct(disk, {X, Z}, segment, {Y}).
Shape cartesianProduct(
  const Shape& a, const std::vector<Axis>& aAxes, const Shape& b, const std::vector<Axis>& bAxes);
/// Projection along `axis` (existential: max over the axis), sampled at `samples` >= 2 equally
/// spaced points on [lo, hi]; the result's domain drops the axis (must be one of Table 1).
/// This is a SAMPLED supremum: the result is a lower bound of the true projection
/// sup_{u in [lo, hi]} f, within L h / 2 for a field with Lipschitz constant L along the axis and
/// spacing h = (hi - lo) / (samples - 1); thin features can be missed between samples.
Shape project(const Shape& a, Axis axis, double lo, double hi, int samples = 64);
/// Linear metamorphosis (1 - s) f1 + s f2 (Pasko et al. 1995); s in [0, 1].
Shape metamorphosis(const Shape& a, const Shape& b, double s);
/// Time-dependent linear metamorphosis: s(t) = clamp((t - t0) / (t1 - t0), 0, 1); the shapes must
/// not use t, and the result lives on their domain extended with t.
Shape metamorphosis(const Shape& a, const Shape& b, double t0, double t1);
/// The parameters of space-time blending: the transition interval [t0, t1], the bounded blend's
/// amplitude a0 (added material, > 0 in the thesis) and scales a1, a2 (operands) and a3 (the
/// bounding time slab), and how far the half-cylinders reach into the slab, as a fraction of
/// t1 - t0 (0 < overlap <= 0.5).
struct SpaceTimeBlendParameters
{
  double t0 = 0, t1 = 1;
  double a0 = 1, a1 = 1, a2 = 1, a3 = 1;
  double overlap = 0.25;
};
/// Throws std::invalid_argument, naming `operation` and the parameter, unless t0 < t1 (both
/// finite), 0 < overlap <= 0.5 and a0..a3 are finite with a1, a2, a3 non-zero.
void validateSpaceTimeBlend(const char* operation, const SpaceTimeBlendParameters& p);
/// Space-time blending (thesis 5.3, L1161-L1171, EXT L3074-L3083; Pasko, Pasko & Kunii 2004) of
/// two fields f1, f2 that do not depend on t, with `t` the time coordinate (Expr::t(), a
/// HyperFun model's x[4], or a constant for one cross-section): the fields become half-cylinders
/// in space-time,
///   F1 = f1 R-intersect (tA - t),  F2 = f2 R-intersect (t - tB),
/// with tA = t0 + overlap (t1 - t0), tB = t1 - overlap (t1 - t0), and are bounded-blended with the
/// time slab F3 = (t - t0) R-intersect (t1 - t) as bounding solid. Hence for t <= t0 the slice has
/// exactly the sign of f1 and for t >= t1 exactly the sign of f2; the transition (with added
/// material a0) happens inside (t0, t1). The half-cylinders reach into the slab (overlap > 0) so
/// that the slices vary continuously in t. Validates p (validateSpaceTimeBlend).
Expr spaceTimeBlendExpr(
  const Expr& f1, const Expr& f2, const Expr& t, const SpaceTimeBlendParameters& p);
/// spaceTimeBlendExpr of two shapes of one time-free domain (X, XY or XYZ); the result lives on
/// their domain extended with t.
Shape spaceTimeBlend(const Shape& a, const Shape& b, const SpaceTimeBlendParameters& p);
/// The same with the parameters spelled out.
Shape spaceTimeBlend(const Shape& a, const Shape& b, double t0, double t1, double a0, double a1,
  double a2, double a3, double overlap = 0.25);

} // namespace ictk::frep
