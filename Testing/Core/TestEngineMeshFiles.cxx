// SPDX-License-Identifier: BSD-3-Clause
// Mesh files as B-cells (issue 16): `shape = file("cube.off")` / `file("tetra.obj")` (and .ply,
// .stl) are read by
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

#include <algorithm>
#include <cstring>
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

namespace
{

// The unit cube of cube.off as 12 outward triangles (each quad a, b, c, d as a b c, a c d).
const double kCorners[8][3] = { { -0.5, -0.5, -0.5 }, { 0.5, -0.5, -0.5 }, { 0.5, 0.5, -0.5 },
  { -0.5, 0.5, -0.5 }, { -0.5, -0.5, 0.5 }, { 0.5, -0.5, 0.5 }, { 0.5, 0.5, 0.5 },
  { -0.5, 0.5, 0.5 } };
const int kQuads[6][4] = { { 0, 3, 2, 1 }, { 4, 5, 6, 7 }, { 0, 1, 5, 4 }, { 2, 3, 7, 6 },
  { 1, 2, 6, 5 }, { 0, 4, 7, 3 } };

std::vector<std::array<int, 3>> cubeTriangles()
{
  std::vector<std::array<int, 3>> t;
  for (const auto& q : kQuads)
  {
    t.push_back({ q[0], q[1], q[2] });
    t.push_back({ q[0], q[2], q[3] });
  }
  return t;
}

template <typename T>
void put(std::ostream& out, T v, bool bigEndian)
{
  unsigned char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  if (bigEndian) // the test machines are little-endian (x86-64, arm64)
    std::reverse(b, b + sizeof(T));
  out.write(reinterpret_cast<const char*>(b), sizeof(T));
}

/// The cube as ASCII and binary .ply (with a normal per vertex, a colour per face, and an edge
/// element the reader must skip) and ASCII and binary .stl.
void writeCubes(const fs::path& dir)
{
  const auto tris = cubeTriangles();
  {
    std::ofstream out(dir / "cube_ascii.ply");
    out << "ply\nformat ascii 1.0\ncomment a unit cube\nelement vertex 8\nproperty float x\n"
           "property float y\nproperty float z\nproperty float nx\nelement face 6\n"
           "property list uchar int vertex_indices\nproperty uchar red\nend_header\n";
    for (const auto& c : kCorners)
      out << c[0] << " " << c[1] << " " << c[2] << " 0\n";
    for (const auto& q : kQuads)
      out << "4 " << q[0] << " " << q[1] << " " << q[2] << " " << q[3] << " 255\n";
  }
  for (const bool big : { false, true })
  {
    std::ofstream out(dir / (big ? "cube_big.ply" : "cube_little.ply"), std::ios::binary);
    out << "ply\nformat " << (big ? "binary_big_endian" : "binary_little_endian")
        << " 1.0\nelement vertex 8\nproperty double x\nproperty double y\nproperty float z\n"
           "property uchar flag\nelement face 12\nproperty list uchar uint vertex_indices\n"
           "element edge 1\nproperty int vertex1\nproperty int vertex2\nend_header\n";
    for (const auto& c : kCorners)
    {
      put(out, c[0], big);
      put(out, c[1], big);
      put(out, static_cast<float>(c[2]), big);
      put(out, std::uint8_t{ 7 }, big);
    }
    for (const auto& t : tris)
    {
      put(out, std::uint8_t{ 3 }, big);
      for (int k : t)
        put(out, static_cast<std::uint32_t>(k), big);
    }
    put(out, std::int32_t{ 0 }, big);
    put(out, std::int32_t{ 1 }, big);
  }
  {
    std::ofstream out(dir / "cube_ascii.stl");
    out << "solid cube\n";
    for (const auto& t : tris)
    {
      out << "  facet normal 0 0 0\n    outer loop\n";
      for (int k : t)
        out << "      vertex " << kCorners[k][0] << " " << kCorners[k][1] << " " << kCorners[k][2]
            << "\n";
      out << "    endloop\n  endfacet\n";
    }
    out << "endsolid cube\n";
  }
  {
    // A binary .stl whose header starts with "solid", as many exporters write.
    std::ofstream out(dir / "cube_binary.stl", std::ios::binary);
    std::string header = "solid cube, binary";
    header.resize(80, ' ');
    out << header;
    put(out, static_cast<std::uint32_t>(tris.size()), false);
    for (const auto& t : tris)
    {
      for (int k = 0; k < 3; ++k)
        put(out, 0.0f, false);
      for (int k : t)
        for (int a = 0; a < 3; ++a)
          put(out, static_cast<float>(kCorners[k][a]), false);
      put(out, std::uint16_t{ 0 }, false);
    }
  }
}

/// Area and enclosed volume (divergence theorem: the sum of p0 . (p1 x p2) / 6) of a surface.
std::pair<double, double> areaAndVolume(const ictk::complex::ExplicitGeometry& g)
{
  double area = 0, volume = 0;
  for (const auto& t : g.triangles)
  {
    const auto &a = g.points[t[0]], &b = g.points[t[1]], &c = g.points[t[2]];
    const double u[3] = { b[0] - a[0], b[1] - a[1], b[2] - a[2] };
    const double v[3] = { c[0] - a[0], c[1] - a[1], c[2] - a[2] };
    const double n[3] = { u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
      u[0] * v[1] - u[1] * v[0] };
    area += 0.5 * std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    volume += (a[0] * (b[1] * c[2] - b[2] * c[1]) + a[1] * (b[2] * c[0] - b[0] * c[2]) +
                a[2] * (b[0] * c[1] - b[1] * c[0])) /
      6.0;
  }
  return { area, volume };
}

} // namespace

