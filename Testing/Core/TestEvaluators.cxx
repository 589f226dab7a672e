// SPDX-License-Identifier: BSD-3-Clause
// Agreement of the four evaluators over random expression trees, tape simplification, sampling.
#include "FRep/Bounds.h"
#include "FRep/Evaluators.h"
#include "FRep/Hypervolume.h"
#include "FRep/Sampling.h"
#include "FRep/SinCos.h"

#include "PortableRandom.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>
#include <limits>

#include <cmath>
#include <cstring>
#include <functional>
#include <random>

using namespace ictk::frep;

namespace
{
using Random = ictk::fixtures::PortableRandom;

// Sample s of a region: its low corner, its high corner, then random points inside.
template <typename Region>
std::array<double, 4> sampleOf(const Region& region, int s, Random& rng)
{
  std::array<double, 4> p;
  for (int a = 0; a < 4; ++a)
  {
    p[a] = s == 0
      ? region.axes[a].lo
      : (s == 1 ? region.axes[a].hi : rng.uniform(region.axes[a].lo, region.axes[a].hi));
  }
  return p;
}

// Random trees. `smooth` restricts to everywhere-differentiable operations (for finite
// differences); otherwise every opcode appears, including the ones that make NaN.
Expr randomTree(Random& rng, int depth, bool smooth)
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
  const Expr a = randomTree(rng, depth - 1, smooth);
  const Expr b = randomTree(rng, depth - 1, smooth);
  if (smooth)
  {
    switch (rng.index(8))
    {
      case 0:
        return a + b;
      case 1:
        return a - b;
      case 2:
        return a * b;
      case 3:
        return sin(a);
      case 4:
        return cos(b);
      case 5:
        return atan(a);
      case 6:
        return sqrt(1.0 + square(a));
      default:
        return exp(sin(a)) * b;
    }
  }
  const Expr c = randomTree(rng, depth - 1, smooth);
  static const Opcode unary[] = { Opcode::Neg, Opcode::Abs, Opcode::Sqrt, Opcode::Square,
    Opcode::Exp, Opcode::Log, Opcode::Sin, Opcode::Cos, Opcode::Tan, Opcode::Asin, Opcode::Acos,
    Opcode::Atan, Opcode::Sign, Opcode::Floor };
  static const Opcode binary[] = { Opcode::Add, Opcode::Sub, Opcode::Mul, Opcode::Div, Opcode::Min,
    Opcode::Max, Opcode::Pow, Opcode::Atan2 };
  switch (rng.index(4))
  {
    case 0:
      return Expr::make(unary[rng.index(14)], a);
    case 1:
      return select(a, b, c);
    default:
      return Expr::make(binary[rng.index(8)], a, b);
  }
}

bool sameDouble(double a, double b)
{
  return std::memcmp(&a, &b, sizeof a) == 0 || (std::isnan(a) && std::isnan(b));
}

constexpr int TreeCount = 300;
} // namespace

TEST(Evaluators, PointAndBatchMatchTheReferenceBitForBit)
{
  Random rng(1);
  for (int n = 0; n < TreeCount; ++n)
  {
    const Expr e = randomTree(rng, 6, false);
    const TapePtr tape = Tape::compile(e);
    PointEvaluator point(tape);
    BatchEvaluator<double> batch(tape);
    std::vector<double> xs(300), ys(300), zs(300), ts(300), out(300);
    for (std::size_t i = 0; i < xs.size(); ++i)
    {
      xs[i] = rng.uniform(-4, 4);
      ys[i] = rng.uniform(-4, 4);
      zs[i] = rng.uniform(-4, 4);
      ts[i] = rng.uniform(-4, 4);
    }
    batch.eval(xs.data(), ys.data(), zs.data(), ts.data(), out.data(), xs.size());
    for (std::size_t i = 0; i < xs.size(); ++i)
    {
      const double ref = evaluateReference(e, { xs[i], ys[i], zs[i], ts[i] });
      const double p = point.eval(xs[i], ys[i], zs[i], ts[i]);
      ASSERT_TRUE(sameDouble(ref, p)) << toString(e) << " ref " << ref << " point " << p;
      ASSERT_TRUE(sameDouble(p, out[i])) << toString(e) << " point " << p << " batch " << out[i];
    }
  }
}

TEST(Evaluators, RowEvaluationMatchesPointEvaluation)
{
  Random rng(2);
  for (int n = 0; n < TreeCount; ++n)
  {
    const Expr e = randomTree(rng, 6, false);
    const TapePtr tape = Tape::compile(e);
    PointEvaluator point(tape);
    BatchEvaluator<double> batch(tape);
    BatchEvaluator<float> batchF(tape);
    const double x0 = rng.uniform(-3, 0), dx = 0.013, y = rng.uniform(-3, 3),
                 z = rng.uniform(-3, 3), t = rng.uniform(-3, 3);
    std::vector<double> row(600);
    std::vector<float> rowF(600);
    batch.evalRowX(x0, dx, 0, y, z, t, row.data(), row.size());
    batchF.evalRowX(x0, dx, 0, y, z, t, rowF.data(), rowF.size());
    std::vector<float> xs(600), ys(600, float(y)), zs(600, float(z)), ts(600, float(t)), outF(600);
    for (std::size_t i = 0; i < row.size(); ++i)
    {
      xs[i] = static_cast<float>(x0 + static_cast<double>(i) * dx);
    }
    batchF.eval(xs.data(), ys.data(), zs.data(), ts.data(), outF.data(), xs.size());
    for (std::size_t i = 0; i < row.size(); ++i)
    {
      const double p = point.eval(x0 + static_cast<double>(i) * dx, y, z, t);
      ASSERT_TRUE(sameDouble(p, row[i])) << toString(e) << " at i=" << i;
      // Float rows and float batches run the same float arithmetic.
      ASSERT_TRUE(std::memcmp(&rowF[i], &outF[i], sizeof(float)) == 0 ||
        (std::isnan(rowF[i]) && std::isnan(outF[i])))
        << toString(e) << " row " << rowF[i] << " batch " << outF[i];
    }
  }
}

