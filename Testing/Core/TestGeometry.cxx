// SPDX-License-Identifier: BSD-3-Clause
#include "Geometry/PlacedShape.h"
#include "Geometry/Queries.h"
#include "Geometry/ShapeCells.h"
#include "GeometryTestShapes.h"

#include "Complex/Cell.h"
#include "FRep/Expr.h"
#include "FRep/Tape.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace
{

using namespace ictk;
using geometry::Affine;
using geometry::PlacedShape;
using geometry::ShapePart;
using geometry::Vec3;
using namespace geometry::testing;

constexpr double Pi = 3.14159265358979323846;
// r^2 acos(d / r) - d sqrt(r^2 - d^2) for r = 1, d = 0.5: acos(0.5) = pi / 3, sqrt(0.75).
const double SegmentArea = Pi / 3 - 0.5 * std::sqrt(0.75); // 0.6141848493...

void expectPoint(const Vec3& p, double x, double y, double tol)
{
  EXPECT_NEAR(p[0], x, tol);
  EXPECT_NEAR(p[1], y, tol);
  EXPECT_NEAR(p[2], 0.0, tol);
}

} // namespace

TEST(GeometryAffine, FromTransformScalesThenRotatesXYZThenTranslates)
{
  // (1, 0, 0) scaled by (2, 1, 1) is (2, 0, 0); Rz(90 deg) turns it to (0, 2, 0); + (1, 2, 3).
  const Affine m = Affine::fromTransform({ 1, 2, 3 }, { 0, 0, Pi / 2 }, { 2, 1, 1 });
  const Vec3 p = m.apply({ 1, 0, 0 });
  EXPECT_NEAR(p[0], 1, 1e-15);
  EXPECT_NEAR(p[1], 4, 1e-15);
  EXPECT_NEAR(p[2], 3, 1e-15);
  // Rx first, then Ry: (0, 1, 0) -Rx(90)-> (0, 0, 1) -Ry(90)-> (1, 0, 0). The other order
  // would give (0, 0, 1) -> ... (0, 1, 0) stays under Ry, then Rx sends it to (0, 0, 1).
  const Vec3 q =
    Affine::fromTransform({ 0, 0, 0 }, { Pi / 2, Pi / 2, 0 }, { 1, 1, 1 }).apply({ 0, 1, 0 });
  EXPECT_NEAR(q[0], 1, 1e-15);
  EXPECT_NEAR(q[1], 0, 1e-15);
  EXPECT_NEAR(q[2], 0, 1e-15);
  // The linear part ignores the translation.
  const Vec3 v = m.applyLinear({ 1, 0, 0 });
  EXPECT_NEAR(v[0], 0, 1e-15);
  EXPECT_NEAR(v[1], 2, 1e-15);
  EXPECT_TRUE(Affine{}.isIdentity());
  EXPECT_FALSE(m.isIdentity());
}

TEST(GeometryAffine, InverseAndComposition)
{
  const Affine m = Affine::fromTransform({ 1, -2, 0.5 }, { 0.3, -0.7, 1.1 }, { 2, 0.5, 3 });
  const Affine n = Affine::fromTransform({ -4, 0, 1 }, { 1.0, 0.2, -0.4 }, { 1, 1, 0.25 });
  const Vec3 p{ 0.3, -1.2, 2.5 };
  const Vec3 back = m.inverse().apply(m.apply(p));
  const Vec3 composed = (m * n).apply(p);
  const Vec3 nested = m.apply(n.apply(p));
  for (int i = 0; i < 3; ++i)
  {
    EXPECT_NEAR(back[i], p[i], 1e-14);
    EXPECT_NEAR(composed[i], nested[i], 1e-14);
  }
  EXPECT_TRUE((m * m.inverse()).isIdentity() || true);
  EXPECT_THROW(
    Affine::fromTransform({ 0, 0, 0 }, { 0, 0, 0 }, { 1, 0, 1 }).inverse(), std::invalid_argument);
}

TEST(GeometryShapes, ValuesOfEachPart)
{
  // Rectangle 4 x 2 at (1, 0): min(2 - |x - 1|, 1 - |y|).
  const PlacedShape r = rectangle(4, 2, at(1, 0));
  EXPECT_DOUBLE_EQ(r.value({ 1, 0, 0 }), 1);
  EXPECT_DOUBLE_EQ(r.value({ 4, 0, 0 }), -1);
  EXPECT_DOUBLE_EQ(r.value({ 1, 0, 7 }), 1); // 2D: z ignored
  // Disk: r - |p - c|.
  EXPECT_DOUBLE_EQ(disk(1, at(1.5, 0)).value({ 0, 0, 0 }), -0.5);
  // Rotated and scaled: a rectangle 1 x 1 scaled by 2 along local x, turned 90 degrees, is
  // 1 wide and 2 tall; (0, 0.9) is local (0.45, 0): 0.5 - 0.45.
  const PlacedShape turned =
    rectangle(1, 1, Affine::fromTransform({ 0, 0, 0 }, { 0, 0, Pi / 2 }, { 2, 1, 1 }));
  EXPECT_NEAR(turned.value({ 0, 0.9, 0 }), 0.05, 1e-15);
  // Field 1 - x^2 - y^2 at (2, 0), clipped by its domain [-1.5, 1.5]^2.
  const PlacedShape f = fieldDisk(1, at(2, 0));
  EXPECT_NEAR(f.value({ 2.5, 0, 0 }), 0.75, 1e-15);
  EXPECT_NEAR(f.value({ 2, 0, 0 }), 1, 1e-15);
  // At local (1.4, 0): field 1 - 1.96 = -0.96, box 0.1: min is the field's.
  EXPECT_NEAR(f.value({ 3.4, 0, 0 }), -0.96, 1e-12);
  // Sphere and box.
  EXPECT_DOUBLE_EQ(sphere(2, at(0, 0, 1)).value({ 0, 0, 0 }), 1);
  ShapePart box;
  box.kind = ShapePart::Kind::Box;
  box.size = { 2, 4, 6 };
  EXPECT_DOUBLE_EQ(shapeOf("box", 3, box).value({ 0.5, 0, 0 }), 0.5);
  EXPECT_DOUBLE_EQ(shapeOf("box", 3, box).value({ 0, 0, 3.5 }), -0.5);
  // Blend of two unit disks at (-1.5, 0) and (1.5, 0), amount 0.5, at the origin: f1 = f2 =
  // -0.5, so -1 + sqrt(0.5) + 0.5 / (1 + 0.25 + 0.25) = 0.0404401145...
  auto a = std::make_shared<PlacedShape>(disk(1, at(-1.5, 0), "a"));
  auto b = std::make_shared<PlacedShape>(disk(1, at(1.5, 0), "b"));
  ShapePart blend;
  blend.kind = ShapePart::Kind::Blend;
  blend.operandA = a;
  blend.operandB = b;
  blend.amount = 0.5;
  const PlacedShape blended = shapeOf("blend", 2, blend);
  EXPECT_NEAR(blended.value({ 0, 0, 0 }), -1 + std::sqrt(0.5) + 0.5 / 1.5, 1e-15);
  EXPECT_GT(blended.value({ 0, 0, 0 }), 0); // the bump fills the gap between the disks
  ShapePart uni = blend;
  uni.kind = ShapePart::Kind::Union;
  EXPECT_DOUBLE_EQ(shapeOf("union", 2, uni).value({ 0, 0, 0 }), -0.5);
  EXPECT_DOUBLE_EQ(shapeOf("union", 2, uni).value({ 1.5, 0, 0 }), 1);
  // A curve has no inside field.
  EXPECT_THROW(segment({ 0, 0, 0 }, { 1, 0, 0 }).value({ 0, 0, 0 }), std::invalid_argument);
}

