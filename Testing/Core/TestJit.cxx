// SPDX-License-Identifier: BSD-3-Clause
// The JIT backend (FRep/Jit.h) against the interpreter (BatchEvaluator<float>): bit-identical
// values (NaN compared as NaN) for every opcode, random trees, every bundled model and
// prospero.vm (when Fidget's models are present), with AVX-512 and AVX2 code; renders with the
// JIT equal to the interpreter's brute-force image.
#include "FRep/BundledModels.h"
#include "FRep/Jit.h"
#include "FRep/ModelRegistry.h"
#include "FRep/Render.h"
#include "Lang/VmReader.h"

#include "PortableRandom.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <limits>
#include <random>
#include <string>

using namespace ictk;
using namespace ictk::frep;

namespace
{
std::filesystem::path benchModels()
{
  if (const char* env = std::getenv("ICTK_BENCH_MODELS"))
  {
    return env;
  }
  return ICTK_BENCH_MODELS_DIR;
}

using Random = ictk::fixtures::PortableRandom;

const Opcode unaryOps[] = { Opcode::Neg, Opcode::Abs, Opcode::Sqrt, Opcode::Square, Opcode::Exp,
  Opcode::Log, Opcode::Sin, Opcode::Cos, Opcode::Tan, Opcode::Asin, Opcode::Acos, Opcode::Atan,
  Opcode::Sign, Opcode::Floor };
const Opcode binaryOps[] = { Opcode::Add, Opcode::Sub, Opcode::Mul, Opcode::Div, Opcode::Min,
  Opcode::Max, Opcode::Pow, Opcode::Atan2 };

// Every opcode, including the ones that make NaN.
Expr randomTree(Random& rng, int depth)
{
  if (depth == 0 || rng.index(5) == 0)
  {
    switch (rng.index(5))
    {
      case 0:
        return Expr::x();
      case 1:
        return Expr::y();
      case 2:
        return Expr::z();
      case 3:
        return Expr::t();
      default:
        return Expr(std::round(rng.uniform(-3, 3) * 8) / 8);
    }
  }
  const Expr a = randomTree(rng, depth - 1);
  const Expr b = randomTree(rng, depth - 1);
  const Expr c = randomTree(rng, depth - 1);
  switch (rng.index(4))
  {
    case 0:
      return Expr::make(unaryOps[rng.index(14)], a);
    case 1:
      return select(a, b, c);
    default:
      return Expr::make(binaryOps[rng.index(8)], a, b);
  }
}

bool same(float a, float b)
{
  return std::memcmp(&a, &b, sizeof a) == 0 || (std::isnan(a) && std::isnan(b));
}

// Counts the values that differ; reports the first.
std::int64_t countDifferent(
  const std::vector<float>& expected, const std::vector<float>& actual, const std::string& what)
{
  std::int64_t differ = 0;
  for (std::size_t i = 0; i < expected.size(); ++i)
  {
    if (!same(expected[i], actual[i]))
    {
      if (differ == 0)
      {
        ADD_FAILURE() << what << ": value " << i << " is " << actual[i]
                      << ", the interpreter gives " << expected[i];
      }
      ++differ;
    }
  }
  return differ;
}

class JitTest : public ::testing::TestWithParam<bool>
{
protected:
  void SetUp() override
  {
    if (!JitEvaluator::available())
    {
      GTEST_SKIP() << "this CPU cannot run the JIT's code (no AVX2)";
    }
    options.allowAvx512 = GetParam();
  }
  JitOptions options;

