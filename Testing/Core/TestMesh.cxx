// SPDX-License-Identifier: BSD-3-Clause
// The permissive side of issue 6: element quality, exact cell volumes, attributes on
// tetrahedra, the structured Kuhn mesh, the writers' error handling, and a real solver (CalculiX)
// on a two-material bar. The files' round trip through independent readers (meshio, gmsh) is
// checked by mesh_files_check.py.

#include "CalculixRun.h"
#include "FRep/Primitives.h"
#include "Mesh/Quality.h"
#include "Mesh/Writers.h"
#include "MeshTestModels.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>

using namespace ictk;
using namespace ictk::mesh;
using ::testing::HasSubstr;
namespace fs = std::filesystem;

namespace
{

const double pi = std::acos(-1.0);

complex::Cell solidCell(const std::string& name, const frep::Shape& shape, const frep::Box3& box)
{
  return complex::frepCell(name, {}, { shape.function() }, box);
}

/// A fresh empty folder under the temporary directory.
fs::path scratch(const std::string& tag)
{
  std::random_device random;
  fs::path p = fs::temp_directory_path() / ("ictk-mesh-" + tag + "-" + std::to_string(random()));
  fs::remove_all(p);
  fs::create_directories(p);
  return p;
}

std::string slurp(const fs::path& p)
{
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

} // namespace

TEST(MeshQuality, RegularTetrahedron)
{
  // Alternate corners of a cube: a regular tetrahedron of edge 2 sqrt 2.
  const TetShape s = tetShape({ 1, 1, 1 }, { -1, -1, 1 }, { -1, 1, -1 }, { 1, -1, -1 });
  EXPECT_NEAR(std::abs(s.volume), 8.0 / 3.0, 1e-12);
  EXPECT_NEAR(s.minDihedralDegrees, 70.52877936550931, 1e-9);
  EXPECT_NEAR(s.maxDihedralDegrees, 70.52877936550931, 1e-9);
  EXPECT_NEAR(s.radiusEdgeRatio, std::sqrt(6.0) / 4, 1e-12);
  EXPECT_NEAR(s.radiusEdgeRatio, 0.6124, 1e-4);
}

TEST(MeshQuality, CornerTetrahedron)
{
  const TetShape s = tetShape({ 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 });
  EXPECT_NEAR(s.volume, 1.0 / 6.0, 1e-15);
  EXPECT_NEAR(s.minDihedralDegrees, std::acos(1 / std::sqrt(3.0)) * 180 / pi, 1e-9);
  EXPECT_NEAR(s.maxDihedralDegrees, 90, 1e-9);
  EXPECT_NEAR(s.radiusEdgeRatio, std::sqrt(3.0) / 2, 1e-12);
  // Negative orientation: negative volume, same angles.
  EXPECT_NEAR(tetShape({ 0, 0, 0 }, { 0, 1, 0 }, { 1, 0, 0 }, { 0, 0, 1 }).volume, -1.0 / 6, 1e-15);
  // Flat: zero angle, infinite ratio.
  const TetShape flat = tetShape({ 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 }, { 1, 1, 0 });
  EXPECT_EQ(flat.volume, 0);
  EXPECT_TRUE(std::isinf(flat.radiusEdgeRatio));
}

TEST(MeshQuality, KuhnCubeReport)
{
  TetMesh m = kuhnTetMesh({ { 0, 0, 0 }, { 1, 1, 1 } }, { 2, 2, 2 });
  m.cells.assign(m.tetrahedra.size(), 0);
  m.materials.assign(m.tetrahedra.size(), 1);
  for (std::size_t t = 0; t < m.tetrahedra.size(); t += 2)
  {
    m.materials[t] = 2;
  }
  m.materialNames = { "a", "b", "empty" };
  EXPECT_NO_THROW(validate(m));
  const QualityReport q = measureQuality(m);
  EXPECT_EQ(q.points, 27u);
  EXPECT_EQ(q.tetrahedra, 48u);
  EXPECT_NEAR(q.volume, 1, 1e-14);
  // Kuhn tetrahedra: dihedral angles of 45, 60 and 90 degrees; circumradius = half the diagonal.
  EXPECT_NEAR(q.minDihedralDegrees, 45, 1e-9);
  EXPECT_NEAR(q.minDihedralPercentile1Degrees, 45, 1e-9);
  EXPECT_NEAR(q.maxDihedralDegrees, 90, 1e-9);
  EXPECT_NEAR(q.maxRadiusEdgeRatio, std::sqrt(3.0) / 2, 1e-12);
  EXPECT_EQ(q.nonPositive, 0u);
  ASSERT_EQ(q.materials.size(), 3u);
  EXPECT_EQ(q.materials[0].tetrahedra, 24u);
  EXPECT_EQ(q.materials[1].tetrahedra, 24u);
  EXPECT_EQ(q.materials[2].tetrahedra, 0u);
  EXPECT_NEAR(q.materials[0].volume, 0.5, 1e-14);
  EXPECT_NEAR(q.materials[1].volume, 0.5, 1e-14);
  EXPECT_TRUE(std::isnan(q.materials[2].minDihedralDegrees));
  const std::string text = formatQualityReport(q);
  EXPECT_THAT(text, HasSubstr("tetrahedra 48"));
  EXPECT_THAT(text, HasSubstr("material 2 'b': 24 tetrahedra"));
}

TEST(MeshQuality, PercentileSeesTheWorstPercent)
{
  // 200 good tetrahedra and 3 slivers: the minimum is the sliver, the 1st percentile is too
  // (nearest rank 0.01 * 202 = 2), 4 slivers of 400 would not be.
  TetMesh m;
  m.points = { { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 }, { 1, 1, 0.01 } };
  for (int i = 0; i < 200; ++i)
  {
    m.tetrahedra.push_back({ 0, 1, 2, 3 });
  }
  for (int i = 0; i < 3; ++i)
  {
    m.tetrahedra.push_back({ 0, 1, 2, 4 });
  }
  const QualityReport q = measureQuality(m);
  EXPECT_LT(q.minDihedralDegrees, 5);
  EXPECT_NEAR(q.minDihedralPercentile1Degrees, q.minDihedralDegrees, 1e-12);
  m.tetrahedra.resize(201);
  EXPECT_NEAR(measureQuality(m).minDihedralPercentile1Degrees, 54.735610317245346, 1e-9);
}

TEST(MeshVolume, UnitSphere)
{
  const auto cell =
    solidCell("ball", frep::sphere({ 0, 0, 0 }, 1), { { -1, -1, -1 }, { 1, 1, 1 } });
  const VolumeEstimate v = cellVolumeEstimate(cell, 1.0 / 64);
  const double exact = 4.0 / 3.0 * pi;
  EXPECT_NEAR(v.volume / exact, 1, 1e-3);
  EXPECT_LE(std::abs(v.volume - exact), v.errorBound);
  EXPECT_LE(v.provenInside, exact);
  EXPECT_GE(v.provenInside + v.undecided, exact);
  EXPECT_GT(v.sampledBoxes, 0u);
  EXPECT_DOUBLE_EQ(cellVolume(cell, 1.0 / 64), v.volume); // deterministic
  std::printf("unit sphere: %.9f (exact %.9f, %+.2e relative), bound %.3g, %zu sampled boxes\n",
    v.volume, exact, v.volume / exact - 1, v.errorBound, v.sampledBoxes);
}

TEST(MeshVolume, BoxIsExact)
{
  // Faces on dyadic planes of the bounds: the sampled boxes are cut by no face.
  const auto cell =
    solidCell("box", frep::block({ 0, 0, 0 }, 1, 1, 1), { { -1, -1, -1 }, { 3, 3, 3 } });
  const VolumeEstimate v = cellVolumeEstimate(cell, 0.05);
  EXPECT_NEAR(v.volume, 1, 1e-12);
  // Outward rounding leaves the boxes next to the faces undecided; all their samples agree.
  EXPECT_LE(v.provenInside, 1);
  EXPECT_GE(v.provenInside + v.undecided, 1);
  // Faces anywhere: within the bound.
  const auto odd =
    solidCell("odd", frep::block({ 0.1, 0.2, 0.3 }, 0.7, 0.5, 0.3), { { 0, 0, 0 }, { 1, 1, 1 } });
  const VolumeEstimate w = cellVolumeEstimate(odd, 0.01);
  EXPECT_NEAR(w.volume, 0.105, 1e-3);
  EXPECT_LE(std::abs(w.volume - 0.105), w.errorBound);
}

TEST(MeshVolume, ExplicitTetrahedraAndErrors)
{
  complex::ExplicitGeometry g;
  g.points = { { 0, 0, 0 }, { 2, 0, 0 }, { 0, 2, 0 }, { 0, 0, 2 } };
  g.tetrahedra = { { 0, 1, 2, 3 } };
  const auto tet = complex::explicitCell("tet", 3, g);
  EXPECT_NEAR(cellVolume(tet, 0.1), 8.0 / 6.0, 1e-14);
  const auto ball =
    solidCell("ball", frep::sphere({ 0, 0, 0 }, 1), { { -1, -1, -1 }, { 1, 1, 1 } });
  try
  {
    cellVolume(ball, 1e-6);
    FAIL();
  }
  catch (const std::invalid_argument& e)
  {
    EXPECT_THAT(e.what(), HasSubstr("cell 'ball'"));
    EXPECT_THAT(e.what(), HasSubstr("1/4096"));
  }
  EXPECT_THROW(cellVolume(ball, 0), std::invalid_argument);
  complex::ExplicitGeometry p;
  p.points = { { 0, 0, 0 } };
  EXPECT_THROW(cellVolume(complex::explicitCell("p", 0, p), 0.1), std::invalid_argument);
}

TEST(MeshVolume, CompareWithComplex)
{
  const auto k = lang::readComplexJson(ictk::testing::barJson(), "bar.json");
  const TetMesh m = ictk::testing::barMesh(k);
  const auto c = compareVolumes(m, k, 0.01);
  ASSERT_EQ(c.size(), 2u);
  for (const auto& v : c)
  {
    EXPECT_NEAR(v.meshVolume, 0.04, 1e-12) << v.name;
    EXPECT_NEAR(v.cellVolume, 0.04, 1e-6) << v.name;
    EXPECT_LT(std::abs(v.relativeDifference), 1e-4) << v.name;
  }
  EXPECT_EQ(c[0].name, "steel");
  EXPECT_EQ(c[1].cell, k.idOf("aluminium"));
  EXPECT_THAT(formatVolumeComparison(c), HasSubstr("material 2 'aluminium': mesh volume 0.04"));
}

TEST(MeshStructured, KuhnMeshIsConformingAndLabelled)
{
  const TetMesh grid = kuhnTetMesh({ { 0, 0, 0 }, { 2, 0.2, 0.2 } }, { 4, 1, 1 });
  EXPECT_EQ(grid.points.size(), 20u);
  EXPECT_EQ(grid.tetrahedra.size(), 24u);
  // Conforming: every interior triangle is shared by exactly two tetrahedra, and the boundary
  // has 2 triangles per block face.
  std::map<std::array<std::uint32_t, 3>, int> faces;
  for (const auto& t : grid.tetrahedra)
  {
    for (int skip = 0; skip < 4; ++skip)
    {
      std::array<std::uint32_t, 3> f;
      for (int i = 0, j = 0; i < 4; ++i)
      {
        if (i != skip)
        {
          f[static_cast<std::size_t>(j++)] = t[static_cast<std::size_t>(i)];
        }
      }
      std::sort(f.begin(), f.end());
      ++faces[f];
    }
  }
  int boundary = 0;
  for (const auto& [f, n] : faces)
  {
    EXPECT_LE(n, 2);
    boundary += n == 1 ? 1 : 0;
  }
  EXPECT_EQ(boundary, 2 * (4 * 4 + 2));

  const auto k = lang::readComplexJson(
    ictk::testing::barJson("left", "right", "210000", /*spare=*/true), "bar.json");
  const TetMesh m = ictk::testing::barMesh(k, 4, 1);
  EXPECT_NO_THROW(validate(m));
  EXPECT_EQ(m.materialNames, (std::vector<std::string>{ "left", "right", "spare" }));
  EXPECT_EQ(std::count(m.materials.begin(), m.materials.end(), 1), 12);
  EXPECT_EQ(std::count(m.materials.begin(), m.materials.end(), 2), 12);
  EXPECT_EQ(m.cells[0], k.idOf("left"));
}

TEST(MeshAttributes, CentroidValuesAndDefaults)
{
  const auto k = lang::readComplexJson(R"({ "name": "two",
    "attributes": {
      "temperature": { "components": 1, "inside": [-7], "outside": [0] },
      "velocity": { "components": 3, "inside": [9, 8, 7] }
    },
    "attribute_functions": { "T": ["100 + x[1] + 10 * x[2]"], "V": ["x[1]", "x[2]", "x[3]"] },
    "cells": [
      { "name": "a", "kind": "F", "dimension": 3, "inside": ["x[1]", "1 - x[1]"],
        "bounds": [[0, 0, 0], [1, 1, 1]], "attributes": { "temperature": "T", "velocity": "V" } },
      { "name": "b", "kind": "F", "dimension": 3, "inside": ["x[1] - 1", "2 - x[1]"],
        "bounds": [[1, 0, 0], [2, 1, 1]] }
    ] })",
    "two.json");
  TetMesh m;
  m.points = { { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 }, { 2, 0, 0 }, { 1, 1, 0 },
    { 1, 0, 1 } };
  m.tetrahedra = { { 0, 1, 2, 3 }, { 1, 4, 5, 6 } };
  m.cells = { k.idOf("a"), k.idOf("b") };
  m.materials = { 1, 2 };
  m.materialNames = { "a", "b" };
  m.cellData.push_back({ "temperature", 1, { 1, 2 } }); // replaced
  assignAttributes(m, k);
  ASSERT_EQ(m.cellData.size(), 2u);
  const TetArray* t = findArray(m, "temperature");
  ASSERT_NE(t, nullptr);
  ASSERT_EQ(t->values.size(), 2u);
  // Centroid of tetrahedron 0: (0.25, 0.25, 0.25).
  EXPECT_DOUBLE_EQ(t->values[0], 100 + 0.25 + 2.5);
  EXPECT_EQ(t->values[1], -7); // cell b binds nothing: theta1
  const TetArray* v = findArray(m, "velocity");
  ASSERT_NE(v, nullptr);
  EXPECT_EQ(v->components, 3);
  EXPECT_EQ(v->values, (std::vector<double>{ 0.25, 0.25, 0.25, 9, 8, 7 }));
  EXPECT_NO_THROW(validate(m));

  m.cells[1] = 42;
  EXPECT_THROW(assignAttributes(m, k), std::invalid_argument);
}

