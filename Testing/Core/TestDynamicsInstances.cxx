// SPDX-License-Identifier: BSD-3-Clause
// IC templates and instances (thesis §3.8-3.9 L1384-1459) on the thesis 5.1 exemplar: a disk
// LHKF moving toward a rectangle DEQS, with instances K1 (apart), K2 (tangent: one intersection
// point, the F point) and K3 (two intersection points: chord, arc, half-disk). The thesis gives
// no numbers (ch2_3 notes §0 item 9); the ones below are ours.
//
//   Rectangle DEQS = [0.25, 4] x [-2, 3]. Disk LHKF: radius r = 0.75, centre
//   c(t) = (-2 + 0.5 t, 0.5) (p(t) = p0 + v t, L1046, with v = (0.5, 0)).
// The disk spans y in [-0.25, 1.25], inside the rectangle's y range, and x <= 1.75 < 4 while
// t <= 5.5, so only the left side x = 0.25 can meet the circle. With d = 0.25 - c_x, the circle
// meets that side in 0 points (|d| > r), 1 point (|d| = r) or 2 points (|d| < r).
//   Tangency: d = r <=> 0.25 - (-2 + 0.5 t) = 0.75 <=> 0.5 t = 1.5 <=> t = 3.
//   Half overlap: d = 0 <=> -2 + 0.5 t = 0.25 <=> t = 4.5; the overlap is then the half-disk
//   right of the centre, of area pi r^2 / 2 = pi * 0.5625 / 2 = 0.88357293382212931.

#include "Dynamics/Instances.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

using namespace ictk::dyn;
using ictk::frep::locateCrossing;
using ::testing::ElementsAre;
using ::testing::HasSubstr;

namespace
{

constexpr double kR = 0.75;
constexpr double kX0 = 0.25, kX1 = 4.0, kY0 = -2.0, kY1 = 3.0; // DEQS
constexpr double kTol = 1e-9; // geometric tolerance of the predicates

double centreX(double t)
{
  return -2.0 + 0.5 * t;
}
constexpr double kCentreY = 0.5;

/// Points where the circle meets the rectangle's boundary (tangent points counted once).
int intersectionCount(double t)
{
  const double cx = centreX(t), cy = kCentreY;
  int n = 0;
  // A side x = X, y in [lo, hi] (or y = Y with the roles swapped): distance d from the centre's
  // line; 0 points when |d| > r, a tangent point when |d| = r, else the two points at
  // +-sqrt(r^2 - d^2) that lie on the side.
  auto side = [&](double d, double c, double lo, double hi)
  {
    if (std::abs(d) > kR + kTol)
      return;
    if (std::abs(std::abs(d) - kR) <= kTol)
    {
      n += (c >= lo && c <= hi) ? 1 : 0;
      return;
    }
    const double h = std::sqrt(kR * kR - d * d);
    n += (c - h >= lo && c - h <= hi) ? 1 : 0;
    n += (c + h >= lo && c + h <= hi) ? 1 : 0;
  };
  side(kX0 - cx, cy, kY0, kY1);
  side(kX1 - cx, cy, kY0, kY1);
  side(kY0 - cy, cx, kX0, kX1);
  side(kY1 - cy, cx, kX0, kX1);
  return n;
}

/// Signed gap between the circle and the left side (> 0 apart, 0 tangent, < 0 overlapping).
double gap(double t)
{
  return (kX0 - centreX(t)) - kR;
}

/// Area of the disk right of x = 0.25: the circular segment r^2 acos(d/r) - d sqrt(r^2 - d^2)
/// with d = 0.25 - c_x, for |d| <= r.
double overlapArea(double t)
{
  const double d = std::clamp(kX0 - centreX(t), -kR, kR);
  return kR * kR * std::acos(d / kR) - d * std::sqrt(kR * kR - d * d);
}

InstanceSet diskAndRectangle()
{
  InstanceSet set;
  set.addTemplate({ "INITIAL_TEMPLATE", { "DEQS", "LHKF" }, {} });
  // K1: no intersection (the thesis predicate !isIntersection, L2469); K2: exactly one point;
  // K3: exactly two points.
  set.addInstance({ "K1", "INITIAL_TEMPLATE", {}, {}, {}, {},
    [](double t)
    {
      return intersectionCount(t) == 0 && gap(t) > 0;
    } });
  set.addInstance({ "K2", "INITIAL_TEMPLATE", {}, { "F_point" }, {}, {},
    [](double t)
    {
      return intersectionCount(t) == 1;
    } });
  set.addInstance({ "K3", "INITIAL_TEMPLATE", {},
    { "KFL_half_disk", "KFL_arc", "KL_segment", "K_point", "L_point" }, {}, {},
    [](double t)
    {
      return intersectionCount(t) == 2;
    } });
  return set;
}

} // namespace

