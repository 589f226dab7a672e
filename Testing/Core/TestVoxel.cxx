// SPDX-License-Identifier: BSD-3-Clause
// Voxel grids as fields: trilinear values and gradients, the enclosure of bound(), the outside
// rule, a sampled sphere read back as a cell, OpenVDB reading and writing, and error messages.

#include "FRep/Expr.h"
#include "FRep/Field.h"
#include "FRep/Tape.h"
#include "TempDir.h"
#include "Voxel/VdbIO.h"
#include "Voxel/VoxelField.h"
#include "Voxel/VoxelGrid.h"

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetSphere.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <random>

using namespace ictk;
using namespace ictk::voxel;
using ::testing::HasSubstr;

namespace
{

namespace fs = std::filesystem;

using ictk::test_support::TempDir;

/// The 2x2x2 grid of the hand computations: corners v[i + 2j + 4k].
std::shared_ptr<VoxelGrid> cube()
{
  auto g = std::make_shared<VoxelGrid>();
  g->dimensions = { 2, 2, 2 };
  g->origin = { 1, 2, 3 };
  g->spacing = { 0.5, 1, 2 };
  g->values = { 1, 3, -2, 5, 0, 7, 4, -1 };
  return g;
}

/// The trilinear interpolant written as the weighted sum of the corners (not as nested lerps).
double trilinear(const VoxelGrid& g, double tx, double ty, double tz)
{
  double s = 0;
  for (int k = 0; k < 2; ++k)
  {
    for (int j = 0; j < 2; ++j)
    {
      for (int i = 0; i < 2; ++i)
      {
        s += g.at(i, j, k) * (i ? tx : 1 - tx) * (j ? ty : 1 - ty) * (k ? tz : 1 - tz);
      }
    }
  }
  return s;
}

std::shared_ptr<VoxelGrid> randomGrid(std::array<std::int64_t, 3> dims, unsigned seed)
{
  auto g = std::make_shared<VoxelGrid>();
  g->dimensions = dims;
  g->origin = { -1.5, 0.25, 2 };
  g->spacing = { 0.1, 0.07, 0.13 };
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-10, 10);
  g->values.resize(static_cast<std::size_t>(g->pointCount()));
  for (auto& v : g->values)
  {
    v = u(rng);
  }
  return g;
}

frep::FieldPtr sphereField(double r)
{
  using frep::Expr;
  const Expr x = Expr::x(), y = Expr::y(), z = Expr::z();
  return frep::tapeField(
    frep::Tape::compile(Expr::constant(r) - frep::sqrt(x * x + y * y + z * z)));
}

double norm(const Point3& p)
{
  return std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
}

} // namespace

TEST(Voxel, TrilinearValuesAtHandComputedPoints)
{
  const auto g = cube();
  // iso 10: every F = v - 10 is negative, so f is exactly the interpolant minus 10.
  const auto f = voxelField(g, 10.0)->evaluator();
  EXPECT_DOUBLE_EQ(f->value({ 1, 2, 3 }), 1 - 10.0);
  EXPECT_DOUBLE_EQ(f->value({ 1.5, 2, 3 }), 3 - 10.0);
  EXPECT_DOUBLE_EQ(f->value({ 1.5, 3, 5 }), -1 - 10.0);
  // Centre: the mean of the corners, (1 + 3 - 2 + 5 + 0 + 7 + 4 - 1) / 8 = 17 / 8.
  EXPECT_DOUBLE_EQ(f->value({ 1.25, 2.5, 4 }), 17.0 / 8 - 10);
  // Middle of the edge between v000 = 1 and v100 = 3: 2.
  EXPECT_DOUBLE_EQ(f->value({ 1.25, 2, 3 }), 2 - 10.0);
  // Centre of the face x = 1 (corners 1, -2, 0, 4): 0.75.
  EXPECT_DOUBLE_EQ(f->value({ 1, 2.5, 4 }), 0.75 - 10);
  // t = (0.25, 0.5, 0.75) by the weighted sum; and one more spelled out:
  // t = (0.5, 0.25, 0): (1 + 3) / 2 * 0.75 + (-2 + 5) / 2 * 0.25 = 1.5 + 0.375 = 1.875.
  EXPECT_NEAR(f->value({ 1.125, 2.5, 4.5 }), trilinear(*g, 0.25, 0.5, 0.75) - 10, 1e-14);
  EXPECT_DOUBLE_EQ(f->value({ 1.25, 2.25, 3 }), 1.875 - 10);

  // Inside below the iso-value: f = iso - v.
  const auto below = voxelField(g, -10.0, false)->evaluator();
  EXPECT_DOUBLE_EQ(below->value({ 1.25, 2.5, 4 }), -10 - 17.0 / 8);
  EXPECT_NEAR(below->value({ 1.125, 2.5, 4.5 }), -10 - trilinear(*g, 0.25, 0.5, 0.75), 1e-14);

  // Batch values agree with single values.
  const double xs[3] = { 1.0, 1.25, 1.125 }, ys[3] = { 2, 2.5, 2.5 }, zs[3] = { 3, 4, 4.5 };
  double out[3];
  f->values(xs, ys, zs, out, 3);
  for (int i = 0; i < 3; ++i)
  {
    EXPECT_EQ(out[i], f->value({ xs[i], ys[i], zs[i] }));
  }
}