TEST(MeshWriters, SetNames)
{
  TetMesh m;
  m.materialNames = { "t_0^3", "1st", "a b", "a_b", "A_B", "" };
  EXPECT_EQ(
    abaqusSetNames(m), (std::vector<std::string>{ "t_0_3", "M1st", "a_b", "a_b_2", "A_B_3", "M" }));
}

TEST(MeshWriters, UnfriendlyMaterialLeavesNoFile)
{
  const fs::path dir = scratch("unfriendly");
  auto k = lang::readComplexJson(ictk::testing::barJson(), "bar.json");
  TetMesh m = ictk::testing::barMesh(k, 4, 1);
  // A modulus missing from the mesh, then a NaN modulus in the second material.
  TetMesh noModulus = m;
  noModulus.cellData.erase(std::find_if(noModulus.cellData.begin(), noModulus.cellData.end(),
    [](const TetArray& a) { return a.name == "youngs_modulus"; }));
  ASSERT_EQ(findArray(noModulus, "youngs_modulus"), nullptr);
  try
  {
    writeAbaqus(noModulus, (dir / "x.inp").string());
    FAIL();
  }
  catch (const std::invalid_argument& e)
  {
    EXPECT_THAT(e.what(), HasSubstr("cell 'steel'"));
    EXPECT_THAT(e.what(), HasSubstr("a solver-unfriendly material"));
  }
  TetMesh nanModulus = m;
  for (auto& a : nanModulus.cellData)
  {
    if (a.name == "youngs_modulus")
    {
      a.values.back() = std::nan("");
    }
  }
  try
  {
    writeAbaqus(nanModulus, (dir / "x.inp").string());
    FAIL();
  }
  catch (const std::invalid_argument& e)
  {
    EXPECT_THAT(e.what(), HasSubstr("cell 'aluminium'"));
    EXPECT_THAT(e.what(), HasSubstr("a solver-unfriendly material"));
  }
  // The mesh alone is fine without materials.
  AbaqusOptions meshOnly;
  meshOnly.materials = false;
  EXPECT_NO_THROW(writeAbaqus(noModulus, (dir / "mesh-only.inp").string(), meshOnly));
  EXPECT_THAT(slurp(dir / "mesh-only.inp"), ::testing::Not(HasSubstr("*MATERIAL")));
  // A failed write keeps the previous file intact; nothing else is left in the folder.
  writeMedit(m, (dir / "x.mesh").string());
  const std::string before = slurp(dir / "x.mesh");
  TetMesh broken = m;
  broken.tetrahedra[0][0] = 9999;
  EXPECT_THROW(writeMedit(broken, (dir / "x.mesh").string()), std::invalid_argument);
  EXPECT_EQ(slurp(dir / "x.mesh"), before);
  EXPECT_THROW(writeGmsh(m, (dir / "missing" / "x.msh").string()), std::runtime_error);
  EXPECT_THROW(writeGmsh(m, dir.string()), std::runtime_error);
  EXPECT_THROW(writeTetMesh(m, (dir / "x.stl").string()), std::invalid_argument);
  std::vector<std::string> left;
  for (const auto& e : fs::directory_iterator(dir))
  {
    left.push_back(e.path().filename().string());
  }
  std::sort(left.begin(), left.end());
  EXPECT_EQ(left, (std::vector<std::string>{ "mesh-only.inp", "x.mesh" }));
  fs::remove_all(dir);
}

