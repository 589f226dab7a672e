// SPDX-License-Identifier: BSD-3-Clause
#include "Render/RayCast.h"

#include "Render/RayCaster.h"

#include "Discretize/Surface.h"
#include "FRep/Evaluators.h"
#include "FRep/RootFinding.h"
#include "FRep/Threads.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>

namespace ictk::render
{

using frep::Box3;
using frep::Interval;
using frep::Point3;
using frep::TapePtr;

namespace
{

/// A rectangle of pixels [i0, i1) x [j0, j1).
struct Rect
{
  int i0, j0, i1, j1;
  bool single() const { return i1 - i0 == 1 && j1 - j0 == 1; }
};

/// The evaluators of one tape at the render's time: the full one, or one simplified for a piece
/// of the view. The point and gradient evaluators are made when first needed (only pixels
/// evaluate points).
class TapeStage final : public detail::Stage
{
public:
  TapeStage(TapePtr tape, const std::vector<double>& parameters, double time)
    : TapeStage(std::move(tape), parameters, time, std::make_shared<Kept>())
  {
  }

  ~TapeStage() override { kept_->instructions -= tape_->instructions().size(); }

  /// Drops the kept narrowings, when the thread keeps more than its budget.
  void forget() override
  {
    if (kept_->instructions > KeptInstructionBudget)
    {
      narrowed_.clear();
      uncached_.reset();
    }
  }

  Interval bound(const Box3& box) override
  {
    frep::Region region;
    for (int a = 0; a < 3; ++a)
    {
      region.axes[a] = { box.lo[a], box.hi[a] };
    }
    region.axes[3] = { time_, time_ };
    return interval_.eval(region);
  }

  /// The tape simplified by the choices of the interval evaluator's last eval, or null when
  /// nothing would be cut. Neighbouring nodes mostly make the same choices, so the stages of the
  /// last few sets of choices are kept and given again: building a tape and its evaluators cost
  /// more than the evaluations of most nodes.
  detail::Stage* narrowed() override
  {
    if (tape_->choiceCount() == 0)
    {
      return nullptr;
    }
    const auto& choices = interval_.choices();
    if (std::all_of(
          choices.begin(), choices.end(), [](frep::Choice c) { return c == frep::Choice::Both; }))
    {
      return nullptr;
    }
    for (Narrowed& n : narrowed_)
    {
      if (n.choices == choices)
      {
        return n.stage.get();
      }
    }
    TapePtr pruned = interval_.simplified();
    if (pruned == tape_)
    {
      return nullptr;
    }
    auto stage =
      std::unique_ptr<TapeStage>(new TapeStage(std::move(pruned), parameters_, time_, kept_));
    if (kept_->instructions > KeptInstructionBudget)
    {
      // Over the thread's budget: this one is not kept (castTile drops the kept ones).
      uncached_ = std::move(stage);
      return uncached_.get();
    }
    if (narrowed_.size() == KeptNarrowings)
    {
      narrowed_.erase(narrowed_.begin()); // the oldest
    }
    narrowed_.push_back({ choices, std::move(stage) });
    return narrowed_.back().stage.get();
  }

  double value(const Point3& p) override
  {
    if (!point_)
    {
      point_.emplace(tape_, parameters_);
    }
    return point_->eval(p[0], p[1], p[2], time_);
  }

  Point3 gradient(const Point3& p) override
  {
    if (!gradient_)
    {
      gradient_.emplace(tape_, parameters_);
    }
    const frep::ValueGradient g = gradient_->eval(p[0], p[1], p[2], time_);
    return { g.gradient[0], g.gradient[1], g.gradient[2] };
  }

private:
  /// What a thread's stages keep: the instructions of all its live stages' tapes.
  struct Kept
  {
    std::size_t instructions = 0;
  };
  /// About 10 MB of tapes and evaluator values per thread (prospero at 512^2, 2 threads: 13 MB more
  /// peak memory than without).
  static constexpr std::size_t KeptInstructionBudget = std::size_t(1) << 16;

  TapeStage(
    TapePtr tape, const std::vector<double>& parameters, double time, std::shared_ptr<Kept> kept)
    : tape_(std::move(tape))
    , parameters_(parameters)
    , time_(time)
    , interval_(tape_, parameters_)
    , kept_(std::move(kept))
  {
    kept_->instructions += tape_->instructions().size();
  }