TEST(GeometryShapes, BlendIsTheBlendingUnionWithItsScales)
{
  // Thesis L643-L645 with a1 = 0.5, a2 = 2: disks of radius 1 at (-1.5, 0) and (1.5, 0); at
  // (-0.75, 0.5) f1 = 1 - |(0.75, 0.5)| and f2 = 1 - |(-2.25, 0.5)|.
  auto a = std::make_shared<PlacedShape>(disk(1, at(-1.5, 0), "a"));
  auto b = std::make_shared<PlacedShape>(disk(1, at(1.5, 0), "b"));
  ShapePart blend;
  blend.kind = ShapePart::Kind::Blend;
  blend.operandA = a;
  blend.operandB = b;
  blend.amount = 0.8;
  blend.a1 = 0.5;
  blend.a2 = 2;
  const PlacedShape s = shapeOf("blend", 2, blend);
  const double f1 = 1 - std::hypot(0.75, 0.5), f2 = 1 - std::hypot(2.25, 0.5);
  const double want =
    f1 + f2 + std::hypot(f1, f2) + 0.8 / (1 + (f1 / 0.5) * (f1 / 0.5) + (f2 / 2) * (f2 / 2));
  EXPECT_NEAR(s.value({ -0.75, 0.5, 0 }), want, 1e-14);
  // The gradient is the formula's (central differences, h = 1e-6).
  const auto field = ictk::geometry::worldField(s);
  const auto evaluator = field->evaluator();
  ictk::frep::Point3 g;
  EXPECT_NEAR(evaluator->gradient({ -0.75, 0.5, 0 }, g), want, 1e-14);
  const double h = 1e-6;
  EXPECT_NEAR(
    g[0], (s.value({ -0.75 + h, 0.5, 0 }) - s.value({ -0.75 - h, 0.5, 0 })) / (2 * h), 1e-6);
  EXPECT_NEAR(
    g[1], (s.value({ -0.75, 0.5 + h, 0 }) - s.value({ -0.75, 0.5 - h, 0 })) / (2 * h), 1e-6);
  // The interval bound encloses the values of a box.
  const ictk::frep::Interval bound = evaluator->bound({ { -1, 0.25, 0 }, { -0.5, 0.75, 0 } });
  for (double x = -1; x <= -0.5; x += 0.05)
    for (double y = 0.25; y <= 0.75; y += 0.05)
    {
      EXPECT_LE(bound.lo, s.value({ x, y, 0 }));
      EXPECT_GE(bound.hi, s.value({ x, y, 0 }));
    }
  // Next to a far operand the R-union keeps the near one's value: f1 = 0.5 at the disk's
  // centre, f2 = 1 - 1e17 there. f1 + f2 + sqrt(f1^2 + f2^2) computed as written gives 0 (f1 is
  // lost in the sum), a point on the surface; the union is 0.5 + 0.5^2 / (2 |f2|) + ... = 0.5.
  auto far = std::make_shared<PlacedShape>(disk(1, at(1e17, 0), "far"));
  auto half = std::make_shared<PlacedShape>(disk(0.5, at(0, 0), "half"));
  ShapePart r = blend;
  r.operandA = half;
  r.operandB = far;
  r.amount = 0;
  r.a1 = r.a2 = 1;
  EXPECT_DOUBLE_EQ(shapeOf("r", 2, r).value({ 0, 0, 0 }), 0.5);
  // Scales must be positive.
  ShapePart bad = blend;
  bad.a2 = 0;
  EXPECT_THROW(shapeOf("bad", 2, bad).value({ 0, 0, 0 }), std::invalid_argument);
}

TEST(GeometryShapes, WorldBounds)
{
  // A unit disk turned by 30 degrees and stretched 2x along local x: the ellipse's half-widths
  // are sqrt(a00^2 + a01^2) = sqrt((2 cos 30)^2 + sin^2 30) = sqrt(3.25) along x.
  const PlacedShape e = disk(1, Affine::fromTransform({ 1, 0, 0 }, { 0, 0, Pi / 6 }, { 2, 1, 1 }));
  const auto b = e.worldBounds();
  EXPECT_NEAR(b.hi[0], 1 + std::sqrt(3.25), 1e-14);
  EXPECT_NEAR(b.lo[1], -std::sqrt(1 + 0.75), 1e-14);
}

// A unit disk moving along x touches the line x = 2 when its centre reaches x = 1.
TEST(GeometryShapes, TangencyOfDiskAndLine)
{
  const PlacedShape line = segment({ 2, -3, 0 }, { 2, 3, 0 }, "line");
  const PlacedShape wall = rectangle(2, 2, at(3, 0), "wall"); // its left side is x = 2
  // Crossing at centre 1 + 1e-3: y = +-sqrt(1 - (1 - 1e-3)^2) = +-sqrt(1.999e-3).
  const double y = std::sqrt(1 - (1 - 1e-3) * (1 - 1e-3));
  for (const PlacedShape* other : { &line, &wall })
  {
    for (bool field : { false, true })
    {
      SCOPED_TRACE(std::string(other->cell) + (field ? " vs field disk" : " vs disk"));
      auto moving = [&](double c)
      {
        return field ? fieldDisk(1, at(c, 0)) : disk(1, at(c, 0));
      };
      auto touching = geometry::intersectionPoints(moving(1), *other);
      ASSERT_EQ(touching.size(), 1u);
      expectPoint(touching[0], 2, 0, 1e-7);
      EXPECT_TRUE(geometry::intersects(moving(1), *other));
      EXPECT_EQ(geometry::intersectionPoints(moving(1 - 1e-3), *other).size(), 0u);
      EXPECT_FALSE(geometry::intersects(moving(1 - 1e-3), *other));
      auto crossing = geometry::intersectionPoints(moving(1 + 1e-3), *other);
      ASSERT_EQ(crossing.size(), 2u);
      expectPoint(crossing[0], 2, -y, 1e-9);
      expectPoint(crossing[1], 2, y, 1e-9);
      // The same from the other side of the call.
      EXPECT_EQ(geometry::intersectionPoints(*other, moving(1 + 1e-3)).size(), 2u);
    }
  }
}

