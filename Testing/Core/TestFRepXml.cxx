// SPDX-License-Identifier: BSD-3-Clause
// FRep XML: round trips, diagnostics, limits; ModelFile on top of it.
#include "FRep/Hypervolume.h"
#include "Lang/FRepXml.h"
#include "Lang/ModelFile.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

using namespace ictk;
using frep::Axis;
using frep::Domain;
using frep::Expr;
using frep::Opcode;

namespace
{

// A random DAG over the axes of `domain` and `params` parameter slots that uses every opcode:
// each new node takes its operands from everything built so far (recent nodes preferred, for
// depth), so sub-expressions are shared.
Expr randomDag(std::mt19937& rng, int size, Domain domain, int params)
{
  std::vector<Expr> pool;
  for (Axis a : frep::domainCoordinates(domain))
  {
    pool.push_back(Expr::variable(a));
  }
  for (int i = 0; i < params; ++i)
  {
    pool.push_back(Expr::parameter(static_cast<std::uint32_t>(i)));
  }
  std::uniform_real_distribution<double> value(-3, 3);
  const double specials[] = { 0.1, -2.5, 1e-7, 1e20, 3.0, 0.5, 1.0 / 3.0, -1e-300 };
  for (int i = 0; i < 3; ++i)
  {
    pool.push_back(Expr::constant(value(rng)));
  }
  pool.push_back(Expr::constant(specials[rng() % 8]));
  const int first = static_cast<int>(Opcode::Neg);
  const int count = static_cast<int>(Opcode::Count_) - first;
  auto pick = [&]() -> const Expr&
  {
    const std::size_t n = pool.size();
    // Half of the time one of the last four nodes, else any node.
    const std::size_t i = (rng() % 2) ? n - 1 - rng() % std::min<std::size_t>(4, n) : rng() % n;
    return pool[i];
  };
  for (int i = 0; i < size; ++i)
  {
    const auto op = static_cast<Opcode>(first + (i < count ? i : static_cast<int>(rng() % count)));
    Expr e;
    switch (frep::opcodeArity(op))
    {
      case 1:
        e = Expr::make(op, pick());
        break;
      case 2:
        e = Expr::make(op, pick(), pick());
        break;
      default:
        e = Expr::make(op, pick(), pick(), pick());
        break;
    }
    pool.push_back(e);
  }
  // Combine the last nodes so the root reaches most of the pool.
  Expr root = pool.back();
  for (std::size_t i = pool.size() > 6 ? pool.size() - 6 : 0; i + 1 < pool.size(); ++i)
  {
    root = Expr::make(Opcode::Add, root, pool[i]);
  }
  return root;
}

bool sameValue(double a, double b)
{
  return (std::isnan(a) && std::isnan(b)) || a == b;
}

// Every output of the hypervolume's tape at random points must be equal.
void expectSameValues(
  const frep::Hypervolume& a, const frep::Hypervolume& b, std::mt19937& rng, int params)
{
  std::vector<double> p(static_cast<std::size_t>(params));
  std::uniform_real_distribution<double> u(-2, 2);
  for (double& v : p)
  {
    v = u(rng);
  }
  frep::PointEvaluator ea(a.compile(), p);
  frep::PointEvaluator eb(b.compile(), p);
  const std::size_t n = ea.tape()->outputs().size();
  ASSERT_EQ(n, eb.tape()->outputs().size());
  std::vector<double> va(n), vb(n);
  for (int k = 0; k < 40; ++k)
  {
    const std::array<double, 4> pt{ u(rng), u(rng), u(rng), u(rng) };
    ea.evalAll(pt, va.data());
    eb.evalAll(pt, vb.data());
    for (std::size_t i = 0; i < n; ++i)
    {
      EXPECT_TRUE(sameValue(va[i], vb[i])) << "output " << i << ": " << va[i] << " vs " << vb[i];
    }
  }
}

std::size_t countOf(const std::string& text, const std::string& what)
{
  std::size_t n = 0;
  for (auto i = text.find(what); i != std::string::npos; i = text.find(what, i + 1))
  {
    ++n;
  }
  return n;
}

// The formatted diagnostics of reading `xml` (empty when it reads).
std::string errorsOf(const std::string& xml, const lang::Limits& limits = {})
{
  try
  {
    lang::readFRepXml(xml, "t.xml", limits);
  }
  catch (const lang::ParseError& e)
  {
    return e.what();
  }
  return {};
}

// A document whose geometry expression is `expr`: the expression starts on line 3, column 5.
std::string document(const std::string& expr, const std::string& domain = "XYZ")
{
  return "<frep version=\"1\" name=\"m\">\n  <geometry domain=\"" + domain +
    "\" threshold=\"0\">\n    " + expr + "\n  </geometry>\n</frep>\n";
}

frep::Hypervolume sphere()
{
  Expr x = Expr::x(), y = Expr::y(), z = Expr::z();
  return frep::Hypervolume(frep::Shape(1.0 - (x * x + y * y + z * z), Domain::XYZ));
}

} // namespace

