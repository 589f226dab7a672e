// SPDX-License-Identifier: BSD-3-Clause
// The engine that runs .icm models (Modules/Core/Engine), on the exemplars of thesis ch. 4.4 and 5
// (Data/Models/icm). Every expected value is derived by hand in the comment next to it.
#include "Engine/Builtins.h"
#include "Engine/DynamicModel.h"
#include "Geometry/Queries.h"
#include "Lang/Icm.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <optional>
#include <string>

namespace
{

using ictk::engine::DynamicModel;
using ictk::engine::FrameRecord;
using ictk::engine::ModelError;
using ictk::engine::Value;

const std::string models = std::string(ICTK_DATA_DIR) + "/Models/icm/";
constexpr double pi = 3.14159265358979323846;

DynamicModel load(const std::string& name)
{
  return DynamicModel::load(models + name);
}

double real(const DynamicModel& m, const std::string& path)
{
  const Value v = m.value(path);
  EXPECT_TRUE(v.isNumber()) << path;
  return v.number;
}

const FrameRecord* transitionTo(const std::vector<FrameRecord>& rs, const std::string& instance)
{
  for (const FrameRecord& r : rs)
    if (r.transition && r.instance == instance)
      return &r;
  return nullptr;
}

DynamicModel fromText(const std::string& text)
{
  return DynamicModel(ictk::lang::readIcm(text, "test.icm"));
}

} // namespace

// Thesis 5.1: the disk of radius 1 starts at (-2, 0) with velocity (1, 0); the rectangle's left
// side is x = 2. Its centre is at x = -2 + t, so the disk touches the side at t = 3 (F = (2, 0))
// and then cuts it in K, L = (2, -+sqrt(1 - d^2)) with d = 4 - t.
TEST(EngineExemplars, DiskRectangleInstancesAndTransitions)
{
  DynamicModel m = load("ch5_1_disk_rectangle.icm");
  EXPECT_EQ(m.timeRange().first, 0.0);
  EXPECT_EQ(m.timeRange().second, 10.0);
  std::vector<FrameRecord> rs = m.advanceTo(2.5, 0.5);
  ASSERT_FALSE(rs.empty());
  EXPECT_EQ(rs.front().instance, "K1");
  EXPECT_TRUE(rs.front().transition); // the initial instance
  EXPECT_EQ(m.activeInstance(), "K1");
  EXPECT_NEAR(real(m, "LHKF.translation.x"), 0.5, 1e-12); // -2 + 2.5

  // A coarse step (0.5 from 2.5 to 3.5) jumps over the tangency; the engine still finds K2.
  rs = m.advanceTo(3.5, 0.5);
  const FrameRecord* k2 = transitionTo(rs, "K2");
  const FrameRecord* k3 = transitionTo(rs, "K3");
  ASSERT_NE(k2, nullptr);
  ASSERT_NE(k3, nullptr);
  EXPECT_NEAR(k2->time, 3.0, 1e-6);
  EXPECT_NEAR(k3->time, 3.0, 1e-6);
  EXPECT_LE(k2->time, k3->time);
  EXPECT_EQ(rs.back().instance, "K3");
  EXPECT_FALSE(rs.back().transition);
  EXPECT_EQ(rs.back().time, 3.5);
  // isIntersection is the active instance's answer after its updatePost.
  ASSERT_FALSE(k2->state.empty());
  EXPECT_EQ(k2->state[0].first, "isIntersection");
  EXPECT_EQ(k2->state[0].second.toJson(), "true");
}

TEST(EngineExemplars, DiskRectangleTangencyPoint)
{
  DynamicModel m = load("ch5_1_disk_rectangle.icm");
  // Stop right at the tangency: K2's updatePost placed F on the rectangle's side.
  const auto rs = m.advanceTo(3.2, 0.4);
  const FrameRecord* k2 = transitionTo(rs, "K2");
  ASSERT_NE(k2, nullptr);
  // Re-run to that instant: the model is deterministic.
  DynamicModel again = load("ch5_1_disk_rectangle.icm");
  again.advanceTo(k2->time, 0.4);
  EXPECT_EQ(again.activeInstance(), "K2");
  const Value f = again.value("F_point.translation");
  EXPECT_NEAR(f.vec[0], 2.0, 1e-6);
  EXPECT_NEAR(f.vec[1], 0.0, 1e-3); // a tangency: the point is located to sqrt(tolerance)
  // K2's complex: the two cells and F, with F on the boundary of both.
  const auto cells = again.cells();
  ASSERT_EQ(cells.size(), 3u);
  EXPECT_EQ(cells[2].name, "F_point");
}

TEST(EngineExemplars, DiskRectangleHalfDisk)
{
  DynamicModel m = load("ch5_1_disk_rectangle.icm");
  // t = 4: the centre is on the side x = 2, so K = (2, -1), L = (2, 1), the chord is 2 long and
  // the half-disk KFL inside the rectangle has area pi / 2, its arc length pi.
  m.advanceTo(4.0, 0.25);
  EXPECT_EQ(m.activeInstance(), "K3");
  const Value k = m.value("K_point.translation"), l = m.value("L_point.translation");
  EXPECT_NEAR(k.vec[0], 2.0, 1e-9);
  EXPECT_NEAR(k.vec[1], -1.0, 1e-6);
  EXPECT_NEAR(l.vec[1], 1.0, 1e-6);
  const Value c = m.value("KL_segment.translation");
  EXPECT_NEAR(c.vec[0], 2.0, 1e-9);
  EXPECT_NEAR(c.vec[1], 0.0, 1e-6);
  ictk::geometry::QueryOptions q;
  for (const auto& cell : m.cells())
  {
    if (cell.name == "KFL_half_disk")
    {
      EXPECT_NEAR(ictk::geometry::measure(*cell.shape, q), pi / 2, 1e-6);
    }
  }

  // t = 3.5: d = 0.5, K, L = (2, -+sqrt(0.75)); the circular segment inside has area
  // acos(0.5) - 0.5 sqrt(0.75) = 0.6141848493.
  DynamicModel n = load("ch5_1_disk_rectangle.icm");
  n.advanceTo(3.5, 0.1);
  EXPECT_NEAR(n.value("L_point.translation").vec[1], std::sqrt(0.75), 1e-9);
  for (const auto& cell : n.cells())
  {
    if (cell.name == "KFL_half_disk")
    {
      EXPECT_NEAR(ictk::geometry::measure(*cell.shape, q), 0.6141848493, 1e-6);
    }
  }
}

