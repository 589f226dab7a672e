// SPDX-License-Identifier: BSD-3-Clause
#include "Dynamics/Dependencies.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <set>
#include <stdexcept>

namespace ictk::dyn
{

const char* dependencyKindName(DependencyKind k)
{
  switch (k)
  {
    case DependencyKind::Parametric:
      return "parametric";
    case DependencyKind::Geometric:
      return "geometric";
    case DependencyKind::AttributeAttribute:
      return "attribute";
    case DependencyKind::GeometryToAttribute:
      return "geometry-attribute";
    case DependencyKind::AttributeToGeometry:
      return "attribute-geometry";
    case DependencyKind::Hierarchical:
      return "hierarchical";
  }
  return "?";
}

std::vector<std::size_t> EvaluationPlan::order() const
{
  std::vector<std::size_t> o;
  for (const auto& l : lists)
    o.insert(o.end(), l.begin(), l.end());
  return o;
}

std::vector<std::vector<std::string>> EvaluationPlan::listNames() const
{
  std::vector<std::vector<std::string>> out;
  for (const auto& l : lists)
  {
    out.emplace_back();
    for (std::size_t e : l)
      out.back().push_back(entities[e]);
  }
  return out;
}

std::vector<bool> EvaluationPlan::readsPrevious(CyclePolicy policy) const
{
  std::vector<bool> r(inCycle.size(), false);
  if (policy == CyclePolicy::PreviousState)
    r = inCycle;
  else if (policy == CyclePolicy::CutEdgePrevious)
    for (std::size_t c : cut)
      r[c] = true;
  return r;
}

std::size_t DependencyGraph::addEntity(const std::string& name, double priority)
{
  if (!std::isfinite(priority))
    throw std::invalid_argument("entity '" + name + "': priority is not finite");
  auto it = index_.find(name);
  if (it != index_.end())
  {
    entities_[it->second].priority = priority;
    return it->second;
  }
  index_[name] = entities_.size();
  entities_.push_back({ name, priority });
  return entities_.size() - 1;
}

std::size_t DependencyGraph::entityIndex(const std::string& name) const
{
  auto it = index_.find(name);
  if (it == index_.end())
    throw std::out_of_range("unknown entity '" + name + "'");
  return it->second;
}

std::size_t DependencyGraph::addRelation(DependencyRelation r)
{
  if (!std::isfinite(r.priority))
    throw std::invalid_argument(
      "relation " + r.master + " -> " + r.dependent + ": priority is not finite");
  if (!index_.count(r.master))
    addEntity(r.master);
  if (!index_.count(r.dependent))
    addEntity(r.dependent);
  relations_.push_back(std::move(r));
  return relations_.size() - 1;
}

std::size_t DependencyGraph::addRelation(const std::string& masterDotParam,
  const std::string& dependentDotParam, double priority, DependencyKind kind)
{
  auto split = [](const std::string& s, std::string& entity, std::string& param)
  {
    const auto dot = s.find('.');
    entity = s.substr(0, dot);
    param = dot == std::string::npos ? std::string() : s.substr(dot + 1);
  };
  DependencyRelation r;
  split(masterDotParam, r.master, r.masterParam);
  split(dependentDotParam, r.dependent, r.dependentParam);
  r.priority = priority;
  r.kind = kind;
  return addRelation(std::move(r));
}

void DependencyGraph::setUserOrder(std::vector<std::string> order)
{
  if (!order.empty())
  {
    std::set<std::string> seen;
    for (const std::string& n : order)
    {
      if (!index_.count(n))
        throw std::invalid_argument("user order names the unknown entity '" + n + "'");
      if (!seen.insert(n).second)
        throw std::invalid_argument("user order names '" + n + "' twice");
    }
    for (const Entity& e : entities_)
      if (!seen.count(e.name))
        throw std::invalid_argument("user order omits the entity '" + e.name + "'");
  }
  userOrder_ = std::move(order);
}

EvaluationPlan DependencyGraph::plan() const
{
  const std::size_t n = entities_.size();
  const std::size_t m = relations_.size();
  EvaluationPlan p;
  for (const Entity& e : entities_)
    p.entities.push_back(e.name);
  std::vector<std::size_t> src(m), dst(m);
  for (std::size_t r = 0; r < m; ++r)
  {
    src[r] = index_.at(relations_[r].master);
    dst[r] = index_.at(relations_[r].dependent);
  }

  // Reachability from `from` to `to` over the relations flagged in `use`.
  auto reaches = [&](std::size_t from, std::size_t to, const std::vector<bool>& use)
  {
    std::vector<bool> seen(n, false);
    std::vector<std::size_t> stack{ from };
    seen[from] = true;
    while (!stack.empty())
    {
      const std::size_t v = stack.back();
      stack.pop_back();
      if (v == to)
        return true;
      for (std::size_t r = 0; r < m; ++r)
        if (use[r] && src[r] == v && !seen[dst[r]])
        {
          seen[dst[r]] = true;
          stack.push_back(dst[r]);
        }
    }
    return false;
  };

  // Strongly connected components of the full graph: a relation is inside a cycle when its
  // dependent reaches its master.
  const std::vector<bool> all(m, true);
  p.inCycle.assign(m, false);
  for (std::size_t r = 0; r < m; ++r)
    p.inCycle[r] = reaches(dst[r], src[r], all);

  std::vector<bool> keep(m, false);
  if (!userOrder_.empty())
  {
    p.userOrder = true;
    std::vector<std::size_t> pos(n);
    for (std::size_t i = 0; i < n; ++i)
    {
      const std::size_t e = index_.at(userOrder_[i]);
      pos[e] = i;
      p.lists.push_back({ e });
    }
    for (std::size_t r = 0; r < m; ++r)
      keep[r] = pos[src[r]] < pos[dst[r]];
  }
  else
  {
    std::vector<std::size_t> byPriority(m);
    std::iota(byPriority.begin(), byPriority.end(), 0);
    std::stable_sort(byPriority.begin(), byPriority.end(),
      [&](std::size_t a, std::size_t b)
      { return relations_[a].priority > relations_[b].priority; });
    for (std::size_t r : byPriority)
      keep[r] = src[r] != dst[r] && !reaches(dst[r], src[r], keep);

    // Longest-path depth over the kept DAG (Kahn, smallest index first).
    std::vector<int> indeg(n, 0);
    for (std::size_t r = 0; r < m; ++r)
      if (keep[r])
        ++indeg[dst[r]];
    std::set<std::size_t> ready;
    for (std::size_t v = 0; v < n; ++v)
      if (indeg[v] == 0)
        ready.insert(v);
    std::vector<std::size_t> depth(n, 0);
    std::size_t maxDepth = 0;
    while (!ready.empty())
    {
      const std::size_t v = *ready.begin();
      ready.erase(ready.begin());
      maxDepth = std::max(maxDepth, depth[v]);
      for (std::size_t r = 0; r < m; ++r)
        if (keep[r] && src[r] == v)
        {
          depth[dst[r]] = std::max(depth[dst[r]], depth[v] + 1);
          if (--indeg[dst[r]] == 0)
            ready.insert(dst[r]);
        }
    }
    if (n > 0)
      p.lists.assign(maxDepth + 1, {});
    for (std::size_t v = 0; v < n; ++v)
      p.lists[depth[v]].push_back(v);
    for (auto& l : p.lists)
      std::stable_sort(l.begin(), l.end(),
        [&](std::size_t a, std::size_t b)
        { return entities_[a].priority > entities_[b].priority; });
  }
  for (std::size_t r = 0; r < m; ++r)
    (keep[r] ? p.kept : p.cut).push_back(r);
  p.reevaluations = p.cut;
  std::stable_sort(p.reevaluations.begin(), p.reevaluations.end(),
    [&](std::size_t a, std::size_t b) { return relations_[a].priority > relations_[b].priority; });
  return p;
}

} // namespace ictk::dyn
