// SPDX-License-Identifier: BSD-3-Clause
// Tests of the parametric implants (FRep/Implants.h, issue 15) with hand-derived numbers: the
// screw's field on and off its thread, the plate's holes counted by the Euler characteristic of
// its meshed surface, the gyroid sheet's wall thickness and volume fraction against the analytic
// values, the interface shell's volume, the placements, the HyperFun entries and the errors.
#include "PrimitivesTesting.h"

#include "Discretize/Surface.h"
#include "FRep/Field.h"
#include "FRep/Implants.h"
#include "FRep/Tape.h"
#include "Lang/HyperFun.h"

#include <cmath>
#include <map>
#include <utility>

using namespace primitivestest;

namespace
{

/// The mean of the solid's indicator over `box` by the midpoint rule on n^3 points: the volume
/// fraction of the solid in the box.
double volumeFraction(const Shape& s, const Box3& box, int n)
{
  BatchEvaluator<double> eval(Tape::compile(s.function()));
  std::vector<double> x(static_cast<std::size_t>(n)), y(x.size()), z(x.size()), t(x.size()),
    v(x.size());
  for (int i = 0; i < n; ++i)
  {
    x[static_cast<std::size_t>(i)] = box.lo[0] + (i + 0.5) * (box.hi[0] - box.lo[0]) / n;
  }
  std::size_t inside = 0;
  for (int k = 0; k < n; ++k)
  {
    for (int j = 0; j < n; ++j)
    {
      std::fill(y.begin(), y.end(), box.lo[1] + (j + 0.5) * (box.hi[1] - box.lo[1]) / n);
      std::fill(z.begin(), z.end(), box.lo[2] + (k + 0.5) * (box.hi[2] - box.lo[2]) / n);
      eval.eval(x.data(), y.data(), z.data(), t.data(), v.data(), x.size());
      inside += static_cast<std::size_t>(
        std::count_if(v.begin(), v.end(), [](double f) { return f >= 0; }));
    }
  }
  return static_cast<double>(inside) / (double(n) * n * n);
}

double volume(const Shape& s, const Box3& box, int n)
{
  return volumeFraction(s, box, n) * (box.hi[0] - box.lo[0]) * (box.hi[1] - box.lo[1]) *
    (box.hi[2] - box.lo[2]);
}

/// V - E + F of a closed triangle mesh; fails the test if an edge is not shared by exactly two
/// triangles.
long eulerCharacteristic(const ictk::discretize::SurfaceMesh& m)
{
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> edges;
  for (const auto& t : m.triangles)
  {
    for (int e = 0; e < 3; ++e)
    {
      const std::uint32_t a = t[e], b = t[(e + 1) % 3];
      ++edges[{ std::min(a, b), std::max(a, b) }];
    }
  }
  for (const auto& [edge, uses] : edges)
  {
    EXPECT_EQ(uses, 2) << "edge " << edge.first << "-" << edge.second;
  }
  return static_cast<long>(m.points.size()) - static_cast<long>(edges.size()) +
    static_cast<long>(m.triangles.size());
}

Shape hyperfun(const std::string& body)
{
  return ictk::lang::readHyperFun("model(x[3], a[1]) {\n  " + body + "\n}", "implant.hf")
    .model.geometry();
}

} // namespace

