// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Recursive-descent parser of the IC model language (grammar in docs/icm.md). Errors are
// collected (several per run): after one, the parser skips to the next ';' or to the end of the
// enclosing braced item and goes on. Nesting and the number of tokens and nodes are bounded by
// Limits, so no input can make it recurse or allocate without bound.

#include "Lang/Diagnostics.h"
#include "Lang/HyperFunLexer.h"
#include "Lang/IcmAst.h"

#include <vector>

namespace ictk::lang::icm
{

/// Parses `source`; errors go to `sink`. With `notation` the thesis' placeholders (`...`, a lone
/// `:`) are accepted.
Model parse(
  const hf::SourceText& source, hf::DiagnosticSink& sink, const Limits& limits, bool notation);

} // namespace ictk::lang::icm
