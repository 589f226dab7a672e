// SPDX-License-Identifier: BSD-3-Clause
// Seed 003's base quadrics and perturbation functions (papers.md 2.2, 5.B items 24-31): the named
// types at hand-derived points, the perturbation function's values and smoothness, superposition,
// and the interval bound of a perturbed quadric over a box (item 31), which is what the
// renderer's culling uses: every sampled value lies inside it.
#include "FRep/Quadrics.h"
#include "FRep/Tape.h"
#include "PrimitivesTesting.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <string>

using namespace ictk::frep;
using namespace primitivestest;

namespace
{

Interval bound(const Expr& e, const Vec3& lo, const Vec3& hi)
{
  IntervalEvaluator evaluator(Tape::compile(e));
  Region region;
  for (int k = 0; k < 3; ++k)
  {
    region.axes[k] = { lo[k], hi[k] };
  }
  region.axes[3] = { 0, 0 };
  return evaluator.eval(region);
}

} // namespace

TEST(Quadrics, TwelveNamedTypes)
{
  // Seed 003 line 141: twelve keywords, in the paper's order.
  const std::vector<std::string> keywords = { "ell", "seat", "ellpar", "unihyp", "duahyp", "cone",
    "cylinder", "layer", "plane", "clin", "parabola", "hyperbola" };
  ASSERT_EQ(quadricTypes().size(), 12u);
  for (std::size_t i = 0; i < keywords.size(); ++i)
  {
    EXPECT_EQ(quadricTypes()[i].keyword, keywords[i]);
    const auto type = quadricTypeFromKeyword(keywords[i]);
    ASSERT_TRUE(type);
    EXPECT_EQ(namedQuadric(*type).label(), keywords[i]);
  }
  EXPECT_FALSE(quadricTypeFromKeyword("torus"));
  EXPECT_FALSE(quadricTypeFromKeyword("Ell"));
  // Each type at points worked out from its formula (Quadrics.h).
  struct Case
  {
    const char* keyword;
    Vec3 p;
    double value;
  };
  const Case cases[] = {
    { "ell", { 0, 0, 0 }, 1 },          // 1 - 0
    { "ell", { 0.5, 0.5, 0.5 }, 0.25 }, // 1 - 3/4
    { "seat", { 1, 2, 0.5 }, 3.5 },     // 0.5 - 1 + 4
    { "ellpar", { 1, 2, 0.5 }, -4.5 },  // 0.5 - 1 - 4
    { "unihyp", { 1, 1, 1 }, 0 },       // 1 - 1 - 1 + 1
    { "unihyp", { 0, 0, 3 }, 10 },      // 1 + 9
    { "duahyp", { 0, 0, 2 }, 3 },       // 4 - 1
    { "duahyp", { 0, 0, 0 }, -1 },      // the gap between the sheets
    { "cone", { 1, 1, 2 }, 2 },         // 4 - 1 - 1
    { "cylinder", { 0.6, 0.8, 9 }, 0 }, // on the unit cylinder, whatever z
    { "layer", { 5, -7, 0.5 }, 0.75 },  // 1 - 0.25
    { "plane", { 3, 4, -2 }, 2 },       // -z
    { "clin", { 1, 8, 3 }, 8 },         // 9 - 1, whatever y
    { "parabola", { 2, 8, 3 }, -1 },    // 3 - 4
    { "hyperbola", { 1, 8, 3 }, 7 },    // 9 - 1 - 1
  };
  for (const Case& c : cases)
  {
    EXPECT_EQ(at(namedQuadric(*quadricTypeFromKeyword(c.keyword)), c.p), c.value) << c.keyword;
  }
}

TEST(Quadrics, EquationOneCoefficients)
{
  // Item 24's values are Primitives3D.QuadricCoefficientOrder's (TestPrimitives.cxx).
  // The completed squares change no value: eq. (1) summed term by term at random points.
  const std::array<double, 10> k{ 1.5, -2, 0.5, 0.3, -0.7, 1, 3, -4, 0.25, 0.2 };
  Random rng(24);
  for (int i = 0; i < 100; ++i)
  {
    const Vec3 p = rng.point(-3, 3);
    const double x = p[0], y = p[1], z = p[2];
    const double expected = k[0] * x * x + k[1] * y * y + k[2] * z * z + k[3] * x * y +
      k[4] * x * z + k[5] * y * z + k[6] * x + k[7] * y + k[8] * z + k[9];
    EXPECT_NEAR(at(quadric(k), p), expected, 1e-12 * (1 + std::abs(expected)));
  }
}