TEST(Implants, ScrewFieldOnAndOffTheThread)
{
  // core 1.5, crest 2, pitch 1, length 10: at theta = 0 the thread's radius is
  // 1.5 + 0.5 (1 - |2 frac(z) - 1|): the crest at z = n + 1/2, the root at z = n.
  const Shape s = screw({ 1.5, 2, 1, 10 });
  EXPECT_NEAR(at(s, 2, 0, 5.5), 0, 1e-12);      // on the crest
  EXPECT_NEAR(at(s, 1.5, 0, 5.0), 0, 1e-12);    // on the root
  EXPECT_NEAR(at(s, 1.75, 0, 5.25), 0, 1e-12);  // half way up the flank
  EXPECT_NEAR(at(s, 1.9, 0, 5.0), -0.4, 1e-12); // between two turns: outside by 0.4
  EXPECT_NEAR(at(s, 1.9, 0, 5.5), 0.1, 1e-12);  // inside the crest
  EXPECT_NEAR(at(s, 0, 0, 5.2), 1.7, 1e-12);    // on the axis (atan2(0, 0) = 0): r = 1.7
  EXPECT_NEAR(at(s, 0, 0, -0.5), -0.5, 1e-12);  // below the tip
  // A quarter turn later (theta = pi/2) the crest is a quarter pitch higher: right-handed.
  EXPECT_NEAR(at(s, 0, 2, 5.75), 0, 1e-12);
  EXPECT_NEAR(at(s, 0, 2, 5.5), -0.25, 1e-12);
  // Across atan2's cut (theta = +-pi) the field is continuous: the crest at z = n.
  EXPECT_NEAR(at(s, -2, 1e-12, 6.0), 0, 1e-9);
  EXPECT_NEAR(at(s, -2, -1e-12, 6.0), 0, 1e-9);
  // The kernel's intervals: a box around the crest point straddles 0, a box off the screw is
  // certified outside, a box on the core inside.
  IntervalEvaluator iv(Tape::compile(s.function()));
  Region r;
  r.axes = { Interval{ 1.95, 2.05 }, Interval{ -0.05, 0.05 }, Interval{ 5.45, 5.55 },
    Interval{ 0, 0 } };
  const Interval crest = iv.eval(r);
  EXPECT_LT(crest.lo, 0);
  EXPECT_GT(crest.hi, 0);
  r.axes = { Interval{ 5, 6 }, Interval{ 5, 6 }, Interval{ 2, 3 }, Interval{ 0, 0 } };
  EXPECT_TRUE(iv.eval(r).negative());
  r.axes = { Interval{ 0.2, 0.6 }, Interval{ 0.2, 0.6 }, Interval{ 4, 5 }, Interval{ 0, 0 } };
  EXPECT_TRUE(iv.eval(r).positive());
}

TEST(Implants, PlacementMovesTheImplantsFrame)
{
  // A pin of radius 2.5 and length 6 along (0, 0, 2) from (10, 20, 30): the identity frame moved.
  const Shape p = pin(2.5, 6, { { 10, 20, 30 }, { 0, 0, 2 } });
  EXPECT_NEAR(at(p, 12.5, 20, 33), 0, 1e-12);
  EXPECT_NEAR(at(p, 10, 20, 33), 2.5, 1e-12);
  EXPECT_NEAR(at(p, 10, 20, 36.5), -0.5, 1e-12);
  // Along (1, 1, 0): 3 along the axis, then 2.5 along z (perpendicular to it) is on the surface.
  const double h = 3 / std::sqrt(2.0);
  const Shape q = pin(2.5, 6, { { 1, 2, 3 }, { 1, 1, 0 } });
  EXPECT_NEAR(at(q, 1 + h, 2 + h, 5.5), 0, 1e-12);
  EXPECT_NEAR(at(q, 1 + h, 2 + h, 3), 2.5, 1e-12);
  EXPECT_NEAR(at(q, 1 - 0.5 / std::sqrt(2.0), 2 - 0.5 / std::sqrt(2.0), 3), -0.5, 1e-12);
  // The plate's local x follows the reference: a plate along y, normal x, from the origin.
  const Shape plateAlongY = plate({ 20, 8, 2, 1.5, {} }, { { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 } });
  // local (x, y, z) = (world y, world z, world x) there: local (10, 4, 1) is world (1, 10, 4).
  EXPECT_NEAR(at(plateAlongY, 1, 10, 4), 1, 1e-12);
  EXPECT_NEAR(at(plateAlongY, 1, 21, 4), -1, 1e-12);
}

