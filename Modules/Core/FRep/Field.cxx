// SPDX-License-Identifier: BSD-3-Clause
#include "FRep/Field.h"

#include "FRep/Evaluators.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

namespace ictk::frep
{
namespace
{

class TapeFieldEvaluator final : public FieldEvaluator
{
public:
  TapeFieldEvaluator(TapePtr tape, double time, const std::vector<double>& parameters)
    : tape_(std::move(tape))
    , time_(time)
    , parameters_(parameters)
  {
  }

  void values(
    const double* x, const double* y, const double* z, double* out, std::size_t n) override
  {
    if (!batch_)
    {
      batch_ = std::make_unique<BatchEvaluator<double>>(tape_, parameters_);
    }
    if (t_.size() < n)
    {
      t_.assign(n, time_);
    }
    batch_->eval(x, y, z, t_.data(), out, n);
  }

  Interval bound(const Box3& box) override { return intervalEvaluator().eval(regionOf(box)); }

  double gradient(const Point3& p, Point3& grad) override
  {
    if (!gradient_)
    {
      gradient_ = std::make_unique<GradientEvaluator>(tape_, parameters_);
    }
    const ValueGradient vg = gradient_->eval(p[0], p[1], p[2], time_);
    grad = { vg.gradient[0], vg.gradient[1], vg.gradient[2] };
    return vg.value;
  }

  std::unique_ptr<FieldEvaluator> narrowed(const Box3& box) override
  {
    if (tape_->choiceCount() == 0)
    {
      return nullptr;
    }
    IntervalEvaluator& iv = intervalEvaluator();
    iv.eval(regionOf(box));
    TapePtr pruned = iv.simplified();
    if (pruned->instructions().size() >= tape_->instructions().size())
    {
      return nullptr;
    }
    return std::make_unique<TapeFieldEvaluator>(std::move(pruned), time_, parameters_);
  }

  bool fingerprint(std::vector<std::uint64_t>& out) const override
  {
    appendTapeFingerprint(*tape_, time_, parameters_, out);
    return true;
  }

private:
  IntervalEvaluator& intervalEvaluator()
  {
    if (!interval_)
    {
      interval_ = std::make_unique<IntervalEvaluator>(tape_, parameters_);
    }
    return *interval_;
  }

  Region regionOf(const Box3& box) const
  {
    Region r;
    for (int a = 0; a < 3; ++a)
    {
      r.axes[a] = Interval{ box.lo[a], box.hi[a] };
    }
    r.axes[3] = Interval{ time_, time_ };
    return r;
  }

  TapePtr tape_;
  double time_;
  std::vector<double> parameters_;
  std::vector<double> t_;
  std::unique_ptr<BatchEvaluator<double>> batch_;
  std::unique_ptr<IntervalEvaluator> interval_;
  std::unique_ptr<GradientEvaluator> gradient_;
};

class TapeField final : public Field
{
public:
  TapeField(TapePtr tape, double time, std::vector<double> parameters)
    : tape_(std::move(tape))
    , time_(time)
    , parameters_(std::move(parameters))
  {
  }
  std::unique_ptr<FieldEvaluator> evaluator() const override
  {
    return std::make_unique<TapeFieldEvaluator>(tape_, time_, parameters_);
  }
  std::optional<FieldSplit> split() const override
  {
    const auto s = tape_->split();
    if (!s)
    {
      return std::nullopt;
    }
    return FieldSplit{ s->op == Opcode::Min, std::make_shared<TapeField>(s->a, time_, parameters_),
      std::make_shared<TapeField>(s->b, time_, parameters_) };
  }

private:
  TapePtr tape_;
  double time_;
  std::vector<double> parameters_;
};

/// -f, or the min or max of several fields.
class CombinedFieldEvaluator final : public FieldEvaluator
{
public:
  enum class Op
  {
    Negate,
    Min,
    Max
  };
  CombinedFieldEvaluator(Op op, std::vector<std::unique_ptr<FieldEvaluator>> parts)
    : op_(op)
    , parts_(std::move(parts))
  {
  }

  void values(
    const double* x, const double* y, const double* z, double* out, std::size_t n) override
  {
    parts_[0]->values(x, y, z, out, n);
    if (op_ == Op::Negate)
    {
      std::transform(out, out + n, out, [](double v) { return -v; });
      return;
    }
    scratch_.resize(n);
    for (std::size_t k = 1; k < parts_.size(); ++k)
    {
      parts_[k]->values(x, y, z, scratch_.data(), n);
      for (std::size_t i = 0; i < n; ++i)
      {
        out[i] = combine(out[i], scratch_[i]);
      }
    }
  }

