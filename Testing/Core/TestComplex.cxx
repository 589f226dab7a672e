// SPDX-License-Identifier: BSD-3-Clause
// Relations, derived relations, cell checks and attribute priority of the implicit complex
// (seed 001 L85-128, thesis L810-866; spec papers.md 5.A items 1-4, 8).

#include "Complex/Attributes.h"
#include "Complex/Complex.h"
#include "FRep/Primitives.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

using namespace ictk;
using namespace ictk::complex;
using ::testing::ElementsAre;
using ::testing::HasSubstr;

namespace
{

Cell point(const std::string& name, Point3 p)
{
  ExplicitGeometry g;
  g.points = { p };
  return explicitCell(name, 0, g);
}

Cell segment(const std::string& name, Point3 a, Point3 b)
{
  ExplicitGeometry g;
  g.points = { a, b };
  g.polylines = { { 0, 1 } };
  return explicitCell(name, 1, g);
}

Cell ball(const std::string& name, Point3 c, double r)
{
  const frep::Expr f = frep::sphere({ c[0], c[1], c[2] }, r).function();
  return frepCell(
    name, {}, { f }, { { c[0] - r, c[1] - r, c[2] - r }, { c[0] + r, c[1] + r, c[2] + r } });
}

/// The unit square as a B-rep: 4 vertices, 4 edges, one face.
struct Square
{
  Complex k;
  CellId v[4], e[4], face;
  Square()
  {
    const Point3 p[4] = { { 0, 0, 0 }, { 1, 0, 0 }, { 1, 1, 0 }, { 0, 1, 0 } };
    for (int i = 0; i < 4; ++i)
    {
      v[i] = k.addCell(point("v" + std::to_string(i), p[i]));
    }
    for (int i = 0; i < 4; ++i)
    {
      e[i] = k.addCell(segment("e" + std::to_string(i), p[i], p[(i + 1) % 4]));
      k.addBoundary(e[i], v[i]);
      k.addBoundary(e[i], v[(i + 1) % 4]);
    }
    ExplicitGeometry g;
    g.points = { p[0], p[1], p[2], p[3] };
    g.triangles = { { 0, 1, 2 }, { 0, 2, 3 } };
    face = k.addCell(explicitCell("face", 2, g));
    for (int i = 0; i < 4; ++i)
    {
      k.addBoundary(face, e[i]);
      k.addBoundary(face, v[i]);
    }
  }
};

} // namespace

TEST(Relation, AddEraseRelated)
{
  // papers.md 5.A item 3 (seed 001 L221).
  Relation r;
  EXPECT_TRUE(r.add(3, 1));
  EXPECT_TRUE(r.add(3, 2));
  EXPECT_FALSE(r.add(3, 2));
  EXPECT_TRUE(r.erase(3, 1));
  EXPECT_FALSE(r.erase(3, 1));
  EXPECT_THAT(r.related(3), ElementsAre(2u));
  EXPECT_THAT(r.inverse(2), ElementsAre(3u));
  EXPECT_TRUE(r.related(2).empty());
}

TEST(Complex, RelationSlots)
{
  // Six boundary slots (s < p) and ten containment slots (s <= p), seed 001 L102, erratum E6.
  Complex k;
  int boundarySlots = 0, containmentSlots = 0;
  for (int p = 0; p <= 3; ++p)
  {
    for (int s = 0; s <= 3; ++s)
    {
      if (s < p)
      {
        EXPECT_NO_THROW(k.boundary(p, s));
        ++boundarySlots;
      }
      else
      {
        EXPECT_THROW(k.boundary(p, s), ComplexError);
      }
      if (s <= p)
      {
        EXPECT_NO_THROW(k.containment(p, s));
        ++containmentSlots;
      }
      else
      {
        EXPECT_THROW(k.containment(p, s), ComplexError);
      }
    }
  }
  EXPECT_EQ(boundarySlots, 6);
  EXPECT_EQ(containmentSlots, 10); // nine non-trivial ones plus Rc^{00}
}

TEST(Complex, BoundaryNeedsLowerDimension)
{
  Square sq;
  try
  {
    sq.k.addBoundary(sq.v[0], sq.e[0]);
    FAIL() << "a 0-cell cannot have a 1-cell on its boundary";
  }
  catch (const ComplexError& e)
  {
    EXPECT_THAT(e.what(), HasSubstr("'v0' (0D)"));
    EXPECT_THAT(e.what(), HasSubstr("s < p"));
  }
  EXPECT_THROW(sq.k.addBoundary(sq.e[0], sq.e[1]), ComplexError); // s == p
}