  TapePtr tape_;
  const std::vector<double>& parameters_;
  double time_;
  // Incremental: the pieces of one pixel's ray, and neighbouring rays, differ in some
  // coordinates only when the rays are parallel to an axis (an orthographic view along it, as
  // libfive's heightmap view), and then the instructions of the others keep their values;
  // otherwise the reuse costs a test per instruction.
  frep::IncrementalIntervalEvaluator interval_;
  std::optional<frep::IncrementalPointEvaluator> point_;
  std::optional<frep::GradientEvaluator> gradient_;
  static constexpr std::size_t KeptNarrowings = 4;
  struct Narrowed
  {
    std::vector<frep::Choice> choices;
    std::unique_ptr<TapeStage> stage;
  };
  std::vector<Narrowed> narrowed_;
  std::shared_ptr<Kept> kept_;
  std::unique_ptr<TapeStage> uncached_; // the last narrowing, when over the budget
};

/// A field's evaluator as a stage.
class FieldStage final : public detail::Stage
{
public:
  explicit FieldStage(std::unique_ptr<frep::FieldEvaluator> evaluator)
    : evaluator_(std::move(evaluator))
  {
  }
  Interval bound(const Box3& box) override
  {
    last_ = box;
    return evaluator_->bound(box);
  }
  detail::Stage* narrowed() override
  {
    std::unique_ptr<frep::FieldEvaluator> n = evaluator_->narrowed(last_);
    narrowed_ = n ? std::make_unique<FieldStage>(std::move(n)) : nullptr;
    return narrowed_.get();
  }
  double value(const Point3& p) override { return evaluator_->value(p); }
  Point3 gradient(const Point3& p) override
  {
    Point3 g{};
    evaluator_->gradient(p, g);
    return g;
  }

private:
  std::unique_ptr<frep::FieldEvaluator> evaluator_;
  Box3 last_{};
  std::unique_ptr<FieldStage> narrowed_;
};

/// A model's attribute at the first point found inside: a colour (3 or 4 components in [0, 1],
/// the last ignored) or a scalar.
class AttributePainter final : public detail::Painter
{
public:
  AttributePainter(const frep::Hypervolume& model, const std::vector<double>& parameters,
    double time, std::size_t offset, bool scalar)
    : evaluator_(model, parameters)
    , values_(model.attributeComponentCount())
    , time_(time)
    , offset_(offset)
    , scalar_(scalar)
  {
  }
  Paint at(const Point3& p) override
  {
    double value = 0;
    evaluator_.eval({ p[0], p[1], p[2], time_ }, value, values_.data());
    Paint paint;
    if (scalar_)
    {
      paint.scalar = values_[offset_];
      return paint;
    }
    for (int c = 0; c < 3; ++c)
    {
      const double x = values_[offset_ + c];
      paint.rgb[c] = std::isfinite(x) ? std::clamp(x, 0.0, 1.0) : NeutralGrey;
    }
    return paint;
  }

private:
  frep::HypervolumeEvaluator evaluator_;
  std::vector<double> values_;
  double time_;
  std::size_t offset_;
  bool scalar_;
};

/// One pixel's ray, with the last value of f computed on it (neighbouring leaves share an end).
struct Ray
{
  int i = 0, j = 0;
  Point3 origin{};
  Point3 direction{};
  double length = 1; // |direction|: the distance along the ray per unit of depth s
  double start = 0;  // the depth where the ray enters the box (or the near end)
  int face = -1;     // the axis of the box face it enters by; -1: the near end
  double lastS = std::numeric_limits<double>::quiet_NaN();
  double lastF = 0;
  Point3 at(double s) const
  {
    return { origin[0] + s * direction[0], origin[1] + s * direction[1],
      origin[2] + s * direction[2] };
  }
};

/// What a thread keeps between tiles.
struct Workspace
{
  explicit Workspace(const detail::Solid& solid)
    : root(solid.stage())
  {
    if (solid.painter)
    {
      painter = solid.painter();
    }
  }
  std::unique_ptr<detail::Stage> root; // the full evaluation: every tile starts with it
  std::unique_ptr<detail::Painter> painter;
  std::vector<std::uint8_t> done; // the current tile's pixels that found their surface
  std::size_t doneCount = 0;      // how many
  /// The same per row of a tile at most 64 pixels wide, bit i for column tile.i0 + i: a node's
  /// pixels still to be found are then a few masks, not a scan of its pixels (1 % of
  /// render-sphere-gyroid's instructions).
  std::vector<std::uint64_t> doneRows;
  /// Per pixel of the tile: the depth of the first piece that was left unresolved (NaN: none).
  std::vector<double> unresolvedAt;
  Rect tile{ 0, 0, 0, 0 };
  detail::CastCounts counts;
};

class RayCaster
{
public:
  RayCaster(
    Canvas& canvas, const detail::Solid& solid, const Camera& camera, const RayCastOptions& options)
    : canvas_(canvas)
    , solid_(solid)
    , box_(solid.box)
    , camera_(camera)
    , options_(options)
  {
    const Box3& box = solid.box;
    const double halfDiagonal = 0.5 * frep::norm(frep::sub(box.hi, box.lo));
    tolerance_ = options.depthTolerance > 0 ? options.depthTolerance : 1e-6 * halfDiagonal;
    // The bounding boxes of the pieces are widened by this much, so that rounding in their
    // corners cannot shrink them below the exact pieces.
    const Point3 c = box.centre();
    pad_ = 1e-12 *
      (halfDiagonal + std::max({ std::abs(c[0]), std::abs(c[1]), std::abs(c[2]) }) +
        frep::norm(frep::sub(camera.eye(), c)));
    // The depths along the viewing axis that the box spans (the ray starts at s = 0).
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (int k = 0; k < 8; ++k)
    {
      const Point3 corner{ (k & 1) ? box.hi[0] : box.lo[0], (k & 2) ? box.hi[1] : box.lo[1],
        (k & 4) ? box.hi[2] : box.lo[2] };
      const double s = frep::dot(frep::sub(corner, camera.eye()), camera.forward());
      lo = std::min(lo, s);
      hi = std::max(hi, s);
    }
    const double nearest =
      camera.projection() == Projection::Perspective ? 1e-9 * halfDiagonal : 0.0;
    near_ = std::max(lo, nearest);
    eyeInBox_ = lo <= nearest;
    far_ = hi;
    // A canvas that already holds surfaces limits the rays (the common z-buffer).
    limited_ = std::any_of(
      canvas.depth.begin(), canvas.depth.end(), [](double d) { return std::isfinite(d); });
  }

