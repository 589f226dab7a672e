// SPDX-License-Identifier: BSD-3-Clause
// The pieces of CurvePieces.h: their carriers (the line, circle or ellipse a piece lies on, as a
// function that vanishes on it), nearest points and distances. Distances between pieces are
// exact for points and segments and, for circles, exact up to the rounding of a golden-section
// search on the exact point-circle distance.
#include "Geometry/CurvePieces.h"
#include "FRep/RootFinding.h"

#include <algorithm>
#include <vector>

namespace ictk::geometry::detail
{
namespace
{

bool segmentsCross(const Piece& a, const Piece& b)
{
  const double d1 = cross(a.q - a.p, b.p - a.p), d2 = cross(a.q - a.p, b.q - a.p);
  const double d3 = cross(b.q - b.p, a.p - b.p), d4 = cross(b.q - b.p, a.q - b.p);
  return ((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0));
}

} // namespace

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
  const std::function<double(double)>& f, double a, double b, double& tBest, double eps)
{
  frep::GoldenSectionOptions o;
  o.tolerance = eps;
  const frep::GoldenSection m = frep::goldenSection(f, a, b, o);
  tBest = m.x;
  return m.value;
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

} // namespace ictk::geometry::detail