TEST(Complex, PairNeverInBothRelations)
{
  // thesis L1233: a pair in Rb cannot be in any containment relation, and the other way round.
  Complex k;
  const CellId b = k.addCell(ball("ball", { 0, 0, 0 }, 1));
  const CellId c = k.addCell(point("centre", { 0, 0, 0 }));
  const CellId s = k.addCell(point("pole", { 0, 0, 1 }));
  k.addContainment(b, c);
  k.addBoundary(b, s);
  try
  {
    k.addBoundary(b, c);
    FAIL();
  }
  catch (const ComplexError& e)
  {
    EXPECT_THAT(e.what(), HasSubstr("already in the containment relation"));
  }
  EXPECT_THROW(k.addContainment(b, s), ComplexError);
  EXPECT_TRUE(k.hasContainment(b, c));
  EXPECT_FALSE(k.hasBoundary(b, c));
  EXPECT_EQ(k.boundaryPairCount(), 1u);
  EXPECT_EQ(k.containmentPairCount(), 1u);
}

TEST(Complex, ContainmentRules)
{
  Complex k;
  const CellId b = k.addCell(ball("ball", { 0, 0, 0 }, 1));
  const CellId small = k.addCell(ball("small", { 0, 0, 0 }, 0.5));
  const CellId p = k.addCell(point("p", { 0, 0, 0 }));
  const CellId seg = k.addCell(segment("seg", { 0, 0, 0 }, { 0.1, 0, 0 }));
  k.addContainment(b, small); // equal dimensions are allowed (thesis L842)
  EXPECT_TRUE(k.containment(3, 3).contains(b, small));
  EXPECT_THROW(k.addContainment(p, b), ComplexError);   // s > p
  EXPECT_THROW(k.addContainment(b, b), ComplexError);   // itself
  EXPECT_THROW(k.addContainment(seg, p), ComplexError); // explicit cells are indivisible
  EXPECT_THROW(k.addContainment(b, 99), ComplexError);  // missing cell
  EXPECT_THROW(k.idOf("nothing"), ComplexError);
  EXPECT_THROW(k.addCell(ball("ball", { 5, 0, 0 }, 1)), ComplexError); // names are unique
}

TEST(Complex, DerivedRelations)
{
  Square sq;
  Complex& k = sq.k;
  EXPECT_EQ(k.cellsOfDimension(0).size(), 4u);
  EXPECT_EQ(k.cellsOfDimension(1).size(), 4u);
  EXPECT_EQ(k.dimension(), 2);
  EXPECT_EQ(k.boundary(1, 0).size(), 8u);
  EXPECT_EQ(k.boundary(2, 1).size(), 4u);
  EXPECT_EQ(k.boundary(2, 0).size(), 4u);
  // Co-boundary of v0: the edges e3 (v3-v0) and e0 (v0-v1), and the face.
  EXPECT_THAT(k.coboundaryOf(sq.v[0]), ElementsAre(sq.e[0], sq.e[3], sq.face));
  EXPECT_THAT(k.boundaryOf(sq.e[1]), ElementsAre(sq.v[1], sq.v[2]));
  // Edges sharing a vertex are adjacent; opposite edges are not.
  EXPECT_THAT(k.adjacentTo(sq.e[0]), ElementsAre(sq.e[1], sq.e[3]));
  EXPECT_THAT(k.incidentTo(sq.e[0]), ElementsAre(sq.v[0], sq.v[1], sq.face));
  // Removing a cell removes its pairs.
  k.removeCell(sq.v[0]);
  EXPECT_EQ(k.boundary(1, 0).size(), 6u);
  EXPECT_EQ(k.boundary(2, 0).size(), 3u);
  EXPECT_FALSE(k.hasCell(sq.v[0]));
  EXPECT_EQ(k.cellCount(), 8u);
}

TEST(Complex, ContainersAndContents)
{
  Complex k;
  const CellId big = k.addCell(ball("big", { 0, 0, 0 }, 2));
  const CellId mid = k.addCell(ball("mid", { 0, 0, 0 }, 1));
  const CellId p = k.addCell(point("p", { 0, 0, 0 }));
  k.addContainment(big, mid);
  k.addContainment(big, p);
  k.addContainment(mid, p);
  EXPECT_THAT(k.containersOf(p), ElementsAre(big, mid));
  EXPECT_THAT(k.contentsOf(big), ElementsAre(mid, p));
  EXPECT_TRUE(k.removeRelation(RelationKind::Containment, big, p));
  EXPECT_THAT(k.containersOf(p), ElementsAre(mid));
}

