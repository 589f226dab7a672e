// SPDX-License-Identifier: BSD-3-Clause
#include "FRep/Domain.h"

#include <gtest/gtest.h>

using namespace ictk::frep;

TEST(Domain, TableOneDomains)
{
  // Thesis Table 1 (L1105-L1114): seven domains from 1D to 4D.
  EXPECT_EQ(domainDimension(Domain::X), 1);
  EXPECT_EQ(domainDimension(Domain::T), 1);
  EXPECT_EQ(domainDimension(Domain::XY), 2);
  EXPECT_EQ(domainDimension(Domain::XT), 2);
  EXPECT_EQ(domainDimension(Domain::XYZ), 3);
  EXPECT_EQ(domainDimension(Domain::XYT), 3);
  EXPECT_EQ(domainDimension(Domain::XYZT), 4);
  EXPECT_EQ(domainFromAxes(0b0101), std::nullopt); // (x, z) is not a modelling domain
  EXPECT_EQ(domainFromName("XYT"), Domain::XYT);
  EXPECT_TRUE(domainContains(Domain::XYZT, Domain::XT));
  EXPECT_FALSE(domainContains(Domain::XYZ, Domain::T));
}

TEST(Domain, ShapeRejectsCoordinatesOutsideItsDomain)
{
  EXPECT_THROW(Shape(Expr::z(), Domain::XY, "bad"), DomainError);
  EXPECT_NO_THROW(Shape(Expr::x(), Domain::XY, "ok"));
}

TEST(Domain, SetOperationBetween2DAnd3DIsAnError)
{
  const Shape circle(Expr(1.0) - square(Expr::x()) - square(Expr::y()), Domain::XY, "circle");
  const Shape block(Expr(1.0) - square(Expr::z()), Domain::XYZ, "block");
  try
  {
    requireSameDomain("union", circle, block);
    FAIL() << "expected a DomainError";
  }
  catch (const DomainError& e)
  {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("'circle' (domain XY)"), std::string::npos) << msg;
    EXPECT_NE(msg.find("'block' (domain XYZ)"), std::string::npos) << msg;
  }
}

TEST(Domain, ReprojectCircleOntoXZPlane)
{
  // Thesis L1139: a 2D shape defined on XY is transferred to XZ of the 3D space.
  const Shape circle(Expr(1.0) - square(Expr::x()) - square(Expr::y()), Domain::XY, "circle");
  const Shape onXZ = reproject(circle, Domain::XYZ, { Axis::X, Axis::Z });
  EXPECT_EQ(onXZ.domain(), Domain::XYZ);
  // f2(x, z): independent of y.
  EXPECT_DOUBLE_EQ(evaluateReference(onXZ.function(), { 0.5, 7.0, 0.5, 0 }), 0.5);
  EXPECT_DOUBLE_EQ(evaluateReference(onXZ.function(), { 0.0, -3.0, 1.0, 0 }), 0.0);
  // A 1D segment on X placed on the Y axis.
  const Shape seg((Expr::x() + 1.0) * (Expr(1.0) - Expr::x()), Domain::X, "segment");
  const Shape onY = reproject(seg, Domain::XYZ, { Axis::Y });
  EXPECT_DOUBLE_EQ(evaluateReference(onY.function(), { 5, 0.5, 5, 0 }), 0.75);
  EXPECT_THROW(reproject(circle, Domain::XYZ, { Axis::X }), DomainError);
  EXPECT_THROW(reproject(circle, Domain::XYZ, { Axis::X, Axis::T }), DomainError);
  EXPECT_THROW(reproject(circle, Domain::XYZ, { Axis::X, Axis::X }), DomainError);
}