  // eval() at the given points and evalRowX along rows of several lengths and offsets (tails
  // shorter than a vector included): JIT and interpreter bit for bit.
  void expectSame(const TapePtr& tape, const std::vector<std::array<float, 4>>& points,
    const std::array<double, 3>& lo, const std::array<double, 3>& hi, const std::string& what,
    const std::vector<double>& parameters = {})
  {
    BatchEvaluator<float> reference(tape, parameters);
    JitEvaluator jit(tape, parameters, options);
    if (!options.allowAvx512)
    {
      EXPECT_EQ(jit.vectorWidth(), 8);
    }
    std::vector<float> coords[4];
    for (const auto& p : points)
    {
      for (int a = 0; a < 4; ++a)
      {
        coords[a].push_back(p[a]);
      }
    }
    const std::size_t n = points.size();
    std::vector<float> expected(n), actual(n, -7.0f);
    reference.eval(
      coords[0].data(), coords[1].data(), coords[2].data(), coords[3].data(), expected.data(), n);
    jit.eval(
      coords[0].data(), coords[1].data(), coords[2].data(), coords[3].data(), actual.data(), n);
    EXPECT_EQ(countDifferent(expected, actual, what + " eval"), 0);

    const std::size_t lengths[] = { 1, 7, 16, 33, 100, 256, 300 };
    for (std::size_t length : lengths)
    {
      const double dx = (hi[0] - lo[0]) / static_cast<double>(length);
      for (int row = 0; row < 5; ++row)
      {
        const double y = lo[1] + (hi[1] - lo[1]) * (row + 0.5) / 5;
        const double z = lo[2] + (hi[2] - lo[2]) * (row + 0.25) / 5;
        const std::int64_t first = row - 2;
        std::vector<float> e(length), g(length, -7.0f);
        reference.evalRowX(lo[0], dx, first, y, z, 0.25 * row, e.data(), length);
        jit.evalRowX(lo[0], dx, first, y, z, 0.25 * row, g.data(), length);
        EXPECT_EQ(countDifferent(e, g, what + " evalRowX, length " + std::to_string(length)), 0);
      }
    }
  }
};

std::vector<std::array<float, 4>> randomPoints(
  Random& rng, std::size_t n, const std::array<double, 3>& lo, const std::array<double, 3>& hi)
{
  std::vector<std::array<float, 4>> points(n);
  for (auto& p : points)
  {
    for (int a = 0; a < 3; ++a)
    {
      p[a] = static_cast<float>(rng.uniform(lo[a], hi[a]));
    }
    p[3] = static_cast<float>(rng.uniform(-1, 1));
  }
  return points;
}

// Special values for the opcode tests: zeros of both signs, infinities, NaN, +-1, large, tiny.
std::vector<float> specials()
{
  const float inf = std::numeric_limits<float>::infinity();
  return { 0.0f, -0.0f, 1.0f, -1.0f, 0.5f, -0.5f, 2.0f, -3.75f, inf, -inf,
    std::numeric_limits<float>::quiet_NaN(), 1e-40f, -1e-40f, 3e38f, -3e38f, 0.9999f, 1.5f, -2.5f,
    7.25f, 100.0f };
}
} // namespace