TEST(DynamicsInstances, CellsDeriveFromTheTemplate)
{
  const InstanceSet set = diskAndRectangle();
  EXPECT_THAT(set.cells(set.index("K1")), ElementsAre("DEQS", "LHKF"));
  EXPECT_THAT(set.cells(set.index("K2")), ElementsAre("DEQS", "LHKF", "F_point"));
  EXPECT_THAT(set.cells(set.index("K3")),
    ElementsAre("DEQS", "LHKF", "KFL_half_disk", "KFL_arc", "KL_segment", "K_point", "L_point"));
  // Removing a cell the template lacks is a warning (ch4 feature 26).
  InstanceSet other;
  other.addTemplate({ "T", { "A", "B" }, { "r1" } });
  other.addInstance({ "I", "T", { "B", "Nope" }, { "C" }, { "r1" }, {}, {} });
  std::vector<std::string> warnings;
  EXPECT_THAT(other.cells(0, &warnings), ElementsAre("A", "C"));
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_THAT(warnings[0], HasSubstr("Nope"));
  EXPECT_TRUE(other.relations(0).empty());
  EXPECT_THROW(other.addInstance({ "J", "Missing", {}, {}, {}, {}, {} }), std::invalid_argument);
}

TEST(DynamicsInstances, ActiveInstanceIsTheUniqueValidOne)
{
  const InstanceSet set = diskAndRectangle();
  EXPECT_EQ(set.instance(set.activeAt(0.0)).name, "K1");
  EXPECT_EQ(set.instance(set.activeAt(2.99)).name, "K1");
  EXPECT_EQ(set.instance(set.activeAt(3.0)).name, "K2"); // gap(3) = 0 exactly
  EXPECT_EQ(set.instance(set.activeAt(3.01)).name, "K3");
  EXPECT_EQ(set.instance(set.activeAt(4.5)).name, "K3");

  // Two valid instances are an error that names both (L1394-1396).
  InstanceSet twice = diskAndRectangle();
  twice.addInstance({ "K3bis", "INITIAL_TEMPLATE", {}, {}, {}, {},
    [](double t)
    {
      return intersectionCount(t) >= 1;
    } });
  try
  {
    (void)twice.activeAt(4.0);
    FAIL();
  }
  catch (const InstanceError& e)
  {
    EXPECT_THAT(e.valid, ElementsAre("K3", "K3bis"));
    EXPECT_THAT(e.what(), HasSubstr("several IC instances are valid"));
  }
  // None valid: an error with an empty list.
  InstanceSet none;
  none.addInstance({ "K3", "", {}, {}, {}, {},
    [](double t)
    {
      return intersectionCount(t) == 2;
    } });
  try
  {
    (void)none.activeAt(0.0);
    FAIL();
  }
  catch (const InstanceError& e)
  {
    EXPECT_TRUE(e.valid.empty());
    EXPECT_THAT(e.what(), HasSubstr("no IC instance is valid"));
  }
  // A life span restricts validity as well.
  InstanceSet life;
  life.addInstance({ "Early", "", {}, {}, {}, {}, {}, TimeSpan::interval(0, 1) });
  EXPECT_TRUE(life.isValid(0, 1.0));
  EXPECT_FALSE(life.isValid(0, 1.5));
}