TEST(Voxel, GradientOfTheTrilinearInterpolant)
{
  const auto g = cube();
  const auto f = voxelField(g, 10.0)->evaluator();
  // At the centre, by hand: d/dtx = mean of the x edge differences (2 + 7 + 7 - 5) / 4 = 2.75,
  // d/dty = (-3 + 2 + 4 - 8) / 4 = -1.25, d/dtz = (-1 + 4 + 6 - 6) / 4 = 0.75; divided by the
  // spacings (0.5, 1, 2).
  Point3 grad;
  const double v = f->gradient({ 1.25, 2.5, 4 }, grad);
  EXPECT_DOUBLE_EQ(v, 17.0 / 8 - 10);
  EXPECT_DOUBLE_EQ(grad[0], 2.75 / 0.5);
  EXPECT_DOUBLE_EQ(grad[1], -1.25 / 1);
  EXPECT_DOUBLE_EQ(grad[2], 0.75 / 2);
  // Elsewhere: central differences of the (smooth, inside the cell) interpolant.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.05, 0.95);
  for (int n = 0; n < 100; ++n)
  {
    const Point3 p{ 1 + 0.5 * u(rng), 2 + 1 * u(rng), 3 + 2 * u(rng) };
    f->gradient(p, grad);
    for (int a = 0; a < 3; ++a)
    {
      Point3 p1 = p, p0 = p;
      const double h = 1e-6;
      p1[a] += h;
      p0[a] -= h;
      EXPECT_NEAR(grad[a], (f->value(p1) - f->value(p0)) / (2 * h), 1e-6);
    }
  }
  // Inside below the iso-value the gradient flips.
  const auto below = voxelField(g, -10.0, false)->evaluator();
  Point3 gb;
  below->gradient({ 1.25, 2.5, 4 }, gb);
  EXPECT_DOUBLE_EQ(gb[0], -2.75 / 0.5);
  // Just outside the face x = 1.5, F(clamp(p)) = 3.5 - 10 is below the box term -L * 1e-3:
  // d/dx is zero (x is clamped), the others are the interpolant's at the clamped point.
  EXPECT_DOUBLE_EQ(f->gradient({ 1.5 + 1e-3, 2.5, 4 }, grad), 3.5 - 10);
  EXPECT_EQ(grad[0], 0.0);
  // d/dty on the face: ((v110 - v100) + (v111 - v101)) / 2 = (2 - 8) / 2, spacing 1;
  // d/dtz: ((v101 - v100) + (v111 - v110)) / 2 = (4 - 6) / 2, spacing 2.
  EXPECT_DOUBLE_EQ(grad[1], -3.0);
  EXPECT_DOUBLE_EQ(grad[2], -1.0 / 2);
  // Far outside the box term wins: L times the outward unit normal, negated.
  const auto f2 = voxelField(g, 2.0)->evaluator();
  f2->gradient({ 10, 2.5, 4 }, grad);
  EXPECT_DOUBLE_EQ(grad[0], -lipschitzBound(*g, 2.0));
  EXPECT_EQ(grad[1], 0.0);
  EXPECT_EQ(grad[2], 0.0);
}

