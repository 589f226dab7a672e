// SPDX-License-Identifier: BSD-3-Clause
// Space-time blending (thesis 5.3.1, fig. 93; issue 16) through its front ends: the .icm T-cell
// `spaceTimeBlendCells(A, B, t0, t1, ...)`, whose shape at global time t is the blend's
// cross-section, and HyperFun's hfSpaceTimeBlend. The example is the thesis's: a cross of two
// bars, [-1, 1] x [-0.25, 0.25] union [-0.25, 0.25] x [-1, 1], turns into two disks of radius 0.4
// at (+-0.7, 0) between t0 = 1 and t1 = 2 (the spec's Scenario A, shifted by 1 since models start
// at t = 0). Before t0 the cross-section has exactly the sign of the cross on every grid point,
// after t1 that of the disks; the cross is one component and the disks two; areas 1.75 and 2 pi
// 0.16.

#include "Engine/DynamicModel.h"
#include "Engine/Interpreter.h"
#include "FRep/Evaluators.h"
#include "FRep/Hypervolume.h"
#include "FRep/Operations.h"
#include "FRep/Tape.h"
#include "Geometry/PlacedShape.h"
#include "Geometry/Queries.h"
#include "Geometry/SpaceTimeWarp.h"
#include "Lang/FRepXml.h"
#include "Lang/HyperFun.h"
#include "Lang/Icm.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <random>
#include <string>
#include <vector>

namespace
{
namespace engine = ictk::engine;
constexpr double Pi = 3.14159265358979323846;

std::string morphModel(const std::string& blendCall, const std::string& dim = "3D")
{
  return R"(name = STB;
TIMESPANS { film : TIMESPAN(0, 3); }
CELLS {
  Cross {
    type = F-CELL;
    shape = hyperfun {
      cross(x[2], a[1]) {
        cross = ((1 - abs(x[1])) & (0.25 - abs(x[2]))) | ((0.25 - abs(x[1])) & (1 - abs(x[2])));
      }
    }
    dim = 2D;
    domain = { -1.5, -1.5, 1.5, 1.5 };
  }
  Disks {
    type = F-CELL;
    shape = hyperfun {
      disks(x[2], a[1]) {
        disks = (0.16 - (x[1] + 0.7)^2 - x[2]^2) | (0.16 - (x[1] - 0.7)^2 - x[2]^2);
      }
    }
    dim = 2D;
    domain = { -1.5, -1.5, 1.5, 1.5 };
  }
  Morph {
    type = T-CELL;
    shape = )" +
    blendCall + R"(;
    dim = )" +
    dim + R"(;
    domain = { -2, -2, 2, 2 };
  }
}
K { CELLS { Morph; } }
)";
}

double cross(double x, double y)
{
  return std::max(
    std::min(1 - std::abs(x), 0.25 - std::abs(y)), std::min(0.25 - std::abs(x), 1 - std::abs(y)));
}

double disks(double x, double y)
{
  return std::max(0.4 - std::hypot(x + 0.7, y), 0.4 - std::hypot(x - 0.7, y));
}

constexpr int N = 121; // grid points per axis over [-1.5, 1.5]
double gridCoordinate(int i)
{
  return -1.5 + 3.0 * i / (N - 1);
}

/// The inside of `f` on the grid (f >= 0), 4-connected components counted by flood fill.
int components(const std::function<double(double, double)>& f)
{
  std::vector<int> label(N * N, 0);
  std::vector<char> inside(N * N);
  for (int j = 0; j < N; ++j)
    for (int i = 0; i < N; ++i)
      inside[j * N + i] = f(gridCoordinate(i), gridCoordinate(j)) >= 0;
  int count = 0;
  for (int start = 0; start < N * N; ++start)
  {
    if (!inside[start] || label[start])
      continue;
    ++count;
    std::vector<int> stack{ start };
    label[start] = count;
    while (!stack.empty())
    {
      const int k = stack.back();
      stack.pop_back();
      const int i = k % N, j = k / N;
      const int next[4][2] = { { i - 1, j }, { i + 1, j }, { i, j - 1 }, { i, j + 1 } };
      for (const auto& n : next)
      {
        if (n[0] < 0 || n[0] >= N || n[1] < 0 || n[1] >= N)
          continue;
        const int m = n[1] * N + n[0];
        if (inside[m] && !label[m])
        {
          label[m] = count;
          stack.push_back(m);
        }
      }
    }
  }
  return count;
}

/// The shape's value at (x, y) (PlacedShape::value's, prepared once for many points).
std::function<double(double, double)> valueOf(const ictk::geometry::PlacedShape& shape)
{
  std::shared_ptr<ictk::frep::FieldEvaluator> ev = ictk::geometry::worldField(shape)->evaluator();
  return [ev](double x, double y)
  {
    return ev->value({ x, y, 0 });
  };
}

/// The area of {f >= 0} over [-1.5, 1.5]^2 counted on the grid (each point stands for a square).
double gridArea(const std::function<double(double, double)>& f)
{
  int inside = 0;
  for (int j = 0; j < N; ++j)
    for (int i = 0; i < N; ++i)
      inside += f(gridCoordinate(i), gridCoordinate(j)) >= 0;
  const double h = 3.0 / (N - 1);
  return inside * h * h;
}

engine::DynamicModel morph(const std::string& blendCall, const std::string& dim = "3D")
{
  return engine::DynamicModel(ictk::lang::readIcm(morphModel(blendCall, dim), "stb.icm"));
}

} // namespace

TEST(SpaceTimeBlend, CellIsTheCrossBeforeAndTheDisksAfter)
{
  engine::DynamicModel m = morph("spaceTimeBlendCells(Cross, Disks, 1, 2, 1, 0.5, 0.5, 0.1)");
  m.start();
  for (double t : { 0.5, 1.0, 2.0, 2.5 })
  {
    m.advanceTo(t, 0.5);
    const std::vector<engine::CellState> cells = m.cells();
    ASSERT_EQ(cells.size(), 1u);
    EXPECT_EQ(cells[0].dimension, 2) << "the cross-section of a 3D (XYT) cell";
    const auto& shape = *cells[0].shape;
    const auto slice = valueOf(shape);
    const auto expected = t <= 1 ? cross : disks;
    int differ = 0;
    for (int j = 0; j < N; ++j)
      for (int i = 0; i < N; ++i)
      {
        const double x = gridCoordinate(i), y = gridCoordinate(j);
        const double e = expected(x, y);
        if (std::abs(e) > 1e-9 && (slice(x, y) >= 0) != (e > 0))
          ++differ;
      }
    EXPECT_EQ(differ, 0) << "t = " << t;
    EXPECT_EQ(components([&](double x, double y) { return slice(x, y); }), t <= 1 ? 1 : 2)
      << "t = " << t;
    // Areas: the cross 2 * 2 * 0.5 - 0.5^2 = 1.75, the disks 2 pi 0.4^2.
    EXPECT_NEAR(ictk::geometry::measure(shape), t <= 1 ? 1.75 : 2 * Pi * 0.16, 2e-3) << "t = " << t;
  }
}