TEST_P(JitTest, EveryOpcodeMatchesTheInterpreterBitForBit)
{
  // Every pair of special values, with the operands varying, uniform along the row (y, read as a
  // scalar operand by the row program), constant, and swapped.
  std::vector<std::array<float, 4>> points;
  for (float a : specials())
  {
    for (float b : specials())
    {
      points.push_back({ a, b, a - b, 0.5f });
    }
  }
  const Expr x = Expr::x(), y = Expr::y(), z = Expr::z();
  const std::array<double, 3> lo{ -4, -4, -4 }, hi{ 4, 4, 4 };
  for (Opcode op : unaryOps)
  {
    const std::string name = "opcode " + std::to_string(static_cast<int>(op));
    expectSame(Tape::compile(Expr::make(op, x)), points, lo, hi, name);
    expectSame(Tape::compile(Expr::make(op, x * y)), points, lo, hi, name + " of x*y");
    expectSame(Tape::compile(Expr::make(op, z) + x), points, lo, hi, name + " of z, + x");
  }
  for (Opcode op : binaryOps)
  {
    const std::string name = "opcode " + std::to_string(static_cast<int>(op));
    expectSame(Tape::compile(Expr::make(op, x, y)), points, lo, hi, name + "(x, y)");
    expectSame(Tape::compile(Expr::make(op, y, x)), points, lo, hi, name + "(y, x)");
    expectSame(Tape::compile(Expr::make(op, x, x * z)), points, lo, hi, name + "(x, x z)");
    expectSame(Tape::compile(Expr::make(op, Expr(0.75), x)), points, lo, hi, name + "(c, x)");
    expectSame(Tape::compile(Expr::make(op, x, Expr(-1.25))), points, lo, hi, name + "(x, c)");
    expectSame(Tape::compile(Expr::make(op, x + z, sin(y))), points, lo, hi, name + "(x+z, sin y)");
  }
  expectSame(Tape::compile(select(x, y, z)), points, lo, hi, "select(x, y, z)");
  expectSame(Tape::compile(select(y, x, z)), points, lo, hi, "select(y, x, z)");
  expectSame(Tape::compile(select(x - z, Expr(2.0), y * x)), points, lo, hi, "select(x-z, 2, yx)");
  expectSame(Tape::compile(select(z, x, Expr(-1.0))), points, lo, hi, "select(z, x, -1)");
  // The Cauchy segment's kernel, with its length uniform along the row (y), constant or varying.
  const Expr u = Expr::make(Opcode::CauchySegment, x, square(z), y);
  expectSame(Tape::compile(u), points, lo, hi, "cauchySegment(x, z^2, y)");
  expectSame(Tape::compile(Expr::make(Opcode::CauchySegment, x, square(x - z), Expr(1.5))), points,
    lo, hi, "cauchySegment(x, (x-z)^2, 1.5)");
  expectSame(Tape::compile(Expr::make(Opcode::CauchySegment, y, square(x), x + z)), points, lo, hi,
    "cauchySegment(y, x^2, x+z)");
}

TEST_P(JitTest, RandomTreesMatchTheInterpreterBitForBit)
{
  Random rng(7);
  const std::array<double, 3> lo{ -3, -3, -3 }, hi{ 3, 3, 3 };
  for (int n = 0; n < 200; ++n)
  {
    const TapePtr tape = Tape::compile(randomTree(rng, 7));
    expectSame(tape, randomPoints(rng, 203, lo, hi), lo, hi, "tree " + std::to_string(n));
  }
}

TEST_P(JitTest, LargeTreesSpillRegisters)
{
  // Hundreds of values live at once: more than the registers, so values are spilled and reloaded.
  Random rng(11);
  std::vector<Expr> terms;
  for (int i = 0; i < 300; ++i)
  {
    terms.push_back(square(Expr::x() - rng.uniform(-1, 1)) + Expr::y() * rng.uniform(-1, 1));
  }
  Expr sum = terms[0];
  for (std::size_t i = 1; i < terms.size(); ++i)
  {
    sum = max(sum, terms[i]) - terms[terms.size() - i] * terms[(i * 7) % terms.size()];
  }
  const std::array<double, 3> lo{ -2, -2, -2 }, hi{ 2, 2, 2 };
  expectSame(Tape::compile(sum), randomPoints(rng, 1000, lo, hi), lo, hi, "large tree");
}