TEST(FRepXml, RoundTripRandomDags)
{
  std::mt19937 rng(12345);
  const Domain domains[] = { Domain::X, Domain::T, Domain::XY, Domain::XT, Domain::XYZ, Domain::XYT,
    Domain::XYZT };
  for (int iteration = 0; iteration < 300; ++iteration)
  {
    const Domain d = domains[iteration % 7];
    const int params = static_cast<int>(rng() % 3);
    Expr f = randomDag(rng, 10 + static_cast<int>(rng() % 60), d, params);
    frep::Hypervolume hv(frep::Shape(f, d), iteration % 3 == 0 ? 0.25 : 0.0);
    if (iteration % 2)
    {
      frep::Attribute a;
      a.name = "colour";
      for (int c = 0; c < 3; ++c)
      {
        a.components.push_back(randomDag(rng, 8, d, params));
      }
      a.partition = randomDag(rng, 5, d, params);
      a.insideDefault = { 1, 0.5, -0.25 };
      a.outsideDefault = { 0, 0.1, 1e-9 };
      hv.addAttribute(a);
      frep::Attribute t;
      t.name = "stress";
      t.tensorRows = 2;
      for (int c = 0; c < 4; ++c)
      {
        t.components.push_back(c == 2 ? f : randomDag(rng, 4, d, params));
      }
      hv.addAttribute(t);
    }
    const std::string xml = lang::writeFRepXml(hv, "random");
    frep::Hypervolume back = lang::readFRepXml(xml, "random.xml");
    ASSERT_EQ(lang::writeFRepXml(back, "random"), xml) << "iteration " << iteration;
    // Hash-consing makes the read DAG the very same nodes.
    EXPECT_TRUE(back.geometry().function().identical(f));
    EXPECT_EQ(back.geometry().domain(), d);
    EXPECT_EQ(back.threshold(), hv.threshold());
    ASSERT_EQ(back.attributes().size(), hv.attributes().size());
    for (std::size_t i = 0; i < hv.attributes().size(); ++i)
    {
      const frep::Attribute& a = hv.attributes()[i];
      const frep::Attribute& b = back.attributes()[i];
      EXPECT_EQ(a.name, b.name);
      EXPECT_EQ(a.tensorRows, b.tensorRows);
      EXPECT_EQ(a.insideDefault, b.insideDefault);
      EXPECT_EQ(a.outsideDefault, b.outsideDefault);
      EXPECT_TRUE(a.partition.identical(b.partition));
    }
    expectSameValues(hv, back, rng, params);
  }
}

TEST(FRepXml, WritingIsDeterministic)
{
  std::mt19937 rng(7);
  Expr f = randomDag(rng, 80, Domain::XYZ, 2);
  frep::Hypervolume hv(frep::Shape(f, Domain::XYZ));
  EXPECT_EQ(lang::writeFRepXml(hv), lang::writeFRepXml(hv));
}