// Thesis 5.2 (numbers in the model's header): O(t) = (0, 1.5 - t), the disk's centre (1, 4.5 - t).
TEST(EngineExemplars, DependencyFollowsAndInstances)
{
  DynamicModel m = load("ch5_2_dependency.icm");
  const auto rs = m.advanceTo(3.4, 0.1);
  // The disk follows the segment (hierarchical dependency) at every evaluated time.
  DynamicModel probe = load("ch5_2_dependency.icm");
  for (double t : { 0.3, 1.0, 2.0, 2.9, 3.4 })
  {
    probe.advanceTo(t, 0.1);
    const Value o = probe.value("OM.center"), d = probe.value("LHKF.center");
    EXPECT_NEAR(o.vec[1], 1.5 - t, 1e-12) << t;
    EXPECT_NEAR(d.vec[0], o.vec[0] + 1.0, 1e-12) << t;
    EXPECT_NEAR(d.vec[1], o.vec[1] + 3.0, 1e-12) << t;
  }
  std::vector<std::pair<std::string, double>> seq;
  for (const FrameRecord& r : rs)
    if (r.transition)
      seq.emplace_back(r.instance, r.time);
  ASSERT_EQ(seq.size(), 5u);
  EXPECT_EQ(seq[0].first, "K1");
  EXPECT_EQ(seq[1].first, "K2");
  EXPECT_NEAR(seq[1].second, 0.5, 1e-6);
  EXPECT_EQ(seq[2].first, "K3");
  EXPECT_NEAR(seq[2].second, 2.5, 1e-6);
  EXPECT_EQ(seq[3].first, "K4"); // the tangency at t = 3, an instant
  EXPECT_NEAR(seq[3].second, 3.0, 1e-6);
  EXPECT_EQ(seq[4].first, "K5");
  EXPECT_NEAR(seq[4].second, 3.0, 1e-6);
  // In K5 at t = 3.4 the segment meets the rectangle at (0, 1) and (0, -1); the order puts OM
  // before the disk it carries.
  const auto order = m.evaluationOrder();
  std::size_t om = 99, disk = 99;
  for (std::size_t i = 0; i < order.size(); ++i)
    for (const std::string& n : order[i])
    {
      if (n == "OM")
        om = i;
      if (n == "LHKF")
        disk = i;
    }
  EXPECT_LT(om, disk);
}

// Thesis 4.4.1: radius 0.5, B1 from x = -1.5 at speed 1, B2 at rest at x = 0; they touch when the
// centres are 1 apart, at t = 0.5; the velocities swap, B1 rests at x = -1 and B2 moves on.
TEST(EngineExemplars, NewtonsCradleSwapsVelocities)
{
  DynamicModel m = load("newtons_cradle.icm");
  const auto rs = m.advanceTo(1.0, 0.1);
  const FrameRecord* contact = transitionTo(rs, "CONTACT");
  ASSERT_NE(contact, nullptr);
  EXPECT_NEAR(contact->time, 0.5, 1e-6);
  ASSERT_EQ(contact->events.size(), 1u);
  EXPECT_EQ(contact->events[0], "COLLISION");
  EXPECT_EQ(m.activeInstance(), "APART");
  EXPECT_NEAR(real(m, "B1.v"), 0.0, 1e-12);
  EXPECT_NEAR(real(m, "B2.v"), 1.0, 1e-12);
  EXPECT_NEAR(real(m, "B1.translation.x"), -1.0, 1e-6);
  EXPECT_NEAR(real(m, "B2.translation.x"), 0.5, 1e-6);
  EXPECT_EQ(m.value("collisions").number, 1.0);
}

// Thesis 5.6 with the model's numbers: alpha(t) = 12 - 2t, hook at y = -0.6 - 0.4t, contact with
// the liquid at t = 3, the shell under the surface at t = 6.346875, then ANDY_OUT.
TEST(EngineExemplars, AndyhausenChainOrderAndInstances)
{
  DynamicModel m = load("andyhausen.icm");
  auto rs = m.advanceTo(1.0, 0.1);
  EXPECT_EQ(m.activeInstance(), "EGG_GOING_DOWN");
  // The bidirectional dependency keeps the handles together and the chain follows.
  EXPECT_NEAR(real(m, "Handle1.alpha"), 10.0, 1e-9);
  EXPECT_NEAR(real(m, "Handle2.alpha"), 10.0, 1e-9);
  EXPECT_NEAR(real(m, "Barrel.alpha"), 10.0, 1e-9);
  EXPECT_NEAR(real(m, "Rope.inactiveLength"), 2.0, 1e-9);
  EXPECT_NEAR(m.value("Hook.translation").vec[1], -1.0, 1e-9);
  EXPECT_NEAR(m.value("Eggshell.center").vec[1], -1.7, 1e-9);
  // Footnote 27: Handle1, Barrel, Handle2, then Handle1 again (the cut relation re-evaluated),
  // in the last frame (after the instance's own update, which drives the handle).
  const auto& log = m.log();
  const auto frame = std::find(log.rbegin(), log.rend(), "EGG_GOING_DOWN.update").base();
  std::vector<std::string> order;
  for (auto it = frame; it != log.end(); ++it)
  {
    const bool chain = it->rfind("Handle", 0) == 0 || it->rfind("Barrel", 0) == 0;
    const bool update = it->size() > 7 && it->compare(it->size() - 7, 7, ".update") == 0;
    if (chain && (update || it->find(".reevaluate") != std::string::npos))
      order.push_back(*it);
  }
  const std::vector<std::string> expected = { "Handle1.update", "Barrel.update", "Handle2.update",
    "Handle1.reevaluate" };
  EXPECT_EQ(order, expected);

  rs = m.advanceTo(8.0, 0.25);
  const FrameRecord* eroding = transitionTo(rs, "EGG_ERODING");
  const FrameRecord* out = transitionTo(rs, "ANDY_OUT");
  ASSERT_NE(eroding, nullptr);
  ASSERT_NE(out, nullptr);
  EXPECT_NEAR(eroding->time, 3.0, 1e-6);
  EXPECT_NEAR(out->time, 6.346875, 1e-5);
  EXPECT_EQ(m.activeInstance(), "ANDY_OUT");
}

