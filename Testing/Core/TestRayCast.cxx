// SPDX-License-Identifier: BSD-3-Clause
// The ray caster (Render/RayCast.h) against analytic ray-sphere and ray-plane intersections:
// which pixels are covered (pixel by pixel; only centres within 1e-6 of a silhouette may differ)
// and at what depth (to the depth tolerance), orthographic and perspective, for fields that are
// distances and fields that are not; thin features; the camera's conventions; colour, time,
// determinism across thread counts and cancellation.
#include "FRep/Expr.h"
#include "FRep/ModelRegistry.h"
#include "Render/Camera.h"
#include "Render/RayCast.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <functional>
#include <limits>

using namespace ictk;
using namespace ictk::frep;
using namespace ictk::render;

namespace
{

const Box3 Cube{ { -1, -1, -1 }, { 1, 1, 1 } };
constexpr double Tolerance = 1e-7;
constexpr double Silhouette = 1e-6;

Expr ballField(const Point3& c, double r)
{
  const Expr x = Expr::x() - c[0], y = Expr::y() - c[1], z = Expr::z() - c[2];
  return Expr(r * r) - (square(x) + square(y) + square(z));
}

/// A ball as the analytic model: the first crossing of the ray (distance along it) and how far
/// the ray passes from the silhouette (its distance from the centre minus r).
struct Ball
{
  Point3 c;
  double r;
  /// Distance along the unit direction from o to the first intersection; +inf when missed.
  double first(const Point3& o, const Point3& d) const
  {
    const Point3 oc = sub(o, c);
    const double b = dot(d, oc);
    const double disc = b * b - (dot(oc, oc) - r * r);
    return disc < 0 ? std::numeric_limits<double>::infinity() : -b - std::sqrt(disc);
  }
  double silhouette(const Point3& o, const Point3& d) const
  {
    const Point3 oc = sub(o, c);
    const double b = dot(d, oc);
    return std::sqrt(std::max(0.0, dot(oc, oc) - b * b)) - r;
  }
};

struct Comparison
{
  int covered = 0;  // pixels covered in the render
  int compared = 0; // pixels away from every silhouette
  int coverage = 0; // of those, covered in one and not the other
  int depth = 0;    // of those covered in both, depth off by more than the tolerance
  double worst = 0; // the largest depth error among them
};

/// Calls visit(i, j, origin, unit direction) for the ray of every pixel centre.
template <typename Visit>
void forEachRay(const Camera& camera, Visit&& visit)
{
  for (int j = 0; j < camera.height(); ++j)
  {
    for (int i = 0; i < camera.width(); ++i)
    {
      const double u = camera.u(i), v = camera.v(j);
      const Point3 d = camera.direction(u, v);
      visit(i, j, camera.origin(u, v), scale(d, 1 / norm(d)));
    }
  }
}

/// Compares a render with the union of `balls` pixel by pixel.
Comparison compare(const RayCastResult& image, const Camera& camera, const std::vector<Ball>& balls)
{
  Comparison c;
  forEachRay(camera,
    [&](int i, int j, const Point3& o, const Point3& d)
    {
      double expected = std::numeric_limits<double>::infinity();
      bool nearEdge = false;
      for (const Ball& b : balls)
      {
        expected = std::min(expected, b.first(o, d));
        nearEdge = nearEdge || std::abs(b.silhouette(o, d)) <= Silhouette;
      }
      const double got = image.depth[static_cast<std::size_t>(j) * camera.width() + i];
      c.covered += std::isfinite(got) ? 1 : 0;
      if (nearEdge)
      {
        return;
      }
      ++c.compared;
      if (std::isfinite(got) != std::isfinite(expected))
      {
        ++c.coverage;
      }
      else if (std::isfinite(got))
      {
        const double error = std::abs(got - expected);
        c.worst = std::max(c.worst, error);
        c.depth += error > Tolerance ? 1 : 0;
      }
    });
  return c;
}

RayCastOptions precise(int threads = 2)
{
  RayCastOptions o;
  o.depthTolerance = Tolerance;
  o.threads = threads;
  return o;
}

void expectBalls(const Expr& field, const std::vector<Ball>& balls, Projection projection,
  const View& view = {}, int width = 64, int height = 48)
{
  const Camera camera = Camera::orbit(Cube, view, projection, width, height);
  const RayCastResult image = rayCast(Tape::compile(field), Cube, camera, precise());
  const Comparison c = compare(image, camera, balls);
  EXPECT_EQ(c.coverage, 0) << "pixels covered in one and not the other";
  EXPECT_EQ(c.depth, 0) << "worst depth error " << c.worst;
  EXPECT_GT(c.covered, width * height / 20);
  EXPECT_GT(c.compared, width * height * 9 / 10);
  EXPECT_GT(image.intervalEvaluations, 0);
  EXPECT_EQ(image.coveredPixels, c.covered);
}

} // namespace

