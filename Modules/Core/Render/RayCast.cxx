// SPDX-License-Identifier: BSD-3-Clause
#include "Render/RayCast.h"

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
using frep::IntervalEvaluator;
using frep::Point3;
using frep::TapePtr;

namespace
{

constexpr double Ambient = 0.25;
constexpr double Diffuse = 0.75;
constexpr double NeutralGrey = 0.8;

/// A rectangle of pixels [i0, i1) x [j0, j1).
struct Rect
{
  int i0, j0, i1, j1;
  bool single() const { return i1 - i0 == 1 && j1 - j0 == 1; }
};

/// The evaluators of one tape: the full one, or one simplified for a piece of the view. The
/// interval evaluator is borrowed from the parent while the tape is the parent's; the point and
/// gradient evaluators are made when first needed (only pixels evaluate points).
class Stage
{
public:
  Stage(TapePtr tape, const std::vector<double>& parameters, IntervalEvaluator* interval)
    : tape_(std::move(tape))
    , parameters_(parameters)
    , interval_(interval)
  {
    if (!interval_)
    {
      ownInterval_.emplace(tape_, parameters_);
      interval_ = &*ownInterval_;
    }
  }
  Stage(const Stage&) = delete;
  Stage& operator=(const Stage&) = delete;

  const TapePtr& tape() const { return tape_; }
  IntervalEvaluator& interval() { return *interval_; }
  frep::PointEvaluator& point()
  {
    if (!point_)
    {
      point_.emplace(tape_, parameters_);
    }
    return *point_;
  }
  frep::GradientEvaluator& gradient()
  {
    if (!gradient_)
    {
      gradient_.emplace(tape_, parameters_);
    }
    return *gradient_;
  }

  /// The tape simplified by the choices of the interval evaluator's last eval, or null when
  /// nothing would be cut.
  TapePtr narrowed() const
  {
    if (tape_->choiceCount() == 0)
    {
      return nullptr;
    }
    const auto& choices = interval_->choices();
    if (std::all_of(
          choices.begin(), choices.end(), [](frep::Choice c) { return c == frep::Choice::Both; }))
    {
      return nullptr;
    }
    TapePtr pruned = interval_->simplified();
    return pruned == tape_ ? nullptr : pruned;
  }

private:
  TapePtr tape_;
  const std::vector<double>& parameters_;
  IntervalEvaluator* interval_;
  std::optional<IntervalEvaluator> ownInterval_;
  std::optional<frep::PointEvaluator> point_;
  std::optional<frep::GradientEvaluator> gradient_;
};

/// One pixel's ray, with the last value of f computed on it (neighbouring leaves share an end).
struct Ray
{
  int i = 0, j = 0;
  Point3 origin{};
  Point3 direction{};
  double length = 1; // |direction|: the distance along the ray per unit of depth s
  double start = 0;  // the depth where the ray enters the box (or the near end)
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
  Workspace(
    const TapePtr& tape, const std::vector<double>& parameters, const frep::Hypervolume* model)
    : interval(tape, parameters)
  {
    if (model)
    {
      attributes.emplace(*model, parameters);
      attributeValues.resize(model->attributeComponentCount());
    }
  }
  IntervalEvaluator interval; // of the full tape: the root stage of every tile borrows it
  std::optional<frep::HypervolumeEvaluator> attributes;
  std::vector<double> attributeValues;
  std::vector<std::uint8_t> done; // the current tile's pixels that found their surface
  /// Per pixel of the tile: the depth of the first piece that was left unresolved (NaN: none).
  std::vector<double> unresolvedAt;
  Stage* root = nullptr; // the full tape's stage of the current tile
  Rect tile{ 0, 0, 0, 0 };
  std::int64_t intervals = 0, points = 0, covered = 0, unresolved = 0, cut = 0;
};

class RayCaster
{
public:
  RayCaster(const TapePtr& tape, const frep::Hypervolume* model, const Box3& box,
    const Camera& camera, const RayCastOptions& options, RayCastResult& out)
    : tape_(tape)
    , model_(model)
    , box_(box)
    , camera_(camera)
    , options_(options)
    , out_(out)
  {
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
    near_ =
      std::max(lo, camera.projection() == Projection::Perspective ? 1e-9 * halfDiagonal : 0.0);
    far_ = hi;
    if (model_)
    {
      std::size_t offset = 0;
      for (const frep::Attribute& a : model_->attributes())
      {
        if ((a.name == "colour" || a.name == "color") &&
          (a.components.size() == 3 || a.components.size() == 4))
        {
          colourOffset_ = static_cast<std::ptrdiff_t>(offset);
          break;
        }
        offset += a.components.size();
      }
    }
  }