TEST(CellCheck, DimensionMustMatchGeometry)
{
  // Two carriers define a curve: declaring the cell 2D is an error naming the cell.
  Cell c =
    frepCell("curve", { frep::Expr::x(), frep::Expr::y() }, {}, { { -1, -1, -1 }, { 1, 1, 1 } });
  c.dimension = 2;
  try
  {
    checkCell(c);
    FAIL();
  }
  catch (const std::invalid_argument& e)
  {
    EXPECT_THAT(e.what(), HasSubstr("cell 'curve'"));
    EXPECT_THAT(e.what(), HasSubstr("2 carrier field(s) define a 1-dimensional set"));
  }
  ExplicitGeometry empty;
  EXPECT_THROW(checkCell(explicitCell("nothing", 0, empty)), std::invalid_argument);
  ExplicitGeometry lines;
  lines.points = { { 0, 0, 0 }, { 1, 0, 0 } };
  lines.polylines = { { 0, 1 } };
  EXPECT_THROW(checkCell(explicitCell("declared 2D", 2, lines)), std::invalid_argument);
  lines.polylines = { { 0, 7 } };
  EXPECT_THROW(checkCell(explicitCell("bad index", 1, lines)), std::invalid_argument);
  Cell unbounded = frepCell("nan box", {}, { frep::Expr::x() }, { { 0, 0, 0 }, { NAN, 1, 1 } });
  EXPECT_THROW(checkCell(unbounded), std::invalid_argument);
}

TEST(CellCheck, NonManifoldMeshRefused)
{
  // Three triangles on one edge.
  ExplicitGeometry g;
  g.points = { { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 }, { 0, -1, 0 }, { 0, 0, 1 } };
  g.triangles = { { 0, 1, 2 }, { 1, 0, 3 }, { 0, 1, 4 } };
  try
  {
    checkCell(explicitCell("fin", 2, g));
    FAIL();
  }
  catch (const std::invalid_argument& e)
  {
    EXPECT_THAT(e.what(), HasSubstr("cell 'fin'"));
    EXPECT_THAT(e.what(), HasSubstr("not a manifold (1 edge(s)"));
  }
}

TEST(Attributes, PriorityDefaultsAndTies)
{
  // Two overlapping balls bind "density" with priorities 1 and 2; a third ball binds nothing.
  Complex k;
  const CellId a = k.addCell(ball("a", { 0, 0, 0 }, 1));
  const CellId b = k.addCell(ball("b", { 1, 0, 0 }, 1));
  const CellId c = k.addCell(ball("c", { 5, 0, 0 }, 1));
  const CellId p = k.addCell(point("p", { -0.5, 0, 0 }));
  (void)c;
  k.declareAttribute("density", { 1, { -1 }, { -2 } });
  auto constant = [](double v)
  {
    auto f = std::make_shared<AttributeFunction>();
    f->name = "S";
    f->components = { frep::tapeField(frep::Tape::compile(frep::Expr::constant(v))) };
    return f;
  };
  k.bindAttribute(a, { "density", constant(10), 1 });
  k.bindAttribute(b, { "density", constant(20), 2 });
  k.bindAttribute(p, { "density", constant(30), 1 });
  EXPECT_THROW(k.bindAttribute(b, { "density", nullptr, 2 }), ComplexError);

  ComplexMesh mesh;
  for (CellId id : k.cellIds())
  {
    CellMesh m;
    m.cell = id;
    m.dimension = k.cell(id).dimension;
    if (id == p)
    {
      m.points.points = { { -0.5, 0, 0 } };
    }
    mesh.cells.push_back(m);
  }
  AttributeLookup lookup(k, mesh, 1e-6);
  EXPECT_EQ(lookup.value("density", { -0.9, 0, 0 }).value, std::vector<double>{ 10 });
  // Overlap of a and b: b has the higher priority.
  auto overlap = lookup.value("density", { 0.5, 0, 0 });
  EXPECT_EQ(overlap.value, std::vector<double>{ 20 });
  EXPECT_EQ(*overlap.cell, b);
  // The point p lies in a; equal priority 1: the lower-dimensional cell wins.
  EXPECT_EQ(lookup.value("density", { -0.5, 0, 0 }).value, std::vector<double>{ 30 });
  // Inside c, which binds nothing: theta1; outside every cell: theta0.
  EXPECT_EQ(lookup.value("density", { 5, 0, 0 }).value, std::vector<double>{ -1 });
  EXPECT_FALSE(lookup.value("density", { 5, 0, 0 }).cell.has_value());
  EXPECT_EQ(lookup.value("density", { 0, 9, 0 }).value, std::vector<double>{ -2 });
  EXPECT_THROW(lookup.value("colour", { 0, 0, 0 }), ComplexError);
}