TEST(Evaluators, FloatBatchIsCloseToDouble)
{
  Random rng(3);
  for (int n = 0; n < TreeCount; ++n)
  {
    const Expr e = randomTree(rng, 4, true);
    const TapePtr tape = Tape::compile(e);
    PointEvaluator point(tape);
    BatchEvaluator<float> batch(tape);
    std::vector<float> xs(64), ys(64), zs(64), ts(64), out(64);
    for (std::size_t i = 0; i < xs.size(); ++i)
    {
      xs[i] = static_cast<float>(rng.uniform(-2, 2));
      ys[i] = static_cast<float>(rng.uniform(-2, 2));
      zs[i] = static_cast<float>(rng.uniform(-2, 2));
      ts[i] = static_cast<float>(rng.uniform(-2, 2));
    }
    batch.eval(xs.data(), ys.data(), zs.data(), ts.data(), out.data(), xs.size());
    for (std::size_t i = 0; i < xs.size(); ++i)
    {
      const double p = point.eval(xs[i], ys[i], zs[i], ts[i]);
      if (std::isfinite(p) && std::fabs(p) < 1e6)
      {
        EXPECT_NEAR(out[i], p, 1e-3 * (1 + std::fabs(p))) << toString(e);
      }
    }
  }
}

TEST(Evaluators, GradientMatchesFiniteDifferences)
{
  Random rng(4);
  for (int n = 0; n < TreeCount; ++n)
  {
    const Expr e = randomTree(rng, 5, true);
    const TapePtr tape = Tape::compile(e);
    PointEvaluator point(tape);
    GradientEvaluator grad(tape);
    for (int s = 0; s < 10; ++s)
    {
      std::array<double, 4> p{ rng.uniform(-2, 2), rng.uniform(-2, 2), rng.uniform(-2, 2),
        rng.uniform(-2, 2) };
      const ValueGradient g = grad.eval(p[0], p[1], p[2], p[3]);
      ASSERT_TRUE(sameDouble(g.value, point.eval(p[0], p[1], p[2], p[3])));
      for (int a = 0; a < 4; ++a)
      {
        const double h = 1e-5;
        auto q = p, r = p;
        q[a] += h;
        r[a] -= h;
        const double fd =
          (point.eval(q[0], q[1], q[2], q[3]) - point.eval(r[0], r[1], r[2], r[3])) / (2 * h);
        if (std::isfinite(fd) && std::fabs(fd) < 1e4)
        {
          EXPECT_NEAR(g.gradient[a], fd, 1e-4 * (1 + std::fabs(fd)))
            << toString(e) << " axis " << a;
        }
      }
    }
  }
}

TEST(Evaluators, GradientOfSphereGivesOutwardNormal)
{
  // f = 1 - x^2 - y^2 - z^2: grad f = (-2x, -2y, -2z); n = -grad/|grad| points outward.
  const Expr f = Expr(1.0) - square(Expr::x()) - square(Expr::y()) - square(Expr::z());
  GradientEvaluator grad(Tape::compile(f));
  const ValueGradient g = grad.eval(0.6, 0.0, 0.8);
  EXPECT_NEAR(g.value, 0.0, 1e-15); // 1 - 0.36 - 0.64 rounds to -1.1e-16
  EXPECT_DOUBLE_EQ(g.gradient[0], -1.2);
  EXPECT_DOUBLE_EQ(g.gradient[2], -1.6);
  const auto n = outwardNormal(g);
  EXPECT_NEAR(n[0], 0.6, 1e-15);
  EXPECT_NEAR(n[1], 0.0, 1e-15);
  EXPECT_NEAR(n[2], 0.8, 1e-15);
}

// Every interval evaluator, as one function from a tape and a region to the enclosure and the
// choices it made, so that each runs the same tests against the point evaluator.
struct IntervalEvaluatorUnderTest
{
  const char* name;
  std::function<std::function<Interval(const Region&, std::vector<Choice>&)>(TapePtr)> make;
};

// An interval evaluator of type E made for a tape, as IntervalEvaluatorUnderTest::make.
template <typename E>
std::function<Interval(const Region&, std::vector<Choice>&)> underTest(TapePtr tape)
{
  auto e = std::make_shared<E>(tape);
  return [e](const Region& r, std::vector<Choice>& choices)
  {
    const Interval v = e->eval(r);
    choices = e->choices();
    return v;
  };
}

std::vector<IntervalEvaluatorUnderTest> intervalEvaluators()
{
  return {
    { "IntervalEvaluator", underTest<IntervalEvaluator> },
    { "IncrementalIntervalEvaluator", underTest<IncrementalIntervalEvaluator> },
  };
}

