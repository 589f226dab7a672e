// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Placed shapes for the Geometry tests and benchmarks (TestGeometry.cxx, BenchGeometry.cxx): the
// analytic parts and HyperFun-style fields (r^2 - |p|^2, not distances) the reaction library meets
// in the thesis exemplars, built the same way in both so that the benchmark times what the tests
// check.

#include "FRep/Expr.h"
#include "FRep/Tape.h"
#include "Geometry/PlacedShape.h"

#include <string>
#include <utility>

namespace ictk::geometry::testing
{

inline Affine at(double x, double y, double z = 0)
{
  return Affine::fromTransform({ x, y, z }, { 0, 0, 0 }, { 1, 1, 1 });
}

inline PlacedShape shapeOf(
  const std::string& name, int dimension, ShapePart part, const Affine& place = {})
{
  PlacedShape s;
  s.cell = name;
  s.dimension = dimension;
  s.parts.push_back(std::move(part));
  s.place = place;
  return s;
}

inline PlacedShape disk(double r, const Affine& place, const std::string& name = "disk")
{
  ShapePart p;
  p.kind = ShapePart::Kind::Disk;
  p.radius = r;
  return shapeOf(name, 2, p, place);
}

inline PlacedShape rectangle(
  double w, double h, const Affine& place, const std::string& name = "rectangle")
{
  ShapePart p;
  p.kind = ShapePart::Kind::Rectangle;
  p.size = { w, h, 0 };
  return shapeOf(name, 2, p, place);
}

inline PlacedShape segment(const Vec3& a, const Vec3& b, const std::string& name = "segment")
{
  ShapePart p;
  p.kind = ShapePart::Kind::Segment;
  p.points = { a, b };
  return shapeOf(name, 1, p);
}

inline PlacedShape sphere(double r, const Affine& place, const std::string& name = "sphere")
{
  ShapePart p;
  p.kind = ShapePart::Kind::Sphere;
  p.radius = r;
  return shapeOf(name, 3, p, place);
}

inline frep::FieldPtr fieldOf(const frep::Expr& e)
{
  return frep::tapeField(frep::Tape::compile(e));
}

/// The HyperFun-style disk r^2 - x^2 - y^2 (not a distance) as a 2D Field part.
inline PlacedShape fieldDisk(double r, const Affine& place, const std::string& name = "fieldDisk")
{
  using frep::Expr;
  ShapePart p;
  p.kind = ShapePart::Kind::Field;
  p.fieldDimension = 2;
  p.field = fieldOf(r * r - Expr::x() * Expr::x() - Expr::y() * Expr::y());
  p.bounds = { { -1.5 * r, -1.5 * r, 0 }, { 1.5 * r, 1.5 * r, 0 } };
  return shapeOf(name, 2, p, place);
}

inline PlacedShape fieldSphere(
  double r, const Affine& place, const std::string& name = "fieldSphere")
{
  using frep::Expr;
  ShapePart p;
  p.kind = ShapePart::Kind::Field;
  p.fieldDimension = 3;
  p.field = fieldOf(r * r - Expr::x() * Expr::x() - Expr::y() * Expr::y() - Expr::z() * Expr::z());
  p.bounds = { { -2 * r, -2 * r, -2 * r }, { 2 * r, 2 * r, 2 * r } };
  return shapeOf(name, 3, p, place);
}

} // namespace ictk::geometry::testing