TEST(FRepXml, ConstantsAreExact)
{
  for (double v : { 0.1, 1.0 / 3.0, 1e-300, 5e-324, 1.7976931348623157e308, -2.5, 123456789.0 })
  {
    frep::Hypervolume hv(frep::Shape(Expr::x() + v, Domain::X));
    frep::Hypervolume back = lang::readFRepXml(lang::writeFRepXml(hv), "c.xml");
    EXPECT_EQ(back.geometry().function().child(1).constantValue(), v);
  }
  const std::string xml =
    lang::writeFRepXml(frep::Hypervolume(frep::Shape(Expr::x() + 0.1, Domain::X)));
  EXPECT_NE(xml.find("<const value=\"0.10000000000000001\"/>"), std::string::npos) << xml;
  // Non-finite constants (folding can make them) are written and read back too.
  frep::Hypervolume inf(
    frep::Shape(Expr::x() + std::numeric_limits<double>::infinity(), Domain::X));
  frep::Hypervolume infBack = lang::readFRepXml(lang::writeFRepXml(inf), "i.xml");
  EXPECT_TRUE(infBack.geometry().function().identical(inf.geometry().function()));
}

TEST(FRepXml, ExpectedLayout)
{
  const Expr x = Expr::x();
  const Expr s = x * x;
  frep::Hypervolume hv(
    frep::Shape(Expr::make(Opcode::Select, s - 1.0, s, Expr::parameter(0)), Domain::XY));
  const std::string xml = lang::writeFRepXml(hv, "demo");
  const std::string expected = R"(<?xml version="1.0" encoding="UTF-8"?>
<frep version="1" name="demo" parameters="1">
  <geometry domain="XY" threshold="0">
    <select>
      <sub>
        <mul id="n1">
          <var axis="x"/>
          <var axis="x"/>
        </mul>
        <const value="1"/>
      </sub>
      <ref id="n1"/>
      <param slot="0"/>
    </select>
  </geometry>
</frep>
)";
  EXPECT_EQ(xml, expected);
}

TEST(FRepXml, SharedNodesAreWrittenOnce)
{
  // e_{k+1} = e_k * e_k + e_k: 2^60 nodes as a tree, 121 as a DAG.
  Expr e = Expr::x() + Expr::y();
  for (int k = 0; k < 60; ++k)
  {
    e = e * e + e;
  }
  frep::Hypervolume hv(frep::Shape(e, Domain::XY));
  const std::string xml = lang::writeFRepXml(hv);
  EXPECT_LT(xml.size(), 40000u);
  EXPECT_EQ(countOf(xml, "<mul"), 60u);
  EXPECT_EQ(countOf(xml, "<add"), 61u);
  frep::Hypervolume back = lang::readFRepXml(xml, "shared.xml");
  EXPECT_TRUE(back.geometry().function().identical(e));
  EXPECT_EQ(lang::writeFRepXml(back), xml);
}

TEST(FRepXml, LongChainsStayUnderTheNestingLimit)
{
  // A union of many shapes is a left-deep chain: the writer moves deep parts into <defs> so that
  // its own reader (nesting limit 200) takes the file back.
  Expr e = Expr::x();
  for (int i = 0; i < 20000; ++i)
  {
    e = frep::max(e, Expr::y() - static_cast<double>(i));
  }
  frep::Hypervolume hv(frep::Shape(e, Domain::XY));
  const std::string xml = lang::writeFRepXml(hv);
  EXPECT_NE(xml.find("<defs>"), std::string::npos);
  frep::Hypervolume back = lang::readFRepXml(xml, "chain.xml");
  EXPECT_TRUE(back.geometry().function().identical(e));
  EXPECT_EQ(lang::writeFRepXml(back), xml);
}

TEST(FRepXml, DeepDocumentsAreRefused)
{
  // 100000 nested elements: refused with a diagnostic, without exhausting the stack.
  const int n = 100000;
  std::string expr;
  for (int i = 0; i < n; ++i)
  {
    expr += "<neg>";
  }
  expr += "<var axis=\"x\"/>";
  for (int i = 0; i < n; ++i)
  {
    expr += "</neg>";
  }
  const std::string errors = errorsOf(document(expr));
  EXPECT_NE(errors.find("nested deeper than 200"), std::string::npos) << errors.substr(0, 300);
  // Just under the limit reads.
  std::string ok;
  for (int i = 0; i < 190; ++i)
  {
    ok += i % 2 ? "<neg>" : "<abs>";
  }
  ok += "<var axis=\"x\"/>";
  for (int i = 189; i >= 0; --i)
  {
    ok += i % 2 ? "</neg>" : "</abs>";
  }
  EXPECT_EQ(errorsOf(document(ok)), "");
  lang::Limits tight;
  tight.maxNesting = 20;
  EXPECT_NE(errorsOf(document(ok), tight).find("nested deeper than 20"), std::string::npos);
}

