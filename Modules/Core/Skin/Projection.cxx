// SPDX-License-Identifier: BSD-3-Clause
#include "Skin/Projection.h"

#include "FRep/Tape.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace ictk::skin
{

namespace
{

struct PointProjection
{
  Vec3 point{ 0, 0, 0 };
  double value = 0;
  Vec3 gradient{ 0, 0, 0 };
  int iterations = 0;
  bool converged = false;
};

/// Newton's projection of p onto F = 0 (see Projection.h).
PointProjection projectPoint(
  frep::FieldEvaluator& evaluator, const Vec3& start, const ProjectionOptions& options)
{
  PointProjection r;
  r.point = start;
  r.value = evaluator.gradient(r.point, r.gradient);
  for (; r.iterations < options.maxIterations && !(std::abs(r.value) < options.epsilon);
       ++r.iterations)
  {
    const double g2 = frep::dot(r.gradient, r.gradient);
    if (!(g2 > 0) || !std::isfinite(r.value))
      break;
    Vec3 step = frep::scale(r.gradient, -r.value / g2);
    // Halve the step while it does not bring F nearer 0 (far from the surface F is flat).
    bool better = false;
    for (int h = 0; h < 60 && !better; ++h, step = frep::scale(step, 0.5))
    {
      Vec3 gq{ 0, 0, 0 };
      const Vec3 q = frep::add(r.point, step);
      const double fq = evaluator.gradient(q, gq);
      if (std::abs(fq) < std::abs(r.value))
      {
        r.point = q;
        r.value = fq;
        r.gradient = gq;
        better = true;
      }
    }
    if (!better)
      break;
  }
  r.converged = std::abs(r.value) < options.epsilon;
  return r;
}

/// Runs `work(evaluator, i)` for every i < count on TBB's threads, one evaluator of `field` per
/// block of vertices: every vertex writes its own slots, so the results do not depend on the
/// threads.
template <class Work>
void forEachVertex(std::size_t count, const frep::Field& field, Work&& work)
{
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, 64),
    [&](const tbb::blocked_range<std::size_t>& range)
    {
      const auto evaluator = field.evaluator();
      for (std::size_t i = range.begin(); i != range.end(); ++i)
        work(*evaluator, i);
    });
}

Vec3 unit(const Vec3& v)
{
  const double n = frep::norm(v);
  return n > 0 ? frep::scale(v, 1 / n) : v;
}

/// The outward unit normal of {F >= 0} from F's gradient.
Vec3 outward(const Vec3& gradient)
{
  return unit(frep::scale(gradient, -1.0));
}

Vec3 cross(const Vec3& a, const Vec3& b)
{
  return { a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0] };
}

double angleDegrees(const Vec3& a, const Vec3& b)
{
  // atan2 of the sine and cosine keeps small angles exact (acos of a dot near 1 does not).
  return std::atan2(frep::norm(cross(a, b)), frep::dot(a, b)) * 180.0 / std::acos(-1.0);
}

Affine inverseTransposeOf(const Affine& place)
{
  const Affine inverse = place.inverse();
  Affine out;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      out.a[static_cast<std::size_t>(3 * r + c)] = inverse.a[static_cast<std::size_t>(3 * c + r)];
  out.b = { 0, 0, 0 };
  return out;
}

} // namespace

Projection projectOntoStandIn(
  const SkinnedMesh& mesh, const StandIn& standIn, const ProjectionOptions& options)
{
  const auto field =
    frep::tapeField(frep::Tape::compile(standInShape(standIn).function()), 0.0, {});
  std::vector<PointProjection> found(mesh.vertexCount());
  forEachVertex(mesh.vertexCount(), *field,
    [&](frep::FieldEvaluator& evaluator, std::size_t i)
    { found[i] = projectPoint(evaluator, mesh.restPoints[i], options); });
  Projection out;
  out.offsets.resize(mesh.vertexCount());
  out.standInNormals.resize(mesh.vertexCount());
  for (std::size_t i = 0; i < mesh.vertexCount(); ++i)
  {
    const PointProjection& r = found[i];
    out.offsets[i] = frep::sub(r.point, mesh.restPoints[i]);
    out.standInNormals[i] = outward(r.gradient);
    out.iterations = std::max(out.iterations, r.iterations);
    out.maxResidual = std::max(out.maxResidual, std::abs(r.value));
    if (!r.converged && out.failures++ == 0)
      out.firstFailure = i;
  }
  return out;
}