TEST(Voxel, OutsideRuleIsNegativeAndContinuous)
{
  const auto g = cube();
  // iso 2: corners above 2 are inside, several of them on the boundary of the (single-cell) grid.
  const auto field = voxelField(g, 2.0);
  const auto f = field->evaluator();
  // L by hand: largest edge differences 7 (x), 8 (y), 6 (z) over spacings 0.5, 1, 2.
  const double L = std::sqrt(14.0 * 14 + 8.0 * 8 + 3.0 * 3);
  EXPECT_DOUBLE_EQ(lipschitzBound(*g, 2.0), L);
  // Outside: f = min(F(clamp p), -L * distance).
  EXPECT_DOUBLE_EQ(f->value({ 0.5, 2, 3 }), std::min(1.0 - 2, -L * 0.5));
  EXPECT_DOUBLE_EQ(f->value({ 2.5, 3, 5 }), std::min(-1.0 - 2, -L * 1.0));
  EXPECT_DOUBLE_EQ(f->value({ 2.5, 4, 5 }), -L * std::sqrt(2.0)); // F(v111) = -3 > -L sqrt(2)
  // On the box, where the material touches it: f = 0 (v101 = 7 is inside).
  EXPECT_DOUBLE_EQ(f->value({ 1.5, 2, 5 }), 0.0);
  // Continuity and the Lipschitz bound along random segments crossing the box.
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int n = 0; n < 2000; ++n)
  {
    const Point3 p{ 1.25 + u(rng), 2.5 + 1.5 * u(rng), 4 + 2.5 * u(rng) };
    const Point3 q{ p[0] + 1e-4 * u(rng), p[1] + 1e-4 * u(rng), p[2] + 1e-4 * u(rng) };
    const double d = std::sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) +
      (p[2] - q[2]) * (p[2] - q[2]));
    EXPECT_LE(std::abs(f->value(p) - f->value(q)), L * d * (1 + 1e-9) + 1e-12);
    const bool inBox = p[0] >= 1 && p[0] <= 1.5 && p[1] >= 2 && p[1] <= 3 && p[2] >= 3 && p[2] <= 5;
    if (!inBox)
    {
      EXPECT_LT(f->value(p), 0);
    }
  }
  // Far away: strongly negative, and NaN coordinates give NaN.
  EXPECT_LT(f->value({ 100, 100, 100 }), -100);
  EXPECT_TRUE(std::isnan(f->value({ NAN, 2, 3 })));
}

TEST(Voxel, BoundEnclosesRandomBoxes)
{
  // 70 x 61 x 66 points: a pyramid of three levels (8, 64, 512 cells per block).
  const auto g = randomGrid({ 70, 61, 66 }, 11);
  const frep::Box3 gb = g->bounds();
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  for (bool above : { true, false })
  {
    const auto f = voxelField(g, 1.5, above)->evaluator();
    for (int b = 0; b < 1000; ++b)
    {
      // Boxes of all sizes, some partly or wholly outside the grid.
      frep::Box3 box;
      const double scale = std::pow(10.0, -3 + 3.5 * u(rng));
      for (int a = 0; a < 3; ++a)
      {
        const double extent = gb.hi[a] - gb.lo[a];
        const double c = gb.lo[a] - 0.2 * extent + 1.4 * extent * u(rng);
        const double w = scale * extent * u(rng);
        box.lo[a] = c - w;
        box.hi[a] = c + w;
      }
      const frep::Interval iv = f->bound(box);
      ASSERT_FALSE(iv.maybeNaN);
      for (int n = 0; n < 10; ++n)
      {
        const Point3 p{ box.lo[0] + (box.hi[0] - box.lo[0]) * u(rng),
          box.lo[1] + (box.hi[1] - box.lo[1]) * u(rng),
          box.lo[2] + (box.hi[2] - box.lo[2]) * u(rng) };
        const double v = f->value(p);
        ASSERT_LE(iv.lo, v) << "box " << b << " point " << n;
        ASSERT_GE(iv.hi, v) << "box " << b << " point " << n;
      }
      // The corners too (the extreme points of the box term).
      for (int c = 0; c < 8; ++c)
      {
        const Point3 p{ c & 1 ? box.hi[0] : box.lo[0], c & 2 ? box.hi[1] : box.lo[1],
          c & 4 ? box.hi[2] : box.lo[2] };
        const double v = f->value(p);
        ASSERT_LE(iv.lo, v);
        ASSERT_GE(iv.hi, v);
      }
    }
  }
}

