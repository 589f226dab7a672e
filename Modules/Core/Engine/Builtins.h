// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The engine's implementations of the built-in library against its one table
// (Lang/IcmBuiltins.h): the interpreter computes the Math entries, the running model the Library
// entries, and building a cell's `shape =` the shape constructors. Each side keeps a table keyed
// by the table's id (lang::icm::BuiltinId, lang::icm::ShapeId); implementationProblems() says where
// the tables and the library disagree, and a test (TestEngine) requires it to say nothing, so a
// built-in added to the table without an implementation, or implemented without an entry, fails
// the suite.

#include "Lang/IcmBuiltins.h"

#include <iterator>
#include <string>
#include <type_traits>
#include <vector>

namespace ictk::engine
{

/// The built-ins the interpreter computes (Interpreter.cxx), in its table's order.
std::vector<lang::icm::BuiltinId> interpreterBuiltins();
/// The built-ins the running model computes (the library calls of DynamicModel), in its order.
std::vector<lang::icm::BuiltinId> libraryBuiltins();
/// The shape constructors the model builds (ModelShapes.cxx), in its order.
std::vector<lang::icm::ShapeId> shapeConstructors();
/// The ids of an implementation table (pairs of an id and a function), in its order.
template <class Table>
auto idsOf(const Table& table)
{
  std::vector<std::decay_t<decltype(std::begin(table)->first)>> ids;
  for (const auto& entry : table)
    ids.push_back(entry.first);
  return ids;
}

/// One line per disagreement: an entry with no implementation, an implementation of an id with
/// no entry or of an entry of the other layer, or two implementations of one entry, for the
/// built-ins and for the shape constructors. Empty when the engine implements exactly the tables.
std::vector<std::string> implementationProblems();

} // namespace ictk::engine
