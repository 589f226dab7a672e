// SPDX-License-Identifier: BSD-3-Clause
// The seed 001 flower (Data/Models/flower) end to end, the complex JSON reader's errors, cell
// and complex attachment, and marching tetrahedra against the analytic sphere (the lower-
// dimensional discretisers are tested in TestDiscretizeCells).

#include "Complex/Attachment.h"
#include "Complex/Validation.h"
#include "Discretize/MarchingTetrahedra.h"
#include "FRep/Primitives.h"
#include "FRep/Tape.h"
#include "Lang/ComplexFile.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

using namespace ictk;
using namespace ictk::complex;
using ::testing::HasSubstr;

namespace
{

const std::string FlowerPath = std::string(ICTK_DATA_DIR) + "/Models/flower/flower.json";

frep::FieldPtr field(const frep::Expr& e)
{
  return frep::tapeField(frep::Tape::compile(e));
}

double norm(const Point3& p)
{
  return std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
}

struct Flower : ::testing::Test
{
  static void SetUpTestSuite()
  {
    k = new Complex(lang::readComplexFile(FlowerPath));
    DiscretizationOptions o;
    o.featureSize = 0.02;
    mesh = new ComplexMesh(discretizeComplex(*k, o));
  }
  static void TearDownTestSuite()
  {
    delete mesh;
    delete k;
  }
  static Complex* k;
  static ComplexMesh* mesh;
};
Complex* Flower::k = nullptr;
ComplexMesh* Flower::mesh = nullptr;

} // namespace

TEST_F(Flower, CellCountsPerDimension)
{
  // papers.md 5.A item 5: |G^0| = 4, |G^1| = 3, |G^2| = 2, |G^3| = 3, three explicit cells.
  EXPECT_EQ(k->cellsOfDimension(0).size(), 4u);
  EXPECT_EQ(k->cellsOfDimension(1).size(), 3u);
  EXPECT_EQ(k->cellsOfDimension(2).size(), 2u);
  EXPECT_EQ(k->cellsOfDimension(3).size(), 3u);
  int explicitCells = 0;
  for (CellId id : k->cellIds())
  {
    explicitCells += k->cell(id).isExplicit() ? 1 : 0;
  }
  EXPECT_EQ(explicitCells, 3);
}

TEST_F(Flower, EveryRelation)
{
  // papers.md 5.A item 6: (Rb10, Rb21, Rb20, Rb32, Rb31, Rb30) = (4, 2, 2, 2, 3, 4), 17 in all,
  // with (e_0^1, e_1^0) for the misprinted pair of line 167 (erratum E1); every Rc empty.
  EXPECT_EQ(k->boundary(1, 0).size(), 4u);
  EXPECT_EQ(k->boundary(2, 1).size(), 2u);
  EXPECT_EQ(k->boundary(2, 0).size(), 2u);
  EXPECT_EQ(k->boundary(3, 2).size(), 2u);
  EXPECT_EQ(k->boundary(3, 1).size(), 3u);
  EXPECT_EQ(k->boundary(3, 0).size(), 4u);
  EXPECT_EQ(k->boundaryPairCount(), 17u);
  EXPECT_EQ(k->containmentPairCount(), 0u);
  EXPECT_TRUE(k->hasBoundary(k->idOf("e_0^1"), k->idOf("e_1^0")));
  // papers.md 5.A item 4: co-boundary(t_1^2) = {t_1^3, t_2^3}.
  EXPECT_THAT(
    k->coboundaryOf(k->idOf("t_1^2")), ::testing::ElementsAre(k->idOf("t_1^3"), k->idOf("t_2^3")));
}

