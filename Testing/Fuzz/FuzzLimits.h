// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The budgets of the fuzz targets that compile HyperFun (FuzzHyperFun, and FuzzComplexJson for
// the fields of its cells): small, so that every run is fast; the limits themselves are what is
// being exercised.
#include "Lang/Diagnostics.h"

inline ictk::lang::Limits hyperFunFuzzLimits()
{
  ictk::lang::Limits limits;
  limits.maxLoopIterations = 100000;
  limits.maxExpressionNodes = 200000;
  limits.maxSyntaxNodes = 100000;
  return limits;
}