TEST(FRepXml, Diagnostics)
{
  struct Case
  {
    std::string xml;
    std::string expected; // the first line of what()
  };
  const std::vector<Case> cases = {
    { document("<foo/>"), "t.xml:3:5: error: unknown element <foo> in an expression" },
    { document("<add><var axis=\"x\"/></add>"),
      "t.xml:3:5: error: <add> takes 2 operand(s), found 1" },
    { document("<sqrt><var axis=\"x\"/><var axis=\"y\"/></sqrt>"),
      "t.xml:3:5: error: <sqrt> takes 1 operand(s), found 2" },
    { document("<const value=\"1.5x\"/>"), "t.xml:3:5: error: bad number '1.5x'" },
    { document("<const value=\"\"/>"), "t.xml:3:5: error: bad number ''" },
    { document("<const/>"), "t.xml:3:5: error: <const> needs the attribute 'value'" },
    { document("<var axis=\"w\"/>"), "t.xml:3:5: error: unknown axis 'w' (x, y, z or t)" },
    { document("<var axis=\"z\"/>", "XY"),
      "t.xml:3:5: error: coordinate 'z' is outside the domain XY" },
    { document("<var axis=\"x\"/>", "XYZW"),
      "t.xml:2:3: error: unknown domain 'XYZW' (X, T, XY, XT, XYZ, XYT or XYZT)" },
    { document("<param slot=\"-1\"/>"),
      "t.xml:3:5: error: bad parameter slot '-1' (an integer from 0 to 1048575)" },
    { document("<ref id=\"n1\"/>"), "t.xml:3:5: error: reference to an undefined id 'n1'" },
    { document("<add><ref id=\"n1\"/><abs id=\"n1\"><var axis=\"x\"/></abs></add>"),
      "t.xml:3:10: error: reference to 'n1' before its definition (at line 3)" },
    { document(
        "<add><abs id=\"n1\"><var axis=\"x\"/></abs><abs id=\"n1\"><var axis=\"y\"/></abs></add>"),
      "t.xml:3:44: error: duplicate id 'n1'" },
    { document("<neg id=\"n1\"><ref id=\"n1\"/></neg>"),
      "t.xml:3:18: error: reference to 'n1' before its definition (at line 3)" },
    { document("<abs colour=\"red\"><var axis=\"x\"/></abs>"),
      "t.xml:3:5: error: unknown attribute 'colour' on <abs>" },
    { document("<abs>text<var axis=\"x\"/></abs>"), "t.xml:3:10: error: unexpected text in <abs>" },
    { "<frep version=\"1\">\n  <geometry domain=\"XYZ\">\n    <var axis=\"x\">\n  "
      "</geometry>\n</frep>\n",
      "t.xml:4:5: error: malformed XML: Start-end tags mismatch" },
    { "<frep version=\"2\">\n</frep>\n",
      "t.xml:1:1: error: unsupported FRep XML version '2' (this reader knows version 1)" },
    { "<model/>", "t.xml:1:1: error: the top-level element is <model>, not <frep>" },
    { "<frep version=\"1\">\n</frep>\n", "t.xml:1:1: error: <frep> has no <geometry>" },
    { "<frep version=\"1\">\n  <geometry domain=\"XY\"/>\n</frep>\n",
      "t.xml:2:3: error: <geometry> has no expression" },
    { "<frep version=\"1\">\n  <geometry domain=\"XY\" threshold=\"nan\"><var "
      "axis=\"x\"/></geometry>\n</frep>\n",
      "t.xml:2:3: error: bad threshold 'nan' (a finite number)" },
    { "<frep version=\"1\">\n  <geometry domain=\"XY\"><var axis=\"x\"/></geometry>\n"
      "  <attribute name=\"c\" components=\"2\">\n    <component><var axis=\"x\"/></component>\n"
      "    <inside>1 2 3</inside>\n  </attribute>\n</frep>\n",
      "t.xml:3:3: error: <attribute> declares 2 component(s) but has 1" },
    { "<frep version=\"1\">\n  <geometry domain=\"XY\"><var axis=\"x\"/></geometry>\n"
      "  <attribute name=\"c\" components=\"1\">\n    <component><var axis=\"z\"/></component>\n"
      "  </attribute>\n</frep>\n",
      "t.xml:4:16: error: coordinate 'z' is outside the domain XY" },
    { "<frep version=\"1\">\n  <bounds lo=\"0 0\" hi=\"1 1 1\"/>\n  <geometry domain=\"XY\"><var "
      "axis=\"x\"/></geometry>\n</frep>\n",
      "t.xml:2:3: error: <bounds> needs three numbers in 'lo' and three in 'hi'" },
    { "", "t.xml:1:1: error: malformed XML: No document element found" },
  };
  for (const Case& c : cases)
  {
    const std::string errors = errorsOf(c.xml);
    EXPECT_EQ(errors.substr(0, errors.find('\n')), c.expected) << c.xml;
  }
}

