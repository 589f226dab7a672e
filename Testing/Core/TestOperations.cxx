// SPDX-License-Identifier: BSD-3-Clause
// Tests of the FRep operation library: set operations, blending, domains, dimension and time, and
// the compiled evaluators; the space mappings are in TestSpaceMaps.cxx. The operands and the
// "probe" method are described in OperationsTesting.h.
#include "OperationsTesting.h"

#include <cmath>
#include <functional>
#include <limits>
#include <string>

using namespace ictk::frep;
using namespace operationstest;

namespace
{
Shape sphere(double r)
{
  return Shape(
    Expr(r * r) - square(Expr::x()) - square(Expr::y()) - square(Expr::z()), Domain::XYZ, "sphere");
}

Shape block3()
{
  // |x|, |y|, |z| <= 1 as a min of slabs (the exact form does not matter for domain tests).
  return Shape(min(min(1.0 - square(Expr::x()), 1.0 - square(Expr::y())), 1.0 - square(Expr::z())),
    Domain::XYZ, "block");
}

// The grid of operand values used for the formula checks.
const double samples[] = { -7.5, -3.0, -1.0, -0.25, 0.0, 0.3, 1.0, 2.0, 4.0, 11.0 };

// Reference forms written straight from the spec, in plain doubles.
double refUnion(double f1, double f2, double a)
{
  return (f1 + f2 + std::sqrt(f1 * f1 + f2 * f2 - 2.0 * a * f1 * f2)) / (1.0 + a);
}
double refIntersection(double f1, double f2, double a)
{
  return (f1 + f2 - std::sqrt(f1 * f1 + f2 * f2 - 2.0 * a * f1 * f2)) / (1.0 + a);
}
// Thesis L651-L659, case by case as written, with amplitude a0.
double refBoundedBlend(double f1, double f2, double f3, double a0, double a1, double a2, double a3)
{
  const double r1sq = (f1 / a1) * (f1 / a1) + (f2 / a2) * (f2 / a2);
  const double r2sq = f3 > 0 ? (f3 / a3) * (f3 / a3) : 0.0;
  const double r = r2sq > 0 ? r1sq / (r1sq + r2sq) : 1.0;
  const double disp = r < 1 ? std::pow(1 - r * r, 3) / (1 + r * r) : 0.0;
  return f1 + f2 + std::sqrt(f1 * f1 + f2 * f2) + a0 * disp;
}
double refRi(double a, double b)
{
  return a + b - std::sqrt(a * a + b * b);
}
} // namespace

// --- set operations --------------------------------------------------------------------------

TEST(Operations, RUnionAndIntersectionThesisValues)
{
  // Spec items 10 and 11 (thesis L620, L622): e.g. R-union(3, 4) = 3 + 4 + 5 = 12,
  // R-intersection(3, -4) = 3 - 4 - 5 = -6.
  const Shape u = unite(probe1, probe2);
  const Shape i = intersect(probe1, probe2);
  EXPECT_NEAR(eval(u, 3, 4), 12.0, tol);
  EXPECT_NEAR(eval(u, -3, -4), -2.0, tol);
  EXPECT_NEAR(eval(u, 3, -4), 4.0, tol);
  EXPECT_NEAR(eval(u, 0, 0), 0.0, tol);
  EXPECT_NEAR(eval(i, 3, 4), 2.0, tol);
  EXPECT_NEAR(eval(i, -3, -4), -12.0, tol);
  EXPECT_NEAR(eval(i, 3, -4), -6.0, tol);
  EXPECT_NEAR(eval(i, 0, 0), 0.0, tol);
  EXPECT_EQ(u.domain(), Domain::XYZ);
}

TEST(Operations, AlphaSystemMatchesFormulaOnSamples)
{
  // Spec item 14 and thesis_ch2_3.md 1.7 [EXT]: alpha-system; alpha = 1 gives max/min exactly.
  for (double alpha : { -0.5, 0.0, 0.3, 0.9 })
  {
    const Shape u = unite(probe1, probe2, alpha);
    const Shape i = intersect(probe1, probe2, alpha);
    const Shape d = subtract(probe1, probe2, alpha);
    for (double f1 : samples)
    {
      for (double f2 : samples)
      {
        const double scaleTol = tol * (1.0 + std::fabs(f1) + std::fabs(f2));
        EXPECT_NEAR(eval(u, f1, f2), refUnion(f1, f2, alpha), scaleTol)
          << alpha << " " << f1 << " " << f2;
        EXPECT_NEAR(eval(i, f1, f2), refIntersection(f1, f2, alpha), scaleTol);
        EXPECT_NEAR(eval(d, f1, f2), refIntersection(f1, -f2, alpha), scaleTol);
      }
    }
  }
  const Shape u1 = unite(probe1, probe2, 1.0);
  const Shape i1 = intersect(probe1, probe2, 1.0);
  for (double f1 : samples)
  {
    for (double f2 : samples)
    {
      EXPECT_EQ(eval(u1, f1, f2), std::max(f1, f2));
      EXPECT_EQ(eval(i1, f1, f2), std::min(f1, f2));
    }
  }
}