TEST(DynamicsInstances, TangencyIsLocatedNotSkipped)
{
  // Steps of 0.4 from 0 sample t = 2.8 and 3.2, never 3: without root finding the trace would go
  // K1 -> K3 and miss the instantaneous K2 (L2469-2688, ch4 feature 49).
  const InstanceSet set = diskAndRectangle();
  EXPECT_EQ(set.instance(set.activeAt(2.8)).name, "K1");
  EXPECT_EQ(set.instance(set.activeAt(3.2)).name, "K3");
  const std::vector<Transition> tr = set.trace(0.0, 5.5, 0.4, { gap });
  ASSERT_EQ(tr.size(), 3u);
  EXPECT_EQ(tr[0].to, "K1");
  EXPECT_EQ(tr[0].time, 0.0);
  EXPECT_EQ(tr[1].from, "K1");
  EXPECT_EQ(tr[1].to, "K2");
  EXPECT_NEAR(tr[1].time, 3.0, 1e-9); // hand value: 0.5 t = 1.5
  EXPECT_EQ(tr[2].from, "K2");
  EXPECT_EQ(tr[2].to, "K3");
  // K2 lasts while |gap| <= 1e-9 (the predicates' tolerance), i.e. 2e-9 of time at speed 0.5.
  EXPECT_NEAR(tr[2].time, 3.0, 1e-8);
  EXPECT_GE(tr[2].time, tr[1].time);

  // The same without guards: bisection on the active instance's identity (to 1e-12) finds the
  // boundaries near 3. It sees K2 here only because the predicates' 1e-9 tolerance makes K2 valid
  // for 4e-9 of time, more than the bisection tolerance; a zero-width instant needs the guard.
  const std::vector<Transition> blind = set.trace(0.0, 5.5, 0.4);
  ASSERT_EQ(blind.size(), 3u);
  EXPECT_EQ(blind[1].to, "K2");
  EXPECT_NEAR(blind[1].time, 3.0, 1e-8);
  EXPECT_EQ(blind[2].to, "K3");
  EXPECT_NEAR(blind[2].time, 3.0, 1e-8);
}

TEST(DynamicsInstances, HalfDiskAreaWhenTheOverlapIsHalf)
{
  // The overlap equals pi r^2 / 2 when the centre is on the side: t = 4.5 (file comment). Locate
  // it by root finding on overlapArea(t) - pi r^2 / 2 over the step [4.4, 4.8].
  const double half = M_PI * kR * kR / 2.0;
  auto c = locateCrossing([&](double t) { return overlapArea(t) - half; }, 4.4, 4.8);
  ASSERT_TRUE(c);
  EXPECT_NEAR(c->time, 4.5, 1e-9);
  EXPECT_NEAR(overlapArea(c->time), 0.88357293382212931, 1e-9);
  const InstanceSet set = diskAndRectangle();
  EXPECT_EQ(set.instance(set.activeAt(c->time)).name, "K3");
  // Cross-check of the half-disk area KFL_half_disk (centred at the disk centre, L2446-2694) by
  // an independent quadrature: the chord length 2 sqrt(r^2 - u^2) integrated over u in [0, r]
  // with the midpoint rule (u = r sin(theta) removes the endpoint singularity:
  // integral of 2 r^2 cos^2(theta) over [0, pi/2]).
  const int n = 20000;
  double area = 0.0;
  for (int i = 0; i < n; ++i)
  {
    const double th = (i + 0.5) * (M_PI / 2.0) / n;
    area += 2.0 * kR * kR * std::cos(th) * std::cos(th) * (M_PI / 2.0) / n;
  }
  EXPECT_NEAR(area, half, 1e-9);
}
