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

// ---- The blending union's other numbers: blend(A, B, a0, a1, a2) -------------------------------
// Thesis 2.2.3 (L643-L647): F_b = f1 + f2 + sqrt(f1^2 + f2^2) + a0 / (1 + (f1/a1)^2 + (f2/a2)^2).
// Here the operands stand still: the liquid f1 = 1 - |p| and the ball f2 = 0.5 - |p - (1.5, 0)|,
// both with domains large enough that no clipping touches the points probed.

namespace
{

std::string scaledModel(const std::string& shape, const std::string& blobReaction = {})
{
  return R"(name = SCALED;
TIMESPANS { film : TIMESPAN(0, 3); }
CELLS {
  LIQUID {
    type = F-CELL;
    shape = hyperfun { liquid(x[2], a[1]) { liquid = 1 - sqrt(x[1]^2 + x[2]^2); } }
    dim = 2D;
    domain = { -4, -4, 4, 4 };
  }
  BALL {
    type = F-CELL;
    shape = hyperfun { ball(x[2], a[1]) { ball = 0.5 - sqrt(x[1]^2 + x[2]^2); } }
    dim = 2D;
    domain = { -4, -4, 4, 4 };
    parameters { translation(1.5, 0, 0); }
  }
  BLOB {
    type = T-CELL;
    shape = )" +
    shape + R"(;
    dim = 2D;
    domain = { -3, -3, 5, 3 };
    parameters { reach : REAL(0.5); }
    REACTIONS {
      updatePost(REAL globalT, REAL localT, REAL lifeT, REAL dt) { )" +
    blobReaction + R"( }
    }
  }
}
K { CELLS { LIQUID; BALL; BLOB; } }
)";
}

/// The thesis's blending union of the two operands at p, computed here from the formula.
double blendingUnion(double x, double y, double a0, double a1, double a2)
{
  const double f1 = 1 - std::hypot(x, y), f2 = 0.5 - std::hypot(x - 1.5, y);
  return f1 + f2 + std::sqrt(f1 * f1 + f2 * f2) +
    a0 / (1 + (f1 / a1) * (f1 / a1) + (f2 / a2) * (f2 / a2));
}

const double kProbes[][2] = { { 1.0, 0.0 }, { 0.0, 0.0 }, { 0.5, 0.0 }, { 1.0, 0.4 }, { 1.2, -0.3 },
  { -2.0, 1.0 }, { 2.5, 0.5 } };

} // namespace

TEST(EngineBlendNumbers, FieldIsTheBlendingUnionOfTheGivenA0A1A2)
{
  engine::DynamicModel m(
    ictk::lang::readIcm(scaledModel("blend(LIQUID, BALL, 0.7, 0.5, 2)"), "scaled.icm"));
  m.start();
  const std::vector<engine::CellState> cells = m.cells();
  const ictk::geometry::PlacedShapePtr blobPtr = cellNamed(cells, "BLOB").shape;
  const auto& blob = *blobPtr;
  ASSERT_EQ(blob.parts.size(), 1u);
  EXPECT_EQ(blob.parts[0].amount, 0.7);
  EXPECT_EQ(blob.parts[0].a1, 0.5);
  EXPECT_EQ(blob.parts[0].a2, 2.0);
  for (const auto& p : kProbes)
    EXPECT_NEAR(blob.value({ p[0], p[1], 0 }), blendingUnion(p[0], p[1], 0.7, 0.5, 2), 1e-12)
      << "at (" << p[0] << ", " << p[1] << ")";
  // Where both operands are 0 (the ball touches the liquid at (1, 0)) the field is a0 itself.
  EXPECT_NEAR(blob.value({ 1, 0, 0 }), 0.7, 1e-12);
  // At the origin f1 = 1, f2 = -1: sqrt 2 + 0.7 / (1 + 4 + 0.25) = 1.547548...
  EXPECT_NEAR(blob.value({ 0, 0, 0 }), std::sqrt(2.0) + 0.7 / 5.25, 1e-12);
  // (1, 0.4) is outside both operands (f1 = -0.0770, f2 = -0.1403) and inside their blend.
  EXPECT_GT(blob.value({ 1, 0.4, 0 }), 0.0);

  // Swapping the operands together with a1 and a2 gives the same field (thesis L647).
  engine::DynamicModel swapped(
    ictk::lang::readIcm(scaledModel("blend(BALL, LIQUID, 0.7, 2, 0.5)"), "swapped.icm"));
  swapped.start();
  const ictk::geometry::PlacedShapePtr otherPtr = cellNamed(swapped.cells(), "BLOB").shape;
  const auto& other = *otherPtr;
  for (const auto& p : kProbes)
    EXPECT_NEAR(other.value({ p[0], p[1], 0 }), blob.value({ p[0], p[1], 0 }), 1e-12);
}

