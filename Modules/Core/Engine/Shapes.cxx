// SPDX-License-Identifier: BSD-3-Clause
// How the queries work, and how exact they are:
//
// - A shape is prepared per query (Prepared): the inverse placement, one field evaluator per
//   Field part, and the world "pieces" of its analytic parts: points, segments and arcs of
//   ellipses (the image of a circle under the placement; a circle when the placement is a
//   similarity in the plane). 0D/1D shapes are their pieces; rectangles, disks and circular
//   segments are bounded by theirs.
// - Meeting points in the plane: a piece is walked against the other's carrier (the line or
//   circle a piece lies on, or a 2D field); sign changes are refined by the Illinois method,
//   and an extremum of the carrier along the walk that comes within the tolerance of 0
//   (|g| / |grad g| <= tolerance, a first-order distance) is a tangency: one point, however the
//   two crossings around it fall. Consecutive samples within the tolerance are one point, and
//   points closer than the tolerance (a polygon's corner found from both edges) merge; for
//   two fields, whose boundary is traced by marching squares (128 cells over the common box)
//   and walked projected onto the first field's curve, the merge distance is 1e-6 of the size.
// - Distances: exact for pieces (segments, points; circles up to rounding of a golden-section
//   search on the exact point-circle distance), spheres placed by similarities; otherwise
//   alternating projections, exact for convex shapes (a local minimum otherwise). Projections
//   onto fields are Newton steps onto {f = 0} alternating with moves to the foot on the
//   tangent plane, from the nearest inside grid sample when the gradient does not lead there.
//   Near a tangency alternating projections crawl (each round trip gains ~gap / radius), so
//   after a few rounds they climb B's field along A to the least gap and go on from there:
//   within 1e-12 in the tests (sizes ~1). Between solids with fields, a branch and bound also looks
//   for a point inside both (distance 0) and refines from the boxes where the two nearly
//   touch.
// - Touching: intersects() is that same distance <= tolerance, and a tangency point of
//   intersectionPoints() is a first-order distance <= tolerance, which agree up to rounding and
//   second-order terms (~gap^2 / radius): a pair intersects exactly when it has meeting points
//   or one holds the other, as long as the distance finds the nearest pair, except for gaps
//   within ~1e-16 x the size of the tolerance itself, where rounding decides each on its own.
// - contains between solids with fields: "no point with fB >= 0 and fA < -tolerance", proved
//   by branch and bound on the interval enclosures (tape fields' own interval evaluators,
//   interval arithmetic through the placement and the analytic parts) or refuted by a witness
//   point. Where B's boundary runs along A's from inside, enclosures cannot decide, so the
//   boxes stop at 1e-2 (2D) / 1e-1 (3D) of B's box and the lowest fA over B is found by a
//   projected descent from the best leaves: the answer flips where min fA over B = -tolerance
//   (A's field values, not a distance), to ~1e-13 (measured on the egg in the liquid), when
//   A's lowest point on B is in the basin of one of those descents; a local search, so likely
//   rather than proved when fA has several minima on B.
//   Tens of microseconds for small HyperFun fields (TestEngineShapes prints the figures).
// - Areas: exact for convex analytic regions (polygon clipping, disk against a polygon by
//   triangle fans, lenses of disks), volumes of spheres, lenses, axis-aligned boxes; otherwise
//   interval-pruned subdivision with a plane estimate per boundary cell and Richardson
//   extrapolation (relative error ~1e-6 in 2D, ~1e-4 in 3D).
#include "Engine/Shapes.h"

#include "Dynamics/RootFinding.h"
#include "FRep/Expr.h"
#include "FRep/Tape.h"
#include "FRep/Vector.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <stdexcept>
#include <utility>