  detail::CastCounts run()
  {
    const int w = camera_.width(), h = camera_.height();
    const int edge = options_.tileSize;
    const int tilesX = (w + edge - 1) / edge, tilesY = (h + edge - 1) / edge;
    const std::int64_t tileCount = static_cast<std::int64_t>(tilesX) * tilesY;
    ProgressScope progress(options_.progress);
    progress.report(0);
    ProgressScope::Items tiles = progress.items(tileCount, 0, 1);
    tbb::enumerable_thread_specific<std::optional<Workspace>> workspaces;
    auto body = [&](const tbb::blocked_range<std::int64_t>& range)
    {
      auto& slot = workspaces.local();
      if (!slot)
      {
        slot.emplace(solid_);
      }
      for (std::int64_t t = range.begin(); t != range.end(); ++t)
      {
        if (progress.cancelled())
        {
          return;
        }
        const int ti = static_cast<int>(t % tilesX), tj = static_cast<int>(t / tilesX);
        const Rect tile{ ti * edge, tj * edge, std::min(w, (ti + 1) * edge),
          std::min(h, (tj + 1) * edge) };
        castTile(*slot, tile);
        tiles.finished();
      }
    };
    const tbb::blocked_range<std::int64_t> all(0, tileCount, 1);
    runOnThreads(options_.threads, [&] { tbb::parallel_for(all, body); });
    progress.report(1);
    detail::CastCounts counts;
    for (const auto& slot : workspaces)
    {
      if (slot)
      {
        counts.intervals += slot->counts.intervals;
        counts.points += slot->counts.points;
        counts.covered += slot->counts.covered;
        counts.unresolved += slot->counts.unresolved;
        counts.cut += slot->counts.cut;
        counts.eyeInside += slot->counts.eyeInside;
      }
    }
    return counts;
  }

private:
  void castTile(Workspace& ws, const Rect& tile)
  {
    ws.tile = tile;
    const std::size_t pixels = static_cast<std::size_t>(tile.i1 - tile.i0) * (tile.j1 - tile.j0);
    ws.done.assign(pixels, 0);
    ws.doneCount = 0;
    ws.doneRows.assign(
      tile.i1 - tile.i0 <= 64 ? static_cast<std::size_t>(tile.j1 - tile.j0) : 0, 0);
    ws.unresolvedAt.assign(pixels, std::numeric_limits<double>::quiet_NaN());
    if (!(far_ > near_))
    {
      return; // the box is behind the camera
    }
    ws.root->forget(); // nothing below the root is in use between tiles
    node(ws, *ws.root, tile, near_, far_);
    // Rays that left a piece unresolved and found nothing behind it within a leaf.
    for (int j = tile.j0; j < tile.j1; ++j)
    {
      for (int i = tile.i0; i < tile.i1; ++i)
      {
        const double u = unresolvedAt(ws, i, j);
        if (!done(ws, i, j) && !std::isnan(u))
        {
          const Ray ray = rayOf(i, j);
          // The surface the canvas holds within a leaf behind the piece is the one found there
          // (the ray was cut at its depth, so the search could not go on to it).
          const double held = canvas_.depth[canvas_.index(i, j)];
          if (held - u * ray.length <= footprint(u))
          {
            continue;
          }
          hit(ws, *ws.root, ray, u, u, true);
        }
      }
    }
  }

  Ray rayOf(int i, int j) const
  {
    Ray ray;
    ray.i = i;
    ray.j = j;
    const double u = camera_.u(i), v = camera_.v(j);
    ray.origin = camera_.origin(u, v);
    ray.direction = camera_.direction(u, v);
    ray.length = frep::norm(ray.direction);
    return ray;
  }

  static std::size_t inTile(const Workspace& ws, int i, int j)
  {
    return static_cast<std::size_t>(j - ws.tile.j0) * (ws.tile.i1 - ws.tile.i0) + (i - ws.tile.i0);
  }
  std::uint8_t& done(Workspace& ws, int i, int j) const { return ws.done[inTile(ws, i, j)]; }
  double& unresolvedAt(Workspace& ws, int i, int j) const
  {
    return ws.unresolvedAt[inTile(ws, i, j)];
  }