TEST(RenderCamera, OrbitConventions)
{
  // Azimuth 0, elevation 0: on +x looking back along -x, +z up and so +y to the right.
  const Camera a = Camera::orbit(Cube, { 0, 0, 5 }, Projection::Perspective, 40, 20);
  for (int k = 0; k < 3; ++k)
  {
    EXPECT_NEAR(a.eye()[k], (Point3{ 5, 0, 0 })[k], 1e-15);
    EXPECT_NEAR(a.forward()[k], (Point3{ -1, 0, 0 })[k], 1e-15);
    EXPECT_NEAR(a.right()[k], (Point3{ 0, 1, 0 })[k], 1e-15);
    EXPECT_NEAR(a.up()[k], (Point3{ 0, 0, 1 })[k], 1e-15);
  }
  // A vertical field of view of 30 degrees over 20 rows; the image's centre is on the axis.
  EXPECT_NEAR(a.pixelSize(), 2 * std::tan(M_PI / 12) / 20, 1e-15);
  EXPECT_NEAR(a.u(19.5), 0, 1e-15);
  EXPECT_NEAR(a.v(9.5), 0, 1e-15);
  EXPECT_NEAR(a.v(19) - a.v(0), 19 * a.pixelSize(), 1e-14);
  // Azimuth 90, elevation 30: above the +y axis.
  const Camera b = Camera::orbit(Cube, { 90, 30, 2 }, Projection::Perspective, 8, 8);
  EXPECT_NEAR(b.eye()[0], 0, 1e-15);
  EXPECT_NEAR(b.eye()[1], 2 * std::cos(M_PI / 6), 1e-15);
  EXPECT_NEAR(b.eye()[2], 1, 1e-15);
  EXPECT_NEAR(dot(b.up(), Point3{ 0, 0, 1 }), std::cos(M_PI / 6), 1e-15);
  // Straight down: +y is up on the picture; the default distance is 2.5 half-diagonals.
  const Box3 box{ { 0, 0, 0 }, { 2, 4, 4 } };
  const Camera c = Camera::orbit(box, { 0, 90, 0 }, Projection::Orthographic, 10, 10);
  EXPECT_NEAR(c.eye()[2], 2 + 2.5 * 3, 1e-12);
  EXPECT_NEAR(c.up()[1], 1, 1e-15);
  EXPECT_NEAR(c.right()[0], 1, 1e-15);
  // Orthographic: 2.2 half-diagonals high, parallel rays.
  EXPECT_NEAR(c.pixelSize(), 2.2 * 3 / 10, 1e-15);
  EXPECT_EQ(c.direction(1, 2), c.forward());
  EXPECT_THROW(Camera::orbit(Cube, {}, Projection::Perspective, 0, 10), std::invalid_argument);
  EXPECT_THROW(
    Camera::orbit(Cube, {}, Projection::Perspective, 10, MaxImageSize + 1), std::invalid_argument);
  EXPECT_THROW(Camera::orbit(Cube, { std::nan(""), 0, 0 }, Projection::Perspective, 10, 10),
    std::invalid_argument);
  EXPECT_THROW(
    Camera::orbit(Cube, { 0, 0, -1 }, Projection::Perspective, 10, 10), std::invalid_argument);
}

