// SPDX-License-Identifier: BSD-3-Clause
// Skinned meshes (issue 17): linear blend skinning against hand-derived positions and normals,
// and the reader on the characters Debian's assimp-testmodels installs (read where the package
// puts them, never copied): glTF2/simple_skin (2 joints, small enough to skin by hand) and
// X/BCN_Epileptic.X (a humanoid, 54 bones, one animation).

#include "Skin/SkinFile.h"
#include "Skin/SkinnedMesh.h"
#include "Skin/StandIn.h"

#include "FRep/Evaluators.h"
#include "FRep/Tape.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

using namespace ictk::skin;

namespace
{

const double pi = std::acos(-1.0);

std::string model(const std::string& relative)
{
  return std::string(ICTK_ASSIMP_MODELS) + "/" + relative;
}

Affine translation(double x, double y, double z)
{
  Affine a;
  a.b = { x, y, z };
  return a;
}

Affine rotationZ(double angle)
{
  return rotationOf({ std::cos(angle / 2), 0, 0, std::sin(angle / 2) });
}

void expectNear(const Vec3& got, const Vec3& want, double tolerance, const std::string& what)
{
  for (int i = 0; i < 3; ++i)
    EXPECT_NEAR(got[i], want[i], tolerance) << what << " component " << i;
}

/// The message of the exception `f` throws ("" when it throws none).
template <class F>
std::string errorOf(F f)
{
  try
  {
    f();
  }
  catch (const std::exception& e)
  {
    return e.what();
  }
  return "";
}

/// One triangle on the plane x + y = 1, its normals (1, 1, 0)/sqrt 2, weighed by two joints.
SkinnedMesh twoJointTriangle(double w0)
{
  SkinnedMesh m;
  m.nodes = { { "root", -1, {} }, { "a", 0, {} }, { "b", 0, {} } };
  m.joints = { { 1, {} }, { 2, {} } };
  m.restPoints = { { 1, 0, 0 }, { 0, 1, 0 }, { 1, 0, 1 } };
  double s = 1 / std::sqrt(2.0);
  m.restNormals.assign(3, Vec3{ s, s, 0 });
  m.triangles = { { 0, 1, 2 } };
  for (int i = 0; i < 3; ++i)
  {
    m.influences.push_back({ 0, w0 });
    m.influences.push_back({ 1, 1 - w0 });
    m.influenceStart.push_back(m.influences.size());
  }
  return m;
}

} // namespace

TEST(Skin, QuaternionRotationAndSlerp)
{
  // A quarter turn about z takes x to y; halfway along the slerp from the identity is an eighth.
  Quaternion quarter{ std::cos(pi / 4), 0, 0, std::sin(pi / 4) };
  expectNear(rotationOf(quarter).apply({ 1, 0, 0 }), { 0, 1, 0 }, 1e-15, "quarter turn");
  Quaternion half = slerp({}, quarter, 0.5);
  EXPECT_NEAR(half.w, std::cos(pi / 8), 1e-15);
  EXPECT_NEAR(half.z, std::sin(pi / 8), 1e-15);
  // q and -q are one rotation: the slerp takes the shorter arc, not the long way round.
  Quaternion minusQuarter{ -quarter.w, 0, 0, -quarter.z };
  Quaternion shorter = slerp({}, minusQuarter, 0.5);
  expectNear(rotationOf(shorter).apply({ 1, 0, 0 }), { std::cos(pi / 4), std::sin(pi / 4), 0 },
    1e-15, "shorter arc");
  // An unnormalised quaternion is normalised.
  expectNear(rotationOf({ 2, 0, 0, 2 }).apply({ 1, 0, 0 }), { 0, 1, 0 }, 1e-15, "normalised");
}

