// SPDX-License-Identifier: BSD-3-Clause
#include "FRep/Sampling.h"

#include "FRep/Threads.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <unistd.h>

#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>

namespace ictk::frep
{

Grid gridOverBox(const std::array<double, 3>& lo, const std::array<double, 3>& hi,
  const std::array<std::int64_t, 3>& resolution, double time)
{
  Grid g;
  g.time = time;
  for (int a = 0; a < 3; ++a)
  {
    g.origin[a] = lo[a];
    g.dimensions[a] = resolution[a];
    g.spacing[a] = resolution[a] > 1 ? (hi[a] - lo[a]) / static_cast<double>(resolution[a] - 1)
                                     : std::max(hi[a] - lo[a], 1.0);
  }
  return g;
}

namespace
{
std::size_t physicalMemory()
{
  const long pages = sysconf(_SC_PHYS_PAGES);
  const long pageSize = sysconf(_SC_PAGESIZE);
  if (pages <= 0 || pageSize <= 0)
  {
    return std::size_t(1) << 32;
  }
  return static_cast<std::size_t>(pages) * static_cast<std::size_t>(pageSize);
}
} // namespace

void checkGrid(const Grid& grid, std::size_t bytesPerPoint, std::size_t maxBytes)
{
  static const char* names[] = { "x", "y", "z" };
  for (int a = 0; a < 3; ++a)
  {
    if (grid.dimensions[a] < 1)
    {
      throw std::invalid_argument(std::string("grid: dimension along ") + names[a] + " is " +
        std::to_string(grid.dimensions[a]) + "; it must be at least 1");
    }
    if (!std::isfinite(grid.origin[a]) || !std::isfinite(grid.spacing[a]) || !(grid.spacing[a] > 0))
    {
      std::ostringstream os;
      os << "grid: origin " << grid.origin[a] << " and spacing " << grid.spacing[a] << " along "
         << names[a] << " must be finite, with a positive spacing";
      throw std::invalid_argument(os.str());
    }
  }
  if (!std::isfinite(grid.time))
  {
    throw std::invalid_argument("grid: the time must be finite");
  }
  if (maxBytes == 0)
  {
    maxBytes = physicalMemory() / 10 * 8;
  }
  // Overflow-safe product: compare in long double.
  const long double bytes = static_cast<long double>(grid.dimensions[0]) * grid.dimensions[1] *
    grid.dimensions[2] * static_cast<long double>(bytesPerPoint);
  if (bytes > static_cast<long double>(maxBytes))
  {
    std::ostringstream os;
    os.precision(3);
    os << "grid: " << grid.dimensions[0] << " x " << grid.dimensions[1] << " x "
       << grid.dimensions[2] << " points need " << static_cast<double>(bytes / 1e9)
       << " GB, more than the " << static_cast<double>(maxBytes) / 1e9 << " GB allowed";
    throw std::invalid_argument(os.str());
  }
}

namespace
{
// Per-thread evaluation state. Neighbouring bricks usually prune to the same tape, so the
// evaluators prepared for the last few sets of choices are kept (simplifying and preparing a
// tape costs about as much as evaluating a small brick).
template <typename T>
struct Workspace
{
  static constexpr std::size_t CacheSize = 16;

  Workspace(const TapePtr& tape, const std::vector<double>& parameters)
    : full(tape, parameters)
    , interval(tape, parameters)
    , parameters(parameters)
  {
  }

  BatchEvaluator<T>& evaluatorFor(const std::vector<Choice>& choices)
  {
    for (auto& entry : cache)
    {
      if (entry.first == choices)
      {
        return *entry.second;
      }
    }
    auto evaluator = std::make_unique<BatchEvaluator<T>>(interval.simplified(), parameters);
    if (cache.size() < CacheSize)
    {
      cache.emplace_back(choices, std::move(evaluator));
      return *cache.back().second;
    }
    auto& victim = cache[next++ % CacheSize];
    victim = { choices, std::move(evaluator) };
    return *victim.second;
  }

