// SPDX-License-Identifier: BSD-3-Clause
// The HyperFun reader: every construct and library name against hand-computed values or the same
// model built with the C++ kernel, compile-time loops and branches, select nodes, diagnostics and
// limits.
#include "FRep/Evaluators.h"
#include "FRep/Operations.h"
#include "FRep/Primitives.h"
#include "Lang/HyperFun.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

using namespace ictk;
using frep::Axis;
using frep::Expr;
using lang::readHyperFun;

namespace
{
frep::Shape geometry(const std::string& text, const std::string& fn = {})
{
  return readHyperFun(text, "test.hf", fn).model.geometry();
}

double at(const frep::Shape& s, double x, double y, double z, double t = 0,
  const std::vector<double>& params = {})
{
  frep::PointEvaluator ev(frep::Tape::compile(s.function()), params);
  return ev.eval(x, y, z, t);
}

double value(const std::string& body, double x = 0.3, double y = -0.2, double z = 0.1)
{
  return at(geometry("m(x[3], a[1]) {\n" + body + "\n}\n"), x, y, z, 0, { 0.5 });
}

// Same values at a set of points on the point evaluator (bit-identical).
void expectSameField(const frep::Shape& a, const frep::Shape& b)
{
  const double pts[][3] = { { 0, 0, 0 }, { 0.3, -0.2, 0.1 }, { 1.1, 0.7, -0.4 }, { -0.9, 0.5, 0.8 },
    { 2, -1.5, 0.25 } };
  for (const auto& p : pts)
  {
    EXPECT_EQ(at(a, p[0], p[1], p[2]), at(b, p[0], p[1], p[2]))
      << p[0] << " " << p[1] << " " << p[2];
  }
}

void expectLibrary(
  const std::string& call, const frep::Shape& reference, const std::string& decls = {})
{
  SCOPED_TRACE(call);
  const std::string text = "m(x[3], a[1]) {\n" + decls + "\nm = " + call + ";\n}\n";
  expectSameField(geometry(text), reference);
}

struct ErrorCase
{
  const char* text;
  int line;
  int column;
  const char* message;
};

lang::ParseError errorOf(const std::string& text, const lang::Limits& limits = {})
{
  try
  {
    readHyperFun(text, "bad.hf", {}, limits);
  }
  catch (const lang::ParseError& e)
  {
    return e;
  }
  ADD_FAILURE() << "no error for:\n" << text;
  return lang::ParseError({ lang::Diagnostic{} });
}
} // namespace

TEST(HyperFun, ArithmeticAndPrecedence)
{
  EXPECT_DOUBLE_EQ(value("m = 1 + 2 * 3 - 4 / 2;"), 5.0);
  EXPECT_DOUBLE_EQ(value("m = 2 ^ 3 ^ 2;"), 64.0); // left-associative as HyperFun
  EXPECT_DOUBLE_EQ(value("m = -2 ^ 2;"), 4.0);     // unary binds tighter than ^ (HyperFun)
  EXPECT_DOUBLE_EQ(value("m = 2 ^ -1;"), 0.5);
  EXPECT_DOUBLE_EQ(value("m = 4 ^ 0.5;"), 2.0);
  EXPECT_DOUBLE_EQ(value("m = x[1] * 10 + x[2] + x[3];"), 3.0 - 0.2 + 0.1);
  EXPECT_DOUBLE_EQ(value("m = a[1] * 2;"), 1.0); // parameter slot 0 = 0.5
  EXPECT_DOUBLE_EQ(value("m = +3 - -2;"), 5.0);
  EXPECT_DOUBLE_EQ(value("-- a comment\nm = 1.5e1; -- another"), 15.0);
  EXPECT_DOUBLE_EQ(value("M = 7;"), 7.0); // identifiers are case-insensitive
}

TEST(HyperFun, MathFunctions)
{
  EXPECT_DOUBLE_EQ(value("m = sqrt(16) + abs(-2);"), 6.0);
  EXPECT_DOUBLE_EQ(value("m = exp(0) + log(1);"), 1.0);
  EXPECT_DOUBLE_EQ(value("m = logd(1000);"), std::log(1000.0) / std::log(10.0));
  EXPECT_DOUBLE_EQ(value("m = sin(0) + cos(0) + tan(0);"), 1.0);
  EXPECT_DOUBLE_EQ(value("m = asin(1) + acos(1) + atan(1);"), std::asin(1.0) + std::atan(1.0));
  EXPECT_DOUBLE_EQ(value("m = atan2(1, 2);"), std::atan2(1.0, 2.0));
  EXPECT_DOUBLE_EQ(value("m = max(1, 3) + min(1, 3);"), 4.0);
  EXPECT_DOUBLE_EQ(value("m = sign(x[2]) + sign(x[1]);"), 0.0);
  EXPECT_DOUBLE_EQ(value("m = sinh(1) + cosh(1);"), std::exp(1.0));
  EXPECT_NEAR(value("m = tanh(0.5);"), std::tanh(0.5), 1e-15);
  EXPECT_DOUBLE_EQ(value("m = mod(7, 3) + floor(2.5) + ceil(2.5) + int(-2.5) + frac(2.25);"),
    1.0 + 2.0 + 3.0 - 2.0 + 0.25);
}

