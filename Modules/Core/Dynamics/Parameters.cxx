// SPDX-License-Identifier: BSD-3-Clause
#include "Dynamics/Parameters.h"

#include <algorithm>
#include <functional>
#include <set>

namespace ictk::dyn
{

namespace
{

std::vector<ParamSlot> slotsOf(const frep::Expr& e)
{
  std::set<ParamSlot> s;
  e.visitPostOrder(
    [&](const frep::Expr& n)
    {
      if (n.opcode() == frep::Opcode::Parameter)
        s.insert(n.parameterSlot());
    });
  return { s.begin(), s.end() };
}

} // namespace

ParamSlot ParameterTable::add(
  const std::string& owner, const std::string& name, Scope scope, double value)
{
  const std::string q = owner.empty() ? name : owner + "." + name;
  if (name.empty())
    throw std::invalid_argument("parameter with an empty name");
  if (byName_.count(q))
    throw std::invalid_argument("parameter '" + q + "' is defined twice");
  const auto s = static_cast<ParamSlot>(entries_.size());
  entries_.push_back({ owner, q, scope, std::nullopt });
  values_.push_back(value);
  byName_[q] = s;
  return s;
}

ParamSlot ParameterTable::addExpression(
  const std::string& owner, const std::string& name, Scope scope, const frep::Expr& e)
{
  checkVisible(owner, e);
  const ParamSlot s = add(owner, name, scope, 0.0);
  entries_[s].expr = e;
  return s;
}

void ParameterTable::setValue(ParamSlot slot, double v)
{
  entries_.at(slot).expr.reset();
  values_.at(slot) = v;
}

void ParameterTable::setExpression(ParamSlot slot, const frep::Expr& e)
{
  checkVisible(entries_.at(slot).owner, e);
  entries_[slot].expr = e;
}

void ParameterTable::checkVisible(const std::string& owner, const frep::Expr& e) const
{
  for (ParamSlot s : slotsOf(e))
  {
    if (s >= entries_.size())
      throw std::invalid_argument("expression of a parameter of '" + owner +
        "' reads the undefined slot " + std::to_string(s));
    if (!visibleFrom(s, owner))
      throw std::invalid_argument("parameter '" + entries_[s].qualified + "' is local to '" +
        entries_[s].owner + "' and not visible from '" + owner + "'");
  }
}

std::optional<ParamSlot> ParameterTable::find(const std::string& qualifiedName) const
{
  auto it = byName_.find(qualifiedName);
  if (it == byName_.end())
    return std::nullopt;
  return it->second;
}

ParamSlot ParameterTable::slot(const std::string& qualifiedName) const
{
  auto s = find(qualifiedName);
  if (!s)
    throw std::out_of_range("unknown parameter '" + qualifiedName + "'");
  return *s;
}

bool ParameterTable::visibleFrom(ParamSlot s, const std::string& reader) const
{
  const Entry& e = entries_.at(s);
  return e.scope == Scope::Global || e.owner == reader;
}

std::vector<ParamSlot> ParameterTable::inputs(ParamSlot s) const
{
  const Entry& e = entries_.at(s);
  return e.expr ? slotsOf(*e.expr) : std::vector<ParamSlot>{};
}

std::vector<ParamSlot> ParameterTable::evaluationOrder() const
{
  const std::size_t n = entries_.size();
  // Edges input -> expression parameter, only between expression parameters (plain values are
  // sources and need no ordering).
  std::vector<std::vector<ParamSlot>> readers(n);
  std::vector<int> pending(n, 0);
  for (ParamSlot s = 0; s < n; ++s)
    for (ParamSlot in : inputs(s))
      if (entries_[in].expr)
      {
        readers[in].push_back(s);
        ++pending[s];
      }
  std::set<ParamSlot> ready;
  for (ParamSlot s = 0; s < n; ++s)
    if (entries_[s].expr && pending[s] == 0)
      ready.insert(s);
  std::vector<ParamSlot> order;
  while (!ready.empty())
  {
    const ParamSlot s = *ready.begin();
    ready.erase(ready.begin());
    order.push_back(s);
    for (ParamSlot r : readers[s])
      if (--pending[r] == 0)
        ready.insert(r);
  }
  std::size_t exprCount = 0;
  for (const Entry& e : entries_)
    exprCount += e.expr ? 1 : 0;
  if (order.size() == exprCount)
    return order;

  // A cycle exists among the slots still pending. Walk back along unresolved inputs from the
  // smallest pending slot until a slot repeats; that loop is a cycle.
  ParamSlot start = 0;
  while (pending[start] == 0)
    ++start;
  std::vector<ParamSlot> path;
  std::vector<int> seenAt(n, -1);
  ParamSlot cur = start;
  while (seenAt[cur] < 0)
  {
    seenAt[cur] = static_cast<int>(path.size());
    path.push_back(cur);
    for (ParamSlot in : inputs(cur))
      if (entries_[in].expr && pending[in] > 0)
      {
        cur = in;
        break;
      }
  }
  // path[seenAt[cur]..] is the cycle, each element reading the next: print it in data-flow order
  // (a -> b means b reads a).
  std::vector<ParamSlot> loop(path.begin() + seenAt[cur], path.end());
  std::reverse(loop.begin(), loop.end());
  // Start the report at the smallest slot (the same cycle is always printed the same way).
  std::rotate(loop.begin(), std::min_element(loop.begin(), loop.end()), loop.end());
  std::vector<std::string> names;
  std::string msg = "cyclic parameter definitions: ";
  for (ParamSlot s : loop)
  {
    names.push_back(entries_[s].qualified);
    msg += entries_[s].qualified + " -> ";
  }
  names.push_back(entries_[loop.front()].qualified);
  msg += entries_[loop.front()].qualified;
  throw ParameterCycleError(msg, names);
}

void ParameterTable::evaluate()
{
  const std::array<double, frep::AxisCount> origin{ 0.0, 0.0, 0.0, 0.0 };
  for (ParamSlot s : evaluationOrder())
    values_[s] = frep::evaluateReference(*entries_[s].expr, origin, values_);
}

} // namespace ictk::dyn
