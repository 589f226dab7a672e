// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Text written into XML by hand (the FRep XML writer, the .pvd index of a time series): one rule
// for a double-quoted attribute value, so that every file ICTK writes reads back as written.

#include <string>

namespace ictk::lang
{

/// `value` for a double-quoted XML attribute: `& < > "` as entities, tab, newline and carriage
/// return as character references (a parser normalises literal white space in attributes).
/// Throws std::invalid_argument ("<what> contains a control character, ...") for the other
/// control characters, which XML 1.0 cannot carry.
std::string xmlAttribute(const std::string& value, const std::string& what);

} // namespace ictk::lang
