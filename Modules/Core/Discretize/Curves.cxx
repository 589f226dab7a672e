// SPDX-License-Identifier: BSD-3-Clause
#include "Discretize/Curves.h"

#include "Discretize/CellDetail.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <sstream>
#include <unordered_map>
#include <unordered_set>

namespace ictk::discretize
{

using namespace detail;

namespace
{

using Index3 = std::array<std::int64_t, 3>;

/// The evaluators one thread needs.
struct Evaluators
{
  std::unique_ptr<frep::FieldEvaluator> g1, g2; // g2 null: the plane z = 0
  std::vector<std::unique_ptr<frep::FieldEvaluator>> trims;
};

/// Segments of the traced curves, hashed on a grid, for "is this point on a traced curve".
class SegmentIndex
{
public:
  explicit SegmentIndex(double cell)
    : cell_(cell)
  {
  }
  void add(const Point3& a, const Point3& b)
  {
    const std::size_t id = segments_.size();
    segments_.push_back({ a, b });
    Index3 lo, hi;
    for (int k = 0; k < 3; ++k)
    {
      lo[k] = cellOf(std::min(a[k], b[k]));
      hi[k] = cellOf(std::max(a[k], b[k]));
    }
    for (auto i = lo[0]; i <= hi[0]; ++i)
      for (auto j = lo[1]; j <= hi[1]; ++j)
        for (auto k = lo[2]; k <= hi[2]; ++k)
        {
          cells_[key({ i, j, k })].push_back(id);
        }
  }
  /// Whether some segment passes within r (<= cell) of p.
  bool near(const Point3& p, double r) const
  {
    Index3 c;
    for (int k = 0; k < 3; ++k)
    {
      c[k] = cellOf(p[k]);
    }
    for (int i = -1; i <= 1; ++i)
      for (int j = -1; j <= 1; ++j)
        for (int k = -1; k <= 1; ++k)
        {
          const auto it = cells_.find(key({ c[0] + i, c[1] + j, c[2] + k }));
          if (it == cells_.end())
          {
            continue;
          }
          for (const std::size_t s : it->second)
          {
            if (pointSegmentDistance(p, segments_[s][0], segments_[s][1]) <= r)
            {
              return true;
            }
          }
        }
    return false;
  }

private:
  std::int64_t cellOf(double v) const { return static_cast<std::int64_t>(std::floor(v / cell_)); }
  static std::uint64_t key(const Index3& c)
  {
    const auto u = [](std::int64_t v)
    {
      return static_cast<std::uint64_t>(v) & 0x1fffffu;
    };
    return u(c[0]) | (u(c[1]) << 21) | (u(c[2]) << 42);
  }
  double cell_;
  std::vector<std::array<Point3, 2>> segments_;
  std::unordered_map<std::uint64_t, std::vector<std::size_t>> cells_;
};

class Tracer
{
public:
  Tracer(const frep::Field& g1, const frep::Field* g2, const std::vector<frep::FieldPtr>& trims,
    const Box3& box, const CurveOptions& o, const char* what)
    : g1_(g1)
    , g2_(g2)
    , trims_(trims)
    , box_(box)
    , o_(o)
    , what_(what)
  {
    const bool flat = g2 == nullptr;
    checkFields(trims, what);
    checkBox(box, flat ? 4u : 0u, what);
    if (!(o.step > 0) || !std::isfinite(o.step))
    {
      throw std::invalid_argument(std::string(what) + ": step must be positive and finite");
    }
    if (!(o.seedSize >= 0) || !std::isfinite(o.seedSize))
    {
      throw std::invalid_argument(std::string(what) + ": seedSize must be >= 0 and finite");
    }
    if (!(o.maxTurn > 0 && o.maxTurn < 1.5))
    {
      throw std::invalid_argument(std::string(what) + ": maxTurn must lie in (0, 1.5) radians");
    }
    if (!(o.tolerance > 0) || !std::isfinite(o.tolerance) || o.maxIterations < 1 ||
      o.maxIterations > 10000)
    {
      throw std::invalid_argument(
        std::string(what) + ": tolerance must be positive, maxIterations in [1, 10000]");
    }
    if (!(o.maxPoints >= 2) || !(o.maxSeedBoxes >= 1) || !(o.degenerateSine >= 0) ||
      !std::isfinite(o.degenerateSine))
    {
      throw std::invalid_argument(
        std::string(what) + ": maxPoints >= 2, maxSeedBoxes >= 1, degenerateSine >= 0 needed");
    }
    if (flat)
    {
      box_.lo[2] = box_.hi[2] = 0.0;
    }
    seedSize_ = o.seedSize > 0 ? o.seedSize : o.step;
    for (int a = 0; a < 3; ++a)
    {
      const double extent = box_.hi[a] - box_.lo[a];
      const double n = flat && a == 2 ? 1.0 : std::max(1.0, std::ceil(extent / seedSize_));
      if (!(n <= double(1 << 20)))
      {
        throw std::invalid_argument(std::string(what) +
          ": absurd resolution (more than 2^20 seed boxes along an axis); raise step/seedSize");
      }
      cells_[a] = static_cast<std::int64_t>(n);
      cellSize_[a] = extent / n;
    }
    degenerateSine_ = o.degenerateSine > 0 ? o.degenerateSine
                                           : std::sqrt(o.tolerance / std::min(o.step, seedSize_));
    dedup_ = std::max(0.25 * std::min(o.step, seedSize_), 100 * o.tolerance);
    slack_ = std::max(1e3 * o.tolerance, 1e-12 * diagonal());
    main_ = makeEvaluators();
  }

