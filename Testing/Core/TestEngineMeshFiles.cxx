// SPDX-License-Identifier: BSD-3-Clause
// Mesh files as B-cells (issue 16): `shape = file("cube.off")` / `file("tetra.obj")` are read by
// Lang/MeshFile.h (faces triangulated as fans) and become explicit 2D cells of the complex, their
// points moved by the cell's placement every frame. A unit cube scaled by 2 and translated by
// (1, 2, 3) has 8 points at (1 +- 1, 2 +- 1, 3 +- 1), 12 triangles and an area of 6 x 2^2 = 24.
// The checker refuses a mesh cell as a query's or a blend's argument, at its place; the engine
// refuses a mesh cell that is not `dim = 2D` and a malformed file, naming its line.

#include "Discretize/Mesh.h"
#include "Engine/FrameSequence.h"
#include "Lang/Icm.h"
#include "Lang/MeshFile.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace
{
namespace engine = ictk::engine;
namespace fs = std::filesystem;

fs::path Folder()
{
  // One folder per test: ctest runs the tests of this file in parallel processes.
  const fs::path dir = fs::temp_directory_path() / "ictk_engine_mesh_files" /
    ::testing::UnitTest::GetInstance()->current_test_info()->name();
  fs::create_directories(dir);
  // A unit cube, six quads (two triangles each), with a comment and the counts on their own line.
  std::ofstream(dir / "cube.off") << "OFF\n# a unit cube\n8 6 12\n"
                                     "-0.5 -0.5 -0.5\n0.5 -0.5 -0.5\n0.5 0.5 -0.5\n-0.5 0.5 -0.5\n"
                                     "-0.5 -0.5 0.5\n0.5 -0.5 0.5\n0.5 0.5 0.5\n-0.5 0.5 0.5\n"
                                     "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 2 3 7 6\n4 1 2 6 5\n"
                                     "4 0 4 7 3\n";
  // A tetrahedron with the corner forms v, v/vt, v//vn, v/vt/vn and negative indices.
  std::ofstream(dir / "tetra.obj") << "# a tetrahedron\no tetra\nv 0 0 0\nv 1 0 0\nv 0 1 0\n"
                                      "v 0 0 1\nvt 0 0\nvn 0 0 1\n"
                                      "f 1 3 2\nf 1/1 2/1 4/1\nf 1//1 4//1 3//1\nf -3/1/1 -2 -1\n";
  std::ofstream(dir / "broken.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 zero\nf 1 2 3\n";
  return dir;
}

engine::DynamicModel Load(const std::string& name, const std::string& text)
{
  const fs::path path = Folder() / name;
  std::ofstream(path) << text;
  return engine::DynamicModel::load(path.string());
}

const char* kCube = R"(name = CUBE;
TIMESPANS { film : TIMESPAN(0, 1); }
CELLS {
  Cube {
    type = B-CELL;
    shape = file("cube.off");
    dim = 2D;
    parameters {
      translation(1, 2, 3);
      scale(2, 2, 2);
    }
    REACTIONS {
      update(REAL globalT, REAL localT, REAL lifeT, REAL dt) { translation.x += dt; }
    }
  }
  Tetra { type = B-CELL; shape = file("tetra.obj"); dim = 2D; }
}
K { CELLS { Cube Tetra; } }
)";

} // namespace

TEST(MeshFiles, ReadsObjAndOffTriangulated)
{
  const fs::path dir = Folder();
  const ictk::complex::ExplicitGeometry cube =
    ictk::lang::readMeshFile((dir / "cube.off").string());
  EXPECT_EQ(cube.points.size(), 8u);
  EXPECT_EQ(cube.triangles.size(), 12u);
  EXPECT_EQ(cube.points[6], (ictk::frep::Point3{ 0.5, 0.5, 0.5 }));
  const ictk::complex::ExplicitGeometry tetra =
    ictk::lang::readMeshFile((dir / "tetra.obj").string());
  ASSERT_EQ(tetra.points.size(), 4u);
  ASSERT_EQ(tetra.triangles.size(), 4u);
  EXPECT_EQ(tetra.triangles[1], (std::array<std::uint32_t, 3>{ 0, 1, 3 }));
  EXPECT_EQ(tetra.triangles[3], (std::array<std::uint32_t, 3>{ 1, 2, 3 })); // -3 -2 -1
  try
  {
    ictk::lang::readMeshFile((dir / "broken.obj").string());
    FAIL() << "a malformed .obj was read";
  }
  catch (const ictk::lang::ParseError& e)
  {
    EXPECT_EQ(e.diagnostics().at(0).where.line, 3);
    EXPECT_NE(std::string(e.what()).find("z is not a finite number: 'zero'"), std::string::npos)
      << e.what();
  }
}

