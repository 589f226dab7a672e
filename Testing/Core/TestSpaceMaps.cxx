// SPDX-License-Identifier: BSD-3-Clause
// Tests of the FRep operation library's space mappings (shift, scale, rotate, affine maps, twist,
// taper, bend, stretch, the cubic and exponential space maps) against HyperFun's definitions;
// the shared operands are in OperationsTesting.h.
#include "OperationsTesting.h"

#include <cmath>
#include <functional>
#include <string>

using namespace ictk::frep;
using namespace operationstest;

namespace
{
const double pi = std::acos(-1.0);

// A non-symmetric XYZ test field, so that mapping errors (wrong sign, wrong axis) show.
double testField(double x, double y, double z)
{
  return 1.0 - (x - 0.3) * (x - 0.3) - 2.0 * (y + 0.2) * (y + 0.2) - 0.5 * z * z + 0.7 * x * y -
    0.4 * z;
}
} // namespace

// --- space mappings ----------------------------------------------------------------------------

TEST(Operations, ShiftAndScale)
{
  // hfShift3D: f'(p) = f(p - v). The unit sphere shifted by (1, 2, 3) has its centre (value 1)
  // there.
  const Shape s = shift(unitSphere(), { 1, 2, 3 });
  EXPECT_NEAR(eval(s, 1, 2, 3), 1.0, tol);
  EXPECT_NEAR(eval(s, 2, 2, 3), 0.0, tol);
  // hfScale3D: f'(p) = f(x/sx, y/sy, z/sz). Scaling by (2, 1, 1): (2, 0, 0) -> (1, 0, 0), boundary.
  const Shape sc = scale(unitSphere(), { 2, 1, 1 });
  EXPECT_NEAR(eval(sc, 2, 0, 0), 0.0, tol);
  EXPECT_NEAR(eval(sc, 0, 1, 0), 0.0, tol);
  const Shape f = testShape();
  const Shape fs = shift(f, { 0.5, -1.5, 2.0 });
  const Shape fc = scale(f, { 2.0, -0.5, 3.0 });
  for (double x : { -1.0, 0.2, 1.7 })
  {
    for (double y : { -0.8, 0.0, 0.9 })
    {
      for (double z : { -1.1, 0.4 })
      {
        EXPECT_NEAR(eval(fs, x, y, z), testField(x - 0.5, y + 1.5, z - 2.0), tol);
        EXPECT_NEAR(eval(fc, x, y, z), testField(x / 2.0, y / -0.5, z / 3.0), tol);
      }
    }
  }
  // A 2D disk can be shifted within its plane, but not along z.
  EXPECT_NEAR(eval(shift(disk(0, 0, 1), { 1, 0, 0 }), 1, 0), 1.0, tol);
  expectThrowMentioning<DomainError>([] { shift(disk(0, 0, 1), { 0, 0, 1 }); }, { "shift", "z" });
  expectThrowMentioning<DomainError>([] { scale(disk(0, 0, 1), { 1, 1, 2 }); }, { "scale", "z" });
  expectThrowMentioning<std::invalid_argument>(
    [] {
      scale(unitSphere(), { 1, 0, 1 });
    },
    { "scale", "s" });
  expectThrowMentioning<std::invalid_argument>(
    [] {
      shift(unitSphere(), { NAN, 0, 1 });
    },
    { "shift", "v" });
}