// The whole film, 0..20 at 0.2 (issue 16: it stopped at t = 10.346875 with no valid instance,
// ANDY_OUT's predicate being `localT < animationDuration("skeletonAnim")` with a 4 s animation).
// The skeleton's animation now lasts 14 s (reach out in 4, pull out in 10 more), so ANDY_OUT
// holds to the end: at t = 20 its local time is 20 - 6.346875 = 13.653125 and the skeleton,
// 2 units up in the last 10 s, is at y = 0.5 + 2 x 9.653125 / 10 = 2.430625 in the hook's frame.
TEST(EngineExemplars, AndyhausenRunsItsWholeFilm)
{
  // At the README's step (`ictk run` without --frames: the film in 100 steps, 0.2) and at 0.05.
  for (const int steps : { 100, 400 })
  {
    SCOPED_TRACE(std::to_string(steps) + " steps");
    const double dt = 20.0 / steps;
    DynamicModel m = load("andyhausen.icm");
    EXPECT_EQ(m.timeRange(), std::make_pair(0.0, 20.0));
    std::vector<std::string> instances;
    std::vector<double> transitions;
    std::size_t frames = 0;
    for (int k = 0; k <= steps; ++k)
    {
      for (const FrameRecord& r : m.advanceTo(dt * k, dt))
      {
        if (instances.empty() || instances.back() != r.instance)
          instances.push_back(r.instance);
        if (r.transition && r.time > 0)
          transitions.push_back(r.time);
        frames += r.transition ? 0 : 1;
      }
    }
    EXPECT_EQ(m.time(), 20.0);
    EXPECT_EQ(frames, static_cast<std::size_t>(steps)); // t = 0 is the start record, a transition
    EXPECT_EQ(instances, (std::vector<std::string>{ "EGG_GOING_DOWN", "EGG_ERODING", "ANDY_OUT" }));
    ASSERT_EQ(transitions.size(), 2u);
    EXPECT_NEAR(transitions[0], 3.0, 1e-6);
    EXPECT_NEAR(transitions[1], 6.346875, 1e-5);
    EXPECT_EQ(m.activeInstance(), "ANDY_OUT");
    EXPECT_NEAR(real(m, "Skeleton.translation.y"), 2.430625, 1e-4);
    EXPECT_NEAR(real(m, "Skeleton.height"), 2.430625, 1e-4);
  }
}

// ANDY_OUT's character (issue 17): BCN_Epileptic on the hook, scaled 0.75 and climbing with
// skeletonAnim; her left hand takes Handle2 and turns it, and the handles turn together through
// the bidirectional dependency. By hand: in ANDY_OUT the handles rest at alpha = 12 - 2 x
// 6.346875 = -0.69375 and the hook at y = -0.6 - 0.4 x 6.346875 = -3.13875. After 3.3 s of the
// instance the skeleton is in its bind pose, where the hand is at 0.75 (0.218128, -0.0719957,
// -0.136143) from the skeleton's origin; the skeleton is moved by (0.7 - 0.75 x 0.218128, k,
// 0.75 x 0.136143) from the hook, so the hand is at (0.7, -3.13875 + k - 0.0539968, 0), under
// Handle2's centre (0.7, -1.2, 0). It takes the handle 0.3 from it, at y = -1.5: k = 1.6927468,
// which skeletonAnim (0.5 at 4 s, +0.2 a second after) reaches at 4 + 1.1927468 / 0.2 =
// 9.963734 s into ANDY_OUT, t = 16.310609. Before that the handles do not move; after it they
// turn at the hand's rate, 1 a second, from the step the hand takes the handle (at most dt later).
TEST(EngineExemplars, AndyhausensAndyTakesTheSecondHandleAndTurnsBoth)
{
  if (!std::ifstream("/usr/share/assimp/models/X/BCN_Epileptic.X"))
    GTEST_SKIP() << "Debian's assimp-testmodels is not installed";
  DynamicModel m = load("andyhausen.icm");
  const double dt = 0.1, switchT = 6.346875, reachT = 16.310609;
  const double restAngle = 12 - 2 * switchT;
  double takenAt = -1;
  for (int k = 1; k <= 200; ++k)
  {
    const double t = dt * k;
    m.advanceTo(t, dt);
    if (t < switchT)
      continue;
    ASSERT_EQ(m.activeInstance(), "ANDY_OUT") << "t = " << t;
    const bool holding = m.value("Andy.holding").number != 0;
    if (t < reachT)
    {
      EXPECT_FALSE(holding) << "t = " << t;
      EXPECT_NEAR(real(m, "Handle2.alpha"), restAngle, 1e-6) << "t = " << t;
      EXPECT_NEAR(real(m, "Handle1.alpha"), restAngle, 1e-6) << "t = " << t;
      continue;
    }
    if (!holding)
    {
      EXPECT_LT(t, reachT + dt) << "the hand has not taken the handle";
      continue;
    }
    if (takenAt < 0)
      takenAt = switchT + real(m, "Andy.reachT");
    // From the step the hand took it, the handle turns at 1 a second, and Handle1 with it.
    const double angle = restAngle + (t - takenAt);
    EXPECT_NEAR(real(m, "Handle2.alpha"), angle, 1e-6) << "t = " << t;
    EXPECT_NEAR(real(m, "Handle1.alpha"), angle, 1e-6) << "t = " << t;
  }
  std::printf("Andy takes Handle2 at t = %.6f; Handle1.alpha %.6f at t = 20\n", takenAt,
    real(m, "Handle1.alpha"));
  EXPECT_GE(takenAt, reachT - 1e-4);
  EXPECT_LT(takenAt, reachT + dt + 1e-4);
  // The last step, t = 20: turned by 20 - takenAt (3.6 to 3.7) since the hand took it.
  EXPECT_GT(real(m, "Handle1.alpha"), restAngle + 3.5);
}

