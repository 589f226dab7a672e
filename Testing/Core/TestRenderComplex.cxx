// SPDX-License-Identifier: BSD-3-Clause
// Complexes composed through one depth buffer (Render/ComplexRender.h) and the exact rasteriser
// (Render/Rasterize.h), against hand-known geometry: a tube passing behind (and in front of) a
// ray-cast ball is hidden exactly where the ball's analytic silhouette says, at the depths of
// the analytic cylinder and ball; a square of two triangles and a sphere cover exactly their
// analytic pixels; colours from attributes and a colour map for a scalar; the flower with every
// cell dimension in view; thread-count independence; bad input.
#include "Complex/Complex.h"
#include "Complex/Discretization.h"
#include "FRep/Expr.h"
#include "FRep/ModelRegistry.h"
#include "FRep/Tape.h"
#include "Lang/ComplexFile.h"
#include "Render/Camera.h"
#include "Render/ComplexRender.h"
#include "Render/Rasterize.h"
#include "Render/RayCast.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

using namespace ictk;
using namespace ictk::frep;
using namespace ictk::render;
using complex::CellId;

namespace
{

constexpr double Silhouette = 1e-6; // rays this close to a silhouette may go either way
constexpr double Inf = std::numeric_limits<double>::infinity();

FieldPtr constant(double v)
{
  return tapeField(Tape::compile(Expr(v)));
}

/// Binds a constant colour (or a 1-component scalar) named `name` to a cell.
void bind(complex::Complex& c, CellId id, const std::string& name, std::vector<double> values)
{
  auto f = std::make_shared<complex::AttributeFunction>();
  f->name = name + std::to_string(id);
  for (double v : values)
  {
    f->components.push_back(constant(v));
    f->text.push_back(std::to_string(v));
  }
  c.bindAttribute(id, complex::AttributeBinding{ name, f, 0 });
}

/// A complex: a ball of radius r at the origin (a 3D F cell, ray cast) and a straight tube along
/// y at (x, z) = (tubeX, tubeZ) from y = -0.9 to 0.9 (a 1D B cell), red and blue.
struct BallAndTube
{
  complex::Complex complex;
  CellId ball = 0, tube = 0;
  double r = 0.5;
  double tubeX = 0, tubeZ = 0.1;
  BallAndTube(double x)
    : tubeX(x)
  {
    const Expr p2 = square(Expr::x()) + square(Expr::y()) + square(Expr::z());
    ball = complex.addCell(complex::frepCell(
      "ball", {}, { Expr(r * r) - p2 }, { { -0.6, -0.6, -0.6 }, { 0.6, 0.6, 0.6 } }));
    complex::ExplicitGeometry g;
    g.points = { { tubeX, -0.9, tubeZ }, { tubeX, 0, tubeZ }, { tubeX, 0.9, tubeZ } };
    g.polylines = { { 0, 1, 2 } };
    tube = complex.addCell(complex::explicitCell("tube", 1, g));
    complex.declareAttribute("colour", { 3, { 0.5, 0.5, 0.5 }, { 0, 0, 0 } });
    bind(complex, ball, "colour", { 1, 0, 0 });
    bind(complex, tube, "colour", { 0, 0, 1 });
  }
  complex::ComplexMesh mesh() const
  {
    complex::DiscretizationOptions o;
    o.cells = render::meshedCells(complex);
    return complex::discretizeComplex(complex, o);
  }
};

/// Looking down -x from +x (azimuth 0, elevation 0): right is +y, up is +z.
Camera sideCamera(const complex::Complex& c, Projection projection, int w, int h)
{
  return Camera::orbit(complex::complexBounds(c), View{ 0, 0, 4 }, projection, w, h);
}

void checkBallAndTube(double tubeX, Projection projection)
{
  BallAndTube scene(tubeX);
  const complex::ComplexMesh mesh = scene.mesh();
  const Camera camera = sideCamera(scene.complex, projection, 120, 90);
  ComplexRenderOptions options;
  options.tubeRadius = 0.05;
  options.threads = 2;
  const ComplexRenderResult result = renderComplex(scene.complex, mesh, camera, options);
  const Canvas& canvas = result.canvas;
  const double rt = options.tubeRadius;
  int ballPixels = 0, tubePixels = 0, hiddenTube = 0, compared = 0;
  for (int j = 0; j < camera.height(); ++j)
  {
    for (int i = 0; i < camera.width(); ++i)
    {
      const double u = camera.u(i), v = camera.v(j);
      const Point3 o = camera.origin(u, v);
      const Point3 dv = camera.direction(u, v);
      const Point3 d = scale(dv, 1 / norm(dv));
      // The ball: the ray's distance from the centre against r.
      const double b = dot(d, o);
      const Point3 foot = sub(o, scale(d, b));
      const double ballGap = norm(foot) - scene.r;
      const double ballDepth =
        ballGap < 0 ? -b - std::sqrt(scene.r * scene.r - dot(foot, foot)) : Inf;
      // The tube's axis is the line (tubeX, y, tubeZ): the ray's distance from it, where the
      // nearest point's y lies well inside the segment (the ends are balls: left out here).
      const Point3 axis{ 0, 1, 0 }, a{ scene.tubeX, 0, scene.tubeZ };
      const Point3 n = cross(d, axis);
      const double lineGap = std::abs(dot(sub(o, a), n)) / norm(n) - rt;
      // The nearest point on the axis: solve for its y.
      const Point3 w0 = sub(o, a);
      const double dd = dot(d, d), da = dot(d, axis), ww = dot(axis, axis);
      const double den = dd * ww - da * da;
      const double yAxis = (dd * dot(axis, w0) - da * dot(d, w0)) / den;
      if (std::abs(ballGap) < Silhouette || std::abs(lineGap) < Silhouette ||
        std::abs(yAxis) > 0.85)
      {
        continue;
      }
      ++compared;
      const std::size_t p = canvas.index(i, j);
      const int who = canvas.owner[p];
      if (ballGap < 0 && (lineGap > 0 || tubeX < 0))
      {
        // The ball's silhouette: the ball is what shows (the tube, if on this ray, is behind).
        ASSERT_EQ(who, static_cast<int>(scene.ball)) << i << "," << j;
        EXPECT_NEAR(canvas.depth[p], ballDepth, 1e-6) << i << "," << j;
        EXPECT_EQ(canvas.colour[4 * p + 2], 0);
        ++ballPixels;
        hiddenTube += lineGap < 0 ? 1 : 0;
      }
      else if (lineGap < 0)
      {
        ASSERT_EQ(who, static_cast<int>(scene.tube)) << i << "," << j;
        EXPECT_EQ(canvas.colour[4 * p + 0], 0);
        if (projection == Projection::Orthographic)
        {
          // Rays along -x: the cylinder's near side, from the image plane through the eye.
          const double z = camera.origin(u, v)[2] - scene.tubeZ;
          const double x = scene.tubeX + std::sqrt(rt * rt - z * z);
          EXPECT_NEAR(canvas.depth[p], camera.eye()[0] - x, 1e-9) << i << "," << j;
        }
        ++tubePixels;
      }
      else
      {
        EXPECT_EQ(who, -1) << i << "," << j;
        EXPECT_EQ(canvas.depth[p], Inf);
      }
    }
  }
  EXPECT_GT(compared, 4000);
  EXPECT_GT(ballPixels, 500);
  EXPECT_GT(tubePixels, 40);
  if (tubeX < 0)
  {
    EXPECT_GT(hiddenTube, 50); // the tube does pass behind the ball
  }
  EXPECT_EQ(result.pixelsByDimension[0], 0);
  EXPECT_EQ(result.pixelsByDimension[2], 0);
  EXPECT_GE(result.pixelsByDimension[1], tubePixels);
  EXPECT_GE(result.pixelsByDimension[3], ballPixels);
  EXPECT_EQ(result.unresolvedPixels, 0);
}

} // namespace

