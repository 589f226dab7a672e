// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The shapes of a running model's cells, placed in the world, and the geometric queries of the
// reaction library (docs/icm.md: distance, intersects, contains, intersectionCount,
// intersectionPoint, intersectionArea).
//
// A cell's shape is one or more parts given in the cell's local coordinates (a rectangle, a disk,
// a box, a HyperFun field, a segment...), placed by an affine map (the cell's translation,
// rotation and scale, composed with its parents' under HIERARCHICAL dependencies). A 2D model
// (cells of `dim = 2D` or less whose fields are functions of x[2]) lies in the plane z = 0.
//
// Queries are exact for the analytic parts (polygons, circles, segments, arcs) and, for fields,
// located to `QueryOptions::tolerance` by Newton steps on the field and interval arithmetic
// (frep::Field) where a proof is needed (intersects, contains). Everything is deterministic: no
// random sampling, no threads.

#include "Complex/Cell.h"
#include "FRep/Field.h"

#include <array>
#include <memory>
#include <string>
#include <vector>

namespace ictk::engine
{

using Vec3 = std::array<double, 3>;

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

struct Shape;
using ShapePtr = std::shared_ptr<const Shape>;

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
    Union      ///< the union of two other cells' placed shapes (world coordinates)
  };
  Kind kind = Kind::Point;
  std::vector<Vec3> points;
  Vec3 size{ 0, 0, 0 };
  double radius = 0.0;
  frep::FieldPtr field; ///< Field: evaluated at local coordinates (z = 0 when 2D)
  int fieldDimension = 3;
  frep::Box3 bounds; ///< Field: the cell's domain (local coordinates)
  /// Blend / Union: the operands, already placed in the world; Blend's `amount` >= 0 is the
  /// blending strength (0 = the plain union, max(f1, f2)).
  ShapePtr operandA, operandB;
  double amount = 0.0;
};

/// A cell's shape placed in the world.
struct Shape
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

/// The distance between the two point sets (0 when they intersect).
double distance(const Shape& a, const Shape& b, const QueryOptions& o = {});
/// Whether they share a point (distance <= tolerance).
bool intersects(const Shape& a, const Shape& b, const QueryOptions& o = {});
/// Whether b lies inside a (a must be 2D or 3D; up to tolerance).
bool contains(const Shape& a, const Shape& b, const QueryOptions& o = {});
/// The isolated points where the boundaries of two shapes in the plane meet: boundary curve of a
/// 2D shape or the curve of a 1D shape, against the same of the other. Points closer than the
/// tolerance are one point (a tangency counts once). Sorted by x, then y, then z (deterministic).
/// Throws std::invalid_argument naming the cells for pairs that do not meet in points (3D
/// shapes).
std::vector<Vec3> intersectionPoints(const Shape& a, const Shape& b, const QueryOptions& o = {});
/// The area (2D pairs) or volume (3D pairs) of the intersection of two 2D or 3D shapes.
double intersectionMeasure(const Shape& a, const Shape& b, const QueryOptions& o = {});
/// The area (2D) or volume (3D) of a shape.
double measure(const Shape& s, const QueryOptions& o = {});

/// The world-space field of a 2D or 3D shape (>= 0 inside; the value Shape::value gives), with
/// interval bounds and gradients, as a frep::Field (the inside field of toComplexCell's cells).
frep::FieldPtr worldField(const Shape& s);

/// The cell of an implicit complex that the placed shape stands for at this instant: implicit
/// geometry for fields, disks, spheres, sectors, blends and unions (2D ones carried by z = 0);
/// explicit points, polylines (arcs sampled with QueryOptions::arcSegments), triangles
/// (rectangles) or tetrahedra (boxes). `kind` and the name/dimension are copied to the cell.
complex::Cell toComplexCell(const Shape& s, complex::CellKind kind, const QueryOptions& o = {});

} // namespace ictk::engine
