// SPDX-License-Identifier: BSD-3-Clause
// Conforming multi-material boundary surfaces (issue 6, the input of the TetGen backend).
#include "Discretize/MultiMaterial.h"
#include "FRep/Expr.h"
#include "FRep/Field.h"
#include "FRep/Tape.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <utility>
#include <vector>

namespace
{

using namespace ictk;
using discretize::MaterialSurface;
using frep::Expr;
using frep::Point3;

frep::FieldPtr field(const Expr& e)
{
  return frep::tapeField(frep::Tape::compile(e));
}

/// min of the six half-spaces of the box [lo, hi].
frep::FieldPtr boxField(const Point3& lo, const Point3& hi)
{
  const Expr x = Expr::x(), y = Expr::y(), z = Expr::z();
  auto c = [](double v)
  {
    return Expr::constant(v);
  };
  return field(min(min(min(x - c(lo[0]), c(hi[0]) - x), min(y - c(lo[1]), c(hi[1]) - y)),
    min(z - c(lo[2]), c(hi[2]) - z)));
}

frep::FieldPtr ballField(const Point3& centre, double r)
{
  const Expr dx = Expr::x() - Expr::constant(centre[0]);
  const Expr dy = Expr::y() - Expr::constant(centre[1]);
  const Expr dz = Expr::z() - Expr::constant(centre[2]);
  return field(Expr::constant(r) - sqrt(dx * dx + dy * dy + dz * dz));
}

/// Every edge of the triangles that bound `label` is used an even number of times.
bool closedBoundary(const MaterialSurface& s, int label)
{
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> uses;
  for (std::size_t t = 0; t < s.triangles.size(); ++t)
  {
    if (s.labels[t][0] != label && s.labels[t][1] != label)
    {
      continue;
    }
    const auto& tri = s.triangles[t];
    for (int e = 0; e < 3; ++e)
    {
      const auto a = tri[e], b = tri[(e + 1) % 3];
      ++uses[{ std::min(a, b), std::max(a, b) }];
    }
  }
  return std::all_of(uses.begin(), uses.end(), [](const auto& u) { return u.second % 2 == 0; });
}

double triangleArea(const MaterialSurface& s, std::size_t t)
{
  const auto& a = s.points[s.triangles[t][0]];
  const auto& b = s.points[s.triangles[t][1]];
  const auto& c = s.points[s.triangles[t][2]];
  const Point3 u{ b[0] - a[0], b[1] - a[1], b[2] - a[2] };
  const Point3 v{ c[0] - a[0], c[1] - a[1], c[2] - a[2] };
  const Point3 n{ u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0] };
  return 0.5 * std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
}

void expectValidPlc(const MaterialSurface& s)
{
  std::set<Point3> distinct(s.points.begin(), s.points.end());
  EXPECT_EQ(distinct.size(), s.points.size()) << "coincident vertices";
  std::vector<bool> used(s.points.size(), false);
  for (std::size_t t = 0; t < s.triangles.size(); ++t)
  {
    EXPECT_GT(triangleArea(s, t), 0) << "degenerate triangle " << t;
    EXPECT_LT(s.labels[t][0], s.labels[t][1]);
    for (auto v : s.triangles[t])
    {
      used[v] = true;
    }
  }
  EXPECT_TRUE(std::all_of(used.begin(), used.end(), [](bool u) { return u; }));
}

TEST(MultiMaterial, TwoTouchingBlocks)
{
  const std::vector<frep::FieldPtr> solids = { boxField({ 0, 0, 0 }, { 1, 0.2, 0.2 }),
    boxField({ 1, 0, 0 }, { 2, 0.2, 0.2 }) };
  const frep::Box3 box{ { 0, 0, 0 }, { 2, 0.2, 0.2 } };
  const MaterialSurface s = discretize::multiMaterialSurface(solids, { 0, 0 }, box, 0.05);
  ASSERT_FALSE(s.triangles.empty());
  expectValidPlc(s);
  EXPECT_TRUE(closedBoundary(s, 1));
  EXPECT_TRUE(closedBoundary(s, 2));
  EXPECT_TRUE(s.overlaps.empty()); // touching is not overlapping
  double interface = 0;
  for (std::size_t t = 0; t < s.triangles.size(); ++t)
  {
    if (s.labels[t][0] == 1 && s.labels[t][1] == 2)
    {
      interface += triangleArea(s, t);
      for (auto v : s.triangles[t])
      {
        EXPECT_NEAR(s.points[v][0], 1.0, 1e-9);
      }
    }
  }
  EXPECT_NEAR(interface, 0.04, 0.04 * 0.01);
  EXPECT_NEAR(discretize::materialVolume(s, 1), 0.04, 0.04 * 0.01);
  EXPECT_NEAR(discretize::materialVolume(s, 2), 0.04, 0.04 * 0.01);
  ASSERT_EQ(s.regions.size(), 2u);
  EXPECT_EQ(s.regions[0].label + s.regions[1].label, 3);
}

