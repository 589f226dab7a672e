// SPDX-License-Identifier: BSD-3-Clause
// Dual contouring (Discretize/Surface.h): accuracy against analytic surfaces, sharp features,
// topology, determinism, cancellation and argument checks. The CGAL self-intersection check is in
// TestDiscretizeSurfaceCgal.cxx (CGAL adds -frounding-math to its executable).
#include "Discretize/Surface.h"
#include "FRep/BundledModels.h"
#include "FRep/Field.h"
#include "FRep/Primitives.h"
#include "FRep/Sampling.h"
#include "FRep/Tape.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <tuple>
#include <vector>

using namespace ictk;
using namespace ictk::discretize;
using frep::Expr;

namespace
{

frep::FieldPtr fieldOf(const Expr& e)
{
  return frep::tapeField(frep::Tape::compile(e));
}

Point3 sub(const Point3& a, const Point3& b)
{
  return { a[0] - b[0], a[1] - b[1], a[2] - b[2] };
}
double dot(const Point3& a, const Point3& b)
{
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
double norm(const Point3& a)
{
  return std::sqrt(dot(a, a));
}

/// Distance from p to the triangle abc (closest point by Voronoi regions).
double pointTriangleDistance(const Point3& p, const Point3& a, const Point3& b, const Point3& c)
{
  const Point3 ab = sub(b, a), ac = sub(c, a), ap = sub(p, a);
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0)
  {
    return norm(ap);
  }
  const Point3 bp = sub(p, b);
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3)
  {
    return norm(bp);
  }
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0)
  {
    const double v = d1 / (d1 - d3);
    return norm(sub(ap, { v * ab[0], v * ab[1], v * ab[2] }));
  }
  const Point3 cp = sub(p, c);
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6)
  {
    return norm(cp);
  }
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0)
  {
    const double w = d2 / (d2 - d6);
    return norm(sub(ap, { w * ac[0], w * ac[1], w * ac[2] }));
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
  {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    const Point3 bc = sub(c, b);
    return norm(sub(bp, { w * bc[0], w * bc[1], w * bc[2] }));
  }
  const double denom = 1.0 / (va + vb + vc);
  const double v = vb * denom, w = vc * denom;
  const Point3 q{ a[0] + ab[0] * v + ac[0] * w, a[1] + ab[1] * v + ac[1] * w,
    a[2] + ab[2] * v + ac[2] * w };
  return norm(sub(p, q));
}

/// Distance from points to a triangle mesh, through a uniform grid of buckets of edge `cell`;
/// returns `cell` when nothing lies within one bucket ring.
class MeshDistance
{
public:
  MeshDistance(const SurfaceMesh& mesh, double cell)
    : mesh_(mesh)
    , cell_(cell)
  {
    for (std::uint32_t t = 0; t < mesh.triangles.size(); ++t)
    {
      Point3 lo{ 1e300, 1e300, 1e300 }, hi{ -1e300, -1e300, -1e300 };
      for (auto v : mesh.triangles[t])
      {
        for (int a = 0; a < 3; ++a)
        {
          lo[a] = std::min(lo[a], mesh.points[v][a]);
          hi[a] = std::max(hi[a], mesh.points[v][a]);
        }
      }
      const auto l = key(lo), h = key(hi);
      for (int i = std::get<0>(l); i <= std::get<0>(h); ++i)
      {
        for (int j = std::get<1>(l); j <= std::get<1>(h); ++j)
        {
          for (int k = std::get<2>(l); k <= std::get<2>(h); ++k)
          {
            buckets_[{ i, j, k }].push_back(t);
          }
        }
      }
    }
  }
  double operator()(const Point3& p) const
  {
    double best = cell_;
    const auto c = key(p);
    for (int i = -1; i <= 1; ++i)
    {
      for (int j = -1; j <= 1; ++j)
      {
        for (int k = -1; k <= 1; ++k)
        {
          const auto it =
            buckets_.find({ std::get<0>(c) + i, std::get<1>(c) + j, std::get<2>(c) + k });
          if (it == buckets_.end())
          {
            continue;
          }
          for (auto t : it->second)
          {
            const auto& tri = mesh_.triangles[t];
            best = std::min(best,
              pointTriangleDistance(
                p, mesh_.points[tri[0]], mesh_.points[tri[1]], mesh_.points[tri[2]]));
          }
        }
      }
    }
    return best;
  }

private:
  std::tuple<int, int, int> key(const Point3& p) const
  {
    return { static_cast<int>(std::floor(p[0] / cell_)), static_cast<int>(std::floor(p[1] / cell_)),
      static_cast<int>(std::floor(p[2] / cell_)) };
  }
  const SurfaceMesh& mesh_;
  double cell_;
  std::map<std::tuple<int, int, int>, std::vector<std::uint32_t>> buckets_;
};