TEST(RenderComplex, TubeBehindBallIsHiddenByItsSilhouette)
{
  checkBallAndTube(-0.8, Projection::Orthographic);
  checkBallAndTube(-0.8, Projection::Perspective);
}

TEST(RenderComplex, TubeInFrontOfBallHidesIt)
{
  // The ray caster stops at the tube's depth: the ball shows only around it.
  checkBallAndTube(0.8, Projection::Orthographic);
  checkBallAndTube(0.8, Projection::Perspective);
}

TEST(RenderRasterize, SquareAndSphereCoverTheirAnalyticPixels)
{
  // An orthographic camera looking down -z at a unit square in z = 0.25 (two triangles) and a
  // ball of radius 0.3 at (0.5, 0.5, 0.5) partly in front of it.
  const Box3 box{ { -1, -1, -1 }, { 1, 1, 1 } };
  const Camera camera = Camera::orbit(box, View{ 0, 90, 3 }, Projection::Orthographic, 64, 64);
  Primitives square;
  square.points = { { 0, 0, 0.25 }, { 1, 0, 0.25 }, { 1, 1, 0.25 }, { 0, 1, 0.25 },
    { 0.5, 0.5, 0.5 } };
  // The second triangle is wound the other way: its normal points away from the eye, and the
  // normal buffer turns it round.
  square.triangles = { { 0, 1, 2 }, { 0, 3, 2 } };
  square.spheres = { 4 };
  square.sphereRadius = 0.3;
  square.paints.assign(5, Paint{});
  square.paints[4].rgb = { 0, 1, 0 };
  Canvas canvas(64, 64);
  rasterize(canvas, camera, square);
  int inSquare = 0, inBall = 0;
  for (int j = 0; j < 64; ++j)
  {
    for (int i = 0; i < 64; ++i)
    {
      const Point3 o = camera.origin(camera.u(i), camera.v(j));
      const std::size_t p = canvas.index(i, j);
      const double dx = o[0] - 0.5, dy = o[1] - 0.5;
      const double ballGap = std::sqrt(dx * dx + dy * dy) - 0.3;
      const bool square01 =
        o[0] > Silhouette && o[0] < 1 - Silhouette && o[1] > Silhouette && o[1] < 1 - Silhouette;
      const bool edge = std::abs(o[0]) < Silhouette || std::abs(o[0] - 1) < Silhouette ||
        std::abs(o[1]) < Silhouette || std::abs(o[1] - 1) < Silhouette;
      if (std::abs(ballGap) < Silhouette || edge)
      {
        continue;
      }
      if (ballGap < 0)
      {
        ++inBall;
        const double dz = std::sqrt(0.09 - dx * dx - dy * dy);
        EXPECT_NEAR(canvas.depth[p], o[2] - (0.5 + dz), 1e-12);
        EXPECT_NEAR(canvas.normal[3 * p + 0], dx / 0.3, 1e-6);
        EXPECT_NEAR(canvas.normal[3 * p + 1], dy / 0.3, 1e-6);
        EXPECT_NEAR(canvas.normal[3 * p + 2], dz / 0.3, 1e-6);
        EXPECT_EQ(canvas.colour[4 * p + 0], 0);
        EXPECT_GT(canvas.colour[4 * p + 1], 0);
      }
      else if (square01)
      {
        ++inSquare;
        EXPECT_NEAR(canvas.depth[p], o[2] - 0.25, 1e-12);
        EXPECT_EQ(canvas.normal[3 * p + 0], 0);
        EXPECT_EQ(canvas.normal[3 * p + 1], 0);
        EXPECT_EQ(canvas.normal[3 * p + 2], 1);
        // Facing the eye: full light on neutral grey.
        EXPECT_EQ(canvas.colour[4 * p + 0], static_cast<int>(std::lround(255 * NeutralGrey)));
      }
      else
      {
        EXPECT_EQ(canvas.depth[p], Inf) << i << "," << j;
        EXPECT_EQ(canvas.colour[4 * p + 3], 0);
        EXPECT_EQ(canvas.normal[3 * p + 2], 0);
      }
    }
  }
  // The square is 1 x 1 of a 2.2 * sqrt(3) high view: about (64 / 3.81)^2 pixels, the ball's
  // disc pi 0.09 of them.
  EXPECT_GT(inSquare + inBall, 250);
  EXPECT_GT(inBall, 60);
}