TEST(RenderRayCast, SphereOrthographic)
{
  const Ball ball{ { 0.1, -0.05, 0.02 }, 0.7 };
  expectBalls(ballField(ball.c, ball.r), { ball }, Projection::Orthographic);
}

TEST(RenderRayCast, SpherePerspective)
{
  const Ball ball{ { 0.1, -0.05, 0.02 }, 0.7 };
  expectBalls(ballField(ball.c, ball.r), { ball }, Projection::Perspective);
  // Closer, from below, through a non-square image.
  expectBalls(
    ballField(ball.c, ball.r), { ball }, Projection::Perspective, { -70, -35, 2.2 }, 50, 70);
}

TEST(RenderRayCast, FieldsThatAreNotDistances)
{
  // HyperFun's scale: 1e4 (r^2 - |p|^2); and its cube, whose gradient vanishes on the surface
  // (sphere tracing cannot step on either).
  const Ball ball{ { -0.1, 0.05, 0 }, 0.6 };
  const Expr f = ballField(ball.c, ball.r);
  expectBalls(Expr(1e4) * f, { ball }, Projection::Orthographic);
  expectBalls(f * f * f, { ball }, Projection::Perspective);
  // A union (max) of two fields of very different scales, where pruning picks one per region.
  const Ball other{ { 0.45, 0.3, 0.2 }, 0.35 };
  expectBalls(max(Expr(1e-3) * f, Expr(50.0) * ballField(other.c, other.r)), { ball, other },
    Projection::Perspective, { 200, 10, 0 });
}

TEST(RenderRayCast, ThinSlabIsFound)
{
  // An oblique slab 2e-5 thick, cut to a ball of radius 0.8: a hundred times thinner than the
  // 2e-3 step of a uniform march, which misses it on most rays.
  const Point3 n{ 1 / std::sqrt(3.0), 1 / std::sqrt(3.0), 1 / std::sqrt(3.0) };
  const double offset = 0.05, half = 1e-5;
  const Expr plane = n[0] * Expr::x() + n[1] * Expr::y() + n[2] * Expr::z() - offset;
  const Expr f = min(Expr(half) - abs(plane), ballField({ 0, 0, 0 }, 0.8));
  const TapePtr tape = Tape::compile(f);
  for (Projection projection : { Projection::Orthographic, Projection::Perspective })
  {
    const Camera camera = Camera::orbit(Cube, { 20, 10, 4 }, projection, 40, 30);
    const RayCastResult image = rayCast(tape, Cube, camera, precise());
    PointEvaluator point(tape);
    int covered = 0, marchMisses = 0;
    forEachRay(camera,
      [&](int i, int j, const Point3& o, const Point3& d)
      {
        // The face towards the camera, where the ray crosses it.
        const double front = dot(n, d) < 0 ? offset + half : offset - half;
        const double t = (front - dot(n, o)) / dot(n, d);
        const Point3 q = add(o, scale(d, t));
        const double got = image.depth[static_cast<std::size_t>(j) * camera.width() + i];
        if (std::abs(norm(q) - 0.8) < 1e-4)
        {
          return; // the rim, where the slab meets the ball's surface
        }
        if (norm(q) > 0.8)
        {
          EXPECT_FALSE(std::isfinite(got)) << i << "," << j;
          return;
        }
        ++covered;
        EXPECT_NEAR(got, t, Tolerance) << i << "," << j;
        bool seen = false;
        for (double s = 0; s < 8 && !seen; s += 2e-3)
        {
          const Point3 p = add(o, scale(d, s));
          seen = point.eval(p[0], p[1], p[2]) >= 0;
        }
        marchMisses += seen ? 0 : 1;
      });
    EXPECT_GT(covered, 80);
    EXPECT_GT(marchMisses, covered / 2);
  }
}

