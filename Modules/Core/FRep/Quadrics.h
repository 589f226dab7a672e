// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The named base quadrics of seed 003 (papers.md 2.3: 'ell', 'seat', 'ellpar', 'unihyp',
// 'duahyp', 'cone', 'cylinder', 'layer', 'plane', 'clin', 'parabola', 'hyperbola'), each as the ten
// coefficients of eq. (1) (FRep/Primitives.h quadric()) in a canonical unit position, so that the
// scene language (Lang/Scene.h) places and sizes them with its transformations and perturbs them
// with perturb(). The paper names the types and never writes them down: the forms below are
// ours (papers.md 2.3 [INF]), chosen so that each type is the one-term-less or sign-changed
// relative of another, and all of them open along z:
//   ell       1 - x^2 - y^2 - z^2      unit ball (ellipsoid once scaled)
//   seat      z - x^2 + y^2            above a hyperbolic paraboloid (saddle)
//   ellpar    z - x^2 - y^2            inside an elliptic paraboloid opening towards +z
//   unihyp    1 - x^2 - y^2 + z^2      inside a hyperboloid of one sheet about z
//   duahyp    z^2 - x^2 - y^2 - 1      inside both sheets of a hyperboloid of two sheets
//   cone      z^2 - x^2 - y^2          inside a double cone about z (half-angle 45 degrees)
//   cylinder  1 - x^2 - y^2            unit cylinder about z
//   layer     1 - z^2                  the slab |z| <= 1
//   plane     -z                       the half-space z <= 0
//   clin      z^2 - x^2                a double wedge about the y axis (Russian "klin", wedge:
//                                      the cone's two-plane relative)
//   parabola  z - x^2                  inside a parabolic cylinder along y
//   hyperbola z^2 - x^2 - 1            inside both sheets of a hyperbolic cylinder along y
// quadric() lowers them in completed-square form, so that interval arithmetic over a box gives
// the exact range of an axis-aligned one (what seed 003's voxel culling bound needs, item 31).

#include "FRep/Domain.h"

#include <array>
#include <optional>
#include <string>
#include <vector>

namespace ictk::frep
{

enum class QuadricType
{
  Ell,
  Seat,
  Ellpar,
  Unihyp,
  Duahyp,
  Cone,
  Cylinder,
  Layer,
  Plane,
  Clin,
  Parabola,
  Hyperbola
};

struct QuadricTypeInfo
{
  QuadricType type;
  const char* keyword;     ///< the scene language's keyword (seed 003 line 141)
  const char* description; ///< what the solid is
  const char* formula;     ///< F(x, y, z) in the canonical position, F >= 0 inside
  /// (A11, A22, A33, A12, A13, A23, A14, A24, A34, A44) of eq. (1).
  std::array<double, 10> coefficients;
};

/// The twelve types, in the paper's order.
const std::vector<QuadricTypeInfo>& quadricTypes();
/// The type of a keyword ("ell", ...), if it is one.
std::optional<QuadricType> quadricTypeFromKeyword(const std::string& keyword);
const QuadricTypeInfo& quadricTypeInfo(QuadricType type);
/// The canonical solid of a type (quadric() of its coefficients), labelled with its keyword.
Shape namedQuadric(QuadricType type);

} // namespace ictk::frep