  void run()
  {
    const int w = camera_.width(), h = camera_.height();
    out_.width = w;
    out_.height = h;
    const std::size_t pixels = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
    out_.colour.assign(4 * pixels, 0);
    for (std::size_t p = 0; p < pixels; ++p)
    {
      out_.colour[4 * p] = out_.colour[4 * p + 1] = out_.colour[4 * p + 2] = 255;
    }
    out_.depth.assign(pixels, std::numeric_limits<double>::infinity());

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
        slot.emplace(tape_, options_.parameters, model_);
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
    for (const auto& slot : workspaces)
    {
      if (slot)
      {
        out_.intervalEvaluations += slot->intervals;
        out_.pointEvaluations += slot->points;
        out_.coveredPixels += slot->covered;
        out_.unresolvedPixels += slot->unresolved;
        out_.cutPixels += slot->cut;
      }
    }
  }

private:
  void castTile(Workspace& ws, const Rect& tile)
  {
    ws.tile = tile;
    const std::size_t pixels = static_cast<std::size_t>(tile.i1 - tile.i0) * (tile.j1 - tile.j0);
    ws.done.assign(pixels, 0);
    ws.unresolvedAt.assign(pixels, std::numeric_limits<double>::quiet_NaN());
    if (!(far_ > near_))
    {
      return; // the box is behind the camera
    }
    Stage root(tape_, options_.parameters, &ws.interval);
    ws.root = &root;
    node(ws, root, tile, near_, far_);
    // Rays that left a piece unresolved and found nothing behind it within a leaf.
    for (int j = tile.j0; j < tile.j1; ++j)
    {
      for (int i = tile.i0; i < tile.i1; ++i)
      {
        const double u = unresolvedAt(ws, i, j);
        if (!done(ws, i, j) && !std::isnan(u))
        {
          const Ray ray = rayOf(i, j);
          hit(ws, root, ray, u, u, true);
        }
      }
    }
    ws.root = nullptr;
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
  bool remaining(Workspace& ws, Rect& r) const
  {
    Rect p{ r.i1, r.j1, r.i0, r.j0 };
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

  /// The lateral size of one pixel at depth s.
  double footprint(double s) const
  {
    return camera_.projection() == Projection::Perspective ? camera_.pixelSize() * s
                                                           : camera_.pixelSize();
  }

  /// An enclosure of f over the points between depths s0 and s1 on the rays of the pixel centres
  /// of `r`, clipped to the model's box; false when that is empty or f < 0 there.
  bool mayHold(Workspace& ws, Stage& stage, const Rect& r, double s0, double s1) const
  {
    const double u[2] = { camera_.u(r.i0), camera_.u(r.i1 - 1) };
    const double v[2] = { camera_.v(r.j0), camera_.v(r.j1 - 1) };
    Point3 lo, hi;
    lo.fill(std::numeric_limits<double>::infinity());
    hi.fill(-std::numeric_limits<double>::infinity());
    for (int k = 0; k < 8; ++k)
    {
      const Point3 p = camera_.point(u[k & 1], v[(k >> 1) & 1], (k & 4) ? s1 : s0);
      for (int a = 0; a < 3; ++a)
      {
        lo[a] = std::min(lo[a], p[a]);
        hi[a] = std::max(hi[a], p[a]);
      }
    }
    return mayHold(ws, stage, lo, hi);
  }

  bool mayHold(Workspace& ws, Stage& stage, Point3 lo, Point3 hi) const
  {
    frep::Region region;
    for (int a = 0; a < 3; ++a)
    {
      lo[a] = std::max(lo[a] - pad_, box_.lo[a]);
      hi[a] = std::min(hi[a] + pad_, box_.hi[a]);
      if (!(lo[a] <= hi[a]))
      {
        return false;
      }
      region.axes[a] = { lo[a], hi[a] };
    }
    region.axes[3] = { options_.time, options_.time };
    ++ws.intervals;
    const Interval f = stage.interval().eval(region);
    return f.hi >= 0; // false for an empty interval too: NaN everywhere is outside
  }

  /// A rectangle of pixels between two depths (step 2 of the header's algorithm).
  void node(Workspace& ws, Stage& stage, Rect r, double s0, double s1)
  {
    if (!remaining(ws, r))
    {
      return;
    }
    if (r.single())
    {
      pixel(ws, stage, r.i0, r.j0, s0, s1);
      return;
    }
    if (!mayHold(ws, stage, r, s0, s1))
    {
      return;
    }
    std::optional<Stage> narrow;
    if (TapePtr pruned = stage.narrowed())
    {
      narrow.emplace(std::move(pruned), options_.parameters, nullptr);
    }
    Stage& next = narrow ? *narrow : stage;
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

  /// One pixel's ray between two depths, clipped to the model's box (step 3).
  void pixel(Workspace& ws, Stage& stage, int i, int j, double s0, double s1)
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
      entry = std::max(entry, e0);
      exit = std::min(exit, e1);
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

  bool segment(Workspace& ws, Stage& stage, Ray& ray, double a, double b)
  {
    const double u = unresolvedAt(ws, ray.i, ray.j);
    if (!std::isnan(u) && (a - u) * ray.length > footprint(u))
    {
      hit(ws, *ws.root, ray, u, u, true); // nothing was found within a leaf behind it
      return true;
    }
    Point3 lo = ray.at(a), hi = ray.at(b);
    for (int k = 0; k < 3; ++k)
    {
      if (lo[k] > hi[k])
      {
        std::swap(lo[k], hi[k]);
      }
    }
    if (!mayHold(ws, stage, lo, hi))
    {
      return false;
    }
    // The tape is not simplified again along one pixel's ray: building a tape there costs more
    // than the instructions it removes (9% of the time of render-sphere-gyroid-1024).
    const double m = 0.5 * (a + b);
    const bool divisible = m > a && m < b;
    if (divisible && (b - a) * ray.length > std::max(footprint(b), tolerance_))
    {
      return segment(ws, stage, ray, a, m) || segment(ws, stage, ray, m, b);
    }
    return leaf(ws, stage, ray, a, b);
  }

  double f(Workspace& ws, Stage& stage, Ray& ray, double s)
  {
    if (s == ray.lastS)
    {
      return ray.lastF;
    }
    const Point3 p = ray.at(s);
    ++ws.points;
    const double value = stage.point().eval(p[0], p[1], p[2], options_.time);
    ray.lastS = s;
    ray.lastF = value;
    return value;
  }

  /// A piece no longer than a leaf whose interval did not exclude 0.
  bool leaf(Workspace& ws, Stage& stage, Ray& ray, double a, double b)
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
      double inside = b;
      auto g = [&](double s)
      {
        const Point3 p = ray.at(s);
        ++ws.points;
        const double value = stage.point().eval(p[0], p[1], p[2], options_.time);
        if (value >= 0)
        {
          inside = std::min(inside, s);
          return value;
        }
        return std::isnan(value) ? -std::numeric_limits<double>::min() : value;
      };
      frep::LocateOptions refine;
      refine.timeTolerance = tolerance_ / ray.length;
      refine.maxIterations = 100;
      const double root = frep::refineRoot(g, a, std::isnan(fa) ? -1.0 : fa, b, fb, refine);
      found(ws, stage, ray, root, inside);
      return true;
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
  void found(Workspace& ws, Stage& stage, const Ray& ray, double s, double inside)
  {
    const double u = unresolvedAt(ws, ray.i, ray.j);
    if (!std::isnan(u) && (s - u) * ray.length > footprint(u))
    {
      hit(ws, *ws.root, ray, u, u, true);
      return;
    }
    hit(ws, stage, ray, s, inside, false);
    ws.cut += s == ray.start ? 1 : 0;
  }

  /// Records the pixel's surface at depth s; `inside` is a depth at which f >= 0 (where the
  /// model's colour is taken) unless the hit is unresolved.
  void hit(Workspace& ws, Stage& stage, const Ray& ray, double s, double inside, bool unresolved)
  {
    done(ws, ray.i, ray.j) = 1;
    ++ws.covered;
    ws.unresolved += unresolved ? 1 : 0;
    const std::size_t index =
      static_cast<std::size_t>(ray.j) * static_cast<std::size_t>(camera_.width()) +
      static_cast<std::size_t>(ray.i);
    out_.depth[index] = s * ray.length;

    double colour[3] = { NeutralGrey, NeutralGrey, NeutralGrey };
    if (colourOffset_ >= 0 && !unresolved)
    {
      const Point3 p = ray.at(inside);
      double value = 0;
      ws.attributes->eval({ p[0], p[1], p[2], options_.time }, value, ws.attributeValues.data());
      for (int c = 0; c < 3; ++c)
      {
        const double x = ws.attributeValues[static_cast<std::size_t>(colourOffset_) + c];
        colour[c] = std::isfinite(x) ? std::clamp(x, 0.0, 1.0) : NeutralGrey;
      }
    }
    // A headlight: the light comes from the eye along the ray, so |n . ray| is the cosine.
    const Point3 p = ray.at(s);
    const frep::ValueGradient g = stage.gradient().eval(p[0], p[1], p[2], options_.time);
    const Point3 n = [&]
    {
      const auto o = frep::outwardNormal(g);
      return Point3{ o[0], o[1], o[2] };
    }();
    const double facing = frep::norm(n) > 0
      ? std::abs(frep::dot(n, ray.direction)) / ray.length
      : 1.0; // no gradient (a flat spot, or a cut by the box): lit as if facing the eye
    const double light = Ambient + Diffuse * facing;
    std::uint8_t* rgba = &out_.colour[4 * index];
    for (int c = 0; c < 3; ++c)
    {
      rgba[c] =
        static_cast<std::uint8_t>(std::lround(255 * std::clamp(colour[c] * light, 0.0, 1.0)));
    }
    rgba[3] = 255;
  }

  const TapePtr& tape_;
  const frep::Hypervolume* model_;
  Box3 box_;
  const Camera& camera_;
  const RayCastOptions& options_;
  RayCastResult& out_;
  double tolerance_ = 0;
  double pad_ = 0;
  double near_ = 0;
  double far_ = 0;
  std::ptrdiff_t colourOffset_ = -1;
};

RayCastResult cast(const TapePtr& tape, const frep::Hypervolume* model, const Box3& box,
  const Camera& camera, const RayCastOptions& options)
{
  if (!tape)
  {
    throw std::invalid_argument("rayCast: no tape");
  }
  for (int a = 0; a < 3; ++a)
  {
    if (!std::isfinite(box.lo[a]) || !std::isfinite(box.hi[a]) || box.lo[a] > box.hi[a])
    {
      throw std::invalid_argument("rayCast: the box must be finite with lo <= hi");
    }
  }
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
  if (tape->parameterCount() > options.parameters.size())
  {
    throw std::invalid_argument("rayCast: the model has " + std::to_string(tape->parameterCount()) +
      " parameter(s) but " + std::to_string(options.parameters.size()) + " value(s) were given");
  }
  RayCastResult result;
  RayCaster(tape, model, box, camera, options, result).run();
  return result;
}

} // namespace

RayCastResult rayCast(
  const TapePtr& field, const Box3& box, const Camera& camera, const RayCastOptions& options)
{
  return cast(field, nullptr, box, camera, options);
}

RayCastResult rayCast(const frep::Hypervolume& model, const Box3& box, const Camera& camera,
  const RayCastOptions& options)
{
  return cast(frep::Tape::compile(model.geometry().function()), &model, box, camera, options);
}

} // namespace ictk::render
