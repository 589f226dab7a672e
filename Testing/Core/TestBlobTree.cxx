// SPDX-License-Identifier: BSD-3-Clause
// Tests of the BlobTree (seed 004, papers.md section 3; items 40-48 and 57-59 of section 5.C):
// kernel values at hand-computed distances, distances against brute-force minimisation over the
// skeleton, the operators' numbers from the spec, the context rule, warps, the expansion of
// generalised cylinders and animation. The lowered expression is checked against the direct tree
// traversal, and interval bounds against samples.
#include "FRep/BlobTree.h"
#include "FRep/Evaluators.h"
#include "FRep/Tape.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace ictk::frep;
using namespace ictk::frep::blob;

namespace
{

double wyvillByHand(double d, double R)
{
  if (d >= R)
  {
    return 0;
  }
  const double q = d * d / (R * R);
  return 1 - 22.0 / 9 * q + 17.0 / 9 * q * q - 4.0 / 9 * q * q * q;
}

// One element alone.
BlobTree single(Kind kind, const std::vector<double>& values)
{
  BlobTree t;
  t.add(kind, values);
  return t;
}

double fieldAt(const BlobTree& t, const Vec3& p)
{
  PointEvaluator e(Tape::compile(potential(t)));
  return e.eval(p[0], p[1], p[2]);
}

// The skeleton as a function of a parameter, for brute-force distances.
double bruteDistance(const std::function<Vec3(double)>& c, const Vec3& p, int samples = 200001)
{
  double best = 1e300;
  for (int i = 0; i < samples; ++i)
  {
    const Vec3 q = c(static_cast<double>(i) / (samples - 1));
    best = std::min(best, std::hypot(p[0] - q[0], p[1] - q[1], p[2] - q[2]));
  }
  return best;
}

// A random box of a test of bounds: for each axis its low corner drawn from `corner`, then its
// side from `side` (lo and size give them back for sampling inside); t fixed at 0.
Region randomRegion(std::mt19937& rng, std::uniform_real_distribution<double>& corner,
  std::uniform_real_distribution<double>& side, std::array<double, 3>& lo,
  std::array<double, 3>& size)
{
  Region region;
  for (int k = 0; k < 3; ++k)
  {
    lo[k] = corner(rng);
    size[k] = side(rng);
    region.axes[k] = Interval{ lo[k], lo[k] + size[k] };
  }
  region.axes[3] = Interval{ 0, 0 };
  return region;
}

} // namespace

TEST(BlobTree, KernelAtKnownDistances)
{
  EXPECT_DOUBLE_EQ(kernel(0, 2), 1.0);
  EXPECT_DOUBLE_EQ(kernel(1, 2), 0.5); // g(R/2) = 1/2: the surface at R/2 for T = 0.5
  EXPECT_DOUBLE_EQ(kernel(4, 2), 0.0);
  EXPECT_DOUBLE_EQ(kernel(9, 2), 0.0);
  EXPECT_DOUBLE_EQ(kernel(1, 2, 3.0), 1.5);
  for (double d = 0; d < 2.5; d += 0.01)
  {
    EXPECT_NEAR(kernel(d * d, 2), wyvillByHand(d, 2), 1e-14);
  }
}

// Item 40: f == 0 for d >= R, non-increasing in d, and the values at hand-computed distances.
TEST(BlobTree, SkeletalElementsAtKnownDistances)
{
  const double R = 2;
  struct Case
  {
    Kind kind;
    std::vector<double> values;
    Vec3 p;
    double d;
  };
  const double s = 0.125, c = std::sqrt(1 - s * s);
  const Case cases[] = {
    { Kind::Point, { R, 1, 1, 2, 3 }, { 1, 2, 3.7 }, 0.7 },
    { Kind::Segment, { R, 1, 0, 0, 0, 2, 0, 0 }, { 1, 0.3, 0 }, 0.3 },
    { Kind::Segment, { R, 1, 0, 0, 0, 2, 0, 0 }, { 3, 0.4, 0 }, std::sqrt(1.16) },
    { Kind::Circle, { R, 1, 0, 0, 0, 0, 0, 3, 1 }, { 0, 0, 0.5 }, std::sqrt(1.25) },
    { Kind::Circle, { R, 1, 0, 0, 0, 0, 0, 3, 1 }, { 1.5, 0, 0 }, 0.5 },
    { Kind::Disc, { R, 1, 0, 0, 0, 0, 0, 1, 1 }, { 0.5, 0, 0.3 }, 0.3 },
    { Kind::Disc, { R, 1, 0, 0, 0, 0, 0, 1, 1 }, { 2, 0, 0.3 }, std::sqrt(1.09) },
    { Kind::Triangle, { R, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0 }, { 0.2, 0.2, 0.5 }, 0.5 },
    { Kind::Triangle, { R, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0 }, { -0.5, 0.5, 0 }, 0.5 },
    { Kind::Triangle, { R, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0 }, { 1, 1, 0 }, std::sqrt(0.5) },
    { Kind::Curve, { R, 1, 0, 0, 0, 1, 0, 0, 1, 1, 0 }, { 1.5, 0.5, 0 }, 0.5 },
    { Kind::Cylinder, { R, 1, 0, 0, 0, 0, 0, 4, 0.5 }, { 1.2, 0, 2 }, 0.7 },
    { Kind::ConeSphere, { R, 1, 0, 0, 0, 4, 0, 0, 1, 0.5 }, { 5.3, 0, 0 }, 0.8 },
    { Kind::ConeSphere, { R, 1, 0, 0, 0, 4, 0, 0, 1, 0.5 }, { -1.5, 0, 0 }, 0.5 },
    // the conical side: n.q - r0 with n = (sin, cos), sin = (r0 - r1) / L
    { Kind::ConeSphere, { R, 1, 0, 0, 0, 4, 0, 0, 1, 0.5 }, { 2, 1.5, 0 }, 2 * s + 1.5 * c - 1 },
  };
  for (const Case& k : cases)
  {
    SCOPED_TRACE(kindName(k.kind));
    const BlobTree t = single(k.kind, k.values);
    EXPECT_NEAR(evaluate(t, k.p), wyvillByHand(k.d, R), 1e-12);
    EXPECT_NEAR(fieldAt(t, k.p), wyvillByHand(k.d, R), 1e-12);
  }
}

// The cone-sphere is the union of the spheres swept linearly from (a, r0) to (b, r1): its distance
// is min over t of |p - c(t)| - r(t), minimised by brute force here.
TEST(BlobTree, ConeSphereAgainstSweptSpheres)
{
  const BlobTree t = single(Kind::ConeSphere, { 3, 1, 0, 0, 0, 2, 1, 0, 0.8, 0.2 });
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-2, 4);
  for (int i = 0; i < 200; ++i)
  {
    const Vec3 p{ u(rng), u(rng), u(rng) };
    double best = 1e300;
    for (int k = 0; k <= 20000; ++k)
    {
      const double s = k / 20000.0;
      best = std::min(best, std::hypot(p[0] - 2 * s, p[1] - s, p[2]) - (0.8 + (0.2 - 0.8) * s));
    }
    EXPECT_NEAR(evaluate(t, p), wyvillByHand(std::max(best, 0.0), 3), 1e-6);
  }
}

TEST(BlobTree, TriangleAndCircleAgainstBruteForce)
{
  const BlobTree tri = single(Kind::Triangle, { 3, 1, 0, 0, 0, 2, 0, 0.5, 0.3, 1.5, 0.2 });
  const BlobTree circle = single(Kind::Circle, { 3, 1, 0.5, 0, 0, 1, 1, 1, 1.2 });
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.5, 2.5);
  const Vec3 n{ 1 / std::sqrt(3.0), 1 / std::sqrt(3.0), 1 / std::sqrt(3.0) };
  const Vec3 e1{ 1 / std::sqrt(2.0), -1 / std::sqrt(2.0), 0 };
  const Vec3 e2{ n[1] * e1[2] - n[2] * e1[1], n[2] * e1[0] - n[0] * e1[2],
    n[0] * e1[1] - n[1] * e1[0] };
  for (int i = 0; i < 40; ++i)
  {
    const Vec3 p{ u(rng), u(rng), u(rng) };
    // The triangle as a 2D family: a + s (b - a) + s t (c - b), sampled on an 800^2 grid.
    double best = 1e300;
    for (int a = 0; a <= 800; ++a)
    {
      const double s = a / 800.0;
      best = std::min(best,
        bruteDistance(
          [&](double w) {
            return Vec3{ 2 * s + s * w * (0.3 - 2), 1.5 * s * w, 0.5 * s + s * w * (0.2 - 0.5) };
          },
          p, 801));
    }
    EXPECT_NEAR(evaluate(tri, p), wyvillByHand(best, 3), 5e-3);
    const double d = bruteDistance(
      [&](double w)
      {
        const double a = 2 * M_PI * w;
        return Vec3{ 0.5 + 1.2 * (std::cos(a) * e1[0] + std::sin(a) * e2[0]),
          1.2 * (std::cos(a) * e1[1] + std::sin(a) * e2[1]),
          1.2 * (std::cos(a) * e1[2] + std::sin(a) * e2[2]) };
      },
      p);
    EXPECT_NEAR(evaluate(circle, p), wyvillByHand(d, 3), 1e-6);
  }
}

