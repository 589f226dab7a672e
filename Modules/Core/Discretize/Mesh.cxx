// SPDX-License-Identifier: BSD-3-Clause
#include "Discretize/Mesh.h"
#include "Discretize/MeshRepair.h"

#include "FRep/Vector.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <map>
#include <numeric>
#include <unordered_map>

namespace ictk::discretize
{
namespace
{

std::atomic<std::int64_t> meshCount{ 0 };

struct UnionFind
{
  std::vector<std::uint32_t> parent;
  explicit UnionFind(std::size_t n)
    : parent(n)
  {
    std::iota(parent.begin(), parent.end(), 0u);
  }
  std::uint32_t find(std::uint32_t i)
  {
    while (parent[i] != i)
    {
      parent[i] = parent[parent[i]];
      i = parent[i];
    }
    return i;
  }
  void unite(std::uint32_t a, std::uint32_t b) { parent[find(a)] = find(b); }
};

std::uint64_t edgeKey(std::uint32_t a, std::uint32_t b)
{
  return (std::uint64_t(std::min(a, b)) << 32) | std::max(a, b);
}

/// The non-degenerate triangles using each vertex.
std::vector<std::vector<std::uint32_t>> trianglesAroundVertices(const SurfaceMesh& mesh)
{
  std::vector<std::vector<std::uint32_t>> around(mesh.points.size());
  for (std::uint32_t f = 0; f < mesh.triangles.size(); ++f)
  {
    const auto& tri = mesh.triangles[f];
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2])
    {
      continue;
    }
    for (auto v : tri)
    {
      around[v].push_back(f);
    }
  }
  return around;
}

/// The fans of vertex v: its triangles grouped by union-find, two linked when they share an
/// edge (v, w). A manifold vertex has one fan; each group lists triangle indices.
std::vector<std::vector<std::uint32_t>> fansAround(
  const SurfaceMesh& mesh, std::uint32_t v, const std::vector<std::uint32_t>& triangles)
{
  std::map<std::uint32_t, std::vector<std::size_t>> byOther;
  for (std::size_t i = 0; i < triangles.size(); ++i)
  {
    for (auto w : mesh.triangles[triangles[i]])
    {
      if (w != v)
      {
        byOther[w].push_back(i);
      }
    }
  }
  UnionFind local(triangles.size());
  for (const auto& [w, list] : byOther)
  {
    (void)w;
    for (std::size_t i = 1; i < list.size(); ++i)
    {
      local.unite(static_cast<std::uint32_t>(list[0]), static_cast<std::uint32_t>(list[i]));
    }
  }
  std::map<std::uint32_t, std::size_t> fanOfRoot;
  std::vector<std::vector<std::uint32_t>> fans;
  for (std::uint32_t i = 0; i < triangles.size(); ++i)
  {
    const auto [it, added] = fanOfRoot.emplace(local.find(i), fans.size());
    if (added)
    {
      fans.emplace_back();
    }
    fans[it->second].push_back(triangles[i]);
  }
  return fans;
}

} // namespace