/// Points spread evenly over the unit sphere (Fibonacci lattice).
std::vector<Point3> fibonacciSphere(int n)
{
  std::vector<Point3> points;
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i)
  {
    const double z = 1.0 - 2.0 * (i + 0.5) / n;
    const double r = std::sqrt(1.0 - z * z);
    points.push_back({ r * std::cos(golden * i), r * std::sin(golden * i), z });
  }
  return points;
}

void expectClosedManifold(const SurfaceMesh& mesh, long euler)
{
  const MeshTopology t = analyzeTopology(mesh);
  EXPECT_GT(t.triangles, 0u);
  EXPECT_TRUE(t.manifold()) << "non-manifold edges " << t.nonManifoldEdges << ", vertices "
                            << t.nonManifoldVertices << ", inconsistent " << t.inconsistentEdges
                            << ", degenerate " << t.degenerateTriangles;
  EXPECT_TRUE(t.closed()) << t.boundaryEdges << " boundary edges";
  EXPECT_EQ(t.eulerCharacteristic, euler);
  // Every point is used and none is repeated.
  EXPECT_EQ(t.vertices, mesh.points.size());
  std::vector<Point3> sorted = mesh.points;
  std::sort(sorted.begin(), sorted.end());
  EXPECT_TRUE(std::adjacent_find(sorted.begin(), sorted.end()) == sorted.end());
}

/// The trilinear interpolant of values on the integer lattice [0, n)^3 (clamped outside): a field
/// whose sign at the grid points of featureSize 1 is chosen freely, to build every cell
/// configuration, ambiguous faces and tunnels included.
class LatticeField final : public frep::Field
{
public:
  LatticeField(int n, std::vector<double> values)
    : n_(n)
    , values_(std::move(values))
  {
  }
  std::unique_ptr<frep::FieldEvaluator> evaluator() const override
  {
    return std::make_unique<Evaluator>(*this);
  }

private:
  class Evaluator final : public frep::FieldEvaluator
  {
  public:
    explicit Evaluator(const LatticeField& f)
      : f_(f)
    {
    }
    void values(
      const double* x, const double* y, const double* z, double* out, std::size_t n) override
    {
      for (std::size_t i = 0; i < n; ++i)
      {
        Point3 g;
        out[i] = eval({ x[i], y[i], z[i] }, g);
      }
    }
    frep::Interval bound(const Box3&) override
    {
      const auto [lo, hi] = std::minmax_element(f_.values_.begin(), f_.values_.end());
      return { *lo, *hi, false };
    }
    double gradient(const Point3& p, Point3& grad) override { return eval(p, grad); }

  private:
    double eval(const Point3& p, Point3& grad) const
    {
      int c[3];
      double t[3];
      for (int a = 0; a < 3; ++a)
      {
        const double q = std::clamp(p[a], 0.0, double(f_.n_ - 1));
        c[a] = std::min(static_cast<int>(std::floor(q)), f_.n_ - 2);
        t[a] = q - c[a];
      }
      auto v = [&](int i, int j, int k)
      {
        return f_.values_[(c[0] + i) + f_.n_ * ((c[1] + j) + f_.n_ * (c[2] + k))];
      };
      double value = 0;
      grad = { 0, 0, 0 };
      for (int k = 0; k < 2; ++k)
      {
        for (int j = 0; j < 2; ++j)
        {
          for (int i = 0; i < 2; ++i)
          {
            const double wx = i ? t[0] : 1 - t[0], wy = j ? t[1] : 1 - t[1],
                         wz = k ? t[2] : 1 - t[2];
            const double vv = v(i, j, k);
            value += wx * wy * wz * vv;
            grad[0] += (i ? 1 : -1) * wy * wz * vv;
            grad[1] += wx * (j ? 1 : -1) * wz * vv;
            grad[2] += wx * wy * (k ? 1 : -1) * vv;
          }
        }
      }
      return value;
    }
    const LatticeField& f_;
  };
  int n_;
  std::vector<double> values_;
};

