// SPDX-License-Identifier: BSD-3-Clause
#include "FRep/Expr.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace ictk::frep;

TEST(Expr, HashConsingMakesEqualSubtreesOneNode)
{
  const Expr x = Expr::x(), y = Expr::y();
  const Expr a = square(x) + square(y);
  const Expr b = square(x) + square(y);
  EXPECT_TRUE(a.identical(b));
  // (x^2 + y^2) * (x^2 + y^2): add, 2 squares, 2 variables and the product are 6 distinct nodes.
  EXPECT_EQ((a * b).nodeCount(), 6u);
}

TEST(Expr, ConstantFoldingAndExactIdentities)
{
  EXPECT_TRUE((Expr(2.0) * Expr(3.0) + Expr(1.0)).isConstant(7.0));
  const Expr x = Expr::x();
  EXPECT_TRUE((x + 0.0).identical(x));
  EXPECT_TRUE((x * 1.0).identical(x));
  EXPECT_TRUE((-(-x)).identical(x));
  EXPECT_TRUE(min(x, x).identical(x));
  EXPECT_TRUE(select(Expr(-1.0), x, Expr::y()).identical(Expr::y()));
}

TEST(Expr, IntegerPowerLowersToSquares)
{
  const Expr x = Expr::x();
  const Expr p = pow(x, 5.0);
  EXPECT_EQ(toString(p), "(mul x (square (square x)))");
  EXPECT_DOUBLE_EQ(evaluateReference(p, { 1.5, 0, 0, 0 }), std::pow(1.5, 5));
  EXPECT_DOUBLE_EQ(evaluateReference(pow(x, -2.0), { 2.0, 0, 0, 0 }), 0.25);
  EXPECT_EQ(pow(x, 2.5).opcode(), Opcode::Pow);
}

TEST(Expr, AxesUsedAndSubstitute)
{
  const Expr f = square(Expr::x()) + Expr::t();
  EXPECT_EQ(f.axesUsed(), 0b1001);
  // x -> x - 1: the disk test of thesis L532-L539 shifted by one.
  const Expr disk = Expr(4.0) - square(Expr::x()) - square(Expr::y());
  EXPECT_DOUBLE_EQ(evaluateReference(disk, { 0, 0, 0, 0 }), 4.0);
  EXPECT_DOUBLE_EQ(evaluateReference(disk, { 2, 0, 0, 0 }), 0.0);
  EXPECT_DOUBLE_EQ(evaluateReference(disk, { 3, -3, 0, 0 }), -14.0);
  const Expr moved = disk.substitute({ Expr::x() - 1.0, Expr::y(), Expr::z(), Expr::t() });
  EXPECT_DOUBLE_EQ(evaluateReference(moved, { 1, 0, 0, 0 }), 4.0);
}

TEST(Expr, ParametersAreReadAtEvaluation)
{
  const Expr r = Expr::parameter(0);
  const Expr f = square(r) - square(Expr::x());
  EXPECT_DOUBLE_EQ(evaluateReference(f, { 1, 0, 0, 0 }, { 2.0 }), 3.0);
  EXPECT_THROW(evaluateReference(f, { 1, 0, 0, 0 }, {}), std::out_of_range);
}

TEST(Expr, DeepChainsDoNotOverflowTheStack)
{
  Expr f = Expr::x();
  for (int i = 0; i < 200000; ++i)
  {
    f = f + Expr::y() * double(i % 7 + 1);
  }
  EXPECT_GT(f.nodeCount(), 200000u);
}

TEST(Expr, SubtreeReplacement)
{
  // Replace the sphere in max(sphere, box) by a smaller one: the box part is shared, not rebuilt.
  const Expr x = Expr::x(), y = Expr::y();
  const Expr sphere = Expr(1.0) - square(x) - square(y);
  const Expr box = min(Expr(0.5) - abs(x), Expr(0.5) - abs(y));
  const Expr model = max(sphere, box);
  const Expr smaller = Expr(0.25) - square(x) - square(y);
  const Expr edited = model.replace(sphere, smaller);
  EXPECT_TRUE(edited.child(1).identical(box));
  EXPECT_DOUBLE_EQ(evaluateReference(model, { 0.8, 0, 0, 0 }), 0.36);
  EXPECT_DOUBLE_EQ(evaluateReference(edited, { 0.8, 0, 0, 0 }), -0.3); // box wins: 0.5 - 0.8
  EXPECT_TRUE(model.replace(Expr::z(), x).identical(model));           // nothing to replace
}