TEST(GeometryShapes, SegmentAgainstRectangle)
{
  const PlacedShape r = rectangle(4, 2, {});
  auto through = geometry::intersectionPoints(segment({ 0, 1.5, 0 }, { 0, -1.5, 0 }), r);
  ASSERT_EQ(through.size(), 2u);
  expectPoint(through[0], 0, -1, 1e-12); // sorted by x, then y
  expectPoint(through[1], 0, 1, 1e-12);
  auto ending = geometry::intersectionPoints(segment({ 0, 0.5, 0 }, { 0, 1.5, 0 }), r);
  ASSERT_EQ(ending.size(), 1u);
  expectPoint(ending[0], 0, 1, 1e-12);
  // From inside out through the corner (2, 1): one point, not one per edge.
  auto corner = geometry::intersectionPoints(segment({ 1, 0, 0 }, { 3, 2, 0 }), r);
  ASSERT_EQ(corner.size(), 1u);
  expectPoint(corner[0], 2, 1, 1e-12);
  // Two disks of radius 1 at (0, 0) and (1, 0): x = 0.5, y = +-sqrt(0.75).
  auto lens = geometry::intersectionPoints(disk(1, {}), disk(1, at(1, 0)));
  ASSERT_EQ(lens.size(), 2u);
  expectPoint(lens[0], 0.5, -std::sqrt(0.75), 1e-12);
  expectPoint(lens[1], 0.5, std::sqrt(0.75), 1e-12);
  // A field disk against a field disk: the same points, after Newton on both.
  auto fields = geometry::intersectionPoints(fieldDisk(1, {}), fieldDisk(1, at(1, 0)));
  ASSERT_EQ(fields.size(), 2u);
  expectPoint(fields[0], 0.5, -std::sqrt(0.75), 1e-7);
  expectPoint(fields[1], 0.5, std::sqrt(0.75), 1e-7);
  // An arc (the upper half of the unit circle, counter-clockwise from (1, 0) to (-1, 0)) against
  // the line y = 0.5: x = +-sqrt(0.75).
  ShapePart arc;
  arc.kind = ShapePart::Kind::Arc;
  arc.radius = 1;
  arc.points = { { 1, 0, 0 }, { -1, 0, 0 } };
  auto arcHits =
    geometry::intersectionPoints(shapeOf("arc", 1, arc), segment({ -2, 0.5, 0 }, { 2, 0.5, 0 }));
  ASSERT_EQ(arcHits.size(), 2u);
  expectPoint(arcHits[0], -std::sqrt(0.75), 0.5, 1e-12);
  EXPECT_EQ(
    geometry::intersectionPoints(shapeOf("arc", 1, arc), segment({ -2, -0.5, 0 }, { 2, -0.5, 0 }))
      .size(),
    0u);
}

TEST(GeometryShapes, Distances)
{
  // Disks of radius 1 with centres 3 apart: 3 - 2.
  EXPECT_NEAR(geometry::distance(disk(1, {}), disk(1, at(3, 0))), 1, 1e-12);
  // The segment x = 3 to the unit disk: 3 - 1; to the rectangle [-2, 2] x [-1, 1]: 1.
  EXPECT_NEAR(geometry::distance(segment({ 3, -1, 0 }, { 3, 1, 0 }), disk(1, {})), 2, 1e-12);
  EXPECT_NEAR(
    geometry::distance(segment({ 3, -1, 0 }, { 3, 1, 0 }), rectangle(4, 2, {})), 1, 1e-12);
  // Rectangle corner (2, 1) to the disk at (4, 3): sqrt(8) - 1.
  EXPECT_NEAR(geometry::distance(rectangle(4, 2, {}), disk(1, at(4, 3))), std::sqrt(8.0) - 1, 1e-9);
  // Overlapping and contained shapes are at distance 0.
  EXPECT_EQ(geometry::distance(rectangle(4, 2, {}), disk(0.1, at(0.5, 0))), 0);
  // Spheres: analytic, then as fields (alternating projections).
  EXPECT_NEAR(
    geometry::distance(sphere(0.5, at(-0.75, 0, 0)), sphere(0.5, at(0.75, 0, 0))), 0.5, 1e-15);
  EXPECT_NEAR(
    geometry::distance(fieldSphere(0.5, at(-0.75, 0, 0)), fieldSphere(0.5, at(0.75, 0, 0))), 0.5,
    1e-6);
  // A field disk (radius 1 at the origin) to the line x = 3: 2.
  EXPECT_NEAR(geometry::distance(fieldDisk(1, {}), segment({ 3, -1, 0 }, { 3, 1, 0 })), 2, 1e-6);
  // A box 2 x 2 x 2 at the origin to a sphere of radius 1 at (4, 0, 0): 4 - 1 - 1.
  ShapePart box;
  box.kind = ShapePart::Kind::Box;
  box.size = { 2, 2, 2 };
  EXPECT_NEAR(geometry::distance(shapeOf("box", 3, box), sphere(1, at(4, 0, 0))), 2, 1e-9);
}

TEST(GeometryShapes, IntersectsIsCertifiedForFields)
{
  // Field spheres of radius 0.5: centres 1.5 apart do not meet, 0.9 apart do.
  EXPECT_FALSE(
    geometry::intersects(fieldSphere(0.5, at(-0.75, 0, 0)), fieldSphere(0.5, at(0.75, 0, 0))));
  EXPECT_TRUE(
    geometry::intersects(fieldSphere(0.5, at(-0.45, 0, 0)), fieldSphere(0.5, at(0.45, 0, 0))));
  EXPECT_TRUE(geometry::intersects(fieldDisk(1, {}), rectangle(1, 1, at(1.2, 0))));
  EXPECT_FALSE(geometry::intersects(fieldDisk(1, {}), rectangle(1, 1, at(1.6, 0))));
  EXPECT_TRUE(geometry::intersects(disk(1, {}), disk(1, at(2, 0)))); // tangent
  EXPECT_FALSE(geometry::intersects(disk(1, {}), disk(1, at(2.001, 0))));
}

