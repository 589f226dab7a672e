// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Internal to the Geometry library: the analytic curves of placed shapes in the world plane
// ("pieces": points, segments and arcs of ellipses; the curve of a 0D/1D part or the boundary of
// a 2D analytic part) and the 2D vectors they are computed with. A 2D model lies in z = 0, so
// the plane's queries work on (x, y) of the world; 3D code uses FRep/Vector.h.

#include "Geometry/PlacedShape.h"

#include <cmath>
#include <functional>
#include <limits>

namespace ictk::geometry::detail
{

constexpr double Pi = 3.14159265358979323846;
constexpr double Inf = std::numeric_limits<double>::infinity();

/// A point or vector of the world plane.
struct V2
{
  double x = 0, y = 0;
};
inline V2 operator+(V2 a, V2 b)
{
  return { a.x + b.x, a.y + b.y };
}
inline V2 operator-(V2 a, V2 b)
{
  return { a.x - b.x, a.y - b.y };
}
inline V2 operator*(double s, V2 a)
{
  return { s * a.x, s * a.y };
}
inline double dot(V2 a, V2 b)
{
  return a.x * b.x + a.y * b.y;
}
inline double cross(V2 a, V2 b)
{
  return a.x * b.y - a.y * b.x;
}
inline double norm(V2 a)
{
  return std::hypot(a.x, a.y);
}
inline V2 xy(const Vec3& p)
{
  return { p[0], p[1] };
}
inline Vec3 lift(V2 p)
{
  return { p.x, p.y, 0.0 };
}

/// One analytic curve of the world plane, parametrised by t in [lo(), hi()].
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

Piece makeSegment(V2 p, V2 q);
Piece makeEllipse(V2 c, V2 u, V2 v, double t0, double t1);

/// The carrier of a piece (its line, circle or ellipse; the point itself), as a function that
/// vanishes on it, with gradient, so that |g| / |grad g| is a first-order distance.
double carrier(const Piece& s, V2 x, V2& grad);

/// Whether a point of the carrier lies on the piece itself (its extent), up to `tol`.
bool onExtent(const Piece& s, V2 x, double tol);

/// The minimum of f over [a, b] by golden-section search (to eps relative to |a| + |b| + 1); its
/// argument in tBest. FRep's goldenSection (FRep/RootFinding.h), in the form the curves use.
double goldenMinimum(
  const std::function<double(double)>& f, double a, double b, double& tBest, double eps = 1e-15);

/// The point of a piece nearest to x.
V2 closestOnPiece(const Piece& s, V2 x);

/// The distance between two pieces: exact for point and segment pairs; otherwise the minimum
/// over the parameter of one piece of the exact distance to the other, sampled and refined by
/// golden section (exact up to rounding for circles and lines).
double pieceDistance(const Piece& a, const Piece& b);

/// Samples per piece when walking it against another curve: a line against a line, circle or
/// ellipse has at most one extremum between samples at this density; fields get more.
int walkSamples(const Piece& s, bool againstField, const QueryOptions& o);

} // namespace ictk::geometry::detail
