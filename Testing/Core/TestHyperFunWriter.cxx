// SPDX-License-Identifier: BSD-3-Clause
// FRep DAG -> HyperFun text, and back through the HyperFun reader.
#include "FRep/Hypervolume.h"
#include "Lang/HyperFun.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <optional>
#include <random>

using namespace ictk;
using frep::Axis;
using frep::Domain;
using frep::Expr;
using frep::Opcode;

namespace
{

std::size_t countOf(const std::string& text, const std::string& what)
{
  std::size_t n = 0;
  for (auto i = text.find(what); i != std::string::npos; i = text.find(what, i + 1))
  {
    ++n;
  }
  return n;
}

bool contains(const std::string& text, const std::string& what)
{
  return text.find(what) != std::string::npos;
}

frep::Hypervolume shape(const Expr& f, Domain d = Domain::XYZ)
{
  return frep::Hypervolume(frep::Shape(f, d));
}

// A random DAG using every opcode but with finite constants only (HyperFun cannot write NaN or
// infinities), Pow only with a non-constant exponent (a constant integer exponent reads back
// through frep::pow as a product of squares, a different node) and Div only by a non-constant
// (HyperFun refuses a constant divisor below 1e-6), CauchySegment only of a square (its terms take
// sqrt(1 + v)).
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
  for (int i = 0; i < 3; ++i)
  {
    pool.push_back(Expr::constant(value(rng)));
  }
  pool.push_back(Expr::constant(1e-7));
  const int first = static_cast<int>(Opcode::Neg);
  const int count = static_cast<int>(Opcode::Count_) - first;
  auto pick = [&]() -> const Expr&
  {
    const std::size_t n = pool.size();
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
      {
        const Expr& a = pick();
        Expr b = pick();
        // HyperFun refuses a constant divisor below its EPS (1e-6).
        if ((op == Opcode::Pow || op == Opcode::Div) && b.isConstant())
        {
          b = pool[0];
        }
        e = Expr::make(op, a, b);
        break;
      }
      default:
      {
        const Expr& a = pick();
        Expr b = pick();
        // The Cauchy segment's second operand is a squared distance: HyperFun refuses the
        // square root of a negative constant that its terms would take otherwise.
        if (op == Opcode::CauchySegment)
        {
          b = frep::square(b);
        }
        e = Expr::make(op, a, b, pick());
        break;
      }
    }
    if (e.isConstant() && !std::isfinite(e.constantValue()))
    {
      continue;
    }
    pool.push_back(e);
  }
  Expr root = pool.back();
  for (std::size_t i = pool.size() > 6 ? pool.size() - 6 : 0; i + 1 < pool.size(); ++i)
  {
    Expr sum = Expr::make(Opcode::Add, root, pool[i]);
    if (!(sum.isConstant() && !std::isfinite(sum.constantValue())))
    {
      root = sum;
    }
  }
  return root;
}

bool sameValue(double a, double b)
{
  return (std::isnan(a) && std::isnan(b)) || a == b;
}

} // namespace

TEST(HyperFunWriter, SmallModel)
{
  const Expr x = Expr::x(), y = Expr::y(), z = Expr::z();
  const std::string text =
    lang::writeHyperFun(shape(1.0 - (frep::square(x) + frep::square(y) + frep::square(z))), "ball");
  const std::string expected = "-- ball: written by ICTK (ictk::lang::writeHyperFun)\n"
                               "-- domain XYZ; coordinates x[1] = x, x[2] = y, x[3] = z, x[4] = t\n"
                               "ball(x[3], a[1])\n"
                               "{\n"
                               "  ball = 1 - (x[1]^2 + x[2]^2 + x[3]^2);\n"
                               "}\n";
  EXPECT_EQ(text, expected);
}

TEST(HyperFunWriter, Operators)
{
  const Expr x = Expr::x(), y = Expr::y();
  const std::string text =
    lang::writeHyperFun(shape(frep::min(frep::sqrt(frep::abs(x)), frep::atan2(y, x)) -
        frep::max(-x, frep::sign(y)) / Expr::make(Opcode::Pow, x, y) *
          frep::exp(
            frep::log(frep::sin(frep::cos(frep::tan(frep::asin(frep::acos(frep::atan(x)))))))),
      Domain::XY));
  for (const char* what :
    { "x[2]", "min(sqrt(abs(x[1])), atan2(x[2], x[1]))", "max(-x[1], sign(x[2]))", "x[1]^x[2]",
      "exp(log(sin(cos(tan(asin(acos(atan(x[1]))))))))", " / ", " * ", " - " })
  {
    EXPECT_TRUE(contains(text, what)) << what << "\n" << text;
  }
  EXPECT_TRUE(contains(text, "model(x[2], a[1])")) << text;
}