TEST_F(Flower, AttributesPerCell)
{
  // papers.md 5.A item 7.
  const std::map<std::string, std::string> expected = { { "e_0^0", "S2" }, { "e_1^0", "S1" },
    { "t_0^0", "S3" }, { "t_1^0", "S3" }, { "e_0^1", "S1" }, { "t_0^1", "S3" }, { "t_1^1", "S2" },
    { "t_0^2", "S3" }, { "t_1^2", "S2" }, { "t_0^3", "S1" }, { "t_1^3", "S2" }, { "t_2^3", "S1" } };
  for (const auto& [cell, function] : expected)
  {
    const Cell* c = k->findCell(cell);
    ASSERT_NE(c, nullptr) << cell;
    ASSERT_EQ(c->attributes.size(), 1u) << cell;
    EXPECT_EQ(c->attributes[0].function->name, function) << cell;
    EXPECT_EQ(c->attributes[0].function->components.size(), 3u);
  }
  // Every output point carries the RGB colour: S1 is the constant (0.95, 0.85, 0.2).
  const CellMesh& stamen = mesh->of(k->idOf("t_0^3"));
  ASSERT_EQ(stamen.surface.pointData.size(), 1u);
  const auto& colour = stamen.surface.pointData[0];
  EXPECT_EQ(colour.name, "colour");
  ASSERT_EQ(colour.values.size(), 3 * stamen.surface.points.size());
  EXPECT_DOUBLE_EQ(colour.values[0], 0.95);
  EXPECT_DOUBLE_EQ(colour.values[2], 0.2);
}

TEST_F(Flower, ValidationFindsNoViolatedPair)
{
  const ValidationReport report = validateComplex(*k, *mesh);
  EXPECT_TRUE(report.ok()) << report.text(*k);
  EXPECT_EQ(report.satisfied.size(), 17u);
  // The rim vertex t_1^0 also lies on the pistil's boundary, a pair the seed does not list.
  ASSERT_EQ(report.undeclared.size(), 1u) << report.text(*k);
  EXPECT_EQ(report.undeclared[0].first, k->idOf("t_2^3"));
  EXPECT_EQ(report.undeclared[0].second, k->idOf("t_1^0"));
}

TEST_F(Flower, FilamentEndsOnStamenAndPistil)
{
  // papers.md 5.A item 18: the filament's ends lie on the pistil and stamen surfaces, and its
  // inner points lie outside both.
  const CellMesh& filament = mesh->of(k->idOf("e_0^1"));
  const auto& line = filament.curves.lines.at(0);
  const Point3 start = filament.curves.points[line.front()];
  const Point3 end = filament.curves.points[line.back()];
  const auto& pistil = std::get<ImplicitGeometry>(k->cell(k->idOf("t_2^3")).geometry);
  const auto& stamen = std::get<ImplicitGeometry>(k->cell(k->idOf("t_0^3")).geometry);
  auto fp = pistil.inside[0]->evaluator();
  auto fs = stamen.inside[0]->evaluator();
  EXPECT_LT(std::abs(fp->value(start)), 1e-9);
  EXPECT_LT(std::abs(fs->value(end)), 1e-9);
  for (std::size_t i = 1; i + 1 < line.size(); ++i)
  {
    const Point3& p = filament.curves.points[line[i]];
    EXPECT_LT(fp->value(p), 0) << i;
    EXPECT_LT(fs->value(p), 0) << i;
  }
}

TEST_F(Flower, LowerDimensionalCellsLieOnTheirSets)
{
  // Rim t_1^1: every vertex on F_r = 0 and F_p = 0 (erratum E4's intended curve), one closed loop.
  const auto& rim = std::get<ImplicitGeometry>(k->cell(k->idOf("t_1^1")).geometry);
  auto fr = rim.carriers[0]->evaluator();
  auto fp = rim.carriers[1]->evaluator();
  const CellMesh& rimMesh = mesh->of(k->idOf("t_1^1"));
  ASSERT_EQ(rimMesh.curves.lines.size(), 1u);
  EXPECT_EQ(rimMesh.curves.lines[0].front(), rimMesh.curves.lines[0].back());
  for (const Point3& p : rimMesh.curves.points)
  {
    EXPECT_LT(std::abs(fr->value(p)), 1e-6);
    EXPECT_LT(std::abs(fp->value(p)), 1e-6);
  }
  // The interface patch lies on the receptacle surface, inside the pistil.
  const CellMesh& patch = mesh->of(k->idOf("t_1^2"));
  ASSERT_GT(patch.surface.triangles.size(), 100u);
  for (const Point3& p : patch.surface.points)
  {
    EXPECT_LT(std::abs(fr->value(p)), 1e-3);
    EXPECT_GE(fp->value(p), -1e-6);
  }
  // No vertex of the petal lies strictly inside the receptacle (papers.md 5.A item 16).
  const CellMesh& petal = mesh->of(k->idOf("t_0^2"));
  for (const Point3& p : petal.surface.points)
  {
    EXPECT_LE(fr->value(p), 1e-6);
  }
}

