// SPDX-License-Identifier: BSD-3-Clause
#include "FRep/Evaluators.h"

#include "FRep/Kernels.h"
#include "FRep/SinCos.h"
#include "FRep/TapeDetail.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>

namespace ictk::frep
{

using detail::applyScalar;

namespace
{
void loadParameters(
  const Tape& tape, const std::vector<double>& parameters, std::vector<double>& destination)
{
  if (parameters.size() < tape.parameterCount())
  {
    throw std::invalid_argument("the model has " + std::to_string(tape.parameterCount()) +
      " parameter(s) but " + std::to_string(parameters.size()) + " value(s) were given");
  }
  destination.assign(parameters.begin(), parameters.begin() + tape.parameterCount());
}

template <typename T>
void runScalar(const std::vector<Instruction>& code, T* s)
{
  for (const Instruction& ins : code)
  {
    s[ins.out] = applyScalar<T>(ins.op, s[ins.a], s[ins.b], s[ins.c]);
  }
}
} // namespace

// ------------------------------------------------------------------------------------------------
PointEvaluator::PointEvaluator(TapePtr tape, const std::vector<double>& parameters)
  : tape_(std::move(tape))
  , slots_(tape_->slotCount(), 0.0)
{
  std::copy(
    tape_->constants().begin(), tape_->constants().end(), slots_.begin() + tape_->constantBase());
  setParameters(parameters);
}

void PointEvaluator::setParameters(const std::vector<double>& parameters)
{
  std::vector<double> p;
  loadParameters(*tape_, parameters, p);
  std::copy(p.begin(), p.end(), slots_.begin() + tape_->parameterBase());
}

double PointEvaluator::eval(double x, double y, double z, double t)
{
  double* s = slots_.data();
  s[0] = x;
  s[1] = y;
  s[2] = z;
  s[3] = t;
  runScalar(tape_->instructions(), s);
  return s[tape_->outputs()[0]];
}

void PointEvaluator::evalAll(const std::array<double, 4>& p, double* out)
{
  eval(p[0], p[1], p[2], p[3]);
  for (std::size_t i = 0; i < tape_->outputs().size(); ++i)
  {
    out[i] = slots_[tape_->outputs()[i]];
  }
}

// ------------------------------------------------------------------------------------------------
namespace
{
// One instruction over n points. Every case is a plain loop over non-aliasing arrays (the register
// allocator never gives an instruction its own input slot), so the compiler vectorises them.
template <typename T>
__attribute__((always_inline)) inline void runChunkImpl(
  const std::vector<Instruction>& code, T* const* slot, const T* scalars, std::size_t n)
{
  constexpr std::uint32_t scalarBit = RowProgram::ScalarOperand;
  for (const Instruction& ins : code)
  {
    // Row programs: one operand of add, sub, mul, div, min, max may be a uniform scalar.
    if ((ins.a | ins.b) & scalarBit)
    {
      T* __restrict o = slot[ins.out];
      const bool first = ins.a & scalarBit;
      const T s = scalars[(first ? ins.a : ins.b) & ~scalarBit];
      const T* __restrict v = slot[first ? ins.b : ins.a];
#define ICTK_SCALAR_LOOP(expr)                                                                     \
  for (std::size_t i = 0; i < n; ++i)                                                              \
  {                                                                                                \
    o[i] = (expr);                                                                                 \
  }                                                                                                \
  break
      if (first)
      {
        switch (ins.op)
        {
          case Opcode::Add:
            ICTK_SCALAR_LOOP(s + v[i]);
          case Opcode::Sub:
            ICTK_SCALAR_LOOP(s - v[i]);
          case Opcode::Mul:
            ICTK_SCALAR_LOOP(s * v[i]);
          case Opcode::Div:
            ICTK_SCALAR_LOOP(s / v[i]);
          case Opcode::Min:
            ICTK_SCALAR_LOOP(detail::minOp(s, v[i]));
          case Opcode::Max:
            ICTK_SCALAR_LOOP(detail::maxOp(s, v[i]));
          default:
            ICTK_SCALAR_LOOP(applyScalar<T>(ins.op, s, v[i], T(0)));
        }
      }
      else
      {
        switch (ins.op)
        {
          case Opcode::Add:
            ICTK_SCALAR_LOOP(v[i] + s);
          case Opcode::Sub:
            ICTK_SCALAR_LOOP(v[i] - s);
          case Opcode::Mul:
            ICTK_SCALAR_LOOP(v[i] * s);
          case Opcode::Div:
            ICTK_SCALAR_LOOP(v[i] / s);
          case Opcode::Min:
            ICTK_SCALAR_LOOP(detail::minOp(v[i], s));
          case Opcode::Max:
            ICTK_SCALAR_LOOP(detail::maxOp(v[i], s));
          default:
            ICTK_SCALAR_LOOP(applyScalar<T>(ins.op, v[i], s, T(0)));
        }
      }
#undef ICTK_SCALAR_LOOP
      continue;
    }
    T* __restrict o = slot[ins.out];
    const T* __restrict a = slot[ins.a];
    const T* __restrict b = slot[ins.b];
    const T* __restrict c = slot[ins.c];
#define ICTK_LOOP(expr)                                                                            \
  for (std::size_t i = 0; i < n; ++i)                                                              \
  {                                                                                                \
    o[i] = (expr);                                                                                 \
  }                                                                                                \
  break
    switch (ins.op)
    {
      case Opcode::Neg:
        ICTK_LOOP(-a[i]);
      case Opcode::Abs:
        ICTK_LOOP(std::abs(a[i]));
      case Opcode::Sqrt:
        ICTK_LOOP(std::sqrt(a[i]));
      case Opcode::Square:
        ICTK_LOOP(a[i] * a[i]);
      case Opcode::Add:
        ICTK_LOOP(a[i] + b[i]);
      case Opcode::Sub:
        ICTK_LOOP(a[i] - b[i]);
      case Opcode::Mul:
        ICTK_LOOP(a[i] * b[i]);
      case Opcode::Div:
        ICTK_LOOP(a[i] / b[i]);
      case Opcode::Min:
        ICTK_LOOP(detail::minOp(a[i], b[i]));
      case Opcode::Max:
        ICTK_LOOP(detail::maxOp(a[i], b[i]));
      case Opcode::Select:
        ICTK_LOOP(a[i] >= T(0) ? b[i] : c[i]);
      default:
        ICTK_LOOP(applyScalar<T>(ins.op, a[i], b[i], c[i]));
    }
#undef ICTK_LOOP
  }
}

// The kernels are compiled for several instruction sets and picked at load time (GCC function
// multi-versioning), so one portable binary uses AVX2/AVX-512 where the CPU has them.
#if defined(__GNUC__) && defined(__x86_64__) && !defined(__clang__) &&                             \
  !defined(__SANITIZE_ADDRESS__)
#define ICTK_TARGET_CLONES __attribute__((target_clones("avx512f", "avx2", "default")))
#else
#define ICTK_TARGET_CLONES
#endif

ICTK_TARGET_CLONES void runChunkFloat(
  const std::vector<Instruction>& code, float* const* slot, const float* scalars, std::size_t n)
{
  runChunkImpl<float>(code, slot, scalars, n);
}

ICTK_TARGET_CLONES void runChunkDouble(
  const std::vector<Instruction>& code, double* const* slot, const double* scalars, std::size_t n)
{
  runChunkImpl<double>(code, slot, scalars, n);
}

template <typename T>
void runChunk(
  const std::vector<Instruction>& code, T* const* slot, std::size_t n, const T* scalars = nullptr)
{
  if constexpr (std::is_same_v<T, float>)
    runChunkFloat(code, slot, scalars, n);
  else
    runChunkDouble(code, slot, scalars, n);
}
} // namespace

template <typename T>
BatchEvaluator<T>::BatchEvaluator(TapePtr tape, const std::vector<double>& parameters)
  : tape_(std::move(tape))
{
  loadParameters(*tape_, parameters, parameters_);
  // Row program along x.
  row_ = tape_->rowProgram(1u << static_cast<int>(Axis::X));
  rowStorage_.assign(static_cast<std::size_t>(row_.chunkSlotCount) * ChunkSize, T(0));
  rowSlots_.resize(row_.chunkSlotCount);
  for (std::uint32_t i = 0; i < row_.chunkSlotCount; ++i)
  {
    rowSlots_[i] = rowStorage_.data() + static_cast<std::size_t>(i) * ChunkSize;
  }
  loadValues(row_, scalars_, rowSlots_);
}

template <typename T>
void BatchEvaluator<T>::setParameters(const std::vector<double>& parameters)
{
  loadParameters(*tape_, parameters, parameters_);
  loadValues(row_, scalars_, rowSlots_);
  if (pointsReady_)
  {
    loadValues(points_, pointScalars_, pointSlots_);
  }
}

template <typename T>
void BatchEvaluator<T>::loadValues(
  const RowProgram& program, std::vector<T>& scalars, const std::vector<T*>& chunks)
{
  const Tape& tape = *tape_;
  scalars.assign(program.scalarSlotCount, T(0));
  for (std::uint32_t i = 0; i < tape.parameterCount(); ++i)
  {
    scalars[tape.parameterBase() + i] = static_cast<T>(parameters_[i]);
  }
  for (std::size_t i = 0; i < tape.constants().size(); ++i)
  {
    scalars[tape.constantBase() + i] = static_cast<T>(tape.constants()[i]);
  }
  // Values that depend on no coordinate (of constants and parameters only) are the same at every
  // point: computed once here, not per point, and broadcast where the per-point code reads them.
  runScalar(program.uniform, scalars.data());
  for (const auto& [scalar, chunk] : program.fixedBroadcasts)
  {
    std::fill_n(chunks[chunk], ChunkSize, scalars[scalar]);
  }
  rowX_ = { 0, 0, -1, 0 };
}

template <typename T>
void BatchEvaluator<T>::preparePoints()
{
  // eval()'s program is set up on first use: evalRowX alone (grid sampling, rendering) does not
  // need it, and for a large tape it is most of the set-up cost. Every axis the tape uses varies.
  points_ = tape_->rowProgram(tape_->axesUsed());
  pointStorage_.assign(static_cast<std::size_t>(points_.chunkSlotCount) * ChunkSize, T(0));
  pointSlots_.resize(points_.chunkSlotCount);
  for (std::uint32_t i = 0; i < points_.chunkSlotCount; ++i)
  {
    pointSlots_[i] = pointStorage_.data() + static_cast<std::size_t>(i) * ChunkSize;
  }
  loadValues(points_, pointScalars_, pointSlots_);
  pointsReady_ = true;
}

template <typename T>
void BatchEvaluator<T>::eval(const T* x, const T* y, const T* z, const T* t, T* out, std::size_t n)
{
  const T* inputs[4] = { x, y, z, t };
  for (int a = 0; a < 4; ++a)
  {
    if (!inputs[a] && (tape_->axesUsed() & (1u << a)))
    {
      throw std::invalid_argument(std::string("BatchEvaluator::eval: the model uses coordinate ") +
        axisName(static_cast<Axis>(a)) + " but no values were given for it");
    }
  }
  if (!pointsReady_)
  {
    preparePoints();
  }
  const RowProgram::Output& output = points_.outputs[0];
  if (!output.varying)
  {
    std::fill_n(out, n, pointScalars_[output.slot]);
    return;
  }
  for (std::size_t start = 0; start < n; start += ChunkSize)
  {
    const std::size_t m = std::min(ChunkSize, n - start);
    // Inputs are read in place: no instruction writes an axis slot. (Writing the output in place
    // as well was measured slower: temporaries sharing its slot then go to the large array.)
    for (int a = 0; a < 4; ++a)
    {
      if (tape_->axesUsed() & (1u << a))
      {
        pointSlots_[points_.axisSlots[a]] = const_cast<T*>(inputs[a] + start);
      }
    }
    runChunk<T>(points_.varying, pointSlots_.data(), m, pointScalars_.data());
    std::copy_n(pointSlots_[output.slot], m, out + start);
  }
}

template <typename T>
void BatchEvaluator<T>::evalRowX(double x0, double dx, std::int64_t first, double y, double z,
  double t, T* const* outputs, std::size_t outputCount, std::size_t n)
{
  if (outputCount > row_.outputs.size())
  {
    throw std::invalid_argument("BatchEvaluator::evalRowX: the tape has " +
      std::to_string(row_.outputs.size()) + " output(s), " + std::to_string(outputCount) +
      " asked");
  }
  T* s = scalars_.data();
  s[0] = static_cast<T>(x0 + static_cast<double>(first) * dx);
  s[1] = static_cast<T>(y);
  s[2] = static_cast<T>(z);
  s[3] = static_cast<T>(t);
  runScalar(row_.uniform, s);
  bool anyVarying = false;
  for (std::size_t k = 0; k < outputCount; ++k)
  {
    const RowProgram::Output& output = row_.outputs[k];
    if (!output.varying)
    {
      std::fill_n(outputs[k], n, s[output.slot]);
    }
    anyVarying = anyVarying || output.varying;
  }
  if (!anyVarying)
  {
    return;
  }
  for (const auto& [scalar, chunk] : row_.broadcasts)
  {
    std::fill_n(rowSlots_[chunk], std::min(n, ChunkSize), s[scalar]);
  }
  T* xs = rowSlots_[row_.axisSlots[0]];
  for (std::size_t start = 0; start < n; start += ChunkSize)
  {
    const std::size_t m = std::min(ChunkSize, n - start);
    // Rows of one brick share their x coordinates: fill them only when they change.
    const RowX key{ x0, dx, first + static_cast<std::int64_t>(start), m };
    if (!(key == rowX_))
    {
      for (std::size_t i = 0; i < m; ++i)
      {
        // Coordinates in double, as every other evaluator receives them.
        xs[i] =
          static_cast<T>(x0 + static_cast<double>(key.first + static_cast<std::int64_t>(i)) * dx);
      }
      rowX_ = key;
    }
    runChunk<T>(row_.varying, rowSlots_.data(), m, s);
    for (std::size_t k = 0; k < outputCount; ++k)
    {
      if (row_.outputs[k].varying)
      {
        std::copy_n(rowSlots_[row_.outputs[k].slot], m, outputs[k] + start);
      }
    }
  }
}

template class BatchEvaluator<float>;
template class BatchEvaluator<double>;

// ------------------------------------------------------------------------------------------------
namespace
{
constexpr double inf = std::numeric_limits<double>::infinity();
constexpr double pi = 3.14159265358979323846;

// std::nextafter(x, +inf) and (x, -inf), inline (interval evaluation calls them for almost every
// instruction): step the bit pattern by one, zeros go to the smallest subnormal, infinities and
// NaN stay.
inline double nextUp(double x)
{
  if (!(x < inf))
    return x;
  if (x == 0)
    return std::numeric_limits<double>::denorm_min();
  std::uint64_t bits;
  std::memcpy(&bits, &x, sizeof bits);
  bits = x > 0 ? bits + 1 : bits - 1;
  std::memcpy(&x, &bits, sizeof bits);
  return x;
}

inline double nextDown(double x)
{
  return -nextUp(-x);
}

// Outward rounding by one ulp each side: the libm functions used are faithful to within an ulp,
// so the widened interval encloses every value the point evaluators can produce.
Interval widen(Interval r)
{
  return { nextDown(r.lo), nextUp(r.hi), r.maybeNaN };
}

// Widening must not push a bound below zero when the result cannot be negative (a square, a sum
// of squares): sqrt would then report possible NaN and pruning would be needlessly cautious.
Interval nonNegative(Interval r)
{
  r.lo = std::max(r.lo, 0.0);
  return r;
}

Interval nowhere()
{
  return { inf, -inf, true };
}

Interval hull(const Interval& a, const Interval& b)
{
  return { std::min(a.lo, b.lo), std::max(a.hi, b.hi), a.maybeNaN || b.maybeNaN };
}

bool hasInfinity(const Interval& a)
{
  return std::isinf(a.lo) || std::isinf(a.hi);
}

Interval monotoneIncreasing(double (*f)(double), const Interval& a)
{
  return widen({ f(a.lo), f(a.hi), a.maybeNaN });
}

Interval mul(const Interval& a, const Interval& b)
{
  const double p[4] = { a.lo * b.lo, a.lo * b.hi, a.hi * b.lo, a.hi * b.hi };
  double lo = inf, hi = -inf;
  for (double v : p)
  {
    // 0 * inf is NaN: a zero bound times an infinite one contributes 0 to the finite values.
    v = std::isnan(v) ? 0.0 : v;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  const bool zeroTimesInf = (a.contains(0) && hasInfinity(b)) || (b.contains(0) && hasInfinity(a));
  const Interval r = widen({ lo, hi, a.maybeNaN || b.maybeNaN || zeroTimesInf });
  const bool sameSign = (a.lo >= 0 && b.lo >= 0) || (a.hi <= 0 && b.hi <= 0);
  return sameSign ? nonNegative(r) : r;
}

Interval squareRange(const Interval& a)
{
  if (a.lo >= 0)
    return nonNegative(widen({ a.lo * a.lo, a.hi * a.hi, a.maybeNaN }));
  if (a.hi <= 0)
    return nonNegative(widen({ a.hi * a.hi, a.lo * a.lo, a.maybeNaN }));
  return nonNegative(widen({ 0.0, std::max(a.lo * a.lo, a.hi * a.hi), a.maybeNaN }));
}

// Range of sin or cos over [lo, hi]: the extremes are at the ends or at the maxima (sin: pi/2 +
// 2k pi, cos: 2k pi) and minima (half a period further) inside the interval.
Interval trigRange(bool isSin, const Interval& a)
{
  if (hasInfinity(a))
    return { -1.0, 1.0, true }; // sin(inf) is NaN
  if (!(a.hi - a.lo < 2 * pi))
    return { -1.0, 1.0, a.maybeNaN };
  const double maxAt = isSin ? pi / 2 : 0.0;
  const bool hasMax = maxAt + 2 * pi * std::ceil((a.lo - maxAt) / (2 * pi)) <= a.hi;
  const double minAt = maxAt + pi;
  const bool hasMin = minAt + 2 * pi * std::ceil((a.lo - minAt) / (2 * pi)) <= a.hi;
  if (hasMax && hasMin)
    return { -1.0, 1.0, a.maybeNaN }; // what widening and clamping give below, without libm
  if (std::abs(a.lo) <= detail::SinCosLimit && std::abs(a.hi) <= detail::SinCosLimit)
  {
    // The ends without libm (SinCos.h), widened by their proven error bound and by an ulp for
    // the widening's own rounding.
    const double fLo = isSin ? detail::sinApprox(a.lo) : detail::cosApprox(a.lo);
    const double fHi = isSin ? detail::sinApprox(a.hi) : detail::cosApprox(a.hi);
    const double lo = hasMin ? -1.0 : nextDown(std::min(fLo, fHi) - detail::SinCosWidening);
    const double hi = hasMax ? 1.0 : nextUp(std::max(fLo, fHi) + detail::SinCosWidening);
    return { std::max(lo, -1.0), std::min(hi, 1.0), a.maybeNaN };
  }
  const double fLo = isSin ? std::sin(a.lo) : std::cos(a.lo);
  const double fHi = isSin ? std::sin(a.hi) : std::cos(a.hi);
  const double lo = hasMin ? -1.0 : std::min(fLo, fHi);
  const double hi = hasMax ? 1.0 : std::max(fLo, fHi);
  Interval r = widen({ lo, hi, a.maybeNaN });
  return { std::max(r.lo, -1.0), std::min(r.hi, 1.0), r.maybeNaN };
}

// Bounds that are finite and ordered, with no NaN: what nearly every instruction of a model sees
// over a box inside its domain.
inline bool plain(const Interval& a)
{
  return !a.maybeNaN && a.lo >= -std::numeric_limits<double>::max() &&
    a.hi <= std::numeric_limits<double>::max() && a.lo <= a.hi;
}

// Opcode::CauchySegment over a box of operands (u, v, length), by its monotony rather than by its
// terms: the integral of k(tau) = 1 / (1 + v + tau^2)^2 over [-u, length - u] decreases in v
// (the integrand does) and increases in the length (the integrand is positive); its derivative in
// u is k(u) - k(length - u), positive while |u| < |length - u|, so for a length >= 0 it rises up
// to u = length / 2 and falls after. The largest value is at the smallest v, the largest length
// and the u nearest half of it; the smallest at the largest v, the smallest length and an end of
// u's interval. Those corners are computed as the point evaluators compute any point, so the
// bound is widened by twice the rounding error a point can have: the four terms of Kernels.h add
// up to at most (1/2 + pi/2) / P^3 in magnitude (P^2 = 1 + v >= 1), and each is computed to
// within about 30 ulps of itself (a dozen roundings, sqrt, atan within an ulp, P's error tripled
// by P^3), so 256 ulps of 2.1 / P^3 each side hold the point values with room to spare. Operands
// outside the kernel's use (v < 0, a negative length, NaN, infinities) get no bound.
Interval cauchySegmentRange(const Interval& u, const Interval& v, const Interval& length)
{
  if (u.empty() || v.empty() || length.empty())
    return nowhere();
  if (!plain(u) || !plain(v) || !plain(length) || v.lo < 0 || length.lo < 0)
    return { -inf, inf, true };
  const double top = std::clamp(0.5 * length.hi, u.lo, u.hi);
  const double largest = detail::cauchySegment(top, v.lo, length.hi);
  const double smallest = std::min(
    detail::cauchySegment(u.lo, v.hi, length.lo), detail::cauchySegment(u.hi, v.hi, length.lo));
  const double p2 = 1 + v.lo;
  const double error = 256 * std::numeric_limits<double>::epsilon() * 2.1 / (p2 * std::sqrt(p2));
  return { nextDown(smallest - error), nextUp(largest + error), false };
}

// The interval counterpart of each opcode. Choices mirror the point semantics exactly, including
// NaN: minOp(a, b) and maxOp(a, b) return a whenever either operand is NaN, and select takes its
// second branch when the condition is NaN; so deciding for the first operand is always safe, and
// deciding for the second needs operands that cannot be NaN.
Interval intervalOp(
  Opcode op, const Interval& a, const Interval& b, const Interval& c, Choice& choice)
{
  choice = Choice::Both;
  switch (op)
  {
    case Opcode::Min:
    case Opcode::Max:
    {
      if (a.empty())
      {
        choice = Choice::First;
        return a;
      }
      if (b.empty())
      {
        choice = Choice::First;
        return a;
      }
      const bool isMin = op == Opcode::Min;
      // Ties return the first operand, so a.hi <= b.lo decides a min for a.
      if (isMin ? a.hi <= b.lo : a.lo >= b.hi)
      {
        choice = Choice::First;
        return a;
      }
      if (!a.maybeNaN && !b.maybeNaN && (isMin ? b.hi < a.lo : b.lo > a.hi))
      {
        choice = Choice::Second;
        return b;
      }
      Interval r = isMin ? Interval{ std::min(a.lo, b.lo), std::min(a.hi, b.hi), a.maybeNaN }
                         : Interval{ std::max(a.lo, b.lo), std::max(a.hi, b.hi), a.maybeNaN };
      if (b.maybeNaN)
      {
        r = hull(r, a); // where b is NaN the result is a
      }
      return r;
    }
    case Opcode::Select:
      if (a.empty() || a.hi < 0)
      {
        choice = Choice::Second;
        return c;
      }
      if (a.lo >= 0 && !a.maybeNaN)
      {
        choice = Choice::First;
        return b;
      }
      if (b.empty())
        return { c.lo, c.hi, true };
      if (c.empty())
        return { b.lo, b.hi, true };
      return hull(b, c);
    case Opcode::Sign:
      if (a.empty())
        return { 0.0, 0.0, false };
      return hull({ detail::signOp(a.lo), detail::signOp(a.hi), false },
        a.maybeNaN ? Interval{ 0.0, 0.0, false }
                   : Interval{ detail::signOp(a.lo), detail::signOp(a.lo), false });
    case Opcode::Pow:
      // pow(1, NaN) and pow(NaN, 0) are 1: NaN operands do not make a NaN result.
      if (a.empty() || b.empty() || a.maybeNaN || b.maybeNaN)
        return { -inf, inf, true };
      break;
    case Opcode::CauchySegment:
      return cauchySegmentRange(a, b, c);
    default:
      break;
  }
  const int arity = detail::arity(op);
  if (a.empty() || (arity > 1 && b.empty()))
  {
    return nowhere();
  }
  const bool nanIn = a.maybeNaN || (arity > 1 && b.maybeNaN);
  switch (op)
  {
    case Opcode::Neg:
      return { -a.hi, -a.lo, a.maybeNaN };
    case Opcode::Abs:
      if (a.lo >= 0)
        return a;
      if (a.hi <= 0)
        return { -a.hi, -a.lo, a.maybeNaN };
      return { 0.0, std::max(-a.lo, a.hi), a.maybeNaN };
    case Opcode::Sqrt:
      if (a.hi < 0)
        return nowhere();
      return nonNegative(
        widen({ std::sqrt(std::max(a.lo, 0.0)), std::sqrt(a.hi), a.maybeNaN || a.lo < 0 }));
    case Opcode::Square:
      return squareRange(a);
    case Opcode::Exp:
      return nonNegative(monotoneIncreasing(std::exp, a));
    case Opcode::Log:
      if (a.hi < 0)
        return nowhere();
      return widen({ a.lo <= 0 ? -inf : std::log(a.lo), std::log(a.hi), a.maybeNaN || a.lo < 0 });
    case Opcode::Sin:
      return trigRange(true, a);
    case Opcode::Cos:
      return trigRange(false, a);
    case Opcode::Tan:
    {
      // Monotone between the poles at pi/2 + k pi.
      const double k = std::ceil((a.lo - pi / 2) / pi);
      if (hasInfinity(a))
        return { -inf, inf, true };
      if (!(a.hi - a.lo < pi) || pi / 2 + k * pi <= a.hi)
        return { -inf, inf, a.maybeNaN };
      return monotoneIncreasing(std::tan, a);
    }
    case Opcode::Asin:
    case Opcode::Acos:
    {
      if (a.hi < -1 || a.lo > 1)
        return nowhere();
      const double lo = std::max(a.lo, -1.0), hi = std::min(a.hi, 1.0);
      const bool outside = a.maybeNaN || a.lo < -1 || a.hi > 1;
      if (op == Opcode::Asin)
        return widen({ std::asin(lo), std::asin(hi), outside });
      return widen({ std::acos(hi), std::acos(lo), outside });
    }
    case Opcode::Atan:
      return monotoneIncreasing(std::atan, a);
    case Opcode::Floor:
      // Exact: floor of a double is a double, and floor is monotone.
      return { std::floor(a.lo), std::floor(a.hi), a.maybeNaN };
    case Opcode::Add:
    {
      const bool infMinusInf = (a.hi == inf && b.lo == -inf) || (a.lo == -inf && b.hi == inf);
      Interval r = widen({ a.lo + b.lo, a.hi + b.hi, nanIn || infMinusInf });
      if (std::isnan(r.lo) || std::isnan(r.hi))
        return { -inf, inf, true };
      return a.lo >= 0 && b.lo >= 0 ? nonNegative(r) : r;
    }
    case Opcode::Sub:
    {
      const bool infMinusInf = (a.hi == inf && b.hi == inf) || (a.lo == -inf && b.lo == -inf);
      Interval r = widen({ a.lo - b.hi, a.hi - b.lo, nanIn || infMinusInf });
      if (std::isnan(r.lo) || std::isnan(r.hi))
        return { -inf, inf, true };
      return r;
    }
    case Opcode::Mul:
      return mul(a, b);
    case Opcode::Div:
      if (b.lo > 0 || b.hi < 0)
      {
        const bool infOverInf = hasInfinity(a) && hasInfinity(b);
        Interval r = mul(a, widen({ 1.0 / b.hi, 1.0 / b.lo, b.maybeNaN }));
        r.maybeNaN = r.maybeNaN || infOverInf;
        if (infOverInf)
          return { -inf, inf, true };
        return r;
      }
      return { -inf, inf, true }; // 0/0 possible
    case Opcode::Pow:
    {
      if ((a.lo > 0 || (a.lo >= 0 && b.lo > 0)) && std::isfinite(a.hi) && std::isfinite(b.lo) &&
        std::isfinite(b.hi))
      {
        // a^b = exp(b ln a) is monotone in b ln a, which is bilinear in (b, ln a): extremes at
        // the corners (with 0^b = 0 for b > 0, the limit of that form).
        const double p[4] = { std::pow(a.lo, b.lo), std::pow(a.lo, b.hi), std::pow(a.hi, b.lo),
          std::pow(a.hi, b.hi) };
        return widen({ *std::min_element(p, p + 4), *std::max_element(p, p + 4), nanIn });
      }
      return { -inf, inf, true };
    }
    case Opcode::Atan2:
      // For x > 0, atan2(y, x) = atan(y / x) and y / x is monotone in each argument: corners.
      if (b.lo > 0 && !hasInfinity(a) && !hasInfinity(b))
      {
        const double p[4] = { std::atan2(a.lo, b.lo), std::atan2(a.lo, b.hi),
          std::atan2(a.hi, b.lo), std::atan2(a.hi, b.hi) };
        return widen({ *std::min_element(p, p + 4), *std::max_element(p, p + 4), nanIn });
      }
      return { -pi, pi, nanIn };
    default:
      return { -inf, inf, true };
  }
}

// mul() of plain operands: finite products, so no NaN and no zero times infinity.
[[gnu::always_inline]] inline Interval plainMul(const Interval& a, const Interval& b)
{
  const double p0 = a.lo * b.lo, p1 = a.lo * b.hi, p2 = a.hi * b.lo, p3 = a.hi * b.hi;
  const Interval r{ nextDown(std::min(std::min(p0, p1), std::min(p2, p3))),
    nextUp(std::max(std::max(p0, p1), std::max(p2, p3))), false };
  const bool sameSign = (a.lo >= 0 && b.lo >= 0) || (a.hi <= 0 && b.hi <= 0);
  return sameSign ? nonNegative(r) : r;
}

// intervalOp for the common opcodes on plain operands, without the checks that only NaN, empty
// or infinite operands need (the same bounds, flags and choices bit for bit: intervalOp's
// branches for such operands reduce to these lines), and inlined into the evaluation loops, so
// that an instruction costs its arithmetic and its outward rounding rather than two dispatches
// and a call. Every other case goes to intervalOp.
// Always inlined: the incremental evaluator calls it from two loops, where GCC otherwise makes it a
// call (14 % more instructions for render-sphere-gyroid).
[[gnu::always_inline]] inline Interval fastIntervalOp(
  Opcode op, const Interval& a, const Interval& b, const Interval& c, Choice& choice)
{
  switch (op)
  {
    case Opcode::Add:
      if (plain(a) && plain(b))
      {
        choice = Choice::Both;
        const Interval r{ nextDown(a.lo + b.lo), nextUp(a.hi + b.hi), false };
        return a.lo >= 0 && b.lo >= 0 ? nonNegative(r) : r;
      }
      break;
    case Opcode::Sub:
      if (plain(a) && plain(b))
      {
        choice = Choice::Both;
        return { nextDown(a.lo - b.hi), nextUp(a.hi - b.lo), false };
      }
      break;
    case Opcode::Mul:
      if (plain(a) && plain(b))
      {
        choice = Choice::Both;
        return plainMul(a, b);
      }
      break;
    case Opcode::Div:
      // a times the widened reciprocal of b, as intervalOp: over a divisor that excludes 0 and
      // whose reciprocal is finite (a divisor below 1/DBL_MAX in magnitude goes there).
      if (plain(a) && plain(b) && (b.lo > 0 || b.hi < 0))
      {
        const Interval reciprocal{ nextDown(1.0 / b.hi), nextUp(1.0 / b.lo), false };
        if (plain(reciprocal))
        {
          choice = Choice::Both;
          return plainMul(a, reciprocal);
        }
      }
      break;
    case Opcode::Min:
    case Opcode::Max:
      if (plain(a) && plain(b))
      {
        const bool isMin = op == Opcode::Min;
        if (isMin ? a.hi <= b.lo : a.lo >= b.hi)
        {
          choice = Choice::First;
          return a;
        }
        if (isMin ? b.hi < a.lo : b.lo > a.hi)
        {
          choice = Choice::Second;
          return b;
        }
        choice = Choice::Both;
        return isMin ? Interval{ std::min(a.lo, b.lo), std::min(a.hi, b.hi), false }
                     : Interval{ std::max(a.lo, b.lo), std::max(a.hi, b.hi), false };
      }
      break;
    case Opcode::Neg:
      if (plain(a))
      {
        choice = Choice::Both;
        return { -a.hi, -a.lo, false };
      }
      break;
    case Opcode::Square:
      if (plain(a))
      {
        choice = Choice::Both;
        return squareRange(a);
      }
      break;
    case Opcode::Abs:
      if (plain(a))
      {
        choice = Choice::Both;
        if (a.lo >= 0)
          return a;
        if (a.hi <= 0)
          return { -a.hi, -a.lo, false };
        return { 0.0, std::max(-a.lo, a.hi), false };
      }
      break;
    case Opcode::Sqrt:
      if (plain(a) && a.hi >= 0)
      {
        choice = Choice::Both;
        return nonNegative(widen({ std::sqrt(std::max(a.lo, 0.0)), std::sqrt(a.hi), a.lo < 0 }));
      }
      break;
    case Opcode::Sin:
    case Opcode::Cos:
      if (plain(a))
      {
        choice = Choice::Both;
        return trigRange(op == Opcode::Sin, a);
      }
      break;
    default:
      break;
  }
  return intervalOp(op, a, b, c, choice);
}
} // namespace

Interval detail::intervalOperation(
  Opcode op, const Interval& a, const Interval& b, const Interval& c, Choice& choice)
{
  return fastIntervalOp(op, a, b, c, choice);
}

Interval detail::intervalOperationReference(
  Opcode op, const Interval& a, const Interval& b, const Interval& c, Choice& choice)
{
  return intervalOp(op, a, b, c, choice);
}

namespace
{
/// The leaves of an interval evaluator's values (constants or parameters) from `first` on: each
/// value a point interval, NaN flagged.
void writeIntervalLeaves(
  const std::vector<double>& leaves, std::uint32_t first, std::vector<Interval>& values)
{
  for (std::size_t i = 0; i < leaves.size(); ++i)
  {
    const double v = leaves[i];
    values[first + i] = { v, v, std::isnan(v) };
  }
}
} // namespace

IntervalEvaluator::IntervalEvaluator(TapePtr tape, const std::vector<double>& parameters)
  : tape_(std::move(tape))
  , slots_(tape_->slotCount())
  , choices_(tape_->instructions().size(), Choice::Both)
{
  writeIntervalLeaves(tape_->constants(), tape_->constantBase(), slots_);
  setParameters(parameters);
}

void IntervalEvaluator::setParameters(const std::vector<double>& parameters)
{
  std::vector<double> p;
  loadParameters(*tape_, parameters, p);
  writeIntervalLeaves(p, tape_->parameterBase(), slots_);
}

Interval IntervalEvaluator::eval(const Region& region)
{
  for (int a = 0; a < 4; ++a)
  {
    slots_[a] = region.axes[a];
  }
  const auto& code = tape_->instructions();
  for (std::size_t i = 0; i < code.size(); ++i)
  {
    const Instruction& ins = code[i];
    slots_[ins.out] =
      fastIntervalOp(ins.op, slots_[ins.a], slots_[ins.b], slots_[ins.c], choices_[i]);
  }
  return slots_[tape_->outputs()[0]];
}

// ------------------------------------------------------------------------------------------------
SsaCode::SsaCode(const Tape& tape)
{
  const std::uint32_t base = tape.temporaryBase();
  const auto& instructions = tape.instructions();
  valueCount = base + static_cast<std::uint32_t>(instructions.size());
  // The value each slot holds at this point of the tape (register allocation reuses slots).
  std::vector<std::uint32_t> valueInSlot(tape.slotCount());
  for (std::uint32_t s = 0; s < tape.slotCount(); ++s)
  {
    valueInSlot[s] = s;
  }
  std::vector<std::uint8_t> axesOf(valueCount, 0);
  for (std::uint32_t a = 0; a < 4; ++a)
  {
    axesOf[a] = static_cast<std::uint8_t>(1u << a);
  }
  code.reserve(instructions.size());
  axes.reserve(instructions.size());
  for (std::size_t i = 0; i < instructions.size(); ++i)
  {
    const Instruction& ins = instructions[i];
    const auto v = static_cast<std::uint32_t>(base + i);
    Instruction out{ ins.op, v, 0, 0, 0 };
    const std::uint32_t operands[3] = { ins.a, ins.b, ins.c };
    std::uint32_t* to[3] = { &out.a, &out.b, &out.c };
    std::uint8_t mask = 0;
    for (int k = 0; k < detail::arity(ins.op); ++k)
    {
      *to[k] = valueInSlot[operands[k]];
      mask = static_cast<std::uint8_t>(mask | axesOf[*to[k]]);
    }
    axesOf[v] = mask;
    used = static_cast<std::uint8_t>(used | mask);
    valueInSlot[ins.out] = v;
    code.push_back(out);
    axes.push_back(mask);
  }
  output = valueInSlot[tape.outputs()[0]];
}

const std::vector<std::uint32_t>& SsaCode::dependents(unsigned changed)
{
  changed &= 0xf;
  std::vector<std::uint32_t>& list = dependents_[changed];
  if (!(listed_ & (1u << changed)))
  {
    for (std::uint32_t i = 0; i < axes.size(); ++i)
    {
      if (axes[i] & changed)
      {
        list.push_back(i);
      }
    }
    listed_ = static_cast<std::uint16_t>(listed_ | (1u << changed));
  }
  return list;
}

namespace
{
bool sameBits(double a, double b)
{
  return std::memcmp(&a, &b, sizeof a) == 0;
}

bool sameInterval(const Interval& a, const Interval& b)
{
  return sameBits(a.lo, b.lo) && sameBits(a.hi, b.hi) && a.maybeNaN == b.maybeNaN;
}
} // namespace

IncrementalIntervalEvaluator::IncrementalIntervalEvaluator(
  TapePtr tape, const std::vector<double>& parameters)
  : tape_(std::move(tape))
  , ssa_(*tape_)
  , values_(ssa_.valueCount)
  , choices_(tape_->instructions().size(), Choice::Both)
{
  writeIntervalLeaves(tape_->constants(), tape_->constantBase(), values_);
  setParameters(parameters);
}

void IncrementalIntervalEvaluator::setParameters(const std::vector<double>& parameters)
{
  std::vector<double> p;
  loadParameters(*tape_, parameters, p);
  writeIntervalLeaves(p, tape_->parameterBase(), values_);
  // The instructions record the axes they depend on, not the parameters: all run again.
  first_ = true;
}

Interval IncrementalIntervalEvaluator::eval(const Region& region)
{
  unsigned changed = first_ ? ~0u : 0u;
  for (int a = 0; a < 4; ++a)
  {
    if (!sameInterval(values_[a], region.axes[a]))
    {
      values_[a] = region.axes[a];
      changed |= 1u << a;
    }
  }
  const auto& code = ssa_.code;
  auto run = [&](std::size_t i) __attribute__((always_inline))
  {
    const Instruction& ins = code[i];
    values_[ins.out] =
      fastIntervalOp(ins.op, values_[ins.a], values_[ins.b], values_[ins.c], choices_[i]);
  };
  ssa_.forEachDependent(changed, std::exchange(first_, false), run);
  return values_[ssa_.output];
}

IncrementalPointEvaluator::IncrementalPointEvaluator(
  TapePtr tape, const std::vector<double>& parameters)
  : tape_(std::move(tape))
  , ssa_(*tape_)
  , values_(ssa_.valueCount, 0.0)
{
  std::copy(
    tape_->constants().begin(), tape_->constants().end(), values_.begin() + tape_->constantBase());
  setParameters(parameters);
}

void IncrementalPointEvaluator::setParameters(const std::vector<double>& parameters)
{
  std::vector<double> p;
  loadParameters(*tape_, parameters, p);
  std::copy(p.begin(), p.end(), values_.begin() + tape_->parameterBase());
  // As IncrementalIntervalEvaluator::setParameters: everything runs again.
  first_ = true;
}

double IncrementalPointEvaluator::eval(double x, double y, double z, double t)
{
  const double p[4] = { x, y, z, t };
  unsigned changed = first_ ? ~0u : 0u;
  for (int a = 0; a < 4; ++a)
  {
    if (!sameBits(values_[a], p[a]))
    {
      values_[a] = p[a];
      changed |= 1u << a;
    }
  }
  double* s = values_.data();
  const auto& code = ssa_.code;
  auto run = [&](std::size_t i) __attribute__((always_inline))
  {
    const Instruction& ins = code[i];
    s[ins.out] = applyScalar<double>(ins.op, s[ins.a], s[ins.b], s[ins.c]);
  };
  ssa_.forEachDependent(changed, std::exchange(first_, false), run);
  return s[ssa_.output];
}

// ------------------------------------------------------------------------------------------------
namespace
{
ValueGradient chain(double value, const ValueGradient& a, double derivative)
{
  ValueGradient r;
  r.value = value;
  for (int k = 0; k < 4; ++k)
  {
    // A zero partial stays zero even where the derivative is infinite (sqrt at 0).
    r.gradient[k] = a.gradient[k] == 0 ? 0 : derivative * a.gradient[k];
  }
  return r;
}

ValueGradient combine(
  double value, const ValueGradient& a, double da, const ValueGradient& b, double db)
{
  ValueGradient r;
  r.value = value;
  for (int k = 0; k < 4; ++k)
  {
    r.gradient[k] =
      (a.gradient[k] == 0 ? 0 : da * a.gradient[k]) + (b.gradient[k] == 0 ? 0 : db * b.gradient[k]);
  }
  return r;
}

ValueGradient gradientOp(
  Opcode op, const ValueGradient& a, const ValueGradient& b, const ValueGradient& c)
{
  const double x = a.value, y = b.value;
  const double v = applyScalar<double>(op, x, y, c.value);
  switch (op)
  {
    case Opcode::Neg:
      return chain(v, a, -1);
    case Opcode::Abs:
      return chain(v, a, detail::signOp(x));
    case Opcode::Sqrt:
      // The derivative is infinite at 0; report 0 there rather than inf * 0 = NaN.
      return chain(v, a, v > 0 ? 0.5 / v : 0.0);
    case Opcode::Square:
      return chain(v, a, 2 * x);
    case Opcode::Exp:
      return chain(v, a, v);
    case Opcode::Log:
      return chain(v, a, 1 / x);
    case Opcode::Sin:
      return chain(v, a, std::cos(x));
    case Opcode::Cos:
      return chain(v, a, -std::sin(x));
    case Opcode::Tan:
      return chain(v, a, 1 + v * v);
    case Opcode::Asin:
      return chain(v, a, 1 / std::sqrt(1 - x * x));
    case Opcode::Acos:
      return chain(v, a, -1 / std::sqrt(1 - x * x));
    case Opcode::Atan:
      return chain(v, a, 1 / (1 + x * x));
    case Opcode::Sign:
    case Opcode::Floor:
      return chain(v, a, 0);
    case Opcode::Add:
      return combine(v, a, 1, b, 1);
    case Opcode::Sub:
      return combine(v, a, 1, b, -1);
    case Opcode::Mul:
      return combine(v, a, y, b, x);
    case Opcode::Div:
      return combine(v, a, 1 / y, b, -x / (y * y));
    case Opcode::Min:
      return y < x ? chain(v, b, 1) : chain(v, a, 1);
    case Opcode::Max:
      return !(x < y) ? chain(v, a, 1) : chain(v, b, 1);
    case Opcode::Pow:
      return combine(v, a, y * std::pow(x, y - 1), b, x > 0 ? v * std::log(x) : 0.0);
    case Opcode::Atan2:
    {
      const double r2 = x * x + y * y;
      return combine(v, a, y / r2, b, -x / r2);
    }
    case Opcode::Select:
      return x >= 0 ? chain(v, b, 1) : chain(v, c, 1);
    case Opcode::CauchySegment:
    {
      // d/du = k(u) - k(length - u), d/dlength = k(length - u) with k(tau) = 1 / (P^2 + tau^2)^2;
      // d/dv = -2 (H(u) + H(length - u)), H the odd antiderivative of 1 / (P^2 + tau^2)^3:
      // H(tau) = tau / (4 P^2 (P^2 + tau^2)^2) + 3 tau / (8 P^4 (P^2 + tau^2))
      //   + 3 atan(tau / P) / (8 P^5).
      const double p2 = 1 + y, p = std::sqrt(p2), w = c.value - x;
      const auto k = [&](double tau)
      {
        const double q = p2 + tau * tau;
        return 1 / (q * q);
      };
      const auto h = [&](double tau)
      {
        const double q = p2 + tau * tau;
        return tau / (4 * p2 * q * q) + 3 * tau / (8 * p2 * p2 * q) +
          3 * std::atan(tau / p) / (8 * p2 * p2 * p);
      };
      ValueGradient r = combine(v, a, k(x) - k(w), b, -2 * (h(x) + h(w)));
      return combine(v, r, 1, c, k(w));
    }
    default:
      return chain(v, a, 0);
  }
}
} // namespace

GradientEvaluator::GradientEvaluator(TapePtr tape, const std::vector<double>& parameters)
  : tape_(std::move(tape))
  , slots_(tape_->slotCount())
{
  for (std::size_t i = 0; i < tape_->constants().size(); ++i)
  {
    slots_[tape_->constantBase() + i].value = tape_->constants()[i];
  }
  for (int a = 0; a < 4; ++a)
  {
    slots_[a].gradient[a] = 1.0;
  }
  setParameters(parameters);
}

void GradientEvaluator::setParameters(const std::vector<double>& parameters)
{
  std::vector<double> p;
  loadParameters(*tape_, parameters, p);
  for (std::size_t i = 0; i < p.size(); ++i)
  {
    slots_[tape_->parameterBase() + i].value = p[i];
  }
}

ValueGradient GradientEvaluator::eval(double x, double y, double z, double t)
{
  slots_[0].value = x;
  slots_[1].value = y;
  slots_[2].value = z;
  slots_[3].value = t;
  for (const Instruction& ins : tape_->instructions())
  {
    slots_[ins.out] = gradientOp(ins.op, slots_[ins.a], slots_[ins.b], slots_[ins.c]);
  }
  return slots_[tape_->outputs()[0]];
}

std::array<double, 3> outwardNormal(const ValueGradient& g)
{
  const double n = std::sqrt(
    g.gradient[0] * g.gradient[0] + g.gradient[1] * g.gradient[1] + g.gradient[2] * g.gradient[2]);
  if (!(n > 0) || !std::isfinite(n))
  {
    return { 0, 0, 0 };
  }
  return { -g.gradient[0] / n, -g.gradient[1] / n, -g.gradient[2] / n };
}

} // namespace ictk::frep