TEST(Operations, RFunctionsStayExactNextToAFarOperand)
{
  // Next to a far operand the plain sum f1 + f2 + sqrt(f1^2 + f2^2) cancels: at (-1e8, 1) it
  // gave 1 for 1.000000005, at (-1e8, 1e-9) 0 for 1e-9, the nearer surface lost. The exact values
  // below are those of the formulas on the same double operands in 80-digit decimal arithmetic,
  // rounded to double; every path must give them to 4 ulps.
  struct Case
  {
    Shape shape;
    double f1, f2, exact;
  };
  const Case cases[] = {
    { unite(probe1, probe2), -1e8, 1, 1.000000005 },
    { unite(probe1, probe2), -1e8, 1e-9, 1e-9 },
    { unite(probe1, probe2), 1e-9, -1e8, 1e-9 },
    { unite(probe1, probe2), -1e8, -1, -0.999999995 },
    { unite(probe1, probe2, 0.5), -1e8, 0.5, 0.500000000625 },
    { unite(probe1, probe2, -0.5), -1e8, 0.5, 0.500000001875 },
    { intersect(probe1, probe2), 1e8, -1, -1.000000005 },
    { intersect(probe1, probe2), 1e8, 1e-9, 1e-9 },
    { intersect(probe1, probe2), 1e8, 1, 0.999999995 },
    { subtract(probe1, probe2), 1e8, -1e-9, 1e-9 },
    { blendUnion(probe1, probe2, 1, 1, 1), -1e8, 1e-9, 1.0000001e-09 },
    { blendIntersection(probe1, probe2, 1, 1, 1), 1e8, 1e-9, 1.0000001e-09 },
  };
  const double ulps = 4 * std::numeric_limits<double>::epsilon();
  for (const Case& c : cases)
  {
    SCOPED_TRACE(c.shape.label() + " at " + std::to_string(c.f1) + ", " + std::to_string(c.f2));
    const double tolerance = ulps * std::fabs(c.exact);
    EXPECT_NEAR(eval(c.shape, c.f1, c.f2), c.exact, tolerance);
    PointEvaluator point(Tape::compile(c.shape.function()));
    EXPECT_NEAR(point.eval(c.f1, c.f2), c.exact, tolerance);
    GradientEvaluator gradient(Tape::compile(c.shape.function()));
    EXPECT_NEAR(gradient.eval(c.f1, c.f2).value, c.exact, tolerance);
    // A box about the operands encloses the values at its corners and, like them, has one sign.
    IntervalEvaluator interval(Tape::compile(c.shape.function()));
    const double w1 = std::min(1.0, 0.25 * std::fabs(c.f1)),
                 w2 = std::min(1.0, 0.25 * std::fabs(c.f2));
    const Interval range = interval.eval(Region{ { Interval{ c.f1 - w1, c.f1 + w1 },
      Interval{ c.f2 - w2, c.f2 + w2 }, Interval{ 0, 0 }, Interval{ 0, 0 } } });
    for (double d1 : { -w1, w1 })
    {
      for (double d2 : { -w2, w2 })
      {
        const double v = point.eval(c.f1 + d1, c.f2 + d2);
        EXPECT_TRUE(range.lo <= v && v <= range.hi) << v << " " << range.lo << " " << range.hi;
      }
    }
    EXPECT_TRUE(c.exact > 0 ? range.lo > 0 : range.hi < 0) << range.lo << " " << range.hi;
  }
  // The double forms are the same formulas.
  EXPECT_NEAR(rUnion(-1e8, 1e-9), 1e-9, ulps * 1e-9);
  EXPECT_NEAR(rIntersection(1e8, -1.0), -1.000000005, ulps);
  EXPECT_NEAR(rUnion(-1e8, 0.5, 0.5), 0.500000000625, ulps);
  EXPECT_EQ(rUnion(-2.0, 3.0, 1.0), 3.0);
  EXPECT_EQ(rIntersection(-2.0, 3.0, 1.0), -2.0);
  // The gradient (1 + f1 / r, 1 + f2 / r) at (-1e8, 1): 1 - 1e8 / sqrt(1e16 + 1) = 5e-17, where
  // the sum's derivative gave 0, and 1.00000001.
  GradientEvaluator gradient(Tape::compile(unite(probe1, probe2).function()));
  const ValueGradient g = gradient.eval(-1e8, 1);
  EXPECT_NEAR(g.gradient[0], 5e-17, 1e-22);
  EXPECT_NEAR(g.gradient[1], 1.00000001, ulps);
}