namespace ictk::engine
{
namespace
{

constexpr double Pi = 3.14159265358979323846;
constexpr double Inf = std::numeric_limits<double>::infinity();

using frep::Box3;
using frep::Interval;

// ---------------------------------------------------------------------------------------------
// Small vector helpers. 2D queries work on (x, y) of the world: 2D models lie in z = 0.

struct V2
{
  double x = 0, y = 0;
};
V2 operator+(V2 a, V2 b)
{
  return { a.x + b.x, a.y + b.y };
}
V2 operator-(V2 a, V2 b)
{
  return { a.x - b.x, a.y - b.y };
}
V2 operator*(double s, V2 a)
{
  return { s * a.x, s * a.y };
}
double dot(V2 a, V2 b)
{
  return a.x * b.x + a.y * b.y;
}
double cross(V2 a, V2 b)
{
  return a.x * b.y - a.y * b.x;
}
double norm(V2 a)
{
  return std::hypot(a.x, a.y);
}
V2 xy(const Vec3& p)
{
  return { p[0], p[1] };
}
Vec3 lift(V2 p)
{
  return { p.x, p.y, 0.0 };
}

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

// ---------------------------------------------------------------------------------------------
// Interval arithmetic for the analytic parts. Rounding is not directed here; the boxes pruned
// with these bounds are never closer than a tolerance to a decision, so the last bits do not
// matter (the tape fields round outward themselves).

Interval iv(double lo, double hi)
{
  return Interval{ lo, hi, false };
}
Interval ivAdd(Interval a, Interval b)
{
  return iv(a.lo + b.lo, a.hi + b.hi);
}
Interval ivNeg(Interval a)
{
  return iv(-a.hi, -a.lo);
}
Interval ivMin(Interval a, Interval b)
{
  return iv(std::min(a.lo, b.lo), std::min(a.hi, b.hi));
}
Interval ivMax(Interval a, Interval b)
{
  return iv(std::max(a.lo, b.lo), std::max(a.hi, b.hi));
}
Interval ivAbs(Interval a)
{
  if (a.lo >= 0)
  {
    return a;
  }
  if (a.hi <= 0)
  {
    return ivNeg(a);
  }
  return iv(0, std::max(-a.lo, a.hi));
}
Interval ivSquare(Interval a)
{
  const Interval m = ivAbs(a);
  return iv(m.lo * m.lo, m.hi * m.hi);
}
Interval ivScale(double s, Interval a)
{
  return s >= 0 ? iv(s * a.lo, s * a.hi) : iv(s * a.hi, s * a.lo);
}

// Pasko's blending union, f1 + f2 + sqrt(f1^2 + f2^2) + a0 / (1 + f1^2 + f2^2) (a1 = a2 = 1):
// an R-function union (its sign is the sign of max(f1, f2)) plus a bump of height a0 where both
// fields are near 0, which fills the crease between the operands.
double blendUnion(double f1, double f2, double a0)
{
  if (a0 <= 0)
  {
    return std::max(f1, f2);
  }
  return f1 + f2 + std::hypot(f1, f2) + a0 / (1 + f1 * f1 + f2 * f2);
}
// The R-function part is nondecreasing in each argument; the bump is bounded by the ranges of
// f1^2 + f2^2.
Interval blendUnion(Interval f1, Interval f2, double a0)
{
  if (a0 <= 0)
  {
    return ivMax(f1, f2);
  }
  if (!std::isfinite(f1.lo) || !std::isfinite(f1.hi) || !std::isfinite(f2.lo) ||
    !std::isfinite(f2.hi))
  {
    return iv(std::isfinite(f1.lo) && std::isfinite(f2.lo) ? std::max(f1.lo, f2.lo) : -Inf, Inf);
  }
  const Interval s1 = ivSquare(f1), s2 = ivSquare(f2);
  const double lo = f1.lo + f2.lo + std::hypot(f1.lo, f2.lo) + a0 / (1 + s1.hi + s2.hi);
  const double hi = f1.hi + f2.hi + std::hypot(f1.hi, f2.hi) + a0 / (1 + s1.lo + s2.lo);
  return iv(lo, hi);
}

// ---------------------------------------------------------------------------------------------
// Pieces: the analytic curves of a shape in the world plane, i.e. the curve of a 0D/1D part or
// the boundary of a 2D analytic part.

struct Piece
{
  enum class Type
  {
    Point,
    Segment,
    Ellipse ///< c + u cos t + v sin t, t in [t0, t1]; a circle when u, v are orthogonal and equal
  };
  Type type = Type::Point;
  V2 p, q;    // Point: p; Segment: p -> q
  V2 c, u, v; // Ellipse
  double t0 = 0, t1 = 0;
  bool circle = false;
  double r = 0;                   // circle radius
  double inv[4] = { 1, 0, 0, 1 }; // [u v]^-1, row-major
  V2 at(double t) const
  {
    if (type == Type::Segment)
    {
      return p + t * (q - p);
    }
    if (type == Type::Ellipse)
    {
      return c + std::cos(t) * u + std::sin(t) * v;
    }
    return p;
  }
  double lo() const { return type == Type::Ellipse ? t0 : 0.0; }
  double hi() const { return type == Type::Ellipse ? t1 : 1.0; }
  V2 unit(V2 x) const
  {
    const V2 d = x - c;
    return { inv[0] * d.x + inv[1] * d.y, inv[2] * d.x + inv[3] * d.y };
  }
  double paramOf(V2 x) const
  {
    const V2 w = unit(x);
    double t = std::atan2(w.y, w.x);
    while (t < t0)
    {
      t += 2 * Pi;
    }
    return t;
  }
};

Piece makeSegment(V2 p, V2 q)
{
  Piece s;
  s.type = Piece::Type::Segment;
  s.p = p;
  s.q = q;
  return s;
}

Piece makeEllipse(V2 c, V2 u, V2 v, double t0, double t1)
{
  Piece e;
  e.type = Piece::Type::Ellipse;
  e.c = c;
  e.u = u;
  e.v = v;
  e.t0 = t0;
  e.t1 = t1;
  const double det = u.x * v.y - v.x * u.y;
  e.inv[0] = v.y / det;
  e.inv[1] = -v.x / det;
  e.inv[2] = -u.y / det;
  e.inv[3] = u.x / det;
  const double nu = norm(u), nv = norm(v);
  e.circle =
    std::abs(nu - nv) <= 1e-12 * std::max(nu, nv) && std::abs(dot(u, v)) <= 1e-12 * nu * nv;
  e.r = 0.5 * (nu + nv);
  return e;
}

/// The carrier of a piece (its line, circle or ellipse; the point itself), as a function that
/// vanishes on it, with gradient, so that |g| / |grad g| is a first-order distance.
double carrier(const Piece& s, V2 x, V2& grad)
{
  switch (s.type)
  {
    case Piece::Type::Point:
    {
      const V2 d = x - s.p;
      const double n = norm(d);
      grad = n > 0 ? (1 / n) * d : V2{ 1, 0 };
      return n;
    }
    case Piece::Type::Segment:
    {
      const V2 e = s.q - s.p;
      const double len = norm(e);
      if (len == 0)
      {
        const V2 d = x - s.p;
        const double n = norm(d);
        grad = n > 0 ? (1 / n) * d : V2{ 1, 0 };
        return n;
      }
      grad = { -e.y / len, e.x / len };
      return dot(grad, x - s.p);
    }
    case Piece::Type::Ellipse:
    {
      if (s.circle)
      {
        const V2 d = x - s.c;
        const double n = norm(d);
        grad = n > 0 ? (-1 / n) * d : V2{ 1, 0 };
        return s.r - n;
      }
      const V2 w = s.unit(x);
      const double n = norm(w);
      const V2 wn = n > 0 ? (1 / n) * w : V2{ 1, 0 };
      grad = { -(s.inv[0] * wn.x + s.inv[2] * wn.y), -(s.inv[1] * wn.x + s.inv[3] * wn.y) };
      return 1 - n;
    }
  }
  return 0;
}

/// Whether a point of the carrier lies on the piece itself (its extent), up to `tol`.
bool onExtent(const Piece& s, V2 x, double tol)
{
  if (s.type == Piece::Type::Segment)
  {
    const V2 e = s.q - s.p;
    const double len2 = dot(e, e);
    if (len2 == 0)
    {
      return norm(x - s.p) <= tol;
    }
    const double t = dot(x - s.p, e) / len2;
    const double slack = tol / std::sqrt(len2);
    return t >= -slack && t <= 1 + slack;
  }
  if (s.type == Piece::Type::Ellipse)
  {
    if (s.t1 - s.t0 >= 2 * Pi)
    {
      return true;
    }
    const double t = s.paramOf(x);
    const double slack = tol / std::max(1e-300, std::min(norm(s.u), norm(s.v)));
    return t <= s.t1 + slack || t >= s.t0 + 2 * Pi - slack;
  }
  return true;
}

double goldenMinimum(
  const std::function<double(double)>& f, double a, double b, double& tBest, double eps = 1e-15)
{
  const double g = 0.5 * (std::sqrt(5.0) - 1);
  double c = b - g * (b - a), d = a + g * (b - a);
  double fc = f(c), fd = f(d);
  for (int i = 0; i < 80 && b - a > eps * (1 + std::abs(a) + std::abs(b)); ++i)
  {
    if (fc <= fd)
    {
      b = d;
      d = c;
      fd = fc;
      c = b - g * (b - a);
      fc = f(c);
    }
    else
    {
      a = c;
      c = d;
      fc = fd;
      d = a + g * (b - a);
      fd = f(d);
    }
  }
  tBest = fc <= fd ? c : d;
  return std::min(fc, fd);
}

V2 closestOnPiece(const Piece& s, V2 x)
{
  switch (s.type)
  {
    case Piece::Type::Point:
      return s.p;
    case Piece::Type::Segment:
    {
      const V2 e = s.q - s.p;
      const double len2 = dot(e, e);
      const double t = len2 > 0 ? std::clamp(dot(x - s.p, e) / len2, 0.0, 1.0) : 0.0;
      return s.p + t * e;
    }
    case Piece::Type::Ellipse:
    {
      if (s.circle)
      {
        const double t = s.paramOf(x);
        if (t <= s.t1)
        {
          return s.at(t);
        }
        const V2 a = s.at(s.t0), b = s.at(s.t1);
        return norm(x - a) <= norm(x - b) ? a : b;
      }
      // An ellipse: the squared distance along the parameter has at most four extrema per turn.
      const int n = 64;
      double best = Inf, tBest = s.t0;
      const double h = (s.t1 - s.t0) / n;
      for (int i = 0; i <= n; ++i)
      {
        const double t = s.t0 + i * h;
        const V2 d = s.at(t) - x;
        if (dot(d, d) < best)
        {
          best = dot(d, d);
          tBest = t;
        }
      }
      double t = tBest;
      goldenMinimum(
        [&](double tt)
        {
          const V2 d = s.at(tt) - x;
          return dot(d, d);
        },
        std::max(s.t0, tBest - h), std::min(s.t1, tBest + h), t);
      return s.at(t);
    }
  }
  return s.p;
}

bool segmentsCross(const Piece& a, const Piece& b)
{
  const double d1 = cross(a.q - a.p, b.p - a.p), d2 = cross(a.q - a.p, b.q - a.p);
  const double d3 = cross(b.q - b.p, a.p - b.p), d4 = cross(b.q - b.p, a.q - b.p);
  return ((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0));
}

/// The distance between two pieces: exact for point and segment pairs; otherwise the minimum
/// over the parameter of one piece of the exact distance to the other, sampled and refined by
/// golden section (exact up to rounding for circles and lines).
double pieceDistance(const Piece& a, const Piece& b)
{
  if (a.type == Piece::Type::Point)
  {
    return norm(a.p - closestOnPiece(b, a.p));
  }
  if (b.type == Piece::Type::Point)
  {
    return norm(b.p - closestOnPiece(a, b.p));
  }
  if (a.type == Piece::Type::Segment && b.type == Piece::Type::Segment)
  {
    if (segmentsCross(a, b))
    {
      return 0;
    }
    return std::min({ norm(a.p - closestOnPiece(b, a.p)), norm(a.q - closestOnPiece(b, a.q)),
      norm(b.p - closestOnPiece(a, b.p)), norm(b.q - closestOnPiece(a, b.q)) });
  }
  // Walk the segment if there is one (the distance to a circle along a line has one minimum
  // on each side of the centre's foot), otherwise a circle rather than an ellipse.
  const Piece* walk = &a;
  const Piece* other = &b;
  if (b.type == Piece::Type::Segment || (!a.circle && b.type == Piece::Type::Ellipse && b.circle))
  {
    std::swap(walk, other);
  }
  const int n = walk->type == Piece::Type::Segment
    ? 16
    : std::max(8, static_cast<int>(std::ceil(32 * (walk->t1 - walk->t0) / (2 * Pi))));
  auto d = [&](double t)
  {
    const V2 x = walk->at(t);
    return norm(x - closestOnPiece(*other, x));
  };
  const double lo = walk->lo(), hi = walk->hi(), h = (hi - lo) / n;
  std::vector<double> v(n + 1);
  for (int i = 0; i <= n; ++i)
  {
    v[i] = d(lo + i * h);
  }
  double best = *std::min_element(v.begin(), v.end());
  for (int i = 0; i <= n; ++i)
  {
    const bool left = i == 0 || v[i] <= v[i - 1];
    const bool right = i == n || v[i] <= v[i + 1];
    if (left && right)
    {
      double t = 0;
      best = std::min(
        best, goldenMinimum(d, lo + std::max(0, i - 1) * h, lo + std::min(n, i + 1) * h, t));
    }
  }
  return best;
}

// ---------------------------------------------------------------------------------------------
// A shape prepared for one query: inverse placements, field evaluators, world pieces.

int partDimension(const ShapePart& p);

int shapeDimension(const Shape& s)
{
  int d = 0;
  for (const auto& p : s.parts)
  {
    d = std::max(d, partDimension(p));
  }
  return d;
}

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
      return 2;
    case ShapePart::Kind::Box:
    case ShapePart::Kind::Sphere:
      return 3;
    case ShapePart::Kind::Field:
      return p.fieldDimension == 2 ? 2 : 3;
    case ShapePart::Kind::Blend:
    case ShapePart::Kind::Union:
      return std::max(
        p.operandA ? shapeDimension(*p.operandA) : 0, p.operandB ? shapeDimension(*p.operandB) : 0);
  }
  return 3;
}

[[noreturn]] void fail(const Shape& s, const std::string& what)
{
  throw std::invalid_argument("cell '" + s.cell + "': " + what);
}

[[noreturn]] void failPair(const Shape& a, const Shape& b, const std::string& what)
{
  throw std::invalid_argument("cells '" + a.cell + "' and '" + b.cell + "': " + what);
}

bool finite3(const Vec3& v)
{
  return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
}

/// A Field part's domain; an unset (empty) one is the [-10, 10]^3 that model files without
/// bounds get.
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

/// The image of a box under an affine map, enclosed in a box (interval arithmetic on the map).
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

void validate(const Shape& s, int depth = 0)
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
      case ShapePart::Kind::Blend:
      case ShapePart::Kind::Union:
        if (!p.operandA || !p.operandB)
        {
          fail(s, "a blend or union needs two operands");
        }
        validate(*p.operandA, depth + 1);
        validate(*p.operandB, depth + 1);
        break;
      default:
        break;
    }
  }
}

struct Prepared;

struct PreparedPart
{
  const ShapePart* part = nullptr;
  int dim = 0;
  Affine toLocal;
  std::unique_ptr<frep::FieldEvaluator> eval;
  Box3 domain;
  std::unique_ptr<Prepared> a, b;
  double hx = 0, hy = 0, hd = 0; // CircularSegment: the chord's half-plane hx x + hy y >= hd
};

struct Prepared
{
  const Shape* shape = nullptr;
  int dim = 0;
  bool flat = true;     ///< lies in z = 0 (dimension <= 2)
  bool analytic = true; ///< every part has world pieces (no fields, blends, 3D parts)
  std::vector<PreparedPart> parts;
  std::vector<Piece> pieces;
  Box3 bounds;
  double scale = 1; ///< the bounds' diagonal, for relative steps

  explicit Prepared(const Shape& s)
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
        case ShapePart::Kind::Box:
        case ShapePart::Kind::Sphere:
          analytic = false;
          break;
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

  V2 world2(double x, double y) const { return xy(shape->place.apply({ x, y, 0 })); }

  void addPieces(const ShapePart& part)
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
          pieces.push_back(
            makeSegment(xy(m.apply(part.points[i])), xy(m.apply(part.points[i + 1]))));
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

