// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Operations between fields of any kind (issue 15): a voxel cell's field (a scan) with an FRep
// shape's, or any two Fields, combined into one Field by the FRep kernel's own formulas, so a
// scan and an implant can be united, intersected, subtracted or blended before meshing.
//
// A combination is g(f0(p), f1(p), ...): g is an ordinary Expr in which x, y, z and t stand for
// the operands' values (so at most four operands), compiled once to a tape. The set operations
// and the bounded blend below build g with Operations.h's functions on those stand-ins, so there
// is one formula for each operation whatever its operands are. The result keeps every property
// the kernel relies on:
// - values: g at the operands' values;
// - bound(box): g's interval extension over the operands' bounds on the box, an enclosure
//   because each operand bound encloses that operand (a voxel cell's bound is exact over the
//   cells the box touches, VoxelField.h); maybeNaN when any operand's or g's may be NaN. Where g
//   is known to be monotone in every operand (the R-functions: d/df1 of f1 + f2 +- sqrt(f1^2 +
//   f2^2 - 2 alpha f1 f2) is 1 +- (f1 - alpha f2) / sqrt(...), never negative for |alpha| <= 1)
//   the bound is also g at the two extreme corners of the operands' bounds, widened by a few
//   ulps, and the tighter of the two enclosures is kept: interval arithmetic alone loses the
//   correlation between the f_i inside the square root, so two negative operands would not
//   certify a box outside their union;
// - gradient: the chain rule, sum_i dg/df_i grad f_i.
// The alpha = 1 set operations (min / max) are minField / maxField in Field.h, which also keep
// their sharp edges visible to the crease tracer (Field::split); these are the smooth ones.

#include "FRep/Expr.h"
#include "FRep/Field.h"

#include <vector>

namespace ictk::frep
{

/// g(f0(p), f1(p), f2(p), f3(p)): g's x, y, z, t are the values of operands 0, 1, 2, 3. Needs
/// one to four non-null operands and a g that uses no stand-in beyond them; throws
/// std::invalid_argument otherwise. `monotone`, when given, has one entry per operand: +1 where g
/// never decreases as that operand grows, -1 where it never increases (a promise the caller
/// keeps; bound() relies on it), or 0 for neither (then the interval extension alone is used).
FieldPtr composedField(
  const Expr& g, std::vector<FieldPtr> operands, std::vector<int> monotone = {});

/// The R-functions of Operations.h (unite, intersect, subtract with alpha in (-1, 1]) between
/// two fields.
FieldPtr uniteFields(FieldPtr a, FieldPtr b, double alpha = 0.0);
FieldPtr intersectFields(FieldPtr a, FieldPtr b, double alpha = 0.0);
FieldPtr subtractFields(FieldPtr a, FieldPtr b, double alpha = 0.0);
/// Operations.h's boundedBlend between two fields, confined to the solid of `bound`.
FieldPtr boundedBlendFields(
  FieldPtr a, FieldPtr b, FieldPtr bound, double a1, double a2, double a3, double a0 = 1.0);

} // namespace ictk::frep
