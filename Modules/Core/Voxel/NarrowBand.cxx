// SPDX-License-Identifier: BSD-3-Clause
#include "Voxel/NarrowBand.h"
#include "Voxel/VdbDetail.h"

#include "FRep/Evaluators.h"
#include "FRep/Threads.h"

#include <openvdb/tools/SignedFloodFill.h>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <optional>
#include <stdexcept>

namespace ictk::voxel
{

struct NarrowBandGrid::Impl
{
  openvdb::FloatGrid::Ptr vdb;
  frep::Grid grid;
  double band = 0;
  NarrowBandStats stats;
};

namespace
{
using Leaf = openvdb::FloatTree::LeafNodeType;
constexpr std::int64_t LeafEdge = Leaf::DIM; // 8
// Edge of the octrees' roots: a block is the unit of parallel work and of progress.
constexpr std::int64_t BlockEdge = 64;

// One tape with its evaluators, made when a node first needs them.
struct NodeTape
{
  explicit NodeTape(frep::TapePtr t, const std::vector<double>& parameters)
    : tape(std::move(t))
    , interval(tape, parameters)
  {
  }
  frep::BatchEvaluator<float>& points(const std::vector<double>& parameters)
  {
    if (!batch)
    {
      batch.emplace(tape, parameters);
    }
    return *batch;
  }
  frep::TapePtr tape;
  frep::IntervalEvaluator interval;
  std::optional<frep::BatchEvaluator<float>> batch;
};

struct Counters
{
  std::atomic<std::int64_t> intervals{ 0 }, sampled{ 0 }, kept{ 0 }, points{ 0 };
};

class Descent
{
public:
  Descent(
    const frep::Grid& grid, float band, const std::vector<double>& parameters, Counters& counters)
    : grid_(grid)
    , band_(band)
    , parameters_(parameters)
    , counters_(counters)
  {
  }

  /// Visits the node of edge `edge` at point index `lo` with `node`'s tape; appends its kept
  /// leaves to `leaves`.
  void visit(NodeTape& node, const std::array<std::int64_t, 3>& lo, std::int64_t edge,
    std::vector<Leaf*>& leaves)
  {
    std::array<std::int64_t, 3> hi;
    for (int a = 0; a < 3; ++a)
    {
      if (lo[a] >= grid_.dimensions[a])
      {
        return;
      }
      hi[a] = std::min(grid_.dimensions[a], lo[a] + edge) - 1;
    }
    frep::Region region;
    for (int a = 0; a < 3; ++a)
    {
      region.axes[a] = { coordinate(a, lo[a]), coordinate(a, hi[a]) };
    }
    region.axes[3] = { grid_.time, grid_.time };
    const frep::Interval bound = node.interval.eval(region);
    ++counters_.intervals;
    if (bound.lo > band_ || bound.hi < -band_)
    {
      return; // no point of the node is in the band
    }
    if (edge == LeafEdge)
    {
      sampleLeaf(node, lo, leaves);
      return;
    }
    // Children of a node with min/max get the tape pruned for it; the leaves (edge 8) are
    // bounded for culling only and sampled with their parent's tape, so that an evaluator is
    // prepared per 16^3 node at most.
    std::optional<NodeTape> pruned;
    NodeTape* childTape = &node;
    if (node.tape->choiceCount() > 0 && edge / 2 > LeafEdge)
    {
      frep::TapePtr simplified = node.interval.simplified();
      if (simplified->instructions().size() < node.tape->instructions().size())
      {
        pruned.emplace(std::move(simplified), parameters_);
        childTape = &*pruned;
      }
    }
    const std::int64_t half = edge / 2;
    for (int c = 0; c < 8; ++c)
    {
      visit(*childTape,
        { lo[0] + (c & 1) * half, lo[1] + ((c >> 1) & 1) * half, lo[2] + ((c >> 2) & 1) * half },
        half, leaves);
    }
  }

private:
  // The coordinate of point index i along axis a, computed as frep::sampleGrid computes it.
  double coordinate(int a, std::int64_t i) const
  {
    return grid_.origin[a] + (grid_.first[a] + i) * grid_.spacing[a];
  }