TEST(Operations, RotateFollowsHyperFunConvention)
{
  // hfRotate3DZ inverse-maps x' = x cos + y sin, y' = -x sin + y cos: the half-space x >= 1 turned
  // by +90 degrees about z becomes y >= 1. At (0, 2, 0): x' = 0 + 2 * 1 = 2, f = 2 - 1 = 1.
  const Shape hx(Expr::x() - 1.0, Domain::XYZ, "x>=1");
  const Shape hy(Expr::y() - 1.0, Domain::XYZ, "y>=1");
  const Shape hz(Expr::z() - 1.0, Domain::XYZ, "z>=1");
  EXPECT_NEAR(eval(rotate(hx, Axis::Z, pi / 2), 0, 2, 0), 1.0, tol);
  EXPECT_NEAR(eval(rotate(hx, Axis::Z, pi / 2), 2, 0, 0), -1.0, tol);
  // About x (y -> z): y >= 1 becomes z >= 1; about y (z -> x): z >= 1 becomes x >= 1.
  EXPECT_NEAR(eval(rotate(hy, Axis::X, pi / 2), 0, 0, 2), 1.0, tol);
  EXPECT_NEAR(eval(rotate(hz, Axis::Y, pi / 2), 2, 0, 0), 1.0, tol);
  // General angle against the HyperFun formulas.
  const double th = 0.7, c = std::cos(th), s = std::sin(th);
  const Shape f = testShape();
  for (double x : { -1.0, 0.5 })
  {
    for (double y : { -0.3, 1.2 })
    {
      for (double z : { -0.9, 0.6 })
      {
        EXPECT_NEAR(
          eval(rotate(f, Axis::Z, th), x, y, z), testField(x * c + y * s, -x * s + y * c, z), tol);
        EXPECT_NEAR(
          eval(rotate(f, Axis::X, th), x, y, z), testField(x, y * c + z * s, -y * s + z * c), tol);
        EXPECT_NEAR(
          eval(rotate(f, Axis::Y, th), x, y, z), testField(-z * s + x * c, y, z * c + x * s), tol);
      }
    }
  }
  // A disk rotates in its own plane; about x it would need z.
  EXPECT_NEAR(eval(rotate(disk(2, 0, 1), Axis::Z, pi / 2), 0, 2), 1.0, tol);
  expectThrowMentioning<DomainError>(
    [] { rotate(disk(0, 0, 1), Axis::X, 1.0); }, { "rotate", "z" });
  expectThrowMentioning<std::invalid_argument>(
    [] { rotate(unitSphere(), Axis::T, 1.0); }, { "rotate", "axis" });
  expectThrowMentioning<std::invalid_argument>(
    [] { rotate(unitSphere(), Axis::Z, INFINITY); }, { "rotate", "angleRadians" });
}

TEST(Operations, AffineInverseMapsTheQueryPoint)
{
  // p' = A p + b; the mapped shape at A p + b equals the original at p.
  const std::array<double, 12> m = { 2.0, 0.5, 0.0, 1.0, //
    -0.3, 1.5, 0.2, -2.0,                                //
    0.1, 0.0, 0.8, 0.5 };
  const Shape f = testShape();
  const Shape g = affine(f, m);
  for (double x : { -1.0, 0.25, 1.5 })
  {
    for (double y : { -0.5, 0.75 })
    {
      for (double z : { -1.2, 0.0, 0.9 })
      {
        const double px = m[0] * x + m[1] * y + m[2] * z + m[3];
        const double py = m[4] * x + m[5] * y + m[6] * z + m[7];
        const double pz = m[8] * x + m[9] * y + m[10] * z + m[11];
        EXPECT_NEAR(eval(g, px, py, pz), testField(x, y, z), 1e-12);
      }
    }
  }
  // A pure translation by (1, 2, 3) agrees with shift.
  const Shape t = affine(unitSphere(), { 1, 0, 0, 1, 0, 1, 0, 2, 0, 0, 1, 3 });
  EXPECT_NEAR(eval(t, 1.5, 2, 3), eval(shift(unitSphere(), { 1, 2, 3 }), 1.5, 2, 3), tol);
  // A map in the xy plane is fine for a disk; one touching z is not.
  const Shape d = affine(disk(0, 0, 1), { 0, -1, 0, 3, 1, 0, 0, 0, 0, 0, 1, 0 });
  EXPECT_NEAR(eval(d, 3, 0), 1.0, tol);
  expectThrowMentioning<DomainError>(
    [] {
      affine(disk(0, 0, 1), { 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 1 });
    },
    { "affine", "z" });
  expectThrowMentioning<DomainError>(
    [] {
      affine(disk(0, 0, 1), { 1, 0, 1, 0, 0, 1, 0, 0, 0, 0, 1, 0 });
    },
    { "affine", "z" });
  // Singular: the third row is the sum of the first two.
  expectThrowMentioning<std::invalid_argument>(
    [] {
      affine(unitSphere(), { 1, 2, 3, 0, 0, 1, 1, 0, 1, 3, 4, 0 });
    },
    { "affine", "matrix", "singular" });
  expectThrowMentioning<std::invalid_argument>(
    [] {
      affine(unitSphere(), { 1, 0, 0, 0, 0, NAN, 0, 0, 0, 0, 1, 0 });
    },
    { "affine", "matrix" });
}