// Random trees (every opcode) over random regions, small and large, that differ from the last
// in a random subset of the axes (as the pieces of a ray do): every point sampled in a region
// (its corners included) has a value, when finite, inside the evaluator's enclosure, and the
// tape simplified by its choices gives the same value there bit for bit. Trees of sin and cos
// over wide coordinates exercise their enclosures near extrema and far from the origin.
TEST(Evaluators, EveryIntervalEvaluatorEnclosesPointValues)
{
  for (const IntervalEvaluatorUnderTest& under : intervalEvaluators())
  {
    Random rng(23);
    std::size_t samples = 0;
    for (int n = 0; n < TreeCount; ++n)
    {
      const bool trig = n % 3 == 0;
      Expr e = randomTree(rng, 5, trig);
      if (trig)
      {
        e = sin(e * rng.uniform(-40, 40)) * cos(Expr::x() * rng.uniform(-4000, 4000)) + e;
      }
      const TapePtr tape = Tape::compile(e);
      auto eval = under.make(tape);
      PointEvaluator point(tape);
      Region region;
      std::vector<Choice> choices;
      for (int r = 0; r < 12; ++r)
      {
        const int mask = r == 0 ? 15 : 1 + rng.index(15);
        for (int a = 0; a < 4; ++a)
        {
          if (mask & (1 << a))
          {
            const double c = rng.uniform(-3, 3), w = rng.uniform(0, r % 3 == 0 ? 2.0 : 0.05);
            region.axes[a] = { c - w, c + w };
          }
        }
        const Interval range = eval(region, choices);
        PointEvaluator pruned(tape->simplify(choices));
        for (int s = 0; s < 40; ++s)
        {
          const std::array<double, 4> p = sampleOf(region, s, rng);
          const double v = point.eval(p[0], p[1], p[2], p[3]);
          if (std::isfinite(v))
          {
            ASSERT_LE(range.lo, v) << under.name << ": " << toString(e);
            ASSERT_GE(range.hi, v) << under.name << ": " << toString(e);
          }
          else if (std::isnan(v))
          {
            ASSERT_TRUE(range.maybeNaN) << under.name << ": " << toString(e);
          }
          ASSERT_TRUE(sameDouble(v, pruned.eval(p[0], p[1], p[2], p[3])))
            << under.name << ": " << toString(e);
          ++samples;
        }
      }
    }
    EXPECT_EQ(samples, std::size_t(TreeCount) * 12 * 40) << under.name;
  }
}

// The fast paths of the interval operations (plain operands: finite, ordered, no NaN) give what
// the general code gives, bounds, NaN flag and choice bit for bit, for every opcode over operands
// of every kind: plain, touching or straddling zero (of either sign), empty, possibly NaN,
// infinite.
TEST(Evaluators, FastIntervalOperationsMatchTheReferenceBitForBit)
{
  Random rng(31);
  constexpr double inf = std::numeric_limits<double>::infinity();
  auto operand = [&]() -> Interval
  {
    switch (rng.index(10))
    {
      case 0:
        return { 0.0, rng.uniform(0, 3), false };
      case 1:
        return { -rng.uniform(0, 3), -0.0, false };
      case 2:
        return { inf, -inf, true }; // NaN everywhere
      case 3:
        return { -rng.uniform(0, 3), rng.uniform(0, 3), true };
      case 4:
        return { -inf, rng.uniform(-3, 3), false };
      case 5:
      {
        const double v = std::round(rng.uniform(-4, 4));
        return { v, v, false };
      }
      case 6:
      {
        const double c = rng.uniform(-1e6, 1e6), w = rng.uniform(0, 10);
        return { c - w, c + w, false };
      }
      default:
      {
        const double c = rng.uniform(-8, 8), w = rng.uniform(0, rng.index(2) ? 0.01 : 4.0);
        return { c - w, c + w, false };
      }
    }
  };
  int plainCases = 0;
  for (int n = 0; n < 200000; ++n)
  {
    const auto op = static_cast<Opcode>(
      static_cast<int>(Opcode::Neg) + rng.index(static_cast<int>(Opcode::Count_) - 3));
    const Interval a = operand(), b = operand(), c = operand();
    Choice fast = Choice::Both, reference = Choice::Both;
    const Interval x = detail::intervalOperation(op, a, b, c, fast);
    const Interval y = detail::intervalOperationReference(op, a, b, c, reference);
    ASSERT_TRUE(sameDouble(x.lo, y.lo) && sameDouble(x.hi, y.hi) && x.maybeNaN == y.maybeNaN &&
      fast == reference)
      << opcodeName(op) << " [" << a.lo << ", " << a.hi << ", " << a.maybeNaN << "] [" << b.lo
      << ", " << b.hi << ", " << b.maybeNaN << "]: " << x.lo << " " << x.hi << " vs " << y.lo << " "
      << y.hi;
    plainCases += !a.maybeNaN && std::isfinite(a.lo) && std::isfinite(a.hi) ? 1 : 0;
  }
  EXPECT_GT(plainCases, 100000);
}

