// SPDX-License-Identifier: BSD-3-Clause
// The HyperFun models shipped in Data/Models: each one reads, and its field has the values
// computed by hand (derivations in the comments) or, for library-heavy models, the values of the
// same model built with the C++ kernel.
#include "FRep/Evaluators.h"
#include "FRep/Operations.h"
#include "FRep/Primitives.h"
#include "FRep/Sampling.h"
#include "Lang/FRepXml.h"
#include "Lang/HyperFun.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

using namespace ictk;
using frep::Axis;
using frep::Expr;
using frep::Shape;

namespace
{
const std::string DataDir = ICTK_DATA_DIR;

lang::HyperFunModel load(const std::string& name)
{
  return lang::readHyperFunFile(DataDir + "/Models/" + name);
}

double at(const lang::HyperFunModel& m, std::array<double, 4> p, const std::vector<double>& a = {})
{
  std::vector<double> params = a;
  params.resize(static_cast<std::size_t>(std::max(m.parameterCount, 0)), 0.0);
  frep::PointEvaluator ev(frep::Tape::compile(m.model.geometry().function()), params);
  return ev.eval(p[0], p[1], p[2], p[3]);
}

// The same field, up to rounding, at points spread over [-2.5, 2.5]^3.
void expectSameField(const lang::HyperFunModel& m, const Shape& reference)
{
  frep::PointEvaluator a(frep::Tape::compile(m.model.geometry().function()),
    std::vector<double>(static_cast<std::size_t>(m.parameterCount), 0.0));
  frep::PointEvaluator b(frep::Tape::compile(reference.function()));
  for (int i = 0; i < 200; ++i)
  {
    // A fixed low-discrepancy sequence (golden-ratio steps), so the points are reproducible.
    const double x = -2.5 + 5 * std::fmod(0.5 + i * 0.6180339887498949, 1.0);
    const double y = -2.5 + 5 * std::fmod(0.5 + i * 0.7548776662466927, 1.0);
    const double z = -2.5 + 5 * std::fmod(0.5 + i * 0.5698402909980532, 1.0);
    const double va = a.eval(x, y, z), vb = b.eval(x, y, z);
    EXPECT_NEAR(va, vb, 1e-12 * (1 + std::fabs(vb)))
      << m.name << " at " << x << " " << y << " " << z;
  }
}
} // namespace

TEST(DataModels, EveryModelReadsAndSamples)
{
  int count = 0;
  for (const auto& entry : std::filesystem::directory_iterator(DataDir + "/Models"))
  {
    if (entry.path().extension() != ".hf")
    {
      continue;
    }
    SCOPED_TRACE(entry.path().string());
    // Specialised to parameter values, as ictk does with --params (parametric_ring needs them).
    const lang::HyperFunModel m =
      lang::readHyperFunFile(entry.path().string(), {}, {}, { 0.8, 0.3 });
    const frep::TapePtr tape = frep::Tape::compile(m.model.geometry().function());
    const frep::Grid grid = frep::gridOverBox({ -2, -2, -2 }, { 2, 2, 2 }, { 9, 9, 9 }, 0.5);
    std::vector<float> values(static_cast<std::size_t>(grid.pointCount()));
    frep::SampleOptions options;
    options.parameters.assign(static_cast<std::size_t>(m.parameterCount), 0.5);
    frep::sampleGrid(tape, grid, values.data(), options);
    ++count;
  }
  EXPECT_GE(count, 15);
}

TEST(DataModels, Sphere)
{
  // 4 - (x - 1)^2 - y^2 - z^2.
  const auto m = load("sphere.hf");
  EXPECT_EQ(m.model.geometry().domain(), frep::Domain::XYZ);
  EXPECT_DOUBLE_EQ(at(m, { 0, 0, 0, 0 }), 3.0);
  EXPECT_DOUBLE_EQ(at(m, { 1, 0, 0, 0 }), 4.0);
  EXPECT_DOUBLE_EQ(at(m, { 3, 0, 0, 0 }), 0.0);
  EXPECT_DOUBLE_EQ(at(m, { 1, 2, 2, 0 }), -4.0);
}

