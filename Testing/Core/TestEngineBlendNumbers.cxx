// SPDX-License-Identifier: BSD-3-Clause
// The numbers of a blend in .icm follow the model (issue 16; thesis 5.4 L3274-L3286, Appendix B
// [OUT 4448]: `blendDensity = 1 / (distanceToBox * distanceToBox)`): `blend(A, B, amount)` and
// `spaceTimeBlendCells(A, B, t0, t1, a0, a1, a2, a3)` take expressions over the cell's and the
// model's parameters, evaluated at every step.
//
// The scene is the thesis's fig. 105 in 2D: a liquid disk of radius 1 at the origin and a ball of
// radius 0.5 whose centre moves from (1.5, 0) along +x at unit speed, so that the gap between them
// is d = t. Both fields are distances (1 - |p|, 0.5 - |p - c|). The blob is their blending union
// with amount a(d) = 1 / (0.5 + d^2), set by the blob's updatePost from distance(LIQUID, BALL).
// The three phases of the thesis appear: one shape while they interact continuously, then the
// separation (two components, exactly one switch), then a reciprocal attraction: the liquid's
// bulge towards the ball, delta(d) = (the liquid's boundary on the +x axis) - 1, is positive and
// shrinks as the ball goes away.

#include "Engine/DynamicModel.h"
#include "Engine/Interpreter.h"
#include "Geometry/Queries.h"
#include "Lang/Icm.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace
{
namespace engine = ictk::engine;

std::string blobModel(const std::string& amount)
{
  return R"(name = BLOB;
TIMESPANS { film : TIMESPAN(0, 3); }
CELLS {
  LIQUID {
    type = F-CELL;
    shape = hyperfun { liquid(x[2], a[1]) { liquid = 1 - sqrt(x[1]^2 + x[2]^2); } }
    dim = 2D;
    domain = { -1.2, -1.2, 1.2, 1.2 };
  }
  BALL {
    type = F-CELL;
    shape = hyperfun { ball(x[2], a[1]) { ball = 0.5 - sqrt(x[1]^2 + x[2]^2); } }
    dim = 2D;
    domain = { -0.7, -0.7, 0.7, 0.7 };
    parameters { translation(1.5, 0, 0); velocity : VECTOR3(1, 0, 0); }
    REACTIONS {
      update(REAL globalT, REAL localT, REAL lifeT, REAL dt) { translation += velocity * dt; }
    }
  }
  BLOB {
    type = T-CELL;
    shape = blend(LIQUID, BALL, )" +
    amount + R"();
    dim = 2D;
    domain = { -2, -2, 6, 2 };
    parameters { density : REAL(2); }
    REACTIONS {
      updatePost(REAL globalT, REAL localT, REAL lifeT, REAL dt)
      {
        REAL d = distance(LIQUID, BALL);
        density = 1 / (0.5 + d * d);
      }
    }
  }
}
K { CELLS { LIQUID; BALL; BLOB; } }
)";
}

const engine::CellState& cellNamed(const std::vector<engine::CellState>& cells, const char* name)
{
  for (const auto& c : cells)
    if (c.name == name)
      return c;
  throw std::runtime_error(std::string("no cell ") + name);
}

/// Inside runs of f along y = 0 from x = -1.5 to `end`, step h: the number of components the
/// shape has on the axis, and where the first run ends.
struct AxisRuns
{
  int runs = 0;
  double firstEnd = 0;
};

AxisRuns runsOnAxis(const ictk::geometry::PlacedShape& s, double end, double h)
{
  AxisRuns out;
  bool inside = false;
  for (double x = -1.5; x <= end; x += h)
  {
    const bool now = s.value({ x, 0, 0 }) >= 0;
    if (now && !inside)
      ++out.runs;
    if (!now && inside && out.runs == 1)
      out.firstEnd = x;
    inside = now;
  }
  return out;
}

} // namespace

TEST(EngineBlendNumbers, AmountFollowsTheCellsParameterAtEveryStep)
{
  engine::DynamicModel m(ictk::lang::readIcm(blobModel("density"), "blob.icm"));
  m.start();
  for (double t : { 0.25, 0.5, 1.0, 2.0 })
  {
    m.advanceTo(t, 0.05);
    const std::vector<engine::CellState> cells = m.cells();
    const auto& blob = cellNamed(cells, "BLOB");
    ASSERT_EQ(blob.shape->parts.size(), 1u);
    // d = t: the ball's centre is at 1.5 + t, its edge at 1 + t.
    EXPECT_NEAR(blob.shape->parts[0].amount, 1 / (0.5 + t * t), 1e-6) << "t = " << t;
  }
}

TEST(EngineBlendNumbers, ThreePhasesOfContact)
{
  engine::DynamicModel m(ictk::lang::readIcm(blobModel("density"), "blob.icm"));
  m.start();
  int switches = 0, previousRuns = 1;
  double separatedAt = -1, previousDelta = 1e9;
  for (int k = 0; k <= 30; ++k)
  {
    const double t = 0.1 * k;
    m.advanceTo(t, 0.05);
    const std::vector<engine::CellState> cells = m.cells();
    const auto& blob = *cellNamed(cells, "BLOB").shape;
    const AxisRuns r = runsOnAxis(blob, 2.5 + t, 1e-3);
    ASSERT_GE(r.runs, 1) << "t = " << t;
    ASSERT_LE(r.runs, 2) << "t = " << t;
    if (r.runs != previousRuns)
      ++switches;
    previousRuns = r.runs;
    if (r.runs == 2)
    {
      if (separatedAt < 0)
        separatedAt = t;
      // Reciprocal attraction: the liquid bulges towards the ball, less as it goes away.
      const double delta = r.firstEnd - 1;
      EXPECT_GT(delta, 0.0) << "t = " << t;
      EXPECT_LE(delta, previousDelta + 1e-3) << "t = " << t;
      previousDelta = delta;
    }
  }
  // Continuous interaction at first, then one separation, never rejoined.
  EXPECT_EQ(switches, 1);
  EXPECT_GT(separatedAt, 0.0);
  EXPECT_LT(separatedAt, 3.0);
}

TEST(EngineBlendNumbers, ConstantAmountStaysAndBadNumbersAreRefusedAtTheirPlace)
{
  engine::DynamicModel m(ictk::lang::readIcm(blobModel("0.5"), "blob.icm"));
  m.start();
  m.advanceTo(1.0, 0.1);
  EXPECT_EQ(cellNamed(m.cells(), "BLOB").shape->parts[0].amount, 0.5);
  // A negative amount (the density's initial value, negated) is refused at load, where it is.
  try
  {
    engine::DynamicModel bad(ictk::lang::readIcm(blobModel("-density"), "blob.icm"));
    FAIL() << "a negative blend amount was accepted";
  }
  catch (const engine::ModelError& e)
  {
    EXPECT_EQ(e.pos.line, 22) << e.what();
    EXPECT_NE(e.message.find("must not be negative"), std::string::npos) << e.message;
  }
}
