// SPDX-License-Identifier: BSD-3-Clause
#include "FRep/Implants.h"

#include "FRep/Operations.h"
#include "FRep/ParameterChecks.h"
#include "FRep/Vector.h"

#include <cmath>

namespace ictk::frep
{
namespace
{
constexpr double pi = 3.14159265358979323846;
using namespace detail;

/// The distance to the z axis in an implant's own frame.
Expr radial()
{
  return sqrt(square(Expr::x()) + square(Expr::y()));
}

/// min(z, length - z): the slab the pin and the screw fill.
Expr slab(const Expr& u, double lo, double hi)
{
  return min(u - lo, hi - u);
}

/// The frame of a placement, checked in the name of `who`: the unit x, y, z axes.
std::array<Vec3, 3> frameOf(const char* who, const Placement& where)
{
  requireFinite(who, "origin", where.origin);
  requireFinite(who, "axis", where.axis);
  requireFinite(who, "reference", where.reference);
  const double axisLength = norm(where.axis);
  if (!(axisLength > 0))
  {
    fail(who, "the placement's axis must not be zero");
  }
  const Vec3 ez = scale(where.axis, 1 / axisLength);
  Vec3 reference = where.reference;
  if (norm(reference) == 0)
  {
    int least = 0;
    for (int a = 1; a < 3; ++a)
    {
      if (std::abs(ez[a]) < std::abs(ez[least]))
      {
        least = a;
      }
    }
    reference[least] = 1;
  }
  const Vec3 along = sub(reference, scale(ez, dot(reference, ez)));
  const double alongLength = norm(along);
  if (!(alongLength > 1e-9 * norm(reference)))
  {
    fail(who, "the placement's reference must not be parallel to its axis");
  }
  const Vec3 ex = scale(along, 1 / alongLength);
  return { ex, cross(ez, ex), ez };
}

Shape placedAs(const char* who, const Shape& local, const Placement& where)
{
  requireAxes(who, local, domainAxes(Domain::XYZ));
  const std::array<Vec3, 3> e = frameOf(who, where);
  // The local coordinates of p are the projections of p - origin on the frame's axes.
  const Expr dx = Expr::x() - where.origin[0];
  const Expr dy = Expr::y() - where.origin[1];
  const Expr dz = Expr::z() - where.origin[2];
  auto project = [&](const Vec3& a)
  {
    return dx * a[0] + dy * a[1] + dz * a[2];
  };
  const std::array<Expr, AxisCount> map{ project(e[0]), project(e[1]), project(e[2]), Expr::t() };
  return Shape(local.function().substitute(map), local.domain(), local.label());
}

Shape placed(const char* implant, const Expr& local, const Placement& where)
{
  return placedAs(implant, Shape(local, Domain::XYZ, implant), where);
}

} // namespace

Shape place(const Shape& local, const Placement& where)
{
  return placedAs("place", local, where);
}

Shape pin(double radius, double length, const Placement& where)
{
  requirePositive("pin", "radius", radius);
  requirePositive("pin", "length", length);
  return placed("pin", min(radius - radial(), slab(Expr::z(), 0, length)), where);
}

Shape screw(const ScrewThread& t, const Placement& where)
{
  requirePositive("screw", "coreRadius", t.coreRadius);
  requirePositive("screw", "majorRadius", t.majorRadius);
  requirePositive("screw", "pitch", t.pitch);
  requirePositive("screw", "length", t.length);
  if (!(t.coreRadius < t.majorRadius))
  {
    fail("screw",
      "coreRadius must be below majorRadius (got " + show(t.coreRadius) + " and " +
        show(t.majorRadius) + ")");
  }
  const Expr v = Expr::z() / t.pitch - atan2(Expr::y(), Expr::x()) / (2 * pi);
  // frac(v), clamped to [0, 1] where it already lies: the clamp changes no value, but gives the
  // interval extension [0, 1] instead of v's width plus floor's.
  const Expr u = min(max(v - floor(v), Expr(0.0)), Expr(1.0));
  const Expr r = t.coreRadius + (t.majorRadius - t.coreRadius) * (1.0 - abs(2.0 * u - 1.0));
  return placed("screw", min(r - radial(), slab(Expr::z(), 0, t.length)), where);
}

Shape plate(const PlateShape& p, const Placement& where)
{
  requirePositive("plate", "length", p.length);
  requirePositive("plate", "width", p.width);
  requirePositive("plate", "thickness", p.thickness);
  requirePositive("plate", "holeRadius", p.holeRadius);
  Expr f = min(min(slab(Expr::x(), 0, p.length), slab(Expr::y(), 0, p.width)),
    slab(Expr::z(), 0, p.thickness));
  for (std::size_t i = 0; i < p.holes.size(); ++i)
  {
    const Vec2& h = p.holes[i];
    const std::string name = "holes[" + std::to_string(i) + "]";
    requireFinite("plate", name, h);
    if (!(h[0] - p.holeRadius > 0 && h[0] + p.holeRadius < p.length && h[1] - p.holeRadius > 0 &&
          h[1] + p.holeRadius < p.width))
    {
      fail("plate",
        name + " (" + show(h[0]) + ", " + show(h[1]) + ") with radius " + show(p.holeRadius) +
          " does not lie within the plate [0, " + show(p.length) + "] x [0, " + show(p.width) +
          "]");
    }
    for (std::size_t j = 0; j < i; ++j)
    {
      if (std::hypot(h[0] - p.holes[j][0], h[1] - p.holes[j][1]) <= 2 * p.holeRadius)
      {
        fail("plate", name + " overlaps holes[" + std::to_string(j) + "]");
      }
    }
    f = min(f, sqrt(square(Expr::x() - h[0]) + square(Expr::y() - h[1])) - p.holeRadius);
  }
  return placed("plate", f, where);
}

Expr gyroidDistance(double cellSize)
{
  requirePositive("gyroid", "cellSize", cellSize);
  const double k = 2 * pi / cellSize;
  const Expr sx = sin(k * Expr::x()), cx = cos(k * Expr::x());
  const Expr sy = sin(k * Expr::y()), cy = cos(k * Expr::y());
  const Expr sz = sin(k * Expr::z()), cz = cos(k * Expr::z());
  const Expr g = sx * cy + sy * cz + sz * cx;
  // grad g / k, differentiated by hand.
  const Expr gx = cx * cy - sz * sx;
  const Expr gy = cy * cz - sx * sy;
  const Expr gz = cz * cx - sy * sz;
  return abs(g) / (k * sqrt(square(gx) + square(gy) + square(gz)));
}

Shape gyroidSheet(double cellSize, const Expr& wallThickness, const Placement& where)
{
  if ((wallThickness.axesUsed() & ~domainAxes(Domain::XYZ)) != 0)
  {
    fail("gyroid", "wallThickness may depend on x, y and z only");
  }
  return placed("gyroid", 0.5 * wallThickness - gyroidDistance(cellSize), where);
}

Shape interfaceShell(const Shape& implant, double thickness)
{
  requirePositive("interfaceShell", "thickness", thickness);
  return intersectMinMax(offset(implant, thickness), negate(implant))
    .withLabel("interface shell of " + implant.label());
}

} // namespace ictk::frep
