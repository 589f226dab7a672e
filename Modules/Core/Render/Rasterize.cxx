// SPDX-License-Identifier: BSD-3-Clause
#include "Render/Rasterize.h"

#include "FRep/Threads.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace ictk::render
{

using frep::add;
using frep::cross;
using frep::dot;
using frep::norm;
using frep::Point3;
using frep::scale;
using frep::sub;

namespace
{

constexpr double Infinity = std::numeric_limits<double>::infinity();
/// The rows of a band, the unit of parallel work.
constexpr int BandRows = 16;

/// Pixels [i0, i1] x [j0, j1] (inclusive); empty when i0 > i1 or j0 > j1.
struct PixelRect
{
  int i0 = 0, j0 = 0, i1 = -1, j1 = -1;
};

/// A hit of a pixel's ray: distance along the unit direction, the normal (any length) and where
/// the paint is taken (weights of up to three points).
struct Hit
{
  double t = Infinity;
  Point3 normal{};
  std::array<std::uint32_t, 3> at{};
  std::array<double, 3> weight{};
};

/// The pixels whose centres may see the box [lo, hi]: the rectangle of its projected corners
/// (the projection of a box in front of a perspective eye lies in their hull); the whole picture
/// when the box reaches behind the eye.
PixelRect screenRect(const Camera& camera, const Point3& lo, const Point3& hi)
{
  double iLo = Infinity, iHi = -Infinity, jLo = Infinity, jHi = -Infinity;
  const bool perspective = camera.projection() == Projection::Perspective;
  for (int k = 0; k < 8; ++k)
  {
    const Point3 corner{ (k & 1) ? hi[0] : lo[0], (k & 2) ? hi[1] : lo[1],
      (k & 4) ? hi[2] : lo[2] };
    const Point3 q = sub(corner, camera.eye());
    const double s = dot(q, camera.forward());
    double u = dot(q, camera.right()), v = dot(q, camera.up());
    if (perspective)
    {
      if (!(s > 0))
      {
        return { 0, 0, camera.width() - 1, camera.height() - 1 };
      }
      u /= s;
      v /= s;
    }
    // u(i) = (i + 0.5 - width / 2) pixelSize, so i = u / pixelSize + width / 2 - 0.5.
    const double i = u / camera.pixelSize() + 0.5 * camera.width() - 0.5;
    const double j = v / camera.pixelSize() + 0.5 * camera.height() - 0.5;
    iLo = std::min(iLo, i);
    iHi = std::max(iHi, i);
    jLo = std::min(jLo, j);
    jHi = std::max(jHi, j);
  }
  PixelRect r;
  r.i0 = static_cast<int>(std::max(0.0, std::floor(iLo)));
  r.j0 = static_cast<int>(std::max(0.0, std::floor(jLo)));
  r.i1 = static_cast<int>(std::min(camera.width() - 1.0, std::ceil(iHi)));
  r.j1 = static_cast<int>(std::min(camera.height() - 1.0, std::ceil(jHi)));
  return r;
}

/// The first point of a ball on the ray o + t d (d a unit vector), t > 0.
double ballHit(const Point3& o, const Point3& d, const Point3& c, double r)
{
  const Point3 oc = sub(o, c);
  const double b = dot(d, oc);
  // The squared distance from the centre to the line, computed from the foot of the
  // perpendicular rather than as |oc|^2 - b^2, which cancels for a far eye and a thin ball.
  const Point3 q = sub(oc, scale(d, b));
  const double h = r * r - dot(q, q);
  if (h < 0)
  {
    return Infinity;
  }
  const double t = -b - std::sqrt(h);
  return t > 0 ? t : Infinity;
}

void triangleHit(
  const Point3& o, const Point3& d, const Primitives& p, std::uint32_t index, Hit& best)
{
  const auto& tri = p.triangles[index];
  const Point3& a = p.points[tri[0]];
  const Point3 e1 = sub(p.points[tri[1]], a), e2 = sub(p.points[tri[2]], a);
  const Point3 pv = cross(d, e2);
  const double det = dot(e1, pv);
  if (det == 0 || !std::isfinite(det))
  {
    return; // the ray lies in the triangle's plane, or the triangle is degenerate
  }
  const Point3 tv = sub(o, a);
  const double u = dot(tv, pv) / det;
  if (u < 0 || u > 1)
  {
    return;
  }
  const Point3 qv = cross(tv, e1);
  const double v = dot(d, qv) / det;
  if (v < 0 || u + v > 1)
  {
    return;
  }
  const double t = dot(e2, qv) / det;
  if (!(t > 0) || !(t < best.t))
  {
    return;
  }
  best.t = t;
  best.at = tri;
  best.weight = { 1 - u - v, u, v };
  Point3 n{};
  if (!p.normals.empty())
  {
    for (int k = 0; k < 3; ++k)
    {
      n = add(n, scale(p.normals[tri[k]], best.weight[k]));
    }
  }
  best.normal = norm(n) > 0 ? n : cross(e1, e2);
}

void tubeHit(const Point3& o, const Point3& d, const Primitives& p, std::uint32_t index, Hit& best)
{
  const auto& seg = p.segments[index];
  const Point3& a = p.points[seg[0]];
  const Point3& b = p.points[seg[1]];
  const double r = p.tubeRadius;
  auto take = [&](double t, const Point3& normal, double along)
  {
    if (t < best.t)
    {
      best.t = t;
      best.normal = normal;
      best.at = { seg[0], seg[1], seg[1] };
      best.weight = { 1 - along, along, 0 };
    }
  };
  // The union's first point is the first of its parts' first points.
  const double ta = ballHit(o, d, a, r);
  if (ta < best.t)
  {
    take(ta, sub(add(o, scale(d, ta)), a), 0);
  }
  const double tb = ballHit(o, d, b, r);
  if (tb < best.t)
  {
    take(tb, sub(add(o, scale(d, tb)), b), 1);
  }
  const Point3 axis = sub(b, a);
  const double length = norm(axis);
  if (!(length > 0))
  {
    return;
  }
  const Point3 w = scale(axis, 1 / length);
  const Point3 oa = sub(o, a);
  // The components across the axis: |op + t dp| = r on the infinite cylinder.
  const double dw = dot(d, w), ow = dot(oa, w);
  const Point3 dp = sub(d, scale(w, dw)), op = sub(oa, scale(w, ow));
  const double A = dot(dp, dp), B = dot(op, dp), C = dot(op, op) - r * r;
  const double h = B * B - A * C;
  if (!(A > 0) || h < 0)
  {
    return; // along the axis (the balls show it) or missed
  }
  const double t = (-B - std::sqrt(h)) / A;
  const double y = ow + t * dw;
  // Entering the infinite cylinder outside the segment is not entering the tube's body; the
  // ray may still enter through an end, which lies inside that end's ball.
  if (t > 0 && y >= 0 && y <= length && t < best.t)
  {
    take(t, sub(add(oa, scale(d, t)), scale(w, y)), y / length);
  }
}

void sphereHit(
  const Point3& o, const Point3& d, const Primitives& p, std::uint32_t index, Hit& best)
{
  const std::uint32_t c = p.spheres[index];
  const double t = ballHit(o, d, p.points[c], p.sphereRadius);
  if (t < best.t)
  {
    best.t = t;
    best.normal = sub(add(o, scale(d, t)), p.points[c]);
    best.at = { c, c, c };
    best.weight = { 1, 0, 0 };
  }
}

Paint paintOf(const Primitives& p, const Hit& hit)
{
  if (p.paints.empty())
  {
    return Paint{};
  }
  Paint out;
  out.rgb = { 0, 0, 0 };
  out.scalar = 0;
  for (int k = 0; k < 3; ++k)
  {
    const double w = hit.weight[k];
    if (w == 0)
    {
      continue;
    }
    const Paint& v = p.paints[hit.at[k]];
    for (int c = 0; c < 3; ++c)
    {
      out.rgb[c] += w * v.rgb[c];
    }
    out.scalar += w * v.scalar;
  }
  return out;
}

void check(const Canvas& canvas, const Camera& camera, const Primitives& p)
{
  if (!canvas.isValidFor(camera))
  {
    throw std::invalid_argument("rasterize: the canvas is not the camera's picture (its size or "
                                "buffers differ)");
  }
  const std::size_t n = p.points.size();
  for (const Point3& q : p.points)
  {
    if (!std::isfinite(q[0]) || !std::isfinite(q[1]) || !std::isfinite(q[2]))
    {
      throw std::invalid_argument("rasterize: a point is not finite");
    }
  }
  if ((!p.normals.empty() && p.normals.size() != n) || (!p.paints.empty() && p.paints.size() != n))
  {
    throw std::invalid_argument(
      "rasterize: " + std::to_string(n) + " points but a per-point array of another size");
  }
  auto inRange = [&](std::uint32_t i)
  {
    if (i >= n)
    {
      throw std::invalid_argument("rasterize: point index " + std::to_string(i) +
        " is out of range (" + std::to_string(n) + " points)");
    }
  };
  for (const auto& t : p.triangles)
  {
    std::for_each(t.begin(), t.end(), inRange);
  }
  for (const auto& s : p.segments)
  {
    std::for_each(s.begin(), s.end(), inRange);
  }
  std::for_each(p.spheres.begin(), p.spheres.end(), inRange);
  if (!p.segments.empty() && !(p.tubeRadius > 0 && std::isfinite(p.tubeRadius)))
  {
    throw std::invalid_argument("rasterize: the tube radius must be positive and finite");
  }
  if (!p.spheres.empty() && !(p.sphereRadius > 0 && std::isfinite(p.sphereRadius)))
  {
    throw std::invalid_argument("rasterize: the sphere radius must be positive and finite");
  }
}

enum class Kind : std::uint8_t
{
  Triangle,
  Tube,
  Sphere
};

struct Item
{
  Kind kind;
  std::uint32_t index;
  PixelRect rect;
};

} // namespace

std::int64_t rasterize(
  Canvas& canvas, const Camera& camera, const Primitives& p, const RasterOptions& options)
{
  check(canvas, camera, p);
  // Every primitive with its rectangle of pixels, in the order they are drawn.
  std::vector<Item> items;
  items.reserve(p.triangles.size() + p.segments.size() + p.spheres.size());
  auto add = [&](Kind kind, std::uint32_t index, Point3 lo, Point3 hi, double pad)
  {
    for (int a = 0; a < 3; ++a)
    {
      lo[a] -= pad;
      hi[a] += pad;
    }
    const PixelRect r = screenRect(camera, lo, hi);
    if (r.i0 <= r.i1 && r.j0 <= r.j1)
    {
      items.push_back({ kind, index, r });
    }
  };
  auto boxOf = [&](std::initializer_list<std::uint32_t> ids, Point3& lo, Point3& hi)
  {
    lo.fill(Infinity);
    hi.fill(-Infinity);
    for (std::uint32_t i : ids)
    {
      for (int a = 0; a < 3; ++a)
      {
        lo[a] = std::min(lo[a], p.points[i][a]);
        hi[a] = std::max(hi[a], p.points[i][a]);
      }
    }
  };
  Point3 lo, hi;
  for (std::uint32_t k = 0; k < p.triangles.size(); ++k)
  {
    const auto& t = p.triangles[k];
    boxOf({ t[0], t[1], t[2] }, lo, hi);
    add(Kind::Triangle, k, lo, hi, 0);
  }
  for (std::uint32_t k = 0; k < p.segments.size(); ++k)
  {
    boxOf({ p.segments[k][0], p.segments[k][1] }, lo, hi);
    add(Kind::Tube, k, lo, hi, p.tubeRadius);
  }
  for (std::uint32_t k = 0; k < p.spheres.size(); ++k)
  {
    boxOf({ p.spheres[k] }, lo, hi);
    add(Kind::Sphere, k, lo, hi, p.sphereRadius);
  }

  const int bands = (camera.height() + BandRows - 1) / BandRows;
  ProgressScope progress(options.progress);
  progress.report(0);
  ProgressScope::Items done = progress.items(bands, 0, 1);
  std::vector<std::int64_t> written(static_cast<std::size_t>(bands), 0);
  auto band = [&](int b)
  {
    if (progress.cancelled())
    {
      return;
    }
    const int j0 = b * BandRows, j1 = std::min(camera.height(), j0 + BandRows) - 1;
    std::int64_t count = 0;
    for (const Item& item : items)
    {
      const int ja = std::max(j0, item.rect.j0), jb = std::min(j1, item.rect.j1);
      for (int j = ja; j <= jb; ++j)
      {
        for (int i = item.rect.i0; i <= item.rect.i1; ++i)
        {
          const double u = camera.u(i), v = camera.v(j);
          const Point3 o = camera.origin(u, v);
          const Point3 direction = camera.direction(u, v);
          const Point3 d = scale(direction, 1 / norm(direction));
          Hit hit;
          hit.t = canvas.depth[canvas.index(i, j)];
          switch (item.kind)
          {
            case Kind::Triangle:
              triangleHit(o, d, p, item.index, hit);
              break;
            case Kind::Tube:
              tubeHit(o, d, p, item.index, hit);
              break;
            case Kind::Sphere:
              sphereHit(o, d, p, item.index, hit);
              break;
          }
          if (hit.t < canvas.depth[canvas.index(i, j)] &&
            canvas.put(canvas.index(i, j), hit.t, headlight(hit.normal, d, 1), paintOf(p, hit),
              p.owner, hit.normal, d))
          {
            ++count;
          }
        }
      }
    }
    written[static_cast<std::size_t>(b)] = count;
    done.finished();
  };
  runOnThreads(options.threads, [&] { tbb::parallel_for(0, bands, band); });
  progress.report(1);
  std::int64_t total = 0;
  for (std::int64_t w : written)
  {
    total += w;
  }
  return total;
}

std::vector<Point3> vertexNormals(
  const std::vector<Point3>& points, const std::vector<std::array<std::uint32_t, 3>>& triangles)
{
  std::vector<Point3> normals(points.size(), Point3{ 0, 0, 0 });
  for (const auto& t : triangles)
  {
    // The cross product's length is twice the area: the sum is area-weighted.
    const Point3 n = cross(sub(points[t[1]], points[t[0]]), sub(points[t[2]], points[t[0]]));
    for (std::uint32_t v : t)
    {
      normals[v] = add(normals[v], n);
    }
  }
  return normals;
}

} // namespace ictk::render
