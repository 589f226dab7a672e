// SPDX-License-Identifier: BSD-3-Clause
// Issue 21: the validity check that every written tetrahedral mesh passes. Each defect a solver
// refuses (micro-tetrahedra, coincident vertices, inverted or overlapping tetrahedra, a face of
// three tetrahedra, a hole) is built by hand on a Kuhn mesh, whose figures are known exactly.

#include "Mesh/Structured.h"
#include "Mesh/Validity.h"
#include "Mesh/Writers.h"
#include "MeshTestModels.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <random>

using namespace ictk;
using namespace ictk::mesh;
using ::testing::HasSubstr;
namespace fs = std::filesystem;

namespace
{

/// The Kuhn mesh of [0, n]^3 in unit blocks, one material.
TetMesh kuhnCube(int n)
{
  TetMesh m = kuhnTetMesh({ { 0, 0, 0 }, { double(n), double(n), double(n) } }, { n, n, n });
  m.cells.assign(m.tetrahedra.size(), 0);
  m.materials.assign(m.tetrahedra.size(), 1);
  m.materialNames = { "block" };
  return m;
}

/// A complex of one box cell [0, n]^3.
complex::Complex boxComplex(int n)
{
  const std::string side = std::to_string(n);
  return lang::readComplexJson(R"({ "cells": [ { "name": "block", "kind": "F", "dimension": 3,
    "inside": ["x[1]", ")" +
      side + R"( - x[1]", "x[2]", ")" + side + R"( - x[2]", "x[3]", ")" + side + R"( - x[3]"],
    "bounds": [[0, 0, 0], [)" +
      side + "," + side + "," + side + "]] } ] }",
    "block.json");
}

} // namespace

TEST(MeshValidity, KuhnCubeFiguresAreExact)
{
  // 2^3 unit blocks of 6 tetrahedra: 48 tetrahedra, 27 points; 2 triangles on each of the 24
  // unit squares of the surface (48 boundary faces), so (4 x 48 - 48) / 2 = 72 interior faces.
  // The shortest edge is a block's side, 1; every tetrahedron has volume 1/6.
  const TetMesh m = kuhnCube(2);
  const complex::Complex k = boxComplex(2);
  const ValidityReport r = checkValidity(m, 1.0, &k);
  EXPECT_TRUE(r.valid()) << formatValidityReport(r);
  EXPECT_EQ(r.tetrahedra, 48u);
  EXPECT_EQ(r.points, 27u);
  EXPECT_EQ(r.boundaryFaces, 48u);
  EXPECT_EQ(r.interiorFaces, 72u);
  EXPECT_EQ(r.nonConformingFaces, 0u);
  EXPECT_EQ(r.strayBoundaryFaces, 0u);
  EXPECT_EQ(r.uncheckedBoundaryFaces, 0u);
  EXPECT_DOUBLE_EQ(r.minEdge, 1.0);
  EXPECT_DOUBLE_EQ(r.minEdgeRelative, 1.0);
  EXPECT_NEAR(r.minVolume, 1.0 / 6, 1e-15);
  // Regular tetrahedron of edge 1: 1 / (6 sqrt 2).
  EXPECT_NEAR(r.minVolumeRelative, std::sqrt(2.0), 1e-12);
  // Without a complex the boundary is not checked, the rest is.
  const ValidityReport alone = checkValidity(m, 1.0);
  EXPECT_TRUE(alone.valid());
  EXPECT_EQ(alone.uncheckedBoundaryFaces, 48u);
  // With no size the mean edge is taken: edges of the Kuhn split are 1, sqrt 2 and sqrt 3.
  const ValidityReport mean = checkValidity(m);
  EXPECT_GT(mean.size, 1.0);
  EXPECT_LT(mean.size, std::sqrt(3.0));
}

TEST(MeshValidity, MicroTetrahedronIsRefusedWithItsPlace)
{
  // The defect of issue 21: a cluster of vertices 1e-8 apart on an interface.
  TetMesh m = kuhnCube(1);
  const auto base = static_cast<std::uint32_t>(m.points.size());
  m.points.push_back({ 0.5, 0.5, 0.5 });
  m.points.push_back({ 0.5 + 1e-8, 0.5, 0.5 });
  m.points.push_back({ 0.5, 0.5 + 1e-8, 0.5 });
  m.points.push_back({ 0.5, 0.5, 0.5 + 1e-8 });
  m.tetrahedra.push_back({ base, base + 1, base + 2, base + 3 });
  m.cells.push_back(0);
  m.materials.push_back(1);
  const ValidityReport r = checkValidity(m, 1.0);
  EXPECT_FALSE(r.valid());
  EXPECT_EQ(r.shortEdges, 1u);
  EXPECT_EQ(r.smallVolumes, 1u);
  EXPECT_NEAR(r.minEdge, 1e-8, 1e-12);
  EXPECT_NEAR(r.minVolume, 1e-24 / 6, 1e-28);
  EXPECT_EQ(r.duplicatePoints, 4u) << "the four points lie within 1e-6 of each other";
  const std::string text = formatValidityReport(r);
  EXPECT_THAT(text, HasSubstr("1 tetrahedra have an edge shorter than 0.001 x size 1"));
  EXPECT_THAT(text, HasSubstr("tetrahedron 6 of 'block' at (0.5"));
  EXPECT_THAT(text, HasSubstr("4 points lie within 1e-06 of another point (the first at (0.5"));
  EXPECT_THROW(requireValid(r, "the test mesh"), std::invalid_argument);
}

TEST(MeshValidity, InvertedAndOverlappingTetrahedra)
{
  TetMesh m = kuhnCube(1);
  std::swap(m.tetrahedra[2][0], m.tetrahedra[2][1]);
  ValidityReport r = checkValidity(m, 1.0);
  EXPECT_EQ(r.nonPositive, 1u);
  // Only the vertex order is wrong: the faces and their sides are those of a sound mesh.
  EXPECT_EQ(r.nonConformingFaces, 0u);
  EXPECT_THAT(formatValidityReport(r), HasSubstr("1 tetrahedra are not positively oriented"));

  // A tetrahedron given twice: each of its four faces is then of two tetrahedra on the same side
  // (on the cube's surface) or of three (inside).
  TetMesh twice = kuhnCube(1);
  twice.tetrahedra.push_back(twice.tetrahedra[0]);
  twice.cells.push_back(0);
  twice.materials.push_back(1);
  r = checkValidity(twice, 1.0);
  EXPECT_EQ(r.nonPositive, 0u);
  EXPECT_EQ(r.nonConformingFaces, 4u);
  EXPECT_THAT(formatValidityReport(r),
    HasSubstr("4 faces are shared by more than two tetrahedra or by two on the same side"));
}

TEST(MeshValidity, HoleInsideACellIsFound)
{
  // 3^3 blocks with the middle block's 6 tetrahedra removed: the hole's 6 squares give 12 faces
  // of one tetrahedron with the cell all around them; the 108 outer ones are on the boundary.
  TetMesh m = kuhnCube(3);
  TetMesh holed = m;
  holed.tetrahedra.clear();
  holed.cells.clear();
  holed.materials.clear();
  for (std::size_t t = 0; t < m.tetrahedra.size(); ++t)
  {
    frep::Point3 c{ 0, 0, 0 };
    for (auto v : m.tetrahedra[t])
    {
      for (int a = 0; a < 3; ++a)
      {
        c[a] += m.points[v][a] / 4;
      }
    }
    if (c[0] > 1 && c[0] < 2 && c[1] > 1 && c[1] < 2 && c[2] > 1 && c[2] < 2)
    {
      continue;
    }
    holed.tetrahedra.push_back(m.tetrahedra[t]);
    holed.cells.push_back(0);
    holed.materials.push_back(1);
  }
  ASSERT_EQ(holed.tetrahedra.size(), 27u * 6 - 6);
  const complex::Complex k = boxComplex(3);
  // Size 0.5: the hole's faces are a whole block (2 x size) from the boundary.
  const ValidityReport r = checkValidity(holed, 0.5, &k);
  EXPECT_EQ(r.boundaryFaces, 9u * 6 * 2 + 12);
  EXPECT_EQ(r.strayBoundaryFaces, 12u);
  EXPECT_EQ(r.nonConformingFaces, 0u);
  EXPECT_THAT(formatValidityReport(r),
    HasSubstr("12 faces of one tetrahedron have cells all "
              "around them, as far as 1 x size: a hole"));
  EXPECT_TRUE(checkValidity(m, 0.5, &k).valid());
}

TEST(MeshValidity, WritersRefuseAnInvalidMeshAndLeaveNoFile)
{
  TetMesh m = kuhnCube(1);
  m.points.push_back({ 1e-9, 0, 0 }); // a second (0, 0, 0)
  m.tetrahedra[0][std::find(m.tetrahedra[0].begin(), m.tetrahedra[0].end(), 0u) -
    m.tetrahedra[0].begin()] = static_cast<std::uint32_t>(m.points.size() - 1);
  TetArray e{ "youngs_modulus", 1, std::vector<double>(m.tetrahedra.size(), 1000) };
  m.cellData.push_back(e);
  std::random_device random;
  const fs::path dir = fs::temp_directory_path() / ("ictk-validity-" + std::to_string(random()));
  fs::create_directories(dir);
  for (const char* name : { "m.inp", "m.msh", "m.mesh" })
  {
    const fs::path path = dir / name;
    try
    {
      writeTetMesh(m, path.string());
      ADD_FAILURE() << name << " was written";
    }
    catch (const std::invalid_argument& error)
    {
      EXPECT_THAT(error.what(), HasSubstr("cannot write '" + path.string() + "'"));
      EXPECT_THAT(error.what(), HasSubstr("points lie within"));
    }
    EXPECT_FALSE(fs::exists(path));
  }
  EXPECT_TRUE(fs::is_empty(dir)) << "no temporary file left";
  fs::remove_all(dir);
}

namespace
{

/// A square pyramid's two tetrahedra over the unit square's diagonal a-c (apex above), the two of
/// a pyramid below over the other diagonal b-d (when `below`), and the flat tetrahedron of the
/// square's four corners between them, each tetrahedron positively oriented where it has volume.
TetMesh squareWithFlatTetrahedron(bool below)
{
  TetMesh m;
  m.points = { { 0, 0, 0 }, { 1, 0, 0 }, { 1, 1, 0 }, { 0, 1, 0 }, { 0.5, 0.5, 1 },
    { 0.5, 0.5, -1 } };
  const auto add = [&](std::array<std::uint32_t, 4> t)
  {
    if (orientation(m.points[t[0]], m.points[t[1]], m.points[t[2]], m.points[t[3]]) < 0)
    {
      std::swap(t[2], t[3]);
    }
    m.tetrahedra.push_back(t);
    m.cells.push_back(0);
    m.materials.push_back(1);
  };
  add({ 0, 1, 2, 4 });
  add({ 0, 2, 3, 4 });
  if (below)
  {
    add({ 0, 1, 3, 5 });
    add({ 1, 2, 3, 5 });
  }
  else
  {
    m.points.pop_back();
  }
  add({ 0, 1, 2, 3 });
  m.materialNames = { "block" };
  m.cellData.push_back({ "id", 1, {} });
  for (std::size_t t = 0; t < m.tetrahedra.size(); ++t)
  {
    m.cellData[0].values.push_back(double(t));
  }
  return m;
}

} // namespace

TEST(MeshValidity, FlatTetrahedraOnTheBoundaryAreRemoved)
{
  // The flat tetrahedron under a pyramid: its faces on the a-c diagonal are the pyramid's, those
  // on b-d the boundary. Removed, the pyramid's two faces are the boundary over the same square.
  TetMesh m = squareWithFlatTetrahedron(false);
  EXPECT_EQ(checkValidity(m, 1.0).smallVolumes, 1u);
  EXPECT_EQ(removeFlatBoundaryTetrahedra(m, 1.0), 1u);
  ASSERT_EQ(m.tetrahedra.size(), 2u);
  EXPECT_EQ(m.points.size(), 5u);
  EXPECT_EQ(m.cellData[0].values, (std::vector<double>{ 0, 1 }));
  const ValidityReport r = checkValidity(m, 1.0);
  EXPECT_TRUE(r.valid()) << formatValidityReport(r);
  EXPECT_EQ(r.interiorFaces, 1u);
  EXPECT_EQ(r.boundaryFaces, 6u);
  // The volume is the pyramid's, 1/3, to the flat tetrahedron's (none).
  double volume = 0;
  for (const auto& t : m.tetrahedra)
  {
    volume += orientation(m.points[t[0]], m.points[t[1]], m.points[t[2]], m.points[t[3]]) / 6;
  }
  EXPECT_NEAR(volume, 1.0 / 3, 1e-15);
  // Nothing flat is left: a second pass removes nothing.
  EXPECT_EQ(removeFlatBoundaryTetrahedra(m, 1.0), 0u);
}

TEST(MeshValidity, FlatTetrahedraBetweenNeighboursAreKept)
{
  // Pyramids above (diagonal a-c) and below (diagonal b-d): the flat tetrahedron joins their
  // faces, and without it they would not be conforming; it stays, and the mesh stays refused.
  TetMesh m = squareWithFlatTetrahedron(true);
  EXPECT_EQ(removeFlatBoundaryTetrahedra(m, 1.0), 0u);
  EXPECT_EQ(m.tetrahedra.size(), 5u);
  EXPECT_EQ(m.points.size(), 6u);
  const ValidityReport r = checkValidity(m, 1.0);
  EXPECT_FALSE(r.valid());
  EXPECT_EQ(r.smallVolumes, 1u);
}