TEST(Operations, RFunctionSignAgreesWithMinMax)
{
  // Spec item 12 (L626): sign(R-union) = sign(max), sign(R-intersection) = sign(min).
  const Shape u = unite(probe1, probe2);
  const Shape i = intersect(probe1, probe2);
  for (double f1 : samples)
  {
    for (double f2 : samples)
    {
      const auto sgn = [](double v)
      {
        return (v > 0) - (v < 0);
      };
      EXPECT_EQ(sgn(eval(u, f1, f2)), sgn(std::max(f1, f2))) << f1 << " " << f2;
      EXPECT_EQ(sgn(eval(i, f1, f2)), sgn(std::min(f1, f2))) << f1 << " " << f2;
    }
  }
}

TEST(Operations, AlphaOutOfRangeIsRejected)
{
  expectThrowMentioning<std::invalid_argument>(
    [] { unite(probe1, probe2, -1.0); }, { "unite", "alpha" });
  expectThrowMentioning<std::invalid_argument>(
    [] { intersect(probe1, probe2, 1.5); }, { "intersect", "alpha" });
  expectThrowMentioning<std::invalid_argument>(
    [] { subtract(probe1, probe2, std::nan("")); }, { "subtract", "alpha" });
}

TEST(Operations, MinMaxForms)
{
  // Spec item 9 (L614-L616): d1 = 1, d2 = -2 gives union 1, intersection -2; subtraction is
  // min(d1, -d2) = min(1, 2) = 1.
  EXPECT_EQ(eval(uniteMinMax(probe1, probe2), 1, -2), 1.0);
  EXPECT_EQ(eval(intersectMinMax(probe1, probe2), 1, -2), -2.0);
  EXPECT_EQ(eval(subtractMinMax(probe1, probe2), 1, -2), 1.0);
  EXPECT_EQ(eval(subtractMinMax(probe1, probe2), 1, 0.5), -0.5);
  EXPECT_EQ(eval(negate(probe1), 2.5), -2.5);
}

TEST(Operations, SubtractionOfConcentricSpheres)
{
  // Spec item 15: sphere(2) \ sphere(1). Centre: f1 = 4, f2 = 1 -> 4 - 1 - sqrt(17) < 0.
  // Shell point (1.5, 0, 0): f1 = 1.75, f2 = -1.25 -> 1.75 + 1.25 - sqrt(1.75^2 + 1.25^2) > 0.
  const Shape shell = subtract(sphere(2.0), sphere(1.0));
  EXPECT_NEAR(eval(shell, 0, 0, 0), 3.0 - std::sqrt(17.0), tol);
  EXPECT_NEAR(eval(shell, 1.5, 0, 0), 3.0 - std::sqrt(1.75 * 1.75 + 1.25 * 1.25), tol);
  EXPECT_GT(eval(shell, 1.5, 0, 0), 0.0);
  EXPECT_LT(eval(shell, 2.5, 0, 0), 0.0);
}

TEST(Operations, UnionOfSeparateDisks)
{
  // Spec item 16: unit disks at (+-1.5, 0).
  const Shape u = unite(disk(-1.5, 0, 1), disk(1.5, 0, 1));
  EXPECT_GT(eval(u, 1.5, 0), 0.0);
  EXPECT_GT(eval(u, -1.5, 0), 0.0);
  EXPECT_LT(eval(u, 0, 0), 0.0);
  EXPECT_EQ(u.domain(), Domain::XY);
}

TEST(Operations, CmRFunctions)
{
  // Pasko & Savchenko: (f1 + f2 +- sqrt(f1^2 + f2^2)) (f1^2 + f2^2)^(m/2). At (3, 4), f1^2 + f2^2 =
  // 25: union m = 1: 12 * 5 = 60; m = 2: 12 * 25 = 300; intersection m = 2: 2 * 25 = 50;
  // subtraction m = 1 (f2 -> -4): (3 - 4 - 5) * 5 = -30.
  EXPECT_NEAR(eval(uniteCm(probe1, probe2, 1), 3, 4), 60.0, tol);
  EXPECT_NEAR(eval(uniteCm(probe1, probe2, 2), 3, 4), 300.0, tol);
  EXPECT_NEAR(eval(intersectCm(probe1, probe2, 2), 3, 4), 50.0, tol);
  EXPECT_NEAR(eval(subtractCm(probe1, probe2, 1), 3, 4), -30.0, tol);
  for (double f1 : samples)
  {
    for (double f2 : samples)
    {
      EXPECT_NEAR(eval(uniteCm(probe1, probe2, 0), f1, f2), refUnion(f1, f2, 0.0), tol * 100);
      const double s = f1 * f1 + f2 * f2;
      EXPECT_NEAR(eval(intersectCm(probe1, probe2, 3), f1, f2),
        refIntersection(f1, f2, 0.0) * s * std::sqrt(s), 1e-12 * (1.0 + s * s));
    }
  }
  EXPECT_THROW(uniteCm(probe1, probe2, -1), std::invalid_argument);
}

// --- blending ----------------------------------------------------------------------------------

