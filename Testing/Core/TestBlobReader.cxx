// SPDX-License-Identifier: BSD-3-Clause
// Tests of the .blob reader (Lang/BlobReader.h): the bundled models read, degrees become radians,
// animations and the threshold, errors at file:line:col (several per run), the limits, and the
// file through the model registry of every command (Lang/ModelFile.h).
#include "FRep/BlobTree.h"
#include "FRep/Evaluators.h"
#include "FRep/Tape.h"
#include "Lang/BlobReader.h"
#include "Lang/ModelFile.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

using namespace ictk;
using namespace ictk::frep::blob;

namespace
{
const std::string Models = std::string(ICTK_DATA_DIR) + "/Models/blob/";

struct Error
{
  int line = 0, column = 0;
  std::string message;
};

Error firstError(const std::string& text)
{
  try
  {
    lang::readBlob(text, "m.blob");
  }
  catch (const lang::ParseError& e)
  {
    const lang::Diagnostic& d = e.diagnostics().at(0);
    EXPECT_EQ(d.where.file, "m.blob");
    return { d.where.line, d.where.column, d.message };
  }
  ADD_FAILURE() << "no error for:\n" << text;
  return {};
}
} // namespace

TEST(BlobReader, SkeletonsModel)
{
  const BlobTree t = lang::readBlobFile(Models + "skeletons.blob");
  EXPECT_EQ(t.threshold(), 0.5);
  EXPECT_EQ(t.count(Kind::GeneralisedCylinder), 1u);
  const BlobTree e = t.expand();
  EXPECT_EQ(e.count(Kind::Cylinder) + e.count(Kind::ConeSphere), 14u); // 12 + 2
  // At the origin the point (R 1.2) and the segment (R 0.8) both give g(0) = 1.
  EXPECT_DOUBLE_EQ(evaluate(e, { 0, 0, 0 }), 2.0);
  for (const Node& n : e.nodes())
  {
    if (n.kind == Kind::Rotate)
    {
      EXPECT_DOUBLE_EQ(
        e.values(static_cast<std::uint32_t>(&n - e.nodes().data()))[3], 30 * M_PI / 180);
    }
  }
}

TEST(BlobReader, AnimatedValuesAndThreshold)
{
  const BlobTree t = lang::readBlob("threshold keys(1, 0 0.5, 2 0.7)\n"
                                    "rotate [0 0 1] wave(0 90 4 0) {\n"
                                    "  segment keys(2, 0 1 0, 1 2 0) 1 [0 0 0] [1 0 0]\n"
                                    "}\n");
  EXPECT_TRUE(t.animated());
  const BlobTree at1 = t.instantiate(1);
  EXPECT_NEAR(at1.threshold(), 0.6, 1e-15);
  EXPECT_DOUBLE_EQ(at1.values(at1.root())[3], M_PI / 2); // 90 degrees at a quarter period
  EXPECT_DOUBLE_EQ(at1.values(0)[0], 2.0);
  // The segment turned by 90 degrees lies along y.
  EXPECT_DOUBLE_EQ(evaluate(at1, { 0, 0.7, 0 }), 1.0);
}

TEST(BlobReader, ErrorsAtLineAndColumn)
{
  Error e = firstError("blend {\n  pint 1 1 [0 0 0]\n}\n");
  EXPECT_EQ(e.line, 2);
  EXPECT_EQ(e.column, 3);
  EXPECT_EQ(e.message, "unknown node 'pint'");
  e = firstError("union {\n  point 1 1 [0 0 0]\n  segment 1 1 [0 0 0]\n}\n");
  EXPECT_EQ(e.line, 3);
  EXPECT_EQ(e.column, 3);
  EXPECT_EQ(e.message, "blobtree: segment: expects 8 values (got 5)");
  e = firstError("blend {\n  point 1 1 [0 0 0\n}\n");
  EXPECT_EQ(e.line, 3);
  EXPECT_EQ(e.message, "expected ']', got '}'");
  e = firstError("blend {\n  point 1 1 [0 0 0]\n");
  EXPECT_EQ(e.line, 3);
  EXPECT_EQ(e.message, "expected '}' closing the blend at 1:1");
  e = firstError("point 1 1 0 0 0\npoint 1 1 0 0 0\n");
  EXPECT_EQ(e.line, 2);
  e = firstError("localblend { point 1 1 0 0 0 point 1 1 1 0 0 }");
  EXPECT_EQ(e.column, 1);
  EXPECT_EQ(e.message, "blobtree: localblend: takes exactly 3 children (got 2)");
  e = firstError("threshold 0\npoint 1 1 0 0 0");
  EXPECT_EQ(e.message, "blobtree: the threshold T must be positive and finite (got 0)");
  e = firstError("point 1 1 0 0 1e999");
  EXPECT_EQ(e.column, 15);
  EXPECT_EQ(e.message, "the number 1e999 is out of range");
  e = firstError("point 1 1 0 0 $");
  EXPECT_EQ(e.message, "unexpected character '$'");
  e = firstError("# nothing\n");
  EXPECT_EQ(e.message, "the file holds no node");
}

