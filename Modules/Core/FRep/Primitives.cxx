// SPDX-License-Identifier: BSD-3-Clause
// The FRep primitive library. Formulas were checked against the HyperFun library C sources
// (repository pmur002/hyperfun, src/hflibrary_lib/hf*.c); where those are wrong or fragile the
// comment says what differs and why. Every field is an Expr, so every evaluator supports it.
#include "FRep/Primitives.h"
#include "FRep/Operations.h"
#include "FRep/ParameterChecks.h"
#include "FRep/Vector.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace ictk::frep
{

namespace
{
constexpr double pi = 3.14159265358979323846;

// --- parameter checks: every message names the primitive and the parameter ----------------------

using detail::fail;
using detail::requireFinite;
using detail::requirePositive;
using detail::show;

std::string indexed(const char* name, std::size_t i)
{
  return std::string(name) + "[" + std::to_string(i) + "]";
}

void requireSameLength(
  const char* primitive, const char* nameA, std::size_t a, const char* nameB, std::size_t b)
{
  if (a != b)
  {
    fail(primitive,
      std::string(nameA) + " and " + nameB + " must have the same length (got " +
        std::to_string(a) + " and " + std::to_string(b) + ")");
  }
}

void requireNonEmpty(const char* primitive, const char* name, std::size_t n)
{
  if (n == 0)
  {
    fail(primitive, std::string(name) + " must not be empty");
  }
}

// --- small vector helpers (build-time doubles and field-time Exprs) -----------------------------

// FRep/Vector.h for doubles (named here: the Expr overloads below would hide them).
using frep::cross;
using frep::dot;
using frep::scale;
using frep::sub;

struct EVec
{
  Expr x, y, z;
};

/// p - c as Exprs.
EVec fromPoint(const Vec3& c)
{
  return { Expr::x() - c[0], Expr::y() - c[1], Expr::z() - c[2] };
}

Expr dot(const EVec& a, const Vec3& b)
{
  return a.x * b[0] + a.y * b[1] + a.z * b[2];
}

/// p - c for a point given by expressions (constants fold to fromPoint(Vec3)'s nodes).
EVec fromPoint(const std::array<Expr, 3>& c)
{
  return { Expr::x() - c[0], Expr::y() - c[1], Expr::z() - c[2] };
}

Expr dot(const EVec& a, const EVec& b)
{
  return a.x * b.x + a.y * b.y + a.z * b.z;
}

Expr norm2(const EVec& a)
{
  return square(a.x) + square(a.y) + square(a.z);
}

/// |a x b|^2 for a field vector and a constant one: a sum of squares, so it never goes negative
/// by rounding (unlike |a|^2 |b|^2 - (a.b)^2, which cancels badly far from the skeleton).
Expr crossNorm2(const EVec& a, const Vec3& b)
{
  return square(a.y * b[2] - a.z * b[1]) + square(a.z * b[0] - a.x * b[2]) +
    square(a.x * b[1] - a.y * b[0]);
}

Expr crossNorm2(const EVec& a, const EVec& b)
{
  return square(a.y * b.z - a.z * b.y) + square(a.z * b.x - a.x * b.z) +
    square(a.x * b.y - a.y * b.x);
}

/// Sum as a balanced tree, so that a model with thousands of skeletons stays shallow (the
/// reference evaluator recurses).
Expr balancedSum(std::vector<Expr> terms)
{
  if (terms.empty())
  {
    return Expr(0.0);
  }
  while (terms.size() > 1)
  {
    std::vector<Expr> next;
    next.reserve((terms.size() + 1) / 2);
    for (std::size_t i = 0; i + 1 < terms.size(); i += 2)
    {
      next.push_back(terms[i] + terms[i + 1]);
    }
    if (terms.size() % 2 == 1)
    {
      next.push_back(terms.back());
    }
    terms = std::move(next);
  }
  return terms.front();
}

/// The axial offset w and the two cross-section offsets (u, v), in x, y, z order, of a primitive
/// aligned with `axis`; this is the ordering of hfEllCylX/Y/Z and hfEllConeX/Y/Z (e.g. Y: u = x,
/// v = z).
struct AxisFrame
{
  Expr w, u, v;
};

AxisFrame axisFrame(const char* primitive, Axis axis, const Vec3& c)
{
  const EVec d = fromPoint(c);
  switch (axis)
  {
    case Axis::X:
      return { d.x, d.y, d.z };
    case Axis::Y:
      return { d.y, d.x, d.z };
    case Axis::Z:
      return { d.z, d.x, d.y };
    default:
      fail(primitive, "axis must be X, Y or Z (got " + std::string(axisName(axis)) + ")");
  }
}

/// Rodrigues' rotation matrix by `radians` about the unit vector k.
std::array<Vec3, 3> rotationMatrix(const Vec3& k, double radians)
{
  const double c = std::cos(radians);
  const double s = std::sin(radians);
  const double t = 1.0 - c;
  return { Vec3{ c + k[0] * k[0] * t, k[0] * k[1] * t - k[2] * s, k[0] * k[2] * t + k[1] * s },
    Vec3{ k[1] * k[0] * t + k[2] * s, c + k[1] * k[1] * t, k[1] * k[2] * t - k[0] * s },
    Vec3{ k[2] * k[0] * t - k[1] * s, k[2] * k[1] * t + k[0] * s, c + k[2] * k[2] * t } };
}

// --- Cauchy-kernel skeleton fields ---------------------------------------------------------------
// h(r) = 1 / (1 + s^2 r^2)^2 (thesis_ch2_3.md 1.7; McCormack & Sherstyuk 1998). The checks are
// shared by the Shape builders, which pass their own name so that messages name the caller.

Expr pointField(const char* primitive, const std::string& what, const Vec3& c, double s)
{
  requireFinite(primitive, what, c);
  requirePositive(primitive, "kernel width s of " + what, s);
  return 1.0 / square(1.0 + (s * s) * norm2(fromPoint(c)));
}

// Segment from b to e, length l, unit direction a; d = p - b, x = d.a. With the skeleton
// parameter u in [0, l] and P^2 = 1 + s^2 |d x a|^2 (|d x a| is the distance to the segment's
// line; hfConvLine's p^2), the integral is
//   int_{-x}^{l-x} du / (P^2 + s^2 u^2)^2
//     = [u / (2 P^2 (P^2 + s^2 u^2)) + atan(s u / P) / (2 s P^3)]_{-x}^{l-x},
// with P^2 + s^2 x^2 = 1 + s^2 |p - b|^2 and P^2 + s^2 (l - x)^2 = 1 + s^2 |p - e|^2. This is
// hfConvLine.c's expression; ICTK takes |d x a|^2 instead of |d|^2 - x^2 so that P^2 cannot round
// below 1. Every denominator is >= 1, so the field has no singular point. Substituting s u, it is
// 1/s times the kernel's integral in the dimensionless s x, s^2 |d x a|^2 and s l, one opcode
// (Opcode::CauchySegment) whose interval bound over a box is tight: written out, x, l - x and P
// each occur in several terms of opposite trends, and intervals over a box many times the
// kernel's width bound it by orders of magnitude more than its range, so a sum of segments far
// away (a stand-in, Skin/StandIn.h) could not be shown negative there.
Expr segmentField(
  const char* primitive, const std::string& what, const Vec3& b, const Vec3& e, double s)
{
  requireFinite(primitive, "start of " + what, b);
  requireFinite(primitive, "end of " + what, e);
  requirePositive(primitive, "kernel width s of " + what, s);
  const Vec3 axis = sub(e, b);
  if (!(std::sqrt(dot(axis, axis)) > 0))
  {
    fail(primitive, what + " has zero length (its two ends coincide)");
  }
  // Constant leaves fold every step that depends on no coordinate, in the same double operations
  // as the evaluators' (so a tape of parameters bound to these values gives the same bits).
  return cauchySegmentField(
    { Expr(b[0]), Expr(b[1]), Expr(b[2]) }, { Expr(e[0]), Expr(e[1]), Expr(e[2]) }, Expr(s));
}

// Arc of radius r, opening theta, in the local frame: centered at the origin in the plane z = 0,
// from angle 0 to theta. With the point at cylindrical (rho, psi, z), |p - q(phi)|^2 =
// r^2 + |p|^2 - 2 r rho cos(phi - psi), so the arc-length integral is
//   r int_0^theta dphi / (B - A cos(phi - psi))^2,  B = 1 + s^2 (r^2 + |p|^2),  A = 2 r s^2 rho.
// B - A = 1 + s^2 ((r - rho)^2 + z^2) >= 1, so with D^2 = B^2 - A^2 = (B - A)(B + A):
//   int dphi / (B - A cos phi)^2
//     = A sin phi / (D^2 (B - A cos phi)) + (B / D^2) int dphi / (B - A cos phi),
//   int dphi / (B - A cos phi) = (phi + 2 atan(A sin phi / (B + D - A cos phi))) / D.
// The last form is the usual 2/D atan(sqrt((B+A)/(B-A)) tan(phi/2)) made continuous in phi (no
// tan(phi/2) pole at phi = pi), so no split at 180 degrees is needed. Substituting phi - psi,
// A sin and A cos at both ends are polynomials in the local x, y, and the phi term integrates to
// theta: no atan2 and no division by x. Every denominator is >= 1.
//
// hfConvArc.c differs in three ways, which ICTK does not copy: it integrates over the angle, not
// over arc length (its value is this field / r; checked numerically against quadrature); it uses
// PI = 3.141592 for the degree conversion; and it adds EPS to the rotation angle and axis and
// divides by the local x ("avoid error"), whereas the form above is regular everywhere.
Expr arcField(const char* primitive, const std::string& what, const Vec3& center, double r,
  double thetaDegrees, const Vec3& axis, double angleDegrees, double s)
{
  requireFinite(primitive, "center of " + what, center);
  requirePositive(primitive, "radius of " + what, r);
  requireFinite(primitive, "theta of " + what, thetaDegrees);
  if (!(thetaDegrees > 0 && thetaDegrees <= 360))
  {
    fail(primitive,
      "theta of " + what + " must lie in (0, 360] degrees (got " + show(thetaDegrees) + ")");
  }
  requireFinite(primitive, "axis of " + what, axis);
  requireFinite(primitive, "angle of " + what, angleDegrees);
  requirePositive(primitive, "kernel width s of " + what, s);
  const double axisLength = std::sqrt(dot(axis, axis));
  if (!(axisLength > 0) && angleDegrees != 0)
  {
    fail(primitive, "axis of " + what + " is zero but its rotation angle is " + show(angleDegrees));
  }

  // The local frame: p_local = R(-angle) (p - center), as hfConvArc rotates the point.
  EVec local = fromPoint(center);
  if (angleDegrees != 0)
  {
    const auto m = rotationMatrix(scale(axis, 1.0 / axisLength), -angleDegrees * pi / 180.0);
    const EVec d = local;
    local = { dot(d, m[0]), dot(d, m[1]), dot(d, m[2]) };
  }
  const Expr& x = local.x;
  const Expr& y = local.y;
  const Expr& z = local.z;

  const double theta = thetaDegrees * pi / 180.0;
  // Exact end point for the full ring, so that it is symmetric to the last bit.
  const double cosTheta = thetaDegrees == 360 ? 1.0 : std::cos(theta);
  const double sinTheta = thetaDegrees == 360 ? 0.0 : std::sin(theta);
  const double s2 = s * s;
  const double a = 2.0 * r * s2;

  const Expr rho = sqrt(square(x) + square(y));
  const Expr z2 = square(z);
  const Expr B = 1.0 + s2 * (r * r + square(x) + square(y) + z2);
  const Expr D2 = (1.0 + s2 * (square(r - rho) + z2)) * (1.0 + s2 * (square(r + rho) + z2));
  const Expr D = sqrt(D2);
  // A sin(phi - psi) and B - A cos(phi - psi) at phi = theta (end) and phi = 0 (start); the
  // latter is 1 + s^2 |p - q(phi)|^2, written as such so that it cannot cancel.
  const Expr sinEnd = a * (x * sinTheta - y * cosTheta);
  const Expr denEnd = 1.0 + s2 * (square(x - r * cosTheta) + square(y - r * sinTheta) + z2);
  const Expr sinStart = -a * y;
  const Expr denStart = 1.0 + s2 * (square(x - r) + square(y) + z2);
  const Expr rational = (sinEnd / denEnd - sinStart / denStart) / D2;
  const Expr angular = B / (D2 * D) *
    (theta + 2.0 * atan(sinEnd / (denEnd + D)) - 2.0 * atan(sinStart / (denStart + D)));
  return r * (rational + angular);
}

// Triangle: the closed form of hfConvTriangle.c (McCormack & Sherstyuk 1998), in a frame built
// on the longest edge a1a2 so that the foot b of the altitude from a3 lies on it: u along a1->a2,
// v along b->a3 (h = |a3 - b|), n normal; a1 is at u = -a1l, a2 at u = a2l. With g = v - h,
// k = u h - a1l g, m = a2l g + u h, C^2 = 1/s^2 + v^2 + n^2, q = 1/s^2 + n^2,
//   I = [k (atan(n3/A) + atan(n4/A)) / A + m (atan(n5/B) + atan(n6/B)) / B
//        + v (atan(n1/C) + atan(n2/C)) / C] / (2 q s^4),
// n1 = a1l + u, n2 = a2l - u, n3 = a1l n1 + v h, n4 = -a1l u - g h, n5 = -a2l n2 - v h,
// n6 = -a2l u + g h, and A^2 = |a3 - a1|^2 (1/s^2 + dist^2(p, line a1a3)), B^2 likewise for
// a2a3 (identities checked numerically; written as sums of squares so they cannot cancel).
//
// hfConvTriangle.c line "f += (arc1 + arc2 + arc3)/(2.0*q*S[n]);" divides by s instead of s^4:
// its value is s^3 times the area integral (checked against 2D quadrature for s = 0.5, 1, 2), so
// it is the convolution only for s = 1. ICTK returns the integral. hfConvTriangle also divides by
// |a2 - b|, which is 0 for a right angle at a2; the unit vector along a1a2 used here is not.
Expr triangleField(
  const char* primitive, const std::string& what, const std::array<Vec3, 3>& t, double s)
{
  for (int i = 0; i < 3; ++i)
  {
    requireFinite(primitive, "vertex " + std::to_string(i) + " of " + what, t[i]);
  }
  requirePositive(primitive, "kernel width s of " + what, s);
  // Rotate the vertices so that edge (a1, a2) is the longest.
  int longest = 0;
  double longestLength2 = -1;
  for (int i = 0; i < 3; ++i)
  {
    const Vec3 e = sub(t[(i + 1) % 3], t[i]);
    if (dot(e, e) > longestLength2)
    {
      longestLength2 = dot(e, e);
      longest = i;
    }
  }
  const Vec3& a1 = t[longest];
  const Vec3& a2 = t[(longest + 1) % 3];
  const Vec3& a3 = t[(longest + 2) % 3];
  const Vec3 edge = sub(a2, a1);
  const double edgeLength = std::sqrt(longestLength2);
  const Vec3 normal = cross(edge, sub(a3, a1));
  const double twiceArea = std::sqrt(dot(normal, normal));
  if (!(edgeLength > 0) || !(twiceArea > 1e-14 * longestLength2))
  {
    fail(primitive, what + " is degenerate (zero area)");
  }
  const Vec3 uHat = scale(edge, 1.0 / edgeLength);
  const double a1l = dot(sub(a3, a1), uHat);
  const double a2l = edgeLength - a1l;
  const Vec3 foot = { a1[0] + a1l * uHat[0], a1[1] + a1l * uHat[1], a1[2] + a1l * uHat[2] };
  const Vec3 altitude = sub(a3, foot);
  const double h = std::sqrt(dot(altitude, altitude));
  const Vec3 vHat = scale(altitude, 1.0 / h);
  const Vec3 nHat = scale(normal, 1.0 / twiceArea);
  const double inverseS2 = 1.0 / (s * s);

  const EVec d = fromPoint(foot);
  const Expr u = dot(d, uHat);
  const Expr v = dot(d, vHat);
  const Expr n = dot(d, nHat);
  const Expr n2 = square(n);
  const Expr q = inverseS2 + n2;
  const Expr C = sqrt(inverseS2 + square(v) + n2);
  const Vec3 e13 = sub(a3, a1);
  const Vec3 e23 = sub(a3, a2);
  const Expr A = sqrt(dot(e13, e13) * inverseS2 + crossNorm2(fromPoint(a1), e13));
  const Expr B = sqrt(dot(e23, e23) * inverseS2 + crossNorm2(fromPoint(a2), e23));
  const Expr g = v - h;
  const Expr k = u * h - a1l * g;
  const Expr m = a2l * g + u * h;
  const Expr n1 = a1l + u;
  const Expr nn2 = a2l - u;
  const Expr n3 = a1l * n1 + v * h;
  const Expr n4 = -a1l * u - g * h;
  const Expr n5 = -a2l * nn2 - v * h;
  const Expr n6 = -a2l * u + g * h;
  const Expr sum = k * (atan(n3 / A) + atan(n4 / A)) / A + m * (atan(n5 / B) + atan(n6 / B)) / B +
    v * (atan(n1 / C) + atan(nn2 / C)) / C;
  return sum / ((2.0 * s * s * s * s) * q);
}

Shape thresholded(std::vector<Expr> fields, double threshold, const char* label)
{
  return Shape(balancedSum(std::move(fields)) - threshold, Domain::XYZ, label);
}

} // namespace

// --- 1D and 2D ------------------------------------------------------------------------------

Shape interval(double a, double b)
{
  requireFinite("interval", "a", a);
  requireFinite("interval", "b", b);
  if (!(a < b))
  {
    fail("interval", "a must be less than b (got a = " + show(a) + ", b = " + show(b) + ")");
  }
  const Expr x = Expr::x();
  return Shape((x - a) * (b - x), Domain::X, "interval");
}

Shape timeInterval(double t0, double t1)
{
  requireFinite("timeInterval", "t0", t0);
  requireFinite("timeInterval", "t1", t1);
  if (!(t0 < t1))
  {
    fail(
      "timeInterval", "t0 must be less than t1 (got t0 = " + show(t0) + ", t1 = " + show(t1) + ")");
  }
  const Expr t = Expr::t();
  return Shape((t - t0) * (t1 - t), Domain::T, "timeInterval");
}

Shape circle(const Vec2& center, double r)
{
  requireFinite("circle", "center", center);
  requirePositive("circle", "radius r", r);
  return Shape(
    r * r - square(Expr::x() - center[0]) - square(Expr::y() - center[1]), Domain::XY, "circle");
}

Shape ellipse(const Vec2& center, double a, double b)
{
  requireFinite("ellipse", "center", center);
  requirePositive("ellipse", "half-axis a", a);
  requirePositive("ellipse", "half-axis b", b);
  return Shape(1.0 - square((Expr::x() - center[0]) / a) - square((Expr::y() - center[1]) / b),
    Domain::XY, "ellipse");
}

Shape rectangle(const Vec2& vertex, double dx, double dy)
{
  requireFinite("rectangle", "vertex", vertex);
  requirePositive("rectangle", "side dx", dx);
  requirePositive("rectangle", "side dy", dy);
  const Expr x = Expr::x();
  const Expr y = Expr::y();
  const Expr slabX = (x - vertex[0]) * ((vertex[0] + dx) - x);
  const Expr slabY = (y - vertex[1]) * ((vertex[1] + dy) - y);
  return Shape(min(slabX, slabY), Domain::XY, "rectangle");
}

// --- 3D ------------------------------------------------------------------------------------------

// hfSphere.c: R^2 - |p - c|^2.
Shape sphere(const Vec3& center, double r)
{
  requireFinite("sphere", "center", center);
  requirePositive("sphere", "radius r", r);
  return Shape(r * r - norm2(fromPoint(center)), Domain::XYZ, "sphere");
}

// hfEllipsoid.c: 1 - sum ((p_i - c_i) / axis_i)^2.
Shape ellipsoid(const Vec3& center, double a, double b, double c)
{
  requireFinite("ellipsoid", "center", center);
  requirePositive("ellipsoid", "half-axis a", a);
  requirePositive("ellipsoid", "half-axis b", b);
  requirePositive("ellipsoid", "half-axis c", c);
  const EVec d = fromPoint(center);
  return Shape(1.0 - square(d.x / a) - square(d.y / b) - square(d.z / c), Domain::XYZ, "ellipsoid");
}

namespace
{
struct Slabs
{
  Expr x, y, z;
};

Slabs blockSlabs(const char* primitive, const Vec3& vertex, double dx, double dy, double dz)
{
  requireFinite(primitive, "vertex", vertex);
  // hfBlock.c accepts zero sides (it rejects only negative ones); a zero side is an empty solid
  // whose field is <= 0 everywhere, which is never what a model means, so ICTK rejects it.
  requirePositive(primitive, "side dx", dx);
  requirePositive(primitive, "side dy", dy);
  requirePositive(primitive, "side dz", dz);
  const Expr x = Expr::x();
  const Expr y = Expr::y();
  const Expr z = Expr::z();
  return { (x - vertex[0]) * ((vertex[0] + dx) - x), (y - vertex[1]) * ((vertex[1] + dy) - y),
    (z - vertex[2]) * ((vertex[2] + dz) - z) };
}

} // namespace

// hfBlock.c with ALPHA = 1: the min of the three slab functions.
Shape block(const Vec3& vertex, double dx, double dy, double dz)
{
  const Slabs s = blockSlabs("block", vertex, dx, dy, dz);
  return Shape(min(min(s.x, s.y), s.z), Domain::XYZ, "block");
}

Shape blockRFunction(const Vec3& vertex, double dx, double dy, double dz, double alpha)
{
  const Slabs s = blockSlabs("blockRFunction", vertex, dx, dy, dz);
  requireFinite("blockRFunction", "alpha", alpha);
  if (!(alpha > -1.0 && alpha <= 1.0))
  {
    fail("blockRFunction", "alpha must lie in (-1, 1] (got " + show(alpha) + ")");
  }
  if (alpha == 1.0)
  {
    // As hfBlock.c: alpha = 1 is exactly the min.
    return Shape(min(min(s.x, s.y), s.z), Domain::XYZ, "blockRFunction");
  }
  return Shape(hyperFunIntersection(hyperFunIntersection(s.x, s.y, alpha), s.z, alpha), Domain::XYZ,
    "blockRFunction");
}

// hfCylinderX/Y/Z.c: R^2 - u^2 - v^2.
Shape cylinder(Axis axis, const Vec3& center, double r)
{
  requireFinite("cylinder", "center", center);
  requirePositive("cylinder", "radius r", r);
  const AxisFrame f = axisFrame("cylinder", axis, center);
  return Shape(r * r - square(f.u) - square(f.v), Domain::XYZ, "cylinder");
}

// hfEllCylX/Y/Z.c: 1 - (u/a)^2 - (v/b)^2. (hfEllCylX's header says "half-axes along x,z"; its
// code, like the Y and Z versions, puts a on the first and b on the second remaining axis.)
Shape ellipticCylinder(Axis axis, const Vec3& center, double a, double b)
{
  requireFinite("ellipticCylinder", "center", center);
  requirePositive("ellipticCylinder", "half-axis a", a);
  requirePositive("ellipticCylinder", "half-axis b", b);
  const AxisFrame f = axisFrame("ellipticCylinder", axis, center);
  return Shape(1.0 - square(f.u / a) - square(f.v / b), Domain::XYZ, "ellipticCylinder");
}

// hfConeX/Y/Z.c: w^2 - (u/R)^2 - (v/R)^2, both nappes.
Shape cone(Axis axis, const Vec3& apex, double r)
{
  requireFinite("cone", "apex", apex);
  requirePositive("cone", "radius r", r);
  const AxisFrame f = axisFrame("cone", axis, apex);
  return Shape(square(f.w) - square(f.u / r) - square(f.v / r), Domain::XYZ, "cone");
}

// hfEllConeX/Y/Z.c: w^2 - (u/a)^2 - (v/b)^2.
Shape ellipticCone(Axis axis, const Vec3& apex, double a, double b)
{
  requireFinite("ellipticCone", "apex", apex);
  requirePositive("ellipticCone", "half-axis a", a);
  requirePositive("ellipticCone", "half-axis b", b);
  const AxisFrame f = axisFrame("ellipticCone", axis, apex);
  return Shape(square(f.w) - square(f.u / a) - square(f.v / b), Domain::XYZ, "ellipticCone");
}

// hfTorusX/Y/Z.c: r0^2 - |p - c|^2 - R^2 + 2 R sqrt(u^2 + v^2), i.e. r0^2 minus the squared
// distance to the core circle. The sqrt argument is a sum of squares.
Shape torus(Axis axis, const Vec3& center, double R, double r)
{
  requireFinite("torus", "center", center);
  requirePositive("torus", "radius of revolution R", R);
  requirePositive("torus", "tube radius r", r);
  const AxisFrame f = axisFrame("torus", axis, center);
  const Expr u2 = square(f.u);
  const Expr v2 = square(f.v);
  return Shape(
    r * r - square(f.w) - u2 - v2 - R * R + (2.0 * R) * sqrt(u2 + v2), Domain::XYZ, "torus");
}

// hfSuperell.c: 1 - (|x'|^(2/s2) + |y'|^(2/s2))^(s2/s1) - |z'|^(2/s1).
Shape superellipsoid(const Vec3& center, double a, double b, double c, double s1, double s2)
{
  requireFinite("superellipsoid", "center", center);
  requirePositive("superellipsoid", "half-axis a", a);
  requirePositive("superellipsoid", "half-axis b", b);
  requirePositive("superellipsoid", "half-axis c", c);
  requirePositive("superellipsoid", "shape exponent s1", s1);
  requirePositive("superellipsoid", "shape exponent s2", s2);
  const EVec d = fromPoint(center);
  const double p = 2.0 / s2;
  const Expr xy = pow(abs(d.x / a), p) + pow(abs(d.y / b), p);
  return Shape(1.0 - pow(xy, s2 / s1) - pow(abs(d.z / c), 2.0 / s1), Domain::XYZ, "superellipsoid");
}

Shape quadric(const std::array<double, 10>& k)
{
  static const char* names[] = { "A11", "A22", "A33", "A12", "A13", "A23", "A14", "A24", "A34",
    "A44" };
  bool allZero = true;
  for (std::size_t i = 0; i < k.size(); ++i)
  {
    requireFinite("quadric", std::string("coefficient ") + names[i], k[i]);
    allZero = allZero && k[i] == 0;
  }
  if (allZero)
  {
    fail("quadric", "all ten coefficients are zero (the field would vanish everywhere)");
  }
  // Completed squares: a squared term with its axis' linear term becomes A (x + b / 2A)^2 and the
  // constant takes -b^2 / 4A. Interval arithmetic then gives the exact range of each such term
  // over an interval (x^2 + b x as two terms would not: x appears twice), so the range of an
  // axis-aligned quadric over a box is exact (papers.md 5.B item 31's max_B F).
  const Expr axes[] = { Expr::x(), Expr::y(), Expr::z() };
  std::vector<Expr> terms;
  double constant = k[9];
  for (std::size_t i = 0; i < 3; ++i)
  {
    const double a = k[i];
    const double b = k[6 + i];
    const double shift = a != 0 ? b / (2 * a) : 0.0;
    if (a != 0 && std::isfinite(a * shift * shift))
    {
      terms.push_back(a * square(axes[i] + shift));
      constant -= a * shift * shift;
    }
    else
    {
      // No square, or one so flat that completing it overflows: the monomials as they are.
      if (a != 0)
      {
        terms.push_back(a * square(axes[i]));
      }
      if (b != 0)
      {
        terms.push_back(b * axes[i]);
      }
    }
  }
  const Expr crossTerms[] = { axes[0] * axes[1], axes[0] * axes[2], axes[1] * axes[2] };
  for (std::size_t i = 0; i < 3; ++i)
  {
    if (k[3 + i] != 0)
    {
      terms.push_back(k[3 + i] * crossTerms[i]);
    }
  }
  if (constant != 0)
  {
    terms.push_back(Expr(constant));
  }
  return Shape(balancedSum(std::move(terms)), Domain::XYZ, "quadric");
}

Shape halfSpace(const Vec3& point, const Vec3& inwardNormal)
{
  requireFinite("halfSpace", "point", point);
  requireFinite("halfSpace", "inwardNormal", inwardNormal);
  const double length = std::sqrt(dot(inwardNormal, inwardNormal));
  if (!(length > 0))
  {
    fail("halfSpace", "inwardNormal must not be the zero vector");
  }
  return Shape(dot(fromPoint(point), scale(inwardNormal, 1.0 / length)), Domain::XYZ, "halfSpace");
}

// --- skeletal primitives
// ---------------------------------------------------------------------------

// hfBlobby.c: sum b_i exp(-a_i r_i^2) - T.
Shape blobby(const std::vector<Vec3>& centers, const std::vector<double>& a,
  const std::vector<double>& b, double threshold)
{
  requireNonEmpty("blobby", "centers", centers.size());
  requireSameLength("blobby", "centers", centers.size(), "a", a.size());
  requireSameLength("blobby", "centers", centers.size(), "b", b.size());
  requireFinite("blobby", "threshold", threshold);
  std::vector<Expr> terms;
  for (std::size_t i = 0; i < centers.size(); ++i)
  {
    requireFinite("blobby", indexed("centers", i), centers[i]);
    requirePositive("blobby", indexed("a", i), a[i]);
    requireFinite("blobby", indexed("b", i), b[i]);
    terms.push_back(b[i] * exp(-a[i] * norm2(fromPoint(centers[i]))));
  }
  return thresholded(std::move(terms), threshold, "blobby");
}

// hfMetaball.c (Nishimura): b (1 - 3 r^2/d^2) for r <= d/3, 1.5 b (1 - r/d)^2 for d/3 < r < d, else
// 0. The two pieces meet at r = d/3 with value 2b/3 and slope -2b/d, so the field is C^1. The test
// r <= d/3 is made on r^2 (no sqrt in the branch), and max(0, 1 - r/d) gives the zero tail.
Shape metaball(const std::vector<Vec3>& centers, const std::vector<double>& b,
  const std::vector<double>& d, double threshold)
{
  requireNonEmpty("metaball", "centers", centers.size());
  requireSameLength("metaball", "centers", centers.size(), "b", b.size());
  requireSameLength("metaball", "centers", centers.size(), "d", d.size());
  requireFinite("metaball", "threshold", threshold);
  std::vector<Expr> terms;
  for (std::size_t i = 0; i < centers.size(); ++i)
  {
    requireFinite("metaball", indexed("centers", i), centers[i]);
    requireFinite("metaball", indexed("b", i), b[i]);
    // hfMetaball.c skips balls with d <= 0 silently; ICTK rejects them.
    requirePositive("metaball", indexed("d", i), d[i]);
    const Expr r2 = norm2(fromPoint(centers[i]));
    const double d2 = d[i] * d[i];
    const Expr inner = b[i] * (1.0 - (3.0 / d2) * r2);
    const Expr outer = (1.5 * b[i]) * square(max(0.0, 1.0 - sqrt(r2) / d[i]));
    terms.push_back(select(d2 / 9.0 - r2, inner, outer));
  }
  return thresholded(std::move(terms), threshold, "metaball");
}

// hfSoft.c / papers.md L441 (Wyvill): g = 1 - 22/9 q + 17/9 q^2 - 4/9 q^3 with q = r^2/d^2, for
// r <= d. The polynomial factors as (1 - q)^2 (9 - 4q) / 9 (it has a double root at q = 1), so with
// m = max(0, 1 - q) it is m^2 (5 + 4m) / 9, which is also exactly 0 for r > d: no branch needed and
// the field is C^1 across r = d.
Shape softObject(const std::vector<Vec3>& centers, const std::vector<double>& d, double threshold)
{
  requireNonEmpty("softObject", "centers", centers.size());
  requireSameLength("softObject", "centers", centers.size(), "d", d.size());
  requireFinite("softObject", "threshold", threshold);
  std::vector<Expr> terms;
  for (std::size_t i = 0; i < centers.size(); ++i)
  {
    requireFinite("softObject", indexed("centers", i), centers[i]);
    requirePositive("softObject", indexed("d", i), d[i]);
    const Expr m = max(0.0, 1.0 - norm2(fromPoint(centers[i])) / (d[i] * d[i]));
    terms.push_back(square(m) * (5.0 + 4.0 * m) / 9.0);
  }
  return thresholded(std::move(terms), threshold, "softObject");
}

// --- convolution surfaces
// --------------------------------------------------------------------------

Expr cauchyPointField(const Vec3& point, double s)
{
  return pointField("cauchyPointField", "point", point, s);
}

Expr cauchySegmentField(const Vec3& begin, const Vec3& end, double s)
{
  return segmentField("cauchySegmentField", "segment", begin, end, s);
}

Expr cauchySegmentField(
  const std::array<Expr, 3>& begin, const std::array<Expr, 3>& end, const Expr& s)
{
  const EVec axis{ end[0] - begin[0], end[1] - begin[1], end[2] - begin[2] };
  const Expr l = sqrt(axis.x * axis.x + axis.y * axis.y + axis.z * axis.z);
  const Expr inverseLength = Expr(1.0) / l;
  const EVec a{ axis.x * inverseLength, axis.y * inverseLength, axis.z * inverseLength };
  const EVec d = fromPoint(begin);
  return Expr::make(Opcode::CauchySegment, s * dot(d, a), (s * s) * crossNorm2(d, a), s * l) / s;
}

Expr cauchyArcField(
  const Vec3& center, double radius, double theta, const Vec3& axis, double angle, double s)
{
  return arcField("cauchyArcField", "arc", center, radius, theta, axis, angle, s);
}

Expr cauchyTriangleField(const std::array<Vec3, 3>& triangle, double s)
{
  return triangleField("cauchyTriangleField", "triangle", triangle, s);
}

// hfConvPoint.c: sum 1/(1 + s^2 r^2)^2 - T.
Shape convolutionPoints(
  const std::vector<Vec3>& points, const std::vector<double>& s, double threshold)
{
  requireNonEmpty("convolutionPoints", "points", points.size());
  requireSameLength("convolutionPoints", "points", points.size(), "s", s.size());
  requireFinite("convolutionPoints", "threshold", threshold);
  std::vector<Expr> terms;
  for (std::size_t i = 0; i < points.size(); ++i)
  {
    terms.push_back(pointField("convolutionPoints", indexed("points", i), points[i], s[i]));
  }
  return thresholded(std::move(terms), threshold, "convolutionPoints");
}

Shape convolutionSegments(
  const std::vector<std::array<Vec3, 2>>& segments, const std::vector<double>& s, double threshold)
{
  requireNonEmpty("convolutionSegments", "segments", segments.size());
  requireSameLength("convolutionSegments", "segments", segments.size(), "s", s.size());
  requireFinite("convolutionSegments", "threshold", threshold);
  std::vector<Expr> terms;
  for (std::size_t i = 0; i < segments.size(); ++i)
  {
    terms.push_back(segmentField(
      "convolutionSegments", indexed("segments", i), segments[i][0], segments[i][1], s[i]));
  }
  return thresholded(std::move(terms), threshold, "convolutionSegments");
}

// hfconvliner.c: the width comes from the radius, the threshold from the last segment, and the
// running sum stops at 1. The per-segment field is the one of hfConvLine.
Shape convolutionSegmentsRadius(const std::vector<std::array<Vec3, 2>>& segments, double radius)
{
  const char* name = "convolutionSegmentsRadius";
  requireNonEmpty(name, "segments", segments.size());
  requirePositive(name, "radius R", radius);
  const double s = radius < 1.0 ? 1.0 / radius : 1.0;
  Expr sum;
  for (std::size_t i = 0; i < segments.size(); ++i)
  {
    const Expr field =
      segmentField(name, indexed("segments", i), segments[i][0], segments[i][1], s);
    sum = min(i == 0 ? field : sum + field, Expr(1.0));
  }
  // The last segment's field at distance R from its start (axial coordinate 0).
  const Vec3 axis = sub(segments.back()[1], segments.back()[0]);
  const double l = std::sqrt(dot(axis, axis));
  const double P2 = 1.0 + s * s * radius * radius;
  const double P = std::sqrt(P2);
  const double Q2 = 1.0 + s * s * (radius * radius + l * l);
  const double T = l / (2.0 * P2 * Q2) + std::atan(s * l / P) / (2.0 * s * P2 * P);
  return Shape(sum - T, Domain::XYZ, name);
}

Shape convolutionArcs(const std::vector<Vec3>& centers, const std::vector<double>& radii,
  const std::vector<double>& thetas, const std::vector<Vec3>& axes,
  const std::vector<double>& angles, const std::vector<double>& s, double threshold)
{
  const char* name = "convolutionArcs";
  requireNonEmpty(name, "centers", centers.size());
  requireSameLength(name, "centers", centers.size(), "radii", radii.size());
  requireSameLength(name, "centers", centers.size(), "thetas", thetas.size());
  requireSameLength(name, "centers", centers.size(), "axes", axes.size());
  requireSameLength(name, "centers", centers.size(), "angles", angles.size());
  requireSameLength(name, "centers", centers.size(), "s", s.size());
  requireFinite(name, "threshold", threshold);
  std::vector<Expr> terms;
  for (std::size_t i = 0; i < centers.size(); ++i)
  {
    terms.push_back(arcField(
      name, "arc " + std::to_string(i), centers[i], radii[i], thetas[i], axes[i], angles[i], s[i]));
  }
  return thresholded(std::move(terms), threshold, name);
}

Shape convolutionTriangles(
  const std::vector<std::array<Vec3, 3>>& triangles, const std::vector<double>& s, double threshold)
{
  requireNonEmpty("convolutionTriangles", "triangles", triangles.size());
  requireSameLength("convolutionTriangles", "triangles", triangles.size(), "s", s.size());
  requireFinite("convolutionTriangles", "threshold", threshold);
  std::vector<Expr> terms;
  for (std::size_t i = 0; i < triangles.size(); ++i)
  {
    terms.push_back(
      triangleField("convolutionTriangles", indexed("triangles", i), triangles[i], s[i]));
  }
  return thresholded(std::move(terms), threshold, "convolutionTriangles");
}

// hfConvCurve.c: the segment field summed over consecutive point pairs.
Shape convolutionCurve(const std::vector<Vec3>& polyline, double s, double threshold)
{
  if (polyline.size() < 2)
  {
    fail("convolutionCurve",
      "polyline needs at least 2 points (got " + std::to_string(polyline.size()) + ")");
  }
  requirePositive("convolutionCurve", "kernel width s", s);
  requireFinite("convolutionCurve", "threshold", threshold);
  std::vector<Expr> terms;
  for (std::size_t i = 0; i + 1 < polyline.size(); ++i)
  {
    terms.push_back(segmentField("convolutionCurve",
      "segment " + std::to_string(i) + " (polyline points " + std::to_string(i) + ", " +
        std::to_string(i + 1) + ")",
      polyline[i], polyline[i + 1], s));
  }
  return thresholded(std::move(terms), threshold, "convolutionCurve");
}

// hfConvMesh.c: the triangle field summed over indexed triangles.
Shape convolutionMesh(const std::vector<Vec3>& vertices,
  const std::vector<std::array<int, 3>>& triangles, double s, double threshold)
{
  requireNonEmpty("convolutionMesh", "vertices", vertices.size());
  requireNonEmpty("convolutionMesh", "triangles", triangles.size());
  requirePositive("convolutionMesh", "kernel width s", s);
  requireFinite("convolutionMesh", "threshold", threshold);
  std::vector<Expr> terms;
  for (std::size_t i = 0; i < triangles.size(); ++i)
  {
    std::array<Vec3, 3> corners;
    for (int j = 0; j < 3; ++j)
    {
      const int index = triangles[i][j];
      if (index < 0 || static_cast<std::size_t>(index) >= vertices.size())
      {
        fail("convolutionMesh",
          indexed("triangles", i) + " has vertex index " + std::to_string(index) + " outside [0, " +
            std::to_string(vertices.size()) + ")");
      }
      corners[j] = vertices[index];
    }
    terms.push_back(triangleField("convolutionMesh", indexed("triangles", i), corners, s));
  }
  return thresholded(std::move(terms), threshold, "convolutionMesh");
}

// --- noise and perturbation ---------------------------------------------------------------------

// hfNoiseG.c (Gardner series, as written by Pasko): with A = amplitude, w = frequency,
//   Ser_x = A sin(w x) + (A/1.17) sin(w x / 1.35 + phase sin(w z)),
//   Ser_y = A sin(w y) + (A/1.17) sin(w y / 1.35 + phase sin(w x)),
//   Ser_z = A sin(w z) + (A/1.17) sin(w z / 1.35 + phase sin(w y)),
// noise = Ser_x Ser_y Ser_z.
Expr gardnerNoise(double amplitude, double frequency, double phase)
{
  requireFinite("gardnerNoise", "amplitude", amplitude);
  requireFinite("gardnerNoise", "frequency", frequency);
  requireFinite("gardnerNoise", "phase", phase);
  const Expr wx = frequency * Expr::x();
  const Expr wy = frequency * Expr::y();
  const Expr wz = frequency * Expr::z();
  const Expr sx = sin(wx);
  const Expr sy = sin(wy);
  const Expr sz = sin(wz);
  const double secondary = amplitude / 1.17;
  const Expr serX = amplitude * sx + secondary * sin(wx / 1.35 + phase * sz);
  const Expr serY = amplitude * sy + secondary * sin(wy / 1.35 + phase * sx);
  const Expr serZ = amplitude * sz + secondary * sin(wz / 1.35 + phase * sy);
  return serX * serY * serZ;
}

// seed 003 eq. (3) with papers.md E9's signed factor. The cube of max(0, Q) is Q^3 where Q >= 0
// and 0 elsewhere, and is C^2 across Q = 0. Under interval arithmetic max(0, Q) is
// [max(0, lo), max(0, hi)] and the cube is monotone there, so the bound of a perturbed field over a
// box is max_B F + sum over k > 0 of k max(0, max_B Q)^3 + sum over k < 0 of k max(0, min_B Q)^3:
// papers.md 2.2's voxel bound (item 31), which the renderer's culling therefore uses.
Expr perturbation(const Expr& perturbingQuadric, double factor)
{
  requireFinite("perturbation", "factor", factor);
  return factor * pow(max(0.0, perturbingQuadric), 3.0);
}

// seed 003 eq. (2): F + sum R_i.
Shape perturb(const Shape& base, const std::vector<Shape>& perturbingQuadrics,
  const std::vector<double>& factors)
{
  requireSameLength(
    "perturb", "perturbingQuadrics", perturbingQuadrics.size(), "factors", factors.size());
  if (perturbingQuadrics.empty())
  {
    return base.withLabel("perturb");
  }
  std::vector<Expr> terms;
  for (std::size_t i = 0; i < perturbingQuadrics.size(); ++i)
  {
    requireSameDomain("perturb", base, perturbingQuadrics[i]);
    requireFinite("perturb", indexed("factors", i), factors[i]);
    terms.push_back(perturbation(perturbingQuadrics[i].function(), factors[i]));
  }
  // Where every Q_i < 0 each term is (+-)0, so F' == F bit for bit (papers.md 5.B item 27).
  return Shape(base.function() + balancedSum(std::move(terms)), base.domain(), "perturb");
}

} // namespace ictk::frep