TEST(RenderBuffers, OpenGlWindowDepthAndNormalsOfABall)
{
  // Seed 003 item 37: the depth buffer in OpenGL's convention ([0, 1], less is nearer) and the
  // normal buffer, for the ball r^2 - |p|^2 (r = 0.5) seen from (0, 0, 10) down -z, 21 x 21
  // pixels 0.05 apart (an orthographic height of 1.05; a perspective one of 6 degrees).
  const Expr p2 = square(Expr::x()) + square(Expr::y()) + square(Expr::z());
  const TapePtr ball = Tape::compile(Expr(0.25) - p2);
  const Box3 box{ { -0.6, -0.6, -0.6 }, { 0.6, 0.6, 0.6 } };
  const std::size_t centre = 10 * 21 + 10, right = 10 * 21 + 16; // (0, 0) and (0.3, 0)
  {
    const Camera camera = Camera::lookAt(
      { 0, 0, 10 }, { 0, 0, 0 }, { 0, 1, 0 }, Projection::Orthographic, 30, 0.525, 21, 21);
    const RayCastResult r = rayCast(ball, box, camera);
    ASSERT_EQ(r.normal.size(), 3u * 21 * 21);
    // Near plane 5, far 15: the top of the ball (z = 0.5, depth 9.5) at (9.5 - 5) / 10; at
    // x = 0.3 the surface is at z = 0.4 (depth 9.6), its normal (0.6, 0, 0.8).
    const std::vector<double> w = windowDepth(r.depth, camera, 5, 15);
    EXPECT_NEAR(w[centre], 0.45, 1e-7);
    EXPECT_NEAR(w[right], 0.46, 1e-7);
    EXPECT_EQ(w[0], 1); // the corner sees nothing: the cleared buffer
    EXPECT_NEAR(r.normal[3 * right + 0], 0.6, 1e-6);
    EXPECT_NEAR(r.normal[3 * right + 1], 0, 1e-6);
    EXPECT_NEAR(r.normal[3 * right + 2], 0.8, 1e-6);
    EXPECT_NEAR(r.normal[3 * centre + 2], 1, 1e-6);
    EXPECT_EQ(r.normal[0], 0);
    // Clamped outside the planes (GL's depth clamping), and nearer is less.
    EXPECT_EQ(windowDepth(r.depth, camera, 9.55, 15)[centre], 0);
    EXPECT_EQ(windowDepth(r.depth, camera, 5, 9.55)[right], 1);
    EXPECT_LT(w[centre], w[right]);
    const std::vector<double> back = depthFromWindow(w, camera, 5, 15);
    EXPECT_NEAR(back[centre], r.depth[centre], 1e-12);
    EXPECT_EQ(back[0], Inf);
  }
  {
    const Camera camera =
      Camera::lookAt({ 0, 0, 10 }, { 0, 0, 0 }, { 0, 1, 0 }, Projection::Perspective, 6, 1, 21, 21);
    const RayCastResult r = rayCast(ball, box, camera);
    // Near 1, far 100: window depth = 100 (z - 1) / (99 z) for the depth z along the axis; at the
    // centre z = 9.5.
    const std::vector<double> w = windowDepth(r.depth, camera, 1, 100);
    EXPECT_NEAR(w[centre], 100 * 8.5 / (99 * 9.5), 1e-9);
    // Off the axis the buffer holds the distance along the ray; the window depth takes the
    // depth along the axis, z = distance * cos(angle): the hit point's own z.
    const std::size_t p = right;
    ASSERT_TRUE(std::isfinite(r.depth[p]));
    const Point3 d = camera.direction(camera.u(16), camera.v(10));
    const Point3 hit = add(camera.eye(), scale(d, r.depth[p] / norm(d)));
    const double z = 10 - hit[2];
    EXPECT_NEAR(w[p], 100 * (z - 1) / (99 * z), 1e-9);
    // The normal there is the hit point's direction from the centre, facing the eye.
    EXPECT_NEAR(r.normal[3 * p + 0], hit[0] / 0.5, 1e-5);
    EXPECT_NEAR(r.normal[3 * p + 2], hit[2] / 0.5, 1e-5);
    const std::vector<double> back = depthFromWindow(w, camera, 1, 100);
    EXPECT_NEAR(back[p], r.depth[p], 1e-9);
    EXPECT_THROW(windowDepth(r.depth, camera, 0, 100), std::invalid_argument);
    EXPECT_THROW(windowDepth(r.depth, camera, 5, 5), std::invalid_argument);
    EXPECT_THROW(windowDepth({ 1.0, 2.0 }, camera, 1, 100), std::invalid_argument);
  }
}