TEST_F(Flower, PetalDomainHasTwoHoles)
{
  // papers.md 5.A item 19: the petal domain (an ellipse minus two) has Euler characteristic -1;
  // the receptacle trim cuts the ellipse's inner end, not the holes.
  const CellMesh& petal = mesh->of(k->idOf("t_0^2"));
  const discretize::MeshTopology t = discretize::analyzeTopology(petal.surface);
  EXPECT_EQ(t.components, 1u);
  EXPECT_EQ(t.eulerCharacteristic, -1);
  EXPECT_TRUE(t.manifold());
}

TEST(ComplexFile, ErrorsNameFileLineAndCell)
{
  const std::string text = R"({
  "cells": [
    { "name": "ball", "kind": "F", "dimension": 3, "inside": ["1 - x[1]^2"],
      "bounds": [[-1, -1, -1], [1, 1, 1]] },
    { "name": "curve", "kind": "F", "dimension": 2, "carriers": ["x[1]", "x[2]"],
      "bounds": [[-1, -1, -1], [1, 1, 1]] }
  ],
  "relations": { "boundary": [["ball", "nothing"]] }
})";
  try
  {
    lang::readComplexJson(text, "bad.json");
    FAIL();
  }
  catch (const lang::ParseError& e)
  {
    const std::string what = e.what();
    EXPECT_THAT(what, HasSubstr("bad.json:5:15: error: cell 'curve'"));
    EXPECT_THAT(what, HasSubstr("2 carrier field(s) define a 1-dimensional set"));
    EXPECT_THAT(what, HasSubstr("bad.json:8:"));
    EXPECT_THAT(what, HasSubstr("no cell named 'nothing'"));
  }
  try
  {
    lang::readComplexJson("{ \"cells\": [ }", "syntax.json");
    FAIL();
  }
  catch (const lang::ParseError& e)
  {
    EXPECT_THAT(e.what(), HasSubstr("syntax.json:1:"));
    EXPECT_THAT(e.what(), HasSubstr("invalid JSON"));
  }
  try
  {
    lang::readComplexJson(R"({ "cells": [ { "name": "b", "kind": "F", "dimension": 3,
      "inside": ["1 - y^2"], "bounds": [[0,0,0],[1,1,1]] } ] })",
      "hf.json");
    FAIL();
  }
  catch (const lang::ParseError& e)
  {
    EXPECT_THAT(e.what(), HasSubstr("cell 'b': cannot compile '1 - y^2'"));
    EXPECT_THAT(e.what(), HasSubstr("unknown variable 'y'"));
  }
  EXPECT_THROW(lang::readComplexFile("/nonexistent/x.json"), lang::ParseError);
}

// Found by FuzzComplexJson (issue 19): a value of another JSON type than expected, or a number
// beyond double's range, escaped the reader as nlohmann's type_error or out_of_range; both are
// diagnostics at their place.
TEST(ComplexFile, ValuesOfTheWrongJsonTypeAreDiagnostics)
{
  auto message = [](const std::string& text)
  {
    try
    {
      lang::readComplexJson(text, "types.json");
    }
    catch (const lang::ParseError& e)
    {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_THAT(message(R"({ "cells": [ { "name": "c", "kind": "F", "dimension": 3,
    "inside": ["1"], "bounds": [[0, 0, 0], [1, 1, 1]], "attributes": { "density": 2.5 } } ] })"),
    HasSubstr("types.json:1:24: error: cell 'c': attribute 'density' must name an attribute "
              "function"));
  EXPECT_THAT(message("{ \"cells\": [ 1e99999 ] }"),
    HasSubstr("types.json:1:14: error: invalid JSON: number overflow parsing '1e99999'"));
  EXPECT_THAT(message(R"({ "name": 5, "cells": [] })"),
    HasSubstr("types.json: error: a value has the wrong JSON type (type must be string, but is "
              "number)"));
}

