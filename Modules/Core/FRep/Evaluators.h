// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The four evaluators of a tape. Each evaluator owns its scratch memory and is not thread-safe;
// give each thread its own (a tape is immutable and shared freely).

#include "FRep/Interval.h"
#include "FRep/Tape.h"

#include <array>
#include <vector>

namespace ictk::frep
{

/// Evaluates one point in double precision.
class PointEvaluator
{
public:
  explicit PointEvaluator(TapePtr tape, const std::vector<double>& parameters = {});
  void setParameters(const std::vector<double>& parameters);
  /// The first output at (x, y, z, t).
  double eval(double x, double y, double z = 0, double t = 0);
  /// Every output at p; `out` has tape->outputs().size() entries.
  void evalAll(const std::array<double, 4>& p, double* out);
  const TapePtr& tape() const { return tape_; }

private:
  TapePtr tape_;
  std::vector<double> slots_;
};

/// Evaluates arrays of points; each instruction runs as one loop over a chunk of points, so the
/// compiler vectorises it. T is float or double.
template <typename T>
class BatchEvaluator
{
public:
  static constexpr std::size_t ChunkSize = 256;

  explicit BatchEvaluator(TapePtr tape, const std::vector<double>& parameters = {});
  void setParameters(const std::vector<double>& parameters);
  /// out[i] = first output at (x[i], y[i], z[i], t[i]); any of the coordinate pointers may be
  /// null for an axis the tape does not use.
  void eval(const T* x, const T* y, const T* z, const T* t, T* out, std::size_t n);
  /// One grid row: points (x0 + (first + i) dx, y, z, t) for i < n, the coordinates computed in
  /// double exactly so. Instructions that do not depend on x run once for the row. Gives the same
  /// values as eval() on those points.
  void evalRowX(
    double x0, double dx, std::int64_t first, double y, double z, double t, T* out, std::size_t n)
  {
    evalRowX(x0, dx, first, y, z, t, &out, 1, n);
  }
  /// The same for the first `outputCount` outputs of the tape: outputs[k] receives output k
  /// (n values each).
  void evalRowX(double x0, double dx, std::int64_t first, double y, double z, double t,
    T* const* outputs, std::size_t outputCount, std::size_t n);
  const TapePtr& tape() const { return tape_; }

private:
  /// Parameters and constants into a program's scalars, its uniform code run, its fixed values
  /// broadcast into its chunks.
  void loadValues(
    const RowProgram& program, std::vector<T>& scalars, const std::vector<T*>& chunks);
  void preparePoints();

  TapePtr tape_;
  std::vector<double> parameters_;
  // The x coordinates currently held by the row program's x slot.
  struct RowX
  {
    double x0, dx;
    std::int64_t first;
    std::size_t count;
    bool operator==(const RowX& o) const
    {
      return x0 == o.x0 && dx == o.dx && first == o.first && count == o.count;
    }
  };