TEST(RenderBuffers, RenderersCheckTheCanvasIsForTheCamera)
{
  // Item 37's IsValidFor: a canvas of another size, or with a buffer of the wrong length, is
  // refused before anything is written.
  const Box3 box{ { -1, -1, -1 }, { 1, 1, 1 } };
  const Camera camera = Camera::orbit(box, View{ 0, 90, 3 }, Projection::Orthographic, 16, 12);
  Primitives triangle;
  triangle.points = { { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 } };
  triangle.triangles = { { 0, 1, 2 } };
  Canvas good(16, 12);
  EXPECT_TRUE(good.isValidFor(camera));
  Canvas wide(17, 12);
  EXPECT_FALSE(wide.isValidFor(camera));
  EXPECT_THROW(rasterize(wide, camera, triangle), std::invalid_argument);
  Canvas cut(16, 12);
  cut.normal.resize(10);
  EXPECT_FALSE(cut.isValidFor(camera));
  EXPECT_THROW(rasterize(cut, camera, triangle), std::invalid_argument);
  EXPECT_TRUE(std::all_of(cut.depth.begin(), cut.depth.end(), [](double d) { return d == Inf; }));
  EXPECT_GT(rasterize(good, camera, triangle), 0);
}

TEST(RenderComplex, ScalarAttributeThroughColourMap)
{
  // Two balls with a scalar 1 and 2: the map's ends, shaded by the light only.
  complex::Complex c;
  const Expr p2a = square(Expr::x() + 0.5) + square(Expr::y()) + square(Expr::z());
  const Expr p2b = square(Expr::x() - 0.5) + square(Expr::y()) + square(Expr::z());
  const CellId a = c.addCell(
    complex::frepCell("a", {}, { Expr(0.16) - p2a }, { { -1, -0.5, -0.5 }, { 0, 0.5, 0.5 } }));
  const CellId b = c.addCell(
    complex::frepCell("b", {}, { Expr(0.16) - p2b }, { { 0, -0.5, -0.5 }, { 1, 0.5, 0.5 } }));
  c.declareAttribute("material", { 1, { 0 }, { -1 } });
  bind(c, a, "material", { 1 });
  bind(c, b, "material", { 2 });
  const Camera camera =
    Camera::orbit(complex::complexBounds(c), View{ 90, 0, 0 }, Projection::Orthographic, 80, 40);
  ComplexRenderOptions options;
  options.colours.attribute = "material";
  options.colours.map = "rainbow";
  const ComplexRenderResult r = renderComplex(c, complex::ComplexMesh{}, camera, options);
  EXPECT_EQ(r.scalarRange[0], 1);
  EXPECT_EQ(r.scalarRange[1], 2);
  int seen[2] = { 0, 0 };
  for (std::size_t p = 0; p < r.canvas.owner.size(); ++p)
  {
    if (r.canvas.owner[p] < 0)
    {
      continue;
    }
    const bool first = r.canvas.owner[p] == static_cast<int>(a);
    ++seen[first ? 0 : 1];
    // rainbow: blue at 1, red at 2, times the light.
    const std::uint8_t* rgba = &r.canvas.colour[4 * p];
    const double light = r.canvas.light[p];
    EXPECT_EQ(rgba[first ? 2 : 0], std::lround(255 * std::clamp(light, 0.0, 1.0)));
    EXPECT_EQ(rgba[first ? 0 : 2], 0);
    EXPECT_EQ(rgba[1], 0);
  }
  EXPECT_GT(seen[0], 100);
  EXPECT_GT(seen[1], 100);
  // A given range: both ends of it.
  options.colours.range = { 0, 4 };
  EXPECT_EQ(renderComplex(c, complex::ComplexMesh{}, camera, options).scalarRange[1], 4);
  const ColourMap map = ColourMap::named("cool-warm");
  EXPECT_NEAR(map.at(0.5)[0], 0.865, 1e-12);
  EXPECT_NEAR(map.at(0.25)[2], 0.5 * (0.754 + 0.865), 1e-12);
  EXPECT_THROW(ColourMap::named("jet"), std::invalid_argument);
}