TEST(Operations, BlendUnionThesisValues)
{
  // Spec items 17-18 (L643-L645): F_b(0, 0) = 0 + 1/(1 + 0 + 0) = 1; F_b(3, 4) = 12 + 1/(1 + 9 +
  // 16).
  const Shape b = blendUnion(probe1, probe2, 1, 1, 1);
  EXPECT_NEAR(eval(b, 0, 0), 1.0, tol);
  EXPECT_NEAR(eval(b, 3, 4), 12.0 + 1.0 / 26.0, tol);
  // Item 19: a0 = 0 is the R-union.
  const Shape b0 = blendUnion(probe1, probe2, 0, 1, 1);
  const Shape u = unite(probe1, probe2);
  for (double f1 : samples)
  {
    for (double f2 : samples)
    {
      EXPECT_NEAR(eval(b0, f1, f2), eval(u, f1, f2), tol);
    }
  }
  // Item 20: the displacement vanishes far away: disp(100, 100) = 1/20001 < 1e-3.
  EXPECT_LT(eval(b, 100, 100) - eval(u, 100, 100), 1e-3);
}

TEST(Operations, BlendsMatchFormulaOnSamples)
{
  const double a0 = 0.7, a1 = 1.3, a2 = 2.5;
  const Shape bu = blendUnion(probe1, probe2, a0, a1, a2);
  const Shape bi = blendIntersection(probe1, probe2, a0, a1, a2);
  // Item 22: swapping the operands together with a1 and a2 gives the same field: `swapped` reads
  // its first operand from y (scaled by a2) and its second from x (scaled by a1).
  const Shape swapped = blendUnion(probe2, probe1, a0, a2, a1);
  for (double f1 : samples)
  {
    for (double f2 : samples)
    {
      const double disp = a0 / (1 + (f1 / a1) * (f1 / a1) + (f2 / a2) * (f2 / a2));
      const double scaleTol = tol * (1.0 + std::fabs(f1) + std::fabs(f2));
      EXPECT_NEAR(eval(bu, f1, f2), refUnion(f1, f2, 0) + disp, scaleTol);
      EXPECT_NEAR(eval(bi, f1, f2), refIntersection(f1, f2, 0) + disp, scaleTol);
      EXPECT_NEAR(eval(swapped, f1, f2), eval(bu, f1, f2), scaleTol);
    }
  }
  // hfBlendInt at (3, 4) with a = 1: 2 + 1/26.
  EXPECT_NEAR(eval(blendIntersection(probe1, probe2, 1, 1, 1), 3, 4), 2.0 + 1.0 / 26.0, tol);
}

TEST(Operations, BlendAddsMaterialBetweenTouchingDisks)
{
  // Item 21: unit disks at (+-1, 0) touch at the origin. Above the contact point, at (0, 0.3), both
  // fields are 1 - 1 - 0.09 = -0.09, so the R-union is -0.18 + 0.09 sqrt(2) < 0; a positive a0 adds
  // 1/(1 + 2 * 0.0081) there and makes it inside, and more a0 never removes material.
  const Shape a = disk(-1, 0, 1), b = disk(1, 0, 1);
  EXPECT_LT(eval(unite(a, b), 0, 0.3), 0.0);
  EXPECT_GT(eval(blendUnion(a, b, 0.5, 1, 1), 0, 0.3), 0.0);
  for (double x = -2.5; x <= 2.5; x += 0.25)
  {
    for (double y = -1.5; y <= 1.5; y += 0.25)
    {
      EXPECT_LE(eval(blendUnion(a, b, 0.2, 1, 1), x, y), eval(blendUnion(a, b, 0.5, 1, 1), x, y));
    }
  }
}

TEST(Operations, BlendParameterValidation)
{
  expectThrowMentioning<std::invalid_argument>(
    [] { blendUnion(probe1, probe2, 1, 0, 1); }, { "blendUnion", "a1" });
  expectThrowMentioning<std::invalid_argument>(
    [] { blendIntersection(probe1, probe2, 1, 1, std::nan("")); }, { "blendIntersection", "a2" });
  expectThrowMentioning<std::invalid_argument>(
    [] { blendUnion(probe1, probe2, INFINITY, 1, 1); }, { "blendUnion", "a0" });
  expectThrowMentioning<std::invalid_argument>(
    [] { boundedBlend(probe1, probe2, probe3, 1, 1, 0); }, { "boundedBlend", "a3" });
  expectThrowMentioning<std::invalid_argument>(
    [] { offset(probe1, std::nan("")); }, { "offset", "d" });
}