TEST(SpaceTimeBlend, TransitionKeepsMaterialAndChangesTopologyOnce)
{
  engine::DynamicModel m = morph("spaceTimeBlendCells(Cross, Disks, 1, 2, 1, 0.5, 0.5, 0.1)");
  m.start();
  std::vector<int> counts;
  double previousArea = 1.75;
  for (int k = 1; k < 20; ++k)
  {
    const double t = 1 + 0.05 * k;
    m.advanceTo(t, 0.05);
    const std::vector<engine::CellState> cells = m.cells();
    const auto& shape = *cells[0].shape;
    const auto slice = valueOf(shape);
    counts.push_back(components(slice));
    const double area = gridArea(slice);
    // The bounded blend's added material (a0 = 1) never lets a slice vanish.
    EXPECT_GT(area, 0.5) << "t = " << t;
    // Slices 0.05 apart in time differ by less than 40 % in area: no jump.
    EXPECT_LT(std::abs(area - previousArea), 0.4 * previousArea) << "t = " << t;
    previousArea = area;
  }
  // One component while the cross dominates, two once the disks separate; never more.
  EXPECT_EQ(counts.front(), 1);
  EXPECT_EQ(counts.back(), 2);
  for (int c : counts)
  {
    EXPECT_GE(c, 1);
    EXPECT_LE(c, 2);
  }
}

TEST(SpaceTimeBlend, CellEqualsTheKernelsBlendOfItsOperands)
{
  // The T-cell's cross-section is frep::spaceTimeBlendExpr of the operands' values (here with
  // non-default parameters), evaluated through the kernel's tape on its own.
  const ictk::frep::SpaceTimeBlendParameters p{ 1.2, 1.8, 0.7, 1.3, 0.9, 0.5 };
  engine::DynamicModel m = morph("spaceTimeBlendCells(Cross, Disks, 1.2, 1.8, 0.7, 1.3, 0.9, 0.5)");
  m.start();
  std::mt19937 random(7);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  for (double t : { 1.3, 1.5, 1.65 })
  {
    m.advanceTo(t, 0.05);
    const std::vector<engine::CellState> cells = m.cells();
    const auto& shape = *cells[0].shape;
    const auto slice = valueOf(shape);
    using ictk::frep::Expr;
    ictk::frep::PointEvaluator blend(
      ictk::frep::Tape::compile(ictk::frep::spaceTimeBlendExpr(Expr::x(), Expr::y(), Expr(t), p)));
    for (int k = 0; k < 200; ++k)
    {
      const double x = u(random), y = u(random);
      // The operands are HyperFun R-functions; their values at (x, y) from the kernel too.
      const double fa = shape.parts[0].operandA->value({ x, y, 0 });
      const double fb = shape.parts[0].operandB->value({ x, y, 0 });
      const double expected = blend.eval(fa, fb, 0, 0);
      EXPECT_NEAR(slice(x, y), expected, 1e-12 * (1 + std::abs(expected)));
    }
  }
}

TEST(SpaceTimeBlend, WrongDimensionsAndParametersAreRefusedAtTheirPlace)
{
  struct Case
  {
    std::string call, dim, words;
  };
  const Case cases[] = {
    { "spaceTimeBlendCells(Cross, Disks, 1, 2, 1, 0.5, 0.5, 0.1)", "4D", "dim = 3D" },
    { "spaceTimeBlendCells(Cross, Disks, 1, 1, 1, 1, 1, 1)", "3D", "t0 < t1" },
    { "spaceTimeBlendCells(Cross, Disks, 1, 2, 1, 0, 1, 1)", "3D", "a1" },
  };
  for (const Case& c : cases)
  {
    try
    {
      morph(c.call, c.dim);
      ADD_FAILURE() << c.call << " was accepted";
    }
    catch (const engine::ModelError& e)
    {
      // The Morph cell's shape is on line 26, after `    shape = `.
      EXPECT_EQ(e.pos.line, 26) << e.what();
      EXPECT_EQ(e.pos.column, 13) << e.what();
      EXPECT_NE(e.message.find(c.words), std::string::npos) << e.message;
    }
  }
}

TEST(SpaceTimeBlend, HyperFunModelIsTheCrossThenTheBalls)
{
  // Data/Models/stb_cross_disks.hf, the 3D version: bars of section 0.5 and balls of radius 0.4.
  const auto model =
    ictk::lang::readHyperFunFile(std::string(ICTK_DATA_DIR) + "/Models/stb_cross_disks.hf");
  EXPECT_EQ(model.model.geometry().domain(), ictk::frep::Domain::XYZT);
  ictk::frep::PointEvaluator field(ictk::frep::Tape::compile(model.model.geometry().function()));
  auto bars = [](double x, double y, double z)
  {
    return std::min(cross(x, y), 0.25 - std::abs(z));
  };
  auto balls = [](double x, double y, double z)
  {
    return std::max(0.4 - std::sqrt((x + 0.7) * (x + 0.7) + y * y + z * z),
      0.4 - std::sqrt((x - 0.7) * (x - 0.7) + y * y + z * z));
  };
  std::mt19937 random(3);
  std::uniform_real_distribution<double> u(-1.2, 1.2);
  int checked = 0;
  for (int k = 0; k < 2000; ++k)
  {
    const double x = u(random), y = u(random), z = u(random);
    for (double t : { -0.5, 0.0, 1.0, 1.5 })
    {
      const double e = t <= 0 ? bars(x, y, z) : balls(x, y, z);
      if (std::abs(e) < 1e-9)
        continue;
      EXPECT_EQ(field.eval(x, y, z, t) >= 0, e > 0) << x << " " << y << " " << z;
      ++checked;
    }
  }
  EXPECT_GT(checked, 7900);
  // In the middle of the transition the blend's added material joins the two: the centre of the
  // cross, inside both the bars and the gap between the balls, stays inside.
  EXPECT_GT(field.eval(0, 0, 0, 0.5), 0.0);
}

