// SPDX-License-Identifier: BSD-3-Clause
// Roots of a scalar function of one variable (FRep/RootFinding.h): sign changes refined, touches
// found. Hand-derived values in the comments.

#include "FRep/RootFinding.h"

#include <gtest/gtest.h>

#include <cmath>

using ictk::frep::Crossing;
using ictk::frep::locateCrossing;
using ictk::frep::LocateOptions;
using ictk::frep::refineRoot;

TEST(FRepRootFinding, SignChangeIsRefined)
{
  // g(t) = 3 - t on [2.5, 3.7]: one secant step from the bracketing samples lands on 3.
  auto c = locateCrossing([](double t) { return 3.0 - t; }, 2.5, 3.7);
  ASSERT_TRUE(c);
  EXPECT_EQ(c->kind, Crossing::Kind::SignChange);
  EXPECT_NEAR(c->time, 3.0, 1e-12);
  // g(t) = t^3 - 2 on [1, 2]: the root is 2^(1/3) = 1.2599210498948732.
  auto d = locateCrossing([](double t) { return t * t * t - 2.0; }, 1.0, 2.0);
  ASSERT_TRUE(d);
  EXPECT_NEAR(d->time, std::cbrt(2.0), 1e-12);
  // The earliest of two roots: (t - 1.2)(t - 1.7) on [1, 2] -> 1.2.
  auto e = locateCrossing([](double t) { return (t - 1.2) * (t - 1.7); }, 1.0, 2.0);
  ASSERT_TRUE(e);
  EXPECT_NEAR(e->time, 1.2, 1e-12);
  EXPECT_FALSE(locateCrossing([](double t) { return t + 1.0; }, 0.0, 1.0));
}

TEST(FRepRootFinding, AConvergedSecantPointClosesTheBracket)
{
  // The ray caster's case: the ray (0.99, 0, -2 + s) through the unit ball, f = 1 - |p|^2,
  // bracketed by a leaf 0.02 long and refined to 1e-5. The crossing is at
  // s = 2 - sqrt(1 - 0.99^2) = 2 - sqrt(0.0199).
  LocateOptions o;
  o.timeTolerance = 1e-5;
  auto f = [](double s)
  {
    const double z = -2 + s;
    return 1 - (0.99 * 0.99 + z * z);
  };
  int evaluations = 0;
  const double a = 1.8589, b = 1.8789;
  EXPECT_NEAR(refineRoot(f, a, f(a), b, f(b), o, &evaluations), 2 - std::sqrt(0.0199), 1e-5);
  // The first secant point is within 3e-6 of the crossing, on its far side; the next one is put
  // half a tolerance inside the bracket, on the near side, which closes it. Illinois alone
  // moved the near end by halving its value and took 3.
  EXPECT_EQ(evaluations, 2);
  // sqrt(t) - 0.3 on [0, 1] (a root at 0.09, a steep end) to 1e-3: 6 (Illinois alone: 7).
  evaluations = 0;
  o.timeTolerance = 1e-3;
  auto g = [](double t)
  {
    return std::sqrt(t) - 0.3;
  };
  EXPECT_NEAR(refineRoot(g, 0.0, g(0.0), 1.0, g(1.0), o, &evaluations), 0.09, 1e-3);
  EXPECT_EQ(evaluations, 6);
  // A linear g: the first secant point is the root (the bracket is then closed by g = 0).
  evaluations = 0;
  EXPECT_NEAR(refineRoot([](double t) { return 3.0 - t; }, 2.5, 0.5, 3.7, -0.7, LocateOptions{},
                &evaluations),
    3.0, 1e-12);
  EXPECT_EQ(evaluations, 1);
}

TEST(FRepRootFinding, InstantaneousTouchIsFound)
{
  // A unit disk passing a rectangle's corner (0,0) along x + y = sqrt(2) at speed sqrt(2):
  // centre c(t) = (sqrt(2)/2 + s, sqrt(2)/2 - s), s = t - 2.5. While the corner is the nearest
  // rectangle point, the gap is g = |c| - 1 = sqrt(1 + 2 s^2) - 1 >= 0, zero only at s = 0: a
  // tangency at t = 2.5 without a sign change. Both ends of the step [2, 3.1] are positive
  // (g(2) = sqrt(1.5) - 1 = 0.22, g(3.1) = sqrt(1.72) - 1 = 0.31), so a two-sample test misses it.
  auto g = [](double t)
  {
    const double s = t - 2.5;
    return std::sqrt(1.0 + 2.0 * s * s) - 1.0;
  };
  ASSERT_GT(g(2.0), 0.2);
  ASSERT_GT(g(3.1), 0.3);
  auto c = locateCrossing(g, 2.0, 3.1);
  ASSERT_TRUE(c);
  EXPECT_EQ(c->kind, Crossing::Kind::Touch);
  // g ~ s^2 is flat below rounding within ~1e-8 of the touch; the parabola-vertex correction
  // (RootFinding.h) recovers the time of this symmetric touch to rounding.
  EXPECT_NEAR(c->time, 2.5, 1e-9);
  EXPECT_LE(std::abs(c->value), 1e-9);
  // An asymmetric touch, g = 2 s^2 + s^3 with s = t - 1.7 on [1, 2.3] (8 samples, spacing
  // 0.1625). The vertex of the parabola through s = -h, 0, +h (h = 1e-4 * 2 * 0.1625 = 3.25e-5)
  // is at -h (gr - gl) / (2 (gl - 2 g0 + gr)) = -h (2 h^3) / (2 * 4 h^2) = -h^2 / 4 = -2.6e-10:
  // the cubic term biases the touch time by 2.6e-10.
  auto a = locateCrossing(
    [](double t)
    {
      const double s = t - 1.7;
      return s * s * (2.0 + s);
    },
    1.0, 2.3);
  ASSERT_TRUE(a);
  EXPECT_EQ(a->kind, Crossing::Kind::Touch);
  EXPECT_NEAR(a->time, 1.7 - 3.25e-5 * 3.25e-5 / 4.0, 1e-11);
  // Passing at distance 1.1 instead (min g = 0.1): no touch.
  EXPECT_FALSE(locateCrossing([&](double t) { return g(t) + 0.1; }, 2.0, 3.1));
}