TEST(RenderRayCast, ColourShadingAndTime)
{
  // The walnut's shell is coloured (0.55, 0.36, 0.2): every covered pixel keeps those ratios
  // (up to 8-bit rounding) under Lambert shading.
  const ModelInfo& info = findModel("walnut");
  const Hypervolume walnut = info.build();
  const Box3 box{ info.boundsLo, info.boundsHi };
  const Camera camera = Camera::orbit(box, {}, Projection::Perspective, 48, 36);
  const RayCastResult image = rayCast(walnut, box, camera);
  ASSERT_GT(image.coveredPixels, 200);
  int checked = 0;
  for (std::size_t p = 0; p < image.depth.size(); ++p)
  {
    const std::uint8_t* rgba = &image.colour[4 * p];
    if (!std::isfinite(image.depth[p]))
    {
      EXPECT_EQ(rgba[3], 0);
      continue;
    }
    EXPECT_EQ(rgba[3], 255);
    if (rgba[0] > 60 && !(rgba[0] == rgba[1] && rgba[1] == rgba[2])) // grey: unresolved
    {
      EXPECT_NEAR(rgba[1] / double(rgba[0]), 0.36 / 0.55, 2.0 / rgba[0]);
      EXPECT_NEAR(rgba[2] / double(rgba[0]), 0.2 / 0.55, 2.0 / rgba[0]);
      ++checked;
    }
  }
  EXPECT_GT(checked, 100);
  // Without a colour attribute: grey. Facing the eye at the image's centre (the sphere's
  // normal is along the ray): ambient + diffuse = full brightness of 0.8.
  const Camera centred = Camera::orbit(Cube, {}, Projection::Orthographic, 31, 31);
  const RayCastResult grey = rayCast(Tape::compile(ballField({ 0, 0, 0 }, 0.5)), Cube, centred);
  const std::uint8_t* middle = &grey.colour[4 * (15 * 31 + 15)];
  EXPECT_EQ(middle[0], 204);
  EXPECT_EQ(middle[1], 204);
  EXPECT_EQ(middle[2], 204);
  // Time: a ball whose radius is 0.3 + 0.4 t, at t = 1.
  const Expr growing = square(Expr(0.3) + Expr(0.4) * Expr::t()) -
    (square(Expr::x()) + square(Expr::y()) + square(Expr::z()));
  RayCastOptions at1 = precise();
  at1.time = 1;
  const Camera camera2 = Camera::orbit(Cube, {}, Projection::Orthographic, 40, 40);
  const RayCastResult timed = rayCast(Tape::compile(growing), Cube, camera2, at1);
  const Comparison c = compare(timed, camera2, { Ball{ { 0, 0, 0 }, 0.7 } });
  EXPECT_EQ(c.coverage, 0);
  EXPECT_EQ(c.depth, 0);
}

TEST(RenderRayCast, NothingInView)
{
  // A ball outside the box is clipped away: an empty, transparent picture.
  const Camera camera = Camera::orbit(Cube, {}, Projection::Perspective, 20, 10);
  const RayCastResult image = rayCast(Tape::compile(ballField({ 3, 0, 0 }, 1)), Cube, camera);
  EXPECT_EQ(image.coveredPixels, 0);
  for (std::size_t p = 0; p < image.depth.size(); ++p)
  {
    EXPECT_TRUE(std::isinf(image.depth[p]));
    EXPECT_EQ(image.colour[4 * p + 3], 0);
  }
}

