// SPDX-License-Identifier: BSD-3-Clause
#include "Discretize/Points.h"

#include "Discretize/CellDetail.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>

namespace ictk::discretize
{

using namespace detail;

namespace
{

using Index3 = std::array<std::int64_t, 3>;

bool mayVanish(const frep::Interval& i)
{
  return !i.empty() && i.lo <= 0 && i.hi >= 0;
}

void checkNewton(double tolerance, int maxIterations, const char* what)
{
  if (!(tolerance > 0) || !std::isfinite(tolerance) || maxIterations < 1 || maxIterations > 10000)
  {
    throw std::invalid_argument(
      std::string(what) + ": tolerance must be positive, maxIterations in [1, 10000]");
  }
}

} // namespace

PointSet solvePoints(const frep::Field& g1, const frep::Field& g2, const frep::Field& g3,
  const Box3& box, const PointOptions& options)
{
  const char* what = "solvePoints";
  checkBox(box, 0u, what);
  checkNewton(options.tolerance, options.maxIterations, what);
  const double diagonal = distance(box.lo, box.hi);
  if (!(options.size >= 0) || !std::isfinite(options.size) || !(options.mergeDistance >= 0) ||
    !std::isfinite(options.mergeDistance) || !(options.maxBoxes >= 1))
  {
    throw std::invalid_argument(
      "solvePoints: size and mergeDistance must be finite and >= 0, maxBoxes >= 1");
  }
  const double size = options.size > 0 ? options.size : diagonal / 64;
  const double merge = options.mergeDistance > 0
    ? options.mergeDistance
    : std::max(1e-7 * diagonal, 100 * options.tolerance);
  Index3 cells;
  std::array<double, 3> cellSize;
  for (int a = 0; a < 3; ++a)
  {
    const double n = std::max(1.0, std::ceil((box.hi[a] - box.lo[a]) / size));
    if (!(n <= double(1 << 20)))
    {
      throw std::invalid_argument(
        "solvePoints: absurd resolution (more than 2^20 boxes along an axis); raise size");
    }
    cells[a] = static_cast<std::int64_t>(n);
    cellSize[a] = (box.hi[a] - box.lo[a]) / n;
  }
  auto boxOf = [&](const Index3& lo, const Index3& hi)
  {
    Box3 b;
    for (int a = 0; a < 3; ++a)
    {
      b.lo[a] = box.lo[a] + double(lo[a]) * cellSize[a];
      b.hi[a] = hi[a] >= cells[a] ? box.hi[a] : box.lo[a] + double(hi[a]) * cellSize[a];
    }
    return b;
  };

  // Candidate leaves, depth first.
  std::vector<Index3> leaves;
  {
    auto e1 = g1.evaluator(), e2 = g2.evaluator(), e3 = g3.evaluator();
    struct Node
    {
      Index3 lo, hi;
    };
    std::vector<Node> stack{ { { 0, 0, 0 }, cells } };
    while (!stack.empty())
    {
      const Node n = stack.back();
      stack.pop_back();
      const Box3 b = boxOf(n.lo, n.hi);
      if (!mayVanish(e1->bound(b)) || !mayVanish(e2->bound(b)) || !mayVanish(e3->bound(b)))
      {
        continue;
      }
      int axis = -1;
      std::int64_t widest = 1;
      for (int a = 0; a < 3; ++a)
      {
        if (n.hi[a] - n.lo[a] > widest)
        {
          widest = n.hi[a] - n.lo[a];
          axis = a;
        }
      }
      if (axis < 0)
      {
        leaves.push_back(n.lo);
        if (double(leaves.size()) > options.maxBoxes)
        {
          throw std::invalid_argument("solvePoints: more than maxBoxes candidate boxes; the "
                                      "fields may vanish on a curve or a surface");
        }
        continue;
      }
      const std::int64_t mid = n.lo[axis] + (n.hi[axis] - n.lo[axis]) / 2;
      Node a = n, c = n;
      a.hi[axis] = mid;
      c.lo[axis] = mid;
      stack.push_back(c);
      stack.push_back(a);
    }
  }

  std::vector<std::optional<Point3>> found(leaves.size());
  forChunks(leaves.size(), 16, options.threads,
    [&](std::size_t b, std::size_t e)
    {
      auto e1 = g1.evaluator(), e2 = g2.evaluator(), e3 = g3.evaluator();
      const Constraint cs[3] = { Constraint::of(*e1), Constraint::of(*e2), Constraint::of(*e3) };
      for (std::size_t i = b; i < e; ++i)
      {
        const Index3& c = leaves[i];
        const Box3 cell = boxOf(c, { c[0] + 1, c[1] + 1, c[2] + 1 });
        const double reach = distance(cell.lo, cell.hi);
        for (int start = -1; start < 8 && !found[i]; ++start)
        {
          Point3 p = cell.centre();
          if (start >= 0)
          {
            for (int a = 0; a < 3; ++a)
            {
              p[a] = (start >> a) & 1 ? 0.25 * cell.lo[a] + 0.75 * cell.hi[a]
                                      : 0.75 * cell.lo[a] + 0.25 * cell.hi[a];
            }
          }
          NewtonSettings s;
          s.tolerance = options.tolerance;
          s.maxIterations = options.maxIterations;
          s.maxStep = reach;
          s.maxDistance = reach;
          if (!projectOnto(cs, 3, p, s))
          {
            continue;
          }
          bool inside = true;
          for (int a = 0; a < 3; ++a)
          {
            const double m = 0.05 * (cell.hi[a] - cell.lo[a]);
            inside = inside && p[a] >= std::max(cell.lo[a] - m, box.lo[a]) &&
              p[a] <= std::min(cell.hi[a] + m, box.hi[a]);
          }
          if (inside)
          {
            found[i] = p;
          }
        }
      }
    });

  std::vector<Point3> roots;
  for (const auto& p : found)
  {
    if (p)
    {
      roots.push_back(*p);
    }
  }
  std::sort(roots.begin(), roots.end());
  PointSet out;
  for (const Point3& p : roots)
  {
    bool duplicate = false;
    for (auto it = out.points.rbegin(); it != out.points.rend() && !duplicate; ++it)
    {
      if (p[0] - (*it)[0] > merge)
      {
        break;
      }
      duplicate = distance(p, *it) <= merge;
    }
    if (!duplicate)
    {
      out.points.push_back(p);
    }
  }
  PointArray sine;
  sine.name = "sine";
  auto e1 = g1.evaluator(), e2 = g2.evaluator(), e3 = g3.evaluator();
  for (const Point3& p : out.points)
  {
    Point3 a, b, c;
    e1->gradient(p, a);
    e2->gradient(p, b);
    e3->gradient(p, c);
    const double scale = norm(a) * norm(b) * norm(c);
    sine.values.push_back(scale > 0 ? std::abs(dot(a, cross(b, c))) / scale : 0.0);
  }
  out.pointData.push_back(std::move(sine));
  return out;
}

PointSet curveCrossings(
  const CurveSet& curves, const frep::Field& g, const CrossingOptions& options)
{
  checkFields(options.carriers, "curveCrossings");
  checkNewton(options.tolerance, options.maxIterations, "curveCrossings");
  if (options.carriers.size() > 2)
  {
    throw std::invalid_argument("curveCrossings: at most 2 carriers");
  }
  for (const auto& line : curves.lines)
  {
    for (auto v : line)
    {
      if (v >= curves.points.size())
      {
        throw std::invalid_argument("curveCrossings: a polyline refers to a missing point");
      }
    }
  }
  std::vector<double> value;
  evaluateAt(g, curves.points, value, 0);
  auto ev = g.evaluator();
  auto carriers = evaluatorsOf(options.carriers);
  PointSet out;
  PointArray lineIds{ "line", 1, {} }, segmentIds{ "segment", 1, {} };
  for (std::size_t l = 0; l < curves.lines.size(); ++l)
  {
    const auto& line = curves.lines[l];
    for (std::size_t s = 0; s + 1 < line.size(); ++s)
    {
      const std::uint32_t ia = line[s], ib = line[s + 1];
      const bool inA = value[ia] >= 0, inB = value[ib] >= 0;
      if (inA == inB)
      {
        continue;
      }
      const Point3 A = curves.points[ia], B = curves.points[ib];
      double ta = 0, tb = 1; // g(A + ta (B - A)) on A's side
      for (int it = 0; it < 64 && tb - ta > 1e-15; ++it)
      {
        const double tm = 0.5 * (ta + tb);
        if ((ev->value(lerp(A, B, tm)) >= 0) == inA)
        {
          ta = tm;
        }
        else
        {
          tb = tm;
        }
      }
      Point3 p = lerp(A, B, 0.5 * (ta + tb));
      if (!carriers.empty())
      {
        Constraint cs[3];
        int n = 0;
        for (auto& c : carriers)
        {
          cs[n++] = Constraint::of(*c);
        }
        cs[n++] = Constraint::of(*ev);
        NewtonSettings ns;
        ns.tolerance = options.tolerance;
        ns.maxIterations = options.maxIterations;
        const double len = distance(A, B);
        ns.maxStep = len;
        ns.maxDistance = len;
        Point3 q = p;
        if (projectOnto(cs, n, q, ns))
        {
          p = q;
        }
      }
      out.points.push_back(p);
      lineIds.values.push_back(static_cast<double>(l));
      segmentIds.values.push_back(static_cast<double>(s));
    }
  }
  out.pointData.push_back(std::move(lineIds));
  out.pointData.push_back(std::move(segmentIds));
  return out;
}

} // namespace ictk::discretize