TEST(Voxel, BoundIsExactOnTheTouchedCells)
{
  // iso above every value: f = v - iso inside the grid, so the bound over a box inside the grid
  // is [min, max] - iso over the vertices of the cells the box touches: exactly for boxes of up to
  // 64^3 vertices; for larger ones an enclosure within the min/max over the 8^3 blocks touched.
  const auto g = randomGrid({ 100, 90, 96 }, 12);
  const auto f = voxelField(g, 20.0)->evaluator();
  auto range = [&](const std::array<std::int64_t, 3>& c0, const std::array<std::int64_t, 3>& c1)
  {
    float lo = std::numeric_limits<float>::infinity(), hi = -lo;
    for (std::int64_t k = c0[2]; k <= c1[2] + 1; ++k)
      for (std::int64_t j = c0[1]; j <= c1[1] + 1; ++j)
        for (std::int64_t i = c0[0]; i <= c1[0] + 1; ++i)
        {
          lo = std::min(lo, g->at(i, j, k));
          hi = std::max(hi, g->at(i, j, k));
        }
    return std::make_pair(double(lo) - 20.0, double(hi) - 20.0);
  };
  std::mt19937 rng(6);
  std::uniform_int_distribution<std::int64_t> pick(0, 59);
  int exact = 0, loose = 0;
  for (int b = 0; b < 300; ++b)
  {
    std::array<std::int64_t, 3> c0, c1, b0, b1;
    frep::Box3 box;
    std::int64_t vertices = 1;
    for (int a = 0; a < 3; ++a)
    {
      // Odd b: boxes of up to 16 cells; even b: 66 to 85 cells.
      c0[a] = b % 2 ? pick(rng) : pick(rng) / 6;
      const std::int64_t extent = b % 2 ? pick(rng) / 4 : 66 + pick(rng) / 3;
      c1[a] = std::min<std::int64_t>(c0[a] + extent, g->dimensions[a] - 2);
      vertices *= c1[a] - c0[a] + 2;
      b0[a] = c0[a] / 8 * 8;
      b1[a] = std::min<std::int64_t>(c1[a] / 8 * 8 + 7, g->dimensions[a] - 2);
      // A box strictly inside cells c0..c1.
      box.lo[a] = g->origin[a] + (static_cast<double>(c0[a]) + 0.25) * g->spacing[a];
      box.hi[a] = g->origin[a] + (static_cast<double>(c1[a]) + 0.75) * g->spacing[a];
    }
    const auto [lo, hi] = range(c0, c1);
    const frep::Interval iv = f->bound(box);
    if (vertices <= 64 * 64 * 64)
    {
      ++exact;
      EXPECT_EQ(iv.lo, lo);
      EXPECT_EQ(iv.hi, hi);
    }
    else
    {
      ++loose;
      const auto [blo, bhi] = range(b0, b1);
      EXPECT_LE(iv.lo, lo);
      EXPECT_GE(iv.hi, hi);
      EXPECT_GE(iv.lo, blo);
      EXPECT_LE(iv.hi, bhi);
    }
  }
  EXPECT_GT(exact, 100);
  EXPECT_GT(loose, 100);
}

