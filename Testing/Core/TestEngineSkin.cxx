// SPDX-License-Identifier: BSD-3-Clause
// Skinned meshes as B-cells (issue 17; thesis Appendix B's Andy): `shape = loadMesh("file",
// "animation")` is a 2D explicit cell whose points are the mesh posed by the animation at the
// cell's time (the model's, or the cell's `timespan` clock), moved by its placement; the built-in
// jointPosition(cell, "joint") gives a joint's place in the world. glTF2/simple_skin (Debian's
// assimp-testmodels, read where the package puts it) is small enough to pose by hand: at 1 s its
// upper joint has turned a quarter about z, and the top-left vertex (0, 2) is at (-1, 0.5). The
// checker refuses a missing file, an animation the file does not have, a joint its skeleton does
// not have, and a query on a skinned cell, at their places.
//
// Skeletons and implicit stand-ins in the engine (issue 17; thesis Appendix B, 5.4): the
// `Skeleton` C-cell of loadSegmentsHierarchy whose `matrices` (an array of TRANSFORM) a
// dependency carries to a loadMesh cell that setDeformation poses with them, and the standIn(cell)
// F-cell that follows the mesh's skeleton.
//
// Besides simple_skin, Data/Models/icm/skinned_tube.gltf: a closed 1 x 2 x 1 box around three
// joints j0 (0, 0, 0) -> j1 (0, 1, 0) -> j2 (0, 2, 0), its lower rings weighed by j0, its upper
// ones by j1, the middle ring half and half; over 2 s j0 moves by (2, 0, 0) and j1 turns a quarter
// about z, so every segment of its stand-in moves rigidly with one joint.

#include "Discretize/Surface.h"
#include "Engine/DynamicModel.h"
#include "Engine/FrameSequence.h"
#include "FRep/Evaluators.h"
#include "FRep/Primitives.h"
#include "FRep/Tape.h"
#include "Lang/Icm.h"
#include "Skin/Projection.h"
#include "Skin/SkinFile.h"
#include "Skin/StandIn.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <string>
#include <vector>

namespace
{
namespace engine = ictk::engine;
namespace fs = std::filesystem;
namespace skin = ictk::skin;
using Vec3 = ictk::geometry::Vec3;

const std::string kSimpleSkin =
  std::string(ICTK_ASSIMP_MODELS) + "/glTF2/simple_skin/simple_skin.gltf";

fs::path Folder()
{
  // One folder per test: ctest runs the tests of this file in parallel processes.
  const fs::path dir = fs::temp_directory_path() / "ictk_engine_skin" /
    ::testing::UnitTest::GetInstance()->current_test_info()->name();
  fs::create_directories(dir);
  return dir;
}

fs::path Write(const std::string& name, const std::string& text)
{
  const fs::path path = Folder() / name;
  std::ofstream(path) << text;
  return path;
}

/// The strip moved by (10, 0, 0); Marker follows its upper joint; Late plays the animation on the
/// clock of a time span that starts at 2.
std::string Model()
{
  return "name = SKIN;\n"
         "TIMESPANS { film : TIMESPAN(0, 5.5); late : TIMESPAN(2, 10); }\n"
         "CELLS {\n"
         "  Strip {\n"
         "    type = B-CELL;\n"
         "    shape = loadMesh(\"" +
    kSimpleSkin +
    "\", \"\");\n"
    "    dim = 2D;\n"
    "    parameters { translation(10, 0, 0); }\n"
    "  }\n"
    "  Late <- Strip { timespan = late; }\n"
    "  Marker {\n"
    "    type = P-CELL; shape = point(0, 0, 0); dim = 0D;\n"
    "    REACTIONS {\n"
    "      update(REAL globalT, REAL localT, REAL lifeT, REAL dt) {\n"
    "        translation = jointPosition(Strip, \"nodes[2]\");\n"
    "      }\n"
    "    }\n"
    "  }\n"
    "}\n"
    "K { CELLS { Strip Late Marker; } }\n";
}

/// "line:col message" of the first diagnostic of loading `text`, or "no error".
std::string ErrorOf(const std::string& text)
{
  try
  {
    engine::DynamicModel::load(Write("bad.icm", text).string());
  }
  catch (const ictk::lang::ParseError& e)
  {
    const auto& d = e.diagnostics().at(0);
    return std::to_string(d.where.line) + ":" + std::to_string(d.where.column) + " " + d.message;
  }
  catch (const engine::ModelError& e)
  {
    return std::to_string(e.pos.line) + ":" + std::to_string(e.pos.column) + " " + e.message;
  }
  return "no error";
}

/// The tube character (see the top of the file), shipped for the metamorphosis model.
std::string Tube()
{
  return std::string(ICTK_DATA_DIR) + "/Models/icm/skinned_tube.gltf";
}

/// Appendix B's pair: the Skeleton C-cell plays the file's animation at `clock` (an expression
/// of globalT) into its matrices, and the dependency carries them to Andy, posed by them.
std::string SkeletonModel(const std::string& file, const std::string& animation,
  const std::string& clock, const std::string& more = "")
{
  return "name = STAND_IN;\n"
         "CELLS {\n"
         "  Skeleton {\n"
         "    type = C-CELL;\n"
         "    shape = loadSegmentsHierarchy(\"" +
    file + "\", \"" + animation +
    "\");\n"
    "    dim = 1D;\n"
    "    parameters { matrices : array of TRANSFORM; }\n"
    "    REACTIONS { update(REAL globalT, REAL localT, REAL lifeT, REAL dt) {\n"
    "      matrices = jointTransforms(Skeleton, " +
    clock +
    ");\n"
    "      setDeformation(Skeleton, matrices);\n"
    "    } }\n"
    "  }\n"
    "  Andy {\n"
    "    type = B-CELL;\n"
    "    shape = loadMesh(\"" +
    file + "\", \"" + animation +
    "\");\n"
    "    dim = 2D;\n"
    "    parameters { transforms : array of TRANSFORM; translation(10, 0, 0); }\n"
    "    REACTIONS { update(REAL globalT, REAL localT, REAL lifeT, REAL dt) {\n"
    "      setDeformation(Andy, transforms);\n"
    "    } }\n"
    "  }\n" +
    more +
    "}\n"
    "K { CELLS { Skeleton Andy" +
    (more.empty() ? "" : " Liquid_Andy") +
    "; }\n"
    "  RELATIONS { dependency { Skeleton.matrices Andy.transforms; } } }\n";
}

const engine::CellState& CellOf(const std::vector<engine::CellState>& cells, const std::string& n)
{
  for (const engine::CellState& c : cells)
    if (c.name == n)
      return c;
  throw std::out_of_range(n);
}

} // namespace

