// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Shapes shared by the dual contouring tests and benchmark.
#include "FRep/Expr.h"

namespace ictk::surfacetest
{

/// libfive's mesh benchmark "sphereGyroid" (libfive test/util/shapes.cpp; the formulas of
/// shared/bench/README.md), negated to FRep's convention (f >= 0 inside):
///   g = sin(x/s)cos(y/s) + sin(y/s)cos(z/s) + sin(z/s)cos(x/s), s = 0.5; gyroid = max(g, g - 0.5)
///   sphere = |p| - 3; sg = max(sphere, gyroid); f = -min(sg, min(sg, 2 sqrt(|sg|) - 0.5)).
inline frep::Expr sphereGyroid()
{
  using frep::Expr;
  const Expr x = Expr::x(), y = Expr::y(), z = Expr::z();
  const double s = 0.5;
  const Expr g = sin(x / s) * cos(y / s) + sin(y / s) * cos(z / s) + sin(z / s) * cos(x / s);
  const Expr gyroid = max(g, g - 0.5);
  const Expr sphere = sqrt(x * x + y * y + z * z) - 3.0;
  const Expr sg = max(sphere, gyroid);
  return -min(sg, min(sg, 2.0 * sqrt(abs(sg)) - 0.5));
}

} // namespace ictk::surfacetest