TEST(Quadrics, PerturbationFunction)
{
  // Item 26: R(Q) = Q^3 for Q >= 0, else 0: R(-0.5) = 0, R(0) = 0, R(0.5) = 0.125, R(2) = 8.
  const Expr q = Expr::x();
  const Expr r = perturbation(q, 1);
  EXPECT_EQ(at(r, -0.5), 0);
  EXPECT_EQ(at(r, 0), 0);
  EXPECT_EQ(at(r, 0.5), 0.125);
  EXPECT_EQ(at(r, 2), 8);
  // The factor k scales it (papers.md E9): k = -10 carves.
  EXPECT_EQ(at(perturbation(q, -10), 0.5), -1.25);
  expectInvalid([&] { perturbation(q, notANumber); }, { "perturbation", "factor" });
}

TEST(Quadrics, PerturbationIsC2AcrossItsSupport)
{
  // Item 28: Q = 1 - |X|^2; along the x axis R(r) = max(0, 1 - r^2)^3. With h = 1e-4 the central
  // differences at r = 1 give |R'| < 1e-6 and |R''| <= 10 h; the one-sided third derivative is
  // -48 from inside (d^3/dr^3 (1 - r^2)^3 = 72 r (1 - r^2) - 48 r^3) and 0 from outside.
  const Expr r = perturbation(sphere({ 0, 0, 0 }, 1).function(), 1);
  auto R = [&](double x)
  {
    return at(r, x);
  };
  const double h = 1e-4;
  EXPECT_LT(std::abs((R(1 + h) - R(1 - h)) / (2 * h)), 1e-6);
  EXPECT_LE(std::abs((R(1 + h) - 2 * R(1) + R(1 - h)) / (h * h)), 10 * h);
  const double inside = (R(1) - 3 * R(1 - h) + 3 * R(1 - 2 * h) - R(1 - 3 * h)) / (h * h * h);
  EXPECT_NEAR(inside, -48, 0.1);
  const double outside = (R(1 + 3 * h) - 3 * R(1 + 2 * h) + 3 * R(1 + h) - R(1)) / (h * h * h);
  EXPECT_EQ(outside, 0);
}

TEST(Quadrics, SuperpositionAndLocality)
{
  // Items 27 and 29: the sum does not depend on the order; a perturbation whose Q < 0 everywhere
  // (Q = -1 - x^2) leaves F' equal to F bit for bit, and so does any point outside every support.
  const Shape base = namedQuadric(QuadricType::Ell);
  const Shape q1 = sphere({ 1, 0, 0 }, 0.5);
  const Shape q2 = sphere({ 0, 1, 0 }, 0.4);
  const Shape never = quadric({ -1, 0, 0, 0, 0, 0, 0, 0, 0, -1 });
  const Shape p = perturb(base, { q1, q2 }, { 2, -3 });
  const Shape swapped = perturb(base, { q2, q1 }, { -3, 2 });
  const Shape withNever = perturb(base, { q1, never, q2 }, { 2, 5, -3 });
  const Shape onlyNever = perturb(base, { never }, { 7 });
  Random rng(29);
  for (int i = 0; i < 300; ++i)
  {
    const Vec3 x = rng.point(-2, 2);
    EXPECT_EQ(at(p, x), at(swapped, x));
    EXPECT_EQ(at(p, x), at(withNever, x));
    EXPECT_EQ(at(onlyNever, x), at(base, x));
    if (at(q1, x) < 0 && at(q2, x) < 0)
    {
      EXPECT_EQ(at(p, x), at(base, x));
    }
  }
}

