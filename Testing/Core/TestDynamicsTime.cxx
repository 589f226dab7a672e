// SPDX-License-Identifier: BSD-3-Clause
// Time spans and life spans (thesis L992-1002, Table 2 L4076-4079) and parameters with
// expressions (L1018-1029). Expected values are derived by hand in the comments.

#include "Dynamics/Parameters.h"
#include "Dynamics/Time.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

using namespace ictk::dyn;
using ::testing::ElementsAre;
using ::testing::HasSubstr;

namespace
{

// T = ([4,6] U [0,2] U [1,3]) |_St=2. Sorting and merging the overlapping [0,2], [1,3] gives
// [0,3] U [4,6] (L994: a span is a union of intervals, possibly disjoint).
TimeSpan twoIntervals()
{
  return TimeSpan({ { 4, 6 }, { 0, 2 }, { 1, 3 } }, 2.0);
}

} // namespace

TEST(DynamicsTime, UnionOfIntervalsIsNormalised)
{
  const TimeSpan t = twoIntervals();
  ASSERT_EQ(t.intervals().size(), 2u);
  EXPECT_EQ(t.intervals()[0], (TimeInterval{ 0, 3 }));
  EXPECT_EQ(t.intervals()[1], (TimeInterval{ 4, 6 }));
  EXPECT_EQ(t.scale(), 2.0);
  EXPECT_EQ(t.start(), 0.0);
  EXPECT_EQ(t.end(), 6.0);
  EXPECT_EQ(t.duration(), 5.0); // 3 + 2
  // Touching intervals merge as well: [0,1] U [1,2] = [0,2].
  EXPECT_EQ(TimeSpan({ { 1, 2 }, { 0, 1 } }).intervals(), (std::vector<TimeInterval>{ { 0, 2 } }));
}

TEST(DynamicsTime, MembershipIsClosed)
{
  const TimeSpan t = twoIntervals();
  EXPECT_TRUE(t.contains(0.0));
  EXPECT_TRUE(t.contains(3.0));  // closed end
  EXPECT_FALSE(t.contains(3.5)); // the gap
  EXPECT_TRUE(t.contains(4.0));
  EXPECT_FALSE(t.contains(6.0 + 1e-12));
  EXPECT_FALSE(t.contains(-1e-12));
  EXPECT_EQ(t.intervalIndex(5.0), std::optional<std::size_t>(1));
  EXPECT_FALSE(TimeSpan().contains(0.0)); // empty span: never alive
  EXPECT_TRUE(TimeSpan::instant(2.5).contains(2.5));
  EXPECT_FALSE(TimeSpan::instant(2.5).contains(2.5 + 1e-15));
}

TEST(DynamicsTime, LocalTimeRestartsPerIntervalAndIsScaled)
{
  const TimeSpan t = twoIntervals();
  // Table 2 L4078: local = (t - start of the current interval) * scale.
  EXPECT_EQ(t.localTime(1.5), std::optional<double>(3.0)); // (1.5 - 0) * 2
  EXPECT_EQ(t.localTime(5.0), std::optional<double>(2.0)); // (5 - 4) * 2
  EXPECT_FALSE(t.localTime(3.5).has_value());
  // Inverse within interval 1: 4 + 2 / 2 = 5.
  EXPECT_EQ(t.globalTime(2.0, 1), 5.0);
  // A span without arguments (ch4 feature 22): infinite, scale 1, local time = global time.
  const TimeSpan inf = TimeSpan::infinite();
  EXPECT_TRUE(inf.contains(-1e300));
  EXPECT_EQ(inf.localTime(7.0), std::optional<double>(7.0));
}

TEST(DynamicsTime, LifeTimeAccumulatesOverIntervals)
{
  const TimeSpan t = twoIntervals();
  // elapsed(5) = (3 - 0) + (5 - 4) = 4 of global time, * 2 = 8.
  EXPECT_EQ(t.elapsed(5.0), 8.0);
  EXPECT_EQ(t.lifeTime(5.0), std::optional<double>(8.0));
  // In the gap the entity is not alive (L1319): no life time; elapsed stays at 3 * 2 = 6.
  EXPECT_FALSE(t.lifeTime(3.5).has_value());
  EXPECT_EQ(t.elapsed(3.5), 6.0);
  EXPECT_EQ(t.elapsed(-1.0), 0.0);
  EXPECT_EQ(t.elapsed(10.0), 10.0); // (3 + 2) * 2
  // Inverse: life 8 -> unscaled 4: the first interval gives 3, the remaining 1 starts at 4 -> 5.
  EXPECT_EQ(t.globalTimeOfLife(8.0), std::optional<double>(5.0));
  EXPECT_EQ(t.globalTimeOfLife(6.0), std::optional<double>(3.0));
  EXPECT_FALSE(t.globalTimeOfLife(11.0).has_value());
}