TEST(EngineSkin, TheCellIsTheMeshPosedAtTheModelsTime)
{
  if (!ictk::skin::canReadSkinnedMeshFiles())
    GTEST_SKIP() << "built without Assimp";
  engine::DynamicModel m = engine::DynamicModel::load(Write("skin.icm", Model()).string());
  const ictk::skin::SkinnedMesh mesh = ictk::skin::readSkinnedMesh(kSimpleSkin);
  for (double t : { 0.25, 1.0, 3.0 })
  {
    m.advanceTo(t, 0.25);
    const ictk::complex::Complex cx = m.complex();
    ASSERT_EQ(cx.cellCount(), 3u);
    const auto& strip = std::get<ictk::complex::ExplicitGeometry>(cx.cell(0).geometry);
    EXPECT_EQ(cx.cell(0).dimension, 2);
    ASSERT_EQ(strip.points.size(), 10u);
    EXPECT_EQ(strip.triangles.size(), 8u);
    // The skinning library's pose at t, moved by the cell's translation.
    const ictk::skin::Posed posed = ictk::skin::pose(mesh, &mesh.animations[0], t);
    for (std::size_t i = 0; i < 10; ++i)
    {
      EXPECT_NEAR(strip.points[i][0], posed.points[i][0] + 10, 1e-12) << "t " << t << " v " << i;
      EXPECT_NEAR(strip.points[i][1], posed.points[i][1], 1e-12) << "t " << t << " v " << i;
    }
    if (t == 1.0)
    {
      // By hand: a quarter turn of the upper joint about (0, 1) takes (0, 2) - (0.5, 1) to
      // (-1, -0.5), back to (-1, 0.5), then the cell's (10, 0, 0).
      EXPECT_NEAR(strip.points[8][0], 9, 1e-6);
      EXPECT_NEAR(strip.points[8][1], 0.5, 1e-6);
    }
    // The upper joint turns about its own origin (0, 1, 0): the marker stays at (10, 1, 0).
    const engine::Value marker = m.value("Marker.translation");
    EXPECT_NEAR(marker.vec[0], 10, 1e-12);
    EXPECT_NEAR(marker.vec[1], 1, 1e-12);
    EXPECT_NEAR(marker.vec[2], 0, 1e-12);
    // Late's clock starts at 2: at 3 it shows the pose of 1 s, before 2 the first one.
    const auto& late = std::get<ictk::complex::ExplicitGeometry>(cx.cell(1).geometry);
    const ictk::skin::Posed held = ictk::skin::pose(mesh, &mesh.animations[0], t < 2 ? 0.0 : t - 2);
    for (std::size_t i = 0; i < 10; ++i)
      EXPECT_NEAR(late.points[i][0], held.points[i][0] + 10, 1e-12) << "t " << t << " v " << i;
  }
}

TEST(EngineSkin, ItsShapeVersionFollowsTheAnimation)
{
  if (!ictk::skin::canReadSkinnedMeshFiles())
    GTEST_SKIP() << "built without Assimp";
  // A frame's coherent discretisation re-meshes the skinned cell at every new time.
  engine::FrameSequenceOptions options;
  options.times = { 0.0, 0.5, 1.0 };
  options.discretization.featureSize = 0.1;
  engine::FrameSequence frames(Write("frames.icm", Model()).string(), options);
  std::vector<double> ys;
  for (std::size_t i = 0; i < 3; ++i)
  {
    const engine::Frame f = frames.frame(i);
    ASSERT_EQ(f.mesh.cells.size(), 3u);
    ASSERT_EQ(f.mesh.cells[0].surface.points.size(), 10u);
    ys.push_back(f.mesh.cells[0].surface.points[8][1]);
    // The dominant joint of each vertex and its weight: row k of the strip weighs
    // (1 - k/4, k/4), the first joint winning the tie of row 2.
    const auto& arrays = f.mesh.cells[0].surface.pointData;
    ASSERT_GE(arrays.size(), 2u);
    EXPECT_EQ(arrays[0].name, "DominantJoint");
    EXPECT_EQ(arrays[1].name, "DominantJointWeight");
    EXPECT_EQ(arrays[0].values, (std::vector<double>{ 0, 0, 0, 0, 0, 0, 1, 1, 1, 1 }));
    EXPECT_EQ(
      arrays[1].values, (std::vector<double>{ 1, 1, 0.75, 0.75, 0.5, 0.5, 0.75, 0.75, 1, 1 }));
  }
  EXPECT_NEAR(ys[0], 2, 1e-6);   // the rest pose
  EXPECT_LT(ys[1], 2 - 0.05);    // turning
  EXPECT_NEAR(ys[2], 0.5, 1e-6); // the quarter turn
}

TEST(EngineSkin, AHumanoidWhosePatchesTouchAtCornersIsABCell)
{
  if (!ictk::skin::canReadSkinnedMeshFiles())
    GTEST_SKIP() << "built without Assimp";
  const std::string epileptic = std::string(ICTK_ASSIMP_MODELS) + "/X/BCN_Epileptic.X";
  engine::DynamicModel m = engine::DynamicModel::load(Write("epileptic.icm",
    "CELLS {\n  Andy { type = B-CELL; shape = loadMesh(\"" + epileptic +
      "\", \"Epileptisch\"); dim = 2D; }\n}\nK { CELLS { Andy; } }\n")
                                                        .string());
  ictk::skin::SkinnedMesh mesh = ictk::skin::readSkinnedMesh(epileptic);
  const std::size_t added = ictk::skin::splitNonManifoldVertices(mesh);
  const ictk::skin::Animation& a = mesh.animation("Epileptisch");
  for (double t : { 0.0, 0.4 * a.durationSeconds() })
  {
    m.advanceTo(t, t > 0 ? t : 0.1);
    const ictk::complex::Complex cx = m.complex();
    const auto& andy = std::get<ictk::complex::ExplicitGeometry>(cx.cell(0).geometry);
    ASSERT_EQ(andy.points.size(), 3613u + added);
    EXPECT_EQ(andy.triangles.size(), 5126u);
    const ictk::skin::Posed posed = ictk::skin::pose(mesh, &a, t);
    double worst = 0;
    for (std::size_t i = 0; i < andy.points.size(); ++i)
      worst = std::max(worst, ictk::frep::distance(andy.points[i], posed.points[i]));
    EXPECT_LT(worst, 1e-12) << "t " << t;
  }
}

TEST(EngineSkin, TheCheckerRefusesWhatCannotWork)
{
  const std::string head = "CELLS {\n  A { type = B-CELL; shape = loadMesh(";
  const std::string tail = "); dim = 2D; }\n}\nK { CELLS { A; } }\n";
  // A missing file: at the path, naming it.
  std::string e = ErrorOf(head + "\"no_such.gltf\", \"walk\"" + tail);
  EXPECT_EQ(e.substr(0, e.find(' ')), "2:39") << e;
  EXPECT_NE(e.find("no_such.gltf"), std::string::npos) << e;
  if (!ictk::skin::canReadSkinnedMeshFiles())
  {
    EXPECT_NE(e.find("without Assimp"), std::string::npos) << e;
    return;
  }
  EXPECT_NE(e.find("no such file"), std::string::npos) << e;
  // An animation the file does not have: at the name.
  e = ErrorOf(head + "\"" + kSimpleSkin + "\", \"walk\"" + tail);
  EXPECT_EQ(e.substr(0, e.find(' ')), "2:" + std::to_string(43 + kSimpleSkin.size())) << e;
  EXPECT_NE(e.find("no animation named 'walk'"), std::string::npos) << e;
  EXPECT_NE(e.find(kSimpleSkin), std::string::npos) << e;
  // A character whose patches touch at corners (vertices where separate fans meet) is a B-cell
  // with those corners split (skin::splitNonManifoldVertices).
  const std::string epileptic = std::string(ICTK_ASSIMP_MODELS) + "/X/BCN_Epileptic.X";
  e = ErrorOf(head + "\"" + epileptic + "\", \"Epileptisch\"" + tail);
  EXPECT_EQ(e, "no error");
  // Not strings.
  e = ErrorOf(head + "\"" + kSimpleSkin + "\", 3" + tail);
  EXPECT_NE(e.find("takes quoted strings"), std::string::npos) << e;
  // A joint the skeleton does not have, and a cell that is not skinned.
  const std::string cells = head + "\"" + kSimpleSkin + "\", \"\"); dim = 2D; }\n" +
    "  B { type = F-CELL; shape = sphere(1); dim = 3D; }\n}\n" +
    "K { CELLS { A B; }\n  REACTIONS { update(REAL g, REAL l, REAL f, REAL dt) {\n";
  e = ErrorOf(cells + "    vec3 p = jointPosition(A, \"hand\"); } } }\n");
  EXPECT_EQ(e.substr(0, e.find(' ')), "7:31") << e;
  EXPECT_NE(e.find("no joint named 'hand'"), std::string::npos) << e;
  e = ErrorOf(cells + "    vec3 p = jointPosition(B, \"nodes[2]\"); } } }\n");
  EXPECT_EQ(e.substr(0, e.find(' ')), "7:28") << e;
  EXPECT_NE(e.find("is not one (shape = loadMesh"), std::string::npos) << e;
  // The queries do not take meshes: distance(B, A) at the A.
  e = ErrorOf(cells + "    real d = distance(B, A); } } }\n");
  EXPECT_EQ(e.substr(0, e.find(' ')), "7:26") << e;
  EXPECT_NE(e.find("is a mesh (.obj/.off, loadMesh)"), std::string::npos) << e;
  // The engine: a skinned cell is a surface, dim = 2D.
  e = ErrorOf(head + "\"" + kSimpleSkin + "\", \"\"); dim = 3D; }\n}\nK { CELLS { A; } }\n");
  EXPECT_NE(e.find("dim = 2D"), std::string::npos) << e;
}