// Item 40: the box short-circuit (no kernel evaluated outside bbox + R), exactly 0 for the
// interval evaluator there, and intervals that hold every sampled value elsewhere.
TEST(BlobTree, BoundingBoxShortCircuitAndIntervals)
{
  BlobTree t;
  const auto a = t.add(Kind::Segment, { 1, 1, 0, 0, 0, 2, 0, 0 });
  const auto b = t.add(Kind::Disc, { 0.8, 1, 0, 2, 0, 0, 1, 1, 0.5 });
  const auto c = t.add(Kind::Triangle, { 1, 1, 0, 0, 1, 1, 0, 1, 0, 1, 2 });
  t.add(Kind::Blend, {}, { a, b, c });
  std::size_t kernels = 0;
  EXPECT_EQ(evaluate(t, { 0, -1.5, 0 }, &kernels), 0.0);
  EXPECT_EQ(kernels, 0u); // outside every box: nothing evaluated
  EXPECT_GT(evaluate(t, { 1.5, -0.5, -0.5 }, &kernels), 0.0);
  EXPECT_EQ(kernels, 1u); // only the segment's box holds the point

  const TapePtr tape = Tape::compile(potential(t));
  IntervalEvaluator interval(tape);
  Region outside;
  outside.axes = { Interval{ 3.5, 4 }, Interval{ -3, -2.5 }, Interval{ 0, 1 }, Interval{ 0, 0 } };
  const Interval none = interval.eval(outside);
  EXPECT_LE(std::fabs(none.lo), 1e-300); // 0 up to the outward rounding
  EXPECT_LE(std::fabs(none.hi), 1e-300);
  EXPECT_LT(interval.simplified()->instructions().size(), 3u);

  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.5, 3.5), w(0.05, 1.0);
  PointEvaluator point(tape);
  for (int r = 0; r < 200; ++r)
  {
    std::array<double, 3> lo{}, size{};
    const Interval bound = interval.eval(randomRegion(rng, u, w, lo, size));
    for (int s = 0; s < 100; ++s)
    {
      std::array<double, 3> p{};
      for (int k = 0; k < 3; ++k)
      {
        p[k] = lo[k] + size[k] * (s == 0 ? 0.0 : std::uniform_real_distribution<double>(0, 1)(rng));
      }
      const double f = point.eval(p[0], p[1], p[2]);
      ASSERT_TRUE(bound.contains(f)) << f << " not in [" << bound.lo << ", " << bound.hi << "]";
    }
  }
}

TEST(BlobTree, ExpressionMatchesTraversal)
{
  BlobTree t;
  std::vector<std::uint32_t> leaves;
  leaves.push_back(t.add(Kind::Point, { 1.2, 1, 0, 0, 0 }));
  leaves.push_back(t.add(Kind::Segment, { 1, 0.8, 0, 0, 0, 1, 1, 0 }));
  leaves.push_back(t.add(Kind::Circle, { 0.7, 1, 0, 0, 1, 0, 1, 0, 0.8 }));
  leaves.push_back(t.add(Kind::Disc, { 0.7, 1, 1, 0, 0, 1, 0, 0, 0.5 }));
  leaves.push_back(t.add(Kind::Triangle, { 0.6, 1.2, 0, 0, 0, 1, 0, 0, 0, 0, 1 }));
  leaves.push_back(t.add(Kind::Curve, { 0.5, 1, -1, 0, 0, -1, 1, 0, -1, 1, 1 }));
  leaves.push_back(t.add(Kind::Cylinder, { 0.5, 1, 0, -1, 0, 0, -1, 1, 0.2 }));
  leaves.push_back(t.add(Kind::ConeSphere, { 0.5, 1, 1, 1, 1, 1.5, 1.5, 1.5, 0.3, 0.1 }));
  const auto u = t.add(Kind::Union, {}, { leaves[0], leaves[1] });
  const auto d = t.add(Kind::Difference, {}, { leaves[2], leaves[3] });
  const auto h = t.add(Kind::HyperBlend, { 3 }, { u, d });
  const auto l = t.add(Kind::LocalBlend, {}, { h, leaves[4], leaves[5] });
  const auto r = t.add(Kind::Rotate, { 1, 2, 3, 0.7 }, { leaves[6] });
  const auto tw = t.add(Kind::Twist, { 0.9 }, { leaves[7] });
  const auto sc = t.add(Kind::Scale, { 1.5, 0.5, 2 }, { tw });
  const auto i = t.add(Kind::Intersection, {}, { r, sc });
  const auto tr = t.add(Kind::Translate, { 0.1, -0.2, 0.3 }, { i });
  t.add(Kind::Blend, {}, { l, tr });
  PointEvaluator e(Tape::compile(potential(t)));
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> x(-2, 2.5);
  int nonZero = 0;
  for (int k = 0; k < 3000; ++k)
  {
    const Vec3 p{ x(rng), x(rng), x(rng) };
    const double f = evaluate(t, p);
    nonZero += f != 0;
    EXPECT_NEAR(e.eval(p[0], p[1], p[2]), f, 1e-12 * (1 + std::fabs(f)));
  }
  EXPECT_GT(nonZero, 300);
  // Outside the support box every element vanishes. The potential is then 0, except that a
  // difference below a blend is the R-intersection of 0 with 2T - 0, which is (2 - sqrt 2) T
  // (docs/blobtree.md: the T-normalised difference is not compactly supported).
  const auto box = supportBox(t);
  for (int k = 0; k < 200; ++k)
  {
    const Vec3 p{ box[1][0] + 0.01 + std::fabs(x(rng)), x(rng), x(rng) };
    EXPECT_NEAR(evaluate(t, p), (2 - std::sqrt(2.0)) * 0.5, 1e-15);
  }
  BlobTree plain = t;
  plain.setRoot(tr); // the same without the blend above: min/max, compact
  const auto plainBox = supportBox(plain);
  for (int k = 0; k < 200; ++k)
  {
    const Vec3 p{ x(rng), plainBox[0][1] - 0.01 - std::fabs(x(rng)), x(rng) };
    EXPECT_EQ(evaluate(plain, p), 0.0);
  }
}

// Items 41-44.
TEST(BlobTree, BlendOperatorNumbers)
{
  EXPECT_NEAR(hyperBlend(0.3, 0.6, 1), 0.9, 1e-5);
  EXPECT_NEAR(hyperBlend(0.3, 0.6, 2), 0.67082, 1e-5);
  EXPECT_NEAR(hyperBlend(0.3, 0.6, 8), 0.60029, 1e-5);
  EXPECT_NEAR(hyperBlend(0.3, 0.6, 64), 0.6, 1e-5);
  EXPECT_DOUBLE_EQ(localBlend(0.3, 0.6, 0), 0.6);
  EXPECT_DOUBLE_EQ(localBlend(0.3, 0.6, 1), 0.9);
  EXPECT_DOUBLE_EQ(localBlend(0.3, 0.6, 0.5), 0.75);
  EXPECT_DOUBLE_EQ(localBlend(0.3, 0.6, 3), 0.9);  // f_R clamped to [0, 1]
  EXPECT_DOUBLE_EQ(localBlend(0.3, 0.6, -2), 0.6); // (line 76)
  EXPECT_DOUBLE_EQ(differenceMinMax(0.8, 0.0, 0.5), 0.8);
  EXPECT_NEAR(differenceMinMax(0.8, 0.9, 0.5), 0.1, 1e-15);
  EXPECT_DOUBLE_EQ(differenceMinMax(0.8, 0.5, 0.5), 0.5);

  // The same through trees: two points with known fields at the origin.
  BlobTree t;
  const auto a = t.add(Kind::Point, { 2, 1, 1, 0, 0 }); // f_A(0) = g(1/2)
  const auto b = t.add(Kind::Point, { 2, 1, 0, 1.5, 0 });
  const double fa = wyvillByHand(1, 2), fb = wyvillByHand(1.5, 2);
  t.add(Kind::Blend, {}, { a, b });
  EXPECT_NEAR(evaluate(t, { 0, 0, 0 }), fa + fb, 1e-15);
  BlobTree l;
  const auto la = l.add(Kind::Point, { 2, 1, 1, 0, 0 });
  const auto lb = l.add(Kind::Point, { 2, 1, 0, 1.5, 0 });
  const auto lr = l.add(Kind::Point, { 4, 1, 0, 0, 2 }); // f_R(0) = g(2; 4) = 0.5
  l.add(Kind::LocalBlend, {}, { la, lb, lr });
  EXPECT_NEAR(evaluate(l, { 0, 0, 0 }), 0.5 * (fa + fb) + 0.5 * std::max(fa, fb), 1e-15);
  EXPECT_NEAR(fieldAt(l, { 0, 0, 0 }), 0.5 * (fa + fb) + 0.5 * std::max(fa, fb), 1e-15);
  EXPECT_THROW(l.add(Kind::LocalBlend, {}, { la, lb }), std::invalid_argument); // 3 children
}

