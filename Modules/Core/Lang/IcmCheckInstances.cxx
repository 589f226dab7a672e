// SPDX-License-Identifier: BSD-3-Clause
// The checks of templates and instances: USE targets and their cycles, the cells, attributes and
// relations an instance derives, relation ends, priorities and names.
#include "Lang/IcmChecker.h"

namespace ictk::lang::icmcheck
{

const Instance* Checker::useTarget(const Use& u) const
{
  const Expr* root = u.what.get();
  while (!root->kids.empty())
  {
    root = root->kids[0].get();
  }
  const auto it = instances_.find(root->text);
  return it == instances_.end() ? nullptr : it->second;
}

void Checker::cellsOf(const Instance& in, CellMap& out, int depth) const
{
  const auto it = cellsCache_.find(&in);
  if (it != cellsCache_.end())
  {
    out.insert(it->second.begin(), it->second.end());
    return;
  }
  if (depth > 64 || !cellsBusy_.insert(&in).second)
  {
    return; // a cycle of USE or bases
  }
  CellMap mine;
  cellsOfImpl(in, mine, depth);
  cellsBusy_.erase(&in);
  out.insert(mine.begin(), mine.end());
  cellsCache_.emplace(&in, std::move(mine));
}

void Checker::cellsOfImpl(const Instance& in, CellMap& out, int depth) const
{
  if (!in.base.text.empty())
  {
    const auto it = instances_.find(in.base.text);
    if (it != instances_.end() && it->second != &in)
    {
      cellsOf(*it->second, out, depth + 1);
    }
  }
  for (const CellsSection& s : in.cells)
  {
    for (const Use& u : s.uses)
    {
      const Instance* t = useTarget(u);
      if (!t || t == &in)
      {
        continue;
      }
      CellMap used;
      cellsOf(*t, used, depth + 1);
      for (const Name& n : u.minus)
      {
        used.erase(n.text);
      }
      for (const Name& n : u.plus)
      {
        const auto g = globalCells_.find(n.text);
        used.emplace(n.text, g == globalCells_.end() ? nullptr : g->second);
      }
      out.insert(used.begin(), used.end());
    }
    for (const Name& r : s.refs)
    {
      const auto g = globalCells_.find(r.text);
      if (g != globalCells_.end())
      {
        out.emplace(r.text, g->second);
      }
    }
    for (const CellDef& d : s.defs)
    {
      out.emplace(d.name.text, &d);
    }
  }
}

void Checker::relationNames(
  const Instance& in, const std::string& section, std::set<std::string>& out, int depth) const
{
  const auto key = std::make_pair(&in, section);
  const auto it = relationsCache_.find(key);
  if (it != relationsCache_.end())
  {
    out.insert(it->second.begin(), it->second.end());
    return;
  }
  if (depth > 64 || !relationsBusy_.insert(key).second)
  {
    return;
  }
  std::set<std::string> mine;
  relationNamesImpl(in, section, mine, depth);
  relationsBusy_.erase(key);
  out.insert(mine.begin(), mine.end());
  relationsCache_.emplace(key, std::move(mine));
}

void Checker::relationNamesImpl(
  const Instance& in, const std::string& section, std::set<std::string>& out, int depth) const
{
  for (const RelationsSection& s : in.relations)
  {
    const std::vector<Relation>& rs = section == "dependency" ? s.dependency
      : section == "containment"                              ? s.containment
                                                              : s.boundary;
    for (const Relation& r : rs)
    {
      if (!r.name.text.empty())
      {
        out.insert(r.name.text);
      }
    }
    const std::vector<Use>& us = section == "dependency" ? s.dependencyUses
      : section == "containment"                         ? s.containmentUses
                                                         : s.boundaryUses;
    for (const Use& u : us)
    {
      const Instance* t = useTarget(u);
      if (t && t != &in)
      {
        relationNames(*t, section, out, depth + 1);
      }
    }
  }
  if (!in.base.text.empty())
  {
    const auto it = instances_.find(in.base.text);
    if (it != instances_.end() && it->second != &in)
    {
      relationNames(*it->second, section, out, depth + 1);
    }
  }
}

std::vector<const Instance*> Checker::sources(const Instance& in) const
{
  std::vector<const Instance*> out;
  const auto add = [&](const Use& u)
  {
    if (const Instance* t = useTarget(u))
    {
      out.push_back(t);
    }
  };
  if (!in.base.text.empty())
  {
    const auto it = instances_.find(in.base.text);
    if (it != instances_.end())
    {
      out.push_back(it->second);
    }
  }
  for (const CellsSection& s : in.cells)
  {
    for (const Use& u : s.uses)
    {
      add(u);
    }
    for (const AttributesSection& a : s.attributes)
    {
      for (const Use& u : a.uses)
      {
        add(u);
      }
    }
  }
  for (const RelationsSection& s : in.relations)
  {
    for (const auto* us : { &s.containmentUses, &s.boundaryUses, &s.dependencyUses })
    {
      for (const Use& u : *us)
      {
        add(u);
      }
    }
  }
  for (const AttributesSection& a : in.attributes)
  {
    for (const Use& u : a.uses)
    {
      add(u);
    }
  }
  return out;
}

bool Checker::reaches(const Instance* from, const Instance* target) const
{
  std::set<const Instance*> seen;
  std::vector<const Instance*> todo = { from };
  while (!todo.empty())
  {
    const Instance* x = todo.back();
    todo.pop_back();
    if (x == target)
    {
      return true;
    }
    if (seen.insert(x).second)
    {
      for (const Instance* y : sources(*x))
      {
        todo.push_back(y);
      }
    }
  }
  return false;
}

void Checker::use(const Use& u, const std::string& section, const Instance* in)
{
  std::vector<const Expr*> chain;
  for (const Expr* e = u.what.get(); e; e = e->kids.empty() ? nullptr : e->kids[0].get())
  {
    chain.insert(chain.begin(), e);
  }
  const Expr* root = chain.front();
  const auto it = instances_.find(root->text);
  if (it == instances_.end())
  {
    err(root->pos, "undefined template or instance '" + root->text + "'");
    return;
  }
  const Instance& t = *it->second;
  if (&t == in)
  {
    err(root->pos, "'" + root->text + "' cannot USE itself");
    return;
  }
  if (in && reaches(&t, in))
  {
    err(root->pos, "USE cycle: '" + root->text + "' takes from '" + in->name.text + "'");
    return;
  }
  std::string want = root->text + "." + section;
  std::string got = root->text;
  for (std::size_t i = 1; i < chain.size(); ++i)
  {
    got += chain[i]->kind == Expr::Kind::Member ? "." + chain[i]->text : "[...]";
  }
  if (section == "RELATIONS.dependency" && chain.size() == 3 && chain[1]->text == "Rd" &&
    chain[2]->kind == Expr::Kind::Index)
  {
    // USE inst.Rd[cellA, cellB]: the unnamed dependencies between two cells of inst.
    CellMap cs;
    cellsOf(t, cs, 0);
    const Expr& ix = *chain[2];
    if (ix.kids.size() != 3)
    {
      err(ix.pos, "Rd[cellA, cellB] names two cells");
    }
    for (std::size_t i = 1; i < ix.kids.size(); ++i)
    {
      if (ix.kids[i]->kind != Expr::Kind::Name || cs.count(ix.kids[i]->text) == 0)
      {
        err(ix.kids[i]->pos, "'" + ix.kids[i]->text + "' is not a cell of " + root->text);
      }
    }
    return;
  }
  if (got != want)
  {
    err(root->pos, "expected USE " + want + ", found " + got);
    return;
  }
  std::set<std::string> names;
  std::string what;
  if (section == "CELLS")
  {
    CellMap cs;
    cellsOf(t, cs, 0);
    for (const auto& c : cs)
    {
      names.insert(c.first);
    }
    what = "a cell of";
  }
  else if (section == "ATTRIBUTES")
  {
    attributesOf(t, names, 0);
    what = "an attribute of";
  }
  else
  {
    relationNames(t, section.substr(section.find('.') + 1), names, 0);
    what = "a named relation of";
  }
  for (const Name& n : u.minus)
  {
    if (names.count(n.text) == 0)
    {
      err(n.pos, "'" + n.text + "' is not " + what + " " + root->text);
    }
  }
  if (section == "CELLS")
  {
    for (const Name& n : u.plus)
    {
      if (globalCells_.count(n.text) == 0)
      {
        err(n.pos, "undefined cell '" + n.text + "'");
      }
    }
  }
}

void Checker::instance(const Instance& in)
{
  if (!in.base.text.empty())
  {
    const auto it = instances_.find(in.base.text);
    if (it == instances_.end())
    {
      err(in.base.pos, "undefined template '" + in.base.text + "'");
    }
    else if (!it->second->isTemplate)
    {
      err(in.base.pos, "'" + in.base.text + "' is an instance, not a template");
    }
    else if (reaches(it->second, &in))
    {
      err(in.base.pos, "cycle: template '" + in.base.text + "' takes from '" + in.name.text + "'");
    }
  }
  CellMap cells;
  cellsOf(in, cells, 0);
  // Cells listed, defined and used.
  std::map<std::string, Pos> listed;
  CellMap inherited;
  if (!in.base.text.empty())
  {
    const auto it = instances_.find(in.base.text);
    if (it != instances_.end() && it->second != &in)
    {
      cellsOf(*it->second, inherited, 0);
    }
  }
  // Parameters.
  std::map<std::string, const ParamDecl*> vars;
  params(in.parameters, vars, &cells, "parameter");
  std::set<std::string> roots;
  for (const auto& v : vars)
  {
    roots.insert(v.first);
  }
  std::map<std::string, const ParamDecl*> state;
  params(in.stateParameters, state, &cells, "state parameter", &roots);
  for (const auto& s : state)
  {
    if (globalVars_.count(s.first) > 0)
    {
      err(s.second->name.pos,
        "duplicate state parameter '" + s.first + "' (also a model-wide state parameter)");
    }
    if (vars.count(s.first) > 0 && s.second->kind != ParamDecl::Kind::Alias)
    {
      err(s.second->name.pos, "'" + s.first + "' is already a parameter of " + in.name.text);
    }
  }
  std::set<std::string> scope = globalVars_;
  for (const auto& v : vars)
  {
    scope.insert(v.first);
  }
  for (const auto& v : state)
  {
    scope.insert(v.first);
  }
  instanceVars_ = scope;
  for (const CellsSection& s : in.cells)
  {
    for (const Use& u : s.uses)
    {
      use(u, "CELLS", &in);
    }
  }
  for (const CellsSection& s : in.cells)
  {
    for (const Name& r : s.refs)
    {
      if (globalCells_.count(r.text) == 0)
      {
        err(r.pos, "undefined cell '" + r.text + "'");
      }
      else if (!listed.emplace(r.text, r.pos).second || inherited.count(r.text) > 0)
      {
        err(r.pos, "cell '" + r.text + "' is already in " + in.name.text);
      }
    }
    for (const CellDef& d : s.defs)
    {
      const auto g = globalCells_.find(d.name.text);
      if (g != globalCells_.end())
      {
        err(d.name.pos,
          "duplicate cell '" + d.name.text + "' (first defined at " + lineOf(g->second->pos) + ")");
      }
      else if (!listed.emplace(d.name.text, d.name.pos).second)
      {
        err(d.name.pos, "cell '" + d.name.text + "' is already in " + in.name.text);
      }
      cell(d, cells, &in);
    }
    reactionsOf(s.reactions, cells, &in, nullptr);
    for (const AttributesSection& a : s.attributes)
    {
      attributes(a, cells, &in);
    }
  }
  // Relations.
  std::map<std::string, Pos> relationNames;
  std::set<std::string> attrs = globalAttributes_;
  attributesOf(in, attrs, 0);
  for (const RelationsSection& s : in.relations)
  {
    for (const Use& u : s.containmentUses)
    {
      use(u, "RELATIONS.containment", &in);
    }
    for (const Use& u : s.boundaryUses)
    {
      use(u, "RELATIONS.boundary", &in);
    }
    for (const Use& u : s.dependencyUses)
    {
      use(u, "RELATIONS.dependency", &in);
    }
    for (const auto* rs : { &s.containment, &s.boundary, &s.dependency })
    {
      const bool dependency = rs == &s.dependency;
      for (const Relation& r : *rs)
      {
        relation(r, dependency, cells, attrs);
        if (!r.name.text.empty())
        {
          const auto it = relationNames.find(r.name.text);
          if (it != relationNames.end())
          {
            err(r.name.pos,
              "duplicate relation '" + r.name.text + "' (first defined at " + lineOf(it->second) +
                ")");
          }
          relationNames.emplace(r.name.text, r.name.pos);
        }
      }
    }
  }
  for (const AttributesSection& a : in.attributes)
  {
    attributes(a, cells, &in);
  }
  // Code.
  reactionsOf(in.reactions, cells, &in, nullptr);
  std::size_t predicates = 0;
  for (const Procedure& p : in.predicates)
  {
    if (++predicates == 2)
    {
      err(p.pos,
        (in.isTemplate ? "template '" : "instance '") + in.name.text +
          "' has more than one predicate");
    }
    Code c;
    c.instance = &in;
    c.cells = &cells;
    c.vars = scope;
    c.predicate = true;
    procedure(p, c);
  }
  instanceVars_.clear();
}

void Checker::relation(
  const Relation& r, bool dependency, const CellMap& cells, const std::set<std::string>& attrs)
{
  std::string texts[2];
  for (int i = 0; i < 2; ++i)
  {
    const ExprPtr& e = r.ends[static_cast<std::size_t>(i)];
    const Expr* root = e.get();
    while (!root->kids.empty())
    {
      root = root->kids[0].get();
    }
    if (cells.count(root->text) > 0)
    {
      if (dependency)
      {
        cellMember(*e, cells);
      }
    }
    else if (!(dependency && attrs.count(root->text) > 0))
    {
      err(root->pos,
        "undefined cell '" + root->text + "' in a " +
          std::string(dependency ? "dependency" : "relation") + " (not in this instance)");
    }
    texts[i] = pathText(*e);
  }
  if (texts[0] == texts[1])
  {
    err(r.pos,
      dependency ? "'" + texts[0] + "' cannot depend on itself"
                 : "a cell cannot be related to itself");
  }
  if (r.hasPriority && r.priority <= 0)
  {
    err(r.pos, "a dependency's priority must be positive");
  }
}

std::string Checker::pathText(const Expr& e)
{
  if (e.kind == Expr::Kind::Member)
  {
    return pathText(*e.kids[0]) + "." + e.text;
  }
  if (e.kind == Expr::Kind::Index)
  {
    return pathText(*e.kids[0]) + "[" + e.kids[1]->text + "]";
  }
  return e.text;
}

} // namespace ictk::lang::icmcheck