std::vector<Vec3> projectedRestPoints(
  const SkinnedMesh& mesh, const Projection& projection, double alpha)
{
  const double a = std::clamp(alpha, 0.0, 1.0);
  std::vector<Vec3> out(mesh.restPoints);
  for (std::size_t i = 0; i < out.size(); ++i)
    out[i] = frep::add(out[i], frep::scale(projection.offsets[i], a));
  return out;
}

std::vector<Vec3> restNormalsOf(const SkinnedMesh& mesh)
{
  if (!mesh.restNormals.empty())
    return mesh.restNormals;
  std::vector<Vec3> out(mesh.vertexCount(), Vec3{ 0, 0, 0 });
  for (const auto& t : mesh.triangles)
  {
    const Vec3& a = mesh.restPoints[static_cast<std::size_t>(t[0])];
    // The cross product of two edges is twice the triangle's area along its normal.
    const Vec3 n = cross(frep::sub(mesh.restPoints[static_cast<std::size_t>(t[1])], a),
      frep::sub(mesh.restPoints[static_cast<std::size_t>(t[2])], a));
    for (int v : t)
      out[static_cast<std::size_t>(v)] = frep::add(out[static_cast<std::size_t>(v)], n);
  }
  for (Vec3& n : out)
    n = unit(n);
  return out;
}

Vec3 slerpDirection(const Vec3& a, const Vec3& b, double s)
{
  if (s <= 0)
    return a;
  if (s >= 1)
    return b;
  const double angle = std::atan2(frep::norm(cross(a, b)), frep::dot(a, b));
  if (!(angle > 1e-12))
    return unit(frep::add(frep::scale(a, 1 - s), frep::scale(b, s)));
  // The unit vector normal to a in the plane of a and b (any normal for opposite vectors).
  Vec3 toward = frep::sub(b, frep::scale(a, frep::dot(a, b)));
  if (!(frep::norm(toward) > 1e-12))
  {
    toward = cross(a, std::abs(a[0]) < 0.9 ? Vec3{ 1, 0, 0 } : Vec3{ 0, 1, 0 });
  }
  toward = unit(toward);
  const double turned = s * angle;
  return unit(frep::add(frep::scale(a, std::cos(turned)), frep::scale(toward, std::sin(turned))));
}

std::vector<double> projectionDelays(const std::vector<double>& weights, double spread)
{
  if (!(spread >= 0 && spread < 1))
    throw std::invalid_argument(
      "the spread of a weight map's delays is in [0, 1), not " + std::to_string(spread));
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (std::size_t i = 0; i < weights.size(); ++i)
  {
    if (!std::isfinite(weights[i]))
      throw std::invalid_argument(
        "the weight map gives vertex " + std::to_string(i) + " a weight that is not finite");
    lo = std::min(lo, weights[i]);
    hi = std::max(hi, weights[i]);
  }
  std::vector<double> out(weights.size(), 0.0);
  if (!(hi > lo))
    return out;
  for (std::size_t i = 0; i < weights.size(); ++i)
    out[i] = spread * (1 - (weights[i] - lo) / (hi - lo));
  return out;
}

double delayedAlpha(double alpha, double delay, double spread)
{
  if (!(spread > 0))
    return std::clamp(alpha, 0.0, 1.0);
  return std::clamp((alpha - delay) / (1 - spread), 0.0, 1.0);
}