TEST(SpaceTimeBlend, OperandsBlendAsTheyArePlaced)
{
  // The disks' cell moved by translation(0, 0.5, 0): after t1 the cross-section is the moved
  // disks, centred at (+-0.7, 0.5), at t = 2.5.
  std::string text = morphModel("spaceTimeBlendCells(Cross, Disks, 1, 2, 1, 0.5, 0.5, 0.1)");
  const std::string disksDomain = "domain = { -1.5, -1.5, 1.5, 1.5 };\n  }\n  Morph";
  const auto at = text.find(disksDomain);
  ASSERT_NE(at, std::string::npos);
  text.replace(at, disksDomain.size(),
    "domain = { -1.5, -1.5, 1.5, 1.5 };\n    parameters { translation(0, 0.5, 0); }\n  }\n  "
    "Morph");
  engine::DynamicModel m(ictk::lang::readIcm(text, "stb.icm"));
  m.start();
  m.advanceTo(2.5, 0.5);
  const std::vector<engine::CellState> cells = m.cells();
  const auto& shape = *cells[0].shape;
  const auto slice = valueOf(shape);
  int differ = 0;
  for (int j = 0; j < N; ++j)
    for (int i = 0; i < N; ++i)
    {
      const double x = gridCoordinate(i), y = gridCoordinate(j);
      const double e = disks(x, y - 0.5);
      if (std::abs(e) > 1e-9 && (slice(x, y) >= 0) != (e > 0))
        ++differ;
    }
  EXPECT_EQ(differ, 0);
}

TEST(SpaceTimeBlend, XYTModelIsASolidOfSpaceTime)
{
  // Data/Models/stb_cross_disks_xyt.xml: the same blend in XYT (t0 = 0, t1 = 1). As a solid of
  // space-time (ictk sample/mesh --space-time) its value at (x, y, z) is the model's at t = z.
  const ictk::frep::Hypervolume xyt =
    ictk::lang::readFRepXmlFile(std::string(ICTK_DATA_DIR) + "/Models/stb_cross_disks_xyt.xml");
  ASSERT_EQ(xyt.geometry().domain(), ictk::frep::Domain::XYT);
  const ictk::frep::Hypervolume solid = ictk::frep::spaceTimeSolid(xyt);
  EXPECT_EQ(solid.geometry().domain(), ictk::frep::Domain::XYZ);
  ictk::frep::PointEvaluator model(ictk::frep::Tape::compile(xyt.geometry().function()));
  ictk::frep::PointEvaluator space(ictk::frep::Tape::compile(solid.geometry().function()));
  std::mt19937 random(11);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  for (int k = 0; k < 500; ++k)
  {
    const double x = u(random), y = u(random), t = 0.5 + u(random) / 1.5;
    EXPECT_EQ(space.eval(x, y, t, 123.0), model.eval(x, y, 0, t));
    // Before t0 the cross, after t1 the disks.
    if (std::abs(cross(x, y)) > 1e-9)
    {
      EXPECT_EQ(space.eval(x, y, -0.25, 0) >= 0, cross(x, y) > 0);
    }
    if (std::abs(disks(x, y)) > 1e-9)
    {
      EXPECT_EQ(space.eval(x, y, 1.25, 0) >= 0, disks(x, y) > 0);
    }
  }
  EXPECT_THROW(ictk::frep::spaceTimeSolid(ictk::frep::Hypervolume(
                 ictk::frep::Shape(ictk::frep::Expr::x(), ictk::frep::Domain::XYZ))),
    ictk::frep::DomainError);
}

namespace
{

/// Thesis 5.3.4's STB_CELL (Data/Models/icm/ch5_3_4_nonlinear_sampling.icm) in the plane: the disk
/// of radius 1 becomes the disk of radius 0.5 at (1.5, 0) between t = 1 and 2, and a step whose
/// cross-section's area changed by more than volumeRate is rejected and retried at dt / 2.
std::string nonlinearSamplingModel(const std::string& update)
{
  return R"(name = NONLINEAR;
steps = grow;
TIMESPANS { film : TIMESPAN(0, 3); }
CELLS {
  BIG { type = F-CELL; shape = disk(1); dim = 2D; domain = { -1, -1, 1, 1 }; }
  SMALL {
    type = F-CELL; shape = disk(0.5); dim = 2D; domain = { -0.5, -0.5, 0.5, 0.5 };
    parameters { translation(1.5, 0, 0); }
  }
  STB_CELL {
    type = T-CELL;
    shape = spaceTimeBlendCells(BIG, SMALL, 1, 2, 1, 1, 1, 0.2);
    dim = 3D;
    domain = { -1.5, -1.5, 2.5, 1.5 };
    parameters {
      shapeVolume : REAL(0.0);
      volumeRate : REAL(0.2);
      timeDivider : REAL(2.0);
      acceptedSteps : INT(0);
      largestChange : REAL(0.0);
    }
    REACTIONS {
      update(REAL globalT, REAL localT, REAL lifeT, REAL dt)
      {
)" + update +
    R"(
      }
    }
  }
}
K { CELLS { STB_CELL; } }
)";
}

const char* const kVolumeRateUpdate = R"(
        SHAPE crossSection = makeCrossSection(shape, globalT);
        REAL curVolume = getVolume(crossSection);
        if (shapeVolume > 0 && abs(curVolume - shapeVolume) > volumeRate * shapeVolume) {
          IC::fireEvent(TIME_REJECTED, dt / timeDivider);
        } else {
          if (shapeVolume > 0) {
            largestChange = max(largestChange, abs(curVolume - shapeVolume) / shapeVolume);
          }
          shapeVolume = curVolume;
          acceptedSteps = acceptedSteps + 1;
        })";

} // namespace

TEST(SpaceTimeBlend, VolumeRateRefinesTheStepsWhereTheTransitionIsFast)
{
  engine::DynamicModel m(
    ictk::lang::readIcm(nonlinearSamplingModel(kVolumeRateUpdate), "nonlinear.icm"));
  m.start();
  // Area pi before t0, pi / 4 after t1 (the blend's area is integrated: 1e-4).
  EXPECT_NEAR(m.value("STB_CELL.shapeVolume").number, Pi, 1e-4 * Pi);
  std::vector<engine::FrameRecord> frames;
  for (int k = 1; k <= 12; ++k)
    for (engine::FrameRecord& r : m.advanceTo(0.25 * k, 0.25))
      frames.push_back(std::move(r));
  // Every requested frame is delivered, each with the steps that reached it.
  ASSERT_EQ(frames.size(), 12u);
  std::size_t steps = 0, rejected = 0;
  double last = 0.0;
  for (std::size_t k = 0; k < frames.size(); ++k)
  {
    const engine::FrameRecord& r = frames[k];
    EXPECT_DOUBLE_EQ(r.time, 0.25 * static_cast<double>(k + 1));
    ASSERT_FALSE(r.steps.empty());
    EXPECT_DOUBLE_EQ(r.steps.back(), r.time);
    for (double t : r.steps)
    {
      EXPECT_GT(t, last); // never back before the last accepted time (thesis L2082)
      last = t;
    }
    steps += r.steps.size();
    rejected += static_cast<std::size_t>(r.rejectedSteps);
    // Outside the transition the area does not change: one step per frame.
    if (r.time <= 1.0 || r.time > 2.25)
    {
      EXPECT_EQ(r.steps.size(), 1u) << "t = " << r.time;
      EXPECT_EQ(r.rejectedSteps, 0) << "t = " << r.time;
    }
  }
  EXPECT_EQ(m.value("STB_CELL.acceptedSteps").number, static_cast<double>(steps + 1)); // + start
  // pi -> pi / 4 at most 20 % a step needs at least ln 4 / ln 1.25 = 6.2 steps, here within the
  // four frames of the transition.
  std::size_t during = 0;
  for (const engine::FrameRecord& r : frames)
    if (r.time > 1.0 && r.time <= 2.25)
      during += r.steps.size();
  EXPECT_GE(during, 7u);
  EXPECT_GT(rejected, 0u);
  EXPECT_LE(m.value("STB_CELL.largestChange").number, 0.2);
  EXPECT_GT(m.value("STB_CELL.largestChange").number, 0.05);
  EXPECT_NEAR(m.value("STB_CELL.shapeVolume").number, Pi / 4, 1e-4 * Pi);
}