  CurveSet run()
  {
    const std::vector<Index3> candidates = candidateBoxes();
    std::vector<std::optional<Point3>> seeds(candidates.size());
    forChunks(candidates.size(), 16, o_.threads,
      [&](std::size_t b, std::size_t e)
      {
        Evaluators ev = makeEvaluators();
        for (std::size_t i = b; i < e; ++i)
        {
          seeds[i] = findSeed(ev, candidates[i]);
        }
      });

    CurveSet out;
    SegmentIndex index(std::max(o_.step, seedSize_));
    std::unordered_set<std::uint64_t> visited;
    for (std::size_t i = 0; i < candidates.size(); ++i)
    {
      if (!seeds[i] || visited.count(cellKey(candidates[i])))
      {
        continue;
      }
      const Point3 seed = *seeds[i];
      if (!insideTrims(main_, seed) || index.near(seed, dedup_))
      {
        continue;
      }
      Point3 t;
      const double sine = tangent(main_, seed, t);
      if (!(sine >= degenerateSine_))
      {
        std::ostringstream msg;
        msg << what_ << ": the carriers are tangent (sine of their angle " << sine << ") at ("
            << seed[0] << ", " << seed[1] << ", " << seed[2]
            << "): their common zero set is not a regular curve there";
        throw DegenerateCurve(msg.str());
      }
      std::vector<Point3> line = traceFrom(seed, t, out.points.size());
      if (line.size() < 2)
      {
        continue;
      }
      const bool closed = closed_;
      std::vector<std::uint32_t> ids;
      const auto first = static_cast<std::uint32_t>(out.points.size());
      for (std::size_t k = 0; k < line.size(); ++k)
      {
        ids.push_back(static_cast<std::uint32_t>(out.points.size()));
        out.points.push_back(line[k]);
        if (k > 0)
        {
          index.add(line[k - 1], line[k]);
          markVisited(visited, line[k - 1], line[k]);
        }
      }
      if (closed)
      {
        ids.push_back(first);
        index.add(line.back(), line.front());
        markVisited(visited, line.back(), line.front());
      }
      out.lines.push_back(std::move(ids));
    }
    return out;
  }

private:
  double diagonal() const { return distance(box_.lo, box_.hi); }

  Evaluators makeEvaluators() const
  {
    Evaluators e;
    e.g1 = g1_.evaluator();
    if (g2_)
    {
      e.g2 = g2_->evaluator();
    }
    e.trims = evaluatorsOf(trims_);
    return e;
  }

  int carriers(Evaluators& ev, Constraint* cs) const
  {
    cs[0] = Constraint::of(*ev.g1);
    cs[1] = ev.g2 ? Constraint::of(*ev.g2) : Constraint::plane(2, 0.0);
    return 2;
  }