TEST(HyperFunWriter, Constants)
{
  const Expr x = Expr::x();
  const std::string text = lang::writeHyperFun(
    shape(x * 0.1 + x * 1e-7 + x * 1e20 + x * -2.5 + x * 5e-324 + x * 3.0, Domain::XY));
  for (const char* what : { "0.10000000000000001", "9.9999999999999995e-8", "1e20", "(-2.5)",
         "4.9406564584124654e-324", " * 3" })
  {
    EXPECT_TRUE(contains(text, what)) << what << "\n" << text;
  }
  EXPECT_FALSE(contains(text, "e+"));
  EXPECT_FALSE(contains(text, "e-0"));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_THROW(lang::writeHyperFun(shape(x + nan)), std::invalid_argument);
  EXPECT_THROW(lang::writeHyperFun(shape(x + inf)), std::invalid_argument);
  EXPECT_THROW(lang::writeHyperFun(shape(x / 1e-7)), std::invalid_argument);
  EXPECT_NO_THROW(lang::writeHyperFun(shape(x / 1e-5)));
  try
  {
    lang::writeHyperFun(shape(x - inf));
  }
  catch (const std::invalid_argument& e)
  {
    EXPECT_TRUE(contains(e.what(), "infinity")) << e.what();
  }
}

TEST(HyperFunWriter, SharedNodesBecomeLocals)
{
  const Expr x = Expr::x(), y = Expr::y();
  const Expr r = x * x + y * y;
  const std::string text =
    lang::writeHyperFun(shape(frep::max(r - 1.0, 0.5 - r), Domain::XY), "ring");
  EXPECT_EQ(countOf(text, "v1 = "), 1u) << text;
  EXPECT_TRUE(contains(text, "v1 = x[1] * x[1] + x[2] * x[2];")) << text;
  EXPECT_TRUE(contains(text, "ring = max(v1 - 1, 0.5 - v1);")) << text;

  // 2^60 nodes as a tree, 121 as a DAG: the text stays small.
  Expr e = x + y;
  for (int k = 0; k < 60; ++k)
  {
    e = e * e + e;
  }
  const std::string big = lang::writeHyperFun(shape(e, Domain::XY));
  EXPECT_LT(big.size(), 10000u);
}

TEST(HyperFunWriter, Select)
{
  const Expr x = Expr::x(), y = Expr::y();
  const std::string text =
    lang::writeHyperFun(shape(frep::select((x + 1.0) * y, x, y * 2.0) + 1.0, Domain::XY), "branch");
  EXPECT_TRUE(contains(text,
    "  v1 = (x[1] + 1) * x[2];\n"
    "  if (v1 >= 0) then\n"
    "    v2 = x[1];\n"
    "  else\n"
    "    v2 = x[2] * 2;\n"
    "  endif;\n"
    "  branch = v2 + 1;\n"))
    << text;
}

TEST(HyperFunWriter, DomainsAndParameters)
{
  const Expr x = Expr::x(), t = Expr::t();
  EXPECT_TRUE(contains(lang::writeHyperFun(shape(x, Domain::X), "m"), "m(x[2], a[1])"));
  const std::string xt = lang::writeHyperFun(shape(x * t, Domain::XT), "m");
  EXPECT_TRUE(contains(xt, "m(x[4], a[1])")) << xt;
  EXPECT_TRUE(contains(xt, "m = x[1] * x[4];")) << xt;
  EXPECT_TRUE(contains(lang::writeHyperFun(shape(t, Domain::T), "m"), "m(x[4], a[1])"));
  EXPECT_TRUE(contains(lang::writeHyperFun(shape(x, Domain::XYT), "m"), "m(x[4], a[1])"));
  EXPECT_TRUE(contains(lang::writeHyperFun(shape(x, Domain::XYZT), "m"), "m(x[4], a[1])"));
  const std::string p = lang::writeHyperFun(shape(x * Expr::parameter(2)), "m");
  EXPECT_TRUE(contains(p, "m(x[3], a[3])")) << p;
  EXPECT_TRUE(contains(p, "x[1] * a[3]")) << p;
  EXPECT_TRUE(contains(lang::writeHyperFun(shape(x), "m", 5), "m(x[3], a[5])"));
}

TEST(HyperFunWriter, ColourAndOtherAttributes)
{
  const Expr x = Expr::x(), y = Expr::y();
  frep::Hypervolume hv = shape(1.0 - x * x, Domain::XY);
  frep::Attribute colour;
  colour.name = "colour";
  colour.components = { x, y * y, 0.5 };
  hv.addAttribute(colour);
  frep::Attribute density;
  density.name = "density\nwith a newline";
  density.components = { x };
  density.partition = y;
  density.insideDefault = { 2 };
  hv.addAttribute(density);
  const std::string text = lang::writeHyperFun(hv, "m");
  EXPECT_TRUE(contains(text, "m(x[2], a[1], s[3])")) << text;
  EXPECT_TRUE(contains(text, "  s[1] = x[1];\n  s[2] = x[2] * x[2];\n  s[3] = 0.5;\n")) << text;
  EXPECT_TRUE(contains(text, "--   attribute 'density?with a newline': 1 component(s)")) << text;
  EXPECT_TRUE(contains(text, "--     inside default  2")) << text;

  // A colour with a partition is not HyperFun's colour: it goes to the comment.
  frep::Hypervolume partitioned = shape(1.0 - x * x, Domain::XY);
  colour.partition = x;
  partitioned.addAttribute(colour);
  const std::string p = lang::writeHyperFun(partitioned, "m");
  EXPECT_FALSE(contains(p, "s[3]")) << p;
  EXPECT_TRUE(contains(p, "attribute 'colour'")) << p;

  frep::Hypervolume thresholded(frep::Shape(x, Domain::XY), 0.5);
  EXPECT_TRUE(contains(lang::writeHyperFun(thresholded, "m"), "--   threshold 0.5"));
}

