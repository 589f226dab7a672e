// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The declarative form of an implicit complex (.json, documented in docs/complex-json.md): cells
// with HyperFun fields, attribute functions, and the boundary and containment relations. The IC
// model language (.icm) produces the same objects.

#include "Complex/Complex.h"
#include "Lang/Diagnostics.h"

#include <string>

namespace ictk::lang
{

/// True for paths ending in .json (case-insensitive).
bool isComplexFile(const std::string& path);

/// Reads a complex from JSON text; `fileName` names the file in diagnostics and is the base of
/// relative paths inside it. Throws ParseError with every problem found (file:line:col where the
/// position is known: JSON syntax, the cell an error belongs to, HyperFun errors inside fields).
complex::Complex readComplexJson(
  const std::string& text, const std::string& fileName, const Limits& limits = {});
/// Reads a .json complex file; an unreadable or too large file is a ParseError too.
complex::Complex readComplexFile(const std::string& path, const Limits& limits = {});

} // namespace ictk::lang
