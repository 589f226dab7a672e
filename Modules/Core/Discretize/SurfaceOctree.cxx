// SPDX-License-Identifier: BSD-3-Clause
// The octree of manifold dual contouring (SurfaceDetail.h): the grid of cells over the box, and
// the descent that visits only the nodes whose interval bound may contain the surface, carrying
// evaluators narrowed to each node (FieldEvaluator::narrowed) down the recursion. Nodes inside
// everywhere are skipped unless they touch the outside padding, where the box closes the solid. The
// descent stops at tasks (handed to the threads) and then at blocks (contoured by BlockContourer);
// both lists come out in octree order, whatever the threads.
#include "Discretize/SurfaceDetail.h"

#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace ictk::discretize::detail::surface
{
namespace
{

enum class NodeKind
{
  Skip,
  Inside, // inside everywhere in the box, but it touches the outside padding
  Mixed
};

NodeKind classify(FieldEvaluator& ev, const Layout& layout, const std::array<int, 3>& o, int size)
{
  if (!layout.intersectsCells(o))
  {
    return NodeKind::Skip;
  }
  const Interval iv = ev.bound(layout.clippedBox(o, size));
  // NaN counts as outside, like a negative value.
  if (iv.empty())
  {
    return iv.maybeNaN ? NodeKind::Skip : NodeKind::Mixed;
  }
  if (iv.hi < 0)
  {
    return NodeKind::Skip;
  }
  if (iv.lo > 0 && !iv.maybeNaN)
  {
    return layout.touchesOutside(o, size) ? NodeKind::Inside : NodeKind::Skip;
  }
  return NodeKind::Mixed;
}

} // namespace

Layout makeLayout(const Box3& box, const SurfaceOptions& options)
{
  const double h = options.featureSize;
  if (!std::isfinite(h) || !(h > 0))
  {
    std::ostringstream os;
    os << "contourSurface: featureSize must be positive and finite (got " << h << ")";
    throw std::invalid_argument(os.str());
  }
  Layout layout;
  layout.h = h;
  long double total = 1;
  for (int a = 0; a < 3; ++a)
  {
    if (!std::isfinite(box.lo[a]) || !std::isfinite(box.hi[a]) || !(box.lo[a] < box.hi[a]))
    {
      std::ostringstream os;
      os << "contourSurface: the box must be finite with lo < hi on every axis (axis " << a << ": ["
         << box.lo[a] << ", " << box.hi[a] << "])";
      throw std::invalid_argument(os.str());
    }
    const double n = (box.hi[a] - box.lo[a]) / h;
    // Points 1..pin at lo + (p - 1) h; the last one may fall on hi up to rounding.
    const double r = std::round(n);
    const double cellsAlong = std::abs(n - r) <= 1e-9 * std::max(1.0, n) ? r : std::floor(n);
    total *= static_cast<long double>(cellsAlong + 2);
    if (cellsAlong + 2 > static_cast<double>(1 << 24))
    {
      total = std::numeric_limits<long double>::infinity();
    }
    layout.pin[a] = static_cast<int>(std::min(cellsAlong, double(1 << 24))) + 1;
    layout.cells[a] = layout.pin[a] + 1;
  }
  if (total > static_cast<long double>(options.maxCells))
  {
    std::ostringstream os;
    os.precision(3);
    os << "contourSurface: featureSize " << h << " needs about " << static_cast<double>(total)
       << " cells over the box, more than maxCells = " << static_cast<double>(options.maxCells);
    throw std::invalid_argument(os.str());
  }
  layout.lo = box.lo;
  for (int a = 0; a < 3; ++a)
  {
    layout.hi[a] = std::max(box.hi[a], layout.coord(a, layout.pin[a]));
  }
  const int largest = std::max({ layout.cells[0], layout.cells[1], layout.cells[2] });
  layout.rootCells = BlockCells;
  while (layout.rootCells < largest)
  {
    layout.rootCells *= 2;
  }
  layout.blocksPerAxis = layout.rootCells / BlockCells;
  return layout;
}

void descend(FieldEvaluator& ev, const Layout& layout, const std::array<int, 3>& o, int size,
  bool knownInside, BlockContourer& contourer, std::vector<std::unique_ptr<Block>>& blocks,
  TaskMemory* memory)
{
  if (size == BlockCells)
  {
    if (knownInside && !layout.touchesOutside(o, size))
    {
      return;
    }
    if (!memory)
    {
      auto block = std::make_unique<Block>();
      if (contourer.run(ev, o, knownInside, *block))
      {
        blocks.push_back(std::move(block));
      }
      return;
    }
    KeptBlock kept;
    kept.key = layout.blockKey(o);
    kept.knownInside = knownInside;
    kept.fingerprinted = !knownInside && ev.fingerprint(kept.fingerprint);
    const KeptBlock* before = memory->find(kept.key);
    if (before &&
      sameWork(knownInside, kept.fingerprinted, kept.fingerprint, before->knownInside,
        before->fingerprinted, before->fingerprint))
    {
      kept.block = before->block;
      if (kept.block)
      {
        blocks.push_back(std::make_unique<Block>(*kept.block));
      }
      ++memory->reused;
    }
    else
    {
      auto block = std::make_unique<Block>();
      if (contourer.run(ev, o, knownInside, *block))
      {
        kept.block = std::make_shared<const Block>(*block);
        blocks.push_back(std::move(block));
      }
      ++memory->contoured;
    }
    memory->next->blocks.push_back(std::move(kept));
    return;
  }
  const int half = size / 2;
  for (int c = 0; c < 8; ++c)
  {
    const std::array<int, 3> child{ o[0] + (c & 1) * half, o[1] + ((c >> 1) & 1) * half,
      o[2] + ((c >> 2) & 1) * half };
    if (!layout.intersectsCells(child))
    {
      continue;
    }
    if (knownInside)
    {
      if (layout.touchesOutside(child, half))
      {
        descend(ev, layout, child, half, true, contourer, blocks, memory);
      }
      continue;
    }
    const NodeKind kind = classify(ev, layout, child, half);
    if (kind == NodeKind::Skip)
    {
      continue;
    }
    if (kind == NodeKind::Inside)
    {
      descend(ev, layout, child, half, true, contourer, blocks, memory);
      continue;
    }
    std::unique_ptr<FieldEvaluator> narrowed = ev.narrowed(layout.clippedBox(child, half));
    descend(narrowed ? *narrowed : ev, layout, child, half, false, contourer, blocks, memory);
  }
}

void collectTasks(FieldEvaluator& ev, const Layout& layout, const std::array<int, 3>& o, int size,
  std::vector<Task>& tasks)
{
  const NodeKind kind = classify(ev, layout, o, size);
  if (kind == NodeKind::Skip)
  {
    return;
  }
  if (size <= TaskCells || kind == NodeKind::Inside)
  {
    tasks.push_back({ o, size, kind == NodeKind::Inside });
    return;
  }
  const int half = size / 2;
  for (int c = 0; c < 8; ++c)
  {
    collectTasks(ev, layout,
      { o[0] + (c & 1) * half, o[1] + ((c >> 1) & 1) * half, o[2] + ((c >> 2) & 1) * half }, half,
      tasks);
  }
}

} // namespace ictk::discretize::detail::surface