// Item 45.
TEST(BlobTree, RFunctionBooleans)
{
  const double T = 0.5;
  std::mt19937 rng(45);
  std::uniform_real_distribution<double> u(0, 1);
  auto sign = [](double v)
  {
    return (v > 0) - (v < 0);
  };
  for (int i = 0; i < 100000; ++i)
  {
    const double a = u(rng), b = u(rng);
    ASSERT_EQ(sign(unionR(a, b, T) - T), sign(std::max(a, b) - T));
    ASSERT_EQ(sign(intersectionR(a, b, T) - T), sign(std::min(a, b) - T));
  }
  for (double x = 0; x <= T; x += 0.01)
  {
    EXPECT_NEAR(unionR(x, x, T), x, 1e-15);
    EXPECT_NEAR(intersectionR(x, x, T), x, 1e-15);
  }
  // 0 up to the rounding of T + (u + v + sqrt(u^2 + v^2)) / (2 - sqrt 2) at u = v = -T (the
  // union's sum, -T (2 - sqrt 2), is computed without cancellation as a quotient, -1.1e-16 off).
  EXPECT_NEAR(unionR(0, 0, T), 0.0, 2e-16);
  EXPECT_NEAR(intersectionR(0, 0, T), 0.0, 2e-16);
  EXPECT_NEAR(unionR(0.7, 0.7, T), 1.665685, 5e-7);
  EXPECT_NEAR(intersectionR(0.7, 0.7, T), 0.534315, 5e-7);
  EXPECT_NEAR(unionR(1, 0, T), 1.707107, 5e-7);
  EXPECT_NEAR(intersectionR(1, 0, T), 0.292893, 5e-7);
}

// Item 46: min/max at the root, R-functions under a blend; the same iso-surface, and a C^1 field
// across f_A = f_B where max has a kink.
TEST(BlobTree, ContextDependentBooleans)
{
  auto twoPoints = [](bool underBlend)
  {
    BlobTree t;
    const auto a = t.add(Kind::Point, { 3, 1, -1, 0, 0 });
    const auto b = t.add(Kind::Point, { 3, 1, 1, 0, 0 });
    const auto u = t.add(Kind::Union, {}, { a, b });
    if (underBlend)
    {
      t.add(Kind::Blend, {}, { u }); // a blend of one child adds nothing but the context
    }
    return t;
  };
  const BlobTree root = twoPoints(false), below = twoPoints(true);
  const double fa = wyvillByHand(1.2, 3), fb = wyvillByHand(0.8, 3);
  EXPECT_NEAR(evaluate(root, { 0.2, 0, 0 }), std::max(fa, fb), 1e-15);
  EXPECT_NEAR(evaluate(below, { 0.2, 0, 0 }), unionR(fa, fb, 0.5), 1e-15);
  BlobTree maxBelow; // the max node ignores the context
  const auto ma = maxBelow.add(Kind::Point, { 3, 1, -1, 0, 0 });
  const auto mb = maxBelow.add(Kind::Point, { 3, 1, 1, 0, 0 });
  maxBelow.add(Kind::Blend, {}, { maxBelow.add(Kind::Max, {}, { ma, mb }) });
  EXPECT_NEAR(evaluate(maxBelow, { 0.2, 0, 0 }), std::max(fa, fb), 1e-15);
  auto sign = [](double v)
  {
    return (v > 0) - (v < 0);
  };
  std::mt19937 rng(46);
  std::uniform_real_distribution<double> u(-4, 4);
  for (int i = 0; i < 20000; ++i)
  {
    const Vec3 p{ u(rng), u(rng), u(rng) };
    ASSERT_EQ(sign(evaluate(root, p) - 0.5), sign(evaluate(below, p) - 0.5));
  }
  // Slopes on either side of x = 0, where f_A = f_B (> T, so the R-function is smooth there).
  auto slope = [](const BlobTree& t, double x)
  {
    const double h = 1e-6;
    return (evaluate(t, { x + h, 0.3, 0 }) - evaluate(t, { x - h, 0.3, 0 })) / (2 * h);
  };
  EXPECT_GT(std::fabs(slope(root, 1e-4) - slope(root, -1e-4)), 0.1);
  EXPECT_LT(std::fabs(slope(below, 1e-4) - slope(below, -1e-4)), 1e-3);
}

// Item 47: f_w(A)(p + t) == f_A(p) and f_w(A)(R p) == f_A(p).
TEST(BlobTree, FrameNodes)
{
  BlobTree a;
  a.add(Kind::ConeSphere, { 1, 1, 0, 0, 0, 1, 0.5, 0.2, 0.4, 0.1 });
  BlobTree moved = a;
  moved.add(Kind::Translate, { 0.3, -1, 2 }, { 0 });
  BlobTree turned = a;
  const double angle = 0.9;
  turned.add(Kind::Rotate, { 0, 0, 2, angle }, { 0 });
  BlobTree tiltedTurn = a;
  tiltedTurn.add(Kind::Rotate, { 1, 1, 1, 2 * M_PI / 3 }, { 0 }); // cycles x -> y -> z -> x
  std::mt19937 rng(47);
  std::uniform_real_distribution<double> u(-1, 2);
  const TapePtr turnedTape = Tape::compile(potential(turned));
  PointEvaluator turnedEval(turnedTape);
  for (int i = 0; i < 500; ++i)
  {
    const Vec3 p{ u(rng), u(rng), u(rng) };
    const double f = evaluate(a, p);
    EXPECT_NEAR(evaluate(moved, { p[0] + 0.3, p[1] - 1, p[2] + 2 }), f, 1e-12);
    const Vec3 rp{ std::cos(angle) * p[0] - std::sin(angle) * p[1],
      std::sin(angle) * p[0] + std::cos(angle) * p[1], p[2] };
    EXPECT_NEAR(evaluate(turned, rp), f, 1e-12);
    EXPECT_NEAR(turnedEval.eval(rp[0], rp[1], rp[2]), f, 1e-12);
    EXPECT_NEAR(evaluate(tiltedTurn, { p[2], p[0], p[1] }), f, 1e-12);
  }
  // The support box follows the frames.
  const auto box = supportBox(moved);
  EXPECT_NEAR(box[0][2], 2 - 1.4, 1e-12);
  EXPECT_NEAR(box[1][0], 0.3 + 1 + 0.1 + 1, 1e-12);
}

// Item 48.
TEST(BlobTree, GeneralisedCylinderLevelOfDetail)
{
  auto cylinder = [](int n, double r0, double r1, double r2)
  {
    BlobTree t;
    t.add(Kind::GeneralisedCylinder, { 0.5, 1, double(n), 0, 0, 0, r0, 1, 1, 0, r1, 2, 0, 1, r2 });
    return t.expand();
  };
  for (int n : { 1, 2, 7, 16 })
  {
    const BlobTree t = cylinder(n, 0.3, 0.3, 0.3);
    EXPECT_EQ(t.leafCount(), std::size_t(n));
    EXPECT_EQ(t.count(Kind::Max), std::size_t(n - 1));  // unions that stay max below blends
    EXPECT_EQ(t.operatorCount(), std::size_t(n - 1));   // union only
    EXPECT_EQ(t.count(Kind::Cylinder), std::size_t(n)); // r_i == r_i+1 > 0
  }
  EXPECT_EQ(cylinder(9, 0, 0, 0).count(Kind::Segment), 9u);          // null radii
  EXPECT_EQ(cylinder(9, 0.1, 0.3, 0.5).count(Kind::ConeSphere), 9u); // varying radii
  EXPECT_LT(cylinder(4, 0.2, 0.2, 0.2).leafCount(), cylinder(12, 0.2, 0.2, 0.2).leafCount());
  // The expansion interpolates the control points: the middle one is on the skeleton (n even).
  const BlobTree t = cylinder(8, 0.3, 0.3, 0.3);
  EXPECT_NEAR(evaluate(t, { 1, 1, 0.3 }), 1.0, 1e-12);
  EXPECT_NEAR(evaluate(t, { 0, 0, 0 }), 1.0, 1e-12);
}