TEST(HyperFun, LogicAndComparisons)
{
  EXPECT_EQ(value("m = (1 < 2) + (2 <= 2) + (3 > 4) + (4 >= 4) + (1 = 1) + (1 /= 1);"), 4.0);
  EXPECT_EQ(value("m = (1 < 2 and 2 < 1) + (1 < 2 or 2 < 1) + (not 0) + (1 xor 1);"), 2.0);
  // On coordinates the comparisons stay exact at ties: x[1] < 0.3 is false at x = 0.3.
  EXPECT_EQ(value("m = (x[1] < 0.3) + 2 * (x[1] <= 0.3) + 4 * (x[1] = 0.3);"), 6.0);
}

TEST(HyperFun, SetOperationsAreHyperFunRFunctions)
{
  const auto s1 = frep::sphere({ 0, 0, 0 }, 1);
  const auto s2 = frep::sphere({ 0.5, 0, 0 }, 0.7);
  const std::string decls = "array c1[3], c2[3];\nc1 = [0, 0, 0];\nc2 = [0.5, 0, 0];\n"
                            "s1 = hfSphere(x, c1, 1);\ns2 = hfSphere(x, c2, 0.7);";
  expectLibrary("s1 | s2", frep::unite(s1, s2), decls);
  expectLibrary("s1 & s2", frep::intersect(s1, s2), decls);
  expectLibrary("s1 \\ s2", frep::subtract(s1, s2), decls);
  expectLibrary("~s1", frep::negate(s1), decls);
  expectLibrary("s1 @ s2", frep::intersect(s1, s2), decls);
  expectLibrary("hfBlendUni(s1, s2, 0.5, 1, 2)", frep::blendUnion(s1, s2, 0.5, 1, 2), decls);
  expectLibrary("hfBlendInt(s1, s2, 0.5, 1, 2)", frep::blendIntersection(s1, s2, 0.5, 1, 2), decls);
  // The same DAG, not only the same values.
  EXPECT_TRUE(geometry("m(x[3], a[1]) {\n" + decls + "\nm = s1 | s2;\n}")
                .function()
                .identical(frep::unite(s1, s2).function()));
}

TEST(HyperFun, Primitives)
{
  const std::string c = "array c[3];\nc = [0.1, -0.2, 0.3];";
  const frep::Vec3 cv = { 0.1, -0.2, 0.3 };
  expectLibrary("hfSphere(x, c, 1.5)", frep::sphere(cv, 1.5), c);
  expectLibrary("hfEllipsoid(x, c, 1, 2, 3)", frep::ellipsoid(cv, 1, 2, 3), c);
  expectLibrary("hfBlock(x, c, 1, 2, 3)", frep::blockRFunction(cv, 1, 2, 3, 0.0), c);
  const std::pair<const char*, Axis> axes[] = { { "X", Axis::X }, { "Y", Axis::Y },
    { "Z", Axis::Z } };
  for (const auto& [s, axis] : axes)
  {
    const std::string sx = s;
    expectLibrary("hfCylinder" + sx + "(x, c, 0.8)", frep::cylinder(axis, cv, 0.8), c);
    expectLibrary(
      "hfEllCyl" + sx + "(x, c, 0.8, 0.5)", frep::ellipticCylinder(axis, cv, 0.8, 0.5), c);
    expectLibrary("hfCone" + sx + "(x, c, 0.8)", frep::cone(axis, cv, 0.8), c);
    expectLibrary("hfEllCone" + sx + "(x, c, 0.8, 0.5)", frep::ellipticCone(axis, cv, 0.8, 0.5), c);
    expectLibrary("hfTorus" + sx + "(x, c, 1, 0.3)", frep::torus(axis, cv, 1, 0.3), c);
  }
  expectLibrary(
    "hfSuperell(x, c, 1, 2, 3, 0.5, 0.7)", frep::superellipsoid(cv, 1, 2, 3, 0.5, 0.7), c);
}

