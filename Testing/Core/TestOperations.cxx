// SPDX-License-Identifier: BSD-3-Clause
// Tests of the FRep operation library. Operands are built directly as Shapes from Exprs (not from
// Primitives.cxx) so that these tests depend on Operations.cxx alone.
//
// Most scalar checks use "probe" operands f1 = x, f2 = y, f3 = z on XYZ: evaluating the result at
// (f1, f2, f3) gives the operation at those operand values, so the spec formulas can be checked on
// a grid of operand values (spec feature list thesis_ch2_3.md section 5, items 9-27).

#include "FRep/Evaluators.h"
#include "FRep/Operations.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <string>

using namespace ictk::frep;

namespace
{
constexpr double tol = 1e-12;
const double pi = std::acos(-1.0);

double eval(const Shape& s, double x, double y = 0.0, double z = 0.0, double t = 0.0)
{
  return evaluateReference(s.function(), { x, y, z, t });
}

const Shape probe1(Expr::x(), Domain::XYZ, "f1");
const Shape probe2(Expr::y(), Domain::XYZ, "f2");
const Shape probe3(Expr::z(), Domain::XYZ, "f3");

Shape unitSphere()
{
  return Shape(
    Expr(1.0) - square(Expr::x()) - square(Expr::y()) - square(Expr::z()), Domain::XYZ, "sphere");
}

Shape sphere(double r)
{
  return Shape(
    Expr(r * r) - square(Expr::x()) - square(Expr::y()) - square(Expr::z()), Domain::XYZ, "sphere");
}

Shape disk(double cx, double cy, double r)
{
  return Shape(Expr(r * r) - square(Expr::x() - cx) - square(Expr::y() - cy), Domain::XY, "circle");
}

Shape block3()
{
  // |x|, |y|, |z| <= 1 as a min of slabs (the exact form does not matter for domain tests).
  return Shape(min(min(1.0 - square(Expr::x()), 1.0 - square(Expr::y())), 1.0 - square(Expr::z())),
    Domain::XYZ, "block");
}

// A non-symmetric XYZ test field, so that mapping errors (wrong sign, wrong axis) show.
double testField(double x, double y, double z)
{
  return 1.0 - (x - 0.3) * (x - 0.3) - 2.0 * (y + 0.2) * (y + 0.2) - 0.5 * z * z + 0.7 * x * y -
    0.4 * z;
}
Shape testShape()
{
  const Expr x = Expr::x(), y = Expr::y(), z = Expr::z();
  return Shape(
    1.0 - square(x - 0.3) - 2.0 * square(y + 0.2) - 0.5 * square(z) + 0.7 * x * y - 0.4 * z,
    Domain::XYZ, "field");
}

// The grid of operand values used for the formula checks.
const double samples[] = { -7.5, -3.0, -1.0, -0.25, 0.0, 0.3, 1.0, 2.0, 4.0, 11.0 };

// Expects `op` to throw E whose message contains every string in `parts`.
template <typename E>
void expectThrowMentioning(
  const std::function<void()>& op, std::initializer_list<const char*> parts)
{
  try
  {
    op();
    ADD_FAILURE() << "expected an exception";
  }
  catch (const E& e)
  {
    const std::string msg = e.what();
    for (const char* p : parts)
    {
      EXPECT_NE(msg.find(p), std::string::npos) << "message '" << msg << "' lacks '" << p << "'";
    }
  }
}

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