TEST(Operations, BoundedBlendThesisValues)
{
  // Item 23: f1 = f2 = 0, f3 = 1: r1^2 = 0, r2^2 = 1, r = 0, disp = 1, F = 0 + 1 = 1.
  const Shape bb = boundedBlend(probe1, probe2, probe3, 1, 1, 1);
  EXPECT_NEAR(eval(bb, 0, 0, 1), 1.0, tol);
  // Item 24: f1 = 1, f2 = 0, f3 = 1: r1^2 = 1, r2^2 = 1, r = 1/2, disp = (1 - 1/4)^3 / (1 + 1/4)
  // = 0.421875 / 1.25 = 0.3375, F = 1 + 0 + 1 + 0.3375 = 2.3375.
  EXPECT_NEAR(eval(bb, 1, 0, 1), 2.3375, tol);
  // Item 27: a0 scales the displacement: a0 = 2 gives 2 + 2 * 0.3375.
  EXPECT_NEAR(eval(boundedBlend(probe1, probe2, probe3, 1, 1, 1, 2.0), 1, 0, 1), 2.675, tol);
  // Where f1 = f2 = 0 and f3 > 0, r = 0 and disp = 1 whatever a3: F = a0.
  EXPECT_NEAR(eval(boundedBlend(probe1, probe2, probe3, 2, 3, 0.5, 0.25), 0, 0, 7), 0.25, tol);
}

TEST(Operations, BoundedBlendMatchesFormulaOnSamples)
{
  const double a0 = 1.7, a1 = 0.8, a2 = 1.9, a3 = 0.6;
  const Shape bb = boundedBlend(probe1, probe2, probe3, a1, a2, a3, a0);
  const Shape u = unite(probe1, probe2);
  for (double f1 : samples)
  {
    for (double f2 : samples)
    {
      for (double f3 : samples)
      {
        const double v = eval(bb, f1, f2, f3);
        EXPECT_NEAR(
          v, refBoundedBlend(f1, f2, f3, a0, a1, a2, a3), tol * (1 + std::fabs(f1) + std::fabs(f2)))
          << f1 << " " << f2 << " " << f3;
        // Item 25: outside the bounding solid the result is the R-union exactly.
        if (f3 <= 0)
        {
          EXPECT_EQ(v, eval(u, f1, f2));
        }
        // Items 26-27: 0 <= r <= 1 means 0 <= disp <= 1, so 0 <= F - union <= a0.
        const double disp = (v - eval(u, f1, f2)) / a0;
        EXPECT_GE(disp, -1e-12);
        EXPECT_LE(disp, 1.0 + 1e-12);
      }
    }
  }
}

TEST(Operations, BoundedBlendIsContinuousAcrossTheBound)
{
  // Item 26: as f3 -> 0+, r -> 1- and disp -> 0, so F approaches the plain union.
  const Shape bb = boundedBlend(probe1, probe2, probe3, 1, 1, 1);
  const double u = eval(unite(probe1, probe2), 0.5, -0.2);
  EXPECT_NEAR(eval(bb, 0.5, -0.2, 1e-4), u, 1e-12);
  EXPECT_GT(eval(bb, 0.5, -0.2, 0.1), u);
}

TEST(Operations, OffsetAddsConstant)
{
  // Sphere r = 1 grown by 3 (f + 3): the centre value 1 becomes 4 and (2, 0, 0) with f = -3 is on
  // the boundary.
  const Shape s = offset(unitSphere(), 3.0);
  EXPECT_NEAR(eval(s, 0, 0, 0), 4.0, tol);
  EXPECT_NEAR(eval(s, 2, 0, 0), 0.0, tol);
}

// --- domains -----------------------------------------------------------------------------------

TEST(Operations, MixedDomainsAreRejected)
{
  // Spec item 68 (L1118): a union of an XY circle and an XYZ block is an error naming both.
  const Shape c = disk(0, 0, 1);
  const Shape b = block3();
  expectThrowMentioning<DomainError>([&] { unite(c, b); }, { "circle", "block", "XY", "XYZ" });
  expectThrowMentioning<DomainError>([&] { intersect(c, b); }, { "circle", "block" });
  expectThrowMentioning<DomainError>([&] { subtract(b, c); }, { "circle", "block" });
  expectThrowMentioning<DomainError>([&] { uniteMinMax(c, b); }, { "circle", "block" });
  expectThrowMentioning<DomainError>([&] { intersectMinMax(c, b); }, { "circle", "block" });
  expectThrowMentioning<DomainError>([&] { subtractMinMax(c, b); }, { "circle", "block" });
  expectThrowMentioning<DomainError>([&] { uniteCm(c, b, 1); }, { "circle", "block" });
  expectThrowMentioning<DomainError>([&] { blendUnion(c, b, 1, 1, 1); }, { "circle", "block" });
  expectThrowMentioning<DomainError>(
    [&] { blendIntersection(c, b, 1, 1, 1); }, { "circle", "block" });
  expectThrowMentioning<DomainError>(
    [&] { boundedBlend(b, b, c, 1, 1, 1); }, { "circle", "block" });
  expectThrowMentioning<DomainError>([&] { metamorphosis(c, b, 0.5); }, { "circle", "block" });
  expectThrowMentioning<DomainError>(
    [&] { spaceTimeBlend(c, b, 0, 1, 1, 1, 1, 1); }, { "circle", "block" });
}

