// SPDX-License-Identifier: BSD-3-Clause
// The points where the boundaries of two shapes in the plane meet (intersectionPoints()).
//
// - Meeting points in the plane: a piece is walked against the other's carrier (the line or
//   circle a piece lies on, or a 2D field); sign changes are refined by the Illinois method,
//   and an extremum of the carrier along the walk that comes within the tolerance of 0
//   (|g| / |grad g| <= tolerance, a first-order distance) is a tangency: one point, however the
//   two crossings around it fall. Consecutive samples within the tolerance are one point, and
//   points closer than the tolerance (a polygon's corner found from both edges) merge; for
//   two fields, whose boundary is traced by marching squares (128 cells over the common box)
//   and walked projected onto the first field's curve, the merge distance is 1e-6 of the size.
// The roots are refined by FRep/RootFinding.h's refineRoot, the same Illinois method that
// locates transitions in time.
#include "Geometry/Prepared.h"
#include "Geometry/Queries.h"

#include "FRep/RootFinding.h"
#include "FRep/Vector.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

namespace ictk::geometry
{
using namespace detail;

namespace
{

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
    frep::LocateOptions o;
    o.timeTolerance = 4e-16 * std::max(1.0, std::abs(a));
    return frep::refineRoot(valueAt, a, fa, b, fb, o);
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

} // namespace

std::vector<Vec3> intersectionPoints(
  const PlacedShape& a, const PlacedShape& b, const QueryOptions& o)
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

} // namespace ictk::geometry