TEST(HyperFunWriter, Names)
{
  const frep::Hypervolume hv = shape(Expr::x());
  EXPECT_NO_THROW(lang::writeHyperFun(hv, "My_Model2"));
  for (const char* bad :
    { "", "2model", "my model", "x", "S", "sqrt", "if", "hfSphere", "v12", "caf\xc3\xa9" })
  {
    EXPECT_THROW(lang::writeHyperFun(hv, bad), std::invalid_argument) << bad;
  }
}

TEST(HyperFunWriter, DeepChainsUseLocals)
{
  Expr e = Expr::x();
  for (int i = 0; i < 5000; ++i)
  {
    e = frep::max(e, Expr::y() - static_cast<double>(i));
  }
  const std::string text = lang::writeHyperFun(shape(e, Domain::XY));
  // No statement nests brackets deeply.
  int depth = 0, deepest = 0;
  for (char c : text)
  {
    depth += c == '(' ? 1 : c == ')' ? -1 : 0;
    deepest = std::max(deepest, depth);
  }
  EXPECT_LT(deepest, 60);
}

// ---- Round trips through the HyperFun reader (HyperFunReader.cxx)

TEST(HyperFunRoundTrip, SmallModels)
{
  const Expr x = Expr::x(), y = Expr::y(), z = Expr::z();
  const Expr r = x * x + y * y;
  const std::vector<Expr> models = { 1.0 - (frep::square(x) + frep::square(y) + frep::square(z)),
    frep::max(r - 1.0, 0.5 - r), frep::select((x + 1.0) * y, x, y * 2.0) + 1.0,
    x * Expr::parameter(1) - frep::pow(frep::abs(y), z) };
  for (const Expr& f : models)
  {
    const std::string text = lang::writeHyperFun(shape(f), "m", 2);
    lang::HyperFunModel back = lang::readHyperFun(text, "m.hf");
    EXPECT_EQ(back.name, "m");
    EXPECT_EQ(back.parameterCount, 2);
    EXPECT_EQ(back.model.geometry().domain(), Domain::XYZ);
    EXPECT_TRUE(back.model.geometry().function().identical(f))
      << text << "\n"
      << frep::toString(back.model.geometry().function());
  }
}

TEST(HyperFunRoundTrip, RandomDags)
{
  std::mt19937 rng(2024);
  std::uniform_real_distribution<double> u(-2, 2);
  const Domain domains[] = { Domain::XY, Domain::XYZ, Domain::XYZT };
  for (int iteration = 0; iteration < 200; ++iteration)
  {
    const Domain d = domains[iteration % 3];
    const int params = 1 + static_cast<int>(rng() % 3);
    const Expr f = randomDag(rng, 10 + static_cast<int>(rng() % 50), d, params);
    frep::Hypervolume hv = shape(f, d);
    if (iteration % 2)
    {
      frep::Attribute colour;
      colour.name = "colour";
      for (int c = 0; c < 3; ++c)
      {
        colour.components.push_back(randomDag(rng, 6, d, params));
      }
      hv.addAttribute(colour);
    }
    const std::string text = lang::writeHyperFun(hv, "model", params);
    std::optional<lang::HyperFunModel> back;
    try
    {
      back.emplace(lang::readHyperFun(text, "random.hf"));
    }
    catch (const std::exception& e)
    {
      FAIL() << e.what() << "\n" << text;
    }
    ASSERT_EQ(back->model.geometry().domain(), d);
    ASSERT_EQ(back->model.attributes().size(), hv.attributes().size()) << text;
    std::vector<double> p(static_cast<std::size_t>(params));
    for (double& v : p)
    {
      v = u(rng);
    }
    frep::PointEvaluator a(hv.compile(), p);
    frep::PointEvaluator b(back->model.compile(), p);
    const std::size_t n = a.tape()->outputs().size();
    ASSERT_EQ(n, b.tape()->outputs().size());
    std::vector<double> va(n), vb(n);
    for (int k = 0; k < 30; ++k)
    {
      const std::array<double, 4> pt{ u(rng), u(rng), u(rng), u(rng) };
      a.evalAll(pt, va.data());
      b.evalAll(pt, vb.data());
      for (std::size_t i = 0; i < n; ++i)
      {
        ASSERT_TRUE(sameValue(va[i], vb[i])) << "iteration " << iteration << " output " << i << ": "
                                             << va[i] << " vs " << vb[i] << "\n"
                                             << text;
      }
    }
  }
}
