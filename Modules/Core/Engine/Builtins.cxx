// SPDX-License-Identifier: BSD-3-Clause
#include "Engine/Builtins.h"

#include <map>

namespace ictk::engine
{

std::vector<std::string> implementationProblems()
{
  using lang::icm::BuiltinLayer;
  std::vector<std::string> problems;
  const auto& table = lang::icm::builtins();
  const std::size_t count = static_cast<std::size_t>(lang::icm::BuiltinId::Count);
  if (table.size() != count)
    problems.push_back("the table has " + std::to_string(table.size()) + " entries for " +
      std::to_string(count) + " ids");
  for (std::size_t i = 0; i < table.size(); ++i)
    if (static_cast<std::size_t>(table[i].id) != i)
      problems.push_back(std::string("the entry ") + table[i].call.name + " is out of order");
  std::map<std::size_t, int> implemented;
  auto check = [&](
                 const std::vector<lang::icm::BuiltinId>& ids, BuiltinLayer layer, const char* who)
  {
    for (const lang::icm::BuiltinId id : ids)
    {
      const std::size_t i = static_cast<std::size_t>(id);
      if (i >= table.size())
      {
        problems.push_back(std::string(who) + " implements the id " + std::to_string(i) +
          ", which has no entry in the table");
        continue;
      }
      if (table[i].layer != layer)
        problems.push_back(std::string(who) + " implements " + table[i].call.name +
          ", which the table gives to the other layer");
      if (++implemented[i] > 1)
        problems.push_back(std::string(table[i].call.name) + " is implemented twice");
    }
  };
  check(interpreterBuiltins(), BuiltinLayer::Math, "the interpreter");
  check(libraryBuiltins(), BuiltinLayer::Library, "the model's library");
  for (std::size_t i = 0; i < table.size(); ++i)
    if (!implemented.count(i))
      problems.push_back(std::string(table[i].call.name) + " has no implementation");
  return problems;
}

} // namespace ictk::engine