TEST(BlobTree, BadInputNamesTheNode)
{
  BlobTree t;
  try
  {
    t.add(Kind::Segment, { -1, 1, 0, 0, 0, 1, 0, 0 });
    FAIL();
  }
  catch (const std::invalid_argument& e)
  {
    EXPECT_STREQ(
      e.what(), "blobtree: segment: the radius of influence R must be positive (got -1)");
  }
  EXPECT_THROW(t.add(Kind::Point, { 1, 1, 0, 0 }), std::invalid_argument);
  EXPECT_THROW(t.add(Kind::Triangle, { 1, 1, 0, 0, 0, 1, 0, 0, 2, 0, 0 }), std::invalid_argument);
  EXPECT_THROW(t.add(Kind::Point, { 1, NAN, 0, 0, 0 }), std::invalid_argument);
  const auto p = t.add(Kind::Point, { 1, 1, 0, 0, 0 });
  EXPECT_THROW(t.add(Kind::Union, {}, { p + 1 }), std::invalid_argument);
  t.add(Kind::Translate, { 1, 0, 0 }, { p });
  EXPECT_THROW(t.add(Kind::Scale, { 1, 1, 1 }, { p }), std::invalid_argument); // a second parent
  EXPECT_THROW(BlobTree(0.0), std::invalid_argument);
  EXPECT_THROW(potential(BlobTree()), std::invalid_argument);
}

// Items 57-59.
TEST(BlobTree, AnimationAndInstantiation)
{
  BlobTree generic;
  const auto a = generic.add(Kind::Point, { 1, 1, 0, 0, 0 });
  const auto g = generic.add(Kind::GeneralisedCylinder, { 0.5, 1, 6, 0, 0, 0, 0.2, 1, 0, 0, 0.2 });
  const auto u = generic.add(Kind::Blend, {}, { a, g });
  generic.add(Kind::Rotate, { 0, 0, 1, 0 }, { u });
  Animation wave;
  wave.base = 0;
  wave.amplitude = 0.5;
  wave.period = 2;
  generic.animate(3, 3, wave); // the rotation angle
  Animation keys;
  keys.type = Animation::Type::Keys;
  keys.order = 2;
  keys.keys = { { 0, 0.3, 0 }, { 1, 0.5, 0.1 } };
  // The first control radius; it stays apart from the second (0.2), so the segments stay
  // cone-spheres (a generalised cylinder's leaf kinds follow its radii at t, item 48).
  generic.animate(g, 6, keys);
  const BlobTree i0 = generic.instantiate(0), i5 = generic.instantiate(0.5),
                 i1 = generic.instantiate(1);
  ASSERT_EQ(i0.nodes().size(), i5.nodes().size());
  ASSERT_EQ(i0.nodes().size(), i1.nodes().size());
  for (std::size_t k = 0; k < i0.nodes().size(); ++k)
  {
    EXPECT_EQ(i0.nodes()[k].kind, i5.nodes()[k].kind);
    EXPECT_EQ(i0.nodes()[k].kind, i1.nodes()[k].kind);
  }
  EXPECT_DOUBLE_EQ(i5.values(i5.root())[3], 0.5); // sin(pi / 2)
  EXPECT_NE(evaluate(i0, { 0.5, 0.3, 0 }), evaluate(i5, { 0.5, 0.3, 0 }));

  // An instance rewritten in place equals a fresh one, also when a cylinder's element kinds
  // change with its radii (equal radii at t = 0: line-swept spheres; cone-spheres after).
  BlobTree changing;
  const auto cg =
    changing.add(Kind::GeneralisedCylinder, { 0.5, 1, 5, 0, 0, 0, 0.2, 1, 0, 0, 0.2 });
  changing.add(Kind::Blend, {}, { changing.add(Kind::Point, { 1, 1, 0, 1, 0 }), cg });
  Animation growing;
  growing.type = Animation::Type::Keys;
  growing.order = 1;
  growing.keys = { { 0, 0.2 }, { 1, 0.4 } };
  changing.animate(cg, 10, growing);
  BlobTree reused;
  for (const double t : { 0.0, 0.5, 0.0, 1.0 })
  {
    changing.instantiate(t, reused);
    const BlobTree fresh = changing.instantiate(t);
    ASSERT_EQ(reused.nodes().size(), fresh.nodes().size());
    for (std::uint32_t k = 0; k < fresh.nodes().size(); ++k)
    {
      ASSERT_EQ(reused.node(k).kind, fresh.node(k).kind);
      ASSERT_EQ(reused.node(k).valueCount, fresh.node(k).valueCount);
      for (std::uint32_t j = 0; j < fresh.node(k).valueCount; ++j)
      {
        ASSERT_EQ(reused.values(k)[j], fresh.values(k)[j]);
      }
    }
    EXPECT_EQ(reused.count(Kind::Cylinder), t == 0 ? 5u : 0u);
    EXPECT_EQ(evaluate(reused, { 0.5, 0.1, 0.1 }), evaluate(fresh, { 0.5, 0.1, 0.1 }));
  }

  // Item 58: order 2 is cubic per span (4th differences vanish), order 3 quintic.
  Animation cubic = keys;
  cubic.keys = { { 0, 1, -2 }, { 2, 3, 1 }, { 3, -1, 0 } };
  EXPECT_DOUBLE_EQ(cubic.eval(0), 1);
  EXPECT_DOUBLE_EQ(cubic.eval(2), 3);
  EXPECT_NEAR((cubic.eval(1e-8) - cubic.eval(0)) / 1e-8, -2, 1e-5);
  EXPECT_NEAR((cubic.eval(2) - cubic.eval(2 - 1e-8)) / 1e-8, 1, 1e-5);
  EXPECT_NEAR((cubic.eval(2 + 1e-8) - cubic.eval(2)) / 1e-8, 1, 1e-5);
  const double h = 0.2;
  auto difference = [&](const Animation& f, int order, double t0)
  {
    double sum = 0, binom = 1;
    for (int k = 0; k <= order; ++k)
    {
      sum += ((order - k) % 2 ? -1 : 1) * binom * f.eval(t0 + k * h);
      binom = binom * (order - k) / (k + 1);
    }
    return sum;
  };
  EXPECT_NEAR(difference(cubic, 4, 0.1), 0, 1e-12);
  EXPECT_GT(std::fabs(difference(cubic, 3, 0.1)), 1e-3);
  Animation quintic;
  quintic.type = Animation::Type::Keys;
  quintic.order = 3;
  quintic.keys = { { 0, 1, 0, 5 }, { 2, 0, 1, -3 } };
  EXPECT_NEAR(difference(quintic, 6, 0.3), 0, 1e-11);
  EXPECT_GT(std::fabs(difference(quintic, 5, 0.3)), 1e-6);
  EXPECT_NEAR(quintic.eval(2), 0, 1e-12);
  const double e = 1e-4;
  EXPECT_NEAR((quintic.eval(2 * e) - 2 * quintic.eval(e) + quintic.eval(0)) / (e * e), 5, 1e-2);

  // Item 59: the threshold is animatable.
  BlobTree sphere;
  sphere.add(Kind::Point, { 2, 1, 0, 0, 0 });
  Animation threshold;
  threshold.type = Animation::Type::Keys;
  threshold.order = 1;
  threshold.keys = { { 0, 0.5 }, { 1, 0.9 } };
  sphere.animateThreshold(threshold);
  EXPECT_DOUBLE_EQ(sphere.instantiate(0).threshold(), 0.5);
  EXPECT_DOUBLE_EQ(sphere.instantiate(1).threshold(), 0.9);
  PointEvaluator s0(Tape::compile(shape(sphere.instantiate(0)).function()));
  PointEvaluator s1(Tape::compile(shape(sphere.instantiate(1)).function()));
  EXPECT_NEAR(s0.eval(1, 0, 0), 0, 1e-15); // the surface at R/2 for T = 0.5
  EXPECT_LT(s1.eval(1, 0, 0), 0);          // a higher threshold shrinks it
}

namespace
{
// Points at the origin: at the origin each gives its intensity exactly (g(0) = 1); each under a
// material node whose six values are `phi`.
std::uint32_t paintedPoint(BlobTree& t, double intensity, double phi)
{
  const auto p = t.add(Kind::Point, { 1, intensity, 0, 0, 0 });
  return t.add(Kind::Material, { phi, phi, phi, phi, phi, phi }, { p });
}

double phiAtOrigin(const BlobTree& t, TextureHyperBlend mode = TextureHyperBlend::Corrected)
{
  std::array<double, MaterialSize> phi{};
  evaluateTextured(t, { 0, 0, 0 }, phi, mode);
  for (int k = 1; k < MaterialSize; ++k)
  {
    EXPECT_EQ(phi[k], phi[0]);
  }
  // The lowered material gives the same.
  PointEvaluator e(Tape::compile(material(t, mode)[0]));
  EXPECT_NEAR(e.eval(0, 0, 0), phi[0], 1e-15);
  return phi[0];
}

BlobTree pair(
  Kind kind, double fa, double fb, double pa, double pb, std::vector<double> values = {})
{
  BlobTree t;
  const auto a = paintedPoint(t, fa, pa);
  const auto b = paintedPoint(t, fb, pb);
  t.add(kind, values, { a, b });
  return t;
}
} // namespace