TEST(Operations, TwistFollowsHfTwist)
{
  // hfTwistZ(z1 = 0, z2 = 1, theta1 = 0, theta2 = pi/2): at z = 0 nothing turns, at z = 1 the
  // half-space x >= 1 is turned like rotate(+90) into y >= 1; the angle is extrapolated (not
  // clamped) outside [z1, z2], so at z = 2, theta = pi and x >= 1 becomes x <= -1:
  // x' = -2 cos(pi) = 2 -> f = 1.
  const Shape hx(Expr::x() - 1.0, Domain::XYZ, "x>=1");
  const Shape tw = twist(hx, Axis::Z, 0, 1, 0, pi / 2);
  EXPECT_NEAR(eval(tw, 2, 0, 0), 1.0, tol);
  EXPECT_NEAR(eval(tw, 0, 2, 1), 1.0, tol);
  EXPECT_NEAR(eval(tw, -2, 0, 2), 1.0, tol);
  const Shape f = testShape();
  const double z1 = -0.5, z2 = 1.5, th1 = 0.3, th2 = -1.1;
  for (double x : { -1.0, 0.6 })
  {
    for (double y : { -0.4, 1.1 })
    {
      for (double z : { -2.0, 0.0, 0.7, 3.0 })
      {
        {
          const double t = (z - z1) / (z2 - z1), th = (1 - t) * th1 + t * th2;
          const double c = std::cos(th), s = std::sin(th);
          EXPECT_NEAR(eval(twist(f, Axis::Z, z1, z2, th1, th2), x, y, z),
            testField(x * c + y * s, -x * s + y * c, z), tol);
        }
        {
          // hfTwistX: t from x; (y, z) turned.
          const double t = (x - z1) / (z2 - z1), th = (1 - t) * th1 + t * th2;
          const double c = std::cos(th), s = std::sin(th);
          EXPECT_NEAR(eval(twist(f, Axis::X, z1, z2, th1, th2), x, y, z),
            testField(x, y * c + z * s, -y * s + z * c), tol);
        }
        {
          // hfTwistY: t from y; (z, x) turned.
          const double t = (y - z1) / (z2 - z1), th = (1 - t) * th1 + t * th2;
          const double c = std::cos(th), s = std::sin(th);
          EXPECT_NEAR(eval(twist(f, Axis::Y, z1, z2, th1, th2), x, y, z),
            testField(-z * s + x * c, y, z * c + x * s), tol);
        }
      }
    }
  }
  expectThrowMentioning<std::invalid_argument>(
    [] { twist(unitSphere(), Axis::Z, 1, 1, 0, 1); }, { "twist", "z1" });
  expectThrowMentioning<DomainError>(
    [] { twist(disk(0, 0, 1), Axis::Z, 0, 1, 0, 1); }, { "twist", "z" });
}

