// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The geometric queries between placed shapes: the reaction library's distance, intersects,
// contains, intersectionCount, intersectionPoint and intersectionArea (docs/icm.md), and areas
// and volumes. One file implements each concern: Distance.cxx, Containment.cxx (intersects,
// contains), MeetingPoints.cxx, Measure.cxx; their first comments say how exact each is.
//
// Queries are exact for the analytic parts (polygons, circles, segments, arcs) and, for fields,
// located to `QueryOptions::tolerance` by Newton steps on the field and interval arithmetic
// (frep::Field) where a proof is needed (intersects, contains). Everything is deterministic: no
// random sampling, no threads.

#include "Geometry/PlacedShape.h"

#include <vector>

namespace ictk::geometry
{

/// The distance between the two point sets (0 when they intersect).
double distance(const PlacedShape& a, const PlacedShape& b, const QueryOptions& o = {});
/// Whether they share a point (distance <= tolerance).
bool intersects(const PlacedShape& a, const PlacedShape& b, const QueryOptions& o = {});
/// Whether b lies inside a (a must be 2D or 3D; up to tolerance).
bool contains(const PlacedShape& a, const PlacedShape& b, const QueryOptions& o = {});
/// The isolated points where the boundaries of two shapes in the plane meet: boundary curve of a
/// 2D shape or the curve of a 1D shape, against the same of the other. Points closer than the
/// tolerance are one point (a tangency counts once). Sorted by x, then y, then z (deterministic).
/// Throws std::invalid_argument naming the cells for pairs that do not meet in points (3D
/// shapes).
std::vector<Vec3> intersectionPoints(
  const PlacedShape& a, const PlacedShape& b, const QueryOptions& o = {});
/// The area (2D pairs) or volume (3D pairs) of the intersection of two 2D or 3D shapes.
double intersectionMeasure(const PlacedShape& a, const PlacedShape& b, const QueryOptions& o = {});
/// The area (2D) or volume (3D) of a shape.
double measure(const PlacedShape& s, const QueryOptions& o = {});

} // namespace ictk::geometry