TEST(DynamicsTime, ClipUnionIntersection)
{
  const TimeSpan t = twoIntervals();
  // [0,3] U [4,6] clipped to [2,5] = [2,3] U [4,5]; the scale is kept.
  const TimeSpan c = t.clipped({ 2, 5 });
  EXPECT_EQ(c.intervals(), (std::vector<TimeInterval>{ { 2, 3 }, { 4, 5 } }));
  EXPECT_EQ(c.scale(), 2.0);
  // U [2.5, 4.5] fills the gap: [0,6].
  EXPECT_EQ(
    unite(t, TimeSpan::interval(2.5, 4.5)).intervals(), (std::vector<TimeInterval>{ { 0, 6 } }));
  // n [1,5] = [1,3] U [4,5].
  EXPECT_EQ(intersect(t, TimeSpan::interval(1, 5)).intervals(),
    (std::vector<TimeInterval>{ { 1, 3 }, { 4, 5 } }));
  // Closed intervals meet in an instant: [0,1] n [1,2] = [1,1].
  EXPECT_EQ(intersect(TimeSpan::interval(0, 1), TimeSpan::interval(1, 2)).intervals(),
    (std::vector<TimeInterval>{ { 1, 1 } }));
  EXPECT_TRUE(intersect(TimeSpan::interval(0, 1), TimeSpan::interval(2, 3)).empty());
}

TEST(DynamicsTime, InvalidSpansAreRejected)
{
  EXPECT_THROW(TimeSpan({ { 2, 1 } }), std::invalid_argument);
  EXPECT_THROW(TimeSpan({ { 0, 1 } }, 0.0), std::invalid_argument);
  EXPECT_THROW(TimeSpan({ { std::nan(""), 1 } }), std::invalid_argument);
  EXPECT_THROW((void)TimeSpan().start(), std::logic_error);
}

// --- Parameters (L1020-1029) -----------------------------------------------------------------

TEST(DynamicsParameters, ExpressionsEvaluateInDependencyOrder)
{
  using ictk::frep::Expr;
  ParameterTable p;
  const ParamSlot g = p.add("", "g", Scope::Global, 2.0);
  // B.d is declared first (slot 1) but will read A.area (slot 3): the order must be by data flow,
  // not by slot.
  const ParamSlot d = p.add("B", "d", Scope::Global, 0.0);
  const ParamSlot r = p.add("A", "r", Scope::Local, 3.0);
  const ParamSlot area =
    p.addExpression("A", "area", Scope::Global, M_PI * Expr::parameter(r) * Expr::parameter(r));
  p.setExpression(d, Expr::parameter(area) / Expr::parameter(g));
  EXPECT_THAT(p.evaluationOrder(), ElementsAre(area, d));
  p.evaluate();
  // area = pi * 3^2 = 28.274333882308138; d = area / 2 = 14.137166941154069.
  EXPECT_NEAR(p.value("A.area"), 9.0 * M_PI, 1e-12);
  EXPECT_NEAR(p.value("B.d"), 4.5 * M_PI, 1e-12);
  EXPECT_EQ(p.inputs(d), (std::vector<ParamSlot>{ g, area }));
  // A value set by a reaction replaces the expression (L1029).
  p.setValue("B.d", 1.0);
  p.evaluate();
  EXPECT_EQ(p.value(d), 1.0);
  EXPECT_FALSE(p.hasExpression(d));
  EXPECT_EQ(p.name(area), "A.area");
  EXPECT_EQ(p.name(g), "g");
}

TEST(DynamicsParameters, LocalParametersAreInvisibleOutsideTheirOwner)
{
  using ictk::frep::Expr;
  ParameterTable p;
  const ParamSlot r = p.add("A", "r", Scope::Local, 3.0);
  EXPECT_TRUE(p.visibleFrom(r, "A"));
  EXPECT_FALSE(p.visibleFrom(r, "B"));
  try
  {
    p.addExpression("B", "twice", Scope::Global, 2.0 * Expr::parameter(r));
    FAIL() << "a local parameter of A was read from B";
  }
  catch (const std::invalid_argument& e)
  {
    EXPECT_THAT(e.what(), HasSubstr("A.r"));
  }
  EXPECT_THROW(p.add("A", "r", Scope::Global, 1.0), std::invalid_argument); // duplicate
  EXPECT_THROW((void)p.slot("A.nothing"), std::out_of_range);
}

TEST(DynamicsParameters, CyclesAreReportedWithTheirNames)
{
  using ictk::frep::Expr;
  ParameterTable p;
  const ParamSlot k = p.add("", "k", Scope::Global, 1.0);
  const ParamSlot x = p.add("C", "x", Scope::Global, 0.0);
  const ParamSlot y = p.add("C", "y", Scope::Global, 0.0);
  const ParamSlot z = p.add("C", "z", Scope::Global, 0.0);
  p.setExpression(x, Expr::parameter(y) + Expr::parameter(k)); // x <- y
  p.setExpression(y, 2.0 * Expr::parameter(z));                // y <- z
  p.setExpression(z, Expr::parameter(x) - 1.0);                // z <- x
  try
  {
    p.evaluate();
    FAIL() << "cycle not detected";
  }
  catch (const ParameterCycleError& e)
  {
    // Data flow x -> z -> y -> x (z reads x, y reads z, x reads y).
    EXPECT_THAT(e.cycle, ElementsAre("C.x", "C.z", "C.y", "C.x"));
    EXPECT_THAT(e.what(), HasSubstr("C.x -> C.z -> C.y -> C.x"));
  }
}