TEST(BlobReader, SeveralErrorsInOneRun)
{
  try
  {
    lang::readBlob("blend {\n  point -1 1 0 0 0\n  segment 1 1 0 0 0 0 0 0\n  disc 1 1 0 0 0 0 0 0 "
                   "1\n}\n",
      "m.blob");
    FAIL();
  }
  catch (const lang::ParseError& e)
  {
    ASSERT_EQ(e.diagnostics().size(), 2u);
    EXPECT_EQ(e.diagnostics()[0].where.line, 2);
    EXPECT_EQ(e.diagnostics()[1].where.line, 4);
    EXPECT_EQ(
      e.diagnostics()[1].message, "blobtree: disc: the normal n must not be the zero vector");
    const std::string what = e.what();
    EXPECT_NE(what.find("m.blob:2:3: error: blobtree: point: the radius of influence R must be "
                        "positive (got -1)"),
      std::string::npos);
  }
}

TEST(BlobReader, Limits)
{
  lang::Limits limits;
  limits.maxNesting = 10;
  std::string deep;
  for (int i = 0; i < 20; ++i)
  {
    deep += "blend { ";
  }
  deep += "point 1 1 0 0 0";
  for (int i = 0; i < 20; ++i)
  {
    deep += " }";
  }
  EXPECT_THROW(lang::readBlob(deep, "", limits), lang::ParseError);
  limits = {};
  limits.maxExpressionNodes = 64 * 100;
  EXPECT_THROW(lang::readBlob("gcylinder 1 1 101 0 0 0 1 1 0 0 1", "", limits), lang::ParseError);
  EXPECT_NO_THROW(lang::readBlob("gcylinder 1 1 100 0 0 0 1 1 0 0 1", "", limits));
  limits = {};
  limits.maxFileBytes = 10;
  EXPECT_THROW(lang::readBlob("point 1 1 0 0 0", "", limits), lang::ParseError);
}

// Through the registry every ictk command uses: the field is potential - T, the bounds the
// support box with a margin; .blob is read only.
TEST(BlobReader, ModelFile)
{
  EXPECT_TRUE(lang::isModelFile("a/b.BLOB"));
  const lang::ModelFile m = lang::loadModelFile(Models + "skeletons.blob");
  EXPECT_EQ(m.name, "skeletons");
  frep::PointEvaluator e(frep::Tape::compile(m.model.geometry().function()));
  EXPECT_DOUBLE_EQ(e.eval(0, 0, 0), 1.5);
  ASSERT_TRUE(m.bounds.has_value());
  const auto box = supportBox(lang::readBlobFile(Models + "skeletons.blob"));
  EXPECT_LT((*m.bounds)[0], box[0][0]);
  EXPECT_GT((*m.bounds)[5], box[1][2]);
  EXPECT_THROW(lang::saveModelFile(m, "/tmp/never.blob"), std::invalid_argument);
}