// A mesh cell that brings its vertex normals (the point array "Normals": a skinned B-cell's) is
// shaded with them. A square in z = 0 seen along -z by a headlight: lit as Ambient + Diffuse |cos|
// of its normal's angle to the view, so the normals at 60 degrees give the mean of those at 0 and
// 90 degrees; without the array, the triangles' own normal (0 degrees).
TEST(RenderComplex, AMeshIsShadedWithItsOwnNormals)
{
  auto lightOf = [](const std::vector<double>* normal)
  {
    complex::Complex c;
    complex::ExplicitGeometry g;
    g.points = { { -0.5, -0.5, 0 }, { 0.5, -0.5, 0 }, { 0.5, 0.5, 0 }, { -0.5, 0.5, 0 } };
    g.triangles = { { 0, 1, 2 }, { 0, 2, 3 } };
    if (normal)
    {
      discretize::PointArray a{ "Normals", 3, {} };
      for (int i = 0; i < 4; ++i)
        a.values.insert(a.values.end(), normal->begin(), normal->end());
      g.pointData.push_back(a);
    }
    const CellId square = c.addCell(complex::explicitCell("square", 2, g));
    // A scalar colouring keeps the light of every pixel (Canvas::light).
    c.declareAttribute("material", { 1, { 0 }, { -1 } });
    bind(c, square, "material", { 1 });
    complex::DiscretizationOptions o;
    o.cells = meshedCells(c);
    const complex::ComplexMesh mesh = complex::discretizeComplex(c, o);
    const Camera camera = Camera::lookAt(
      { 0, 0, 5 }, { 0, 0, 0 }, { 0, 1, 0 }, Projection::Orthographic, 30, 1, 20, 20);
    ComplexRenderOptions options;
    options.colours.attribute = "material";
    const ComplexRenderResult r = renderComplex(c, mesh, camera, options);
    std::vector<double> lights;
    for (std::size_t p = 0; p < r.canvas.owner.size(); ++p)
      if (r.canvas.owner[p] == 0)
        lights.push_back(r.canvas.light[p]);
    return lights;
  };
  const double s60 = std::sqrt(3.0) / 2;
  const std::vector<double> facing{ 0, 0, 1 }, tilted{ s60, 0, 0.5 }, edgeOn{ 1, 0, 0 };
  const std::vector<double> own = lightOf(nullptr), l0 = lightOf(&facing), l60 = lightOf(&tilted),
                            l90 = lightOf(&edgeOn);
  ASSERT_EQ(own.size(), 100u); // the square covers 10 x 10 of the 20 x 20 pixels over 2 x 2
  ASSERT_EQ(l0.size(), own.size());
  ASSERT_EQ(l60.size(), own.size());
  ASSERT_EQ(l90.size(), own.size());
  for (std::size_t i = 0; i < own.size(); ++i)
  {
    EXPECT_NEAR(l0[i], own[i], 1e-12);
    EXPECT_NEAR(l60[i], 0.5 * (l0[i] + l90[i]), 1e-12);
    EXPECT_LT(l90[i], l0[i] - 0.1);
  }
}

