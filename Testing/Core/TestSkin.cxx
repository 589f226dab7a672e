// SPDX-License-Identifier: BSD-3-Clause
// Skinned meshes (issue 17): linear blend skinning against hand-derived positions and normals,
// and the reader on the characters Debian's assimp-testmodels installs (read where the package
// puts them, never copied): glTF2/simple_skin (2 joints, small enough to skin by hand) and
// X/BCN_Epileptic.X (a humanoid, 54 bones, one animation).

#include "Skin/SkinFile.h"
#include "Skin/SkinnedMesh.h"
#include "Skin/StandIn.h"

#include "Complex/Cell.h"
#include "Discretize/MeshRepair.h"
#include "FRep/Evaluators.h"
#include "FRep/Tape.h"

#include "SkinnedTube.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>

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

TEST(SkinFile, EpilepticsTouchingCornersAreSplitIntoAManifold)
{
  if (!canReadSkinnedMeshFiles())
    GTEST_SKIP() << "built without Assimp";
  // BCN_Epileptic's surface is patches cut along its texture seams: no edge has three triangles,
  // but 266 vertices join separate fans (patches touching at a corner), which a B-cell cannot
  // have. Splitting them gives every fan its own copy of the vertex.
  const SkinnedMesh file = readSkinnedMesh(model("X/BCN_Epileptic.X"));
  auto topologyOf = [](const SkinnedMesh& m)
  {
    ictk::discretize::SurfaceMesh s;
    s.points = m.restPoints;
    for (const auto& t : m.triangles)
      s.triangles.push_back({ static_cast<std::uint32_t>(t[0]), static_cast<std::uint32_t>(t[1]),
        static_cast<std::uint32_t>(t[2]) });
    return ictk::discretize::analyzeTopology(s);
  };
  const ictk::discretize::MeshTopology before = topologyOf(file);
  EXPECT_EQ(before.nonManifoldEdges, 0u);
  EXPECT_EQ(before.nonManifoldVertices, 266u);
  SkinnedMesh m = file;
  const std::size_t added = splitNonManifoldVertices(m);
  const ictk::discretize::MeshTopology after = topologyOf(m);
  std::printf("BCN_Epileptic: %zu vertices join separate fans; %zu copies added (%zu -> %zu "
              "vertices), %zu boundary edges\n",
    before.nonManifoldVertices, added, file.vertexCount(), m.vertexCount(), after.boundaryEdges);
  // Each of the 266 vertices gets at least one copy; the surface's edges and triangles stay, so
  // the Euler characteristic rises by the copies.
  EXPECT_GE(added, 266u);
  EXPECT_EQ(m.vertexCount(), 3613u + added);
  EXPECT_EQ(after.nonManifoldVertices, 0u);
  EXPECT_EQ(after.nonManifoldEdges, 0u);
  EXPECT_EQ(after.edges, before.edges);
  EXPECT_EQ(after.triangles, 5126u);
  EXPECT_EQ(after.eulerCharacteristic, before.eulerCharacteristic + static_cast<long>(added));
  EXPECT_NO_THROW(m.validate());
  // Nothing moves: every triangle has the same corner positions as in the file, and at every
  // instant the copies are skinned exactly as the vertices they copy.
  // The vertex each one stands for, read off the triangles: a copy replaces its vertex in the
  // triangles of one fan.
  std::vector<int> source(m.vertexCount(), -1);
  for (std::size_t t = 0; t < m.triangles.size(); ++t)
    for (std::size_t k = 0; k < 3; ++k)
    {
      const auto v = static_cast<std::size_t>(m.triangles[t][k]);
      const int original = file.triangles[t][k];
      ASSERT_TRUE(v == static_cast<std::size_t>(original) || v >= file.vertexCount())
        << "triangle " << t;
      ASSERT_TRUE(source[v] == -1 || source[v] == original) << "vertex " << v;
      source[v] = original;
    }
  for (std::size_t i = file.vertexCount(); i < m.vertexCount(); ++i)
  {
    ASSERT_GE(source[i], 0) << "copy " << i << " is used by no triangle";
    EXPECT_EQ(m.restPoints[i], file.restPoints[static_cast<std::size_t>(source[i])]);
    EXPECT_EQ(m.restNormals[i], file.restNormals[static_cast<std::size_t>(source[i])]);
  }
  const Animation& a = m.animation("Epileptisch");
  const Posed posed = pose(m, &a, a.durationSeconds() / 3);
  const Posed plain = pose(file, &a, a.durationSeconds() / 3);
  for (std::size_t i = 0; i < m.vertexCount(); ++i)
  {
    if (source[i] >= 0)
    {
      ASSERT_EQ(posed.points[i], plain.points[static_cast<std::size_t>(source[i])]) << i;
    }
  }
  // The B-cell's check accepts the split surface and refuses the file's.
  auto cellOf = [](const SkinnedMesh& s)
  {
    ictk::complex::ExplicitGeometry g;
    g.points = s.restPoints;
    for (const auto& t : s.triangles)
      g.triangles.push_back({ static_cast<std::uint32_t>(t[0]), static_cast<std::uint32_t>(t[1]),
        static_cast<std::uint32_t>(t[2]) });
    return ictk::complex::explicitCell("Andy", 2, std::move(g));
  };
  EXPECT_NO_THROW(ictk::complex::checkCell(cellOf(m)));
  EXPECT_THROW(ictk::complex::checkCell(cellOf(file)), std::invalid_argument);
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

SkinnedMesh tube()
{
  return fixtures::skinnedTube(40, 13);
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
  // A pose that breaks a segment is refused, compiled or bound to the one tape, not a NaN field.
  const StandInField tape(1);
  for (int broken = 0; broken < 3; ++broken)
  {
    StandIn bad = s;
    if (broken == 0)
      bad.segments[0].b = bad.segments[0].a;
    else if (broken == 1)
      bad.segments[0].a[1] = std::nan("");
    else
      bad.segments[0].radius = 0;
    EXPECT_THROW(standInShape(bad), std::invalid_argument) << broken;
    EXPECT_THROW(tape.parameters(bad), std::invalid_argument) << broken;
  }
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

// The posed stand-in's field from one tape whose segments' ends, widths and weights are
// parameters, rebound every frame: at every frame of the animation (each tick) and every skinned
// vertex it equals, bit for bit, the field of the posed stand-in compiled with its numbers as
// constants (what every frame did before). The ends are still the skinned joints' origins.
TEST(StandIn, OneTapeReboundAtEveryFrameGivesTheRecompiledFieldBitForBit)
{
  if (!canReadSkinnedMeshFiles())
    GTEST_SKIP() << "built without Assimp";
  SkinnedMesh m = readSkinnedMesh(model("X/BCN_Epileptic.X"));
  const StandIn s = fittedStandIn(m);
  const StandInField field(s.segments.size());
  EXPECT_EQ(field.tape()->parameterCount(), StandInField::ParametersPerSegment * s.segments.size());
  // Its frames: every key time of every channel (the poses the file gives) and 25 a second
  // between them.
  const Animation& a = m.animation("Epileptisch");
  std::set<double> ticks;
  for (const Channel& c : a.channels)
  {
    for (const VectorKey& k : c.positions)
      ticks.insert(k.time);
    for (const RotationKey& k : c.rotations)
      ticks.insert(k.time);
    for (const VectorKey& k : c.scales)
      ticks.insert(k.time);
  }
  for (double tick = 0; tick <= a.duration; tick += a.ticksPerSecond / 25)
    ticks.insert(tick);
  const int frames = static_cast<int>(ticks.size());
  ASSERT_GT(frames, 80);
  ictk::frep::BatchEvaluator<double> rebound(field.tape(), field.parameters(s));
  const std::size_t n = m.vertexCount();
  std::vector<double> x(n), y(n), z(n), got(n), want(n);
  std::size_t different = 0, inside = 0;
  double farthestEnd = 0;
  for (const double tick : ticks)
  {
    const double t = tick / a.ticksPerSecond;
    const std::vector<Affine> globals = poseNodes(m, &a, t);
    const std::vector<Affine> matrices = jointMatrices(m, globals);
    const StandIn posed = poseStandIn(s, matrices);
    const Posed mesh = skin(m, matrices);
    for (std::size_t i = 0; i < n; ++i)
    {
      x[i] = mesh.points[i][0];
      y[i] = mesh.points[i][1];
      z[i] = mesh.points[i][2];
    }
    rebound.setParameters(field.parameters(posed));
    rebound.eval(x.data(), y.data(), z.data(), nullptr, got.data(), n);
    ictk::frep::BatchEvaluator<double> recompiled(
      ictk::frep::Tape::compile(standInShape(posed).function()));
    recompiled.eval(x.data(), y.data(), z.data(), nullptr, want.data(), n);
    for (std::size_t i = 0; i < n; ++i)
    {
      different += std::memcmp(&got[i], &want[i], sizeof(double)) != 0 ? 1 : 0;
      inside += got[i] >= 0 ? 1 : 0;
    }
    for (const StandInSegment& g : posed.segments)
    {
      const Vec3& start = globals[static_cast<std::size_t>(m.joints[g.parentJoint].node)].b;
      const Vec3& end = globals[static_cast<std::size_t>(m.joints[g.joint].node)].b;
      for (int c = 0; c < 3; ++c)
        farthestEnd =
          std::max({ farthestEnd, std::abs(g.a[c] - start[c]), std::abs(g.b[c] - end[c]) });
    }
  }
  EXPECT_EQ(different, 0u) << "of " << n * static_cast<std::size_t>(frames);
  EXPECT_LE(farthestEnd, 1e-9);
  // The stand-in is embedded, so few vertices have F >= 0 (its working range, not a constant).
  std::printf("%d frames x %zu vertices, %zu with F >= 0\n", frames, n, inside);
  EXPECT_LT(inside, n * static_cast<std::size_t>(frames) / 10);
  StandIn fewer = s;
  fewer.segments.pop_back();
  EXPECT_THROW(field.parameters(fewer), std::invalid_argument);
}

// Thesis L3276: the stand-in "fully embedded" in the mesh. The embedded fit keeps F <= -margin
// at the mesh's vertices, edge middles and centroids; its surface samples are tested against the
// mesh by the generalised winding number.
//
// skinned_tube.gltf is closed (a 1 x 2 x 1 box on three joints): every sample of the embedded
// fit is inside. The initial approximation is not (its radius is the distance to the nearest
// vertex, and the two segments' fields add up where they meet: 1 sample of 192 is inside), so
// the embedded fit's algebraic distance is compared with the initial approximation shrunk by
// the largest common factor that puts it inside (F <= 0 at the same points).
TEST(StandIn, TheEmbeddedFitOfAClosedMeshIsInsideAndCloser)
{
  if (!canReadSkinnedMeshFiles())
    GTEST_SKIP() << "built without Assimp";
  const SkinnedMesh m =
    readSkinnedMesh(std::string(ICTK_DATA_DIR) + "/Models/icm/skinned_tube.gltf");
  const StandIn initial = initialStandIn(m);
  StandIn s = initial;
  const StandInFitReport r = fitEmbeddedStandIn(s, m.restPoints, m.triangles);
  const StandInEmbedding before = standInEmbedding(m, initial), after = standInEmbedding(m, s);
  EXPECT_EQ(r.violations, 0u);
  EXPECT_EQ(before.inside, 1u);
  EXPECT_GT(after.samples, 100u);
  EXPECT_EQ(after.inside, after.samples);
  // The constraint points: vertices, edge middles, centroids.
  std::vector<Vec3> points = m.restPoints;
  for (const auto& t : m.triangles)
    for (int k = 0; k < 3; ++k)
    {
      const Vec3& a = m.restPoints[static_cast<std::size_t>(t[k])];
      const Vec3& b = m.restPoints[static_cast<std::size_t>(t[(k + 1) % 3])];
      const Vec3& c = m.restPoints[static_cast<std::size_t>(t[(k + 2) % 3])];
      points.push_back(ictk::frep::lerp(a, b, 0.5));
      points.push_back(ictk::frep::scale(ictk::frep::add(ictk::frep::add(a, b), c), 1.0 / 3));
    }
  auto largestF = [&](const StandIn& x)
  {
    ictk::frep::PointEvaluator f(ictk::frep::Tape::compile(standInShape(x).function()));
    double worst = -1e300;
    for (const Vec3& p : points)
      worst = std::max(worst, f.eval(p[0], p[1], p[2]));
    return worst;
  };
  auto meanF = [&](const StandIn& x)
  {
    ictk::frep::PointEvaluator f(ictk::frep::Tape::compile(standInShape(x).function()));
    double sum = 0;
    for (const Vec3& p : m.restPoints)
      sum += std::abs(f.eval(p[0], p[1], p[2]));
    return sum / static_cast<double>(m.restPoints.size());
  };
  EXPECT_LE(largestF(s), 1e-9);
  EXPECT_GT(largestF(initial), 0);
  double inside = 0, outside = 1;
  for (int it = 0; it < 50; ++it)
  {
    const double c = 0.5 * (inside + outside);
    StandIn shrunk = initial;
    for (StandInSegment& g : shrunk.segments)
      g.radius *= c;
    (largestF(shrunk) <= 0 ? inside : outside) = c;
  }
  StandIn shrunk = initial;
  for (StandInSegment& g : shrunk.segments)
    g.radius *= inside;
  std::printf("skinned_tube embedded stand-in: mean |F| %.4f (initial approximation, %zu/%zu "
              "samples inside), %.4f (shrunk by %.4f to lie inside), %.4f (embedded fit, %zu/%zu "
              "inside, %d Newton steps)\n",
    r.initialMeanDistance, before.inside, before.samples, meanF(shrunk), inside,
    r.finalMeanDistance, after.inside, after.samples, r.iterations);
  EXPECT_NEAR(meanF(s), r.finalMeanDistance, 1e-6);
  // The fit is the optimum among the stand-ins inside, so it is at least as near; here it is the
  // shrunk one itself (0.5332 both: the two segments are alike and the same middle points bind).
  EXPECT_LE(r.finalMeanDistance, meanF(shrunk) + 1e-9);
}

// BCN_Epileptic is open (its patches are not sewn at the texture seams: 2,292 boundary edges),
// so inside is |winding number| > 1/2. Its initial approximation is 70 % inside (where bones
// meet, the segments' fields add up past the mesh), the unconstrained fit (fitStandIn) 58 %; the
// embedded one (margin 0.05) 99 %, at a higher mean algebraic distance than the initial
// approximation's: the embedded fit is the least-squares optimum among the stand-ins inside
// (a convex programme), and no radii that keep it inside come nearer the vertices.
TEST(StandIn, TheEmbeddedFitOfEpilepticStaysInsideTheMesh)
{
  if (!canReadSkinnedMeshFiles())
    GTEST_SKIP() << "built without Assimp";
  SkinnedMesh m = readSkinnedMesh(model("X/BCN_Epileptic.X"));
  splitNonManifoldVertices(m);
  const StandIn initial = initialStandIn(m);
  StandIn s = initial;
  StandInFitOptions o;
  o.margin = 0.05;
  const StandInFitReport r = fitEmbeddedStandIn(s, m.restPoints, m.triangles, o);
  StandIn unconstrained = initial;
  fitStandIn(unconstrained, m.restPoints);
  const StandInEmbedding before = standInEmbedding(m, initial);
  const StandInEmbedding free = standInEmbedding(m, unconstrained);
  const StandInEmbedding after = standInEmbedding(m, s);
  std::printf("BCN_Epileptic embedded stand-in: %zu segments, mean |F| %.4f -> %.4f, cost %.4g -> "
              "%.4g, %d Newton steps, %.3f s, %zu points positive at radius 0; samples inside: "
              "initial %zu/%zu, unconstrained fit %zu/%zu, embedded fit %zu/%zu (%.2f%%)\n",
    s.segments.size(), r.initialMeanDistance, r.finalMeanDistance, r.initialCost, r.finalCost,
    r.iterations, r.seconds, r.violations, before.inside, before.samples, free.inside, free.samples,
    after.inside, after.samples, 100 * after.fraction());
  EXPECT_GT(after.samples, 4000u);
  EXPECT_GE(after.fraction(), 0.99);
  EXPECT_LT(before.fraction(), 0.75);
  EXPECT_LT(free.fraction(), before.fraction());
  // The constraint holds where it was asked (but at the points positive from the start).
  ictk::frep::PointEvaluator f(ictk::frep::Tape::compile(standInShape(s).function()));
  std::size_t positive = 0;
  for (const Vec3& p : m.restPoints)
    positive += f.eval(p[0], p[1], p[2]) > -o.margin + 1e-9 ? 1 : 0;
  EXPECT_LE(positive, r.violations);
}

TEST(StandIn, WindingNumbersOfAClosedBox)
{
  // The unit cube, outward triangles: 1 inside, 0 outside, 1/2 on a face's middle.
  const std::vector<Vec3> p = { { 0, 0, 0 }, { 1, 0, 0 }, { 1, 1, 0 }, { 0, 1, 0 }, { 0, 0, 1 },
    { 1, 0, 1 }, { 1, 1, 1 }, { 0, 1, 1 } };
  const std::vector<std::array<int, 3>> t = { { 0, 2, 1 }, { 0, 3, 2 }, { 4, 5, 6 }, { 4, 6, 7 },
    { 0, 1, 5 }, { 0, 5, 4 }, { 2, 3, 7 }, { 2, 7, 6 }, { 1, 2, 6 }, { 1, 6, 5 }, { 0, 4, 7 },
    { 0, 7, 3 } };
  EXPECT_NEAR(windingNumber(p, t, { 0.5, 0.5, 0.5 }), 1, 1e-12);
  EXPECT_NEAR(windingNumber(p, t, { 0.1, 0.8, 0.3 }), 1, 1e-12);
  EXPECT_NEAR(windingNumber(p, t, { 1.5, 0.5, 0.5 }), 0, 1e-12);
  EXPECT_NEAR(windingNumber(p, t, { -3, 7, 2 }), 0, 1e-12);
  // Without its top (an open box) the middle sees 5 of the 6 faces: 5/6.
  std::vector<std::array<int, 3>> noTop(t.begin(), t.end());
  noTop.erase(noTop.begin() + 2, noTop.begin() + 4);
  EXPECT_NEAR(windingNumber(p, noTop, { 0.5, 0.5, 0.5 }), 5.0 / 6, 1e-12);
}

// Thesis L3268-3270: the stand-in is fitted in the bind pose; where a pose brings the mesh nearer
// a bone than the stand-in's surface reaches from it, the stand-in shows through, and a refit is
// made at that key frame; between keys the radii are interpolated. skinned_tube.gltf (a 1 x 2 x 1
// box on three joints, the upper joint turning a quarter about z over 2 s) folds at its middle.
TEST(StandIn, RefitsAtKeyFramesWhereTheStandInReachesPastTheMesh)
{
  if (!canReadSkinnedMeshFiles())
    GTEST_SKIP() << "built without Assimp";
  const SkinnedMesh m =
    readSkinnedMesh(std::string(ICTK_DATA_DIR) + "/Models/icm/skinned_tube.gltf");
  const Animation& a = m.animations.at(0);
  auto matricesAt = [&](double t)
  {
    return jointMatrices(m, poseNodes(m, &a, t));
  };
  StandIn rest = initialStandIn(m);
  fitEmbeddedStandIn(rest, m.restPoints, m.triangles);
  auto exceeded = [&](const StandIn& s, double t)
  {
    const std::vector<Affine> matrices = matricesAt(t);
    std::vector<int> out;
    const auto c = boneClearances(poseStandIn(s, matrices), skin(m, matrices).points);
    for (std::size_t i = 0; i < c.size(); ++i)
      if (c[i].exceeds())
        out.push_back(static_cast<int>(i));
    return out;
  };
  // In the bind pose the embedded stand-in is inside: no bone's clearance is exceeded. Folded
  // at 2 s, the mesh's inner corner comes nearer the bones than the stand-in reaches.
  EXPECT_TRUE(exceeded(rest, 0).empty());
  EXPECT_FALSE(exceeded(rest, 2).empty());
  // The automatic keys over the frames 0, 0.5, ..., 2: a key where the trigger fires, none where
  // it does not; at every key the refitted stand-in is inside again.
  const StandInKeys keys = refitAtKeyFrames(rest, m, matricesAt, {}, { 0, 0.5, 1, 1.5, 2 });
  ASSERT_FALSE(keys.times.empty());
  for (double t : keys.times)
  {
    EXPECT_TRUE(exceeded(keys.at(rest, t), t).empty()) << "key " << t;
    EXPECT_FALSE(exceeded(rest, t).empty()) << "key " << t << " needed no refit";
  }
  // A user key at 1 and the interpolation between keys: halfway the radii are the mean.
  const StandInKeys user = refitAtKeyFrames(rest, m, matricesAt, { 0, 2 }, {});
  ASSERT_EQ(user.times, (std::vector<double>{ 0, 2 }));
  const StandIn half = user.at(rest, 1);
  for (std::size_t i = 0; i < half.segments.size(); ++i)
    EXPECT_NEAR(half.segments[i].radius, 0.5 * (user.radii[0][i] + user.radii[1][i]), 1e-15);
  EXPECT_EQ(user.at(rest, -1).segments[0].radius, user.radii[0][0]);
  EXPECT_EQ(user.at(rest, 5).segments[0].radius, user.radii[1][0]);
}