TEST(MarchingTetrahedra, SphereSurfaceWithinTolerance)
{
  // Marching tetrahedra with vertices refined onto f = 0: vertices within 1e-6 of the sphere;
  // triangle centroids within the chord error h^2 / (8 R) (h the longest edge, here at most
  // sqrt(3) * 0.05); closed, oriented manifold; volume within 1 % of 4/3 pi.
  const frep::FieldPtr f = field(frep::sphere({ 0, 0, 0 }, 1).function());
  discretize::ContourOptions o;
  o.featureSize = 0.05;
  const discretize::SurfaceMesh m =
    discretize::marchingTetrahedra(*f, { { -1.2, -1.2, -1.2 }, { 1.2, 1.2, 1.2 } }, o);
  double worstVertex = 0, worstCentroid = 0;
  for (const Point3& p : m.points)
  {
    worstVertex = std::max(worstVertex, std::abs(norm(p) - 1));
  }
  for (const auto& t : m.triangles)
  {
    Point3 c{ 0, 0, 0 };
    for (auto i : t)
    {
      for (int a = 0; a < 3; ++a)
      {
        c[a] += m.points[i][a] / 3;
      }
    }
    worstCentroid = std::max(worstCentroid, std::abs(norm(c) - 1));
  }
  EXPECT_LT(worstVertex, 1e-6);
  const double h = std::sqrt(3.0) * 0.05;
  EXPECT_LT(worstCentroid, h * h / 8);
  const discretize::MeshTopology t = discretize::analyzeTopology(m);
  EXPECT_TRUE(t.manifold()) << t.nonManifoldEdges << " " << t.nonManifoldVertices << " "
                            << t.inconsistentEdges << " " << t.degenerateTriangles;
  EXPECT_TRUE(t.closed());
  EXPECT_EQ(t.eulerCharacteristic, 2);
  EXPECT_NEAR(discretize::enclosedVolume(m), 4.0 / 3.0 * M_PI, 0.01 * 4.0 / 3.0 * M_PI);
  // Deterministic for any thread count.
  o.threads = 1;
  const discretize::SurfaceMesh one =
    discretize::marchingTetrahedra(*f, { { -1.2, -1.2, -1.2 }, { 1.2, 1.2, 1.2 } }, o);
  EXPECT_EQ(one.points, m.points);
  EXPECT_EQ(one.triangles, m.triangles);
  o.featureSize = 1e-6;
  EXPECT_THROW(
    discretize::marchingTetrahedra(*f, { { -1, -1, -1 }, { 1, 1, 1 } }, o), std::invalid_argument);
}