TEST(EngineSkeleton, TheDependencyCarriesTheSkeletonsMatricesToTheMesh)
{
  if (!skin::canReadSkinnedMeshFiles())
    GTEST_SKIP() << "built without Assimp";
  // The skeleton plays at half speed: Andy, posed by what the dependency carries and not by its
  // own animation, shows the pose of t / 2.
  engine::DynamicModel m = engine::DynamicModel::load(
    Write("skeleton.icm", SkeletonModel(kSimpleSkin, "", "0.5 * globalT")).string());
  const skin::SkinnedMesh mesh = skin::readSkinnedMesh(kSimpleSkin);
  for (double t : { 0.5, 2.0, 3.0 })
  {
    m.advanceTo(t, 0.25);
    const ictk::complex::Complex cx = m.complex();
    ASSERT_EQ(cx.cellCount(), 2u);
    const auto& andy = std::get<ictk::complex::ExplicitGeometry>(cx.cell(1).geometry);
    ASSERT_EQ(andy.points.size(), 10u);
    const skin::Posed posed = skin::pose(mesh, &mesh.animations[0], t / 2);
    for (std::size_t i = 0; i < 10; ++i)
    {
      EXPECT_NEAR(andy.points[i][0], posed.points[i][0] + 10, 1e-6) << "t " << t << " v " << i;
      EXPECT_NEAR(andy.points[i][1], posed.points[i][1], 1e-6) << "t " << t << " v " << i;
    }
    if (t == 2.0)
    {
      // By hand (the pose of 1 s): (0, 2) turned a quarter about the upper joint is (-1, 0.5),
      // then the cell's (10, 0, 0).
      EXPECT_NEAR(andy.points[8][0], 9, 1e-6);
      EXPECT_NEAR(andy.points[8][1], 0.5, 1e-6);
    }
    // What the dependency carried: Andy.transforms is Skeleton.matrices, the library's matrices.
    const engine::Value a = m.value("Skeleton.matrices"), b = m.value("Andy.transforms");
    ASSERT_EQ(a.type, engine::Value::Type::Transforms);
    ASSERT_EQ(a.transforms->size(), 2u);
    ASSERT_EQ(b.transforms->size(), 2u);
    const auto expected =
      skin::jointMatrices(mesh, skin::poseNodes(mesh, &mesh.animations[0], t / 2));
    for (std::size_t j = 0; j < 2; ++j)
      for (int k = 0; k < 9; ++k)
      {
        EXPECT_EQ((*b.transforms)[j].a[k], (*a.transforms)[j].a[k]);
        EXPECT_NEAR((*a.transforms)[j].a[k], expected[j].a[k], 1e-12);
      }
  }
}

TEST(EngineSkeleton, TheSkeletonsSegmentsEndAtTheJoints)
{
  if (!skin::canReadSkinnedMeshFiles())
    GTEST_SKIP() << "built without Assimp";
  const std::string tube = Tube();
  const std::string markers =
    "  M1 { type = P-CELL; shape = point(0, 0, 0); dim = 0D;\n"
    "    REACTIONS { update(REAL globalT, REAL localT, REAL lifeT, REAL dt) {\n"
    "      translation = jointPosition(Skeleton, \"j1\"); } } }\n"
    "  M2 <- M1 { REACTIONS { update(REAL globalT, REAL localT, REAL lifeT, REAL dt) {\n"
    "      translation = jointPosition(Skeleton, \"j2\"); } } }\n";
  std::string text = SkeletonModel(tube, "walk", "globalT", markers);
  text.replace(text.find(" Liquid_Andy;"), 13, " M1 M2;");
  // The markers read the skeleton after it moved.
  text.replace(text.find("Andy.transforms;"), 16,
    "Andy.transforms; Skeleton.shape M1.translation; Skeleton.shape M2.translation;");
  engine::DynamicModel m = engine::DynamicModel::load(Write("tube.icm", text).string());
  for (double t : { 0.0, 1.0, 2.0 })
  {
    m.advanceTo(t, 0.25);
    const auto cells = m.cells();
    const auto& skeleton = CellOf(cells, "Skeleton");
    ASSERT_EQ(skeleton.shape->parts.size(), 2u); // j0 -> j1, j1 -> j2
    // By hand: j0 has moved by (t, 0, 0); j1 turns by t / 2 quarters about z over j0, and j2
    // lies one up from j1 along the turned y axis.
    const double angle = t / 2 * std::acos(0.0);
    const Vec3 j0{ t, 0, 0 }, j1{ t, 1, 0 }, j2{ t - std::sin(angle), 1 + std::cos(angle), 0 };
    const auto& p0 = skeleton.shape->parts[0].points;
    const auto& p1 = skeleton.shape->parts[1].points;
    for (int k = 0; k < 3; ++k)
    {
      EXPECT_NEAR(p0[0][k], j0[k], 1e-6) << t;
      EXPECT_NEAR(p0[1][k], j1[k], 1e-6) << t;
      EXPECT_NEAR(p1[0][k], j1[k], 1e-6) << t;
      EXPECT_NEAR(p1[1][k], j2[k], 1e-6) << t;
      // jointPosition of a skeleton posed by setDeformation: the same places.
      EXPECT_NEAR(m.value("M1.translation").vec[k], j1[k], 1e-6) << t;
      EXPECT_NEAR(m.value("M2.translation").vec[k], j2[k], 1e-6) << t;
    }
  }
}