  /// The smallest rectangle that holds the pixels of `r` still to be found; false if none.
  /// `limit`: a depth s beyond which none of them needs searching (the canvas's depths, which
  /// are distances along rays of |direction| >= 1, bound their s from above).
  bool remaining(Workspace& ws, Rect& r, double& limit) const
  {
    limit = limited_ ? 0 : std::numeric_limits<double>::infinity();
    if (ws.doneCount == 0 && !limited_)
    {
      return true; // nothing found yet in this tile: every pixel remains
    }
    Rect p{ r.i1, r.j1, r.i0, r.j0 };
    if (!limited_ && !ws.doneRows.empty())
    {
      const int first = r.i0 - ws.tile.i0, width = r.i1 - r.i0;
      const std::uint64_t columns =
        (width == 64 ? ~std::uint64_t(0) : (std::uint64_t(1) << width) - 1) << first;
      for (int j = r.j0; j < r.j1; ++j)
      {
        const std::uint64_t open = ~ws.doneRows[static_cast<std::size_t>(j - ws.tile.j0)] & columns;
        if (open)
        {
          p.j0 = std::min(p.j0, j);
          p.j1 = j + 1;
          p.i0 = std::min(p.i0, ws.tile.i0 + __builtin_ctzll(open));
          p.i1 = std::max(p.i1, ws.tile.i0 + 64 - __builtin_clzll(open));
        }
      }
      if (p.i0 >= p.i1)
      {
        return false;
      }
      r = p;
      return true;
    }
    for (int j = r.j0; j < r.j1; ++j)
    {
      for (int i = r.i0; i < r.i1; ++i)
      {
        if (!done(ws, i, j))
        {
          p.i0 = std::min(p.i0, i);
          p.j0 = std::min(p.j0, j);
          p.i1 = std::max(p.i1, i + 1);
          p.j1 = std::max(p.j1, j + 1);
          if (limited_)
          {
            limit = std::max(limit, searched(canvas_.depth[canvas_.index(i, j)]));
          }
        }
      }
    }
    if (p.i0 >= p.i1)
    {
      return false;
    }
    r = p;
    return true;
  }

  /// How far a ray is searched when the canvas holds a surface at distance `held` along it: a
  /// leaf beyond, so that a solid whose surface lies at the held one (a patch on a solid's
  /// boundary, a tube along it) is found by a sign change there rather than by halving the
  /// pieces in front of it down to the depth tolerance; hits beyond `held` are not drawn.
  double searched(double held) const { return held + footprint(held); }

  /// The lateral size of one pixel at depth s.
  double footprint(double s) const
  {
    return camera_.projection() == Projection::Perspective ? camera_.pixelSize() * s
                                                           : camera_.pixelSize();
  }

  /// An enclosure of f over the points between depths s0 and s1 on the rays of the pixel centres
  /// of `r`, clipped to the solid's box; false when that is empty or f < 0 there.
  bool mayHold(Workspace& ws, detail::Stage& stage, const Rect& r, double s0, double s1) const
  {
    const double u[2] = { camera_.u(r.i0), camera_.u(r.i1 - 1) };
    const double v[2] = { camera_.v(r.j0), camera_.v(r.j1 - 1) };
    Point3 lo, hi;
    lo.fill(std::numeric_limits<double>::infinity());
    hi.fill(-std::numeric_limits<double>::infinity());
    // Camera::point(u, v, s) at the 8 corners, each ray's origin and direction made once: the
    // same arithmetic, so the same points bit for bit.
    for (int k = 0; k < 4; ++k)
    {
      const Point3 o = camera_.origin(u[k & 1], v[k >> 1]);
      const Point3 d = camera_.direction(u[k & 1], v[k >> 1]);
      for (const double s : { s0, s1 })
      {
        const Point3 p = frep::add(o, frep::scale(d, s));
        for (int a = 0; a < 3; ++a)
        {
          lo[a] = std::min(lo[a], p[a]);
          hi[a] = std::max(hi[a], p[a]);
        }
      }
    }
    return mayHold(ws, stage, lo, hi);
  }

  bool mayHold(Workspace& ws, detail::Stage& stage, Point3 lo, Point3 hi) const
  {
    Box3 box;
    for (int a = 0; a < 3; ++a)
    {
      box.lo[a] = std::max(lo[a] - pad_, box_.lo[a]);
      box.hi[a] = std::min(hi[a] + pad_, box_.hi[a]);
      if (!(box.lo[a] <= box.hi[a]))
      {
        return false;
      }
    }
    ++ws.counts.intervals;
    const Interval f = stage.bound(box);
    return f.hi >= 0; // false for an empty interval too: NaN everywhere is outside
  }