TEST(Voxel, BoundIsTightOnAConstantGrid)
{
  for (float c : { -3.0f, 7.0f })
  {
    auto g = std::make_shared<VoxelGrid>();
    g->dimensions = { 30, 20, 25 };
    g->origin = { 0, 0, 0 };
    g->spacing = { 0.1, 0.1, 0.1 };
    g->values.assign(static_cast<std::size_t>(g->pointCount()), c);
    const auto f = voxelField(g, 5.0)->evaluator();
    const double F = c - 5.0;
    // Deep inside (c = 7: the box term L * depth exceeds F = 2 once depth > 2 / L).
    const double L = lipschitzBound(*g, 5.0);
    const double m = F > 0 ? F / L + 1e-9 : 0.0;
    frep::Box3 box{ { 0.3 + m, 0.2 + m, 0.4 + m }, { 2.2 - m, 1.7 - m, 2.0 - m } };
    if (!box.valid())
    {
      box = { { 1.2, 0.8, 1.0 }, { 1.3, 0.9, 1.1 } };
    }
    const frep::Interval iv = f->bound(box);
    EXPECT_EQ(iv.lo, F);
    EXPECT_EQ(iv.hi, F);
    EXPECT_EQ(f->value(box.centre()), F);
  }
}

TEST(Voxel, SampledSphereReadBackAsACell)
{
  const double R = 0.8;
  const frep::FieldPtr sphere = sphereField(R);
  const frep::Box3 box{ { -1, -1, -1 }, { 1, 1, 1 } };
  auto grid = std::make_shared<VoxelGrid>(sampleToGrid(*sphere, box, { 64, 64, 64 }));
  ASSERT_EQ(grid->pointCount(), 64 * 64 * 64);
  const double h = 2.0 / 63;
  EXPECT_DOUBLE_EQ(grid->spacing[0], h);
  // The grid holds the field's values at its points.
  EXPECT_FLOAT_EQ(grid->at(0, 0, 0), static_cast<float>(R - std::sqrt(3.0)));
  const auto f = voxelField(grid, 0.0)->evaluator();

  // The zero along radial rays, by bisection between r = 0.5 (inside) and r = 1 (outside).
  std::mt19937 rng(17);
  std::normal_distribution<double> gauss;
  double worst = 0;
  for (int n = 0; n < 500; ++n)
  {
    Point3 d{ gauss(rng), gauss(rng), gauss(rng) };
    const double l = norm(d);
    d = { d[0] / l, d[1] / l, d[2] / l };
    double a = 0.5, b = 1.0;
    ASSERT_GT(f->value({ a * d[0], a * d[1], a * d[2] }), 0);
    ASSERT_LT(f->value({ b * d[0], b * d[1], b * d[2] }), 0);
    for (int it = 0; it < 60; ++it)
    {
      const double m = 0.5 * (a + b);
      (f->value({ m * d[0], m * d[1], m * d[2] }) > 0 ? a : b) = m;
    }
    worst = std::max(worst, std::abs(0.5 * (a + b) - R));
  }
  EXPECT_LT(worst, 0.5 * h);
  std::cout << "[ sphere 64^3 ] largest radial error of the zero set: " << worst << " (voxel " << h
            << ", " << worst / h << " voxel)\n";

  // Inside / outside agree with the analytic sphere farther than one voxel from the surface,
  // including outside the grid.
  std::uniform_real_distribution<double> u(-1.3, 1.3);
  int checked = 0;
  for (int n = 0; n < 20000; ++n)
  {
    const Point3 p{ u(rng), u(rng), u(rng) };
    const double exact = R - norm(p);
    if (std::abs(exact) <= h)
    {
      continue;
    }
    ++checked;
    ASSERT_EQ(f->value(p) > 0, exact > 0) << p[0] << " " << p[1] << " " << p[2];
  }
  EXPECT_GT(checked, 15000);
}