TEST(FRepXml, SeveralErrorsAtOnce)
{
  const std::string xml = document(
    "<add>\n      <var axis=\"w\"/>\n      <const value=\"x\"/>\n      <foo/>\n    </add>");
  try
  {
    lang::readFRepXml(xml, "t.xml");
    FAIL() << "read a bad document";
  }
  catch (const lang::ParseError& e)
  {
    // <foo> still counts as an operand of <add>.
    ASSERT_EQ(e.diagnostics().size(), 4u) << e.what();
    EXPECT_EQ(e.diagnostics()[0].message, "<add> takes 2 operand(s), found 3");
    EXPECT_EQ(e.diagnostics()[1].where.line, 4);
    EXPECT_EQ(e.diagnostics()[2].where.line, 5);
    EXPECT_EQ(e.diagnostics()[3].where.line, 6);
    EXPECT_EQ(e.diagnostics()[3].where.column, 7);
    EXPECT_EQ(e.diagnostics()[3].sourceLine, "      <foo/>");
  }
  lang::Limits two;
  two.maxDiagnostics = 2;
  try
  {
    lang::readFRepXml(xml, "t.xml", two);
  }
  catch (const lang::ParseError& e)
  {
    EXPECT_EQ(e.diagnostics().size(), 2u);
  }
}

TEST(FRepXml, Limits)
{
  const std::string xml = lang::writeFRepXml(sphere());
  lang::Limits small;
  small.maxFileBytes = 100;
  EXPECT_NE(errorsOf(xml, small).find("more than the limit of 100"), std::string::npos);
  lang::Limits few;
  few.maxExpressionNodes = 5;
  EXPECT_NE(errorsOf(xml, few).find("more than 5 expression nodes"), std::string::npos);
  EXPECT_EQ(errorsOf(xml), "");
}

TEST(FRepXml, AttributesAndNames)
{
  frep::Hypervolume hv = sphere();
  frep::Attribute colour;
  colour.name = "colour";
  colour.components = { Expr::x(), Expr::y(), 0.5 };
  colour.partition = Expr::z();
  colour.insideDefault = { 1, 1, 1 };
  colour.outsideDefault = { 0, 0, 0.25 };
  hv.addAttribute(colour);
  frep::Attribute odd;
  odd.name = "a<b & \"c\"\nd\te";
  odd.components = { Expr::x() * Expr::y() };
  hv.addAttribute(odd);
  const std::string xml = lang::writeFRepXml(hv, "name with <xml> & \"quotes\"");
  frep::Hypervolume back = lang::readFRepXml(xml, "attributes.xml");
  ASSERT_EQ(back.attributes().size(), 2u);
  EXPECT_EQ(back.attributes()[1].name, odd.name);
  EXPECT_EQ(back.attributes()[0].insideDefault, colour.insideDefault);
  EXPECT_EQ(back.attributes()[0].outsideDefault, colour.outsideDefault);
  EXPECT_EQ(lang::writeFRepXml(back, "name with <xml> & \"quotes\""), xml);
  std::mt19937 rng(3);
  expectSameValues(hv, back, rng, 0);
  EXPECT_THROW(lang::writeFRepXml(hv, std::string("bell\a")), std::invalid_argument);
}