// SinCos.h's bound, against long double: random arguments over its whole range, arguments next to
// multiples of pi/4 (where the reduction cancels most and the quadrant changes), and small ones.
// The error stays below SinCosError, and libm's value (the point evaluators') within
// SinCosWidening.
TEST(Evaluators, SinCosWithoutLibmKeepsItsErrorBound)
{
  Random rng(41);
  long double worst = 0;
  auto check = [&](double x)
  {
    const long double s = std::sin(static_cast<long double>(x));
    const long double c = std::cos(static_cast<long double>(x));
    const double as = detail::sinApprox(x), ac = detail::cosApprox(x);
    worst = std::max({ worst, std::fabs(as - s), std::fabs(ac - c) });
    ASSERT_LE(std::fabs(as - s), detail::SinCosError) << x;
    ASSERT_LE(std::fabs(ac - c), detail::SinCosError) << x;
    ASSERT_LE(std::fabs(as - std::sin(x)), detail::SinCosWidening) << x;
    ASSERT_LE(std::fabs(ac - std::cos(x)), detail::SinCosWidening) << x;
  };
  for (int n = 0; n < 1000000; ++n)
  {
    const double magnitude = std::ldexp(1.0, rng.index(21)); // 1 .. 2^20
    check(rng.uniform(-magnitude, magnitude));
    const double k = std::round(rng.uniform(-magnitude, magnitude) * 4 / 3.14159265358979);
    const double near = k * (3.14159265358979323846 / 4);
    if (std::abs(near) <= detail::SinCosLimit)
    {
      check(near);
      check(std::nextafter(near, 0.0));
      check(near + rng.uniform(-1e-9, 1e-9));
    }
    check(rng.uniform(-1e-6, 1e-6));
  }
  check(0.0);
  check(-0.0);
  check(detail::SinCosLimit);
  check(-detail::SinCosLimit);
  // The bound is not loose by orders of magnitude: the worst case seen is within 8x of it.
  EXPECT_GT(worst, detail::SinCosError / 8) << static_cast<double>(worst);
  std::cout << "largest error of sinApprox/cosApprox seen: " << static_cast<double>(worst) << "\n";
}

TEST(Evaluators, IntervalsEnclosePointSamplesAndPruningKeepsValues)
{
  Random rng(5);
  std::size_t cut = 0, total = 0;
  for (int n = 0; n < TreeCount; ++n)
  {
    const Expr e = randomTree(rng, 6, false);
    const TapePtr tape = Tape::compile(e);
    IntervalEvaluator interval(tape);
    PointEvaluator point(tape);
    for (int r = 0; r < 8; ++r)
    {
      Region region;
      for (auto& axis : region.axes)
      {
        const double c = rng.uniform(-3, 3), w = rng.uniform(0, r < 4 ? 0.1 : 2.0);
        axis = { c - w, c + w };
      }
      const Interval range = interval.eval(region);
      const TapePtr pruned = interval.simplified();
      total += tape->instructions().size();
      cut += tape->instructions().size() - pruned->instructions().size();
      PointEvaluator prunedPoint(pruned);
      for (int s = 0; s < 50; ++s)
      {
        const std::array<double, 4> p = sampleOf(region, s, rng);
        const double v = point.eval(p[0], p[1], p[2], p[3]);
        if (std::isfinite(v))
        {
          ASSERT_LE(range.lo, v) << toString(e);
          ASSERT_GE(range.hi, v) << toString(e);
        }
        ASSERT_TRUE(sameDouble(v, prunedPoint.eval(p[0], p[1], p[2], p[3]))) << toString(e);
      }
    }
  }
  // The property is only meaningful if pruning happens: random min/max/select trees lose
  // instructions in small regions.
  EXPECT_GT(cut, total / 50) << "cut " << cut << " of " << total;
}

TEST(Evaluators, IncrementalEvaluationMatchesFullEvaluationBitForBit)
{
  // Sequences of regions and points where each step changes a random subset of the axes (often
  // one, sometimes none): the incremental evaluators reuse the instructions of the others and
  // must give what a full evaluation gives, bounds, NaN flags and choices alike.
  Random rng(11);
  int reused = 0;
  for (int n = 0; n < TreeCount; ++n)
  {
    const Expr e = randomTree(rng, 6, false) + Expr::parameter(0) * Expr::y();
    const TapePtr tape = Tape::compile(e);
    const std::vector<double> parameters{ rng.uniform(-2, 2) };
    IntervalEvaluator full(tape, parameters);
    IncrementalIntervalEvaluator incremental(tape, parameters);
    PointEvaluator point(tape, parameters);
    IncrementalPointEvaluator incrementalPoint(tape, parameters);
    Region region;
    std::array<double, 4> p{};
    for (int step = 0; step < 24; ++step)
    {
      const int mask = step == 0 ? 15 : rng.index(16);
      reused += mask != 15 ? 1 : 0;
      for (int a = 0; a < 4; ++a)
      {
        if (mask & (1 << a))
        {
          const double c = rng.uniform(-3, 3), w = rng.uniform(0, step % 2 ? 0.05 : 1.5);
          region.axes[a] = { c - w, c + w };
          p[a] = rng.index(8) == 0 ? -0.0 : c;
        }
      }
      const Interval a = full.eval(region), b = incremental.eval(region);
      ASSERT_TRUE(sameDouble(a.lo, b.lo) && sameDouble(a.hi, b.hi)) << toString(e);
      ASSERT_EQ(a.maybeNaN, b.maybeNaN) << toString(e);
      ASSERT_EQ(full.choices(), incremental.choices()) << toString(e);
      const double v = point.eval(p[0], p[1], p[2], p[3]);
      ASSERT_TRUE(sameDouble(v, incrementalPoint.eval(p[0], p[1], p[2], p[3]))) << toString(e);
    }
  }
  EXPECT_GT(reused, TreeCount * 20);
}