TEST(HyperFun, SkeletalPrimitives)
{
  const std::string d = "array x0[2], y0[2], z0[2], p[2], q[2];\n"
                        "x0 = [0, 1]; y0 = [0, 0.5]; z0 = [0.2, 0]; p = [1, 2]; q = [1.5, 0.8];";
  const std::vector<frep::Vec3> centers = { { 0, 0, 0.2 }, { 1, 0.5, 0 } };
  expectLibrary(
    "hfBlobby(x, x0, y0, z0, p, q, 0.5)", frep::blobby(centers, { 1, 2 }, { 1.5, 0.8 }, 0.5), d);
  expectLibrary("hfMetaBall(x, x0, y0, z0, p, q, 0.5)",
    frep::metaball(centers, { 1, 2 }, { 1.5, 0.8 }, 0.5), d);
  expectLibrary("hfSoft(x, x0, y0, z0, q, 0.5)", frep::softObject(centers, { 1.5, 0.8 }, 0.5), d);
  const std::string v = "array v[6], e[6], s[2];\nv = [0, 0, 0, 1, 0, 0];\n"
                        "e = [0, 1, 0, 1, 1, 0];\ns = [0.9, 1.1];";
  expectLibrary("hfConvPoint(x, v, s, 0.3)",
    frep::convolutionPoints({ { 0, 0, 0 }, { 1, 0, 0 } }, { 0.9, 1.1 }, 0.3), v);
  expectLibrary("hfConvLine(x, v, e, s, 0.3)",
    frep::convolutionSegments({ { frep::Vec3{ 0, 0, 0 }, frep::Vec3{ 0, 1, 0 } },
                                { frep::Vec3{ 1, 0, 0 }, frep::Vec3{ 1, 1, 0 } } },
      { 0.9, 1.1 }, 0.3),
    v);
  expectLibrary(
    "hfConvCurve(x, v, s, 0.3)", frep::convolutionCurve({ { 0, 0, 0 }, { 1, 0, 0 } }, 0.9, 0.3), v);
  const std::string m = "array v[9], t[3], s[1];\nv = [0, 0, 0, 1, 0, 0, 0, 1, 0];\n"
                        "t = [1, 2, 3];\ns = [1.2];";
  expectLibrary("hfConvMesh(x, v, t, s, 0.2)",
    frep::convolutionMesh({ { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 } }, { { 0, 1, 2 } }, 1.2, 0.2), m);
  const std::array<frep::Vec3, 3> tri = { frep::Vec3{ 0, 0, 0 }, frep::Vec3{ 1, 0, 0 },
    frep::Vec3{ 0, 1, 0 } };
  expectLibrary("hfConvTriangle(x, v, s, 0.2)",
    frep::Shape(1.2 * 1.2 * 1.2 * frep::cauchyTriangleField(tri, 1.2) - 0.2, frep::Domain::XYZ), m);
  const std::string arc =
    "array c[3], r[1], th[1], ax[3], an[1], s[1];\n"
    "c = [0, 0, 0]; r = [2]; th = [90]; ax = [1, 0, 0]; an = [30]; s = [0.8];";
  expectLibrary("hfConvArc(x, c, r, th, ax, an, s, 0.1)",
    frep::Shape(frep::cauchyArcField({ 0, 0, 0 }, 2, 90, { 1, 0, 0 }, 30, 0.8) / 2.0 - 0.1,
      frep::Domain::XYZ),
    arc);
  expectLibrary(
    "hfNoiseG(x, 0.5, 2, 0.3)", frep::Shape(frep::gardnerNoise(0.5, 2, 0.3), frep::Domain::XYZ));
}

TEST(HyperFun, SpaceMapsModifyTheirArrayInPlace)
{
  const auto s = frep::sphere({ 0, 0, 0 }, 1);
  const std::string pre = "array xt[3], c[3];\nc = [0, 0, 0];\nxt = x;\n";
  auto model = [&](const std::string& maps)
  {
    return geometry("m(x[3], a[1]) {\n" + pre + maps + "\nm = hfSphere(xt, c, 1);\n}");
  };
  expectSameField(model("hfShift3D(xt, 1, 2, 3);"), frep::shift(s, { 1, 2, 3 }));
  expectSameField(model("hfScale3D(xt, 1, 2, 3);"), frep::scale(s, { 1, 2, 3 }));
  expectSameField(model("hfRotate3DX(xt, 0.5);"), frep::rotate(s, Axis::X, 0.5));
  expectSameField(model("hfRotate3DY(xt, 0.5);"), frep::rotate(s, Axis::Y, 0.5));
  expectSameField(model("hfRotate3DZ(xt, 0.5);"), frep::rotate(s, Axis::Z, 0.5));
  for (Axis ax : { Axis::X, Axis::Y, Axis::Z })
  {
    const std::string n = frep::axisName(ax);
    const std::string N(1, static_cast<char>(std::toupper(n[0])));
    expectSameField(model("hfTwist" + N + "(xt, -1, 1, 0, 1);"), frep::twist(s, ax, -1, 1, 0, 1));
    expectSameField(
      model("hfTaper" + N + "(xt, -1, 1, 0.5, 2);"), frep::taper(s, ax, -1, 1, 0.5, 2));
  }
  expectSameField(model("array c0[3];\nc0 = [1, 0, 0];\nhfStretch3D(xt, c0, 2, 1, 0.5);"),
    frep::stretch(s, { 1, 0, 0 }, { 2, 1, 0.5 }));
  // In-place composition: shift, then rotate, as HyperFun applies them to xt.
  expectSameField(model("dummy = hfShift3D(xt, 1, 0, 0);\nhfRotate3DZ(xt, 0.5);"),
    frep::shift(frep::rotate(s, Axis::Z, 0.5), { 1, 0, 0 }));
  // The shifted sphere is the same DAG as the C++ one.
  EXPECT_TRUE(
    model("hfShift3D(xt, 1, 2, 3);").function().identical(frep::shift(s, { 1, 2, 3 }).function()));
}

