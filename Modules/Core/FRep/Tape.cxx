// SPDX-License-Identifier: BSD-3-Clause
#include "FRep/Tape.h"

#include "FRep/TapeDetail.h"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <unordered_map>
#include <unordered_set>

namespace ictk::frep
{

namespace detail
{
std::uint32_t allocateRegisters(const std::vector<SsaOp>& ssa, std::uint32_t firstFree,
  const std::vector<std::uint32_t>& pinned, std::vector<Instruction>& code,
  std::vector<std::uint32_t>& slotOfValue)
{
  constexpr auto never = std::numeric_limits<std::size_t>::max();
  constexpr auto unused = never - 1;
  // lastUse[v]: index of the last instruction reading value v; pinned values live to the end.
  // Value ids are dense (below slotOfValue.size()), so a vector is enough: this runs for every
  // pruned tape, so it must be cheap.
  std::vector<std::size_t> lastUse(slotOfValue.size(), unused);
  // Operands flagged RowProgram::ScalarOperand are not values of this allocation: they pass
  // through unchanged.
  constexpr std::uint32_t scalar = RowProgram::ScalarOperand;
  for (std::size_t i = 0; i < ssa.size(); ++i)
  {
    for (int k = 0; k < detail::arity(ssa[i].op); ++k)
    {
      if (!(ssa[i].operand[k] & scalar))
      {
        lastUse.at(ssa[i].operand[k]) = i;
      }
    }
  }
  for (std::uint32_t v : pinned)
  {
    lastUse.at(v) = never;
  }
  std::vector<std::uint32_t> freeSlots; // LIFO, so the allocation is deterministic
  std::uint32_t slotCount = firstFree;
  code.clear();
  code.reserve(ssa.size());
  for (std::size_t i = 0; i < ssa.size(); ++i)
  {
    const SsaOp& op = ssa[i];
    std::uint32_t out;
    if (!freeSlots.empty())
    {
      out = freeSlots.back();
      freeSlots.pop_back();
    }
    else
    {
      out = slotCount++;
    }
    Instruction ins{ op.op, out, 0, 0, 0 };
    std::uint32_t* operands[3] = { &ins.a, &ins.b, &ins.c };
    const int arity = detail::arity(op.op);
    for (int k = 0; k < arity; ++k)
    {
      *operands[k] = (op.operand[k] & scalar) ? op.operand[k] : slotOfValue.at(op.operand[k]);
    }
    // Inputs are released after the output is allocated, so an instruction never writes the slot
    // it reads: batch kernels may then treat their pointers as non-aliasing.
    for (int k = 0; k < arity; ++k)
    {
      const std::uint32_t v = op.operand[k];
      if (v & scalar)
      {
        continue;
      }
      bool repeated = false;
      for (int j = 0; j < k; ++j)
      {
        repeated = repeated || op.operand[j] == v;
      }
      if (!repeated && lastUse[v] == i && slotOfValue.at(v) >= firstFree)
      {
        freeSlots.push_back(slotOfValue.at(v));
      }
    }
    slotOfValue.at(op.result) = out;
    code.push_back(ins);
  }
  return slotCount;
}
} // namespace detail

using detail::SsaOp;

TapePtr Tape::compile(const Expr& output)
{
  return compile(std::vector<Expr>{ output });
}

TapePtr Tape::compile(const std::vector<Expr>& outputs)
{
  if (outputs.empty())
  {
    throw std::invalid_argument("Tape::compile: no outputs");
  }
  // Post-order over all outputs, each node once.
  std::vector<Expr> order;
  std::unordered_set<const Node*> seen;
  for (const Expr& out : outputs)
  {
    out.visitPostOrder(
      [&](const Expr& e)
      {
        if (seen.insert(e.id()).second)
        {
          order.push_back(e);
        }
      });
  }
  std::uint32_t parameterCount = 0;
  std::vector<double> constants;
  for (const Expr& e : order)
  {
    if (e.opcode() == Opcode::Parameter)
    {
      parameterCount = std::max(parameterCount, e.parameterSlot() + 1);
    }
    else if (e.opcode() == Opcode::Constant)
    {
      constants.push_back(e.constantValue());
    }
  }
  const std::uint32_t constantBase = 4 + parameterCount;
  const std::uint32_t leafCount = constantBase + static_cast<std::uint32_t>(constants.size());
  std::unordered_map<const Node*, std::uint32_t> valueOf;
  std::vector<TapeSsa> ssa;
  std::uint32_t nextConstant = 0;
  for (const Expr& e : order)
  {
    std::uint32_t v;
    switch (e.opcode())
    {
      case Opcode::Variable:
        v = static_cast<std::uint32_t>(e.axis());
        break;
      case Opcode::Parameter:
        v = 4 + e.parameterSlot();
        break;
      case Opcode::Constant:
        v = constantBase + nextConstant++;
        break;
      default:
      {
        TapeSsa ins{ e.opcode(), 0, 0, 0 };
        std::uint32_t* operands[3] = { &ins.a, &ins.b, &ins.c };
        for (int k = 0; k < e.arity(); ++k)
        {
          *operands[k] = valueOf.at(e.child(k).id());
        }
        if (ins.op == Opcode::Mul && ins.a == ins.b)
        {
          // a * a evaluated as Square: the same product in IEEE arithmetic, but its interval is
          // that of a square, >= 0, where two independent factors over an interval around 0 are
          // bounded below by -|lo| hi (a sphere written x * x + y * y + z * z excludes nothing
          // next to the axes). The model keeps the product as written (its XML, its HyperFun).
          ins = { Opcode::Square, ins.a, 0, 0 };
        }
        v = leafCount + static_cast<std::uint32_t>(ssa.size());
        ssa.push_back(ins);
      }
    }
    valueOf.emplace(e.id(), v);
  }
  std::vector<std::uint32_t> outputValues;
  for (const Expr& out : outputs)
  {
    outputValues.push_back(valueOf.at(out.id()));
  }
  return build(parameterCount, std::move(constants), std::move(ssa), std::move(outputValues));
}

TapePtr Tape::build(std::uint32_t parameterCount, std::vector<double> constants,
  std::vector<TapeSsa> ssa, std::vector<std::uint32_t> outputValues)
{
  auto tape = std::shared_ptr<Tape>(new Tape);
  tape->parameterCount_ = parameterCount;
  tape->constants_ = std::move(constants);
  tape->ssa_ = std::move(ssa);
  tape->outputValues_ = std::move(outputValues);
  const std::uint32_t leafCount = tape->temporaryBase();

  // Which axes each value depends on (for axesUsed and row specialisation).
  std::vector<std::uint8_t> axes(leafCount + tape->ssa_.size(), 0);
  for (std::uint32_t a = 0; a < 4; ++a)
  {
    axes[a] = static_cast<std::uint8_t>(1u << a);
  }
  std::vector<SsaOp> ops;
  ops.reserve(tape->ssa_.size());
  for (std::size_t i = 0; i < tape->ssa_.size(); ++i)
  {
    const TapeSsa& s = tape->ssa_[i];
    const auto result = static_cast<std::uint32_t>(leafCount + i);
    ops.push_back({ s.op, result, { s.a, s.b, s.c } });
    if (s.op == Opcode::Min || s.op == Opcode::Max || s.op == Opcode::Select)
    {
      ++tape->choiceCount_;
    }
    for (int k = 0; k < detail::arity(s.op); ++k)
    {
      axes[result] |= axes[ops.back().operand[k]];
    }
  }
  tape->axes_ = axes;
  for (std::uint32_t v : tape->outputValues_)
  {
    tape->axesUsed_ |= axes[v];
  }

  std::vector<std::uint32_t> slotOfValue(leafCount + tape->ssa_.size());
  for (std::uint32_t v = 0; v < leafCount; ++v)
  {
    slotOfValue[v] = v;
  }
  tape->slotCount_ = detail::allocateRegisters(
    ops, leafCount, tape->outputValues_, tape->instructions_, slotOfValue);
  for (std::uint32_t v : tape->outputValues_)
  {
    tape->outputs_.push_back(slotOfValue[v]);
  }
  return tape;
}

TapePtr Tape::simplify(const std::vector<Choice>& choices) const
{
  if (choices.size() != ssa_.size())
  {
    throw std::invalid_argument("Tape::simplify: one choice per instruction expected");
  }
  const std::uint32_t leafCount = temporaryBase();
  // Forward pass: a decided min/max/select becomes an alias of the winning operand.
  std::vector<std::uint32_t> alias(leafCount + ssa_.size());
  for (std::uint32_t v = 0; v < leafCount; ++v)
  {
    alias[v] = v;
  }
  bool changed = false;
  for (std::size_t i = 0; i < ssa_.size(); ++i)
  {
    const TapeSsa& s = ssa_[i];
    const auto v = static_cast<std::uint32_t>(leafCount + i);
    alias[v] = v;
    if (choices[i] == Choice::Both)
    {
      continue;
    }
    if (s.op == Opcode::Min || s.op == Opcode::Max)
    {
      alias[v] = alias[choices[i] == Choice::First ? s.a : s.b];
      changed = true;
    }
    else if (s.op == Opcode::Select)
    {
      alias[v] = alias[choices[i] == Choice::First ? s.b : s.c];
      changed = true;
    }
  }
  if (!changed)
  {
    return shared_from_this();
  }
  return extract(alias, outputValues_);
}

std::optional<Tape::Split> Tape::split() const
{
  const std::uint32_t leafCount = temporaryBase();
  if (outputValues_.empty() || outputValues_[0] < leafCount)
  {
    return std::nullopt;
  }
  const TapeSsa& s = ssa_[outputValues_[0] - leafCount];
  if (s.op != Opcode::Min && s.op != Opcode::Max)
  {
    return std::nullopt;
  }
  std::vector<std::uint32_t> identity(leafCount + ssa_.size());
  for (std::uint32_t v = 0; v < identity.size(); ++v)
  {
    identity[v] = v;
  }
  return Split{ s.op, extract(identity, { s.a }), extract(identity, { s.b }) };
}

TapePtr Tape::extract(
  const std::vector<std::uint32_t>& alias, const std::vector<std::uint32_t>& outputValues) const
{
  const std::uint32_t leafCount = temporaryBase();
  // Backward pass: keep only instructions some output still reaches.
  std::vector<bool> live(leafCount + ssa_.size(), false);
  for (std::uint32_t v : outputValues)
  {
    live[alias[v]] = true;
  }
  for (std::size_t i = ssa_.size(); i-- > 0;)
  {
    const auto v = static_cast<std::uint32_t>(leafCount + i);
    if (!live[v] || alias[v] != v)
    {
      continue;
    }
    const TapeSsa& s = ssa_[i];
    const std::uint32_t operands[3] = { s.a, s.b, s.c };
    for (int k = 0; k < detail::arity(s.op); ++k)
    {
      live[alias[operands[k]]] = true;
    }
  }
  // Only the constants still read are kept (a pruned tape is often a small part of a large one, and
  // evaluators set up every constant slot).
  std::vector<std::uint32_t> renumber(leafCount + ssa_.size());
  std::vector<double> keptConstants;
  for (std::uint32_t v = 0; v < leafCount; ++v)
  {
    renumber[v] = v;
    if (v >= constantBase() && live[v])
    {
      renumber[v] = constantBase() + static_cast<std::uint32_t>(keptConstants.size());
      keptConstants.push_back(constants_[v - constantBase()]);
    }
  }
  const auto newLeafCount = constantBase() + static_cast<std::uint32_t>(keptConstants.size());
  std::vector<TapeSsa> kept;
  for (std::size_t i = 0; i < ssa_.size(); ++i)
  {
    const auto v = static_cast<std::uint32_t>(leafCount + i);
    if (!live[v] || alias[v] != v)
    {
      continue;
    }
    TapeSsa s = ssa_[i];
    s.a = renumber[alias[s.a]];
    if (detail::arity(s.op) > 1)
      s.b = renumber[alias[s.b]];
    if (detail::arity(s.op) > 2)
      s.c = renumber[alias[s.c]];
    renumber[v] = static_cast<std::uint32_t>(newLeafCount + kept.size());
    kept.push_back(s);
  }
  std::vector<std::uint32_t> outputs;
  for (std::uint32_t v : outputValues)
  {
    outputs.push_back(renumber[alias[v]]);
  }
  return build(parameterCount_, std::move(keptConstants), std::move(kept), std::move(outputs));
}

RowProgram Tape::rowProgram(std::uint8_t varyingAxes) const
{
  const std::uint32_t leafCount = temporaryBase();
  const std::size_t valueCount = leafCount + ssa_.size();
  RowProgram p;
  p.scalarSlotCount = static_cast<std::uint32_t>(valueCount);
  auto varies = [&](std::uint32_t v)
  {
    return (axes_[v] & varyingAxes) != 0;
  };

  // Uniform part: scalar code over value ids (no register reuse: it runs once per row).
  std::vector<SsaOp> varyingOps;
  for (std::size_t i = 0; i < ssa_.size(); ++i)
  {
    const TapeSsa& s = ssa_[i];
    const auto v = static_cast<std::uint32_t>(leafCount + i);
    if (!varies(v))
    {
      p.uniform.push_back({ s.op, v, s.a, s.b, s.c });
    }
    else
    {
      SsaOp op{ s.op, v, { s.a, s.b, s.c } };
      // One uniform operand of a simple binary operation is read as a scalar.
      const bool scalarForm = s.op == Opcode::Add || s.op == Opcode::Sub || s.op == Opcode::Mul ||
        s.op == Opcode::Div || s.op == Opcode::Min || s.op == Opcode::Max;
      for (int k = 0; scalarForm && k < 2; ++k)
      {
        if (!varies(op.operand[k]))
        {
          op.operand[k] |= RowProgram::ScalarOperand;
        }
      }
      varyingOps.push_back(op);
    }
  }

  // Varying part: chunk slots. The varying axes come first, then one slot per uniform value that a
  // varying instruction reads (filled by broadcast once per row), then temporaries.
  std::vector<std::uint32_t> slotOfValue(valueCount, std::numeric_limits<std::uint32_t>::max());
  std::uint32_t next = 0;
  for (std::uint32_t a = 0; a < 4; ++a)
  {
    if (varyingAxes & (1u << a))
    {
      p.axisSlots[a] = next;
      slotOfValue[a] = next++;
    }
  }
  for (const SsaOp& op : varyingOps)
  {
    for (int k = 0; k < detail::arity(op.op); ++k)
    {
      const std::uint32_t v = op.operand[k];
      if (v & RowProgram::ScalarOperand)
      {
        continue;
      }
      if (!varies(v) && slotOfValue[v] == std::numeric_limits<std::uint32_t>::max())
      {
        slotOfValue[v] = next;
        (axes_[v] ? p.broadcasts : p.fixedBroadcasts).push_back({ v, next++ });
      }
    }
  }
  std::vector<std::uint32_t> pinned;
  for (std::uint32_t v : outputValues_)
  {
    if (varies(v))
    {
      pinned.push_back(v);
    }
  }
  p.chunkSlotCount = detail::allocateRegisters(varyingOps, next, pinned, p.varying, slotOfValue);
  for (std::uint32_t v : outputValues_)
  {
    p.outputs.push_back({ varies(v), varies(v) ? slotOfValue[v] : v });
  }
  return p;
}

} // namespace ictk::frep
