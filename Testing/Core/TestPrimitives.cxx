// SPDX-License-Identifier: BSD-3-Clause
// Tests of the FRep primitive library: the 1D, 2D and 3D primitives, the skeletal ones, noise and
// perturbation, every primitive on every evaluator, and bad input. Expected numbers are derived by
// hand in the comments. The convolution surfaces, checked against quadrature, are in
// TestConvolution.cxx; both share PrimitivesTesting.h.
#include "FRep/Tape.h"
#include "PrimitivesTesting.h"

#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

using namespace ictk::frep;
using namespace primitivestest;

namespace
{

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
  // g = 1 + 4 - sqrt(1 + 16) = 5 - sqrt(17), then g + 9 - sqrt(g^2 + 81) = 0.83427618362456564...
  // (50-digit decimal arithmetic). That formula in doubles is 2e-15 off (its cancellation); the
  // kernel's R-intersection, computed without it, is within 2 ulps.
  const double ulp2 = 2 * std::numeric_limits<double>::epsilon();
  const Shape s0 = blockRFunction({ 0, 0, 0 }, 2, 4, 6, 0.0);
  EXPECT_NEAR(at(s0, 1, 2, 3), 0.83427618362456564, ulp2 * 0.83);
  // With alpha = 0.5: g = 5 - sqrt(1 + 16 - 4) = 5 - sqrt(13), then
  // g + 9 - sqrt(g^2 + 81 - 9 g) = 2.0043087540387359...
  const Shape s5 = blockRFunction({ 0, 0, 0 }, 2, 4, 6, 0.5);
  EXPECT_NEAR(at(s5, 1, 2, 3), 2.0043087540387359, ulp2 * 2);
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
