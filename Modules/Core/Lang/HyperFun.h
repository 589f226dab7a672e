// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The HyperFun language (.hf): reader (text -> FRep DAG) and writer (FRep DAG -> text).

#include "FRep/Hypervolume.h"
#include "Lang/Diagnostics.h"

#include <string>
#include <vector>

namespace ictk::lang
{

/// A HyperFun model compiled to the FRep kernel.
struct HyperFunModel
{
  std::string name;        ///< the function that defines the model
  int parameterCount = 0;  ///< size of its parameter array (`a[n]`): Expr::parameter slots 0..n-1
  frep::Hypervolume model; ///< geometry on the domain given by the size of its coordinate array
                           ///< (x[2] XY, x[3] XYZ, x[4] XYZT), attributes set by the model
};

/// Compiles HyperFun source text; `fileName` is used in diagnostics. The model is the function
/// named `function`, or when empty the one HyperFun's interpreter evaluates: `my_model`, else
/// the file's first function. With `parameterValues` the model
/// is specialised to them: its parameter array holds those constants, so parameters may also stand
/// where HyperFun's library needs numbers (a radius, a centre); without, the parameters are slots
/// (Expr::parameter) set at evaluation time, and such library arguments are an error that says so.
/// Throws ParseError.
HyperFunModel readHyperFun(const std::string& text, const std::string& fileName,
  const std::string& function = {}, const Limits& limits = {},
  const std::vector<double>& parameterValues = {});
/// Reads and compiles a file. Throws ParseError (also for an unreadable or too large file).
HyperFunModel readHyperFunFile(const std::string& path, const std::string& function = {},
  const Limits& limits = {}, const std::vector<double>& parameterValues = {});

/// Prints a hypervolume as a HyperFun model that reads back to the same field (bit-identical
/// values on the point evaluator) and attributes. `parameterCount` sizes the `a` array.
std::string writeHyperFun(
  const frep::Hypervolume& model, const std::string& name = "model", int parameterCount = 0);

} // namespace ictk::lang
