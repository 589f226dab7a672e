// SPDX-License-Identifier: BSD-3-Clause
#include "FRep/Quadrics.h"

#include "FRep/Primitives.h"

#include <stdexcept>

namespace ictk::frep
{

const std::vector<QuadricTypeInfo>& quadricTypes()
{
  // Coefficients in eq. (1)'s order: A11 A22 A33 A12 A13 A23 A14 A24 A34 A44.
  static const std::vector<QuadricTypeInfo> types = {
    { QuadricType::Ell, "ell", "ellipsoid (the unit ball)", "1 - x^2 - y^2 - z^2",
      { -1, -1, -1, 0, 0, 0, 0, 0, 0, 1 } },
    { QuadricType::Seat, "seat", "above a hyperbolic paraboloid (saddle)", "z - x^2 + y^2",
      { -1, 1, 0, 0, 0, 0, 0, 0, 1, 0 } },
    { QuadricType::Ellpar, "ellpar", "elliptic paraboloid opening towards +z", "z - x^2 - y^2",
      { -1, -1, 0, 0, 0, 0, 0, 0, 1, 0 } },
    { QuadricType::Unihyp, "unihyp", "hyperboloid of one sheet about z", "1 - x^2 - y^2 + z^2",
      { -1, -1, 1, 0, 0, 0, 0, 0, 0, 1 } },
    { QuadricType::Duahyp, "duahyp", "hyperboloid of two sheets about z", "z^2 - x^2 - y^2 - 1",
      { -1, -1, 1, 0, 0, 0, 0, 0, 0, -1 } },
    { QuadricType::Cone, "cone", "double cone about z, half-angle 45 degrees", "z^2 - x^2 - y^2",
      { -1, -1, 1, 0, 0, 0, 0, 0, 0, 0 } },
    { QuadricType::Cylinder, "cylinder", "unit cylinder about z", "1 - x^2 - y^2",
      { -1, -1, 0, 0, 0, 0, 0, 0, 0, 1 } },
    { QuadricType::Layer, "layer", "the slab |z| <= 1", "1 - z^2",
      { 0, 0, -1, 0, 0, 0, 0, 0, 0, 1 } },
    { QuadricType::Plane, "plane", "the half-space z <= 0", "-z",
      { 0, 0, 0, 0, 0, 0, 0, 0, -1, 0 } },
    { QuadricType::Clin, "clin", "double wedge about the y axis", "z^2 - x^2",
      { -1, 0, 1, 0, 0, 0, 0, 0, 0, 0 } },
    { QuadricType::Parabola, "parabola", "parabolic cylinder along y", "z - x^2",
      { -1, 0, 0, 0, 0, 0, 0, 0, 1, 0 } },
    { QuadricType::Hyperbola, "hyperbola", "hyperbolic cylinder along y", "z^2 - x^2 - 1",
      { -1, 0, 1, 0, 0, 0, 0, 0, 0, -1 } },
  };
  return types;
}

std::optional<QuadricType> quadricTypeFromKeyword(const std::string& keyword)
{
  for (const QuadricTypeInfo& t : quadricTypes())
  {
    if (keyword == t.keyword)
    {
      return t.type;
    }
  }
  return std::nullopt;
}

const QuadricTypeInfo& quadricTypeInfo(QuadricType type)
{
  for (const QuadricTypeInfo& t : quadricTypes())
  {
    if (t.type == type)
    {
      return t;
    }
  }
  throw std::invalid_argument("quadricTypeInfo: not a quadric type");
}

Shape namedQuadric(QuadricType type)
{
  const QuadricTypeInfo& t = quadricTypeInfo(type);
  return quadric(t.coefficients).withLabel(t.keyword);
}

} // namespace ictk::frep
