// SPDX-License-Identifier: BSD-3-Clause
#include "FRep/Render.h"

#include "FRep/Threads.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>

namespace ictk::frep
{

namespace
{
/// Pixel centres: coordinate(a, i) = origin[a] + i * spacing[a], exactly as evalRowX computes x.
struct Layout
{
  std::array<double, 3> origin{};
  std::array<double, 3> spacing{};
  std::array<std::int64_t, 3> dims{};
  double time = 0;
  double coordinate(int a, std::int64_t i) const
  {
    return origin[a] + static_cast<double>(i) * spacing[a];
  }
};

struct Box
{
  std::array<std::int64_t, 3> lo;
  std::array<std::int64_t, 3> hi; // exclusive
};

struct Counts
{
  std::int64_t filled = 0, evaluated = 0, instructions = 0, pixels = 0;
};

template <typename T>
class Renderer
{
public:
  Renderer(
    const TapePtr& tape, const Layout& layout, const RenderOptions& options, std::uint8_t* image)
    : tape_(tape)
    , layout_(layout)
    , options_(options)
    , image_(image)
  {
  }

  void run()
  {
    const std::int64_t top = options_.prune ? options_.tileSizes.front() : 0;
    std::array<std::int64_t, 3> tiles{ 1, 1, 1 };
    std::array<std::int64_t, 3> edge{};
    for (int a = 0; a < 3; ++a)
    {
      // Brute force: one tile per row (rows are long along x).
      edge[a] = options_.prune ? top : (a == 0 ? layout_.dims[0] : 1);
      tiles[a] = (layout_.dims[a] + edge[a] - 1) / edge[a];
    }
    const std::int64_t count = tiles[0] * tiles[1] * tiles[2];
    auto body = [&](const tbb::blocked_range<std::int64_t>& range)
    {
      auto& slot = workspaces_.local();
      if (!slot)
      {
        slot.emplace(tape_, options_.parameters);
      }
      Workspace& ws = *slot;
      for (std::int64_t t = range.begin(); t != range.end(); ++t)
      {
        const std::int64_t ti = t % tiles[0], tj = (t / tiles[0]) % tiles[1],
                           tk = t / (tiles[0] * tiles[1]);
        Box box;
        const std::int64_t index[3] = { ti, tj, tk };
        for (int a = 0; a < 3; ++a)
        {
          box.lo[a] = index[a] * edge[a];
          box.hi[a] = std::min(layout_.dims[a], box.lo[a] + edge[a]);
        }
        if (options_.prune)
        {
          subdivide(ws, 0, tape_, ws.interval, box);
        }
        else if (useFast())
        {
          if (!ws.fast)
          {
            ws.fast = options_.rowEvaluator(tape_, options_.parameters);
          }
          evaluate(ws, *ws.fast, box);
        }
        else
        {
          evaluate(ws, ws.full, box);
        }
      }
    };
    const tbb::blocked_range<std::int64_t> all(0, count, 1);
    runOnThreads(options_.threads, [&] { tbb::parallel_for(all, body); });
    if (options_.stats)
    {
      Counts total;
      for (const auto& slot : workspaces_)
      {
        if (slot)
        {
          total.filled += slot->counts.filled;
          total.evaluated += slot->counts.evaluated;
          total.instructions += slot->counts.instructions;
          total.pixels += slot->counts.pixels;
        }
      }
      *options_.stats = { total.filled, total.evaluated, total.instructions, total.pixels };
    }
  }

private:
  struct Workspace
  {
    Workspace(const TapePtr& tape, const std::vector<double>& parameters)
      : parameters(parameters)
      , full(tape, parameters)
      , interval(tape, parameters)
    {
    }
    std::vector<double> parameters;
    BatchEvaluator<T> full;
    std::unique_ptr<RowEvaluator> fast; // options.rowEvaluator's evaluator of the full tape
    IntervalEvaluator interval;
    std::vector<T> row;
    Counts counts;
  };