TEST(HyperFun, ControlPointSpaceMapsAndConvLineR)
{
  // hfSpaceMapCubic/Exp(xt, source, target, b) (int_global.c argument order), two control points
  // (3 items each), applied in place to xt like the other space maps.
  const auto s = frep::sphere({ 0, 0, 0 }, 1);
  const std::string pre = "array xt[3], c[3], src[6], dst[6], b[6];\nc = [0, 0, 0];\nxt = x;\n"
                          "src = [0, 0, 0, 0.5, 0, 0];\ndst = [0.5, 0.2, 0, 0.5, -0.4, 0.3];\n"
                          "b = [1, 1, 1, 0.8, 2, 1];\n";
  auto model = [&](const std::string& map)
  {
    return geometry("m(x[3], a[1]) {\n" + pre + map + "\nm = hfSphere(xt, c, 1);\n}");
  };
  const std::vector<frep::Vec3> src{ { 0, 0, 0 }, { 0.5, 0, 0 } };
  const std::vector<frep::Vec3> dst{ { 0.5, 0.2, 0 }, { 0.5, -0.4, 0.3 } };
  const std::vector<frep::Vec3> b{ { 1, 1, 1 }, { 0.8, 2, 1 } };
  expectSameField(model("hfSpaceMapCubic(xt, src, dst, b);"), frep::spaceMapCubic(s, src, dst, b));
  expectSameField(model("hfSpaceMapExp(xt, src, dst, b);"), frep::spaceMapExp(s, src, dst, b));
  // Applied after another map, on the already moved coordinates.
  expectSameField(model("hfShift3D(xt, 1, 0, 0);\nhfSpaceMapExp(xt, src, dst, b);"),
    frep::shift(frep::spaceMapExp(s, src, dst, b), { 1, 0, 0 }));
  // hfConvLineR(x, begin, end, R): two segments.
  const std::vector<std::array<frep::Vec3, 2>> segs{ { frep::Vec3{ -1, 0, 0 },
                                                       frep::Vec3{ 0, 0.5, 0 } },
    { frep::Vec3{ 0, 0.5, 0 }, frep::Vec3{ 1, 0, 0.2 } } };
  expectLibrary("hfConvLineR(x, bg, en, 0.4)", frep::convolutionSegmentsRadius(segs, 0.4),
    "array bg[6], en[6];\nbg = [-1, 0, 0, 0, 0.5, 0];\nen = [0, 0.5, 0, 1, 0, 0.2];");
  // Diagnostics: a source array that is not whole points, a short target, a zero b.
  auto error = [&](const std::string& map)
  {
    try
    {
      model(map);
    }
    catch (const lang::ParseError& e)
    {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(error("array s5[5];\ns5 = [0, 0, 0, 1, 1];\nhfSpaceMapCubic(xt, s5, dst, b);")
              .find("3 items per control point"),
    std::string::npos);
  EXPECT_NE(error("array d3[3];\nd3 = [1, 1, 1];\nhfSpaceMapExp(xt, src, d3, b);")
              .find("argument 3 of hfSpaceMapExp must have 6 items"),
    std::string::npos);
  EXPECT_NE(
    error("b[2] = 0;\nhfSpaceMapCubic(xt, src, dst, b);").find("influence"), std::string::npos);
}

TEST(HyperFun, DomainsAndParameters)
{
  const auto m2 = readHyperFun("disk(x[2], a[2]) { disk = a[1] - x[1]^2 - x[2]^2; }", "d.hf");
  EXPECT_EQ(m2.model.geometry().domain(), frep::Domain::XY);
  EXPECT_EQ(m2.parameterCount, 2);
  EXPECT_EQ(m2.name, "disk");
  EXPECT_DOUBLE_EQ(at(m2.model.geometry(), 0.5, 0.5, 0, 0, { 1, 0 }), 0.5);
  const auto m4 = readHyperFun("st(x[4], a[1]) { st = x[4] - x[1]; }", "t.hf");
  EXPECT_EQ(m4.model.geometry().domain(), frep::Domain::XYZT);
  EXPECT_DOUBLE_EQ(at(m4.model.geometry(), 1, 0, 0, 3), 2.0);
}

TEST(HyperFun, SeveralFunctionsCallingEachOther)
{
  const std::string text = "ball(x[3], a[1]) {\n array c[3];\n c = [0, 0, 0];\n"
                           " ball = hfSphere(x, c, 1) + a[1];\n}\n"
                           "shifted(x[3], b[1]) {\n array xt[3], r[1];\n xt = x;\n r = [2];\n"
                           " hfShift3D(xt, 1, 0, 0);\n shifted = ball(xt, r);\n}\n";
  // The callee's a[1] is the caller's r[1] = 2.
  const auto g = geometry(text, "shifted");
  expectSameField(g,
    frep::Shape(
      frep::shift(frep::sphere({ 0, 0, 0 }, 1), { 1, 0, 0 }).function() + 2.0, frep::Domain::XYZ));
  // Choosing a function by name.
  EXPECT_EQ(readHyperFun(text, "f.hf", "BALL").name, "ball");
}

TEST(HyperFun, TheModelIsMyModelElseTheFirstFunction)
{
  // As HyperFun's interpreter (hfp -o, default my_model; a name not in the file: the first).
  const std::string first = "a(x[3], p[1]) {\n a = 1 - x[1];\n}\nb(x[3], p[1]) {\n b = 2;\n}\n";
  const auto model = readHyperFun(first, "f.hf");
  EXPECT_EQ(model.name, "a");
  EXPECT_EQ(at(model.model.geometry(), 0.25, 0, 0), 0.75);
  const std::string named = first + "my_model(x[3], p[1]) {\n my_model = 3 - x[2];\n}\n";
  EXPECT_EQ(readHyperFun(named, "f.hf").name, "my_model");
  EXPECT_EQ(at(geometry(named), 0, 0.5, 0), 2.5);
}

TEST(HyperFun, StrictRefusesWhatHyperFunDoesNotRead)
{
  lang::Limits strict;
  strict.strictHyperFun = true;
  // A call of a function defined later in the file (HyperFun calls only earlier ones).
  const std::string later = "my_model(x[3], a[1]) {\n my_model = ball(x, a) + 1;\n}\n"
                            "ball(x[3], a[1]) {\n array c[3];\n c = [0, 0, 0];\n"
                            " ball = hfSphere(x, c, 1);\n}\n";
  EXPECT_EQ(at(geometry(later), 0, 0, 0), 2.0); // ICTK reads it
  lang::ParseError e = errorOf(later, strict);
  ASSERT_EQ(e.diagnostics().size(), 1u);
  EXPECT_EQ(e.diagnostics()[0].where.line, 2);
  EXPECT_EQ(e.diagnostics()[0].where.column, 13);
  EXPECT_EQ(e.diagnostics()[0].message,
    "'ball' is defined after 'my_model': HyperFun calls only functions defined before the caller "
    "(refused by --strict)");
  // The same two functions in HyperFun's order read the same under --strict.
  const std::string before = "ball(x[3], a[1]) {\n array c[3];\n c = [0, 0, 0];\n"
                             " ball = hfSphere(x, c, 1);\n}\n"
                             "my_model(x[3], a[1]) {\n my_model = ball(x, a) + 1;\n}\n";
  EXPECT_EQ(at(readHyperFun(before, "f.hf", {}, strict).model.geometry(), 0, 0, 0), 2.0);
  // ICTK's own library functions.
  for (const char* call : { "hfGyroid(x, 1, 0.1)", "hfPin(x, o, o, 0.1, 1)" })
  {
    SCOPED_TRACE(call);
    const std::string text =
      std::string("m(x[3], a[1]) {\n array o[3];\n o = [0, 0, 1];\n m = ") + call + ";\n}\n";
    EXPECT_NO_THROW(readHyperFun(text, "f.hf"));
    e = errorOf(text, strict);
    ASSERT_EQ(e.diagnostics().size(), 1u);
    EXPECT_EQ(e.diagnostics()[0].where.line, 4);
    EXPECT_EQ(e.diagnostics()[0].where.column, 6);
    EXPECT_EQ(e.diagnostics()[0].message,
      "'" + std::string(call).substr(0, std::string(call).find('(')) +
        "' is ICTK's own, not in HyperFun's library (refused by --strict)");
  }
}

TEST(HyperFun, LoopsAndConstantBranchesFoldToTheClosedForm)
{
  const auto looped =
    geometry("m(x[3], a[1]) {\n"
             " f = 0; i = 1;\n"
             " while (i <= 3) loop\n"
             "   if (i = 2) then f = f + x[2] * i; else f = f + x[1] * i; endif;\n"
             "   i = i + 1;\n"
             " endloop;\n"
             " m = f;\n}");
  const Expr X = Expr::x(), Y = Expr::y();
  const Expr closed = ((Expr(0.0) + X * 1.0) + Y * 2.0) + X * 3.0;
  EXPECT_TRUE(looped.function().identical(closed)) << frep::toString(looped.function());
  // Arrays, item assignment and a loop filling them.
  EXPECT_DOUBLE_EQ(
    value("array v[4];\ni = 1;\nwhile i <= 4 loop v[i] = i * i; i = i + 1; endloop;\n"
          "m = v[1] + v[2] + v[3] + v[4];"),
    30.0);
}

TEST(HyperFun, BranchOnCoordinatesBecomesSelect)
{
  const auto s = geometry("m(x[3], a[1]) {\n"
                          " if x[1] < 0 then f = x[2]; else f = -x[2]; endif;\n"
                          " m = f;\n}");
  const Expr& f = s.function();
  ASSERT_EQ(f.opcode(), frep::Opcode::Select);
  EXPECT_DOUBLE_EQ(at(s, -1, 0.5, 0), 0.5);
  EXPECT_DOUBLE_EQ(at(s, 1, 0.5, 0), -0.5);
  EXPECT_DOUBLE_EQ(at(s, 0, 0.5, 0), -0.5); // tie: 0 < 0 is false
  frep::IntervalEvaluator iv(frep::Tape::compile(f));
  frep::Region region;
  region.axes = { frep::Interval{ -1, 1 }, frep::Interval{ -1, 1 }, frep::Interval{ -1, 1 },
    frep::Interval{ 0, 0 } };
  const auto range = iv.eval(region);
  for (double x = -1; x <= 1; x += 0.25)
  {
    for (double y = -1; y <= 1; y += 0.25)
    {
      const double v = at(s, x, y, 0);
      EXPECT_LE(range.lo, v);
      EXPECT_GE(range.hi, v);
    }
  }
  // A return inside a coordinate branch.
  const auto r = geometry("m(x[3], a[1]) {\n if x[1] > 0 then m = 1; endif;\n m = 2;\n}");
  EXPECT_DOUBLE_EQ(at(r, 1, 0, 0), 1.0);
  EXPECT_DOUBLE_EQ(at(r, -1, 0, 0), 2.0);
  // A branch on a parameter is also a select (parameters change without recompiling).
  const auto pm =
    readHyperFun("m(x[3], a[1]) { if a[1] > 0 then m = x[1]; else m = x[2]; endif; }", "p.hf");
  EXPECT_DOUBLE_EQ(at(pm.model.geometry(), 3, 4, 0, 0, { 1 }), 3.0);
  EXPECT_DOUBLE_EQ(at(pm.model.geometry(), 3, 4, 0, 0, { -1 }), 4.0);
}

TEST(HyperFun, ColourAttribute)
{
  const auto m = readHyperFun("m(x[3], a[1], s[3]) {\n array c[3];\n c = [0, 0, 0];\n"
                              " f = hfSphere(x, c, 1);\n hfA_SetColor(f, s, 1, 0.5, 0.25);\n"
                              " m = f;\n}",
    "c.hf");
  const auto* colour = m.model.findAttribute("colour");
  ASSERT_NE(colour, nullptr);
  ASSERT_EQ(colour->components.size(), 3u);
  frep::HypervolumeEvaluator ev(m.model);
  double f = 0, rgb[3] = {};
  ev.eval({ 0, 0, 0, 0 }, f, rgb);
  EXPECT_EQ(rgb[0], 1.0);
  EXPECT_EQ(rgb[1], 0.5);
  EXPECT_EQ(rgb[2], 0.25);
  ev.eval({ 2, 0, 0, 0 }, f, rgb);
  EXPECT_EQ(rgb[0], 0.0);
}

TEST(HyperFun, Diagnostics)
{
  const ErrorCase cases[] = {
    { "m(x[3], a[1]) {\n m = 1 +;\n}", 2, 9, "expected an expression" },
    { "m(x[3], a[1]) {\n m = (1 + 2;\n}", 2, 12, "expected ')'" },
    { "m(x[3], a[1]) {\n m = 1\n}", 3, 1, "expected ';'" },
    { "m(x[3], a[1]) {\n m = hfFoo(x);\n}", 2, 6, "unknown library function 'hfFoo'" },
    { "m(x[3], a[1]) {\n m = q + 1;\n}", 2, 6, "unknown variable 'q'" },
    { "m(x[3], a[1]) {\n m = x[4];\n}", 2, 8, "out of range" },
    { "m(x[3], a[1]) {\n m = 1 # 2;\n}", 2, 8, "unexpected character '#'" },
    { "m(x[3], a[1]) {\n m = 1.5e;\n}", 2, 6, "malformed number" },
    { "m(x[3], a[1]) {\n if 1 then m = 1;\n}", 2, 2, "this 'if' is not closed by 'endif'" },
    { "m(x[3], a[1]) {\n while x[1] < 1 loop m = 1; endloop;\n}", 2, 8,
      "must be known at compile time" },
    { "m(x[3], a[1]) {\n i = 0;\n while i < a[1] loop i = i + 1; endloop;\n m = 1;\n}", 3, 8,
      "model parameters" },
    { "m(x[3], a[1]) {\n m = a[x[1]];\n}", 2, 8, "index into 'a' must be known at compile time" },
    { "m(x[3], a[1]) {\n m = 1 / 0;\n}", 2, 8, "division by zero" },
    { "m(x[3], a[1]) {\n array c[3];\n c = [1, 2];\n m = 1;\n}", 3, 2, "wrong number of items" },
    { "m(x[3], a[1]) {\n m = sqrt(1, 2);\n}", 2, 6, "sqrt takes 1 argument" },
    { "m(x[3], a[1]) {\n f = 1;\n}", 3, 1, "never assigns its result" },
    { "m(x[7], a[1]) {\n m = 1;\n}", 1, 3, "1 to 4 items" },
    { "m(x[3], a[1]) {\n array c[3];\n m = hfSphere(x, c, 1);\n}", 3, 18, "used before" },
    { "m(x[3], a[1]) {\n array c[3];\n c = [0,0,0];\n m = hfSphere(x, c, -1);\n}", 4, 6,
      "hfSphere: sphere" },
    { "m(x[3], a[1]) {\n m = sqrt(-1);\n}", 2, 6, "square root of a negative" },
    { "m(x[3] a[1]) {\n m = 1;\n}", 1, 8, "expected ')'" },
    { "m(x[3], a[1]) {\n endif;\n m = 1;\n}", 2, 2, "unexpected 'endif'" },
  };
  for (const auto& c : cases)
  {
    SCOPED_TRACE(c.text);
    const auto e = errorOf(c.text);
    ASSERT_FALSE(e.diagnostics().empty());
    const auto& d = e.diagnostics()[0];
    const std::string prefix =
      "bad.hf:" + std::to_string(c.line) + ":" + std::to_string(c.column) + ": error: ";
    const std::string text = lang::formatDiagnostic(d);
    EXPECT_EQ(text.rfind(prefix, 0), 0u) << text;
    EXPECT_NE(text.find(c.message), std::string::npos) << text;
    // The source line follows, then the caret under the column.
    const auto nl = text.find('\n');
    ASSERT_NE(nl, std::string::npos) << text;
    const auto nl2 = text.find('\n', nl + 1);
    ASSERT_NE(nl2, std::string::npos) << text;
    const std::string caret = text.substr(nl2 + 1);
    EXPECT_EQ(caret.size(), static_cast<std::size_t>(c.column)) << text;
    EXPECT_EQ(caret.back(), '^');
  }
}

TEST(HyperFun, SeveralErrorsInOneRun)
{
  const auto e = errorOf("m(x[3], a[1]) {\n a1 = 1 +;\n a2 = );\n m = hfNope(x);\n}\n"
                         "n(x[3], a[1]) {\n n = 1 2;\n}\n");
  ASSERT_GE(e.diagnostics().size(), 3u);
  EXPECT_EQ(e.diagnostics()[0].where.line, 2);
  EXPECT_EQ(e.diagnostics()[1].where.line, 3);
  EXPECT_EQ(e.diagnostics()[2].where.line, 7);
  // Compile errors are reported together too (after a clean parse).
  const auto c = errorOf("m(x[3], a[1]) {\n p = hfNope(x);\n q = zz;\n m = 1;\n}");
  ASSERT_EQ(c.diagnostics().size(), 2u);
  EXPECT_NE(std::string(c.what()).find("test"), 0u);
  EXPECT_NE(c.diagnostics()[0].message.find("'hfNope'"), std::string::npos);
  EXPECT_EQ(c.diagnostics()[0].where.line, 2);
  EXPECT_EQ(c.diagnostics()[1].where.line, 3);
}

TEST(HyperFun, Limits)
{
  // Deep nesting: a clean error, no stack overflow.
  const auto deep = errorOf("m(x[3], a[1]) { m = " + std::string(100000, '(') + "1; }");
  EXPECT_NE(deep.diagnostics()[0].message.find("nesting deeper"), std::string::npos);
  const auto unary = errorOf("m(x[3], a[1]) { m = " + std::string(100000, '~') + "1; }");
  EXPECT_NE(unary.diagnostics()[0].message.find("nesting deeper"), std::string::npos);
  // Huge loop.
  lang::Limits small;
  small.maxLoopIterations = 1000;
  const auto loop = errorOf("m(x[3], a[1]) {\n i = 0;\n while i < 1e12 loop i = i + 1; endloop;\n"
                            " m = i;\n}",
    small);
  EXPECT_NE(loop.diagnostics()[0].message.find("limit of 1000 iterations"), std::string::npos);
  EXPECT_EQ(loop.diagnostics()[0].where.line, 3);
  // Infinite loop with the default limit still ends.
  lang::Limits medium;
  medium.maxLoopIterations = 200000;
  errorOf("m(x[3], a[1]) { while 1 loop endloop; m = 1; }", medium);
  // File too large.
  lang::Limits tiny;
  tiny.maxFileBytes = 10;
  const auto big = errorOf("m(x[3], a[1]) { m = 1; }", tiny);
  EXPECT_NE(big.diagnostics()[0].message.find("too large"), std::string::npos);
  // DAG size.
  lang::Limits nodes;
  nodes.maxExpressionNodes = 1000;
  const auto dag = errorOf("m(x[3], a[1]) {\n f = 0; i = 0;\n while i < 5000 loop f = f + x[1] * i;"
                           " i = i + 1; endloop;\n m = f;\n}",
    nodes);
  EXPECT_NE(dag.diagnostics()[0].message.find("too large"), std::string::npos);
  // A long flat chain is fine (not nesting).
  std::string chain = "m(x[3], a[1]) { m = x[1]";
  for (int i = 0; i < 20000; ++i)
  {
    chain += " + 1";
  }
  EXPECT_NO_THROW(readHyperFun(chain + "; }", "chain.hf"));
}

TEST(HyperFun, NeverCrashesOnGarbage)
{
  const std::string samples[] = { "", "{", "}", "m(", "m(x[3]", "m(x[0], a[1]) {}",
    "m(x[3], a[1]) { m = ; }", "m(x[3], a[1]) { array ; }", "m(x[3],a[1]){ if then endif; }",
    "m(x[3],a[1]){m=m(x,a);}", "\xff\xfe\x00\x01", "m(x[3],a[1]){ x = 1; m = x; }",
    "m(x[3],a[1]){ array b[2000000]; m = 1; }", "m(x[3],a[1]){ m = 1e400; }",
    "m(x[3],a[1]){ m = 2^1e300; }",
    "m(x[3],a[1]){ array c[3]; c = [0,0,0]; m = hfSphere(c, c, 1); }" };
  for (const auto& s : samples)
  {
    try
    {
      readHyperFun(s, "g.hf");
    }
    catch (const lang::ParseError&)
    {
    }
  }
}

TEST(HyperFun, ParametersSpecialiseLibraryArguments)
{
  // a[1] as a radius and a[2] in a centre: refused as parameter slots (the library needs numbers),
  // accepted once the model is specialised to values, giving the ball of radius 0.8 at (0.5, 0, 0).
  const std::string text = "m(x[3], a[2]) {\n array c[3];\n c = [a[2], 0, 0];\n"
                           " m = hfSphere(x, c, a[1]);\n}\n";
  try
  {
    readHyperFun(text, "p.hf");
    FAIL() << "a parameter as a library argument was accepted without values";
  }
  catch (const lang::ParseError& e)
  {
    EXPECT_NE(std::string(e.what()).find("give their values"), std::string::npos) << e.what();
  }
  const auto m = readHyperFun(text, "p.hf", {}, {}, { 0.8, 0.5 });
  EXPECT_EQ(m.parameterCount, 2);
  expectSameField(m.model.geometry(), frep::sphere({ 0.5, 0, 0 }, 0.8));
  EXPECT_THROW(readHyperFun(text, "p.hf", {}, {}, { 0.8 }), lang::ParseError);
}

TEST(HyperFun, RoundingFunctionsOnCoordinates)
{
  // At (2.7, -1.2, -3.6): floor(2.7) = 2, ceil(-1.2) = -1, int(-3.6) = -3 (towards zero),
  // frac(2.7) = 2.7 - 2, mod(27, 4) = 3 (27 = 10 * 2.7 rounded, as HyperFun rounds mod's
  // arguments).
  const double v = value(
    "m = floor(x[1]) + ceil(x[2]) + int(x[3]) + frac(x[1]) + mod(x[1] * 10, 4);", 2.7, -1.2, -3.6);
  EXPECT_DOUBLE_EQ(v, 2.0 - 1.0 - 3.0 + (2.7 - 2.0) + 3.0);
  // fmod keeps the dividend's sign: mod(-7, 3) = -1; frac(-2.25) = -0.25.
  EXPECT_DOUBLE_EQ(value("m = mod(x[1] * 10, 3) + frac(x[2]);", -0.7, -2.25, 0), -1.25);
  // A floor on a coordinate is an opcode, so intervals and pruning still work on the model.
  const auto g = geometry("m(x[3], a[1]) {\n m = floor(x[1]) - 0.5;\n}\n");
  frep::IntervalEvaluator interval(frep::Tape::compile(g.function()));
  frep::Region r;
  r.axes = { frep::Interval{ 0.2, 0.8 }, frep::Interval{ 0, 0 }, frep::Interval{ 0, 0 },
    frep::Interval{ 0, 0 } };
  const frep::Interval range = interval.eval(r);
  // floor maps [0.2, 0.8] to exactly [0, 0]; the subtraction widens by one ulp each side.
  EXPECT_NEAR(range.lo, -0.5, 1e-15);
  EXPECT_NEAR(range.hi, -0.5, 1e-15);
}