  /// sin of the angle between the carriers' normals; t = the unit tangent.
  double tangent(Evaluators& ev, const Point3& p, Point3& t) const
  {
    Point3 a, b{ 0, 0, 1 };
    ev.g1->gradient(p, a);
    if (ev.g2)
    {
      ev.g2->gradient(p, b);
    }
    const Point3 c = cross(a, b);
    const double na = norm(a), nb = norm(b), nc = norm(c);
    if (!(na > 0) || !(nb > 0) || !std::isfinite(nc) || !(nc > 0))
    {
      t = { 0, 0, 0 };
      return 0.0;
    }
    t = scale(c, 1.0 / nc);
    return nc / (na * nb);
  }

  bool correct(Evaluators& ev, Point3& p, double maxMove, const Constraint* extra = nullptr) const
  {
    Constraint cs[3];
    int n = carriers(ev, cs);
    if (extra)
    {
      cs[n++] = *extra;
    }
    NewtonSettings s;
    s.tolerance = o_.tolerance;
    s.maxIterations = o_.maxIterations;
    s.maxStep = maxMove;
    s.maxDistance = maxMove;
    return projectOnto(cs, n, p, s);
  }

  bool insideBox(const Point3& p) const
  {
    for (int a = 0; a < 3; ++a)
    {
      if (!(p[a] >= box_.lo[a] - slack_ && p[a] <= box_.hi[a] + slack_))
      {
        return false;
      }
    }
    return true;
  }

  bool insideTrims(Evaluators& ev, const Point3& p) const
  {
    for (auto& h : ev.trims)
    {
      Point3 g;
      const double v = h->gradient(p, g);
      if (!(v >= -1e2 * o_.tolerance * std::max(1.0, norm(g))))
      {
        return false;
      }
    }
    return true;
  }

  Index3 cellOf(const Point3& p) const
  {
    Index3 c;
    for (int a = 0; a < 3; ++a)
    {
      const double f = cellSize_[a] > 0 ? (p[a] - box_.lo[a]) / cellSize_[a] : 0.0;
      c[a] = std::clamp<std::int64_t>(static_cast<std::int64_t>(std::floor(f)), 0, cells_[a] - 1);
    }
    return c;
  }
  static std::uint64_t cellKey(const Index3& c)
  {
    return static_cast<std::uint64_t>(c[0]) | (static_cast<std::uint64_t>(c[1]) << 21) |
      (static_cast<std::uint64_t>(c[2]) << 42);
  }
  void markVisited(std::unordered_set<std::uint64_t>& visited, const Point3& a, const Point3& b)
  {
    double minCell = std::min(cellSize_[0], cellSize_[1]);
    if (cellSize_[2] > 0)
    {
      minCell = std::min(minCell, cellSize_[2]);
    }
    const int samples = 1 + static_cast<int>(std::min(1e4, 4.0 * distance(a, b) / minCell));
    for (int s = 0; s <= samples; ++s)
    {
      visited.insert(cellKey(cellOf(lerp(a, b, double(s) / samples))));
    }
  }

  Box3 boxOf(const Index3& lo, const Index3& hi) const
  {
    Box3 b;
    for (int a = 0; a < 3; ++a)
    {
      b.lo[a] = box_.lo[a] + double(lo[a]) * cellSize_[a];
      b.hi[a] = hi[a] >= cells_[a] ? box_.hi[a] : box_.lo[a] + double(hi[a]) * cellSize_[a];
    }
    return b;
  }

  static bool mayVanish(const frep::Interval& i)
  {
    return !i.empty() && i.lo <= 0 && i.hi >= 0; // [lo, hi] bounds the non-NaN values
  }

  /// The seed boxes (leaf cells) where both carriers may vanish and no trim is surely < 0, in
  /// depth-first order of a binary subdivision of the cell ranges.
  std::vector<Index3> candidateBoxes()
  {
    struct Node
    {
      Index3 lo, hi;
    };
    std::vector<Index3> leaves;
    std::vector<Node> stack{ { { 0, 0, 0 }, cells_ } };
    while (!stack.empty())
    {
      const Node n = stack.back();
      stack.pop_back();
      const Box3 b = boxOf(n.lo, n.hi);
      if (!mayVanish(main_.g1->bound(b)) || (main_.g2 && !mayVanish(main_.g2->bound(b))))
      {
        continue;
      }
      bool trimmedAway = false;
      for (auto& h : main_.trims)
      {
        const frep::Interval i = h->bound(b);
        trimmedAway = trimmedAway || (!i.maybeNaN && i.hi < 0);
      }
      if (trimmedAway)
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
        if (double(leaves.size()) > o_.maxSeedBoxes)
        {
          throw std::invalid_argument(std::string(what_) +
            ": more than maxSeedBoxes candidate seed boxes; the carriers may vanish on a "
            "surface (coincident or -(G)^2 carriers) or the step is too small");
        }
        continue;
      }
      const std::int64_t mid = n.lo[axis] + (n.hi[axis] - n.lo[axis]) / 2;
      Node a = n, c = n;
      a.hi[axis] = mid;
      c.lo[axis] = mid;
      stack.push_back(c); // visited second
      stack.push_back(a);
    }
    return leaves;
  }

