// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// A JIT backend for float batch evaluation (issue 7), optional (CMake ICTK_ENABLE_JIT, asmjit;
// library ICTK::FRepJit, which defines ICTK_HAVE_JIT for its users).
//
// The varying part of a RowProgram (Tape::rowProgram) is compiled to straight-line x86-64 code
// over one SIMD vector of points (AVX-512: 16 floats in zmm registers; AVX2: 8 in ymm), run in a
// loop over the row. Chunk slots live in registers, allocated over the instruction stream
// (furthest-next-use eviction; a value is stored to memory only when evicted while still needed).
// The uniform part runs once per row in scalar form, exactly as BatchEvaluator<float> runs it.
// neg, abs, sqrt, square, add, sub, mul, div, min, max, select, sign and floor are native SIMD
// instructions with the interpreter's semantics (NaN and signed zeros included); exp, log, sin,
// cos, tan, asin, acos, atan, pow and atan2 call the interpreter's scalar kernel (Kernels.h) per
// vector. So results are bit-identical to BatchEvaluator<float> for every opcode (tested).

#include "FRep/Render.h"

#include <cstdint>
#include <memory>
#include <vector>

namespace ictk::frep
{

struct JitOptions
{
  /// Use AVX-512 (zmm, 32 registers) when the CPU has it; false: AVX2 (ymm, 16 registers).
  bool allowAvx512 = true;
};

/// Same interface shape as BatchEvaluator<float>. One per thread; the tape is shared.
class JitEvaluator final : public RowEvaluator
{
public:
  /// True when this CPU can run the generated code (AVX2 at least).
  static bool available();

  /// Compiles the row program along x (eval()'s program is compiled on first use). Throws
  /// std::runtime_error when !available() or code generation fails.
  explicit JitEvaluator(
    TapePtr tape, const std::vector<double>& parameters = {}, const JitOptions& options = {});
  ~JitEvaluator() override;
  JitEvaluator(const JitEvaluator&) = delete;
  JitEvaluator& operator=(const JitEvaluator&) = delete;

  void setParameters(const std::vector<double>& parameters);
  /// As BatchEvaluator<float>::eval.
  void eval(
    const float* x, const float* y, const float* z, const float* t, float* out, std::size_t n);
  /// As BatchEvaluator<float>::evalRowX.
  void evalRowX(double x0, double dx, std::int64_t first, double y, double z, double t, float* out,
    std::size_t n) override;
  void evalRowX(double x0, double dx, std::int64_t first, double y, double z, double t,
    float* const* outputs, std::size_t outputCount, std::size_t n);
  const TapePtr& tape() const override;

  /// Floats per vector (16 with AVX-512, 8 with AVX2).
  int vectorWidth() const;
  /// Bytes of machine code generated for the row program.
  std::size_t codeSize() const;

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// A factory for RenderOptions::rowEvaluator that makes JitEvaluators; empty (no factory) when
/// !JitEvaluator::available(), so renders then use the interpreter.
RowEvaluatorFactory jitRowEvaluatorFactory(const JitOptions& options = {});

} // namespace ictk::frep
