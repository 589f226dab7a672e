// SPDX-License-Identifier: BSD-3-Clause
#include "FRep/RootFinding.h"

#include <cmath>
#include <stdexcept>
#include <vector>

namespace ictk::frep
{

namespace
{
bool opposite(double a, double b)
{
  return (a < 0.0 && b > 0.0) || (a > 0.0 && b < 0.0);
}
} // namespace

GoldenSection goldenSection(
  const std::function<double(double)>& f, double a, double b, const GoldenSectionOptions& o)
{
  auto key = [&](double v)
  {
    return o.magnitude ? std::abs(v) : v;
  };
  const double invPhi = (std::sqrt(5.0) - 1.0) / 2.0;
  double x1 = b - invPhi * (b - a), x2 = a + invPhi * (b - a);
  double f1 = f(x1), f2 = f(x2);
  GoldenSection r;
  r.evaluations = 2;
  for (int it = 0; it < o.maxIterations &&
       (b - a) > (o.relative ? o.tolerance * (1 + std::abs(a) + std::abs(b)) : o.tolerance);
       ++it)
  {
    if (o.stop)
    {
      if (o.stop(x1, f1))
        return { x1, f1, true, r.evaluations };
      if (o.stop(x2, f2))
        return { x2, f2, true, r.evaluations };
    }
    if (key(f1) <= key(f2))
    {
      b = x2;
      x2 = x1;
      f2 = f1;
      x1 = b - invPhi * (b - a);
      f1 = f(x1);
    }
    else
    {
      a = x1;
      x1 = x2;
      f1 = f2;
      x2 = a + invPhi * (b - a);
      f2 = f(x2);
    }
    ++r.evaluations;
  }
  const bool first = key(f1) <= key(f2);
  r.x = first ? x1 : x2;
  r.value = first ? f1 : f2;
  return r;
}

double refineRoot(const std::function<double(double)>& g, double a, double ga, double b, double gb,
  const LocateOptions& o, int* evaluations)
{
  if (ga == 0.0)
    return a;
  if (gb == 0.0)
    return b;
  if (!opposite(ga, gb))
    throw std::invalid_argument("refineRoot: g(a) and g(b) do not bracket a root");
  int side = 0; // which end was retained last: -1 a, +1 b
  double c = a;
  for (int it = 0; it < o.maxIterations && std::abs(b - a) > o.timeTolerance; ++it)
  {
    c = (a * gb - b * ga) / (gb - ga);
    const double lo = std::min(a, b), hi = std::max(a, b);
    // Near the root the secant points approach it from one side, so the bracket's far end only
    // moves by the halvings of its value. A point within half the tolerance of an end is put
    // half the tolerance inside instead: when the secant point is that close to the root, the
    // next evaluation is on the root's other side and closes the bracket (on a ray of the ray
    // caster, 3 evaluations for a pixel-wide bracket refined a thousandfold, against 4 to 7).
    const double h = 0.5 * o.timeTolerance;
    if (c - lo < h)
      c = lo + h;
    else if (hi - c < h)
      c = hi - h;
    if (!(c > lo && c < hi))
      c = 0.5 * (a + b); // rounding pushed the secant point out: bisect
    const double gc = g(c);
    if (evaluations)
      ++*evaluations;
    if (gc == 0.0 || std::abs(gc) <= o.valueTolerance)
      return c;
    if (opposite(ga, gc))
    {
      b = c;
      gb = gc;
      if (side == -1)
        ga *= 0.5;
      side = -1;
    }
    else
    {
      a = c;
      ga = gc;
      if (side == +1)
        gb *= 0.5;
      side = +1;
    }
  }
  // The bracket is below tolerance: return its end with the smaller |g| estimate.
  return std::abs(ga) <= std::abs(gb) ? a : b;
}

std::optional<Crossing> locateCrossing(
  const std::function<double(double)>& g, double t0, double t1, const LocateOptions& o)
{
  if (!(t1 > t0))
    return std::nullopt;
  const int n = std::max(o.samples, 2);
  int evals = 0;
  std::vector<double> s(n + 1), v(n + 1);
  for (int i = 0; i <= n; ++i)
  {
    s[i] = i == n ? t1 : t0 + (t1 - t0) * i / n;
    v[i] = g(s[i]);
    ++evals;
  }
  auto signChange = [&](double a, double ga, double b, double gb)
  {
    Crossing c;
    c.kind = Crossing::Kind::SignChange;
    c.time = refineRoot(g, a, ga, b, gb, o, &evals);
    c.value = g(c.time);
    c.evaluations = ++evals;
    return c;
  };
  // Starting on a zero (|g(t0)| <= touchTolerance): that event belongs to the previous step; its
  // rounding residual must not be reported again as a crossing right after t0.
  if (std::abs(v[0]) <= o.touchTolerance)
    v[0] = 0.0;
  for (int i = 0; i < n; ++i)
  {
    // An exact zero at an interior sample is a crossing or a touch at that sample.
    if (i + 1 < n && v[i + 1] == 0.0)
    {
      Crossing c;
      c.kind = opposite(v[i], v[i + 2]) ? Crossing::Kind::SignChange : Crossing::Kind::Touch;
      c.time = s[i + 1];
      c.evaluations = evals;
      return c;
    }
    if (opposite(v[i], v[i + 1]) || (v[i + 1] == 0.0 && v[i] != 0.0 && i + 1 == n))
      return signChange(s[i], v[i], s[i + 1], v[i + 1]);
    // Touch candidate: an interior local minimum of |g| at s[i+1].
    if (i + 1 < n && std::abs(v[i + 1]) <= std::abs(v[i]) &&
      std::abs(v[i + 1]) <= std::abs(v[i + 2]) && !opposite(v[i + 1], v[i + 2]))
    {
      // Golden-section search for min |g| on [s_i, s_i+2]; a value of the other sign on the
      // way is a bracket.
      GoldenSectionOptions golden;
      golden.maxIterations = o.maxIterations;
      golden.tolerance = o.timeTolerance;
      golden.relative = false;
      golden.magnitude = true;
      golden.stop = [&](double, double gx)
      {
        return opposite(gx, v[i]);
      };
      const GoldenSection m = goldenSection(g, s[i], s[i + 2], golden);
      evals += m.evaluations;
      if (m.stopped)
        return signChange(s[i], v[i], m.x, m.value);
      double tm = m.x;
      double gm = m.value;
      // Near a tangency g ~ c (t - t*)^2 is flat below rounding within ~sqrt(eps) of t*, so the
      // golden section stops anywhere on that plateau. A parabola through g at tm - h, tm, tm + h
      // with h well above the plateau puts the vertex back on t* (exact for a quadratic g).
      const double h = 1e-4 * (s[i + 2] - s[i]);
      const double gl = g(tm - h), gr = g(tm + h);
      evals += 2;
      const double curvature = gl - 2.0 * gm + gr;
      if (curvature != 0.0 && !opposite(gl, gm) && !opposite(gr, gm))
      {
        const double tv = tm - 0.5 * h * (gr - gl) / curvature;
        if (std::abs(tv - tm) < h)
        {
          const double gv = g(tv);
          ++evals;
          if (opposite(gv, v[i]))
            return signChange(s[i], v[i], tv, gv);
          if (std::abs(gv) <= std::abs(gm) + o.touchTolerance)
          {
            tm = tv;
            gm = gv;
          }
        }
      }
      if (std::abs(gm) <= o.touchTolerance)
      {
        Crossing c;
        c.kind = Crossing::Kind::Touch;
        c.time = tm;
        c.value = gm;
        c.evaluations = evals;
        return c;
      }
    }
  }
  if (v[n] != 0.0 && std::abs(v[n]) <= o.touchTolerance)
  {
    Crossing c;
    c.kind = Crossing::Kind::Touch;
    c.time = t1;
    c.value = v[n];
    c.evaluations = evals;
    return c;
  }
  return std::nullopt;
}

} // namespace ictk::frep