TEST(EngineBlendNumbers, ScalesDefaultToOneAndAmountZeroIsTheRUnion)
{
  engine::DynamicModel m(ictk::lang::readIcm(scaledModel("blend(LIQUID, BALL, 0.7)"), "a.icm"));
  m.start();
  const ictk::geometry::PlacedShapePtr blobPtr = cellNamed(m.cells(), "BLOB").shape;
  const auto& blob = *blobPtr;
  for (const auto& p : kProbes)
    EXPECT_NEAR(blob.value({ p[0], p[1], 0 }), blendingUnion(p[0], p[1], 0.7, 1, 1), 1e-12);

  // a0 = 0 is the R-union f1 + f2 + sqrt(f1^2 + f2^2) (thesis L620), not a jump to max(f1, f2):
  // at the origin 1 - 1 + sqrt 2; its sign is that of `union` everywhere probed.
  engine::DynamicModel zero(ictk::lang::readIcm(scaledModel("blend(LIQUID, BALL, 0)"), "z.icm"));
  zero.start();
  const ictk::geometry::PlacedShapePtr rPtr = cellNamed(zero.cells(), "BLOB").shape;
  const auto& r = *rPtr;
  EXPECT_NEAR(r.value({ 0, 0, 0 }), std::sqrt(2.0), 1e-12);
  for (const auto& p : kProbes)
  {
    const double f1 = 1 - std::hypot(p[0], p[1]), f2 = 0.5 - std::hypot(p[0] - 1.5, p[1]);
    EXPECT_NEAR(r.value({ p[0], p[1], 0 }), blendingUnion(p[0], p[1], 0, 1, 1), 1e-12);
    if (std::max(f1, f2) != 0)
    {
      EXPECT_EQ(r.value({ p[0], p[1], 0 }) > 0, std::max(f1, f2) > 0);
    }
  }
}

TEST(EngineBlendNumbers, BlendCellsIsTheThesisNameOfBlend)
{
  for (const char* shape :
    { "blendCells(LIQUID, BALL, 0.7, 0.5, 2)", "IC::blendCells(LIQUID, BALL, 0.7, 0.5, 2)" })
  {
    engine::DynamicModel m(ictk::lang::readIcm(scaledModel(shape), "alias.icm"));
    m.start();
    const ictk::geometry::PlacedShapePtr blobPtr = cellNamed(m.cells(), "BLOB").shape;
    const auto& blob = *blobPtr;
    for (const auto& p : kProbes)
      EXPECT_NEAR(blob.value({ p[0], p[1], 0 }), blendingUnion(p[0], p[1], 0.7, 0.5, 2), 1e-12)
        << shape;
  }
}

