// SPDX-License-Identifier: BSD-3-Clause
// The TetGen backend (issue 6): volumes, conforming material interfaces, determinism, errors.
#include "Complex/Complex.h"
#include "FRep/Expr.h"
#include "Mesh/Quality.h"
#include "Mesh/TetGen/MeshTetGen.h"
#include "MeshTestModels.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace
{

using namespace ictk;
using complex::Cell;
using frep::Expr;
using frep::Point3;

Expr boxExpr(const Point3& lo, const Point3& hi)
{
  const Expr x = Expr::x(), y = Expr::y(), z = Expr::z();
  auto c = [](double v)
  {
    return Expr::constant(v);
  };
  return min(min(min(x - c(lo[0]), c(hi[0]) - x), min(y - c(lo[1]), c(hi[1]) - y)),
    min(z - c(lo[2]), c(hi[2]) - z));
}

Cell block(const std::string& name, const Point3& lo, const Point3& hi, double priority = 0)
{
  Cell cell = complex::frepCell(name, {}, { boxExpr(lo, hi) }, { lo, hi });
  cell.priority = priority;
  return cell;
}

Cell ball(const std::string& name, const Point3& c, double r, double priority = 0)
{
  const Expr dx = Expr::x() - Expr::constant(c[0]);
  const Expr dy = Expr::y() - Expr::constant(c[1]);
  const Expr dz = Expr::z() - Expr::constant(c[2]);
  Cell cell = complex::frepCell(name, {}, { Expr::constant(r) - sqrt(dx * dx + dy * dy + dz * dz) },
    { { c[0] - r, c[1] - r, c[2] - r }, { c[0] + r, c[1] + r, c[2] + r } });
  cell.priority = priority;
  return cell;
}

double volume(const mesh::TetMesh& m, std::size_t t)
{
  const auto& tet = m.tetrahedra[t];
  return mesh::tetShape(m.points[tet[0]], m.points[tet[1]], m.points[tet[2]], m.points[tet[3]])
    .volume;
}

double materialVolume(const mesh::TetMesh& m, int material)
{
  double v = 0;
  for (std::size_t t = 0; t < m.tetrahedra.size(); ++t)
  {
    v += m.materials[t] == material ? volume(m, t) : 0;
  }
  return v;
}

TEST(MeshTetGen, SphereVolume)
{
  complex::Complex k;
  k.addCell(ball("sphere", { 0, 0, 0 }, 1));
  mesh::TetraOptions o;
  o.size = 0.1;
  mesh::TetGenReport report;
  const mesh::TetMesh m = mesh::tetrahedralizeTetGen(k, o, &report);
  EXPECT_NO_THROW(mesh::validate(m));
  ASSERT_GT(m.tetrahedra.size(), 1000u);
  const double exact = 4.0 / 3.0 * M_PI;
  EXPECT_NEAR(materialVolume(m, 1), exact, exact * 0.02);
  ASSERT_EQ(m.materialNames.size(), 1u);
  EXPECT_EQ(m.materialNames[0], "sphere");
  EXPECT_GT(report.surfaceTriangles, 0u);
}

TEST(MeshTetGen, TwoMaterialBar)
{
  complex::Complex k;
  const auto a = k.addCell(block("steel", { 0, 0, 0 }, { 1, 0.2, 0.2 }));
  const auto b = k.addCell(block("aluminium", { 1, 0, 0 }, { 2, 0.2, 0.2 }));
  mesh::TetraOptions o;
  o.size = 0.05;
  o.deterministic = true;
  const mesh::TetMesh m = mesh::tetrahedralizeTetGen(k, o);
  EXPECT_NO_THROW(mesh::validate(m));
  EXPECT_NEAR(materialVolume(m, 1), 0.04, 0.04 * 0.01);
  EXPECT_NEAR(materialVolume(m, 2), 0.04, 0.04 * 0.01);
  ASSERT_EQ(m.materialNames.size(), 2u);
  EXPECT_EQ(m.materialNames[0], "steel");
  EXPECT_EQ(m.materialNames[1], "aluminium");
  std::size_t straddling = 0;
  for (std::size_t t = 0; t < m.tetrahedra.size(); ++t)
  {
    EXPECT_EQ(m.cells[t], m.materials[t] == 1 ? a : b);
    for (auto v : m.tetrahedra[t])
    {
      const double x = m.points[v][0];
      if (m.materials[t] == 1 ? x > 1 + 1e-9 : x < 1 - 1e-9)
      {
        ++straddling;
      }
    }
  }
  EXPECT_EQ(straddling, 0u);
  // Deterministic: a second run gives the same mesh.
  const mesh::TetMesh again = mesh::tetrahedralizeTetGen(k, o);
  EXPECT_EQ(m.points, again.points);
  EXPECT_EQ(m.tetrahedra, again.tetrahedra);
  EXPECT_EQ(m.materials, again.materials);
}

TEST(MeshTetGen, SphereInBoxAndVoid)
{
  complex::Complex k;
  k.addCell(block("matrix", { -1, -1, -1 }, { 1, 1, 1 }, 0));
  k.addCell(ball("inclusion", { 0.1, 0, 0 }, 0.5, 1));
  mesh::TetraOptions o;
  o.size = 0.1;
  const mesh::TetMesh m = mesh::tetrahedralizeTetGen(k, o);
  EXPECT_NO_THROW(mesh::validate(m));
  const double ballVolume = 4.0 / 3.0 * M_PI * 0.125;
  EXPECT_NEAR(materialVolume(m, 2), ballVolume, ballVolume * 0.02);
  EXPECT_NEAR(materialVolume(m, 1), 8 - ballVolume, (8 - ballVolume) * 0.005);

  // A hollow ball: the cavity is a hole, not meshed.
  complex::Complex hollow;
  const Expr r = sqrt(Expr::x() * Expr::x() + Expr::y() * Expr::y() + Expr::z() * Expr::z());
  hollow.addCell(complex::frepCell("shell", {}, { Expr::constant(1) - r, r - Expr::constant(0.5) },
    { { -1, -1, -1 }, { 1, 1, 1 } }));
  const mesh::TetMesh h = mesh::tetrahedralizeTetGen(hollow, o);
  EXPECT_NO_THROW(mesh::validate(h));
  const double shell = 4.0 / 3.0 * M_PI * (1 - 0.125);
  EXPECT_NEAR(materialVolume(h, 1), shell, shell * 0.03);
}

// A 2D cell inside a solid: the square {z = 0, |x|, |y| <= 0.3} in the box [-0.5, 0.5]^3 must
// be made of faces two tetrahedra share, and every tetrahedron still belongs to the box.
TEST(MeshTetGen, InternalSurface)
{
  complex::Complex k;
  const auto solid = k.addCell(block("box", { -0.5, -0.5, -0.5 }, { 0.5, 0.5, 0.5 }));
  const Expr x = Expr::x(), y = Expr::y();
  k.addCell(complex::frepCell("patch", { Expr::z() },
    { Expr::constant(0.3) - abs(x), Expr::constant(0.3) - abs(y) },
    { { -0.3, -0.3, -0.1 }, { 0.3, 0.3, 0.1 } }));
  mesh::TetraOptions o;
  o.size = 0.1;
  mesh::TetGenReport report;
  const mesh::TetMesh m = mesh::tetrahedralizeTetGen(k, o, &report);
  EXPECT_NO_THROW(mesh::validate(m));
  EXPECT_EQ(report.internalCells, 1u);
  EXPECT_GT(report.internalTriangles, 36u);
  EXPECT_NEAR(materialVolume(m, 1), 1.0, 1e-9);
  for (std::size_t t = 0; t < m.tetrahedra.size(); ++t)
  {
    ASSERT_EQ(m.cells[t], solid);
    ASSERT_EQ(m.materials[t], 1);
  }
  double once = 0;
  const double area = ictk::testing::sharedAreaOnPlane(m, 0, 1e-12, &once);
  EXPECT_NEAR(area, 0.36, 0.36 * 0.01);
  EXPECT_EQ(once, 0.0);

  // Without the patch no face lies on z = 0 (the grid is offset from it).
  complex::Complex plain;
  plain.addCell(block("box", { -0.5, -0.5, -0.5 }, { 0.5, 0.5, 0.5 }));
  const mesh::TetMesh p = mesh::tetrahedralizeTetGen(plain, o);
  EXPECT_LT(ictk::testing::sharedAreaOnPlane(p, 0, 1e-12, &once), 0.01);

  // A closed 2D cell (a sphere surface) inside the box: a region no region point reaches, still
  // labelled as the box; its surface is faces two tetrahedra share.
  complex::Complex closed;
  const auto box = closed.addCell(block("box", { -0.5, -0.5, -0.5 }, { 0.5, 0.5, 0.5 }));
  const Expr r2 = x * x + y * y + Expr::z() * Expr::z();
  closed.addCell(complex::frepCell(
    "shell", { Expr::constant(0.09) - r2 }, {}, { { -0.3, -0.3, -0.3 }, { 0.3, 0.3, 0.3 } }));
  const mesh::TetMesh c = mesh::tetrahedralizeTetGen(closed, o, &report);
  EXPECT_NO_THROW(mesh::validate(c));
  EXPECT_EQ(report.internalCells, 1u);
  EXPECT_NEAR(materialVolume(c, 1), 1.0, 1e-9);
  for (std::size_t t = 0; t < c.tetrahedra.size(); ++t)
  {
    ASSERT_EQ(c.cells[t], box);
  }
}

TEST(MeshTetGen, Errors)
{
  mesh::TetraOptions o;
  o.size = 0.1;
  {
    complex::Complex k;
    k.addCell(ball("left", { 0, 0, 0 }, 0.5));
    k.addCell(ball("right", { 0.4, 0, 0 }, 0.5));
    try
    {
      mesh::tetrahedralizeTetGen(k, o);
      FAIL() << "equal-priority overlap accepted";
    }
    catch (const std::invalid_argument& e)
    {
      const std::string what = e.what();
      EXPECT_NE(what.find("'left'"), std::string::npos) << what;
      EXPECT_NE(what.find("'right'"), std::string::npos) << what;
      EXPECT_NE(what.find("priority"), std::string::npos) << what;
    }
  }
  {
    complex::Complex k;
    k.addCell(ball("sphere", { 0, 0, 0 }, 1));
    o.maxTetrahedra = 1000;
    try
    {
      mesh::tetrahedralizeTetGen(k, o);
      FAIL() << "budget not enforced";
    }
    catch (const std::invalid_argument& e)
    {
      const std::string what = e.what();
      EXPECT_NE(what.find("tetrahedra"), std::string::npos) << what;
      EXPECT_NE(what.find("1000"), std::string::npos) << what;
    }
    o.size = 0.002; // refused by the coarse estimate, before the fine grid
    o.maxTetrahedra = 2e7;
    EXPECT_THROW(mesh::tetrahedralizeTetGen(k, o), std::invalid_argument);
    o.size = 0;
    EXPECT_THROW(mesh::tetrahedralizeTetGen(k, o), std::invalid_argument);
  }
  {
    // A 3D cell with no volume (a ball of radius 0, a field negative everywhere) is named.
    o.size = 0.1;
    const Expr dx = Expr::x() - Expr::constant(2.5), dy = Expr::y() - Expr::constant(2.5),
               dz = Expr::z() - Expr::constant(2.5);
    for (const Expr& empty :
      { Expr::constant(0) - sqrt(dx * dx + dy * dy + dz * dz), Expr::constant(-1) })
    {
      complex::Complex k;
      k.addCell(block("body", { -1, -1, -1 }, { 1, 1, 1 }));
      k.addCell(complex::frepCell("ghost", {}, { empty }, { { 2, 2, 2 }, { 3, 3, 3 } }));
      try
      {
        mesh::tetrahedralizeTetGen(k, o);
        FAIL() << "a cell with no volume accepted";
      }
      catch (const std::invalid_argument& e)
      {
        const std::string what = e.what();
        EXPECT_NE(what.find("'ghost'"), std::string::npos) << what;
        EXPECT_NE(what.find("no volume"), std::string::npos) << what;
      }
    }
  }
  {
    complex::Complex k;
    complex::ExplicitGeometry g;
    g.points = { { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 } };
    g.tetrahedra = { { 0, 1, 2, 3 } };
    k.addCell(complex::explicitCell("tet", 3, g));
    o.size = 0.1;
    EXPECT_THROW(mesh::tetrahedralizeTetGen(k, o), std::invalid_argument);
    complex::Complex empty;
    EXPECT_THROW(mesh::tetrahedralizeTetGen(empty, o), std::invalid_argument);
  }
}

} // namespace