TEST(Evaluators, ReboundParametersGiveWhatTheirValuesCompiledAsConstantsGive)
{
  // A model whose numbers move (a skeleton's joints) compiles once with Expr::parameter leaves
  // and rebinds them per frame. Every evaluator, rebound from other values after use, must give
  // bit for bit what a new one gives; the double ones also what the tape with those values as
  // constants gives (constant folding runs the evaluators' own operations). Random trees with t
  // replaced by a mix of parameters and coordinates (with values never 0 or +-1, where folding
  // would apply an identity that the parameters' tape does not).
  Random rng(12);
  const Expr p0 = Expr::parameter(0), p1 = Expr::parameter(1), p2 = Expr::parameter(2);
  for (int n = 0; n < TreeCount; ++n)
  {
    const Expr tree = randomTree(rng, 6, false);
    const auto bound = [&](const Expr& a, const Expr& b, const Expr& c)
    {
      return tree.substitute(
        { Expr::x(), Expr::y(), Expr::z(), a * Expr::z() - b * Expr::x() + sin(c) });
    };
    const TapePtr tape = Tape::compile(bound(p0, p1, p2));
    const auto values = [&]
    {
      std::vector<double> q(3);
      for (double& v : q)
        v = (rng.index(2) ? 1 : -1) * rng.uniform(0.1, 0.9) * (rng.index(2) ? 1 : 3);
      return q;
    };
    const std::vector<double> before = values(), q = values();
    const TapePtr constants = Tape::compile(bound(Expr(q[0]), Expr(q[1]), Expr(q[2])));

    PointEvaluator point(tape, before), pointConstants(constants);
    IncrementalPointEvaluator incremental(tape, before);
    GradientEvaluator gradient(tape, before), gradientConstants(constants);
    BatchEvaluator<double> batch(tape, before), batchConstants(constants);
    BatchEvaluator<float> batchF(tape, before), batchFFresh(tape, q);
    IntervalEvaluator interval(tape, before), intervalFresh(tape, q);
    IncrementalIntervalEvaluator incrementalInterval(tape, before);
    std::vector<double> xs(40), ys(40), zs(40), out(40), outConstants(40);
    std::vector<float> xf(40), yf(40), zf(40), outF(40), outFFresh(40);
    for (std::size_t i = 0; i < xs.size(); ++i)
    {
      xs[i] = rng.uniform(-3, 3);
      ys[i] = rng.uniform(-3, 3);
      zs[i] = rng.uniform(-3, 3);
      xf[i] = static_cast<float>(xs[i]);
      yf[i] = static_cast<float>(ys[i]);
      zf[i] = static_cast<float>(zs[i]);
    }
    Region region;
    region.axes = { Interval{ -1, 0.5 }, Interval{ 0.25, 2 }, Interval{ -2, -1 },
      Interval{ 0, 0 } };
    // Used with the values before, so that stale values would show.
    point.eval(xs[0], ys[0], zs[0]);
    incremental.eval(xs[0], ys[0], zs[0]);
    gradient.eval(xs[0], ys[0], zs[0]);
    batch.eval(xs.data(), ys.data(), zs.data(), nullptr, out.data(), xs.size());
    batch.evalRowX(-1, 0.1, 0, 0.5, 0.5, 0, out.data(), out.size());
    batchF.eval(xf.data(), yf.data(), zf.data(), nullptr, outF.data(), xf.size());
    interval.eval(region);
    incrementalInterval.eval(region);
    point.setParameters(q);
    incremental.setParameters(q);
    gradient.setParameters(q);
    batch.setParameters(q);
    batchF.setParameters(q);
    interval.setParameters(q);
    incrementalInterval.setParameters(q);

    const std::string what = toString(bound(p0, p1, p2));
    for (std::size_t i = 0; i < xs.size(); ++i)
    {
      const double v = pointConstants.eval(xs[i], ys[i], zs[i]);
      ASSERT_TRUE(sameDouble(v, point.eval(xs[i], ys[i], zs[i]))) << what;
      ASSERT_TRUE(sameDouble(v, incremental.eval(xs[i], ys[i], zs[i]))) << what;
      const ValueGradient g = gradient.eval(xs[i], ys[i], zs[i]);
      const ValueGradient h = gradientConstants.eval(xs[i], ys[i], zs[i]);
      ASSERT_TRUE(sameDouble(g.value, h.value)) << what;
      for (int a = 0; a < 4; ++a)
        ASSERT_TRUE(sameDouble(g.gradient[a], h.gradient[a])) << what;
    }
    batch.eval(xs.data(), ys.data(), zs.data(), nullptr, out.data(), xs.size());
    batchConstants.eval(xs.data(), ys.data(), zs.data(), nullptr, outConstants.data(), xs.size());
    for (std::size_t i = 0; i < xs.size(); ++i)
      ASSERT_TRUE(sameDouble(out[i], outConstants[i])) << what;
    batch.evalRowX(-1, 0.1, 0, 0.5, 0.5, 0, out.data(), out.size());
    batchConstants.evalRowX(-1, 0.1, 0, 0.5, 0.5, 0, outConstants.data(), out.size());
    for (std::size_t i = 0; i < out.size(); ++i)
      ASSERT_TRUE(sameDouble(out[i], outConstants[i])) << what;
    batchF.eval(xf.data(), yf.data(), zf.data(), nullptr, outF.data(), xf.size());
    batchFFresh.eval(xf.data(), yf.data(), zf.data(), nullptr, outFFresh.data(), xf.size());
    for (std::size_t i = 0; i < outF.size(); ++i)
      ASSERT_TRUE(std::memcmp(&outF[i], &outFFresh[i], sizeof(float)) == 0 ||
        (std::isnan(outF[i]) && std::isnan(outFFresh[i])))
        << what;
    const Interval a = interval.eval(region), b = intervalFresh.eval(region),
                   c = incrementalInterval.eval(region);
    ASSERT_TRUE(sameDouble(a.lo, b.lo) && sameDouble(a.hi, b.hi) && a.maybeNaN == b.maybeNaN)
      << what;
    ASSERT_TRUE(sameDouble(c.lo, b.lo) && sameDouble(c.hi, b.hi) && c.maybeNaN == b.maybeNaN)
      << what;
    ASSERT_EQ(interval.choices(), intervalFresh.choices()) << what;
    ASSERT_EQ(incrementalInterval.choices(), intervalFresh.choices()) << what;
  }
}

