// SPDX-License-Identifier: BSD-3-Clause
#include "Skin/StandIn.h"

#include "FRep/Evaluators.h"
#include "FRep/Primitives.h"
#include "FRep/Tape.h"

#include <Eigen/Dense>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>

namespace ictk::skin
{

namespace
{

using frep::norm;
using frep::sub;

double distanceToSegment(const Vec3& p, const Vec3& a, const Vec3& b)
{
  const Vec3 ab = sub(b, a);
  const double t = std::clamp(frep::dot(sub(p, a), ab) / frep::dot(ab, ab), 0.0, 1.0);
  return frep::distance(p, frep::lerp(a, b, t));
}

/// A unit vector normal to `axis`.
Vec3 normalTo(const Vec3& axis)
{
  int k = 0;
  for (int i = 1; i < 3; ++i)
    if (std::abs(axis[i]) < std::abs(axis[k]))
      k = i;
  Vec3 e{ 0, 0, 0 };
  e[k] = 1;
  const Vec3 n = frep::cross(axis, e);
  return frep::scale(n, 1 / norm(n));
}

/// The segments' Cauchy fields f_i, one output each, evaluated together.
class SegmentFields
{
public:
  explicit SegmentFields(const StandIn& standIn)
  {
    std::vector<frep::Expr> fields;
    for (const StandInSegment& g : standIn.segments)
      fields.push_back(frep::cauchySegmentField(g.a, g.b, g.s));
    evaluator_.emplace(frep::Tape::compile(fields));
    values_.resize(fields.size());
  }

  const std::vector<double>& at(const Vec3& p)
  {
    evaluator_->evalAll({ p[0], p[1], p[2], 0 }, values_.data());
    return values_;
  }

