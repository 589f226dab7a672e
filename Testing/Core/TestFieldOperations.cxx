// SPDX-License-Identifier: BSD-3-Clause
// Operations between a voxel cell's field and an FRep's (FRep/FieldOperations.h, issue 15), and
// stamping an implant into a scan (Voxel/VoxelGrid.h): values against hand-computed formulas,
// interval bounds that enclose every sample and certify empty boxes, the chain-rule gradient
// against finite differences, and the stamped voxel count against a count of lattice points.
#include "FRep/Evaluators.h"
#include "FRep/FieldOperations.h"
#include "FRep/Implants.h"
#include "FRep/Tape.h"
#include "Voxel/VoxelField.h"
#include "Voxel/VoxelGrid.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace ictk;
using frep::Expr;

namespace
{

/// A 9 x 9 x 9 grid of spacing 1 from the origin holding the plane field x - 1 (the trilinear
/// interpolant reproduces it exactly): the solid x >= 1 of a "scan". Its field is x - 1 where
/// that is at most the distance to the grid's box (VoxelField.h, L = 1).
frep::FieldPtr planeScan()
{
  auto grid = std::make_shared<voxel::VoxelGrid>();
  grid->dimensions = { 9, 9, 9 };
  for (std::int64_t k = 0; k < 9; ++k)
    for (std::int64_t j = 0; j < 9; ++j)
      for (std::int64_t i = 0; i < 9; ++i)
        grid->values.push_back(static_cast<float>(i) - 1.0f);
  return voxel::voxelField(grid, 0);
}

/// The FRep y - 1 as a field.
frep::FieldPtr frepField(const Expr& e)
{
  return frep::tapeField(frep::Tape::compile(e));
}

} // namespace

TEST(FieldOperations, SetOperationsOfAScanAndAnFRep)
{
  const frep::FieldPtr scan = planeScan();
  const frep::FieldPtr implant = frepField(Expr::y() - 1.0);
  // At (3, 3, 4): scan 2, implant 2. R-union 4 + 2 sqrt 2, R-intersection 4 - 2 sqrt 2, and
  // scan minus implant 2 - 2 - sqrt 8.
  const frep::Point3 p{ 3, 3, 4 };
  EXPECT_NEAR(
    frep::uniteFields(scan, implant)->evaluator()->value(p), 4 + 2 * std::sqrt(2.0), 1e-6);
  EXPECT_NEAR(
    frep::intersectFields(scan, implant)->evaluator()->value(p), 4 - 2 * std::sqrt(2.0), 1e-6);
  EXPECT_NEAR(frep::subtractFields(scan, implant)->evaluator()->value(p), -std::sqrt(8.0), 1e-6);
  // alpha = 1 is max / min: at (2, 1.5, 4) scan 1, implant 0.5.
  EXPECT_NEAR(frep::uniteFields(scan, implant, 1.0)->evaluator()->value({ 2, 1.5, 4 }), 1, 1e-6);
  EXPECT_NEAR(
    frep::intersectFields(scan, implant, 1.0)->evaluator()->value({ 2, 1.5, 4 }), 0.5, 1e-6);
}

TEST(FieldOperations, BoundedBlendOfAScanAndAnFRep)
{
  // f1 = 0.5 (scan at x = 1.5), f2 = 0.5 (implant at y = 1.5), bound f3 = 1 (z - 1 at z = 2),
  // a0 = a1 = a2 = a3 = 1: r1^2 = 0.5, r2^2 = 1, r = 1/3, disp = (8/9)^3 / (10/9) = 512/810;
  // the R-union 1 + sqrt(0.5) plus it.
  const frep::FieldPtr f = frep::boundedBlendFields(
    planeScan(), frepField(Expr::y() - 1.0), frepField(Expr::z() - 1.0), 1, 1, 1, 1);
  auto e = f->evaluator();
  EXPECT_NEAR(e->value({ 1.5, 1.5, 2 }), 1 + std::sqrt(0.5) + 512.0 / 810.0, 1e-6);
  // Outside the bounding solid (z < 1) the blend is the plain R-union: 1 + sqrt(0.5).
  EXPECT_NEAR(e->value({ 1.5, 1.5, 0.5 }), 1 + std::sqrt(0.5), 1e-6);
}