TEST(FRepXml, UnreadableFile)
{
  try
  {
    lang::readFRepXmlFile("/nonexistent/folder/model.xml");
    FAIL();
  }
  catch (const lang::ParseError& e)
  {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/folder/model.xml"), std::string::npos);
  }
}

namespace
{
std::filesystem::path scratchFolder(const std::string& name)
{
  auto dir = std::filesystem::temp_directory_path() /
    ("ictk-" + name + "-" + std::to_string(std::random_device{}()));
  std::filesystem::create_directories(dir);
  return dir;
}
} // namespace

TEST(ModelFile, Extensions)
{
  EXPECT_TRUE(lang::isModelFile("a/b.hf"));
  EXPECT_TRUE(lang::isModelFile("B.XML"));
  EXPECT_TRUE(lang::isModelFile("c.Hf"));
  EXPECT_FALSE(lang::isModelFile("c.icm"));
  EXPECT_FALSE(lang::isModelFile("xml"));
  EXPECT_THROW(lang::loadModelFile("model.obj"), std::invalid_argument);
  lang::ModelFile m{ "m", 0, sphere(), std::nullopt };
  EXPECT_THROW(lang::saveModelFile(m, "model.obj"), std::invalid_argument);
}

TEST(ModelFile, XmlRoundTrip)
{
  const auto dir = scratchFolder("modelfile");
  const std::string path = (dir / "ball.XML").string();
  Expr f = 1.0 - (Expr::x() * Expr::x() + Expr::y() * Expr::y()) * Expr::parameter(1);
  lang::ModelFile m{ "ball", 3, frep::Hypervolume(frep::Shape(f, Domain::XY)),
    std::array<double, 6>{ -1, 1, -2, 2, 0, 0 } };
  lang::saveModelFile(m, path);
  // Saving again over the file works and leaves no temporary file behind.
  lang::saveModelFile(m, path);
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir), {}), 1);
  lang::ModelFile back = lang::loadModelFile(path);
  EXPECT_EQ(back.name, "ball");
  EXPECT_EQ(back.parameterCount, 3);
  ASSERT_TRUE(back.bounds);
  EXPECT_EQ(*back.bounds, *m.bounds);
  EXPECT_TRUE(back.model.geometry().function().identical(f));
  std::filesystem::remove_all(dir);
}

TEST(ModelFile, ErrorsNameTheFile)
{
  const auto dir = scratchFolder("modelfile-errors");
  const std::string path = (dir / "bad.xml").string();
  std::ofstream(path) << document("<foo/>");
  try
  {
    lang::loadModelFile(path);
    FAIL();
  }
  catch (const lang::ParseError& e)
  {
    EXPECT_EQ(std::string(e.what()).rfind(path + ":3:5: error:", 0), 0u) << e.what();
  }
  try
  {
    lang::loadModelFile((dir / "missing.xml").string());
    FAIL();
  }
  catch (const lang::ParseError& e)
  {
    EXPECT_NE(std::string(e.what()).find("missing.xml"), std::string::npos);
  }
  lang::ModelFile m{ "m", 0, sphere(), std::nullopt };
  EXPECT_THROW(
    lang::saveModelFile(m, (dir / "no" / "such" / "folder.xml").string()), std::runtime_error);
  std::filesystem::remove_all(dir);
}

TEST(ModelFile, SavesHyperFun)
{
  const auto dir = scratchFolder("modelfile-hf");
  const std::string path = (dir / "ball.hf").string();
  // A name HyperFun cannot take is made into one it can.
  lang::ModelFile m{ "my ball", 0, sphere(), std::nullopt };
  lang::saveModelFile(m, path);
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_NE(text.str().find("my_ball(x[3], a[1])"), std::string::npos) << text.str();
  // And back through the HyperFun reader.
  lang::ModelFile back = lang::loadModelFile(path);
  EXPECT_EQ(back.name, "my_ball");
  EXPECT_TRUE(back.model.geometry().function().identical(m.model.geometry().function()));
  EXPECT_FALSE(back.bounds);
  std::filesystem::remove_all(dir);
}
