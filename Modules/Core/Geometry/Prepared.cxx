// SPDX-License-Identifier: BSD-3-Clause
// The prepared shape of Prepared.h: its world pieces, field, enclosure and gradient.
//
// - A shape is prepared per query (Prepared): the inverse placement, one field evaluator per
//   Field part, and the world "pieces" of its analytic parts: points, segments and arcs of
//   ellipses (the image of a circle under the placement; a circle when the placement is a
//   similarity in the plane). 0D/1D shapes are their pieces; rectangles, disks and circular
//   segments are bounded by theirs.
//
// Its enclosures (bound) are interval arithmetic through the placement: the tape fields' own
// interval evaluators for Field parts, the helpers of Prepared.h for the analytic parts.
#include "Geometry/Prepared.h"

#include "FRep/Vector.h"

#include <algorithm>
#include <cmath>
#include <queue>
#include <stdexcept>
#include <utility>

namespace ictk::geometry::detail
{
namespace
{

/// An operand's value as the blends take it: -Inf (outside every part, or NaN) and huge values
/// would make its squares overflow; beyond 1e150 the sign of a blend no longer changes.
double operandValue(double f)
{
  return std::isnan(f) ? -1e150 : std::clamp(f, -1e150, 1e150);
}

/// The R-function union f1 + f2 + sqrt(f1^2 + f2^2) (thesis L620), its sign the sign of
/// max(f1, f2). Where f1 + f2 < 0 it is computed as 2 f1 f2 / (f1 + f2 - sqrt(f1^2 + f2^2)), the
/// same number without the cancellation that loses the nearer operand next to a far one
/// (f1 = -1e9, f2 = 0.5: 0.5, where the sum gives 0).
double rUnion(double f1, double f2)
{
  const double s = f1 + f2, h = std::hypot(f1, f2);
  return s >= 0 ? s + h : 2 * f1 * f2 / (s - h);
}

/// Pasko's blending union (thesis 2.2.3, L643-L647): the R-union plus the displacement
/// a0 / (1 + (f1/a1)^2 + (f2/a2)^2), a bump of height a0 where both fields are near 0 that
/// fills the crease between the operands; a1 and a2 say how far into each operand it reaches.
double blendUnion(double f1, double f2, const ShapePart& p)
{
  f1 = operandValue(f1);
  f2 = operandValue(f2);
  const double q1 = f1 / p.a1, q2 = f2 / p.a2;
  return rUnion(f1, f2) + p.amount / (1 + q1 * q1 + q2 * q2);
}
// The R-function part is nondecreasing in each argument; the bump is bounded by the ranges of
// f1^2 + f2^2.

/// Where a space-time blend's operand is evaluated for the world point w: w moved by its
/// warp's backward displacement (SpaceTimeWarp.h), or w itself without a warp.
Vec3 warped(const SpaceTimeWarp& warp, const std::vector<Vec3>& shifts, const Vec3& w)
{
  if (warp.empty())
    return w;
  const Vec3 d = warp.shift(shifts, w);
  return { w[0] + d[0], w[1] + d[1], w[2] + d[2] };
}

/// The boxes an operand is evaluated on for the world box w: the displacement is a convex
/// combination of the nodes' shifts, so it lies in their bounding box.
Box3 warpedBox(const std::vector<Vec3>& shifts, Box3 w)
{
  if (shifts.empty())
    return w;
  for (int k = 0; k < 3; ++k)
  {
    double lo = Inf, hi = -Inf;
    for (const Vec3& d : shifts)
    {
      lo = std::min(lo, d[k]);
      hi = std::max(hi, d[k]);
    }
    w.lo[k] += lo;
    w.hi[k] += hi;
  }
  return w;
}

/// An operand's value at the warped point and its gradient with respect to w (the chain rule:
/// the transposed Jacobian of w -> w + shift(w) times the operand's gradient there).
double warpedGradient(const Prepared& operand, const SpaceTimeWarp& warp,
  const std::vector<Vec3>& shifts, const Vec3& w, Vec3& g)
{
  if (warp.empty())
    return operand.gradient(w, g);
  double j[9];
  const Vec3 d = warp.shift(shifts, w, j);
  Vec3 go;
  const double v = operand.gradient({ w[0] + d[0], w[1] + d[1], w[2] + d[2] }, go);
  for (int c = 0; c < 3; ++c)
    g[c] = go[c] + j[c] * go[0] + j[3 + c] * go[1] + j[6 + c] * go[2];
  return v;
}

/// The cross-section's value g(fa, fb) and its partial derivatives (dg/dfa, dg/dfb, 0).
double spaceTimeSlice(const PreparedPart& pp, double fa, double fb, Vec3& dg)
{
  frep::Point3 grad;
  const double v = pp.eval->gradient({ operandValue(fa), operandValue(fb), 0 }, grad);
  dg = { grad[0], grad[1], 0 };
  return std::isnan(v) ? -Inf : v;
}

// The R-union is nondecreasing in each argument (its partial derivatives are 1 + f_i / h >= 0),
// so its range is between its values at the low and the high corners; the displacement's is
// bounded by the ranges of (f1/a1)^2 + (f2/a2)^2.
Interval blendUnion(Interval f1, Interval f2, const ShapePart& p)
{
  // NaN is outside in blendUnion(double...): an enclosure must allow its -1e150.
  auto low = [](const Interval& f)
  {
    return f.maybeNaN ? -1e150 : operandValue(f.lo);
  };
  auto high = [](const Interval& f)
  {
    return std::isnan(f.hi) ? 1e150 : operandValue(f.hi);
  };
  const double lo1 = low(f1), hi1 = high(f1), lo2 = low(f2), hi2 = high(f2);
  const Interval s1 = ivSquare(iv(lo1 / p.a1, hi1 / p.a1)),
                 s2 = ivSquare(iv(lo2 / p.a2, hi2 / p.a2));
  const double lo = rUnion(lo1, lo2) + p.amount / (1 + s1.hi + s2.hi);
  const double hi = rUnion(hi1, hi2) + p.amount / (1 + s1.lo + s2.lo);
  return iv(lo, hi);
}

} // namespace

double boxDiagonal(const Box3& b)
{
  return frep::norm(frep::sub(b.hi, b.lo));
}

Box3 joinBoxes(const Box3& a, const Box3& b)
{
  Box3 r;
  for (int i = 0; i < 3; ++i)
  {
    r.lo[i] = std::min(a.lo[i], b.lo[i]);
    r.hi[i] = std::max(a.hi[i], b.hi[i]);
  }
  return r;
}

Box3 meetBoxes(const Box3& a, const Box3& b)
{
  Box3 r;
  for (int i = 0; i < 3; ++i)
  {
    r.lo[i] = std::max(a.lo[i], b.lo[i]);
    r.hi[i] = std::min(a.hi[i], b.hi[i]);
  }
  return r;
}

Prepared::Prepared(const PlacedShape& s)
  : shape(&s)
{
  dim = shapeDimension(s);
  flat = dim <= 2;
  Affine inverse;
  try
  {
    inverse = s.place.inverse();
  }
  catch (const std::invalid_argument&)
  {
    fail(s, "its placement is singular (a zero scale?)");
  }
  for (const auto& part : s.parts)
  {
    PreparedPart pp;
    pp.part = &part;
    pp.dim = partDimension(part);
    pp.toLocal = inverse;
    switch (part.kind)
    {
      case ShapePart::Kind::Field:
        pp.eval = part.field->evaluator();
        pp.domain = fieldDomain(part);
        analytic = false;
        break;
      case ShapePart::Kind::Blend:
      case ShapePart::Kind::Union:
        pp.a = std::make_unique<Prepared>(*part.operandA);
        pp.b = std::make_unique<Prepared>(*part.operandB);
        analytic = false;
        break;
      case ShapePart::Kind::SpaceTimeBlend:
        pp.a = std::make_unique<Prepared>(*part.operandA);
        pp.b = std::make_unique<Prepared>(*part.operandB);
        // g(fa, fb) as a field of (x, y): its values, bounds and gradient are the kernel's.
        pp.eval = part.blend->evaluator();
        analytic = false;
        break;
      case ShapePart::Kind::Box:
      case ShapePart::Kind::Sphere:
        analytic = false;
        break;
      case ShapePart::Kind::Mesh:
        fail(s,
          "is a mesh (a .obj or .off surface): the geometric queries, fields, blends and "
          "unions do not take meshes");
      default:
        break;
    }
    if (part.kind == ShapePart::Kind::CircularSegment)
    {
      // The chord runs from the arc's end q to its start p; the region is on its left.
      const double a0 = std::atan2(part.points[0][1], part.points[0][0]);
      const double a1 = std::atan2(part.points[1][1], part.points[1][0]);
      const V2 p{ part.radius * std::cos(a0), part.radius * std::sin(a0) };
      const V2 q{ part.radius * std::cos(a1), part.radius * std::sin(a1) };
      const V2 e = p - q;
      const double len = norm(e);
      if (len == 0)
      {
        pp.hx = pp.hy = 0;
        pp.hd = -Inf; // a full disk
      }
      else
      {
        pp.hx = -e.y / len;
        pp.hy = e.x / len;
        pp.hd = pp.hx * q.x + pp.hy * q.y;
      }
    }
    parts.push_back(std::move(pp));
    addPieces(part);
  }
  bounds = s.worldBounds();
  scale = std::max(boxDiagonal(bounds), 1e-300);
}

Prepared::Prepared(const Prepared& parent, const Box3& w, bool& changed)
  : shape(parent.shape)
  , dim(parent.dim)
  , flat(parent.flat)
  , analytic(parent.analytic)
  , pieces(parent.pieces)
  , bounds(parent.bounds)
  , scale(parent.scale)
{
  const Box3 world = flatten(w, flat);
  for (const PreparedPart& from : parent.parts)
  {
    PreparedPart pp;
    pp.part = from.part;
    pp.dim = from.dim;
    pp.toLocal = from.toLocal;
    pp.eval = from.eval;
    pp.domain = from.domain;
    pp.hx = from.hx;
    pp.hy = from.hy;
    pp.hd = from.hd;
    const ShapePart::Kind kind = from.part->kind;
    if (kind == ShapePart::Kind::Field && pp.dim >= 2)
    {
      // The local points of w lie in mapBox(toLocal, w) up to the rounding of the map, which the
      // margin covers: the narrowed field is only ever evaluated inside the box it was narrowed
      // to.
      Box3 l = mapBox(pp.toLocal, world);
      if (pp.dim <= 2)
      {
        l.lo[2] = l.hi[2] = 0;
      }
      for (int i = 0; i < 3; ++i)
      {
        const double margin =
          1e-9 * (std::abs(l.lo[i]) + std::abs(l.hi[i]) + (l.hi[i] - l.lo[i])) + 1e-300;
        l.lo[i] -= margin;
        l.hi[i] += margin;
      }
      if (auto n = from.eval->narrowed(l))
      {
        pp.eval = std::move(n);
        changed = true;
      }
    }
    else if ((kind == ShapePart::Kind::Blend || kind == ShapePart::Kind::Union) && from.a && from.b)
    {
      pp.a = std::make_unique<Prepared>(*from.a, w, changed);
      pp.b = std::make_unique<Prepared>(*from.b, w, changed);
    }
    else if (from.a && from.b)
    {
      // A space-time blend evaluates its operands at warped points: left as they are.
      pp.a = std::make_unique<Prepared>(*from.a->shape);
      pp.b = std::make_unique<Prepared>(*from.b->shape);
    }
    parts.push_back(std::move(pp));
  }
}

bool Prepared::fingerprint(std::vector<std::uint64_t>& out) const
{
  using frep::fingerprintWord;
  // A nested list of words is preceded by its count, so that no two shapes give the same words.
  auto nested = [&out](const auto& append)
  {
    const std::size_t at = out.size();
    out.push_back(0);
    if (!append())
    {
      return false;
    }
    out[at] = out.size() - at - 1;
    return true;
  };
  out.push_back(0x7072657061726564ull); // "prepared"
  out.push_back(static_cast<std::uint64_t>(dim));
  out.push_back(flat ? 1 : 0);
  out.push_back(parts.size());
  for (const PreparedPart& pp : parts)
  {
    const ShapePart& p = *pp.part;
    out.push_back(static_cast<std::uint64_t>(p.kind));
    out.push_back(static_cast<std::uint64_t>(pp.dim));
    if (pp.dim < 2)
    {
      continue; // points and curves are not part of the field (value() skips them)
    }
    for (double v : pp.toLocal.a)
    {
      out.push_back(fingerprintWord(v));
    }
    for (double v : pp.toLocal.b)
    {
      out.push_back(fingerprintWord(v));
    }
    switch (p.kind)
    {
      case ShapePart::Kind::Rectangle:
      case ShapePart::Kind::Disk:
      case ShapePart::Kind::CircularSegment:
      case ShapePart::Kind::Box:
      case ShapePart::Kind::Sphere:
        for (double v : { p.size[0], p.size[1], p.size[2], p.radius, pp.hx, pp.hy, pp.hd })
        {
          out.push_back(fingerprintWord(v));
        }
        break;
      case ShapePart::Kind::Field:
        for (int i = 0; i < 3; ++i)
        {
          out.push_back(fingerprintWord(pp.domain.lo[i]));
          out.push_back(fingerprintWord(pp.domain.hi[i]));
        }
        if (!nested([&] { return pp.eval->fingerprint(out); }))
        {
          return false;
        }
        break;
      case ShapePart::Kind::Blend:
      case ShapePart::Kind::Union:
        out.push_back(fingerprintWord(p.amount));
        if (!nested([&] { return pp.a->fingerprint(out); }) ||
          !nested([&] { return pp.b->fingerprint(out); }))
        {
          return false;
        }
        break;
      default:
        return false;
    }
  }
  return true;
}

V2 Prepared::world2(double x, double y) const
{
  return xy(shape->place.apply({ x, y, 0 }));
}

void Prepared::addPieces(const ShapePart& part)
{
  const Affine& m = shape->place;
  auto arc = [&](double r, double t0, double t1)
  {
    const V2 c = world2(0, 0);
    const V2 u = xy(m.applyLinear({ r, 0, 0 }));
    const V2 v = xy(m.applyLinear({ 0, r, 0 }));
    pieces.push_back(makeEllipse(c, u, v, t0, t1));
  };
  auto arcAngles = [&](double& t0, double& t1)
  {
    t0 = std::atan2(part.points[0][1], part.points[0][0]);
    t1 = std::atan2(part.points[1][1], part.points[1][0]);
    while (t1 <= t0)
    {
      t1 += 2 * Pi;
    }
  };
  switch (part.kind)
  {
    case ShapePart::Kind::Point:
      for (const auto& p : part.points)
      {
        Piece pt;
        pt.p = xy(m.apply(p));
        pieces.push_back(pt);
      }
      break;
    case ShapePart::Kind::Segment:
    case ShapePart::Kind::Polyline:
      for (std::size_t i = 0; i + 1 < part.points.size(); ++i)
      {
        pieces.push_back(makeSegment(xy(m.apply(part.points[i])), xy(m.apply(part.points[i + 1]))));
      }
      break;
    case ShapePart::Kind::Arc:
    {
      double t0, t1;
      arcAngles(t0, t1);
      arc(part.radius, t0, t1);
      break;
    }
    case ShapePart::Kind::CircularSegment:
    {
      double t0, t1;
      arcAngles(t0, t1);
      arc(part.radius, t0, t1);
      const Piece& e = pieces.back();
      if (t1 - t0 < 2 * Pi)
      {
        pieces.push_back(makeSegment(e.at(t1), e.at(t0)));
      }
      break;
    }
    case ShapePart::Kind::Rectangle:
    {
      const double w = 0.5 * part.size[0], h = 0.5 * part.size[1];
      const V2 c[4] = { world2(-w, -h), world2(w, -h), world2(w, h), world2(-w, h) };
      for (int i = 0; i < 4; ++i)
      {
        pieces.push_back(makeSegment(c[i], c[(i + 1) % 4]));
      }
      break;
    }
    case ShapePart::Kind::Disk:
      arc(part.radius, 0, 2 * Pi);
      break;
    default:
      break;
  }
}

double Prepared::partValue(const PreparedPart& pp, Vec3 w) const
{
  const ShapePart& p = *pp.part;
  if (p.kind == ShapePart::Kind::Blend || p.kind == ShapePart::Kind::Union)
  {
    const double fa = pp.a->value(w), fb = pp.b->value(w);
    return p.kind == ShapePart::Kind::Union ? std::max(fa, fb) : blendUnion(fa, fb, p);
  }
  if (p.kind == ShapePart::Kind::SpaceTimeBlend)
  {
    Vec3 unused;
    return spaceTimeSlice(pp, pp.a->value(warped(p.warp, p.warp.shiftA, w)),
      pp.b->value(warped(p.warp, p.warp.shiftB, w)), unused);
  }
  Vec3 l = pp.toLocal.apply(w);
  if (pp.dim <= 2)
  {
    l[2] = 0;
  }
  switch (p.kind)
  {
    case ShapePart::Kind::Rectangle:
      return std::min(0.5 * p.size[0] - std::abs(l[0]), 0.5 * p.size[1] - std::abs(l[1]));
    case ShapePart::Kind::Disk:
      return p.radius - std::hypot(l[0], l[1]);
    case ShapePart::Kind::CircularSegment:
      return std::min(p.radius - std::hypot(l[0], l[1]), pp.hx * l[0] + pp.hy * l[1] - pp.hd);
    case ShapePart::Kind::Box:
      return std::min({ 0.5 * p.size[0] - std::abs(l[0]), 0.5 * p.size[1] - std::abs(l[1]),
        0.5 * p.size[2] - std::abs(l[2]) });
    case ShapePart::Kind::Sphere:
      return p.radius - frep::norm(l);
    case ShapePart::Kind::Field:
    {
      // One point at a time: the gradient evaluator is cheaper than a batch of one.
      frep::Point3 unused;
      double f = pp.eval->gradient(l, unused);
      if (std::isnan(f))
      {
        f = -Inf;
      }
      const int axes = pp.dim == 2 ? 2 : 3;
      for (int i = 0; i < axes; ++i)
      {
        f = std::min({ f, l[i] - pp.domain.lo[i], pp.domain.hi[i] - l[i] });
      }
      return f;
    }
    default:
      return -Inf;
  }
}

double Prepared::value(Vec3 w) const
{
  if (flat)
  {
    w[2] = 0;
  }
  double v = -Inf;
  for (const auto& pp : parts)
  {
    if (pp.dim >= 2)
    {
      v = std::max(v, partValue(pp, w));
    }
  }
  return v;
}

void Prepared::values(
  const double* x, const double* y, const double* z, double* out, std::size_t n) const
{
  std::fill(out, out + n, -Inf);
  std::vector<double> zeros;
  if (flat)
  {
    zeros.assign(n, 0.0);
    z = zeros.data();
  }
  std::vector<double> part(n);
  for (const auto& pp : parts)
  {
    if (pp.dim >= 2)
    {
      partValues(pp, x, y, z, part.data(), n);
      for (std::size_t i = 0; i < n; ++i)
      {
        out[i] = std::max(out[i], part[i]);
      }
    }
  }
}

void Prepared::partValues(const PreparedPart& pp, const double* x, const double* y, const double* z,
  double* out, std::size_t n) const
{
  const ShapePart& p = *pp.part;
  if (p.kind == ShapePart::Kind::Blend || p.kind == ShapePart::Kind::Union)
  {
    std::vector<double> fb(n);
    pp.a->values(x, y, z, out, n);
    pp.b->values(x, y, z, fb.data(), n);
    for (std::size_t i = 0; i < n; ++i)
    {
      out[i] =
        p.kind == ShapePart::Kind::Union ? std::max(out[i], fb[i]) : blendUnion(out[i], fb[i], p);
    }
    return;
  }
  if (p.kind != ShapePart::Kind::Field)
  {
    for (std::size_t i = 0; i < n; ++i)
    {
      out[i] = partValue(pp, { x[i], y[i], z[i] });
    }
    return;
  }
  // The local points, then the field at all of them in one call.
  std::vector<double> local(3 * n);
  double* lx = local.data();
  double* ly = lx + n;
  double* lz = ly + n;
  for (std::size_t i = 0; i < n; ++i)
  {
    const Vec3 l = pp.toLocal.apply({ x[i], y[i], z[i] });
    lx[i] = l[0];
    ly[i] = l[1];
    lz[i] = pp.dim <= 2 ? 0.0 : l[2];
  }
  pp.eval->values(lx, ly, lz, out, n);
  const int axes = pp.dim == 2 ? 2 : 3;
  for (std::size_t i = 0; i < n; ++i)
  {
    double f = std::isnan(out[i]) ? -Inf : out[i];
    const double l[3] = { lx[i], ly[i], lz[i] };
    for (int a = 0; a < axes; ++a)
    {
      f = std::min({ f, l[a] - pp.domain.lo[a], pp.domain.hi[a] - l[a] });
    }
    out[i] = f;
  }
}

Interval Prepared::partBound(const PreparedPart& pp, const Box3& w) const
{
  const ShapePart& p = *pp.part;
  if (p.kind == ShapePart::Kind::Blend || p.kind == ShapePart::Kind::Union)
  {
    const Interval fa = pp.a->bound(w), fb = pp.b->bound(w);
    return p.kind == ShapePart::Kind::Union ? ivMax(fa, fb) : blendUnion(fa, fb, p);
  }
  if (p.kind == ShapePart::Kind::SpaceTimeBlend)
  {
    const Interval fa = pp.a->bound(warpedBox(p.warp.shiftA, w)),
                   fb = pp.b->bound(warpedBox(p.warp.shiftB, w));
    const Interval g = pp.eval->bound({ { operandValue(fa.lo), operandValue(fb.lo), 0 },
      { operandValue(fa.hi), operandValue(fb.hi), 0 } });
    return g.empty() || g.maybeNaN ? iv(-Inf, Inf) : g;
  }
  Box3 l = mapBox(pp.toLocal, w);
  if (pp.dim <= 2)
  {
    l.lo[2] = l.hi[2] = 0;
  }
  const Interval x = iv(l.lo[0], l.hi[0]), y = iv(l.lo[1], l.hi[1]), z = iv(l.lo[2], l.hi[2]);
  auto half = [&](double s, Interval c)
  {
    return ivAdd(iv(0.5 * s, 0.5 * s), ivNeg(ivAbs(c)));
  };
  auto radial = [&](int axes)
  {
    // The nearest and farthest points of the box from the origin.
    double near = 0, far = 0;
    for (int i = 0; i < axes; ++i)
    {
      const double c = std::clamp(0.0, l.lo[i], l.hi[i]);
      const double f = std::max(std::abs(l.lo[i]), std::abs(l.hi[i]));
      near += c * c;
      far += f * f;
    }
    return iv(p.radius - std::sqrt(far), p.radius - std::sqrt(near));
  };
  switch (p.kind)
  {
    case ShapePart::Kind::Rectangle:
      return ivMin(half(p.size[0], x), half(p.size[1], y));
    case ShapePart::Kind::Disk:
      return radial(2);
    case ShapePart::Kind::CircularSegment:
    {
      Interval h = ivAdd(ivScale(pp.hx, x), ivScale(pp.hy, y));
      h = ivAdd(h, iv(-pp.hd, -pp.hd));
      return ivMin(radial(2), h);
    }
    case ShapePart::Kind::Box:
      return ivMin(ivMin(half(p.size[0], x), half(p.size[1], y)), half(p.size[2], z));
    case ShapePart::Kind::Sphere:
      return radial(3);
    case ShapePart::Kind::Field:
    {
      Interval f = pp.eval->bound(l);
      if (f.empty() || f.maybeNaN)
      {
        // NaN counts as outside in value(); an enclosure must allow it.
        f = iv(-Inf, f.empty() ? -Inf : f.hi);
      }
      const int axes = pp.dim == 2 ? 2 : 3;
      for (int i = 0; i < axes; ++i)
      {
        const Interval c = iv(l.lo[i], l.hi[i]);
        f = ivMin(f, ivAdd(c, iv(-pp.domain.lo[i], -pp.domain.lo[i])));
        f = ivMin(f, ivAdd(iv(pp.domain.hi[i], pp.domain.hi[i]), ivNeg(c)));
      }
      return f;
    }
    default:
      return iv(-Inf, -Inf);
  }
}

Interval Prepared::bound(Box3 w) const
{
  if (flat)
  {
    w.lo[2] = w.hi[2] = 0;
  }
  Interval r = iv(-Inf, -Inf);
  for (const auto& pp : parts)
  {
    if (pp.dim >= 2)
    {
      r = ivMax(r, partBound(pp, w));
    }
  }
  return r;
}

double Prepared::partGradient(const PreparedPart& pp, Vec3 w, Vec3& g) const
{
  const ShapePart& p = *pp.part;
  if (p.kind == ShapePart::Kind::Blend || p.kind == ShapePart::Kind::Union)
  {
    Vec3 ga, gb;
    const double fa = pp.a->gradient(w, ga), fb = pp.b->gradient(w, gb);
    if (p.kind == ShapePart::Kind::Union)
    {
      g = fa >= fb ? ga : gb;
      return std::max(fa, fb);
    }
    // d/df1 of the blending union: 1 + f1 / h - 2 a0 f1 / (a1^2 q^2), and likewise for f2.
    const double f1 = operandValue(fa), f2 = operandValue(fb);
    const double h = std::hypot(f1, f2);
    const double q = 1 + (f1 / p.a1) * (f1 / p.a1) + (f2 / p.a2) * (f2 / p.a2);
    const double da = 1 + (h > 0 ? f1 / h : 0) - 2 * p.amount * f1 / (p.a1 * p.a1 * q * q);
    const double db = 1 + (h > 0 ? f2 / h : 0) - 2 * p.amount * f2 / (p.a2 * p.a2 * q * q);
    for (int i = 0; i < 3; ++i)
    {
      g[i] = da * ga[i] + db * gb[i];
    }
    return blendUnion(fa, fb, p);
  }
  if (p.kind == ShapePart::Kind::SpaceTimeBlend)
  {
    Vec3 ga, gb, dg;
    const double fa = warpedGradient(*pp.a, p.warp, p.warp.shiftA, w, ga);
    const double fb = warpedGradient(*pp.b, p.warp, p.warp.shiftB, w, gb);
    const double v = spaceTimeSlice(pp, fa, fb, dg);
    for (int i = 0; i < 3; ++i)
    {
      g[i] = dg[0] * ga[i] + dg[1] * gb[i];
    }
    return v;
  }
  Vec3 l = pp.toLocal.apply(w);
  if (pp.dim <= 2)
  {
    l[2] = 0;
  }
  Vec3 gl{ 0, 0, 0 };
  double v = -Inf;
  auto faces = [&](int axes, const Vec3& half)
  {
    for (int i = 0; i < axes; ++i)
    {
      const double f = half[i] - std::abs(l[i]);
      if (f < v || i == 0)
      {
        v = f;
        gl = { 0, 0, 0 };
        gl[i] = l[i] >= 0 ? -1 : 1;
      }
    }
  };
  auto radial = [&](int axes)
  {
    const double n = axes == 2 ? std::hypot(l[0], l[1]) : frep::norm(l);
    v = p.radius - n;
    gl = { 0, 0, 0 };
    for (int i = 0; i < axes && n > 0; ++i)
    {
      gl[i] = -l[i] / n;
    }
  };
  switch (p.kind)
  {
    case ShapePart::Kind::Rectangle:
      faces(2, { 0.5 * p.size[0], 0.5 * p.size[1], 0 });
      break;
    case ShapePart::Kind::Box:
      faces(3, { 0.5 * p.size[0], 0.5 * p.size[1], 0.5 * p.size[2] });
      break;
    case ShapePart::Kind::Disk:
      radial(2);
      break;
    case ShapePart::Kind::Sphere:
      radial(3);
      break;
    case ShapePart::Kind::CircularSegment:
    {
      radial(2);
      const double c = pp.hx * l[0] + pp.hy * l[1] - pp.hd;
      if (c < v)
      {
        v = c;
        gl = { pp.hx, pp.hy, 0 };
      }
      break;
    }
    case ShapePart::Kind::Field:
    {
      frep::Point3 fg{ 0, 0, 0 };
      v = pp.eval->gradient(l, fg);
      gl = fg;
      if (!std::isfinite(v) || !finite3(gl))
      {
        v = std::isnan(v) ? -Inf : v;
        gl = { 0, 0, 0 };
      }
      const int axes = pp.dim == 2 ? 2 : 3;
      if (axes == 2)
      {
        gl[2] = 0;
      }
      for (int i = 0; i < axes; ++i)
      {
        if (l[i] - pp.domain.lo[i] < v)
        {
          v = l[i] - pp.domain.lo[i];
          gl = { 0, 0, 0 };
          gl[i] = 1;
        }
        if (pp.domain.hi[i] - l[i] < v)
        {
          v = pp.domain.hi[i] - l[i];
          gl = { 0, 0, 0 };
          gl[i] = -1;
        }
      }
      break;
    }
    default:
      break;
  }
  const auto& ai = pp.toLocal.a;
  for (int j = 0; j < 3; ++j)
  {
    g[j] = gl[0] * ai[j] + gl[1] * ai[3 + j] + gl[2] * ai[6 + j];
  }
  return v;
}

double Prepared::gradient(Vec3 w, Vec3& g) const
{
  if (flat)
  {
    w[2] = 0;
  }
  double v = -Inf;
  g = { 0, 0, 0 };
  for (const auto& pp : parts)
  {
    if (pp.dim >= 2)
    {
      Vec3 gp;
      const double f = partGradient(pp, w, gp);
      if (f > v)
      {
        v = f;
        g = gp;
      }
    }
  }
  if (flat)
  {
    g[2] = 0;
  }
  return v;
}

double Prepared::boundaryDistance(const Vec3& w) const
{
  Vec3 g;
  const double v = gradient(w, g);
  const double n = frep::norm(g);
  return n > 0 ? std::abs(v) / n : (v == 0 ? 0 : Inf);
}

const std::vector<Vec3>& Prepared::insideSamples() const
{
  if (!sampled_)
  {
    sampled_ = true;
    const int n = flat ? 32 : 16;
    const Box3 b = bounds;
    for (int k = 0; k < (flat ? 1 : n); ++k)
    {
      for (int j = 0; j < n; ++j)
      {
        for (int i = 0; i < n; ++i)
        {
          const Vec3 p{ b.lo[0] + (i + 0.5) / n * (b.hi[0] - b.lo[0]),
            b.lo[1] + (j + 0.5) / n * (b.hi[1] - b.lo[1]),
            flat ? 0.0 : b.lo[2] + (k + 0.5) / n * (b.hi[2] - b.lo[2]) };
          if (value(p) >= 0)
          {
            inside_.push_back(p);
          }
        }
      }
    }
  }
  return inside_;
}

double defaultTolerance(const Prepared& a, const Prepared& b, const QueryOptions& o)
{
  if (o.tolerance > 0)
  {
    return o.tolerance;
  }
  return 1e-9 * std::max(boxDiagonal(joinBoxes(a.bounds, b.bounds)), 1e-300);
}

void checkOptions(const PlacedShape& a, const PlacedShape& b, const QueryOptions& o)
{
  if (!std::isfinite(o.tolerance) || o.tolerance < 0 || o.arcSegments < 3)
  {
    failPair(a, b, "the query tolerance must be finite and >= 0, arcSegments >= 3");
  }
  validate(a);
  validate(b);
}

bool searchBoxes(const Box3& box, bool flat, double minSize,
  const std::function<double(const Box3&)>& promise,
  const std::function<bool(const Vec3&)>& witness, int budget, std::vector<Box3>* leaves)
{
  struct Item
  {
    double promise;
    Box3 box;
    bool operator<(const Item& o) const { return promise < o.promise; }
  };
  std::priority_queue<Item> queue;
  auto push = [&](const Box3& b)
  {
    const double p = promise(b);
    if (!(p < 0))
    {
      queue.push({ p, b });
    }
  };
  push(box);
  int visited = 0;
  while (!queue.empty() && visited < budget)
  {
    const Box3 b = queue.top().box;
    queue.pop();
    ++visited;
    if (witness(b.centre()))
    {
      return true;
    }
    int axis = 0;
    for (int i = 1; i < (flat ? 2 : 3); ++i)
    {
      if (b.hi[i] - b.lo[i] > b.hi[axis] - b.lo[axis])
      {
        axis = i;
      }
    }
    if (b.hi[axis] - b.lo[axis] <= minSize)
    {
      if (leaves && leaves->size() < 4096)
      {
        leaves->push_back(b);
      }
      continue;
    }
    const double mid = 0.5 * (b.lo[axis] + b.hi[axis]);
    Box3 lo = b, hi = b;
    lo.hi[axis] = mid;
    hi.lo[axis] = mid;
    push(lo);
    push(hi);
  }
  return false;
}

Box3 flatten(Box3 b, bool flat)
{
  if (flat)
  {
    b.lo[2] = b.hi[2] = 0;
  }
  return b;
}

Box3 padded(Box3 b, double pad)
{
  for (int i = 0; i < 3; ++i)
  {
    b.lo[i] -= pad;
    b.hi[i] += pad;
  }
  return b;
}

} // namespace ictk::geometry::detail