// Without the character's file the model is refused at load, naming the file at the place (line
// and column) of the first call that reads it.
TEST(EngineExemplars, AndyhausenWithoutItsCharacterFileIsRefusedNamingIt)
{
  std::ifstream in(models + "andyhausen.icm");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string file = "/usr/share/assimp/models/X/BCN_Epileptic.X";
  const std::string missing = "/usr/share/assimp/models/X/BCN_Missing.X";
  const std::size_t first = text.find(file);
  ASSERT_NE(first, std::string::npos);
  const auto line =
    1 + std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(first), '\n');
  const auto column = first - text.rfind('\n', first); // 1-based, at the string's quote
  for (std::size_t at = first; at != std::string::npos; at = text.find(file, at))
    text.replace(at, file.size(), missing);
  const std::string path = ::testing::TempDir() + "andyhausen_missing.icm";
  std::ofstream(path) << text;
  try
  {
    DynamicModel::load(path);
    ADD_FAILURE() << "loaded without " << missing;
  }
  catch (const std::exception& e)
  {
    const std::string what = e.what();
    EXPECT_NE(what.find(missing), std::string::npos) << what;
    EXPECT_NE(what.find("andyhausen_missing.icm:" + std::to_string(line) + ":" +
                std::to_string(column - 1)),
      std::string::npos)
      << what;
  }
}

namespace
{

std::optional<ictk::engine::CellState> cellNamed(const DynamicModel& m, const std::string& name)
{
  for (const ictk::engine::CellState& c : m.cells())
    if (c.name == name)
      return c;
  return std::nullopt;
}

/// The centroid of {value >= 0} of a 3D shape, from the centres of an n^3 grid over its world box.
ictk::geometry::Vec3 sampledCentroid(const ictk::geometry::PlacedShape& shape, int n)
{
  const ictk::frep::Box3 b = shape.worldBounds();
  ictk::geometry::Vec3 sum{ 0, 0, 0 };
  double count = 0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k)
      {
        const ictk::geometry::Vec3 p{ b.lo[0] + (i + 0.5) * (b.hi[0] - b.lo[0]) / n,
          b.lo[1] + (j + 0.5) * (b.hi[1] - b.lo[1]) / n,
          b.lo[2] + (k + 0.5) * (b.hi[2] - b.lo[2]) / n };
        if (shape.value(p) >= 0)
        {
          for (int d = 0; d < 3; ++d)
            sum[d] += p[d];
          count += 1;
        }
      }
  EXPECT_GT(count, 0) << shape.cell;
  return { sum[0] / count, sum[1] / count, sum[2] / count };
}

} // namespace

// Issue 16: the egg contents stay in the egg when their parent changes. EGG_ERODING carries
// Egg_contents by Eggshell (HIERARCHICAL); ANDY_OUT, from t = 6.346875, drops that relation and
// the shell. The contents then kept only their own transform, the identity, and jumped to the
// origin. A cell whose hierarchical parent changes now keeps its place in the world: the
// contents stay where the shell left them, centred 0.7 below the hook of the switch,
// y = -0.6 - 0.4 x 6.346875 - 0.7 = -3.83875.
TEST(EngineExemplars, AndyhausenEggContentsStayInTheEgg)
{
  DynamicModel m = load("andyhausen.icm");
  m.advanceTo(6.0, 0.25);
  std::optional<ictk::frep::Box3> egg;
  std::string lastInstance;
  int framesOut = 0;
  for (int k = 1; k <= 20; ++k) // 6.05 .. 7.0
  {
    const double t = 6.0 + 0.05 * k;
    m.advanceTo(t, 0.05);
    if (const auto shell = cellNamed(m, "Eggshell"))
    {
      egg = shell->shape->worldBounds();
      // The shell's centre is 0.7 below the hook (hook at y = -0.6 - 0.4 t).
      EXPECT_NEAR(0.5 * (egg->lo[1] + egg->hi[1]), -1.3 - 0.4 * t, 1e-9) << "t = " << t;
    }
    ASSERT_TRUE(egg.has_value());
    const auto contents = cellNamed(m, "Egg_contents");
    ASSERT_TRUE(contents.has_value()) << "t = " << t;
    const ictk::geometry::Vec3 c = sampledCentroid(*contents->shape, 24);
    for (int d = 0; d < 3; ++d)
    {
      EXPECT_GE(c[d], egg->lo[d]) << "t = " << t << " axis " << d;
      EXPECT_LE(c[d], egg->hi[d]) << "t = " << t << " axis " << d;
    }
    // The contents are symmetric about their centre: the sampled centroid is the centre to a
    // fraction of a grid cell (1.2 / 24 = 0.05 along y).
    const double centre = t < 6.346875 ? -1.3 - 0.4 * t : -3.83875;
    EXPECT_NEAR(c[1], centre, 0.01) << "t = " << t;
    EXPECT_NEAR(c[0], 0.0, 0.01) << "t = " << t;
    EXPECT_NEAR(c[2], 0.0, 0.01) << "t = " << t;
    if (m.activeInstance() == "ANDY_OUT")
    {
      ++framesOut;
      EXPECT_NEAR(contents->shape->place.apply({ 0, 0, 0 })[1], -3.83875, 1e-5) << "t = " << t;
    }
    lastInstance = m.activeInstance();
  }
  EXPECT_EQ(lastInstance, "ANDY_OUT");
  EXPECT_EQ(framesOut, 14); // 6.35 .. 7.0
}