  std::optional<Point3> findSeed(Evaluators& ev, const Index3& cell) const
  {
    const Box3 b = boxOf(cell, { cell[0] + 1, cell[1] + 1, cell[2] + 1 });
    const double diag = distance(b.lo, b.hi);
    const double reach = std::max(diag, o_.step);
    auto inCell = [&](const Point3& p)
    {
      for (int a = 0; a < 3; ++a)
      {
        const double m = 0.05 * (b.hi[a] - b.lo[a]) + slack_;
        if (!(p[a] >= b.lo[a] - m && p[a] <= b.hi[a] + m))
        {
          return false;
        }
      }
      return insideBox(p);
    };
    for (int start = -1; start < 8; ++start)
    {
      Point3 p = b.centre();
      if (start >= 0)
      {
        for (int a = 0; a < 3; ++a)
        {
          p[a] =
            (start >> a) & 1 ? 0.25 * b.lo[a] + 0.75 * b.hi[a] : 0.75 * b.lo[a] + 0.25 * b.hi[a];
        }
      }
      if (correct(ev, p, reach) && inCell(p))
      {
        return p;
      }
    }
    return std::nullopt;
  }

  /// The exact point where the curve leaves the trims or the box between p (inside) and q (on
  /// the curve, outside), or nullopt when q is inside.
  std::optional<Point3> exitPoint(const Point3& p, const Point3& q, const Point3& tp)
  {
    // The earliest violated condition along the chord p -> q.
    double best = 2.0;
    Constraint limit;
    bool found = false;
    for (std::size_t k = 0; k < main_.trims.size(); ++k)
    {
      const double hq = main_.trims[k]->value(q);
      if (hq >= 0)
      {
        continue;
      }
      const double hp = main_.trims[k]->value(p);
      const double s = std::isnan(hq) ? 0.5 : std::clamp(hp / (hp - hq), 0.0, 1.0);
      if (s < best)
      {
        best = s;
        limit = Constraint::of(*main_.trims[k]);
        found = true;
      }
    }
    for (int a = 0; a < 3; ++a)
    {
      if (box_.hi[a] == box_.lo[a])
      {
        continue;
      }
      for (const double bound : { box_.lo[a], box_.hi[a] })
      {
        const bool out = bound == box_.lo[a] ? q[a] < bound : q[a] > bound;
        if (!out)
        {
          continue;
        }
        const double s = std::clamp((bound - p[a]) / (q[a] - p[a]), 0.0, 1.0);
        if (s < best)
        {
          best = s;
          limit = Constraint::plane(a, bound);
          found = true;
        }
      }
    }
    if (!found)
    {
      return std::nullopt;
    }
    const double d = distance(p, q);
    Point3 x = lerp(p, q, best);
    if (correct(main_, x, d, &limit) && distance(x, p) <= 1.5 * d && insideBox(x) &&
      insideTrims(main_, x))
    {
      return x;
    }
    // Fallback: bisection on the arc length along the tangent at p.
    double lo = 0, hi = d;
    Point3 good = p;
    for (int it = 0; it < 60 && hi - lo > o_.tolerance; ++it)
    {
      const double mid = 0.5 * (lo + hi);
      Point3 y = add(p, scale(tp, mid));
      if (correct(main_, y, d) && insideBox(y) && insideTrims(main_, y))
      {
        lo = mid;
        good = y;
      }
      else
      {
        hi = mid;
      }
    }
    return good;
  }