TEST(DataModels, Disk2dIsTwoDimensional)
{
  // f1 = 4 - x^2 - y^2, f2 = 0.25 - (x - 1)^2 - y^2, f1 \ f2 = f1 - f2 - sqrt(f1^2 + f2^2):
  // at (0, 0): 4 + 0.75 - sqrt(16.5625) = 0.68029485097507...; at (1, 0): 2.75 - sqrt(9.0625).
  const auto m = load("disk2d.hf");
  EXPECT_EQ(m.model.geometry().domain(), frep::Domain::XY);
  EXPECT_NEAR(at(m, { 0, 0, 0, 0 }), 0.6802948509750735, 1e-15);
  EXPECT_NEAR(at(m, { 1, 0, 0, 0 }), -0.26039864469807394, 1e-15);
  EXPECT_NEAR(at(m, { -1.5, 0.5, 0, 0 }), 1.3225199339087794, 1e-15);
}

TEST(DataModels, GrowingBallIsSpaceTime)
{
  // r = 0.5 + t, f = r^2 - (x - t)^2 - y^2 - z^2.
  const auto m = load("growing_ball.hf");
  EXPECT_EQ(m.model.geometry().domain(), frep::Domain::XYZT);
  EXPECT_DOUBLE_EQ(at(m, { 0, 0, 0, 0 }), 0.25);
  EXPECT_DOUBLE_EQ(at(m, { 0.5, 0, 0, 0.5 }), 1.0);
  EXPECT_DOUBLE_EQ(at(m, { 1.5, 0, 0, 0.5 }), 0.0);
  EXPECT_DOUBLE_EQ(at(m, { 1, 1, 0, 1 }), 1.25);
}

TEST(DataModels, BranchesOnConstantsAndCoordinates)
{
  // mode = 2 selects r = 1 at compile time. Above z = 0: 1 - |p|^2, at (0, 0, 0.5): 0.75. Below:
  // ((1 - |x|) & (1 - |y|)) & (1 - |z|) with R-intersections: at (0, 0, -0.5),
  // (2 - sqrt(2)) & 0.5 = 0.31562687590763...
  const auto m = load("branches.hf");
  EXPECT_DOUBLE_EQ(at(m, { 0, 0, 0.5, 0 }), 0.75);
  EXPECT_NEAR(at(m, { 0, 0, -0.5, 0 }), 0.31562687590763383, 1e-15);
  // The coordinate branch is a select node: interval pruning decides it per region.
  frep::IntervalEvaluator interval(frep::Tape::compile(m.model.geometry().function()));
  frep::Region above;
  above.axes = { frep::Interval{ -1, 1 }, frep::Interval{ -1, 1 }, frep::Interval{ 0.1, 1 },
    frep::Interval{ 0, 0 } };
  interval.eval(above);
  EXPECT_LT(interval.simplified()->instructions().size(), interval.tape()->instructions().size());
}

TEST(DataModels, LoopBuildsTheClosedForm)
{
  // loops = ((((-1 | s0) | s1) | s2) | s3) | s4 with s_i the ball of radius 0.45 at (i - 2, 0, 0).
  const auto m = load("loops.hf");
  Shape closed(Expr(-1.0), frep::Domain::XYZ, "start");
  for (int i = 0; i < 5; ++i)
  {
    closed = frep::unite(closed, frep::sphere({ i - 2.0, 0, 0 }, 0.45));
  }
  expectSameField(m, closed);
}

TEST(DataModels, OperatorsAndLogic)
{
  // disk @ layer is their R-intersection; hollow = cylinder & -(0.25 - x^2 - y^2); the logic
  // factor is 1 for |x| < 2 and 0 beyond (y <= 5 there; z > 10 is false, so xor keeps it):
  // values computed by hand from these forms.
  const auto m = load("operators.hf");
  EXPECT_NEAR(at(m, { 0.75, 0, 0, 0 }), 0.13366099826182526, 1e-15);
  EXPECT_NEAR(at(m, { 0.2, 0, 0, 0 }), -0.29469964279669714, 1e-15);
  EXPECT_DOUBLE_EQ(at(m, { 3, 0, 0, 0 }), -1.0);
}

TEST(DataModels, MathFunctions)
{
  const auto m = load("math.hf");
  EXPECT_NEAR(at(m, { 0.3, -0.2, 0.1, 0 }), 0.28197224362268003, 1e-14);
  EXPECT_NEAR(at(m, { -1, 0.5, 0.4, 0 }), -0.08151440324678715, 1e-14);
  EXPECT_NEAR(at(m, { 0, 0, 0, 0 }), 0.3, 1e-15);
}

