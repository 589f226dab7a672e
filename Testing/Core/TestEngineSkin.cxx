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

// Data/Models/icm/metamorphosis.icm (thesis 5.5): K1 the source mesh, K2 it moving onto its
// stand-in, K3 the space-time blend of the two stand-ins, K4 the destination leaving its
// stand-in, K5 the destination mesh. Read here with the two stand-ins also shown in K3, so that
// the blend can be compared with them.
TEST(EngineSkeleton, TheMetamorphosisGoesFromTheSourceMeshToTheDestinationMesh)
{
  if (!skin::canReadSkinnedMeshFiles())
    GTEST_SKIP() << "built without Assimp";
  std::ifstream in(std::string(ICTK_DATA_DIR) + "/Models/icm/metamorphosis.icm");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  text.replace(text.find("\"skinned_tube.gltf\""), 19, "\"" + Tube() + "\"");
  text.replace(text.find("CELLS { Morph; }"), 16, "CELLS { Morph Source_standIn Target_standIn; }");
  engine::DynamicModel m = engine::DynamicModel::load(Write("metamorphosis.icm", text).string());
  const skin::SkinnedMesh source =
    skin::readSkinnedMesh(std::string(ICTK_ASSIMP_MODELS) + "/FBX/huesitos.fbx");
  const skin::SkinnedMesh target = skin::readSkinnedMesh(Tube());
  const auto sourcePlace =
    ictk::geometry::Affine::fromTransform({ -1.6, -2.7, 2.6 }, { 0, 0, 0 }, { 0.01, 0.01, 0.01 });
  const auto targetPlace =
    ictk::geometry::Affine::fromTransform({ 0, -2.5, 0 }, { 0, 0, 0 }, { 2.5, 2.5, 2.5 });
  // The projections the engine makes, made again with the library: in the bind pose every
  // vertex ends on its stand-in (|F| < 1e-9).
  auto projectionOf = [](const skin::SkinnedMesh& mesh)
  {
    return skin::projectOntoStandIn(mesh, skin::fittedStandIn(mesh));
  };
  const skin::Projection sourceProjection = projectionOf(source);
  const skin::Projection targetProjection = projectionOf(target);
  EXPECT_EQ(sourceProjection.failures, 0);
  EXPECT_LT(sourceProjection.maxResidual, 1e-9);
  EXPECT_EQ(targetProjection.failures, 0);
  EXPECT_LT(targetProjection.maxResidual, 1e-9);
  // A mesh cell's world points against the library's skinning of the given rest points.
  auto expectMesh = [&](const std::string& cell, const skin::SkinnedMesh& mesh,
                      const ictk::geometry::Affine& place, double t, const std::vector<Vec3>& rest)
  {
    const auto cells = m.cells();
    const auto& shape = *CellOf(cells, cell).shape;
    const auto posed = skin::skin(
      mesh, skin::jointMatrices(mesh, skin::poseNodes(mesh, &mesh.animations[0], t)), rest);
    ASSERT_EQ(shape.parts[0].points.size(), posed.points.size());
    for (std::size_t i = 0; i < posed.points.size(); ++i)
    {
      const Vec3 got = shape.place.apply(shape.parts[0].points[i]);
      const Vec3 want = place.apply(posed.points[i]);
      for (int c = 0; c < 3; ++c)
        ASSERT_NEAR(got[c], want[c], 1e-9 * (1 + std::abs(want[c]))) << cell << " t " << t;
    }
  };
  // K1: the plain animated source.
  m.advanceTo(0.5, 0.25);
  EXPECT_EQ(m.activeInstance(), "K1");
  expectMesh("Source", source, sourcePlace, 0.5, source.restPoints);
  // K2, alpha = 1 from t = 1.5: the source on its stand-in, still skinned.
  m.advanceTo(1.75, 0.25);
  EXPECT_EQ(m.activeInstance(), "K2");
  expectMesh(
    "Source", source, sourcePlace, 1.75, skin::projectedRestPoints(source, sourceProjection, 1.0));
  // K3: the blend is the source's stand-in at t0 = 2 and the destination's from t1 = 3.5 (the
  // same inside and outside on a grid).
  for (const auto& [t, operand] : { std::pair<double, const char*>{ 2.0, "Source_standIn" },
         std::pair<double, const char*>{ 3.75, "Target_standIn" } })
  {
    m.advanceTo(t, 0.25);
    EXPECT_EQ(m.activeInstance(), "K3");
    const auto cells = m.cells();
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
            << t << " at " << x << " " << y << " " << z;
        }
    EXPECT_GT(inside, 10) << t;
  }
  // K4, alpha = 1 until t = 4: the destination on its stand-in; K5: the plain destination.
  m.advanceTo(4.0, 0.25);
  EXPECT_EQ(m.activeInstance(), "K4");
  expectMesh(
    "Target", target, targetPlace, 4.0, skin::projectedRestPoints(target, targetProjection, 1.0));
  m.advanceTo(5.5, 0.25);
  EXPECT_EQ(m.activeInstance(), "K5");
  expectMesh("Target", target, targetPlace, 5.5, target.restPoints);
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
