// SPDX-License-Identifier: BSD-3-Clause
// Skinned meshes as B-cells (issue 17; thesis Appendix B's Andy): `shape = loadMesh("file",
// "animation")` is a 2D explicit cell whose points are the mesh posed by the animation at the
// cell's time (the model's, or the cell's `timespan` clock), moved by its placement; the built-in
// jointPosition(cell, "joint") gives a joint's place in the world. glTF2/simple_skin (Debian's
// assimp-testmodels, read where the package puts it) is small enough to pose by hand: at 1 s its
// upper joint has turned a quarter about z, and the top-left vertex (0, 2) is at (-1, 0.5). The
// checker refuses a missing file, an animation the file does not have, a joint its skeleton does
// not have, and a query on a skinned cell, at their places.

#include "Engine/DynamicModel.h"
#include "Engine/FrameSequence.h"
#include "Lang/Icm.h"
#include "Skin/SkinFile.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace
{
namespace engine = ictk::engine;
namespace fs = std::filesystem;

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
  // A character whose surface is not a manifold (vertices where separate fans meet): a B-cell
  // cannot be one.
  const std::string epileptic = std::string(ICTK_ASSIMP_MODELS) + "/X/BCN_Epileptic.X";
  e = ErrorOf(head + "\"" + epileptic + "\", \"Epileptisch\"" + tail);
  EXPECT_EQ(e.substr(0, e.find(' ')), "2:39") << e;
  EXPECT_NE(e.find("not a manifold (0 edge(s) shared by more than two triangles, 266 vertex(es)"),
    std::string::npos)
    << e;
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