  void fill(const Box& box, std::uint8_t value)
  {
    const auto& d = layout_.dims;
    for (std::int64_t k = box.lo[2]; k < box.hi[2]; ++k)
    {
      for (std::int64_t j = box.lo[1]; j < box.hi[1]; ++j)
      {
        std::uint8_t* p = image_ + (k * d[1] + j) * d[0];
        std::fill(p + box.lo[0], p + box.hi[0], value);
      }
    }
  }

  void subdivide(Workspace& ws, std::size_t level, const TapePtr& tape, IntervalEvaluator& interval,
    const Box& box)
  {
    Region region;
    for (int a = 0; a < 3; ++a)
    {
      region.axes[a] = { layout_.coordinate(a, box.lo[a]), layout_.coordinate(a, box.hi[a] - 1) };
    }
    region.axes[3] = { layout_.time, layout_.time };
    const Interval r = interval.eval(region);
    if (!(r.hi >= 0)) // also an empty interval: NaN everywhere, which is outside
    {
      fill(box, 0);
      ++ws.counts.filled;
      return;
    }
    if (r.lo >= 0 && !r.maybeNaN)
    {
      fill(box, 1);
      ++ws.counts.filled;
      return;
    }
    const TapePtr pruned = interval.simplified();
    if (level + 1 < options_.tileSizes.size())
    {
      const std::int64_t edge = options_.tileSizes[level + 1];
      std::optional<IntervalEvaluator> own;
      if (pruned != tape)
      {
        own.emplace(pruned, ws.parameters);
      }
      IntervalEvaluator& next = own ? *own : interval;
      Box child;
      for (child.lo[2] = box.lo[2]; child.lo[2] < box.hi[2]; child.lo[2] += edge)
      {
        child.hi[2] = std::min(box.hi[2], child.lo[2] + edge);
        for (child.lo[1] = box.lo[1]; child.lo[1] < box.hi[1]; child.lo[1] += edge)
        {
          child.hi[1] = std::min(box.hi[1], child.lo[1] + edge);
          for (child.lo[0] = box.lo[0]; child.lo[0] < box.hi[0]; child.lo[0] += edge)
          {
            child.hi[0] = std::min(box.hi[0], child.lo[0] + edge);
            subdivide(ws, level + 1, pruned, next, child);
          }
        }
      }
      return;
    }
    if (useFast())
    {
      evaluate(ws, *options_.rowEvaluator(pruned, ws.parameters), box);
      return;
    }
    if (pruned == tape_)
    {
      evaluate(ws, ws.full, box);
      return;
    }
    BatchEvaluator<T> leaf(pruned, ws.parameters);
    evaluate(ws, leaf, box);
  }

  bool useFast() const { return std::is_same_v<T, float> && options_.rowEvaluator; }

  template <typename Evaluator>
  void evaluate(Workspace& ws, Evaluator& evaluator, const Box& box)
  {
    const auto& d = layout_.dims;
    const std::size_t n = static_cast<std::size_t>(box.hi[0] - box.lo[0]);
    ws.row.resize(n);
    ++ws.counts.evaluated;
    ws.counts.instructions += static_cast<std::int64_t>(evaluator.tape()->instructions().size());
    for (std::int64_t k = box.lo[2]; k < box.hi[2]; ++k)
    {
      const double z = layout_.coordinate(2, k);
      for (std::int64_t j = box.lo[1]; j < box.hi[1]; ++j)
      {
        const double y = layout_.coordinate(1, j);
        if constexpr (std::is_same_v<Evaluator, RowEvaluator>)
        {
          if constexpr (std::is_same_v<T, float>) // only float renders use it (useFast())
          {
            evaluator.evalRowX(layout_.origin[0], layout_.spacing[0], box.lo[0], y, z, layout_.time,
              ws.row.data(), n);
          }
        }
        else
        {
          evaluator.evalRowX(
            layout_.origin[0], layout_.spacing[0], box.lo[0], y, z, layout_.time, ws.row.data(), n);
        }
        std::uint8_t* p = image_ + (k * d[1] + j) * d[0] + box.lo[0];
        const T* v = ws.row.data();
        for (std::size_t i = 0; i < n; ++i)
        {
          p[i] = v[i] >= T(0) ? 1 : 0;
        }
        ws.counts.pixels += static_cast<std::int64_t>(n);
      }
    }
  }