TEST(Voxel, ValuesAndBoundsAreDeterministic)
{
  const auto g = randomGrid({ 40, 33, 37 }, 21);
  const auto field = voxelField(g, 0.5);
  auto e1 = field->evaluator();
  auto e2 = field->evaluator();
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-2, 8);
  std::vector<double> x(4000), y(4000), z(4000), a(4000), b(4000), c(4000);
  for (std::size_t i = 0; i < x.size(); ++i)
  {
    x[i] = u(rng);
    y[i] = u(rng);
    z[i] = u(rng);
  }
  e1->values(x.data(), y.data(), z.data(), a.data(), x.size());
  e1->values(x.data(), y.data(), z.data(), b.data(), x.size());
  e2->values(x.data(), y.data(), z.data(), c.data(), x.size());
  EXPECT_EQ(a, b);
  EXPECT_EQ(a, c);
  for (std::size_t i = 0; i + 1 < x.size(); i += 2)
  {
    const frep::Box3 box{ { std::min(x[i], x[i + 1]), std::min(y[i], y[i + 1]),
                            std::min(z[i], z[i + 1]) },
      { std::max(x[i], x[i + 1]), std::max(y[i], y[i + 1]), std::max(z[i], z[i + 1]) } };
    const frep::Interval i1 = e1->bound(box), i2 = e2->bound(box), i3 = e1->bound(box);
    EXPECT_EQ(i1.lo, i2.lo);
    EXPECT_EQ(i1.hi, i2.hi);
    EXPECT_EQ(i1.lo, i3.lo);
    EXPECT_EQ(i1.hi, i3.hi);
  }
  // A second field of the same grid (a new pyramid) gives the same results.
  auto e3 = voxelField(g, 0.5)->evaluator();
  e3->values(x.data(), y.data(), z.data(), c.data(), x.size());
  EXPECT_EQ(a, c);
}

TEST(Voxel, ValidationRejectsBadGrids)
{
  auto g = cube();
  g->values[1] = std::numeric_limits<float>::quiet_NaN();
  g->values[6] = std::numeric_limits<float>::quiet_NaN();
  try
  {
    voxelField(g, 0.0);
    FAIL() << "a NaN value was accepted";
  }
  catch (const std::invalid_argument& e)
  {
    EXPECT_THAT(e.what(), HasSubstr("(1, 0, 0)"));
    EXPECT_THAT(e.what(), HasSubstr("index 1"));
    EXPECT_THAT(e.what(), HasSubstr("2 non-finite values"));
  }
  g = cube();
  g->values.pop_back();
  EXPECT_THROW(validate(*g), std::invalid_argument);
  g = cube();
  g->spacing[1] = 0;
  EXPECT_THROW(validate(*g), std::invalid_argument);
  g = cube();
  g->spacing[2] = std::numeric_limits<double>::infinity();
  EXPECT_THROW(validate(*g), std::invalid_argument);
  g = cube();
  g->dimensions = { 1, 4, 2 };
  EXPECT_THROW(validate(*g), std::invalid_argument);
  EXPECT_THROW(voxelField(cube(), NAN), std::invalid_argument);
  EXPECT_THROW(voxelField(nullptr, 0.0), std::invalid_argument);
  EXPECT_THROW(sampleToGrid(*sphereField(1), { { 0, 0, 0 }, { 1, 1, 1 } }, { 1, 4, 4 }),
    std::invalid_argument);
  EXPECT_THROW(sampleToGrid(*sphereField(1), { { 0, 0, 0 }, { 0, 1, 1 } }, { 4, 4, 4 }),
    std::invalid_argument);
}

TEST(Voxel, OpenVdbRoundTrip)
{
  TempDir dir;
  for (bool uniform : { true, false })
  {
    auto g = randomGrid({ 21, 14, 9 }, uniform ? 31 : 32);
    if (uniform)
    {
      g->spacing = { 0.25, 0.25, 0.25 };
    }
    const std::string path = dir.file(uniform ? "uniform.vdb" : "scaled.vdb");
    writeVdb(*g, path, "density", 42.0f);
    writeVdb(*g, path, "density", 42.0f); // replacing an existing file
    const auto r = readVdb(path);
    // The same extent plus the one-voxel margin of background.
    ASSERT_EQ(r->dimensions[0], 23);
    ASSERT_EQ(r->dimensions[1], 16);
    ASSERT_EQ(r->dimensions[2], 11);
    for (int a = 0; a < 3; ++a)
    {
      EXPECT_NEAR(r->spacing[a], g->spacing[a], 1e-15);
      EXPECT_NEAR(r->origin[a], g->origin[a] - g->spacing[a], 1e-12);
    }
    for (std::int64_t k = 0; k < r->dimensions[2]; ++k)
      for (std::int64_t j = 0; j < r->dimensions[1]; ++j)
        for (std::int64_t i = 0; i < r->dimensions[0]; ++i)
        {
          const bool margin = i == 0 || j == 0 || k == 0 || i == 22 || j == 15 || k == 10;
          ASSERT_EQ(r->at(i, j, k), margin ? 42.0f : g->at(i - 1, j - 1, k - 1));
        }
    // The default background is the first value.
    writeVdb(*g, path, "other");
    EXPECT_EQ(readVdb(path, "other")->at(0, 0, 0), g->values[0]);
  }
  // Nothing but the written files is left in the folder (no temporary files).
  int files = 0;
  for (const auto& entry : fs::directory_iterator(dir.path()))
  {
    (void)entry;
    ++files;
  }
  EXPECT_EQ(files, 2);
}

