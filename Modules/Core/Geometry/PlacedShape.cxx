// SPDX-License-Identifier: BSD-3-Clause
// Placed shapes (PlacedShape.h): affine placements, the checks every query starts with, the
// dimensions and world bounds of shapes, and their world field as an frep::Field.
#include "Geometry/PlacedShape.h"

#include "Geometry/Prepared.h"

#include "FRep/Tape.h"
#include "FRep/Vector.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace ictk::geometry
{
namespace detail
{

int partDimension(const ShapePart& p)
{
  switch (p.kind)
  {
    case ShapePart::Kind::Point:
      return 0;
    case ShapePart::Kind::Segment:
    case ShapePart::Kind::Polyline:
    case ShapePart::Kind::Arc:
      return 1;
    case ShapePart::Kind::CircularSegment:
    case ShapePart::Kind::Rectangle:
    case ShapePart::Kind::Disk:
    case ShapePart::Kind::Mesh:
      return 2;
    case ShapePart::Kind::Box:
    case ShapePart::Kind::Sphere:
      return 3;
    case ShapePart::Kind::Field:
      return p.fieldDimension == 2 ? 2 : 3;
    case ShapePart::Kind::Blend:
    case ShapePart::Kind::Union:
    case ShapePart::Kind::SpaceTimeBlend:
      return std::max(
        p.operandA ? shapeDimension(*p.operandA) : 0, p.operandB ? shapeDimension(*p.operandB) : 0);
  }
  return 3;
}

int shapeDimension(const PlacedShape& s)
{
  int d = 0;
  for (const auto& p : s.parts)
  {
    d = std::max(d, partDimension(p));
  }
  return d;
}

[[noreturn]] void fail(const PlacedShape& s, const std::string& what)
{
  throw std::invalid_argument("cell '" + s.cell + "': " + what);
}

[[noreturn]] void failPair(const PlacedShape& a, const PlacedShape& b, const std::string& what)
{
  throw std::invalid_argument("cells '" + a.cell + "' and '" + b.cell + "': " + what);
}

bool finite3(const Vec3& v)
{
  return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
}

Box3 fieldDomain(const ShapePart& p)
{
  Box3 b = p.bounds;
  bool set = b.valid();
  for (int i = 0; i < (p.fieldDimension == 2 ? 2 : 3); ++i)
  {
    set = set && b.hi[i] > b.lo[i];
  }
  if (!set)
  {
    b = Box3{ { -10, -10, -10 }, { 10, 10, 10 } };
  }
  if (p.fieldDimension == 2)
  {
    b.lo[2] = b.hi[2] = 0;
  }
  return b;
}

Box3 mapBox(const Affine& m, const Box3& b)
{
  Box3 r;
  for (int i = 0; i < 3; ++i)
  {
    double c = m.b[i], h = 0;
    for (int j = 0; j < 3; ++j)
    {
      c += m.a[3 * i + j] * 0.5 * (b.lo[j] + b.hi[j]);
      h += std::abs(m.a[3 * i + j]) * 0.5 * (b.hi[j] - b.lo[j]);
    }
    r.lo[i] = c - h;
    r.hi[i] = c + h;
  }
  return r;
}

void validate(const PlacedShape& s, int depth)
{
  if (depth > 64)
  {
    fail(s, "blends and unions nest too deeply (a cycle?)");
  }
  if (s.parts.empty())
  {
    fail(s, "has no shape");
  }
  for (double v : s.place.a)
  {
    if (!std::isfinite(v))
    {
      fail(s, "its placement has a non-finite entry");
    }
  }
  if (!finite3(s.place.b))
  {
    fail(s, "its placement has a non-finite entry");
  }
  for (const auto& p : s.parts)
  {
    for (const auto& q : p.points)
    {
      if (!finite3(q))
      {
        fail(s, "a shape point has a non-finite coordinate");
      }
    }
    if (!finite3(p.size) || !std::isfinite(p.radius) || !std::isfinite(p.amount))
    {
      fail(s, "a shape size, radius or blend amount is not finite");
    }
    if (p.size[0] < 0 || p.size[1] < 0 || p.size[2] < 0 || p.radius < 0 || p.amount < 0)
    {
      fail(s, "a shape size, radius or blend amount is negative");
    }
    if (!(p.a1 > 0 && p.a2 > 0 && std::isfinite(p.a1) && std::isfinite(p.a2)))
    {
      fail(s, "a blend's scales a1 and a2 must be positive and finite");
    }
    switch (p.kind)
    {
      case ShapePart::Kind::Point:
        if (p.points.empty())
        {
          fail(s, "a point needs its coordinates");
        }
        break;
      case ShapePart::Kind::Segment:
      case ShapePart::Kind::Arc:
      case ShapePart::Kind::CircularSegment:
      case ShapePart::Kind::Polyline:
        if (p.points.size() < 2)
        {
          fail(s, "a segment, polyline or arc needs two points or more");
        }
        break;
      case ShapePart::Kind::Field:
        if (!p.field)
        {
          fail(s, "a field shape has no field");
        }
        if (!finite3(p.bounds.lo) || !finite3(p.bounds.hi))
        {
          fail(s, "a field shape has non-finite bounds");
        }
        break;
      case ShapePart::Kind::Mesh:
        if (p.triangles.empty())
        {
          fail(s, "a mesh has no triangles");
        }
        for (const auto& t : p.triangles)
        {
          for (std::uint32_t i : t)
          {
            if (i >= p.points.size() || !finite3(p.points[i]))
            {
              fail(s, "a mesh triangle uses a missing or non-finite point");
            }
          }
        }
        break;
      case ShapePart::Kind::Blend:
      case ShapePart::Kind::Union:
      case ShapePart::Kind::SpaceTimeBlend:
        if (!p.operandA || !p.operandB)
        {
          fail(s, "a blend or union needs two operands");
        }
        if (p.kind == ShapePart::Kind::SpaceTimeBlend && !p.blend)
        {
          fail(s, "a space-time blend needs its function (made by spaceTimeBlendPart)");
        }
        validate(*p.operandA, depth + 1);
        validate(*p.operandB, depth + 1);
        break;
      default:
        break;
    }
  }
}

} // namespace detail

using namespace detail;

namespace
{

/// The local box of a part (where it lies before placement).
Box3 localBox(const ShapePart& p)
{
  switch (p.kind)
  {
    case ShapePart::Kind::Rectangle:
      return { { -0.5 * p.size[0], -0.5 * p.size[1], 0 }, { 0.5 * p.size[0], 0.5 * p.size[1], 0 } };
    case ShapePart::Kind::Disk:
    case ShapePart::Kind::Arc:
    case ShapePart::Kind::CircularSegment:
      return { { -p.radius, -p.radius, 0 }, { p.radius, p.radius, 0 } };
    case ShapePart::Kind::Box:
      return { { -0.5 * p.size[0], -0.5 * p.size[1], -0.5 * p.size[2] },
        { 0.5 * p.size[0], 0.5 * p.size[1], 0.5 * p.size[2] } };
    case ShapePart::Kind::Sphere:
      return { { -p.radius, -p.radius, -p.radius }, { p.radius, p.radius, p.radius } };
    case ShapePart::Kind::Field:
      return fieldDomain(p);
    default:
    {
      Box3 b{ { Inf, Inf, Inf }, { -Inf, -Inf, -Inf } };
      for (const auto& q : p.points)
      {
        for (int i = 0; i < 3; ++i)
        {
          b.lo[i] = std::min(b.lo[i], q[i]);
          b.hi[i] = std::max(b.hi[i], q[i]);
        }
      }
      return b;
    }
  }
}

// ---------------------------------------------------------------------------------------------
// World fields of placed shapes, for complex cells.

class ShapeFieldEvaluator final : public frep::FieldEvaluator
{
public:
  explicit ShapeFieldEvaluator(std::shared_ptr<const PlacedShape> shape)
    : shape_(std::move(shape))
    , prepared_(std::make_unique<Prepared>(*shape_))
  {
  }
  ShapeFieldEvaluator(std::shared_ptr<const PlacedShape> shape, std::unique_ptr<Prepared> prepared)
    : shape_(std::move(shape))
    , prepared_(std::move(prepared))
  {
  }
  void values(
    const double* x, const double* y, const double* z, double* out, std::size_t n) override
  {
    prepared_->values(x, y, z, out, n);
  }
  Interval bound(const Box3& box) override { return prepared_->bound(box); }
  double gradient(const frep::Point3& p, frep::Point3& grad) override
  {
    Vec3 g;
    const double v = prepared_->gradient(p, g);
    grad = g;
    return v;
  }
  /// The fields of the parts narrowed to the box (their tapes pruned there): cheaper, and
  /// what a region's fingerprint depends on is only what can matter there.
  std::unique_ptr<frep::FieldEvaluator> narrowed(const Box3& box) override
  {
    bool changed = false;
    auto p = std::make_unique<Prepared>(*prepared_, box, changed);
    if (!changed)
    {
      return nullptr;
    }
    return std::make_unique<ShapeFieldEvaluator>(shape_, std::move(p));
  }
  bool fingerprint(std::vector<std::uint64_t>& out) const override
  {
    return prepared_->fingerprint(out);
  }

private:
  std::shared_ptr<const PlacedShape> shape_;
  std::unique_ptr<Prepared> prepared_;
};

class ShapeField final : public frep::Field
{
public:
  explicit ShapeField(std::shared_ptr<const PlacedShape> shape)
    : shape_(std::move(shape))
  {
  }
  std::unique_ptr<frep::FieldEvaluator> evaluator() const override
  {
    return std::make_unique<ShapeFieldEvaluator>(shape_);
  }

private:
  std::shared_ptr<const PlacedShape> shape_;
};

} // namespace

frep::FieldPtr worldField(const PlacedShape& s)
{
  return std::make_shared<ShapeField>(std::make_shared<const PlacedShape>(s));
}

Affine Affine::fromTransform(const Vec3& translation, const Vec3& rotation, const Vec3& scale)
{
  const double cx = std::cos(rotation[0]), sx = std::sin(rotation[0]);
  const double cy = std::cos(rotation[1]), sy = std::sin(rotation[1]);
  const double cz = std::cos(rotation[2]), sz = std::sin(rotation[2]);
  // R = Rz Ry Rx, row-major.
  const double r[9] = { cz * cy, cz * sy * sx - sz * cx, cz * sy * cx + sz * sx, //
    sz * cy, sz * sy * sx + cz * cx, sz * sy * cx - cz * sx,                     //
    -sy, cy * sx, cy * cx };
  Affine m;
  for (int i = 0; i < 3; ++i)
  {
    for (int j = 0; j < 3; ++j)
    {
      m.a[3 * i + j] = r[3 * i + j] * scale[j];
    }
  }
  m.b = translation;
  return m;
}

Vec3 Affine::apply(const Vec3& p) const
{
  const Vec3 l = applyLinear(p);
  return { l[0] + b[0], l[1] + b[1], l[2] + b[2] };
}

Vec3 Affine::applyLinear(const Vec3& v) const
{
  return { a[0] * v[0] + a[1] * v[1] + a[2] * v[2], a[3] * v[0] + a[4] * v[1] + a[5] * v[2],
    a[6] * v[0] + a[7] * v[1] + a[8] * v[2] };
}

Affine Affine::operator*(const Affine& other) const
{
  Affine m;
  for (int i = 0; i < 3; ++i)
  {
    for (int j = 0; j < 3; ++j)
    {
      m.a[3 * i + j] =
        a[3 * i] * other.a[j] + a[3 * i + 1] * other.a[3 + j] + a[3 * i + 2] * other.a[6 + j];
    }
  }
  m.b = apply(other.b);
  return m;
}

Affine Affine::inverse() const
{
  const double c00 = a[4] * a[8] - a[5] * a[7], c01 = a[5] * a[6] - a[3] * a[8],
               c02 = a[3] * a[7] - a[4] * a[6];
  const double det = a[0] * c00 + a[1] * c01 + a[2] * c02;
  double big = 0;
  for (double v : a)
  {
    big = std::max(big, std::abs(v));
  }
  // Relative to the entries' size: a zero scale gives det = 0 exactly, a near-zero one a
  // matrix whose inverse is meaningless.
  if (!std::isfinite(det) || std::abs(det) <= 1e-14 * big * big * big)
  {
    throw std::invalid_argument("singular placement (a zero scale?)");
  }
  Affine m;
  const double inv = 1 / det;
  m.a = { c00 * inv, (a[2] * a[7] - a[1] * a[8]) * inv, (a[1] * a[5] - a[2] * a[4]) * inv,
    c01 * inv, (a[0] * a[8] - a[2] * a[6]) * inv, (a[2] * a[3] - a[0] * a[5]) * inv, c02 * inv,
    (a[1] * a[6] - a[0] * a[7]) * inv, (a[0] * a[4] - a[1] * a[3]) * inv };
  const Vec3 t = m.applyLinear(b);
  m.b = { -t[0], -t[1], -t[2] };
  return m;
}

bool Affine::isIdentity() const
{
  return a == std::array<double, 9>{ 1, 0, 0, 0, 1, 0, 0, 0, 1 } && b == Vec3{ 0, 0, 0 };
}

ShapePart spaceTimeBlendPart(PlacedShapePtr a, PlacedShapePtr b,
  const frep::SpaceTimeBlendParameters& p, double time, const std::vector<ControlPair>& pairs)
{
  ShapePart part;
  part.kind = ShapePart::Kind::SpaceTimeBlend;
  part.operandA = std::move(a);
  part.operandB = std::move(b);
  part.spaceTime = p;
  part.time = time;
  part.blend = frep::tapeField(frep::Tape::compile(
    frep::spaceTimeBlendExpr(frep::Expr::x(), frep::Expr::y(), frep::Expr(time), p)));
  part.warp = SpaceTimeWarp::at(pairs, std::clamp((time - p.t0) / (p.t1 - p.t0), 0.0, 1.0));
  return part;
}

double PlacedShape::value(const Vec3& world) const
{
  validate(*this);
  if (shapeDimension(*this) < 2)
  {
    fail(*this, "a point or curve has no inside field");
  }
  if (!finite3(world))
  {
    fail(*this, "the query point is not finite");
  }
  return Prepared(*this).value(world);
}

frep::Box3 PlacedShape::worldBounds() const
{
  Box3 r{ { Inf, Inf, Inf }, { -Inf, -Inf, -Inf } };
  auto add = [&](const Box3& b)
  {
    r = joinBoxes(r, b);
  };
  for (const auto& p : parts)
  {
    switch (p.kind)
    {
      case ShapePart::Kind::Disk:
      case ShapePart::Kind::Arc:
      case ShapePart::Kind::CircularSegment:
      case ShapePart::Kind::Sphere:
      {
        // The image of a circle (sphere) extends r |row i| about the centre along axis i.
        const int cols = p.kind == ShapePart::Kind::Sphere ? 3 : 2;
        Box3 b;
        for (int i = 0; i < 3; ++i)
        {
          double s = 0;
          for (int j = 0; j < cols; ++j)
          {
            s += place.a[3 * i + j] * place.a[3 * i + j];
          }
          const double h = p.radius * std::sqrt(s);
          b.lo[i] = place.b[i] - h;
          b.hi[i] = place.b[i] + h;
        }
        add(b);
        break;
      }
      case ShapePart::Kind::Point:
      case ShapePart::Kind::Segment:
      case ShapePart::Kind::Polyline:
        for (const auto& q : p.points)
        {
          const Vec3 w = place.apply(q);
          add({ w, w });
        }
        break;
      case ShapePart::Kind::Blend:
      case ShapePart::Kind::Union:
      case ShapePart::Kind::SpaceTimeBlend:
      {
        if (!p.operandA || !p.operandB)
        {
          break;
        }
        // The blend's bump reaches about 1.7 a0 beyond the operands where their fields are
        // distances (a0 / (1 + 2 d^2) = (2 - sqrt 2) d); 2 a0 covers it. The bounded blend's
        // displacement is at most a0 too (disp <= 1), and its half-cylinders are at most the
        // operands (an R-intersection is at most either argument).
        const double bump = p.kind == ShapePart::Kind::Blend ? p.amount
          : p.kind == ShapePart::Kind::SpaceTimeBlend        ? std::abs(p.spaceTime.a0)
                                                             : 0.0;
        // A warped operand is seen up to its largest displacement away.
        double reach = 0;
        for (const auto* shifts : { &p.warp.shiftA, &p.warp.shiftB })
          for (const Vec3& d : *shifts)
            reach = std::max(reach, frep::norm(d));
        add(padded(
          joinBoxes(p.operandA->worldBounds(), p.operandB->worldBounds()), 2 * bump + reach));
        break;
      }
      default:
        add(mapBox(place, localBox(p)));
        break;
    }
  }
  return r;
}

} // namespace ictk::geometry