  double partValue(const PreparedPart& pp, Vec3 w) const
  {
    const ShapePart& p = *pp.part;
    if (p.kind == ShapePart::Kind::Blend || p.kind == ShapePart::Kind::Union)
    {
      const double fa = pp.a->value(w), fb = pp.b->value(w);
      return p.kind == ShapePart::Kind::Union ? std::max(fa, fb) : blendUnion(fa, fb, p.amount);
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

  double value(Vec3 w) const
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

  Interval partBound(const PreparedPart& pp, const Box3& w) const
  {
    const ShapePart& p = *pp.part;
    if (p.kind == ShapePart::Kind::Blend || p.kind == ShapePart::Kind::Union)
    {
      const Interval fa = pp.a->bound(w), fb = pp.b->bound(w);
      return p.kind == ShapePart::Kind::Union ? ivMax(fa, fb) : blendUnion(fa, fb, p.amount);
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

  Interval bound(Box3 w) const
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

  /// A part's value and its world gradient (the chain rule through the placement: the local
  /// gradient times the inverse's linear part).
  double partGradient(const PreparedPart& pp, Vec3 w, Vec3& g) const
  {
    const ShapePart& p = *pp.part;
    if (p.kind == ShapePart::Kind::Blend || p.kind == ShapePart::Kind::Union)
    {
      Vec3 ga, gb;
      const double fa = pp.a->gradient(w, ga), fb = pp.b->gradient(w, gb);
      if (p.kind == ShapePart::Kind::Union || p.amount <= 0)
      {
        g = fa >= fb ? ga : gb;
        return std::max(fa, fb);
      }
      const double h = std::hypot(fa, fb), q = 1 + fa * fa + fb * fb;
      const double da = 1 + (h > 0 ? fa / h : 0) - 2 * p.amount * fa / (q * q);
      const double db = 1 + (h > 0 ? fb / h : 0) - 2 * p.amount * fb / (q * q);
      for (int i = 0; i < 3; ++i)
      {
        g[i] = da * ga[i] + db * gb[i];
      }
      return blendUnion(fa, fb, p.amount);
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

  /// The value and its world gradient (of the part that gives the max).
  double gradient(Vec3 w, Vec3& g) const
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

  /// |f| / |grad f|: the first-order distance to the boundary.
  double boundaryDistance(const Vec3& w) const
  {
    Vec3 g;
    const double v = gradient(w, g);
    const double n = frep::norm(g);
    return n > 0 ? std::abs(v) / n : (v == 0 ? 0 : Inf);
  }

  bool solid() const { return dim >= 2; }

  /// Centres of a 32 x 32 (16^3) grid over the bounds where the shape is inside, computed on
  /// first use: starting points for projections onto fields.
  const std::vector<Vec3>& insideSamples() const
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

private:
  mutable bool sampled_ = false;
  mutable std::vector<Vec3> inside_;
};

double defaultTolerance(const Prepared& a, const Prepared& b, const QueryOptions& o)
{
  if (o.tolerance > 0)
  {
    return o.tolerance;
  }
  return 1e-9 * std::max(boxDiagonal(joinBoxes(a.bounds, b.bounds)), 1e-300);
}

void checkOptions(const Shape& a, const Shape& b, const QueryOptions& o)
{
  if (!std::isfinite(o.tolerance) || o.tolerance < 0 || o.arcSegments < 3)
  {
    failPair(a, b, "the query tolerance must be finite and >= 0, arcSegments >= 3");
  }
  validate(a);
  validate(b);
}

// ---------------------------------------------------------------------------------------------
// Roots along a piece.

struct Sample
{
  double t = 0, v = 0;
  bool near = false;
  bool extremum = false;
};

/// The points of the curve at(t), t in [lo, hi], where g vanishes: sign changes (refined by the
/// Illinois method) and extrema of g that come within `tol` of 0 (|g| / |grad g| <= tol)
/// without a sign change, which are tangencies. Two crossings around such an extremum are that
/// one tangency. `g(x, grad)` returns the function and its gradient at the world point x.
/// `ends`: also look for extrema next to the first and last samples (off when the walks overlap).
template <class At, class F, class G>
void curveRoots(const At& at, double lo, double hi, int n, const F& f, const G& g, double tol,
  std::vector<V2>& out, bool ends = true)
{
  const double h = (hi - lo) / n;
  auto valueAt = [&](double t)
  {
    return f(at(t));
  };
  auto nearZero = [&](double t, double v)
  {
    V2 grad;
    g(at(t), grad);
    return std::abs(v) <= tol * norm(grad);
  };
  std::vector<Sample> raw(n + 1);
  for (int i = 0; i <= n; ++i)
  {
    raw[i].t = i == n ? hi : lo + i * h;
    raw[i].v = valueAt(raw[i].t);
  }
  // Between samples the function is assumed to have at most one extremum: a discrete extremum
  // at sample k has its continuous one in [t_{k-1}, t_{k+1}] (an end sample: between it and its
  // neighbour), where two crossings may hide or a tangency sits. Only extrema towards 0 can
  // hide crossings: a maximum of negative samples, a minimum of positive ones, or a sample
  // already within the tolerance.
  std::vector<Sample> series(raw);
  for (int k = ends ? 0 : 1; k <= (ends ? n : n - 1); ++k)
  {
    for (double sign : { 1.0, -1.0 })
    {
      const double a = k > 0 ? sign * raw[k - 1].v : -Inf, b = sign * raw[k].v;
      const double c = k < n ? sign * raw[k + 1].v : -Inf;
      if (b >= a && b >= c && (b > a || b > c) && n > 1 && (b <= 0 || nearZero(raw[k].t, raw[k].v)))
      {
        double t = raw[k].t;
        goldenMinimum([&](double tt) { return -sign * valueAt(tt); }, raw[std::max(0, k - 1)].t,
          raw[std::min(n, k + 1)].t, t, 1e-12);
        Sample e;
        e.t = t;
        e.v = valueAt(t);
        e.extremum = true;
        series.push_back(e);
      }
    }
  }
  std::sort(
    series.begin(), series.end(), [](const Sample& a, const Sample& b) { return a.t < b.t; });
  for (auto& sm : series)
  {
    sm.near = nearZero(sm.t, sm.v);
  }
  // Illinois on the sign change (the same refinement the stepper uses), to the last bits of t.
  auto illinois = [&](double a, double fa, double b, double fb)
  {
    dyn::LocateOptions o;
    o.timeTolerance = 4e-16 * std::max(1.0, std::abs(a));
    return dyn::refineRoot(valueAt, a, fa, b, fb, o);
  };
  // Consecutive samples within tolerance of the other curve are one meeting point: near a
  // tangency g stays within tolerance over a stretch of width ~sqrt(tolerance x radius).
  const std::size_t m = series.size();
  auto opposite = [](double a, double b)
  {
    return (a > 0 && b < 0) || (a < 0 && b > 0);
  };
  for (std::size_t i = 0; i < m;)
  {
    const Sample& sm = series[i];
    if (sm.near)
    {
      std::size_t j = i;
      while (j + 1 < m && series[j + 1].near)
      {
        ++j;
      }
      std::size_t best = i;
      bool tangent = false;
      for (std::size_t k = i; k <= j; ++k)
      {
        if (series[k].extremum && (!tangent || std::abs(series[k].v) < std::abs(series[best].v)))
        {
          best = k;
          tangent = true;
        }
        else if (!tangent && std::abs(series[k].v) < std::abs(series[best].v))
        {
          best = k;
        }
      }
      if (!tangent && i > 0 && j + 1 < m && opposite(series[i - 1].v, series[j + 1].v))
      {
        out.push_back(
          at(illinois(series[i - 1].t, series[i - 1].v, series[j + 1].t, series[j + 1].v)));
      }
      else
      {
        out.push_back(at(series[best].t));
      }
      i = j + 1;
      continue;
    }
    if (i + 1 < m && !series[i + 1].near && opposite(sm.v, series[i + 1].v))
    {
      out.push_back(at(illinois(sm.t, sm.v, series[i + 1].t, series[i + 1].v)));
    }
    ++i;
  }
}

template <class F, class G>
void curveRoots(const Piece& s, int n, const F& f, const G& g, double tol, std::vector<V2>& out)
{
  curveRoots([&](double t) { return s.at(t); }, s.lo(), s.hi(), n, f, g, tol, out);
}

/// Samples per piece when walking it against another curve: a line against a line, circle or
/// ellipse has at most one extremum between samples at this density; fields get more.
int walkSamples(const Piece& s, bool againstField, const QueryOptions& o)
{
  if (s.type == Piece::Type::Segment)
  {
    return againstField ? 64 : 8;
  }
  const double turns = (s.t1 - s.t0) / (2 * Pi);
  const int perTurn = againstField ? std::max(64, o.arcSegments / 2) : 32;
  return std::max(4, static_cast<int>(std::ceil(perTurn * turns)));
}

/// Merges points closer than `merge` (keeping the first found) and sorts by x, y, z.
std::vector<Vec3> mergeAndSort(const std::vector<Vec3>& points, double merge)
{
  std::vector<Vec3> out;
  for (const auto& p : points)
  {
    bool seen = false;
    for (const auto& q : out)
    {
      seen = seen || frep::distance(p, q) <= merge;
    }
    if (!seen)
    {
      out.push_back(p);
    }
  }
  // Coordinates equal up to the merge distance compare equal, so that a rounding difference
  // in x does not decide the order of two points one above the other.
  auto key = [&](const Vec3& p)
  {
    const double q = merge > 0 ? merge : 1e-300;
    return std::array<double, 3>{ std::round(p[0] / q), std::round(p[1] / q),
      std::round(p[2] / q) };
  };
  std::sort(out.begin(), out.end(), [&](const Vec3& a, const Vec3& b) { return key(a) < key(b); });
  return out;
}

/// The zero contour of a flat field shape over a box, as segments (marching squares with the
/// saddle cells split by the centre value).
std::vector<Piece> traceContour(const Prepared& s, const Box3& box, int resolution)
{
  std::vector<Piece> out;
  const double wx = box.hi[0] - box.lo[0], wy = box.hi[1] - box.lo[1];
  const double h = std::max(wx, wy) / resolution;
  if (!(h > 0))
  {
    return out;
  }
  const int nx = std::max(1, static_cast<int>(std::ceil(wx / h)));
  const int ny = std::max(1, static_cast<int>(std::ceil(wy / h)));
  std::vector<double> f((nx + 1) * (ny + 1));
  auto node = [&](int i, int j)
  {
    return V2{ box.lo[0] + i * wx / nx, box.lo[1] + j * wy / ny };
  };
  for (int j = 0; j <= ny; ++j)
  {
    for (int i = 0; i <= nx; ++i)
    {
      f[j * (nx + 1) + i] = s.value(lift(node(i, j)));
    }
  }
  auto cut = [](V2 p, double fp, V2 q, double fq)
  {
    const double t = fp / (fp - fq);
    return p + t * (q - p);
  };
  for (int j = 0; j < ny; ++j)
  {
    for (int i = 0; i < nx; ++i)
    {
      const V2 p[4] = { node(i, j), node(i + 1, j), node(i + 1, j + 1), node(i, j + 1) };
      const double v[4] = { f[j * (nx + 1) + i], f[j * (nx + 1) + i + 1],
        f[(j + 1) * (nx + 1) + i + 1], f[(j + 1) * (nx + 1) + i] };
      std::vector<V2> cuts;
      for (int e = 0; e < 4; ++e)
      {
        const int n = (e + 1) % 4;
        if ((v[e] >= 0) != (v[n] >= 0))
        {
          cuts.push_back(cut(p[e], v[e], p[n], v[n]));
        }
      }
      if (cuts.size() == 2)
      {
        out.push_back(makeSegment(cuts[0], cuts[1]));
      }
      else if (cuts.size() == 4)
      {
        const double centre = s.value(lift(0.5 * (p[0] + p[2])));
        if ((centre >= 0) == (v[0] >= 0))
        {
          out.push_back(makeSegment(cuts[0], cuts[1]));
          out.push_back(makeSegment(cuts[2], cuts[3]));
        }
        else
        {
          out.push_back(makeSegment(cuts[3], cuts[0]));
          out.push_back(makeSegment(cuts[1], cuts[2]));
        }
      }
    }
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// Closest points and distances.

/// A foot of x on {f = 0} from `start`: Newton steps onto the boundary alternating with moves
/// to the foot of x on the tangent plane there.
Vec3 footPoint(const Prepared& s, const Vec3& x, Vec3 y)
{
  const int axes = s.flat ? 2 : 3;
  for (int it = 0; it < 100; ++it)
  {
    const Vec3 before = y;
    for (int k = 0; k < 4; ++k)
    {
      Vec3 g;
      const double f = s.gradient(y, g);
      const double g2 = g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
      if (!(g2 > 0) || !std::isfinite(f))
      {
        return y;
      }
      // Keep a step within the shape's size: far from the boundary a field need not be linear.
      double step = -f / g2;
      const double len = std::abs(step) * std::sqrt(g2);
      if (len > 0.25 * s.scale)
      {
        step *= 0.25 * s.scale / len;
      }
      for (int i = 0; i < axes; ++i)
      {
        y[i] += step * g[i];
      }
    }
    Vec3 g;
    s.gradient(y, g);
    const double gn = frep::norm(g);
    if (gn > 0)
    {
      double along = 0;
      for (int i = 0; i < axes; ++i)
      {
        along += (x[i] - y[i]) * g[i] / gn;
      }
      Vec3 z = y;
      for (int i = 0; i < axes; ++i)
      {
        z[i] = x[i] - along * g[i] / gn;
      }
      // Move along the tangent plane only part of the way when far: the plane is first order.
      const double move = frep::distance(z, y);
      const double limit = 0.25 * s.scale;
      const double t = move > limit ? limit / move : 1.0;
      for (int i = 0; i < axes; ++i)
      {
        y[i] += t * (z[i] - y[i]);
      }
    }
    if (frep::distance(before, y) <= 1e-12 * s.scale)
    {
      break;
    }
  }
  // Land on the surface after the last tangential move.
  for (int k = 0; k < 4; ++k)
  {
    Vec3 g;
    const double f = s.gradient(y, g);
    const double g2 = g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
    if (!(g2 > 0))
    {
      break;
    }
    for (int i = 0; i < axes; ++i)
    {
      y[i] -= f * g[i] / g2;
    }
  }
  return y;
}

/// The point of the shape nearest to x: exact for pieces, disks and circles, spheres and boxes
/// placed by a similarity; otherwise the foot of x on {f = 0} by alternating Newton steps onto
/// the surface and projections onto its tangent plane (a local foot, exact for spheres).
Vec3 closestPoint(const Prepared& s, Vec3 x)
{
  if (s.flat)
  {
    x[2] = 0;
  }
  if (s.solid() && s.value(x) >= 0)
  {
    return x;
  }
  if (s.analytic)
  {
    double best = Inf;
    V2 bestPoint{};
    for (const auto& pc : s.pieces)
    {
      const V2 c = closestOnPiece(pc, xy(x));
      if (norm(c - xy(x)) < best)
      {
        best = norm(c - xy(x));
        bestPoint = c;
      }
    }
    return lift(bestPoint);
  }
  if (s.parts.size() == 1 && !s.flat)
  {
    const ShapePart& p = *s.parts[0].part;
    const auto& a = s.shape->place.a;
    // Columns of the linear part: orthogonal columns make boxes boxes; equal lengths too make
    // spheres spheres.
    Vec3 col[3];
    double len[3];
    for (int j = 0; j < 3; ++j)
    {
      col[j] = { a[j], a[3 + j], a[6 + j] };
      len[j] = frep::norm(col[j]);
    }
    auto d = [&](int i, int j)
    {
      return col[i][0] * col[j][0] + col[i][1] * col[j][1] + col[i][2] * col[j][2];
    };
    const double big = std::max({ len[0], len[1], len[2] });
    const bool orthogonal = std::abs(d(0, 1)) <= 1e-12 * big * big &&
      std::abs(d(0, 2)) <= 1e-12 * big * big && std::abs(d(1, 2)) <= 1e-12 * big * big;
    const Vec3 c = s.shape->place.b;
    if (orthogonal && p.kind == ShapePart::Kind::Box)
    {
      Vec3 r = c;
      for (int j = 0; j < 3; ++j)
      {
        const double half = 0.5 * p.size[j] * len[j];
        const double t = std::clamp(d(j, j) > 0
            ? (((x[0] - c[0]) * col[j][0] + (x[1] - c[1]) * col[j][1] + (x[2] - c[2]) * col[j][2]) /
                len[j])
            : 0.0,
          -half, half);
        for (int i = 0; i < 3; ++i)
        {
          r[i] += t * col[j][i] / len[j];
        }
      }
      return r;
    }
    const bool similar = orthogonal && std::abs(len[0] - len[1]) <= 1e-12 * big &&
      std::abs(len[0] - len[2]) <= 1e-12 * big;
    if (similar && p.kind == ShapePart::Kind::Sphere)
    {
      const Vec3 e = frep::sub(x, c);
      const double n = frep::norm(e);
      const double r = p.radius * len[0];
      return n > 0 ? Vec3{ c[0] + r * e[0] / n, c[1] + r * e[1] / n, c[2] + r * e[2] / n }
                   : Vec3{ c[0] + r, c[1], c[2] };
    }
  }
  // From x itself (exact for spheres, and a local foot elsewhere); when that does not reach
  // the boundary (a field whose gradient at x does not lead there, e.g. on a symmetry line
  // between two blobs), from where the segment to the nearest inside sample crosses it.
  const double onTol = 1e-6 * s.scale;
  Vec3 best = footPoint(s, x, x);
  double bestDistance = s.boundaryDistance(best) <= onTol ? frep::distance(best, x) : Inf;
  const auto& inside = bestDistance < Inf ? std::vector<Vec3>{} : s.insideSamples();
  if (!inside.empty())
  {
    const Vec3* seed = &inside[0];
    for (const auto& q : inside)
    {
      if (frep::distance(q, x) < frep::distance(*seed, x))
      {
        seed = &q;
      }
    }
    Vec3 out = x, in = *seed;
    for (int it = 0; it < 60; ++it)
    {
      Vec3 mid;
      for (int i = 0; i < 3; ++i)
      {
        mid[i] = 0.5 * (out[i] + in[i]);
      }
      (s.value(mid) >= 0 ? in : out) = mid;
    }
    const Vec3 crossing = in;
    const Vec3 refined = footPoint(s, x, crossing);
    const Vec3 candidate = s.boundaryDistance(refined) <= onTol &&
        frep::distance(refined, x) <= frep::distance(crossing, x)
      ? refined
      : crossing;
    if (frep::distance(candidate, x) < bestDistance)
    {
      best = candidate;
      bestDistance = frep::distance(candidate, x);
    }
  }
  return best;
}

/// Newton steps towards {f >= 0} along grad f, each at most `maxStep` long (none from inside).
Vec3 intoShape(const Prepared& s, Vec3 x, double maxStep)
{
  const int axes = s.flat ? 2 : 3;
  for (int k = 0; k < 8; ++k)
  {
    Vec3 g;
    const double f = s.gradient(x, g);
    const double g2 = g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
    if (f >= 0 || !std::isfinite(f) || !(g2 > 0))
    {
      break;
    }
    double step = -f / g2;
    const double len = step * std::sqrt(g2);
    if (len > maxStep)
    {
      step *= maxStep / len;
    }
    for (int i = 0; i < axes; ++i)
    {
      x[i] += step * g[i];
    }
    // Quadratic convergence: the next step would be below rounding.
    if (len <= 1e-12 * s.scale)
    {
      break;
    }
  }
  return x;
}

/// A local minimum of sign x fA over {fB >= 0} from x (left where it ends): steps along the
/// descent direction, tangent to B's boundary where they would leave B, pulled back onto B by
/// Newton steps, the step length doubled after a success and halved after a failure, down to
/// 1e-9 of the size (the value then varies by ~curvature x step^2 at most). `inB` is how far
/// outside B (first order) a point may be and still count as B's (rounding of the Newton
/// steps). Stops early once the objective < `stop`. Returns the objective there (+inf when x
/// could not be brought into B).
double lowestInside(const Prepared& a, const Prepared& b, Vec3& x, double step, double inB,
  double stop, double sign = 1)
{
  const int axes = a.flat && b.flat ? 2 : 3;
  auto objective = [&](const Vec3& y, Vec3& g)
  {
    const double v = sign * a.gradient(y, g);
    for (auto& c : g)
    {
      c *= sign;
    }
    return v;
  };
  auto member = [&](const Vec3& y)
  {
    return b.value(y) >= 0 || b.boundaryDistance(y) <= inB;
  };
  x = intoShape(b, x, step);
  if (!member(x))
  {
    return Inf;
  }
  Vec3 ga;
  double fa = objective(x, ga);
  const double smallest = 1e-9 * std::max(a.scale, b.scale);
  for (int it = 0; it < 200 && fa >= stop && step > smallest; ++it)
  {
    Vec3 gb;
    const double fb = b.gradient(x, gb);
    Vec3 d{ -ga[0], -ga[1], axes == 3 ? -ga[2] : 0.0 };
    const double gb2 = gb[0] * gb[0] + gb[1] * gb[1] + gb[2] * gb[2];
    const double out = d[0] * gb[0] + d[1] * gb[1] + d[2] * gb[2];
    // Only on the boundary itself: inside, B's active piece need not be its boundary there (a
    // clipping domain's face above a field's top), and a step out is pulled back anyway.
    if (gb2 > 0 && out < 0 && fb <= inB * std::sqrt(gb2))
    {
      for (int i = 0; i < axes; ++i)
      {
        d[i] -= out / gb2 * gb[i];
      }
    }
    const double dn = frep::norm(d);
    if (!(dn > 0))
    {
      break;
    }
    bool moved = false;
    while (!moved && step > smallest)
    {
      Vec3 y = x;
      for (int i = 0; i < axes; ++i)
      {
        y[i] += step * d[i] / dn;
      }
      y = intoShape(b, y, step);
      Vec3 gy;
      const double fy = member(y) ? objective(y, gy) : Inf;
      if (fy < fa)
      {
        x = y;
        fa = fy;
        ga = gy;
        step *= 2;
        moved = true;
      }
      else
      {
        step *= 0.5;
      }
    }
  }
  return fa;
}

/// Alternating projections between the shapes from a seed projected onto `first`: the nearest
/// pair for convex shapes, a local one otherwise.
double alternatingFrom(const Prepared& first, const Prepared& second, const Vec3& seed)
{
  const double scale = std::max(first.scale, second.scale);
  Vec3 p = closestPoint(first, seed);
  Vec3 q = closestPoint(second, p);
  double d = frep::distance(p, q);
  for (int it = 0; it < 500 && d > 0; ++it)
  {
    if (it == 16 && first.solid() && second.solid())
    {
      // Still going: nearly tangent boundaries, where a round trip gains only ~gap / radius of
      // the offset from the nearest pair, which then costs ~offset^2 / radius of distance.
      // Climb fB along A instead (its maximum over A is where the gap is least, to first order
      // in the gap), and go on alternating from there.
      Vec3 x = p;
      const double top =
        -lowestInside(second, first, x, std::max(d, 1e-3 * scale), 1e-12 * scale, 0.0, -1.0);
      if (top < Inf)
      {
        const Vec3 p2 = closestPoint(first, x);
        const Vec3 q2 = closestPoint(second, p2);
        if (frep::distance(p2, q2) < d)
        {
          p = p2;
          q = q2;
          d = frep::distance(p2, q2);
          continue;
        }
      }
    }
    const Vec3 p2 = closestPoint(first, q);
    const Vec3 q2 = closestPoint(second, p2);
    const double d2 = frep::distance(p2, q2);
    p = p2;
    q = q2;
    // The distance is stationary at the nearest pair, so its error is about the last
    // decrease over (1 - the contraction rate).
    const bool stalled = d - d2 <= 1e-12 * scale;
    d = std::min(d, d2);
    if (stalled)
    {
      break;
    }
  }
  return d;
}

/// From both centres (the second only when the first gives more than `enough`).
double alternatingDistance(const Prepared& a, const Prepared& b, double enough = 0)
{
  const double d = alternatingFrom(a, b, b.bounds.centre());
  return d > enough ? std::min(d, alternatingFrom(b, a, a.bounds.centre())) : d;
}

/// A point of each piece (to test whether one shape has points inside the other).
std::vector<V2> piecePoints(const Prepared& s)
{
  std::vector<V2> out;
  for (const auto& pc : s.pieces)
  {
    out.push_back(pc.at(pc.lo()));
  }
  return out;
}

double analyticDistance(const Prepared& a, const Prepared& b)
{
  for (int k = 0; k < 2; ++k)
  {
    const Prepared& outer = k == 0 ? a : b;
    const Prepared& inner = k == 0 ? b : a;
    if (outer.solid())
    {
      for (const V2& p : piecePoints(inner))
      {
        if (outer.value(lift(p)) >= 0)
        {
          return 0;
        }
      }
    }
  }
  double best = Inf;
  for (const auto& pa : a.pieces)
  {
    for (const auto& pb : b.pieces)
    {
      best = std::min(best, pieceDistance(pa, pb));
    }
  }
  return best;
}

bool sphereSphere(const Prepared& s, Vec3& centre, double& radius)
{
  if (s.parts.size() != 1 || s.parts[0].part->kind != ShapePart::Kind::Sphere)
  {
    return false;
  }
  const auto& a = s.shape->place.a;
  double len[3];
  for (int j = 0; j < 3; ++j)
  {
    len[j] = std::sqrt(a[j] * a[j] + a[3 + j] * a[3 + j] + a[6 + j] * a[6 + j]);
  }
  const double big = std::max({ len[0], len[1], len[2] });
  for (int i = 0; i < 3; ++i)
  {
    for (int j = i + 1; j < 3; ++j)
    {
      if (std::abs(a[i] * a[j] + a[3 + i] * a[3 + j] + a[6 + i] * a[6 + j]) > 1e-12 * big * big)
      {
        return false;
      }
    }
  }
  if (std::abs(len[0] - len[1]) > 1e-12 * big || std::abs(len[0] - len[2]) > 1e-12 * big)
  {
    return false;
  }
  centre = s.shape->place.b;
  radius = s.parts[0].part->radius * len[0];
  return true;
}

// ---------------------------------------------------------------------------------------------
// Branch and bound over boxes with the shapes' interval enclosures.

/// Searches `box` for a point where `witness` holds. `promise` bounds from above, by interval
/// arithmetic, how well a box can do; a negative promise proves there is no witness in the box.
/// The most promising box is split first, so that an existing witness is met early. Boxes
/// smaller than `minSize` are decided by their centre only, and at most `budget` boxes are
/// visited; both limits are where a "no" stops being a proof. `leaves`, when given, receives
/// the boxes left undecided at `minSize` (up to 4096), for the caller to refine locally.
bool searchBoxes(const Box3& box, bool flat, double minSize,
  const std::function<double(const Box3&)>& promise,
  const std::function<bool(const Vec3&)>& witness, int budget = 200000,
  std::vector<Box3>* leaves = nullptr)
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

// ---------------------------------------------------------------------------------------------
// Local refinement of what the boxes leave undecided. Interval enclosures cannot separate two
// boundaries that touch or nearly touch (the enclosures overlap at every box size), so the
// searches stop at a box size and the leaves they leave are decided by local optimisation from
// their centres: accurate to rounding at the optimum it converges to, but a local optimum, so
// only as good as the leaves' centres are as starting points (the few best are refined).

/// The distance between two shapes, one number for distance() and intersects() (which compares
/// it with the tolerance), so that the two never disagree: exact for analytic pairs and
/// similar spheres; otherwise alternating projections from the centres, 0 when the boxes find
/// a point inside both, and the alternating projections again from the most promising leaves
/// (where the boundaries nearly touch). Returns as soon as it is known to be <= `enough`.
double separation(const Prepared& a, const Prepared& b, double enough)
{
  if (a.analytic && b.analytic)
  {
    return analyticDistance(a, b);
  }
  Vec3 ca, cb;
  double ra, rb;
  if (sphereSphere(a, ca, ra) && sphereSphere(b, cb, rb))
  {
    return std::max(0.0, frep::distance(ca, cb) - ra - rb);
  }
  double d = alternatingDistance(a, b, enough);
  if (d <= enough || !a.solid() || !b.solid())
  {
    return d;
  }
  const bool flat = a.flat && b.flat;
  const Box3 box = flatten(meetBoxes(a.bounds, b.bounds), flat);
  if (!box.valid())
  {
    return d;
  }
  std::vector<Box3> leaves;
  const double minSize = (flat ? 1e-3 : 2e-2) * boxDiagonal(box);
  if (searchBoxes(
        box, flat, minSize, [&](const Box3& c) { return std::min(a.bound(c).hi, b.bound(c).hi); },
        [&](const Vec3& p) { return std::min(a.value(p), b.value(p)) >= 0; }, 200000, &leaves))
  {
    return 0;
  }
  std::vector<std::pair<double, Vec3>> seeds;
  for (const auto& leaf : leaves)
  {
    const Vec3 c = leaf.centre();
    seeds.push_back({ -std::min(a.value(c), b.value(c)), c });
  }
  const std::size_t refined = std::min<std::size_t>(seeds.size(), 4);
  std::partial_sort(seeds.begin(), seeds.begin() + refined, seeds.end(),
    [](const auto& x, const auto& y) { return x.first < y.first; });
  for (std::size_t i = 0; i < refined && d > enough; ++i)
  {
    d = std::min(d, alternatingFrom(a, b, seeds[i].second));
  }
  return d;
}

// ---------------------------------------------------------------------------------------------
// Areas and volumes.

/// The signed area of the disk of radius r at the origin intersected with the triangle
/// (origin, a, b): the segment a -> b is split where it crosses the circle; the parts inside
/// contribute triangles, the parts outside circular sectors.
double diskTriangleArea(V2 a, V2 b, double r)
{
  // The segment's line enters the disk for t in (t1, t2); without two roots it stays outside
  // (a tangent line touches in one point, which has no area).
  const V2 d = b - a;
  const double A = dot(d, d), B = dot(a, d), C = dot(a, a) - r * r;
  const double disc = B * B - A * C;
  double t1 = 2, t2 = 2;
  if (A > 0 && disc > 0)
  {
    const double s = std::sqrt(disc);
    t1 = (-B - s) / A;
    t2 = (-B + s) / A;
  }
  auto sector = [&](V2 p, V2 q)
  {
    return 0.5 * r * r * std::atan2(cross(p, q), dot(p, q));
  };
  const double lo = std::clamp(t1, 0.0, 1.0), hi = std::clamp(t2, 0.0, 1.0);
  if (!(lo < hi))
  {
    return sector(a, b);
  }
  const V2 p = a + lo * d, q = a + hi * d;
  return sector(a, p) + 0.5 * cross(p, q) + sector(q, b);
}

/// Clips a counter-clockwise convex polygon by the half-plane n . x >= d.
std::vector<V2> clipHalfPlane(const std::vector<V2>& poly, V2 n, double d)
{
  std::vector<V2> out;
  for (std::size_t i = 0; i < poly.size(); ++i)
  {
    const V2 p = poly[i], q = poly[(i + 1) % poly.size()];
    const double fp = dot(n, p) - d, fq = dot(n, q) - d;
    if (fp >= 0)
    {
      out.push_back(p);
    }
    if ((fp >= 0) != (fq >= 0))
    {
      out.push_back(p + (fp / (fp - fq)) * (q - p));
    }
  }
  return out;
}

double polygonArea(const std::vector<V2>& poly)
{
  double a = 0;
  for (std::size_t i = 0; i < poly.size(); ++i)
  {
    a += cross(poly[i], poly[(i + 1) % poly.size()]);
  }
  return 0.5 * a;
}

/// A convex 2D region given exactly: a counter-clockwise convex polygon, intersected with a disk
/// when `round`.
struct ConvexRegion
{
  std::vector<V2> polygon;
  bool round = false;
  V2 centre;
  double radius = 0;
};

std::vector<V2> ccw(std::vector<V2> poly)
{
  if (polygonArea(poly) < 0)
  {
    std::reverse(poly.begin(), poly.end());
  }
  return poly;
}

/// The region of a single analytic 2D part when its placement keeps circles circles.
bool convexRegion(const Prepared& s, ConvexRegion& r)
{
  if (s.parts.size() != 1 || s.dim != 2 || !s.analytic)
  {
    return false;
  }
  const ShapePart& p = *s.parts[0].part;
  if (p.kind == ShapePart::Kind::Rectangle)
  {
    std::vector<V2> poly;
    for (const auto& pc : s.pieces)
    {
      poly.push_back(pc.p);
    }
    r.polygon = ccw(poly);
    return true;
  }
  const Piece& e = s.pieces[0];
  if (!e.circle)
  {
    return false;
  }
  r.round = true;
  r.centre = e.c;
  r.radius = e.r;
  r.polygon = { e.c + V2{ -e.r, -e.r }, e.c + V2{ e.r, -e.r }, e.c + V2{ e.r, e.r },
    e.c + V2{ -e.r, e.r } };
  if (p.kind == ShapePart::Kind::CircularSegment && s.pieces.size() == 2)
  {
    // Keep the side of the chord q -> p where the arc's middle lies.
    const Piece& chord = s.pieces[1];
    const V2 dir = chord.q - chord.p;
    V2 n{ -dir.y, dir.x };
    const V2 mid = e.at(0.5 * (e.t0 + e.t1));
    if (dot(n, mid - chord.p) < 0)
    {
      n = -1.0 * n;
    }
    r.polygon = clipHalfPlane(r.polygon, n, dot(n, chord.p));
  }
  return true;
}

/// The exact area of the intersection of two such regions, when at most one is round or both
/// are plain disks (the lens). False when no closed form applies.
bool exactArea(const ConvexRegion& a, const ConvexRegion& b, double& area)
{
  if (a.round && b.round)
  {
    if (a.polygon.size() != 4 || b.polygon.size() != 4)
    {
      return false; // two circular segments: no closed form here
    }
    // Is either a plain disk? The bounding square has 4 vertices; a clipped one usually
    // more, but a chord may also cut off a corner only: compare with the square's area.
    const bool diskA =
      std::abs(polygonArea(a.polygon) - 4 * a.radius * a.radius) <= 1e-12 * a.radius * a.radius;
    const bool diskB =
      std::abs(polygonArea(b.polygon) - 4 * b.radius * b.radius) <= 1e-12 * b.radius * b.radius;
    if (!diskA || !diskB)
    {
      return false;
    }
    const double d = norm(a.centre - b.centre), r1 = a.radius, r2 = b.radius;
    if (d >= r1 + r2)
    {
      area = 0;
    }
    else if (d <= std::abs(r1 - r2))
    {
      area = Pi * std::min(r1, r2) * std::min(r1, r2);
    }
    else
    {
      // Two circular segments on either side of the radical line.
      const double x = (d * d + r1 * r1 - r2 * r2) / (2 * d);
      const double y = d - x;
      auto segment = [](double r, double h)
      {
        return r * r * std::acos(std::clamp(h / r, -1.0, 1.0)) - h * std::sqrt(r * r - h * h);
      };
      area = segment(r1, x) + segment(r2, y);
    }
    return true;
  }
  std::vector<V2> poly = a.polygon;
  for (std::size_t i = 0; i < b.polygon.size() && !poly.empty(); ++i)
  {
    const V2 p = b.polygon[i], q = b.polygon[(i + 1) % b.polygon.size()];
    const V2 n{ -(q.y - p.y), q.x - p.x };
    poly = clipHalfPlane(poly, n, dot(n, p));
  }
  if (poly.size() < 3)
  {
    area = 0;
    return true;
  }
  const ConvexRegion* round = a.round ? &a : b.round ? &b : nullptr;
  if (!round)
  {
    area = polygonArea(poly);
    return true;
  }
  area = 0;
  for (std::size_t i = 0; i < poly.size(); ++i)
  {
    area += diskTriangleArea(
      poly[i] - round->centre, poly[(i + 1) % poly.size()] - round->centre, round->radius);
  }
  return true;
}

/// The sub-box k (bit i: the upper half along axis i) of a box.
Box3 child(const Box3& b, int k, int axes)
{
  Box3 c = b;
  for (int i = 0; i < axes; ++i)
  {
    const double mid = 0.5 * (b.lo[i] + b.hi[i]);
    if ((k >> i) & 1)
    {
      c.lo[i] = mid;
    }
    else
    {
      c.hi[i] = mid;
    }
  }
  return c;
}

/// The part of a cell where m >= 0, taking the boundary as the plane of m linearised at the
/// centre: the cell's extent across it is w = sum |n_i| h_i, the part inside about 1/2 + d / w
/// for the signed distance d of the centre (exact in 1D; in 2D and 3D the error is odd in d and
/// mostly cancels along a boundary).
double planeFraction(const Box3& b, int axes, const std::function<double(const Vec3&, Vec3&)>& m)
{
  Vec3 g;
  const double v = m(b.centre(), g);
  double gn = 0, w = 0;
  for (int i = 0; i < axes; ++i)
  {
    gn += g[i] * g[i];
  }
  gn = std::sqrt(gn);
  for (int i = 0; i < axes && gn > 0; ++i)
  {
    w += std::abs(g[i]) / gn * (b.hi[i] - b.lo[i]);
  }
  if (!(w > 0) || !std::isfinite(v))
  {
    return v >= 0 ? 1.0 : 0.0;
  }
  return std::clamp(0.5 + v / gn / w, 0.0, 1.0);
}

// Levels of subdivision of boundary cells (per side 1/256 of the box in 2D, 1/64 in 3D, then
// one more for the extrapolation): relative errors ~1e-7 for a disk, ~5e-5 for a sphere.
constexpr int Depth2 = 8, Depth3 = 6;
/// The measure of {m >= 0} over `box` by interval-pruned subdivision: boxes proved inside count
/// whole, boxes proved outside nothing, and boundary boxes are split down to `depth` levels
/// (about 1/2^depth of the box per side), then estimated by planeFraction with Richardson.
double integrate(const Box3& box, bool flat, int depth,
  const std::function<Interval(const Box3&)>& bound,
  const std::function<double(const Vec3&, Vec3&)>& m)
{
  const int axes = flat ? 2 : 3;
  double total = 0;
  struct Item
  {
    Box3 b;
    int level;
  };
  std::vector<Item> stack{ { box, 0 } };
  while (!stack.empty())
  {
    const Item it = stack.back();
    stack.pop_back();
    double vol = 1;
    for (int i = 0; i < axes; ++i)
    {
      vol *= it.b.hi[i] - it.b.lo[i];
    }
    if (!(vol > 0))
    {
      continue;
    }
    const Interval r = bound(it.b);
    if (r.lo >= 0 && !r.maybeNaN)
    {
      total += vol;
      continue;
    }
    if (r.hi < 0)
    {
      continue;
    }
    if (it.level >= depth)
    {
      // Richardson: the plane estimate's error is O(h^2) relative (the boundary's curvature),
      // so (4 x the estimate over the 2^d half-size children - the cell's own) / 3 removes it.
      double fine = 0;
      for (int k = 0; k < (1 << axes); ++k)
      {
        fine += planeFraction(child(it.b, k, axes), axes, m);
      }
      fine *= vol / (1 << axes);
      const double coarse = vol * planeFraction(it.b, axes, m);
      total += std::clamp((4 * fine - coarse) / 3, 0.0, vol);
      continue;
    }
    // Split every axis: the tree stays balanced and the levels mean the same in each axis.
    for (int k = 0; k < (1 << axes); ++k)
    {
      Box3 c = it.b;
      for (int i = 0; i < axes; ++i)
      {
        const double mid = 0.5 * (it.b.lo[i] + it.b.hi[i]);
        if ((k >> i) & 1)
        {
          c.lo[i] = mid;
        }
        else
        {
          c.hi[i] = mid;
        }
      }
      stack.push_back({ c, it.level + 1 });
    }
  }
  return total;
}

double linearDeterminant(const Affine& m, bool flat)
{
  const auto& a = m.a;
  if (flat)
  {
    return a[0] * a[4] - a[1] * a[3];
  }
  return a[0] * (a[4] * a[8] - a[5] * a[7]) - a[1] * (a[3] * a[8] - a[5] * a[6]) +
    a[2] * (a[3] * a[7] - a[4] * a[6]);
}

/// The exact measure of a single analytic part, or -1.
double exactMeasure(const Prepared& s)
{
  if (s.parts.size() != 1)
  {
    return -1;
  }
  const ShapePart& p = *s.parts[0].part;
  const double det2 = std::abs(linearDeterminant(s.shape->place, true));
  const double det3 = std::abs(linearDeterminant(s.shape->place, false));
  switch (p.kind)
  {
    case ShapePart::Kind::Rectangle:
      return p.size[0] * p.size[1] * det2;
    case ShapePart::Kind::Disk:
      return Pi * p.radius * p.radius * det2;
    case ShapePart::Kind::CircularSegment:
    {
      const Piece& e = s.pieces[0];
      const double theta = e.t1 - e.t0;
      return 0.5 * p.radius * p.radius * (theta - std::sin(theta)) * det2;
    }
    case ShapePart::Kind::Box:
      return p.size[0] * p.size[1] * p.size[2] * det3;
    case ShapePart::Kind::Sphere:
      return 4.0 / 3.0 * Pi * p.radius * p.radius * p.radius * det3;
    default:
      return -1;
  }
}

/// Two axis-aligned world boxes (boxes placed without rotation or shear): their overlap.
bool worldAxisBox(const Prepared& s, Box3& box)
{
  if (s.parts.size() != 1 || s.parts[0].part->kind != ShapePart::Kind::Box)
  {
    return false;
  }
  const auto& a = s.shape->place.a;
  if (a[1] != 0 || a[2] != 0 || a[3] != 0 || a[5] != 0 || a[6] != 0 || a[7] != 0)
  {
    return false;
  }
  box = s.bounds;
  return true;
}

double sphereLens(double r1, double r2, double d)
{
  if (d >= r1 + r2)
  {
    return 0;
  }
  if (d <= std::abs(r1 - r2))
  {
    const double r = std::min(r1, r2);
    return 4.0 / 3.0 * Pi * r * r * r;
  }
  const double s = r1 + r2 - d;
  return Pi * s * s * (d * d + 2 * d * (r1 + r2) - 3 * (r1 - r2) * (r1 - r2)) / (12 * d);
}

// ---------------------------------------------------------------------------------------------
// World fields of placed shapes, for complex cells.

class ShapeFieldEvaluator final : public frep::FieldEvaluator
{
public:
  explicit ShapeFieldEvaluator(std::shared_ptr<const Shape> shape)
    : shape_(std::move(shape))
    , prepared_(*shape_)
  {
  }
  void values(
    const double* x, const double* y, const double* z, double* out, std::size_t n) override
  {
    for (std::size_t i = 0; i < n; ++i)
    {
      out[i] = prepared_.value({ x[i], y[i], z[i] });
    }
  }
  Interval bound(const Box3& box) override { return prepared_.bound(box); }
  double gradient(const frep::Point3& p, frep::Point3& grad) override
  {
    Vec3 g;
    const double v = prepared_.gradient(p, g);
    grad = g;
    return v;
  }

private:
  std::shared_ptr<const Shape> shape_;
  Prepared prepared_;
};

class ShapeField final : public frep::Field
{
public:
  explicit ShapeField(std::shared_ptr<const Shape> shape)
    : shape_(std::move(shape))
  {
  }
  std::unique_ptr<frep::FieldEvaluator> evaluator() const override
  {
    return std::make_unique<ShapeFieldEvaluator>(shape_);
  }

private:
  std::shared_ptr<const Shape> shape_;
};

} // namespace

// -------------------------------------------------------------------------------------------------

frep::FieldPtr worldField(const Shape& s)
{
  return std::make_shared<ShapeField>(std::make_shared<const Shape>(s));
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

double Shape::value(const Vec3& world) const
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

frep::Box3 Shape::worldBounds() const
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
      {
        if (!p.operandA || !p.operandB)
        {
          break;
        }
        // The blend's bump reaches about 1.7 a0 beyond the operands where their fields are
        // distances (a0 / (1 + 2 d^2) = (2 - sqrt 2) d); 2 a0 covers it.
        add(padded(joinBoxes(p.operandA->worldBounds(), p.operandB->worldBounds()),
          p.kind == ShapePart::Kind::Blend ? 2 * p.amount : 0.0));
        break;
      }
      default:
        add(mapBox(place, localBox(p)));
        break;
    }
  }
  return r;
}

double distance(const Shape& a, const Shape& b, const QueryOptions& o)
{
  checkOptions(a, b, o);
  const Prepared pa(a), pb(b);
  return separation(pa, pb, 0.0);
}

bool intersects(const Shape& a, const Shape& b, const QueryOptions& o)
{
  checkOptions(a, b, o);
  const Prepared pa(a), pb(b);
  // The very number distance() returns, compared with the tolerance: touching is "distance <=
  // tolerance" everywhere, which intersectionPoints' tangency rule (a first-order distance <=
  // tolerance) agrees with up to rounding and second-order terms (~1e-16 for the engine's
  // sizes), so that a pair never intersects without meeting points or one inside the other.
  const double tol = defaultTolerance(pa, pb, o);
  return separation(pa, pb, tol) <= tol;
}

bool contains(const Shape& a, const Shape& b, const QueryOptions& o)
{
  checkOptions(a, b, o);
  const Prepared pa(a), pb(b);
  if (!pa.solid())
  {
    failPair(a, b, "contains() needs a 2D or 3D container, '" + a.cell + "' is a point or curve");
  }
  const double tol = defaultTolerance(pa, pb, o);
  auto inside = [&](const Vec3& p)
  {
    return pa.value(p) >= 0 || pa.boundaryDistance(p) <= tol;
  };
  // Points and curves (and the boundary of an analytic region inside a single analytic
  // region, which is convex): the lowest value of A along each piece.
  const bool convexA = pa.analytic && pa.parts.size() == 1;
  if (!pb.solid() || (pb.analytic && convexA))
  {
    for (const auto& pc : pb.pieces)
    {
      if (pc.type == Piece::Type::Point)
      {
        if (!inside(lift(pc.p)))
        {
          return false;
        }
        continue;
      }
      const int n = walkSamples(pc, !pa.analytic, o);
      const double lo = pc.lo(), hi = pc.hi(), h = (hi - lo) / n;
      std::vector<double> v(n + 1);
      for (int i = 0; i <= n; ++i)
      {
        v[i] = pa.value(lift(pc.at(lo + i * h)));
        if (!inside(lift(pc.at(lo + i * h))))
        {
          return false;
        }
      }
      for (int i = 1; i < n; ++i)
      {
        if (v[i] <= v[i - 1] && v[i] <= v[i + 1])
        {
          double t = lo + i * h;
          goldenMinimum([&](double tt) { return pa.value(lift(pc.at(tt))); }, t - h, t + h, t);
          if (!inside(lift(pc.at(t))))
          {
            return false;
          }
        }
      }
    }
    return true;
  }
  // Solids: no point with fB >= 0 and fA < -tol. The boxes prove it where A's enclosure stays
  // above -tol, or find a witness; where B's boundary runs along A's (B touching A from
  // inside) no box size decides, so they stop at 1e-2 (2D) or 1e-1 (3D) of B's box, coarse
  // to stay cheap, and the lowest fA over B is found by descent from the best few leaves: the
  // answer then flips within the descent's accuracy (~1e-13 measured) of the placement where
  // min fA over B = -tol, as long as A's lowest point on B is the minimum that one of those
  // descents reaches (a local search from up to four distinct leaves, ranked by fA: right
  // whenever the lowest point is in one of their basins, likely but not proved).
  const bool flat = pa.flat && pb.flat;
  const Box3 box = flatten(pb.bounds, flat);
  const double minSize = std::max(tol, (flat ? 1e-2 : 1e-1) * boxDiagonal(box));
  std::vector<Box3> leaves;
  const bool escapes = searchBoxes(
    box, flat, minSize,
    [&](const Box3& c)
    {
      const double outside = -tol - pa.bound(c).lo;
      return outside > 0 ? std::min(pb.bound(c).hi, outside) : -1.0;
    },
    [&](const Vec3& p) { return pb.value(p) >= 0 && pa.value(p) < -tol; }, 200000, &leaves);
  if (escapes)
  {
    return false;
  }
  // Rank the leaves by fA where their centres land on B; a leaf near where an earlier descent
  // ended would descend to the same point.
  std::vector<std::pair<double, Vec3>> seeds;
  for (const auto& leaf : leaves)
  {
    const Vec3 p = intoShape(pb, leaf.centre(), minSize);
    seeds.push_back({ pa.value(p), leaf.centre() });
  }
  std::sort(
    seeds.begin(), seeds.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
  std::vector<Vec3> ends;
  const double reach = 2 * (flat ? std::sqrt(2.0) : std::sqrt(3.0)) * minSize;
  for (const auto& seed : seeds)
  {
    if (ends.size() >= 4)
    {
      break;
    }
    if (std::any_of(ends.begin(), ends.end(),
          [&](const Vec3& e) { return frep::distance(e, seed.second) <= reach; }))
    {
      continue;
    }
    Vec3 x = seed.second;
    if (lowestInside(pa, pb, x, minSize, 1e-3 * tol, -tol) < -tol)
    {
      return false;
    }
    ends.push_back(x);
  }
  return true;
}

std::vector<Vec3> intersectionPoints(const Shape& a, const Shape& b, const QueryOptions& o)
{
  checkOptions(a, b, o);
  const Prepared pa(a), pb(b);
  if (pa.dim == 3 || pb.dim == 3)
  {
    failPair(a, b,
      "intersection points need two shapes in the plane (points, curves or 2D "
      "regions), not 3D solids");
  }
  const double tol = defaultTolerance(pa, pb, o);
  std::vector<V2> found;
  // Points: a point shape meets the other where it lies on its curve or boundary.
  auto pointsOn = [&](const Prepared& p, const Prepared& other)
  {
    for (const auto& pc : p.pieces)
    {
      const Vec3 x = lift(pc.p);
      bool on = false;
      if (other.analytic)
      {
        for (const auto& q : other.pieces)
        {
          on = on || pieceDistance(pc, q) <= tol;
        }
      }
      else
      {
        on = other.boundaryDistance(x) <= tol;
      }
      if (on)
      {
        found.push_back(pc.p);
      }
    }
  };
  auto onBoundary = [&](const Prepared& s, V2 x)
  {
    // Several parts: a part's boundary inside another part is not the union's boundary.
    return s.parts.size() < 2 || !s.solid() || s.value(lift(x)) <= 0 ||
      s.boundaryDistance(lift(x)) <= tol;
  };
  if (pa.dim == 0 || pb.dim == 0)
  {
    if (pa.dim == 0)
    {
      pointsOn(pa, pb);
    }
    if (pb.dim == 0)
    {
      pointsOn(pb, pa);
    }
  }
  else if (pa.analytic && pb.analytic)
  {
    for (const auto& p : pa.pieces)
    {
      for (const auto& q : pb.pieces)
      {
        // Walk the segment, or the circle, along the other's carrier.
        const bool swap = q.type == Piece::Type::Segment && p.type != Piece::Type::Segment;
        const Piece& walk = swap ? q : p;
        const Piece& other = swap ? p : q;
        std::vector<V2> cand;
        curveRoots(
          walk, walkSamples(walk, false, o),
          [&](V2 x)
          {
            V2 grad;
            return carrier(other, x, grad);
          },
          [&](V2 x, V2& grad) { return carrier(other, x, grad); }, tol, cand);
        for (const V2& x : cand)
        {
          if (onExtent(other, x, tol) && onBoundary(pa, x) && onBoundary(pb, x))
          {
            found.push_back(x);
          }
        }
      }
    }
  }
  else if (pa.analytic || pb.analytic)
  {
    const Prepared& curves = pa.analytic ? pa : pb;
    const Prepared& field = pa.analytic ? pb : pa;
    for (const auto& p : curves.pieces)
    {
      std::vector<V2> cand;
      curveRoots(
        p, walkSamples(p, true, o), [&](V2 x) { return field.value(lift(x)); },
        [&](V2 x, V2& grad)
        {
          Vec3 g;
          const double v = field.gradient(lift(x), g);
          grad = { g[0], g[1] };
          return v;
        },
        tol, cand);
      for (const V2& x : cand)
      {
        if (onBoundary(curves, x))
        {
          found.push_back(x);
        }
      }
    }
  }
  else
  {
    // Two fields: trace A's boundary over the common box; walk each traced segment projected
    // onto A's curve (Newton steps along grad fA), a little beyond its ends so that an extremum
    // at a shared vertex is inside some walk, and find B's crossings and tangencies there.
    const Box3 box = flatten(padded(meetBoxes(pa.bounds, pb.bounds), 1e-6 * pa.scale), true);
    if (box.lo[0] <= box.hi[0] && box.lo[1] <= box.hi[1])
    {
      auto ontoA = [&](V2 x)
      {
        for (int k = 0; k < 6; ++k)
        {
          Vec3 g;
          const double f = pa.gradient(lift(x), g);
          const double g2 = g[0] * g[0] + g[1] * g[1];
          if (!(g2 > 0))
          {
            break;
          }
          const V2 step{ -f * g[0] / g2, -f * g[1] / g2 };
          x = x + step;
          if (norm(step) <= 1e-15 * pa.scale)
          {
            break;
          }
        }
        return x;
      };
      auto fB = [&](V2 x, V2& grad)
      {
        Vec3 g;
        const double v = pb.gradient(lift(x), g);
        grad = { g[0], g[1] };
        return v;
      };
      for (const auto& seg : traceContour(pa, box, 128))
      {
        const double len = norm(seg.q - seg.p);
        V2 gp, gq;
        const double vp = fB(seg.p, gp), vq = fB(seg.q, gq);
        const bool far = ((vp > 0) == (vq > 0)) &&
          std::min(std::abs(vp) / std::max(norm(gp), 1e-300),
            std::abs(vq) / std::max(norm(gq), 1e-300)) > 2 * len + tol;
        if (far)
        {
          continue;
        }
        std::vector<V2> cand;
        curveRoots([&](double t) { return ontoA(seg.at(t)); }, -0.5, 1.5, 8,
          [&](V2 x) { return pb.value(lift(x)); }, fB, tol, cand, false);
        for (const V2& x : cand)
        {
          if (pa.boundaryDistance(lift(x)) <= std::max(tol, 1e-9 * pa.scale) &&
            pb.boundaryDistance(lift(x)) <= tol)
          {
            found.push_back(x);
          }
        }
      }
    }
  }
  std::vector<Vec3> points;
  for (const V2& x : found)
  {
    points.push_back(lift(x));
  }
  // A meeting found twice (at a polygon's corner from both edges, from both sides of a traced
  // cell, from overlapping walks) is one point: the merge distance is the tolerance, and
  // 1e-6 x the size for two fields, whose tangency points are located to ~1e-8 x the size.
  const double merge =
    (pa.analytic || pb.analytic) ? tol : std::max(tol, 1e-6 * std::max(pa.scale, pb.scale));
  return mergeAndSort(points, merge);
}

double intersectionMeasure(const Shape& a, const Shape& b, const QueryOptions& o)
{
  checkOptions(a, b, o);
  const Prepared pa(a), pb(b);
  if (!pa.solid() || !pb.solid() || pa.flat != pb.flat)
  {
    failPair(a, b, "an intersection area or volume needs two 2D or two 3D shapes");
  }
  ConvexRegion ra, rb;
  double area = 0;
  if (convexRegion(pa, ra) && convexRegion(pb, rb) && exactArea(ra, rb, area))
  {
    return std::max(0.0, area);
  }
  Vec3 ca, cb;
  double r1, r2;
  if (sphereSphere(pa, ca, r1) && sphereSphere(pb, cb, r2))
  {
    return sphereLens(r1, r2, frep::distance(ca, cb));
  }
  Box3 ba, bb;
  if (worldAxisBox(pa, ba) && worldAxisBox(pb, bb))
  {
    const Box3 m = meetBoxes(ba, bb);
    double v = 1;
    for (int i = 0; i < 3; ++i)
    {
      v *= std::max(0.0, m.hi[i] - m.lo[i]);
    }
    return v;
  }
  const bool flat = pa.flat;
  const Box3 box = flatten(meetBoxes(pa.bounds, pb.bounds), flat);
  if (!box.valid())
  {
    return 0;
  }
  return integrate(
    box, flat, flat ? Depth2 : Depth3,
    [&](const Box3& c) { return ivMin(pa.bound(c), pb.bound(c)); },
    [&](const Vec3& p, Vec3& g)
    {
      Vec3 gb;
      const double fa = pa.gradient(p, g), fb = pb.gradient(p, gb);
      if (fb < fa)
      {
        g = gb;
      }
      return std::min(fa, fb);
    });
}

double measure(const Shape& s, const QueryOptions& o)
{
  checkOptions(s, s, o);
  const Prepared p(s);
  if (!p.solid())
  {
    fail(s, "a point or curve has no area or volume");
  }
  const double exact = exactMeasure(p);
  if (exact >= 0)
  {
    return exact;
  }
  const Box3 box = flatten(p.bounds, p.flat);
  return integrate(
    box, p.flat, p.flat ? Depth2 : Depth3, [&](const Box3& c) { return p.bound(c); },
    [&](const Vec3& x, Vec3& g) { return p.gradient(x, g); });
}

complex::Cell toComplexCell(const Shape& s, complex::CellKind kind, const QueryOptions& o)
{
  validate(s);
  const Prepared p(s);
  complex::Cell cell;
  cell.name = s.cell;
  cell.dimension = p.dim;
  cell.kind = kind;
  bool explicitOnly = true;
  for (const auto& pp : p.parts)
  {
    const auto k = pp.part->kind;
    explicitOnly = explicitOnly &&
      (k == ShapePart::Kind::Point || k == ShapePart::Kind::Segment ||
        k == ShapePart::Kind::Polyline || k == ShapePart::Kind::Arc ||
        k == ShapePart::Kind::Rectangle || k == ShapePart::Kind::Box) &&
      pp.dim == p.dim;
  }
  if (explicitOnly)
  {
    complex::ExplicitGeometry g;
    auto add = [&](const Vec3& local)
    {
      g.points.push_back(s.place.apply(local));
      return static_cast<std::uint32_t>(g.points.size() - 1);
    };
    for (const auto& pp : p.parts)
    {
      const ShapePart& part = *pp.part;
      switch (part.kind)
      {
        case ShapePart::Kind::Point:
          for (const auto& q : part.points)
          {
            add(q);
          }
          break;
        case ShapePart::Kind::Segment:
        case ShapePart::Kind::Polyline:
        {
          std::vector<std::uint32_t> line;
          for (const auto& q : part.points)
          {
            line.push_back(add(q));
          }
          g.polylines.push_back(line);
          break;
        }
        case ShapePart::Kind::Arc:
        {
          const double t0 = std::atan2(part.points[0][1], part.points[0][0]);
          double t1 = std::atan2(part.points[1][1], part.points[1][0]);
          while (t1 <= t0)
          {
            t1 += 2 * Pi;
          }
          const int n =
            std::max(2, static_cast<int>(std::ceil(o.arcSegments * (t1 - t0) / (2 * Pi))));
          std::vector<std::uint32_t> line;
          for (int i = 0; i <= n; ++i)
          {
            const double t = t0 + (t1 - t0) * i / n;
            line.push_back(add({ part.radius * std::cos(t), part.radius * std::sin(t), 0 }));
          }
          g.polylines.push_back(line);
          break;
        }
        case ShapePart::Kind::Rectangle:
        {
          const double w = 0.5 * part.size[0], h = 0.5 * part.size[1];
          const auto c0 = add({ -w, -h, 0 }), c1 = add({ w, -h, 0 }), c2 = add({ w, h, 0 }),
                     c3 = add({ -w, h, 0 });
          g.triangles.push_back({ c0, c1, c2 });
          g.triangles.push_back({ c0, c2, c3 });
          break;
        }
        case ShapePart::Kind::Box:
        {
          std::uint32_t c[8];
          for (int k = 0; k < 8; ++k)
          {
            c[k] = add({ (k & 1 ? 0.5 : -0.5) * part.size[0], (k & 2 ? 0.5 : -0.5) * part.size[1],
              (k & 4 ? 0.5 : -0.5) * part.size[2] });
          }
          // Six tetrahedra around the diagonal 0-7 (the Kuhn split of the cube).
          const int paths[6][2] = { { 1, 3 }, { 1, 5 }, { 2, 3 }, { 2, 6 }, { 4, 5 }, { 4, 6 } };
          for (const auto& q : paths)
          {
            g.tetrahedra.push_back({ c[0], c[q[0]], c[q[1]], c[7] });
          }
          break;
        }
        default:
          break;
      }
    }
    if (cell.kind != complex::CellKind::Point && cell.kind != complex::CellKind::BRep)
    {
      // An explicit geometry is a P or B cell whatever the model called it.
      cell.kind = p.dim == 0 ? complex::CellKind::Point : complex::CellKind::BRep;
    }
    cell.geometry = std::move(g);
    return cell;
  }
  if (p.dim < 2)
  {
    fail(s, "mixes points and curves of different dimensions; no single complex cell holds it");
  }
  complex::ImplicitGeometry g;
  g.inside.push_back(std::make_shared<ShapeField>(std::make_shared<const Shape>(s)));
  g.insideText.push_back("shape of " + s.cell);
  g.bounds = p.bounds;
  if (p.flat)
  {
    g.carriers.push_back(frep::tapeField(frep::Tape::compile(frep::Expr::z())));
    g.carrierText.push_back("z");
    // A thin slab about z = 0, so that the box has a thickness for discretisers.
    const double pad = 1e-3 * p.scale;
    g.bounds.lo[2] = -pad;
    g.bounds.hi[2] = pad;
  }
  if (cell.kind == complex::CellKind::Point || cell.kind == complex::CellKind::BRep ||
    cell.kind == complex::CellKind::MappedFRep)
  {
    cell.kind = complex::CellKind::FRep;
  }
  cell.geometry = std::move(g);
  return cell;
}

} // namespace ictk::engine