TEST(Voxel, ReadsAnOpenVdbLevelSet)
{
  openvdb::initialize();
  TempDir dir;
  const double R = 0.8, voxel = 0.05;
  const openvdb::Vec3f centre(0.1f, -0.05f, 0.2f);
  openvdb::FloatGrid::Ptr ls =
    openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(float(R), centre, float(voxel), 3.0f);
  ls->setName("sphere");
  // A vector grid first: readVdb must skip it when looking for the first float grid.
  openvdb::Vec3SGrid::Ptr vec = openvdb::Vec3SGrid::create();
  vec->setName("a_velocity");
  vec->tree().setValue(openvdb::Coord(0, 0, 0), openvdb::Vec3s(1, 0, 0));
  const std::string path = dir.file("sphere.vdb");
  openvdb::io::File(path).write(openvdb::GridPtrVec{ vec, ls });

  const auto grid = readVdb(path);
  EXPECT_EQ(grid->spacing[0], double(float(voxel))); // OpenVDB stores the float voxel size
  // OpenVDB level sets are negative inside.
  const auto f = voxelField(grid, 0.0, false)->evaluator();
  auto dist = [&](const Point3& p)
  {
    return std::sqrt(std::pow(p[0] - centre[0], 2) + std::pow(p[1] - centre[1], 2) +
      std::pow(p[2] - centre[2], 2));
  };
  std::mt19937 rng(23);
  std::normal_distribution<double> gauss;
  std::uniform_real_distribution<double> band(-2 * voxel, 2 * voxel);
  double worst = 0;
  for (int n = 0; n < 2000; ++n)
  {
    Point3 d{ gauss(rng), gauss(rng), gauss(rng) };
    const double l = norm(d);
    const double r = R + band(rng);
    const Point3 p{ centre[0] + r * d[0] / l, centre[1] + r * d[1] / l, centre[2] + r * d[2] / l };
    const double err = std::abs(f->value(p) - (R - dist(p)));
    worst = std::max(worst, err);
  }
  EXPECT_LT(worst, voxel);
  std::cout << "[ level set ] largest |f - exact distance| within 2 voxels of the surface: "
            << worst << " (voxel " << voxel << ")\n";
  // Deep inside (inactive interior voxels: the negated background) and outside.
  EXPECT_GT(f->value({ centre[0], centre[1], centre[2] }), 0);
  EXPECT_LT(f->value({ centre[0] + 1.0, centre[1], centre[2] }), 0);
  EXPECT_LT(f->value({ 5, 5, 5 }), 0);
  // Also by name.
  EXPECT_EQ(readVdb(path, "sphere")->values, grid->values);
}