// Item 68: the T-Rex-scale model, 66 generalised cylinders under local blends with 21 frame
// nodes, instantiates to the order of the paper's 1,835 elements; item 57 on it: instances at
// several times have the same structure.
TEST(BlobReader, TRexModel)
{
  const BlobTree generic = lang::readBlobFile(Models + "trex.blob");
  EXPECT_EQ(generic.count(Kind::GeneralisedCylinder), 66u);
  EXPECT_EQ(generic.count(Kind::Rotate), 21u);
  EXPECT_GE(generic.count(Kind::LocalBlend), 10u);
  EXPECT_TRUE(generic.animated());
  const BlobTree i0 = generic.instantiate(0), i1 = generic.instantiate(0.7);
  EXPECT_EQ(
    i0.count(Kind::Cylinder) + i0.count(Kind::ConeSphere) + i0.count(Kind::Segment), 66u * 28);
  EXPECT_NEAR(static_cast<double>(i0.leafCount()), 1835.0, 0.05 * 1835);
  // Exactly: the cylinders' 1,848 segments and 18 points, the 1,866 skeletal elements that
  // `ictk bench --only trex` reports (docs/blobtree.md, docs/performance.md).
  EXPECT_EQ(i0.count(Kind::Point), 18u);
  EXPECT_EQ(i0.leafCount(), 1866u);
  EXPECT_EQ(i0.operatorCount(), 1812u);
  ASSERT_EQ(i0.nodes().size(), i1.nodes().size());
  for (std::size_t k = 0; k < i0.nodes().size(); ++k)
  {
    ASSERT_EQ(i0.nodes()[k].kind, i1.nodes()[k].kind);
  }
  // The torso is inside and moves forwards with the walk (12 units in 10 s).
  EXPECT_GT(evaluate(i0, { 1.5, 0, 3 }), 0.5);
  EXPECT_LT(evaluate(i0, { 1.5, 0, 6 }), 0.5);
  const BlobTree walked = generic.instantiate(5);
  EXPECT_GT(evaluate(walked, { 7.5, 0, 3 }), 0.5);
  EXPECT_LT(evaluate(walked, { 1.5, 0, 3 }), 0.5);
  // The lowered field agrees with the traversal.
  frep::PointEvaluator e(frep::Tape::compile(potential(i0)));
  for (const Vec3& p :
    { Vec3{ 1.5, 0, 3 }, Vec3{ 4.5, 0.2, 4.4 }, Vec3{ -4, 0.1, 3.5 }, Vec3{ 0.3, 0.9, 1.2 } })
  {
    EXPECT_NEAR(e.eval(p[0], p[1], p[2]), evaluate(i0, p), 1e-12);
  }
}

// A TextureTree read from a file: its materials are the model's attributes.
TEST(BlobReader, TexturedModelHasMaterialAttributes)
{
  const lang::ModelFile m = lang::loadModelFile(Models + "textured.blob");
  const frep::Attribute* colour = m.model.findAttribute("colour");
  ASSERT_NE(colour, nullptr);
  ASSERT_NE(m.model.findAttribute("optics"), nullptr);
  frep::HypervolumeEvaluator e(m.model);
  double f = 0;
  std::vector<double> a(m.model.attributeComponentCount());
  e.eval({ 2, 0, 0, 0 }, f, a.data()); // inside the red part, away from the blue ring
  EXPECT_GT(f, 0);
  EXPECT_DOUBLE_EQ(a[0], 0.85);
  EXPECT_DOUBLE_EQ(a[2], 0.15);
}

// An animated file is a model only at a time: loadModelFile refuses it with its path (never the
// t = 0 instance), and loadBlobModelFile(path).at(t) is the C++ instantiation at t, as the ictk
// commands read it with --time (Testing/VTK/blob_check.py checks them against the formula).
TEST(BlobReader, AnimatedModelFileAtTime)
{
  try
  {
    lang::loadModelFile(Models + "trex.blob");
    ADD_FAILURE() << "an animated tree was read without a time";
  }
  catch (const std::invalid_argument& e)
  {
    EXPECT_NE(std::string(e.what()).find("trex.blob' is an animated BlobTree"), std::string::npos)
      << e.what();
  }
  const lang::BlobModelFile file = lang::loadBlobModelFile(Models + "trex.blob");
  EXPECT_TRUE(file.animated());
  EXPECT_EQ(file.name, "trex");
  const BlobTree generic = lang::readBlobFile(Models + "trex.blob");
  for (const double t : { 0.4, 5.0 })
  {
    const lang::ModelFile m = file.at(t);
    const BlobTree instance = generic.instantiate(t);
    frep::PointEvaluator e(frep::Tape::compile(m.model.geometry().function()));
    for (const Vec3& p : { Vec3{ 1.5, 0, 3 }, Vec3{ 7.5, 0, 3 }, Vec3{ 4.5, 0.2, 4.4 } })
    {
      EXPECT_NEAR(e.eval(p[0], p[1], p[2]), evaluate(instance, p) - instance.threshold(), 1e-12);
    }
    const auto box = supportBox(instance);
    ASSERT_TRUE(m.bounds.has_value());
    EXPECT_LT((*m.bounds)[0], box[0][0]);
    EXPECT_GT((*m.bounds)[1], box[1][0]);
  }
  // The walk moves the torso: inside at (1.5, 0, 3) at t = 0.4, outside there at t = 5.
  frep::PointEvaluator a(frep::Tape::compile(file.at(0.4).model.geometry().function()));
  frep::PointEvaluator b(frep::Tape::compile(file.at(5.0).model.geometry().function()));
  EXPECT_GT(a.eval(1.5, 0, 3), 0);
  EXPECT_LT(b.eval(1.5, 0, 3), 0);
  // pulse.blob by hand: at t = 1 the point is at x = sin(pi / 2) = 1 with R = 2.5, so at
  // (1.5, 0, 0) q = 0.25 / 6.25 and f = 1 - 22/9 q + 17/9 q^2 - 4/9 q^3 - 1/2.
  const lang::ModelFile pulse = lang::loadBlobModelFile(Models + "pulse.blob").at(1.0);
  const double q = 0.04;
  frep::PointEvaluator c(frep::Tape::compile(pulse.model.geometry().function()));
  EXPECT_NEAR(
    c.eval(1.5, 0, 0), 1 - 22.0 / 9 * q + 17.0 / 9 * q * q - 4.0 / 9 * q * q * q - 0.5, 1e-14);
}

