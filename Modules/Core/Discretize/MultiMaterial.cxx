// SPDX-License-Identifier: BSD-3-Clause
#include "Discretize/MultiMaterial.h"

#include "FRep/Sampling.h"
#include "FRep/Vector.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <numeric>
#include <stdexcept>
#include <string>
#include <utility>

namespace ictk::discretize
{
namespace
{

using frep::FieldEvaluator;
using Label = std::int16_t;
constexpr std::uint64_t kNone = std::numeric_limits<std::uint64_t>::max();

using frep::cross;
using frep::dot;
using frep::lerp;
using frep::sub;

// The six tetrahedra of the Kuhn split (corners by bits x = 1, y = 2, z = 4); their edges all go
// from a corner to one with more bits set, so the grid graph of tetrahedron edges has the seven
// neighbours of non-negative offsets.
constexpr int kTets[6][4] = { { 0, 1, 3, 7 }, { 0, 1, 5, 7 }, { 0, 2, 3, 7 }, { 0, 2, 6, 7 },
  { 0, 4, 5, 7 }, { 0, 4, 6, 7 } };
// Where the grid samples the inside of the box on each axis: at box.lo + (i - phase) h for
// i = 1..m, plus the box faces themselves. Planes at multiples of h from box.lo thus never pass
// through grid points, and the phases differ per axis so that grid diagonals do not cross such
// planes where two of them meet.
constexpr double kPhase[3] = { 0.5, 0.4, 0.6 };
constexpr std::int64_t kBlock = 8;
constexpr int kBisections = 44;
constexpr double kEdgeClamp = 0.1;
constexpr double kFaceClamp = 0.02;
constexpr double kFaceAside = 0.1;

/// A vertex: the sorted grid points of its grid point (1), edge (2), face (3) or tetrahedron
/// (4), kNone-padded.
struct VKey
{
  std::array<std::uint64_t, 4> v{ kNone, kNone, kNone, kNone };
  int size() const { return v[3] != kNone ? 4 : (v[2] != kNone ? 3 : (v[1] != kNone ? 2 : 1)); }
  bool operator<(const VKey& o) const { return v < o.v; }
  bool operator==(const VKey& o) const { return v == o.v; }
};

VKey makeKey(std::initializer_list<std::uint64_t> ids)
{
  VKey k;
  std::size_t i = 0;
  for (auto id : ids)
  {
    k.v[i++] = id;
  }
  std::sort(k.v.begin(), k.v.begin() + static_cast<std::ptrdiff_t>(i));
  return k;
}

struct Tri
{
  std::array<VKey, 3> key;
  std::array<std::int32_t, 2> labels;
};

struct BlockOut
{
  std::vector<Tri> triangles;
  std::vector<MaterialOverlap> overlaps;
};

struct Grid
{
  std::array<std::int64_t, 3> n{}; // points per axis (interior + the two box faces)
  Point3 lo{}, hi{}, h{};
  double coord(int a, std::int64_t i) const
  {
    return i == 0 ? lo[a]
                  : (i == n[a] - 1 ? hi[a] : lo[a] + (static_cast<double>(i) - kPhase[a]) * h[a]);
  }
  std::uint64_t index(std::int64_t i, std::int64_t j, std::int64_t k) const
  {
    return static_cast<std::uint64_t>((k * n[1] + j) * n[0] + i);
  }
  std::array<std::int64_t, 3> ijk(std::uint64_t p) const
  {
    const auto q = static_cast<std::int64_t>(p);
    return { q % n[0], (q / n[0]) % n[1], q / (n[0] * n[1]) };
  }
  Point3 point(std::uint64_t p) const
  {
    const auto c = ijk(p);
    return { coord(0, c[0]), coord(1, c[1]), coord(2, c[2]) };
  }
  bool onBox(std::int64_t i, std::int64_t j, std::int64_t k) const
  {
    return i == 0 || j == 0 || k == 0 || i == n[0] - 1 || j == n[1] - 1 || k == n[2] - 1;
  }
  bool onBox(std::uint64_t p) const
  {
    const auto c = ijk(p);
    return onBox(c[0], c[1], c[2]);
  }
};

/// Label ranks: rank(label) grows with priority, ties to the lower index, outside (0) lowest.
struct Ranking
{
  std::vector<int> order;       // solids, winner first
  std::vector<int> rankOfLabel; // by label (0 = outside)
  bool beats(int a, int b) const { return rankOfLabel[a] > rankOfLabel[b]; }
};

bool insideValue(double v)
{
  return v >= 0; // NaN is outside
}

struct Evaluators
{
  explicit Evaluators(const std::vector<frep::FieldPtr>& solids)
    : fields(&solids)
    , e(solids.size())
  {
  }
  FieldEvaluator& of(int solid)
  {
    auto& p = e[static_cast<std::size_t>(solid)];
    if (!p)
    {
      p = (*fields)[static_cast<std::size_t>(solid)]->evaluator();
    }
    return *p;
  }
  const std::vector<frep::FieldPtr>* fields;
  std::vector<std::unique_ptr<FieldEvaluator>> e;
};

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
  std::atomic<bool> cancelled{ false };
  std::atomic<std::int64_t> done{ 0 };
  auto report = [&](double fraction)
  {
    if (o.progress && !cancelled.load() && !o.progress(fraction))
    {
      cancelled = true;
    }
  };
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