TEST(Voxel, OpenVdbErrorsNameTheFileAndTheGrid)
{
  openvdb::initialize();
  TempDir dir;
  auto expectError = [](auto&& call, const std::vector<std::string>& parts)
  {
    try
    {
      call();
      ADD_FAILURE() << "no exception";
    }
    catch (const std::runtime_error& e)
    {
      for (const auto& s : parts)
      {
        EXPECT_THAT(e.what(), HasSubstr(s));
      }
    }
  };
  const std::string missing = dir.file("missing.vdb");
  expectError([&] { readVdb(missing); }, { missing, "no such file" });

  const std::string text = dir.file("text.vdb");
  std::ofstream(text) << "this is not an OpenVDB file\n";
  expectError([&] { readVdb(text); }, { text, "not a readable OpenVDB file" });

  const std::string good = dir.file("good.vdb");
  writeVdb(*cube(), good, "density");
  expectError([&] { readVdb(good, "nope"); }, { good, "'nope'", "'density' (float)" });
  expectError([&] { readVdb(good, "", 10); }, { good, "'density'", "budget of 10 voxels" });

  // No float grid; an empty grid; a rotated transform.
  const std::string vecOnly = dir.file("vec.vdb");
  openvdb::Vec3SGrid::Ptr vec = openvdb::Vec3SGrid::create();
  vec->setName("v");
  vec->tree().setValue(openvdb::Coord(1, 2, 3), openvdb::Vec3s(1, 0, 0));
  openvdb::io::File(vecOnly).write(openvdb::GridPtrVec{ vec });
  expectError([&] { readVdb(vecOnly); }, { vecOnly, "no float or double grid", "'v' (vec3s)" });
  expectError([&] { readVdb(vecOnly, "v"); }, { vecOnly, "'v'", "vec3s" });

  const std::string empty = dir.file("empty.vdb");
  openvdb::FloatGrid::Ptr e = openvdb::FloatGrid::create(1.0f);
  e->setName("nothing");
  openvdb::io::File(empty).write(openvdb::GridPtrVec{ e });
  expectError([&] { readVdb(empty); }, { empty, "'nothing'", "no active voxels" });

  const std::string rotated = dir.file("rotated.vdb");
  openvdb::FloatGrid::Ptr rg = openvdb::FloatGrid::create(0.0f);
  rg->setName("turned");
  rg->tree().setValue(openvdb::Coord(0, 0, 0), 1.0f);
  openvdb::math::Transform::Ptr xf = openvdb::math::Transform::createLinearTransform(0.5);
  xf->preRotate(0.3, openvdb::math::Z_AXIS);
  rg->setTransform(xf);
  openvdb::io::File(rotated).write(openvdb::GridPtrVec{ rg });
  expectError([&] { readVdb(rotated); }, { rotated, "'turned'", "rotates or shears" });

  // NaN values: refused when writing (naming the file) and when reading (naming file and grid).
  auto bad = cube();
  bad->values[3] = NAN;
  try
  {
    writeVdb(*bad, dir.file("nan.vdb"));
    ADD_FAILURE() << "no exception";
  }
  catch (const std::invalid_argument& ex)
  {
    EXPECT_THAT(ex.what(), HasSubstr("nan.vdb"));
    EXPECT_THAT(ex.what(), HasSubstr("(1, 1, 0)"));
  }
  EXPECT_FALSE(fs::exists(dir.file("nan.vdb")));
  const std::string nanFile = dir.file("nan2.vdb");
  openvdb::FloatGrid::Ptr ng = openvdb::FloatGrid::create(0.0f);
  ng->setName("holes");
  ng->tree().setValue(openvdb::Coord(0, 0, 0), std::numeric_limits<float>::quiet_NaN());
  openvdb::io::File(nanFile).write(openvdb::GridPtrVec{ ng });
  try
  {
    readVdb(nanFile);
    ADD_FAILURE() << "no exception";
  }
  catch (const std::invalid_argument& ex)
  {
    EXPECT_THAT(ex.what(), HasSubstr(nanFile));
    EXPECT_THAT(ex.what(), HasSubstr("'holes'"));
    EXPECT_THAT(ex.what(), HasSubstr("(1, 1, 1)"));
  }

  // A failed write leaves an existing file untouched: the temporary name is too long for the
  // file system, so writing fails before anything reaches `target`.
  const std::string target = dir.file(std::string(250, 'x') + ".vdb");
  std::ofstream(target) << "previous";
  expectError([&] { writeVdb(*cube(), target); }, { target, "cannot write" });
  std::ifstream in(target);
  std::string content;
  in >> content;
  EXPECT_EQ(content, "previous");
  expectError([&] { writeVdb(*cube(), dir.file("no/such/folder/x.vdb")); }, { "does not exist" });
}