TEST(DataModels, FunctionsCallingEachOther)
{
  // my_model = a[2] * (b1 | b2 | b3) + a[1], the beads being balls of radius 0.5 at x = -1, 0,
  // 1: the model is my_model, though another function comes first (HyperFun's rule).
  const auto m = load("functions.hf");
  EXPECT_EQ(m.name, "my_model");
  EXPECT_EQ(m.parameterCount, 2);
  const Shape beads =
    frep::unite(frep::unite(frep::sphere({ -1, 0, 0 }, 0.5), frep::sphere({ 0, 0, 0 }, 0.5)),
      frep::sphere({ 1, 0, 0 }, 0.5));
  frep::PointEvaluator reference(frep::Tape::compile(beads.function()));
  for (const auto& p :
    { std::array<double, 4>{ 0, 0, 0, 0 }, { 0.5, 0.45, 0, 0 }, { 1.2, 0.1, 0, 0 } })
  {
    const double b = reference.eval(p[0], p[1], p[2]);
    EXPECT_NEAR(at(m, p, { 0.1, 2.0 }), 2.0 * b + 0.1, 1e-14);
  }
}

TEST(DataModels, BracketSigns)
{
  // In the hole on the axis: outside; in the plate beside the hole and in the cap: inside.
  const auto m = load("bracket.hf");
  EXPECT_LT(at(m, { 0, 0, 0, 0 }), 0.0);
  EXPECT_GT(at(m, { 0.7, 0, 0, 0 }), 0.0);
  EXPECT_GT(at(m, { 0.5, 0, 1.0, 0 }), 0.0);
  EXPECT_LT(at(m, { 0, 0, 1.4, 0 }), 0.0);
  const Shape plate = frep::blockRFunction({ -1, -1, -0.5 }, 2, 2, 1, 0.0);
  const Shape cap = frep::sphere({ 0, 0, 0.5 }, 0.8);
  const Shape hole = frep::cylinder(Axis::Z, { 0, 0, 0 }, 0.4);
  expectSameField(m, frep::subtract(frep::unite(plate, cap), hole));
}

TEST(DataModels, ColourAttribute)
{
  // hfA_SetColor: the band |z| < 0.1 of the wall is blue, the rest of the wall orange.
  const auto m = load("coloured_vase.hf");
  const frep::Attribute* colour = m.model.findAttribute("colour");
  ASSERT_NE(colour, nullptr);
  ASSERT_EQ(colour->components.size(), 3u);
  frep::HypervolumeEvaluator ev(m.model);
  double f, c[3];
  ev.eval({ 0.55, 0, 0, 0 }, f, c);
  EXPECT_GT(f, 0.0);
  EXPECT_DOUBLE_EQ(c[0], 0.1);
  EXPECT_DOUBLE_EQ(c[1], 0.2);
  EXPECT_DOUBLE_EQ(c[2], 0.9);
  ev.eval({ 0.55, 0, 0.5, 0 }, f, c);
  EXPECT_GT(f, 0.0);
  EXPECT_DOUBLE_EQ(c[0], 0.8);
  EXPECT_DOUBLE_EQ(c[1], 0.5);
  EXPECT_DOUBLE_EQ(c[2], 0.2);
}