TEST(Evaluators, PruningCutsTheLosingBranchOfAUnion)
{
  // max(sphere at -2, sphere at +2): near x = +2 only the second sphere matters.
  const Expr x = Expr::x(), y = Expr::y(), z = Expr::z();
  const Expr left = Expr(1.0) - square(x + 2.0) - square(y) - square(z);
  const Expr right = Expr(1.0) - square(x - 2.0) - square(y) - square(z);
  const TapePtr tape = Tape::compile(max(left, right));
  IntervalEvaluator interval(tape);
  Region region;
  region.axes = { Interval{ 1.5, 2.5 }, Interval{ -0.5, 0.5 }, Interval{ -0.5, 0.5 },
    Interval{ 0, 0 } };
  const Interval r = interval.eval(region);
  EXPECT_EQ(interval.choices().back(), Choice::Second);
  const TapePtr pruned = interval.simplified();
  EXPECT_LT(pruned->instructions().size(), tape->instructions().size());
  EXPECT_TRUE(r.contains(1.0));
  PointEvaluator p(pruned);
  EXPECT_DOUBLE_EQ(p.eval(2, 0, 0), 1.0);
}

TEST(Evaluators, AProductOfAValueWithItselfIsBoundedAsASquare)
{
  // 1 - (x x + y y + z z), a ball written with products: over [-1, 2] x [-0.5, 0.5] x [0, 0] the
  // sum of squares lies in [0, 4.25], so f in [-3.25, 1]. Bounded as products of independent
  // factors, x x would reach down to -2 and y y to -0.25, and f up to 3.25.
  const Expr x = Expr::x(), y = Expr::y(), z = Expr::z();
  const TapePtr tape = Tape::compile(Expr(1.0) - (x * x + y * y + z * z));
  IntervalEvaluator interval(tape);
  Region region;
  region.axes = { Interval{ -1, 2 }, Interval{ -0.5, 0.5 }, Interval{ 0, 0 }, Interval{ 0, 0 } };
  const Interval r = interval.eval(region);
  EXPECT_NEAR(r.lo, -3.25, 1e-12);
  EXPECT_NEAR(r.hi, 1.0, 1e-12);
  // The point values are the products', bit for bit.
  PointEvaluator p(tape);
  for (const double v : { -1.0, 0.3, 1.7, 1e-200, 3e150 })
    EXPECT_EQ(p.eval(v, 0, 0), 1.0 - (v * v + 0.0 * 0.0 + 0.0 * 0.0));
}

TEST(Evaluators, MultipleOutputsAndParameters)
{
  const Expr r = Expr::parameter(0);
  const TapePtr tape = Tape::compile({ square(r) - square(Expr::x()), Expr::x() * 2.0, Expr(5.0) });
  PointEvaluator p(tape, { 3.0 });
  std::array<double, 3> out;
  p.evalAll({ 1, 0, 0, 0 }, out.data());
  EXPECT_EQ(out[0], 8.0);
  EXPECT_EQ(out[1], 2.0);
  EXPECT_EQ(out[2], 5.0);
  p.setParameters({ 1.0 });
  EXPECT_EQ(p.eval(1, 0, 0), 0.0);
  EXPECT_THROW(PointEvaluator(tape, {}), std::invalid_argument);
}