  void sampleLeaf(NodeTape& node, const std::array<std::int64_t, 3>& lo, std::vector<Leaf*>& leaves)
  {
    frep::BatchEvaluator<float>& evaluator = node.points(parameters_);
    const std::int64_t nx = std::min(LeafEdge, grid_.dimensions[0] - lo[0]);
    const std::int64_t ny = std::min(LeafEdge, grid_.dimensions[1] - lo[1]);
    const std::int64_t nz = std::min(LeafEdge, grid_.dimensions[2] - lo[2]);
    auto leaf = std::make_unique<Leaf>(
      openvdb::Coord(static_cast<openvdb::Int32>(lo[0]), static_cast<openvdb::Int32>(lo[1]),
        static_cast<openvdb::Int32>(lo[2])),
      -band_, false);
    float row[LeafEdge];
    bool any = false;
    for (std::int64_t k = 0; k < nz; ++k)
    {
      const double z = coordinate(2, lo[2] + k);
      for (std::int64_t j = 0; j < ny; ++j)
      {
        const double y = coordinate(1, lo[1] + j);
        evaluator.evalRowX(grid_.origin[0], grid_.spacing[0], grid_.first[0] + lo[0], y, z,
          grid_.time, row, static_cast<std::size_t>(nx));
        for (std::int64_t i = 0; i < nx; ++i)
        {
          // OpenVDB's leaf order: z fastest.
          const openvdb::Index offset = static_cast<openvdb::Index>((i << 6) | (j << 3) | k);
          const float v = row[i];
          if (std::abs(v) <= band_)
          {
            leaf->setValueOn(offset, v);
            any = true;
          }
          else
          {
            leaf->setValueOff(offset, v > 0 ? band_ : -band_);
          }
        }
      }
    }
    ++counters_.sampled;
    counters_.points += nx * ny * nz;
    if (any)
    {
      ++counters_.kept;
      leaves.push_back(leaf.release());
    }
  }

