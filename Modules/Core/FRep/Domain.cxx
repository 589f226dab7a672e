// SPDX-License-Identifier: BSD-3-Clause
#include "FRep/Domain.h"

#include <sstream>

namespace ictk::frep
{

namespace
{
constexpr std::uint8_t bit(Axis a)
{
  return static_cast<std::uint8_t>(1u << static_cast<int>(a));
}

struct DomainInfo
{
  Domain domain;
  const char* name;
  std::uint8_t axes;
};

constexpr DomainInfo domainTable[] = {
  { Domain::X, "X", bit(Axis::X) },
  { Domain::T, "T", bit(Axis::T) },
  { Domain::XY, "XY", bit(Axis::X) | bit(Axis::Y) },
  { Domain::XT, "XT", bit(Axis::X) | bit(Axis::T) },
  { Domain::XYZ, "XYZ", bit(Axis::X) | bit(Axis::Y) | bit(Axis::Z) },
  { Domain::XYT, "XYT", bit(Axis::X) | bit(Axis::Y) | bit(Axis::T) },
  { Domain::XYZT, "XYZT", bit(Axis::X) | bit(Axis::Y) | bit(Axis::Z) | bit(Axis::T) },
};

std::string axesString(std::uint8_t axes)
{
  std::string s;
  for (int i = 0; i < AxisCount; ++i)
  {
    if (axes & (1u << i))
    {
      s += axisName(static_cast<Axis>(i));
    }
  }
  return s.empty() ? "none" : s;
}
} // namespace

const char* domainName(Domain d)
{
  return domainTable[static_cast<int>(d)].name;
}

std::uint8_t domainAxes(Domain d)
{
  return domainTable[static_cast<int>(d)].axes;
}

int domainDimension(Domain d)
{
  int n = 0;
  for (int i = 0; i < AxisCount; ++i)
  {
    n += (domainAxes(d) >> i) & 1;
  }
  return n;
}

std::vector<Axis> domainCoordinates(Domain d)
{
  std::vector<Axis> axes;
  for (int i = 0; i < AxisCount; ++i)
  {
    if (domainAxes(d) & (1u << i))
    {
      axes.push_back(static_cast<Axis>(i));
    }
  }
  return axes;
}

std::optional<Domain> domainFromAxes(std::uint8_t axes)
{
  for (const auto& info : domainTable)
  {
    if (info.axes == axes)
    {
      return info.domain;
    }
  }
  return std::nullopt;
}

std::optional<Domain> domainFromName(const std::string& name)
{
  for (const auto& info : domainTable)
  {
    if (name == info.name)
    {
      return info.domain;
    }
  }
  return std::nullopt;
}

bool domainContains(Domain outer, Domain inner)
{
  return (domainAxes(outer) & domainAxes(inner)) == domainAxes(inner);
}

Shape::Shape(Expr f, Domain domain, std::string label)
  : f_(std::move(f))
  , domain_(domain)
  , label_(std::move(label))
{
  const std::uint8_t extra = static_cast<std::uint8_t>(f_.axesUsed() & ~domainAxes(domain_));
  if (extra)
  {
    throw DomainError("shape '" + label_ + "' is declared on domain " + domainName(domain_) +
      " but its function uses coordinate(s) " + axesString(extra) + " outside that domain");
  }
}

std::string Shape::describe() const
{
  std::ostringstream os;
  os << "'" << (label_.empty() ? "shape" : label_) << "' (domain " << domainName(domain_) << ")";
  return os.str();
}

void requireSameDomain(const char* operation, const Shape& a, const Shape& b)
{
  if (a.domain() != b.domain())
  {
    throw DomainError(std::string(operation) + ": cannot combine " + a.describe() + " with " +
      b.describe() +
      "; operands must share one modelling domain (re-project the lower-dimensional one with "
      "reproject() or build a cartesianProduct() first)");
  }
}

void requireAxes(const char* operation, const Shape& s, std::uint8_t axes)
{
  const std::uint8_t missing = static_cast<std::uint8_t>(axes & ~domainAxes(s.domain()));
  if (missing)
  {
    throw DomainError(std::string(operation) + ": " + s.describe() + " has no coordinate(s) " +
      axesString(missing));
  }
}

Shape reproject(const Shape& s, Domain target, const std::vector<Axis>& axisMap)
{
  const std::vector<Axis> source = domainCoordinates(s.domain());
  if (axisMap.size() != source.size())
  {
    throw DomainError("reproject: " + s.describe() + " has " + std::to_string(source.size()) +
      " coordinate(s) but the axis map names " + std::to_string(axisMap.size()));
  }
  std::uint8_t used = 0;
  std::array<Expr, AxisCount> map{ Expr::x(), Expr::y(), Expr::z(), Expr::t() };
  for (std::size_t i = 0; i < source.size(); ++i)
  {
    const std::uint8_t b = bit(axisMap[i]);
    if (!(domainAxes(target) & b))
    {
      throw DomainError("reproject: target domain " + std::string(domainName(target)) +
        " has no coordinate " + axisName(axisMap[i]) + " for " + s.describe());
    }
    if (used & b)
    {
      throw DomainError("reproject: coordinate " + std::string(axisName(axisMap[i])) +
        " is used twice in the axis map for " + s.describe());
    }
    used |= b;
    map[static_cast<int>(source[i])] = Expr::variable(axisMap[i]);
  }
  if (domainDimension(target) < domainDimension(s.domain()))
  {
    throw DomainError("reproject: target domain " + std::string(domainName(target)) +
      " has fewer coordinates than " + s.describe() + "; use project() to lower dimension");
  }
  return Shape(s.function().substitute(map), target, s.label());
}

} // namespace ictk::frep