SurfaceMesh contour(const Expr& e, const Box3& box, double h, int threads = 0, bool sharp = true)
{
  SurfaceOptions options;
  options.featureSize = h;
  options.threads = threads;
  options.sharpFeatures = sharp;
  return contourSurface(*fieldOf(e), box, options);
}

} // namespace

// Unit sphere, h = 0.05, grid offset from the centre. Tolerances: a vertex lies on the tangent
// planes of the crossings of its cell, at most a cell diagonal (sqrt(3) h) from where they touch
// the sphere, so |p| - 1 <= 3 h^2 / 2 = 0.075 h (R = 1) plus the crossing error (3 false-position
// steps: ~1e-6 h); bound 0.1 h. A triangle centroid also sags by up to (edge/2)^2 / 2R with
// edges <= 2 h: 0.05 h more; bound 0.15 h. Points of the sphere lie within 0.1 h of the mesh by
// the same argument. Volume: the faceted surface sits within 0.1 h = 0.005 of the sphere, i.e.
// within 1.5% in volume at worst; asserted within 1%.
TEST(DiscretizeSurface, SphereAccuracyAndTopology)
{
  const double h = 0.05;
  const Box3 box{ { -1.31, -1.27, -1.23 }, { 1.29, 1.33, 1.26 } };
  const SurfaceMesh mesh = contour(frep::sphere({ 0, 0, 0 }, 1.0).function(), box, h);
  expectClosedManifold(mesh, 2);
  EXPECT_EQ(analyzeTopology(mesh).components, 1u);

  double vertexError = 0;
  for (const Point3& p : mesh.points)
  {
    vertexError = std::max(vertexError, std::abs(norm(p) - 1.0));
  }
  EXPECT_LT(vertexError, 0.1 * h);

  double centroidError = 0;
  for (const auto& t : mesh.triangles)
  {
    Point3 c{ 0, 0, 0 };
    for (auto v : t)
    {
      for (int a = 0; a < 3; ++a)
      {
        c[a] += mesh.points[v][a] / 3.0;
      }
    }
    centroidError = std::max(centroidError, std::abs(norm(c) - 1.0));
  }
  EXPECT_LT(centroidError, 0.15 * h);

  const MeshDistance distance(mesh, 2 * h);
  double sampleError = 0;
  for (const Point3& p : fibonacciSphere(20000))
  {
    sampleError = std::max(sampleError, distance(p));
  }
  EXPECT_LT(sampleError, 0.1 * h);
  std::printf("[ info ] sphere h = %g: %zu triangles; errors / h: vertices %.4f, centroids %.4f, "
              "samples %.4f; volume error %.4f%%\n",
    h, mesh.triangles.size(), vertexError / h, centroidError / h, sampleError / h,
    100 * (enclosedVolume(mesh) / (4.0 / 3.0 * M_PI) - 1));

  const double volume = enclosedVolume(mesh);
  EXPECT_NEAR(volume, 4.0 / 3.0 * M_PI, 0.01 * 4.0 / 3.0 * M_PI);
  EXPECT_GT(volume, 0); // outward orientation
  // Same with mass-point vertices: still a closed manifold, a little less accurate.
  const SurfaceMesh smooth = contour(frep::sphere({ 0, 0, 0 }, 1.0).function(), box, h, 0, false);
  expectClosedManifold(smooth, 2);
  EXPECT_NEAR(enclosedVolume(smooth), 4.0 / 3.0 * M_PI, 0.01 * 4.0 / 3.0 * M_PI);
}