TEST(EngineExemplars, AndyhausenRopeFollowsTheBarrel)
{
  // The rope's hanging segment is segment(0, (0, -curLength, 0)) with curLength = 3 - 0.2 alpha =
  // 0.6 + 0.4 t while the handle turns (alpha = 12 - 2t): its end is where the hook hangs.
  DynamicModel m = load("andyhausen.icm");
  for (const double t : { 0.0, 1.0, 2.5, 5.0 })
  {
    m.advanceTo(t, 0.25);
    const double length = real(m, "Rope.curLength");
    EXPECT_NEAR(length, 0.6 + 0.4 * t, 1e-9) << "t = " << t;
    bool found = false;
    for (const ictk::engine::CellState& c : m.cells())
    {
      if (c.name != "Rope")
        continue;
      found = true;
      ASSERT_EQ(c.shape->parts.size(), 2u);
      const auto& segment = c.shape->parts[0];
      ASSERT_EQ(segment.points.size(), 2u);
      const auto end = c.shape->place.apply(segment.points[1]);
      EXPECT_NEAR(segment.points[1][1], -length, 1e-12) << "t = " << t;
      EXPECT_NEAR(end[1], real(m, "Hook.translation.y"), 1e-9) << "t = " << t;
    }
    EXPECT_TRUE(found) << "t = " << t;
  }
}

TEST(EngineExemplars, AndyhausenMeltingEggFollowsItsBlendRate)
{
  // Melting_egg = blend(Liquid, Egg_contents, 0.5 * blendRate), blendRate = clamp(lifeT / 5, 0, 1)
  // (thesis L3636-L3659): from the instance EGG_ERODING on, the blend grows from a plain union to
  // an amount of 0.5 over the cell's first five seconds, step by step.
  DynamicModel m = load("andyhausen.icm");
  std::vector<double> amounts;
  for (int k = 0; k <= 100; ++k)
  {
    m.advanceTo(0.2 * k, 0.2);
    for (const ictk::engine::CellState& c : m.cells())
    {
      if (c.name != "Melting_egg")
        continue;
      ASSERT_EQ(c.shape->parts.size(), 1u);
      const double rate = real(m, "Melting_egg.blendRate");
      EXPECT_GE(rate, 0.0);
      EXPECT_LE(rate, 1.0);
      EXPECT_DOUBLE_EQ(c.shape->parts[0].amount, 0.5 * rate) << "t = " << m.time();
      amounts.push_back(c.shape->parts[0].amount);
    }
  }
  ASSERT_GE(amounts.size(), 30u);
  EXPECT_LT(amounts.front(), 0.05);
  EXPECT_DOUBLE_EQ(amounts.back(), 0.5);
  EXPECT_TRUE(std::is_sorted(amounts.begin(), amounts.end()));
}

// Thesis L3627-L3633: the liquid's noise changes its phase with time. Its field is
// (-3.2 - y + 0.02 sin(2t) sin(8x) sin(8z)) & (4 - x^2 - z^2) with the phase 2t set by its update
// (setShapeParameter), so at a point the field moves between two times as the formula says, and at
// t = k pi / 2 (phase k pi) the surface is flat again: a point on the level y = -3.2 is on it.
TEST(EngineExemplars, AndyhausenLiquidNoisePhaseFollowsTime)
{
  DynamicModel m = load("andyhausen.icm");
  const ictk::geometry::Vec3 p{ 0.3, -3.2, -0.15 }, q{ 1.1, -3.25, 0.7 };
  auto formula = [](const ictk::geometry::Vec3& x, double t)
  {
    // HyperFun's & is the R-function intersection f + g - sqrt(f^2 + g^2).
    const double f = -3.2 - x[1] + 0.02 * std::sin(2 * t) * std::sin(8 * x[0]) * std::sin(8 * x[2]);
    const double g = 4 - x[0] * x[0] - x[2] * x[2];
    return f + g - std::sqrt(f * f + g * g);
  };
  std::vector<double> values;
  for (const double t : { 0.5, 1.25, pi / 2, 4.0, 9.0 })
  {
    m.advanceTo(t, 0.25);
    EXPECT_NEAR(real(m, "Liquid.noisePhase"), 2 * t, 1e-12);
    bool found = false;
    for (const ictk::engine::CellState& c : m.cells())
    {
      if (c.name != "Liquid")
        continue;
      found = true;
      EXPECT_NEAR(c.shape->value(p), formula(p, t), 1e-9) << "t = " << t;
      EXPECT_NEAR(c.shape->value(q), formula(q, t), 1e-9) << "t = " << t;
      values.push_back(c.shape->value(p));
    }
    ASSERT_TRUE(found) << "t = " << t;
  }
  // p is on the rest level: there the ripple 0.02 sin(2t) sin(2.4) sin(-1.2) (-0.0106 at t = 0.5,
  // -0.0075 at 1.25, 0 at pi / 2) is the first operand.
  EXPECT_LT(values[0], -0.01);
  EXPECT_GT(values[1], values[0] + 0.0025);
  EXPECT_NEAR(values[2], 0.0, 1e-9);
}

TEST(EngineExemplars, Deterministic)
{
  auto run = []
  {
    DynamicModel m = load("andyhausen.icm");
    std::string trace;
    for (const FrameRecord& r : m.advanceTo(7.0, 0.5))
    {
      trace += r.instance + "@" + std::to_string(r.time);
      for (const auto& [n, v] : r.state)
        trace += " " + n + "=" + v.toJson();
      trace += "\n";
    }
    return trace;
  };
  EXPECT_EQ(run(), run());
}