TEST_P(JitTest, ParametersAndSeveralOutputs)
{
  const Expr x = Expr::x(), y = Expr::y();
  const Expr p0 = Expr::parameter(0), p1 = Expr::parameter(1);
  const TapePtr tape = Tape::compile(std::vector<Expr>{ x * p0 - y, sqrt(x * x + p1), y * p1 });
  const std::vector<double> parameters{ 1.5, -0.25 };
  BatchEvaluator<float> reference(tape, parameters);
  JitEvaluator jit(tape, parameters, options);
  for (std::size_t n : { 5, 64, 70 })
  {
    std::vector<float> e[3], g[3];
    float* eo[3];
    float* go[3];
    for (int k = 0; k < 3; ++k)
    {
      e[k].assign(n, 0);
      g[k].assign(n, -7);
      eo[k] = e[k].data();
      go[k] = g[k].data();
    }
    reference.evalRowX(-1.0, 0.03, 3, 0.5, 0, 0, eo, 3, n);
    jit.evalRowX(-1.0, 0.03, 3, 0.5, 0, 0, go, 3, n);
    for (int k = 0; k < 3; ++k)
    {
      EXPECT_EQ(countDifferent(e[k], g[k], "output " + std::to_string(k)), 0);
    }
  }
  jit.setParameters({ -2.0, 4.0 });
  reference.setParameters({ -2.0, 4.0 });
  std::vector<float> e(40), g(40);
  reference.evalRowX(-1.0, 0.05, 0, 0.5, 0, 0, e.data(), 40);
  jit.evalRowX(-1.0, 0.05, 0, 0.5, 0, 0, g.data(), 40);
  EXPECT_EQ(countDifferent(e, g, "after setParameters"), 0);
  // Rebound, the JIT gives what a new evaluator with these values gives.
  BatchEvaluator<float> fresh(tape, { -2.0, 4.0 });
  std::vector<float> f(40);
  fresh.evalRowX(-1.0, 0.05, 0, 0.5, 0, 0, f.data(), 40);
  EXPECT_EQ(countDifferent(f, g, "rebound against new"), 0);
  EXPECT_THROW(JitEvaluator(tape, { 1.0 }, options), std::invalid_argument);
  // The first output constant along the row, the second varying; only the first asked.
  JitEvaluator mixed(Tape::compile(std::vector<Expr>{ y * 2.0, x + y }), {}, options);
  std::vector<float> m(11, 0);
  mixed.evalRowX(0, 1, 0, 1.5, 0, 0, m.data(), 11);
  EXPECT_EQ(m, std::vector<float>(11, 3.0f));
  // A model without coordinates: every output constant.
  JitEvaluator constant(Tape::compile(Expr(2.5) * Expr(2.0)), {}, options);
  std::vector<float> c(9, 0);
  constant.evalRowX(0, 1, 0, 0, 0, 0, c.data(), 9);
  constant.eval(nullptr, nullptr, nullptr, nullptr, c.data(), 9);
  EXPECT_EQ(c, std::vector<float>(9, 5.0f));
}

TEST_P(JitTest, BundledModelsMatchTheInterpreterBitForBit)
{
  Random rng(3);
  int models = 0, withAttributes = 0;
  for (const ModelInfo& info : bundled::modelInfos())
  {
    const Hypervolume hv = info.build();
    std::array<double, 3> lo = info.boundsLo, hi = info.boundsHi;
    for (int a = 0; a < 3; ++a)
    {
      if (!(lo[a] < hi[a]))
      {
        lo[a] -= 1;
        hi[a] += 1;
      }
    }
    const TapePtr tape = Tape::compile(hv.geometry().function());
    expectSame(tape, randomPoints(rng, 4099, lo, hi), lo, hi, info.name);
    ++models;
    // Geometry and every attribute component and partition in one tape (several outputs).
    std::vector<Expr> outputs{ hv.geometry().function() };
    for (const Attribute& attribute : hv.attributes())
    {
      outputs.insert(outputs.end(), attribute.components.begin(), attribute.components.end());
      outputs.push_back(attribute.partition);
    }
    if (outputs.size() == 1)
    {
      continue;
    }
    const TapePtr all = Tape::compile(outputs);
    BatchEvaluator<float> reference(all);
    JitEvaluator jit(all, {}, options);
    const std::size_t n = 150;
    std::vector<std::vector<float>> e(outputs.size(), std::vector<float>(n));
    std::vector<std::vector<float>> g(outputs.size(), std::vector<float>(n, -7.0f));
    std::vector<float*> eo, go;
    for (std::size_t k = 0; k < outputs.size(); ++k)
    {
      eo.push_back(e[k].data());
      go.push_back(g[k].data());
    }
    for (int row = 0; row < 20; ++row)
    {
      const double y = lo[1] + (hi[1] - lo[1]) * (row + 0.5) / 20;
      const double dx = (hi[0] - lo[0]) / n;
      reference.evalRowX(lo[0], dx, 0, y, 0.5 * (lo[2] + hi[2]), 0, eo.data(), outputs.size(), n);
      jit.evalRowX(lo[0], dx, 0, y, 0.5 * (lo[2] + hi[2]), 0, go.data(), outputs.size(), n);
      for (std::size_t k = 0; k < outputs.size(); ++k)
      {
        EXPECT_EQ(countDifferent(e[k], g[k], info.name + " output " + std::to_string(k)), 0);
      }
    }
    ++withAttributes;
  }
  EXPECT_GE(models, 8);
  EXPECT_GE(withAttributes, 1);
}

