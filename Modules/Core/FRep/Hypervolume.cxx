// SPDX-License-Identifier: BSD-3-Clause
#include "FRep/Hypervolume.h"

#include <cmath>
#include <stdexcept>

namespace ictk::frep
{

Hypervolume::Hypervolume(Shape geometry, double threshold)
  : geometry_(std::move(geometry))
  , threshold_(threshold)
{
  if (!std::isfinite(threshold))
  {
    throw std::invalid_argument("Hypervolume: the threshold must be finite");
  }
}

Hypervolume& Hypervolume::addAttribute(Attribute attribute)
{
  const std::string where = "attribute '" + attribute.name + "'";
  if (attribute.name.empty())
  {
    throw std::invalid_argument("Hypervolume: an attribute needs a name");
  }
  if (findAttribute(attribute.name))
  {
    throw std::invalid_argument("Hypervolume: " + where + " is defined twice");
  }
  const std::size_t n = attribute.components.size();
  if (n == 0)
  {
    throw std::invalid_argument("Hypervolume: " + where + " has no component");
  }
  if (attribute.insideDefault.empty())
  {
    attribute.insideDefault.assign(n, 0.0);
  }
  if (attribute.outsideDefault.empty())
  {
    attribute.outsideDefault.assign(n, 0.0);
  }
  if (attribute.insideDefault.size() != n || attribute.outsideDefault.size() != n)
  {
    throw std::invalid_argument("Hypervolume: " + where + " has " + std::to_string(n) +
      " component(s) but its defaults have " + std::to_string(attribute.insideDefault.size()) +
      " (inside) and " + std::to_string(attribute.outsideDefault.size()) + " (outside)");
  }
  if (attribute.tensorRows < 0 ||
    (attribute.tensorRows > 0 && n % static_cast<std::size_t>(attribute.tensorRows) != 0))
  {
    throw std::invalid_argument("Hypervolume: " + where + " has " + std::to_string(n) +
      " components, not a tensor with " + std::to_string(attribute.tensorRows) + " rows");
  }
  const std::uint8_t allowed = domainAxes(geometry_.domain());
  auto check = [&](const Expr& e, const char* what)
  {
    if (e.axesUsed() & ~allowed)
    {
      throw std::invalid_argument("Hypervolume: the " + std::string(what) + " of " + where +
        " uses coordinates outside the geometry's domain " + domainName(geometry_.domain()));
    }
  };
  check(attribute.partition, "partition");
  for (const Expr& c : attribute.components)
  {
    check(c, "function");
  }
  attributes_.push_back(std::move(attribute));
  return *this;
}

const Attribute* Hypervolume::findAttribute(const std::string& name) const
{
  for (const Attribute& a : attributes_)
  {
    if (a.name == name)
    {
      return &a;
    }
  }
  return nullptr;
}

std::size_t Hypervolume::attributeComponentCount() const
{
  std::size_t n = 0;
  for (const Attribute& a : attributes_)
  {
    n += a.components.size();
  }
  return n;
}

TapePtr Hypervolume::compile() const
{
  std::vector<Expr> outputs{ geometry_.function() };
  for (const Attribute& a : attributes_)
  {
    outputs.push_back(a.partition);
    outputs.insert(outputs.end(), a.components.begin(), a.components.end());
  }
  return Tape::compile(outputs);
}

HypervolumeEvaluator::HypervolumeEvaluator(
  const Hypervolume& hv, const std::vector<double>& parameters)
  : hv_(hv)
  , evaluator_(hv.compile(), parameters)
  , outputs_(evaluator_.tape()->outputs().size())
{
}

void HypervolumeEvaluator::eval(const std::array<double, 4>& p, double& value, double* attributes)
{
  evaluator_.evalAll(p, outputs_.data());
  value = outputs_[0];
  const bool inside = value >= hv_.threshold();
  std::size_t k = 1;
  for (const Attribute& a : hv_.attributes())
  {
    const bool inPartition = outputs_[k++] >= 0;
    for (std::size_t c = 0; c < a.components.size(); ++c, ++k)
    {
      *attributes++ =
        inPartition ? outputs_[k] : (inside ? a.insideDefault[c] : a.outsideDefault[c]);
    }
  }
}

int HypervolumeEvaluator::membership(const std::array<double, 4>& p)
{
  const double f = evaluator_.eval(p[0], p[1], p[2], p[3]);
  const double T = hv_.threshold();
  return f > T ? 2 : (f == T ? 1 : 0);
}

Hypervolume spaceTimeSolid(const Hypervolume& hv)
{
  if (hv.geometry().domain() != Domain::XYT)
  {
    throw DomainError(std::string("spaceTimeSolid: the model's domain is ") +
      domainName(hv.geometry().domain()) +
      "; only an XYT model (2D over time) is a 3D solid in space-time");
  }
  std::array<Expr, AxisCount> map;
  for (int a = 0; a < AxisCount; ++a)
    map[static_cast<std::size_t>(a)] = Expr::variable(static_cast<Axis>(a));
  map[static_cast<std::size_t>(Axis::T)] = Expr::z();
  const Shape& g = hv.geometry();
  Hypervolume out(
    Shape(g.function().substitute(map), Domain::XYZ, "spaceTimeSolid(" + g.label() + ")"),
    hv.threshold());
  for (Attribute a : hv.attributes())
  {
    a.partition = a.partition.substitute(map);
    for (Expr& c : a.components)
      c = c.substitute(map);
    out.addAttribute(std::move(a));
  }
  return out;
}

} // namespace ictk::frep
