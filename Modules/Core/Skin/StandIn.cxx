// SPDX-License-Identifier: BSD-3-Clause
#include "Skin/StandIn.h"

#include "FRep/Evaluators.h"
#include "FRep/Primitives.h"
#include "FRep/RootFinding.h"
#include "FRep/Tape.h"

#include <Eigen/Dense>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>

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

/// The scale of a joint's matrix: the cube root of its linear part's determinant.
double scaleOf(const Affine& m)
{
  const auto& a = m.a;
  const double det = a[0] * (a[4] * a[8] - a[5] * a[7]) - a[1] * (a[3] * a[8] - a[5] * a[6]) +
    a[2] * (a[3] * a[7] - a[4] * a[6]);
  return std::cbrt(std::abs(det));
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

namespace
{

/// The Cauchy field of a segment whose ends and kernel width are the parameters [a, b, s] from
/// `slot` on (7 slots), or constants when `g` is given.
frep::Expr segmentField(const StandInSegment* g, std::uint32_t slot)
{
  const auto input = [&](int k, double value)
  {
    return g ? frep::Expr(value) : frep::Expr::parameter(slot + static_cast<std::uint32_t>(k));
  };
  const Vec3 a = g ? g->a : Vec3{ 0, 0, 0 }, b = g ? g->b : Vec3{ 0, 0, 0 };
  return frep::cauchySegmentField({ input(0, a[0]), input(1, a[1]), input(2, a[2]) },
    { input(3, b[0]), input(4, b[1]), input(5, b[2]) }, input(6, g ? g->s : 0));
}

/// Refuses a segment a posed or refitted stand-in cannot be built on (the constant path of
/// FRep's segment field checked the same; parameters are not checked when they are bound).
void checkSegment(const StandInSegment& g, std::size_t i)
{
  const auto finite = [](const Vec3& v)
  {
    return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
  };
  const std::string which =
    "stand-in segment " + std::to_string(i) + " (joint " + std::to_string(g.joint) + ")";
  if (!finite(g.a) || !finite(g.b))
  {
    throw std::invalid_argument(which + ": an end is not finite");
  }
  if (!(norm(sub(g.b, g.a)) > 0))
  {
    throw std::invalid_argument(which + " has zero length (its two ends coincide)");
  }
  if (!(g.s > 0) || !std::isfinite(g.s) || !(g.radius > 0) || !std::isfinite(g.radius))
  {
    throw std::invalid_argument(
      which + ": its kernel width and radius must be positive and finite");
  }
}

/// 1 / f_i(r_i): the weight that makes a segment alone zero at its radius from its middle. From
/// one tape of a segment's parameters, compiled once for every stand-in and pose.
double segmentWeight(const StandInSegment& g)
{
  static const frep::TapePtr tape = frep::Tape::compile(segmentField(nullptr, 0));
  frep::PointEvaluator own(tape, { g.a[0], g.a[1], g.a[2], g.b[0], g.b[1], g.b[2], g.s });
  const Vec3 p =
    frep::add(frep::lerp(g.a, g.b, 0.5), frep::scale(normalTo(sub(g.b, g.a)), g.radius));
  return 1 / own.eval(p[0], p[1], p[2]);
}

/// F = sum_i w_i f_i - 1 (w_i = segmentWeight), over constants when `standIn` is given, else
/// over the parameters of n segments (StandInField's layout: a, b, s, w from slot 8 i on).
frep::Expr standInSum(const StandIn* standIn, std::size_t n)
{
  frep::Expr sum;
  for (std::size_t i = 0; i < n; ++i)
  {
    const StandInSegment* g = standIn ? &standIn->segments[i] : nullptr;
    if (g)
    {
      checkSegment(*g, i);
    }
    const auto slot = static_cast<std::uint32_t>(StandInField::ParametersPerSegment * i);
    const frep::Expr weight = g ? frep::Expr(segmentWeight(*g)) : frep::Expr::parameter(slot + 7);
    const frep::Expr term = weight * segmentField(g, slot);
    sum = i == 0 ? term : sum + term;
  }
  return sum - frep::Expr(1.0);
}

} // namespace

frep::Shape standInShape(const StandIn& standIn)
{
  return frep::Shape(standInSum(&standIn, standIn.segments.size()), frep::Domain::XYZ, "standIn");
}

StandInField::StandInField(std::size_t segmentCount)
  : segmentCount_(segmentCount)
  , tape_(frep::Tape::compile(standInSum(nullptr, segmentCount)))
{
}

std::vector<double> StandInField::parameters(const StandIn& standIn) const
{
  if (standIn.segments.size() != segmentCount_)
    throw std::invalid_argument("StandInField: a stand-in of " +
      std::to_string(standIn.segments.size()) + " segments bound to a tape of " +
      std::to_string(segmentCount_));
  std::vector<double> out;
  out.reserve(ParametersPerSegment * segmentCount_);
  for (std::size_t i = 0; i < segmentCount_; ++i)
  {
    const StandInSegment& g = standIn.segments[i];
    checkSegment(g, i);
    out.insert(out.end(), { g.a[0], g.a[1], g.a[2], g.b[0], g.b[1], g.b[2], g.s });
    out.push_back(segmentWeight(g));
  }
  return out;
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

namespace ictk::skin
{

namespace
{

/// The stand-in's field F as a point evaluator.
frep::PointEvaluator fieldOf(const StandIn& standIn)
{
  return frep::PointEvaluator(frep::Tape::compile(standInShape(standIn).function()));
}

double valueAt(frep::PointEvaluator& f, const Vec3& p)
{
  return f.eval(p[0], p[1], p[2]);
}

/// How far from `from` along the unit `direction` F first falls to 0, marching in steps of `step`
/// for at most `steps` of them; nothing when F(from) <= 0 or no fall is met.
std::optional<double> reachAlong(
  frep::PointEvaluator& f, const Vec3& from, const Vec3& direction, double step, int steps)
{
  auto g = [&](double t)
  {
    return valueAt(f, frep::add(from, frep::scale(direction, t)));
  };
  double t0 = 0, g0 = g(0);
  if (!(g0 > 0))
    return std::nullopt;
  for (int k = 1; k <= steps; ++k)
  {
    const double t1 = k * step, g1 = g(t1);
    if (g1 <= 0)
    {
      frep::LocateOptions o;
      o.timeTolerance = 1e-12 * (1 + t1);
      return g1 == 0 ? t1 : frep::refineRoot(g, t0, g0, t1, g1, o);
    }
    t0 = t1;
    g0 = g1;
  }
  return std::nullopt;
}

/// A unit vector of the Fibonacci lattice of n points on the sphere.
Vec3 fibonacciDirection(int k, int n)
{
  const double z = 1 - (2.0 * k + 1) / n;
  const double r = std::sqrt(std::max(0.0, 1 - z * z));
  const double phi = k * 3.14159265358979323846 * (3 - std::sqrt(5.0));
  return { r * std::cos(phi), r * std::sin(phi), z };
}

} // namespace

StandInFitReport fitEmbeddedStandIn(StandIn& standIn, const std::vector<Vec3>& points,
  const std::vector<std::array<int, 3>>& triangles, const StandInFitOptions& options)
{
  const auto started = std::chrono::steady_clock::now();
  const std::size_t n = standIn.segments.size();
  const auto N = static_cast<Eigen::Index>(n);
  SegmentFields fields(standIn);
  auto rowsOf = [&](const std::vector<Vec3>& at)
  {
    Eigen::MatrixXd M(static_cast<Eigen::Index>(at.size()), N);
    for (std::size_t v = 0; v < at.size(); ++v)
    {
      const std::vector<double>& f = fields.at(at[v]);
      for (std::size_t i = 0; i < n; ++i)
        M(static_cast<Eigen::Index>(v), static_cast<Eigen::Index>(i)) = f[i];
    }
    return M;
  };
  // The cost's rows (the vertices) and the constraints' (vertices, edge middles, centroids).
  const Eigen::MatrixXd A = rowsOf(points);
  std::vector<Vec3> constrained = points;
  {
    std::vector<std::pair<int, int>> edges;
    for (const auto& t : triangles)
    {
      const Vec3& a = points[static_cast<std::size_t>(t[0])];
      const Vec3& b = points[static_cast<std::size_t>(t[1])];
      const Vec3& c = points[static_cast<std::size_t>(t[2])];
      constrained.push_back(frep::scale(frep::add(frep::add(a, b), c), 1.0 / 3));
      for (int k = 0; k < 3; ++k)
        edges.emplace_back(std::min(t[k], t[(k + 1) % 3]), std::max(t[k], t[(k + 1) % 3]));
    }
    std::sort(edges.begin(), edges.end());
    edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
    for (const auto& [a, b] : edges)
      constrained.push_back(
        frep::lerp(points[static_cast<std::size_t>(a)], points[static_cast<std::size_t>(b)], 0.5));
  }
  const Eigen::MatrixXd C = rowsOf(constrained);
  const Eigen::MatrixXd G = A.transpose() * A;
  const Eigen::VectorXd b = A.transpose() * Eigen::VectorXd::Ones(A.rows());
  const double m = static_cast<double>(A.rows());
  auto costOf = [&](const Eigen::VectorXd& k)
  {
    return 0.5 * k.dot(G * k) - b.dot(k) + 0.5 * m;
  };
  auto meanOf = [&](const Eigen::VectorXd& k)
  {
    return (A * k - Eigen::VectorXd::Ones(A.rows())).cwiseAbs().mean();
  };

  StandInFitReport report;
  Eigen::VectorXd k(N), lo(N), hi(N), rhi(N);
  for (std::size_t i = 0; i < n; ++i)
  {
    const StandInSegment& g = standIn.segments[i];
    const auto e = static_cast<Eigen::Index>(i);
    k(e) = 1 / fields.midField(g, i, g.radius);
    lo(e) = 1 / fields.midField(g, i, 0.0);
    rhi(e) = options.maxFactor * g.radius;
    hi(e) = 1 / fields.midField(g, i, rhi(e));
  }
  report.initialCost = costOf(k);
  report.initialMeanDistance = meanOf(k);
  // A point positive with every radius 0 cannot be helped (every field is positive everywhere,
  // so its bound would hold every weight at 0 radius): it is left out.
  std::vector<Eigen::Index> kept;
  {
    const Eigen::VectorXd atZero = C * lo;
    for (Eigen::Index v = 0; v < C.rows(); ++v)
      (atZero(v) < 1 - options.margin ? kept.push_back(v) : void(++report.violations));
  }
  Eigen::MatrixXd K(static_cast<Eigen::Index>(kept.size()), N);
  for (std::size_t v = 0; v < kept.size(); ++v)
    K.row(static_cast<Eigen::Index>(v)) = C.row(kept[v]);
  // The barrier method (Boyd and Vandenberghe 11.3): Newton's method on
  //   t cost(k) - sum log(1 - K k) - sum log(k - lo) - sum log(hi - k)
  // for t growing by 20 until the duality gap (the number of constraints / t) is below
  // relativeTolerance x the cost, from a strictly feasible start near every radius 0.
  const auto count = static_cast<double>(K.rows() + 2 * N);
  double start = 1e-3;
  k = lo + start * (hi - lo);
  while ((K * k).maxCoeff() >= 1 - options.margin && start > 1e-15)
    k = lo + (start *= 0.1) * (hi - lo);
  const double tolerance = std::max(options.relativeTolerance, 1e-9);
  int newtonSteps = 0;
  auto barrier = [&](const Eigen::VectorXd& x, double t)
  {
    const Eigen::VectorXd slack = Eigen::VectorXd::Constant(K.rows(), 1 - options.margin) - K * x;
    if (slack.minCoeff() <= 0 || (x - lo).minCoeff() <= 0 || (hi - x).minCoeff() <= 0)
      return std::numeric_limits<double>::infinity();
    return t * costOf(x) - slack.array().log().sum() - (x - lo).array().log().sum() -
      (hi - x).array().log().sum();
  };
  for (double t = 1; count / t > tolerance * std::max(costOf(k), 1e-300); t *= 20)
  {
    for (int it = 0; it < 50 && newtonSteps < 50 * options.maxIterations; ++it, ++newtonSteps)
    {
      const Eigen::VectorXd slack = Eigen::VectorXd::Constant(K.rows(), 1 - options.margin) - K * k;
      const Eigen::VectorXd inverse = slack.cwiseInverse();
      const Eigen::VectorXd below = (k - lo).cwiseInverse(), above = (hi - k).cwiseInverse();
      const Eigen::VectorXd gradient = t * (G * k - b) + K.transpose() * inverse - below + above;
      Eigen::MatrixXd H = t * G + K.transpose() * inverse.cwiseAbs2().asDiagonal() * K;
      H.diagonal() += below.cwiseAbs2() + above.cwiseAbs2();
      const Eigen::VectorXd step = H.ldlt().solve(-gradient);
      const double decrement = -gradient.dot(step);
      if (!(decrement > 2e-10))
        break;
      // Backtracking (Armijo) within the feasible set.
      const double before = barrier(k, t);
      double s = 1;
      while (s > 1e-12 && !(barrier(k + s * step, t) <= before - 0.25 * s * decrement))
        s *= 0.5;
      if (s <= 1e-12)
        break;
      k += s * step;
    }
  }
  const double cost = costOf(k);
  const int sweep = newtonSteps;
  // The radii: f_i(r_i) = 1 / k_i, f_i falling with r from f_i(0) = 1 / lo_i.
  for (std::size_t i = 0; i < n; ++i)
  {
    StandInSegment& g = standIn.segments[i];
    const auto e = static_cast<Eigen::Index>(i);
    const double target = 1 / k(e);
    double a = 0, z = rhi(e);
    for (int it = 0; it < 200 && z - a > 1e-15 * rhi(e); ++it)
    {
      const double mid = 0.5 * (a + z);
      (fields.midField(g, i, mid) > target ? a : z) = mid;
    }
    g.radius = 0.5 * (a + z);
  }
  report.finalCost = cost;
  report.finalMeanDistance = meanOf(k);
  report.iterations = sweep;
  report.seconds =
    std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return report;
}

StandIn fittedStandIn(const SkinnedMesh& mesh, StandInFitReport* report)
{
  StandIn out = initialStandIn(mesh);
  StandInFitOptions options;
  options.margin = 0.05;
  const StandInFitReport r = fitEmbeddedStandIn(out, mesh.restPoints, mesh.triangles, options);
  if (report)
    *report = r;
  return out;
}

std::vector<Vec3> standInSurfaceSamples(const StandIn& standIn, int along, int directions)
{
  frep::PointEvaluator f = fieldOf(standIn);
  double largest = 0;
  for (const StandInSegment& g : standIn.segments)
    largest = std::max(largest, g.radius);
  std::vector<Vec3> out;
  for (const StandInSegment& g : standIn.segments)
  {
    if (!(g.radius > 0))
      continue;
    // A quarter of the segment's radius (of a fiftieth of the largest for a thin one) per step;
    // the surface lies within twice the largest radius of a segment (standInBounds).
    const double step = 0.25 * std::max(g.radius, 0.02 * largest);
    const int steps = static_cast<int>(std::ceil(4 * largest / step)) + 1;
    for (int u = 0; u < along; ++u)
    {
      const Vec3 from = frep::lerp(g.a, g.b, along > 1 ? double(u) / (along - 1) : 0.5);
      for (int d = 0; d < directions; ++d)
      {
        const Vec3 direction = fibonacciDirection(d, directions);
        if (const auto t = reachAlong(f, from, direction, step, steps))
          out.push_back(frep::add(from, frep::scale(direction, *t)));
      }
    }
  }
  return out;
}

double windingNumber(
  const std::vector<Vec3>& points, const std::vector<std::array<int, 3>>& triangles, const Vec3& p)
{
  double sum = 0;
  for (const auto& t : triangles)
  {
    const Vec3 a = sub(points[static_cast<std::size_t>(t[0])], p);
    const Vec3 b = sub(points[static_cast<std::size_t>(t[1])], p);
    const Vec3 c = sub(points[static_cast<std::size_t>(t[2])], p);
    const double la = norm(a), lb = norm(b), lc = norm(c);
    const double numerator = frep::dot(a, frep::cross(b, c));
    const double denominator =
      la * lb * lc + frep::dot(a, b) * lc + frep::dot(b, c) * la + frep::dot(c, a) * lb;
    sum += 2 * std::atan2(numerator, denominator);
  }
  return sum / (4 * 3.14159265358979323846);
}

StandInEmbedding standInEmbedding(const SkinnedMesh& mesh, const StandIn& standIn)
{
  StandInEmbedding out;
  for (const Vec3& p : standInSurfaceSamples(standIn))
  {
    ++out.samples;
    if (std::abs(windingNumber(mesh.restPoints, mesh.triangles, p)) > 0.5)
      ++out.inside;
  }
  return out;
}

std::vector<BoneClearance> boneClearances(
  const StandIn& posed, const std::vector<Vec3>& posedPoints)
{
  frep::PointEvaluator f = fieldOf(posed);
  double largest = 0;
  for (const StandInSegment& g : posed.segments)
    largest = std::max(largest, g.radius);
  std::vector<BoneClearance> out;
  for (const StandInSegment& g : posed.segments)
  {
    BoneClearance c;
    c.boneToMesh = std::numeric_limits<double>::infinity();
    for (const Vec3& p : posedPoints)
      c.boneToMesh = std::min(c.boneToMesh, distanceToSegment(p, g.a, g.b));
    const Vec3 axis = sub(g.b, g.a);
    const Vec3 e1 = normalTo(axis);
    const Vec3 e2 = frep::scale(frep::cross(axis, e1), 1 / norm(axis));
    const double step = 0.25 * std::max(g.radius, 0.02 * largest);
    const int steps = static_cast<int>(std::ceil(4 * largest / step)) + 1;
    for (double u : { 0.25, 0.5, 0.75 })
      for (int d = 0; d < 8; ++d)
      {
        const double angle = d * 3.14159265358979323846 / 4;
        const Vec3 direction =
          frep::add(frep::scale(e1, std::cos(angle)), frep::scale(e2, std::sin(angle)));
        if (const auto t = reachAlong(f, frep::lerp(g.a, g.b, u), direction, step, steps))
          c.standInToBone = std::max(c.standInToBone, *t);
      }
    out.push_back(c);
  }
  return out;
}

StandIn StandInKeys::at(const StandIn& rest, double t) const
{
  StandIn out = rest;
  if (times.empty())
    return out;
  std::size_t hiKey =
    static_cast<std::size_t>(std::upper_bound(times.begin(), times.end(), t) - times.begin());
  const std::size_t loKey = hiKey == 0 ? 0 : hiKey - 1;
  hiKey = std::min(hiKey, times.size() - 1);
  const double s =
    hiKey == loKey ? 0.0 : std::clamp((t - times[loKey]) / (times[hiKey] - times[loKey]), 0.0, 1.0);
  for (std::size_t i = 0; i < out.segments.size(); ++i)
    out.segments[i].radius = (1 - s) * radii[loKey][i] + s * radii[hiKey][i];
  return out;
}

StandInFitReport refitStandIn(StandIn& rest, const SkinnedMesh& mesh,
  const std::vector<Affine>& jointMatrices, const StandInFitOptions& options)
{
  StandIn posed = poseStandIn(rest, jointMatrices);
  const Posed points = skin(mesh, jointMatrices);
  StandInFitReport report = fitEmbeddedStandIn(posed, points.points, mesh.triangles, options);
  for (std::size_t i = 0; i < rest.segments.size(); ++i)
  {
    StandInSegment& g = rest.segments[i];
    const double scale = 0.5 *
      (scaleOf(jointMatrices[static_cast<std::size_t>(g.parentJoint)]) +
        scaleOf(jointMatrices[static_cast<std::size_t>(g.joint)]));
    g.radius = posed.segments[i].radius / (scale > 0 && std::isfinite(scale) ? scale : 1.0);
  }
  return report;
}

StandInKeys refitAtKeyFrames(const StandIn& rest, const SkinnedMesh& mesh,
  const std::function<std::vector<Affine>(double)>& matricesAt, const std::vector<double>& times,
  const std::vector<double>& candidates, const StandInFitOptions& options)
{
  StandInKeys keys;
  auto add = [&](double t, const StandIn& start)
  {
    StandIn fitted = start;
    refitStandIn(fitted, mesh, matricesAt(t), options);
    const auto at = std::lower_bound(keys.times.begin(), keys.times.end(), t);
    std::vector<double> radii;
    for (const StandInSegment& g : fitted.segments)
      radii.push_back(g.radius);
    keys.radii.insert(keys.radii.begin() + (at - keys.times.begin()), radii);
    keys.times.insert(at, t);
  };
  std::vector<double> user = times;
  std::sort(user.begin(), user.end());
  for (double t : user)
    add(t, rest);
  std::vector<double> automatic = candidates;
  std::sort(automatic.begin(), automatic.end());
  for (double t : automatic)
  {
    if (std::binary_search(keys.times.begin(), keys.times.end(), t))
      continue;
    const std::vector<Affine> matrices = matricesAt(t);
    const StandIn now = keys.at(rest, t);
    const std::vector<BoneClearance> clearances =
      boneClearances(poseStandIn(now, matrices), skin(mesh, matrices).points);
    if (std::any_of(
          clearances.begin(), clearances.end(), [](const BoneClearance& c) { return c.exceeds(); }))
      add(t, now);
  }
  return keys;
}

} // namespace ictk::skin