// --- dimension and time ------------------------------------------------------------------------

TEST(Operations, CartesianProductOfDiskAndTimeInterval)
{
  // XY disk x T interval -> XYT: the R-intersection of f1(x, y) and f2(t).
  const Shape d = disk(0, 0, 1);
  const Shape ti((Expr::t() - 0.0) * (2.0 - Expr::t()), Domain::T, "interval");
  const Shape p = cartesianProduct(d, ti);
  EXPECT_EQ(p.domain(), Domain::XYT);
  // (0.5, 0, t = 1): f1 = 0.75, f2 = 1 -> 1.75 - 1.25 = 0.5.
  EXPECT_NEAR(eval(p, 0.5, 0, 0, 1), 0.5, tol);
  EXPECT_LT(eval(p, 0.5, 0, 0, 3), 0.0);
  EXPECT_LT(eval(p, 1.5, 0, 0, 1), 0.0);
  for (double x : { -1.2, 0.3 })
  {
    for (double t : { -0.5, 0.7, 1.9 })
    {
      EXPECT_NEAR(eval(p, x, 0.4, 0, t), refRi(1 - x * x - 0.16, t * (2 - t)), tol);
    }
  }
  const Shape seg((Expr::x() + 1.0) * (1.0 - Expr::x()), Domain::X, "segment");
  EXPECT_EQ(cartesianProduct(seg, ti).domain(), Domain::XT);
  expectThrowMentioning<DomainError>(
    [&] { cartesianProduct(d, seg); }, { "cartesianProduct", "circle", "segment" });
  expectThrowMentioning<DomainError>(
    [&] { cartesianProduct(d, unitSphere()); }, { "cartesianProduct" });
}

TEST(Operations, CartesianProductWithPlacementThesisExample)
{
  // Spec item 72 (L1139-L1141): the XZ disk (r = 1) x the Y segment [-2, 2] is a cylinder along y.
  const Shape d = disk(0, 0, 1);
  const Shape seg((Expr::x() + 2.0) * (2.0 - Expr::x()), Domain::X, "segment");
  const Shape c = cartesianProduct(d, { Axis::X, Axis::Z }, seg, { Axis::Y });
  EXPECT_EQ(c.domain(), Domain::XYZ);
  EXPECT_EQ(domainDimension(c.domain()), 3);
  EXPECT_GT(eval(c, 0, 0, 0), 0.0);
  EXPECT_LT(eval(c, 0, 3, 0), 0.0);
  EXPECT_LT(eval(c, 1.5, 0, 0), 0.0);
  // (0.5, 1, 0.5): f_disk(0.5, 0.5) = 0.5, f_seg(1) = 3 -> R-intersection.
  EXPECT_NEAR(eval(c, 0.5, 1, 0.5), refRi(0.5, 3.0), tol);
  // x, z and t do not form a domain.
  expectThrowMentioning<DomainError>(
    [&] {
      cartesianProduct(d, { Axis::X, Axis::Z }, Shape(Expr::t(), Domain::T, "ti"), { Axis::T });
    },
    { "cartesianProduct" });
  expectThrowMentioning<DomainError>(
    [&] {
      cartesianProduct(d, { Axis::X, Axis::Y }, seg, { Axis::Y });
    },
    { "cartesianProduct" });
}

TEST(Operations, ProjectionIsASampledMaximum)
{
  // Unit sphere projected along z on [-2, 2] with 5 samples (z = -2, -1, 0, 1, 2): the z = 0
  // sample gives the exact disk 1 - x^2 - y^2.
  const Shape p = project(unitSphere(), Axis::Z, -2, 2, 5);
  EXPECT_EQ(p.domain(), Domain::XY);
  EXPECT_NEAR(eval(p, 0.5, 0), 0.75, tol);
  EXPECT_NEAR(eval(p, 0, 0), 1.0, tol);
  // With 4 samples (z = -2, -2/3, 2/3, 2) the centre gets 1 - 4/9 = 5/9: a lower bound of the
  // true projection 1.
  const Shape coarse = project(unitSphere(), Axis::Z, -2, 2, 4);
  EXPECT_NEAR(eval(coarse, 0, 0), 5.0 / 9.0, tol);
  for (double x : { -1.5, -0.5, 0.0, 0.8 })
  {
    EXPECT_LE(eval(coarse, x, 0.1), 1.0 - x * x - 0.01 + 1e-15);
  }
  // XYZT -> XYZ by dropping t.
  const Shape moving(1.0 - square(Expr::x() - Expr::t()) - square(Expr::y()) - square(Expr::z()),
    Domain::XYZT, "moving");
  const Shape swept = project(moving, Axis::T, 0, 3, 31);
  EXPECT_EQ(swept.domain(), Domain::XYZ);
  EXPECT_NEAR(eval(swept, 2, 0, 0), 1.0, tol); // t = 2 is sample 20
  expectThrowMentioning<DomainError>(
    [] { project(unitSphere(), Axis::Y, -1, 1); }, { "project", "y" });
  expectThrowMentioning<DomainError>(
    [] { project(disk(0, 0, 1), Axis::T, -1, 1); }, { "project", "t" });
  expectThrowMentioning<std::invalid_argument>(
    [] { project(unitSphere(), Axis::Z, -1, 1, 1); }, { "project", "samples" });
  expectThrowMentioning<std::invalid_argument>(
    [] { project(unitSphere(), Axis::Z, 1, 1); }, { "project", "lo" });
}

