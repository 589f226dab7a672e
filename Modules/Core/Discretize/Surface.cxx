// SPDX-License-Identifier: BSD-3-Clause
// contourSurface (Surface.h): manifold dual contouring over an interval-pruned octree, whose
// pieces SurfaceDetail.h lists. This file runs them and assembles the mesh:
//  1. The octree is descended sequentially to tasks; each task (in parallel) descends to its
//     blocks and contours them (Hermite data and one vertex per patch component of each cell).
//  2. The blocks are sorted by position (the output does not depend on the threads), the rare
//     non-manifold configurations are repaired by splitting a vertex, vertices are numbered block
//     by block, and each sign-changing edge becomes a quad of the vertices of the four cells
//     around it, split along the diagonal whose triangles face most along the edge.
#include "Discretize/Surface.h"

#include "Discretize/SurfaceDetail.h"
#include "FRep/Threads.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <utility>
#include <vector>

namespace ictk::discretize
{
namespace
{

using namespace detail::surface;

double triangleScore(const Point3& a, const Point3& b, const Point3& c, int axis, double sign)
{
  const double u[3] = { b[0] - a[0], b[1] - a[1], b[2] - a[2] };
  const double v[3] = { c[0] - a[0], c[1] - a[1], c[2] - a[2] };
  const double n[3] = { u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
    u[0] * v[1] - u[1] * v[0] };
  const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  return len > 0 ? sign * n[axis] / len : -2.0;
}

/// The quads of the sign-changing edges owned by the block (the edges at corner 0 of its cells).
void emitQuads(Block& block, std::vector<std::unique_ptr<Block>>& blocks, const BlockIndex& index,
  const Layout& layout, const std::vector<Point3>& points)
{
  // Neighbour blocks on the negative sides, by (dx | dy << 1 | dz << 2).
  Block* neighbour[8];
  for (int d = 0; d < 8; ++d)
  {
    std::array<int, 3> o = block.origin;
    bool valid = true;
    for (int a = 0; a < 3; ++a)
    {
      if ((d >> a) & 1)
      {
        o[a] -= BlockCells;
        valid = valid && o[a] >= 0;
      }
    }
    const std::int64_t b = valid ? index.find(layout.blockKey(o)) : -1;
    neighbour[d] = b >= 0 ? blocks[b].get() : nullptr;
  }
  auto vertexOf = [&](const std::array<int, 3>& l, int edge) -> std::int64_t
  {
    int d = 0;
    int m[3];
    for (int a = 0; a < 3; ++a)
    {
      m[a] = l[a];
      if (l[a] < 0)
      {
        d |= 1 << a;
        m[a] += BlockCells;
      }
    }
    const Block* b = neighbour[d];
    if (!b)
    {
      return -1;
    }
    const std::uint16_t s = b->slot[m[0] + BlockCells * (m[1] + BlockCells * m[2])];
    if (s == NoVertex || b->cells[s].edgeVertex[edge] == NoVertex)
    {
      return -1;
    }
    return static_cast<std::int64_t>(b->vertexOffset) + b->cells[s].edgeVertex[edge];
  };
  for (const CellRecord& cell : block.cells)
  {
    const std::array<int, 3> l{ cell.local % BlockCells, (cell.local / BlockCells) % BlockCells,
      cell.local / (BlockCells * BlockCells) };
    for (int a = 0; a < 3; ++a)
    {
      const bool in0 = inside(cell.mask, 0);
      if (in0 == inside(cell.mask, 1 << a))
      {
        continue;
      }
      const int b = OtherAxes[a][0], c = OtherAxes[a][1];
      // The four cells around the edge, counter-clockwise in the (b, c) plane.
      static constexpr int ring[4][2] = { { 0, 0 }, { 1, 0 }, { 1, 1 }, { 0, 1 } };
      std::int64_t q[4];
      bool complete = true;
      for (int r = 0; r < 4; ++r)
      {
        std::array<int, 3> m = l;
        m[b] -= ring[r][0];
        m[c] -= ring[r][1];
        q[r] = vertexOf(m, 4 * a + ring[r][0] + 2 * ring[r][1]);
        complete = complete && q[r] >= 0;
      }
      if (!complete)
      {
        continue; // cannot happen for an exact field evaluator
      }
      // The ring's normal is +a for a = x, z and -a for a = y (b x c); the surface normal points
      // from the inside end of the edge to the outside one.
      const double ringSign = a == 1 ? -1.0 : 1.0;
      const double want = in0 ? 1.0 : -1.0;
      if (ringSign != want)
      {
        std::swap(q[1], q[3]);
      }
      const Point3 &p0 = points[q[0]], &p1 = points[q[1]], &p2 = points[q[2]], &p3 = points[q[3]];
      const double split02 =
        std::min(triangleScore(p0, p1, p2, a, want), triangleScore(p0, p2, p3, a, want));
      const double split13 =
        std::min(triangleScore(p1, p2, p3, a, want), triangleScore(p1, p3, p0, a, want));
      const auto v = [&](int r)
      {
        return static_cast<std::uint32_t>(q[r]);
      };
      if (split02 >= split13)
      {
        block.triangles.push_back({ v(0), v(1), v(2) });
        block.triangles.push_back({ v(0), v(2), v(3) });
      }
      else
      {
        block.triangles.push_back({ v(1), v(2), v(3) });
        block.triangles.push_back({ v(1), v(3), v(0) });
      }
    }
  }
}

bool sameGrid(const SurfaceMemory::State& kept, const Layout& layout, bool sharp)
{
  return kept.valid && kept.lo == layout.lo && kept.h == layout.h && kept.pin == layout.pin &&
    kept.sharp == sharp;
}

/// The previous call's tasks by place.
std::map<std::pair<std::array<int, 3>, int>, std::size_t> tasksByPlace(
  const SurfaceMemory::State& kept)
{
  std::map<std::pair<std::array<int, 3>, int>, std::size_t> index;
  for (std::size_t t = 0; t < kept.tasks.size(); ++t)
  {
    index.emplace(std::make_pair(kept.tasks[t].origin, kept.tasks[t].size), t);
  }
  return index;
}

} // namespace

SurfaceMemory::SurfaceMemory()
  : state_(std::make_unique<State>())
{
}

SurfaceMemory::~SurfaceMemory() = default;

void SurfaceMemory::clear()
{
  *state_ = State{};
  last_ = {};
}

SurfaceMesh contourSurface(
  const frep::Field& field, const frep::Box3& box, const SurfaceOptions& options)
{
  detail::countMeshMade();
  const Layout layout = makeLayout(box, options);
  caseTable(); // built once, before the threads need it

  std::vector<Task> tasks;
  {
    auto ev = field.evaluator();
    collectTasks(*ev, layout, { 0, 0, 0 }, layout.rootCells, tasks);
  }

  // Time coherence: the previous call's tasks, when they were made on this grid, and this call's.
  SurfaceMemory* memory = options.memory;
  if (memory && !sameGrid(memory->state(), layout, options.sharpFeatures))
  {
    memory->clear();
  }
  const SurfaceMemory::State* before = memory ? &memory->state() : nullptr;
  const auto previousTasks =
    before ? tasksByPlace(*before) : std::map<std::pair<std::array<int, 3>, int>, std::size_t>{};
  std::vector<KeptTask> keptTasks(memory ? tasks.size() : 0);
  std::vector<SurfaceReuse> taskReuse(memory ? tasks.size() : 0);

  std::vector<std::vector<std::unique_ptr<Block>>> taskBlocks(tasks.size());
  struct ThreadState
  {
    std::unique_ptr<FieldEvaluator> evaluator;
    std::unique_ptr<BlockContourer> contourer;
  };
  tbb::enumerable_thread_specific<ThreadState> states;
  ProgressScope progress(options.progress);
  // Contouring is ~90% of the time; assembly the rest.
  constexpr double contourShare = 0.9;
  ProgressScope::Items contoured =
    progress.items(static_cast<std::int64_t>(tasks.size()), 0, contourShare);

  auto runTask = [&](std::size_t t)
  {
    ThreadState& state = states.local();
    if (!state.evaluator)
    {
      state.evaluator = field.evaluator();
      state.contourer = std::make_unique<BlockContourer>(layout, options.sharpFeatures);
    }
    const Task& task = tasks[t];
    std::unique_ptr<FieldEvaluator> narrowed;
    if (!task.knownInside)
    {
      narrowed = state.evaluator->narrowed(layout.clippedBox(task.origin, task.size));
    }
    FieldEvaluator& ev = narrowed ? *narrowed : *state.evaluator;
    if (!memory)
    {
      descend(
        ev, layout, task.origin, task.size, task.knownInside, *state.contourer, taskBlocks[t]);
      return;
    }
    KeptTask& kept = keptTasks[t];
    kept.origin = task.origin;
    kept.size = task.size;
    kept.knownInside = task.knownInside;
    kept.fingerprinted = !task.knownInside && ev.fingerprint(kept.fingerprint);
    const auto found = previousTasks.find(std::make_pair(task.origin, task.size));
    const KeptTask* previous =
      found != previousTasks.end() ? &before->tasks[found->second] : nullptr;
    SurfaceReuse& reuse = taskReuse[t];
    if (previous &&
      sameWork(task.knownInside, kept.fingerprinted, kept.fingerprint, previous->knownInside,
        previous->fingerprinted, previous->fingerprint))
    {
      // The same evaluator over the whole node: its descent would take the same path to the
      // same blocks.
      kept.blocks = previous->blocks;
      for (const KeptBlock& b : kept.blocks)
      {
        if (b.block)
        {
          taskBlocks[t].push_back(std::make_unique<Block>(*b.block));
        }
      }
      reuse.blocksReused = kept.blocks.size();
      reuse.tasksReused = 1;
      return;
    }
    TaskMemory taskMemory;
    taskMemory.previous = previous;
    taskMemory.next = &kept;
    if (previous)
    {
      taskMemory.byKey.reserve(previous->blocks.size());
      for (std::size_t b = 0; b < previous->blocks.size(); ++b)
      {
        taskMemory.byKey.emplace_back(previous->blocks[b].key, b);
      }
      std::sort(taskMemory.byKey.begin(), taskMemory.byKey.end());
    }
    descend(ev, layout, task.origin, task.size, task.knownInside, *state.contourer, taskBlocks[t],
      &taskMemory);
    reuse.blocksContoured = taskMemory.contoured;
    reuse.blocksReused = taskMemory.reused;
  };
  auto body = [&](const tbb::blocked_range<std::size_t>& range)
  {
    for (std::size_t t = range.begin(); t != range.end(); ++t)
    {
      if (progress.cancelled())
      {
        return;
      }
      runTask(t);
      contoured.finished();
    }
  };

  std::vector<std::unique_ptr<Block>> blocks;
  std::vector<std::uint32_t> triangleOffset;
  SurfaceMesh mesh;
  auto run = [&]
  {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, tasks.size(), 1), body);
    progress.report(contourShare);
    for (auto& list : taskBlocks)
    {
      for (auto& b : list)
      {
        blocks.push_back(std::move(b));
      }
    }
    std::sort(blocks.begin(), blocks.end(),
      [](const std::unique_ptr<Block>& x, const std::unique_ptr<Block>& y)
      { return x->key < y->key; });
    const BlockIndex index(blocks);
    splitVertices(blocks, index, layout, options.sharpFeatures);
    std::size_t vertexCount = 0;
    for (auto& b : blocks)
    {
      b->vertexOffset = static_cast<std::uint32_t>(vertexCount);
      vertexCount += b->vertices.size();
    }
    mesh.points.resize(vertexCount);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, blocks.size()),
      [&](const tbb::blocked_range<std::size_t>& range)
      {
        for (std::size_t b = range.begin(); b != range.end(); ++b)
        {
          std::copy(blocks[b]->vertices.begin(), blocks[b]->vertices.end(),
            mesh.points.begin() + blocks[b]->vertexOffset);
        }
      });
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, blocks.size()),
      [&](const tbb::blocked_range<std::size_t>& range)
      {
        for (std::size_t b = range.begin(); b != range.end(); ++b)
        {
          emitQuads(*blocks[b], blocks, index, layout, mesh.points);
        }
      });
    std::size_t triangleCount = 0;
    triangleOffset.resize(blocks.size());
    for (std::size_t b = 0; b < blocks.size(); ++b)
    {
      triangleOffset[b] = static_cast<std::uint32_t>(triangleCount);
      triangleCount += blocks[b]->triangles.size();
    }
    mesh.triangles.resize(triangleCount);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, blocks.size()),
      [&](const tbb::blocked_range<std::size_t>& range)
      {
        for (std::size_t b = range.begin(); b != range.end(); ++b)
        {
          std::copy(blocks[b]->triangles.begin(), blocks[b]->triangles.end(),
            mesh.triangles.begin() + triangleOffset[b]);
        }
      });
  };
  runOnThreads(options.threads, run);
  if (memory)
  {
    // Kept only once the call has succeeded (a cancelled call keeps the previous state).
    SurfaceReuse total;
    total.tasks = tasks.size();
    for (const SurfaceReuse& r : taskReuse)
    {
      total.blocksContoured += r.blocksContoured;
      total.blocksReused += r.blocksReused;
      total.tasksReused += r.tasksReused;
    }
    SurfaceMemory::State& state = memory->state();
    state.valid = true;
    state.lo = layout.lo;
    state.h = layout.h;
    state.pin = layout.pin;
    state.sharp = options.sharpFeatures;
    state.tasks = std::move(keptTasks);
    memory->setLastCall(total);
  }
  progress.report(1.0);
  return mesh;
}

} // namespace ictk::discretize
