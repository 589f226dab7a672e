// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Internal helpers shared by the discretisers of 0D, 1D and 2D implicit cells (Patches.cxx,
// Curves.cxx, Points.cxx). Not part of the public API: the declarations may change freely.

#include "Discretize/Mesh.h"
#include "FRep/Vector.h"

#include <cmath>
#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace ictk::discretize::detail
{

using frep::add;
using frep::cross;
using frep::distance;
using frep::dot;
using frep::lerp;
using frep::norm;
using frep::scale;
using frep::sub;

inline bool finite(const Point3& p)
{
  return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]);
}
/// Distance from p to the segment [a, b].
double pointSegmentDistance(const Point3& p, const Point3& a, const Point3& b);

/// One equation c(p) = 0 of a projection: a field, or the plane x_axis = value.
struct Constraint
{
  frep::FieldEvaluator* field = nullptr;
  int axis = -1;
  double value = 0;
  static Constraint of(frep::FieldEvaluator& f)
  {
    Constraint c;
    c.field = &f;
    return c;
  }
  static Constraint plane(int axis, double value)
  {
    Constraint c;
    c.axis = axis;
    c.value = value;
    return c;
  }
  double eval(const Point3& p, Point3& grad) const;
};

struct NewtonSettings
{
  /// Converged when every |c_i| <= tolerance * |grad c_i| (a distance).
  double tolerance = 1e-10;
  int maxIterations = 30;
  /// Longest single step (0 = unlimited).
  double maxStep = 0;
  /// Fail when the point moves farther than this from where it started (0 = unlimited).
  double maxDistance = 0;
};

/// Gauss-Newton with the minimum-norm step (a complete orthogonal decomposition of the 1..3 x 3
/// Jacobian, so rank-deficient systems still step) onto {c_i = 0}. Returns false when it did not
/// converge within the settings; p is then the last iterate.
bool projectOnto(const Constraint* constraints, int count, Point3& p, const NewtonSettings& s);

/// Runs fn(begin, end) over [0, n) in chunks of `grain`, on `threads` threads (0 = TBB's default).
/// The chunks are fixed by n and grain only, so results written per index do not depend on the
/// thread count.
void forChunks(std::size_t n, std::size_t grain, int threads,
  const std::function<void(std::size_t, std::size_t)>& fn);

/// Throws std::invalid_argument unless the box is finite and non-inverted; `flatAxes` may be
/// zero-width (bit a for axis a); the other axes must have positive width.
void checkBox(const Box3& box, unsigned flatAxes, const char* what);
/// Throws std::invalid_argument naming `what` unless every pointer is non-null.
void checkFields(const std::vector<frep::FieldPtr>& fields, const char* what);

/// out[i] = field(points[i]), in parallel chunks.
void evaluateAt(const frep::Field& field, const std::vector<Point3>& points,
  std::vector<double>& out, int threads);

/// A non-owning FieldPtr to a field the caller keeps alive.
inline frep::FieldPtr borrow(const frep::Field& f)
{
  return frep::FieldPtr(frep::FieldPtr(), &f);
}

/// Evaluators of a list of fields (one set per thread or chunk).
std::vector<std::unique_ptr<frep::FieldEvaluator>> evaluatorsOf(
  const std::vector<frep::FieldPtr>& fields);

/// Clipping a triangle mesh by fields >= 0. `onTrim[v]` has bit k set when vertex v is known to
/// lie on {trims[k] = 0} (it then counts as inside trim k and cut edges from it end at v). Cut
/// points are found by bisection along the edge, then projected onto {carrier = 0, trim = 0} (and
/// the trims both edge ends lie on). carrier == nullptr means the plane z = planeZ.
struct ClipSettings
{
  const frep::Field* carrier = nullptr;
  double planeZ = 0;
  NewtonSettings newton;
  int threads = 0;
};
SurfaceMesh clipMesh(SurfaceMesh mesh, std::vector<unsigned>& onTrim,
  const std::vector<frep::FieldPtr>& trims, const ClipSettings& settings);

} // namespace ictk::discretize::detail