  /// A rectangle of pixels between two depths (step 2 of the header's algorithm).
  void node(Workspace& ws, detail::Stage& stage, Rect r, double s0, double s1)
  {
    double limit = 0;
    if (!remaining(ws, r, limit) || !(s0 < limit))
    {
      return;
    }
    s1 = std::min(s1, limit);
    if (r.single())
    {
      pixel(ws, stage, r.i0, r.j0, s0, s1);
      return;
    }
    if (!mayHold(ws, stage, r, s0, s1))
    {
      return;
    }
    // Every node simplifies its tape, those whose children are single pixels too: with the
    // narrowings kept (TapeStage::narrowed), a simplified tape is mostly found rather than built
    // (building one for a few evaluations of at most four rays cost more than they saved).
    detail::Stage* narrow = stage.narrowed();
    detail::Stage& next = narrow ? *narrow : stage;
    const int across = std::max(r.i1 - r.i0, r.j1 - r.j0);
    if (s1 - s0 > across * footprint(s1))
    {
      const double m = 0.5 * (s0 + s1);
      node(ws, next, r, s0, m);
      node(ws, next, r, m, s1);
      return;
    }
    const int im = r.i1 - r.i0 > 1 ? (r.i0 + r.i1) / 2 : r.i1;
    const int jm = r.j1 - r.j0 > 1 ? (r.j0 + r.j1) / 2 : r.j1;
    const Rect quarters[4] = { { r.i0, r.j0, im, jm }, { im, r.j0, r.i1, jm },
      { r.i0, jm, im, r.j1 }, { im, jm, r.i1, r.j1 } };
    for (const Rect& q : quarters)
    {
      if (q.i0 < q.i1 && q.j0 < q.j1)
      {
        node(ws, next, q, s0, s1);
      }
    }
  }

  /// One pixel's ray between two depths, clipped to the solid's box and to the depth the canvas
  /// holds (step 3).
  void pixel(Workspace& ws, detail::Stage& stage, int i, int j, double s0, double s1)
  {
    Ray ray = rayOf(i, j);
    // The ray's part inside the box: [entry, exit] of the depths near_..far_.
    double entry = near_, exit = far_;
    for (int a = 0; a < 3; ++a)
    {
      const double o = ray.origin[a], d = ray.direction[a];
      if (d == 0)
      {
        if (o < box_.lo[a] || o > box_.hi[a])
        {
          return;
        }
        continue;
      }
      double e0 = (box_.lo[a] - o) / d, e1 = (box_.hi[a] - o) / d;
      if (e0 > e1)
      {
        std::swap(e0, e1);
      }
      if (e0 >= entry)
      {
        entry = e0; // on a tie with the near end (which the box's corners give) too
        ray.face = a;
      }
      exit = std::min(exit, e1);
    }
    if (limited_)
    {
      exit = std::min(exit, searched(canvas_.depth[canvas_.index(i, j)]) / ray.length);
    }
    ray.start = entry;
    s0 = std::max(s0, entry);
    s1 = std::min(s1, exit);
    if (!(s0 <= s1))
    {
      return;
    }
    segment(ws, stage, ray, s0, s1);
  }

  bool segment(Workspace& ws, detail::Stage& stage, Ray& ray, double a, double b)
  {
    const double u = unresolvedAt(ws, ray.i, ray.j);
    if (!std::isnan(u) && (a - u) * ray.length > footprint(u))
    {
      hit(ws, *ws.root, ray, u, u, true); // nothing was found within a leaf behind it
      return true;
    }
    const double m = 0.5 * (a + b);
    const bool divisible = m > a && m < b;
    const double leafLength = std::max(footprint(b), tolerance_);
    if (divisible && (b - a) * ray.length > leafLength && (b - a) * ray.length <= 2 * leafLength)
    {
      // At most two leaves: bounding the whole first is wasted when it is not excluded (two thirds
      // of such pieces on render-sphere-gyroid), so the halves are bounded directly.
      return segment(ws, stage, ray, a, m) || segment(ws, stage, ray, m, b);
    }
    if (!divisible || (b - a) * ray.length <= leafLength)
    {
      return leaf(ws, stage, ray, a, b);
    }
    if (!mayHold(ws, stage, ray, a, b))
    {
      return false;
    }
    // The tape is not simplified again along one pixel's ray: building a tape there cost more
    // than the instructions it removes (9% of the time of render-sphere-gyroid-1024), and with
    // the narrowings kept (TapeStage::narrowed) it saves nothing measurable either.
    return segment(ws, stage, ray, a, m) || segment(ws, stage, ray, m, b);
  }

  /// An enclosure of f on the ray between depths a and b; false when f < 0 there.
  bool mayHold(Workspace& ws, detail::Stage& stage, const Ray& ray, double a, double b) const
  {
    Point3 lo = ray.at(a), hi = ray.at(b);
    for (int k = 0; k < 3; ++k)
    {
      if (lo[k] > hi[k])
      {
        std::swap(lo[k], hi[k]);
      }
    }
    return mayHold(ws, stage, lo, hi);
  }

  double f(Workspace& ws, detail::Stage& stage, Ray& ray, double s)
  {
    if (s == ray.lastS)
    {
      return ray.lastF;
    }
    ++ws.counts.points;
    const double value = stage.value(ray.at(s));
    ray.lastS = s;
    ray.lastF = value;
    return value;
  }

