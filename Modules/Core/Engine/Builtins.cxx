// SPDX-License-Identifier: BSD-3-Clause
#include "Engine/Builtins.h"

#include <map>

namespace ictk::engine
{

namespace
{

/// An entry of a table as the check sees it: its id, the layer that computes it, its name.
struct Entry
{
  std::size_t id;
  int layer;
  const char* name;
};

/// An implementation table: the ids it implements, the layer it is, its name for the messages.
struct Implementation
{
  std::vector<std::size_t> ids;
  int layer;
  const char* who;
};

template <class Id>
std::vector<std::size_t> indices(const std::vector<Id>& ids)
{
  std::vector<std::size_t> out;
  for (const Id id : ids)
    out.push_back(static_cast<std::size_t>(id));
  return out;
}

/// Appends the disagreements between a table (`what`, with `count` ids) and its implementations.
void checkTable(const std::vector<Entry>& table, std::size_t count, const std::string& what,
  const std::vector<Implementation>& implementations, std::vector<std::string>& problems)
{
  if (table.size() != count)
    problems.push_back(what + " has " + std::to_string(table.size()) + " entries for " +
      std::to_string(count) + " ids");
  for (std::size_t i = 0; i < table.size(); ++i)
    if (table[i].id != i)
      problems.push_back(std::string("the entry ") + table[i].name + " is out of order");
  std::map<std::size_t, int> implemented;
  for (const Implementation& by : implementations)
    for (const std::size_t i : by.ids)
    {
      if (i >= table.size())
      {
        problems.push_back(std::string(by.who) + " implements the id " + std::to_string(i) +
          ", which has no entry in " + what);
        continue;
      }
      if (table[i].layer != by.layer)
        problems.push_back(std::string(by.who) + " implements " + table[i].name +
          ", which the table gives to the other layer");
      if (++implemented[i] > 1)
        problems.push_back(std::string(table[i].name) + " is implemented twice");
    }
  for (std::size_t i = 0; i < table.size(); ++i)
    if (!implemented.count(i))
      problems.push_back(std::string(table[i].name) + " has no implementation");
}

} // namespace

std::vector<std::string> implementationProblems()
{
  using lang::icm::BuiltinId;
  using lang::icm::BuiltinLayer;
  std::vector<std::string> problems;
  std::vector<Entry> builtins;
  for (const lang::icm::Builtin& b : lang::icm::builtins())
    builtins.push_back({ static_cast<std::size_t>(b.id), static_cast<int>(b.layer), b.call.name });
  checkTable(builtins, static_cast<std::size_t>(BuiltinId::Count), "the table",
    { { indices(interpreterBuiltins()), static_cast<int>(BuiltinLayer::Math), "the interpreter" },
      { indices(libraryBuiltins()), static_cast<int>(BuiltinLayer::Library),
        "the model's library" } },
    problems);
  // The shape constructors have one layer: building a cell's `shape =`.
  std::vector<Entry> shapes;
  for (const lang::icm::ShapeBuiltin& b : lang::icm::shapeBuiltins())
    shapes.push_back({ static_cast<std::size_t>(b.id), 0, b.call.name });
  checkTable(shapes, static_cast<std::size_t>(lang::icm::ShapeId::Count),
    "the table of shape constructors",
    { { indices(shapeConstructors()), 0, "the model's shape builder" } }, problems);
  return problems;
}

} // namespace ictk::engine
