// SPDX-License-Identifier: BSD-3-Clause
// The positions of the vertices of multi-material marching tetrahedra (MultiMaterialDetail.h),
// once the topology is known: a vertex on a grid edge by bisection on the field of the winning
// label of its two ends (batched per solid, kept 0.1 of the edge away from the ends so that no
// triangle is tiny), a vertex on a face with three labels on the triple line between two edge
// vertices, and one inside a tetrahedron at the mean of its face vertices. The batches are fixed,
// so the positions do not depend on the threads.
#include "Discretize/MultiMaterialDetail.h"

#include "FRep/Threads.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

#include <cmath>

namespace ictk::discretize::detail::material
{
namespace
{

// Bisection steps on an edge or a face segment: to ~1e-13 of its length.
constexpr int kBisections = 44;
// Edge vertices keep this fraction of the edge away from its ends (no tiny triangles).
constexpr double kEdgeClamp = 0.1;
// A triple line this close to an end of the face's segment: the vertex goes kFaceAside of the way
// from that end towards the third edge vertex instead.
constexpr double kFaceClamp = 0.02;
constexpr double kFaceAside = 0.1;

} // namespace

std::vector<Point3> placeVertices(const std::vector<VKey>& keys, const Grid& g,
  const std::vector<Label>& labels, const Ranking& rank, const std::vector<frep::FieldPtr>& solids,
  int threads)
{
  std::vector<std::uint32_t> edges, faces, centres;
  std::vector<Point3> pos(keys.size());
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
  runOnThreads(threads,
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
  runOnThreads(threads,
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
            const Point3 e1 = pos[keyIndex(keys, makeKey({ c[0], c[1] }))];
            const Point3 e2 = pos[keyIndex(keys, makeKey({ c[0], c[2] }))];
            const Point3 e3 = pos[keyIndex(keys, makeKey({ c[1], c[2] }))];
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
        const Point3& x = pos[keyIndex(keys, makeKey({ f[0], f[1], f[2] }))];
        for (int a = 0; a < 3; ++a)
        {
          sum[a] += x[a];
        }
        ++m;
      }
    }
    pos[v] = { sum[0] / m, sum[1] / m, sum[2] / m };
  }
  return pos;
}

} // namespace ictk::discretize::detail::material