TEST(MeshFiles, AreExplicitCellsMovedByTheirPlacement)
{
  engine::DynamicModel m = Load("cube.icm", kCube);
  for (double t : { 0.0, 0.5 })
  {
    m.advanceTo(t, 0.25);
    const ictk::complex::Complex cx = m.complex();
    ASSERT_EQ(cx.cellCount(), 2u);
    const ictk::complex::Cell& cube = cx.cell(0);
    EXPECT_EQ(cube.name, "Cube");
    EXPECT_EQ(cube.kind, ictk::complex::CellKind::BRep);
    EXPECT_EQ(cube.dimension, 2);
    const auto& g = std::get<ictk::complex::ExplicitGeometry>(cube.geometry);
    ASSERT_EQ(g.points.size(), 8u);
    EXPECT_EQ(g.triangles.size(), 12u);
    // Local (-0.5, -0.5, -0.5) and (0.5, 0.5, 0.5), scaled by 2, moved by (1 + t, 2, 3).
    for (int a = 0; a < 3; ++a)
    {
      const double c = (a == 0 ? 1 + t : a == 1 ? 2 : 3);
      EXPECT_NEAR(g.points[0][a], c - 1, 1e-12) << "t = " << t;
      EXPECT_NEAR(g.points[6][a], c + 1, 1e-12) << "t = " << t;
    }
    const auto& tetra = std::get<ictk::complex::ExplicitGeometry>(cx.cell(1).geometry);
    EXPECT_EQ(tetra.points.size(), 4u);
    EXPECT_EQ(tetra.triangles.size(), 4u);
  }
}

TEST(MeshFiles, FramesDiscretiseThemAsTheirTriangles)
{
  engine::FrameSequenceOptions options;
  options.times = { 0.0, 1.0 };
  options.discretization.featureSize = 0.1;
  const fs::path path = Folder() / "cube_frames.icm";
  std::ofstream(path) << kCube;
  engine::FrameSequence frames(path.string(), options);
  for (std::size_t i = 0; i < 2; ++i)
  {
    const engine::Frame f = frames.frame(i);
    ASSERT_EQ(f.mesh.cells.size(), 2u);
    EXPECT_NEAR(ictk::discretize::surfaceArea(f.mesh.cells[0].surface), 24.0, 1e-9);
    // The tetrahedron's faces: three right triangles of area 1/2 and one of sqrt(3)/2.
    EXPECT_NEAR(
      ictk::discretize::surfaceArea(f.mesh.cells[1].surface), 1.5 + std::sqrt(3.0) / 2, 1e-9);
    double xmin = 1e9;
    for (const auto& p : f.mesh.cells[0].surface.points)
      xmin = std::min(xmin, p[0]);
    EXPECT_NEAR(xmin, f.time, 1e-12); // 1 + t - 1
  }
}

TEST(MeshFiles, CheckerAndEngineRefuseWhatTheyCannotDo)
{
  auto error = [](const std::string& name, const std::string& text)
  {
    try
    {
      Load(name, text);
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
    return std::string("no error");
  };
  const std::string cells = "CELLS {\n"
                            "  A { type = B-CELL; shape = file(\"cube.off\"); dim = 2D; }\n"
                            "  B { type = F-CELL; shape = sphere(1); dim = 3D; }\n";
  // A query with a mesh cell: line 7, column 26 is the A of distance(B, A).
  std::string e = error("query.icm",
    cells +
      "}\nK { CELLS { A B; }\n  REACTIONS { update(REAL g, REAL l, REAL f, REAL dt) { "
      "\n    real d = distance(B, A); } } }\n");
  EXPECT_EQ(e.substr(0, e.find(' ')), "7:26") << e;
  EXPECT_NE(e.find("'distance' does not take meshes"), std::string::npos) << e;
  e = error("blend.icm",
    cells +
      "  C { type = T-CELL; shape = blend(B, A, 0.5); dim = 3D; }\n}\nK { CELLS { A B C; } }\n");
  EXPECT_EQ(e.substr(0, e.find(' ')), "4:39") << e;
  EXPECT_NE(e.find("is a mesh"), std::string::npos) << e;
  e = error("stl.icm", "CELLS {\n  A { type = B-CELL; shape = file(\"a.stl\"); dim = 2D; }\n}\n");
  EXPECT_EQ(e.substr(0, e.find(' ')), "2:35") << e;
  e = error("dim.icm",
    "CELLS {\n  A { type = B-CELL;\n    shape = file(\"cube.off\");\n    dim = 3D; }\n}\nK { CELLS "
    "{ A; } }\n");
  EXPECT_EQ(e.substr(0, e.find(' ')), "4:5") << e;
  EXPECT_NE(e.find("dim = 2D"), std::string::npos) << e;
  e = error("broken.icm",
    "CELLS {\n  A { type = B-CELL; shape = file(\"broken.obj\"); dim = 2D; }\n}\nK { CELLS { A; } "
    "}\n");
  EXPECT_EQ(e.substr(0, e.find(' ')), "2:30") << e;
  EXPECT_NE(e.find("broken.obj:3"), std::string::npos) << e;
}