TEST(SpaceTimeBlend, CrossSectionsAreTakenAtTheTimeBeingEvaluated)
{
  // makeCrossSection cuts where the engine evaluates; anywhere else is refused, never computed
  // silently at another time; a cell without time has no cross-section.
  for (const auto& [update, message] : std::vector<std::pair<std::string, std::string>>{
         { "REAL v = getVolume(makeCrossSection(shape, globalT + 0.5));",
           "the model is evaluating t = " },
         { "REAL v = getVolume(makeCrossSection(BIG.shape, globalT));",
           "BIG is not a space-time cell" },
         { "REAL v = getVolume(segment(vec3(0, 0, 0), vec3(1, 0, 0)));",
           "getVolume takes a cell's shape" } })
  {
    engine::DynamicModel m(ictk::lang::readIcm(nonlinearSamplingModel(update), "nonlinear.icm"));
    try
    {
      m.start();
      m.advanceTo(0.5, 0.25);
      ADD_FAILURE() << update;
    }
    catch (const engine::ModelError& e)
    {
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("nonlinear.icm:"), std::string::npos) << e.what();
    }
  }
}

namespace
{

/// Two disks of radius 0.3 at x = -1 and x = 1 blended between t = 1 and t = 2: far apart for
/// their size, the case thesis 5.3.2 says breaks into separate components (L3096).
engine::DynamicModel farDisks(const std::string& align)
{
  return engine::DynamicModel(ictk::lang::readIcm(R"(name = FAR;
TIMESPANS { film : TIMESPAN(0, 3); }
CELLS {
  LEFT {
    type = F-CELL; shape = disk(0.3); dim = 2D; domain = { -0.3, -0.3, 0.3, 0.3 };
    parameters { translation(-1, 0, 0); }
  }
  RIGHT {
    type = F-CELL; shape = disk(0.3); dim = 2D; domain = { -0.3, -0.3, 0.3, 0.3 };
    parameters { translation(1, 0, 0); }
  }
  MORPH {
    type = T-CELL;
    shape = spaceTimeBlendCells(LEFT, RIGHT, 1, 2, 0.5, 1, 1, 0.2)" +
      align + R"();
    dim = 3D;
    domain = { -1.5, -1.5, 1.5, 1.5 };
  }
}
K { CELLS { MORPH; } }
)",
    "far.icm"));
}

} // namespace

