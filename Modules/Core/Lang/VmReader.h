// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The .vm format of the Fidget project's benchmark models: one SSA instruction per line,
// `_ID OPCODE ARGS...`, the last instruction being the result, negative inside. Read into the FRep
// kernel NEGATED, so that f >= 0 inside as everywhere in ICTK.
//
//   # a comment
//   _0 var-x
//   _1 const 0.5
//   _2 sub _0 _1
//
// Opcodes: const NUMBER; var-x, var-y, var-z; neg, square, sqrt, abs, exp, ln, sin, cos (one
// operand); add, sub, mul, div, min, max (two operands). Operands name earlier instructions.

#include "FRep/Expr.h"
#include "Lang/Diagnostics.h"

#include <cstddef>
#include <string>

namespace ictk::lang
{

struct VmModel
{
  /// The FRep field: minus the value of the file's last instruction.
  frep::Expr function;
  /// The value of the last instruction as written in the file (negative inside).
  frep::Expr raw;
  /// Number of instructions (non-blank, non-comment lines).
  std::size_t instructionCount = 0;
  /// Bit i set when the file uses coordinate i (x, y, z).
  std::uint8_t axesUsed = 0;
};

/// Parses .vm text; `fileName` names the source in diagnostics. Throws ParseError with every
/// error found (up to limits.maxDiagnostics), each at its line and column.
VmModel readVm(
  const std::string& text, const std::string& fileName = {}, const Limits& limits = {});
/// Reads and parses a file. Throws ParseError (also for an unreadable or too large file).
VmModel readVmFile(const std::string& path, const Limits& limits = {});

} // namespace ictk::lang
