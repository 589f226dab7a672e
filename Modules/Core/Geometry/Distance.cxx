// SPDX-License-Identifier: BSD-3-Clause
// Distances between placed shapes (distance(), and the separation that intersects() compares
// with the tolerance), nearest points, and the local searches containment reuses.
//
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
#include "Geometry/Prepared.h"
#include "Geometry/Queries.h"

#include "FRep/Vector.h"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

namespace ictk::geometry
{
namespace detail
{
namespace
{

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

} // namespace

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

double lowestInside(
  const Prepared& a, const Prepared& b, Vec3& x, double step, double inB, double stop, double sign)
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

namespace
{

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

} // namespace

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

// Local refinement of what the boxes leave undecided. Interval enclosures cannot separate two
// boundaries that touch or nearly touch (the enclosures overlap at every box size), so the
// searches stop at a box size and the leaves they leave are decided by local optimisation from
// their centres: accurate to rounding at the optimum it converges to, but a local optimum, so
// only as good as the leaves' centres are as starting points (the few best are refined).

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

} // namespace detail

using namespace detail;

double distance(const PlacedShape& a, const PlacedShape& b, const QueryOptions& o)
{
  checkOptions(a, b, o);
  const Prepared pa(a), pb(b);
  return separation(pa, pb, 0.0);
}

} // namespace ictk::geometry