TEST(RenderComplex, FlowerShowsEveryDimension)
{
  const complex::Complex flower =
    lang::readComplexFile(std::string(ICTK_DATA_DIR) + "/Models/flower/flower.json");
  complex::DiscretizationOptions o;
  o.cells = meshedCells(flower);
  const complex::ComplexMesh mesh = complex::discretizeComplex(flower, o);
  // From the side of the filament (y < 0 looking at +y), a little above.
  const Camera camera = Camera::orbit(
    complex::complexBounds(flower), View{ -70, 25, 0 }, Projection::Perspective, 160, 120);
  ComplexRenderOptions options;
  options.threads = 1;
  const ComplexRenderResult one = renderComplex(flower, mesh, camera, options);
  for (int d = 0; d < 4; ++d)
  {
    EXPECT_GT(one.pixelsByDimension[d], 0) << "dimension " << d;
  }
  EXPECT_EQ(one.unresolvedPixels, 0);
  // The stamen is yellow (S1: 0.95, 0.85, 0.2): red > green > blue wherever it shows.
  const CellId stamen = flower.idOf("t_0^3");
  int stamenPixels = 0;
  for (std::size_t p = 0; p < one.canvas.owner.size(); ++p)
  {
    if (one.canvas.owner[p] == static_cast<int>(stamen))
    {
      ++stamenPixels;
      EXPECT_GT(one.canvas.colour[4 * p], one.canvas.colour[4 * p + 2]);
    }
  }
  EXPECT_GT(stamenPixels, 0);
  options.threads = 2;
  const ComplexRenderResult two = renderComplex(flower, mesh, camera, options);
  EXPECT_EQ(one.canvas.colour, two.canvas.colour);
  EXPECT_EQ(one.canvas.depth, two.canvas.depth);
}