// Issue 16: .ply (ASCII, binary little- and big-endian) and .stl (ASCII, binary) read as the
// unit cube: 8 points (the .stl's 36 corners welded), 12 triangles, area 6, volume 1.
TEST(MeshFiles, ReadsPlyAndStl)
{
  const fs::path dir = Folder();
  writeCubes(dir);
  for (const char* name :
    { "cube_ascii.ply", "cube_little.ply", "cube_big.ply", "cube_ascii.stl", "cube_binary.stl" })
  {
    SCOPED_TRACE(name);
    const ictk::complex::ExplicitGeometry g = ictk::lang::readMeshFile((dir / name).string());
    EXPECT_EQ(g.points.size(), 8u);
    EXPECT_EQ(g.triangles.size(), 12u);
    const auto [area, volume] = areaAndVolume(g);
    EXPECT_NEAR(area, 6.0, 1e-12);
    EXPECT_NEAR(volume, 1.0, 1e-12);
  }
  // Bad files name what is wrong.
  std::ofstream(dir / "bad.ply") << "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
                                    "property float y\nend_header\n0 0\n";
  std::ofstream(dir / "bad.stl") << "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n"
                                    "vertex 1 0 0\nendloop\nendfacet\nendsolid\n";
  std::ofstream(dir / "bad_index.ply") << "ply\nformat ascii 1.0\nelement vertex 3\n"
                                          "property float x\nproperty float y\nproperty float z\n"
                                          "element face 1\nproperty list uchar int vertex_indices\n"
                                          "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 5\n";
  const std::pair<const char*, const char*> bad[] = { { "bad.ply", "no x, y and z properties" },
    { "bad.stl", "fewer than 3" }, { "bad_index.ply", "a face uses vertex 6 of 3" } };
  for (const auto& [name, message] : bad)
  {
    try
    {
      ictk::lang::readMeshFile((dir / name).string());
      ADD_FAILURE() << name << " was read";
    }
    catch (const ictk::lang::ParseError& e)
    {
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    }
  }
}

// Each format as the shape of a running model's B-cell, scaled by 2: area 24 in every frame.
TEST(MeshFiles, PlyAndStlCellsRunInFrames)
{
  const fs::path dir = Folder();
  writeCubes(dir);
  std::string cells, names;
  const char* files[] = { "cube_ascii.ply", "cube_big.ply", "cube_binary.stl", "cube_ascii.stl" };
  for (int i = 0; i < 4; ++i)
  {
    cells += "  C" + std::to_string(i) + " { type = B-CELL; shape = file(\"" + files[i] +
      "\"); dim = 2D; parameters { scale(2, 2, 2); } }\n";
    names += " C" + std::to_string(i);
  }
  const fs::path path = dir / "formats.icm";
  std::ofstream(path) << "TIMESPANS { film : TIMESPAN(0, 1); }\nCELLS {\n"
                      << cells << "}\nK { CELLS {" << names << "; } }\n";
  engine::FrameSequenceOptions options;
  options.times = { 0.0, 1.0 };
  options.discretization.featureSize = 0.1;
  engine::FrameSequence frames(path.string(), options);
  for (std::size_t f = 0; f < 2; ++f)
  {
    const engine::Frame frame = frames.frame(f);
    ASSERT_EQ(frame.mesh.cells.size(), 4u);
    for (std::size_t i = 0; i < 4; ++i)
      EXPECT_NEAR(ictk::discretize::surfaceArea(frame.mesh.cells[i].surface), 24.0, 1e-9)
        << files[i];
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
  e = error("vtp.icm", "CELLS {\n  A { type = B-CELL; shape = file(\"a.vtp\"); dim = 2D; }\n}\n");
  EXPECT_EQ(e.substr(0, e.find(' ')), "2:35") << e;
  EXPECT_NE(e.find("save a .vtp surface as .ply or .stl"), std::string::npos) << e;
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
