// SPDX-License-Identifier: BSD-3-Clause
// The cube tables of manifold dual contouring (SurfaceDetail.h): which grid edges of a cell the
// surface crosses, how they pair into the boundary cycles of the cell's marching-cubes patch (one
// vertex per cycle makes the surface manifold), and how an ambiguous face is resolved (the
// asymptotic decider, so that the two cells of a face agree). The 256 x 64 cases are tabulated
// once; the cycles themselves are also walked again by the non-manifold repair.
#include "Discretize/SurfaceDetail.h"

#include <algorithm>
#include <iterator>
#include <utility>

namespace ictk::discretize::detail::surface
{

CubeGeometry::CubeGeometry()
{
  for (int e = 0; e < 12; ++e)
  {
    const int a = e / 4, u = e & 1, v = (e >> 1) & 1;
    int c[3];
    c[a] = 0;
    c[OtherAxes[a][0]] = u;
    c[OtherAxes[a][1]] = v;
    edgeCorner[e][0] = cornerAt(c);
    c[a] = 1;
    edgeCorner[e][1] = cornerAt(c);
    edgeFace[e][0] = 2 * OtherAxes[a][0] + u;
    edgeFace[e][1] = 2 * OtherAxes[a][1] + v;
  }
  for (int f = 0; f < 6; ++f)
  {
    const int a = f / 2, s = f & 1, b = OtherAxes[a][0], cc = OtherAxes[a][1];
    for (int v = 0; v < 2; ++v)
    {
      for (int u = 0; u < 2; ++u)
      {
        int c[3];
        c[a] = s;
        c[b] = u;
        c[cc] = v;
        faceCorner[f][u + 2 * v] = cornerAt(c);
      }
    }
    for (int v = 0; v < 2; ++v)
    {
      int c[3] = { 0, 0, 0 };
      c[a] = s;
      c[cc] = v;
      faceEdgeB[f][v] = edgeAt(b, c);
    }
    for (int u = 0; u < 2; ++u)
    {
      int c[3] = { 0, 0, 0 };
      c[a] = s;
      c[b] = u;
      faceEdgeC[f][u] = edgeAt(cc, c);
    }
  }
}

const CubeGeometry& cube()
{
  static const CubeGeometry g;
  return g;
}

namespace
{

/// Faces whose four corners alternate in sign (two diagonal inside corners).
int ambiguousFaces(int mask)
{
  const CubeGeometry& g = cube();
  int faces = 0;
  for (int f = 0; f < 6; ++f)
  {
    const bool q00 = inside(mask, g.faceCorner[f][0]), q10 = inside(mask, g.faceCorner[f][1]),
               q01 = inside(mask, g.faceCorner[f][2]), q11 = inside(mask, g.faceCorner[f][3]);
    if (q00 == q11 && q10 == q01 && q00 != q10)
    {
      faces |= 1 << f;
    }
  }
  return faces;
}

} // namespace

std::vector<std::vector<CycleStep>> patchCycles(int mask, int connected)
{
  const CubeGeometry& g = cube();
  int partner[12][2];
  for (auto& p : partner)
  {
    p[0] = p[1] = -1;
  }
  auto link = [&](int f, int e1, int e2)
  {
    partner[e1][g.edgeFace[e1][0] == f ? 0 : 1] = e2;
    partner[e2][g.edgeFace[e2][0] == f ? 0 : 1] = e1;
  };
  auto crosses = [&](int e)
  {
    return inside(mask, g.edgeCorner[e][0]) != inside(mask, g.edgeCorner[e][1]);
  };
  for (int f = 0; f < 6; ++f)
  {
    const int eb0 = g.faceEdgeB[f][0], eb1 = g.faceEdgeB[f][1], ec0 = g.faceEdgeC[f][0],
              ec1 = g.faceEdgeC[f][1];
    const int edges[4] = { eb0, eb1, ec0, ec1 };
    int active[4], n = 0;
    for (int e : edges)
    {
      if (crosses(e))
      {
        active[n++] = e;
      }
    }
    if (n == 2)
    {
      link(f, active[0], active[1]);
    }
    else if (n == 4)
    {
      // Cut off the two corners of the sign that is not joined across the face; corner q(u,v)
      // touches eb[v] and ec[u].
      const bool q00Inside = inside(mask, g.faceCorner[f][0]);
      const bool joinedInside = (connected >> f) & 1;
      // The separated corners are q00 and q11 when they are inside and not joined, or outside
      // while the inside (q10, q01) is joined.
      if (q00Inside != joinedInside)
      {
        link(f, eb0, ec0); // q00
        link(f, eb1, ec1); // q11
      }
      else
      {
        link(f, eb0, ec1); // q10
        link(f, eb1, ec0); // q01
      }
    }
  }
  std::vector<std::vector<CycleStep>> cycles;
  bool seen[12] = {};
  for (int start = 0; start < 12; ++start)
  {
    if (seen[start] || !crosses(start))
    {
      continue;
    }
    std::vector<CycleStep> cycle;
    int e = start, slot = 0;
    do
    {
      seen[e] = true;
      const int face = g.edgeFace[e][slot];
      const int next = partner[e][slot];
      cycle.push_back({ e, face });
      slot = g.edgeFace[next][0] == face ? 1 : 0;
      e = next;
    } while (e != start);
    cycles.push_back(std::move(cycle));
  }
  return cycles;
}

CaseTable::CaseTable()
  : entries(256 * 64)
{
  for (int mask = 0; mask < 256; ++mask)
  {
    ambiguous[mask] = static_cast<std::uint8_t>(ambiguousFaces(mask));
    for (int bits = 0; bits < 64; ++bits)
    {
      if ((bits & ~ambiguous[mask]) != 0)
      {
        continue;
      }
      CaseEntry& entry = entries[mask * 64 + bits];
      std::fill(std::begin(entry.component), std::end(entry.component), 0xFF);
      const auto cycles = patchCycles(mask, bits);
      entry.components = static_cast<std::uint8_t>(cycles.size());
      for (std::size_t k = 0; k < cycles.size(); ++k)
      {
        int facesSeen = 0;
        for (const CycleStep& s : cycles[k])
        {
          entry.component[s.edge] = static_cast<std::uint8_t>(k);
          if ((facesSeen >> s.face) & 1)
          {
            entry.doubled |= static_cast<std::uint8_t>(1 << s.face);
          }
          facesSeen |= 1 << s.face;
        }
      }
    }
  }
}

const CaseTable& caseTable()
{
  static const CaseTable table;
  return table;
}

int joinedFaces(int mask, const double v[8])
{
  const CubeGeometry& g = cube();
  const int faces = caseTable().ambiguous[mask];
  int bits = 0;
  for (int f = 0; f < 6; ++f)
  {
    if ((faces >> f) & 1)
    {
      const int* q = g.faceCorner[f];
      const double diagonal00 = v[q[0]] * v[q[3]], diagonal10 = v[q[1]] * v[q[2]];
      const bool q00Inside = inside(mask, q[0]);
      const double in = q00Inside ? diagonal00 : diagonal10;
      const double out = q00Inside ? diagonal10 : diagonal00;
      if (in >= out)
      {
        bits |= 1 << f;
      }
    }
  }
  return bits;
}

} // namespace ictk::discretize::detail::surface