  const frep::Grid& grid_;
  const float band_;
  const std::vector<double>& parameters_;
  Counters& counters_;
};

} // namespace

std::int64_t NarrowBandGrid::activeVoxelCount() const
{
  return static_cast<std::int64_t>(impl_->vdb->activeVoxelCount());
}

std::size_t NarrowBandGrid::memoryBytes() const
{
  return static_cast<std::size_t>(impl_->vdb->memUsage());
}

double NarrowBandGrid::band() const
{
  return impl_->band;
}

const frep::Grid& NarrowBandGrid::grid() const
{
  return impl_->grid;
}

const NarrowBandStats& NarrowBandGrid::stats() const
{
  return impl_->stats;
}

float NarrowBandGrid::value(const std::array<std::int64_t, 3>& ijk, bool* active) const
{
  const openvdb::Coord c(static_cast<openvdb::Int32>(ijk[0]), static_cast<openvdb::Int32>(ijk[1]),
    static_cast<openvdb::Int32>(ijk[2]));
  const openvdb::FloatTree& tree = impl_->vdb->tree();
  if (active)
  {
    *active = tree.isValueOn(c);
  }
  return tree.getValue(c);
}

void NarrowBandGrid::forEachActive(
  const std::function<void(const std::array<std::int64_t, 3>&, float)>& visit) const
{
  for (auto it = impl_->vdb->cbeginValueOn(); it; ++it)
  {
    // Narrow-band grids have no active tiles: every active value is a voxel.
    const openvdb::Coord c = it.getCoord();
    visit({ c.x(), c.y(), c.z() }, *it);
  }
}

void NarrowBandGrid::write(const std::string& path, const std::string& gridName) const
{
  const std::string where = "sampleNarrowBand: '" + path + "'";
  if (gridName.empty())
  {
    throw std::invalid_argument(where + ": the grid name is empty");
  }
  // A shallow copy shares the tree: only the name and metadata are the file's.
  openvdb::FloatGrid::Ptr named = impl_->vdb->copy();
  named->setName(gridName);
  detail::writeAtomically(named, path, where);
}

NarrowBandGrid sampleNarrowBand(
  const frep::TapePtr& tape, const frep::Grid& grid, const NarrowBandOptions& options)
{
  frep::checkGrid(grid, 0);
  for (int a = 0; a < 3; ++a)
  {
    if (grid.dimensions[a] > std::int64_t(1) << 30)
    {
      throw std::invalid_argument("sampleNarrowBand: too many points along an axis for OpenVDB");
    }
  }
  if (tape->parameterCount() > options.parameters.size())
  {
    throw std::invalid_argument("sampleNarrowBand: the model has " +
      std::to_string(tape->parameterCount()) + " parameter(s) but " +
      std::to_string(options.parameters.size()) + " value(s) were given");
  }
  const double band = options.band == 0
    ? 3 * std::max({ grid.spacing[0], grid.spacing[1], grid.spacing[2] })
    : options.band;
  if (!std::isfinite(band) || !(band > 0) || band > 3e38)
  {
    throw std::invalid_argument("sampleNarrowBand: the band must be finite and positive");
  }
  detail::initialiseOpenVdb();

  std::array<std::int64_t, 3> blocks;
  for (int a = 0; a < 3; ++a)
  {
    blocks[a] = (grid.dimensions[a] + BlockEdge - 1) / BlockEdge;
  }
  const std::int64_t blockCount = blocks[0] * blocks[1] * blocks[2];
  std::vector<std::vector<Leaf*>> leaves(static_cast<std::size_t>(blockCount));
  Counters counters;
  const float bandF = static_cast<float>(band);
  tbb::enumerable_thread_specific<std::optional<NodeTape>> roots;
  ProgressScope progress(options.progress);
  ProgressScope::Items done = progress.items(blockCount, 0, 0.95);
  auto body = [&](const tbb::blocked_range<std::int64_t>& range)
  {
    auto& root = roots.local();
    if (!root)
    {
      root.emplace(tape, options.parameters);
    }
    Descent descent(grid, bandF, options.parameters, counters);
    for (std::int64_t b = range.begin(); b != range.end(); ++b)
    {
      if (progress.cancelled())
      {
        return;
      }
      const std::array<std::int64_t, 3> lo{ (b % blocks[0]) * BlockEdge,
        (b / blocks[0] % blocks[1]) * BlockEdge, b / (blocks[0] * blocks[1]) * BlockEdge };
      descent.visit(*root, lo, BlockEdge, leaves[static_cast<std::size_t>(b)]);
      done.finished();
    }
  };
  auto result = std::make_shared<NarrowBandGrid::Impl>();
  try
  {
    runOnThreads(options.threads,
      [&] { tbb::parallel_for(tbb::blocked_range<std::int64_t>(0, blockCount, 1), body); });
    progress.report(0.95);
    result->vdb = openvdb::FloatGrid::create(-bandF);
    openvdb::FloatTree& tree = result->vdb->tree();
    for (std::vector<Leaf*>& block : leaves)
    {
      for (Leaf*& leaf : block)
      {
        tree.addLeaf(leaf); // takes ownership
        leaf = nullptr;
      }
    }
  }
  catch (...)
  {
    for (const std::vector<Leaf*>& block : leaves)
    {
      for (Leaf* leaf : block)
      {
        delete leaf;
      }
    }
    throw;
  }
  // Inactive voxels and tiles take +band where the field is positive (inside) and -band where it
  // is negative (outside), from the signs of the active voxels around them.
  openvdb::tools::signedFloodFillWithValues(result->vdb->tree(), bandF, bandF);
  // The flood fill makes the background OpenVDB's "outside" (positive); ICTK's outside is negative.
  result->vdb->tree().root().setBackground(-bandF, false);
  // Index (0, 0, 0) is the grid's first point.
  std::array<double, 3> origin;
  for (int a = 0; a < 3; ++a)
  {
    origin[a] = grid.origin[a] + grid.first[a] * grid.spacing[a];
  }
  result->vdb->setTransform(detail::gridTransform(origin, grid.spacing));
  result->vdb->insertMeta("ictk_band", openvdb::DoubleMetadata(band));
  result->grid = grid;
  result->band = band;
  result->stats.intervalEvaluations = counters.intervals;
  result->stats.leavesSampled = counters.sampled;
  result->stats.leavesKept = counters.kept;
  result->stats.pointsEvaluated = counters.points;
  progress.report(1.0);
  NarrowBandGrid out;
  out.impl_ = std::move(result);
  return out;
}

} // namespace ictk::voxel