TEST(Quadrics, GrowthOnlyAndTheFixture)
{
  // Item 30: F = 1 - |X|^2, Q = 0.25 - |X - (1,0,0)|^2 (papers.md 2.2's table). F'(1,0,0) =
  // 0.015625 for k = 1; the surface crosses the +x axis at 1.0077766 (k = 1), 1.0709777 (k = 10)
  // and, carving, 0.9242621 (k = -10), to 7 digits.
  const Shape f = namedQuadric(QuadricType::Ell);
  const Shape q = sphere({ 1, 0, 0 }, 0.5);
  EXPECT_EQ(at(perturb(f, { q }, { 1 }), 1, 0, 0), 0.015625);
  struct Row
  {
    double k, crossing, lo, hi;
  };
  for (const Row& row : { Row{ 1, 1.0077766, 1.0, 1.4 }, Row{ 10, 1.0709777, 1.0, 1.4 },
         Row{ -10, 0.9242621, 0.5, 1.0 } })
  {
    const Shape p = perturb(f, { q }, { row.k });
    double lo = row.lo, hi = row.hi;
    ASSERT_LT(at(p, lo) * at(p, hi), 0);
    for (int i = 0; i < 200 && hi - lo > 1e-15; ++i)
    {
      const double m = 0.5 * (lo + hi);
      ((at(p, m) >= 0) == (at(p, row.lo) >= 0) ? lo : hi) = m;
    }
    EXPECT_NEAR(lo, row.crossing, 5e-8) << "k = " << row.k;
  }
  // With k = 1 the solid only grows: F >= 0 implies F' >= 0 at every sample.
  const Shape grown = perturb(f, { q }, { 1 });
  Random rng(30);
  for (int i = 0; i < 2000; ++i)
  {
    const Vec3 x = rng.point(-1.6, 1.6);
    if (at(f, x) >= 0)
    {
      EXPECT_GE(at(grown, x), 0);
    }
  }
}

TEST(Quadrics, VoxelBoundIsTheIntervalBound)
{
  // Item 31's fixture: B = [0.9, 1.1] x [-0.1, 0.1]^2: max_B F = 1 - 0.81 = 0.19, max_B Q = 0.25,
  // bound 0.19 + 0.25^3 = 0.205625 >= the sampled max 0.203824 (21^3 grid).
  const Shape f = namedQuadric(QuadricType::Ell);
  const Shape q = sphere({ 1, 0, 0 }, 0.5);
  const Shape p = perturb(f, { q }, { 1 });
  const Interval b = bound(p.function(), { 0.9, -0.1, -0.1 }, { 1.1, 0.1, 0.1 });
  EXPECT_NEAR(b.hi, 0.205625, 1e-12);
  EXPECT_GE(b.hi, 0.205625);
  double sampled = -1e300;
  for (int i = 0; i <= 20; ++i)
  {
    for (int j = 0; j <= 20; ++j)
    {
      for (int k = 0; k <= 20; ++k)
      {
        sampled = std::max(sampled, at(p, 0.9 + 0.01 * i, -0.1 + 0.01 * j, -0.1 + 0.01 * k));
      }
    }
  }
  EXPECT_NEAR(sampled, 0.203824, 5e-7);
  EXPECT_LE(sampled, b.hi);
}