TEST(EngineErrors, NoValidInstanceNamesTheTime)
{
  const std::string text = "CELLS { A { type = F-CELL; shape = disk(1); dim = 2D;\n"
                           "  parameters { v : REAL(1); }\n"
                           "  REACTIONS { update(REAL g, REAL l, REAL f, REAL dt) { "
                           "translation.x += v * dt; } } } }\n"
                           "K : TEMPLATE_IC { CELLS { A; } }\n"
                           "ONE : K { PREDICATE { bool evaluate(REAL g, REAL l, REAL dt) { "
                           "return A.translation.x < 1.0; } } }\n";
  DynamicModel m = fromText(text);
  try
  {
    m.advanceTo(2.0, 0.5);
    FAIL() << "expected a ModelError";
  }
  catch (const ModelError& e)
  {
    const std::string what = e.what();
    EXPECT_NE(what.find("no instance is valid"), std::string::npos) << what;
    EXPECT_NE(what.find("t = 1.0"), std::string::npos) << what;
  }
}

TEST(EngineErrors, RuntimeErrorsHaveThePlace)
{
  // Line 3, column 60: the division makes x NaN.
  const std::string text = "CELLS { A { type = F-CELL; shape = disk(1); dim = 2D;\n"
                           "  parameters { x : REAL(0); }\n"
                           "  REACTIONS { update(REAL g, REAL l, REAL f, REAL dt) { x = 0.0 / "
                           "0.0; } } } }\n"
                           "K : TEMPLATE_IC { CELLS { A; } }\nONE : K { }\n";
  DynamicModel m = fromText(text);
  try
  {
    m.advanceTo(1.0, 0.5);
    FAIL() << "expected a ModelError";
  }
  catch (const ModelError& e)
  {
    EXPECT_EQ(e.file, "test.icm");
    EXPECT_EQ(e.pos.line, 3);
    EXPECT_NE(std::string(e.what()).find("NaN"), std::string::npos) << e.what();
  }
}

// The imperative core through a model: a function, a bounded loop, relative assignment on
// vectors and components, if/else, integer and real arithmetic, animation curves.
TEST(EngineInterpreter, CoreConstructs)
{
  const std::string text =
    "ANIMATIONS { ramp { keys = { 0, 0 }, { 2, 4 }; }\n"
    "  path { keys = { 0, 0, 0, 0 }, { 1, 1, 2, 3 }; } }\n"
    "function sumTo(int n) { int s = 0; for i in 0..n { s += i; } "
    "return s; }\n"
    "STATE_PARAMETERS { total : INT(0); ratio : REAL(0); w : VECTOR3(1, 2, 3); "
    "flag : BOOL(false); }\n"
    "CELLS { A { type = F-CELL; shape = disk(1); dim = 2D; } }\n"
    "K : TEMPLATE_IC { CELLS { A; } }\n"
    "ONE : K { REACTIONS { update(REAL g, REAL l, REAL f, REAL dt) {\n"
    "  total = sumTo(5);\n"                     // 0+1+2+3+4 = 10
    "  ratio = 7 / 2;\n"                        // real division: 3.5
    "  w *= 2; w.y += 1; w -= vec3(1, 1, 1);\n" // (2,4,6) -> (2,5,6) -> (1,4,5)
    "  if (length(w) > 6.0) { flag = true; } else { flag = false; }\n"
    "  A.translation = animation(\"path\", 0.5) + vec3(0, 0, animationValue(\"ramp\", 1));\n"
    "} } }\n";
  DynamicModel m = fromText(text);
  m.advanceTo(0.1, 0.1);
  EXPECT_EQ(m.value("total").number, 10.0);
  EXPECT_EQ(m.value("total").type, Value::Type::Int);
  EXPECT_EQ(m.value("ratio").number, 3.5);
  const Value w = m.value("w");
  // Two frames ran (settle at 0 and the step to 0.1): (1,2,3) -> (1,4,5) -> (1,8,9).
  EXPECT_EQ(w.vec[0], 1.0);
  EXPECT_EQ(w.vec[1], 8.0);
  EXPECT_EQ(w.vec[2], 9.0);
  EXPECT_EQ(m.value("flag").toJson(), "true"); // |(1,8,9)| = 12.08 > 6
  // path at 0.5: (0.5, 1, 1.5); ramp at 1: 2.
  const Value t = m.value("A.translation");
  EXPECT_DOUBLE_EQ(t.vec[0], 0.5);
  EXPECT_DOUBLE_EQ(t.vec[1], 1.0);
  EXPECT_DOUBLE_EQ(t.vec[2], 3.5);
}

// A loop bound the model sets (a user number that sets the work) is refused before the loop
// runs, with the limit, at the loop's place.
TEST(EngineInterpreter, LoopBoundOverTheLimitIsRefused)
{
  const std::string text =
    "function count(int n) { int s = 0; for i in 0..n { s += 1; } return s; }\n"
    "STATE_PARAMETERS { total : INT(0); }\n"
    "CELLS { A { type = F-CELL; shape = disk(1); dim = 2D; } }\n"
    "K : TEMPLATE_IC { CELLS { A; } }\n"
    "ONE : K { REACTIONS { update(REAL g, REAL l, REAL f, REAL dt) {\n"
    "  total = count(100000000);\n"
    "} } }\n";
  try
  {
    DynamicModel m = fromText(text);
    m.advanceTo(0.1, 0.1);
    ADD_FAILURE() << "a loop of 1e8 iterations ran";
  }
  catch (const ModelError& e)
  {
    EXPECT_EQ(e.pos.line, 1);
    EXPECT_NE(std::string(e.what()).find("the loop would run more than 10000000 iterations in one "
                                         "reaction"),
      std::string::npos)
      << e.what();
  }
}