TEST(Operations, Metamorphosis)
{
  // (1 - s) f1 + s f2 at s = 0.25, f1 = 3, f2 = -5: 2.25 - 1.25 = 1.
  EXPECT_NEAR(eval(metamorphosis(probe1, probe2, 0.25), 3, -5), 1.0, tol);
  for (double s : { 0.0, 0.4, 1.0 })
  {
    for (double f1 : samples)
    {
      EXPECT_NEAR(
        eval(metamorphosis(probe1, probe2, s), f1, 2.0), (1 - s) * f1 + s * 2.0, tol * 10);
    }
  }
  expectThrowMentioning<std::invalid_argument>(
    [] { metamorphosis(probe1, probe2, 1.5); }, { "metamorphosis", "s" });
  expectThrowMentioning<std::invalid_argument>(
    [] { metamorphosis(probe1, probe2, NAN); }, { "metamorphosis", "s" });
  // Over time: s = clamp((t - 1)/2, 0, 1); the disks of radius 1 and 2 -> XYT.
  const Shape m = metamorphosis(disk(0, 0, 1), disk(0, 0, 2), 1.0, 3.0);
  EXPECT_EQ(m.domain(), Domain::XYT);
  EXPECT_NEAR(eval(m, 0.5, 0, 0, 0.0), 0.75, tol);
  EXPECT_NEAR(eval(m, 0.5, 0, 0, 2.0), 0.5 * 0.75 + 0.5 * 3.75, tol);
  EXPECT_NEAR(eval(m, 0.5, 0, 0, 9.0), 3.75, tol);
  expectThrowMentioning<DomainError>(
    [&] { metamorphosis(m, m, 0.0, 1.0); }, { "metamorphosis", "t" });
  expectThrowMentioning<std::invalid_argument>(
    [] { metamorphosis(probe1, probe2, 2.0, 1.0); }, { "metamorphosis", "t0" });
}

namespace
{
// The space-time blend of two disks, written directly from the construction in Operations.h.
double refStb(double f1, double f2, double t, double t0, double t1, double a0, double a1, double a2,
  double a3, double overlap)
{
  const double tA = t0 + overlap * (t1 - t0), tB = t1 - overlap * (t1 - t0);
  return refBoundedBlend(
    refRi(f1, tA - t), refRi(f2, t - tB), refRi(t - t0, t1 - t), a0, a1, a2, a3);
}
} // namespace

TEST(Operations, SpaceTimeBlendOfTwoDisks)
{
  // Unit disks at (-1.5, 0) and (1.5, 0), t in [0, 1]. The parameters a0 = 5, a1 = a2 = 5,
  // a3 = 0.1 were chosen (by plotting slices) so that the added material joins the disks.
  const Shape d1 = disk(-1.5, 0, 1), d2 = disk(1.5, 0, 1);
  const double t0 = 0, t1 = 1, a0 = 5, a1 = 5, a2 = 5, a3 = 0.1;
  const Shape stb = spaceTimeBlend(d1, d2, t0, t1, a0, a1, a2, a3);
  EXPECT_EQ(stb.domain(), Domain::XYT);
  const auto f1 = [](double x, double y)
  {
    return 1 - (x + 1.5) * (x + 1.5) - y * y;
  };
  const auto f2 = [](double x, double y)
  {
    return 1 - (x - 1.5) * (x - 1.5) - y * y;
  };
  const auto sgn = [](double v)
  {
    return (v > 0) - (v < 0);
  };
  for (double x = -3.0; x <= 3.0; x += 0.25)
  {
    for (double y = -1.25; y <= 1.25; y += 0.25)
    {
      // Slices t <= t0 reproduce the sign of f1, slices t >= t1 that of f2 (away from the
      // boundary, where a sign is fragile in floating point).
      if (std::fabs(f1(x, y)) > 1e-9)
      {
        EXPECT_EQ(sgn(eval(stb, x, y, 0, t0)), sgn(f1(x, y))) << x << " " << y;
        EXPECT_EQ(sgn(eval(stb, x, y, 0, t0 - 0.5)), sgn(f1(x, y))) << x << " " << y;
      }
      if (std::fabs(f2(x, y)) > 1e-9)
      {
        EXPECT_EQ(sgn(eval(stb, x, y, 0, t1)), sgn(f2(x, y))) << x << " " << y;
      }
      // The field matches the construction formula everywhere.
      for (double t : { -0.2, 0.1, 0.3, 0.5, 0.8, 1.2 })
      {
        EXPECT_NEAR(eval(stb, x, y, 0, t),
          refStb(f1(x, y), f2(x, y), t, t0, t1, a0, a1, a2, a3, 0.25),
          1e-12 * (1 + std::fabs(f1(x, y)) + std::fabs(f2(x, y))));
      }
    }
  }
  // The mid slice is one piece joining the disks: every point of the segment between the centres
  // is inside, and the ends of the row (-3 and 3) stay outside.
  for (double x = -1.5; x <= 1.5; x += 0.05)
  {
    EXPECT_GT(eval(stb, x, 0, 0, 0.5), 0.0) << x;
  }
  EXPECT_LT(eval(stb, -3, 0, 0, 0.5), 0.0);
  EXPECT_LT(eval(stb, 3, 0, 0, 0.5), 0.0);
  // Without added material (a0 = 0) the gap between the disks stays empty at mid-time.
  EXPECT_LT(eval(spaceTimeBlend(d1, d2, t0, t1, 0, a1, a2, a3), 0, 0, 0, 0.5), 0.0);
}

