// SPDX-License-Identifier: BSD-3-Clause
// The animation entity of thesis Table 3 (L4150-4162) and §3.9 (L1461-1465): keys, interpolation
// kinds, out-of-range modes. Every expected value is computed by hand in the comments.

#include "Dynamics/Animation.h"

#include <gtest/gtest.h>

using namespace ictk::dyn;

namespace
{
// Keys (0,0), (1,10), (3,4): unequal segment lengths, so the cubic tangents are non-trivial.
AnimationCurve threeKeys(Interpolation k)
{
  return AnimationCurve({ { 0, 0 }, { 1, 10 }, { 3, 4 } }, k);
}
} // namespace

TEST(DynamicsAnimation, TimeRangeIsFirstToLastKey)
{
  // L4156: the range is derived from the key times; keys may be given unsorted.
  const AnimationCurve c({ { 3, 4 }, { 0, 0 }, { 1, 10 } });
  EXPECT_EQ(c.rangeStart(), 0.0);
  EXPECT_EQ(c.rangeEnd(), 3.0);
  EXPECT_EQ(c.duration(), 3.0);
  EXPECT_THROW(AnimationCurve(std::vector<Key>{}), std::invalid_argument);
  EXPECT_THROW(AnimationCurve({ { 1, 0 }, { 1, 2 } }), std::invalid_argument);
}

TEST(DynamicsAnimation, Linear)
{
  // ch4 feature 74: keys (0,0), (1,10) give 5 at t = 0.5.
  EXPECT_DOUBLE_EQ(AnimationCurve({ { 0, 0 }, { 1, 10 } }).evaluate(0.5), 5.0);
  const AnimationCurve c = threeKeys(Interpolation::Linear);
  // Segment [1,3]: 10 + (4 - 10) * (2 - 1) / 2 = 7.
  EXPECT_DOUBLE_EQ(c.evaluate(2.0), 7.0);
  EXPECT_DOUBLE_EQ(c.evaluate(1.0), 10.0); // at a key
  EXPECT_DOUBLE_EQ(c.evaluate(3.0), 4.0);
}

TEST(DynamicsAnimation, StepHoldsThePreviousKey)
{
  const AnimationCurve c = threeKeys(Interpolation::Step);
  EXPECT_EQ(c.evaluate(0.5), 0.0);
  EXPECT_EQ(c.evaluate(1.0), 10.0);
  EXPECT_EQ(c.evaluate(2.9), 10.0);
  EXPECT_EQ(c.evaluate(3.0), 4.0);
}

TEST(DynamicsAnimation, CatmullRomCubic)
{
  // Tangents: m0 = (10 - 0) / (1 - 0) = 10 (one-sided), m1 = (4 - 0) / (3 - 0) = 4/3,
  // m2 = (4 - 10) / (3 - 1) = -3 (one-sided). At s = 0.5: h00 = h01 = 1/2, h10 = 1/8, h11 = -1/8.
  const AnimationCurve c = threeKeys(Interpolation::CatmullRom);
  // t = 0.5, h = 1: 0/2 + 1/8 * 10 + 10/2 - 1/8 * 4/3 = 1.25 + 5 - 1/6 = 73/12.
  EXPECT_NEAR(c.evaluate(0.5), 73.0 / 12.0, 1e-14);
  // t = 2, h = 2: 10/2 + 1/8 * 2 * 4/3 + 4/2 - 1/8 * 2 * (-3) = 5 + 1/3 + 2 + 3/4 = 97/12.
  EXPECT_NEAR(c.evaluate(2.0), 97.0 / 12.0, 1e-14);
  // Interpolating: the keys are reproduced.
  EXPECT_DOUBLE_EQ(c.evaluate(1.0), 10.0);
}

TEST(DynamicsAnimation, HermiteUsesTheAdditionalValues)
{
  // ch4 feature 77: the tangents are Table 3's additional values (L4155). Zero tangents at
  // (0,0), (1,10) give the smoothstep 10 (3 s^2 - 2 s^3): s = 0.25 -> 10 * (3/16 - 2/64) = 1.5625.
  AnimationCurve flat({ { 0, 0, 0.0 }, { 1, 10, 0.0 } }, Interpolation::Hermite);
  EXPECT_NEAR(flat.evaluate(0.25), 1.5625, 1e-14);
  EXPECT_NEAR(flat.evaluate(0.5), 5.0, 1e-14);
  // A key without a tangent falls back to the Catmull-Rom one: m0 = 20 given, m1 = (10-0)/1 = 10.
  // s = 0.5: 1/8 * 20 + 5 - 1/8 * 10 = 6.25.
  AnimationCurve mixed({ { 0, 0, 20.0 }, { 1, 10, std::nullopt } }, Interpolation::Hermite);
  EXPECT_NEAR(mixed.evaluate(0.5), 6.25, 1e-14);
}