  /// A piece no longer than a leaf. Its ends are sampled before it is bounded: an end inside
  /// settles the piece without an interval, whose bound would only have confirmed it (on
  /// render-sphere-gyroid about a third of the leaves reached hold the surface); only a piece
  /// with both ends outside needs the interval to tell an empty piece from a feature inside it.
  bool leaf(Workspace& ws, detail::Stage& stage, Ray& ray, double a, double b)
  {
    const double fa = f(ws, stage, ray, a);
    if (fa >= 0)
    {
      found(ws, stage, ray, a, a);
      return true;
    }
    const double fb = f(ws, stage, ray, b);
    if (fb >= 0)
    {
      // One pointer captured, so that std::function keeps it without allocating.
      struct Probe
      {
        Workspace& ws;
        detail::Stage& stage;
        const Ray& ray;
        double inside;
      } probe{ ws, stage, ray, b };
      auto g = [p = &probe](double s)
      {
        ++p->ws.counts.points;
        const double value = p->stage.value(p->ray.at(s));
        if (value >= 0)
        {
          p->inside = std::min(p->inside, s);
          return value;
        }
        return std::isnan(value) ? -std::numeric_limits<double>::min() : value;
      };
      frep::LocateOptions refine;
      refine.timeTolerance = tolerance_ / ray.length;
      refine.maxIterations = 100;
      const double root = frep::refineRoot(g, a, std::isnan(fa) ? -1.0 : fa, b, fb, refine);
      found(ws, stage, ray, root, probe.inside);
      return true;
    }
    if (!mayHold(ws, stage, ray, a, b))
    {
      return false;
    }
    const double m = 0.5 * (a + b);
    if ((b - a) * ray.length <= tolerance_ || !(m > a && m < b))
    {
      // A feature thinner than the tolerance may hide here. The search goes on behind it: a
      // surface found within a leaf is taken instead (this piece was then the overestimate of
      // intervals right in front of it); otherwise the pixel is covered here, unresolved.
      double& u = unresolvedAt(ws, ray.i, ray.j);
      if (std::isnan(u))
      {
        u = m;
      }
      return false;
    }
    return segment(ws, stage, ray, a, m) || segment(ws, stage, ray, m, b);
  }

  /// A crossing found at depth s (f >= 0 at depth `inside`): the pixel's surface, unless a piece
  /// in front of it was left unresolved more than a leaf before.
  void found(Workspace& ws, detail::Stage& stage, const Ray& ray, double s, double inside)
  {
    const double u = unresolvedAt(ws, ray.i, ray.j);
    if (!std::isnan(u) && (s - u) * ray.length > footprint(u))
    {
      hit(ws, *ws.root, ray, u, u, true);
      return;
    }
    if (hit(ws, stage, ray, s, inside, false))
    {
      ws.counts.cut += s == ray.start ? 1 : 0;
      ws.counts.eyeInside += s == ray.start && eyeInBox_ && ray.start == near_ ? 1 : 0;
    }
  }

  /// Records the pixel's surface at depth s; `inside` is a depth at which f >= 0 (where the
  /// paint is taken) unless the hit is unresolved. False when the canvas holds a nearer one.
  bool hit(
    Workspace& ws, detail::Stage& stage, const Ray& ray, double s, double inside, bool unresolved)
  {
    std::uint8_t& d = done(ws, ray.i, ray.j);
    ws.doneCount += d ? 0 : 1;
    d = 1;
    if (!ws.doneRows.empty())
    {
      ws.doneRows[static_cast<std::size_t>(ray.j - ws.tile.j0)] |= std::uint64_t(1)
        << (ray.i - ws.tile.i0);
    }
    const Paint paint = ws.painter && !unresolved ? ws.painter->at(ray.at(inside)) : Paint{};
    // A solid cut by its box shows the cut flat, lit by the face's normal (its gradient there
    // belongs to no surface: on a tie of a min or max it even flips from pixel to pixel).
    frep::Point3 normal{ 0, 0, 0 };
    if (!unresolved && s == ray.start && ray.face >= 0)
    {
      normal[static_cast<std::size_t>(ray.face)] = 1;
    }
    else
    {
      normal = stage.gradient(ray.at(s));
    }
    const double light = headlight(normal, ray.direction, ray.length);
    // The normal buffer takes the outward normal, -gradient (f >= 0 inside).
    const frep::Point3 outward{ -normal[0], -normal[1], -normal[2] };
    if (!canvas_.put(canvas_.index(ray.i, ray.j), s * ray.length, light, paint, solid_.owner,
          outward, ray.direction))
    {
      return false;
    }
    ++ws.counts.covered;
    ws.counts.unresolved += unresolved ? 1 : 0;
    return true;
  }