TEST(RenderComplex, BadInput)
{
  BallAndTube scene(-0.8);
  const Camera camera = sideCamera(scene.complex, Projection::Perspective, 8, 8);
  // The tube's discretisation is missing.
  EXPECT_THROW(renderComplex(scene.complex, complex::ComplexMesh{}, camera), std::invalid_argument);
  const complex::ComplexMesh mesh = scene.mesh();
  ComplexRenderOptions options;
  options.tubeRadius = -1;
  EXPECT_THROW(renderComplex(scene.complex, mesh, camera, options), std::invalid_argument);
  options.tubeRadius = 0;
  options.colours.attribute = "density";
  EXPECT_THROW(renderComplex(scene.complex, mesh, camera, options), std::invalid_argument);
  options.colours.attribute = "";
  options.colours.map = "jet";
  EXPECT_THROW(renderComplex(scene.complex, mesh, camera, options), std::invalid_argument);
  Primitives bad;
  bad.points = { { 0, 0, 0 } };
  bad.triangles = { { 0, 0, 1 } };
  Canvas canvas(8, 8);
  EXPECT_THROW(rasterize(canvas, camera, bad), std::invalid_argument);
  bad.triangles.clear();
  bad.spheres = { 0 };
  EXPECT_THROW(rasterize(canvas, camera, bad), std::invalid_argument); // no radius
}

TEST(RenderRayCast, WalnutMaterialsThroughColourMap)
{
  // The walnut cut open by a box that ends at y = 0, seen from +y: the cut shows the shell
  // (material 1) and the kernel (2), at the two ends of the grey map.
  const frep::ModelInfo& info = frep::findModel("walnut");
  const Hypervolume walnut = info.build();
  Box3 box{ info.boundsLo, info.boundsHi };
  box.hi[1] = 0;
  const Camera camera = Camera::orbit(box, View{ 90, 0, 0 }, Projection::Orthographic, 64, 48);
  RayCastOptions options;
  options.colours.attribute = "material";
  options.colours.map = "rainbow";
  const RayCastResult r = rayCast(walnut, box, camera, options);
  EXPECT_EQ(r.scalarRange[0], 1);
  EXPECT_EQ(r.scalarRange[1], 2);
  EXPECT_GT(r.cutPixels, 100);
  // rainbow: the shell blue, the kernel red, whatever the light.
  int shell = 0, kernel = 0;
  for (std::size_t p = 0; p < r.depth.size(); ++p)
  {
    const std::uint8_t* rgba = &r.colour[4 * p];
    if (rgba[3] == 255)
    {
      EXPECT_EQ(rgba[1], 0);
      EXPECT_TRUE((rgba[0] == 0) != (rgba[2] == 0));
      shell += rgba[2] > 0 ? 1 : 0;
      kernel += rgba[0] > 0 ? 1 : 0;
    }
  }
  EXPECT_GT(shell, 50);
  EXPECT_GT(kernel, 50);
  options.colours.attribute = "temperature";
  EXPECT_THROW(rayCast(walnut, box, camera, options), std::invalid_argument);
}

