// SPDX-License-Identifier: BSD-3-Clause
// The topology of multi-material marching tetrahedra (MultiMaterialDetail.h): the triangles of
// each tetrahedron of the Kuhn split of a grid cell, from the labels of its corners alone. Two
// labels give the one or two triangles of marching tetrahedra; three or four give cones from an
// inner vertex over the segments of the faces, so they cannot intersect. Triangles are made of
// vertex keys (the grid points of their edge, face or tetrahedron), welded later, and oriented by
// reference positions (the barycentric subdivision of the tetrahedron), so positions are not
// needed yet. Tetrahedron faces on the box are capped with each label's part of them.
#include "Discretize/MultiMaterialDetail.h"

#include <utility>

namespace ictk::discretize::detail::material
{
namespace
{

// The six tetrahedra of the Kuhn split (corners by bits x = 1, y = 2, z = 4); their edges all go
// from a corner to one with more bits set, so the grid graph of tetrahedron edges has the seven
// neighbours of non-negative offsets.
constexpr int kTets[6][4] = { { 0, 1, 3, 7 }, { 0, 1, 5, 7 }, { 0, 2, 3, 7 }, { 0, 2, 6, 7 },
  { 0, 4, 5, 7 }, { 0, 4, 6, 7 } };

// The faces of a tetrahedron that lie on the box: each label's part of them, tagged (0, label)
// (the solids cut by the box are closed by it, with sharp box edges and corners).
void capBoxFaces(const Grid& g, const int* tet, std::int64_t i, std::int64_t j, std::int64_t k,
  const int* L, const std::uint64_t* G, const Point3* R, std::vector<Tri>& tris)
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
}

} // namespace

void triangulateBlock(const Grid& g, const std::vector<Label>& labels,
  const std::array<std::int64_t, 3>& f0, const std::array<std::int64_t, 3>& ext,
  std::vector<Tri>& tris)
{
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
        const bool cubeOnBox =
          i == 0 || j == 0 || k == 0 || i + 2 == g.n[0] || j + 2 == g.n[1] || k + 2 == g.n[2];
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
          auto emit =
            [&](const std::array<VKey, 3>& key, const std::array<Point3, 3>& ref, int u, int v)
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
            capBoxFaces(g, tet, i, j, k, L, G, R, tris);
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
                { edgeRef(apex, o3[0]), edgeRef(apex, o3[1]), edgeRef(apex, o3[2]) }, apex, o3[0]);
            }
            else
            {
              emit({ ekey(A[0], B[0]), ekey(A[0], B[1]), ekey(A[1], B[1]) },
                { edgeRef(A[0], B[0]), edgeRef(A[0], B[1]), edgeRef(A[1], B[1]) }, A[0], B[0]);
              emit({ ekey(A[0], B[0]), ekey(A[1], B[1]), ekey(A[1], B[0]) },
                { edgeRef(A[0], B[0]), edgeRef(A[1], B[1]), edgeRef(A[1], B[0]) }, A[0], B[0]);
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
            const bool three = L[fc[0]] != L[fc[1]] && L[fc[1]] != L[fc[2]] && L[fc[0]] != L[fc[2]];
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
                emit({ C, ekey(uv[0], uv[1]), F }, { cref, edgeRef(uv[0], uv[1]), fref }, uv[0],
                  uv[1]);
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
                  { cref, edgeRef(cut[0][0], cut[0][1]), edgeRef(cut[1][0], cut[1][1]) }, cut[0][0],
                  cut[0][1]);
              }
            }
          }
        }
      }
    }
  }
}

} // namespace ictk::discretize::detail::material