  Interval bound(const Box3& box) override
  {
    Interval r = parts_[0]->bound(box);
    if (op_ == Op::Negate)
    {
      return Interval{ -r.hi, -r.lo, r.maybeNaN };
    }
    for (std::size_t k = 1; k < parts_.size(); ++k)
    {
      const Interval b = parts_[k]->bound(box);
      r = Interval{ combine(r.lo, b.lo), combine(r.hi, b.hi), r.maybeNaN || b.maybeNaN };
    }
    return r;
  }

  double gradient(const Point3& p, Point3& grad) override
  {
    double v = parts_[0]->gradient(p, grad);
    if (op_ == Op::Negate)
    {
      grad = { -grad[0], -grad[1], -grad[2] };
      return -v;
    }
    for (std::size_t k = 1; k < parts_.size(); ++k)
    {
      Point3 g;
      const double w = parts_[k]->gradient(p, g);
      if (combine(v, w) != v)
      {
        v = w;
        grad = g;
      }
    }
    return v;
  }

  std::unique_ptr<FieldEvaluator> narrowed(const Box3& box) override
  {
    std::vector<std::unique_ptr<FieldEvaluator>> parts;
    std::vector<FieldPtr> sources;
    bool changed = false;
    if (op_ != Op::Negate && parts_.size() > 1)
    {
      // Drop the operands that can never win inside the box.
      std::vector<Interval> bounds;
      for (auto& p : parts_)
      {
        bounds.push_back(p->bound(box));
      }
      for (std::size_t k = 0; k < parts_.size(); ++k)
      {
        bool dominated = false;
        for (std::size_t j = 0; j < parts_.size() && !dominated; ++j)
        {
          if (j != k && !bounds[j].maybeNaN && !bounds[k].maybeNaN)
          {
            dominated = op_ == Op::Min ? bounds[j].hi < bounds[k].lo : bounds[j].lo > bounds[k].hi;
          }
        }
        if (dominated)
        {
          changed = true;
          continue;
        }
        auto n = parts_[k]->narrowed(box);
        changed = changed || n != nullptr;
        parts.push_back(n ? std::move(n) : sources_[k]->evaluator());
        sources.push_back(sources_[k]);
      }
    }
    else
    {
      for (std::size_t k = 0; k < parts_.size(); ++k)
      {
        auto n = parts_[k]->narrowed(box);
        changed = changed || n != nullptr;
        parts.push_back(n ? std::move(n) : sources_[k]->evaluator());
        sources.push_back(sources_[k]);
      }
    }
    if (!changed)
    {
      return nullptr;
    }
    if (parts.size() == 1 && op_ != Op::Negate)
    {
      return std::move(parts[0]);
    }
    auto e = std::make_unique<CombinedFieldEvaluator>(op_, std::move(parts));
    e->setSources(std::move(sources));
    return e;
  }

  bool fingerprint(std::vector<std::uint64_t>& out) const override
  {
    out.push_back(0x636f6d62696e6564ull); // "combined"
    out.push_back(static_cast<std::uint64_t>(op_));
    out.push_back(parts_.size());
    // Each part's words are preceded by their count, so that no two lists of parts give the
    // same words.
    auto nested = [&out](const FieldEvaluator& e)
    {
      const std::size_t at = out.size();
      out.push_back(0);
      if (!e.fingerprint(out))
      {
        return false;
      }
      out[at] = out.size() - at - 1;
      return true;
    };
    for (const auto& p : parts_)
    {
      if (!nested(*p))
      {
        return false;
      }
    }
    // narrowed() falls back on the source fields' own evaluators: they are part of what it does.
    out.push_back(sources_.size());
    for (const auto& f : sources_)
    {
      if (!nested(*f->evaluator()))
      {
        return false;
      }
    }
    return true;
  }