  /// f_i at distance r from the middle of segment i.
  double midField(const StandInSegment& g, std::size_t i, double r)
  {
    const Vec3 middle = frep::lerp(g.a, g.b, 0.5);
    return at(frep::add(middle, frep::scale(normalTo(sub(g.b, g.a)), r)))[i];
  }

private:
  std::optional<frep::PointEvaluator> evaluator_;
  std::vector<double> values_;
};

} // namespace

StandIn initialStandIn(const SkinnedMesh& mesh)
{
  double size = 0;
  for (const Vec3& p : mesh.restPoints)
    size = std::max(size, norm(sub(p, mesh.restPoints.front())));
  StandIn out;
  for (const Bone& bone : bonesOf(mesh))
  {
    StandInSegment g;
    g.joint = bone.joint;
    g.parentJoint = bone.parentJoint;
    g.a = jointMarker(mesh, g.parentJoint);
    g.b = jointMarker(mesh, g.joint);
    if (!(norm(sub(g.b, g.a)) > 1e-9 * size))
      continue;
    g.radius = std::numeric_limits<double>::infinity();
    for (const Vec3& p : mesh.restPoints)
      g.radius = std::min(g.radius, distanceToSegment(p, g.a, g.b));
    // A bone that touches the mesh has no room for a surface around it.
    if (!(g.radius > 1e-9 * size))
      continue;
    g.s = 1 / g.radius;
    out.segments.push_back(g);
  }
  if (out.segments.empty())
    throw std::invalid_argument((mesh.file.empty() ? std::string("skinned mesh") : mesh.file) +
      ": no bone inside the mesh to build a stand-in on");
  return out;
}

frep::Shape standInShape(const StandIn& standIn)
{
  SegmentFields fields(standIn);
  frep::Expr sum;
  for (std::size_t i = 0; i < standIn.segments.size(); ++i)
  {
    const StandInSegment& g = standIn.segments[i];
    const frep::Expr term =
      frep::Expr(1 / fields.midField(g, i, g.radius)) * frep::cauchySegmentField(g.a, g.b, g.s);
    sum = i == 0 ? term : sum + term;
  }
  return frep::Shape(sum - frep::Expr(1.0), frep::Domain::XYZ, "standIn");
}

frep::Box3 standInBounds(const StandIn& standIn)
{
  frep::Box3 box{ { std::numeric_limits<double>::infinity(),
                    std::numeric_limits<double>::infinity(),
                    std::numeric_limits<double>::infinity() },
    { -std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
      -std::numeric_limits<double>::infinity() } };
  double radius = 0;
  for (const StandInSegment& g : standIn.segments)
  {
    radius = std::max(radius, g.radius);
    for (int k = 0; k < 3; ++k)
    {
      box.lo[k] = std::min({ box.lo[k], g.a[k], g.b[k] });
      box.hi[k] = std::max({ box.hi[k], g.a[k], g.b[k] });
    }
  }
  for (int k = 0; k < 3; ++k)
  {
    box.lo[k] -= 2 * radius;
    box.hi[k] += 2 * radius;
  }
  return box;
}

StandIn poseStandIn(const StandIn& standIn, const std::vector<Affine>& matrices)
{
  // The scale of a joint's matrix: the cube root of its linear part's determinant.
  auto scaleOf = [](const Affine& m)
  {
    const auto& a = m.a;
    const double det = a[0] * (a[4] * a[8] - a[5] * a[7]) - a[1] * (a[3] * a[8] - a[5] * a[6]) +
      a[2] * (a[3] * a[7] - a[4] * a[6]);
    return std::cbrt(std::abs(det));
  };
  StandIn out = standIn;
  for (StandInSegment& g : out.segments)
  {
    const Affine& start = matrices[static_cast<std::size_t>(g.parentJoint)];
    const Affine& end = matrices[static_cast<std::size_t>(g.joint)];
    g.a = start.apply(g.a);
    g.b = end.apply(g.b);
    const double scale = 0.5 * (scaleOf(start) + scaleOf(end));
    if (scale > 0 && std::isfinite(scale))
    {
      g.radius *= scale;
      g.s /= scale;
    }
  }
  return out;
}

StandInFitReport fitStandIn(
  StandIn& standIn, const std::vector<Vec3>& points, const StandInFitOptions& options)
{
  const auto started = std::chrono::steady_clock::now();
  const std::size_t n = standIn.segments.size();
  const auto m = static_cast<Eigen::Index>(points.size());
  SegmentFields fields(standIn);
  // The residuals are linear in k_i = 1 / f_i(r_i): F = A k - 1, A(v, i) = f_i(v).
  Eigen::MatrixXd A(m, static_cast<Eigen::Index>(n));
  for (Eigen::Index v = 0; v < m; ++v)
  {
    const std::vector<double>& f = fields.at(points[static_cast<std::size_t>(v)]);
    for (std::size_t i = 0; i < n; ++i)
      A(v, static_cast<Eigen::Index>(i)) = f[i];
  }
  const Eigen::MatrixXd G = A.transpose() * A;
  const Eigen::VectorXd ones = Eigen::VectorXd::Ones(m);
  const Eigen::VectorXd b = A.transpose() * ones;

  Eigen::VectorXd r(n), lo(n), hi(n);
  for (std::size_t i = 0; i < n; ++i)
  {
    const auto e = static_cast<Eigen::Index>(i);
    r(e) = standIn.segments[i].radius;
    lo(e) = options.minFactor * r(e);
    hi(e) = options.maxFactor * r(e);
  }
  auto kOf = [&](const Eigen::VectorXd& radii)
  {
    Eigen::VectorXd k(n);
    for (std::size_t i = 0; i < n; ++i)
      k(static_cast<Eigen::Index>(i)) =
        1 / fields.midField(standIn.segments[i], i, radii(static_cast<Eigen::Index>(i)));
    return k;
  };
  auto costOf = [&](const Eigen::VectorXd& k)
  {
    return 0.5 * (A * k - ones).squaredNorm();
  };

  StandInFitReport report;
  Eigen::VectorXd k = kOf(r);
  double cost = costOf(k);
  report.initialCost = cost;
  report.initialMeanDistance = (A * k - ones).cwiseAbs().mean();
  double lambda = 1e-3;
  bool converged = false;
  for (int it = 0; it < options.maxIterations && !converged && lambda < 1e12; ++it)
  {
    // dk_i/dr_i by central differences; J = A diag(dk/dr).
    Eigen::VectorXd dk(n);
    for (std::size_t i = 0; i < n; ++i)
    {
      const auto e = static_cast<Eigen::Index>(i);
      const double h = 1e-6 * r(e);
      const StandInSegment& g = standIn.segments[i];
      dk(e) = (1 / fields.midField(g, i, r(e) + h) - 1 / fields.midField(g, i, r(e) - h)) / (2 * h);
    }
    const Eigen::MatrixXd JtJ = dk.asDiagonal() * G * dk.asDiagonal();
    const Eigen::VectorXd JtF = dk.cwiseProduct(G * k - b);
    bool accepted = false;
    while (!accepted && lambda < 1e12)
    {
      Eigen::MatrixXd H = JtJ;
      H.diagonal() += lambda * JtJ.diagonal() + Eigen::VectorXd::Constant(n, 1e-300);
      const Eigen::VectorXd step = H.ldlt().solve(-JtF);
      const Eigen::VectorXd trial = (r + step).cwiseMax(lo).cwiseMin(hi);
      const Eigen::VectorXd trialK = kOf(trial);
      const double trialCost = costOf(trialK);
      if (trialCost < cost)
      {
        const double change = cost - trialCost;
        r = trial;
        k = trialK;
        cost = trialCost;
        lambda = std::max(lambda / 3, 1e-12);
        accepted = true;
        report.iterations = it + 1;
        converged = change <= options.relativeTolerance * cost;
      }
      else
      {
        lambda *= 4;
      }
    }
  }
  for (std::size_t i = 0; i < n; ++i)
    standIn.segments[i].radius = r(static_cast<Eigen::Index>(i));
  report.finalCost = cost;
  report.finalMeanDistance = (A * k - ones).cwiseAbs().mean();
  report.seconds =
    std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return report;
}

} // namespace ictk::skin
