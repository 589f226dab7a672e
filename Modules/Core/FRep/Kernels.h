// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Internal to the FRep library: the arithmetic of each opcode, shared by every evaluator so that
// point, row and batch evaluation give bit-identical results.

#include "FRep/Expr.h"

#include <cmath>

namespace ictk::frep::detail
{

// min/max written as comparisons (not fmin/fmax) so that loops over them vectorise; on ties
// the first operand is returned, which the interval evaluator's choices rely on.
template <typename T>
inline T minOp(T a, T b)
{
  return b < a ? b : a;
}
template <typename T>
inline T maxOp(T a, T b)
{
  return a < b ? b : a;
}
template <typename T>
inline T signOp(T a)
{
  return a > T(0) ? T(1) : (a < T(0) ? T(-1) : T(0));
}

/// Opcode::CauchySegment: the integral of 1 / (1 + v + tau^2)^2 over tau in [-u, length - u],
/// with P^2 = 1 + v and w = length - u,
///   u / (2 P^2 (P^2 + u^2)) + w / (2 P^2 (P^2 + w^2)) + (atan(u / P) + atan(w / P)) / (2 P^3).
/// For v >= 0 the four terms add up to at most (1/2 + pi/2) / P^3 in magnitude, which bounds the
/// rounding error (the interval evaluator widens by it). Out of line (Expr.cxx), compiled once
/// for the baseline instruction set: inlined into the batch kernels that are also compiled for
/// FMA, its products and sums would be fused there and differ from the point values in the last
/// bits.
double cauchySegment(double u, double v, double length);
float cauchySegment(float u, float v, float length);

template <typename T>
inline T applyScalar(Opcode op, T a, T b, T c)
{
  switch (op)
  {
    case Opcode::Neg:
      return -a;
    case Opcode::Abs:
      return std::abs(a);
    case Opcode::Sqrt:
      return std::sqrt(a);
    case Opcode::Square:
      return a * a;
    case Opcode::Exp:
      return std::exp(a);
    case Opcode::Log:
      return std::log(a);
    case Opcode::Sin:
      return std::sin(a);
    case Opcode::Cos:
      return std::cos(a);
    case Opcode::Tan:
      return std::tan(a);
    case Opcode::Asin:
      return std::asin(a);
    case Opcode::Acos:
      return std::acos(a);
    case Opcode::Atan:
      return std::atan(a);
    case Opcode::Sign:
      return signOp(a);
    case Opcode::Floor:
      return std::floor(a);
    case Opcode::Add:
      return a + b;
    case Opcode::Sub:
      return a - b;
    case Opcode::Mul:
      return a * b;
    case Opcode::Div:
      return a / b;
    case Opcode::Min:
      return minOp(a, b);
    case Opcode::Max:
      return maxOp(a, b);
    case Opcode::Pow:
      return std::pow(a, b);
    case Opcode::Atan2:
      return std::atan2(a, b);
    case Opcode::Select:
      return a >= T(0) ? b : c;
    case Opcode::CauchySegment:
      return cauchySegment(a, b, c);
    default:
      return T(0);
  }
}

} // namespace ictk::frep::detail