TEST(EngineInterpreter, TypeErrorsAtRunTime)
{
  // A BOOL state parameter assigned a number: caught where it happens (line 4).
  const std::string text =
    "STATE_PARAMETERS { flag : BOOL(false); }\n"
    "CELLS { A { type = F-CELL; shape = disk(1); dim = 2D; } }\n"
    "K : TEMPLATE_IC { CELLS { A; } }\n"
    "ONE : K { REACTIONS { update(REAL g, REAL l, REAL f, REAL dt) { flag = g; } } }\n";
  DynamicModel m = fromText(text);
  try
  {
    m.advanceTo(1.0, 0.5);
    FAIL() << "expected a ModelError";
  }
  catch (const ModelError& e)
  {
    EXPECT_EQ(e.pos.line, 4);
    EXPECT_NE(std::string(e.what()).find("flag is a bool"), std::string::npos) << e.what();
  }
}

// The complex of the active instance: its cells with their dimensions and the instance's
// boundary and containment relations (thesis 5.1 K3; 5.6 EGG_GOING_DOWN).
TEST(EngineComplex, RelationsOfTheActiveInstance)
{
  DynamicModel m = load("ch5_1_disk_rectangle.icm");
  m.advanceTo(4.0, 0.5);
  const ictk::complex::Complex c = m.complex();
  const auto cells = m.cells();
  // DEQS, LHKF, then K3's T-cells: half-disk (2D), arc, chord (1D), K, L (0D).
  ASSERT_EQ(cells.size(), 7u);
  EXPECT_EQ(c.cellsOfDimension(2).size(), 3u);
  EXPECT_EQ(c.cellsOfDimension(1).size(), 2u);
  EXPECT_EQ(c.cellsOfDimension(0).size(), 2u);
  // K3 declares six boundary pairs: the chord and the arc bound the half-disk, K and L bound both.
  EXPECT_EQ(c.boundaryPairCount(), 6u);
  auto id = [&](const std::string& n)
  {
    for (std::size_t i = 0; i < cells.size(); ++i)
      if (cells[i].name == n)
        return static_cast<ictk::complex::CellId>(i);
    ADD_FAILURE() << n;
    return ictk::complex::CellId(0);
  };
  EXPECT_TRUE(c.hasBoundary(id("KFL_half_disk"), id("KL_segment")));
  EXPECT_TRUE(c.hasBoundary(id("KL_segment"), id("K_point")));

  DynamicModel egg = load("andyhausen.icm");
  egg.advanceTo(1.0, 0.5);
  const ictk::complex::Complex e = egg.complex();
  const auto ecells = egg.cells();
  auto eid = [&](const std::string& n)
  {
    for (std::size_t i = 0; i < ecells.size(); ++i)
      if (ecells[i].name == n)
        return static_cast<ictk::complex::CellId>(i);
    ADD_FAILURE() << n;
    return ictk::complex::CellId(0);
  };
  EXPECT_TRUE(e.hasContainment(eid("Eggshell"), eid("Egg_contents")));
  EXPECT_TRUE(e.hasBoundary(eid("Eggshell"), eid("Hook")));
  // Cells of every dimension coexist: the hook 0D, the rope 1D, the egg 3D.
  EXPECT_EQ(e.cell(eid("Hook")).dimension, 0);
  EXPECT_EQ(e.cell(eid("Rope")).dimension, 1);
  EXPECT_EQ(e.cell(eid("Eggshell")).dimension, 3);
}

// TIME_REJECTED from the language (thesis L2075): a reaction that accepts steps of at most 0.1
// makes the engine retry a 0.5 step with 0.1 from the last accepted time, so the count of
// accepted frames reaching t = 1 is 10 (plus the settling frame at t = 0, which has dt = 0).
TEST(EngineEvents, TimeRejectedFromAReaction)
{
  const std::string text = "STATE_PARAMETERS { frames : INT(0); }\n"
                           "CELLS { A { type = F-CELL; shape = disk(1); dim = 2D; } }\n"
                           "K : TEMPLATE_IC { CELLS { A; } }\n"
                           "ONE : K { REACTIONS { update(REAL g, REAL l, REAL f, REAL dt) {\n"
                           "  if (dt > 0.1000001) { fireEvent(TIME_REJECTED, 0.1); }\n"
                           "  frames += 1;\n"
                           "} } }\n";
  DynamicModel m = fromText(text);
  const auto rs = m.advanceTo(1.0, 0.5);
  EXPECT_EQ(m.value("frames").number, 11.0);
  // The records are the requested times (0, 0.5, 1), not the sub-steps.
  ASSERT_EQ(rs.size(), 3u);
  EXPECT_EQ(rs[1].time, 0.5);
  EXPECT_EQ(rs[2].time, 1.0);
}

// Thesis 5.6: the egg contents' attribute (a HyperFun density, 1 at the yolk's centre, 0.3 in
// the white) is bound to the cell and follows it: at t = 1 the contents' centre is at
// (0, -1.7, 0), so the density there is 1 and 0.4 above it is 0.3 + 0.7 exp(-8) = 0.300235.
TEST(EngineComplex, AttributesFollowTheirCell)
{
  DynamicModel m = load("andyhausen.icm");
  m.advanceTo(1.0, 0.5);
  const ictk::complex::Complex c = m.complex();
  const auto cells = m.cells();
  std::size_t contents = cells.size();
  for (std::size_t i = 0; i < cells.size(); ++i)
    if (cells[i].name == "Egg_contents")
      contents = i;
  ASSERT_LT(contents, cells.size());
  const auto& cell = c.cell(static_cast<ictk::complex::CellId>(contents));
  ASSERT_EQ(cell.attributes.size(), 1u);
  EXPECT_EQ(cell.attributes[0].attribute, "eggContentsAttr");
  auto eval = cell.attributes[0].function->components[0]->evaluator();
  double x[2] = { 0.0, 0.0 }, y[2] = { -1.7, -1.3 }, z[2] = { 0.0, 0.0 }, v[2];
  eval->values(x, y, z, v, 2);
  EXPECT_NEAR(v[0], 1.0, 1e-12);
  EXPECT_NEAR(v[1], 0.3 + 0.7 * std::exp(-8.0), 1e-12);
  // The external mapping of the liquid is named but has no function: not bound.
  for (std::size_t i = 0; i < cells.size(); ++i)
    if (cells[i].name == "Liquid")
    {
      EXPECT_TRUE(c.cell(static_cast<ictk::complex::CellId>(i)).attributes.empty());
    }
}