TEST(DataModels, LibraryModelsMatchTheCppKernel)
{
  using frep::unite;
  {
    // twisted_torus: hfTwistZ then hfTorusZ on the twisted coordinates.
    const Shape torus = frep::torus(Axis::Z, { 0, 0, 0 }, 1, 0.3);
    expectSameField(load("twisted_torus.hf"), frep::twist(torus, Axis::Z, -1, 1, -0.5, 0.5));
  }
  {
    const Shape e1 = frep::ellipsoid({ -0.6, 0, 0 }, 0.8, 0.5, 0.5);
    const Shape e2 = frep::ellipsoid({ 0.6, 0, 0 }, 0.8, 0.5, 0.5);
    const Shape slab(Expr(0.09) - square(Expr::z()), frep::Domain::XYZ, "slab");
    expectSameField(load("blended_ellipsoids.hf"),
      frep::blendIntersection(frep::blendUnion(e1, e2, 0.5, 1, 1), slab, 0.1, 1, 1));
  }
  {
    const Shape s = unite(frep::superellipsoid({ 0, 0, 0 }, 1, 1, 1, 0.2, 0.2),
      frep::torus(Axis::X, { 2.5, 0, 0 }, 0.8, 0.2));
    expectSameField(load("superellipsoid.hf"), s);
  }
  {
    const std::vector<frep::Vec3> c{ { -1, 0, 0 }, { 0, 0.5, 0 }, { 1, 0, 0 } };
    const Shape blobby = frep::blobby(c, { 2, 2, 2 }, { 1, 1, 1 }, 0.3);
    const std::vector<frep::Vec3> cm{ { -1, 0, 0 }, { 0, 0, 0.5 }, { 1, 0, 0 } };
    const Shape meta = frep::metaball(cm, { 1, 1, 1 }, { 1.2, 1.2, 1.2 }, 0.4);
    const std::vector<frep::Vec3> cs{ { 0, -1, 0 }, { 0, 0, 0.5 }, { 0, 1, 0 } };
    const Shape soft = frep::softObject(cs, { 1.2, 1.2, 1.2 }, 0.2);
    expectSameField(load("blobs.hf"), unite(unite(blobby, meta), soft));
  }
  {
    // space_map_warp: the ball's coordinates go through hfSpaceMapCubic, then hfSpaceMapExp (in
    // place), so the C++ map applied first is the outer one; the rod only through hfSpaceMapExp.
    const std::vector<frep::Vec3> src{ { 0, 0, 0.8 }, { 0.8, 0, 0 } };
    const std::vector<frep::Vec3> dst{ { 0, 0, 1.2 }, { 1.1, 0.2, 0 } };
    const std::vector<frep::Vec3> b{ { 0.8, 0.8, 1.3 }, { 1.2, 1.2, 1.2 } };
    const std::vector<frep::Vec3> es{ { 0, 0, -0.8 } }, ed{ { 0.4, 0, -0.8 } },
      eb{ { 0.5, 0.5, 0.3 } };
    const Shape ball = frep::spaceMapCubic(
      frep::spaceMapExp(frep::sphere({ 0, 0, 0 }, 0.9), es, ed, eb), src, dst, b);
    const Shape rod =
      frep::spaceMapExp(frep::ellipsoid({ 0, 0, -1.6 }, 0.25, 0.25, 0.8), es, ed, eb);
    const auto m = load("space_map_warp.hf");
    expectSameField(m, unite(ball, rod));
    // The target (0, 0, 1.2) of the first control point maps exactly onto its source (0, 0, 0.8)
    // (w = 1; the second control point and the exp map move it by < 1e-5), where the ball's field
    // is 0.81 - 0.64 = 0.17: material outside the unwarped ball of radius 0.9.
    EXPECT_GT(at(m, { 0, 0, 1.2, 0 }), 0.0);
    EXPECT_GT(at(m, { 1.05, 0.1, 0, 0 }), 0.0); // the side pulled out
    EXPECT_LT(at(m, { -1.05, 0, 0, 0 }), 0.0);  // the other side is not
    EXPECT_GT(at(m, { 0.3, 0, -1, 0 }), 0.0);   // the rod pushed towards +x
    EXPECT_LT(at(m, { -0.3, 0, -1, 0 }), 0.0);
  }
}

TEST(DataModels, NoisyEggWithoutNoiseIsTheEllipsoid)
{
  // a[1] = 0 removes the noise: 1 - (x/0.8)^2 - (y/0.8)^2 - (z/1.1)^2; at (0.4, 0, 0.55):
  // 1 - 0.25 - 0.25 = 0.5. With a[1] = 1 the noise (amplitude 0.05) changes the value.
  const auto m = load("noisy_egg.hf");
  EXPECT_NEAR(at(m, { 0.4, 0, 0.55, 0 }, { 0.0 }), 0.5, 1e-15);
  EXPECT_NEAR(at(m, { 0, 0, 0, 0 }, { 0.0 }), 1.0, 1e-15);
  EXPECT_NE(at(m, { 0.4, 0.1, 0.55, 0 }, { 1.0 }), at(m, { 0.4, 0.1, 0.55, 0 }, { 0.0 }));
}