TEST(Implants, PlateHolesAreHandlesOfItsSurface)
{
  // A closed surface of genus g has Euler characteristic 2 - 2g; each hole through the plate
  // adds one handle.
  const Box3 box{ { -1, -1, -1 }, { 21, 9, 3 } };
  ictk::discretize::SurfaceOptions o;
  o.featureSize = 0.25;
  for (std::size_t holes = 0; holes <= 3; ++holes)
  {
    PlateShape p{ 20, 8, 2, 1.5, {} };
    for (std::size_t i = 0; i < holes; ++i)
    {
      p.holes.push_back({ 4 + 6.0 * static_cast<double>(i), 4 });
    }
    const auto mesh =
      ictk::discretize::contourSurface(*tapeField(Tape::compile(plate(p).function())), box, o);
    EXPECT_EQ(eulerCharacteristic(mesh), 2 - 2 * static_cast<long>(holes)) << holes << " holes";
  }
  // The field: a face distance on the rim, a hole's radial distance inside it.
  const Shape p = plate({ 20, 8, 2, 1.5, { { 4, 4 } } });
  EXPECT_NEAR(at(p, 10, 4, 1), 1, 1e-12);
  EXPECT_NEAR(at(p, 4, 4, 1), -1.5, 1e-12);
  EXPECT_NEAR(at(p, 4, 6, 1), 0.5, 1e-12);
}

TEST(Implants, GyroidWallAndVolumeFraction)
{
  // The nodal gyroid passes through the origin with grad g / k = (1, 1, 1): walking w/2 along
  // the unit normal reaches the wall's side (to first order in w / a).
  const double a = 2, w = 0.1;
  const Shape s = gyroidSheet(a, Expr(w));
  EXPECT_NEAR(at(s, 0, 0, 0), w / 2, 1e-12);
  const double d = w / 2 / std::sqrt(3.0);
  EXPECT_NEAR(at(s, d, d, d), 0, 0.02 * w / 2);
  // Volume fraction at w = a / 20 over one cell: (A / V) w - (4 pi / 3) (w / a)^3 with Schoen's
  // A / V = 3.0915 / a: 0.154575 - 0.000524 = 0.154051. (The wall is a first-order distance:
  // thinner than w where it is thick against the cell, by 0.7 % in volume here, 3.6 % at
  // w = a / 10.)
  const double expected = 3.0915 * 0.05 - 4 * pi / 3 * 0.05 * 0.05 * 0.05;
  const Box3 cell{ { 0, 0, 0 }, { a, a, a } };
  const double vf = volumeFraction(s, cell, 160);
  EXPECT_NEAR(vf / expected, 1, 0.01) << vf;
  // Graded along z from a / 40 to 3 a / 40: the fraction is the mean of the local ones,
  // 3.0915 mean(w / a) - (4 pi / 3) mean((w / a)^3) = 0.154575 - 4.18879 * 1.5625e-4.
  const Expr graded = 0.025 * a + 0.05 * Expr::z();
  const double gradedExpected = 3.0915 * 0.05 - 4 * pi / 3 * 1.5625e-4;
  const Shape g = gyroidSheet(a, graded);
  EXPECT_NEAR(volumeFraction(g, cell, 160) / gradedExpected, 1, 0.015);
  // The wall follows the field: the bottom fifth (mean w / a = 0.03) against the top fifth
  // (0.07) holds 3/7 as much, to first order.
  const double bottom = volumeFraction(g, { { 0, 0, 0 }, { a, a, 0.4 } }, 160);
  const double top = volumeFraction(g, { { 0, 0, 1.6 }, { a, a, a } }, 160);
  EXPECT_NEAR(bottom / top, 3.0 / 7.0, 0.03) << bottom << " " << top;
}

TEST(Implants, InterfaceShellVolume)
{
  // The shell of 0.5 around a pin of radius 2.5 and length 6 (the slab ends offset too, so the
  // shell also caps the pin's ends): pi (3^2 - 2.5^2) 6 in the pin's slab, plus two caps of
  // pi 3^2 0.5.
  const Shape shell = interfaceShell(pin(2.5, 6), 0.5);
  const double side = pi * (9 - 6.25) * 6;
  const double caps = 2 * pi * 9 * 0.5;
  // The samples' cells end on the planar faces (z = -0.5, 0, 6, 6.5: multiples of 7 / 140).
  const Box3 box{ { -3, -3, -0.5 }, { 3, 3, 6.5 } };
  EXPECT_NEAR(volume(shell, box, 140) / (side + caps), 1, 0.005);
  EXPECT_NEAR(at(shell, 2.75, 0, 3), 0.25, 1e-12);
  EXPECT_NEAR(at(shell, 2, 0, 3), -0.5, 1e-12);
}