TEST(RenderCamera, LookAtIsTheOrbitGivenItsValues)
{
  // The orbit's camera of view 30,20,4 about the cube, restated as position, focal point and up.
  const Box3 cube{ { -1, -1, -1 }, { 1, 1, 1 } };
  for (Projection p : { Projection::Perspective, Projection::Orthographic })
  {
    const Camera a = Camera::orbit(cube, View{ 30, 20, 4 }, p, 40, 30);
    const Camera b = Camera::lookAt(a.eye(), add(a.eye(), a.forward()), { 0, 0, 1 }, p,
      PerspectiveFieldOfView, 0.5 * OrthographicHeight * std::sqrt(3.0), 40, 30);
    for (int k = 0; k < 3; ++k)
    {
      EXPECT_NEAR(a.forward()[k], b.forward()[k], 1e-15);
      EXPECT_NEAR(a.right()[k], b.right()[k], 1e-15);
      EXPECT_NEAR(a.up()[k], b.up()[k], 1e-15);
    }
    EXPECT_NEAR(a.pixelSize(), b.pixelSize(), 1e-15);
    EXPECT_NEAR(b.viewAngle(), p == Projection::Perspective ? 30 : b.viewAngle(), 1e-12);
  }
  // A hand-made one: from (0, 0, 5) looking down at the origin with +y up, 90 degrees high.
  const Camera c =
    Camera::lookAt({ 0, 0, 5 }, { 0, 0, 0 }, { 0, 1, 0 }, Projection::Perspective, 90, 0, 10, 10);
  EXPECT_NEAR(c.right()[0], 1, 1e-15);
  EXPECT_NEAR(c.up()[1], 1, 1e-15);
  EXPECT_NEAR(c.pixelSize(), 0.2, 1e-15);
  EXPECT_THROW(
    Camera::lookAt({ 0, 0, 5 }, { 0, 0, 5 }, { 0, 1, 0 }, Projection::Perspective, 30, 0, 8, 8),
    std::invalid_argument);
  EXPECT_THROW(
    Camera::lookAt({ 0, 0, 5 }, { 0, 0, 0 }, { 0, 0, 1 }, Projection::Perspective, 30, 0, 8, 8),
    std::invalid_argument);
  EXPECT_THROW(
    Camera::lookAt({ 0, 0, 5 }, { 0, 0, 0 }, { 0, 1, 0 }, Projection::Perspective, 180, 0, 8, 8),
    std::invalid_argument);
  EXPECT_THROW(
    Camera::lookAt({ 0, 0, 5 }, { 0, 0, 0 }, { 0, 1, 0 }, Projection::Orthographic, 30, 0, 8, 8),
    std::invalid_argument);
}

TEST(RenderRayCast, ACutByTheBoxIsLitByItsFace)
{
  // A ball larger than the cube, seen from +x: the face x = 1 cuts it, and every pixel of the
  // cut faces the eye, so it gets the full light whatever the field's gradient does there.
  const Box3 cube{ { -1, -1, -1 }, { 1, 1, 1 } };
  const Expr ball = Expr(1.44) - (square(Expr::x()) + square(Expr::y()) + square(Expr::z()));
  const Camera front = Camera::orbit(cube, View{ 0, 0, 3 }, Projection::Orthographic, 16, 16);
  const RayCastResult cut = rayCast(Tape::compile(ball), cube, front);
  ASSERT_GT(cut.cutPixels, 20);
  int flat = 0;
  for (std::size_t p = 0; p < cut.depth.size(); ++p)
  {
    if (cut.depth[p] == 2.0) // the face x = 1, from the image plane at x = 3
    {
      ++flat;
      EXPECT_EQ(cut.colour[4 * p], std::lround(255 * NeutralGrey));
    }
  }
  EXPECT_EQ(flat, cut.cutPixels);
}