TEST(Operations, SpaceTimeBlendValidation)
{
  const Shape d1 = disk(-1.5, 0, 1);
  const Shape withT(Expr::t() - square(Expr::x()), Domain::XT, "timed");
  expectThrowMentioning<DomainError>(
    [&] { spaceTimeBlend(withT, withT, 0, 1, 1, 1, 1, 1); }, { "spaceTimeBlend", "timed" });
  expectThrowMentioning<std::invalid_argument>(
    [&] { spaceTimeBlend(d1, d1, 1, 1, 1, 1, 1, 1); }, { "spaceTimeBlend", "t0" });
  expectThrowMentioning<std::invalid_argument>(
    [&] { spaceTimeBlend(d1, d1, 0, 1, 1, 1, 1, 0); }, { "spaceTimeBlend", "a3" });
  expectThrowMentioning<std::invalid_argument>(
    [&] { spaceTimeBlend(d1, d1, 0, 1, 1, 1, 1, 1, 0.0); }, { "spaceTimeBlend", "overlap" });
  // A 3D pair goes to XYZT.
  EXPECT_EQ(spaceTimeBlend(unitSphere(), sphere(2), 0, 1, 1, 1, 1, 1).domain(), Domain::XYZT);
}

TEST(Operations, CompiledEvaluatorsAgreeWithTheReference)
{
  // The operations are plain Exprs, so the compiled point evaluator must give the reference values
  // and the interval evaluator must enclose them with finite bounds (bounded blending divides
  // inside a select(); its quotient is built so that the interval stays finite and r <= 1).
  // maybeNaN is not asserted: the interval square/add round a 0 bound outwards to -4.9e-324, so
  // every sqrt(f1^2 + f2^2) is flagged, which is an evaluator matter, not an operation one.
  const Shape d1 = disk(-1.5, 0, 1), d2 = disk(1.5, 0, 1);
  const std::vector<Shape> shapes = { spaceTimeBlend(d1, d2, 0, 1, 5, 5, 5, 0.1),
    boundedBlend(probe1, probe2, probe3, 1, 2, 0.5, 1.5), unite(probe1, probe2, 0.4),
    twist(testShape(), Axis::Z, 0, 1, 0, 1), bend(testShape(), Axis::X, 0.8),
    taper(testShape(), Axis::Y, -1, 1, 0.5, 2), project(unitSphere(), Axis::Z, -1, 1, 9) };
  for (const Shape& s : shapes)
  {
    PointEvaluator point(Tape::compile(s.function()));
    IntervalEvaluator interval(Tape::compile(s.function()));
    const Region box{ { Interval{ -1.0, 1.0 }, Interval{ -0.5, 0.5 }, Interval{ -0.25, 0.75 },
      Interval{ 0.2, 0.6 } } };
    const Interval range = interval.eval(box);
    EXPECT_TRUE(std::isfinite(range.lo) && std::isfinite(range.hi)) << s.label();
    for (double x : { -1.0, -0.3, 0.4, 1.0 })
    {
      for (double y : { -0.5, 0.1, 0.5 })
      {
        for (double zt : { 0.2, 0.55 })
        {
          const double ref = eval(s, x, y, zt, zt);
          EXPECT_NEAR(point.eval(x, y, zt, zt), ref, 1e-12 * (1 + std::fabs(ref))) << s.label();
          EXPECT_TRUE(range.lo <= ref + 1e-12 && ref - 1e-12 <= range.hi)
            << s.label() << " " << ref;
        }
      }
    }
  }
}