TEST(Hypervolume, AttributeDefaultsFollowTheConsistentReadingOfL715)
{
  // Unit sphere with a density partition g = x (only the half x >= 0 has the function S = 10 + z).
  const Shape ball(
    Expr(1.0) - square(Expr::x()) - square(Expr::y()) - square(Expr::z()), Domain::XYZ, "ball");
  Hypervolume hv(ball);
  Attribute density;
  density.name = "density";
  density.components = { Expr(10.0) + Expr::z() };
  density.partition = Expr::x();
  density.insideDefault = { 1.0 };   // theta1
  density.outsideDefault = { -1.0 }; // theta0
  hv.addAttribute(density);
  HypervolumeEvaluator ev(hv);
  double f, a;
  ev.eval({ 0.5, 0, 0.25, 0 }, f, &a); // g >= 0: S
  EXPECT_DOUBLE_EQ(f, 0.6875);
  EXPECT_DOUBLE_EQ(a, 10.25);
  ev.eval({ 3.0, 0, 0.0, 0 }, f, &a); // g >= 0 outside the ball: still S (case 1 of L715)
  EXPECT_DOUBLE_EQ(a, 10.0);
  ev.eval({ -0.5, 0, 0, 0 }, f, &a); // inside, g < 0: theta1
  EXPECT_DOUBLE_EQ(a, 1.0);
  ev.eval({ -3.0, 0, 0, 0 }, f, &a); // outside, g < 0: theta0
  EXPECT_DOUBLE_EQ(a, -1.0);
  // Point membership, thesis eq. 2 (L673-L677).
  EXPECT_EQ(ev.membership({ 0, 0, 0, 0 }), 2);
  EXPECT_EQ(ev.membership({ 1, 0, 0, 0 }), 1);
  EXPECT_EQ(ev.membership({ 2, 0, 0, 0 }), 0);
  EXPECT_THROW(hv.addAttribute(density), std::invalid_argument);
  Attribute colour;
  colour.name = "colour";
  colour.components = { Expr(1.0), Expr(0.5), Expr::t() };
  EXPECT_THROW(hv.addAttribute(colour), std::invalid_argument); // t is outside XYZ
}

TEST(Sampling, GridValuesEqualPointEvaluationForAnyThreadCount)
{
  Random rng(6);
  const Expr e = max(randomTree(rng, 7, false),
    min(Expr(1.0) - square(Expr::x()) - square(Expr::y()), Expr(0.5) - square(Expr::z())));
  const TapePtr tape = Tape::compile(e);
  const Grid grid = gridOverBox({ -2, -2, -2 }, { 2, 2, 2 }, { 37, 29, 23 }, 0.25);
  std::vector<double> one(grid.pointCount()), two(grid.pointCount()), flat(grid.pointCount());
  SampleOptions options;
  options.threads = 1;
  options.brickSize = 8;
  sampleGrid(tape, grid, one.data(), options);
  options.threads = 2;
  sampleGrid(tape, grid, two.data(), options);
  options.prune = false;
  sampleGrid(tape, grid, flat.data(), options);
  PointEvaluator point(tape);
  for (std::int64_t k = 0; k < grid.dimensions[2]; ++k)
    for (std::int64_t j = 0; j < grid.dimensions[1]; ++j)
      for (std::int64_t i = 0; i < grid.dimensions[0]; ++i)
      {
        const std::size_t idx =
          static_cast<std::size_t>((k * grid.dimensions[1] + j) * grid.dimensions[0] + i);
        const double v = point.eval(grid.origin[0] + i * grid.spacing[0],
          grid.origin[1] + j * grid.spacing[1], grid.origin[2] + k * grid.spacing[2], 0.25);
        ASSERT_TRUE(sameDouble(v, one[idx])) << i << " " << j << " " << k;
        ASSERT_TRUE(sameDouble(one[idx], two[idx]));
        ASSERT_TRUE(sameDouble(one[idx], flat[idx]));
      }
}

TEST(Sampling, BadGridsAndCancellation)
{
  const TapePtr tape = Tape::compile(Expr(1.0) - square(Expr::x()));
  std::vector<float> out(8);
  Grid empty = gridOverBox({ 0, 0, 0 }, { 1, 1, 1 }, { 0, 2, 2 });
  EXPECT_THROW(sampleGrid(tape, empty, out.data()), std::invalid_argument);
  Grid nan = gridOverBox({ 0, 0, 0 }, { 1, 1, 1 }, { 2, 2, 2 });
  nan.spacing[1] = std::nan("");
  EXPECT_THROW(sampleGrid(tape, nan, out.data()), std::invalid_argument);
  // 100000^3 floats are 4 PB: refused before any allocation.
  const Grid huge = gridOverBox({ 0, 0, 0 }, { 1, 1, 1 }, { 100000, 100000, 100000 });
  try
  {
    checkGrid(huge, sizeof(float));
    FAIL();
  }
  catch (const std::invalid_argument& e)
  {
    EXPECT_NE(std::string(e.what()).find("GB"), std::string::npos) << e.what();
  }
  const Grid grid = gridOverBox({ -1, -1, -1 }, { 1, 1, 1 }, { 64, 64, 64 });
  std::vector<float> big(grid.pointCount());
  SampleOptions options;
  options.brickSize = 4;
  int calls = 0;
  options.progress = [&](double)
  {
    return ++calls < 3;
  };
  EXPECT_THROW(sampleGrid(tape, grid, big.data(), options), Cancelled);
  EXPECT_EQ(calls, 3);
}