TEST(MeshWriters, MaterialsAreVolumeWeightedMeans)
{
  auto k = lang::readComplexJson(
    ictk::testing::barJson("steel", "aluminium", "200000 + 1000 * x[1]"), "bar.json");
  const TetMesh m = ictk::testing::barMesh(k, 10, 2);
  const auto materials = solidMaterials(m);
  ASSERT_EQ(materials.size(), 2u);
  EXPECT_NEAR(materials[0].youngsModulus, 200500, 1e-6); // the mean of a linear function
  EXPECT_EQ(materials[0].setName, "steel");
  EXPECT_EQ(materials[0].poissonRatio, 0);
  EXPECT_NEAR(materials[0].density, 7.8e-9, 1e-20);
  EXPECT_NEAR(materials[1].youngsModulus, 70000, 1e-9);
  EXPECT_NEAR(materials[1].density, 1e-9, 1e-20); // theta1: aluminium binds no density
}

// Issue 15's modulus bins leave the two-material bar as it was: its cells' moduli are constant,
// so the default 1 % bins write the very bytes of one material per cell (an infinite bin width:
// the deck before binning), two *MATERIAL cards and no extra element sets.
TEST(MeshAbaqus, TwoMaterialBarDeckUnchangedByModulusBins)
{
  const auto k = lang::readComplexJson(ictk::testing::barJson(), "bar.json");
  const TetMesh m = ictk::testing::barMesh(k, 20, 2);
  const fs::path dir = scratch("bar-bins");
  AbaqusOptions perCell;
  perCell.modulusBinWidth = std::numeric_limits<double>::infinity();
  writeAbaqus(m, (dir / "binned.inp").string());
  writeAbaqus(m, (dir / "per-cell.inp").string(), perCell);
  const std::string deck = slurp(dir / "binned.inp");
  EXPECT_EQ(deck, slurp(dir / "per-cell.inp"));
  std::size_t materials = 0;
  for (auto at = deck.find("*MATERIAL"); at != std::string::npos;
       at = deck.find("*MATERIAL", at + 1))
  {
    ++materials;
  }
  EXPECT_EQ(materials, 2u);
  EXPECT_EQ(deck.find("*ELSET"), std::string::npos);
  fs::remove_all(dir);
}