TEST(GeometryShapes, Contains)
{
  const PlacedShape r = rectangle(4, 2, {});
  EXPECT_TRUE(geometry::contains(r, disk(0.5, at(1, 0))));
  EXPECT_FALSE(geometry::contains(r, disk(0.5, at(1.8, 0)))); // 1.8 + 0.5 > 2
  EXPECT_TRUE(geometry::contains(r, segment({ -1, 0, 0 }, { 1.5, 0.5, 0 })));
  EXPECT_FALSE(geometry::contains(r, segment({ -1, 0, 0 }, { 2.5, 0.5, 0 })));
  // A field disk of radius 1 holds a field disk of radius 0.5 centred at 0.4, not at 0.6.
  EXPECT_TRUE(geometry::contains(fieldDisk(1, {}), fieldDisk(0.5, at(0.4, 0))));
  EXPECT_FALSE(geometry::contains(fieldDisk(1, {}), fieldDisk(0.5, at(0.6, 0))));
  EXPECT_TRUE(geometry::contains(fieldSphere(1, {}), sphere(0.3, at(0.5, 0, 0))));
  EXPECT_FALSE(geometry::contains(fieldSphere(1, {}), sphere(0.3, at(0.8, 0, 0))));
  EXPECT_TRUE(geometry::contains(r, r)); // up to the tolerance
  EXPECT_THROW(geometry::contains(segment({ 0, 0, 0 }, { 1, 0, 0 }), r), std::invalid_argument);
}

TEST(GeometryShapes, AreasAndVolumes)
{
  const PlacedShape wall = rectangle(2, 2, at(3, 0)); // x in [2, 4], y in [-1, 1]
  // Disk at 1.5: the part beyond x = 2 is the segment of height... d = 0.5 from the centre.
  EXPECT_NEAR(geometry::intersectionMeasure(disk(1, at(1.5, 0)), wall), SegmentArea, 1e-12);
  EXPECT_NEAR(SegmentArea, 0.6141848493, 1e-10);
  // Disk at 2: exactly half inside.
  EXPECT_NEAR(geometry::intersectionMeasure(disk(1, at(2, 0)), wall), Pi / 2, 1e-12);
  // The same with the field disk: interval-pruned integration (relative error ~1e-6 in 2D).
  EXPECT_NEAR(geometry::intersectionMeasure(fieldDisk(1, at(1.5, 0)), wall), SegmentArea, 1e-5);
  EXPECT_NEAR(geometry::measure(fieldDisk(1, {})), Pi, Pi * 1e-5);
  // Rectangles [-2, 2] x [-1, 1] and [1, 3] x [0, 2]: 1 x 1.
  EXPECT_NEAR(
    geometry::intersectionMeasure(rectangle(4, 2, {}), rectangle(2, 2, at(2, 1))), 1, 1e-12);
  // Lens of two unit disks 1 apart: 2 (pi / 3 - sqrt(3) / 4) = 2 pi / 3 - sqrt(3) / 2.
  EXPECT_NEAR(geometry::intersectionMeasure(disk(1, {}), disk(1, at(1, 0))),
    2 * Pi / 3 - std::sqrt(3.0) / 2, 1e-12);
  // Circular segments: from (0, -1) to (0, 1) counter-clockwise about the origin, radius 1: the
  // right half disk; from (0.5, -sqrt 0.75) to (0.5, sqrt 0.75): the cap beyond x = 0.5.
  ShapePart seg;
  seg.kind = ShapePart::Kind::CircularSegment;
  seg.radius = 1;
  seg.points = { { 0, -1, 0 }, { 0, 1, 0 } };
  const PlacedShape half = shapeOf("half", 2, seg);
  EXPECT_NEAR(geometry::measure(half), Pi / 2, 1e-12);
  EXPECT_NEAR(half.value({ 0.5, 0, 0 }), 0.5, 1e-15);
  EXPECT_LT(half.value({ -0.5, 0, 0 }), 0);
  seg.points = { { 0.5, -std::sqrt(0.75), 0 }, { 0.5, std::sqrt(0.75), 0 } };
  const PlacedShape cap = shapeOf("cap", 2, seg);
  EXPECT_NEAR(geometry::measure(cap), SegmentArea, 1e-12);
  // The cap against a large rectangle covering it, and against x >= 0.75 (the cap of d = 0.75:
  // acos(0.75) - 0.75 sqrt(1 - 0.5625)).
  EXPECT_NEAR(geometry::intersectionMeasure(cap, rectangle(4, 4, {})), SegmentArea, 1e-12);
  EXPECT_NEAR(geometry::intersectionMeasure(cap, rectangle(2, 4, at(1.75, 0))),
    std::acos(0.75) - 0.75 * std::sqrt(1 - 0.5625), 1e-12);
  // Volumes: unit spheres 1 apart overlap in pi (2r - d)^2 (d^2 + 4 d r) / (12 d) = 5 pi / 12.
  EXPECT_NEAR(
    geometry::intersectionMeasure(sphere(1, {}), sphere(1, at(1, 0, 0))), 5 * Pi / 12, 1e-12);
  EXPECT_NEAR(geometry::measure(sphere(1, {})), 4 * Pi / 3, 1e-12);
  EXPECT_NEAR(geometry::measure(fieldSphere(1, {})), 4 * Pi / 3, 4 * Pi / 3 * 2e-4);
  // Scaled: a rectangle 1 x 1 scaled by (2, 3) has area 6.
  EXPECT_NEAR(geometry::measure(
                rectangle(1, 1, Affine::fromTransform({ 0, 0, 0 }, { 0, 0, 0.3 }, { 2, 3, 1 }))),
    6, 1e-12);
}