TEST(Quadrics, IntervalBoundHoldsEverySample)
{
  // Item 31 in general: for random axis-aligned quadric types placed by move and scale, with
  // perturbations of both signs, over random boxes: (a) the upper bound is the formula
  // max_B F + sum_{k>0} k max(0, max_B Q)^3 + sum_{k<0} k max(0, min_B Q)^3 with max_B F exact
  // (the completed squares: each term's range is exact and the terms are in separate
  // coordinates); (b) every sampled value of F' lies in the interval, so no box holding a point
  // of the solid is culled.
  Random rng(31);
  const std::vector<QuadricTypeInfo>& types = quadricTypes();
  for (int trial = 0; trial < 60; ++trial)
  {
    // A type's coefficients moved to c and scaled by s: A_ii / s_i^2 (x_i - c_i)^2 ... expanded.
    auto placed = [&](const QuadricTypeInfo& t)
    {
      const Vec3 c = rng.point(-0.5, 0.5);
      const Vec3 s = rng.point(0.5, 1.5);
      std::array<double, 10> k{};
      k[9] = t.coefficients[9];
      for (int i = 0; i < 3; ++i)
      {
        const double a = t.coefficients[i] / (s[i] * s[i]);
        const double b = t.coefficients[6 + i] / s[i];
        k[i] = a;
        k[6 + i] = b - 2 * a * c[i];
        k[9] += a * c[i] * c[i] - b * c[i];
      }
      return k;
    };
    const std::array<double, 10> fk = placed(types[static_cast<std::size_t>(trial) % 12]);
    const Shape base = quadric(fk);
    std::vector<Shape> qs;
    std::vector<double> factors;
    for (int n = 0; n < 3; ++n)
    {
      qs.push_back(quadric(placed(types[static_cast<std::size_t>(trial + 5 * n + 1) % 12])));
      factors.push_back(rng.uniform(-4, 4));
    }
    const Shape p = perturb(base, qs, factors);
    const Vec3 c = rng.point(-1, 1);
    const double w = rng.uniform(0.05, 0.6);
    const Vec3 lo{ c[0] - w, c[1] - w, c[2] - w };
    const Vec3 hi{ c[0] + w, c[1] + w, c[2] + w };
    const Interval total = bound(p.function(), lo, hi);
    // max_B F of the separable quadric, exactly: per axis, the max of a x^2 + b x on [lo, hi].
    double maxF = fk[9];
    for (int i = 0; i < 3; ++i)
    {
      const double a = fk[i], b = fk[6 + i];
      double m = std::max(a * lo[i] * lo[i] + b * lo[i], a * hi[i] * hi[i] + b * hi[i]);
      const double v = a != 0 ? -b / (2 * a) : lo[i] - 1;
      if (v > lo[i] && v < hi[i])
      {
        m = std::max(m, a * v * v + b * v);
      }
      maxF += m;
    }
    EXPECT_NEAR(bound(base.function(), lo, hi).hi, maxF, 1e-9 * (1 + std::abs(maxF)));
    double formula = bound(base.function(), lo, hi).hi;
    for (std::size_t n = 0; n < qs.size(); ++n)
    {
      const Interval qb = bound(qs[n].function(), lo, hi);
      const double m = std::max(0.0, factors[n] > 0 ? qb.hi : qb.lo);
      formula += factors[n] * m * m * m;
    }
    EXPECT_NEAR(total.hi, formula, 1e-9 * (1 + std::abs(formula))) << "trial " << trial;
    for (int i = 0; i < 9; ++i)
    {
      for (int j = 0; j < 9; ++j)
      {
        for (int k = 0; k < 9; ++k)
        {
          const Vec3 x{ lo[0] + (hi[0] - lo[0]) * i / 8, lo[1] + (hi[1] - lo[1]) * j / 8,
            lo[2] + (hi[2] - lo[2]) * k / 8 };
          const double v = at(p, x);
          ASSERT_TRUE(total.contains(v))
            << "trial " << trial << ": " << v << " not in [" << total.lo << ", " << total.hi << "]";
        }
      }
    }
  }
}

TEST(Quadrics, EveryEvaluatorAgrees)
{
  // The named types and a perturbed one through the compiled point evaluator (and so the JIT's
  // opcodes: they lower to the kernel's ordinary operations) against the reference.
  std::vector<Shape> shapes;
  for (const QuadricTypeInfo& t : quadricTypes())
  {
    shapes.push_back(namedQuadric(t.type));
  }
  shapes.push_back(perturb(namedQuadric(QuadricType::Cone), { sphere({ 0, 0, 1 }, 0.5) }, { -2 }));
  Random rng(32);
  for (const Shape& s : shapes)
  {
    PointEvaluator point(Tape::compile(s.function()));
    for (int i = 0; i < 50; ++i)
    {
      const Vec3 p = rng.point(-2, 2);
      EXPECT_NEAR(point.eval(p[0], p[1], p[2]), at(s, p), 1e-12) << s.label();
    }
  }
}