TEST(Skin, LinearBlendOfTwoJoints)
{
  // p' = 0.25 T(2, 0, 0) p + 0.75 Rz(90) p.
  SkinnedMesh m = twoJointTriangle(0.25);
  m.validate();
  Posed p = skin(m, { translation(2, 0, 0), rotationZ(pi / 2) });
  expectNear(p.points[0], { 0.25 * 3 + 0.75 * 0, 0.75 * 1, 0 }, 1e-15, "vertex 0");
  expectNear(p.points[1], { 0.25 * 2 + 0.75 * -1, 0.25 * 1, 0 }, 1e-15, "vertex 1");
  expectNear(p.points[2], { 0.25 * 3, 0.75, 1 }, 1e-15, "vertex 2");
  // The blended linear part A = 0.25 I + 0.75 Rz(90) = [[.25, -.75], [.75, .25]] is a scaled
  // rotation, so A^-T = A / det A (det 0.625 > 0) and A n for n = (1, 1)/sqrt 2 is along
  // (.25 - .75, .75 + .25) = (-0.5, 1): the unit normal is (-0.5, 1, 0)/|.|, normal to the
  // posed triangle.
  Vec3 edge = ictk::frep::sub(p.points[1], p.points[0]);
  double n = std::sqrt(0.25 + 1);
  expectNear(p.normals[0], { -0.5 / n, 1 / n, 0 }, 1e-15, "normal");
  EXPECT_NEAR(ictk::frep::dot(edge, p.normals[0]), 0, 1e-15);
}

TEST(Skin, NormalsByTheInverseTransposeUnderANonUniformScale)
{
  // One joint scaling x by 2: the plane x + y = 1 becomes x/2 + y = 1, whose normal is
  // (0.5, 1, 0)/|.|. The thesis' M^-1 (L3418) would give (0.5, 1, 0) too only by chance of
  // symmetry; M itself would give (2, 1, 0), which is not normal to the scaled plane.
  SkinnedMesh m = twoJointTriangle(1.0);
  Affine scale;
  scale.a = { 2, 0, 0, 0, 1, 0, 0, 0, 1 };
  Posed p = skin(m, { scale, scale });
  double n = std::sqrt(0.25 + 1);
  for (int i = 0; i < 3; ++i)
    expectNear(p.normals[i], { 0.5 / n, 1 / n, 0 }, 1e-15, "scaled normal");
  Vec3 edge = ictk::frep::sub(p.points[1], p.points[0]); // (-2, 1, 0)
  EXPECT_NEAR(ictk::frep::dot(edge, p.normals[0]), 0, 1e-15);
  // A rotation and a non-uniform scale: the normal stays normal to both posed edges.
  Affine sheared = rotationZ(0.3) * scale;
  p = skin(m, { sheared, sheared });
  for (Vec3 e :
    { ictk::frep::sub(p.points[1], p.points[0]), ictk::frep::sub(p.points[2], p.points[0]) })
    EXPECT_NEAR(ictk::frep::dot(e, p.normals[0]), 0, 1e-14);
}

TEST(Skin, KeysAreInterpolatedAndHeldAtTheEnds)
{
  // One node animated by position keys (lerp) and rotation keys (slerp) at 10 ticks a second.
  SkinnedMesh m = twoJointTriangle(1.0);
  Animation a;
  a.name = "move";
  a.ticksPerSecond = 10;
  a.duration = 20;
  Channel c;
  c.node = 1;
  c.positions = { { 0, { 0, 0, 0 } }, { 20, { 4, 0, 0 } } };
  c.rotations = { { 0, {} }, { 10, { std::cos(pi / 4), 0, 0, std::sin(pi / 4) } } };
  a.channels = { c };
  m.animations = { a };
  std::vector<Affine> g = poseNodes(m, &m.animation("move"), 0.5); // 5 ticks
  expectNear(g[1].b, { 1, 0, 0 }, 1e-15, "a quarter of the way");
  expectNear(g[1].applyLinear({ 1, 0, 0 }), { std::cos(pi / 4), std::sin(pi / 4), 0 }, 1e-15,
    "half the quarter turn");
  g = poseNodes(m, &m.animation("move"), 5.0); // after the last key: held
  expectNear(g[1].b, { 4, 0, 0 }, 1e-15, "held position");
  expectNear(g[1].applyLinear({ 1, 0, 0 }), { 0, 1, 0 }, 1e-15, "held rotation");
  g = poseNodes(m, &m.animation("move"), -1.0); // before the first: held
  expectNear(g[1].b, { 0, 0, 0 }, 1e-15, "held start");
  // A node no channel animates keeps its bind-pose transform.
  EXPECT_TRUE(g[2].isIdentity());
  EXPECT_NE(errorOf([&] { m.animation("walk"); }).find("no animation named 'walk' (it has 'move')"),
    std::string::npos);
}

TEST(Skin, ValidationNamesTheProblem)
{
  SkinnedMesh m = twoJointTriangle(0.5);
  m.file = "andy.x";
  m.influences[3].joint = 7;
  EXPECT_EQ(errorOf([&] { m.validate(); }), "andy.x: vertex 1 names no joint");
  m = twoJointTriangle(0.5);
  m.influences[0].weight = -1;
  EXPECT_EQ(
    errorOf([&] { m.validate(); }), "skinned mesh: vertex 0 has a negative or non-finite weight");
}

