// SPDX-License-Identifier: BSD-3-Clause
// multiMaterialSurface (MultiMaterial.h): the label of every grid point, then the triangles
// (MultiMaterialTetra.cxx) and their vertices' positions (MultiMaterialVertices.cxx), assembled
// here with the regions of each label. Blocks whose interval bounds decide a single label are
// neither sampled nor triangulated (except for their box caps).
#include "Discretize/MultiMaterial.h"

#include "Discretize/MultiMaterialDetail.h"
#include "FRep/Threads.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>

namespace ictk::discretize
{

using namespace detail::material;

namespace
{

// Blocks of this many cells per axis: the unit of interval pruning and of parallel work.
constexpr std::int64_t kBlock = 8;

} // namespace

double materialVolume(const MaterialSurface& surface, int label)
{
  double volume = 0;
  for (std::size_t t = 0; t < surface.triangles.size(); ++t)
  {
    const auto& tri = surface.triangles[t];
    const Point3& a = surface.points[tri[0]];
    const Point3& b = surface.points[tri[1]];
    const Point3& c = surface.points[tri[2]];
    const double v = dot(a, cross(b, c)) / 6;
    if (surface.labels[t][0] == label)
    {
      volume += v;
    }
    if (surface.labels[t][1] == label)
    {
      volume -= v;
    }
  }
  return volume;
}

MaterialSurface multiMaterialSurface(const std::vector<frep::FieldPtr>& solids,
  const std::vector<double>& priorities, const Box3& box, double size,
  const MultiMaterialOptions& o)
{
  detail::countMeshMade();
  for (int a = 0; a < 3; ++a)
  {
    if (!std::isfinite(box.lo[a]) || !std::isfinite(box.hi[a]) || !(box.lo[a] < box.hi[a]))
    {
      throw std::invalid_argument("multiMaterialSurface: the box must be finite with lo < hi");
    }
  }
  if (!(size > 0) || !std::isfinite(size))
  {
    throw std::invalid_argument("multiMaterialSurface: the size must be a positive number");
  }
  if (solids.size() > 32766)
  {
    throw std::invalid_argument("multiMaterialSurface: at most 32766 solids");
  }
  if (!priorities.empty() && priorities.size() != solids.size())
  {
    throw std::invalid_argument("multiMaterialSurface: " + std::to_string(priorities.size()) +
      " priorities for " + std::to_string(solids.size()) + " solids");
  }
  for (std::size_t s = 0; s < solids.size(); ++s)
  {
    if (!solids[s])
    {
      throw std::invalid_argument("multiMaterialSurface: solid " + std::to_string(s) + " is null");
    }
  }
  const int count = static_cast<int>(solids.size());
  auto priority = [&](int s)
  {
    return priorities.empty() ? 0.0 : priorities[std::size_t(s)];
  };

  Ranking rank;
  rank.order.resize(solids.size());
  std::iota(rank.order.begin(), rank.order.end(), 0);
  std::stable_sort(
    rank.order.begin(), rank.order.end(), [&](int a, int b) { return priority(a) > priority(b); });
  rank.rankOfLabel.assign(solids.size() + 1, 0);
  for (int r = 0; r < count; ++r)
  {
    rank.rankOfLabel[std::size_t(rank.order[std::size_t(r)]) + 1] = count - r;
  }

  Grid g;
  g.lo = box.lo;
  g.hi = box.hi;
  double cells = 1;
  for (int a = 0; a < 3; ++a)
  {
    const double length = box.hi[a] - box.lo[a];
    const double m = std::max(1.0, std::round(length / size));
    if (m > 1e7)
    {
      throw std::invalid_argument(
        "multiMaterialSurface: size " + std::to_string(size) + " is too small for this box");
    }
    g.h[a] = length / m;
    g.n[a] = static_cast<std::int64_t>(m) + 2;
    cells *= m + 1;
  }
  if (cells > o.maxCells)
  {
    throw std::invalid_argument("multiMaterialSurface: size " + std::to_string(size) +
      " over this box needs " + std::to_string(cells) + " grid cells, more than the limit of " +
      std::to_string(o.maxCells));
  }
  const std::size_t pointCount = static_cast<std::size_t>(g.n[0] * g.n[1] * g.n[2]);
  std::vector<Label> labels(pointCount, 0);

  std::array<std::int64_t, 3> nc{ g.n[0] - 1, g.n[1] - 1, g.n[2] - 1 }; // cells per axis
  std::array<std::int64_t, 3> blocks{};
  for (int a = 0; a < 3; ++a)
  {
    blocks[a] = (nc[a] + kBlock - 1) / kBlock;
  }
  const std::int64_t blockCount = blocks[0] * blocks[1] * blocks[2];
  std::vector<char> needsContour(static_cast<std::size_t>(blockCount), 0);
  std::vector<BlockOut> results(static_cast<std::size_t>(blockCount));
  ProgressScope progress(o.progress);
  auto blockRange =
    [&](std::int64_t b, std::array<std::int64_t, 3>& first, std::array<std::int64_t, 3>& extent)
  {
    const std::array<std::int64_t, 3> bc{ b % blocks[0], (b / blocks[0]) % blocks[1],
      b / (blocks[0] * blocks[1]) };
    for (int a = 0; a < 3; ++a)
    {
      first[a] = bc[a] * kBlock;
      extent[a] = std::min(kBlock, nc[a] - first[a]);
    }
  };

  // Phase 1: labels of the grid points, sampled only in blocks the intervals cannot decide.
  ProgressScope::Items labelled = progress.items(blockCount, 0, 0.4);
  runOnThreads(o.threads,
    [&]
    {
      tbb::parallel_for(tbb::blocked_range<std::int64_t>(0, blockCount, 1),
        [&](const tbb::blocked_range<std::int64_t>& range)
        {
          Evaluators ev(solids);
          std::vector<double> xs, ys, zs;
          std::vector<std::vector<double>> values(solids.size());
          std::vector<frep::Interval> bounds(solids.size());
          std::vector<char> out(solids.size()), in(solids.size());
          for (std::int64_t b = range.begin(); b != range.end(); ++b)
          {
            if (progress.cancelled())
            {
              return;
            }
            std::array<std::int64_t, 3> f0, ext;
            blockRange(b, f0, ext);
            Box3 bb;
            for (int a = 0; a < 3; ++a)
            {
              bb.lo[a] = g.coord(a, f0[a]);
              bb.hi[a] = g.coord(a, f0[a] + ext[a]);
            }
            const bool touchesBox = f0[0] == 0 || f0[1] == 0 || f0[2] == 0 ||
              f0[0] + ext[0] == nc[0] || f0[1] + ext[1] == nc[1] || f0[2] + ext[2] == nc[2];
            for (int s = 0; s < count; ++s)
            {
              const frep::Interval iv = ev.of(s).bound(bb);
              out[std::size_t(s)] = iv.empty() || (!iv.maybeNaN && iv.hi < 0);
              in[std::size_t(s)] = !iv.empty() && !iv.maybeNaN && iv.lo >= 0;
            }
            int constant = 0; // label when decided
            bool ambiguous = false;
            for (int s : rank.order)
            {
              if (out[std::size_t(s)])
              {
                continue;
              }
              if (in[std::size_t(s)])
              {
                constant = s + 1;
                for (int t = 0; t < count; ++t)
                {
                  if (t != s && priority(t) == priority(s) && !out[std::size_t(t)])
                  {
                    ambiguous = true; // may overlap: sample to find out
                  }
                }
              }
              else
              {
                ambiguous = true;
              }
              break;
            }
            // Owned points: the block's cells' lower corners, plus the last layer at the end.
            std::array<std::int64_t, 3> own;
            for (int a = 0; a < 3; ++a)
            {
              own[a] = ext[a] + (f0[a] + ext[a] == nc[a] ? 1 : 0);
            }
            if (!ambiguous)
            {
              for (std::int64_t k = 0; k < own[2]; ++k)
              {
                for (std::int64_t j = 0; j < own[1]; ++j)
                {
                  for (std::int64_t i = 0; i < own[0]; ++i)
                  {
                    const std::int64_t gi = f0[0] + i, gj = f0[1] + j, gk = f0[2] + k;
                    labels[g.index(gi, gj, gk)] = static_cast<Label>(constant);
                  }
                }
              }
              needsContour[std::size_t(b)] = touchesBox && constant != 0;
              labelled.finished();
              continue;
            }
            needsContour[std::size_t(b)] = 1;
            const auto n = static_cast<std::size_t>(own[0] * own[1] * own[2]);
            xs.resize(n);
            ys.resize(n);
            zs.resize(n);
            std::size_t c = 0;
            for (std::int64_t k = 0; k < own[2]; ++k)
            {
              for (std::int64_t j = 0; j < own[1]; ++j)
              {
                for (std::int64_t i = 0; i < own[0]; ++i, ++c)
                {
                  xs[c] = g.coord(0, f0[0] + i);
                  ys[c] = g.coord(1, f0[1] + j);
                  zs[c] = g.coord(2, f0[2] + k);
                }
              }
            }
            for (int s = 0; s < count; ++s)
            {
              if (out[std::size_t(s)])
              {
                continue;
              }
              auto& v = values[std::size_t(s)];
              v.resize(n);
              auto narrowed = ev.of(s).narrowed(bb);
              (narrowed ? *narrowed : ev.of(s))
                .values(xs.data(), ys.data(), zs.data(), v.data(), n);
            }
            BlockOut& result = results[std::size_t(b)];
            c = 0;
            for (std::int64_t k = 0; k < own[2]; ++k)
            {
              for (std::int64_t j = 0; j < own[1]; ++j)
              {
                for (std::int64_t i = 0; i < own[0]; ++i, ++c)
                {
                  const std::int64_t gi = f0[0] + i, gj = f0[1] + j, gk = f0[2] + k;
                  int label = 0;
                  for (int s : rank.order)
                  {
                    if (!out[std::size_t(s)] && insideValue(values[std::size_t(s)][c]))
                    {
                      label = s + 1;
                      break;
                    }
                  }
                  labels[g.index(gi, gj, gk)] = static_cast<Label>(label);
                  if (label == 0 || !(values[std::size_t(label - 1)][c] > 0))
                  {
                    continue;
                  }
                  for (int t = 0; t < count; ++t)
                  {
                    if (t != label - 1 && !out[std::size_t(t)] &&
                      priority(t) == priority(label - 1) && values[std::size_t(t)][c] > 0)
                    {
                      const int first = std::min(t, label - 1), second = std::max(t, label - 1);
                      const bool known = std::any_of(result.overlaps.begin(), result.overlaps.end(),
                        [&](const MaterialOverlap& m)
                        { return m.first == first && m.second == second; });
                      if (!known)
                      {
                        result.overlaps.push_back({ first, second, { xs[c], ys[c], zs[c] } });
                      }
                    }
                  }
                }
              }
            }
            labelled.finished();
          }
        });
    });
  progress.report(0.4);

  // Phase 2: triangles of the blocks with more than one label, as vertex keys.
  runOnThreads(o.threads,
    [&]
    {
      tbb::parallel_for(tbb::blocked_range<std::int64_t>(0, blockCount, 1),
        [&](const tbb::blocked_range<std::int64_t>& range)
        {
          for (std::int64_t b = range.begin(); b != range.end(); ++b)
          {
            if (!needsContour[std::size_t(b)])
            {
              continue;
            }
            std::array<std::int64_t, 3> f0, ext;
            blockRange(b, f0, ext);
            auto& tris = results[std::size_t(b)].triangles;
            triangulateBlock(g, labels, f0, ext, tris);
          }
        });
    });
  progress.report(0.5);

  // Phase 3: the vertices, in ascending key order; positions by kind (edges, faces, centres).
  std::vector<VKey> keys;
  for (const auto& r : results)
  {
    for (const auto& t : r.triangles)
    {
      keys.insert(keys.end(), t.key.begin(), t.key.end());
    }
  }
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  MaterialSurface surface;
  surface.spacing = g.h;
  surface.points = placeVertices(keys, g, labels, rank, solids, o.threads);
  progress.report(0.8);

  for (const auto& r : results)
  {
    for (const auto& t : r.triangles)
    {
      surface.triangles.push_back(
        { keyIndex(keys, t.key[0]), keyIndex(keys, t.key[1]), keyIndex(keys, t.key[2]) });
      surface.labels.push_back(t.labels);
    }
    for (const auto& m : r.overlaps)
    {
      const bool known = std::any_of(surface.overlaps.begin(), surface.overlaps.end(),
        [&](const MaterialOverlap& x) { return x.first == m.first && x.second == m.second; });
      if (!known)
      {
        surface.overlaps.push_back(m);
      }
    }
  }

  // Regions: connected components of equal labels over the tetrahedron edges of the grid.
  std::vector<std::uint32_t> parent(pointCount);
  std::iota(parent.begin(), parent.end(), 0u);
  auto find = [&](std::uint32_t x)
  {
    while (parent[x] != x)
    {
      parent[x] = parent[parent[x]];
      x = parent[x];
    }
    return x;
  };
  for (std::int64_t k = 0; k < g.n[2]; ++k)
  {
    for (std::int64_t j = 0; j < g.n[1]; ++j)
    {
      for (std::int64_t i = 0; i < g.n[0]; ++i)
      {
        const auto p = static_cast<std::uint32_t>(g.index(i, j, k));
        for (int c = 1; c < 8; ++c)
        {
          const std::int64_t ii = i + (c & 1), jj = j + ((c >> 1) & 1), kk = k + (c >> 2);
          if (ii >= g.n[0] || jj >= g.n[1] || kk >= g.n[2])
          {
            continue;
          }
          const auto q = static_cast<std::uint32_t>(g.index(ii, jj, kk));
          if (labels[p] == labels[q])
          {
            const std::uint32_t rp = find(p), rq = find(q);
            if (rp != rq)
            {
              parent[std::max(rp, rq)] = std::min(rp, rq); // roots are the smallest indices
            }
          }
        }
      }
    }
  }
  // Outside regions that reach the box are not enclosed.
  std::vector<char> reachesBox(pointCount, 0);
  for (std::size_t p = 0; p < pointCount; ++p)
  {
    if (labels[p] == 0 && g.onBox(static_cast<std::uint64_t>(p)))
    {
      reachesBox[find(static_cast<std::uint32_t>(p))] = 1;
    }
  }
  // A point strictly inside each region: its first grid point off the box, else its root moved
  // a little into the box (a region that only touches the box).
  std::vector<std::uint32_t> inner(pointCount, std::numeric_limits<std::uint32_t>::max());
  for (std::size_t p = 0; p < pointCount; ++p)
  {
    if (!g.onBox(static_cast<std::uint64_t>(p)))
    {
      auto& first = inner[find(static_cast<std::uint32_t>(p))];
      first = std::min(first, static_cast<std::uint32_t>(p));
    }
  }
  auto regionPoint = [&](std::uint32_t root)
  {
    if (inner[root] != std::numeric_limits<std::uint32_t>::max())
    {
      return g.point(inner[root]);
    }
    const auto c = g.ijk(root);
    Point3 x = g.point(root);
    for (int a = 0; a < 3; ++a)
    {
      if (c[std::size_t(a)] == 0 || c[std::size_t(a)] == g.n[a] - 1)
      {
        const double step = 0.005 * std::min(g.h[a] * (1 - kPhase[a]), g.h[a] * kPhase[a]);
        x[a] += c[std::size_t(a)] == 0 ? step : -step;
      }
    }
    return x;
  };
  for (std::size_t p = 0; p < pointCount; ++p)
  {
    const auto pp = static_cast<std::uint32_t>(p);
    if (find(pp) == pp && !(labels[p] == 0 && reachesBox[p]))
    {
      surface.regions.push_back({ regionPoint(pp), labels[p] });
    }
  }
  progress.report(1.0);
  return surface;
}

} // namespace ictk::discretize
