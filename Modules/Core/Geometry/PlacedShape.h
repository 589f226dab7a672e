// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Shapes placed in the world: the shapes of a running model's cells, which the geometric queries
// of Queries.h (the reaction library's, docs/icm.md) and the conversion to complex cells
// (ShapeCells.h) work on.
//
// A cell's shape is one or more parts given in the cell's local coordinates (a rectangle, a disk,
// a box, a HyperFun field, a segment...), placed by an affine map (the cell's translation,
// rotation and scale, composed with its parents' under HIERARCHICAL dependencies). A 2D model
// (cells of `dim = 2D` or less whose fields are functions of x[2]) lies in the plane z = 0.
//
// The engine (Engine/DynamicModel) builds a cell's placed shape at an instant; its field
// (PlacedShape::value, worldField) is >= 0 inside, as every FRep field.

#include "Discretize/Mesh.h"
#include "FRep/Field.h"
#include "FRep/Operations.h"
#include "FRep/Vector.h"
#include "Geometry/SpaceTimeWarp.h"

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace ictk::geometry
{

/// A point or vector of the world: the kernel's (FRep/Vector.h).
using Vec3 = frep::Point3;

/// x -> A x + b.
struct Affine
{
  std::array<double, 9> a{ 1, 0, 0, 0, 1, 0, 0, 0, 1 }; ///< row-major
  Vec3 b{ 0, 0, 0 };

  /// T(translation) R_z R_y R_x S(scale): scale first, then rotations about x, y, z (radians),
  /// then the translation.
  static Affine fromTransform(const Vec3& translation, const Vec3& rotation, const Vec3& scale);
  Vec3 apply(const Vec3& p) const;
  /// The linear part only (directions).
  Vec3 applyLinear(const Vec3& v) const;
  /// (this * other)(x) = this(other(x)).
  Affine operator*(const Affine& other) const;
  /// Throws std::invalid_argument when singular (a zero scale).
  Affine inverse() const;
  bool isIdentity() const;
};

struct PlacedShape;
using PlacedShapePtr = std::shared_ptr<const PlacedShape>;

/// One part of a shape, in the cell's local coordinates.
struct ShapePart
{
  enum class Kind
  {
    Point,           ///< points[0]                                           0D
    Segment,         ///< points[0] -> points[1]                              1D
    Polyline,        ///< points[0] -> ... -> points[n-1]                     1D
    Arc,             ///< the circle |p| = radius from points[0] counter-clockwise (about +z) to
                     ///< points[1] (both projected onto the circle)                            1D
    CircularSegment, ///< the region between that Arc and its chord points[1] -> points[0] 2D
    Rectangle, ///< [-size.x/2, size.x/2] x [-size.y/2, size.y/2] in z = 0                    2D
    Disk,      ///< |p| <= radius in z = 0                                                    2D
    Box,       ///< [-size/2, size/2]                                                         3D
    Sphere,    ///< |p| <= radius                                                             3D
    Field,     ///< {field >= 0} (3D; 2D in z = 0 when fieldDimension == 2), inside `bounds`
    Blend,     ///< the blended union of two other cells' placed shapes (world coordinates)
    Union,     ///< the union of two other cells' placed shapes (world coordinates)
    SpaceTimeBlend, ///< the cross-section at `time` of the space-time blend of two other cells'
                    ///< placed shapes (world coordinates; frep::spaceTimeBlendExpr)
    Mesh ///< the triangle surface `triangles` over `points` (a .obj/.off B-cell)           2D
  };
  Kind kind = Kind::Point;
  std::vector<Vec3> points;
  /// Mesh: corners of the triangles, indices into points. An explicit surface is discretised as
  /// itself; the queries of Queries.h and worldField do not take it (they need a field).
  std::vector<std::array<std::uint32_t, 3>> triangles;
  /// Mesh: values per point that go with it into the complex cell (a skinned mesh's dominant
  /// joint and its weight).
  std::vector<discretize::PointArray> pointData;
  Vec3 size{ 0, 0, 0 };
  double radius = 0.0;
  frep::FieldPtr field; ///< Field: evaluated at local coordinates (z = 0 when 2D)
  int fieldDimension = 3;
  frep::Box3 bounds; ///< Field: the cell's domain (local coordinates)
  /// Blend / Union: the operands, already placed in the world. Blend is Pasko's blending union
  /// (thesis 2.2.3, L643-L647), f1 + f2 + sqrt(f1^2 + f2^2) + a0 / (1 + (f1/a1)^2 + (f2/a2)^2),
  /// with a0 = `amount` >= 0 the material added where both operands are near (0: the R-union,
  /// the same solid as Union's max(f1, f2)) and a1, a2 > 0 how far it reaches into each operand.
  PlacedShapePtr operandA, operandB;
  double amount = 0.0;
  double a1 = 1.0, a2 = 1.0;
  /// SpaceTimeBlend: the blend's parameters, the time of the cross-section, and the
  /// cross-section's function g(fa, fb) of the operands' values as a field of (x, y) = (fa, fb)
  /// (compiled once; made by spaceTimeBlendPart).
  frep::SpaceTimeBlendParameters spaceTime;
  double time = 0.0;
  frep::FieldPtr blend;
  /// SpaceTimeBlend: the warp of the operands at `time` (thesis 5.3.3; SpaceTimeWarp.h): cellA
  /// is evaluated at p + warp.shift(warp.shiftA, p), cellB likewise; empty: no warp.
  SpaceTimeWarp warp;
};

/// Blend, Union and SpaceTimeBlend parts are made of two other cells' placed shapes (world
/// coordinates), not of local geometry.
inline bool combinesCells(const ShapePart& p)
{
  return p.kind == ShapePart::Kind::Blend || p.kind == ShapePart::Kind::Union ||
    p.kind == ShapePart::Kind::SpaceTimeBlend;
}

/// The SpaceTimeBlend part of two placed shapes: the cross-section at `time` of their space-time
/// blend with parameters `p` (frep::spaceTimeBlendExpr; throws std::invalid_argument for bad
/// parameters). `bounds` is left empty. With control `pairs` the operands are warped so that
/// each source feature of `a` travels to its destination in `b` during the transition
/// (SpaceTimeWarp.h, thesis 5.3.3).
ShapePart spaceTimeBlendPart(PlacedShapePtr a, PlacedShapePtr b,
  const frep::SpaceTimeBlendParameters& p, double time, const std::vector<ControlPair>& pairs = {});

/// A cell's shape placed in the world.
struct PlacedShape
{
  std::string cell;             ///< the cell's name, for error messages
  int dimension = 3;            ///< the cell's declared dimension (0..3)
  std::vector<ShapePart> parts; ///< the union of its parts
  Affine place;                 ///< local -> world (ignored by Blend / Union parts)

  /// The signed field of a 2D/3D shape in world coordinates (>= 0 inside; for 2D shapes a
  /// function of (x, y), z ignored). Throws std::invalid_argument for 0D/1D shapes.
  double value(const Vec3& world) const;
  /// The world box the shape lies in.
  frep::Box3 worldBounds() const;
};

struct QueryOptions
{
  /// Absolute length below which two sets count as touching and two intersection points as one
  /// (a tangency). 0 = 1e-9 x the diagonal of the two shapes' joint bounds.
  double tolerance = 0.0;
  /// Polygon sides for circular parts when they must be discretised (curve-curve distances).
  int arcSegments = 256;
};

/// The world-space field of a 2D or 3D shape (>= 0 inside; the value PlacedShape::value gives),
/// with interval bounds and gradients, as a frep::Field (the inside field of toComplexCell's
/// cells).
frep::FieldPtr worldField(const PlacedShape& s);

} // namespace ictk::geometry