// Item 1 of docs/blobtree.md's checks: a value valid when read may leave its range at some t. The
// radius R(t) = 1 - 0.8 t (linear keys from 1 at t = 0 to -0.6 at t = 2) is -0.2 at t = 1.5:
// instantiation there is refused at the node's keyword, naming the value and t, by the checks of
// add(); the threshold likewise (wave 0.5 + 0.6 sin(pi t / 2) is -0.1 at t = 3).
TEST(BlobReader, AnimatedValueOutOfRangeAtTime)
{
  const std::string text = "threshold wave(0.5 0.6 4 0)\n"
                           "blend {\n"
                           "  point 1 1 [2 0 0]\n"
                           "  point keys(1, 0 1, 2 -0.6) 1 [0 0 0]\n"
                           "}\n";
  lang::BlobOrigins origins;
  const BlobTree generic = lang::readBlob(text, "m.blob", {}, &origins);
  ASSERT_EQ(origins.nodes.size(), 1u);
  ASSERT_TRUE(origins.threshold.has_value());
  EXPECT_EQ(origins.threshold->where.line, 1);
  // t = 0 and t = 1 are fine (R = 1, 0.2).
  EXPECT_DOUBLE_EQ(lang::instantiateBlob(generic, origins, 0.0).values(1)[0], 1.0);
  EXPECT_NEAR(lang::instantiateBlob(generic, origins, 1.0).values(1)[0], 0.2, 1e-15);
  try
  {
    lang::instantiateBlob(generic, origins, 1.5);
    ADD_FAILURE() << "a negative radius at t = 1.5 was instantiated";
  }
  catch (const lang::ParseError& e)
  {
    ASSERT_EQ(e.diagnostics().size(), 1u);
    const lang::Diagnostic& d = e.diagnostics()[0];
    EXPECT_EQ(d.where.file, "m.blob");
    EXPECT_EQ(d.where.line, 4);
    EXPECT_EQ(d.where.column, 3);
    EXPECT_EQ(d.message,
      "blobtree: point: the radius of influence R must be positive (got -0.2) at t = 1.5");
    EXPECT_EQ(d.sourceLine, "  point keys(1, 0 1, 2 -0.6) 1 [0 0 0]");
  }
  // Without origins (a tree built in C++), the InstanceError names the node.
  try
  {
    generic.instantiate(1.5);
    ADD_FAILURE() << "a negative radius at t = 1.5 was instantiated";
  }
  catch (const InstanceError& e)
  {
    EXPECT_EQ(e.node(), 1u);
    EXPECT_EQ(e.time(), 1.5);
    EXPECT_EQ(std::string(e.what()),
      "blobtree: point: the radius of influence R must be positive (got -0.2) at t = 1.5 (node 1)");
  }
  // A refused instance leaves the one it would have overwritten as it was.
  BlobTree out = generic.instantiate(1.0);
  EXPECT_THROW(generic.instantiate(1.5, out), InstanceError);
  EXPECT_NEAR(out.values(1)[0], 0.2, 1e-15);
  try
  {
    lang::instantiateBlob(generic, origins, 3.0);
    ADD_FAILURE() << "a negative threshold at t = 3 was instantiated";
  }
  catch (const lang::ParseError& e)
  {
    EXPECT_EQ(e.diagnostics().at(0).where.line, 1);
    EXPECT_NE(e.diagnostics()[0].message.find("the threshold T must be positive and finite (got "),
      std::string::npos);
    EXPECT_NE(e.diagnostics()[0].message.find(" at t = 3"), std::string::npos);
  }
}