// A real solver: CalculiX on the two-material bar, pulled by F = 100 at x = 2. With nu = 0 the
// uniform-strain solution is exact on any conforming linear mesh: u = F L1 / (E1 A) + F L2 /
// (E2 A).
TEST(MeshCalculix, TwoMaterialBarMatchesSpringsInSeries)
{
  const auto k = lang::readComplexJson(ictk::testing::barJson(), "bar.json");
  const TetMesh m = ictk::testing::barMesh(k, 20, 2);
  const double force = 100, area = 0.2 * 0.2;
  std::vector<std::size_t> tip;
  const std::string deck = ictk::testing::barPullDeck(m, force, tip);
  const auto run = ictk::testing::runCalculix(m, deck, ICTK_CCX);
  EXPECT_EQ(run.status, 0) << run.log;
  EXPECT_THAT(run.log, HasSubstr("Job finished")) << run.log;
  EXPECT_THAT(run.log, ::testing::Not(HasSubstr("*ERROR"))) << run.log;
  ASSERT_TRUE(run.tables.count("displacements")) << run.dat;
  const auto& u = run.tables.at("displacements");
  EXPECT_EQ(u.size(), m.points.size());
  ASSERT_EQ(tip.size(), 9u);
  double tipSum = 0, tipMin = 1e300, tipMax = -1e300;
  for (const std::size_t id : tip)
  {
    tipSum += u.at(id)[0];
    tipMin = std::min(tipMin, u.at(id)[0]);
    tipMax = std::max(tipMax, u.at(id)[0]);
  }
  const double expected = force * 1 / (210000 * area) + force * 1 / (70000 * area);
  const double mean = tipSum / double(tip.size());
  EXPECT_NEAR(mean / expected, 1, 1e-4) << "tip ux " << mean << ", springs in series " << expected;
  EXPECT_NEAR(tipMax - tipMin, 0, 1e-4 * expected); // a uniform pull
  std::printf("CalculiX tip displacement %.9g, springs in series %.9g (%+.4f%%)\n", mean, expected,
    100 * (mean / expected - 1));
}