TEST(EngineBlendNumbers, A1FollowsAReactionAndTheFieldFollowsTheFormula)
{
  // The blob's updatePost sets reach = 0.5 + globalT: a1 grows from 0.5 to 2.5 over the film,
  // the bump reaching further into the liquid. At (0.5, 0), f1 = 0.5 and f2 = -0.5.
  engine::DynamicModel m(ictk::lang::readIcm(
    scaledModel("blend(LIQUID, BALL, 0.7, reach, 1)", "reach = 0.5 + globalT;"), "reach.icm"));
  m.start();
  double previous = -1;
  for (double t : { 0.5, 1.0, 2.0 })
  {
    m.advanceTo(t, 0.25);
    const ictk::geometry::PlacedShapePtr blobPtr = cellNamed(m.cells(), "BLOB").shape;
    const auto& blob = *blobPtr;
    const double a1 = 0.5 + t;
    EXPECT_NEAR(blob.parts[0].a1, a1, 1e-12) << "t = " << t;
    for (const auto& p : kProbes)
      EXPECT_NEAR(blob.value({ p[0], p[1], 0 }), blendingUnion(p[0], p[1], 0.7, a1, 1), 1e-12)
        << "t = " << t << " at (" << p[0] << ", " << p[1] << ")";
    // sqrt(0.5) + 0.7 / (1 + (0.5 / a1)^2 + 0.25): 1.1738 at t = 0.5, 1.2221 at 1, 1.2573 at 2.
    const double v = blob.value({ 0.5, 0, 0 });
    EXPECT_NEAR(v, std::sqrt(0.5) + 0.7 / (1.25 + (0.5 / a1) * (0.5 / a1)), 1e-12);
    EXPECT_GT(v, previous);
    previous = v;
  }
}

TEST(EngineBlendNumbers, BadScalesAreRefusedAtTheirPlace)
{
  // Written out: the checker, at the number. The shape is on line 19, `    shape = ` before it.
  auto checkerError = [](const std::string& shape)
  {
    try
    {
      ictk::lang::readIcm(scaledModel(shape), "bad.icm");
    }
    catch (const ictk::lang::ParseError& e)
    {
      return e.diagnostics().front();
    }
    ADD_FAILURE() << shape << " was accepted";
    return ictk::lang::Diagnostic{};
  };
  ictk::lang::Diagnostic d = checkerError("blend(LIQUID, BALL, 0.7, 0, 1)");
  EXPECT_EQ(d.where.line, 19);
  EXPECT_EQ(d.where.column, 38);
  EXPECT_NE(d.message.find("a1 must be positive"), std::string::npos) << d.message;
  d = checkerError("blend(LIQUID, BALL, 0.7, 1, -2)");
  EXPECT_EQ(d.where.column, 41);
  EXPECT_NE(d.message.find("a2 must be positive"), std::string::npos) << d.message;
  d = checkerError("blend(LIQUID, BALL, 0.7, 1)");
  EXPECT_EQ(d.where.column, 38);
  EXPECT_NE(d.message.find("a1 and a2 together"), std::string::npos) << d.message;
  d = checkerError("blendCells(LIQUID, BALL, -0.7)");
  EXPECT_EQ(d.where.column, 38);
  EXPECT_NE(d.message.find("must not be negative"), std::string::npos) << d.message;

  // An expression: the engine, at load and at every step, at the expression.
  try
  {
    engine::DynamicModel bad(
      ictk::lang::readIcm(scaledModel("blend(LIQUID, BALL, 0.7, 1, -reach)"), "bad.icm"));
    FAIL() << "a2 = -0.5 was accepted";
  }
  catch (const engine::ModelError& e)
  {
    EXPECT_EQ(e.pos.line, 19);
    EXPECT_EQ(e.pos.column, 41);
    EXPECT_NE(e.message.find("a2 of BLOB"), std::string::npos) << e.message;
  }
  // reach = 1 - globalT reaches 0 at t = 1: the step that makes it so is refused, there.
  engine::DynamicModel late(ictk::lang::readIcm(
    scaledModel("blend(LIQUID, BALL, 0.7, reach, 1)", "reach = 1 - globalT;"), "late.icm"));
  late.start();
  late.advanceTo(0.75, 0.25);
  try
  {
    late.advanceTo(1.5, 0.25);
    FAIL() << "a1 = 0 was accepted at t = 1";
  }
  catch (const engine::ModelError& e)
  {
    EXPECT_EQ(e.pos.line, 19);
    EXPECT_EQ(e.pos.column, 38);
    EXPECT_NE(e.message.find("must be positive, it is 0"), std::string::npos) << e.message;
  }
}