  /// Traces from the seed in direction `sign` (+1/-1) until the curve closes (allowClose), stops
  /// at the trims or the box, or meets a singular point.
  std::vector<Point3> traceDirection(
    const Point3& seed, const Point3& seedTangent, double sign, bool allowClose, std::size_t used)
  {
    std::vector<Point3> pts{ seed };
    Point3 p = seed;
    Point3 tp = scale(seedTangent, sign);
    double h = o_.step;
    const double hMin = o_.step * 1e-6;
    const double cosTurn = std::cos(o_.maxTurn);
    for (;;)
    {
      if (double(used + pts.size()) > o_.maxPoints)
      {
        throw std::runtime_error(
          std::string(what_) + ": more than maxPoints points; raise step or maxPoints");
      }
      Point3 q, tq;
      bool accepted = false;
      while (!accepted)
      {
        if (h < hMin)
        {
          return pts; // singular point or a corrector that cannot follow: end here
        }
        q = add(p, scale(tp, h));
        if (!correct(main_, q, h))
        {
          h *= 0.5;
          continue;
        }
        const Point3 chord = sub(q, p);
        const double d = norm(chord);
        const double sine = tangent(main_, q, tq);
        tq = scale(tq, sign);
        if (!(d >= 0.25 * h && d <= std::min(1.5 * h, o_.step)) || !(sine >= degenerateSine_) ||
          dot(tq, tp) < cosTurn || dot(chord, tp) < cosTurn * d)
        {
          h *= 0.5;
          continue;
        }
        accepted = true;
      }
      if (allowClose && pts.size() >= 3)
      {
        // Back at the seed: it lies on this step's chord (within the chord's sag).
        const Point3 chord = sub(q, p);
        const double d2 = dot(chord, chord);
        const double s = d2 > 0 ? dot(sub(seed, p), chord) / d2 : -1.0;
        if (s >= 0 && s <= 1 && pointSegmentDistance(seed, p, q) <= 0.1 * std::sqrt(d2) + slack_ &&
          dot(tp, seedTangent) * sign > 0)
        {
          closed_ = true;
          if (s * std::sqrt(d2) < 0.2 * o_.step && pts.size() > 3 &&
            distance(pts[pts.size() - 2], seed) <= o_.step)
          {
            pts.pop_back();
          }
          return pts;
        }
      }
      if (const auto exit = exitPoint(p, q, tp))
      {
        if (distance(*exit, p) > slack_)
        {
          pts.push_back(*exit);
        }
        return pts;
      }
      pts.push_back(q);
      p = q;
      tp = tq;
      h = std::min(o_.step, 1.5 * h);
    }
  }

  std::vector<Point3> traceFrom(const Point3& seed, const Point3& t, std::size_t used)
  {
    closed_ = false;
    std::vector<Point3> forward = traceDirection(seed, t, 1.0, true, used);
    if (closed_)
    {
      return forward;
    }
    std::vector<Point3> backward = traceDirection(seed, t, -1.0, false, used + forward.size());
    std::vector<Point3> line(backward.rbegin(), backward.rend());
    line.insert(line.end(), forward.begin() + 1, forward.end());
    return line;
  }

  const frep::Field& g1_;
  const frep::Field* g2_;
  const std::vector<frep::FieldPtr>& trims_;
  Box3 box_;
  CurveOptions o_;
  const char* what_;
  double seedSize_ = 0;
  Index3 cells_{ 1, 1, 1 };
  std::array<double, 3> cellSize_{ 0, 0, 0 };
  double degenerateSine_ = 0;
  double dedup_ = 0;
  double slack_ = 0;
  bool closed_ = false;
  Evaluators main_;
};

} // namespace

CurveSet traceCurve(const frep::Field& g1, const frep::Field& g2,
  const std::vector<frep::FieldPtr>& trims, const Box3& box, const CurveOptions& options)
{
  Tracer tracer(g1, &g2, trims, box, options, "traceCurve");
  detail::countMeshMade();
  return tracer.run();
}

CurveSet traceCurve2D(const frep::Field& g, const std::vector<frep::FieldPtr>& trims,
  const Box3& box, const CurveOptions& options)
{
  Tracer tracer(g, nullptr, trims, box, options, "traceCurve2D");
  detail::countMeshMade();
  return tracer.run();
}

} // namespace ictk::discretize