TEST(Attachment, CellAttachmentDerivesRelations)
{
  // papers.md 5.A items 9 and 10: attaching a segment to its two end points adds both Rb^{10}
  // pairs; an implicit ball attached around a point adds Rc^{30}; an explicit cell contains
  // nothing.
  Complex k;
  ExplicitGeometry a, b;
  a.points = { { 0, 0, 0 } };
  b.points = { { 0.5, 0, 0 } };
  const CellId pa = k.addCell(explicitCell("a", 0, a));
  const CellId pb = k.addCell(explicitCell("b", 0, b));
  ExplicitGeometry seg;
  seg.points = { { 0, 0, 0 }, { 0.25, 0, 0 }, { 0.5, 0, 0 } };
  seg.polylines = { { 0, 1, 2 } };
  AttachOptions o;
  o.discretization.featureSize = 0.05;
  const AttachResult r1 = attachCell(k, explicitCell("seg", 1, seg), o);
  EXPECT_EQ(r1.boundaryPairs.size(), 2u);
  EXPECT_TRUE(k.hasBoundary(r1.id, pa));
  EXPECT_TRUE(k.hasBoundary(r1.id, pb));
  EXPECT_TRUE(r1.containmentPairs.empty());
  const AttachResult r2 = attachCell(k,
    frepCell("ball", {}, { frep::sphere({ 0.25, 0, 0 }, 1).function() },
      { { -0.75, -1, -1 }, { 1.25, 1, 1 } }),
    o);
  // The ball strictly contains the two points and the segment.
  EXPECT_TRUE(r2.boundaryPairs.empty());
  EXPECT_EQ(r2.containmentPairs.size(), 3u);
  EXPECT_TRUE(k.hasContainment(r2.id, pa));
  EXPECT_TRUE(k.hasContainment(r2.id, r1.id));
  // An explicit point attached on the ball's surface: Rb^{30}, not Rc.
  ExplicitGeometry pole;
  pole.points = { { 0.25, 0, 1 } };
  const AttachResult r3 = attachCell(k, explicitCell("pole", 0, pole), o);
  EXPECT_TRUE(k.hasBoundary(r2.id, r3.id));
  EXPECT_FALSE(k.hasContainment(r2.id, r3.id));
}

TEST(Attachment, ComplexAttachmentQuotientsSharedCells)
{
  // papers.md 5.A item 11: K (a, b, ab) and L (b', c, b'c) joined along b ~ b': the counts add up
  // minus the shared cell, and L's relations are carried over through psi.
  auto pointCell = [](const char* name, Point3 p)
  {
    ExplicitGeometry g;
    g.points = { p };
    return explicitCell(name, 0, g);
  };
  auto segmentCell = [](const char* name, Point3 p, Point3 q)
  {
    ExplicitGeometry g;
    g.points = { p, q };
    g.polylines = { { 0, 1 } };
    return explicitCell(name, 1, g);
  };
  Complex k;
  const CellId a = k.addCell(pointCell("a", { 0, 0, 0 }));
  const CellId b = k.addCell(pointCell("b", { 1, 0, 0 }));
  const CellId ab = k.addCell(segmentCell("ab", { 0, 0, 0 }, { 1, 0, 0 }));
  k.addBoundary(ab, a);
  k.addBoundary(ab, b);
  Complex l;
  const CellId b2 = l.addCell(pointCell("b'", { 1, 0, 0 }));
  const CellId c = l.addCell(pointCell("c", { 2, 0, 0 }));
  const CellId bc = l.addCell(segmentCell("bc", { 1, 0, 0 }, { 2, 0, 0 }));
  l.addBoundary(bc, b2);
  l.addBoundary(bc, c);
  const auto map = attachComplex(k, l, { { b2, b } });
  EXPECT_EQ(k.cellsOfDimension(0).size(), 3u); // 2 + 2 - 1
  EXPECT_EQ(k.cellsOfDimension(1).size(), 2u); // 1 + 1 - 0
  EXPECT_TRUE(k.hasBoundary(map.at(bc), b));
  EXPECT_EQ(k.coboundaryOf(b).size(), 2u);
  EXPECT_EQ(k.findCell("b'"), nullptr);
  // A map between cells of different dimensions is refused before anything changes.
  Complex l2;
  const CellId x = l2.addCell(pointCell("x", { 5, 0, 0 }));
  EXPECT_THROW(attachComplex(k, l2, { { x, ab } }), ComplexError);
  EXPECT_EQ(k.cellCount(), 5u);
}