TEST(Operations, TaperFollowsHfTaper)
{
  // hfTaperZ(z1 = 0, z2 = 1, s1 = 1, s2 = 2) on the unit cylinder 1 - x^2 - y^2: the radius is
  // 1 below z = 0, 1.5 at z = 0.5, 2 at z = 1 and stays 2 above.
  const Shape cyl(1.0 - square(Expr::x()) - square(Expr::y()), Domain::XYZ, "cylinder");
  const Shape tp = taper(cyl, Axis::Z, 0, 1, 1, 2);
  EXPECT_NEAR(eval(tp, 1, 0, -3), 0.0, tol);
  EXPECT_NEAR(eval(tp, 1.5, 0, 0.5), 0.0, tol);
  EXPECT_NEAR(eval(tp, 0, 2, 1), 0.0, tol);
  EXPECT_NEAR(eval(tp, 0, 2, 5), 0.0, tol);
  // At z = 0.25, scale = 1.25: (1, 0) -> (0.8, 0), f = 1 - 0.64 = 0.36.
  EXPECT_NEAR(eval(tp, 1, 0, 0.25), 0.36, tol);
  const Shape f = testShape();
  const Shape tx = taper(f, Axis::X, -1, 2, 0.5, 3);
  for (double x : { -2.0, -1.0, 0.0, 1.3, 2.0, 4.0 })
  {
    const double t = std::min(std::max((x + 1) / 3.0, 0.0), 1.0);
    const double sc = (1 - t) * 0.5 + t * 3;
    EXPECT_NEAR(eval(tx, x, 0.7, -0.4), testField(x, 0.7 / sc, -0.4 / sc), tol);
  }
  expectThrowMentioning<std::invalid_argument>(
    [&] { taper(cyl, Axis::Z, 0, 1, 0, 2); }, { "taper", "s1" });
  expectThrowMentioning<std::invalid_argument>(
    [&] { taper(cyl, Axis::Z, 0, 1, 1, -2); }, { "taper", "s2" });
  expectThrowMentioning<std::invalid_argument>(
    [&] { taper(cyl, Axis::Z, 1, 0, 1, 2); }, { "taper", "z1" });
  expectThrowMentioning<DomainError>(
    [] { taper(disk(0, 0, 1), Axis::Z, 0, 1, 1, 2); }, { "taper" });
}

TEST(Operations, BendWrapsTheLengthAxisOntoACircle)
{
  // Barr bend about x with k = 1 (R = 1): the forward map sends (u, v) = (y, z) to
  // (-sin(k u)(v - R), cos(k u)(v - R) + R). The point (0, pi/2, 0) goes to (0, 1, 1), so the bent
  // field there equals the original at (0, pi/2, 0).
  const Shape f = testShape();
  const Shape b = bend(f, Axis::X, 1.0);
  EXPECT_NEAR(eval(b, 0, 1, 1), testField(0, pi / 2, 0), tol);
  for (double k : { 1.0, -0.6, 2.5 })
  {
    const double R = 1.0 / k;
    for (double u : { -0.9, -0.2, 0.0, 0.5, 1.1 })
    {
      for (double v : { -0.3, 0.0, 0.2 })
      {
        if (std::fabs(k * u) >= pi)
        {
          continue;
        }
        const double U = -std::sin(k * u) * (v - R), V = std::cos(k * u) * (v - R) + R;
        // About x: (y, z) plane; about y: (z, x); about z: (x, y).
        EXPECT_NEAR(eval(bend(f, Axis::X, k), 0.4, U, V), testField(0.4, u, v), 1e-12)
          << k << " " << u << " " << v;
        EXPECT_NEAR(eval(bend(f, Axis::Y, k), V, 0.4, U), testField(v, 0.4, u), 1e-12);
        EXPECT_NEAR(eval(bend(f, Axis::Z, k), U, V, 0.4), testField(u, v, 0.4), 1e-12);
      }
    }
  }
  EXPECT_EQ(eval(bend(f, Axis::Z, 0.0), 0.3, 0.2, 0.1), eval(f, 0.3, 0.2, 0.1));
  // A disk bends in its plane (about z) but not about x.
  EXPECT_NO_THROW(bend(disk(0, 0, 1), Axis::Z, 0.5));
  expectThrowMentioning<DomainError>([] { bend(disk(0, 0, 1), Axis::X, 0.5); }, { "bend", "z" });
  expectThrowMentioning<std::invalid_argument>(
    [&] { bend(f, Axis::X, NAN); }, { "bend", "curvature" });
}