  BatchEvaluator<T> full;
  IntervalEvaluator interval;
  std::vector<double> parameters;
  std::vector<std::pair<std::vector<Choice>, std::unique_ptr<BatchEvaluator<T>>>> cache;
  std::size_t next = 0;
};

// Runs `writeRow(evaluator, offset, i0, n, y, z)` for every grid row segment of every brick, in
// parallel; `offset` is the index of the segment's first point in VTK point order.
template <typename T, typename RowWriter>
void sampleRows(const TapePtr& tape, const Grid& grid, std::size_t bytesPerPoint,
  const SampleOptions& options, const RowWriter& writeRow)
{
  checkGrid(grid, bytesPerPoint);
  if (tape->parameterCount() > options.parameters.size())
  {
    throw std::invalid_argument("sampleGrid: the model has " +
      std::to_string(tape->parameterCount()) + " parameter(s) but " +
      std::to_string(options.parameters.size()) + " value(s) were given");
  }
  // Bricks are longer along x, the row direction, so that per-row work is amortised.
  const std::int64_t edge = std::max(1, options.brickSize);
  const std::array<std::int64_t, 3> brick{ 4 * edge, edge, edge };
  const auto& dims = grid.dimensions;
  std::array<std::int64_t, 3> bricks;
  for (int a = 0; a < 3; ++a)
  {
    bricks[a] = (dims[a] + brick[a] - 1) / brick[a];
  }
  const std::int64_t brickCount = bricks[0] * bricks[1] * bricks[2];

  tbb::enumerable_thread_specific<std::optional<Workspace<T>>> workspaces;
  ProgressScope progress(options.progress);
  ProgressScope::Items sampled = progress.items(brickCount, 0, 1);
  std::atomic<std::int64_t> statPoints{ 0 }, statInstructions{ 0 };

  auto sampleBrick = [&](std::int64_t b)
  {
    auto& slot = workspaces.local();
    if (!slot)
    {
      slot.emplace(tape, options.parameters);
    }
    Workspace<T>& ws = *slot;
    const std::int64_t bi = b % bricks[0], bj = (b / bricks[0]) % bricks[1],
                       bk = b / (bricks[0] * bricks[1]);
    const std::int64_t i0 = bi * brick[0], j0 = bj * brick[1], k0 = bk * brick[2];
    const std::int64_t i1 = std::min(dims[0], i0 + brick[0]), j1 = std::min(dims[1], j0 + brick[1]),
                       k1 = std::min(dims[2], k0 + brick[2]);
    BatchEvaluator<T>* evaluator = &ws.full;
    if (options.prune && tape->choiceCount() > 0)
    {
      Region region;
      const auto& g = grid.first;
      region.axes[0] = { grid.origin[0] + (g[0] + i0) * grid.spacing[0],
        grid.origin[0] + (g[0] + i1 - 1) * grid.spacing[0] };
      region.axes[1] = { grid.origin[1] + (g[1] + j0) * grid.spacing[1],
        grid.origin[1] + (g[1] + j1 - 1) * grid.spacing[1] };
      region.axes[2] = { grid.origin[2] + (g[2] + k0) * grid.spacing[2],
        grid.origin[2] + (g[2] + k1 - 1) * grid.spacing[2] };
      region.axes[3] = { grid.time, grid.time };
      ws.interval.eval(region);
      evaluator = &ws.evaluatorFor(ws.interval.choices());
    }
    if (options.stats)
    {
      const std::int64_t points = (i1 - i0) * (j1 - j0) * (k1 - k0);
      statPoints += points;
      statInstructions +=
        points * static_cast<std::int64_t>(evaluator->tape()->instructions().size());
    }
    for (std::int64_t k = k0; k < k1; ++k)
    {
      const double z = grid.origin[2] + (grid.first[2] + k) * grid.spacing[2];
      for (std::int64_t j = j0; j < j1; ++j)
      {
        const double y = grid.origin[1] + (grid.first[1] + j) * grid.spacing[1];
        // The row's index along x in the whole grid, from which evalRowX computes x.
        writeRow(*evaluator, (k * dims[1] + j) * dims[0] + i0, grid.first[0] + i0,
          static_cast<std::size_t>(i1 - i0), y, z);
      }
    }
  };

  auto body = [&](const tbb::blocked_range<std::int64_t>& range)
  {
    for (std::int64_t b = range.begin(); b != range.end(); ++b)
    {
      if (progress.cancelled())
      {
        return;
      }
      sampleBrick(b);
      sampled.finished();
    }
  };
  // Row evaluation and brick pruning are independent of which thread runs a brick, so the output
  // does not depend on the thread count.
  runOnThreads(options.threads,
    [&] { tbb::parallel_for(tbb::blocked_range<std::int64_t>(0, brickCount, 1), body); });
  if (options.stats)
  {
    options.stats->bricks = brickCount;
    options.stats->pointsEvaluated = statPoints;
    options.stats->instructionEvaluations = statInstructions;
  }
  progress.report(1.0);
}
template <typename T>
void sample(const TapePtr& tape, const Grid& grid, T* out, const SampleOptions& options)
{
  sampleRows<T>(tape, grid, sizeof(T), options,
    [&](BatchEvaluator<T>& evaluator, std::int64_t offset, std::int64_t i0, std::size_t n, double y,
      double z)
    { evaluator.evalRowX(grid.origin[0], grid.spacing[0], i0, y, z, grid.time, out + offset, n); });
}

template <typename T>
void sampleHypervolume(const Hypervolume& hv, const Grid& grid, T* value,
  const std::vector<T*>& attributes, const SampleOptions& options)
{
  if (attributes.size() != hv.attributes().size())
  {
    throw std::invalid_argument("sampleHypervolume: the hypervolume has " +
      std::to_string(hv.attributes().size()) + " attribute(s) but " +
      std::to_string(attributes.size()) + " array(s) were given");
  }
  // One tape for the geometry, the partitions and the attribute functions: what they share is
  // computed once per point.
  const TapePtr tape = hv.compile();
  const std::size_t outputCount = tape->outputs().size();
  const T threshold = static_cast<T>(hv.threshold());
  tbb::enumerable_thread_specific<std::vector<T>> buffers;
  sampleRows<T>(tape, grid, (1 + hv.attributeComponentCount()) * sizeof(T), options,
    [&](BatchEvaluator<T>& evaluator, std::int64_t offset, std::int64_t i0, std::size_t n, double y,
      double z)
    {
      std::vector<T>& buffer = buffers.local();
      buffer.resize(outputCount * n);
      std::vector<T*> rows(outputCount);
      rows[0] = value + offset;
      for (std::size_t k = 1; k < outputCount; ++k)
      {
        rows[k] = buffer.data() + k * n;
      }
      evaluator.evalRowX(
        grid.origin[0], grid.spacing[0], i0, y, z, grid.time, rows.data(), outputCount, n);
      // The default rule of HypervolumeEvaluator (thesis L715, consistent reading).
      const T* f = rows[0];
      std::size_t k = 1;
      for (std::size_t a = 0; a < attributes.size(); ++a)
      {
        const Attribute& attribute = hv.attributes()[a];
        const std::size_t components = attribute.components.size();
        const T* partition = rows[k++];
        T* destination = attributes[a] + offset * static_cast<std::int64_t>(components);
        for (std::size_t c = 0; c < components; ++c, ++k)
        {
          const T* function = rows[k];
          const T inside = static_cast<T>(attribute.insideDefault[c]);
          const T outside = static_cast<T>(attribute.outsideDefault[c]);
          for (std::size_t i = 0; i < n; ++i)
          {
            destination[i * components + c] =
              partition[i] >= 0 ? function[i] : (f[i] >= threshold ? inside : outside);
          }
        }
      }
    });
}
} // namespace

void sampleGrid(const TapePtr& tape, const Grid& grid, float* out, const SampleOptions& options)
{
  sample(tape, grid, out, options);
}

void sampleGrid(const TapePtr& tape, const Grid& grid, double* out, const SampleOptions& options)
{
  sample(tape, grid, out, options);
}

void sampleGrid(const Hypervolume& hv, const Grid& grid, float* value,
  const std::vector<float*>& attributes, const SampleOptions& options)
{
  sampleHypervolume(hv, grid, value, attributes, options);
}

void sampleGrid(const Hypervolume& hv, const Grid& grid, double* value,
  const std::vector<double*>& attributes, const SampleOptions& options)
{
  sampleHypervolume(hv, grid, value, attributes, options);
}

} // namespace ictk::frep