TEST(DynamicsAnimation, OutOfRangeModes)
{
  // ch4 feature 75, keys (0,0), (1,10), t = 1.5: Constant -> 10, Linear -> 15, Loop -> 5,
  // Mirror -> 5. Before the range, t = -0.25: Constant -> 0; Linear -> -2.5; Loop wraps to 0.75
  // -> 7.5; Mirror (period 2) maps -0.25 to 1.75, played backwards to 0.25 -> 2.5.
  auto curve = [](OutOfRange m)
  {
    return AnimationCurve({ { 0, 0 }, { 1, 10 } }, Interpolation::Linear, m, m);
  };
  EXPECT_DOUBLE_EQ(curve(OutOfRange::Constant).evaluate(1.5), 10.0);
  EXPECT_DOUBLE_EQ(curve(OutOfRange::Linear).evaluate(1.5), 15.0);
  EXPECT_DOUBLE_EQ(curve(OutOfRange::Loop).evaluate(1.5), 5.0);
  EXPECT_DOUBLE_EQ(curve(OutOfRange::Mirror).evaluate(1.5), 5.0);
  EXPECT_DOUBLE_EQ(curve(OutOfRange::Constant).evaluate(-0.25), 0.0);
  EXPECT_DOUBLE_EQ(curve(OutOfRange::Linear).evaluate(-0.25), -2.5);
  EXPECT_DOUBLE_EQ(curve(OutOfRange::Loop).evaluate(-0.25), 7.5);
  EXPECT_DOUBLE_EQ(curve(OutOfRange::Mirror).evaluate(-0.25), 2.5);
  // Loop at 2.25 -> 0.25 -> 2.5; Mirror at 1.75 -> 0.25 -> 2.5, at 2.5 -> 0.5 -> 5.
  EXPECT_DOUBLE_EQ(curve(OutOfRange::Loop).evaluate(2.25), 2.5);
  EXPECT_DOUBLE_EQ(curve(OutOfRange::Mirror).evaluate(1.75), 2.5);
  EXPECT_DOUBLE_EQ(curve(OutOfRange::Mirror).evaluate(2.5), 5.0);
  // Before and after chosen separately.
  const AnimationCurve mixed(
    { { 0, 0 }, { 1, 10 } }, Interpolation::Linear, OutOfRange::Constant, OutOfRange::Linear);
  EXPECT_DOUBLE_EQ(mixed.evaluate(-1.0), 0.0);
  EXPECT_DOUBLE_EQ(mixed.evaluate(2.0), 20.0);
}

TEST(DynamicsAnimation, LinearExtrapolationUsesTheEndSlopeOfTheKind)
{
  // Catmull-Rom end tangent at (3,4) is -3: t = 4 -> 4 + 1 * (-3) = 1; at the start m0 = 10:
  // t = -0.5 -> 0 - 0.5 * 10 = -5.
  AnimationCurve c = threeKeys(Interpolation::CatmullRom);
  c.setOutOfRange(OutOfRange::Linear, OutOfRange::Linear);
  EXPECT_DOUBLE_EQ(c.evaluate(4.0), 1.0);
  EXPECT_DOUBLE_EQ(c.evaluate(-0.5), -5.0);
  // Linear kind: last segment slope (4 - 10) / 2 = -3 as well; Step: slope 0.
  AnimationCurve s = threeKeys(Interpolation::Step);
  s.setOutOfRange(OutOfRange::Linear, OutOfRange::Linear);
  EXPECT_DOUBLE_EQ(s.evaluate(10.0), 4.0);
}

TEST(DynamicsAnimation, CustomProcedures)
{
  // F_in "a custom evaluation procedure" and F_out "custom" (L1465, L4160).
  AnimationCurve c({ { 0, 0 }, { 2, 4 } });
  c.setInterpolation(Interpolation::Custom, [](const AnimationCurve&, double t) { return t * t; });
  c.setOutOfRange(OutOfRange::Constant, OutOfRange::Custom,
    [](const AnimationCurve& a, double t) { return a.evaluateInRange(a.rangeEnd()) + t; });
  EXPECT_DOUBLE_EQ(c.evaluate(1.5), 2.25);
  EXPECT_DOUBLE_EQ(c.evaluate(3.0), 4.0 + 3.0);
  EXPECT_DOUBLE_EQ(c.evaluate(-1.0), 0.0); // Constant before: the first key's value
  EXPECT_THROW(c.setInterpolation(Interpolation::Custom), std::invalid_argument);
}