  const TapePtr& tape_;
  const Layout& layout_;
  const RenderOptions& options_;
  std::uint8_t* image_;
  tbb::enumerable_thread_specific<std::optional<Workspace>> workspaces_;
};

std::vector<std::uint8_t> render(const TapePtr& tape, const RenderRegion& region,
  const std::array<std::int64_t, 3>& dims, bool flat, const RenderOptions& options)
{
  if (!tape)
  {
    throw std::invalid_argument("render: no tape");
  }
  Layout layout;
  layout.time = region.time;
  for (int a = 0; a < 3; ++a)
  {
    if (dims[a] < 1 || dims[a] > (std::int64_t(1) << 20))
    {
      throw std::invalid_argument("render: size " + std::to_string(dims[a]) + " along axis " +
        std::to_string(a) + " must be in [1, 2^20]");
    }
    if (flat && a == 2)
    {
      layout.origin[a] = region.lo[a];
      layout.spacing[a] = 1;
    }
    else
    {
      if (!std::isfinite(region.lo[a]) || !std::isfinite(region.hi[a]) ||
        !(region.lo[a] < region.hi[a]))
      {
        throw std::invalid_argument("render: the region must be finite with lo < hi on each axis");
      }
      layout.spacing[a] = (region.hi[a] - region.lo[a]) / static_cast<double>(dims[a]);
      layout.origin[a] = region.lo[a] + 0.5 * layout.spacing[a];
    }
    layout.dims[a] = dims[a];
  }
  if (static_cast<long double>(dims[0]) * static_cast<long double>(dims[1]) *
      static_cast<long double>(dims[2]) >
    static_cast<long double>(std::int64_t(1) << 34))
  {
    throw std::invalid_argument("render: more than 2^34 pixels asked");
  }
  if (!std::isfinite(layout.origin[2]) || !std::isfinite(region.time))
  {
    throw std::invalid_argument("render: z and t must be finite");
  }
  if (options.prune)
  {
    if (options.tileSizes.empty())
    {
      throw std::invalid_argument("render: tileSizes is empty");
    }
    for (std::size_t i = 0; i < options.tileSizes.size(); ++i)
    {
      const int s = options.tileSizes[i];
      if (s < 1 || (i > 0 && options.tileSizes[i - 1] % s != 0))
      {
        throw std::invalid_argument(
          "render: tile sizes must be positive, each a multiple of the next");
      }
    }
  }
  if (tape->parameterCount() > options.parameters.size())
  {
    throw std::invalid_argument("render: the model has " + std::to_string(tape->parameterCount()) +
      " parameter(s) but " + std::to_string(options.parameters.size()) + " value(s) were given");
  }
  std::vector<std::uint8_t> image(static_cast<std::size_t>(dims[0] * dims[1] * dims[2]), 0);
  if (options.singlePrecision)
  {
    Renderer<float>(tape, layout, options, image.data()).run();
  }
  else
  {
    Renderer<double>(tape, layout, options, image.data()).run();
  }
  return image;
}
} // namespace

std::vector<std::uint8_t> renderSign2D(const TapePtr& tape, const RenderRegion& region, int width,
  int height, const RenderOptions& options)
{
  return render(tape, region, { width, height, 1 }, true, options);
}

std::vector<std::uint8_t> renderSign3D(const TapePtr& tape, const RenderRegion& region,
  const std::array<int, 3>& dims, const RenderOptions& options)
{
  return render(tape, region, { dims[0], dims[1], dims[2] }, false, options);
}

} // namespace ictk::frep