TEST(Evaluators, RUnionAtTheZeroSetIsNotFlaggedNaN)
{
  // f1 + f2 + sqrt(f1^2 + f2^2) over a region containing f1 = f2 = 0: the sqrt argument is a sum of
  // squares, so no point can give NaN and pruning stays possible.
  const Expr f1 = Expr::x(), f2 = Expr::y();
  const TapePtr tape = Tape::compile(f1 + f2 + sqrt(square(f1) + square(f2)));
  IntervalEvaluator interval(tape);
  Region region;
  region.axes = { Interval{ -1, 1 }, Interval{ -1, 1 }, Interval{ 0, 0 }, Interval{ 0, 0 } };
  const Interval r = interval.eval(region);
  EXPECT_FALSE(r.maybeNaN);
  // True range over the square: from -2 + sqrt(2) at (-1, -1) to 2 + sqrt(2) at (1, 1).
  EXPECT_LE(r.lo, -2.0 + std::sqrt(2.0));
  EXPECT_GE(r.hi, 2.0 + std::sqrt(2.0));
}

TEST(Sampling, HypervolumeInOnePassMatchesPointEvaluation)
{
  // A ball with a density on the half x >= 0 and a colour everywhere in the ball.
  const Shape ball(
    Expr(1.0) - square(Expr::x()) - square(Expr::y()) - square(Expr::z()), Domain::XYZ, "ball");
  Hypervolume hv(ball);
  Attribute density;
  density.name = "density";
  density.components = { Expr(10.0) + Expr::z() };
  density.partition = Expr::x();
  density.insideDefault = { 1.0 };
  density.outsideDefault = { -1.0 };
  hv.addAttribute(density);
  Attribute colour;
  colour.name = "colour";
  colour.components = { Expr(1.0), abs(Expr::y()), max(Expr::x(), Expr::z()) };
  colour.partition = ball.function();
  colour.outsideDefault = { 0.0, 0.0, 0.5 };
  hv.addAttribute(colour);
  const Grid grid = gridOverBox({ -1.3, -1.3, -1.3 }, { 1.3, 1.3, 1.3 }, { 19, 17, 15 });
  const auto n = static_cast<std::size_t>(grid.pointCount());
  std::vector<double> f(n), d(n), c(3 * n);
  SampleOptions options;
  options.brickSize = 4;
  sampleGrid(hv, grid, f.data(), { d.data(), c.data() }, options);
  HypervolumeEvaluator ev(hv);
  std::size_t idx = 0;
  std::size_t defaults = 0;
  for (std::int64_t k = 0; k < grid.dimensions[2]; ++k)
    for (std::int64_t j = 0; j < grid.dimensions[1]; ++j)
      for (std::int64_t i = 0; i < grid.dimensions[0]; ++i, ++idx)
      {
        double value, attributes[4];
        ev.eval({ grid.origin[0] + i * grid.spacing[0], grid.origin[1] + j * grid.spacing[1],
                  grid.origin[2] + k * grid.spacing[2], 0 },
          value, attributes);
        ASSERT_EQ(f[idx], value);
        ASSERT_EQ(d[idx], attributes[0]);
        ASSERT_EQ(c[3 * idx + 0], attributes[1]);
        ASSERT_EQ(c[3 * idx + 1], attributes[2]);
        ASSERT_EQ(c[3 * idx + 2], attributes[3]);
        defaults += attributes[0] == 1.0 || attributes[0] == -1.0;
      }
  EXPECT_GT(defaults, n / 4); // both defaults are exercised (half the box has x < 0)
  EXPECT_THROW(sampleGrid(hv, grid, f.data(), { d.data() }), std::invalid_argument);
}

TEST(Bounds, IntervalBoundingBoxHoldsTheSolid)
{
  // A ball of radius 0.5 at (1, -2, 0.25): the box found in [-10, 10]^3 at depth 7 (cells of
  // 20/128 = 0.156) holds [0.5, 1.5] x [-2.5, -1.5] x [-0.25, 0.75] and exceeds it by at most
  // two cells per side.
  const Expr f =
    Expr(0.25) - square(Expr::x() - 1.0) - square(Expr::y() + 2.0) - square(Expr::z() - 0.25);
  const auto box = boundingBox(Tape::compile(f), { { -10, -10, -10 }, { 10, 10, 10 } }, 7);
  ASSERT_TRUE(box.has_value());
  const std::array<double, 3> lo{ 0.5, -2.5, -0.25 }, hi{ 1.5, -1.5, 0.75 };
  for (int a = 0; a < 3; ++a)
  {
    EXPECT_LE(box->lo[a], lo[a]);
    EXPECT_GE(box->hi[a], hi[a]);
    EXPECT_GT(box->lo[a], lo[a] - 2 * 0.15625);
    EXPECT_LT(box->hi[a], hi[a] + 2 * 0.15625);
  }
  // Nothing inside: no box. An infinite cylinder along z: the search box's z extent.
  EXPECT_FALSE(
    boundingBox(Tape::compile(Expr(-1.0) - square(Expr::x())), { { -1, -1, -1 }, { 1, 1, 1 } })
      .has_value());
  const auto cyl = boundingBox(Tape::compile(Expr(1.0) - square(Expr::x()) - square(Expr::y())),
    { { -10, -10, -10 }, { 10, 10, 10 } }, 6);
  ASSERT_TRUE(cyl.has_value());
  EXPECT_EQ(cyl->lo[2], -10.0);
  EXPECT_EQ(cyl->hi[2], 10.0);
  EXPECT_LT(cyl->hi[0], 2.0);
}
