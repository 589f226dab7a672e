// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Points and vectors of E^3 as std::array<double, 3>, and the few operations every algorithm needs
// on them: one set for the whole toolkit (issue 13). Callers inside other namespaces bring them
// in with using-declarations, since argument-dependent lookup only sees std.

#include <array>
#include <cmath>

namespace ictk::frep
{

using Point3 = std::array<double, 3>;

inline Point3 add(const Point3& a, const Point3& b)
{
  return { a[0] + b[0], a[1] + b[1], a[2] + b[2] };
}
inline Point3 sub(const Point3& a, const Point3& b)
{
  return { a[0] - b[0], a[1] - b[1], a[2] - b[2] };
}
inline Point3 scale(const Point3& a, double s)
{
  return { a[0] * s, a[1] * s, a[2] * s };
}
inline double dot(const Point3& a, const Point3& b)
{
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
inline Point3 cross(const Point3& a, const Point3& b)
{
  return { a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0] };
}
inline double norm(const Point3& a)
{
  return std::sqrt(dot(a, a));
}
inline double distance(const Point3& a, const Point3& b)
{
  return norm(sub(a, b));
}
/// a + t (b - a).
inline Point3 lerp(const Point3& a, const Point3& b, double t)
{
  return { a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), a[2] + t * (b[2] - a[2]) };
}

} // namespace ictk::frep