// Items 51-55: the TextureTree's (f, Phi) and its operators, on fields and materials known at the
// origin.
TEST(BlobTree, TextureTree)
{
  BlobTree leaf;
  const auto p = leaf.add(Kind::Point, { 2, 1, 0, 0, 0 });
  leaf.add(Kind::Material, { 0.9, 0.1, 0.2, 0.3, 0.4, 1.5 }, { p });
  std::array<double, MaterialSize> phi{};
  EXPECT_DOUBLE_EQ(evaluateTextured(leaf, { 1, 0, 0 }, phi), 0.5); // item 51: (f, Phi)
  EXPECT_EQ(phi, (std::array<double, MaterialSize>{ 0.9, 0.1, 0.2, 0.3, 0.4, 1.5 }));
  evaluateTextured(single(Kind::Point, { 1, 1, 0, 0, 0 }), { 0, 0, 0 }, phi);
  EXPECT_EQ(phi[0], DefaultMaterial[0]);

  EXPECT_NEAR(phiAtOrigin(pair(Kind::Blend, 0.3, 0.6, 0.2, 0.9)), 0.666667, 5e-7); // item 52
  EXPECT_NEAR(phiAtOrigin(pair(Kind::Blend, 0.4, 0.4, 0.2, 0.9)), 0.55, 1e-15);    // the mean

  // Item 53 and E11: the hyper-blend as printed tends to 0.45, the corrected one to Phi_A.
  const auto verbatim = TextureHyperBlend::Verbatim;
  EXPECT_NEAR(
    phiAtOrigin(pair(Kind::HyperBlend, 0.3, 0.6, 0.2, 0.9, { 1 }), verbatim), 0.666667, 5e-7);
  EXPECT_NEAR(
    phiAtOrigin(pair(Kind::HyperBlend, 0.6, 0.3, 0.2, 0.9, { 1 }), verbatim), 0.43333, 5e-6);
  EXPECT_NEAR(
    phiAtOrigin(pair(Kind::HyperBlend, 0.6, 0.3, 0.2, 0.9, { 32 }), verbatim), 0.45000, 5e-6);
  EXPECT_NEAR(phiAtOrigin(pair(Kind::HyperBlend, 0.6, 0.3, 0.2, 0.9, { 1 })), 0.43333, 5e-6);
  EXPECT_NEAR(phiAtOrigin(pair(Kind::HyperBlend, 0.6, 0.3, 0.2, 0.9, { 32 })), 0.2, 1e-9);

  // Item 54: Booleans pick one child's Phi; ties go to B.
  EXPECT_EQ(phiAtOrigin(pair(Kind::Union, 0.6, 0.3, 0.2, 0.9)), 0.2);
  EXPECT_EQ(phiAtOrigin(pair(Kind::Union, 0.3, 0.6, 0.2, 0.9)), 0.9);
  EXPECT_EQ(phiAtOrigin(pair(Kind::Union, 0.4, 0.4, 0.2, 0.9)), 0.9);
  EXPECT_EQ(phiAtOrigin(pair(Kind::Intersection, 0.3, 0.6, 0.2, 0.9)), 0.2);
  EXPECT_EQ(phiAtOrigin(pair(Kind::Intersection, 0.6, 0.3, 0.2, 0.9)), 0.9);
  EXPECT_EQ(phiAtOrigin(pair(Kind::Difference, 0.3, 0.6, 0.2, 0.9)), 0.2); // 0.3 < 1 - 0.6
  EXPECT_EQ(phiAtOrigin(pair(Kind::Difference, 0.5, 0.6, 0.2, 0.9)), 0.9);

  // Item 55: the local blend mixes the blend's and the union's Phi by f_R.
  for (const double w : { 0.0, 0.5, 1.0 })
  {
    BlobTree t;
    const auto a = paintedPoint(t, 0.3, 0.2);
    const auto b = paintedPoint(t, 0.6, 0.9);
    const auto r = t.add(Kind::Point, { 1, w, 0, 0, 0 });
    t.add(Kind::LocalBlend, {}, { a, b, r });
    EXPECT_NEAR(phiAtOrigin(t), w * (0.3 * 0.2 + 0.6 * 0.9) / 0.9 + (1 - w) * 0.9, 1e-15);
  }
}

// The lowered materials agree with the traversal everywhere, and flow into a hypervolume's
// attributes.
TEST(BlobTree, TextureTreeLoweredAndAsAttributes)
{
  BlobTree t;
  const auto a = t.add(
    Kind::Material, { 1, 0, 0, 0.1, 0, 1.2 }, { t.add(Kind::Segment, { 1, 1, 0, 0, 0, 1, 0, 0 }) });
  const auto b = t.add(Kind::Material, { 0, 0, 1, 0.5, 0.2, 1.4 },
    { t.add(Kind::Disc, { 0.8, 1, 0.5, 1.5, 0, 0, 1, 0, 0.5 }) });
  const auto c = t.add(Kind::Point, { 0.9, 1, 0, 0.6, 0.3 });
  const auto u = t.add(Kind::Union, {}, { a, c });
  t.add(Kind::Rotate, { 0, 0, 1, 0.4 }, { t.add(Kind::HyperBlend, { 2 }, { u, b }) });
  const std::array<Expr, MaterialSize> phi = material(t);
  std::vector<Expr> outputs(phi.begin(), phi.end());
  PointEvaluator e(Tape::compile(outputs));
  std::mt19937 rng(56);
  std::uniform_real_distribution<double> x(-1, 2);
  for (int k = 0; k < 2000; ++k)
  {
    const Vec3 p{ x(rng), x(rng), x(rng) };
    std::array<double, MaterialSize> expected{}, got{};
    evaluateTextured(t, p, expected);
    e.evalAll({ p[0], p[1], p[2], 0 }, got.data());
    for (int m = 0; m < MaterialSize; ++m)
    {
      ASSERT_NEAR(got[m], expected[m], 1e-12);
    }
  }
  const Hypervolume hv = texturedHypervolume(t);
  ASSERT_NE(hv.findAttribute("colour"), nullptr);
  HypervolumeEvaluator he(hv);
  double f = 0;
  std::vector<double> attributes(hv.attributeComponentCount());
  he.eval({ 0.5, 0, 0, 0 }, f, attributes.data()); // on the red segment, turned by 0.4 rad
  const double c0 = std::cos(0.4), s0 = std::sin(0.4);
  std::array<double, MaterialSize> expected{};
  evaluateTextured(t, { 0.5, 0, 0 }, expected);
  EXPECT_NEAR(f, evaluate(t, { 0.5, 0, 0 }) - 0.5, 1e-12);
  EXPECT_NEAR(attributes[0], expected[0], 1e-12);
  he.eval({ 0.5 * c0, 0.5 * s0, 0, 0 }, f, attributes.data());
  EXPECT_DOUBLE_EQ(attributes[0], 1.0); // on the segment, away from the disc: pure red
  EXPECT_DOUBLE_EQ(attributes[2], 0.0);
}

namespace
{
// The hash of FRep/SolidTexture.h written out again from its formula, for the tests.
double fract(double x)
{
  return x - std::floor(x);
}
double latticeHash(double i, double j, double k)
{
  const double a = fract(0.1031 * i), b = fract(0.1031 * j), c = fract(0.1031 * k);
  const double d = a * (c + 33.33) + b * (b + 33.33) + c * (a + 33.33);
  return fract((a + d + b + d) * (c + d));
}

// A ball of radius 2 (R = 4 about the origin) under one solid texture node with colours
// A = (1, 0, 0) and B = (0, 0, 1), optics (0.1, 0.2, 1.3).
BlobTree texturedBall(Kind kind, double lambda, double amplitude, int octaves)
{
  BlobTree t;
  const auto p = t.add(Kind::Point, { 4, 1, 0, 0, 0 });
  t.add(kind, { 1, 0, 0, 0, 0, 1, 0.1, 0.2, 1.3, lambda, amplitude, double(octaves) }, { p });
  return t;
}

// s, the pattern, read back from the blue channel (B - A = (-1, 0, 1)), by traversal and by the
// lowered attribute (which must agree).
double patternAt(const BlobTree& t, const Vec3& p)
{
  std::array<double, MaterialSize> phi{};
  evaluateTextured(t, p, phi);
  EXPECT_NEAR(phi[0], 1 - phi[2], 1e-15);
  EXPECT_EQ(phi[3], 0.1);
  EXPECT_EQ(phi[5], 1.3);
  PointEvaluator e(Tape::compile(material(t)[2]));
  EXPECT_NEAR(e.eval(p[0], p[1], p[2]), phi[2], 1e-12);
  return phi[2];
}
} // namespace