TEST_P(JitTest, ProsperoMatchesTheInterpreterBitForBit)
{
  const std::filesystem::path file = benchModels() / "prospero.vm";
  if (!std::filesystem::exists(file))
  {
    GTEST_SKIP() << file << " is absent (set ICTK_BENCH_MODELS to Fidget's models folder)";
  }
  const TapePtr tape = Tape::compile(lang::readVmFile(file.string()).function);
  Random rng(5);
  const std::array<double, 3> lo{ -1, -1, 0 }, hi{ 1, 1, 0 };
  expectSame(tape, randomPoints(rng, 2000, lo, hi), lo, hi, "prospero");
  // A 256^2 image's rows, as the renderer asks for them.
  BatchEvaluator<float> reference(tape);
  JitEvaluator jit(tape, {}, options);
  std::int64_t differ = 0;
  std::vector<float> e(256), g(256);
  for (int j = 0; j < 256; ++j)
  {
    const double y = -1 + (j + 0.5) * 2.0 / 256;
    reference.evalRowX(-1 + 1.0 / 256, 2.0 / 256, 0, y, 0, 0, e.data(), 256);
    jit.evalRowX(-1 + 1.0 / 256, 2.0 / 256, 0, y, 0, 0, g.data(), 256);
    differ += countDifferent(e, g, "prospero row " + std::to_string(j));
  }
  EXPECT_EQ(differ, 0);
}

TEST_P(JitTest, RendersWithTheJitEqualBruteForce)
{
  std::vector<std::pair<std::string, TapePtr>> models;
  for (const char* name : { "disk2d", "csg3", "random1000", "blend100" })
  {
    models.emplace_back(name, Tape::compile(findModel(name).build().geometry().function()));
  }
  const std::filesystem::path file = benchModels() / "prospero.vm";
  if (std::filesystem::exists(file))
  {
    models.emplace_back("prospero", Tape::compile(lang::readVmFile(file.string()).function));
  }
  std::int64_t evaluated = 0;
  for (const auto& [name, tape] : models)
  {
    RenderOptions brute;
    brute.prune = false;
    brute.threads = 1;
    const std::vector<std::uint8_t> reference = renderSign2D(tape, RenderRegion{}, 300, 257, brute);
    RenderOptions jitBrute = brute;
    jitBrute.rowEvaluator = jitRowEvaluatorFactory(options);
    ASSERT_TRUE(jitBrute.rowEvaluator);
    RenderOptions jitPruned = jitBrute;
    jitPruned.prune = true;
    jitPruned.threads = 2;
    RenderStats stats;
    jitPruned.stats = &stats;
    EXPECT_EQ(renderSign2D(tape, RenderRegion{}, 300, 257, jitBrute), reference) << name;
    EXPECT_EQ(renderSign2D(tape, RenderRegion{}, 300, 257, jitPruned), reference) << name;
    evaluated += stats.pixelsEvaluated;
  }
  EXPECT_GT(evaluated, 0);
  // 3D as well.
  const TapePtr csg3 = Tape::compile(findModel("csg3").build().geometry().function());
  RenderRegion box;
  box.lo = { -1.1, -1.1, -1.1 };
  box.hi = { 1.1, 1.1, 1.1 };
  RenderOptions brute;
  brute.prune = false;
  RenderOptions jit = brute;
  jit.rowEvaluator = jitRowEvaluatorFactory(options);
  jit.prune = true;
  EXPECT_EQ(
    renderSign3D(csg3, box, { 40, 37, 33 }, jit), renderSign3D(csg3, box, { 40, 37, 33 }, brute));
}

INSTANTIATE_TEST_SUITE_P(Jit, JitTest, ::testing::Values(true, false),
  [](const ::testing::TestParamInfo<bool>& info) { return info.param ? "Avx512" : "Avx2"; });
