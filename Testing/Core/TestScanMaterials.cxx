// SPDX-License-Identifier: BSD-3-Clause
// Materials from a scan (issue 15, Mesh/ScanMaterials.h) on hand-made fields, against values
// derived by hand: the default laws and floors, the integrated (Bonemat-style) mean of E over an
// element (exact for a quadratic E), fixed materials by cell, and the refusals.

#include "Mesh/ScanMaterials.h"
#include "Mesh/TetAttributes.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

using namespace ictk;
using ::testing::HasSubstr;

namespace
{

/// HU as a function of the point.
class FunctionField final : public frep::Field
{
public:
  explicit FunctionField(std::function<double(const frep::Point3&)> f)
    : f_(std::move(f))
  {
  }
  std::unique_ptr<frep::FieldEvaluator> evaluator() const override
  {
    return std::make_unique<Evaluator>(f_);
  }

private:
  class Evaluator final : public frep::FieldEvaluator
  {
  public:
    explicit Evaluator(std::function<double(const frep::Point3&)> f)
      : f_(std::move(f))
    {
    }
    void values(
      const double* x, const double* y, const double* z, double* out, std::size_t n) override
    {
      for (std::size_t i = 0; i < n; ++i)
      {
        out[i] = f_({ x[i], y[i], z[i] });
      }
    }
    frep::Interval bound(const frep::Box3&) override { return { -1e30, 1e30 }; }
    double gradient(const frep::Point3& p, frep::Point3& g) override
    {
      g = { 0, 0, 0 };
      return f_(p);
    }

  private:
    std::function<double(const frep::Point3&)> f_;
  };
  std::function<double(const frep::Point3&)> f_;
};

/// Two tetrahedra: 'bone' (the unit corner tetrahedron) and 'pin' (the same moved by 2 in x).
mesh::TetMesh twoTets()
{
  mesh::TetMesh m;
  m.points = { { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 }, { 2, 0, 0 }, { 3, 0, 0 },
    { 2, 1, 0 }, { 2, 0, 1 } };
  m.tetrahedra = { { 0, 1, 2, 3 }, { 4, 5, 6, 7 } };
  m.cells = { 0, 1 };
  m.materials = { 1, 2 };
  m.materialNames = { "bone", "pin" };
  return m;
}

mesh::ScanMaterialOptions options()
{
  mesh::ScanMaterialOptions o;
  o.scanCells = { "bone" };
  o.fixed["pin"] = { 110000, 0.34, 4.43 };
  return o;
}

double value(const mesh::TetMesh& m, const char* name, std::size_t t)
{
  return mesh::findArray(m, name)->values.at(t);
}

TEST(ScanMaterials, DefaultLaws)
{
  // HU 1000 -> rho = 1 + 0.001 * 1000 = 2 -> E = 6850 * 2^1.49, in both samplings (constant).
  auto m = twoTets();
  const auto o = options();
  const FunctionField constant([](const frep::Point3&) { return 1000.0; });
  const auto summary = mesh::assignScanMaterials(m, constant, o);
  const double exact = 6850 * std::pow(2.0, 1.49);
  EXPECT_NEAR(value(m, "youngs_modulus", 0), exact, 1e-9 * exact);
  EXPECT_NEAR(value(m, "density", 0), 2, 1e-12);
  EXPECT_EQ(value(m, "poisson_ratio", 0), 0.3);
  EXPECT_EQ(value(m, "label", 0), 1);
  // The pin's fixed material.
  EXPECT_EQ(value(m, "youngs_modulus", 1), 110000);
  EXPECT_EQ(value(m, "poisson_ratio", 1), 0.34);
  EXPECT_EQ(value(m, "density", 1), 4.43);
  EXPECT_EQ(value(m, "label", 1), 2);
  EXPECT_NEAR(summary.minModulus, exact, 1e-9 * exact);
  EXPECT_EQ(summary.maxModulus, summary.minModulus);
  EXPECT_NEAR(mesh::scanModulus(1000, o), exact, 1e-9 * exact);
  // Air: rho = 1 - 1.024 < 0 -> E at the 1 MPa floor, density at its 0.001 floor.
  EXPECT_EQ(mesh::scanModulus(-1024, o), 1);
  const FunctionField air([](const frep::Point3&) { return -1024.0; });
  mesh::assignScanMaterials(m, air, o);
  EXPECT_EQ(value(m, "youngs_modulus", 0), 1);
  EXPECT_EQ(value(m, "density", 0), 1e-3);
}

TEST(ScanMaterials, IntegratedIsTheMeanOfE)
{
  // rho = 1 + 0.001 HU with HU = 1000 x: rho = 1 + x, linear; E = 100 rho^2 (a = 0, b = 100,
  // c = 2), no binning. For a linear u with vertex values u_i the mean of u^2 over a tetrahedron
  // is (sum u_i^2 + sum_{i<j} u_i u_j) / 10; the vertices' x are 0, 1, 0, 0: u = 1, 2, 1, 1.
  auto m = twoTets();
  auto o = options();
  o.modulus = { 0, 100, 2 };
  const FunctionField linear([](const frep::Point3& p) { return 1000 * p[0]; });
  mesh::assignScanMaterials(m, linear, o);
  const double squares = 1 + 4 + 1 + 1;
  const double products = 1 * 2 + 1 * 1 + 1 * 1 + 2 * 1 + 2 * 1 + 1 * 1;
  EXPECT_NEAR(value(m, "youngs_modulus", 0), 100 * (squares + products) / 10, 1e-9);
  // At the centroid instead: rho = 1.25, E = 156.25.
  o.sampling = mesh::ScanSampling::Centroid;
  mesh::assignScanMaterials(m, linear, o);
  EXPECT_NEAR(value(m, "youngs_modulus", 0), 156.25, 1e-9);
  // The arrays are replaced, not repeated.
  EXPECT_EQ(m.cellData.size(), 4u);
}

TEST(ScanMaterials, Refusals)
{
  const FunctionField constant([](const frep::Point3&) { return 0.0; });
  auto error = [&](mesh::ScanMaterialOptions o)
  {
    auto m = twoTets();
    try
    {
      mesh::assignScanMaterials(m, constant, o);
    }
    catch (const std::invalid_argument& e)
    {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  auto o = options();
  o.fixed.clear();
  EXPECT_THAT(error(o), HasSubstr("cell 'pin' is neither a scan cell nor given a fixed material"));
  o = options();
  o.scanCells.insert("marrow");
  EXPECT_THAT(error(o), HasSubstr("'marrow' is no cell of the mesh"));
  o = options();
  o.minimumModulus = 0;
  EXPECT_THAT(error(o), HasSubstr("minimum modulus"));
  o = options();
  o.fixed["pin"].youngsModulus = 0;
  EXPECT_THAT(error(o), HasSubstr("'pin' needs a positive modulus"));
  const FunctionField nan([](const frep::Point3&) { return NAN; });
  auto m = twoTets();
  EXPECT_THROW(mesh::assignScanMaterials(m, nan, options()), std::invalid_argument);
}

} // namespace
