// SPDX-License-Identifier: BSD-3-Clause
// A tetrahedral mesh cut open (Render/TetCut.h) against a cut worked out by hand: the box
// [0,2] x [0,1] x [0,1] as two unit cubes of six tetrahedra each (Kuhn's subdivision along the
// main diagonal, conforming across the shared square), materials 1 and 2. Uncut, its visible
// faces are the box's 10 unit squares (20 triangles, area 10); cut by x = 1 the first cube's 6
// squares (12 triangles, area 6). Drawn orthographically from +x, the cut face x = 1 covers
// exactly the pixels whose centres lie in the unit square, at the depth of the plane, in the
// colour of the kept material.
#include "Render/Camera.h"
#include "Render/Canvas.h"
#include "Render/Rasterize.h"
#include "Render/TetCut.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

using namespace ictk;
using namespace ictk::render;
using frep::Point3;

namespace
{

struct TwoCubes
{
  std::vector<Point3> points;
  std::vector<std::array<std::uint32_t, 4>> tetrahedra;
  std::vector<double> material; // per tetrahedron
  std::vector<double> x;        // per point: its x

  TwoCubes()
  {
    // Points (i, j, k) for i = 0..2, j, k = 0..1, at index i * 4 + j * 2 + k.
    for (int i = 0; i <= 2; ++i)
    {
      for (int j = 0; j <= 1; ++j)
      {
        for (int k = 0; k <= 1; ++k)
        {
          points.push_back({ double(i), double(j), double(k) });
          x.push_back(i);
        }
      }
    }
    // Kuhn: the six paths from (0,0,0) to (1,1,1) adding one axis at a time.
    const int paths[6][3] = { { 0, 1, 2 }, { 0, 2, 1 }, { 1, 0, 2 }, { 1, 2, 0 }, { 2, 0, 1 },
      { 2, 1, 0 } };
    for (int cube = 0; cube < 2; ++cube)
    {
      for (const auto& path : paths)
      {
        int c[3] = { cube, 0, 0 };
        std::array<std::uint32_t, 4> t{};
        t[0] = static_cast<std::uint32_t>(c[0] * 4 + c[1] * 2 + c[2]);
        for (int s = 0; s < 3; ++s)
        {
          ++c[path[s]];
          t[s + 1] = static_cast<std::uint32_t>(c[0] * 4 + c[1] * 2 + c[2]);
        }
        tetrahedra.push_back(t);
        material.push_back(cube + 1);
      }
    }
  }
};

double area(const std::vector<Point3>& p, const std::array<std::uint32_t, 3>& t)
{
  const Point3 u = frep::sub(p[t[1]], p[t[0]]), v = frep::sub(p[t[2]], p[t[0]]);
  return 0.5 * frep::norm(frep::cross(u, v));
}

double totalArea(const std::vector<Point3>& p, const TetFaces& f)
{
  double a = 0;
  for (const auto& t : f.triangles)
  {
    a += area(p, t);
  }
  return a;
}

} // namespace

TEST(RenderTetCut, FacesOfTheWholeMeshAreItsBoundary)
{
  const TwoCubes m;
  const TetFaces f = tetrahedronFaces(m.points, m.tetrahedra, std::nullopt);
  EXPECT_EQ(f.keptTetrahedra, 12);
  EXPECT_EQ(f.triangles.size(), 20u);
  EXPECT_NEAR(totalArea(m.points, f), 10.0, 1e-12);
}

