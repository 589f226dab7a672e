// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// What the tests of the FRep operation library share (TestOperations.cxx, TestSpaceMaps.cxx).
// Operands are built directly as Shapes from Exprs (not from Primitives.cxx) so that these tests
// depend on Operations.cxx alone.
//
// Most scalar checks use "probe" operands f1 = x, f2 = y, f3 = z on XYZ: evaluating the result at
// (f1, f2, f3) gives the operation at those operand values, so the spec formulas can be checked on
// a grid of operand values (spec feature list thesis_ch2_3.md section 5, items 9-27).
#include "FRep/Evaluators.h"
#include "FRep/Operations.h"

#include <gtest/gtest.h>

#include <functional>
#include <initializer_list>
#include <string>

namespace operationstest
{
using namespace ictk::frep;

inline constexpr double tol = 1e-12;

inline double eval(const Shape& s, double x, double y = 0.0, double z = 0.0, double t = 0.0)
{
  return evaluateReference(s.function(), { x, y, z, t });
}

inline const Shape probe1(Expr::x(), Domain::XYZ, "f1");
inline const Shape probe2(Expr::y(), Domain::XYZ, "f2");
inline const Shape probe3(Expr::z(), Domain::XYZ, "f3");

inline Shape unitSphere()
{
  return Shape(
    Expr(1.0) - square(Expr::x()) - square(Expr::y()) - square(Expr::z()), Domain::XYZ, "sphere");
}

inline Shape disk(double cx, double cy, double r)
{
  return Shape(Expr(r * r) - square(Expr::x() - cx) - square(Expr::y() - cy), Domain::XY, "circle");
}

inline Shape testShape()
{
  const Expr x = Expr::x(), y = Expr::y(), z = Expr::z();
  return Shape(
    1.0 - square(x - 0.3) - 2.0 * square(y + 0.2) - 0.5 * square(z) + 0.7 * x * y - 0.4 * z,
    Domain::XYZ, "field");
}

// Expects `op` to throw E whose message contains every string in `parts`.
template <typename E>
inline void expectThrowMentioning(
  const std::function<void()>& op, std::initializer_list<const char*> parts)
{
  try
  {
    op();
    ADD_FAILURE() << "expected an exception";
  }
  catch (const E& e)
  {
    const std::string msg = e.what();
    for (const char* p : parts)
    {
      EXPECT_NE(msg.find(p), std::string::npos) << "message '" << msg << "' lacks '" << p << "'";
    }
  }
}

} // namespace operationstest
