// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// HyperFun syntax tree -> FRep expression DAG, by symbolic interpretation: every scalar variable
// holds an Expr, arrays hold vectors of Exprs, loops run at compile time and branches on
// coordinates or parameters become select nodes. The semantics (operators, R-functions with
// HyperFun's default ALPHA = 0, EPS = 1e-6 truth tests, library argument orders) follow the
// HyperFun interpreter; HyperFunCompiler.cxx documents each choice and the source it comes from.

#include "Lang/HyperFun.h"
#include "Lang/HyperFunParser.h"

namespace ictk::lang::hf
{

/// Compiles the function named `function` (lower-cased comparison), or the last one when empty.
/// With `parameterValues`, the parameter array holds those constants (a specialised model);
/// otherwise it holds parameter slots. Errors go to `sink`; the result is meaningful only when the
/// sink stays empty.
HyperFunModel compile(const Program& program, DiagnosticSink& sink, const std::string& function,
  const Limits& limits, const std::vector<double>& parameterValues = {});

} // namespace ictk::lang::hf
