// SPDX-License-Identifier: BSD-3-Clause
#include "Discretize/Patches.h"

#include "Discretize/CellDetail.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace ictk::discretize
{

using namespace detail;

namespace
{

void checkNewton(double tolerance, int maxIterations, const char* what)
{
  if (!(tolerance > 0) || !std::isfinite(tolerance))
  {
    throw std::invalid_argument(std::string(what) + ": tolerance must be positive and finite");
  }
  if (maxIterations < 1 || maxIterations > 10000)
  {
    throw std::invalid_argument(std::string(what) + ": maxIterations must be in [1, 10000]");
  }
}

void checkPointData(const std::vector<PointArray>& data, std::size_t points, const char* what)
{
  for (const auto& a : data)
  {
    if (a.components < 1 || a.values.size() != points * static_cast<std::size_t>(a.components))
    {
      throw std::invalid_argument(
        std::string(what) + ": point array '" + a.name + "' does not have one tuple per point");
    }
  }
}

template <typename Points>
void mapPoints(Points& points, std::vector<PointArray>& pointData, const frep::Field& hx,
  const frep::Field& hy, const frep::Field& hz)
{
  checkPointData(pointData, points.size(), "mapToSpace");
  std::vector<Point3> uv(points.size());
  PointArray uvArray;
  uvArray.name = "uv";
  uvArray.components = 2;
  uvArray.values.resize(2 * points.size());
  for (std::size_t i = 0; i < points.size(); ++i)
  {
    uv[i] = { points[i][0], points[i][1], 0.0 };
    uvArray.values[2 * i] = points[i][0];
    uvArray.values[2 * i + 1] = points[i][1];
  }
  std::vector<double> x, y, z;
  evaluateAt(hx, uv, x, 0);
  evaluateAt(hy, uv, y, 0);
  evaluateAt(hz, uv, z, 0);
  for (std::size_t i = 0; i < points.size(); ++i)
  {
    points[i] = { x[i], y[i], z[i] };
  }
  pointData.erase(std::remove_if(pointData.begin(), pointData.end(),
                    [](const PointArray& a) { return a.name == "uv"; }),
    pointData.end());
  pointData.push_back(std::move(uvArray));
}

} // namespace

SurfaceMesh trimSurface(const SurfaceMesh& carrierMesh, const frep::Field& carrier,
  const std::vector<frep::FieldPtr>& trims, const TrimOptions& options)
{
  detail::countMeshMade();
  checkFields(trims, "trimSurface");
  checkNewton(options.tolerance, options.maxIterations, "trimSurface");
  checkPointData(carrierMesh.pointData, carrierMesh.points.size(), "trimSurface");
  for (const auto& t : carrierMesh.triangles)
  {
    for (auto v : t)
    {
      if (v >= carrierMesh.points.size())
      {
        throw std::invalid_argument("trimSurface: a triangle refers to a missing vertex");
      }
    }
  }
  ClipSettings settings;
  settings.carrier = &carrier;
  settings.newton.tolerance = options.tolerance;
  settings.newton.maxIterations = options.maxIterations;
  settings.threads = options.threads;
  std::vector<unsigned> onTrim;
  return clipMesh(carrierMesh, onTrim, trims, settings);
}

SurfaceMesh triangulateRegion2D(
  const frep::Field& f, const Box3& box, const Region2DOptions& options)
{
  const char* what = "triangulateRegion2D";
  detail::countMeshMade();
  checkBox(box, 4u, what);
  checkNewton(options.tolerance, options.maxIterations, what);
  if (!(options.size > 0) || !std::isfinite(options.size))
  {
    throw std::invalid_argument("triangulateRegion2D: size must be positive and finite");
  }
  if (!(options.snap >= 0 && options.snap <= 0.3))
  {
    throw std::invalid_argument("triangulateRegion2D: snap must lie in [0, 0.3]");
  }
  const double w = box.hi[0] - box.lo[0], h = box.hi[1] - box.lo[1];
  const double nxd = std::ceil(w / options.size), nyd = std::ceil(h / options.size);
  if (!(nxd * nyd <= options.maxCells) || nxd > 1e8 || nyd > 1e8)
  {
    throw std::invalid_argument("triangulateRegion2D: the grid would have " +
      std::to_string(nxd * nyd) + " squares, more than maxCells; raise size");
  }
  const auto nx = static_cast<std::size_t>(std::max(1.0, nxd));
  const auto ny = static_cast<std::size_t>(std::max(1.0, nyd));
  const double dx = w / static_cast<double>(nx), dy = h / static_cast<double>(ny);

  SurfaceMesh mesh;
  mesh.points.resize((nx + 1) * (ny + 1));
  for (std::size_t j = 0; j <= ny; ++j)
  {
    for (std::size_t i = 0; i <= nx; ++i)
    {
      const double u = i == nx ? box.hi[0] : box.lo[0] + static_cast<double>(i) * dx;
      const double v = j == ny ? box.hi[1] : box.lo[1] + static_cast<double>(j) * dy;
      mesh.points[j * (nx + 1) + i] = { u, v, 0.0 };
    }
  }
  for (std::size_t j = 0; j < ny; ++j)
  {
    for (std::size_t i = 0; i < nx; ++i)
    {
      const auto v00 = static_cast<std::uint32_t>(j * (nx + 1) + i);
      const auto v10 = v00 + 1;
      const auto v01 = static_cast<std::uint32_t>(v00 + nx + 1);
      const auto v11 = v01 + 1;
      mesh.triangles.push_back({ v00, v10, v11 });
      mesh.triangles.push_back({ v00, v11, v01 });
    }
  }

  // Snap grid vertices near the boundary onto f = 0 (border vertices slide along the border;
  // the rectangle's corners stay).
  std::vector<unsigned> onTrim(mesh.points.size(), 0u);
  if (options.snap > 0)
  {
    const double reach = options.snap * std::min(dx, dy);
    forChunks(mesh.points.size(), 1024, options.threads,
      [&](std::size_t b, std::size_t e)
      {
        auto ev = f.evaluator();
        for (std::size_t k = b; k < e; ++k)
        {
          const std::size_t i = k % (nx + 1), j = k / (nx + 1);
          const bool borderU = i == 0 || i == nx, borderV = j == 0 || j == ny;
          if (borderU && borderV)
          {
            continue;
          }
          Point3 g;
          const double value = ev->gradient(mesh.points[k], g);
          const double gn = std::hypot(g[0], g[1]);
          if (!std::isfinite(value) || !(gn > 0) || std::abs(value) >= reach * gn)
          {
            continue;
          }
          Constraint cs[3];
          int n = 0;
          cs[n++] = Constraint::of(*ev);
          cs[n++] = Constraint::plane(2, 0.0);
          if (borderU)
          {
            cs[n++] = Constraint::plane(0, mesh.points[k][0]);
          }
          else if (borderV)
          {
            cs[n++] = Constraint::plane(1, mesh.points[k][1]);
          }
          NewtonSettings ns;
          ns.tolerance = options.tolerance;
          ns.maxIterations = options.maxIterations;
          ns.maxStep = reach;
          ns.maxDistance = 1.2 * reach;
          Point3 p = mesh.points[k];
          if (projectOnto(cs, n, p, ns))
          {
            mesh.points[k] = p;
            onTrim[k] = 1u;
          }
        }
      });
  }

  ClipSettings settings;
  settings.carrier = nullptr;
  settings.planeZ = 0.0;
  settings.newton.tolerance = options.tolerance;
  settings.newton.maxIterations = options.maxIterations;
  settings.threads = options.threads;
  return clipMesh(std::move(mesh), onTrim, { borrow(f) }, settings);
}

void mapToSpace(
  SurfaceMesh& mesh, const frep::Field& hx, const frep::Field& hy, const frep::Field& hz)
{
  mapPoints(mesh.points, mesh.pointData, hx, hy, hz);
}

void mapToSpace(
  CurveSet& curves, const frep::Field& hx, const frep::Field& hy, const frep::Field& hz)
{
  mapPoints(curves.points, curves.pointData, hx, hy, hz);
}

void mapToSpace(
  PointSet& points, const frep::Field& hx, const frep::Field& hy, const frep::Field& hz)
{
  mapPoints(points.points, points.pointData, hx, hy, hz);
}

} // namespace ictk::discretize
