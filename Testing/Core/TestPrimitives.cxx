// SPDX-License-Identifier: BSD-3-Clause
// Tests of the FRep primitive library. Expected numbers are derived by hand in the comments; the
// convolution fields are checked against numerical quadrature written here (adaptive Gauss-Kronrod
// 7-15), independent of the closed forms in Primitives.cxx.
#include "FRep/Evaluators.h"
#include "FRep/Primitives.h"
#include "FRep/Tape.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <vector>

using namespace ictk::frep;

namespace
{
constexpr double pi = 3.14159265358979323846;
const double notANumber = std::numeric_limits<double>::quiet_NaN();
const double infinity = std::numeric_limits<double>::infinity();

double at(const Expr& e, double x, double y = 0, double z = 0, double t = 0)
{
  return evaluateReference(e, { x, y, z, t });
}

double at(const Shape& s, double x, double y = 0, double z = 0, double t = 0)
{
  return at(s.function(), x, y, z, t);
}

double at(const Shape& s, const Vec3& p)
{
  return at(s.function(), p[0], p[1], p[2]);
}

double at(const Expr& e, const Vec3& p)
{
  return at(e, p[0], p[1], p[2]);
}

/// Uniform numbers with a mapping of our own, so that the random points are the same everywhere.
class Random
{
public:
  explicit Random(std::uint64_t seed)
    : engine_(seed)
  {
  }
  double uniform(double lo, double hi)
  {
    return lo + (hi - lo) * static_cast<double>(engine_() >> 11) * 0x1.0p-53;
  }
  Vec3 point(double lo, double hi) { return { uniform(lo, hi), uniform(lo, hi), uniform(lo, hi) }; }

private:
  std::mt19937_64 engine_;
};

// --- independent quadrature: adaptive Gauss-Kronrod 7-15
// -------------------------------------------

const double kronrodNodes[8] = { 0.991455371120812639206854697526329,
  0.949107912342758524526189684047851, 0.864864423359769072789712788640926,
  0.741531185599394439863864773280788, 0.586087235467691130294144845693013,
  0.405845151377397166906606412076961, 0.207784955007898467600689403773245, 0.0 };
const double kronrodWeights[8] = { 0.022935322010529224963732008058970,
  0.063092092629978553290700663189204, 0.104790010322250183839876322541518,
  0.140653259715525918745189590510238, 0.169004726639267902826583426598550,
  0.190350578064785409913256402421014, 0.204432940075298892414161999234649,
  0.209482141084727828012999174891714 };
// Gauss 7-point weights, at the odd Kronrod nodes 1, 3, 5, 7.
const double gaussWeights[4] = { 0.129484966168869693270611432679082,
  0.279705391489276667901467771423780, 0.381830050505118944950369775488975,
  0.417959183673469387755102040816327 };

double adaptiveKronrod(
  const std::function<double(double)>& f, double a, double b, double tolerance, int depth)
{
  const double half = 0.5 * (b - a);
  const double mid = 0.5 * (a + b);
  const double fm = f(mid);
  double kronrod = kronrodWeights[7] * fm;
  double gauss = gaussWeights[3] * fm;
  for (int i = 0; i < 7; ++i)
  {
    const double sum = f(mid - half * kronrodNodes[i]) + f(mid + half * kronrodNodes[i]);
    kronrod += kronrodWeights[i] * sum;
    if (i % 2 == 1)
    {
      gauss += gaussWeights[i / 2] * sum;
    }
  }
  kronrod *= half;
  gauss *= half;
  if (std::fabs(kronrod - gauss) <= tolerance || depth >= 40)
  {
    return kronrod;
  }
  return adaptiveKronrod(f, a, mid, 0.5 * tolerance, depth + 1) +
    adaptiveKronrod(f, mid, b, 0.5 * tolerance, depth + 1);
}

/// int_a^b f with a relative tolerance (absolute from a first coarse estimate).
double integrate(
  const std::function<double(double)>& f, double a, double b, double relative = 1e-14)
{
  const double coarse = adaptiveKronrod(f, a, b, infinity, 0);
  return adaptiveKronrod(f, a, b, relative * std::fabs(coarse) + 1e-300, 0);
}

double cauchy(double s, double r2)
{
  return 1.0 / ((1.0 + s * s * r2) * (1.0 + s * s * r2));
}

double distance2(const Vec3& a, const Vec3& b)
{
  return (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
    (a[2] - b[2]) * (a[2] - b[2]);
}

Vec3 lerp(const Vec3& a, const Vec3& b, double u)
{
  return { a[0] + u * (b[0] - a[0]), a[1] + u * (b[1] - a[1]), a[2] + u * (b[2] - a[2]) };
}

/// int over the segment of h(|p - q|) dq (arc length).
double segmentQuadrature(const Vec3& p, const Vec3& a, const Vec3& b, double s)
{
  const double length = std::sqrt(distance2(a, b));
  return length *
    integrate([&](double u) { return cauchy(s, distance2(p, lerp(a, b, u))); }, 0.0, 1.0);
}

/// Rotation of v by `radians` about the unit vector k, written as v cos + (k x v) sin + k (k.v)(1 -
/// cos).
Vec3 rotateAbout(const Vec3& v, const Vec3& k, double radians)
{
  const double c = std::cos(radians);
  const double s = std::sin(radians);
  const double kv = k[0] * v[0] + k[1] * v[1] + k[2] * v[2];
  const Vec3 kxv = { k[1] * v[2] - k[2] * v[1], k[2] * v[0] - k[0] * v[2],
    k[0] * v[1] - k[1] * v[0] };
  return { v[0] * c + kxv[0] * s + k[0] * kv * (1 - c), v[1] * c + kxv[1] * s + k[1] * kv * (1 - c),
    v[2] * c + kxv[2] * s + k[2] * kv * (1 - c) };
}

/// int over the arc of h dq (arc length): the arc c + Rot(axis, angle) (r cos phi, r sin phi, 0),
/// phi in [0, theta] (HyperFun's hfConvArc parametrisation, angles in degrees).
double arcQuadrature(const Vec3& p, const Vec3& c, double r, double thetaDegrees, const Vec3& axis,
  double angleDegrees, double s)
{
  const double n = std::sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
  const Vec3 k = { axis[0] / n, axis[1] / n, axis[2] / n };
  const double theta = thetaDegrees * pi / 180;
  auto integrand = [&](double phi)
  {
    const Vec3 local =
      rotateAbout({ r * std::cos(phi), r * std::sin(phi), 0.0 }, k, angleDegrees * pi / 180);
    return cauchy(s, distance2(p, { c[0] + local[0], c[1] + local[1], c[2] + local[2] }));
  };
  return r * integrate(integrand, 0.0, theta);
}

/// int over the triangle of h dA, by the Duffy map q = a + u (b - a) + u v (c - b) (Jacobian
/// u |(b - a) x (c - b)|) and nested adaptive Gauss-Kronrod.
double triangleQuadrature(const Vec3& p, const std::array<Vec3, 3>& t, double s)
{
  const Vec3 e1 = { t[1][0] - t[0][0], t[1][1] - t[0][1], t[1][2] - t[0][2] };
  const Vec3 e2 = { t[2][0] - t[1][0], t[2][1] - t[1][1], t[2][2] - t[1][2] };
  const Vec3 n = { e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
    e1[0] * e2[1] - e1[1] * e2[0] };
  const double jacobian = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  auto inner = [&](double u)
  {
    return integrate(
      [&](double v)
      {
        const Vec3 q = { t[0][0] + u * e1[0] + u * v * e2[0], t[0][1] + u * e1[1] + u * v * e2[1],
          t[0][2] + u * e1[2] + u * v * e2[2] };
        return u * cauchy(s, distance2(p, q));
      },
      0.0, 1.0, 1e-14);
  };
  return jacobian * integrate(inner, 0.0, 1.0, 1e-13);
}

/// The root of f in [lo, hi] (f(lo), f(hi) of opposite signs) by bisection to 1e-13.
double bisect(const std::function<double(double)>& f, double lo, double hi)
{
  const double flo = f(lo);
  EXPECT_LT(flo * f(hi), 0) << "no sign change in [" << lo << ", " << hi << "]";
  for (int i = 0; i < 200 && hi - lo > 1e-13; ++i)
  {
    const double mid = 0.5 * (lo + hi);
    if ((f(mid) < 0) == (flo < 0))
    {
      lo = mid;
    }
    else
    {
      hi = mid;
    }
  }
  return 0.5 * (lo + hi);
}

/// Expects std::invalid_argument whose message contains every word.
void expectInvalid(const std::function<void()>& build, const std::vector<std::string>& words)
{
  try
  {
    build();
    ADD_FAILURE() << "no exception; expected one mentioning '" << words.front() << "'";
  }
  catch (const std::invalid_argument& e)
  {
    const std::string message = e.what();
    for (const std::string& w : words)
    {
      EXPECT_NE(message.find(w), std::string::npos) << "'" << w << "' missing from: " << message;
    }
  }
}

} // namespace

// --- 1D and 2D ------------------------------------------------------------------------------

TEST(Primitives1D, Interval)
{
  // (x + 1)(3 - x): 2 * 2 = 4 at the midpoint x = 1, 0 at both ends, (5)(-1) = -5 at x = 4.
  const Shape s = interval(-1, 3);
  EXPECT_EQ(s.domain(), Domain::X);
  EXPECT_DOUBLE_EQ(at(s, 1), 4);
  EXPECT_DOUBLE_EQ(at(s, -1), 0);
  EXPECT_DOUBLE_EQ(at(s, 3), 0);
  EXPECT_DOUBLE_EQ(at(s, 4), -5);
  EXPECT_DOUBLE_EQ(at(s, -2), -5);
}

TEST(Primitives1D, TimeInterval)
{
  // t (2 - t): 1 at t = 1, 3 * (-1) = -3 at t = 3; x is not a coordinate of the domain.
  const Shape s = timeInterval(0, 2);
  EXPECT_EQ(s.domain(), Domain::T);
  EXPECT_DOUBLE_EQ(at(s, 0, 0, 0, 1), 1);
  EXPECT_DOUBLE_EQ(at(s, 0, 0, 0, 0), 0);
  EXPECT_DOUBLE_EQ(at(s, 0, 0, 0, 3), -3);
  EXPECT_DOUBLE_EQ(at(s, 7, 0, 0, 1), 1);
}

TEST(Primitives2D, Circle)
{
  // 0.25 - (x-1)^2 - (y-2)^2: 0.25 at the center, 0 at (1.5, 2), 0.25 - 1 = -0.75 at (1, 3).
  const Shape s = circle({ 1, 2 }, 0.5);
  EXPECT_EQ(s.domain(), Domain::XY);
  EXPECT_DOUBLE_EQ(at(s, 1, 2), 0.25);
  EXPECT_DOUBLE_EQ(at(s, 1.5, 2), 0);
  EXPECT_DOUBLE_EQ(at(s, 1, 1.5), 0);
  EXPECT_DOUBLE_EQ(at(s, 1, 3), -0.75);
}

TEST(Primitives2D, Ellipse)
{
  // 1 - (x/2)^2 - y^2: 0 at (2, 0) and (0, 1); at (1, 0.5): 1 - 0.25 - 0.25 = 0.5.
  const Shape s = ellipse({ 0, 0 }, 2, 1);
  EXPECT_DOUBLE_EQ(at(s, 0, 0), 1);
  EXPECT_DOUBLE_EQ(at(s, 2, 0), 0);
  EXPECT_DOUBLE_EQ(at(s, 0, -1), 0);
  EXPECT_DOUBLE_EQ(at(s, 1, 0.5), 0.5);
  EXPECT_LT(at(s, 0, 1.1), 0);
}

TEST(Primitives2D, Rectangle)
{
  // min(x (2 - x), y (1 - y)) on [0,2]x[0,1]: at the center (1, 0.5) min(1, 0.25) = 0.25; 0 on
  // the edge x = 0; at (3, 0.5): min(3 * (-1), 0.25) = -3.
  const Shape s = rectangle({ 0, 0 }, 2, 1);
  EXPECT_DOUBLE_EQ(at(s, 1, 0.5), 0.25);
  EXPECT_DOUBLE_EQ(at(s, 0, 0.5), 0);
  EXPECT_DOUBLE_EQ(at(s, 1, 1), 0);
  EXPECT_DOUBLE_EQ(at(s, 3, 0.5), -3);
  EXPECT_LT(at(s, 2.1, 1.1), 0);
}

// --- 3D ------------------------------------------------------------------------------------------

TEST(Primitives3D, Sphere)
{
  // 4 - |p - (1,-2,3)|^2: 4 at the center, 0 at distance 2, 4 - 9 = -5 at distance 3.
  const Shape s = sphere({ 1, -2, 3 }, 2);
  EXPECT_EQ(s.domain(), Domain::XYZ);
  EXPECT_DOUBLE_EQ(at(s, 1, -2, 3), 4);
  EXPECT_DOUBLE_EQ(at(s, 3, -2, 3), 0);
  EXPECT_DOUBLE_EQ(at(s, 1, -2, 1), 0);
  EXPECT_DOUBLE_EQ(at(s, 1, -2, 6), -5);
  // Central symmetry.
  EXPECT_DOUBLE_EQ(at(s, 1.3, -2.4, 3.5), at(s, 0.7, -1.6, 2.5));
}

TEST(Primitives3D, Ellipsoid)
{
  // 1 - x^2 - (y/2)^2 - (z/3)^2: 0 at the three vertices; at (0.5, 1, 1.5): 1 - 3 * 0.25 = 0.25.
  const Shape s = ellipsoid({ 0, 0, 0 }, 1, 2, 3);
  EXPECT_DOUBLE_EQ(at(s, 1, 0, 0), 0);
  EXPECT_DOUBLE_EQ(at(s, 0, 2, 0), 0);
  EXPECT_DOUBLE_EQ(at(s, 0, 0, -3), 0);
  EXPECT_DOUBLE_EQ(at(s, 0.5, 1, 1.5), 0.25);
  EXPECT_DOUBLE_EQ(at(s, 0, 0, 0), 1);
}

TEST(Primitives3D, Block)
{
  // Slabs x (2 - x), y (4 - y), z (6 - z). At the center (1, 2, 3): min(1, 4, 9) = 1. On the
  // face x = 0: 0. At x = -1 (y, z central): -1 * 3 = -3.
  const Shape s = block({ 0, 0, 0 }, 2, 4, 6);
  EXPECT_DOUBLE_EQ(at(s, 1, 2, 3), 1);
  EXPECT_DOUBLE_EQ(at(s, 0, 2, 3), 0);
  EXPECT_DOUBLE_EQ(at(s, 1, 4, 3), 0);
  EXPECT_DOUBLE_EQ(at(s, -1, 2, 3), -3);
  EXPECT_DOUBLE_EQ(at(s, 1, 2, 6.5), -3.25);
  // The corner vertex is offset correctly.
  const Shape t = block({ 10, 20, 30 }, 1, 1, 1);
  EXPECT_DOUBLE_EQ(at(t, 10.5, 20.5, 30.5), 0.25);
  EXPECT_LT(at(t, 0.5, 0.5, 0.5), 0);
}

TEST(Primitives3D, BlockRFunctionFollowsHfBlock)
{
  // hfBlock with ALPHA = 0 at the center (1, 2, 3) of [0,2]x[0,4]x[0,6]: slabs 1, 4, 9;
  // g = 1 + 4 - sqrt(1 + 16) = 5 - sqrt(17), then g + 9 - sqrt(g^2 + 81).
  const double g = 5 - std::sqrt(17.0);
  const Shape s0 = blockRFunction({ 0, 0, 0 }, 2, 4, 6, 0.0);
  EXPECT_NEAR(at(s0, 1, 2, 3), g + 9 - std::sqrt(g * g + 81), 1e-15);
  // With alpha = 0.5: g = 5 - sqrt(1 + 16 - 4) = 5 - sqrt(13), then g + 9 - sqrt(g^2 + 81 - 9 g).
  const double h = 5 - std::sqrt(13.0);
  const Shape s5 = blockRFunction({ 0, 0, 0 }, 2, 4, 6, 0.5);
  EXPECT_NEAR(at(s5, 1, 2, 3), h + 9 - std::sqrt(h * h + 81 - 9 * h), 1e-15);
  // On a face one slab is 0: 0 + f2 - |f2| = 0, then 0 + f3 - |f3| = 0.
  EXPECT_NEAR(at(s0, 0, 2, 3), 0, 1e-15);
  // alpha = 1 is exactly the min (block()).
  const Shape s1 = blockRFunction({ 0, 0, 0 }, 2, 4, 6, 1.0);
  const Shape b = block({ 0, 0, 0 }, 2, 4, 6);
  for (const Vec3& p : { Vec3{ 1, 2, 3 }, Vec3{ 0.3, 3.9, 1 }, Vec3{ -1, 5, 7 } })
  {
    EXPECT_EQ(at(s1, p), at(b, p));
  }
}

TEST(Primitives3D, CylinderAlongEachAxis)
{
  // Z: 4 - (x-1)^2 - (y-1)^2, independent of z.
  const Shape z = cylinder(Axis::Z, { 1, 1, 0 }, 2);
  EXPECT_DOUBLE_EQ(at(z, 1, 1, 100), 4);
  EXPECT_DOUBLE_EQ(at(z, 3, 1, -7), 0);
  EXPECT_DOUBLE_EQ(at(z, 1, 4, 0), -5);
  // X: 1 - y^2 - z^2, independent of x.
  const Shape x = cylinder(Axis::X, { 0, 0, 0 }, 1);
  EXPECT_DOUBLE_EQ(at(x, 50, 0, 0), 1);
  EXPECT_DOUBLE_EQ(at(x, -3, 0, 1), 0);
  EXPECT_DOUBLE_EQ(at(x, 2, 0, 0), 1);
  // Y: 1 - x^2 - z^2.
  const Shape y = cylinder(Axis::Y, { 0, 0, 0 }, 1);
  EXPECT_DOUBLE_EQ(at(y, 0, 9, 0), 1);
  EXPECT_DOUBLE_EQ(at(y, 1, -9, 0), 0);
  EXPECT_DOUBLE_EQ(at(y, 0, 0, 1), 0);
}

TEST(Primitives3D, EllipticCylinderHalfAxesFollowHyperFun)
{
  // hfEllCylY: a along x, b along z: 1 - (x/2)^2 - (z/3)^2.
  const Shape y = ellipticCylinder(Axis::Y, { 0, 0, 0 }, 2, 3);
  EXPECT_DOUBLE_EQ(at(y, 2, 9, 0), 0);
  EXPECT_DOUBLE_EQ(at(y, 0, -5, 3), 0);
  EXPECT_DOUBLE_EQ(at(y, 0, 0, 2), 1 - 4.0 / 9.0);
  // hfEllCylX: a along y, b along z.
  const Shape x = ellipticCylinder(Axis::X, { 0, 0, 0 }, 2, 3);
  EXPECT_DOUBLE_EQ(at(x, 7, 2, 0), 0);
  EXPECT_DOUBLE_EQ(at(x, 7, 0, 3), 0);
  // hfEllCylZ: a along x, b along y.
  const Shape z = ellipticCylinder(Axis::Z, { 1, 0, 0 }, 2, 3);
  EXPECT_DOUBLE_EQ(at(z, 3, 0, 5), 0);
  EXPECT_DOUBLE_EQ(at(z, 1, 3, 5), 0);
  EXPECT_DOUBLE_EQ(at(z, 2, 0, 5), 0.75);
}

TEST(Primitives3D, Cone)
{
  // (z-1)^2 - (x/0.5)^2 - (y/0.5)^2: 0 at the apex; 1 on the axis at height 1; radius 0.5 at
  // height 1 (either nappe) is on the surface; (1, 0, 1) level with the apex: -4.
  const Shape s = cone(Axis::Z, { 0, 0, 1 }, 0.5);
  EXPECT_DOUBLE_EQ(at(s, 0, 0, 1), 0);
  EXPECT_DOUBLE_EQ(at(s, 0, 0, 2), 1);
  EXPECT_DOUBLE_EQ(at(s, 0.5, 0, 2), 0);
  EXPECT_DOUBLE_EQ(at(s, 0, -0.5, 0), 0);
  EXPECT_DOUBLE_EQ(at(s, 1, 0, 1), -4);
  // Along X: x^2 - y^2 - z^2 with r = 1.
  const Shape x = cone(Axis::X, { 0, 0, 0 }, 1);
  EXPECT_DOUBLE_EQ(at(x, 2, 1, 1), 2);
}

TEST(Primitives3D, EllipticCone)
{
  // Along X with a = 1 (y), b = 2 (z): x^2 - y^2 - (z/2)^2. (1, 1, 0) and (1, 0, 2) are on the
  // surface; (2, 1, 1): 4 - 1 - 0.25 = 2.75.
  const Shape s = ellipticCone(Axis::X, { 0, 0, 0 }, 1, 2);
  EXPECT_DOUBLE_EQ(at(s, 1, 1, 0), 0);
  EXPECT_DOUBLE_EQ(at(s, 1, 0, 2), 0);
  EXPECT_DOUBLE_EQ(at(s, 2, 1, 1), 2.75);
  // Along Y (hfEllConeY: a along x, b along z): y^2 - (x/a)^2 - (z/b)^2.
  const Shape y = ellipticCone(Axis::Y, { 0, 0, 0 }, 1, 2);
  EXPECT_DOUBLE_EQ(at(y, 1, 1, 0), 0);
  EXPECT_DOUBLE_EQ(at(y, 0, 1, 2), 0);
}

TEST(Primitives3D, Torus)
{
  // R = 2, r = 0.5 around Z: f = 0.25 - |p|^2 - 4 + 4 sqrt(x^2 + y^2).
  // Tube center (2,0,0): 0.25 - 4 - 4 + 8 = 0.25.
  // Outer equator (2.5,0,0): 0.25 - 6.25 - 4 + 10 = 0.
  // Torus center: 0.25 - 4 = -3.75. Top of the tube (0,2,0.5): 0.25 - 4.25 - 4 + 8 = 0.
  const Shape s = torus(Axis::Z, { 0, 0, 0 }, 2, 0.5);
  EXPECT_DOUBLE_EQ(at(s, 2, 0, 0), 0.25);
  EXPECT_DOUBLE_EQ(at(s, 2.5, 0, 0), 0);
  EXPECT_DOUBLE_EQ(at(s, 1.5, 0, 0), 0);
  EXPECT_DOUBLE_EQ(at(s, 0, 0, 0), -3.75);
  EXPECT_DOUBLE_EQ(at(s, 0, 2, 0.5), 0);
  // Around X the ring lies in the yz plane: (0, 2, 0) is the tube center, (2, 0, 0) is on the
  // axis: 0.25 - 4 - 4 + 0 = -7.75.
  const Shape x = torus(Axis::X, { 0, 0, 0 }, 2, 0.5);
  EXPECT_DOUBLE_EQ(at(x, 0, 2, 0), 0.25);
  EXPECT_DOUBLE_EQ(at(x, 0, 0, 2.5), 0);
  EXPECT_DOUBLE_EQ(at(x, 2, 0, 0), -7.75);
  // Around Y, shifted center.
  const Shape y = torus(Axis::Y, { 1, 1, 1 }, 2, 0.5);
  EXPECT_DOUBLE_EQ(at(y, 1, 1, 3), 0.25);
}

TEST(Primitives3D, Superellipsoid)
{
  // s1 = s2 = 1 is the ellipsoid: 1 - (x^2 + y^2) - z^2 (axes scaled).
  const Shape s = superellipsoid({ 1, 0, 0 }, 1, 2, 3, 1, 1);
  const Shape e = ellipsoid({ 1, 0, 0 }, 1, 2, 3);
  Random rng(7);
  for (int i = 0; i < 20; ++i)
  {
    const Vec3 p = rng.point(-3, 3);
    EXPECT_NEAR(at(s, p), at(e, p), 1e-12);
  }
  // s1 = s2 = 2: exponents 1: the octahedron 1 - |x| - |y| - |z|.
  const Shape o = superellipsoid({ 0, 0, 0 }, 1, 1, 1, 2, 2);
  EXPECT_NEAR(at(o, 0.2, -0.3, 0.1), 0.4, 1e-15);
  EXPECT_NEAR(at(o, 0.5, 0.5, 0), 0, 1e-15);
  // s1 = 1, s2 = 0.5: 1 - (x^4 + y^4)^(1/2) - z^2; at (0.5, 0.5, 0.5): 1 - sqrt(0.125) - 0.25.
  const Shape r = superellipsoid({ 0, 0, 0 }, 1, 1, 1, 1, 0.5);
  EXPECT_NEAR(at(r, 0.5, 0.5, 0.5), 0.75 - std::sqrt(0.125), 1e-15);
  // Non-integer exponents (2/0.7) are finite at the center and on the axes: 1 and 0.
  const Shape q = superellipsoid({ 0, 0, 0 }, 2, 1, 1, 0.7, 0.7);
  EXPECT_DOUBLE_EQ(at(q, 0, 0, 0), 1);
  EXPECT_NEAR(at(q, 2, 0, 0), 0, 1e-15);
  EXPECT_NEAR(at(q, 0, 0, -1), 0, 1e-15);
}

TEST(Primitives3D, QuadricCoefficientOrder)
{
  // papers.md 5.B item 24: (-1,-1,-1,0,...,0,1) is the unit sphere: F(0)=1, F(1,0,0)=0,
  // F(2,0,0)=-3.
  const Shape s = quadric({ -1, -1, -1, 0, 0, 0, 0, 0, 0, 1 });
  EXPECT_DOUBLE_EQ(at(s, 0, 0, 0), 1);
  EXPECT_DOUBLE_EQ(at(s, 1, 0, 0), 0);
  EXPECT_DOUBLE_EQ(at(s, 2, 0, 0), -3);
  // No factor 2 on cross terms: A12 = 1 gives F(1,1,0) = 1.
  EXPECT_DOUBLE_EQ(at(quadric({ 0, 0, 0, 1, 0, 0, 0, 0, 0, 0 }), 1, 1, 0), 1);
  // Coefficients 1..10 at (2, 3, 5): 1*4 + 2*9 + 3*25 + 4*6 + 5*10 + 6*15 + 7*2 + 8*3 + 9*5 + 10
  // = 4 + 18 + 75 + 24 + 50 + 90 + 14 + 24 + 45 + 10 = 354.
  EXPECT_DOUBLE_EQ(at(quadric({ 1, 2, 3, 4, 5, 6, 7, 8, 9, 10 }), 2, 3, 5), 354);
}

TEST(Primitives3D, HalfSpaceIsSignedDistance)
{
  // Plane z = 1, inward normal +z (length 2, normalised): f = z - 1.
  const Shape s = halfSpace({ 0, 0, 1 }, { 0, 0, 2 });
  EXPECT_DOUBLE_EQ(at(s, 5, 5, 3), 2);
  EXPECT_DOUBLE_EQ(at(s, 0, 0, 0), -1);
  // Oblique: through the origin, normal (1, 1, 0): f = (x + y)/sqrt(2); (1, 1, 0) -> sqrt(2).
  const Shape o = halfSpace({ 0, 0, 0 }, { 1, 1, 0 });
  EXPECT_NEAR(at(o, 1, 1, 0), std::sqrt(2.0), 1e-15);
  EXPECT_NEAR(at(o, 1, -1, 7), 0, 1e-15);
}

// --- skeletal primitives -----------------------------------------------------------------------

TEST(Skeletal, Blobby)
{
  // One blob at (1,0,0), a = 2, b = 3, T = 1: 3 exp(-2 r^2) - 1. At the center 2; at r = 0.5:
  // 3 e^-0.5 - 1; on the surface r = sqrt(ln(3)/2) it is 0.
  const Shape s = blobby({ { 1, 0, 0 } }, { 2 }, { 3 }, 1);
  EXPECT_DOUBLE_EQ(at(s, 1, 0, 0), 2);
  EXPECT_NEAR(at(s, 1.5, 0, 0), 3 * std::exp(-0.5) - 1, 1e-15);
  const double surface = std::sqrt(std::log(3.0) / 2);
  EXPECT_NEAR(at(s, 1, surface, 0), 0, 1e-15);
  // Two blobs add: midway between blobs at (+-1,0,0) with a = 1, b = 1: 2 e^-1 - T.
  const Shape two = blobby({ { -1, 0, 0 }, { 1, 0, 0 } }, { 1, 1 }, { 1, 1 }, 0.5);
  EXPECT_NEAR(at(two, 0, 0, 0), 2 * std::exp(-1.0) - 0.5, 1e-15);
}

TEST(Skeletal, MetaballPieces)
{
  // b = 1, d = 3, T = 0: r = 0 -> 1; r = 1 = d/3 -> 1 - 3/9 = 2/3 (and 1.5 (2/3)^2 = 2/3 from the
  // other piece); r = 2 -> 1.5 (1/3)^2 = 1/6; r = 3 and beyond -> 0.
  const Shape s = metaball({ { 0, 0, 0 } }, { 1 }, { 3 }, 0);
  EXPECT_DOUBLE_EQ(at(s, 0, 0, 0), 1);
  EXPECT_NEAR(at(s, 1, 0, 0), 2.0 / 3.0, 1e-15);
  EXPECT_NEAR(at(s, 0, 2, 0), 1.0 / 6.0, 1e-15);
  EXPECT_NEAR(at(s, 0, 0, 3), 0, 1e-15);
  EXPECT_EQ(at(s, 4, 0, 0), 0);
  // C^1 at r = d/3: both one-sided slopes are -2b/d = -2/3.
  const double h = 1e-6;
  EXPECT_NEAR((at(s, 1, 0, 0) - at(s, 1 - h, 0, 0)) / h, -2.0 / 3.0, 1e-5);
  EXPECT_NEAR((at(s, 1 + h, 0, 0) - at(s, 1, 0, 0)) / h, -2.0 / 3.0, 1e-5);
  // Threshold and b scale: b = 2, T = 0.5 at the center: 1.5.
  EXPECT_DOUBLE_EQ(at(metaball({ { 0, 0, 0 } }, { 2 }, { 3 }, 0.5), 0, 0, 0), 1.5);
}

TEST(Skeletal, SoftObjectWyvill)
{
  // papers.md L441: g(0) = 1, g(R/2) = 0.5 (q = 1/4: (576 - 352 + 68 - 4)/576 = 1/2), g(R) = 0,
  // and 0 beyond R (the polynomial alone is (1-q)^2 (9-4q)/9 > 0 for 1 < q < 9/4).
  const Shape s = softObject({ { 0, 0, 0 } }, { 2 }, 0);
  EXPECT_DOUBLE_EQ(at(s, 0, 0, 0), 1);
  EXPECT_NEAR(at(s, 1, 0, 0), 0.5, 1e-15);
  EXPECT_NEAR(at(s, 0, 2, 0), 0, 1e-15);
  EXPECT_EQ(at(s, 0, 0, 2.4), 0);
  // Against hfSoft's polynomial 1 - 22q/9 + 17q^2/9 - 4q^3/9 inside.
  Random rng(11);
  for (int i = 0; i < 20; ++i)
  {
    const double r = rng.uniform(0, 2);
    const double q = r * r / 4;
    EXPECT_NEAR(at(s, 0, r, 0), 1 - 22 * q / 9 + 17 * q * q / 9 - 4 * q * q * q / 9, 1e-14);
  }
  // Two objects and a threshold: at (0.5, 0, 0) between centers 0 and 1 (d = 1): 2 g(1/2) - 0.5.
  const Shape two = softObject({ { 0, 0, 0 }, { 1, 0, 0 } }, { 1, 1 }, 0.5);
  EXPECT_NEAR(at(two, 0.5, 0, 0), 0.5, 1e-15);
}

// --- convolution surfaces
// ---------------------------------------------------------------------------

TEST(Convolution, Points)
{
  // s = 2 at (1,1,1), T = 0.1: at the point 1 - 0.1; at distance 0.5: 1/(1 + 1)^2 - 0.1 = 0.15.
  const Shape s = convolutionPoints({ { 1, 1, 1 } }, { 2 }, 0.1);
  EXPECT_DOUBLE_EQ(at(s, 1, 1, 1), 0.9);
  EXPECT_NEAR(at(s, 1.5, 1, 1), 0.15, 1e-15);
  // Two points add (s = 1, distance 1 from each: 2 * 1/4).
  const Shape two = convolutionPoints({ { -1, 0, 0 }, { 1, 0, 0 } }, { 1, 1 }, 0);
  EXPECT_NEAR(at(two, 0, 0, 0), 0.5, 1e-15);
  EXPECT_NEAR(at(cauchyPointField({ 0, 0, 0 }, 3), 0, 1, 0), 0.01, 1e-16);
}

TEST(Convolution, SegmentHandValues)
{
  // Segment (-1,0,0)-(1,0,0), s = 1. With P^2 = 1 + h^2 at perpendicular distance h from the
  // midpoint: int_{-1}^{1} du / (P^2 + u^2)^2 = 2 [1/(2 P^2 (P^2 + 1)) + atan(1/P)/(2 P^3)].
  // h = 0: 1/2 + pi/4. h = 1: 1/6 + atan(1/sqrt 2) / (2 sqrt 2).
  const Shape s = convolutionSegments({ { Vec3{ -1, 0, 0 }, Vec3{ 1, 0, 0 } } }, { 1 }, 0);
  EXPECT_NEAR(at(s, 0, 0, 0), 0.5 + pi / 4, 1e-15);
  EXPECT_NEAR(
    at(s, 0, 1, 0), 1.0 / 6 + std::atan(1 / std::sqrt(2.0)) / (2 * std::sqrt(2.0)), 1e-15);
  EXPECT_NEAR(at(s, 0, 0, -1), at(s, 0, 1, 0), 1e-15);
}

TEST(Convolution, SegmentsWithRadiusFollowHfConvLineR)
{
  // Segment (0,0,0)-(1,0,0), R = 0.5 < 1, so s = 1/R = 2 and l = 1. At the midpoint (axial
  // coordinate u = 1/2, distance 0): with P^2 = 1 + s^2 * 0 = 1 and both ends at distance 1/2,
  //   field = int_0^1 du / (1 + 4 (u - 1/2)^2)^2 = 2 [1/2 / (2 * 1 * 2) + atan(1) / (2 * 2)]
  //         = 1/4 + pi/8.
  // Threshold: P^2 = 1 + 4 * 0.25 = 2, Q^2 = 2 + 4 * 1 = 6,
  //   T = 1 / (2 * 2 * 6) + atan(2 / sqrt 2) / (2 * 2 * 2 sqrt 2) = 1/24 + atan(sqrt 2) / (8 sqrt
  //   2).
  const double T = 1.0 / 24 + std::atan(std::sqrt(2.0)) / (8 * std::sqrt(2.0));
  const std::array<Vec3, 2> seg{ Vec3{ 0, 0, 0 }, Vec3{ 1, 0, 0 } };
  const Shape one = convolutionSegmentsRadius({ seg }, 0.5);
  EXPECT_NEAR(at(one, 0.5, 0, 0), 0.25 + pi / 8 - T, 1e-15);
  // At distance R from the start on the normal plane the field is the threshold: f = 0.
  EXPECT_NEAR(at(one, 0, 0.5, 0), 0.0, 1e-15);
  EXPECT_NEAR(at(one, 0, 0, -0.5), 0.0, 1e-15);
  // Two copies of the segment: the sum 2 (1/4 + pi/8) = 1.285 is clamped at 1.
  const Shape two = convolutionSegmentsRadius({ seg, seg }, 0.5);
  EXPECT_NEAR(at(two, 0.5, 0, 0), 1.0 - T, 1e-15);
  // R >= 1 keeps s = 1: the field is convolutionSegments with s = 1 and the threshold above with
  // s = 1, R = 2: P^2 = 5, Q^2 = 6, T = 1/60 + atan(1/sqrt 5) / (2 * 5 sqrt 5).
  const double T2 = 1.0 / 60 + std::atan(1 / std::sqrt(5.0)) / (10 * std::sqrt(5.0));
  EXPECT_NEAR(at(convolutionSegmentsRadius({ seg }, 2), 0.3, 0.4, 0.1),
    at(convolutionSegments({ seg }, { 1 }, T2), 0.3, 0.4, 0.1), 1e-15);
  expectInvalid([] { convolutionSegmentsRadius({}, 0.5); },
    { "convolutionSegmentsRadius", "segments", "empty" });
  expectInvalid(
    [&] { convolutionSegmentsRadius({ seg }, 0); }, { "convolutionSegmentsRadius", "radius R" });
  expectInvalid([&] { convolutionSegmentsRadius({ seg }, notANumber); },
    { "convolutionSegmentsRadius", "radius R" });
  expectInvalid(
    [] {
      convolutionSegmentsRadius({ { Vec3{ 1, 1, 1 }, Vec3{ 1, 1, 1 } } }, 1);
    },
    { "convolutionSegmentsRadius", "segments[0]", "zero length" });
}

TEST(Convolution, SegmentMatchesQuadrature)
{
  // thesis_ch5_6.md T-5.4 item 1: relative error < 1e-8 at 1000 random points.
  Random rng(2024);
  double worst = 0;
  for (int i = 0; i < 1000; ++i)
  {
    const Vec3 a = rng.point(-1, 1);
    const Vec3 b = rng.point(-1, 1);
    const double sk = rng.uniform(0.3, 4);
    const Vec3 p = rng.point(-2.5, 2.5);
    const double closed = at(cauchySegmentField(a, b, sk), p);
    const double numeric = segmentQuadrature(p, a, b, sk);
    worst = std::max(worst, std::fabs(closed - numeric) / numeric);
  }
  EXPECT_LT(worst, 1e-8);
  RecordProperty("worstRelativeError", std::to_string(worst));
  std::printf("segment closed form vs quadrature: worst relative error %.3g\n", worst);
}

TEST(Convolution, SegmentSymmetryInfinityAndSuperposition)
{
  Random rng(5);
  const Vec3 a = { -0.3, 0.2, 0.5 };
  const Vec3 b = { 0.9, -0.4, 0.1 };
  const Vec3 m = lerp(a, b, 0.5);
  const double sk = 1.7;
  const Expr forward = cauchySegmentField(a, b, sk);
  const Expr backward = cauchySegmentField(b, a, sk);
  const Expr halves = cauchySegmentField(a, m, sk) + cauchySegmentField(m, b, sk);
  for (int i = 0; i < 200; ++i)
  {
    const Vec3 p = rng.point(-3, 3);
    const double f = at(forward, p);
    // Reversal: the skeleton is the same set.
    EXPECT_NEAR(at(backward, p), f, 1e-13 * f);
    // Two collinear halves make the whole.
    EXPECT_NEAR(at(halves, p), f, 1e-13 * f);
  }
  // Far away the field is bounded by length * h(distance - length) and decreases to 0.
  const double length = std::sqrt(distance2(a, b));
  double previous = infinity;
  for (double d : { 1e1, 1e2, 1e3, 1e6 })
  {
    for (const Vec3& dir :
      { Vec3{ 1, 0, 0 }, Vec3{ 0, 0.6, 0.8 }, Vec3{ 2.0 / 3, -1.0 / 3, -2.0 / 3 } })
    {
      const double f = at(forward, d * dir[0], d * dir[1], d * dir[2]);
      EXPECT_GE(f, -1e-18);
      EXPECT_LE(f, length * cauchy(sk, (d - 2) * (d - 2)) + 1e-18);
    }
    const double f = at(forward, d, 0, 0);
    EXPECT_LT(f, previous);
    previous = f;
  }
}

TEST(Convolution, ArcHandValues)
{
  // A full ring (theta = 360) of radius r: every point of it is at distance sqrt(r^2 + z^2) from
  // the axis point (0, 0, z), so the field there is 2 pi r / (1 + s^2 (r^2 + z^2))^2.
  const double r = 1.5;
  const double sk = 0.8;
  const Expr ring = cauchyArcField({ 0, 0, 0 }, r, 360, { 0, 0, 1 }, 0, sk);
  EXPECT_NEAR(at(ring, 0, 0, 0), 2 * pi * r * cauchy(sk, r * r), 1e-14);
  EXPECT_NEAR(at(ring, 0, 0, 0.7), 2 * pi * r * cauchy(sk, r * r + 0.49), 1e-14);
  // The ring is symmetric about its axis and its plane.
  EXPECT_NEAR(at(ring, 0.3, 0.4, 0.2), at(ring, 0.5, 0, -0.2), 1e-14);
  EXPECT_NEAR(at(ring, -0.4, 0.3, 0.2), at(ring, 0, -0.5, 0.2), 1e-14);
}

TEST(Convolution, ArcMatchesQuadrature)
{
  Random rng(99);
  double worst = 0;
  for (int i = 0; i < 300; ++i)
  {
    const Vec3 c = rng.point(-0.5, 0.5);
    const double r = rng.uniform(0.2, 1.5);
    const double theta = rng.uniform(1, 360);
    const Vec3 axis = rng.point(-1, 1);
    const double angle = rng.uniform(-180, 180);
    const double sk = rng.uniform(0.3, 3);
    const Vec3 p = rng.point(-2, 2);
    const double closed = at(cauchyArcField(c, r, theta, axis, angle, sk), p);
    const double numeric = arcQuadrature(p, c, r, theta, axis, angle, sk);
    worst = std::max(worst, std::fabs(closed - numeric) / numeric);
  }
  EXPECT_LT(worst, 1e-9);
  RecordProperty("worstRelativeError", std::to_string(worst));
  std::printf("arc closed form vs quadrature: worst relative error %.3g\n", worst);
}

TEST(Convolution, ArcParametrisationAndSuperposition)
{
  // hfConvArc's frame: theta = 90 about axis x by 90 degrees maps (cos phi, sin phi, 0) to
  // (cos phi, 0, sin phi), so the arc runs from +x to +z in the xz plane. The point (0.5, 0, 0.5)
  // near it must see a larger field than its mirror (0.5, 0, -0.5).
  const Expr quarter = cauchyArcField({ 0, 0, 0 }, 1, 90, { 1, 0, 0 }, 90, 2);
  EXPECT_GT(at(quarter, 0.5, 0, 0.5), 2 * at(quarter, 0.5, 0, -0.5));
  EXPECT_NEAR(at(quarter, 0.5, 0, 0.5),
    arcQuadrature({ 0.5, 0, 0.5 }, { 0, 0, 0 }, 1, 90, { 1, 0, 0 }, 90, 2), 1e-12);
  // Two half rings (the second turned by 180 degrees about z) make the full ring; so do 100 + 260
  // degrees (an arc past 180 degrees, which hfConvArc splits in two).
  const Vec3 c = { 0.2, -0.1, 0.3 };
  const Expr ring = cauchyArcField(c, 0.9, 360, { 0, 0, 1 }, 0, 1.3);
  const Expr halves = cauchyArcField(c, 0.9, 180, { 0, 0, 1 }, 0, 1.3) +
    cauchyArcField(c, 0.9, 180, { 0, 0, 1 }, 180, 1.3);
  const Expr uneven = cauchyArcField(c, 0.9, 100, { 0, 0, 1 }, 0, 1.3) +
    cauchyArcField(c, 0.9, 260, { 0, 0, 1 }, 100, 1.3);
  Random rng(3);
  for (int i = 0; i < 100; ++i)
  {
    const Vec3 p = rng.point(-2, 2);
    const double f = at(ring, p);
    EXPECT_NEAR(at(halves, p), f, 1e-13 * f);
    EXPECT_NEAR(at(uneven, p), f, 1e-13 * f);
  }
  // A full ring of radius r has length 2 pi r, so far away (distance d, s = 1) its field is about
  // 2 pi r h(d) ~ 2 pi r / d^4: the arc-length integral (hfConvArc's per-angle field is 1/r of it,
  // which would fail here with r = 2).
  const double far = at(cauchyArcField({ 0, 0, 0 }, 2, 360, { 0, 0, 1 }, 0, 1), 0, 0, 1000);
  EXPECT_NEAR(far / (2 * pi * 2 / 1e12), 1, 1e-5);
  // Convolution arcs shape: sum minus threshold.
  const Shape s = convolutionArcs({ c, c }, { 0.9, 0.9 }, { 180, 180 },
    { { 0, 0, 1 }, { 0, 0, 1 } }, { 0, 180 }, { 1.3, 1.3 }, 0.25);
  EXPECT_NEAR(at(s, 0.1, 0.2, 0.3), at(ring, 0.1, 0.2, 0.3) - 0.25, 1e-13);
}

TEST(Convolution, TriangleMatchesQuadrature)
{
  // The closed form against nested adaptive quadrature (Duffy map), random triangles and points,
  // including points in the triangle's plane.
  Random rng(314);
  double worst = 0;
  for (int i = 0; i < 60; ++i)
  {
    const std::array<Vec3, 3> t = { rng.point(-1, 1), rng.point(-1, 1), rng.point(-1, 1) };
    const double sk = rng.uniform(0.4, 3);
    Vec3 p = rng.point(-2, 2);
    if (i % 4 == 0)
    {
      // A point in the plane of the triangle (barycentric, possibly outside).
      const double u = rng.uniform(-0.5, 1.2);
      const double v = rng.uniform(-0.5, 1.2 - u);
      for (int k = 0; k < 3; ++k)
      {
        p[k] = t[0][k] + u * (t[1][k] - t[0][k]) + v * (t[2][k] - t[0][k]);
      }
    }
    const double closed = at(cauchyTriangleField(t, sk), p);
    const double numeric = triangleQuadrature(p, t, sk);
    worst = std::max(worst, std::fabs(closed - numeric) / numeric);
  }
  EXPECT_LT(worst, 1e-9);
  RecordProperty("worstRelativeError", std::to_string(worst));
  std::printf("triangle closed form vs quadrature: worst relative error %.3g\n", worst);
}

TEST(Convolution, TriangleRightAnglesOrderAndSplit)
{
  // Right angle at each corner (the altitude foot is a vertex of the longest edge's end), with
  // points on a vertex, an edge, inside and off the plane; and all six vertex orders.
  const std::array<Vec3, 3> t = { Vec3{ 0, 0, 0 }, Vec3{ 1, 0, 0 }, Vec3{ 0, 2, 0 } };
  const double sk = 1.5;
  const std::array<std::array<int, 3>, 6> orders = { { { 0, 1, 2 }, { 0, 2, 1 }, { 1, 0, 2 },
    { 1, 2, 0 }, { 2, 0, 1 }, { 2, 1, 0 } } };
  for (const Vec3& p : { Vec3{ 0, 0, 0 }, Vec3{ 0.5, 0, 0 }, Vec3{ 0.2, 0.3, 0 },
         Vec3{ 0.5, 0.5, 0.3 }, Vec3{ -1, 3, -0.5 } })
  {
    const double numeric = triangleQuadrature(p, t, sk);
    for (const auto& o : orders)
    {
      const double closed = at(cauchyTriangleField({ t[o[0]], t[o[1]], t[o[2]] }, sk), p);
      EXPECT_NEAR(closed, numeric, 1e-10 * numeric);
    }
  }
  // Splitting at the midpoint of an edge: the two halves add up to the whole.
  const std::array<Vec3, 3> u = { Vec3{ -0.4, 0.1, 0.2 }, Vec3{ 0.8, -0.3, 0.0 },
    Vec3{ 0.1, 0.9, -0.3 } };
  const Vec3 mid = lerp(u[0], u[1], 0.5);
  const Expr whole = cauchyTriangleField(u, 0.9);
  const Expr split =
    cauchyTriangleField({ u[0], mid, u[2] }, 0.9) + cauchyTriangleField({ mid, u[1], u[2] }, 0.9);
  Random rng(8);
  for (int i = 0; i < 100; ++i)
  {
    const Vec3 p = rng.point(-2, 2);
    EXPECT_NEAR(at(split, p), at(whole, p), 1e-12 * at(whole, p));
  }
}

TEST(Convolution, TriangleFarFieldScalesAsAreaOverS4)
{
  // Far away, h(r) ~ 1/(s^4 r^4), so the field ~ area / (s^4 d^4). This pins the s scaling
  // (hfConvTriangle's formula is s^3 times the integral, which would fail for s != 1).
  const std::array<Vec3, 3> t = { Vec3{ 0, 0, 0 }, Vec3{ 1, 0, 0 }, Vec3{ 0.3, 0.8, 0 } };
  const double area = 0.5 * 0.8;
  for (double sk : { 0.5, 1.0, 2.0 })
  {
    const double d = 1000;
    const double f = at(cauchyTriangleField(t, sk), 0.6 * d, 0.0, 0.8 * d);
    EXPECT_NEAR(f / (area / (sk * sk * sk * sk * d * d * d * d)), 1, 5e-3) << "s = " << sk;
  }
  // And it decreases to 0.
  const Expr f = cauchyTriangleField(t, 1);
  EXPECT_GT(at(f, 0, 0, 10), at(f, 0, 0, 100));
  EXPECT_LT(at(f, 0, 0, 1e6), 1e-24);
  EXPECT_GE(at(f, 0, 0, 1e6), 0);
}

TEST(Convolution, CurveIsSumOfSegments)
{
  const std::vector<Vec3> polyline = { { 0, 0, 0 }, { 1, 0, 0 }, { 1, 1, 0 }, { 1, 1, 1 } };
  const Shape curve = convolutionCurve(polyline, 1.2, 0.3);
  const Shape segments = convolutionSegments(
    { { polyline[0], polyline[1] }, { polyline[1], polyline[2] }, { polyline[2], polyline[3] } },
    { 1.2, 1.2, 1.2 }, 0.3);
  // Collinear polyline = one straight segment (superposition).
  const Shape straight = convolutionCurve({ { 0, 0, 0 }, { 0.25, 0.5, 0 }, { 1, 2, 0 } }, 2, 0);
  const Expr segment = cauchySegmentField({ 0, 0, 0 }, { 1, 2, 0 }, 2);
  Random rng(17);
  for (int i = 0; i < 50; ++i)
  {
    const Vec3 p = rng.point(-1, 2);
    EXPECT_NEAR(at(curve, p), at(segments, p), 1e-14);
    EXPECT_NEAR(at(straight, p), at(segment, p), 1e-13 * at(segment, p));
  }
}

TEST(Convolution, MeshIsSumOfTriangles)
{
  // A unit square as two triangles (0-based indices) equals the two triangle fields; the square's
  // field is symmetric about its center.
  const std::vector<Vec3> vertices = { { 0, 0, 0 }, { 1, 0, 0 }, { 1, 1, 0 }, { 0, 1, 0 } };
  const Shape mesh = convolutionMesh(vertices, { { 0, 1, 2 }, { 0, 2, 3 } }, 1.1, 0.2);
  const Shape triangles = convolutionTriangles(
    { { vertices[0], vertices[1], vertices[2] }, { vertices[0], vertices[2], vertices[3] } },
    { 1.1, 1.1 }, 0.2);
  Random rng(23);
  for (int i = 0; i < 50; ++i)
  {
    const Vec3 p = rng.point(-1, 2);
    EXPECT_NEAR(at(mesh, p), at(triangles, p), 1e-14);
    EXPECT_NEAR(at(mesh, p) + 0.2, at(mesh, { 1 - p[0], 1 - p[1], -p[2] }) + 0.2, 1e-12);
  }
  // At the square's center, against quadrature of both halves.
  const Vec3 c = { 0.5, 0.5, 0.25 };
  const double numeric = triangleQuadrature(c, { vertices[0], vertices[1], vertices[2] }, 1.1) +
    triangleQuadrature(c, { vertices[0], vertices[2], vertices[3] }, 1.1);
  EXPECT_NEAR(at(mesh, c), numeric - 0.2, 1e-11);
}

// --- noise and perturbation
// ---------------------------------------------------------------------------

TEST(Noise, GardnerSeries)
{
  // amplitude 1, frequency pi/2, phase 0 at (1,1,1): each series is sin(pi/2) + sin(pi/2.7)/1.17
  // = 1 + sin(pi/2.7)/1.17, and the noise is its cube.
  const Expr n = gardnerNoise(1, pi / 2, 0);
  const double series = 1 + std::sin(pi / 2 / 1.35) / 1.17;
  EXPECT_NEAR(at(n, 1, 1, 1), series * series * series, 1e-14);
  // With a phase the series couple: hfNoiseG's formula transcribed at (0.3, -0.7, 1.1).
  const double A = 0.25, w = 12, ph = 1.4;
  const double x = 0.3, y = -0.7, z = 1.1;
  const double sx = std::sin(w * x), sy = std::sin(w * y), sz = std::sin(w * z);
  const double expected = (A * sx + A / 1.17 * std::sin(w * x / 1.35 + ph * sz)) *
    (A * sy + A / 1.17 * std::sin(w * y / 1.35 + ph * sx)) *
    (A * sz + A / 1.17 * std::sin(w * z / 1.35 + ph * sy));
  const Expr walnut = gardnerNoise(A, w, ph);
  EXPECT_NEAR(at(walnut, x, y, z), expected, 1e-15);
  // On a coordinate axis two coordinates are 0, and the series of the one after them (cyclically)
  // is A sin(0) + A/1.17 sin(0 + phase sin(0)) = 0: the noise vanishes on the axes.
  EXPECT_EQ(at(walnut, 0.37, 0, 0), 0);
  EXPECT_EQ(at(walnut, 0, -0.81, 0), 0);
  EXPECT_EQ(at(walnut, 0, 0, 0.55), 0);
  // Each series is linear in the amplitude, so the noise scales with its cube.
  EXPECT_NEAR(at(gardnerNoise(2 * A, w, ph), x, y, z), 8 * expected, 1e-14);
}

TEST(Perturbation, VyatkinTable)
{
  // papers.md 2.2 / 5.B item 30: F = 1 - |X|^2, Q = 0.25 - |X - (1,0,0)|^2.
  // F'(1,0,0) = 0 + k 0.25^3 = k / 64; crossings on +x as listed.
  const Shape base = sphere({ 0, 0, 0 }, 1);
  const Shape q = sphere({ 1, 0, 0 }, 0.5);
  struct Row
  {
    double k, value, crossing, lo, hi;
  };
  const Row rows[] = {
    { 1, 0.015625, 1.0077766, 1.0, 1.4 },
    { 10, 0.15625, 1.0709777, 1.0, 1.4 },
    { -1, -0.015625, 0.992163, 0.5, 1.0 },
    { -10, -0.15625, 0.9242621, 0.5, 1.0 },
  };
  for (const Row& r : rows)
  {
    const Shape p = perturb(base, { q }, { r.k });
    EXPECT_DOUBLE_EQ(at(p, 1, 0, 0), r.value) << "k = " << r.k;
    const double x = bisect([&](double t) { return at(p, t, 0, 0); }, r.lo, r.hi);
    EXPECT_NEAR(x, r.crossing, 1e-6) << "k = " << r.k;
  }
}

TEST(Perturbation, LocalityOrderAndSupport)
{
  const Shape base = ellipsoid({ 0, 0, 0 }, 1, 0.8, 0.6);
  const Shape q1 = sphere({ 1, 0, 0 }, 0.4);
  const Shape q2 =
    quadric({ -4, -4, -4, 0, 0, 0, 0, 0, -4 * 2 * 0.5, 1 - 4 * 0.25 }); // 1 - 4|X - (0,0,-0.5)|^2
  const Shape p12 = perturb(base, { q1, q2 }, { 2, -3 });
  const Shape p21 = perturb(base, { q2, q1 }, { -3, 2 });
  Random rng(41);
  int outside = 0;
  for (int i = 0; i < 400; ++i)
  {
    const Vec3 p = rng.point(-1.5, 1.5);
    const double f = at(base, p);
    const double a = at(q1, p);
    const double b = at(q2, p);
    // Eq. (2)-(3) by hand.
    const double expected = f + 2 * (a > 0 ? a * a * a : 0) - 3 * (b > 0 ? b * b * b : 0);
    EXPECT_NEAR(at(p12, p), expected, 1e-14);
    // Order of the perturbations does not matter.
    EXPECT_EQ(at(p12, p), at(p21, p));
    if (a < 0 && b < 0)
    {
      // Outside every support F' is F, bit for bit (papers.md 5.B item 27).
      EXPECT_EQ(at(p12, p), f);
      ++outside;
    }
  }
  EXPECT_GT(outside, 100);
  // No perturbation: the base field.
  EXPECT_EQ(at(perturb(base, {}, {}), 0.2, 0.1, 0), at(base, 0.2, 0.1, 0));
}

// --- every evaluator ----------------------------------------------------------------------------

TEST(Evaluators, EveryPrimitiveOnEveryEvaluator)
{
  // The compiled point and gradient evaluators agree with the reference evaluator, and interval
  // evaluation over small boxes encloses the sampled values without NaN (no sqrt of a negative,
  // no division by zero anywhere in the built expressions).
  const Vec3 o = { 0, 0, 0 };
  const std::vector<Shape> shapes = {
    sphere({ 0.1, 0, 0 }, 1),
    ellipsoid(o, 1, 0.7, 0.5),
    block({ -0.5, -0.5, -0.5 }, 1, 1, 1),
    blockRFunction({ -0.5, -0.5, -0.5 }, 1, 1, 1, 0.0),
    blockRFunction({ -0.5, -0.5, -0.5 }, 1, 1, 1, 0.99),
    cylinder(Axis::Y, o, 0.5),
    ellipticCylinder(Axis::Z, o, 0.5, 0.3),
    cone(Axis::X, o, 0.5),
    ellipticCone(Axis::Y, o, 0.5, 0.3),
    torus(Axis::Z, o, 1, 0.3),
    superellipsoid(o, 1, 0.8, 0.6, 0.4, 1.7),
    quadric({ 1, -2, 0.5, 0.3, 0, 1, 0, 0, -1, 0.2 }),
    halfSpace(o, { 1, 2, 3 }),
    blobby({ o, { 0.5, 0, 0 } }, { 2, 3 }, { 1, 0.5 }, 0.3),
    metaball({ o, { 0.5, 0, 0 } }, { 1, 0.7 }, { 1, 0.8 }, 0.3),
    softObject({ o, { 0.3, 0.2, 0 } }, { 1, 0.7 }, 0.3),
    convolutionPoints({ o }, { 2 }, 0.1),
    convolutionSegments({ { Vec3{ -0.5, 0, 0 }, Vec3{ 0.5, 0.2, 0 } } }, { 2 }, 0.3),
    convolutionArcs({ o }, { 0.6 }, { 270 }, { { 1, 1, 0 } }, { 40 }, { 2 }, 0.2),
    convolutionTriangles({ { Vec3{ 0, 0, 0 }, Vec3{ 1, 0, 0 }, Vec3{ 0, 1, 0.2 } } }, { 1.5 }, 0.2),
    convolutionCurve({ o, { 0.5, 0, 0 }, { 0.5, 0.5, 0 } }, 2, 0.3),
    convolutionMesh(
      { o, { 1, 0, 0 }, { 1, 1, 0 }, { 0, 1, 0 } }, { { 0, 1, 2 }, { 0, 2, 3 } }, 1.5, 0.2),
    Shape(sphere(o, 1).function() + gardnerNoise(0.25, 12, 1.4), Domain::XYZ, "noisy"),
    perturb(sphere(o, 1), { sphere({ 1, 0, 0 }, 0.5) }, { -3 }),
  };
  Random rng(77);
  for (const Shape& shape : shapes)
  {
    const TapePtr tape = Tape::compile(shape.function());
    PointEvaluator point(tape);
    GradientEvaluator gradient(tape);
    IntervalEvaluator interval(tape);
    for (int box = 0; box < 20; ++box)
    {
      Region region;
      const Vec3 c = rng.point(-1.2, 1.2);
      const double w = box < 10 ? 0.05 : 0.4;
      for (int k = 0; k < 3; ++k)
      {
        region.axes[k] = { c[k] - w, c[k] + w };
      }
      region.axes[3] = { 0, 0 };
      const Interval range = interval.eval(region);
      // Known limitation of the interval evaluator (Evaluators.cxx, Opcode::Pow): a^b with a
      // non-integer b gives [-inf, inf] "maybe NaN" unless a.lo > 0, so the superellipsoid's
      // |x'|^(2/s2) is unbounded on boxes that straddle a coordinate plane through its center.
      bool straddlesCenterPlane = false;
      for (int k = 0; k < 3; ++k)
      {
        straddlesCenterPlane = straddlesCenterPlane || (c[k] - w <= 0 && c[k] + w >= 0);
      }
      if (!(shape.label() == "superellipsoid" && straddlesCenterPlane))
      {
        EXPECT_FALSE(range.maybeNaN) << shape.label();
      }
      for (int i = 0; i < 10; ++i)
      {
        const Vec3 p = { rng.uniform(c[0] - w, c[0] + w), rng.uniform(c[1] - w, c[1] + w),
          rng.uniform(c[2] - w, c[2] + w) };
        const double reference = at(shape, p);
        ASSERT_TRUE(std::isfinite(reference)) << shape.label();
        const double tolerance = 1e-12 * (1 + std::fabs(reference));
        EXPECT_NEAR(point.eval(p[0], p[1], p[2]), reference, tolerance) << shape.label();
        EXPECT_NEAR(gradient.eval(p[0], p[1], p[2]).value, reference, tolerance) << shape.label();
        EXPECT_LE(range.lo, reference + tolerance) << shape.label();
        EXPECT_GE(range.hi, reference - tolerance) << shape.label();
      }
    }
  }
}

// --- bad input ---------------------------------------------------------------------------------

TEST(BadInput, SizesAndNumbers)
{
  expectInvalid([] { interval(2, 1); }, { "interval", "a must be less than b" });
  expectInvalid([] { interval(notANumber, 1); }, { "interval", "a", "finite" });
  expectInvalid([] { timeInterval(1, 1); }, { "timeInterval", "t0" });
  expectInvalid([] { circle({ 0, 0 }, 0); }, { "circle", "radius r", "positive" });
  expectInvalid([] { circle({ notANumber, 0 }, 1); }, { "circle", "center" });
  expectInvalid([] { ellipse({ 0, 0 }, -1, 1); }, { "ellipse", "half-axis a" });
  expectInvalid([] { rectangle({ 0, 0 }, 1, 0); }, { "rectangle", "side dy" });
  expectInvalid([] { sphere({ 0, 0, 0 }, -1); }, { "sphere", "radius r", "positive", "-1" });
  expectInvalid([] { sphere({ 0, 0, 0 }, notANumber); }, { "sphere", "radius r", "finite" });
  expectInvalid([] { sphere({ 0, infinity, 0 }, 1); }, { "sphere", "center" });
  expectInvalid([] { ellipsoid({ 0, 0, 0 }, 1, 0, 1); }, { "ellipsoid", "half-axis b" });
  expectInvalid([] { block({ 0, 0, 0 }, 1, 1, -1); }, { "block", "side dz" });
  expectInvalid([] { blockRFunction({ 0, 0, 0 }, 1, 1, 1, 1.5); }, { "blockRFunction", "alpha" });
  expectInvalid([] { blockRFunction({ 0, 0, 0 }, 1, 1, 1, -1); }, { "blockRFunction", "alpha" });
  expectInvalid([] { cylinder(Axis::T, { 0, 0, 0 }, 1); }, { "cylinder", "axis" });
  expectInvalid([] { cylinder(Axis::Z, { 0, 0, 0 }, infinity); }, { "cylinder", "radius r" });
  expectInvalid(
    [] {
      ellipticCylinder(Axis::X, { 0, 0, 0 }, 0, 1);
    },
    { "ellipticCylinder", "half-axis a" });
  expectInvalid([] { cone(Axis::Y, { 0, 0, 0 }, 0); }, { "cone", "radius r" });
  expectInvalid(
    [] {
      ellipticCone(Axis::Z, { 0, 0, 0 }, 1, notANumber);
    },
    { "ellipticCone", "half-axis b" });
  expectInvalid([] { torus(Axis::Z, { 0, 0, 0 }, 0, 1); }, { "torus", "radius of revolution R" });
  expectInvalid([] { torus(Axis::Z, { 0, 0, 0 }, 1, -0.5); }, { "torus", "tube radius r" });
  expectInvalid(
    [] {
      superellipsoid({ 0, 0, 0 }, 1, 1, 1, 0, 1);
    },
    { "superellipsoid", "shape exponent s1" });
  expectInvalid([] { quadric({ 0, 0, 0, 0, 0, 0, 0, 0, 0, 0 }); }, { "quadric", "zero" });
  expectInvalid([] { quadric({ 1, 0, 0, 0, 0, notANumber, 0, 0, 0, 0 }); }, { "quadric", "A23" });
  expectInvalid([] { halfSpace({ 0, 0, 0 }, { 0, 0, 0 }); }, { "halfSpace", "inwardNormal" });
}

TEST(BadInput, SkeletalVectors)
{
  expectInvalid(
    [] {
      blobby({ { 0, 0, 0 }, { 1, 0, 0 } }, { 1 }, { 1, 1 }, 0.5);
    },
    { "blobby", "centers", "a", "same length", "2", "1" });
  expectInvalid(
    [] {
      blobby({ { 0, 0, 0 }, { 1, 0, 0 } }, { 1, -1 }, { 1, 1 }, 0.5);
    },
    { "blobby", "a[1]" });
  expectInvalid([] { blobby({}, {}, {}, 0.5); }, { "blobby", "centers", "empty" });
  expectInvalid(
    [] {
      blobby({ { 0, 0, 0 } }, { 1 }, { 1 }, notANumber);
    },
    { "blobby", "threshold" });
  expectInvalid([] { metaball({ { 0, 0, 0 } }, { 1 }, { 0 }, 0.5); }, { "metaball", "d[0]" });
  expectInvalid(
    [] {
      metaball({ { 0, 0, 0 } }, { 1, 2 }, { 1 }, 0.5);
    },
    { "metaball", "b", "same length" });
  expectInvalid(
    [] {
      softObject({ { 0, 0, 0 } }, { 1, 1 }, 0.5);
    },
    { "softObject", "d", "same length" });
  expectInvalid(
    [] {
      softObject({ { 0, notANumber, 0 } }, { 1 }, 0.5);
    },
    { "softObject", "centers[0]" });
}

TEST(BadInput, ConvolutionSkeletons)
{
  expectInvalid(
    [] {
      convolutionPoints({ { 0, 0, 0 } }, { 0 }, 0.5);
    },
    { "convolutionPoints", "kernel width s", "points[0]" });
  expectInvalid(
    [] {
      convolutionPoints({ { 0, 0, 0 } }, { 1, 1 }, 0.5);
    },
    { "convolutionPoints", "same length" });
  expectInvalid(
    [] {
      convolutionSegments({ { Vec3{ 1, 1, 1 }, Vec3{ 1, 1, 1 } } }, { 1 }, 0.5);
    },
    { "convolutionSegments", "segments[0]", "zero length" });
  expectInvalid(
    [] {
      convolutionSegments({ { Vec3{ 0, 0, 0 }, Vec3{ 1, 1, 1 } } }, {}, 0.5);
    },
    { "convolutionSegments", "s", "same length" });
  const Vec3 o = { 0, 0, 0 };
  const Vec3 z = { 0, 0, 1 };
  expectInvalid([&] { convolutionArcs({ o }, { 1 }, { 0 }, { z }, { 0 }, { 1 }, 0.5); },
    { "convolutionArcs", "theta of arc 0" });
  expectInvalid([&] { convolutionArcs({ o }, { 1 }, { 400 }, { z }, { 0 }, { 1 }, 0.5); },
    { "convolutionArcs", "theta of arc 0", "360" });
  expectInvalid([&] { convolutionArcs({ o }, { -1 }, { 90 }, { z }, { 0 }, { 1 }, 0.5); },
    { "convolutionArcs", "radius of arc 0" });
  expectInvalid([&] { convolutionArcs({ o }, { 1 }, { 90 }, { o }, { 30 }, { 1 }, 0.5); },
    { "convolutionArcs", "axis of arc 0" });
  expectInvalid(
    [&] {
      convolutionArcs({ o }, { 1 }, { 90, 90 }, { z }, { 0 }, { 1 }, 0.5);
    },
    { "convolutionArcs", "thetas", "same length" });
  expectInvalid([&] { convolutionArcs({ o }, { 1 }, { 90 }, { z }, { notANumber }, { 1 }, 0.5); },
    { "convolutionArcs", "angle of arc 0" });
  // A zero axis with a zero angle is fine (nothing to rotate).
  EXPECT_NO_THROW(convolutionArcs({ o }, { 1 }, { 90 }, { o }, { 0 }, { 1 }, 0.5));
  expectInvalid(
    [] {
      convolutionTriangles({ { Vec3{ 0, 0, 0 }, Vec3{ 1, 1, 1 }, Vec3{ 2, 2, 2 } } }, { 1 }, 0.5);
    },
    { "convolutionTriangles", "triangles[0]", "degenerate" });
  expectInvalid(
    [] {
      convolutionCurve({ { 0, 0, 0 } }, 1, 0.5);
    },
    { "convolutionCurve", "polyline", "2" });
  expectInvalid(
    [] {
      convolutionCurve({ { 0, 0, 0 }, { 1, 0, 0 }, { 1, 0, 0 } }, 1, 0.5);
    },
    { "convolutionCurve", "segment 1", "zero length" });
  expectInvalid(
    [] {
      convolutionCurve({ { 0, 0, 0 }, { 1, 0, 0 } }, -2, 0.5);
    },
    { "convolutionCurve", "kernel width s" });
  const std::vector<Vec3> v = { { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 } };
  expectInvalid(
    [&] {
      convolutionMesh(v, { { 0, 1, 3 } }, 1, 0.5);
    },
    { "convolutionMesh", "triangles[0]", "vertex index 3" });
  expectInvalid(
    [&] {
      convolutionMesh(v, { { -1, 1, 2 } }, 1, 0.5);
    },
    { "convolutionMesh", "vertex index -1" });
  expectInvalid(
    [&] {
      convolutionMesh(v, { { 0, 1, 2 } }, 0, 0.5);
    },
    { "convolutionMesh", "kernel width s" });
  expectInvalid(
    [&] {
      convolutionMesh(v, { { 0, 1, 1 } }, 1, 0.5);
    },
    { "convolutionMesh", "degenerate" });
}

TEST(BadInput, NoiseAndPerturbation)
{
  expectInvalid([] { gardnerNoise(notANumber, 1, 1); }, { "gardnerNoise", "amplitude" });
  expectInvalid([] { gardnerNoise(1, infinity, 1); }, { "gardnerNoise", "frequency" });
  const Shape base = sphere({ 0, 0, 0 }, 1);
  const Shape q = sphere({ 1, 0, 0 }, 0.5);
  expectInvalid([&] { perturb(base, { q }, { 1, 2 }); }, { "perturb", "factors", "same length" });
  expectInvalid([&] { perturb(base, { q }, { notANumber }); }, { "perturb", "factors[0]" });
  EXPECT_THROW(perturb(base, { circle({ 0, 0 }, 1) }, { 1 }), DomainError);
}
