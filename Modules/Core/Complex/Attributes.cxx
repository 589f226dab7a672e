// SPDX-License-Identifier: BSD-3-Clause
#include "Complex/Attributes.h"

namespace ictk::complex
{

AttributeLookup::AttributeLookup(const Complex& complex, const ComplexMesh& mesh, double tolerance)
  : complex_(complex)
  , tolerance_(tolerance)
{
  for (CellId id : complex.cellIds())
  {
    locators_.emplace(id, CellLocator(complex.cell(id), mesh.of(id)));
  }
}

AttributeLookup::Result AttributeLookup::value(const std::string& attribute, const Point3& p)
{
  auto declared = complex_.attributes().find(attribute);
  if (declared == complex_.attributes().end())
  {
    throw ComplexError("the complex has no attribute '" + attribute + "'");
  }
  const AttributeBinding* best = nullptr;
  const Cell* bestCell = nullptr;
  bool inSomeCell = false;
  for (auto& [id, locator] : locators_)
  {
    if (!(locator.distance(p) <= tolerance_))
    {
      continue;
    }
    inSomeCell = true;
    const Cell& c = complex_.cell(id);
    for (const auto& b : c.attributes)
    {
      if (b.attribute != attribute)
      {
        continue;
      }
      const bool better = !best || b.priority > best->priority ||
        (b.priority == best->priority && c.dimension < bestCell->dimension);
      if (better)
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
  }
  else
  {
    r.value = inSomeCell ? declared->second.inside : declared->second.outside;
  }
  return r;
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