// Procedural solid textures (papers.md 3.5): marble, wood and granite patterns by hand from their
// formulas, deterministic noise, and the texture moving with a frame node (item 56).
TEST(BlobTree, SolidTextures)
{
  // Marble without turbulence: s = (1 + sin(2 pi x / lambda)) / 2.
  const BlobTree marble = texturedBall(Kind::Marble, 1.6, 0, 1);
  EXPECT_NEAR(patternAt(marble, { 0.4, 0.3, -0.2 }), 1.0, 1e-15); // x = lambda / 4: the crest
  EXPECT_NEAR(patternAt(marble, { 1.2, 0, 0 }), 0.0, 1e-15);      // x = 3 lambda / 4
  EXPECT_NEAR(patternAt(marble, { 0.2, 1, 1 }), 0.5 + 0.5 * std::sin(M_PI / 4), 1e-15);
  // Wood without turbulence: rings about z, s = fr(r / lambda), period lambda = 0.5.
  const BlobTree wood = texturedBall(Kind::Wood, 0.5, 0, 1);
  EXPECT_NEAR(patternAt(wood, { 0.5, 0, 0.7 }), 0.0, 1e-15);       // r = lambda: a ring starts
  EXPECT_NEAR(patternAt(wood, { 0.375, 0.5, -0.3 }), 0.25, 1e-15); // r = 0.625 = 1.25 lambda
  EXPECT_NEAR(patternAt(wood, { 0.6, 0, 0 }), 0.2, 1e-12);
  for (const double r : { 0.13, 0.37, 0.61 })
  {
    EXPECT_NEAR(patternAt(wood, { r, 0, 0.2 }), patternAt(wood, { 0, r + 0.5, 0.2 }), 1e-12);
    EXPECT_NEAR(patternAt(wood, { r, 0, 0.2 }), patternAt(wood, { r + 1.0, 0, -0.9 }), 1e-12);
  }
  // The noise at lattice points is the hash: granite with lambda = 0.5 at p = lambda (i, j, k)
  // sees noise(i, j, k) = hash(i, j, k) and, one octave up, hash(2i, 2j, 2k).
  const BlobTree granite1 = texturedBall(Kind::Granite, 0.5, 0, 1);
  const BlobTree granite2 = texturedBall(Kind::Granite, 0.5, 0, 2);
  for (const Vec3& ijk : { Vec3{ 1, 2, 3 }, Vec3{ -2, 0, 1 }, Vec3{ 3, -1, -2 } })
  {
    const Vec3 p{ 0.5 * ijk[0], 0.5 * ijk[1], 0.5 * ijk[2] };
    const double h = latticeHash(ijk[0], ijk[1], ijk[2]);
    EXPECT_NEAR(patternAt(granite1, p), h, 1e-12);
    EXPECT_NEAR(patternAt(granite2, p),
      (h + 0.5 * latticeHash(2 * ijk[0], 2 * ijk[1], 2 * ijk[2])) / 1.5, 1e-12);
  }
  // Between lattice points, the smooth trilinear mix: at (i + 1/2, j, k), u = 1/2.
  EXPECT_NEAR(patternAt(granite1, { 0.75, 1, 1.5 }),
    0.5 * (latticeHash(1, 2, 3) + latticeHash(2, 2, 3)), 1e-12);
  // The hash's values spread over [0, 1] (not a constant): 1,000 lattice points.
  double lo = 1, hi = 0, mean = 0;
  for (int k = 0; k < 1000; ++k)
  {
    const double h = latticeHash(k % 10, (k / 10) % 10, k / 100);
    lo = std::min(lo, h);
    hi = std::max(hi, h);
    mean += h / 1000;
  }
  EXPECT_LT(lo, 0.02);
  EXPECT_GT(hi, 0.98);
  EXPECT_NEAR(mean, 0.5, 0.05);
  // Marble with turbulence: s = (1 + sin(2 pi (x + a fbm(p / lambda)) / lambda)) / 2 at a
  // lattice point of p / lambda (lambda = 1, a = 0.3, one octave).
  const BlobTree veined = texturedBall(Kind::Marble, 1, 0.3, 1);
  EXPECT_NEAR(patternAt(veined, { 1, -1, 0 }),
    0.5 + 0.5 * std::sin(2 * M_PI * (1 + 0.3 * latticeHash(1, -1, 0))), 1e-12);

  // Item 56: under a frame node the texture moves with the geometry. Translating the wood by
  // (0.25, 0, 0) moves its rings' centre there.
  BlobTree moved;
  const auto p = moved.add(Kind::Point, { 4, 1, 0, 0, 0 });
  const auto w = moved.add(Kind::Wood, { 1, 0, 0, 0, 0, 1, 0.1, 0.2, 1.3, 0.5, 0, 1 }, { p });
  moved.add(Kind::Translate, { 0.25, 0, 0 }, { w });
  EXPECT_NEAR(patternAt(moved, { 0.85, 0, 0 }), 0.2, 1e-12);      // r = 0.6 from (0.25, 0, 0)
  EXPECT_NEAR(patternAt(moved, { 0.25, 0.375, 0 }), 0.75, 1e-15); // r = 0.375

  // Bad values are refused with the node's name.
  BlobTree bad;
  const auto q = bad.add(Kind::Point, { 1, 1, 0, 0, 0 });
  EXPECT_THROW(bad.add(Kind::Wood, { 1, 0, 0, 0, 0, 1, 0, 0, 1, 0, 0, 1 }, { q }),
    std::invalid_argument); // lambda = 0
  EXPECT_THROW(bad.add(Kind::Marble, { 1, 0, 0, 0, 0, 1, 0, 0, 1, 1, 0, 9 }, { q }),
    std::invalid_argument); // 9 octaves
  EXPECT_THROW(bad.add(Kind::Granite, { 1, 0, 0, 0, -1, 1, 0, 0, 1, 1, 0, 2 }, { q }),
    std::invalid_argument); // a negative colour
  // A texture node is neither an operator nor a warp.
  EXPECT_EQ(moved.operatorCount(), 0u);
  EXPECT_EQ(moved.warpCount(), 1u);
}

// Item 50: surfaces of revolution with variable thickness (papers.md 3.4, lines 142-159), with
// numbers derived by hand in the meridian half-plane (rho, h).
TEST(BlobTree, SurfaceOfRevolution)
{
  const double R = 1.5;
  // A tube about z: profile (rho, h, t) = (1, 0, 0.2) -> (1, 2, 0.2), one segment. Equal end
  // radii give the cylinder of line 159: the distance is |rho - 1| - 0.2 between the end tori.
  BlobTree tube;
  tube.add(Kind::SurfaceOfRevolution, { R, 1, 1, 0, 0, 0, 0, 0, 1, 1, 0, 0.2, 1, 2, 0.2 });
  EXPECT_EQ(tube.expand().count(Kind::HollowCone), 1u);
  for (const double phi : { 0.0, 1.0, 2.5, 4.0 })
  {
    const double c = std::cos(phi), s = std::sin(phi);
    EXPECT_NEAR(evaluate(tube, { 1.1 * c, 1.1 * s, 1 }), 1.0, 1e-12); // in the wall
    EXPECT_NEAR(evaluate(tube, { 1.5 * c, 1.5 * s, 0.7 }), wyvillByHand(0.3, R), 1e-12);
    EXPECT_NEAR(evaluate(tube, { 0.5 * c, 0.5 * s, 1.3 }), wyvillByHand(0.3, R), 1e-12);
    // Below the end: the junction torus of line 155, major radius 1, minor 0.2.
    EXPECT_NEAR(evaluate(tube, { c, s, -0.5 }), wyvillByHand(0.3, R), 1e-12);
  }
  // A bulging profile (1, 0, 0.3), (2, 1, 0.1), (1, 2, 0.3) in n = 2 segments, whose samples are
  // the control points. The junction at v_1 = (2, 1) is a torus of major radius
  // distance(v_1, axis) = 2 and minor radius t_1 = 0.1: at (rho, h) = (2.4, 1), beyond both
  // hollow cones' ends, the distance is 0.4 - 0.1 = 0.3 at every azimuth.
  BlobTree vase;
  vase.add(
    Kind::SurfaceOfRevolution, { R, 1, 2, 0, 0, 0, 0, 0, 1, 1, 0, 0.3, 2, 1, 0.1, 1, 2, 0.3 });
  const BlobTree pieces = vase.expand();
  EXPECT_EQ(pieces.count(Kind::HollowCone), 2u);
  EXPECT_EQ(pieces.count(Kind::Max), 1u);
  for (const double phi : { 0.3, 2.0, 5.0 })
  {
    const double c = std::cos(phi), s = std::sin(phi);
    EXPECT_NEAR(evaluate(vase, { 2.4 * c, 2.4 * s, 1 }), wyvillByHand(0.3, R), 1e-12);
    // No bulge (line 114): at the junction, inside both pieces, the max is 1, not their sum 2.
    EXPECT_DOUBLE_EQ(evaluate(vase, { 2 * c, 2 * s, 1 }), 1.0);
  }
  BlobTree summed;
  {
    const BlobTree e = vase.expand();
    std::vector<std::uint32_t> leaves;
    for (std::uint32_t k = 0; k < e.nodes().size(); ++k)
    {
      if (e.node(k).kind == Kind::HollowCone)
      {
        const double* v = e.values(k);
        leaves.push_back(summed.add(Kind::HollowCone, std::vector<double>(v, v + 14)));
      }
    }
    summed.add(Kind::Blend, {}, leaves);
  }
  EXPECT_DOUBLE_EQ(evaluate(summed, { 2, 0, 1 }), 2.0);
  // Level of detail: n segments give n hollow cones under n - 1 max nodes, on an axis that need
  // not be z (here along (1, 1, 0) through (0.5, 0, 0)); the lowered field agrees with the
  // traversal everywhere, inside the elements' boxes and outside.
  BlobTree tilted;
  tilted.add(Kind::SurfaceOfRevolution,
    { R, 1, 16, 0.5, 0, 0, 1, 1, 0, 0.5, -1, 0.2, 1.5, 0, 0.05, 0.8, 1, 0.3, 0.2, 2, 0 });
  const BlobTree lod = tilted.expand();
  EXPECT_EQ(lod.count(Kind::HollowCone), 16u);
  EXPECT_EQ(lod.count(Kind::Max), 15u);
  PointEvaluator e(Tape::compile(potential(tilted)));
  std::mt19937 rng(50);
  std::uniform_real_distribution<double> x(-5, 5);
  int inside = 0;
  for (int k = 0; k < 1000; ++k)
  {
    const Vec3 p{ x(rng), x(rng), x(rng) };
    const double f = evaluate(tilted, p);
    inside += f > 0.5;
    ASSERT_NEAR(e.eval(p[0], p[1], p[2]), f, 1e-12);
  }
  EXPECT_GT(inside, 5);
  // Zero thickness: the plain hollow cone, its surface at distance 0.
  BlobTree bare;
  bare.add(Kind::SurfaceOfRevolution, { R, 1, 1, 0, 0, 0, 0, 0, 1, 1, 0, 0, 2, 2, 0 });
  EXPECT_DOUBLE_EQ(evaluate(bare, { 0, -1.5, 1 }), 1.0); // (rho, h) = (1.5, 1) on the segment
  // 0.3 along the profile's normal (2, -1) / sqrt 5 from (1.5, 1): the distance is 0.3.
  const double off = 0.3 / std::sqrt(5.0);
  EXPECT_NEAR(evaluate(bare, { 1.5 + 2 * off, 0, 1 - off }), wyvillByHand(0.3, R), 1e-12);
  // Bad values are refused.
  BlobTree bad;
  EXPECT_THROW(bad.add(Kind::SurfaceOfRevolution, { R, 1, 1, 0, 0, 0, 0, 0, 0, 1, 0, 0, 1, 1, 0 }),
    std::invalid_argument); // a zero axis
  EXPECT_THROW(bad.add(Kind::SurfaceOfRevolution, { R, 1, 1, 0, 0, 0, 0, 0, 1, -1, 0, 0, 1, 1, 0 }),
    std::invalid_argument); // rho < 0
  EXPECT_THROW(bad.add(Kind::SurfaceOfRevolution, { R, 1, 0, 0, 0, 0, 0, 0, 1, 1, 0, 0, 1, 1, 0 }),
    std::invalid_argument); // no segment
}

