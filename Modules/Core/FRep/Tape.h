// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// A model compiled to a flat tape: SSA instructions in evaluation order, register-allocated into a
// small set of slots so that batch evaluation touches little memory (libfive/Fidget style).

#include "FRep/Expr.h"

#include <cstdint>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

namespace ictk::frep
{

/// One tape instruction, reading and writing slots. Slots [0, 4) hold x, y, z, t; then the
/// parameters; then the constants; then temporaries.
struct Instruction
{
  Opcode op;
  std::uint32_t out;
  std::uint32_t a;
  std::uint32_t b;
  std::uint32_t c;
};

/// A tape split for evaluation along grid rows: instructions that do not depend on the varying
/// axes run once per row in scalar form; the rest run per point over chunks.
struct RowProgram
{
  struct Output
  {
    bool varying; ///< true: a chunk slot; false: a scalar slot (constant along the row)
    std::uint32_t slot;
  };
  /// Scalar code over value ids (slots [0, 4) x, y, z, t; parameters; constants; temporaries).
  std::vector<Instruction> uniform;
  std::uint32_t scalarSlotCount = 0;
  /// (scalar slot, chunk slot): uniform values that per-point code reads, copied once per row.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> broadcasts;
  /// The same for values that depend on no coordinate (constants, parameters): copied once.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> fixedBroadcasts;
  /// Per-point code over chunk slots. An operand with the ScalarOperand bit set is a uniform value
  /// read from the scalar slots (value id = operand without the bit): add, sub, mul, div, min and
  /// max take one operand that way instead of a broadcast chunk, which saves the memory traffic.
  static constexpr std::uint32_t ScalarOperand = 0x80000000u;
  std::vector<Instruction> varying;
  std::uint32_t chunkSlotCount = 0;
  /// Chunk slot of each varying axis.
  std::uint32_t axisSlots[4] = { 0, 0, 0, 0 };
  std::vector<Output> outputs;
};

/// SSA form of a tape instruction; operands are value ids (leaf slots, then
/// Tape::temporaryBase() + instruction index).
struct TapeSsa
{
  Opcode op;
  std::uint32_t a, b, c;
};

/// What interval evaluation learned about a min, max or select over a region.
enum class Choice : std::uint8_t
{
  Both,   ///< either operand may win
  First,  ///< min/max: operand a always wins; select: the condition is always >= 0
  Second, ///< min/max: operand b always wins; select: the condition is always < 0
};

class Tape : public std::enable_shared_from_this<Tape>
{
public:
  /// Compiles one or more outputs into one tape (shared sub-expressions are computed once).
  static std::shared_ptr<const Tape> compile(const std::vector<Expr>& outputs);
  static std::shared_ptr<const Tape> compile(const Expr& output);

  const std::vector<Instruction>& instructions() const { return instructions_; }
  std::uint32_t slotCount() const { return slotCount_; }
  std::uint32_t parameterBase() const { return 4; }
  std::uint32_t parameterCount() const { return parameterCount_; }
  std::uint32_t constantBase() const { return 4 + parameterCount_; }
  const std::vector<double>& constants() const { return constants_; }
  /// First temporary slot (everything below is an input, parameter or constant).
  std::uint32_t temporaryBase() const
  {
    return constantBase() + static_cast<std::uint32_t>(constants_.size());
  }
  /// The slot that holds each output after evaluation.
  const std::vector<std::uint32_t>& outputs() const { return outputs_; }
  /// Bit i set when some output depends on Axis(i).
  std::uint8_t axesUsed() const { return axesUsed_; }
  /// Number of min, max and select instructions: what interval pruning can cut.
  std::size_t choiceCount() const { return choiceCount_; }

  /// A shorter tape that gives identical results wherever `choices` hold (one entry per
  /// instruction, as filled by IntervalEvaluator). Returns this tape's twin when nothing is cut.
  std::shared_ptr<const Tape> simplify(const std::vector<Choice>& choices) const;

  /// A min or max at the root of the first output: an intersection or union of two solids, whose
  /// boundaries meet in sharp edges. The operator and a tape for each operand (parameters
  /// numbered as here); nullopt when the output is computed otherwise.
  struct Split
  {
    Opcode op;
    std::shared_ptr<const Tape> a;
    std::shared_ptr<const Tape> b;
  };
  std::optional<Split> split() const;

  /// Splits the tape for rows along which only `varyingAxes` (a mask of axes) change.
  RowProgram rowProgram(std::uint8_t varyingAxes) const;

private:
  Tape() = default;
  /// The tape of `outputValues` with every value v read as alias[v], without the instructions
  /// no output reaches.
  std::shared_ptr<const Tape> extract(
    const std::vector<std::uint32_t>& alias, const std::vector<std::uint32_t>& outputValues) const;
  static std::shared_ptr<const Tape> build(std::uint32_t parameterCount,
    std::vector<double> constants, std::vector<TapeSsa> ssa,
    std::vector<std::uint32_t> outputValues);

  std::uint32_t parameterCount_ = 0;
  std::vector<double> constants_;
  std::vector<TapeSsa> ssa_;
  std::vector<std::uint8_t> axes_; // axes each value depends on
  std::vector<std::uint32_t> outputValues_;
  std::vector<Instruction> instructions_;
  std::vector<std::uint32_t> outputs_;
  std::uint32_t slotCount_ = 0;
  std::uint8_t axesUsed_ = 0;
  std::size_t choiceCount_ = 0;
};

using TapePtr = std::shared_ptr<const Tape>;

} // namespace ictk::frep