TEST(Operations, StretchFollowsHfStretch)
{
  // hfStretch3D: x' = x0 + (x - x0)/s. Unit sphere, centre (1, 1, 1), factors (2, 1, 1):
  // (3, 0, 0) -> x' = 1 + 2/2 = 2, f = 1 - 4 = -3; (-1, 0, 0) -> x' = 1 - 1 = 0, f = 1.
  const Shape s = stretch(unitSphere(), { 1, 1, 1 }, { 2, 1, 1 });
  EXPECT_NEAR(eval(s, 3, 0, 0), -3.0, tol);
  EXPECT_NEAR(eval(s, -1, 0, 0), 1.0, tol);
  const Shape g = stretch(testShape(), { 0.5, -1, 2 }, { 3, 0.5, -2 });
  EXPECT_NEAR(eval(g, 1, 1, 1), testField(0.5 + 0.5 / 3, -1 + 2 / 0.5, 2 + (-1) / -2.0), tol);
  expectThrowMentioning<std::invalid_argument>(
    [] {
      stretch(unitSphere(), { 0, 0, 0 }, { 1, 0, 1 });
    },
    { "stretch", "factors" });
  expectThrowMentioning<DomainError>(
    [] {
      stretch(disk(0, 0, 1), { 0, 0, 0 }, { 1, 1, 3 });
    },
    { "stretch", "z" });
}

TEST(Operations, SpaceMapCubicFollowsHfSpaceMapCubic)
{
  // One control point, source (0, 0, 0) -> target (1, 0, 0), b = (1, 1, 1): d = (1, 0, 0), the
  // influence half-axes are b_k (1 + |d_k|) = (2, 1, 1). With u = ((x - 1) / 2, y, z), r = |u| and
  // w = (1 - r)^3 / (1 + r) for r <= 1 (else 0), x' = x - w, y' = y, z' = z. The probe f1 = x
  // returns x', f2 = y returns y'.
  //   (1, 0, 0), the target: r = 0, w = 1, x' = 0 (the source).
  //   (2, 0, 0): r = 1/2, w = (1/8) / (3/2) = 1/12, x' = 23/12.
  //   (0, 0, 0): r = 1/2, x' = -1/12.   (1, 0.5, 0): r = 1/2, x' = 11/12, y' = 0.5.
  //   (1, 0, 2): r = 2 > 1, w = 0, x' = 1.   (3, 0, 0): r = 1 exactly, w = 0, x' = 3.
  const std::vector<Vec3> src{ { 0, 0, 0 } }, dst{ { 1, 0, 0 } }, b{ { 1, 1, 1 } };
  const Shape mx = spaceMapCubic(probe1, src, dst, b);
  const Shape my = spaceMapCubic(probe2, src, dst, b);
  EXPECT_NEAR(eval(mx, 1, 0, 0), 0.0, tol);
  EXPECT_NEAR(eval(mx, 2, 0, 0), 23.0 / 12, tol);
  EXPECT_NEAR(eval(mx, 0, 0, 0), -1.0 / 12, tol);
  EXPECT_NEAR(eval(mx, 1, 0.5, 0), 11.0 / 12, tol);
  EXPECT_EQ(eval(my, 1, 0.5, 0), 0.5);
  EXPECT_EQ(eval(mx, 1, 0, 2), 1.0);
  EXPECT_EQ(eval(mx, 3, 0, 0), 3.0);
  // A diagonal move: source (0, 0, 0) -> target (1, -2, 0), b = (0.5, 1, 2): d = (1, -2, 0),
  // half-axes (0.5 * 2, 1 * 3, 2 * 1) = (1, 3, 2). At (1.5, -2, 1): u = (0.5, 0, 0.5),
  // r = 1/sqrt(2), w = (1 - r)^3 / (1 + r); p' = (1.5 - w, -2 + 2 w, 1), and the field is the test
  // field there.
  const double r = 1 / std::sqrt(2.0);
  const double w = std::pow(1 - r, 3) / (1 + r);
  const Shape g = spaceMapCubic(testShape(), src, { { 1, -2, 0 } }, { { 0.5, 1, 2 } });
  EXPECT_NEAR(eval(g, 1.5, -2, 1), testField(1.5 - w, -2 + 2 * w, 1), tol);
  // The material at the source appears at the target.
  EXPECT_NEAR(eval(g, 1, -2, 0), testField(0, 0, 0), tol);
  // No control points: the identity.
  EXPECT_EQ(eval(spaceMapCubic(testShape(), {}, {}, {}), 0.3, 0.2, 0.1), testField(0.3, 0.2, 0.1));
}