  tbb::task_arena arena(o.threads > 0 ? o.threads : tbb::task_arena::automatic);

  // Phase 1: labels of the grid points, sampled only in blocks the intervals cannot decide.
  arena.execute(
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
            if (cancelled.load())
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
            const std::int64_t finished = ++done;
            if (o.progress && finished % 64 == 0)
            {
              static std::mutex progressMutex;
              std::lock_guard<std::mutex> lock(progressMutex);
              report(0.4 * double(finished) / double(blockCount));
            }
          }
        });
    });
  if (cancelled)
  {
    throw frep::Cancelled();
  }

  // The faces of a tetrahedron that lie on the box: each label's part of them, tagged (0, label)
  // (the solids cut by the box are closed by it, with sharp box edges and corners).
  auto capBoxFaces = [&](const int* tet, std::int64_t i, std::int64_t j, std::int64_t k,
                       const int* L, const std::uint64_t* G, const Point3* R,
                       std::vector<Tri>& tris)
  {
    for (int omit = 0; omit < 4; ++omit)
    {
      int fc[3], m = 0;
      for (int t = 0; t < 4; ++t)
      {
        if (t != omit)
        {
          fc[m++] = t;
        }
      }
      Point3 inward{ 0, 0, 0 };
      bool onFace = false;
      for (int a = 0; a < 3 && !onFace; ++a)
      {
        const std::int64_t base = a == 0 ? i : (a == 1 ? j : k);
        const std::int64_t c0 = base + ((tet[fc[0]] >> a) & 1);
        const std::int64_t c1 = base + ((tet[fc[1]] >> a) & 1);
        const std::int64_t c2 = base + ((tet[fc[2]] >> a) & 1);
        if (c0 == c1 && c1 == c2 && (c0 == 0 || c0 == g.n[a] - 1))
        {
          onFace = true;
          inward[a] = c0 == 0 ? 1 : -1;
        }
      }
      if (!onFace || (L[fc[0]] == 0 && L[fc[1]] == 0 && L[fc[2]] == 0))
      {
        continue;
      }
      auto cap = [&](const std::array<VKey, 3>& key, const std::array<Point3, 3>& ref, int label)
      {
        if (label == 0)
        {
          return;
        }
        // Normal from 0 (outside the box) into the label: into the box.
        Tri tri{ key, { 0, label } };
        if (dot(cross(sub(ref[1], ref[0]), sub(ref[2], ref[0])), inward) < 0)
        {
          std::swap(tri.key[1], tri.key[2]);
        }
        tris.push_back(tri);
      };
      auto pkey = [&](int t)
      {
        return makeKey({ G[t] });
      };
      auto ekey = [&](int u, int v)
      {
        return makeKey({ G[u], G[v] });
      };
      auto eref = [&](int u, int v)
      {
        return lerp(R[u], R[v], 0.5);
      };
      const int a = fc[0], b = fc[1], c = fc[2];
      if (L[a] == L[b] && L[b] == L[c])
      {
        cap({ pkey(a), pkey(b), pkey(c) }, { R[a], R[b], R[c] }, L[a]);
      }
      else if (L[a] != L[b] && L[b] != L[c] && L[a] != L[c])
      {
        const VKey F = makeKey({ G[a], G[b], G[c] });
        Point3 fref;
        for (int x = 0; x < 3; ++x)
        {
          fref[x] = (R[a][x] + R[b][x] + R[c][x]) / 3;
        }
        const int corners[3][3] = { { a, b, c }, { b, c, a }, { c, a, b } };
        for (const auto& cc : corners)
        {
          const int x = cc[0], y = cc[1], z = cc[2];
          cap({ F, ekey(x, y), pkey(x) }, { fref, eref(x, y), R[x] }, L[x]);
          cap({ F, pkey(x), ekey(x, z) }, { fref, R[x], eref(x, z) }, L[x]);
        }
      }
      else
      {
        // One corner alone: its triangle, and the quad of the other two.
        const int lone = L[a] == L[b] ? c : (L[a] == L[c] ? b : a);
        const int o1 = lone == a ? b : a;
        const int o2 = lone == c ? b : c;
        cap({ pkey(lone), ekey(lone, o1), ekey(lone, o2) },
          { R[lone], eref(lone, o1), eref(lone, o2) }, L[lone]);
        cap({ ekey(lone, o1), pkey(o1), pkey(o2) }, { eref(lone, o1), R[o1], R[o2] }, L[o1]);
        cap({ ekey(lone, o1), pkey(o2), ekey(lone, o2) }, { eref(lone, o1), R[o2], eref(lone, o2) },
          L[o1]);
      }
    }
  };

  // Phase 2: triangles of the blocks with more than one label, as vertex keys.
  arena.execute(
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
            for (std::int64_t k = f0[2]; k < f0[2] + ext[2]; ++k)
            {
              for (std::int64_t j = f0[1]; j < f0[1] + ext[1]; ++j)
              {
                for (std::int64_t i = f0[0]; i < f0[0] + ext[0]; ++i)
                {
                  std::uint64_t id[8];
                  int lab[8];
                  bool mixed = false;
                  for (int c = 0; c < 8; ++c)
                  {
                    id[c] = g.index(i + (c & 1), j + ((c >> 1) & 1), k + (c >> 2));
                    lab[c] = labels[id[c]];
                    mixed = mixed || lab[c] != lab[0];
                  }
                  const bool cubeOnBox = i == 0 || j == 0 || k == 0 || i + 2 == g.n[0] ||
                    j + 2 == g.n[1] || k + 2 == g.n[2];
                  if (!mixed && (lab[0] == 0 || !cubeOnBox))
                  {
                    continue;
                  }
                  for (const auto& tet : kTets)
                  {
                    int L[4];
                    std::uint64_t G[4];
                    Point3 R[4];
                    for (int t = 0; t < 4; ++t)
                    {
                      L[t] = lab[tet[t]];
                      G[t] = id[tet[t]];
                      R[t] = { double(tet[t] & 1), double((tet[t] >> 1) & 1), double(tet[t] >> 2) };
                    }
                    int distinct = 1;
                    for (int t = 1; t < 4; ++t)
                    {
                      bool seen = false;
                      for (int u = 0; u < t; ++u)
                      {
                        seen = seen || L[u] == L[t];
                      }
                      distinct += seen ? 0 : 1;
                    }
                    // Reference positions (the barycentric subdivision) orient the triangles.
                    auto edgeRef = [&](int u, int v)
                    {
                      return lerp(R[u], R[v], 0.5);
                    };
                    auto emit = [&](const std::array<VKey, 3>& key,
                                  const std::array<Point3, 3>& ref, int u, int v)
                    {
                      // (u, v): the corners of an edge vertex of the triangle.
                      const int la = std::min(L[u], L[v]), lb = std::max(L[u], L[v]);
                      const Point3 dir = L[u] == la ? sub(R[v], R[u]) : sub(R[u], R[v]);
                      const Point3 normal = cross(sub(ref[1], ref[0]), sub(ref[2], ref[0]));
                      Tri tri{ key, { la, lb } };
                      if (dot(normal, dir) < 0)
                      {
                        std::swap(tri.key[1], tri.key[2]);
                      }
                      tris.push_back(tri);
                    };
                    auto ekey = [&](int u, int v)
                    {
                      return makeKey({ G[u], G[v] });
                    };
                    if (cubeOnBox)
                    {
                      capBoxFaces(tet, i, j, k, L, G, R, tris);
                    }
                    if (distinct == 1)
                    {
                      continue;
                    }
                    if (distinct == 2)
                    {
                      int A[4], B[4], na = 0, nb = 0;
                      for (int t = 0; t < 4; ++t)
                      {
                        (L[t] == L[0] ? A[na++] : B[nb++]) = t;
                      }
                      if (na == 1 || nb == 1)
                      {
                        const int apex = na == 1 ? A[0] : B[0];
                        const int* o3 = na == 1 ? B : A;
                        emit({ ekey(apex, o3[0]), ekey(apex, o3[1]), ekey(apex, o3[2]) },
                          { edgeRef(apex, o3[0]), edgeRef(apex, o3[1]), edgeRef(apex, o3[2]) },
                          apex, o3[0]);
                      }
                      else
                      {
                        emit({ ekey(A[0], B[0]), ekey(A[0], B[1]), ekey(A[1], B[1]) },
                          { edgeRef(A[0], B[0]), edgeRef(A[0], B[1]), edgeRef(A[1], B[1]) }, A[0],
                          B[0]);
                        emit({ ekey(A[0], B[0]), ekey(A[1], B[1]), ekey(A[1], B[0]) },
                          { edgeRef(A[0], B[0]), edgeRef(A[1], B[1]), edgeRef(A[1], B[0]) }, A[0],
                          B[0]);
                      }
                      continue;
                    }
                    // Three or four labels: cones from the inner vertex C over the segments
                    // of the faces.
                    const VKey C = makeKey({ G[0], G[1], G[2], G[3] });
                    Point3 cref{ 0, 0, 0 };
                    int faces3 = 0;
                    for (int omit = 0; omit < 4; ++omit)
                    {
                      int fc[3], m = 0;
                      for (int t = 0; t < 4; ++t)
                      {
                        if (t != omit)
                        {
                          fc[m++] = t;
                        }
                      }
                      if (L[fc[0]] != L[fc[1]] && L[fc[1]] != L[fc[2]] && L[fc[0]] != L[fc[2]])
                      {
                        for (int a = 0; a < 3; ++a)
                        {
                          cref[a] += (R[fc[0]][a] + R[fc[1]][a] + R[fc[2]][a]) / 3;
                        }
                        ++faces3;
                      }
                    }
                    for (int a = 0; a < 3; ++a)
                    {
                      cref[a] /= faces3;
                    }
                    for (int omit = 0; omit < 4; ++omit)
                    {
                      int fc[3], m = 0;
                      for (int t = 0; t < 4; ++t)
                      {
                        if (t != omit)
                        {
                          fc[m++] = t;
                        }
                      }
                      const int e[3][2] = { { fc[0], fc[1] }, { fc[1], fc[2] }, { fc[0], fc[2] } };
                      const bool three =
                        L[fc[0]] != L[fc[1]] && L[fc[1]] != L[fc[2]] && L[fc[0]] != L[fc[2]];
                      if (three)
                      {
                        const VKey F = makeKey({ G[fc[0]], G[fc[1]], G[fc[2]] });
                        Point3 fref;
                        for (int a = 0; a < 3; ++a)
                        {
                          fref[a] = (R[fc[0]][a] + R[fc[1]][a] + R[fc[2]][a]) / 3;
                        }
                        for (const auto& uv : e)
                        {
                          emit({ C, ekey(uv[0], uv[1]), F }, { cref, edgeRef(uv[0], uv[1]), fref },
                            uv[0], uv[1]);
                        }
                      }
                      else
                      {
                        int cut[2][2], nCut = 0;
                        for (const auto& uv : e)
                        {
                          if (L[uv[0]] != L[uv[1]])
                          {
                            cut[nCut][0] = uv[0];
                            cut[nCut][1] = uv[1];
                            ++nCut;
                          }
                        }
                        if (nCut == 2)
                        {
                          emit({ C, ekey(cut[0][0], cut[0][1]), ekey(cut[1][0], cut[1][1]) },
                            { cref, edgeRef(cut[0][0], cut[0][1]), edgeRef(cut[1][0], cut[1][1]) },
                            cut[0][0], cut[0][1]);
                        }
                      }
                    }
                  }
                }
              }
            }
          }
        });
    });
  report(0.5);
  if (cancelled)
  {
    throw frep::Cancelled();
  }

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
  auto indexOf = [&](const VKey& key)
  {
    return static_cast<std::uint32_t>(
      std::lower_bound(keys.begin(), keys.end(), key) - keys.begin());
  };
  std::vector<std::uint32_t> edges, faces, centres;
  MaterialSurface surface;
  surface.spacing = g.h;
  surface.points.resize(keys.size());
  auto& pos = surface.points;
  for (std::size_t v = 0; v < keys.size(); ++v)
  {
    const int sz = keys[v].size();
    if (sz == 1)
    {
      pos[v] = g.point(keys[v].v[0]); // a grid point on the box
      continue;
    }
    (sz == 2 ? edges : (sz == 3 ? faces : centres)).push_back(static_cast<std::uint32_t>(v));
  }

  // Edges: bisection on the winning label's field (in batches).
  arena.execute(
    [&]
    {
      tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, edges.size(), 512),
        [&](const tbb::blocked_range<std::size_t>& range)
        {
          Evaluators ev(solids);
          struct Job
          {
            int solid;
            std::uint32_t vertex;
            Point3 a, b; // a inside the solid, b not
          };
          std::vector<Job> jobs;
          for (std::size_t e = range.begin(); e != range.end(); ++e)
          {
            const std::uint32_t v = edges[e];
            const std::uint64_t p = keys[v].v[0], q = keys[v].v[1];
            const Point3 P = g.point(p), Q = g.point(q);
            const int lp = labels[p], lq = labels[q];
            const bool pWins = rank.beats(lp, lq);
            const int winner = pWins ? lp : lq;
            jobs.push_back({ winner - 1, v, pWins ? P : Q, pWins ? Q : P });
          }
          std::stable_sort(
            jobs.begin(), jobs.end(), [](const Job& x, const Job& y) { return x.solid < y.solid; });
          std::vector<double> lo, hi, xs, ys, zs, vs;
          for (std::size_t first = 0; first < jobs.size();)
          {
            std::size_t last = first;
            while (last < jobs.size() && jobs[last].solid == jobs[first].solid)
            {
              ++last;
            }
            const std::size_t n = last - first;
            lo.assign(n, 0);
            hi.assign(n, 1);
            xs.resize(n);
            ys.resize(n);
            zs.resize(n);
            vs.resize(n);
            FieldEvaluator& f = ev.of(jobs[first].solid);
            for (int it = 0; it < kBisections; ++it)
            {
              for (std::size_t i = 0; i < n; ++i)
              {
                const Point3 x = lerp(jobs[first + i].a, jobs[first + i].b, 0.5 * (lo[i] + hi[i]));
                xs[i] = x[0];
                ys[i] = x[1];
                zs[i] = x[2];
              }
              f.values(xs.data(), ys.data(), zs.data(), vs.data(), n);
              for (std::size_t i = 0; i < n; ++i)
              {
                (insideValue(vs[i]) ? lo[i] : hi[i]) = 0.5 * (lo[i] + hi[i]);
              }
            }
            for (std::size_t i = 0; i < n; ++i)
            {
              const Job& j = jobs[first + i];
              const double t = std::clamp(0.5 * (lo[i] + hi[i]), kEdgeClamp, 1 - kEdgeClamp);
              pos[j.vertex] = lerp(j.a, j.b, t);
            }
            first = last;
          }
        },
        tbb::simple_partitioner()); // fixed batches: the same values for any thread count
    });

  // Faces with three labels: on the segment between the two edge vertices next to the lowest
  // ranked corner, on the triple line.
  arena.execute(
    [&]
    {
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, faces.size(), 64),
        [&](const tbb::blocked_range<std::size_t>& range)
        {
          Evaluators ev(solids);
          for (std::size_t fi = range.begin(); fi != range.end(); ++fi)
          {
            const std::uint32_t v = faces[fi];
            std::array<std::uint64_t, 3> c{ keys[v].v[0], keys[v].v[1], keys[v].v[2] };
            std::sort(c.begin(), c.end(),
              [&](std::uint64_t x, std::uint64_t y) {
                return rank.rankOfLabel[std::size_t(labels[x])] <
                  rank.rankOfLabel[std::size_t(labels[y])];
              });
            const Point3 e1 = pos[indexOf(makeKey({ c[0], c[1] }))];
            const Point3 e2 = pos[indexOf(makeKey({ c[0], c[2] }))];
            const Point3 e3 = pos[indexOf(makeKey({ c[1], c[2] }))];
            // Near the boundary of the lowest ranked label, the other two fields both vanish
            // at the triple line: it lies where f_b - f_c changes sign (robust where e1 and e2
            // sit on a flat face of the lowest label, where f_b and f_c themselves are ~0).
            FieldEvaluator& fb = ev.of(labels[c[1]] - 1);
            FieldEvaluator& fc = ev.of(labels[c[2]] - 1);
            auto bWins = [&](const Point3& x)
            {
              const double vb = fb.value(x), vc = fc.value(x);
              return std::isnan(vc) || (!std::isnan(vb) && vb >= vc);
            };
            const bool q1 = bWins(e1), q2 = bWins(e2);
            if (q1 == q2)
            {
              pos[v] = { (e1[0] + e2[0] + e3[0]) / 3, (e1[1] + e2[1] + e3[1]) / 3,
                (e1[2] + e2[2] + e3[2]) / 3 };
              continue;
            }
            double lo = 0, hi = 1; // lo: the side of e1's decision
            for (int it = 0; it < kBisections; ++it)
            {
              const double mid = 0.5 * (lo + hi);
              (bWins(lerp(e1, e2, mid)) == q1 ? lo : hi) = mid;
            }
            // The triple line through e1 (or e2) itself: stay off it, towards e3, on the
            // boundary of b (or c), which the triple line leaves the face along.
            const double t = 0.5 * (lo + hi);
            pos[v] = t < kFaceClamp
              ? lerp(e1, e3, kFaceAside)
              : (t > 1 - kFaceClamp ? lerp(e2, e3, kFaceAside) : lerp(e1, e2, t));
          }
        });
    });

  // Centres: the mean of the tetrahedron's three-label face vertices (in key order).
  for (const std::uint32_t v : centres)
  {
    const auto& k = keys[v].v;
    Point3 sum{ 0, 0, 0 };
    int m = 0;
    for (int omit = 0; omit < 4; ++omit)
    {
      std::uint64_t f[3];
      int c = 0;
      for (int t = 0; t < 4; ++t)
      {
        if (t != omit)
        {
          f[c++] = k[std::size_t(t)];
        }
      }
      if (labels[f[0]] != labels[f[1]] && labels[f[1]] != labels[f[2]] &&
        labels[f[0]] != labels[f[2]])
      {
        const Point3& x = pos[indexOf(makeKey({ f[0], f[1], f[2] }))];
        for (int a = 0; a < 3; ++a)
        {
          sum[a] += x[a];
        }
        ++m;
      }
    }
    pos[v] = { sum[0] / m, sum[1] / m, sum[2] / m };
  }
  report(0.8);
  if (cancelled)
  {
    throw frep::Cancelled();
  }

  for (const auto& r : results)
  {
    for (const auto& t : r.triangles)
    {
      surface.triangles.push_back({ indexOf(t.key[0]), indexOf(t.key[1]), indexOf(t.key[2]) });
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
  if (o.progress && !o.progress(1.0))
  {
    throw frep::Cancelled();
  }
  return surface;
}

} // namespace ictk::discretize