// An axis-aligned box (the min of six half-spaces) with every face off the grid: each of its 8
// corners has a mesh vertex within 0.05 h, every vertex lies on the box surface, and the volume
// is exact to 1e-6.
TEST(DiscretizeSurface, BoxCornersAreSharp)
{
  const double h = 0.05;
  const Point3 lo{ -0.53, -0.47, -0.29 }, hi{ 0.61, 0.38, 0.44 };
  const Expr x = Expr::x(), y = Expr::y(), z = Expr::z();
  const Expr f =
    min(min(min(x - lo[0], hi[0] - x), min(y - lo[1], hi[1] - y)), min(z - lo[2], hi[2] - z));
  const SurfaceMesh mesh = contour(f, { { -1, -1, -1 }, { 1, 1, 1 } }, h);
  expectClosedManifold(mesh, 2);
  for (int c = 0; c < 8; ++c)
  {
    const Point3 corner{ (c & 1) ? hi[0] : lo[0], (c & 2) ? hi[1] : lo[1],
      (c & 4) ? hi[2] : lo[2] };
    double nearest = 1e300;
    for (const Point3& p : mesh.points)
    {
      nearest = std::min(nearest, norm(sub(p, corner)));
    }
    EXPECT_LT(nearest, 0.05 * h) << "corner " << c;
  }
  double offSurface = 0;
  for (const Point3& p : mesh.points)
  {
    double d = 1e300;
    for (int a = 0; a < 3; ++a)
    {
      d = std::min({ d, std::abs(p[a] - lo[a]), std::abs(p[a] - hi[a]) });
    }
    offSurface = std::max(offSurface, d);
  }
  EXPECT_LT(offSurface, 1e-6 * h);
  const double exact = (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]);
  EXPECT_NEAR(enclosedVolume(mesh), exact, 1e-6 * exact);
}

// A cylinder (radius 0.5, axis z) cut by the slab |z| <= 0.3 (off the grid): the two circles
// where they meet are sharp edges. Points of the circles lie within 0.1 h of the mesh (a chamfered
// edge is several times farther, as the mass-point variant shows), and every vertex lies within
// 3 h^2 / 2r = 0.15 h of the solid's surface (tangent planes at most a cell diagonal from where
// they touch the cylinder of radius r = 10 h).
TEST(DiscretizeSurface, CylinderSlabEdge)
{
  const double h = 0.05, r = 0.5, top = 0.3;
  const Expr x = Expr::x(), y = Expr::y(), z = Expr::z();
  const Expr f =
    min(frep::cylinder(frep::Axis::Z, { 0, 0, 0 }, r).function(), min(top - z, z + top));
  const Box3 box{ { -0.81, -0.83, -0.77 }, { 0.8, 0.8, 0.8 } };
  const SurfaceMesh mesh = contour(f, box, h);
  expectClosedManifold(mesh, 2);
  auto surfaceDistance = [&](const Point3& p)
  {
    const double radial = std::hypot(p[0], p[1]);
    const double dr = radial - r, dz = std::abs(p[2]) - top;
    if (dr <= 0 && dz <= 0)
    {
      return std::min(-dr, -dz);
    }
    return std::hypot(std::max(dr, 0.0), std::max(dz, 0.0));
  };
  double vertexError = 0;
  for (const Point3& p : mesh.points)
  {
    vertexError = std::max(vertexError, surfaceDistance(p));
  }
  EXPECT_LT(vertexError, 0.15 * h);
  auto edgeError = [&](const SurfaceMesh& m)
  {
    const MeshDistance distance(m, 2 * h);
    double worst = 0;
    for (int i = 0; i < 2000; ++i)
    {
      const double t = 2 * M_PI * i / 2000;
      for (double s : { -1.0, 1.0 })
      {
        worst = std::max(worst, distance({ r * std::cos(t), r * std::sin(t), s * top }));
      }
    }
    return worst;
  };
  const double sharpError = edgeError(mesh);
  EXPECT_LT(sharpError, 0.1 * h);
  const double smoothError = edgeError(contour(f, box, h, 0, false));
  EXPECT_GT(smoothError, 2 * sharpError);
  std::printf("[ info ] cylinder edge: vertices within %.4f h, circle within %.4f h (mass point: "
              "%.4f h)\n",
    vertexError / h, sharpError / h, smoothError / h);
  const double exact = M_PI * r * r * 2 * top;
  EXPECT_NEAR(enclosedVolume(mesh), exact, 0.005 * exact);
}