TEST(EngineSkeleton, TheStandInFollowsTheSkeleton)
{
  if (!skin::canReadSkinnedMeshFiles())
    GTEST_SKIP() << "built without Assimp";
  const std::string tube = Tube();
  const std::string liquid = "  Liquid_Andy { type = F-CELL; shape = standIn(Andy); dim = 3D; }\n";
  engine::DynamicModel m = engine::DynamicModel::load(
    Write("standin.icm", SkeletonModel(tube, "walk", "globalT", liquid)).string());
  // The stand-in the engine fits, fitted again here with the library (deterministic).
  const skin::SkinnedMesh mesh = skin::readSkinnedMesh(tube);
  skin::StandInFitReport report;
  skin::StandIn fitted = skin::fittedStandIn(mesh, &report);
  ASSERT_EQ(fitted.segments.size(), 2u);
  EXPECT_EQ(report.violations, 0u);
  // k_i = 1 / f_i(r_i) and the bound of f_i by its segment's length l_i: f_i(p) <= l_i h(d_i)
  // with h(d) = 1 / (1 + s_i^2 d^2)^2 the kernel and d_i the distance from p to the segment.
  std::vector<double> k;
  for (const skin::StandInSegment& g : fitted.segments)
  {
    ictk::frep::PointEvaluator f(
      ictk::frep::Tape::compile(ictk::frep::cauchySegmentField(g.a, g.b, g.s)));
    const Vec3 mid = ictk::frep::lerp(g.a, g.b, 0.5);
    k.push_back(1 / f.eval(mid[0] + g.radius, mid[1], mid[2]));
  }
  auto segmentDistance = [](const Vec3& p, const Vec3& a, const Vec3& b)
  {
    const Vec3 ab = ictk::frep::sub(b, a);
    const double u =
      std::clamp(ictk::frep::dot(ictk::frep::sub(p, a), ab) / ictk::frep::dot(ab, ab), 0.0, 1.0);
    return ictk::frep::distance(p, ictk::frep::lerp(a, b, u));
  };
  const ictk::frep::Shape rest = skin::standInShape(fitted);
  ictk::frep::PointEvaluator restField(ictk::frep::Tape::compile(rest.function()));
  for (double t : { 0.0, 0.5, 1.0, 2.0 })
  {
    m.advanceTo(t, 0.25);
    const auto cells = m.cells();
    const auto& standIn = CellOf(cells, "Liquid_Andy");
    const auto matrices = skin::jointMatrices(mesh, skin::poseNodes(mesh, &mesh.animations[0], t));
    const skin::StandIn posed = skin::poseStandIn(fitted, matrices);
    // The segments' ends are the joints' places (the skeleton's, by hand, as above).
    const double angle = t / 2 * std::acos(0.0);
    const Vec3 joints[3] = { { t, 0, 0 }, { t, 1, 0 },
      { t - std::sin(angle), 1 + std::cos(angle), 0 } };
    for (const skin::StandInSegment& g : posed.segments)
      for (int c = 0; c < 3; ++c)
      {
        EXPECT_NEAR(g.a[c], joints[g.parentJoint][c], 1e-6) << t;
        EXPECT_NEAR(g.b[c], joints[g.joint][c], 1e-6) << t;
      }
    // The engine's field (placed with Andy at (10, 0, 0)) is the posed stand-in's, within its
    // bounds (the distance to their faces where that is smaller).
    ictk::frep::PointEvaluator field(
      ictk::frep::Tape::compile(skin::standInShape(posed).function()));
    const ictk::frep::Box3 box = skin::standInBounds(posed);
    for (const Vec3& p :
      { Vec3{ t, 0.5, 0 }, Vec3{ t + 0.3, 1.2, 0.1 }, Vec3{ t - 0.6, 1.8, -0.2 } })
    {
      double expected = field.eval(p[0], p[1], p[2]);
      for (int c = 0; c < 3; ++c)
        expected = std::min({ expected, p[c] - box.lo[c], box.hi[c] - p[c] });
      EXPECT_NEAR(standIn.shape->value({ p[0] + 10, p[1], p[2] }), expected, 1e-12) << t;
    }
    // At every vertex weighed by one joint the field is its bind pose value, but for the
    // segment that moves with the other joint: |F_t(p_i(t)) - F_0(v_i)| <= k_o l_o h(d) with d
    // the smaller of the vertex's distances to that segment then and now.
    const skin::Posed skinned = skin::skin(mesh, matrices);
    for (std::size_t i = 0; i < mesh.vertexCount(); ++i)
    {
      const int ring = static_cast<int>(i / 4);
      if (ring == 2)
        continue; // the middle ring is weighed by both joints
      const std::size_t other = ring < 2 ? 1 : 0;
      const skin::StandInSegment& g = fitted.segments[other];
      const skin::StandInSegment& h = posed.segments[other];
      const double d = std::min(segmentDistance(mesh.restPoints[i], g.a, g.b),
        segmentDistance(skinned.points[i], h.a, h.b));
      const double bound =
        k[other] * ictk::frep::distance(g.a, g.b) / std::pow(1 + g.s * g.s * d * d, 2);
      const Vec3& v = mesh.restPoints[i];
      const Vec3& p = skinned.points[i];
      const double now = standIn.shape->value({ p[0] + 10, p[1], p[2] });
      EXPECT_LE(std::abs(now - restField.eval(v[0], v[1], v[2])), bound + 1e-12)
        << "t " << t << " v " << i;
    }
  }
}

TEST(EngineSkeleton, TheCheckerAndTheEngineRefuseWhatCannotWork)
{
  if (!skin::canReadSkinnedMeshFiles())
    GTEST_SKIP() << "built without Assimp";
  const std::string tube = Tube();
  // Two skeletons of different joint counts: at the dependency.
  std::string text = SkeletonModel(kSimpleSkin, "", "globalT");
  text.replace(text.find("loadMesh(\"" + kSimpleSkin + "\", \"\")"), 12 + kSimpleSkin.size() + 4,
    "loadMesh(\"" + tube + "\", \"walk\")");
  std::string e = ErrorOf(text);
  EXPECT_NE(e.find("connects 2 transforms to 3"), std::string::npos) << e;
  // A stand-in of a cell that is not a skinned mesh: at the cell's name.
  e = ErrorOf("CELLS { A { type = F-CELL; shape = sphere(1); dim = 3D; }\n"
              "  S { type = F-CELL; shape = standIn(A); dim = 3D; } }\nK { CELLS { A S; } }\n");
  EXPECT_EQ(e.substr(0, e.find(' ')), "2:38") << e;
  EXPECT_NE(e.find("standIn takes a skinned mesh cell"), std::string::npos) << e;
  // A stand-in of a mesh without a bone inside it (simple_skin's two joints are one place).
  e = ErrorOf("CELLS { A { type = B-CELL; shape = loadMesh(\"" + kSimpleSkin +
    "\", \"\"); dim = 2D; }\n"
    "  S { type = F-CELL; shape = standIn(A); dim = 3D; } }\nK { CELLS { A S; } }\n");
  EXPECT_NE(e.find("no bone inside the mesh"), std::string::npos) << e;
  // setDeformation on a cell that is not skinned: at the cell.
  e = ErrorOf(
    "CELLS { A { type = F-CELL; shape = sphere(1); dim = 3D;\n"
    "  REACTIONS { update(REAL g, REAL l, REAL f, REAL dt) { setDeformation(A, 1); } } } }\n"
    "K { CELLS { A; } }\n");
  EXPECT_NE(e.find("setDeformation takes a skinned cell"), std::string::npos) << e;
}

// Data/Models/icm/metamorphosis.icm (thesis 5.5; T-5.5 of ../shared/spec/thesis_ch5_6.md): K1 the
// source mesh, K2 it moving onto its stand-in with the weight map sourceTop (z in the file: the
// top first), K3 the space-time blend of the two stand-ins from the switch on, K4 the destination
// leaving its stand-in, K5 the destination mesh. The switch K2 -> K3 is the first time every
// vertex of the source is within 1e-6 of its posed stand-in and every normal within 1 degree of
// the stand-in's (L3420). Read here with the two stand-ins also shown in K3, so that the blend can
// be compared with them.
namespace
{

struct Metamorphosis
{
  std::string text;
  skin::SkinnedMesh source, target;
  skin::StandIn sourceStandIn, targetStandIn;
  skin::Projection sourceProjection, targetProjection;
  ictk::geometry::Affine sourcePlace, targetPlace;

