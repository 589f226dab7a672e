// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The IC model language (.icm): the concrete form of the thesis' notation for dynamic implicit
// complexes (time spans, events, cells, attributes, templates, instances, relations, state
// parameters, reactions, predicates, functions). docs/icm.md has the grammar and the library.
//
// This is the front end only: syntax and semantic checks, producing a syntax tree with source
// positions. Inline HyperFun shapes are kept as text with their position, to be compiled with
// readHyperFun (the text and its line and column are in icm::Property).

#include "Lang/Diagnostics.h"
#include "Lang/IcmAst.h"

#include <string>

namespace ictk::lang
{

using IcmModel = icm::Model;

/// Parses and checks a model; `fileName` is used in diagnostics. Throws ParseError with every
/// error found (up to Limits::maxDiagnostics): syntax errors, undefined or duplicate names, wrong
/// relation arity, non-numeric priorities, unknown built-ins and wrong argument counts.
IcmModel readIcm(const std::string& text, const std::string& fileName, const Limits& limits = {});
/// Reads a file and calls readIcm; the model's `directory` is the file's folder.
IcmModel readIcmFile(const std::string& path, const Limits& limits = {});

/// The thesis' notation as printed (the normalised fixtures): the same grammar, but `...` and a
/// lone `:` are accepted as placeholders, the type names and method calls of its pseudo-code are
/// not checked, and no semantic checks are made. Throws ParseError on syntax errors.
IcmModel parseIcmNotation(
  const std::string& text, const std::string& fileName, const Limits& limits = {});

/// The semantic checks alone, on a parsed model (appends to `out`, at most
/// `limits.maxDiagnostics`). Inline HyperFun shapes are compiled with readHyperFun, and their
/// errors are reported at their place in the model text.
/// The file a model's `loadMesh("path", ...)` names: `path` itself when absolute, else relative to
/// the model's folder (IcmModel::directory, or the folder of its fileName before readIcmFile sets
/// it, as when the checker reads it).
std::string modelFilePath(const IcmModel& model, const std::string& path);

void checkIcm(const IcmModel& model, const std::string& text, std::vector<Diagnostic>& out,
  const Limits& limits = {});

} // namespace ictk::lang