MeshTopology analyzeTopology(const SurfaceMesh& mesh)
{
  MeshTopology t;
  t.triangles = mesh.triangles.size();
  // Per edge: the triangles using it and how many traverse it a->b with a < b.
  struct EdgeUse
  {
    std::uint32_t count = 0;
    std::uint32_t forward = 0;
    std::uint32_t firstTriangle = 0;
  };
  std::unordered_map<std::uint64_t, EdgeUse> edges;
  std::vector<char> used(mesh.points.size(), 0);
  UnionFind triangleSets(mesh.triangles.size());
  for (std::uint32_t f = 0; f < mesh.triangles.size(); ++f)
  {
    const auto& tri = mesh.triangles[f];
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2])
    {
      ++t.degenerateTriangles;
      continue;
    }
    for (int k = 0; k < 3; ++k)
    {
      const std::uint32_t a = tri[k], b = tri[(k + 1) % 3];
      used[a] = 1;
      EdgeUse& e = edges[edgeKey(a, b)];
      if (e.count == 0)
      {
        e.firstTriangle = f;
      }
      else
      {
        triangleSets.unite(f, e.firstTriangle);
      }
      ++e.count;
      e.forward += a < b ? 1 : 0;
    }
  }
  t.vertices = static_cast<std::size_t>(std::count(used.begin(), used.end(), 1));
  t.edges = edges.size();
  for (const auto& [key, e] : edges)
  {
    (void)key;
    if (e.count == 1)
    {
      ++t.boundaryEdges;
    }
    else if (e.count > 2)
    {
      ++t.nonManifoldEdges;
    }
    else if (e.forward != 1)
    {
      ++t.inconsistentEdges;
    }
  }
  // A manifold vertex: its incident triangles, linked through shared edges around it, form one
  // fan.
  const std::vector<std::vector<std::uint32_t>> around = trianglesAroundVertices(mesh);
  for (std::uint32_t v = 0; v < mesh.points.size(); ++v)
  {
    if (fansAround(mesh, v, around[v]).size() > 1)
    {
      ++t.nonManifoldVertices;
    }
  }
  for (std::uint32_t f = 0; f < mesh.triangles.size(); ++f)
  {
    const auto& tri = mesh.triangles[f];
    if (!(tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2]) && triangleSets.find(f) == f)
    {
      ++t.components;
    }
  }
  t.eulerCharacteristic = static_cast<long>(t.vertices) - static_cast<long>(t.edges) +
    static_cast<long>(t.triangles - t.degenerateTriangles);
  return t;
}

std::vector<std::uint32_t> splitNonManifoldVertices(SurfaceMesh& mesh)
{
  const std::vector<std::vector<std::uint32_t>> around = trianglesAroundVertices(mesh);
  std::vector<std::uint32_t> copied;
  const auto n = static_cast<std::uint32_t>(mesh.points.size());
  for (std::uint32_t v = 0; v < n; ++v)
  {
    const auto fans = fansAround(mesh, v, around[v]);
    // The first fan keeps v; every other one gets a copy of it at the same place.
    for (std::size_t k = 1; k < fans.size(); ++k)
    {
      const auto copy = static_cast<std::uint32_t>(mesh.points.size());
      mesh.points.push_back(mesh.points[v]);
      for (PointArray& a : mesh.pointData)
      {
        const auto c = static_cast<std::size_t>(a.components);
        for (std::size_t j = 0; j < c; ++j)
        {
          a.values.push_back(a.values[v * c + j]);
        }
      }
      copied.push_back(v);
      for (std::uint32_t f : fans[k])
      {
        for (auto& corner : mesh.triangles[f])
        {
          if (corner == v)
          {
            corner = copy;
          }
        }
      }
    }
  }
  return copied;
}

namespace
{
using frep::cross;
using frep::sub;

} // namespace

double surfaceArea(const SurfaceMesh& mesh)
{
  double area = 0;
  for (const auto& tri : mesh.triangles)
  {
    const Point3 n = cross(
      sub(mesh.points[tri[1]], mesh.points[tri[0]]), sub(mesh.points[tri[2]], mesh.points[tri[0]]));
    area += 0.5 * std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  }
  return area;
}

double enclosedVolume(const SurfaceMesh& mesh)
{
  double volume = 0;
  for (const auto& tri : mesh.triangles)
  {
    const Point3& a = mesh.points[tri[0]];
    const Point3 n = cross(mesh.points[tri[1]], mesh.points[tri[2]]);
    volume += (a[0] * n[0] + a[1] * n[1] + a[2] * n[2]) / 6.0;
  }
  return volume;
}

std::int64_t meshesMade()
{
  return meshCount.load(std::memory_order_relaxed);
}

void detail::countMeshMade()
{
  meshCount.fetch_add(1, std::memory_order_relaxed);
}

} // namespace ictk::discretize