  Canvas& canvas_;
  const detail::Solid& solid_;
  Box3 box_;
  const Camera& camera_;
  const RayCastOptions& options_;
  double tolerance_ = 0;
  double pad_ = 0;
  double near_ = 0;
  double far_ = 0;
  bool limited_ = false;
  bool eyeInBox_ = false; // rays start at the camera, not where they enter the box
};

void checkBox(const Box3& box)
{
  for (int a = 0; a < 3; ++a)
  {
    if (!std::isfinite(box.lo[a]) || !std::isfinite(box.hi[a]) || box.lo[a] > box.hi[a])
    {
      throw std::invalid_argument("rayCast: the box must be finite with lo <= hi");
    }
  }
}

/// Where a model's attribute `name` (empty: its colour, "colour" or "color" with 3 or 4
/// components, if any) starts among its attribute values, and whether it is a scalar; -1: none.
std::pair<std::ptrdiff_t, bool> attributeOf(const frep::Hypervolume& model, const std::string& name)
{
  std::size_t offset = 0;
  for (const frep::Attribute& a : model.attributes())
  {
    const std::size_t n = a.components.size();
    if (name.empty() ? (a.name == "colour" || a.name == "color") && (n == 3 || n == 4)
                     : a.name == name)
    {
      if (n != 1 && n != 3 && n != 4)
      {
        throw std::invalid_argument("the attribute '" + name + "' has " + std::to_string(n) +
          " components: a colour has 3 (or 4), a scalar 1");
      }
      return { static_cast<std::ptrdiff_t>(offset), n == 1 };
    }
    offset += n;
  }
  if (!name.empty())
  {
    std::string known;
    for (const frep::Attribute& a : model.attributes())
    {
      known += (known.empty() ? "" : ", ") + a.name;
    }
    throw std::invalid_argument("the model has no attribute '" + name +
      "' (it has: " + (known.empty() ? std::string("none") : known) + ")");
  }
  return { -1, false };
}

RayCastResult castModel(const TapePtr& tape, const frep::Hypervolume* model, const Box3& box,
  const Camera& camera, const RayCastOptions& options)
{
  if (!tape)
  {
    throw std::invalid_argument("rayCast: no tape");
  }
  if (tape->parameterCount() > options.parameters.size())
  {
    throw std::invalid_argument("rayCast: the model has " + std::to_string(tape->parameterCount()) +
      " parameter(s) but " + std::to_string(options.parameters.size()) + " value(s) were given");
  }
  std::pair<std::ptrdiff_t, bool> attribute{ -1, false };
  if (model)
  {
    attribute = attributeOf(*model, options.colours.attribute);
  }
  const bool scalar = attribute.first >= 0 && attribute.second;
  ColourMap::named(options.colours.map); // an unknown map fails before the work
  Canvas canvas(
    camera.width(), camera.height(), scalar ? Canvas::Colouring::Scalar : Canvas::Colouring::Rgb);
  detail::Solid solid;
  solid.box = box;
  solid.stage = [&]
  {
    return std::make_unique<TapeStage>(tape, options.parameters, options.time);
  };
  if (attribute.first >= 0)
  {
    solid.painter = [&]
    {
      return std::make_unique<AttributePainter>(*model, options.parameters, options.time,
        static_cast<std::size_t>(attribute.first), scalar);
    };
  }
  const detail::CastCounts counts = detail::cast(canvas, solid, camera, options);
  RayCastResult result;
  if (scalar)
  {
    result.scalarRange = finishColours(canvas, options.colours);
  }
  result.width = canvas.width;
  result.height = canvas.height;
  result.colour = std::move(canvas.colour);
  result.depth = std::move(canvas.depth);
  result.normal = std::move(canvas.normal);
  result.coveredPixels = counts.covered;
  result.unresolvedPixels = counts.unresolved;
  result.cutPixels = counts.cut;
  result.intervalEvaluations = counts.intervals;
  result.pointEvaluations = counts.points;
  return result;
}

} // namespace

namespace detail
{

std::unique_ptr<Stage> fieldStage(const frep::Field& field)
{
  return std::make_unique<FieldStage>(field.evaluator());
}

CastCounts cast(
  Canvas& canvas, const Solid& solid, const Camera& camera, const RayCastOptions& options)
{
  checkBox(solid.box);
  if (!std::isfinite(options.depthTolerance) || options.depthTolerance < 0)
  {
    throw std::invalid_argument("rayCast: the depth tolerance must be finite and >= 0");
  }
  if (options.tileSize < 1)
  {
    throw std::invalid_argument("rayCast: the tile size must be at least 1");
  }
  if (!std::isfinite(options.time))
  {
    throw std::invalid_argument("rayCast: the time must be finite");
  }
  if (!canvas.isValidFor(camera))
  {
    throw std::invalid_argument("rayCast: the canvas is not the camera's picture (its size or "
                                "buffers differ)");
  }
  return RayCaster(canvas, solid, camera, options).run();
}

} // namespace detail

RayCastResult rayCast(
  const TapePtr& field, const Box3& box, const Camera& camera, const RayCastOptions& options)
{
  return castModel(field, nullptr, box, camera, options);
}

ScenePrimitives modelScene(const frep::Hypervolume& model, const Box3& box, double featureSize,
  const RayCastOptions& options)
{
  const frep::TapePtr tape = frep::Tape::compile(model.geometry().function());
  if (tape->parameterCount() > options.parameters.size())
  {
    throw std::invalid_argument("the model has " + std::to_string(tape->parameterCount()) +
      " parameter(s) but " + std::to_string(options.parameters.size()) + " value(s) were given");
  }
  const auto [offset, scalar] = attributeOf(model, options.colours.attribute);
  ColourMap::named(options.colours.map); // an unknown map fails before the work
  if (!(featureSize > 0))
  {
    // The default of `ictk mesh` for a complex: 1/64 of the largest side.
    featureSize =
      std::max({ box.hi[0] - box.lo[0], box.hi[1] - box.lo[1], box.hi[2] - box.lo[2] }) / 64;
  }
  discretize::SurfaceOptions so;
  so.featureSize = featureSize;
  so.threads = options.threads;
  so.progress = options.progress;
  discretize::SurfaceMesh mesh =
    discretize::contourSurface(*frep::tapeField(tape, options.time, options.parameters), box, so);
  Primitives p;
  p.points = std::move(mesh.points);
  p.triangles = std::move(mesh.triangles);
  p.normals = vertexNormals(p.points, p.triangles);
  if (offset >= 0)
  {
    // As the ray caster, the attribute is taken inside the solid: a vertex of the contour lies
    // on f = 0 to the root finder's accuracy, on either side, and where the attribute changes at
    // the surface (a material outside the solid) the outside value would show. A vertex outside
    // is moved along the gradient (towards larger f) in steps growing from 1e-4 of a cell until
    // f >= 0 (at most about a cell).
    AttributePainter painter(
      model, options.parameters, options.time, static_cast<std::size_t>(offset), scalar);
    frep::GradientEvaluator gradient(tape, options.parameters);
    p.paints.reserve(p.points.size());
    for (const Point3& x : p.points)
    {
      Point3 q = x;
      frep::ValueGradient g = gradient.eval(x[0], x[1], x[2], options.time);
      const double n = std::hypot(g.gradient[0], g.gradient[1], g.gradient[2]);
      double step = 1e-4 * featureSize;
      for (int k = 0; k < 14 && g.value < 0 && n > 0 && std::isfinite(n); ++k, step *= 2)
      {
        for (int a = 0; a < 3; ++a)
        {
          q[a] = x[a] + step * g.gradient[a] / n;
        }
        g.value = gradient.eval(q[0], q[1], q[2], options.time).value;
      }
      p.paints.push_back(painter.at(g.value >= 0 ? q : x));
    }
  }
  ScenePrimitives scene;
  scene.scalar = offset >= 0 && scalar;
  scene.meshed.push_back(std::move(p));
  return scene;
}

RayCastResult rayCast(const frep::Hypervolume& model, const Box3& box, const Camera& camera,
  const RayCastOptions& options)
{
  return castModel(frep::Tape::compile(model.geometry().function()), &model, box, camera, options);
}

Pick pick(const frep::Hypervolume& model, const Box3& box, const Camera& camera, int i, int j,
  const std::string& attribute, const RayCastOptions& options)
{
  if (i < 0 || j < 0 || i >= camera.width() || j >= camera.height())
  {
    throw std::invalid_argument("pick: the pixel (" + std::to_string(i) + ", " + std::to_string(j) +
      ") is outside the " + std::to_string(camera.width()) + " x " +
      std::to_string(camera.height()) + " picture");
  }
  std::size_t offset = 0;
  std::size_t count = 0;
  for (const frep::Attribute& a : model.attributes())
  {
    if (a.name == attribute)
    {
      count = a.components.size();
      break;
    }
    offset += a.components.size();
  }
  if (count == 0 && !attribute.empty())
  {
    attributeOf(model, attribute); // throws, naming the attributes the model has
  }
  // A one-pixel camera whose centre ray is the pixel's ray and whose pixel is as large: the same
  // search as the picture's at that pixel.
  const double u = camera.u(i);
  const double v = camera.v(j);
  const Point3 origin = camera.origin(u, v);
  Point3 direction = camera.direction(u, v);
  const double length = std::sqrt(
    direction[0] * direction[0] + direction[1] * direction[1] + direction[2] * direction[2]);
  for (double& c : direction)
  {
    c /= length;
  }
  const Point3 focal{ origin[0] + direction[0], origin[1] + direction[1],
    origin[2] + direction[2] };
  const bool perspective = camera.projection() == Projection::Perspective;
  const double degrees = 180 / 3.14159265358979323846;
  const Camera one = Camera::lookAt(origin, focal, camera.up(), camera.projection(),
    perspective ? 2 * std::atan(0.5 * camera.pixelSize()) * degrees : 30,
    perspective ? 1 : 0.5 * camera.pixelSize(), 1, 1);
  RayCastOptions single = options;
  single.tileSize = 1;
  single.colours = {};
  const RayCastResult r =
    rayCast(frep::Tape::compile(model.geometry().function()), box, one, single);
  Pick result;
  if (!std::isfinite(r.depth[0]))
  {
    return result;
  }
  result.hit = true;
  result.depth = r.depth[0];
  for (int a = 0; a < 3; ++a)
  {
    result.point[a] = origin[a] + r.depth[0] * direction[a];
  }
  frep::HypervolumeEvaluator evaluator(model, options.parameters);
  std::vector<double> values(model.attributeComponentCount());
  double f = 0;
  evaluator.eval(
    { result.point[0], result.point[1], result.point[2], options.time }, f, values.data());
  result.values.assign(values.begin() + static_cast<std::ptrdiff_t>(offset),
    values.begin() + static_cast<std::ptrdiff_t>(offset + count));
  return result;
}

} // namespace ictk::render