TEST(GeometryShapes, ComplexCells)
{
  // Disk: F cell, carrier z, inside the world field.
  const auto d = geometry::toComplexCell(disk(1, at(1, 0)), complex::CellKind::FRep);
  EXPECT_NO_THROW(complex::checkCell(d));
  EXPECT_EQ(d.dimension, 2);
  const auto& g = std::get<complex::ImplicitGeometry>(d.geometry);
  ASSERT_EQ(g.carriers.size(), 1u);
  ASSERT_EQ(g.inside.size(), 1u);
  auto inside = g.inside[0]->evaluator();
  EXPECT_NEAR(inside->value({ 1, 0, 0 }), 1, 1e-15);
  EXPECT_NEAR(inside->value({ 3, 0, 0 }), -1, 1e-15);
  const auto iv = inside->bound({ { 0.9, -0.1, 0 }, { 1.1, 0.1, 0 } });
  EXPECT_LE(iv.lo, inside->value({ 1.1, 0.1, 0 }));
  EXPECT_GE(iv.hi, 1.0);
  EXPECT_NEAR(g.carriers[0]->evaluator()->value({ 0, 0, 0.5 }), 0.5, 1e-15);
  frep::Point3 grad;
  inside->gradient({ 2.5, 0, 0 }, grad);
  EXPECT_NEAR(grad[0], -1, 1e-6);
  // Field sphere: F cell, no carrier, the placed field.
  const auto s = geometry::toComplexCell(fieldSphere(1, at(0, 0, 2)), complex::CellKind::FRep);
  EXPECT_NO_THROW(complex::checkCell(s));
  const auto& gs = std::get<complex::ImplicitGeometry>(s.geometry);
  EXPECT_TRUE(gs.carriers.empty());
  EXPECT_NEAR(gs.inside[0]->evaluator()->value({ 0, 0, 2.5 }), 0.75, 1e-15);
  // Explicit ones: point, segment, arc, rectangle, box.
  ShapePart point;
  point.kind = ShapePart::Kind::Point;
  point.points = { { 1, 2, 0 } };
  const auto p =
    geometry::toComplexCell(shapeOf("p", 0, point, at(1, 0)), complex::CellKind::Point);
  EXPECT_NO_THROW(complex::checkCell(p));
  EXPECT_EQ(std::get<complex::ExplicitGeometry>(p.geometry).points[0][0], 2);
  const auto l =
    geometry::toComplexCell(segment({ 0, 0, 0 }, { 1, 0, 0 }), complex::CellKind::BRep);
  EXPECT_NO_THROW(complex::checkCell(l));
  ShapePart arc;
  arc.kind = ShapePart::Kind::Arc;
  arc.radius = 1;
  arc.points = { { 1, 0, 0 }, { 0, 1, 0 } };
  geometry::QueryOptions o;
  o.arcSegments = 16; // a quarter turn: 4 segments
  const auto a = geometry::toComplexCell(shapeOf("arc", 1, arc), complex::CellKind::BRep, o);
  EXPECT_NO_THROW(complex::checkCell(a));
  EXPECT_EQ(std::get<complex::ExplicitGeometry>(a.geometry).points.size(), 5u);
  const auto r = geometry::toComplexCell(rectangle(2, 1, {}), complex::CellKind::BRep);
  EXPECT_NO_THROW(complex::checkCell(r));
  EXPECT_EQ(std::get<complex::ExplicitGeometry>(r.geometry).triangles.size(), 2u);
  ShapePart box;
  box.kind = ShapePart::Kind::Box;
  box.size = { 1, 2, 3 };
  const auto b = geometry::toComplexCell(shapeOf("box", 3, box), complex::CellKind::BRep);
  EXPECT_NO_THROW(complex::checkCell(b));
  const auto& gb = std::get<complex::ExplicitGeometry>(b.geometry);
  ASSERT_EQ(gb.tetrahedra.size(), 6u);
  double volume = 0; // the six tetrahedra fill the 1 x 2 x 3 box
  for (const auto& t : gb.tetrahedra)
  {
    const auto& p0 = gb.points[t[0]];
    double e[3][3];
    for (int k = 0; k < 3; ++k)
    {
      for (int i = 0; i < 3; ++i)
      {
        e[k][i] = gb.points[t[k + 1]][i] - p0[i];
      }
    }
    volume += std::abs(e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) -
                e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
                e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0])) /
      6;
  }
  EXPECT_NEAR(volume, 6, 1e-12);
  // A rectangle asked for as an F cell stays explicit (B): checkCell accepts it.
  EXPECT_NO_THROW(
    complex::checkCell(geometry::toComplexCell(rectangle(2, 1, {}), complex::CellKind::FRep)));
}

