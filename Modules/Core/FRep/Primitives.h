// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The FRep primitive library (f >= 0 inside). Formulas follow the HyperFun library (hf* names in
// brackets) so that HyperFun models read later give the same fields; every function lowers to the
// expression DAG, so all evaluators support every primitive.
//
// Errors: a size that must be positive (radius, half-axis, side, kernel width...), a NaN or
// infinite parameter, or parallel vectors of different lengths raise std::invalid_argument whose
// message names the primitive and the parameter, e.g. "sphere: radius r must be positive (got -1)".
//
// Where ICTK deliberately differs from the HyperFun C library, the function says so (convolution
// arcs and triangles, hfBlock's alpha); the Primitives.cxx comments give the source lines.

#include "FRep/Domain.h"

#include <array>
#include <vector>

namespace ictk::frep
{
using Vec2 = std::array<double, 2>;
using Vec3 = std::array<double, 3>;

// --- 1D and 2D ------------------------------------------------------------------------------
/// Segment [a, b] on axis X (domain X): (x - a)(b - x). Needs a < b.
Shape interval(double a, double b);
/// Time interval [t0, t1] (domain T): (t - t0)(t1 - t). Needs t0 < t1.
Shape timeInterval(double t0, double t1);
/// Disk (domain XY): r^2 - |p - c|^2.
Shape circle(const Vec2& center, double r);
/// Elliptic disk (domain XY): 1 - ((x-cx)/a)^2 - ((y-cy)/b)^2.
Shape ellipse(const Vec2& center, double a, double b);
/// Axis-aligned rectangle (domain XY) with corner `vertex` and sides dx, dy:
/// min((x - vx)(vx + dx - x), (y - vy)(vy + dy - y)), the 2D analogue of block().
Shape rectangle(const Vec2& vertex, double dx, double dy);

// --- 3D (domain XYZ) ---------------------------------------------------------------------------
/// r^2 - |p - c|^2 [hfSphere].
Shape sphere(const Vec3& center, double r);
/// 1 - ((x-cx)/a)^2 - ((y-cy)/b)^2 - ((z-cz)/c)^2 [hfEllipsoid].
Shape ellipsoid(const Vec3& center, double a, double b, double c);
/// Axis-aligned box with corner `vertex` and sides dx, dy, dz: the min (alpha = 1) intersection
/// of the three slabs (x - vx)(vx + dx - x), ... [hfBlock with ALPHA = 1].
Shape block(const Vec3& vertex, double dx, double dy, double dz);
/// The same box intersected with HyperFun's R-function form for any alpha in (-1, 1]
/// [hfBlock]: g = f1 + f2 - sqrt(f1^2 + f2^2 - 2 alpha f1 f2), applied twice (x with y, then
/// with z), with no 1/(1 + alpha) factor, exactly as hfBlock. alpha = 1 equals block().
Shape blockRFunction(const Vec3& vertex, double dx, double dy, double dz, double alpha = 0.0);
/// Infinite cylinder along `axis` (X, Y or Z) through `center`: r^2 - (squared distance to the
/// axis line) [hfCylinderX/Y/Z].
Shape cylinder(Axis axis, const Vec3& center, double r);
/// Elliptic cylinder along `axis`: 1 - (u/a)^2 - (v/b)^2, where (u, v) are the two other
/// coordinates in x, y, z order relative to the center (X: (y, z), Y: (x, z), Z: (x, y))
/// [hfEllCylX/Y/Z].
Shape ellipticCylinder(Axis axis, const Vec3& center, double a, double b);
/// Double cone with apex `apex` along `axis`, radius r at distance 1 from the apex:
/// w^2 - (u/r)^2 - (v/r)^2, w the axial offset [hfConeX/Y/Z].
Shape cone(Axis axis, const Vec3& apex, double r);
/// Elliptic double cone: w^2 - (u/a)^2 - (v/b)^2, (u, v) as in ellipticCylinder [hfEllConeX/Y/Z].
Shape ellipticCone(Axis axis, const Vec3& apex, double a, double b);
/// Torus around `axis` through `center`, radius of revolution R, tube radius r:
/// r^2 - |p - c|^2 - R^2 + 2 R sqrt(u^2 + v^2) [hfTorusX/Y/Z].
Shape torus(Axis axis, const Vec3& center, double R, double r);
/// Superellipsoid 1 - (|x'|^(2/s2) + |y'|^(2/s2))^(s2/s1) - |z'|^(2/s1), x' = (x - cx)/a, ...
/// [hfSuperell]. s1, s2 > 0 (s = 1: ellipsoid; s -> 0: box; s = 2: octahedron).
Shape superellipsoid(const Vec3& center, double a, double b, double c, double s1, double s2);
/// General quadric with 10 coefficients (seed 003 eq. 1), no factor 2 on the cross terms:
/// A11x^2 + A22y^2 + A33z^2 + A12xy + A13xz + A23yz + A14x + A24y + A34z + A44,
/// coefficients in that order. All ten zero is rejected (f would vanish everywhere). Lowered with
/// each axis' square completed (A11 (x + A14 / 2A11)^2 ...), so that interval arithmetic gives the
/// exact range of an axis-aligned quadric over a box. The named types of seed 003 are in
/// FRep/Quadrics.h.
Shape quadric(const std::array<double, 10>& coefficients);
/// Half-space bounded by the plane through `point` with normal `inwardNormal` (pointing into the
/// solid): f = n.(p - point) / |n|, the signed distance to the plane (>= 0 on the normal's side).
Shape halfSpace(const Vec3& point, const Vec3& inwardNormal);

// --- skeletal and convolution primitives --------------------------------------------------------
/// Blobby model [hfBlobby] (Blinn 1982): sum_i b_i exp(-a_i r_i^2) - T, a_i > 0.
Shape blobby(const std::vector<Vec3>& centers, const std::vector<double>& a,
  const std::vector<double>& b, double threshold);
/// Metaballs [hfMetaBall] (Nishimura 1985): sum_i g_i(r_i) - T with
/// g(r) = b (1 - 3 r^2/d^2) for r <= d/3, 1.5 b (1 - r/d)^2 for d/3 < r <= d, 0 beyond; d_i > 0.
Shape metaball(const std::vector<Vec3>& centers, const std::vector<double>& b,
  const std::vector<double>& d, double threshold);
/// Soft objects [hfSoft] (Wyvill, McPheeters & Wyvill 1986): sum_i g(r_i) - T with
/// g(r) = 1 - (22/9)(r/d)^2 + (17/9)(r/d)^4 - (4/9)(r/d)^6 for r <= d, 0 beyond; d_i > 0.
Shape softObject(const std::vector<Vec3>& centers, const std::vector<double>& d, double threshold);

/// Convolution surfaces with the Cauchy kernel h(r) = 1 / (1 + s^2 r^2)^2
/// (thesis_ch2_3.md section 1.7; McCormack & Sherstyuk 1998), f = sum of skeleton fields - T.
/// Each skeleton field is the exact integral of h over the skeleton (per unit length or unit
/// area), in closed form. s_i > 0 is the kernel width control of skeleton i.
Shape convolutionPoints(
  const std::vector<Vec3>& points, const std::vector<double>& s, double threshold);
/// Line segments [hfConvLine].
Shape convolutionSegments(
  const std::vector<std::array<Vec3, 2>>& segments, const std::vector<double>& s, double threshold);
/// Line segments given a radius instead of s and T [hfConvLineR]: one kernel width for all,
/// s = 1/R for R < 1 and s = 1 otherwise; the segment fields are summed in order with the running
/// sum clamped at 1 (min(sum + field_i, 1)); the threshold is the field of the last segment alone
/// at distance R from its start, on the plane normal to it there:
///   T = l / (2 P^2 Q^2) + atan(s l / P) / (2 s P^3),  P^2 = 1 + s^2 R^2,  Q^2 = P^2 + s^2 l^2,
/// l the last segment's length. R > 0; segments must have non-zero length (hfConvLineR divides by
/// the length).
Shape convolutionSegmentsRadius(const std::vector<std::array<Vec3, 2>>& segments, double radius);
/// Circular arcs [hfConvArc], in HyperFun's parametrisation: arc i has its center, radius and
/// opening angle theta (degrees, 0 < theta <= 360); before rotation it lies in the plane z = 0 of
/// its center, starting on the +x direction and turning counter-clockwise; it is then rotated by
/// `angles[i]` degrees about the direction `axes[i]` (through the center). A zero axis is allowed
/// only with a zero angle. Unlike hfConvArc, the field is integrated over arc length (hfConvArc
/// integrates over the angle, i.e. it is this field divided by the radius).
Shape convolutionArcs(const std::vector<Vec3>& centers, const std::vector<double>& radii,
  const std::vector<double>& thetas, const std::vector<Vec3>& axes,
  const std::vector<double>& angles, const std::vector<double>& s, double threshold);
/// Triangles [hfConvTriangle]. Unlike hfConvTriangle, the field is the area integral of h
/// (hfConvTriangle returns s^3 times it).
Shape convolutionTriangles(const std::vector<std::array<Vec3, 3>>& triangles,
  const std::vector<double>& s, double threshold);
/// A polyline skeleton (consecutive points joined by segments) [hfConvCurve], one s for all.
Shape convolutionCurve(const std::vector<Vec3>& polyline, double s, double threshold);
/// A triangle-mesh skeleton [hfConvMesh]: 0-based vertex indices (hfConvMesh's are 1-based).
Shape convolutionMesh(const std::vector<Vec3>& vertices,
  const std::vector<std::array<int, 3>>& triangles, double s, double threshold);

/// The single-skeleton Cauchy fields (no threshold), for callers that weight or combine them
/// (e.g. a HyperFun reader reproducing hfConvArc's 1/radius or hfConvTriangle's s^3 scaling).
Expr cauchyPointField(const Vec3& point, double s);
Expr cauchySegmentField(const Vec3& begin, const Vec3& end, double s);
/// The same with its ends and kernel width as expressions, e.g. Expr::parameter slots: a skeleton
/// that moves compiles to one tape whose parameters each pose rebinds. Bound to values, such a
/// tape gives in double precision what the overload above gives with those values as constants,
/// bit for bit (that one is this one with constant leaves, folded in the same operations). No
/// checks: the ends must differ and s be positive (the overload above checks them).
Expr cauchySegmentField(
  const std::array<Expr, 3>& begin, const std::array<Expr, 3>& end, const Expr& s);
/// Arc parameters as in convolutionArcs (theta and angle in degrees).
Expr cauchyArcField(
  const Vec3& center, double radius, double theta, const Vec3& axis, double angle, double s);
Expr cauchyTriangleField(const std::array<Vec3, 3>& triangle, double s);

// --- noise and perturbation ---------------------------------------------------------------------
/// Gardner-style solid noise [hfNoiseG], added to a field to roughen it:
/// Ser(x) Ser(y) Ser(z), Ser(x) = A sin(w x) + (A/1.17) sin(w x/1.35 + phase sin(w z)), and
/// cyclically (y uses sin(w x), z uses sin(w y)); A = amplitude, w = frequency.
Expr gardnerNoise(double amplitude, double frequency, double phase);
/// One perturbation function (seed 003 eq. 3 with the factor of papers.md E9):
/// R = k Q^3 where Q >= 0, else 0 (k max(0, Q)^3). C^2 across Q = 0; its interval bound over a box
/// is k max(0, max_B Q)^3 from above for k > 0 and k max(0, min_B Q)^3 for k < 0 (item 31).
Expr perturbation(const Expr& perturbingQuadric, double factor);
/// Vyatkin perturbation (seed 003 eq. 2-3, with the signed factor of papers.md E9):
/// F' = F + sum_i k_i R_i, R_i = Q_i^3 where Q_i >= 0, else 0. The quadrics (any shapes, in
/// fact) must share the base's domain; k_i = 1 is eq. (3), k_i < 0 carves.
Shape perturb(const Shape& base, const std::vector<Shape>& perturbingQuadrics,
  const std::vector<double>& factors);

} // namespace ictk::frep