TEST(SpaceTimeBlend, AutomaticAlignmentKeepsTheTransitionInOnePiece)
{
  std::vector<int> plain, aligned;
  for (const std::string align : { "", ", 1" })
  {
    engine::DynamicModel m = farDisks(align);
    m.start();
    for (int k = 0; k <= 10; ++k)
    {
      const double t = 0.95 + 0.1 * k; // 0.95 .. 1.95, then 2.5
      m.advanceTo(k == 10 ? 2.5 : t, 0.5);
      const auto slice = valueOf(*m.cells()[0].shape);
      (align.empty() ? plain : aligned).push_back(components(slice));
      // Aligned, both extrusions sit on the same box, the one a fraction u of the way from LEFT
      // to RIGHT: the slice is centred at x = -1 + 2u.
      if (!align.empty() && k < 10 && t > 1)
      {
        double sum = 0;
        int inside = 0;
        for (int j = 0; j < N; ++j)
          for (int i = 0; i < N; ++i)
            if (slice(gridCoordinate(i), gridCoordinate(j)) >= 0)
            {
              sum += gridCoordinate(i);
              ++inside;
            }
        ASSERT_GT(inside, 0);
        EXPECT_NEAR(sum / inside, -1 + 2 * (t - 1), 0.02) << "t = " << t;
      }
      // Before t0 LEFT, after t1 RIGHT, aligned or not (sign on the grid).
      if (k == 0 || k == 10)
      {
        const double cx = k == 0 ? -1 : 1;
        int differ = 0;
        for (int j = 0; j < N; ++j)
          for (int i = 0; i < N; ++i)
          {
            const double x = gridCoordinate(i), y = gridCoordinate(j);
            const double e = 0.3 - std::hypot(x - cx, y);
            differ += std::abs(e) > 1e-2 && (slice(x, y) >= 0) != (e > 0);
          }
        EXPECT_EQ(differ, 0) << "align '" << align << "' at t = " << t;
      }
    }
  }
  // Plain blending loses the shape halfway (no component at t = 1.35 .. 1.65); aligned, one
  // component at every slice.
  EXPECT_GE(std::count(plain.begin(), plain.end(), 0), 3);
  EXPECT_EQ(std::count(aligned.begin(), aligned.end(), 1), 11);
  // A fraction outside [0, 1] is refused at its place.
  try
  {
    farDisks(", 1.5");
    ADD_FAILURE() << "align 1.5 accepted";
  }
  catch (const engine::ModelError& e)
  {
    EXPECT_NE(std::string(e.what()).find("far.icm:"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("alignment of MORPH"), std::string::npos) << e.what();
  }
}

TEST(SpaceTimeBlend, ThesisStbCellSamplesItsFourDimensionalFilm)
{
  // Data/Models/icm/ch5_3_4_nonlinear_sampling.icm: the ball of radius 1 becomes the ball of
  // radius 0.5 at x = 1.5 between t = 1 and 2, the volume 4/3 pi -> 4/3 pi / 8 in accepted steps
  // that each change it by at most 20 %, refined only during the transition.
  engine::DynamicModel m = engine::DynamicModel::load(
    std::string(ICTK_DATA_DIR) + "/Models/icm/ch5_3_4_nonlinear_sampling.icm");
  m.start();
  EXPECT_NEAR(m.value("STB_CELL.shapeVolume").number, 4 * Pi / 3, 1e-3 * 4 * Pi / 3);
  std::size_t outside = 0, during = 0;
  for (int k = 1; k <= 6; ++k)
    for (const engine::FrameRecord& r : m.advanceTo(0.5 * k, 0.5))
      (r.time > 1 && r.time <= 2.5 ? during : outside) += r.steps.size();
  EXPECT_EQ(outside, 3u); // t = 0.5, 1 and 3
  // A step keeps at least 80 % of the volume: ln 8 / ln 1.25 = 9.3, at least 10 steps.
  EXPECT_GE(during, 10u);
  EXPECT_LE(m.value("STB_CELL.largestChange").number, 0.2);
  EXPECT_NEAR(m.value("STB_CELL.shapeVolume").number, Pi / 6, 1e-3 * Pi / 6);
}

// ---- Thesis 5.3.3: warps from control points, and the automatic control points of eq. (4). ----

namespace
{

using ictk::geometry::PlacedShape;
using ictk::geometry::PlacedShapePtr;
using ictk::geometry::ShapePart;
using ictk::geometry::Vec3;

/// A disk of radius r centred at (x, y), placed.
PlacedShapePtr diskAt(double r, double x, double y)
{
  auto s = std::make_shared<PlacedShape>();
  s->cell = "disk";
  s->dimension = 2;
  ShapePart p;
  p.kind = ShapePart::Kind::Disk;
  p.radius = r;
  s->parts.push_back(p);
  s->place.b = { x, y, 0 };
  return s;
}

PlacedShapePtr unionOf(PlacedShapePtr a, PlacedShapePtr b)
{
  auto s = std::make_shared<PlacedShape>();
  s->cell = "union";
  s->dimension = 2;
  ShapePart p;
  p.kind = ShapePart::Kind::Union;
  p.operandA = std::move(a);
  p.operandB = std::move(b);
  s->parts.push_back(p);
  return s;
}

double distance3(const Vec3& a, const Vec3& b)
{
  return std::sqrt(
    (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

/// A disk of radius 0.5 at the origin becomes two disks of radius 0.3 at (+-1.5, 0) between t = 1
/// and t = 2: one feature becomes two far away, plain blending breaks the slices into pieces.
engine::DynamicModel diskToTwoDisks(const std::string& after)
{
  return engine::DynamicModel(ictk::lang::readIcm(R"(name = SPLIT;
TIMESPANS { film : TIMESPAN(0, 3); }
CELLS {
  ONE { type = F-CELL; shape = disk(0.5); dim = 2D; domain = { -0.5, -0.5, 0.5, 0.5 }; }
  TWO {
    type = F-CELL;
    shape = hyperfun {
      two(x[2], a[1]) {
        two = (0.3 - sqrt((x[1] + 1.5)^2 + x[2]^2)) | (0.3 - sqrt((x[1] - 1.5)^2 + x[2]^2));
      }
    }
    dim = 2D;
    domain = { -2, -0.5, 2, 0.5 };
  }
  MORPH {
    type = T-CELL;
    shape = spaceTimeBlendCells(ONE, TWO, 1, 2, 0.5, 1, 1, 0.2)" +
      after + R"();
    dim = 3D;
    domain = { -2, -1.5, 2, 1.5 };
  }
}
K { CELLS { MORPH; } }
)",
    "split.icm"));
}

constexpr int M = 161; // grid points per axis over [-2, 2] for the split example
double splitCoordinate(int i)
{
  return -2.0 + 4.0 * i / (M - 1);
}

/// 4-connected components of {f >= 0} on the M x M grid over [-2, 2]^2.
int splitComponents(const std::function<double(double, double)>& f)
{
  std::vector<int> label(M * M, 0);
  std::vector<char> inside(M * M);
  for (int j = 0; j < M; ++j)
    for (int i = 0; i < M; ++i)
      inside[j * M + i] = f(splitCoordinate(i), splitCoordinate(j)) >= 0;
  int count = 0;
  for (int start = 0; start < M * M; ++start)
  {
    if (!inside[start] || label[start])
      continue;
    ++count;
    std::vector<int> stack{ start };
    label[start] = count;
    while (!stack.empty())
    {
      const int k = stack.back();
      stack.pop_back();
      const int i = k % M, j = k / M;
      const int next[4][2] = { { i - 1, j }, { i + 1, j }, { i, j - 1 }, { i, j + 1 } };
      for (const auto& n : next)
      {
        if (n[0] < 0 || n[0] >= M || n[1] < 0 || n[1] >= M)
          continue;
        const int m = n[1] * M + n[0];
        if (inside[m] && !label[m])
        {
          label[m] = count;
          stack.push_back(m);
        }
      }
    }
  }
  return count;
}

} // namespace

TEST(SpaceTimeBlend, ThickFeaturesAreTheMaximaOfTheDistanceTransform)
{
  // Union of the disks r = 1 at (0, 0) and r = 0.5 at (3, 0) (the spec's Scenario E): the
  // maxima are the centres, at depths 1 and 0.5. The grid: 128 cells over the 4.5-wide box.
  const double h = 4.5 / 128;
  const PlacedShapePtr disks = unionOf(diskAt(1, 0, 0), diskAt(0.5, 3, 0));
  std::vector<double> depths;
  std::vector<Vec3> points = ictk::geometry::thickFeatures(*disks, 2, 0.5, &depths);
  ASSERT_EQ(points.size(), 2u);
  EXPECT_LE(distance3(points[0], { 0, 0, 0 }), std::sqrt(2.0) * h) << points[0][0];
  EXPECT_LE(distance3(points[1], { 3, 0, 0 }), std::sqrt(2.0) * h) << points[1][0];
  EXPECT_NEAR(depths[0], 1.0, h);
  EXPECT_NEAR(depths[1], 0.5, h);
  // One point: the deepest. Three asked: the big disk has no other maximum 0.5 away, but the
  // small one's is taken only once either way.
  points = ictk::geometry::thickFeatures(*disks, 1, 0.5);
  ASSERT_EQ(points.size(), 1u);
  EXPECT_LE(distance3(points[0], { 0, 0, 0 }), std::sqrt(2.0) * h);
  EXPECT_EQ(ictk::geometry::thickFeatures(*disks, 3, 0.5).size(), 2u);

  // A 4 x 1 rectangle: its medial axis is the segment |x| <= 1.5, y = 0, where the distance is
  // 0.5 all along (a flat ridge); three points at least 1 apart lie on it.
  auto rectangle = std::make_shared<PlacedShape>();
  rectangle->cell = "rectangle";
  rectangle->dimension = 2;
  ShapePart r;
  r.kind = ShapePart::Kind::Rectangle;
  r.size = { 4, 1, 0 };
  rectangle->parts.push_back(r);
  const double hr = 4.0 / 128;
  points = ictk::geometry::thickFeatures(*rectangle, 3, 1.0, &depths);
  ASSERT_EQ(points.size(), 3u);
  for (std::size_t i = 0; i < points.size(); ++i)
  {
    EXPECT_LE(std::abs(points[i][1]), hr) << i;
    EXPECT_LE(std::abs(points[i][0]), 1.5 + hr) << i;
    EXPECT_NEAR(depths[i], 0.5, hr) << i;
    for (std::size_t j = 0; j < i; ++j)
      EXPECT_GE(distance3(points[i], points[j]), 1.0) << i << " " << j;
  }

  // A ball of radius 1 centred at (0.2, 0, -0.3): one maximum, the centre (64 cells over 2).
  auto ball = std::make_shared<PlacedShape>();
  ball->cell = "ball";
  ball->dimension = 3;
  ShapePart b;
  b.kind = ShapePart::Kind::Sphere;
  b.radius = 1;
  ball->parts.push_back(b);
  ball->place.b = { 0.2, 0, -0.3 };
  points = ictk::geometry::thickFeatures(*ball, 2, 0.5, &depths);
  ASSERT_EQ(points.size(), 1u);
  EXPECT_LE(distance3(points[0], { 0.2, 0, -0.3 }), std::sqrt(3.0) * 2.0 / 64);
  // The depth: the cell centre may be sqrt(3) h / 2 off the centre, and the boundary up to h / 2
  // off the half-cell correction.
  EXPECT_NEAR(depths[0], 1.0, 2 * 2.0 / 64);

  EXPECT_THROW(ictk::geometry::thickFeatures(*ball, 0, 0.5), std::invalid_argument);
  EXPECT_THROW(ictk::geometry::thickFeatures(*ball, 1, -1), std::invalid_argument);
}

TEST(SpaceTimeBlend, ControlPointsArePairedByLeastTotalDistance)
{
  // Crossing pairs would cost 1.1 + 0.9 = 2.0; the straight ones 0.1 + 0.1.
  auto pairs = ictk::geometry::pairControlPoints(
    { { 0, 0, 0 }, { 1, 0, 0 } }, { { 1.1, 0, 0 }, { 0.1, 0, 0 } });
  ASSERT_EQ(pairs.size(), 2u);
  EXPECT_EQ(pairs[0].destination[0], 0.1);
  EXPECT_EQ(pairs[1].destination[0], 1.1);
  // One source, two destinations: the source goes to both (the first by the matching, the
  // other as its nearest source).
  pairs = ictk::geometry::pairControlPoints({ { 0, 0, 0 } }, { { -1.5, 0, 0 }, { 1.5, 0, 0 } });
  ASSERT_EQ(pairs.size(), 2u);
  EXPECT_EQ(pairs[0].source[0], 0.0);
  EXPECT_EQ(pairs[1].source[0], 0.0);
  EXPECT_EQ(pairs[0].destination[0] + pairs[1].destination[0], 0.0);
  EXPECT_EQ(std::abs(pairs[0].destination[0]), 1.5);
  // Three sources, one destination: all three go there.
  pairs =
    ictk::geometry::pairControlPoints({ { 0, 0, 0 }, { 1, 0, 0 }, { 2, 0, 0 } }, { { 5, 0, 0 } });
  ASSERT_EQ(pairs.size(), 3u);
  for (const auto& p : pairs)
    EXPECT_EQ(p.destination[0], 5.0);
  EXPECT_THROW(ictk::geometry::pairControlPoints(std::vector<Vec3>(9), { { 0, 0, 0 } }),
    std::invalid_argument);
}

TEST(SpaceTimeBlend, WarpMovesFeaturesAlongTime)
{
  // The warp at progress u: cellA at p + D_A(p), cellB at p + D_B(p); at a node m_i = s_i +
  // u (d_i - s_i) they read s_i and d_i exactly, and between nodes D is Shepard's average.
  const std::vector<ictk::geometry::ControlPair> pairs = { { { 0, 0, 0 }, { -1.5, 0, 0 } },
    { { 0, 0, 0 }, { 1.5, 0, 0 } } };
  const auto w = ictk::geometry::SpaceTimeWarp::at(pairs, 0.4);
  ASSERT_EQ(w.nodes.size(), 2u);
  EXPECT_DOUBLE_EQ(w.nodes[1][0], 0.6);
  for (std::size_t i = 0; i < 2; ++i)
  {
    const Vec3 a = w.shift(w.shiftA, w.nodes[i]), b = w.shift(w.shiftB, w.nodes[i]);
    EXPECT_DOUBLE_EQ(w.nodes[i][0] + a[0], 0.0);
    EXPECT_DOUBLE_EQ(w.nodes[i][0] + b[0], pairs[i].destination[0]);
  }
  // At (0, 1): distances equal, the mean of the shifts, 0.
  EXPECT_NEAR(w.shift(w.shiftA, { 0, 1, 0 })[0], 0.0, 1e-15);
  // At (1, 0.5): weights 1 / (0.4^2 + 0.25) and 1 / (1.6^2 + 0.25), by hand.
  const double w1 = 1 / (0.16 + 0.25), w0 = 1 / (2.56 + 0.25);
  EXPECT_NEAR(w.shift(w.shiftA, { 1, 0.5, 0 })[0], (w0 * 0.6 + w1 * -0.6) / (w0 + w1), 1e-14);
  // The Jacobian against central differences.
  double j[9];
  const Vec3 p{ 0.3, 0.7, 0 };
  w.shift(w.shiftB, p, j);
  for (int c = 0; c < 2; ++c)
  {
    Vec3 lo = p, hi = p;
    lo[c] -= 1e-6;
    hi[c] += 1e-6;
    for (int row = 0; row < 2; ++row)
      EXPECT_NEAR(
        j[3 * row + c], (w.shift(w.shiftB, hi)[row] - w.shift(w.shiftB, lo)[row]) / 2e-6, 1e-6);
  }
}

TEST(SpaceTimeBlend, WarpKeepsTheSplitInOnePieceUntilItSeparates)
{
  // Plain, the middle disk shrinks while the two far disks grow: the slices in the middle are
  // empty (measured: 1 1 1 1 0 0 0 0 2 2 2 2 2 over the 13 times below). Warped (the automatic
  // control points: ONE's centre, TWO's two centres; or the same pairs given), ONE is stretched
  // toward both destinations while TWO's disks come from the centre: one component, then two, never
  // anything else; the features sit on the moving nodes (+-1.5 u, 0).
  for (const std::string after :
    { "", ", 0, 2, 0.5", ", 0, vec3(0, 0, 0), vec3(-1.5, 0, 0), vec3(0, 0, 0), vec3(1.5, 0, 0)" })
  {
    engine::DynamicModel m = diskToTwoDisks(after);
    m.start();
    std::vector<int> counts;
    for (int k = 0; k <= 12; ++k)
    {
      const double t = k == 0 ? 0.5 : k == 12 ? 2.5 : 1 + 0.1 * (k - 1) + 0.05; // 1.05 .. 2.05
      m.advanceTo(t, 0.5);
      const auto slice = valueOf(*m.cells()[0].shape);
      counts.push_back(splitComponents(slice));
      if (k == 0 || k == 12)
      {
        // Before t0 ONE, after t1 TWO: the warp is the identity there.
        int differ = 0;
        for (int jj = 0; jj < M; ++jj)
          for (int i = 0; i < M; ++i)
          {
            const double x = splitCoordinate(i), y = splitCoordinate(jj);
            const double e = k == 0
              ? 0.5 - std::hypot(x, y)
              : std::max(0.3 - std::hypot(x + 1.5, y), 0.3 - std::hypot(x - 1.5, y));
            differ += std::abs(e) > 1e-9 && (slice(x, y) >= 0) != (e > 0);
          }
        EXPECT_EQ(differ, 0) << "'" << after << "' t = " << t;
      }
      else if (!after.empty() && t < 2)
      {
        const double u = t - 1;
        EXPECT_GT(slice(1.5 * u, 0), 0) << "'" << after << "' t = " << t;
        EXPECT_GT(slice(-1.5 * u, 0), 0) << "'" << after << "' t = " << t;
      }
    }
    std::string seen;
    for (int c : counts)
      seen += std::to_string(c) + " ";
    EXPECT_EQ(counts.front(), 1) << seen;
    EXPECT_EQ(counts.back(), 2) << seen;
    if (after.empty())
    {
      EXPECT_TRUE(std::any_of(counts.begin(), counts.end(), [](int c) { return c == 0 || c > 2; }))
        << "plain: " << seen;
    }
    else
    {
      // 1 ... 1 2 ... 2: monotone, never empty, never more than the destination's two.
      EXPECT_TRUE(std::is_sorted(counts.begin(), counts.end())) << after << ": " << seen;
      for (int c : counts)
      {
        EXPECT_GE(c, 1) << after << ": " << seen;
        EXPECT_LE(c, 2) << after << ": " << seen;
      }
    }
  }
}

TEST(SpaceTimeBlend, MalformedWarpsAreRefusedAtTheirPlace)
{
  struct Case
  {
    std::string after, words;
  };
  const Case cases[] = {
    { ", 0, vec3(0, 0, 0), vec3(1, 0, 0), vec3(0, 0, 0)", "pairs" },
    { ", 0, vec3(0, 0, 0), vec3(1, 0, 0)", "2 pairs or more" },
    { ", 0, vec3(0, 0, 0), vec3(1, 0, 0), vec3(0, 0, 0), 3", "argument 13" },
    { ", 1, 2, 0.5", "align = 0" },
    { ", 0, 9, 0.5", "from 1 to 8" },
    { ", 0, 1.5, 0.5", "whole number" },
    { ", 0, 2, -1", "separation" },
    { ", 0, 2", "two numbers" },
  };
  for (const Case& c : cases)
  {
    try
    {
      diskToTwoDisks(c.after);
      ADD_FAILURE() << c.after << " was accepted";
    }
    catch (const engine::ModelError& e)
    {
      EXPECT_NE(std::string(e.what()).find("split.icm:17:"), std::string::npos) << e.what();
      EXPECT_NE(e.message.find(c.words), std::string::npos) << e.message;
    }
  }
}

// ---- Thesis 5.3.2, the manual variant: the operands' own time-dependent placements. ----

namespace
{

/// cellA and cellB, both placed by `placeA` / `placeB` (reaction statements run at every step,
/// u the transition's progress), blended between t = 1 and t = 2.
engine::DynamicModel placedInTime(const std::string& shapeA, const std::string& shapeB,
  const std::string& placeA, const std::string& placeB, const std::string& t1 = "2")
{
  auto cell = [](const std::string& name, const std::string& shape, const std::string& place)
  {
    return "  " + name + " {\n    type = F-CELL; shape = " + shape +
      "; dim = 2D; domain = { -1.5, -1.5, 1.5, 1.5 };\n" +
      "    REACTIONS {\n      update(REAL globalT, REAL localT, REAL lifeT, REAL dt)\n      {\n" +
      "        REAL u = min(max(globalT - 1, 0) / (T1 - 1), 1);\n        " + place +
      "\n      }\n    }\n  }\n";
  };
  return engine::DynamicModel(ictk::lang::readIcm("name = PLACED;\nparameters { T1 : REAL(" + t1 +
      "); }\nTIMESPANS { film : TIMESPAN(0, 5); }\nCELLS {\n" + cell("A", shapeA, placeA) +
      cell("B", shapeB, placeB) +
      "  MORPH {\n    type = T-CELL;\n    shape = spaceTimeBlendCells(A, B, 1, T1, 0.5, 1, 1, "
      "0.2);\n    dim = 3D;\n    domain = { -2, -2, 2, 2 };\n  }\n}\n"
      "K { CELLS { MORPH; A; B; } }\n",
    "placed.icm"));
}

std::function<double(double, double)> morphSlice(const engine::DynamicModel& m)
{
  for (const engine::CellState& c : m.cells())
    if (c.name == "MORPH")
      return valueOf(*c.shape);
  ADD_FAILURE() << "no MORPH";
  return [](double, double)
  {
    return -1.0;
  };
}

/// The inside's area, centroid, and principal direction (radians, of the larger second moment)
/// and the ratio of the second moments, on the N x N grid over [-1.5, 1.5]^2.
struct Moments
{
  double area = 0, cx = 0, cy = 0, angle = 0, ratio = 0;
};

Moments momentsOf(const std::function<double(double, double)>& f)
{
  std::vector<std::pair<double, double>> in;
  for (int j = 0; j < N; ++j)
    for (int i = 0; i < N; ++i)
      if (f(gridCoordinate(i), gridCoordinate(j)) >= 0)
        in.emplace_back(gridCoordinate(i), gridCoordinate(j));
  Moments r;
  if (in.empty())
    return r;
  const double h = 3.0 / (N - 1);
  r.area = static_cast<double>(in.size()) * h * h;
  for (const auto& [x, y] : in)
  {
    r.cx += x / static_cast<double>(in.size());
    r.cy += y / static_cast<double>(in.size());
  }
  double xx = 0, yy = 0, xy = 0;
  for (const auto& [x, y] : in)
  {
    xx += (x - r.cx) * (x - r.cx);
    yy += (y - r.cy) * (y - r.cy);
    xy += (x - r.cx) * (y - r.cy);
  }
  r.angle = 0.5 * std::atan2(2 * xy, xx - yy);
  const double mean = 0.5 * (xx + yy), dev = std::hypot(0.5 * (xx - yy), xy);
  r.ratio = (mean + dev) / std::max(mean - dev, 1e-12);
  return r;
}

} // namespace

TEST(SpaceTimeBlend, RotationAboutTheTimeAxisTurnsTheBar)
{
  // A bar 2 x 0.4 becomes the same bar turned by 90 degrees. Plain, the middle slice is both bars
  // at once (a cross: equal second moments). Both operands turned by (pi / 2) u about the time
  // axis (their rotation.z set by a reaction), each slice is one bar at the angle (pi / 2) u.
  const std::string bar = "rectangle(2, 0.4)";
  engine::DynamicModel plain =
    placedInTime(bar, bar, "rotation.z = 0;", "rotation.z = 1.5707963267948966;");
  plain.start();
  plain.advanceTo(1.5, 0.5);
  const Moments cross = momentsOf(morphSlice(plain));
  EXPECT_GT(cross.area, 0.5);
  EXPECT_LT(cross.ratio, 1.2) << "plain: a cross, no direction";

  const std::string turn = "rotation.z = 1.5707963267948966 * u;";
  engine::DynamicModel turned = placedInTime(bar, bar, turn, turn);
  turned.start();
  for (double t : { 0.5, 1.1, 1.25, 1.5, 1.75, 1.9, 2.5 })
  {
    turned.advanceTo(t, 0.05);
    const auto slice = morphSlice(turned);
    const Moments mo = momentsOf(slice);
    const double u = std::clamp(t - 1, 0.0, 1.0);
    double angle = mo.angle;
    if (u > 0.75 && angle < 0)
      angle += Pi; // atan2's branch: a bar at 90 degrees is also at -90
    EXPECT_NEAR(angle, 0.5 * Pi * u, 2 * Pi / 180) << "t = " << t;
    EXPECT_GT(mo.ratio, 4.0) << "t = " << t << ": a bar";
    EXPECT_EQ(components(slice), 1) << "t = " << t;
    EXPECT_NEAR(mo.cx, 0, 1e-9);
    EXPECT_NEAR(mo.cy, 0, 1e-9);
    if (t < 1 || t > 2)
    {
      // The bar itself, 2 x 0.4, counted on the same grid.
      const double grid =
        gridArea([](double x, double y) { return std::min(1 - std::abs(x), 0.2 - std::abs(y)); });
      EXPECT_NEAR(grid, 0.8, 0.07);
      EXPECT_NEAR(mo.area, grid, 1e-9) << "t = " << t;
    }
  }
}

TEST(SpaceTimeBlend, TranslationAlongTimeCarriesTheFeature)
{
  // Two disks of radius 0.3 at x = -1 and x = 1 (the far disks above, where plain blending
  // loses the shape): both translated to x = -1 + 2u, a feature moved along t, each slice is one
  // disk centred there.
  engine::DynamicModel m = placedInTime(
    "disk(0.3)", "disk(0.3)", "translation.x = -1 + 2 * u;", "translation.x = -1 + 2 * u;");
  m.start();
  for (double t : { 0.5, 1.1, 1.3, 1.5, 1.7, 1.9, 2.5 })
  {
    m.advanceTo(t, 0.05);
    const auto slice = morphSlice(m);
    const Moments mo = momentsOf(slice);
    const double u = std::clamp(t - 1, 0.0, 1.0);
    EXPECT_EQ(components(slice), 1) << "t = " << t;
    EXPECT_NEAR(mo.cx, -1 + 2 * u, 0.01) << "t = " << t;
    EXPECT_NEAR(mo.cy, 0, 0.01) << "t = " << t;
    EXPECT_GT(mo.area, 0.2) << "t = " << t;
    if (t < 1 || t > 2)
    {
      EXPECT_NEAR(mo.area, Pi * 0.09, 0.01) << "t = " << t;
    }
  }
}

TEST(SpaceTimeBlend, ScalingAlongTimeStretchesTheTransition)
{
  // A disk of radius 0.6 becomes a bar 2.4 x 0.4. Scaling the space-time object along t about t0
  // by s is the interval [t0, t0 + s (t1 - t0)]: t1 is an expression, here the model's T1. With
  // s = 1 the slice at t = 2 is the bar; with s = 2 it is still between the two (and the bar
  // comes at t = 3), while before t0 both are the disk.
  auto signDiffers = [](const std::function<double(double, double)>& slice,
                       const std::function<double(double, double)>& shape)
  {
    int differ = 0;
    for (int j = 0; j < N; ++j)
      for (int i = 0; i < N; ++i)
      {
        const double x = gridCoordinate(i), y = gridCoordinate(j), e = shape(x, y);
        differ += std::abs(e) > 1e-9 && (slice(x, y) >= 0) != (e > 0);
      }
    return differ;
  };
  auto disk = [](double x, double y)
  {
    return 0.6 - std::hypot(x, y);
  };
  auto bar = [](double x, double y)
  {
    return std::min(1.2 - std::abs(x), 0.2 - std::abs(y));
  };
  for (const std::string t1 : { "2", "3" })
  {
    engine::DynamicModel m =
      placedInTime("disk(0.6)", "rectangle(2.4, 0.4)", "u = 0;", "u = 0;", t1);
    m.start();
    m.advanceTo(1, 0.5);
    EXPECT_EQ(signDiffers(morphSlice(m), disk), 0) << "T1 = " << t1;
    m.advanceTo(2, 0.1);
    const int atTwo = signDiffers(morphSlice(m), bar);
    if (t1 == "2")
    {
      EXPECT_EQ(atTwo, 0);
    }
    else
    {
      EXPECT_GT(atTwo, 100) << "halfway through the stretched transition";
      EXPECT_GT(signDiffers(morphSlice(m), disk), 100);
      m.advanceTo(3, 0.1);
      EXPECT_EQ(signDiffers(morphSlice(m), bar), 0);
    }
  }
}

TEST(SpaceTimeBlend, HyperFunRefusesAlignAndWarpAtTheirPlaceNamingTheIcmWay)
{
  // hfSpaceTimeBlend gets the operands' values at x, so it cannot evaluate them at moved points
  // (align, warp): an argument after a3 is refused where it is, not ignored.
  const std::string text =
    "m(x[4], a[1])\n{\n  f1 = 0.25 - x[1]^2 - x[2]^2;\n"
    "  f2 = 0.09 - x[1]^2 - x[2]^2;\n"
    "  m = hfSpaceTimeBlend(f1, f2, x[4], 0, 1, 1, 0.5, 0.5, 0.1, 0.5);\n}\n";
  try
  {
    ictk::lang::readHyperFun(text, "stb.hf");
    FAIL() << "an align argument was accepted";
  }
  catch (const ictk::lang::ParseError& e)
  {
    ASSERT_EQ(e.diagnostics().size(), 1u) << e.what();
    const ictk::lang::Diagnostic& d = e.diagnostics()[0];
    EXPECT_EQ(d.where.line, 5);
    EXPECT_EQ(d.where.column, 62);
    EXPECT_NE(d.message.find("no align or warp"), std::string::npos) << d.message;
    EXPECT_NE(d.message.find("spaceTimeBlendCells in .icm models"), std::string::npos) << d.message;
  }
  // The nine arguments still read.
  const std::string nine = text.substr(0, text.find(", 0.5);")) + ");\n}\n";
  EXPECT_NO_THROW(ictk::lang::readHyperFun(nine, "stb.hf"));
}