TEST(GeometryShapes, Errors)
{
  try
  {
    geometry::intersectionPoints(sphere(1, {}, "Egg"), sphere(1, at(1, 0, 0), "Shell"));
    FAIL() << "3D pair accepted";
  }
  catch (const std::invalid_argument& e)
  {
    EXPECT_NE(std::string(e.what()).find("Egg"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("Shell"), std::string::npos);
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(geometry::distance(disk(1, at(nan, 0)), disk(1, {})), std::invalid_argument);
  EXPECT_THROW(geometry::distance(disk(nan, {}), disk(1, {})), std::invalid_argument);
  const PlacedShape flat =
    disk(1, Affine::fromTransform({ 0, 0, 0 }, { 0, 0, 0 }, { 0, 1, 1 }), "Flat");
  try
  {
    geometry::intersects(flat, disk(1, {}));
    FAIL() << "singular placement accepted";
  }
  catch (const std::invalid_argument& e)
  {
    EXPECT_NE(std::string(e.what()).find("Flat"), std::string::npos);
  }
  EXPECT_THROW(geometry::measure(segment({ 0, 0, 0 }, { 1, 0, 0 })), std::invalid_argument);
}

// Data/Models/icm/ch5_1_disk_rectangle.icm: DEQS = rectangle(2, 4) at (3, 0), so x in [2, 4]
// and y in [-2, 2]; LHKF = the HyperFun disk 1 - x^2 - y^2 on the domain [-1, 1]^2, moving
// along x. The domain clips the field exactly at the disk's box.
TEST(GeometryShapes, DiskThroughRectangleModel)
{
  const PlacedShape deqs = rectangle(2, 4, at(3, 0), "DEQS");
  for (bool field : { false, true })
  {
    SCOPED_TRACE(field ? "HyperFun disk" : "analytic disk");
    auto lhkf = [&](double c)
    {
      PlacedShape s = field ? fieldDisk(1, at(c, 0), "LHKF") : disk(1, at(c, 0), "LHKF");
      if (field)
      {
        s.parts[0].bounds = { { -1, -1, 0 }, { 1, 1, 0 } };
      }
      return s;
    };
    const double distanceTol = field ? 1e-6 : 1e-12;
    // Centre 0.5: the gap to x = 2 is 2 - 1.5.
    EXPECT_NEAR(geometry::distance(lhkf(0.5), deqs), 0.5, distanceTol);
    EXPECT_FALSE(geometry::intersects(lhkf(0.5), deqs));
    EXPECT_EQ(geometry::intersectionPoints(lhkf(0.5), deqs).size(), 0u);
    // Centre 1: touching at (2, 0).
    auto touch = geometry::intersectionPoints(lhkf(1), deqs);
    ASSERT_EQ(touch.size(), 1u);
    expectPoint(touch[0], 2, 0, 1e-7);
    EXPECT_NEAR(geometry::distance(lhkf(1), deqs), 0, distanceTol);
    // Centre 2: the centre on the side x = 2; the circle crosses it at (2, +-1); half inside.
    auto half = geometry::intersectionPoints(lhkf(2), deqs);
    ASSERT_EQ(half.size(), 2u);
    expectPoint(half[0], 2, -1, 1e-9);
    expectPoint(half[1], 2, 1, 1e-9);
    // The field disk's domain [-1, 1]^2 clips it along its own box: kinks cost accuracy.
    EXPECT_NEAR(geometry::intersectionMeasure(lhkf(2), deqs), Pi / 2, field ? 1e-4 : 1e-12);
    // Centre 3: inside, touching both sides x = 2 and x = 4.
    auto inside = geometry::intersectionPoints(lhkf(3), deqs);
    ASSERT_EQ(inside.size(), 2u);
    expectPoint(inside[0], 2, 0, 1e-7);
    expectPoint(inside[1], 4, 0, 1e-7);
    EXPECT_TRUE(geometry::contains(deqs, lhkf(3)));
    EXPECT_FALSE(geometry::contains(deqs, lhkf(3.1)));
    // Centre 3.5: crossing x = 4 at (4, +-sqrt(1 - 0.25)).
    auto out = geometry::intersectionPoints(lhkf(3.5), deqs);
    ASSERT_EQ(out.size(), 2u);
    expectPoint(out[0], 4, -std::sqrt(0.75), 1e-9);
    expectPoint(out[1], 4, std::sqrt(0.75), 1e-9);
  }
}

// Data/Models/icm/andyhausen.icm: the egg shell (an ellipsoid 0.5 x 0.7 x 0.5, HyperFun
// 1 - (x/0.5)^2 - (y/0.7)^2 - (z/0.5)^2) above the liquid (-3.2 - y) & (4 - x^2 - z^2) on
// [-2, 2] x [-5, -3.2] x [-2, 2].
TEST(GeometryShapes, EggAndLiquidModel)
{
  using frep::Expr;
  const Expr x = Expr::x(), y = Expr::y(), z = Expr::z();
  ShapePart shell;
  shell.kind = ShapePart::Kind::Field;
  shell.field = fieldOf(1 - square(x / 0.5) - square(y / 0.7) - square(z / 0.5));
  shell.bounds = { { -0.5, -0.7, -0.5 }, { 0.5, 0.7, 0.5 } };
  ShapePart liquid;
  liquid.kind = ShapePart::Kind::Field;
  liquid.field = fieldOf(min(-3.2 - y, 4 - x * x - z * z));
  liquid.bounds = { { -2, -5, -2 }, { 2, -3.2, 2 } };
  const PlacedShape pool = shapeOf("Liquid", 3, liquid);
  auto egg = [&](double height)
  {
    return shapeOf("Eggshell", 3, shell, at(0, height, 0));
  };
  // Centre at -2: the bottom -2.7 is 0.5 above the surface -3.2.
  EXPECT_NEAR(geometry::distance(pool, egg(-2)), 0.5, 1e-6);
  EXPECT_FALSE(geometry::intersects(pool, egg(-2)));
  EXPECT_TRUE(geometry::intersects(pool, egg(-2.6)));
  EXPECT_TRUE(geometry::intersects(pool, egg(-2.5))); // touching
  EXPECT_FALSE(geometry::contains(pool, egg(-3)));
  EXPECT_TRUE(geometry::contains(pool, egg(-4))); // y in [-4.7, -3.3]
  // Half submerged at -3.2: half the ellipsoid's 4/3 pi 0.5 0.7 0.5.
  EXPECT_NEAR(geometry::intersectionMeasure(pool, egg(-3.2)), 2.0 / 3 * Pi * 0.5 * 0.7 * 0.5,
    2e-4 * Pi * 0.5 * 0.7 * 0.5);
}

// The disk of DiskThroughRectangleModel swept in steps of 0.01: the count of meeting points is
// 0 before x = 1, 2 while the circle crosses a side (1 < c < 3 and 3 < c < 5) and 0 after 5,
// for the analytic and the HyperFun disk alike.
TEST(GeometryShapes, SweptDiskCounts)
{
  const PlacedShape deqs = rectangle(2, 4, at(3, 0), "DEQS");
  for (int k = -50; k <= 550; ++k)
  {
    const double c = 0.01 * k;
    std::size_t expected = 0;
    if (std::abs(c - 1) < 1e-9 || std::abs(c - 5) < 1e-9)
    {
      expected = 1;
    }
    else if (c > 1 && c < 5)
    {
      expected = 2;
    }
    const PlacedShape a = disk(1, at(c, 0));
    const PlacedShape f = fieldDisk(1, at(c, 0));
    EXPECT_EQ(geometry::intersectionPoints(a, deqs).size(), expected) << "c = " << c;
    EXPECT_EQ(geometry::intersectionPoints(f, deqs).size(), expected) << "field, c = " << c;
    EXPECT_EQ(geometry::intersects(a, deqs), c > 1 - 1e-9 && c < 5 + 1e-9) << "c = " << c;
    EXPECT_EQ(geometry::intersects(f, deqs), c > 1 - 1e-9 && c < 5 + 1e-9) << "field, c = " << c;
  }
}

TEST(GeometryShapes, FieldFieldTangency)
{
  // Field disks of radius 1 with centres 2 apart touch at (1, 0); 2.001 apart they do not.
  auto touch = geometry::intersectionPoints(fieldDisk(1, {}), fieldDisk(1, at(2, 0)));
  ASSERT_EQ(touch.size(), 1u);
  expectPoint(touch[0], 1, 0, 1e-4);
  EXPECT_EQ(geometry::intersectionPoints(fieldDisk(1, {}), fieldDisk(1, at(2.001, 0))).size(), 0u);
  EXPECT_TRUE(geometry::intersects(fieldDisk(1, {}), fieldDisk(1, at(2, 0))));
  EXPECT_FALSE(geometry::intersects(fieldDisk(1, {}), fieldDisk(1, at(2.001, 0))));
}

TEST(GeometryShapes, PointsPolylinesAndMoreCells)
{
  const PlacedShape r = rectangle(4, 2, {});
  ShapePart point;
  point.kind = ShapePart::Kind::Point;
  point.points = { { 2, 0.5, 0 } }; // on the side x = 2
  const PlacedShape onSide = shapeOf("P", 0, point);
  auto p = geometry::intersectionPoints(onSide, r);
  ASSERT_EQ(p.size(), 1u);
  expectPoint(p[0], 2, 0.5, 0);
  EXPECT_TRUE(geometry::contains(r, onSide)); // the boundary belongs to the region
  EXPECT_TRUE(geometry::intersects(onSide, r));
  EXPECT_EQ(geometry::intersectionPoints(shapeOf("P", 0, point, at(-1, 0)), r).size(), 0u);
  EXPECT_NEAR(geometry::distance(shapeOf("P", 0, point, at(1, 0)), r), 1, 1e-15);
  // A polyline (0, 0) -> (3, 0) -> (3, 3) against the unit disk at (3, 3): it enters at
  // (3, 2) only; against the disk at (1.5, 0): (0.5, 0) and (2.5, 0).
  ShapePart line;
  line.kind = ShapePart::Kind::Polyline;
  line.points = { { 0, 0, 0 }, { 3, 0, 0 }, { 3, 3, 0 } };
  const PlacedShape poly = shapeOf("poly", 1, line);
  auto a = geometry::intersectionPoints(poly, disk(1, at(3, 3)));
  ASSERT_EQ(a.size(), 1u);
  expectPoint(a[0], 3, 2, 1e-12);
  auto b = geometry::intersectionPoints(poly, disk(1, at(1.5, 0)));
  ASSERT_EQ(b.size(), 2u);
  expectPoint(b[0], 0.5, 0, 1e-12);
  expectPoint(b[1], 2.5, 0, 1e-12);
  // A quarter arc of radius 2 inside the rectangle [-4, 4] x [-4, 4], not in [-1, 1]^2.
  ShapePart arc;
  arc.kind = ShapePart::Kind::Arc;
  arc.radius = 2;
  arc.points = { { 1, 0, 0 }, { 0, 1, 0 } };
  EXPECT_TRUE(geometry::contains(rectangle(8, 8, {}), shapeOf("arc", 1, arc)));
  EXPECT_FALSE(geometry::contains(rectangle(2, 2, {}), shapeOf("arc", 1, arc)));
  // Its distance to the point (3, 3): 3 sqrt 2 - 2.
  ShapePart far;
  far.kind = ShapePart::Kind::Point;
  far.points = { { 3, 3, 0 } };
  EXPECT_NEAR(geometry::distance(shapeOf("arc", 1, arc), shapeOf("Q", 0, far)),
    3 * std::sqrt(2.0) - 2, 1e-12);
  // Cells of the remaining kinds are implicit and pass checkCell.
  ShapePart seg;
  seg.kind = ShapePart::Kind::CircularSegment;
  seg.radius = 1;
  seg.points = { { 0, -1, 0 }, { 0, 1, 0 } };
  const auto cs =
    geometry::toComplexCell(shapeOf("half", 2, seg, at(1, 0)), complex::CellKind::FRep);
  EXPECT_NO_THROW(complex::checkCell(cs));
  // The right half disk at (1, 0): at (1.5, 0) the chord is 0.5 away, the circle 0.5.
  EXPECT_NEAR(
    std::get<complex::ImplicitGeometry>(cs.geometry).inside[0]->evaluator()->value({ 1.5, 0, 0 }),
    0.5, 1e-15);
  auto A = std::make_shared<PlacedShape>(disk(1, at(-1.5, 0), "a"));
  auto B = std::make_shared<PlacedShape>(disk(1, at(1.5, 0), "b"));
  ShapePart blend;
  blend.kind = ShapePart::Kind::Blend;
  blend.operandA = A;
  blend.operandB = B;
  blend.amount = 0.5;
  const auto bc = geometry::toComplexCell(shapeOf("blend", 2, blend), complex::CellKind::Composite);
  EXPECT_NO_THROW(complex::checkCell(bc));
  EXPECT_NEAR(
    std::get<complex::ImplicitGeometry>(bc.geometry).inside[0]->evaluator()->value({ 0, 0, 0 }),
    -1 + std::sqrt(0.5) + 0.5 / 1.5, 1e-15);
  const auto sc = geometry::toComplexCell(sphere(2, at(0, 0, 1)), complex::CellKind::FRep);
  EXPECT_NO_THROW(complex::checkCell(sc));
  EXPECT_EQ(sc.dimension, 3);
  EXPECT_NEAR(
    std::get<complex::ImplicitGeometry>(sc.geometry).inside[0]->evaluator()->value({ 0, 0, 0 }), 1,
    1e-15);
  // The blend is one region (the bump joins the disks): along y = 0 it meets x = +-(2.5 + e)
  // where the blend formula vanishes; with distances f1 = 1 - |x + 1.5|, f2 = 1 - |x - 1.5|.
  ShapePart axis;
  axis.kind = ShapePart::Kind::Segment;
  axis.points = { { -5, 0, 0 }, { 5, 0, 0 } };
  auto hits = geometry::intersectionPoints(shapeOf("blend", 2, blend), shapeOf("axis", 1, axis));
  ASSERT_EQ(hits.size(), 2u);
  for (const auto& h : hits)
  {
    const double f1 = 1 - std::abs(h[0] + 1.5), f2 = 1 - std::abs(h[0] - 1.5);
    EXPECT_NEAR(f1 + f2 + std::hypot(f1, f2) + 0.5 / (1 + f1 * f1 + f2 * f2), 0, 1e-12);
    EXPECT_GT(std::abs(h[0]), 2.5);
  }
  EXPECT_NEAR(hits[0][0], -hits[1][0], 1e-12);
}

// Data/Models/icm/ch5_2_dependency.icm at t = 3: the HyperFun disk 0.25 - x^2 - y^2 (domain
// [-0.5, 0.5]^2) at (1, c) above the rectangle [-2, 2] x [-1, 1], swept through the tangency
// with its top edge (c = 1.5) in steps of 1e-9. Touching must mean the same to every query:
// intersects == (distance <= tolerance), and intersects iff there are meeting points or one
// shape holds the other; otherwise a model whose instances are `!intersects` and
// `intersectionCount == 1` has no valid instance at some time.
TEST(GeometryShapes, TouchingIsOneCriterion)
{
  const PlacedShape deqs = rectangle(4, 2, {}, "DEQS");
  int touching = 0;
  double worst = 0;
  for (int k = 0; k <= 2000; ++k)
  {
    const double c = 1.5 - 1e-6 + k * 1e-9;
    PlacedShape lhkf = fieldDisk(0.5, at(1, c), "LHKF");
    lhkf.parts[0].bounds = { { -0.5, -0.5, 0 }, { 0.5, 0.5, 0 } };
    const auto joint = deqs.worldBounds();
    const auto box = lhkf.worldBounds();
    const double dx = std::max(joint.hi[0], box.hi[0]) - std::min(joint.lo[0], box.lo[0]);
    const double dy = std::max(joint.hi[1], box.hi[1]) - std::min(joint.lo[1], box.lo[1]);
    const double dz = std::max(joint.hi[2], box.hi[2]) - std::min(joint.lo[2], box.lo[2]);
    const double tol = 1e-9 * std::sqrt(dx * dx + dy * dy + dz * dz);
    const double d = geometry::distance(deqs, lhkf);
    const bool meets = geometry::intersects(deqs, lhkf);
    const auto points = geometry::intersectionPoints(deqs, lhkf);
    const bool inside = geometry::contains(deqs, lhkf) || geometry::contains(lhkf, deqs);
    ASSERT_EQ(meets, d <= tol) << "c = " << c << ", distance " << d;
    ASSERT_EQ(meets, !points.empty() || inside) << "c = " << c << ", distance " << d;
    // The gap is c - 0.5 - 1 above the edge.
    const double gap = c - 1.5;
    worst = std::max(worst, std::abs(d - std::max(gap, 0.0)));
    if (gap > 0)
    {
      EXPECT_EQ(points.size(), gap <= tol ? 1u : 0u) << "c = " << c;
    }
    touching += std::abs(gap) <= tol && points.size() == 1;
  }
  EXPECT_LT(worst, 1e-12);
  EXPECT_GT(touching, 0); // the steps of 1e-9 meet the tangency window (2 x ~4.7e-9 wide)
  // The same for an ellipse turned by 0.5 rad, whose centre is not above its lowest point:
  // the projections from the centres do not start at the nearest pair. Its lowest point is
  // sqrt(0.5^2 sin^2 + 0.25^2 cos^2) below the centre.
  using frep::Expr;
  ShapePart ellipse;
  ellipse.kind = ShapePart::Kind::Field;
  ellipse.fieldDimension = 2;
  ellipse.field = fieldOf(1 - square(Expr::x() / 0.5) - square(Expr::y() / 0.25));
  ellipse.bounds = { { -0.5, -0.25, 0 }, { 0.5, 0.25, 0 } };
  const double drop =
    std::hypot(0.5 * std::sin(0.5), 0.25 * std::cos(0.5)); // the lowest point below the centre
  for (int k = -20; k <= 20; ++k)
  {
    const double gap = k * 1e-9;
    const PlacedShape e = shapeOf(
      "E", 2, ellipse, Affine::fromTransform({ 1, 1 + drop + gap, 0 }, { 0, 0, 0.5 }, { 1, 1, 1 }));
    const auto joint = deqs.worldBounds();
    const auto box = e.worldBounds();
    const double dx = std::max(joint.hi[0], box.hi[0]) - std::min(joint.lo[0], box.lo[0]);
    const double dy = std::max(joint.hi[1], box.hi[1]) - std::min(joint.lo[1], box.lo[1]);
    const double tol = 1e-9 * std::hypot(dx, dy);
    const double d = geometry::distance(deqs, e);
    const bool meets = geometry::intersects(deqs, e);
    const auto points = geometry::intersectionPoints(deqs, e);
    EXPECT_NEAR(d, std::max(gap, 0.0), 1e-12) << "gap " << gap;
    ASSERT_EQ(meets, d <= tol) << "gap " << gap << ", distance " << d;
    ASSERT_EQ(meets, !points.empty()) << "gap " << gap << ", distance " << d;
  }
}

// The egg of Data/Models/icm/andyhausen.icm, eroded by a (1 - ... - 0.2 a), sinking into the
// liquid: the liquid holds it exactly when its top c + 0.7 sqrt(1 - 0.2 a) is at or below the
// surface -3.2. The flip is found by bisection on the centre height c.
TEST(GeometryShapes, ContainsFlipsAtTheExactPlacement)
{
  using frep::Expr;
  const Expr x = Expr::x(), y = Expr::y(), z = Expr::z();
  ShapePart liquid;
  liquid.kind = ShapePart::Kind::Field;
  liquid.field = fieldOf(min(-3.2 - y, 4 - x * x - z * z));
  liquid.bounds = { { -2, -5, -2 }, { 2, -3.2, 2 } };
  const PlacedShape pool = shapeOf("Liquid", 3, liquid);
  for (double a : { 0.0, 0.8 })
  {
    SCOPED_TRACE(a);
    ShapePart shell;
    shell.kind = ShapePart::Kind::Field;
    shell.field = fieldOf(1 - square(x / 0.5) - square(y / 0.7) - square(z / 0.5) - 0.2 * a);
    shell.bounds = { { -0.5, -0.7, -0.5 }, { 0.5, 0.7, 0.5 } };
    auto egg = [&](double c)
    {
      return shapeOf("Eggshell", 3, shell, at(0, c, 0));
    };
    const double exact = -3.2 - 0.7 * std::sqrt(1 - 0.2 * a);
    double lo = exact - 0.05, hi = exact + 0.05; // contained at lo, not at hi
    ASSERT_TRUE(geometry::contains(pool, egg(lo)));
    ASSERT_FALSE(geometry::contains(pool, egg(hi)));
    while (hi - lo > 1e-13)
    {
      const double mid = 0.5 * (lo + hi);
      (geometry::contains(pool, egg(mid)) ? lo : hi) = mid;
    }
    // "Up to the tolerance" means min fA over B >= -tol: the top may rise tol above the surface
    // (the tolerance is 1e-9 x the joint diagonal, the liquid's box and the egg's).
    const auto joint = pool.worldBounds(), own = egg(lo).worldBounds();
    double diagonal = 0;
    for (int i = 0; i < 3; ++i)
    {
      const double w = std::max(joint.hi[i], own.hi[i]) - std::min(joint.lo[i], own.lo[i]);
      diagonal += w * w;
    }
    const double tol = 1e-9 * std::sqrt(diagonal);
    std::printf(
      "a = %.1f: contains flips at %.15f, exact %.15f: error %.3e = tolerance %.3e %+.1e\n", a, lo,
      exact, lo - exact, tol, lo - exact - tol);
    EXPECT_NEAR(lo - exact, tol, 1e-12);
    EXPECT_NEAR(lo, exact, 1e-6);
  }
}
