// SPDX-License-Identifier: BSD-3-Clause
#include "Discretize/MarchingTetrahedra.h"

#include "FRep/Sampling.h"
#include "FRep/Threads.h"
#include "FRep/Vector.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <unordered_map>

namespace ictk::discretize
{
namespace
{

using frep::FieldEvaluator;

using frep::cross;
using frep::dot;
using frep::lerp;
using frep::sub;

void checkBox(const Box3& box, double size, const char* what)
{
  for (int a = 0; a < 3; ++a)
  {
    if (!std::isfinite(box.lo[a]) || !std::isfinite(box.hi[a]) || box.lo[a] > box.hi[a])
    {
      throw std::invalid_argument(std::string(what) + ": the box must be finite with lo <= hi");
    }
  }
  if (!(size > 0) || !std::isfinite(size))
  {
    throw std::invalid_argument(std::string(what) + ": the feature size must be positive");
  }
}

/// Finds the zero of f on the segment [a, b] (f(a) >= 0 > f(b) or the reverse) by regula falsi
/// with the Illinois modification, starting from the linear estimate.
Point3 edgeRoot(FieldEvaluator& f, Point3 a, double fa, Point3 b, double fb, int iterations = 8)
{
  Point3 p = lerp(a, b, fa / (fa - fb));
  int side = 0;
  for (int i = 0; i < iterations; ++i)
  {
    const double t = fa / (fa - fb);
    p = lerp(a, b, t);
    const double fp = f.value(p);
    if (fp == 0 || !std::isfinite(fp))
    {
      break;
    }
    if ((fp >= 0) == (fa >= 0))
    {
      a = p;
      fa = fp;
      if (side == -1)
      {
        fb *= 0.5;
      }
      side = -1;
    }
    else
    {
      b = p;
      fb = fp;
      if (side == 1)
      {
        fa *= 0.5;
      }
      side = 1;
    }
  }
  return p;
}

// The six tetrahedra of the Kuhn split of a cube (corners by bits x = 1, y = 2, z = 4): every
// cube is split the same way, so faces match and there is no ambiguity.
constexpr int kTets[6][4] = { { 0, 1, 3, 7 }, { 0, 1, 5, 7 }, { 0, 2, 3, 7 }, { 0, 2, 6, 7 },
  { 0, 4, 5, 7 }, { 0, 4, 6, 7 } };

struct BlockResult
{
  // Each triangle vertex is an edge key; positions are found after the merge.
  std::vector<std::array<std::uint64_t, 3>> triangles;
};

} // namespace

SurfaceMesh marchingTetrahedra(const frep::Field& field, const Box3& box, const ContourOptions& o)
{
  checkBox(box, o.featureSize, "marchingTetrahedra");
  detail::countMeshMade();
  const double h = o.featureSize;
  std::array<std::int64_t, 3> cells;
  double total = 1;
  for (int a = 0; a < 3; ++a)
  {
    cells[a] =
      std::max<std::int64_t>(1, static_cast<std::int64_t>(std::ceil((box.hi[a] - box.lo[a]) / h)));
    total *= static_cast<double>(cells[a]);
  }
  if (total > o.maxCells)
  {
    throw std::invalid_argument("marchingTetrahedra: feature size " + std::to_string(h) +
      " over this box needs " + std::to_string(total) + " grid cells, more than the limit of " +
      std::to_string(o.maxCells));
  }
  // With closeAtBox, one layer of outside cells surrounds the box.
  const std::int64_t pad = o.closeAtBox ? 1 : 0;
  std::array<std::int64_t, 3> n; // grid points per axis
  Point3 origin;
  for (int a = 0; a < 3; ++a)
  {
    n[a] = cells[a] + 1 + 2 * pad;
    origin[a] = box.lo[a] - pad * h;
  }
  auto pointIndex = [&](std::int64_t i, std::int64_t j, std::int64_t k)
  {
    return static_cast<std::uint64_t>((k * n[1] + j) * n[0] + i);
  };
  constexpr std::int64_t B = 8; // cells per block edge
  std::array<std::int64_t, 3> blocks;
  for (int a = 0; a < 3; ++a)
  {
    blocks[a] = (n[a] - 1 + B - 1) / B;
  }
  const std::int64_t blockCount = blocks[0] * blocks[1] * blocks[2];
  std::vector<BlockResult> results(static_cast<std::size_t>(blockCount));
  ProgressScope progress(o.progress);
  // Blocks are ~90% of the time; merging and placing the vertices the rest.
  constexpr double blockShare = 0.9;
  ProgressScope::Items blocksDone = progress.items(blockCount, 0, blockShare);

  auto runBlock = [&](std::int64_t b, FieldEvaluator& root, std::vector<double>& xs,
                    std::vector<double>& ys, std::vector<double>& zs, std::vector<double>& vs)
  {
    const std::int64_t bi = b % blocks[0];
    const std::int64_t bj = (b / blocks[0]) % blocks[1];
    const std::int64_t bk = b / (blocks[0] * blocks[1]);
    const std::int64_t i0 = bi * B, j0 = bj * B, k0 = bk * B;
    const std::int64_t ni = std::min(B, n[0] - 1 - i0), nj = std::min(B, n[1] - 1 - j0),
                       nk = std::min(B, n[2] - 1 - k0);
    Box3 blockBox;
    blockBox.lo = { origin[0] + i0 * h, origin[1] + j0 * h, origin[2] + k0 * h };
    blockBox.hi = { origin[0] + (i0 + ni) * h, origin[1] + (j0 + nj) * h,
      origin[2] + (k0 + nk) * h };
    const frep::Interval bound = root.bound(blockBox);
    const bool touchesPad = pad &&
      (i0 == 0 || j0 == 0 || k0 == 0 || i0 + ni == n[0] - 1 || j0 + nj == n[1] - 1 ||
        k0 + nk == n[2] - 1);
    if (!bound.maybeNaN && (bound.negative() || (bound.positive() && !touchesPad)))
    {
      return;
    }
    std::unique_ptr<FieldEvaluator> narrowed = root.narrowed(blockBox);
    FieldEvaluator& f = narrowed ? *narrowed : root;
    const std::int64_t pi = ni + 1, pj = nj + 1, pk = nk + 1;
    const auto count = static_cast<std::size_t>(pi * pj * pk);
    xs.resize(count);
    ys.resize(count);
    zs.resize(count);
    vs.resize(count);
    std::size_t c = 0;
    for (std::int64_t k = 0; k < pk; ++k)
    {
      for (std::int64_t j = 0; j < pj; ++j)
      {
        for (std::int64_t i = 0; i < pi; ++i, ++c)
        {
          xs[c] = origin[0] + (i0 + i) * h;
          ys[c] = origin[1] + (j0 + j) * h;
          zs[c] = origin[2] + (k0 + k) * h;
        }
      }
    }
    f.values(xs.data(), ys.data(), zs.data(), vs.data(), count);
    if (pad)
    {
      c = 0;
      for (std::int64_t k = 0; k < pk; ++k)
      {
        for (std::int64_t j = 0; j < pj; ++j)
        {
          for (std::int64_t i = 0; i < pi; ++i, ++c)
          {
            const std::int64_t gi = i0 + i, gj = j0 + j, gk = k0 + k;
            if (gi == 0 || gj == 0 || gk == 0 || gi == n[0] - 1 || gj == n[1] - 1 || gk == n[2] - 1)
            {
              vs[c] = -h; // outside the box
            }
          }
        }
      }
    }
    auto local = [&](std::int64_t i, std::int64_t j, std::int64_t k)
    {
      return static_cast<std::size_t>((k * pj + j) * pi + i);
    };
    BlockResult& out = results[static_cast<std::size_t>(b)];
    for (std::int64_t k = 0; k < nk; ++k)
    {
      for (std::int64_t j = 0; j < nj; ++j)
      {
        for (std::int64_t i = 0; i < ni; ++i)
        {
          double v[8];
          bool anyIn = false, anyOut = false;
          for (int corner = 0; corner < 8; ++corner)
          {
            v[corner] = vs[local(i + (corner & 1), j + ((corner >> 1) & 1), k + (corner >> 2))];
            if (!(v[corner] >= 0))
            {
              v[corner] = std::isnan(v[corner]) ? -h : v[corner]; // NaN counts as outside
            }
            (v[corner] >= 0 ? anyIn : anyOut) = true;
          }
          if (!anyIn || !anyOut)
          {
            continue;
          }
          const std::int64_t gi = i0 + i, gj = j0 + j, gk = k0 + k;
          auto key = [&](int a, int bCorner)
          {
            const int lo = std::min(a, bCorner), hi = std::max(a, bCorner);
            const std::uint64_t p = pointIndex(gi + (lo & 1), gj + ((lo >> 1) & 1), gk + (lo >> 2));
            return p * 8 + static_cast<std::uint64_t>(lo ^ hi);
          };
          for (const auto& tet : kTets)
          {
            int in[4], out4[4], nin = 0, nout = 0;
            for (int t = 0; t < 4; ++t)
            {
              (v[tet[t]] >= 0 ? in[nin++] : out4[nout++]) = tet[t];
            }
            if (nin == 0 || nout == 0)
            {
              continue;
            }
            // Orient each triangle so that its normal points from inside to outside, computed
            // on the midpoints of its edges: those never degenerate, unlike the final vertices,
            // which may coincide when a corner value is zero.
            auto emit = [&](int a, int b, int c1, int c2, int d1, int d2)
            {
              auto mid = [](int p, int q)
              {
                return Point3{ 0.5 * ((p & 1) + (q & 1)), 0.5 * (((p >> 1) & 1) + ((q >> 1) & 1)),
                  0.5 * ((p >> 2) + (q >> 2)) };
              };
              const Point3 m0 = mid(a, b), m1 = mid(c1, c2), m2 = mid(d1, d2);
              const Point3 normal = cross(sub(m1, m0), sub(m2, m0));
              const int inCorner = v[a] >= 0 ? a : b, outCorner = v[a] >= 0 ? b : a;
              const Point3 outward{ double((outCorner & 1) - (inCorner & 1)),
                double(((outCorner >> 1) & 1) - ((inCorner >> 1) & 1)),
                double((outCorner >> 2) - (inCorner >> 2)) };
              if (dot(normal, outward) >= 0)
              {
                out.triangles.push_back({ key(a, b), key(c1, c2), key(d1, d2) });
              }
              else
              {
                out.triangles.push_back({ key(a, b), key(d1, d2), key(c1, c2) });
              }
            };
            if (nin == 1 || nout == 1)
            {
              const int apex = nin == 1 ? in[0] : out4[0];
              const int* others = nin == 1 ? out4 : in;
              emit(apex, others[0], apex, others[1], apex, others[2]);
            }
            else
            {
              emit(in[0], out4[0], in[0], out4[1], in[1], out4[1]);
              emit(in[0], out4[0], in[1], out4[1], in[1], out4[0]);
            }
          }
        }
      }
    }
  };

  runOnThreads(o.threads,
    [&]
    {
      tbb::parallel_for(tbb::blocked_range<std::int64_t>(0, blockCount, 1),
        [&](const tbb::blocked_range<std::int64_t>& range)
        {
          auto root = field.evaluator();
          std::vector<double> xs, ys, zs, vs;
          for (std::int64_t b = range.begin(); b != range.end(); ++b)
          {
            if (progress.cancelled())
            {
              return;
            }
            runBlock(b, *root, xs, ys, zs, vs);
            blocksDone.finished();
          }
        });
    });
  progress.report(blockShare);

  // Merge in block order: vertex ids by ascending edge key, so the output does not depend on
  // the thread schedule.
  std::vector<std::uint64_t> keys;
  for (const auto& r : results)
  {
    for (const auto& t : r.triangles)
    {
      keys.insert(keys.end(), t.begin(), t.end());
    }
  }
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  SurfaceMesh mesh;
  mesh.points.resize(keys.size());
  auto corner = [&](std::uint64_t p, int offset)
  {
    const std::int64_t pi64 = static_cast<std::int64_t>(p);
    const std::int64_t i = pi64 % n[0] + (offset & 1);
    const std::int64_t j = (pi64 / n[0]) % n[1] + ((offset >> 1) & 1);
    const std::int64_t k = pi64 / (n[0] * n[1]) + (offset >> 2);
    return Point3{ origin[0] + i * h, origin[1] + j * h, origin[2] + k * h };
  };
  auto padded = [&](const Point3& p)
  {
    for (int a = 0; a < 3; ++a)
    {
      if (p[a] < box.lo[a] - 0.5 * h || p[a] > box.hi[a] + 0.5 * h)
      {
        return true;
      }
    }
    return false;
  };
  runOnThreads(o.threads,
    [&]
    {
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, keys.size(), 256),
        [&](const tbb::blocked_range<std::size_t>& range)
        {
          auto f = field.evaluator();
          for (std::size_t v = range.begin(); v != range.end(); ++v)
          {
            const Point3 a = corner(keys[v] / 8, 0);
            const Point3 b = corner(keys[v] / 8, static_cast<int>(keys[v] % 8));
            double fa = padded(a) ? -h : f->value(a);
            double fb = padded(b) ? -h : f->value(b);
            fa = std::isnan(fa) ? -h : fa;
            fb = std::isnan(fb) ? -h : fb;
            if ((fa >= 0) == (fb >= 0))
            {
              mesh.points[v] = lerp(a, b, 0.5);
            }
            else if (padded(a) || padded(b))
            {
              // The cut by the box: the vertex stays on the box face.
              const Point3& inside = fa >= 0 ? a : b;
              const Point3& outside = fa >= 0 ? b : a;
              Point3 p = inside;
              for (int ax = 0; ax < 3; ++ax)
              {
                if (outside[ax] != inside[ax])
                {
                  p[ax] = std::clamp(outside[ax], box.lo[ax], box.hi[ax]);
                }
              }
              mesh.points[v] = p;
            }
            else
            {
              mesh.points[v] = edgeRoot(*f, a, fa, b, fb);
            }
          }
        });
    });
  auto indexOf = [&](std::uint64_t key)
  {
    return static_cast<std::uint32_t>(
      std::lower_bound(keys.begin(), keys.end(), key) - keys.begin());
  };
  for (const auto& r : results)
  {
    for (const auto& t : r.triangles)
    {
      const std::array<std::uint32_t, 3> tri = { indexOf(t[0]), indexOf(t[1]), indexOf(t[2]) };
      mesh.triangles.push_back(tri);
    }
  }
  progress.report(1.0);
  return mesh;
}

} // namespace ictk::discretize
