// SPDX-License-Identifier: BSD-3-Clause
#include "Complex/Complex.h"

#include <algorithm>

namespace ictk::complex
{
namespace
{

std::string describe(const Cell& c)
{
  return "'" + c.name + "' (" + std::to_string(c.dimension) + "D)";
}

void appendUnique(std::vector<CellId>& out, const std::vector<CellId>& more)
{
  out.insert(out.end(), more.begin(), more.end());
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
}

} // namespace

std::vector<CellId> Relation::related(CellId first) const
{
  std::vector<CellId> out;
  for (auto it = pairs_.lower_bound({ first, 0 }); it != pairs_.end() && it->first == first; ++it)
  {
    out.push_back(it->second);
  }
  return out;
}

std::vector<CellId> Relation::inverse(CellId second) const
{
  std::vector<CellId> out;
  for (const auto& [p, s] : pairs_)
  {
    if (s == second)
    {
      out.push_back(p);
    }
  }
  return out;
}

CellId Complex::addCell(Cell cell)
{
  checkCell(cell);
  if (names_.count(cell.name))
  {
    throw ComplexError("a cell named '" + cell.name + "' is already in the complex");
  }
  for (CellId operand : cell.operands)
  {
    checkedCell(operand, ("operand of '" + cell.name + "'").c_str());
  }
  for (const auto& b : cell.attributes)
  {
    auto it = attributes_.find(b.attribute);
    if (it != attributes_.end() &&
      static_cast<int>(b.function->components.size()) != it->second.components)
    {
      throw ComplexError("cell '" + cell.name + "': attribute '" + b.attribute + "' has " +
        std::to_string(b.function->components.size()) + " components, declared " +
        std::to_string(it->second.components));
    }
  }
  cell.id = static_cast<CellId>(cells_.size());
  names_[cell.name] = cell.id;
  cells_.emplace_back(std::move(cell));
  ++live_;
  return cells_.back()->id;
}

void Complex::removeCell(CellId id)
{
  const Cell& c = checkedCell(id, "cell to remove");
  for (auto* relations : { &boundary_, &containment_ })
  {
    for (Relation& r : *relations)
    {
      std::vector<std::pair<CellId, CellId>> drop;
      for (const auto& pair : r.pairs())
      {
        if (pair.first == id || pair.second == id)
        {
          drop.push_back(pair);
        }
      }
      for (const auto& [a, b] : drop)
      {
        r.erase(a, b);
      }
    }
  }
  names_.erase(c.name);
  cells_[id].reset();
  --live_;
}

const Cell& Complex::checkedCell(CellId id, const char* role) const
{
  if (!hasCell(id))
  {
    throw ComplexError(std::string(role) + ": no cell with id " + std::to_string(id));
  }
  return *cells_[id];
}

const Cell& Complex::cell(CellId id) const
{
  return checkedCell(id, "cell");
}

Cell& Complex::cell(CellId id)
{
  checkedCell(id, "cell");
  return *cells_[id];
}

const Cell* Complex::findCell(const std::string& name) const
{
  auto it = names_.find(name);
  return it == names_.end() ? nullptr : &*cells_[it->second];
}

CellId Complex::idOf(const std::string& name) const
{
  auto it = names_.find(name);
  if (it == names_.end())
  {
    throw ComplexError("no cell named '" + name + "' in the complex");
  }
  return it->second;
}

std::vector<CellId> Complex::cellIds() const
{
  std::vector<CellId> out;
  for (CellId i = 0; i < cells_.size(); ++i)
  {
    if (cells_[i])
    {
      out.push_back(i);
    }
  }
  return out;
}

std::vector<CellId> Complex::cellsOfDimension(int p) const
{
  std::vector<CellId> out;
  for (CellId i = 0; i < cells_.size(); ++i)
  {
    if (cells_[i] && cells_[i]->dimension == p)
    {
      out.push_back(i);
    }
  }
  return out;
}

int Complex::dimension() const
{
  int d = -1;
  for (const auto& c : cells_)
  {
    if (c)
    {
      d = std::max(d, c->dimension);
    }
  }
  return d;
}

void Complex::addBoundary(CellId cellId, CellId boundaryId)
{
  const Cell& p = checkedCell(cellId, "boundary relation");
  const Cell& s = checkedCell(boundaryId, "boundary relation");
  if (s.dimension >= p.dimension)
  {
    throw ComplexError("boundary relation (" + describe(p) + ", " + describe(s) +
      "): a boundary cell must have a lower dimension (Rb^{ps} needs s < p)");
  }
  if (containment_[slot(p.dimension, s.dimension)].contains(cellId, boundaryId))
  {
    throw ComplexError("boundary relation (" + describe(p) + ", " + describe(s) +
      "): the pair is already in the containment relation; a pair cannot be in both");
  }
  boundary_[slot(p.dimension, s.dimension)].add(cellId, boundaryId);
}

void Complex::addContainment(CellId containerId, CellId containedId)
{
  const Cell& p = checkedCell(containerId, "containment relation");
  const Cell& s = checkedCell(containedId, "containment relation");
  if (containerId == containedId)
  {
    throw ComplexError("containment relation (" + describe(p) +
      ", itself): a cell does not "
      "contain itself");
  }
  if (s.dimension > p.dimension)
  {
    throw ComplexError("containment relation (" + describe(p) + ", " + describe(s) +
      "): a contained cell cannot have a higher dimension (Rc^{ps} needs s <= p)");
  }
  if (p.isExplicit())
  {
    throw ComplexError("containment relation (" + describe(p) + ", " + describe(s) +
      "): explicit cells are indivisible and contain no other cells");
  }
  if (boundary_[slot(p.dimension, s.dimension)].contains(containerId, containedId))
  {
    throw ComplexError("containment relation (" + describe(p) + ", " + describe(s) +
      "): the pair is already in the boundary relation; a pair cannot be in both");
  }
  containment_[slot(p.dimension, s.dimension)].add(containerId, containedId);
}

bool Complex::removeRelation(RelationKind kind, CellId first, CellId second)
{
  if (!hasCell(first) || !hasCell(second))
  {
    return false;
  }
  auto& relations = kind == RelationKind::Boundary ? boundary_ : containment_;
  return relations[slot(cells_[first]->dimension, cells_[second]->dimension)].erase(first, second);
}

const Relation& Complex::boundary(int p, int s) const
{
  if (p < 1 || p > 3 || s < 0 || s >= p)
  {
    throw ComplexError("there is no boundary relation Rb^{" + std::to_string(p) +
      std::to_string(s) + "}: it needs 0 <= s < p <= 3");
  }
  return boundary_[slot(p, s)];
}

const Relation& Complex::containment(int p, int s) const
{
  if (p < 0 || p > 3 || s < 0 || s > p)
  {
    throw ComplexError("there is no containment relation Rc^{" + std::to_string(p) +
      std::to_string(s) + "}: it needs 0 <= s <= p <= 3");
  }
  return containment_[slot(p, s)];
}

const Relation& Complex::relation(RelationKind kind, int p, int s) const
{
  return kind == RelationKind::Boundary ? boundary(p, s) : containment(p, s);
}

bool Complex::hasBoundary(CellId c, CellId b) const
{
  return hasCell(c) && hasCell(b) &&
    boundary_[slot(cells_[c]->dimension, cells_[b]->dimension)].contains(c, b);
}

bool Complex::hasContainment(CellId c, CellId b) const
{
  return hasCell(c) && hasCell(b) &&
    containment_[slot(cells_[c]->dimension, cells_[b]->dimension)].contains(c, b);
}

std::size_t Complex::boundaryPairCount() const
{
  std::size_t n = 0;
  for (const auto& r : boundary_)
  {
    n += r.size();
  }
  return n;
}

std::size_t Complex::containmentPairCount() const
{
  std::size_t n = 0;
  for (const auto& r : containment_)
  {
    n += r.size();
  }
  return n;
}

std::vector<CellId> Complex::boundaryOf(CellId c) const
{
  const int p = checkedCell(c, "boundaryOf").dimension;
  std::vector<CellId> out;
  for (int s = 0; s < p; ++s)
  {
    appendUnique(out, boundary_[slot(p, s)].related(c));
  }
  return out;
}

std::vector<CellId> Complex::coboundaryOf(CellId c) const
{
  const int s = checkedCell(c, "coboundaryOf").dimension;
  std::vector<CellId> out;
  for (int p = s + 1; p <= 3; ++p)
  {
    appendUnique(out, boundary_[slot(p, s)].inverse(c));
  }
  return out;
}

std::vector<CellId> Complex::contentsOf(CellId c) const
{
  const int p = checkedCell(c, "contentsOf").dimension;
  std::vector<CellId> out;
  for (int s = 0; s <= p; ++s)
  {
    appendUnique(out, containment_[slot(p, s)].related(c));
  }
  return out;
}

std::vector<CellId> Complex::containersOf(CellId c) const
{
  const int s = checkedCell(c, "containersOf").dimension;
  std::vector<CellId> out;
  for (int p = s; p <= 3; ++p)
  {
    appendUnique(out, containment_[slot(p, s)].inverse(c));
  }
  return out;
}

std::vector<CellId> Complex::incidentTo(CellId c) const
{
  std::vector<CellId> out = boundaryOf(c);
  appendUnique(out, coboundaryOf(c));
  return out;
}

std::vector<CellId> Complex::adjacentTo(CellId c) const
{
  const int p = checkedCell(c, "adjacentTo").dimension;
  std::vector<CellId> out;
  for (CellId b : boundaryOf(c))
  {
    for (CellId other : coboundaryOf(b))
    {
      if (other != c && cells_[other]->dimension == p)
      {
        out.push_back(other);
      }
    }
  }
  appendUnique(out, {});
  return out;
}

void Complex::declareAttribute(const std::string& attribute, AttributeDefaults defaults)
{
  if (attribute.empty() || defaults.components < 1)
  {
    throw ComplexError("attribute '" + attribute + "' needs a name and at least one component");
  }
  const auto n = static_cast<std::size_t>(defaults.components);
  if (defaults.inside.empty())
  {
    defaults.inside.assign(n, 0.0);
  }
  if (defaults.outside.empty())
  {
    defaults.outside.assign(n, 0.0);
  }
  if (defaults.inside.size() != n || defaults.outside.size() != n)
  {
    throw ComplexError(
      "attribute '" + attribute + "': the defaults need " + std::to_string(n) + " components");
  }
  for (const auto& c : cells_)
  {
    if (!c)
    {
      continue;
    }
    for (const auto& b : c->attributes)
    {
      if (b.attribute == attribute && b.function->components.size() != n)
      {
        throw ComplexError("attribute '" + attribute + "' is bound to cell '" + c->name +
          "' with " + std::to_string(b.function->components.size()) + " components, not " +
          std::to_string(n));
      }
    }
  }
  attributes_[attribute] = std::move(defaults);
}

void Complex::bindAttribute(CellId cellId, AttributeBinding binding)
{
  Cell& c = cell(cellId);
  if (!binding.function || binding.function->components.empty())
  {
    throw ComplexError(
      "cell '" + c.name + "': attribute '" + binding.attribute + "' has no function");
  }
  auto it = attributes_.find(binding.attribute);
  if (it != attributes_.end() &&
    static_cast<int>(binding.function->components.size()) != it->second.components)
  {
    throw ComplexError("cell '" + c.name + "': attribute '" + binding.attribute + "' has " +
      std::to_string(binding.function->components.size()) + " components, declared " +
      std::to_string(it->second.components));
  }
  for (auto& b : c.attributes)
  {
    if (b.attribute == binding.attribute)
    {
      b = std::move(binding);
      return;
    }
  }
  c.attributes.push_back(std::move(binding));
}

} // namespace ictk::complex
