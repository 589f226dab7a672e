// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The engine's implementations of the built-in library against its one table
// (Lang/IcmBuiltins.h): the interpreter computes the Math entries, the running model the Library
// entries. Each side keeps a table keyed by lang::icm::BuiltinId; implementationProblems() says
// where the tables and the library disagree, and a test (TestEngine) requires it to say nothing,
// so a built-in added to the table without an implementation, or implemented without an entry,
// fails the suite.

#include "Lang/IcmBuiltins.h"

#include <string>
#include <vector>

namespace ictk::engine
{

/// The built-ins the interpreter computes (Interpreter.cxx), in its table's order.
std::vector<lang::icm::BuiltinId> interpreterBuiltins();
/// The built-ins the running model computes (the library calls of DynamicModel), in its order.
std::vector<lang::icm::BuiltinId> libraryBuiltins();
/// The ids of an implementation table (pairs of BuiltinId and function), in its order.
template <class Table>
std::vector<lang::icm::BuiltinId> idsOf(const Table& table)
{
  std::vector<lang::icm::BuiltinId> ids;
  for (const auto& entry : table)
    ids.push_back(entry.first);
  return ids;
}

/// One line per disagreement: an entry with no implementation, an implementation of an id with
/// no entry or of an entry of the other layer, or two implementations of one entry. Empty when
/// the engine implements exactly the table.
std::vector<std::string> implementationProblems();

} // namespace ictk::engine
