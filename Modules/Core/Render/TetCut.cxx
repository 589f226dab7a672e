// SPDX-License-Identifier: BSD-3-Clause
#include "Render/TetCut.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace ictk::render
{

TetFaces tetrahedronFaces(const std::vector<frep::Point3>& points,
  const std::vector<std::array<std::uint32_t, 4>>& tetrahedra, const std::optional<CutPlane>& cut)
{
  if (cut)
  {
    const frep::Point3& n = cut->normal;
    if (!std::isfinite(n[0]) || !std::isfinite(n[1]) || !std::isfinite(n[2]) ||
      !std::isfinite(cut->offset))
    {
      throw std::invalid_argument("the cut plane is not finite numbers");
    }
    if (n[0] == 0 && n[1] == 0 && n[2] == 0)
    {
      throw std::invalid_argument("the cut plane's normal is zero");
    }
  }
  for (const frep::Point3& p : points)
  {
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
    {
      throw std::invalid_argument("the mesh has a point that is not finite");
    }
  }
  // Every face of every kept tetrahedron, keyed by its sorted vertices; a key met twice is
  // shared by two kept tetrahedra and hidden between them.
  struct Face
  {
    std::array<std::uint32_t, 3> key;
    std::uint32_t tetrahedron;
    std::uint8_t local;
  };
  std::vector<Face> all;
  all.reserve(tetrahedra.size() * 4);
  TetFaces out;
  for (std::size_t t = 0; t < tetrahedra.size(); ++t)
  {
    const auto& v = tetrahedra[t];
    for (std::uint32_t i : v)
    {
      if (i >= points.size())
      {
        throw std::invalid_argument("tetrahedron " + std::to_string(t) + " has the vertex " +
          std::to_string(i) + " of a mesh of " + std::to_string(points.size()) + " points");
      }
    }
    if (cut)
    {
      double s = 0;
      for (int a = 0; a < 3; ++a)
      {
        s += cut->normal[a] *
          (points[v[0]][a] + points[v[1]][a] + points[v[2]][a] + points[v[3]][a]) / 4;
      }
      if (s > cut->offset)
      {
        continue;
      }
    }
    ++out.keptTetrahedra;
    for (std::uint8_t k = 0; k < 4; ++k)
    {
      std::array<std::uint32_t, 3> f{ v[(k + 1) % 4], v[(k + 2) % 4], v[(k + 3) % 4] };
      std::sort(f.begin(), f.end());
      all.push_back({ f, static_cast<std::uint32_t>(t), k });
    }
  }
  std::vector<std::size_t> order(all.size());
  for (std::size_t i = 0; i < order.size(); ++i)
  {
    order[i] = i;
  }
  std::sort(order.begin(), order.end(),
    [&](std::size_t a, std::size_t b)
    { return all[a].key < all[b].key || (all[a].key == all[b].key && a < b); });
  std::vector<bool> seen(all.size(), false);
  for (std::size_t k = 0; k < order.size();)
  {
    std::size_t e = k + 1;
    while (e < order.size() && all[order[e]].key == all[order[k]].key)
    {
      ++e;
    }
    if (e - k == 1)
    {
      seen[order[k]] = true;
    }
    k = e;
  }
  for (std::size_t i = 0; i < all.size(); ++i)
  {
    if (!seen[i])
    {
      continue;
    }
    const auto& v = tetrahedra[all[i].tetrahedron];
    const int k = all[i].local;
    out.triangles.push_back({ v[(k + 1) % 4], v[(k + 2) % 4], v[(k + 3) % 4] });
    out.tetrahedron.push_back(all[i].tetrahedron);
  }
  return out;
}

Primitives tetrahedronFacePrimitives(
  const std::vector<frep::Point3>& points, const TetFaces& faces, const TetPaint& paint)
{
  if (!paint.perPoint.empty() && paint.perPoint.size() != points.size())
  {
    throw std::invalid_argument("the point values number " + std::to_string(paint.perPoint.size()) +
      " for " + std::to_string(points.size()) + " points");
  }
  std::uint32_t tetrahedra = 0;
  for (std::uint32_t t : faces.tetrahedron)
  {
    tetrahedra = std::max(tetrahedra, t + 1);
  }
  if (!paint.perTetrahedron.empty() && paint.perTetrahedron.size() < tetrahedra)
  {
    throw std::invalid_argument("the tetrahedron values number " +
      std::to_string(paint.perTetrahedron.size()) + ", fewer than the tetrahedra");
  }
  const bool painted = !paint.perPoint.empty() || !paint.perTetrahedron.empty();
  Primitives p;
  p.points.reserve(faces.triangles.size() * 3);
  for (std::size_t f = 0; f < faces.triangles.size(); ++f)
  {
    const auto n = static_cast<std::uint32_t>(p.points.size());
    for (std::uint32_t v : faces.triangles[f])
    {
      p.points.push_back(points[v]);
      if (painted)
      {
        Paint c;
        c.scalar =
          paint.perPoint.empty() ? paint.perTetrahedron[faces.tetrahedron[f]] : paint.perPoint[v];
        p.paints.push_back(c);
      }
    }
    p.triangles.push_back({ n, n + 1, n + 2 });
  }
  return p;
}

} // namespace ictk::render
