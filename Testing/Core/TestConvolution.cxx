// SPDX-License-Identifier: BSD-3-Clause
// Tests of the FRep convolution surfaces (points, segments, arcs, triangles, curves, meshes) and
// their bad input. The fields are checked against numerical quadrature written here (adaptive
// Gauss-Kronrod 7-15), independent of the closed forms in Primitives.cxx.
#include "PrimitivesTesting.h"

#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

using namespace ictk::frep;
using namespace primitivestest;

namespace
{

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

} // namespace

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