TEST(DataModels, SkeletalAndMappedModelsHaveTheirMaterialWhereExpected)
{
  // convolution: on the segment from (-1, 1, 0) to (1, 1, 0) the field is far above the
  // threshold; at the corner of the box nothing is near.
  const auto conv = load("convolution.hf");
  EXPECT_GT(at(conv, { 0, 1, 0, 0 }), 0.0);
  EXPECT_LT(at(conv, { 2.4, 2.4, 2.4, 0 }), 0.0);
  // quadrics: the x-axis cylinder of radius 0.3 holds the origin; (2.9, 2.9, -2.9) is in none.
  const auto quadrics = load("quadrics.hf");
  EXPECT_GT(at(quadrics, { 0, 0, 0, 0 }), 0.0);
  // space_maps: every map used keeps the origin fixed for part2 (the ball of radius 0.6), so the
  // origin is inside; far away nothing is.
  const auto maps = load("space_maps.hf");
  EXPECT_GT(at(maps, { 0, 0, 0, 0 }), 0.0);
  EXPECT_LT(at(maps, { 2.4, -2.4, 2.4, 0 }), 0.0);
}

TEST(DataModels, HyperFunXmlHyperFunRoundTripIsValueIdentical)
{
  // Every model: HyperFun -> DAG -> XML -> DAG -> HyperFun -> DAG, the same values (bit for bit)
  // at points spread over [-2.5, 2.5]^3 (time 0.5 for space-time models).
  for (const auto& entry : std::filesystem::directory_iterator(DataDir + "/Models"))
  {
    if (entry.path().extension() != ".hf")
    {
      continue;
    }
    SCOPED_TRACE(entry.path().string());
    const lang::HyperFunModel original =
      lang::readHyperFunFile(entry.path().string(), {}, {}, { 0.7, 0.7 });
    const std::string xml = lang::writeFRepXml(original.model, original.name);
    const frep::Hypervolume fromXml = lang::readFRepXml(xml, "round-trip.xml");
    const std::string hf = lang::writeHyperFun(fromXml, original.name, original.parameterCount);
    const lang::HyperFunModel back = lang::readHyperFun(hf, "round-trip.hf");
    const std::vector<double> params(static_cast<std::size_t>(original.parameterCount), 0.7);
    frep::HypervolumeEvaluator a(original.model, params), b(fromXml, params), c(back.model, params);
    std::vector<double> va(original.model.attributeComponentCount()), vb(va.size()), vc(va.size());
    for (int i = 0; i < 100; ++i)
    {
      const std::array<double, 4> p{ -2.5 + 5 * std::fmod(0.5 + i * 0.6180339887498949, 1.0),
        -2.5 + 5 * std::fmod(0.5 + i * 0.7548776662466927, 1.0),
        -2.5 + 5 * std::fmod(0.5 + i * 0.5698402909980532, 1.0), 0.5 };
      double fa, fb, fc;
      a.eval(p, fa, va.data());
      b.eval(p, fb, vb.data());
      c.eval(p, fc, vc.data());
      ASSERT_EQ(fa, fb);
      ASSERT_EQ(fa, fc);
      ASSERT_EQ(va, vb);
    }
    // HyperFun carries the colour only; it comes back where the original has it.
    if (original.model.findAttribute("colour"))
    {
      EXPECT_NE(back.model.findAttribute("colour"), nullptr);
    }
  }
}

TEST(DataModels, ParametricRingIsSpecialisedToItsParameters)
{
  // hfTorusZ with R = a[1] = 0.8, r = a[2] = 0.3: r^2 - |p|^2 - R^2 + 2 R sqrt(x^2 + y^2); at
  // (0.8, 0, 0): 0.09 - 0.64 - 0.64 + 1.28 = 0.09; at the centre: 0.09 - 0.64 = -0.55.
  const auto m =
    lang::readHyperFunFile(DataDir + "/Models/parametric_ring.hf", {}, {}, { 0.8, 0.3 });
  EXPECT_NEAR(at(m, { 0.8, 0, 0, 0 }), 0.09, 1e-15);
  EXPECT_NEAR(at(m, { 0, 0, 0, 0 }), -0.55, 1e-15);
  EXPECT_THROW(load("parametric_ring.hf"), lang::ParseError); // no values: the library needs them
}