// Item 49: surfaces with variable thickness (papers.md 3.4, lines 127-140), numbers by hand on
// the triangle (0, 0, 0), (2, 0, 0), (0, 2, 0) with thicknesses 0.2, 0.4, 0.2: its top is the
// plane through v + t n, z = 0.2 + 0.1 x.
TEST(BlobTree, SurfaceWithVariableThickness)
{
  const double R = 1.5;
  BlobTree s;
  s.add(Kind::ThickSurface, { R, 1, 0, 0, 0, 0.2, 2, 0, 0, 0.4, 0, 2, 0, 0.2 });
  const BlobTree e = s.expand();
  EXPECT_EQ(e.count(Kind::ThickTriangle), 1u);
  // Over the triangle, d = |h| - t(q): at (0.5, 0.5) the barycentric coordinates are
  // (0.5, 0.25, 0.25), t = 0.25.
  EXPECT_NEAR(evaluate(s, { 0.5, 0.5, 0.5 }), wyvillByHand(0.25, R), 1e-12);
  EXPECT_NEAR(evaluate(s, { 0.5, 0.5, -0.5 }), wyvillByHand(0.25, R), 1e-12);
  EXPECT_DOUBLE_EQ(evaluate(s, { 0.5, 0.5, 0.1 }), 1.0); // inside the slab
  EXPECT_DOUBLE_EQ(evaluate(s, { 1, 0.5, 0.3 }), 1.0);   // on the top plane z = 0.2 + 0.1 x
  EXPECT_NEAR(evaluate(s, { 1, 0.5, 0.8 }), wyvillByHand(0.5, R), 1e-12);
  // Beyond edge ab: from its nearest point (1, 0, 0), where t = 0.3: d = 0.5 - 0.3.
  EXPECT_NEAR(evaluate(s, { 1, -0.5, 0 }), wyvillByHand(0.2, R), 1e-12);
  // Beyond vertex b: d = |p - b| - 0.4.
  EXPECT_NEAR(evaluate(s, { 2.6, -0.8, 0 }), wyvillByHand(0.6, R), 1e-12);
  // Null thickness is the triangle element (line 139).
  BlobTree thin;
  thin.add(Kind::ThickSurface, { R, 1, 0, 0, 0, 0, 2, 0, 0, 0, 0, 2, 0, 0 });
  EXPECT_EQ(thin.expand().count(Kind::Triangle), 1u);
  const BlobTree triangle = single(Kind::Triangle, { R, 1, 0, 0, 0, 2, 0, 0, 0, 2, 0 });
  // Equal thickness, the prism: d = |h| - 0.3 over the triangle.
  BlobTree prism;
  prism.add(Kind::ThickSurface, { R, 1, 0, 0, 0, 0.3, 2, 0, 0, 0.3, 0, 2, 0, 0.3 });
  std::mt19937 rng(49);
  std::uniform_real_distribution<double> x(-1.5, 3);
  for (int k = 0; k < 300; ++k)
  {
    const Vec3 p{ x(rng), x(rng), x(rng) };
    ASSERT_NEAR(evaluate(thin, p), evaluate(triangle, p), 1e-12);
    if (p[0] > 0 && p[1] > 0 && p[0] + p[1] < 2)
    {
      ASSERT_NEAR(evaluate(prism, p), wyvillByHand(std::max(std::fabs(p[2]) - 0.3, 0.0), R), 1e-12);
    }
  }
  // A folded surface of two triangles sharing the edge (0, 0, 0)-(0, 2, 0): two elements under a
  // max node, and no crack along the fold: on the shared edge's rounded side both give the same.
  BlobTree fold;
  fold.add(Kind::ThickSurface,
    { R, 1, 0, 0, 0, 0.1, 2, 0, 0, 0.1, 0, 2, 0, 0.1, 0, 0, 0, 0.1, 0, 2, 0, 0.1, -1, 0, 1.5,
      0.1 });
  const BlobTree folded = fold.expand();
  EXPECT_EQ(folded.count(Kind::ThickTriangle), 2u);
  EXPECT_EQ(folded.count(Kind::Max), 1u);
  EXPECT_NEAR(evaluate(fold, { -0.3, 1, -0.3 }), wyvillByHand(std::sqrt(0.18) - 0.1, R), 1e-12);
  // The lowered field agrees with the traversal.
  PointEvaluator pe(Tape::compile(potential(fold)));
  for (int k = 0; k < 500; ++k)
  {
    const Vec3 p{ x(rng), x(rng), x(rng) };
    ASSERT_NEAR(pe.eval(p[0], p[1], p[2]), evaluate(fold, p), 1e-12);
  }
  BlobTree bad;
  EXPECT_THROW(bad.add(Kind::ThickSurface, { R, 1, 0, 0, 0, 0, 1, 0, 0, 0, 2, 0, 0, 0 }),
    std::invalid_argument); // collinear
  EXPECT_THROW(bad.add(Kind::ThickSurface, { R, 1, 0, 0, 0, -1, 2, 0, 0, 0, 0, 2, 0, 0 }),
    std::invalid_argument); // negative thickness
}

