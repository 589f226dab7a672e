// SPDX-License-Identifier: BSD-3-Clause
#include "Geometry/SpaceTimeWarp.h"

#include "Geometry/Prepared.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>

namespace ictk::geometry
{

namespace
{

/// Squared distance to the nearest zero of `f` along one line of n samples (unit spacing): the
/// lower envelope of the parabolas (q - p)^2 + f[p] (Felzenszwalb and Huttenlocher's separable
/// distance transform). `f` holds 0 at outside samples and a large number inside.
void squaredDistanceLine(std::vector<double>& f, std::size_t n, std::vector<double>& out,
  std::vector<std::size_t>& apex, std::vector<double>& from)
{
  auto meet = [&](std::size_t q, std::size_t p)
  {
    const double dq = static_cast<double>(q), dp = static_cast<double>(p);
    return ((f[q] + dq * dq) - (f[p] + dp * dp)) / (2 * dq - 2 * dp);
  };
  std::size_t k = 0;
  apex[0] = 0;
  from[0] = -std::numeric_limits<double>::infinity();
  from[1] = std::numeric_limits<double>::infinity();
  for (std::size_t q = 1; q < n; ++q)
  {
    double s = meet(q, apex[k]);
    while (s <= from[k])
    {
      --k;
      s = meet(q, apex[k]);
    }
    ++k;
    apex[k] = q;
    from[k] = s;
    from[k + 1] = std::numeric_limits<double>::infinity();
  }
  k = 0;
  for (std::size_t q = 0; q < n; ++q)
  {
    while (from[k + 1] < static_cast<double>(q))
      ++k;
    const double d = static_cast<double>(q) - static_cast<double>(apex[k]);
    out[q] = d * d + f[apex[k]];
  }
}

double distance(const Vec3& a, const Vec3& b)
{
  return std::sqrt(
    (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

} // namespace

std::vector<Vec3> thickFeatures(
  const PlacedShape& shape, int count, double separation, std::vector<double>* depths)
{
  if (count < 1)
    throw std::invalid_argument("thickFeatures: the number of points must be at least 1");
  if (!(separation >= 0) || !std::isfinite(separation))
    throw std::invalid_argument("thickFeatures: the separation must be a finite number >= 0");
  const detail::Prepared prepared(shape);
  if (!prepared.solid())
    detail::fail(shape, "a point or curve has no inside, so no thick features");
  const frep::Box3 box = shape.worldBounds();
  const int axes = prepared.flat ? 2 : 3;
  double longest = 0;
  for (int a = 0; a < axes; ++a)
    longest = std::max(longest, box.hi[a] - box.lo[a]);
  if (!(longest > 0) || !std::isfinite(longest))
    detail::fail(shape, "has no finite extent, so no thick features");
  const double h = longest / (axes == 2 ? 128 : 64);
  // One outside cell of padding on every side, so the EDT has outside cells to measure from.
  std::size_t n[3] = { 1, 1, 1 };
  double origin[3] = { 0, 0, 0 };
  for (int a = 0; a < axes; ++a)
  {
    n[a] = static_cast<std::size_t>(std::ceil((box.hi[a] - box.lo[a]) / h)) + 2;
    origin[a] = box.lo[a] - h;
  }
  const std::size_t total = n[0] * n[1] * n[2];
  auto centre = [&](std::size_t i, std::size_t j, std::size_t k)
  {
    return Vec3{ origin[0] + (static_cast<double>(i) + 0.5) * h,
      origin[1] + (static_cast<double>(j) + 0.5) * h,
      axes == 2 ? 0.0 : origin[2] + (static_cast<double>(k) + 0.5) * h };
  };
  const double far = 1e30;
  std::vector<double> d2(total, 0.0);
  for (std::size_t k = 0; k < n[2]; ++k)
    for (std::size_t j = 0; j < n[1]; ++j)
      for (std::size_t i = 0; i < n[0]; ++i)
      {
        const bool border = i == 0 || j == 0 || i + 1 == n[0] || j + 1 == n[1] ||
          (axes == 3 && (k == 0 || k + 1 == n[2]));
        if (!border && prepared.value(centre(i, j, k)) >= 0)
          d2[(k * n[1] + j) * n[0] + i] = far;
      }
  // The separable squared EDT, one axis at a time (in cells).
  const std::size_t longestLine = std::max({ n[0], n[1], n[2] });
  std::vector<double> line(longestLine), out(longestLine), from(longestLine + 1);
  std::vector<std::size_t> apex(longestLine);
  const std::size_t stride[3] = { 1, n[0], n[0] * n[1] };
  for (int a = 0; a < axes; ++a)
  {
    for (std::size_t start = 0; start < total; ++start)
    {
      // Visit each line once, from its first cell (coordinate 0 along axis a).
      if ((start / stride[a]) % n[a] != 0)
        continue;
      for (std::size_t q = 0; q < n[a]; ++q)
        line[q] = d2[start + q * stride[a]];
      squaredDistanceLine(line, n[a], out, apex, from);
      for (std::size_t q = 0; q < n[a]; ++q)
        d2[start + q * stride[a]] = out[q];
    }
  }
  // Local maxima (no neighbour larger), deepest first, ties in grid order.
  struct Candidate
  {
    double d2;
    std::size_t index;
  };
  std::vector<Candidate> candidates;
  const long reach = axes == 3 ? 1 : 0;
  for (std::size_t k = 0; k < n[2]; ++k)
    for (std::size_t j = 0; j < n[1]; ++j)
      for (std::size_t i = 0; i < n[0]; ++i)
      {
        const std::size_t index = (k * n[1] + j) * n[0] + i;
        const double v = d2[index];
        if (v <= 0)
          continue;
        bool maximum = true;
        for (long dk = -reach; dk <= reach && maximum; ++dk)
          for (long dj = -1; dj <= 1 && maximum; ++dj)
            for (long di = -1; di <= 1 && maximum; ++di)
            {
              // Inside cells are never on the border, so their neighbours exist.
              const std::size_t m = static_cast<std::size_t>(static_cast<long>(index) + di +
                dj * static_cast<long>(stride[1]) + dk * static_cast<long>(stride[2]));
              maximum = d2[m] <= v;
            }
        if (maximum)
          candidates.push_back({ v, index });
      }
  std::stable_sort(candidates.begin(), candidates.end(),
    [](const Candidate& x, const Candidate& y) { return x.d2 > y.d2; });
  std::vector<Vec3> points;
  if (depths)
    depths->clear();
  for (const Candidate& c : candidates)
  {
    if (static_cast<int>(points.size()) == count)
      break;
    const std::size_t i = c.index % n[0], j = (c.index / n[0]) % n[1], k = c.index / (n[0] * n[1]);
    const Vec3 p = centre(i, j, k);
    bool apart = true;
    for (const Vec3& q : points)
      apart = apart && distance(p, q) >= separation;
    if (!apart)
      continue;
    points.push_back(p);
    if (depths)
      depths->push_back(std::sqrt(c.d2) * h - 0.5 * h);
  }
  return points;
}

std::vector<ControlPair> pairControlPoints(
  const std::vector<Vec3>& sources, const std::vector<Vec3>& destinations)
{
  if (sources.size() > static_cast<std::size_t>(kMaxControlPoints) ||
    destinations.size() > static_cast<std::size_t>(kMaxControlPoints))
    throw std::invalid_argument("pairControlPoints: at most " + std::to_string(kMaxControlPoints) +
      " control points per shape");
  if (sources.empty() || destinations.empty())
    return {};
  const bool sourcesSmaller = sources.size() <= destinations.size();
  const std::vector<Vec3>& small = sourcesSmaller ? sources : destinations;
  const std::vector<Vec3>& large = sourcesSmaller ? destinations : sources;
  std::vector<std::size_t> order(large.size()), best;
  std::iota(order.begin(), order.end(), 0);
  double least = std::numeric_limits<double>::infinity();
  do
  {
    double cost = 0;
    for (std::size_t i = 0; i < small.size(); ++i)
      cost += distance(small[i], large[order[i]]);
    // Strictly less (by more than rounding): the first least assignment stays.
    if (cost < least * (1 - 1e-12))
    {
      least = cost;
      best = order;
    }
  } while (std::next_permutation(order.begin(), order.end()));
  std::vector<ControlPair> pairs;
  auto add = [&](const Vec3& s, const Vec3& l)
  {
    pairs.push_back(sourcesSmaller ? ControlPair{ s, l } : ControlPair{ l, s });
  };
  std::vector<bool> matched(large.size(), false);
  for (std::size_t i = 0; i < small.size(); ++i)
  {
    add(small[i], large[best[i]]);
    matched[best[i]] = true;
  }
  for (std::size_t l = 0; l < large.size(); ++l)
  {
    if (matched[l])
      continue;
    std::size_t nearest = 0;
    for (std::size_t i = 1; i < small.size(); ++i)
      if (distance(small[i], large[l]) < distance(small[nearest], large[l]))
        nearest = i;
    add(small[nearest], large[l]);
  }
  return pairs;
}

SpaceTimeWarp SpaceTimeWarp::at(const std::vector<ControlPair>& pairs, double u)
{
  SpaceTimeWarp w;
  for (const ControlPair& p : pairs)
  {
    Vec3 m, a, b;
    for (int k = 0; k < 3; ++k)
    {
      const double d = p.destination[k] - p.source[k];
      m[k] = p.source[k] + u * d;
      a[k] = -u * d;
      b[k] = (1 - u) * d;
    }
    w.nodes.push_back(m);
    w.shiftA.push_back(a);
    w.shiftB.push_back(b);
  }
  return w;
}

Vec3 SpaceTimeWarp::shift(const std::vector<Vec3>& shifts, const Vec3& p, double* jacobian) const
{
  if (jacobian)
    std::fill(jacobian, jacobian + 9, 0.0);
  Vec3 r{ 0, 0, 0 };
  // At a node the interpolation is the node's value (the mean of coincident nodes'), with a
  // zero derivative.
  int coincident = 0;
  for (std::size_t i = 0; i < nodes.size(); ++i)
  {
    const double r2 = (p[0] - nodes[i][0]) * (p[0] - nodes[i][0]) +
      (p[1] - nodes[i][1]) * (p[1] - nodes[i][1]) + (p[2] - nodes[i][2]) * (p[2] - nodes[i][2]);
    if (r2 < 1e-24)
    {
      for (int k = 0; k < 3; ++k)
        r[k] += shifts[i][k];
      ++coincident;
    }
  }
  if (coincident > 0)
  {
    for (int k = 0; k < 3; ++k)
      r[k] /= coincident;
    return r;
  }
  std::vector<double> w(nodes.size());
  double total = 0;
  for (std::size_t i = 0; i < nodes.size(); ++i)
  {
    const double r2 = (p[0] - nodes[i][0]) * (p[0] - nodes[i][0]) +
      (p[1] - nodes[i][1]) * (p[1] - nodes[i][1]) + (p[2] - nodes[i][2]) * (p[2] - nodes[i][2]);
    w[i] = 1 / r2;
    total += w[i];
    for (int k = 0; k < 3; ++k)
      r[k] += w[i] * shifts[i][k];
  }
  for (int k = 0; k < 3; ++k)
    r[k] /= total;
  if (jacobian)
  {
    // d/dp_c of sum w_i s_i / sum w_i = sum (dw_i/dp_c)(s_i - D) / sum w_i, with
    // dw_i/dp_c = -2 (p_c - m_ic) w_i^2.
    for (std::size_t i = 0; i < nodes.size(); ++i)
      for (int c = 0; c < 3; ++c)
      {
        const double dw = -2 * (p[c] - nodes[i][c]) * w[i] * w[i];
        for (int row = 0; row < 3; ++row)
          jacobian[3 * row + c] += dw * (shifts[i][row] - r[row]) / total;
      }
  }
  return r;
}

} // namespace ictk::geometry
