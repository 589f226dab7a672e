// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Internal to the FRep library: register allocation shared by Tape and its row programs.

#include "FRep/Tape.h"

namespace ictk::frep::detail
{

/// opcodeArity, inline (the enumeration is ordered: leaves, unary, binary, ternary).
inline int arity(Opcode op)
{
  if (op >= Opcode::Add)
  {
    return op >= Opcode::Select ? 3 : 2;
  }
  return op >= Opcode::Neg ? 1 : 0;
}

struct SsaOp
{
  Opcode op;
  std::uint32_t result;
  std::uint32_t operand[3];
};

/// Linear-scan allocation of `ssa` into slots >= firstFree, reusing a slot once its value is dead.
/// `slotOfValue` maps value ids to slots: it must hold the operands that are not results of `ssa`
/// (leaves), and receives the results. Values in `pinned` are never released. Returns the slot
/// count.
std::uint32_t allocateRegisters(const std::vector<SsaOp>& ssa, std::uint32_t firstFree,
  const std::vector<std::uint32_t>& pinned, std::vector<Instruction>& code,
  std::vector<std::uint32_t>& slotOfValue);

} // namespace ictk::frep::detail