TEST(RenderTetCut, ACutKeepsWholeTetrahedraOnOneSide)
{
  const TwoCubes m;
  // x <= 1 kept: the first cube (centroids at x in (0, 1)), its 6 squares.
  const TetFaces f = tetrahedronFaces(m.points, m.tetrahedra, CutPlane{ { 1, 0, 0 }, 1 });
  EXPECT_EQ(f.keptTetrahedra, 6);
  ASSERT_EQ(f.triangles.size(), 12u);
  EXPECT_NEAR(totalArea(m.points, f), 6.0, 1e-12);
  for (std::uint32_t t : f.tetrahedron)
  {
    EXPECT_EQ(m.material[t], 1.0);
  }
  // A plane through no centroid between the cubes' keeps the same; the normal's length does not
  // matter; the other side keeps the second cube.
  EXPECT_EQ(
    tetrahedronFaces(m.points, m.tetrahedra, CutPlane{ { 3, 0, 0 }, 3.3 }).keptTetrahedra, 6);
  const TetFaces g = tetrahedronFaces(m.points, m.tetrahedra, CutPlane{ { -1, 0, 0 }, -1 });
  EXPECT_EQ(g.keptTetrahedra, 6);
  for (std::uint32_t t : g.tetrahedron)
  {
    EXPECT_EQ(m.material[t], 2.0);
  }
  // Everything cut away: nothing to see.
  EXPECT_TRUE(
    tetrahedronFaces(m.points, m.tetrahedra, CutPlane{ { 1, 0, 0 }, -1 }).triangles.empty());
}

TEST(RenderTetCut, TheCutFaceCoversItsPixelsInTheKeptMaterialsColour)
{
  const TwoCubes m;
  // From +x, up +z: right is +y; 40 x 40 pixels of 0.05 over y, z in [-0.5, 1.5].
  const Camera camera = Camera::lookAt(
    { 5, 0.5, 0.5 }, { 0, 0.5, 0.5 }, { 0, 0, 1 }, Projection::Orthographic, 30, 1, 40, 40);
  for (const bool perPoint : { false, true })
  {
    const TetFaces f = tetrahedronFaces(m.points, m.tetrahedra, CutPlane{ { 1, 0, 0 }, 1 });
    TetPaint paint;
    (perPoint ? paint.perPoint : paint.perTetrahedron) = perPoint ? m.x : m.material;
    Canvas canvas(40, 40, Canvas::Colouring::Scalar);
    rasterize(canvas, camera, tetrahedronFacePrimitives(m.points, f, paint));
    ColourOptions colours;
    colours.map = "grey";
    colours.range = { perPoint ? 0.0 : 1.0, 2.0 };
    finishColours(canvas, colours);
    // The square's pixels: centres u = (i + 0.5 - 20) 0.05 + 0.5 in (0, 1), i = 10..29.
    std::int64_t inside = 0;
    for (int j = 0; j < 40; ++j)
    {
      for (int i = 0; i < 40; ++i)
      {
        const std::size_t p = canvas.index(i, j);
        const bool expected = i >= 10 && i < 30 && j >= 10 && j < 30;
        ASSERT_EQ(std::isfinite(canvas.depth[p]), expected) << i << "," << j;
        if (!expected)
        {
          continue;
        }
        ++inside;
        EXPECT_NEAR(canvas.depth[p], 4.0, 1e-12);
        // Value 1 at the map's t = 0 (material 1 of [1, 2]) or t = 1/2 (x = 1 of [0, 2]),
        // facing the headlight: light 1. grey is 0.15 + 0.85 t.
        const double grey = 0.15 + 0.85 * (perPoint ? 0.5 : 0.0);
        EXPECT_NEAR(canvas.colour[4 * p], 255 * grey, 0.51);
        EXPECT_EQ(canvas.colour[4 * p + 3], 255);
      }
    }
    EXPECT_EQ(inside, 400);
  }
}

TEST(RenderTetCut, BadInput)
{
  const TwoCubes m;
  EXPECT_THROW(
    tetrahedronFaces(m.points, { { 0, 1, 2, 99 } }, std::nullopt), std::invalid_argument);
  EXPECT_THROW(
    tetrahedronFaces(m.points, m.tetrahedra, CutPlane{ { 0, 0, 0 }, 1 }), std::invalid_argument);
  EXPECT_THROW(
    tetrahedronFaces(m.points, m.tetrahedra, CutPlane{ { 1, 0, 0 }, NAN }), std::invalid_argument);
  const TetFaces f = tetrahedronFaces(m.points, m.tetrahedra, std::nullopt);
  TetPaint short_;
  short_.perPoint = { 1, 2 };
  EXPECT_THROW(tetrahedronFacePrimitives(m.points, f, short_), std::invalid_argument);
}