Posed skinProjected(const SkinnedMesh& mesh, const Projection& projection,
  const std::vector<Affine>& jointMatrices, const std::vector<double>& alphas)
{
  const std::size_t n = mesh.vertexCount();
  if (alphas.size() != n || projection.offsets.size() != n)
    throw std::invalid_argument("skinProjected: the projection or the alphas are not one per "
                                "vertex of the mesh");
  const std::vector<Vec3> normals = restNormalsOf(mesh);
  std::vector<Vec3> points(mesh.restPoints), turned(normals);
  for (std::size_t i = 0; i < n; ++i)
  {
    const double a = std::clamp(alphas[i], 0.0, 1.0);
    if (a > 0)
    {
      points[i] = frep::add(points[i], frep::scale(projection.offsets[i], a));
      turned[i] = slerpDirection(normals[i], projection.standInNormals[i], a);
    }
  }
  return skin(mesh, jointMatrices, points, turned);
}

ProjectedPose poseOnStandIn(const SkinnedMesh& mesh, const Projection& projection,
  const std::vector<Affine>& jointMatrices, const std::vector<double>& alphas,
  const frep::Field& posedStandIn, const ProjectionOptions& options)
{
  ProjectedPose out;
  out.posed = skinProjected(mesh, projection, jointMatrices, alphas);
  const std::size_t n = mesh.vertexCount();
  if (std::none_of(alphas.begin(), alphas.end(), [](double a) { return a > 0; }))
    return out;
  // q0_i: the whole bind-pose projection skinned, the start of the posed remainder.
  const Posed whole =
    skin(mesh, jointMatrices, projectedRestPoints(mesh, projection, 1.0), std::vector<Vec3>{});
  std::vector<char> converged(n, 1);
  forEachVertex(n, posedStandIn,
    [&](frep::FieldEvaluator& evaluator, std::size_t i)
    {
      const double a = std::clamp(alphas[i], 0.0, 1.0);
      if (!(a > 0))
        return;
      const PointProjection r = projectPoint(evaluator, whole.points[i], options);
      converged[i] = r.converged;
      const Vec3 remainder = frep::sub(r.point, whole.points[i]);
      Vec3& p = out.posed.points[i];
      // At a = 1 the point is the projection itself, not a sum that rounds next to it.
      p = a == 1.0 ? r.point : frep::add(p, frep::scale(remainder, a));
      out.posed.normals[i] = slerpDirection(out.posed.normals[i], outward(r.gradient), a);
    });
  for (std::size_t i = 0; i < n; ++i)
    if (!converged[i] && out.failures++ == 0)
      out.firstFailure = i;
  return out;
}

ProjectionResidual projectionResidual(
  const Posed& posed, const frep::Field& posedStandIn, const Affine& place)
{
  const Affine normalMap = inverseTransposeOf(place);
  const std::size_t n = posed.points.size();
  std::vector<double> distances(n, 0.0), degrees(n, 0.0);
  forEachVertex(n, posedStandIn,
    [&](frep::FieldEvaluator& evaluator, std::size_t i)
    {
      Vec3 g{ 0, 0, 0 };
      const double f = evaluator.gradient(posed.points[i], g);
      const Vec3 gw = normalMap.applyLinear(g);
      const double length = frep::norm(gw);
      distances[i] = length > 0 && std::isfinite(f) ? std::abs(f) / length
                                                    : std::numeric_limits<double>::infinity();
      if (!posed.normals.empty())
      {
        const Vec3 normal = unit(normalMap.applyLinear(posed.normals[i]));
        degrees[i] = length > 0 ? angleDegrees(normal, outward(gw)) : 180.0;
      }
    });
  ProjectionResidual out;
  for (std::size_t i = 0; i < n; ++i)
  {
    if (distances[i] > out.distance)
    {
      out.distance = distances[i];
      out.farthest = i;
    }
    out.degrees = std::max(out.degrees, degrees[i]);
  }
  return out;
}

} // namespace ictk::skin
