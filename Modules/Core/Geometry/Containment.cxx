// SPDX-License-Identifier: BSD-3-Clause
// Whether two placed shapes share a point (intersects()) and whether one holds the other
// (contains()).
//
// - Touching: intersects() is the distance of Distance.cxx (separation) <= tolerance, and a
// tangency point of
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
//   Tens of microseconds for small HyperFun fields (TestGeometry prints the figures).
#include "Geometry/Prepared.h"
#include "Geometry/Queries.h"

#include "FRep/Vector.h"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

namespace ictk::geometry
{
using namespace detail;

bool intersects(const PlacedShape& a, const PlacedShape& b, const QueryOptions& o)
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

bool contains(const PlacedShape& a, const PlacedShape& b, const QueryOptions& o)
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

} // namespace ictk::geometry