// --- Files -------------------------------------------------------------------------------------

TEST(SkinFile, SimpleSkinByHand)
{
  if (!canReadSkinnedMeshFiles())
    GTEST_SKIP() << "built without Assimp";
  // glTF2/simple_skin: ten vertices (0|1, 0..2 by 0.5), joint 0 = node 1 at T(0, 1, 0), joint 1
  // = node 2 below it, rotated about z by the animation; both inverse bind matrices are
  // T(-0.5, -1, 0) and vertex row k weighs (1 - k/4, k/4).
  SkinnedMesh m = readSkinnedMesh(model("glTF2/simple_skin/simple_skin.gltf"));
  ASSERT_EQ(m.vertexCount(), 10u);
  EXPECT_EQ(m.triangles.size(), 8u);
  ASSERT_EQ(m.joints.size(), 2u);
  ASSERT_EQ(m.animations.size(), 1u);
  const Animation& a = m.animations[0];
  EXPECT_NEAR(a.durationSeconds(), 5.5, 1e-9);
  // The file's keys (single precision): 0.383 + 0.924 w at 0.5 s, 0.707 (z, w) at 1 s.
  const double eighth = 2 * std::atan2(double(0.383f), double(0.924f));
  struct Case
  {
    double seconds, angle;
  };
  for (Case c : { Case{ 0.0, 0.0 }, Case{ 0.25, eighth / 2 }, Case{ 1.0, pi / 2 },
         Case{ 2.25, eighth / 2 }, Case{ 4.0, -pi / 2 } })
  {
    Posed p = pose(m, &a, c.seconds);
    Affine j0 = translation(-0.5, 0, 0);
    Affine j1 = translation(0, 1, 0) * rotationZ(c.angle) * translation(-0.5, -1, 0);
    for (int k = 0; k < 5; ++k)
      for (int x = 0; x < 2; ++x)
      {
        Vec3 rest{ double(x), 0.5 * k, 0 };
        double w1 = k / 4.0;
        Vec3 want = ictk::frep::add(
          ictk::frep::scale(j0.apply(rest), 1 - w1), ictk::frep::scale(j1.apply(rest), w1));
        expectNear(p.points[static_cast<std::size_t>(2 * k + x)], want, 1e-6,
          "t = " + std::to_string(c.seconds) + " vertex " + std::to_string(2 * k + x));
      }
  }
  // Written out once: at 1 s the top-left vertex (0, 2) swings to (-1, 0.5), the middle one
  // (0, 1) half of the way to (-0.25, 0.75).
  Posed quarter = pose(m, &a, 1.0);
  expectNear(quarter.points[8], { -1, 0.5, 0 }, 1e-6, "top left");
  expectNear(quarter.points[4], { -0.25, 0.75, 0 }, 1e-6, "middle left");
}

TEST(SkinFile, EpilepticHumanoid)
{
  if (!canReadSkinnedMeshFiles())
    GTEST_SKIP() << "built without Assimp";
  // The counts `assimp info` prints for the file (the reader imports with the same preset).
  SkinnedMesh m = readSkinnedMesh(model("X/BCN_Epileptic.X"));
  EXPECT_EQ(m.vertexCount(), 3613u);
  EXPECT_EQ(m.triangles.size(), 5126u);
  EXPECT_EQ(m.nodes.size(), 58u);
  EXPECT_EQ(m.joints.size(), 54u);
  ASSERT_EQ(m.animations.size(), 1u);
  const Animation& a = m.animation("Epileptisch");
  EXPECT_EQ(a.ticksPerSecond, 4800);
  EXPECT_EQ(a.channels.size(), 57u);
  ASSERT_EQ(m.restNormals.size(), m.vertexCount());

  // The bind pose (the hierarchy's own transforms) reproduces the rest mesh, and so does the
  // animation's start (its first keys are the bind pose), to the file's single precision
  // (measured: 3.2e-6 and 4.4e-6 on a body 1.9 long).
  auto farthest = [&](const Posed& p)
  {
    double worst = 0;
    for (std::size_t i = 0; i < m.vertexCount(); ++i)
      worst = std::max(worst, ictk::frep::distance(p.points[i], m.restPoints[i]));
    return worst;
  };
  EXPECT_LT(farthest(pose(m, nullptr, 0)), 1e-5);
  EXPECT_LT(farthest(pose(m, &a, 0)), 1e-5);

  // Over the animation the box stays finite and moves.
  auto box = [&](const Posed& p)
  {
    std::array<double, 6> b{ 1e300, -1e300, 1e300, -1e300, 1e300, -1e300 };
    for (const Vec3& v : p.points)
      for (int i = 0; i < 3; ++i)
      {
        EXPECT_TRUE(std::isfinite(v[i]));
        b[2 * i] = std::min(b[2 * i], v[i]);
        b[2 * i + 1] = std::max(b[2 * i + 1], v[i]);
      }
    return b;
  };
  std::array<double, 6> first = box(pose(m, &a, 0));
  double moved = 0;
  for (int k = 1; k <= 8; ++k)
  {
    std::array<double, 6> b = box(pose(m, &a, a.durationSeconds() * k / 8));
    for (int i = 0; i < 6; ++i)
      moved = std::max(moved, std::abs(b[i] - first[i]));
  }
  EXPECT_GT(moved, 0.01);
  // Normals stay unit.
  for (const Vec3& n : pose(m, &a, a.durationSeconds() / 3).normals)
    ASSERT_NEAR(ictk::frep::norm(n), 1, 1e-9);
}