TEST(Operations, SpaceMapExpFollowsHfSpaceMapExp)
{
  // As above with w = exp(-r^2) everywhere: source (0, 0, 0) -> target (1, 0, 0), b = (1, 1, 1),
  // half-axes (2, 1, 1).
  //   (1, 0, 0): w = 1, x' = 0.   (2, 0, 0): r^2 = 1/4, x' = 2 - e^(-1/4).
  //   (1, 0, 2): r^2 = 4, x' = 1 - e^(-4) (no cut-off, unlike the cubic map).
  const std::vector<Vec3> src{ { 0, 0, 0 } }, dst{ { 1, 0, 0 } }, b{ { 1, 1, 1 } };
  const Shape mx = spaceMapExp(probe1, src, dst, b);
  EXPECT_NEAR(eval(mx, 1, 0, 0), 0.0, tol);
  EXPECT_NEAR(eval(mx, 2, 0, 0), 2 - std::exp(-0.25), tol);
  EXPECT_NEAR(eval(mx, 1, 0, 2), 1 - std::exp(-4.0), tol);
  EXPECT_EQ(eval(spaceMapExp(probe3, src, dst, b), 1, 0, 2), 2.0);
  // Diagonal move as in the cubic test: at (1.5, -2, 1), r^2 = 1/2, w = e^(-1/2).
  const double w = std::exp(-0.5);
  const Shape g = spaceMapExp(testShape(), src, { { 1, -2, 0 } }, { { 0.5, 1, 2 } });
  EXPECT_NEAR(eval(g, 1.5, -2, 1), testField(1.5 - w, -2 + 2 * w, 1), tol);
  // Two control points act one after the other on the moved point (HyperFun updates its array in
  // place): (0, 0, 0) -> (1, 0, 0) then (0, 0, 0) -> (0, 1, 0), b = (1, 1, 1) for both. At
  // (1, 0, 0) the first step gives (0, 0, 0) (w = 1); the second has d = (0, 1, 0), half-axes
  // (1, 2, 1), u = (0, -1/2, 0), w = e^(-1/4): the point ends at (0, -e^(-1/4), 0). (Evaluating
  // both steps at the original point would give u = (1, -1/2, 0) instead.)
  const std::vector<Vec3> src2{ { 0, 0, 0 }, { 0, 0, 0 } }, dst2{ { 1, 0, 0 }, { 0, 1, 0 } },
    b2{ { 1, 1, 1 }, { 1, 1, 1 } };
  EXPECT_NEAR(eval(spaceMapExp(probe1, src2, dst2, b2), 1, 0, 0), 0.0, tol);
  EXPECT_NEAR(eval(spaceMapExp(probe2, src2, dst2, b2), 1, 0, 0), -std::exp(-0.25), tol);
}

TEST(Operations, SpaceMapValidation)
{
  const std::vector<Vec3> one{ { 0, 0, 0 } }, two{ { 0, 0, 0 }, { 1, 1, 1 } };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  expectThrowMentioning<std::invalid_argument>(
    [&] { spaceMapCubic(unitSphere(), one, two, one); }, { "spaceMapCubic", "target" });
  expectThrowMentioning<std::invalid_argument>(
    [&] { spaceMapExp(unitSphere(), one, one, two); }, { "spaceMapExp", "influence" });
  expectThrowMentioning<std::invalid_argument>(
    [&] {
      spaceMapCubic(unitSphere(), { { nan, 0, 0 } }, one, { { 1, 1, 1 } });
    },
    { "spaceMapCubic", "source" });
  expectThrowMentioning<std::invalid_argument>(
    [&] {
      spaceMapExp(unitSphere(), one, { { 0, nan, 0 } }, { { 1, 1, 1 } });
    },
    { "spaceMapExp", "target" });
  expectThrowMentioning<std::invalid_argument>(
    [&] {
      spaceMapCubic(unitSphere(), one, { { 1, 0, 0 } }, { { 1, 0, 1 } });
    },
    { "spaceMapCubic", "influence" });
  expectThrowMentioning<DomainError>(
    [&] {
      spaceMapExp(disk(0, 0, 1), one, { { 1, 0, 0 } }, { { 1, 1, 1 } });
    },
    { "spaceMapExp", "z" });
}