TEST(Implants, HyperFunPlacesTheSameShapes)
{
  Random random(15);
  auto same = [&](const Shape& a, const Shape& b)
  {
    for (int i = 0; i < 50; ++i)
    {
      const Vec3 p = random.point(-3, 12);
      EXPECT_NEAR(at(a, p), at(b, p), 1e-12) << p[0] << " " << p[1] << " " << p[2];
    }
  };
  same(hyperfun("array o[3], d[3];\n  o = [1, 2, 3]; d = [0, 1, 1];\n"
                "  model = hfScrew(x, o, d, 1.5, 2, 1, 8);"),
    screw({ 1.5, 2, 1, 8 }, { { 1, 2, 3 }, { 0, 1, 1 } }));
  same(hyperfun("array o[3], d[3];\n  o = [1, 2, 3]; d = [0, 0, 1];\n"
                "  model = hfPin(x, o, d, 2.5, 6);"),
    pin(2.5, 6, { { 1, 2, 3 }, { 0, 0, 1 } }));
  same(hyperfun("array o[3], d[3], r[3], h[4];\n  o = [0, 0, 1]; d = [0, 0, 1]; r = [1, 1, 0];\n"
                "  h = [3, 4, 9, 4];\n  model = hfPlate(x, o, d, r, 12, 8, 2, 1.5, h);"),
    plate({ 12, 8, 2, 1.5, { { 3, 4 }, { 9, 4 } } }, { { 0, 0, 1 }, { 0, 0, 1 }, { 1, 1, 0 } }));
  // The wall is any expression: graded along z.
  same(
    hyperfun("model = hfGyroid(x, 2, 0.1 + 0.02 * x[3]);"), gyroidSheet(2, 0.1 + 0.02 * Expr::z()));
}

TEST(Implants, BadParametersNameTheImplant)
{
  expectInvalid([] { screw({ 1.5, 2, notANumber, 10 }); }, { "screw", "pitch", "nan" });
  expectInvalid([] { screw({ 2, 1.5, 1, 10 }); }, { "screw", "coreRadius", "majorRadius" });
  expectInvalid([] { pin(-1, 5); }, { "pin", "radius", "positive" });
  expectInvalid([] { pin(1, 5, { { 0, 0, 0 }, { 0, 0, 0 } }); }, { "pin", "axis" });
  expectInvalid([] { pin(1, 5, { { 0, infinity, 0 } }); }, { "pin", "origin", "finite" });
  expectInvalid(
    []
    {
      plate(
        {
          20,
          8,
          2,
          1.5,
          {},
        },
        { {}, { 0, 0, 1 }, { 0, 0, 3 } });
    },
    { "plate", "parallel" });
  expectInvalid([] { plate({ 20, 8, 2, 1.5, { { 1, 4 } } }); }, { "plate", "holes[0]", "within" });
  expectInvalid(
    [] {
      plate({ 20, 8, 2, 1.5, { { 4, 4 }, { 6, 4 } } });
    },
    { "plate", "holes[1]", "overlaps" });
  expectInvalid([] { gyroidSheet(0, Expr(0.1)); }, { "gyroid", "cellSize" });
  expectInvalid([] { gyroidSheet(1, Expr::t()); }, { "gyroid", "wallThickness" });
  expectInvalid([] { interfaceShell(pin(1, 1), notANumber); }, { "interfaceShell", "thickness" });
  try
  {
    hyperfun("array o[3], d[3];\n  o = [0, 0, 0]; d = [0, 0, 1];\n"
             "  model = hfScrew(x, o, d, 1.5, 2, 0, 8);");
    ADD_FAILURE() << "a zero pitch was accepted";
  }
  catch (const std::exception& e)
  {
    EXPECT_NE(
      std::string(e.what()).find("hfScrew: screw: pitch must be positive"), std::string::npos)
      << e.what();
  }
}