// A solid cut by the box is closed by the box faces: the unit ball in the box [0, 2]^3 (faces on
// the grid) and in [0.013, 2]^3 (faces off the grid) gives a closed octant.
TEST(DiscretizeSurface, SolidCutByTheBoxIsClosed)
{
  const double h = 0.05;
  const Expr ball = frep::sphere({ 0, 0, 0 }, 1.0).function();
  for (double lo : { 0.0, 0.013 })
  {
    const SurfaceMesh mesh = contour(ball, { { lo, lo, lo }, { 2, 2, 2 } }, h);
    expectClosedManifold(mesh, 2);
    for (const Point3& p : mesh.points)
    {
      EXPECT_GE(std::min({ p[0], p[1], p[2] }), lo);
    }
    // The part of the ball above lo on every axis, by the midpoint rule over (x, y).
    double exact = 0;
    const int n = 1000;
    const double d = (1 - lo) / n;
    for (int i = 0; i < n; ++i)
    {
      for (int j = 0; j < n; ++j)
      {
        const double x = lo + (i + 0.5) * d, y = lo + (j + 0.5) * d;
        exact += std::max(0.0, std::sqrt(std::max(0.0, 1 - x * x - y * y)) - lo) * d * d;
      }
    }
    EXPECT_NEAR(enclosedVolume(mesh), exact, 0.01 * exact);
  }
}

// A ball inside a hollow ball: three spheres (three components, Euler characteristic 6); the
// middle one bounds the cavity and faces into it, so the enclosed volume is the material's.
TEST(DiscretizeSurface, NestedShells)
{
  const Expr r2 = Expr::x() * Expr::x() + Expr::y() * Expr::y() + Expr::z() * Expr::z();
  // Inside for r < 0.4 or 0.7 < r < 1.
  const Expr f = max(0.16 - r2, min(r2 - 0.49, 1.0 - r2));
  const SurfaceMesh mesh = contour(f, { { -1.2, -1.2, -1.2 }, { 1.2, 1.2, 1.2 } }, 0.05);
  expectClosedManifold(mesh, 6);
  EXPECT_EQ(analyzeTopology(mesh).components, 3u);
  const double exact = 4.0 / 3.0 * M_PI * (1 - 0.343 + 0.064);
  EXPECT_NEAR(enclosedVolume(mesh), exact, 0.01 * exact);
}

// The benchmark shape at coarse sizes (and a gyroid with tunnels through single cells): always a
// closed manifold, whatever the resolution.
TEST(DiscretizeSurface, GyroidIsManifold)
{
  const Expr sg = frep::bundled::sphereGyroidField();
  for (double h : { 0.1, 0.17, 0.31 })
  {
    const SurfaceMesh mesh = contour(sg, { { -5, -5, -5 }, { 5, 5, 5 } }, h);
    SCOPED_TRACE(h);
    const MeshTopology t = analyzeTopology(mesh);
    EXPECT_TRUE(t.manifold()) << t.nonManifoldEdges << " " << t.nonManifoldVertices << " "
                              << t.inconsistentEdges;
    EXPECT_TRUE(t.closed());
    EXPECT_GT(enclosedVolume(mesh), 0);
  }
}

TEST(DiscretizeSurface, IdenticalForAnyThreadCount)
{
  const Expr sg = frep::bundled::sphereGyroidField();
  const Box3 box{ { -5, -5, -5 }, { 5, 5, 5 } };
  const SurfaceMesh one = contour(sg, box, 0.1, 1);
  const SurfaceMesh two = contour(sg, box, 0.1, 2);
  const SurfaceMesh any = contour(sg, box, 0.1, 0);
  ASSERT_GT(one.triangles.size(), 10000u);
  EXPECT_TRUE(one.points == two.points);
  EXPECT_TRUE(one.triangles == two.triangles);
  EXPECT_TRUE(one.points == any.points);
  EXPECT_TRUE(one.triangles == any.triangles);
}