TEST(ComplexFile, CompositeAndComputedCells)
{
  // Two unit balls 1.2 apart: their union (C), their intersection lens (C), and the circle where
  // their boundaries meet (T): x = 0.6, y^2 + z^2 = 1 - 0.36 = 0.64, radius 0.8.
  const Complex k = lang::readComplexJson(R"({
  "cells": [
    { "name": "a", "kind": "F", "dimension": 3, "inside": ["1 - x[1]^2 - x[2]^2 - x[3]^2"],
      "bounds": [[-1, -1, -1], [1, 1, 1]] },
    { "name": "b", "kind": "F", "dimension": 3,
      "inside": ["1 - (x[1] - 1.2)^2 - x[2]^2 - x[3]^2"], "bounds": [[0.2, -1, -1], [2.2, 1, 1]] },
    { "name": "both", "kind": "C", "dimension": 3, "operation": "union", "operands": ["a", "b"] },
    { "name": "lens", "kind": "C", "dimension": 3, "operation": "intersection",
      "operands": ["a", "b"] },
    { "name": "rim", "kind": "T", "dimension": 1, "boundary_of": ["a", "b"] }
  ],
  "relations": { "boundary": [["lens", "rim"]], "containment": [["both", "lens"]] }
})",
    "two-balls.json");
  DiscretizationOptions o;
  o.featureSize = 0.04;
  const ComplexMesh mesh = discretizeComplex(k, o);
  // The union's volume: two balls minus the lens, 2 (4/3 pi) - 2 pi h^2 (3 - h) / 3, h = 0.4.
  const double lens = 2 * M_PI * 0.4 * 0.4 * (3 - 0.4) / 3;
  EXPECT_NEAR(discretize::enclosedVolume(mesh.of(k.idOf("both")).surface),
    2 * 4.0 / 3.0 * M_PI - lens, 0.01 * (8.0 / 3.0 * M_PI));
  EXPECT_NEAR(discretize::enclosedVolume(mesh.of(k.idOf("lens")).surface), lens, 0.02 * lens);
  const CellMesh& rim = mesh.of(k.idOf("rim"));
  ASSERT_EQ(rim.curves.lines.size(), 1u);
  for (const Point3& p : rim.curves.points)
  {
    EXPECT_NEAR(p[0], 0.6, 1e-8);
    EXPECT_NEAR(std::hypot(p[1], p[2]), 0.8, 1e-8);
  }
  const ValidationReport report = validateComplex(k, mesh);
  EXPECT_TRUE(report.ok()) << report.text(k);
  EXPECT_EQ(report.satisfied.size(), 2u);
  // The rim also bounds both balls and the union contains both balls: found, not declared.
  EXPECT_GE(report.undeclared.size(), 2u) << report.text(k);
}

TEST(ComplexFile, EmptyCellsAreErrors)
{
  // An FRep cell with no inside point, and the boundary curve of two balls that do not meet
  // (their boxes overlap, the spheres do not): both are named, not silently dropped.
  const Complex k = lang::readComplexJson(R"({
  "cells": [
    { "name": "nothing", "kind": "F", "dimension": 3, "inside": ["-1 - x[1]^2"],
      "bounds": [[-1, -1, -1], [1, 1, 1]] },
    { "name": "a", "kind": "F", "dimension": 3, "inside": ["1 - x[1]^2 - x[2]^2 - x[3]^2"],
      "bounds": [[-1, -1, -1], [1, 1, 1]] },
    { "name": "b", "kind": "F", "dimension": 3,
      "inside": ["1 - (x[1] - 1.9)^2 - (x[2] - 1.9)^2 - x[3]^2"], "bounds": [[0.9, 0.9, -1], [2.9, 2.9, 1]] },
    { "name": "meet", "kind": "T", "dimension": 1, "boundary_of": ["a", "b"] }
  ]
})",
    "empty.json");
  DiscretizationOptions o;
  o.featureSize = 0.05;
  for (const char* name : { "nothing", "meet" })
  {
    try
    {
      discretizeCell(k, k.idOf(name), o);
      FAIL() << name;
    }
    catch (const ComplexError& e)
    {
      EXPECT_THAT(e.what(), HasSubstr("cell '" + std::string(name) + "'"));
      EXPECT_THAT(e.what(), HasSubstr("is empty"));
    }
  }
  EXPECT_NO_THROW(discretizeCell(k, k.idOf("a"), o));
}