  Metamorphosis()
  {
    std::ifstream in(std::string(ICTK_DATA_DIR) + "/Models/icm/metamorphosis.icm");
    text.assign((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    text.replace(text.find("\"skinned_tube.gltf\""), 19, "\"" + Tube() + "\"");
    text.replace(
      text.find("CELLS { Morph; }"), 16, "CELLS { Morph Source_standIn Target_standIn; }");
    source = skin::readSkinnedMesh(std::string(ICTK_ASSIMP_MODELS) + "/FBX/huesitos.fbx");
    target = skin::readSkinnedMesh(Tube());
    sourceStandIn = skin::fittedStandIn(source);
    targetStandIn = skin::fittedStandIn(target);
    sourceProjection = skin::projectOntoStandIn(source, sourceStandIn);
    targetProjection = skin::projectOntoStandIn(target, targetStandIn);
    sourcePlace =
      ictk::geometry::Affine::fromTransform({ -1.6, -2.7, 2.6 }, { 0, 0, 0 }, { 0.01, 0.01, 0.01 });
    targetPlace =
      ictk::geometry::Affine::fromTransform({ 0, -2.5, 0 }, { 0, 0, 0 }, { 2.5, 2.5, 2.5 });
  }

  static double smooth(double x)
  {
    const double c = std::clamp(x, 0.0, 1.0);
    return c * c * (3 - 2 * c);
  }

  /// The model's pose of a mesh at t, made again with the library: alpha delayed per vertex by
  /// the weight map `axis` of the rest points (spread 1/2).
  static skin::ProjectedPose poseAt(const skin::SkinnedMesh& mesh, const skin::StandIn& standIn,
    const skin::Projection& projection, double t, double alpha, int axis)
  {
    const auto matrices = skin::jointMatrices(mesh, skin::poseNodes(mesh, &mesh.animations[0], t));
    std::vector<double> weights;
    for (const Vec3& p : mesh.restPoints)
      weights.push_back(p[static_cast<std::size_t>(axis)]);
    const std::vector<double> delays = skin::projectionDelays(weights, 0.5);
    std::vector<double> alphas;
    for (double d : delays)
      alphas.push_back(skin::delayedAlpha(alpha, d, 0.5));
    return skin::poseOnStandIn(mesh, projection, matrices, alphas, *posedField(mesh, standIn, t));
  }

  static ictk::frep::FieldPtr posedField(
    const skin::SkinnedMesh& mesh, const skin::StandIn& standIn, double t)
  {
    const auto matrices = skin::jointMatrices(mesh, skin::poseNodes(mesh, &mesh.animations[0], t));
    return ictk::frep::tapeField(
      ictk::frep::Tape::compile(
        skin::standInShape(skin::poseStandIn(standIn, matrices)).function()),
      0.0, {});
  }
};

/// A mesh cell's world points and normals against a pose made with the library.
void ExpectMesh(const engine::DynamicModel& m, const std::string& cell,
  const ictk::geometry::Affine& place, const skin::Posed& want, const std::string& when)
{
  const auto cells = m.cells();
  const auto& shape = *CellOf(cells, cell).shape;
  const auto& part = shape.parts[0];
  ASSERT_EQ(part.points.size(), want.points.size());
  for (std::size_t i = 0; i < want.points.size(); ++i)
  {
    const Vec3 got = shape.place.apply(part.points[i]);
    const Vec3 w = place.apply(want.points[i]);
    for (int c = 0; c < 3; ++c)
      ASSERT_NEAR(got[c], w[c], 1e-9 * (1 + std::abs(w[c]))) << cell << " " << when;
  }
  // The normals (in the cell's frame) go with the points as the array "Normals".
  const auto normals = std::find_if(part.pointData.begin(), part.pointData.end(),
    [](const ictk::discretize::PointArray& a) { return a.name == "Normals"; });
  ASSERT_NE(normals, part.pointData.end()) << cell << " " << when;
  ASSERT_EQ(normals->values.size(), 3 * want.normals.size());
  for (std::size_t i = 0; i < want.normals.size(); ++i)
    for (int c = 0; c < 3; ++c)
      ASSERT_NEAR(normals->values[3 * i + static_cast<std::size_t>(c)], want.normals[i][c], 1e-9)
        << cell << " " << when;
}

} // namespace

TEST(EngineSkeleton, TheMetamorphosisGoesFromTheSourceMeshToTheDestinationMesh)
{
  if (!skin::canReadSkinnedMeshFiles())
    GTEST_SKIP() << "built without Assimp";
  const Metamorphosis x;
  // The projections the engine makes, made again with the library: in the bind pose every
  // vertex ends on its stand-in (|F| < 1e-9) within 10 Newton steps (T-5.5 item 7).
  EXPECT_EQ(x.sourceProjection.failures, 0);
  EXPECT_LT(x.sourceProjection.maxResidual, 1e-9);
  EXPECT_LE(x.sourceProjection.iterations, 10);
  EXPECT_EQ(x.targetProjection.failures, 0);
  EXPECT_LT(x.targetProjection.maxResidual, 1e-9);
  EXPECT_LE(x.targetProjection.iterations, 10);
  engine::DynamicModel m = engine::DynamicModel::load(Write("metamorphosis.icm", x.text).string());
  auto plain = [](const skin::SkinnedMesh& mesh, double t)
  {
    return skin::skin(mesh,
      skin::jointMatrices(mesh, skin::poseNodes(mesh, &mesh.animations[0], t)), mesh.restPoints,
      skin::restNormalsOf(mesh));
  };
  // K1: the plain animated source, its normals the skinned ones.
  m.advanceTo(0.5, 0.25);
  EXPECT_EQ(m.activeInstance(), "K1");
  ExpectMesh(m, "Source", x.sourcePlace, plain(x.source, 0.5), "t 0.5");
  // K2 begins at t = 1 with alpha = 0: the plain skinned source still (T-5.5 item 1).
  m.advanceTo(1.0, 0.25);
  EXPECT_EQ(m.activeInstance(), "K2");
  ExpectMesh(m, "Source", x.sourcePlace, plain(x.source, 1.0), "t 1");
  // K2 at 1.25 (alpha = 1/2): the library's pose, the top of the cylinder further on its way.
  m.advanceTo(1.25, 0.25);
  EXPECT_EQ(m.activeInstance(), "K2");
  const skin::ProjectedPose half =
    Metamorphosis::poseAt(x.source, x.sourceStandIn, x.sourceProjection, 1.25, 0.5, 2);
  EXPECT_EQ(half.failures, 0);
  ExpectMesh(m, "Source", x.sourcePlace, half.posed, "t 1.25");
  // The switch: the first time every vertex is within 1e-6 and every normal within 1 degree. As
  // alpha = smoothstep(2 (t - 1)) nears 1 at t = 1.5 the last vertices (those of the lowest z,
  // alpha_i = 2 alpha - 1) come within 1e-6: just before 1.5.
  double switchTime = -1;
  for (const engine::FrameRecord& r : m.advanceTo(1.75, 0.25))
    if (r.transition)
    {
      EXPECT_EQ(r.instance, "K3");
      switchTime = r.time;
    }
  std::printf("K2 -> K3 at t = %.9f: residual %.3g, normals within %.3g degrees\n", switchTime,
    m.value("residualAtSwitch").number, m.value("angleAtSwitch").number);
  EXPECT_GT(switchTime, 1.49);
  EXPECT_LE(switchTime, 1.5);
  EXPECT_EQ(m.value("morphStart").number, switchTime);
  EXPECT_GE(m.value("residualAtSwitch").number, 0);
  EXPECT_LT(m.value("residualAtSwitch").number, 1e-6);
  EXPECT_LT(m.value("angleAtSwitch").number, 1);
  // The same with the library (T-5.5 item 1): at the switch every vertex satisfies
  // |F| < 1e-6 |grad F| (world units) and every normal is within 1 degree; a millisecond before,
  // not all of them.
  auto residualAt = [&](double t)
  {
    const skin::ProjectedPose p = Metamorphosis::poseAt(
      x.source, x.sourceStandIn, x.sourceProjection, t, Metamorphosis::smooth(2 * (t - 1)), 2);
    return skin::projectionResidual(
      p.posed, *Metamorphosis::posedField(x.source, x.sourceStandIn, t), x.sourcePlace);
  };
  const skin::ProjectionResidual atSwitch = residualAt(switchTime);
  EXPECT_LT(atSwitch.distance, 1e-6);
  EXPECT_LT(atSwitch.degrees, 1);
  EXPECT_GT(residualAt(switchTime - 1e-3).distance, 1e-6);
  // No popping (T-5.5 item 2): at the switch the blend is the source's stand-in, on which the
  // mesh lies (the same inside and outside on a grid); from t1 = 3.5 it is the destination's.
  engine::DynamicModel atStart =
    engine::DynamicModel::load(Write("metamorphosis.icm", x.text).string());
  atStart.advanceTo(switchTime, 0.25);
  EXPECT_EQ(atStart.activeInstance(), "K3");
  m.advanceTo(3.75, 0.25);
  EXPECT_EQ(m.activeInstance(), "K3");
  for (const auto& [model, operand] :
    { std::pair<const engine::DynamicModel*, const char*>{ &atStart, "Source_standIn" },
      std::pair<const engine::DynamicModel*, const char*>{ &m, "Target_standIn" } })
  {
    const auto cells = model->cells();
    const auto& morph = *CellOf(cells, "Morph").shape;
    const auto& shape = *CellOf(cells, operand).shape;
    int inside = 0;
    for (double x = -4; x <= 4; x += 0.25)
      for (double y = -4; y <= 4; y += 0.25)
        for (double z = -4; z <= 4; z += 0.5)
        {
          const double f = shape.value({ x, y, z });
          if (std::abs(f) < 1e-6)
            continue;
          inside += f > 0;
          EXPECT_EQ(morph.value({ x, y, z }) > 0, f > 0)
            << operand << " at " << x << " " << y << " " << z;
        }
    EXPECT_GT(inside, 10) << operand;
  }
  // K4, alpha = 1 at t = 4: the destination on its posed stand-in, normals along it.
  m.advanceTo(4.0, 0.25);
  EXPECT_EQ(m.activeInstance(), "K4");
  const skin::ProjectedPose on =
    Metamorphosis::poseAt(x.target, x.targetStandIn, x.targetProjection, 4.0, 1.0, 1);
  ExpectMesh(m, "Target", x.targetPlace, on.posed, "t 4");
  const skin::ProjectionResidual r = skin::projectionResidual(
    on.posed, *Metamorphosis::posedField(x.target, x.targetStandIn, 4.0), x.targetPlace);
  EXPECT_LT(r.distance, 1e-9);
  EXPECT_LT(r.degrees, 1e-6);
  // K4 from t = 4.5, alpha = 0 with every delay: the plain destination already.
  m.advanceTo(4.75, 0.25);
  EXPECT_EQ(m.activeInstance(), "K4");
  ExpectMesh(m, "Target", x.targetPlace, plain(x.target, 4.75), "t 4.75");
  // K5: the plain destination, points and normals (T-5.5 item 4: 1e-9).
  m.advanceTo(5.5, 0.25);
  EXPECT_EQ(m.activeInstance(), "K5");
  ExpectMesh(m, "Target", x.targetPlace, plain(x.target, 5.5), "t 5.5");
}

// T-5.5 item 3: the topology of the B-cells' meshes holds in K1/K2 (the source) and K4/K5 (the
// destination): each frame's mesh, its vertices welded where the file's bind pose has the same
// point (the file splits vertices along seams), has the bind pose's Euler characteristic, and the
// vertices welded there stay together (the projection tears no seam). A change of topology can
// only be the F-cell's: at the switch the Morph's surface (dual contouring) is closed, manifold
// and has the source mesh's Euler characteristic, and from t1 on the destination's. (Both
// meshes here are closed and of genus 0, so the Euler characteristics are 2 throughout.)
template <typename Triangles>
ictk::discretize::MeshTopology WeldedTopology(const std::vector<Vec3>& bind,
  const Triangles& triangles, const std::vector<Vec3>& posed, double* seamGap = nullptr)
{
  std::map<std::array<double, 3>, std::uint32_t> first;
  std::vector<std::uint32_t> weld(bind.size());
  ictk::discretize::SurfaceMesh mesh;
  for (std::uint32_t i = 0; i < bind.size(); ++i)
  {
    const auto [at, added] =
      first.emplace(std::array<double, 3>{ bind[i][0], bind[i][1], bind[i][2] },
        static_cast<std::uint32_t>(mesh.points.size()));
    if (added)
      mesh.points.push_back({ posed[i][0], posed[i][1], posed[i][2] });
    weld[i] = at->second;
    if (seamGap)
    {
      const auto& p = mesh.points[at->second];
      for (int c = 0; c < 3; ++c)
        *seamGap = std::max(*seamGap, std::abs(p[c] - posed[i][c]));
    }
  }
  for (const auto& t : triangles)
    mesh.triangles.push_back({ weld[static_cast<std::size_t>(t[0])],
      weld[static_cast<std::size_t>(t[1])], weld[static_cast<std::size_t>(t[2])] });
  return ictk::discretize::analyzeTopology(mesh);
}

TEST(EngineSkeleton, TheMeshesKeepTheirTopologyOutsideTheMorph)
{
  if (!skin::canReadSkinnedMeshFiles())
    GTEST_SKIP() << "built without Assimp";
  const Metamorphosis x;
  engine::DynamicModel m = engine::DynamicModel::load(Write("metamorphosis.icm", x.text).string());
  auto topologyOf = [&](const char* cell, const skin::SkinnedMesh& file, const std::string& when)
  {
    const auto cells = m.cells();
    const auto& part = CellOf(cells, cell).shape->parts[0];
    EXPECT_EQ(part.points.size(), file.restPoints.size()) << cell << " " << when;
    double seamGap = 0;
    const auto t = WeldedTopology(file.restPoints, part.triangles, part.points, &seamGap);
    EXPECT_LT(seamGap, 1e-9) << cell << " " << when;
    return t;
  };
  const auto source = WeldedTopology(x.source.restPoints, x.source.triangles, x.source.restPoints);
  const auto target = WeldedTopology(x.target.restPoints, x.target.triangles, x.target.restPoints);
  std::printf("source: V %zu E %zu F %zu, chi %ld, %zu components, %zu boundary edges\n",
    source.vertices, source.edges, source.triangles, source.eulerCharacteristic, source.components,
    source.boundaryEdges);
  std::printf("target: V %zu E %zu F %zu, chi %ld, %zu components, %zu boundary edges\n",
    target.vertices, target.edges, target.triangles, target.eulerCharacteristic, target.components,
    target.boundaryEdges);
  // The mesh of `cell` at each of `times`, all in the instances `a` or `b`, is `file`'s.
  auto expectKept = [&](const char* cell, const skin::SkinnedMesh& file,
                      const ictk::discretize::MeshTopology& bind,
                      std::initializer_list<double> times, const char* a, const char* b)
  {
    for (const double t : times)
    {
      m.advanceTo(t, 0.25);
      ASSERT_TRUE(m.activeInstance() == a || m.activeInstance() == b) << t;
      const auto got = topologyOf(cell, file, "t " + std::to_string(t));
      EXPECT_EQ(got.eulerCharacteristic, bind.eulerCharacteristic) << t;
      EXPECT_EQ(got.edges, bind.edges) << t;
      EXPECT_EQ(got.components, bind.components) << t;
    }
  };
  expectKept("Source", x.source, source, { 0.5, 1.0, 1.25, 1.45 }, "K1", "K2");
  // K3: the Morph's surface, by dual contouring in its box with cells of 0.2.
  auto morphTopology = [&](const engine::DynamicModel& model, const std::string& when)
  {
    const auto cells = model.cells();
    const auto& morph = *CellOf(cells, "Morph").shape;
    ictk::discretize::SurfaceOptions options;
    options.featureSize = 0.2;
    const auto t = ictk::discretize::analyzeTopology(ictk::discretize::contourSurface(
      *ictk::geometry::worldField(morph), morph.worldBounds(), options));
    std::printf("Morph at %s: chi %ld, %zu components, %zu triangles\n", when.c_str(),
      t.eulerCharacteristic, t.components, t.triangles);
    EXPECT_TRUE(t.manifold()) << when;
    EXPECT_TRUE(t.closed()) << when;
    return t;
  };
  double switchTime = -1;
  for (const engine::FrameRecord& r : m.advanceTo(1.75, 0.25))
    if (r.transition)
      switchTime = r.time;
  ASSERT_GT(switchTime, 1.49);
  engine::DynamicModel atSwitch =
    engine::DynamicModel::load(Write("metamorphosis.icm", x.text).string());
  atSwitch.advanceTo(switchTime, 0.25);
  ASSERT_EQ(atSwitch.activeInstance(), "K3");
  const auto first = morphTopology(atSwitch, "the switch");
  EXPECT_EQ(first.eulerCharacteristic, source.eulerCharacteristic);
  EXPECT_EQ(first.components, source.components);
  m.advanceTo(3.75, 0.25);
  ASSERT_EQ(m.activeInstance(), "K3");
  const auto last = morphTopology(m, "t 3.75");
  EXPECT_EQ(last.eulerCharacteristic, target.eulerCharacteristic);
  EXPECT_EQ(last.components, target.components);
  expectKept("Target", x.target, target, { 4.0, 4.25, 4.75, 5.5 }, "K4", "K5");
}

// T-5.5 item 5 in the model: with the weight map sourceTop the vertices of the higher z (in the
// file) reach the stand-in first. Frames every 0.02 through K2; a vertex is done at the first
// frame where its distance to the posed stand-in is below 1e-6 (world units).
TEST(EngineSkeleton, TheWeightMapCollapsesTheTopFirst)
{
  if (!skin::canReadSkinnedMeshFiles())
    GTEST_SKIP() << "built without Assimp";
  const Metamorphosis x;
  engine::DynamicModel m = engine::DynamicModel::load(Write("metamorphosis.icm", x.text).string());
  const std::size_t n = x.source.vertexCount();
  std::vector<double> done(n, -1);
  m.advanceTo(1.0, 0.25);
  for (double t = 1.02; t < 1.5 + 1e-9; t += 0.02)
  {
    m.advanceTo(t, 0.02);
    if (m.activeInstance() != "K2")
      break;
    const auto cells = m.cells();
    const auto& shape = *CellOf(cells, "Source").shape;
    const auto field = Metamorphosis::posedField(x.source, x.sourceStandIn, t);
    const auto e = field->evaluator();
    for (std::size_t i = 0; i < n; ++i)
    {
      Vec3 g{ 0, 0, 0 };
      const double f = e->gradient(shape.parts[0].points[i], g);
      // The placement scales by 0.01: world distance = 0.01 |F| / |grad F|.
      if (done[i] < 0 && 0.01 * std::abs(f) / std::sqrt(ictk::frep::dot(g, g)) < 1e-6)
        done[i] = t;
    }
  }
  // The vertices of the top tenth of z (in the file, u_i >= 0.9) and of the bottom tenth: the top
  // is done when alpha_i = 1, by alpha = 1 - 0.5 * 0.9 = 0.55 (smoothstep(2 (t - 1)) = 0.55 at
  // t = 1.2667: the frame 1.28); the bottom only as alpha nears 1 (u_i <= 0.1: alpha >= 0.95,
  // t >= 1.43).
  double zmin = 1e9, zmax = -1e9;
  for (const Vec3& p : x.source.restPoints)
  {
    zmin = std::min(zmin, p[2]);
    zmax = std::max(zmax, p[2]);
  }
  double topLast = 0, bottomFirst = 2;
  int top = 0, bottom = 0, inversions = 0, pairs = 0;
  for (std::size_t i = 0; i < n; ++i)
  {
    const double u = (x.source.restPoints[i][2] - zmin) / (zmax - zmin);
    const double when = done[i] < 0 ? 2.0 : done[i];
    if (u >= 0.9)
    {
      ++top;
      topLast = std::max(topLast, when);
    }
    if (u <= 0.1)
    {
      ++bottom;
      bottomFirst = std::min(bottomFirst, when);
    }
    for (std::size_t j = 0; j < n; ++j)
    {
      const double uj = (x.source.restPoints[j][2] - zmin) / (zmax - zmin);
      if (uj > u + 0.1)
      {
        ++pairs;
        inversions += (done[j] < 0 ? 2.0 : done[j]) > when;
      }
    }
  }
  std::printf("%d top vertices done by t = %.2f, %d bottom ones from t = %.2f; %d of %d pairs "
              "0.1 apart in u done in the wrong order\n",
    top, topLast, bottom, bottomFirst, inversions, pairs);
  EXPECT_GT(top, 0);
  EXPECT_GT(bottom, 0);
  EXPECT_LE(topLast, 1.28 + 1e-9);
  EXPECT_GE(bottomFirst, 1.42);
  EXPECT_EQ(inversions, 0);
}

// T-5.5 item 6 in the complex: a skinned cell's normals go with its points as "Normals", and a
// non-uniform placement, scale(2, 1, 1), maps them by its inverse transpose diag(1/2, 1, 1)
// (normalised), not by the scale itself. At t = 1 the upper joint has turned an eighth about z:
// the normals there are no longer along the axes, where the two would agree.
TEST(EngineSkeleton, TheComplexCarriesTheNormalsByTheInverseTranspose)
{
  if (!skin::canReadSkinnedMeshFiles())
    GTEST_SKIP() << "built without Assimp";
  engine::DynamicModel m = engine::DynamicModel::load(Write("normals.icm",
    "CELLS { A { type = B-CELL; shape = loadMesh(\"" + Tube() +
      "\", \"walk\"); dim = 2D; parameters { scale(2, 1, 1); } } }\nK { CELLS { A; } }\n")
                                                        .string());
  m.advanceTo(1.0, 0.5);
  const auto cells = m.cells();
  const auto& part = CellOf(cells, "A").shape->parts[0];
  const ictk::complex::Complex cx = m.complex();
  const auto& g = std::get<ictk::complex::ExplicitGeometry>(cx.cell(0).geometry);
  auto normalsOf = [](const std::vector<ictk::discretize::PointArray>& arrays)
  {
    for (const auto& a : arrays)
      if (a.name == "Normals")
        return a.values;
    return std::vector<double>{};
  };
  const std::vector<double> local = normalsOf(part.pointData), world = normalsOf(g.pointData);
  ASSERT_EQ(local.size(), 3 * part.points.size());
  ASSERT_EQ(world.size(), local.size());
  double apartFromTheScale = 0;
  for (std::size_t i = 0; i < local.size(); i += 3)
  {
    const Vec3 n{ 0.5 * local[i], local[i + 1], local[i + 2] };
    const double k = std::sqrt(ictk::frep::dot(n, n));
    for (std::size_t c = 0; c < 3; ++c)
      EXPECT_NEAR(world[i + c], n[c] / k, 1e-15) << "vertex " << i / 3;
    const Vec3 byScale{ 2 * local[i], local[i + 1], local[i + 2] };
    const double s = std::sqrt(ictk::frep::dot(byScale, byScale));
    apartFromTheScale = std::max(apartFromTheScale, std::abs(world[i] - byScale[0] / s));
  }
  EXPECT_GT(apartFromTheScale, 0.1);
}

// What cannot work is refused at its place: a weight map that names no function or a function
// of the wrong arity or is not quoted, a spread outside [0, 1), a mesh cell with no stand-in, a
// projection built-in on a cell that is not a mesh.
TEST(EngineSkeleton, TheCheckerRefusesABadProjection)
{
  if (!skin::canReadSkinnedMeshFiles())
    GTEST_SKIP() << "built without Assimp";
  // Line 4 holds the call; the error's column is that of `mark` in it.
  auto model = [&](const std::string& call, bool standIn = true)
  {
    return "function w2(real x, real y) { return x; }\n"
           "function top(real x, real y, real z) { return y; }\n"
           "CELLS { A { type = B-CELL; shape = loadMesh(\"" +
      Tube() +
      "\", \"walk\"); dim = 2D;\n"
      "  REACTIONS { update(REAL g, REAL l, REAL f, REAL dt) { " +
      call +
      "; } } }\n"
      "  B { type = F-CELL; shape = sphere(1); dim = 3D; }\n" +
      (standIn ? "  S { type = F-CELL; shape = standIn(A); dim = 3D; }\n" : "") + "}\n" +
      "K { CELLS { A B" + (standIn ? " S" : "") + "; } }\n";
  };
  auto at = [](const std::string& call, const std::string& mark)
  {
    const std::string line = "  REACTIONS { update(REAL g, REAL l, REAL f, REAL dt) { " + call;
    return "4:" + std::to_string(line.find(mark) + 1);
  };
  struct Case
  {
    std::string call, mark, message;
    bool standIn = true;
  };
  for (const Case& c : std::vector<Case>{
         { "setProjection(A, 0.5, \"nothing\")", "\"nothing\"",
           "setProjection: no model function named 'nothing'" },
         { "setProjection(A, 0.5, \"w2\")", "\"w2\"",
           "setProjection: function 'w2' takes 2 argument(s), and a weight map takes the "
           "bind-pose position (x, y, z)" },
         { "setProjection(A, 0.5, 3)", "3",
           "setProjection's weight map is the name of a model "
           "function, in quotes" },
         { "setProjection(A, 0.5, \"top\", 1.5)", "1.5",
           "setProjection: the spread of the delays is in [0, 1)" },
         { "setProjection(A, 0.5)", "A,", "setProjection: no cell is the stand-in of 'A'", false },
         { "real r = projectionResidual(B)", "B)",
           "projectionResidual takes a skinned mesh cell, and cell 'B' is not one" },
       })
  {
    const std::string e = ErrorOf(model(c.call, c.standIn));
    EXPECT_EQ(e.substr(0, e.find(' ')), at(c.call, c.mark)) << e;
    EXPECT_NE(e.find(c.message), std::string::npos) << e;
  }
  // A good call passes.
  EXPECT_EQ(ErrorOf(model("setProjection(A, 0.5, \"top\", 0.25)")), "no error");
}

// Appendix B's model, Data/Models/icm/standin.icm: BCN_Epileptic carried along +x out of the
// liquid box x in [-1, 0.6], y in [-1.1, 0], z in [-0.7, 0.7]. ANDY_WITHIN_BOX holds while a
// vertex of the mesh may be in the box, ANDY_OUT_OF_BOX from the switch on, with the blend's a0
// the honey preset's 0.5 / (1 + (d / 0.25)^2) of the stand-in's distance d to the box.
TEST(EngineStandInModel, TheCharacterWalksOutOfTheLiquidBox)
{
  if (!skin::canReadSkinnedMeshFiles())
    GTEST_SKIP() << "built without Assimp";
  engine::DynamicModel m =
    engine::DynamicModel::load(std::string(ICTK_DATA_DIR) + "/Models/icm/standin.icm");
  auto insideBox = [](const Vec3& p)
  {
    return p[0] >= -1 && p[0] <= 0.6 && p[1] >= -1.1 && p[1] <= 0 && std::abs(p[2]) <= 0.7;
  };
  int transitions = 0;
  double switchTime = -1, lastInside = -1;
  for (double t = 0; t <= 4 + 1e-9; t += 0.5)
  {
    for (const engine::FrameRecord& r : m.advanceTo(t, 0.5))
      if (r.transition && r.time > 0) // the first record chooses the initial instance
      {
        ++transitions;
        switchTime = r.time;
        EXPECT_EQ(r.instance, "ANDY_OUT_OF_BOX");
      }
    const ictk::complex::Complex cx = m.complex();
    const std::vector<engine::CellState> cells = m.cells();
    std::size_t andy = cells.size();
    for (std::size_t i = 0; i < cells.size(); ++i)
      if (cells[i].name == "Andy")
        andy = i;
    ASSERT_LT(andy, cells.size());
    const auto& mesh = std::get<ictk::complex::ExplicitGeometry>(cx.cell(andy).geometry);
    ASSERT_EQ(mesh.points.size(), 3938u);
    const auto inside = std::count_if(mesh.points.begin(), mesh.points.end(), insideBox);
    if (inside > 0)
      lastInside = t;
    const std::string instance = m.activeInstance();
    // The switch only once the mesh is out: no vertex in the box after it.
    if (instance == "ANDY_OUT_OF_BOX")
    {
      EXPECT_EQ(inside, 0) << "t " << t;
    }
    // The blend follows the distance by the honey preset.
    const double d = m.value("distanceToBox").number;
    const double x = std::max(d, 0.0) / 0.25;
    EXPECT_NEAR(m.value("Liquid_on_Andy.blendDensity").number, 0.5 / (1 + x * x), 1e-12)
      << "t " << t;
    std::printf("t %.1f %s: %ld vertices in the box, distance %.4f, a0 %.4f\n", t, instance.c_str(),
      static_cast<long>(inside), d, m.value("Liquid_on_Andy.blendDensity").number);
  }
  EXPECT_EQ(transitions, 1);
  EXPECT_GT(switchTime, lastInside);
  EXPECT_LT(switchTime, 4.0);
  std::printf("switch at %.4f; last frame with a vertex in the box %.1f\n", switchTime, lastInside);
}