  // The fields the parts came from: a part that does not narrow is re-created from its field,
  // so that a narrowed evaluator never shares state with its parent.
  void setSources(std::vector<FieldPtr> sources) { sources_ = std::move(sources); }

private:
  double combine(double a, double b) const
  {
    return op_ == Op::Min ? std::min(a, b) : std::max(a, b);
  }
  Op op_;
  std::vector<std::unique_ptr<FieldEvaluator>> parts_;
  std::vector<FieldPtr> sources_;
  std::vector<double> scratch_;
};

class CombinedField final : public Field
{
public:
  CombinedField(CombinedFieldEvaluator::Op op, std::vector<FieldPtr> fields)
    : op_(op)
    , fields_(std::move(fields))
  {
    if (fields_.empty())
    {
      throw std::invalid_argument("a combination of fields needs at least one field");
    }
    for (const auto& f : fields_)
    {
      if (!f)
      {
        throw std::invalid_argument("a combination of fields was given a null field");
      }
    }
  }
  std::unique_ptr<FieldEvaluator> evaluator() const override
  {
    std::vector<std::unique_ptr<FieldEvaluator>> parts;
    for (const auto& f : fields_)
    {
      parts.push_back(f->evaluator());
    }
    auto e = std::make_unique<CombinedFieldEvaluator>(op_, std::move(parts));
    e->setSources(fields_);
    return e;
  }
  std::optional<FieldSplit> split() const override
  {
    using Op = CombinedFieldEvaluator::Op;
    if (op_ == Op::Negate)
    {
      // -min(a, b) = max(-a, -b) and -max(a, b) = min(-a, -b).
      auto s = fields_[0]->split();
      if (!s)
      {
        return std::nullopt;
      }
      return FieldSplit{ !s->minimum, negatedField(s->a), negatedField(s->b) };
    }
    if (fields_.size() == 1)
    {
      return fields_[0]->split();
    }
    FieldPtr rest = fields_.size() == 2
      ? fields_[1]
      : std::make_shared<CombinedField>(
          op_, std::vector<FieldPtr>(fields_.begin() + 1, fields_.end()));
    return FieldSplit{ op_ == Op::Min, fields_[0], std::move(rest) };
  }

private:
  CombinedFieldEvaluator::Op op_;
  std::vector<FieldPtr> fields_;
};

} // namespace

std::uint64_t fingerprintWord(double v)
{
  std::uint64_t w = 0;
  std::memcpy(&w, &v, sizeof w);
  return w;
}

void appendTapeFingerprint(const Tape& tape, double time, const std::vector<double>& parameters,
  std::vector<std::uint64_t>& out)
{
  const auto& code = tape.instructions();
  out.push_back(0x7461706500000000ull); // "tape"
  out.push_back(tape.parameterCount());
  out.push_back(tape.constants().size());
  out.push_back(code.size());
  out.push_back(tape.outputs().size());
  out.push_back(tape.slotCount());
  // The slots the tape reads: the parameters and t it does not read cannot change its results.
  std::vector<bool> read(tape.temporaryBase(), false);
  auto reads = [&](std::uint32_t slot)
  {
    if (slot < read.size())
    {
      read[slot] = true;
    }
  };
  for (const Instruction& ins : code)
  {
    out.push_back((static_cast<std::uint64_t>(ins.op) << 32) | ins.out);
    out.push_back((static_cast<std::uint64_t>(ins.a) << 32) | ins.b);
    out.push_back(ins.c);
    const int arity = opcodeArity(ins.op);
    if (arity >= 1)
    {
      reads(ins.a);
    }
    if (arity >= 2)
    {
      reads(ins.b);
    }
    if (arity >= 3)
    {
      reads(ins.c);
    }
  }
  for (std::uint32_t o : tape.outputs())
  {
    out.push_back(o);
    reads(o);
  }
  for (double c : tape.constants())
  {
    out.push_back(fingerprintWord(c));
  }
  // Which slots are read follows from the instructions above; an unread one gets a fixed word.
  constexpr std::uint64_t Unread = 0x756e72656164ull; // "unread"
  for (std::uint32_t i = 0; i < tape.parameterCount(); ++i)
  {
    out.push_back(read[tape.parameterBase() + i] && i < parameters.size()
        ? fingerprintWord(parameters[i])
        : Unread);
  }
  out.push_back(read[static_cast<std::size_t>(Axis::T)] ? fingerprintWord(time) : Unread);
}

FieldPtr tapeField(TapePtr tape, double time, std::vector<double> parameters)
{
  if (!tape)
  {
    throw std::invalid_argument("tapeField: null tape");
  }
  if (parameters.size() < tape->parameterCount())
  {
    parameters.resize(tape->parameterCount(), 0.0);
  }
  return std::make_shared<TapeField>(std::move(tape), time, std::move(parameters));
}

FieldPtr negatedField(FieldPtr f)
{
  return std::make_shared<CombinedField>(
    CombinedFieldEvaluator::Op::Negate, std::vector<FieldPtr>{ std::move(f) });
}

FieldPtr minField(std::vector<FieldPtr> fields)
{
  return std::make_shared<CombinedField>(CombinedFieldEvaluator::Op::Min, std::move(fields));
}

FieldPtr maxField(std::vector<FieldPtr> fields)
{
  return std::make_shared<CombinedField>(CombinedFieldEvaluator::Op::Max, std::move(fields));
}

} // namespace ictk::frep