TEST(SkinFile, BadFilesNameTheFile)
{
  std::string missing = model("X/no_such_character.x");
  EXPECT_EQ(errorOf([&] { readSkinnedMesh(missing); }).rfind(missing + ": ", 0), 0u);
  if (!canReadSkinnedMeshFiles())
  {
    EXPECT_NE(
      errorOf([&] { readSkinnedMesh(missing); }).find("built without Assimp"), std::string::npos);
    return;
  }
  EXPECT_EQ(errorOf([&] { readSkinnedMesh(missing); }), missing + ": no such file");
  // Not a model at all.
  std::string text = (std::filesystem::temp_directory_path() / "ictk_skin_not_a_model.x").string();
  std::ofstream(text) << "this is not a model\n";
  std::string e = errorOf([&] { readSkinnedMesh(text); });
  EXPECT_EQ(e.rfind(text + ": Assimp cannot read it", 0), 0u) << e;
  std::filesystem::remove(text);
  // A model with points only: no triangle.
  std::string points =
    (std::filesystem::temp_directory_path() / "ictk_skin_points_only.obj").string();
  std::ofstream(points) << "v 0 0 0\nv 1 0 0\nv 0 1 0\np 1 2 3\n";
  e = errorOf([&] { readSkinnedMesh(points); });
  EXPECT_TRUE(e == points + ": has no triangle mesh" || e == points + ": has no mesh") << e;
  std::filesystem::remove(points);
  // An animation the file does not have.
  SkinnedMesh m = readSkinnedMesh(model("X/BCN_Epileptic.X"));
  EXPECT_EQ(errorOf([&] { m.animation("Walk"); }),
    model("X/BCN_Epileptic.X") + ": no animation named 'Walk' (it has 'Epileptisch')");
}

// --- Implicit stand-ins (thesis 5.4)
// ---------------------------------------------------------------

namespace
{

/// An open tube of radius 0.3 around the z axis for |z| <= 0.6 (40 sides, 13 rings), skinned to
/// a bone from (0, 0, -1.5) to (0, 0, 1.5): its joints' offsets are the translations that bring
/// their markers to the origin.
SkinnedMesh tube()
{
  SkinnedMesh m;
  m.file = "tube";
  m.nodes = { { "root", -1, {} }, { "hip", 0, translation(0, 0, -1.5) },
    { "knee", 1, translation(0, 0, 3) } };
  m.joints = { { 1, translation(0, 0, 1.5) }, { 2, translation(0, 0, -1.5) } };
  const int sides = 40, rings = 13;
  for (int k = 0; k < rings; ++k)
    for (int i = 0; i < sides; ++i)
    {
      double a = 2 * pi * i / sides;
      m.restPoints.push_back(
        { 0.3 * std::cos(a), 0.3 * std::sin(a), -0.6 + 1.2 * k / (rings - 1) });
      m.influences.push_back({ 0, 1.0 });
      m.influenceStart.push_back(m.influences.size());
    }
  for (int k = 0; k + 1 < rings; ++k)
    for (int i = 0; i < sides; ++i)
    {
      int p = k * sides + i, q = k * sides + (i + 1) % sides;
      m.triangles.push_back({ p, q, q + sides });
      m.triangles.push_back({ p, q + sides, p + sides });
    }
  m.validate();
  return m;
}

double fieldAt(const ictk::frep::Shape& shape, const Vec3& p)
{
  ictk::frep::PointEvaluator e(ictk::frep::Tape::compile(shape.function()));
  return e.eval(p[0], p[1], p[2]);
}

} // namespace