// Frames requested at i x 0.1 (0.30000000000000004, 0.6000000000000001, ...) with steps of 0.1
// give one record each: no extra frame for a rounding remainder.
TEST(EngineExemplars, OneRecordPerRequestedFrame)
{
  DynamicModel m = load("ch5_1_disk_rectangle.icm");
  std::size_t records = 0;
  for (int i = 1; i <= 20; ++i)
    for (const FrameRecord& r : m.advanceTo(i * 0.1, 0.1))
      records += r.transition ? 0 : 1;
  EXPECT_EQ(records, 20u);
}

// One table of built-ins (Lang/IcmBuiltins.h): the engine implements every entry once, in the
// layer the entry names, and nothing else; likewise every shape constructor.
TEST(EngineBuiltins, EveryEntryHasOneImplementation)
{
  const std::vector<std::string> problems = ictk::engine::implementationProblems();
  std::string all;
  for (const std::string& p : problems)
    all += p + "\n";
  EXPECT_TRUE(problems.empty()) << all;
  EXPECT_EQ(ictk::engine::interpreterBuiltins().size() + ictk::engine::libraryBuiltins().size(),
    ictk::lang::icm::builtins().size());
  EXPECT_EQ(ictk::engine::shapeConstructors().size(), ictk::lang::icm::shapeBuiltins().size());
}

namespace
{

/// The rows of docs/icm.md's table after the line that starts with `marker`, up to the first line
/// that is not a row, header excluded; nullopt when there is no such marker.
std::optional<std::string> icmDocTable(const std::string& marker)
{
  std::ifstream in(std::string(ICTK_DATA_DIR) + "/../docs/icm.md");
  std::string line, rows;
  bool found = false, table = false;
  while (std::getline(in, line))
  {
    if (!found)
    {
      found = line.rfind(marker, 0) == 0;
      continue;
    }
    if (line.rfind("|---", 0) == 0)
    {
      table = true;
      continue;
    }
    if (!table)
      continue;
    if (line.rfind("|", 0) != 0)
      break;
    rows += line + "\n";
  }
  if (!found)
    return std::nullopt;
  return rows;
}

} // namespace

// docs/icm.md's tables of built-ins and of shape constructors are the tables' renderings
// (builtinsMarkdown, shapeBuiltinsMarkdown).
TEST(Docs, IcmBuiltins)
{
  ASSERT_TRUE(std::ifstream(std::string(ICTK_DATA_DIR) + "/../docs/icm.md")) << "docs/icm.md";
  const std::optional<std::string> builtins = icmDocTable("<!-- builtins");
  ASSERT_TRUE(builtins) << "docs/icm.md has no <!-- builtins marker";
  EXPECT_EQ(*builtins, ictk::lang::icm::builtinsMarkdown())
    << "docs/icm.md's built-ins differ from Lang/IcmBuiltins.cxx; the table's rows should be:\n"
    << ictk::lang::icm::builtinsMarkdown();
  const std::optional<std::string> shapes = icmDocTable("<!-- shapes");
  ASSERT_TRUE(shapes) << "docs/icm.md has no <!-- shapes marker";
  EXPECT_EQ(*shapes, ictk::lang::icm::shapeBuiltinsMarkdown())
    << "docs/icm.md's shape constructors differ from Lang/IcmBuiltins.cxx; the table's rows "
       "should be:\n"
    << ictk::lang::icm::shapeBuiltinsMarkdown();
}

// An instance's cells are its template's minus the removed plus the added, in the template's order
// then the added ones' (thesis L1459, I_j = TI \ {...} U {...}).
TEST(EngineInstances, CellsDeriveFromTheTemplate)
{
  // EGG_GOING_DOWN = TEMPLATE_IC1.CELLS \ { Melting_egg } + Eggshell (App. C).
  DynamicModel m = load("andyhausen.icm");
  m.start();
  std::vector<std::string> names;
  for (const auto& c : m.cells())
    names.push_back(c.name);
  const std::vector<std::string> expected = { "Handle1", "Handle2", "Barrel", "Rope", "Hook",
    "Egg_contents", "Egg_yolk", "Egg_white", "Liquid", "Eggshell" };
  EXPECT_EQ(names, expected);

  DynamicModel d = fromText("CELLS { A { shape = disk(1); dim = 2D; }\n"
                            "  B { shape = disk(2); dim = 2D; }\n"
                            "  C { shape = disk(3); dim = 2D; } }\n"
                            "T : TEMPLATE_IC { CELLS { A B; } }\n"
                            "I { CELLS { USE T.CELLS \\ { A } U { C }; } }\n");
  d.start();
  names.clear();
  for (const auto& c : d.cells())
    names.push_back(c.name);
  EXPECT_EQ(names, (std::vector<std::string>{ "B", "C" }));
}

// Exactly one instance is valid at a time (L1394-1396): two valid ones are an error naming both.
TEST(EngineErrors, SeveralValidInstancesAreNamed)
{
  const std::string text = "CELLS { A { shape = disk(1); dim = 2D; } }\n"
                           "K : TEMPLATE_IC { CELLS { A; } }\n"
                           "ONE : K { }\n"
                           "TWO : K { PREDICATE { bool evaluate(REAL g, REAL l, REAL dt) { "
                           "return A.translation.x < 1.0; } } }\n";
  DynamicModel m = fromText(text);
  try
  {
    m.start();
    FAIL() << "expected a ModelError";
  }
  catch (const ModelError& e)
  {
    const std::string what = e.what();
    EXPECT_NE(what.find("several instances are valid: ONE, TWO"), std::string::npos) << what;
  }
}