TEST(DiscretizeSurface, ProgressAndCancellation)
{
  const auto field = fieldOf(frep::bundled::sphereGyroidField());
  const Box3 box{ { -5, -5, -5 }, { 5, 5, 5 } };
  SurfaceOptions options;
  options.featureSize = 0.1;
  std::vector<double> reported;
  options.progress = [&](double f)
  {
    reported.push_back(f);
    return true;
  };
  contourSurface(*field, box, options);
  ASSERT_GE(reported.size(), 2u);
  EXPECT_TRUE(std::is_sorted(reported.begin(), reported.end()));
  EXPECT_EQ(reported.back(), 1.0);
  int calls = 0;
  options.progress = [&](double)
  {
    ++calls;
    return false;
  };
  EXPECT_THROW(contourSurface(*field, box, options), frep::Cancelled);
  EXPECT_EQ(calls, 1);
}

TEST(DiscretizeSurface, RejectsBadArguments)
{
  const auto field = fieldOf(frep::sphere({ 0, 0, 0 }, 1.0).function());
  SurfaceOptions options;
  options.featureSize = 0.1;
  const Box3 good{ { -1, -1, -1 }, { 1, 1, 1 } };
  EXPECT_THROW(
    contourSurface(*field, { { 1, -1, -1 }, { -1, 1, 1 } }, options), std::invalid_argument);
  EXPECT_THROW(
    contourSurface(*field, { { -1, -1, -1 }, { 1, 1, -1 } }, options), std::invalid_argument);
  EXPECT_THROW(
    contourSurface(*field, { { -1, -1, NAN }, { 1, 1, 1 } }, options), std::invalid_argument);
  for (double h : { 0.0, -0.1, double(NAN), double(INFINITY) })
  {
    options.featureSize = h;
    EXPECT_THROW(contourSurface(*field, good, options), std::invalid_argument) << h;
  }
  options.featureSize = 1e-6;
  try
  {
    contourSurface(*field, good, options);
    ADD_FAILURE() << "an absurd resolution was accepted";
  }
  catch (const std::invalid_argument& e)
  {
    EXPECT_NE(std::string(e.what()).find("cells"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("8e+18"), std::string::npos) << e.what();
  }
  // A tighter limit is honoured, a sufficient one is not in the way.
  options.featureSize = 0.1;
  options.maxCells = 1000;
  EXPECT_THROW(contourSurface(*field, good, options), std::invalid_argument);
  options.maxCells = 22 * 22 * 22;
  EXPECT_NO_THROW(contourSurface(*field, good, options));
}

// A tunnel through two cells: the inside corners form a ring through cells A = [0,1]^3 and
// B = [1,2] x [0,1]^2 whose shared face is ambiguous with its inside corners apart (the trilinear
// solid is a solid torus). Each cell's patch is one disc that crosses the shared face twice, so
// one vertex per cell would make the edge between the two vertices bound four quads (a
// non-manifold pinch). Both vertices are split instead: the tunnel, narrower than a cell, is
// closed off and the surface is a sphere (Euler characteristic 2), one component, manifold.
TEST(DiscretizeSurface, TunnelThroughTwoCellsStaysManifold)
{
  std::vector<double> values(27, -1.0);
  auto set = [&](int i, int j, int k, double v)
  {
    values[i + 3 * (j + 3 * k)] = v;
  };
  for (const auto& c : std::vector<std::array<int, 3>>{ { 1, 0, 0 }, { 0, 0, 0 }, { 0, 1, 0 },
         { 0, 1, 1 }, { 1, 1, 1 }, { 2, 1, 1 }, { 2, 1, 0 }, { 2, 0, 0 } })
  {
    set(c[0], c[1], c[2], 0.1);
  }
  const LatticeField field(3, values);
  SurfaceOptions options;
  options.featureSize = 1;
  for (bool sharp : { true, false })
  {
    options.sharpFeatures = sharp;
    const SurfaceMesh mesh = contourSurface(field, { { 0, 0, 0 }, { 2, 1, 1 } }, options);
    expectClosedManifold(mesh, 2);
    EXPECT_EQ(analyzeTopology(mesh).components, 1u);
    EXPECT_GT(enclosedVolume(mesh), 0);
  }
}

// Random signs on a lattice (every kind of cell, ambiguous faces, tunnels, cuts by the box):
// the result is always a closed, consistently oriented 2-manifold without repeated points.
TEST(DiscretizeSurface, RandomLatticesAreClosedManifolds)
{
  std::mt19937_64 rng(12345);
  const int n = 6;
  int nonEmpty = 0;
  for (int trial = 0; trial < 300; ++trial)
  {
    std::vector<double> values(n * n * n);
    for (double& v : values)
    {
      // Uniform in [-1, 1), with exact zeros now and then.
      v = static_cast<double>(rng() % 2001) / 1000.0 - 1.0;
    }
    const LatticeField field(n, values);
    SurfaceOptions options;
    options.featureSize = 1;
    options.sharpFeatures = trial % 2 == 0;
    // Grid on the lattice or offset from it; box cutting the lattice or not.
    const double offset = trial % 3 == 0 ? 0.37 : 0.0;
    const Box3 box{ { offset, 0, 0 }, { n - 1.0, n - 1.0 - offset, n - 1.0 } };
    const SurfaceMesh mesh = contourSurface(field, box, options);
    SCOPED_TRACE(trial);
    if (mesh.triangles.empty())
    {
      continue;
    }
    ++nonEmpty;
    const MeshTopology t = analyzeTopology(mesh);
    ASSERT_TRUE(t.manifold()) << t.nonManifoldEdges << " " << t.nonManifoldVertices << " "
                              << t.inconsistentEdges << " " << t.degenerateTriangles;
    ASSERT_TRUE(t.closed());
    ASSERT_EQ(t.vertices, mesh.points.size());
    EXPECT_GT(enclosedVolume(mesh), 0);
  }
  EXPECT_GT(nonEmpty, 250);
}

namespace
{

/// An axis-aligned cube of half side 0.49 centred at (cx, 1, 1), as min of its slabs: its interval
/// bounds over a box are exact (up to outward rounding), so the octree's decisions can be counted
/// by hand.
Expr cubeAt(const Expr& cx)
{
  const auto slab = [](const Expr& v, const Expr& c)
  {
    return 0.49 - frep::abs(v - c);
  };
  return frep::min(frep::min(slab(Expr::x(), cx), slab(Expr::y(), Expr::constant(1))),
    slab(Expr::z(), Expr::constant(1)));
}

} // namespace

// Time coherence below the cell (SurfaceMemory): two cubes, A at x = 1 + 0.001 p (p a tape
// parameter) and B at x = 5, as max(A, B) over [0, 6] x [0, 2] x [0, 2] at h = 1/16. The tasks
// are nodes of 32 cells (2 units) and the blocks 8 cells (0.5 units), cell c spanning
// [(c - 1) h, c h]: only the tasks at x cells 0..31 (A) and 64..95 (B) may hold the surface.
// Each cube crosses blocks 1..3 of its task along each axis (its faces 0.49 from the centre;
// block 0 and the far ones are outside), 27 blocks of which the centre one is inside: 26 blocks
// a cube. In B's task A's interval lies below B's, so the pruned tape is B's alone and does not
// read p: when p changes, that task is copied whole and only A's 26 blocks are contoured.
TEST(DiscretizeSurface, MemoryReusesWhatTheParameterCannotReach)
{
  const auto tape = frep::Tape::compile(
    frep::max(cubeAt(1.0 + 0.001 * Expr::parameter(0)), cubeAt(Expr::constant(5))));
  const Box3 box{ { 0, 0, 0 }, { 6, 2, 2 } };
  SurfaceMemory memory;
  auto run = [&](double p, int threads, SurfaceMemory* m)
  {
    SurfaceOptions options;
    options.featureSize = 1.0 / 16;
    options.threads = threads;
    options.memory = m;
    return contourSurface(*frep::tapeField(tape, 0, { p }), box, options);
  };
  struct Expected
  {
    double p;
    std::size_t contoured, reused, tasksReused;
  };
  // First call: nothing kept. Then p changes: B's task is reused. Then p stays: everything is.
  // Then p = 5 (A's centre at 1.005, the same blocks): A's blocks again, but for three. In A's
  // blocks at x in [0.9375, 1.4375] and y in [1.4375, 1.9375] (block coordinates 16 and 24),
  // A's y slab is at most 0.49 - 0.4375 = 0.0525 and its x slab at least 0.49 - (1.4375 - c):
  // 0.0535 for c = 1.001, 0.0575 for c = 1.005, so min(x slab, y slab) is the y slab there and
  // the pruned tape does not read p (for c = 1, 0.0525 against 0.0525 prunes nothing: the second
  // call contours them). Those three blocks (z blocks 8, 16, 24) keep their mesh.
  const Expected calls[] = { { 0, 52, 0, 0 }, { 1, 26, 26, 1 }, { 1, 0, 52, 2 }, { 5, 23, 29, 1 } };
  for (const Expected& e : calls)
  {
    const SurfaceMesh kept = run(e.p, 0, &memory);
    const SurfaceMesh fresh = run(e.p, 1, nullptr);
    ASSERT_GT(fresh.triangles.size(), 100u);
    // The same mesh, bit for bit, as contouring from scratch.
    EXPECT_TRUE(kept.points == fresh.points) << "p = " << e.p;
    EXPECT_TRUE(kept.triangles == fresh.triangles) << "p = " << e.p;
    const SurfaceReuse& r = memory.lastCall();
    EXPECT_EQ(r.tasks, 2u) << "p = " << e.p;
    EXPECT_EQ(r.blocksContoured, e.contoured) << "p = " << e.p;
    EXPECT_EQ(r.blocksReused, e.reused) << "p = " << e.p;
    EXPECT_EQ(r.tasksReused, e.tasksReused) << "p = " << e.p;
  }
  // The counts do not depend on the threads either.
  SurfaceMemory one;
  run(0, 1, &one);
  const SurfaceMesh single = run(1, 1, &one);
  EXPECT_EQ(one.lastCall().blocksReused, 26u);
  EXPECT_TRUE(single.points == run(1, 2, nullptr).points);
  // Another grid forgets what was kept.
  SurfaceOptions finer;
  finer.featureSize = 1.0 / 32;
  finer.memory = &memory;
  contourSurface(*frep::tapeField(tape, 0, { 1.0 }), box, finer);
  EXPECT_EQ(memory.lastCall().blocksReused, 0u);
  EXPECT_GT(memory.lastCall().blocksContoured, 0u);
}

// A field that changes everywhere (a parameter in a term no interval can prune, as in an
// R-function) reuses nothing: its mesh really changes in every block.
TEST(DiscretizeSurface, MemoryReusesNothingOfAFieldThatChangesEverywhere)
{
  const Expr r = 1.0 - Expr::x() * Expr::x() - Expr::y() * Expr::y() - Expr::z() * Expr::z();
  const auto moving = frep::Tape::compile(r + 0.01 * frep::sin(Expr::parameter(0)));
  const Box3 box{ { -1.5, -1.5, -1.5 }, { 1.5, 1.5, 1.5 } };
  SurfaceMemory memory;
  SurfaceOptions options;
  options.featureSize = 0.05;
  options.memory = &memory;
  contourSurface(*frep::tapeField(moving, 0, { 0.0 }), box, options);
  const std::size_t all = memory.lastCall().blocksContoured;
  EXPECT_GT(all, 0u);
  const SurfaceMesh kept = contourSurface(*frep::tapeField(moving, 0, { 0.5 }), box, options);
  EXPECT_EQ(memory.lastCall().blocksContoured, all);
  EXPECT_EQ(memory.lastCall().blocksReused, 0u);
  options.memory = nullptr;
  const SurfaceMesh fresh = contourSurface(*frep::tapeField(moving, 0, { 0.5 }), box, options);
  EXPECT_TRUE(kept.points == fresh.points);
  EXPECT_TRUE(kept.triangles == fresh.triangles);
}
