// SPDX-License-Identifier: BSD-3-Clause
#include "Complex/Attributes.h"

#include <algorithm>
#include <set>

namespace ictk::complex
{

AttributeLookup::AttributeLookup(const Complex& complex, const ComplexMesh& mesh, double tolerance)
  : complex_(complex)
  , mesh_(mesh)
  , tolerance_(tolerance)
{
  for (CellId id : complex.cellIds())
  {
    Box3 b = complex.cell(id).bounds();
    for (int a = 0; a < 3; ++a)
    {
      b.lo[a] -= tolerance;
      b.hi[a] += tolerance;
    }
    boxes_.emplace(id, b);
  }
}

bool AttributeLookup::holds(CellId id, const Point3& p)
{
  const Box3& b = boxes_.at(id);
  for (int a = 0; a < 3; ++a)
  {
    if (!(p[a] >= b.lo[a] && p[a] <= b.hi[a]))
    {
      return false;
    }
  }
  auto it = locators_.find(id);
  if (it == locators_.end())
  {
    it = locators_.emplace(id, CellLocator(complex_.cell(id), mesh_.of(id))).first;
  }
  return it->second.distance(p) <= tolerance_;
}

AttributeLookup::Result AttributeLookup::value(
  const std::string& attribute, const Point3& p, std::optional<CellId> on)
{
  auto declared = complex_.attributes().find(attribute);
  if (declared == complex_.attributes().end())
  {
    throw ComplexError("the complex has no attribute '" + attribute + "'");
  }
  // Only cells that bind the attribute can give its value; the others matter only for the
  // choice of default (inside some cell or outside all), asked when nothing binds.
  const AttributeBinding* best = nullptr;
  const Cell* bestCell = nullptr;
  for (CellId id : complex_.cellIds())
  {
    const Cell& c = complex_.cell(id);
    for (const auto& b : c.attributes)
    {
      if (b.attribute != attribute)
      {
        continue;
      }
      const bool better = !best || b.priority > best->priority ||
        (b.priority == best->priority && c.dimension < bestCell->dimension);
      if (better && holds(id, p))
      {
        best = &b;
        bestCell = &c;
      }
    }
  }
  Result r;
  if (best)
  {
    r.cell = bestCell->id;
    for (const auto& component : best->function->components)
    {
      r.value.push_back(component->evaluator()->value(p));
    }
    return r;
  }
  bool inSomeCell = on.has_value();
  for (CellId id : complex_.cellIds())
  {
    if (inSomeCell)
    {
      break;
    }
    inSomeCell = holds(id, p);
  }
  r.value = inSomeCell ? declared->second.inside : declared->second.outside;
  return r;
}

namespace
{
bool binds(const Cell& c, const std::string& attribute)
{
  return std::any_of(c.attributes.begin(), c.attributes.end(),
    [&](const AttributeBinding& b) { return b.attribute == attribute; });
}

bool near(const Box3& a, const Box3& b, double tolerance)
{
  for (int k = 0; k < 3; ++k)
  {
    if (a.lo[k] > b.hi[k] + tolerance || b.lo[k] > a.hi[k] + tolerance)
    {
      return false;
    }
  }
  return true;
}
} // namespace

std::vector<CellId> attributeSupport(
  const Complex& complex, const std::vector<CellId>& targets, double tolerance)
{
  std::vector<CellId> support;
  const std::set<CellId> targetSet(targets.begin(), targets.end());
  for (CellId id : complex.cellIds())
  {
    if (targetSet.count(id))
    {
      continue;
    }
    const Cell& c = complex.cell(id);
    const Box3 box = c.bounds();
    const bool needed = std::any_of(c.attributes.begin(), c.attributes.end(),
      [&](const AttributeBinding& b)
      {
        return std::any_of(targets.begin(), targets.end(),
          [&](CellId t)
          {
            const Cell& target = complex.cell(t);
            return !binds(target, b.attribute) && near(box, target.bounds(), tolerance);
          });
      });
    if (needed)
    {
      support.push_back(id);
    }
  }
  return support;
}

void appendUnboundAttributes(
  const Complex& complex, ComplexMesh& mesh, double tolerance, const std::vector<CellId>& targets)
{
  if (complex.attributes().empty())
  {
    return;
  }
  const std::set<CellId> targetSet(targets.begin(), targets.end());
  AttributeLookup lookup(complex, mesh, tolerance);
  for (CellMesh& m : mesh.cells)
  {
    if (!targetSet.empty() && !targetSet.count(m.cell))
    {
      continue;
    }
    const Cell& c = complex.cell(m.cell);
    for (const auto& [name, defaults] : complex.attributes())
    {
      const bool bound = std::any_of(c.attributes.begin(), c.attributes.end(),
        [&name = name](const AttributeBinding& b) { return b.attribute == name; });
      if (bound)
      {
        continue;
      }
      discretize::PointArray array;
      array.name = name;
      array.components = defaults.components;
      for (const Point3& p : m.vertices())
      {
        const auto v = lookup.value(name, p, m.cell).value;
        array.values.insert(array.values.end(), v.begin(), v.end());
      }
      m.pointData().push_back(std::move(array));
    }
  }
}

void appendAttribute(const AttributeBinding& binding, const std::vector<Point3>& points,
  std::vector<discretize::PointArray>& arrays)
{
  discretize::PointArray array;
  array.name = binding.attribute;
  const auto components = binding.function->components.size();
  array.components = static_cast<int>(components);
  array.values.resize(points.size() * components);
  std::vector<double> x(points.size()), y(points.size()), z(points.size()), v(points.size());
  for (std::size_t i = 0; i < points.size(); ++i)
  {
    x[i] = points[i][0];
    y[i] = points[i][1];
    z[i] = points[i][2];
  }
  for (std::size_t c = 0; c < components; ++c)
  {
    if (!points.empty())
    {
      binding.function->components[c]->evaluator()->values(
        x.data(), y.data(), z.data(), v.data(), points.size());
    }
    for (std::size_t i = 0; i < points.size(); ++i)
    {
      array.values[i * components + c] = v[i];
    }
  }
  arrays.push_back(std::move(array));
}

} // namespace ictk::complex
