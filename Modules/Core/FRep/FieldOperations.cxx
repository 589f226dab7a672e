// SPDX-License-Identifier: BSD-3-Clause
#include "FRep/FieldOperations.h"

#include "FRep/Evaluators.h"
#include "FRep/Operations.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace ictk::frep
{
namespace
{

class ComposedFieldEvaluator final : public FieldEvaluator
{
public:
  ComposedFieldEvaluator(const TapePtr& g, std::vector<std::unique_ptr<FieldEvaluator>> operands,
    const std::vector<int>& monotone)
    : operands_(std::move(operands))
    , monotone_(monotone)
    , point_(g)
    , batch_(g)
    , interval_(g)
    , gradient_(g)
  {
  }

  void values(
    const double* x, const double* y, const double* z, double* out, std::size_t n) override
  {
    scratch_.resize(AxisCount * n);
    std::fill(scratch_.begin(), scratch_.end(), 0.0);
    for (std::size_t i = 0; i < operands_.size(); ++i)
    {
      operands_[i]->values(x, y, z, scratch_.data() + i * n, n);
    }
    const double* s = scratch_.data();
    batch_.eval(s, s + n, s + 2 * n, s + 3 * n, out, n);
  }

  Interval bound(const Box3& box) override
  {
    Region r;
    bool maybeNaN = false;
    for (std::size_t i = 0; i < operands_.size(); ++i)
    {
      r.axes[i] = operands_[i]->bound(box);
      maybeNaN = maybeNaN || r.axes[i].maybeNaN;
      r.axes[i].maybeNaN = false;
    }
    Interval out = interval_.eval(r);
    out.maybeNaN = out.maybeNaN || maybeNaN;
    if (monotone_.empty() || out.maybeNaN)
    {
      return out;
    }
    // g at the corners of the operands' box where it is least and greatest.
    std::array<double, AxisCount> low{}, high{};
    for (std::size_t i = 0; i < operands_.size(); ++i)
    {
      const bool up = monotone_[i] > 0;
      low[i] = up ? r.axes[i].lo : r.axes[i].hi;
      high[i] = up ? r.axes[i].hi : r.axes[i].lo;
    }
    const double lo = point_.eval(low[0], low[1], low[2], low[3]);
    const double hi = point_.eval(high[0], high[1], high[2], high[3]);
    if (std::isfinite(lo))
    {
      out.lo = std::max(out.lo, widened(lo, -1));
    }
    if (std::isfinite(hi))
    {
      out.hi = std::min(out.hi, widened(hi, +1));
    }
    return out;
  }

  double gradient(const Point3& p, Point3& grad) override
  {
    std::array<double, AxisCount> value{};
    std::array<Point3, AxisCount> partial{};
    for (std::size_t i = 0; i < operands_.size(); ++i)
    {
      value[i] = operands_[i]->gradient(p, partial[i]);
    }
    const ValueGradient g = gradient_.eval(value[0], value[1], value[2], value[3]);
    grad = { 0, 0, 0 };
    for (std::size_t i = 0; i < operands_.size(); ++i)
    {
      for (int a = 0; a < 3; ++a)
      {
        grad[a] += g.gradient[i] * partial[i][a];
      }
    }
    return g.value;
  }

private:
  /// v moved outwards by a few ulps (and an absolute hair at 0): the point evaluation rounds.
  static double widened(double v, int direction)
  {
    return v + direction * (8 * std::numeric_limits<double>::epsilon() * std::abs(v) + 1e-300);
  }

  std::vector<std::unique_ptr<FieldEvaluator>> operands_;
  std::vector<int> monotone_;
  PointEvaluator point_;
  BatchEvaluator<double> batch_;
  IntervalEvaluator interval_;
  GradientEvaluator gradient_;
  std::vector<double> scratch_;
};

class ComposedField final : public Field
{
public:
  ComposedField(TapePtr g, std::vector<FieldPtr> operands, std::vector<int> monotone)
    : g_(std::move(g))
    , operands_(std::move(operands))
    , monotone_(std::move(monotone))
  {
  }
  std::unique_ptr<FieldEvaluator> evaluator() const override
  {
    std::vector<std::unique_ptr<FieldEvaluator>> parts;
    for (const auto& f : operands_)
    {
      parts.push_back(f->evaluator());
    }
    return std::make_unique<ComposedFieldEvaluator>(g_, std::move(parts), monotone_);
  }

private:
  TapePtr g_;
  std::vector<FieldPtr> operands_;
  std::vector<int> monotone_;
};

/// The stand-in of operand i as a shape, for Operations.h's functions.
Shape operand(Axis a)
{
  return Shape(Expr::variable(a), Domain::XYZT);
}

} // namespace

FieldPtr composedField(const Expr& g, std::vector<FieldPtr> operands, std::vector<int> monotone)
{
  if (operands.empty() || operands.size() > AxisCount)
  {
    throw std::invalid_argument(
      "composedField: needs one to four operands (got " + std::to_string(operands.size()) + ")");
  }
  for (std::size_t i = 0; i < operands.size(); ++i)
  {
    if (!operands[i])
    {
      throw std::invalid_argument(
        "composedField: operand " + std::to_string(i) + " is a null field");
    }
  }
  if ((g.axesUsed() >> operands.size()) != 0)
  {
    throw std::invalid_argument("composedField: the combination uses an operand beyond the " +
      std::to_string(operands.size()) + " given");
  }
  if (!monotone.empty() && monotone.size() != operands.size())
  {
    throw std::invalid_argument("composedField: monotone needs one entry per operand");
  }
  // Monotone in some operands only: the corners are not the extremes; use intervals alone.
  if (std::find(monotone.begin(), monotone.end(), 0) != monotone.end())
  {
    monotone.clear();
  }
  return std::make_shared<ComposedField>(
    Tape::compile(g), std::move(operands), std::move(monotone));
}

FieldPtr uniteFields(FieldPtr a, FieldPtr b, double alpha)
{
  const Expr g = unite(operand(Axis::X), operand(Axis::Y), alpha).function();
  return composedField(g, { std::move(a), std::move(b) }, { 1, 1 });
}

FieldPtr intersectFields(FieldPtr a, FieldPtr b, double alpha)
{
  const Expr g = intersect(operand(Axis::X), operand(Axis::Y), alpha).function();
  return composedField(g, { std::move(a), std::move(b) }, { 1, 1 });
}

FieldPtr subtractFields(FieldPtr a, FieldPtr b, double alpha)
{
  const Expr g = subtract(operand(Axis::X), operand(Axis::Y), alpha).function();
  return composedField(g, { std::move(a), std::move(b) }, { 1, -1 });
}

FieldPtr boundedBlendFields(
  FieldPtr a, FieldPtr b, FieldPtr bound, double a1, double a2, double a3, double a0)
{
  return composedField(
    boundedBlend(operand(Axis::X), operand(Axis::Y), operand(Axis::Z), a1, a2, a3, a0).function(),
    { std::move(a), std::move(b), std::move(bound) });
}

} // namespace ictk::frep
