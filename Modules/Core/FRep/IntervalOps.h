// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The kernel's interval arithmetic one operation at a time: what IntervalEvaluator computes for an
// instruction (outward rounding by one ulp where the result is not exact, possible NaN tracked).
// For code that encloses fields written by hand rather than as tapes (Geometry's analytic shape
// parts), so that every enclosure in the toolkit rounds the same way.

#include "FRep/Expr.h"
#include "FRep/Interval.h"

namespace ictk::frep
{

/// The enclosure of op(a, b, c) for every value of the operands in their intervals (unary
/// operations read only a, binary ones a and b).
Interval intervalOf(Opcode op, const Interval& a, const Interval& b = {}, const Interval& c = {});

} // namespace ictk::frep