TEST(StandIn, InitialApproximationOfATube)
{
  // One bone; its marker segment (0, 0, -1.5) -> (0, 0, 1.5) lies 0.3 from every vertex.
  SkinnedMesh m = tube();
  StandIn s = initialStandIn(m);
  ASSERT_EQ(s.segments.size(), 1u);
  expectNear(s.segments[0].a, { 0, 0, -1.5 }, 1e-15, "hip marker");
  expectNear(s.segments[0].b, { 0, 0, 1.5 }, 1e-15, "knee marker");
  EXPECT_NEAR(s.segments[0].radius, 0.3, 1e-12);
  // The field is 0 at distance r from the segment's middle, positive inside, negative outside.
  ictk::frep::Shape f = standInShape(s);
  EXPECT_NEAR(fieldAt(f, { 0.3, 0, 0 }), 0, 1e-12);
  EXPECT_NEAR(fieldAt(f, { 0, -0.3, 0 }), 0, 1e-12);
  EXPECT_GT(fieldAt(f, { 0.1, 0, 0.5 }), 0);
  EXPECT_LT(fieldAt(f, { 0.5, 0, 0 }), 0);
}

TEST(StandIn, TheFitRecoversATubesRadius)
{
  // Started at 0.2 (too thin), the projected Levenberg-Marquardt fit of the algebraic distance
  // comes back to the tube's 0.3: the segment is long against the tube (its ends 0.9 beyond the
  // last ring), so its field is nearly the infinite line's there.
  SkinnedMesh m = tube();
  StandIn s = initialStandIn(m);
  s.segments[0].radius = 0.2;
  StandInFitReport r = fitStandIn(s, m.restPoints);
  EXPECT_NEAR(s.segments[0].radius, 0.3, 0.003);
  EXPECT_LT(r.finalCost, 1e-3 * r.initialCost);
  EXPECT_LT(r.finalMeanDistance, 0.01);
  EXPECT_GT(r.initialMeanDistance, 0.3); // measured: 0.39
  EXPECT_GE(r.iterations, 1);
  // The bounds hold: [0.25, 4] x the starting radius.
  s.segments[0].radius = 0.05;
  fitStandIn(s, m.restPoints, { 0.25, 2.0 });
  EXPECT_NEAR(s.segments[0].radius, 0.1, 1e-12);
}

TEST(StandIn, EpilepticsStandInFitsAndFollowsTheSkeleton)
{
  if (!canReadSkinnedMeshFiles())
    GTEST_SKIP() << "built without Assimp";
  SkinnedMesh m = readSkinnedMesh(model("X/BCN_Epileptic.X"));
  StandIn s = initialStandIn(m);
  EXPECT_GT(s.segments.size(), 30u);
  for (const StandInSegment& g : s.segments)
    EXPECT_GT(g.radius, 0);
  StandInFitReport r = fitStandIn(s, m.restPoints);
  std::printf("BCN_Epileptic stand-in: %zu segments, mean |F| %.4f -> %.4f, cost %.4g -> %.4g, "
              "%d iterations, %.3f s\n",
    s.segments.size(), r.initialMeanDistance, r.finalMeanDistance, r.initialCost, r.finalCost,
    r.iterations, r.seconds);
  EXPECT_LT(r.finalCost, r.initialCost);
  EXPECT_LT(r.finalMeanDistance, r.initialMeanDistance);
  // At every frame the posed segments' ends are the posed joints' origins.
  const Animation& a = m.animation("Epileptisch");
  for (int k = 0; k <= 4; ++k)
  {
    double t = a.durationSeconds() * k / 4;
    std::vector<Affine> globals = poseNodes(m, &a, t);
    StandIn posed = poseStandIn(s, jointMatrices(m, globals));
    for (const StandInSegment& g : posed.segments)
    {
      expectNear(
        g.a, globals[static_cast<std::size_t>(m.joints[g.parentJoint].node)].b, 1e-9, "start");
      expectNear(g.b, globals[static_cast<std::size_t>(m.joints[g.joint].node)].b, 1e-9, "end");
    }
  }
}