// The new nodes in the file form: a surface of revolution and a solid texture read as built in
// C++.
TEST(BlobReader, RevolutionAndSolidTexture)
{
  const BlobTree read = lang::readBlob("wood [1 0 0] [0 0 1] 0 0 1 0.5 0 1 {\n"
                                       "  revolution 1.5 1 2 [0 0 0] [0 0 1] [1 0 0.3] [2 1 0.1] "
                                       "[1 2 0.3]\n}\n",
    "r.blob");
  BlobTree built;
  const auto r = built.add(
    Kind::SurfaceOfRevolution, { 1.5, 1, 2, 0, 0, 0, 0, 0, 1, 1, 0, 0.3, 2, 1, 0.1, 1, 2, 0.3 });
  built.add(Kind::Wood, { 1, 0, 0, 0, 0, 1, 0, 0, 1, 0.5, 0, 1 }, { r });
  for (const Vec3& p : { Vec3{ 2.4, 0, 1 }, Vec3{ 0.3, 1.7, 0.2 }, Vec3{ -1, 1, 1.5 } })
  {
    std::array<double, MaterialSize> a{}, b{};
    EXPECT_EQ(evaluateTextured(read, p, a), evaluateTextured(built, p, b));
    EXPECT_EQ(a, b);
  }
  EXPECT_EQ(firstError("granite [1 0 0] [0 0 1] 0 0 1 0.5 0 12 { point 1 1 [0 0 0] }\n").line, 1);
}

// The writer (task: a .blob writer): every bundled model written and read back is the same tree,
// the same values (angles to an ulp through degrees) and animations, so the same field at every
// time.
TEST(BlobReader, WriterRoundTrip)
{
  for (const char* name :
    { "skeletons.blob", "textured.blob", "trex.blob", "pulse.blob", "solid_textures.blob" })
  {
    SCOPED_TRACE(name);
    const BlobTree a = lang::readBlobFile(Models + name);
    const std::string text = lang::writeBlob(a);
    const BlobTree b = lang::readBlob(text, "written.blob");
    ASSERT_EQ(a.nodes().size(), b.nodes().size());
    EXPECT_EQ(a.threshold(), b.threshold());
    EXPECT_EQ(a.animated(), b.animated());
    EXPECT_EQ(a.thresholdAnimation() != nullptr, b.thresholdAnimation() != nullptr);
    // The reader numbers nodes children first, as the writer lists them: the same order.
    std::size_t animated = 0;
    for (std::uint32_t i = 0; i < a.nodes().size(); ++i)
    {
      ASSERT_EQ(a.node(i).kind, b.node(i).kind);
      ASSERT_EQ(a.node(i).valueCount, b.node(i).valueCount);
      ASSERT_EQ(a.node(i).childCount, b.node(i).childCount);
      for (std::uint32_t k = 0; k < a.node(i).valueCount; ++k)
      {
        const Animation* x = a.animation(i, k);
        const Animation* y = b.animation(i, k);
        ASSERT_EQ(x != nullptr, y != nullptr);
        animated += x != nullptr;
        if (!x)
        {
          EXPECT_NEAR(a.values(i)[k], b.values(i)[k], 1e-15 * std::fabs(a.values(i)[k]));
          continue;
        }
        for (const double t : { -1.0, 0.0, 0.37, 2.5, 7.0, 100.0 })
        {
          EXPECT_NEAR(x->eval(t), y->eval(t), 1e-13 * (1 + std::fabs(x->eval(t))));
        }
      }
    }
    EXPECT_EQ(animated > 0 || a.thresholdAnimation() != nullptr, a.animated());
    for (const double t : { 0.0, 1.3 })
    {
      const BlobTree ia = a.instantiate(t), ib = b.instantiate(t);
      for (const Vec3& p : { Vec3{ 0.1, 0.2, 0.3 }, Vec3{ 1.5, 0, 3 }, Vec3{ -1.6, 0.4, 0.2 } })
      {
        std::array<double, MaterialSize> pa{}, pb{};
        EXPECT_NEAR(evaluateTextured(ia, p, pa), evaluateTextured(ib, p, pb), 1e-12);
        for (int m = 0; m < MaterialSize; ++m)
        {
          EXPECT_NEAR(pa[m], pb[m], 1e-12);
        }
      }
    }
  }
  // Shortest exact numbers, degrees for angles, one node a line.
  BlobTree t;
  const auto p = t.add(Kind::Point, { 0.1, 1, 0, 0, 0 });
  t.add(Kind::Rotate, { 0, 0, 1, M_PI / 2 }, { p });
  Animation wave;
  wave.base = 1;
  wave.amplitude = 0.5;
  wave.period = 2;
  t.animate(1, 0, wave);
  EXPECT_EQ(lang::writeBlob(t),
    "# A BlobTree (docs/blobtree.md), written by ICTK\n"
    "threshold 0.5\n"
    "rotate wave(1 0.5 2 0) 0 1 90 {\n"
    "  point 0.1 1 0 0 0\n"
    "}\n");
  EXPECT_THROW(lang::writeBlob(BlobTree{}), std::invalid_argument);
}