TEST(MultiMaterial, BlocksInsideALargerBox)
{
  // The blocks' faces are inside the box: found by bisection, not by the box cut.
  const std::vector<frep::FieldPtr> solids = { boxField({ 0, 0, 0 }, { 1, 0.2, 0.2 }),
    boxField({ 1, 0, 0 }, { 2, 0.2, 0.2 }) };
  const frep::Box3 box{ { -0.13, -0.11, -0.12 }, { 2.1, 0.33, 0.31 } };
  const MaterialSurface s = discretize::multiMaterialSurface(solids, {}, box, 0.04);
  expectValidPlc(s);
  EXPECT_TRUE(closedBoundary(s, 1));
  EXPECT_TRUE(closedBoundary(s, 2));
  EXPECT_TRUE(closedBoundary(s, 0));
  for (std::size_t t = 0; t < s.triangles.size(); ++t)
  {
    if (s.labels[t][0] == 1 && s.labels[t][1] == 2)
    {
      for (auto v : s.triangles[t])
      {
        EXPECT_NEAR(s.points[v][0], 1.0, 1e-9);
      }
    }
  }
  // The block edges are rounded off by about a cell.
  EXPECT_NEAR(discretize::materialVolume(s, 1), 0.04, 0.04 * 0.1);
}

TEST(MultiMaterial, SphereInBoxByPriority)
{
  const std::vector<frep::FieldPtr> solids = { boxField({ -1, -1, -1 }, { 1, 1, 1 }),
    ballField({ 0.05, -0.02, 0.01 }, 0.5) };
  const frep::Box3 box{ { -1, -1, -1 }, { 1, 1, 1 } };
  discretize::MultiMaterialOptions o;
  o.threads = 1;
  const MaterialSurface s = discretize::multiMaterialSurface(solids, { 0, 1 }, box, 0.05, o);
  expectValidPlc(s);
  EXPECT_TRUE(closedBoundary(s, 1));
  EXPECT_TRUE(closedBoundary(s, 2));
  const double ball = 4.0 / 3.0 * M_PI * 0.125;
  EXPECT_NEAR(discretize::materialVolume(s, 2), ball, ball * 0.01);
  EXPECT_NEAR(discretize::materialVolume(s, 1), 8 - ball, (8 - ball) * 0.001);
  EXPECT_EQ(s.regions.size(), 2u);
  EXPECT_TRUE(s.overlaps.empty());
  // Deterministic for any thread count.
  o.threads = 2;
  const MaterialSurface t = discretize::multiMaterialSurface(solids, { 0, 1 }, box, 0.05, o);
  EXPECT_EQ(s.points, t.points);
  EXPECT_EQ(s.triangles, t.triangles);
  EXPECT_EQ(s.labels, t.labels);
}

TEST(MultiMaterial, FourMaterialsMeetAtAPoint)
{
  // Three balls in a box: triple lines and (where all four meet) quadruple points.
  const std::vector<frep::FieldPtr> solids = { boxField({ -1, -1, -1 }, { 1, 1, 1 }),
    ballField({ 0.3, 0, 0 }, 0.5), ballField({ -0.15, 0.26, 0 }, 0.5),
    ballField({ -0.15, -0.26, 0.1 }, 0.5) };
  const frep::Box3 box{ { -1.2, -1.2, -1.2 }, { 1.2, 1.2, 1.2 } };
  const MaterialSurface s = discretize::multiMaterialSurface(solids, { 0, 3, 2, 1 }, box, 0.07);
  expectValidPlc(s);
  for (int label = 0; label <= 4; ++label)
  {
    EXPECT_TRUE(closedBoundary(s, label)) << label;
  }
  double total = 0;
  for (int label = 1; label <= 4; ++label)
  {
    total += discretize::materialVolume(s, label);
  }
  EXPECT_NEAR(total, 8, 8 * 0.02);
}

TEST(MultiMaterial, EqualPriorityOverlapAndVoids)
{
  const std::vector<frep::FieldPtr> overlapping = { ballField({ 0, 0, 0 }, 0.5),
    ballField({ 0.4, 0, 0 }, 0.5) };
  const frep::Box3 box{ { -1, -1, -1 }, { 1.5, 1, 1 } };
  const MaterialSurface s = discretize::multiMaterialSurface(overlapping, {}, box, 0.1);
  ASSERT_EQ(s.overlaps.size(), 1u);
  EXPECT_EQ(s.overlaps[0].first, 0);
  EXPECT_EQ(s.overlaps[0].second, 1);
  const MaterialSurface ordered = discretize::multiMaterialSurface(overlapping, { 1, 0 }, box, 0.1);
  EXPECT_TRUE(ordered.overlaps.empty());

  // A hollow ball: its cavity is an enclosed void region of label 0.
  const Expr r = sqrt(Expr::x() * Expr::x() + Expr::y() * Expr::y() + Expr::z() * Expr::z());
  const std::vector<frep::FieldPtr> shell = { field(
    min(Expr::constant(0.9) - r, r - Expr::constant(0.5))) };
  const MaterialSurface h =
    discretize::multiMaterialSurface(shell, {}, { { -1, -1, -1 }, { 1, 1, 1 } }, 0.1);
  expectValidPlc(h);
  ASSERT_EQ(h.regions.size(), 2u);
  int voids = 0;
  for (const auto& region : h.regions)
  {
    voids += region.label == 0 ? 1 : 0;
  }
  EXPECT_EQ(voids, 1);
}

TEST(MultiMaterial, BadInput)
{
  const std::vector<frep::FieldPtr> one = { ballField({ 0, 0, 0 }, 0.5) };
  EXPECT_THROW(discretize::multiMaterialSurface(one, {}, { { 0, 0, 0 }, { 0, 1, 1 } }, 0.1),
    std::invalid_argument);
  EXPECT_THROW(discretize::multiMaterialSurface(one, {}, { { 0, 0, 0 }, { 1, 1, 1 } }, 0),
    std::invalid_argument);
  EXPECT_THROW(discretize::multiMaterialSurface(one, { 1, 2 }, { { 0, 0, 0 }, { 1, 1, 1 } }, 0.1),
    std::invalid_argument);
}

} // namespace