TEST(FieldOperations, BoundsEncloseAndCertify)
{
  // A ball of radius 1.2 sampled into a scan, united with an FRep pin, blended in a box.
  auto grid = std::make_shared<voxel::VoxelGrid>(
    voxel::sampleToGrid(*frepField(1.44 - frep::square(Expr::x() - 2.0) -
                          frep::square(Expr::y() - 2.0) - frep::square(Expr::z() - 2.0)),
      { { 0, 0, 0 }, { 4, 4, 4 } }, { 17, 17, 17 }));
  const frep::FieldPtr scan = voxel::voxelField(grid, 0);
  const frep::FieldPtr pin = frepField(frep::pin(0.4, 3, { { 3, 3, 0.5 } }).function());
  const frep::FieldPtr bound = frepField(frep::square(Expr(1.0)) - frep::square(Expr::x() - 2.5) -
    frep::square(Expr::y() - 2.5) - frep::square(Expr::z() - 2.0));
  const std::vector<frep::FieldPtr> fields = { frep::uniteFields(scan, pin),
    frep::subtractFields(scan, pin, 0.5),
    frep::boundedBlendFields(scan, pin, bound, 1, 1, 1, 0.5) };
  std::mt19937_64 random(15);
  std::uniform_real_distribution<double> u(-0.5, 4.5), size(0.05, 1.5);
  for (const auto& f : fields)
  {
    auto e = f->evaluator();
    for (int b = 0; b < 200; ++b)
    {
      frep::Box3 box;
      for (int a = 0; a < 3; ++a)
      {
        box.lo[a] = u(random);
        box.hi[a] = box.lo[a] + size(random);
      }
      const frep::Interval iv = e->bound(box);
      for (int s = 0; s < 20; ++s)
      {
        frep::Point3 p;
        for (int a = 0; a < 3; ++a)
        {
          p[a] = box.lo[a] +
            (box.hi[a] - box.lo[a]) * (s * 0.618034 * (a + 1) - std::floor(s * 0.618034 * (a + 1)));
        }
        const double v = e->value(p);
        EXPECT_LE(iv.lo, v + 1e-9);
        EXPECT_GE(iv.hi, v - 1e-9);
      }
    }
  }
  // Far from the ball and the pin both operands are negative: the union is certified outside
  // (by monotonicity: the interval extension of the R-union alone gives [-10.9, +7.5] here).
  const frep::Box3 far{ { 0, 3.2, 3.2 }, { 0.8, 4, 4 } };
  EXPECT_TRUE(fields[0]->evaluator()->bound(far).negative());
  EXPECT_TRUE(fields[1]->evaluator()->bound(far).negative());
  // In the ball's core the scan is certified inside, and so the union.
  EXPECT_TRUE(fields[0]->evaluator()->bound({ { 1.8, 1.8, 1.8 }, { 2.2, 2.2, 2.2 } }).positive());
  // The pin's core is cut out of the scan: the difference is certified outside there.
  EXPECT_TRUE(fields[1]->evaluator()->bound({ { 2.9, 2.9, 1 }, { 3.1, 3.1, 2 } }).negative());
}

TEST(FieldOperations, ChainRuleGradient)
{
  const frep::FieldPtr f = frep::uniteFields(planeScan(),
    frepField(frep::square(Expr::y() - 2.0) + frep::square(Expr::z() - 2.0) - 1.0), 0.3);
  auto e = f->evaluator();
  const frep::Point3 p{ 1.7, 2.6, 1.3 };
  frep::Point3 g;
  const double v = e->gradient(p, g);
  EXPECT_NEAR(v, e->value(p), 1e-9);
  const double h = 1e-6;
  for (int a = 0; a < 3; ++a)
  {
    frep::Point3 hi = p, lo = p;
    hi[a] += h;
    lo[a] -= h;
    EXPECT_NEAR(g[a], (e->value(hi) - e->value(lo)) / (2 * h), 1e-5) << "axis " << a;
  }
}

TEST(FieldOperations, BadOperandsAreRefused)
{
  EXPECT_THROW(frep::composedField(Expr::x(), {}), std::invalid_argument);
  EXPECT_THROW(frep::composedField(Expr::x() + Expr::y(), { planeScan() }), std::invalid_argument);
  EXPECT_THROW(frep::uniteFields(planeScan(), nullptr), std::invalid_argument);
}

TEST(FieldOperations, StampAnImplantIntoAScan)
{
  // 11 x 11 x 5 points of spacing 1 centred on the z axis; a pin of radius 2.5 from z = 0 to 2
  // covers the lattice points with i^2 + j^2 <= 6.25 (21 per layer: 1 + 4 + 4 + 4 + 8) on the
  // layers z = 0, 1, 2: 63 points.
  voxel::VoxelGrid grid;
  grid.dimensions = { 11, 11, 5 };
  grid.origin = { -5, -5, 0 };
  grid.values.assign(static_cast<std::size_t>(grid.pointCount()), 40.0f);
  const auto pin = frepField(frep::pin(2.5, 2).function());
  EXPECT_EQ(voxel::stamp(grid, *pin, 3000), 63);
  EXPECT_EQ(grid.at(5, 5, 1), 3000.0f);
  EXPECT_EQ(grid.at(7, 6, 2), 3000.0f); // (2, 1, 2)
  EXPECT_EQ(grid.at(7, 7, 1), 40.0f);   // (2, 2, 1): 8 > 6.25
  EXPECT_EQ(grid.at(5, 5, 3), 40.0f);   // above the pin
  EXPECT_THROW(voxel::stamp(grid, *pin, std::nan("")), std::invalid_argument);
}