TEST(RenderRayCast, CameraInsideTheSolid)
{
  // The eye at distance 0.3 from the centre of a ball of radius 0.9: every ray starts inside.
  const Camera camera = Camera::orbit(Cube, { 0, 0, 0.3 }, Projection::Perspective, 16, 12);
  const RayCastResult inside = rayCast(Tape::compile(ballField({ 0, 0, 0 }, 0.9)), Cube, camera);
  EXPECT_EQ(inside.coveredPixels, 16 * 12);
  EXPECT_EQ(inside.cutPixels, 16 * 12);
  // A ball larger than the box is cut by its faces: the pixels that see a face are cut, at the
  // depth where the ray enters the box.
  const Camera front = Camera::orbit(Cube, { 0, 0, 3 }, Projection::Orthographic, 16, 16);
  const RayCastResult cut = rayCast(Tape::compile(ballField({ 0, 0, 0 }, 1.2)), Cube, front);
  EXPECT_GT(cut.cutPixels, 0);
  EXPECT_LT(cut.cutPixels, cut.coveredPixels);
  EXPECT_DOUBLE_EQ(cut.depth[8 * 16 + 8], 2.0); // the face x = 1, seen from x = 3
  // Outside a ball nothing is cut.
  EXPECT_EQ(rayCast(Tape::compile(ballField({ 0, 0, 0 }, 0.5)), Cube, front).cutPixels, 0);
}

TEST(RenderRayCast, SameResultOnAnyThreadCount)
{
  const ModelInfo& info = findModel("walnut");
  const Hypervolume walnut = info.build();
  const Box3 box{ info.boundsLo, info.boundsHi };
  const Camera camera = Camera::orbit(box, { 10, 30, 0 }, Projection::Perspective, 96, 72);
  RayCastOptions one, two;
  one.threads = 1;
  two.threads = 2;
  two.tileSize = one.tileSize;
  const RayCastResult a = rayCast(walnut, box, camera, one);
  const RayCastResult b = rayCast(walnut, box, camera, two);
  ASSERT_EQ(a.colour.size(), b.colour.size());
  ASSERT_EQ(a.depth.size(), b.depth.size());
  EXPECT_EQ(std::memcmp(a.colour.data(), b.colour.data(), a.colour.size()), 0);
  EXPECT_EQ(std::memcmp(a.depth.data(), b.depth.data(), a.depth.size() * sizeof(double)), 0);
  EXPECT_EQ(a.intervalEvaluations, b.intervalEvaluations);
  EXPECT_EQ(a.pointEvaluations, b.pointEvaluations);
  EXPECT_GT(a.coveredPixels, 1000);
}

TEST(RenderRayCast, Cancellation)
{
  const Camera camera = Camera::orbit(Cube, {}, Projection::Perspective, 64, 64);
  const TapePtr tape = Tape::compile(ballField({ 0, 0, 0 }, 0.5));
  RayCastOptions stop;
  stop.threads = 1;
  stop.progress = [](double)
  {
    return false;
  };
  EXPECT_THROW(rayCast(tape, Cube, camera, stop), Cancelled);
  // Stopped half way: the loop stops taking tiles and the render throws after it.
  int calls = 0;
  double last = 0;
  RayCastOptions half;
  half.threads = 1; // the calling thread does every tile: the reports are deterministic
  half.tileSize = 8;
  half.progress = [&](double f)
  {
    ++calls;
    last = f;
    return f < 0.5;
  };
  EXPECT_THROW(rayCast(tape, Cube, camera, half), Cancelled);
  EXPECT_GE(last, 0.5);
  EXPECT_LT(last, 1.0);
  // Without a callback, or with one that never asks to stop, it completes (and reports 1).
  RayCastOptions go;
  go.progress = [&](double f)
  {
    last = f;
    return true;
  };
  EXPECT_GT(rayCast(tape, Cube, camera, go).coveredPixels, 0);
  EXPECT_EQ(last, 1.0);
}

TEST(RenderRayCast, BadInput)
{
  const Camera camera = Camera::orbit(Cube, {}, Projection::Perspective, 8, 8);
  EXPECT_THROW(rayCast(TapePtr(), Cube, camera), std::invalid_argument);
  RayCastOptions o;
  o.depthTolerance = -1;
  EXPECT_THROW(rayCast(Tape::compile(Expr::x()), Cube, camera, o), std::invalid_argument);
  o = {};
  o.tileSize = 0;
  EXPECT_THROW(rayCast(Tape::compile(Expr::x()), Cube, camera, o), std::invalid_argument);
  EXPECT_THROW(rayCast(Tape::compile(Expr::parameter(0)), Cube, camera), std::invalid_argument);
}