// The box element (item 49): d = |max(|q| - h, 0)| - r in its frame, at hand-computed distances;
// turned by its axes as by a rotate node; its degenerate forms (half-sides (L/2, 0, 0): the
// cylinder of radius r); the box short-circuit and exact intervals as for every element.
TEST(BlobTree, BoxElement)
{
  const double R = 2;
  // Centre (1, 2, 3), half-sides (1, 0.5, 0.25), rounding 0.1.
  const BlobTree box = single(Kind::Box, { R, 1, 1, 2, 3, 1, 0, 0, 0, 1, 0, 1, 0.5, 0.25, 0.1 });
  EXPECT_DOUBLE_EQ(evaluate(box, { 1.5, 2, 3 }), 1.0);                      // inside
  EXPECT_NEAR(evaluate(box, { 1, 2, 3.75 }), wyvillByHand(0.4, R), 1e-12);  // over a face
  EXPECT_NEAR(evaluate(box, { 2.3, 2.9, 3 }), wyvillByHand(0.4, R), 1e-12); // by an edge
  EXPECT_NEAR(evaluate(box, { 2.3, 2.9, 3.37 }), wyvillByHand(std::sqrt(0.2644) - 0.1, R),
    1e-12); // by a corner: excess (0.3, 0.4, 0.12)
  EXPECT_NEAR(fieldAt(box, { 2.3, 2.9, 3.37 }), wyvillByHand(std::sqrt(0.2644) - 0.1, R), 1e-12);
  // Its axes turn it as a rotate node turns the axis-aligned box: e1 = (1, 1, 0), e2 = (-1, 1, 0)
  // is the rotation by 45 degrees about z.
  BlobTree turned;
  turned.add(Kind::Box, { 1.5, 1, 0, 0, 0, 1, 1, 0, -1, 1, 0, 1, 0.5, 0.25, 0.2 });
  BlobTree rotated;
  rotated.add(Kind::Rotate, { 0, 0, 1, M_PI / 4 },
    { rotated.add(Kind::Box, { 1.5, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 0.5, 0.25, 0.2 }) });
  // A cylinder is the box of half-sides (L/2, 0, 0) and rounding r.
  const BlobTree cylinder = single(Kind::Cylinder, { 1.5, 1, 0, 0, 0, 2, 0, 0, 0.3 });
  const BlobTree asBox = single(Kind::Box, { 1.5, 1, 1, 0, 0, 1, 0, 0, 0, 1, 0, 1, 0, 0, 0.3 });
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> x(-2.5, 3.5);
  PointEvaluator lowered(Tape::compile(potential(turned)));
  int nonZero = 0;
  for (int k = 0; k < 2000; ++k)
  {
    const Vec3 p{ x(rng), x(rng), x(rng) };
    const double f = evaluate(turned, p);
    nonZero += f != 0;
    ASSERT_NEAR(f, evaluate(rotated, p), 1e-12);
    ASSERT_NEAR(lowered.eval(p[0], p[1], p[2]), f, 1e-12);
    ASSERT_NEAR(evaluate(cylinder, p), evaluate(asBox, p), 1e-12);
  }
  EXPECT_GT(nonZero, 200);
  // The short-circuit: the turned box's extent along x is (1 + 0.5) / sqrt 2 + 0.2 + 1.5.
  const double reach = 1.5 / std::sqrt(2.0) + 1.7;
  const auto support = supportBox(turned);
  EXPECT_NEAR(support[1][0], reach, 1e-12);
  EXPECT_NEAR(support[0][2], -(0.25 + 1.7), 1e-12);
  std::size_t kernels = 0;
  EXPECT_EQ(evaluate(turned, { reach + 0.01, 0, 0 }, &kernels), 0.0);
  EXPECT_EQ(kernels, 0u);
  const TapePtr tape = Tape::compile(potential(turned));
  IntervalEvaluator interval(tape);
  Region outside;
  outside.axes = { Interval{ reach + 0.01, reach + 1 }, Interval{ -1, 1 }, Interval{ -1, 1 },
    Interval{ 0, 0 } };
  const Interval none = interval.eval(outside);
  EXPECT_LE(std::fabs(none.lo), 1e-300);
  EXPECT_LE(std::fabs(none.hi), 1e-300);
  std::uniform_real_distribution<double> size(0.05, 1.0);
  for (int r = 0; r < 200; ++r)
  {
    std::array<double, 3> lo{}, w{};
    const Interval bound = interval.eval(randomRegion(rng, x, size, lo, w));
    for (int s = 0; s < 50; ++s)
    {
      const double f =
        lowered.eval(lo[0] + w[0] * std::uniform_real_distribution<double>(0, 1)(rng),
          lo[1] + w[1] * std::uniform_real_distribution<double>(0, 1)(rng),
          lo[2] + w[2] * std::uniform_real_distribution<double>(0, 1)(rng));
      ASSERT_TRUE(bound.contains(f)) << f << " not in [" << bound.lo << ", " << bound.hi << "]";
    }
  }
  BlobTree bad;
  EXPECT_THROW(bad.add(Kind::Box, { R, 1, 0, 0, 0, 1, 0, 0, 2, 0, 0, 1, 1, 1, 0 }),
    std::invalid_argument); // parallel axes
  EXPECT_THROW(bad.add(Kind::Box, { R, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 1, -1, 1, 0 }),
    std::invalid_argument); // negative half-side
  EXPECT_THROW(bad.add(Kind::Box, { R, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 1, -0.1 }),
    std::invalid_argument); // negative rounding
}

// Item 49's last simplification (line 140): the two halves of a rectangle in a surface with
// variable thickness, of one thickness t, are one box of half-sides (a, b, 0) and rounding t,
// whose field is the two thick triangles' union (max) to 1e-12 everywhere, flat or tilted.
TEST(BlobTree, ThickRectangleIsOneBox)
{
  const double R = 1.2, t = 0.2;
  // The rectangle a, a + u, a + u + w, a + w: flat, then tilted (u, w orthogonal, inexact).
  const std::vector<std::array<Vec3, 3>> rectangles = {
    { Vec3{ 0, 0, 0 }, Vec3{ 2, 0, 0 }, Vec3{ 0, 1, 0 } },
    { Vec3{ 0.3, -0.2, 0.1 }, Vec3{ 2.0 / 3, 4.0 / 3, 4.0 / 3 },
      Vec3{ 2.0 / 3, -2.0 / 3, 1.0 / 3 } },
  };
  std::mt19937 rng(140);
  std::uniform_real_distribution<double> x(-1.5, 3);
  for (const auto& [a, u, w] : rectangles)
  {
    const Vec3 b{ a[0] + u[0], a[1] + u[1], a[2] + u[2] };
    const Vec3 c{ b[0] + w[0], b[1] + w[1], b[2] + w[2] };
    const Vec3 d{ a[0] + w[0], a[1] + w[1], a[2] + w[2] };
    BlobTree surface;
    surface.add(Kind::ThickSurface,
      { R, 1, a[0], a[1], a[2], t, b[0], b[1], b[2], t, c[0], c[1], c[2], t, a[0], a[1], a[2], t,
        c[0], c[1], c[2], t, d[0], d[1], d[2], t });
    const BlobTree expanded = surface.expand();
    EXPECT_EQ(expanded.count(Kind::Box), 1u);
    EXPECT_EQ(expanded.count(Kind::ThickTriangle), 0u);
    EXPECT_EQ(expanded.nodes().size(), 1u);
    BlobTree prisms;
    prisms.add(Kind::Max, {},
      { prisms.add(Kind::ThickTriangle,
          { R, 1, a[0], a[1], a[2], b[0], b[1], b[2], c[0], c[1], c[2], t, t, t }),
        prisms.add(Kind::ThickTriangle,
          { R, 1, a[0], a[1], a[2], c[0], c[1], c[2], d[0], d[1], d[2], t, t, t }) });
    PointEvaluator lowered(Tape::compile(potential(expanded)));
    int nonZero = 0;
    for (int k = 0; k < 3000; ++k)
    {
      const Vec3 p{ x(rng), x(rng), x(rng) };
      const double f = evaluate(prisms, p);
      nonZero += f != 0;
      ASSERT_NEAR(evaluate(expanded, p), f, 1e-12);
      ASSERT_NEAR(lowered.eval(p[0], p[1], p[2]), f, 1e-12);
    }
    EXPECT_GT(nonZero, 300);
  }
  // Not merged: a parallelogram, unequal thicknesses, or an animated surface.
  BlobTree parallelogram;
  parallelogram.add(Kind::ThickSurface,
    { R, 1, 0, 0, 0, t, 2, 0, 0, t, 3, 1, 0, t, 0, 0, 0, t, 3, 1, 0, t, 1, 1, 0, t });
  EXPECT_EQ(parallelogram.expand().count(Kind::ThickTriangle), 2u);
  BlobTree uneven;
  uneven.add(Kind::ThickSurface,
    { R, 1, 0, 0, 0, t, 2, 0, 0, t, 2, 1, 0, t, 0, 0, 0, t, 2, 1, 0, t, 0, 1, 0, 0.3 });
  EXPECT_EQ(uneven.expand().count(Kind::ThickTriangle), 2u);
  BlobTree animated;
  const auto s = animated.add(Kind::ThickSurface,
    { R, 1, 0, 0, 0, t, 2, 0, 0, t, 2, 1, 0, t, 0, 0, 0, t, 2, 1, 0, t, 0, 1, 0, t });
  Animation wave;
  wave.base = R;
  wave.amplitude = 0.1;
  animated.animate(s, 0, wave);
  EXPECT_EQ(animated.instantiate(0.3).count(Kind::ThickTriangle), 2u);
  EXPECT_EQ(animated.instantiate(0.3).count(Kind::Box), 0u);
}