  // eval(): the tape split with every axis it uses varying, so that what depends on parameters
  // and constants only runs once per binding (as JitEvaluator::eval does), not per point.
  bool pointsReady_ = false;
  RowProgram points_;
  std::vector<T> pointStorage_;
  std::vector<T*> pointSlots_;
  std::vector<T> pointScalars_;
  RowProgram row_;            // evalRowX(): the tape split along x
  std::vector<T> rowStorage_; // evalRowX(): chunkSlotCount chunks
  std::vector<T*> rowSlots_;  // evalRowX(): where each chunk slot's values are
  std::vector<T> scalars_;    // evalRowX(): one value per value id
  RowX rowX_{ 0, 0, -1, 0 };
};

/// Interval arithmetic over a region, with the choices needed to simplify the tape there.
class IntervalEvaluator
{
public:
  explicit IntervalEvaluator(TapePtr tape, const std::vector<double>& parameters = {});
  void setParameters(const std::vector<double>& parameters);
  /// An interval that encloses the first output over the region.
  Interval eval(const Region& region);
  /// The choices made by the last eval (one per instruction).
  const std::vector<Choice>& choices() const { return choices_; }
  /// The tape simplified for the region of the last eval.
  TapePtr simplified() const { return tape_->simplify(choices_); }
  const TapePtr& tape() const { return tape_; }

private:
  TapePtr tape_;
  std::vector<Interval> slots_;
  std::vector<Choice> choices_;
};

/// The tape in single-assignment form for the incremental evaluators below: every instruction
/// writes a value of its own (leaves first, then one per instruction), so a value stays valid
/// until its inputs change; with the axes each instruction depends on.
struct SsaCode
{
  explicit SsaCode(const Tape& tape);
  std::vector<Instruction> code;  ///< out and operands are value ids
  std::vector<std::uint8_t> axes; ///< per instruction: bit a set when it depends on Axis(a)
  std::uint32_t valueCount = 0;
  std::uint32_t output = 0; ///< the value id of the first output
  std::uint8_t used = 0;    ///< the axes some instruction depends on
  /// The instructions (indices into code) that depend on an axis in `changed` (bit a: Axis(a)),
  /// listed when first asked, so that an eval runs them without testing the others.
  const std::vector<std::uint32_t>& dependents(unsigned changed);
  /// Calls run(i) for every instruction i that depends on an axis in `changed`, in order (`all`:
  /// for every instruction, those of constants and parameters alone too, as an evaluator's first
  /// eval needs): when every axis changed, by testing each instruction's axes (a list would only
  /// add an indirection), else from the list.
  template <typename Run>
  [[gnu::always_inline]] void forEachDependent(unsigned changed, bool all, Run&& run)
  {
    if (all)
    {
      for (std::size_t i = 0; i < code.size(); ++i)
      {
        run(i);
      }
      return;
    }
    if ((changed & used) == used)
    {
      for (std::size_t i = 0; i < code.size(); ++i)
      {
        if (axes[i] & changed)
        {
          run(i);
        }
      }
      return;
    }
    for (const std::uint32_t i : dependents(changed))
    {
      run(i);
    }
  }

private:
  std::array<std::vector<std::uint32_t>, 16> dependents_;
  std::uint16_t listed_ = 0; ///< bit m: dependents_[m] is made
};

/// The same enclosures and choices as IntervalEvaluator, for regions that often differ from the
/// last one in some axes only (the pieces of one ray along a coordinate axis, neighbouring rays
/// of an axis-aligned view): instructions that depend on no axis that changed keep their value
/// and choice from the last eval. Each instruction keeps a value of its own (no register reuse),
/// so it is for tapes that are evaluated many times in a row, not for pruned tapes of a few uses.
class IncrementalIntervalEvaluator
{
public:
  explicit IncrementalIntervalEvaluator(TapePtr tape, const std::vector<double>& parameters = {});
  /// New parameter values; the next eval runs every instruction.
  void setParameters(const std::vector<double>& parameters);
  Interval eval(const Region& region);
  const std::vector<Choice>& choices() const { return choices_; }
  TapePtr simplified() const { return tape_->simplify(choices_); }
  const TapePtr& tape() const { return tape_; }

private:
  TapePtr tape_;
  SsaCode ssa_;
  std::vector<Interval> values_;
  std::vector<Choice> choices_;
  bool first_ = true;
};

/// The same values as PointEvaluator, reusing the instructions that depend on no coordinate
/// that changed since the last eval (the points of one ray along a coordinate axis).
class IncrementalPointEvaluator
{
public:
  explicit IncrementalPointEvaluator(TapePtr tape, const std::vector<double>& parameters = {});
  /// New parameter values; the next eval runs every instruction.
  void setParameters(const std::vector<double>& parameters);
  double eval(double x, double y, double z = 0, double t = 0);
  const TapePtr& tape() const { return tape_; }

private:
  TapePtr tape_;
  SsaCode ssa_;
  std::vector<double> values_;
  bool first_ = true;
};

/// Value and gradient (d/dx, d/dy, d/dz, d/dt) by forward-mode differentiation.
struct ValueGradient
{
  double value = 0;
  std::array<double, 4> gradient{};
};

class GradientEvaluator
{
public:
  explicit GradientEvaluator(TapePtr tape, const std::vector<double>& parameters = {});
  void setParameters(const std::vector<double>& parameters);
  ValueGradient eval(double x, double y, double z = 0, double t = 0);
  const TapePtr& tape() const { return tape_; }

private:
  TapePtr tape_;
  std::vector<ValueGradient> slots_;
};

namespace detail
{
/// The interval counterpart of one opcode, as the interval evaluators apply it: an enclosure of
/// the point values over operands in a, b, c, and the choice a min, max or select can make.
Interval intervalOperation(
  Opcode op, const Interval& a, const Interval& b, const Interval& c, Choice& choice);
/// The same without the fast paths for plain operands (finite, ordered, no NaN): the reference
/// the fast paths must match bit for bit (Testing/Core/TestEvaluators.cxx).
Interval intervalOperationReference(
  Opcode op, const Interval& a, const Interval& b, const Interval& c, Choice& choice);
} // namespace detail

/// Outward unit normal n = -grad f / |grad f| (thesis L608-L610); zero where the gradient vanishes.
std::array<double, 3> outwardNormal(const ValueGradient& g);

} // namespace ictk::frep
