// SPDX-License-Identifier: BSD-3-Clause
#include "FRep/Operations.h"

#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

namespace ictk::frep
{

namespace
{
constexpr std::uint8_t bit(Axis a)
{
  return static_cast<std::uint8_t>(1u << static_cast<int>(a));
}

constexpr std::uint8_t xyzBits = bit(Axis::X) | bit(Axis::Y) | bit(Axis::Z);

std::string number(double v)
{
  std::ostringstream os;
  os.precision(17);
  os << v;
  return os.str();
}

[[noreturn]] void invalid(const char* operation, const std::string& what)
{
  throw std::invalid_argument(std::string(operation) + ": " + what);
}

void requireFinite(const char* operation, const char* parameter, double v)
{
  if (!std::isfinite(v))
  {
    invalid(operation, std::string("parameter ") + parameter + " must be finite, got " + number(v));
  }
}

void requireNonZero(const char* operation, const char* parameter, double v)
{
  requireFinite(operation, parameter, v);
  if (v == 0.0)
  {
    invalid(operation, std::string("parameter ") + parameter + " must be non-zero");
  }
}

void requireAlpha(const char* operation, double alpha)
{
  // The alpha-system is defined for -1 < alpha <= 1: at alpha = -1 the 1/(1 + alpha) factor is
  // singular, and beyond 1 the radicand f1^2 + f2^2 - 2 alpha f1 f2 can be negative.
  if (!(alpha > -1.0 && alpha <= 1.0))
  {
    invalid(operation, "parameter alpha must lie in (-1, 1], got " + number(alpha));
  }
}

std::string binaryLabel(const char* op, const Shape& a, const Shape& b)
{
  return std::string(op) + "(" + a.label() + ", " + b.label() + ")";
}

std::string unaryLabel(const char* op, const Shape& a)
{
  return std::string(op) + "(" + a.label() + ")";
}

// The two plane coordinates orthogonal to `axis`, in right-handed cyclic order, so that a positive
// angle turns the first towards the second (X: y->z, Y: z->x, Z: x->y).
std::pair<Axis, Axis> planeOf(const char* operation, Axis axis)
{
  switch (axis)
  {
    case Axis::X:
      return { Axis::Y, Axis::Z };
    case Axis::Y:
      return { Axis::Z, Axis::X };
    case Axis::Z:
      return { Axis::X, Axis::Y };
    default:
      invalid(operation, "parameter axis must be X, Y or Z (the mapping acts on space, not on t)");
  }
}

std::array<Expr, AxisCount> identityMap()
{
  return { Expr::x(), Expr::y(), Expr::z(), Expr::t() };
}

Shape mapped(const Shape& a, const std::array<Expr, AxisCount>& map, const char* op)
{
  return Shape(a.function().substitute(map), a.domain(), unaryLabel(op, a));
}

// --- the scalar forms, on Exprs -----------------------------------------------------------------

// The alpha-system's R-functions for both scalar types, Expr and double, one formula each.
namespace rfunction
{
inline double select(double condition, double ifTrue, double ifFalse)
{
  return condition >= 0 ? ifTrue : ifFalse;
}
inline double square(double a)
{
  return a * a;
}
inline double sqrt(double a)
{
  return std::sqrt(a);
}
// Expr's min and max: the first operand where either is NaN.
inline double min(double a, double b)
{
  return b < a ? b : a;
}
inline double max(double a, double b)
{
  return a < b ? b : a;
}

// sqrt(f1^2 + f2^2 - 2 alpha f1 f2). For |alpha| < 1 the radicand is >= (1 - |alpha|)(f1^2 + f2^2)
// >= 0; the max only guards against rounding when alpha is close to 1.
template <class S>
S root(const S& f1, const S& f2, double alpha)
{
  if (alpha == 0.0)
  {
    return sqrt(square(f1) + square(f2));
  }
  return sqrt(max(square(f1) + square(f2) - 2.0 * alpha * f1 * f2, S(0.0)));
}

// s + r with s = f1 + f2 and r = root(f1, f2, alpha): (1 + alpha) times the R-union. Where s < 0
// the sum cancels, and the nearer operand is lost next to a far one (f1 = -1e8, f2 = 1e-9 gives 0,
// not about 1e-9). There it is the quotient -2 (1 + alpha) f1 f2 / (r - s) instead, the same number
// ((s + r)(r - s) = r^2 - s^2 = -2 (1 + alpha) f1 f2) made of a product and a sum of two terms of
// one sign (r - s >= -s > 0 where it is taken). Where s >= 0 the sum has no cancellation, and
// the quotient, 0/0 at f1 = f2 = 0, is not taken.
// The quotient lies in [s, r] where it is taken, and it is clamped to [s, 2 r]: an identity on its
// values (each bound is at least r away from s + r), but an interval box where s takes both signs
// encloses both branches, and there numerator and denominator can both contain 0 (a box around
// f1 = f2 = 0), which alone would enclose the union in [-inf, inf]. The quotient is the second
// operand of min and max, which return the first where either is NaN (Evaluators.cxx), so that an
// operand flagged as possibly NaN does not bring the unbounded quotient back.
template <class S>
S sumPlusRoot(const S& f1, const S& f2, double alpha)
{
  const S s = f1 + f2;
  const S r = root(f1, f2, alpha);
  const S quotient = -2.0 * (1.0 + alpha) * f1 * f2 / (r - s);
  return select(s, s + r, min(2.0 * r, max(s, quotient)));
}

// s - r, (1 + alpha) times the R-intersection: the mirror image (s - r = -((-s) + r)), the quotient
// 2 (1 + alpha) f1 f2 / (s + r) where s > 0, clamped to [-2 r, s].
template <class S>
S sumMinusRoot(const S& f1, const S& f2, double alpha)
{
  const S s = f1 + f2;
  const S r = root(f1, f2, alpha);
  const S quotient = 2.0 * (1.0 + alpha) * f1 * f2 / (s + r);
  return select(-s, s - r, max(-2.0 * r, min(s, quotient)));
}

template <class S>
S unionOf(const S& f1, const S& f2, double alpha)
{
  if (alpha == 1.0)
  {
    // (f1 + f2 + |f1 - f2|) / 2 = max exactly; build max so that no rounding creeps in.
    return max(f1, f2);
  }
  if (alpha == 0.0)
  {
    // Thesis L620.
    return sumPlusRoot(f1, f2, 0.0);
  }
  // thesis_ch2_3.md 1.7 [EXT].
  return sumPlusRoot(f1, f2, alpha) / (1.0 + alpha);
}

template <class S>
S intersectionOf(const S& f1, const S& f2, double alpha)
{
  if (alpha == 1.0)
  {
    return min(f1, f2);
  }
  if (alpha == 0.0)
  {
    // Thesis L622.
    return sumMinusRoot(f1, f2, 0.0);
  }
  return sumMinusRoot(f1, f2, alpha) / (1.0 + alpha);
}
} // namespace rfunction

// (f1^2 + f2^2)^(m/2) for an integer m >= 0, written with integer powers and one sqrt so that
// every evaluator gets it exactly.
Expr cmFactor(const Expr& f1, const Expr& f2, int m)
{
  const Expr s = square(f1) + square(f2);
  if (m % 2 == 0)
  {
    return pow(s, Expr(static_cast<double>(m / 2)));
  }
  return sqrt(s) * pow(s, Expr(static_cast<double>((m - 1) / 2)));
}

void requireCm(const char* operation, int m)
{
  if (m < 0 || m > 64)
  {
    invalid(operation, "parameter m must lie in [0, 64], got " + std::to_string(m));
  }
}

void requireBlendScales(const char* operation, double a0, double a1, double a2)
{
  requireFinite(operation, "a0", a0);
  requireNonZero(operation, "a1", a1);
  requireNonZero(operation, "a2", a2);
}

// Thesis L645 (a0 / (1 + (f1/a1)^2 + (f2/a2)^2)); the same displacement serves hfBlendInt.
Expr blendDisplacement(const Expr& f1, const Expr& f2, double a0, double a1, double a2)
{
  return a0 / (1.0 + square(f1 / a1) + square(f2 / a2));
}

void requireBoundedBlendScales(const char* operation, double a0, double a1, double a2, double a3)
{
  requireBlendScales(operation, a0, a1, a2);
  requireNonZero(operation, "a3", a3);
}

// Bounded blending, thesis L651-L659, with the amplitude a0 of thesis_ch2_3.md 0.4 (a0 = 1 is the
// thesis formula). L653 tests "r < 1" in one case and "r^2 >= 1" in the other; for r >= 0 these are
// complementary, and r stays in [0, 1], so disp = (1 - r^2)^3 / (1 + r^2) clamped at 0 covers both.
Expr boundedBlendExpr(
  const Expr& f1, const Expr& f2, const Expr& f3, double a0, double a1, double a2, double a3)
{
  const Expr r1sq = square(f1 / a1) + square(f2 / a2);
  // L659: (f3/a3)^2 where f3 > 0, else 0; max(f3, 0) gives exactly that without a branch.
  const Expr r2sq = square(max(f3, Expr(0.0)) / a3);
  // L655: r = r1^2 / (r1^2 + r2^2) where r2 > 0, else 1. select() takes its first branch when the
  // condition is >= 0, and -r2sq >= 0 exactly when r2sq == 0.
  // The quotient is built so that interval arithmetic, which sees both branches and cannot tell
  // that numerator and denominator are correlated, neither flags a possible 0/0 nor loses the
  // bound r <= 1: the smallest normal double added to the denominator keeps it away from 0 (it
  // changes no result: on the taken branch the denominator is >= r2sq > 0 and absorbs it unless
  // below 1e-292), and min(., 1) is an identity on values that states r <= 1.
  const Expr noBound = -r2sq;
  const Expr quotient = min(r1sq / (r1sq + r2sq + std::numeric_limits<double>::min()), Expr(1.0));
  const Expr r = select(noBound, Expr(1.0), quotient);
  const Expr rsq = square(r);
  const Expr oneMinus = max(1.0 - rsq, Expr(0.0));
  const Expr disp = square(oneMinus) * oneMinus / (1.0 + rsq);
  return rUnion(f1, f2, 0.0) + a0 * disp;
}

std::uint8_t axesOfNonDefault(const Vec3& v, double neutral)
{
  std::uint8_t axes = 0;
  for (int i = 0; i < 3; ++i)
  {
    if (v[i] != neutral)
    {
      axes |= static_cast<std::uint8_t>(1u << i);
    }
  }
  return axes;
}

// The domain of a time-free shape with t added (X -> XT, XY -> XYT, XYZ -> XYZT).
Domain withTime(const char* operation, const Shape& s)
{
  if (domainAxes(s.domain()) & bit(Axis::T))
  {
    throw DomainError(std::string(operation) + ": " + s.describe() +
      " already has coordinate t; the operation adds t to a purely geometric shape");
  }
  const auto d = domainFromAxes(static_cast<std::uint8_t>(domainAxes(s.domain()) | bit(Axis::T)));
  if (!d)
  {
    throw DomainError(std::string(operation) + ": " + s.describe() +
      " extended with t is not a modelling domain of Table 1");
  }
  return *d;
}

std::uint8_t axesOfList(const char* operation, const std::vector<Axis>& axes)
{
  std::uint8_t bits = 0;
  for (Axis a : axes)
  {
    if (bits & bit(a))
    {
      throw DomainError(
        std::string(operation) + ": coordinate " + axisName(a) + " is listed twice");
    }
    bits |= bit(a);
  }
  return bits;
}

Expr maxTree(std::vector<Expr> values)
{
  // Pairwise reduction keeps the DAG shallow (depth log2(n) instead of n), which matters for the
  // recursive reference evaluator and tightens nothing else.
  while (values.size() > 1)
  {
    std::vector<Expr> next;
    next.reserve((values.size() + 1) / 2);
    for (std::size_t i = 0; i + 1 < values.size(); i += 2)
    {
      next.push_back(max(values[i], values[i + 1]));
    }
    if (values.size() % 2)
    {
      next.push_back(values.back());
    }
    values = std::move(next);
  }
  return values.front();
}
} // namespace

// --- set-theoretic operations ------------------------------------------------------------------

Expr rUnion(const Expr& f1, const Expr& f2, double alpha)
{
  return rfunction::unionOf(f1, f2, alpha);
}

Expr rIntersection(const Expr& f1, const Expr& f2, double alpha)
{
  return rfunction::intersectionOf(f1, f2, alpha);
}

double rUnion(double f1, double f2, double alpha)
{
  return rfunction::unionOf(f1, f2, alpha);
}

double rIntersection(double f1, double f2, double alpha)
{
  return rfunction::intersectionOf(f1, f2, alpha);
}

Expr hyperFunIntersection(const Expr& f1, const Expr& f2, double alpha)
{
  return rfunction::sumMinusRoot(f1, f2, alpha);
}

Shape unite(const Shape& a, const Shape& b, double alpha)
{
  requireSameDomain("unite", a, b);
  requireAlpha("unite", alpha);
  return Shape(rUnion(a.function(), b.function(), alpha), a.domain(), binaryLabel("union", a, b));
}

Shape intersect(const Shape& a, const Shape& b, double alpha)
{
  requireSameDomain("intersect", a, b);
  requireAlpha("intersect", alpha);
  return Shape(rIntersection(a.function(), b.function(), alpha), a.domain(),
    binaryLabel("intersection", a, b));
}

Shape subtract(const Shape& a, const Shape& b, double alpha)
{
  requireSameDomain("subtract", a, b);
  requireAlpha("subtract", alpha);
  return Shape(rIntersection(a.function(), -b.function(), alpha), a.domain(),
    binaryLabel("subtraction", a, b));
}

Shape uniteCm(const Shape& a, const Shape& b, int m)
{
  // Thesis L633-L635 is garbled (k-th root of f^(1/k)); Pasko & Savchenko 1994 form used
  // (thesis_ch2_3.md 1.7 [EXT]).
  requireSameDomain("uniteCm", a, b);
  requireCm("uniteCm", m);
  const Expr& f1 = a.function();
  const Expr& f2 = b.function();
  return Shape(rUnion(f1, f2, 0.0) * cmFactor(f1, f2, m), a.domain(), binaryLabel("unionCm", a, b));
}

Shape intersectCm(const Shape& a, const Shape& b, int m)
{
  // See uniteCm: thesis L633-L635 garbled; Pasko & Savchenko 1994 form used.
  requireSameDomain("intersectCm", a, b);
  requireCm("intersectCm", m);
  const Expr& f1 = a.function();
  const Expr& f2 = b.function();
  return Shape(rIntersection(f1, f2, 0.0) * cmFactor(f1, f2, m), a.domain(),
    binaryLabel("intersectionCm", a, b));
}

Shape subtractCm(const Shape& a, const Shape& b, int m)
{
  requireSameDomain("subtractCm", a, b);
  requireCm("subtractCm", m);
  const Expr& f1 = a.function();
  const Expr f2 = -b.function();
  return Shape(rIntersection(f1, f2, 0.0) * cmFactor(f1, f2, m), a.domain(),
    binaryLabel("subtractionCm", a, b));
}

Shape uniteMinMax(const Shape& a, const Shape& b)
{
  requireSameDomain("uniteMinMax", a, b);
  return Shape(max(a.function(), b.function()), a.domain(), binaryLabel("unionMinMax", a, b));
}

Shape intersectMinMax(const Shape& a, const Shape& b)
{
  requireSameDomain("intersectMinMax", a, b);
  return Shape(
    min(a.function(), b.function()), a.domain(), binaryLabel("intersectionMinMax", a, b));
}

Shape subtractMinMax(const Shape& a, const Shape& b)
{
  requireSameDomain("subtractMinMax", a, b);
  return Shape(
    min(a.function(), -b.function()), a.domain(), binaryLabel("subtractionMinMax", a, b));
}

Shape negate(const Shape& a)
{
  return Shape(-a.function(), a.domain(), unaryLabel("complement", a));
}

Shape blendUnion(const Shape& a, const Shape& b, double a0, double a1, double a2)
{
  requireSameDomain("blendUnion", a, b);
  requireBlendScales("blendUnion", a0, a1, a2);
  const Expr& f1 = a.function();
  const Expr& f2 = b.function();
  // Thesis L643-L645.
  return Shape(rUnion(f1, f2, 0.0) + blendDisplacement(f1, f2, a0, a1, a2), a.domain(),
    binaryLabel("blendUnion", a, b));
}

Shape blendIntersection(const Shape& a, const Shape& b, double a0, double a1, double a2)
{
  requireSameDomain("blendIntersection", a, b);
  requireBlendScales("blendIntersection", a0, a1, a2);
  const Expr& f1 = a.function();
  const Expr& f2 = b.function();
  // Not in the thesis; HyperFun hfblendint.c adds the L645 displacement to the R-intersection.
  return Shape(rIntersection(f1, f2, 0.0) + blendDisplacement(f1, f2, a0, a1, a2), a.domain(),
    binaryLabel("blendIntersection", a, b));
}

Shape boundedBlend(
  const Shape& a, const Shape& b, const Shape& bound, double a1, double a2, double a3, double a0)
{
  requireSameDomain("boundedBlend", a, b);
  requireSameDomain("boundedBlend", a, bound);
  requireBoundedBlendScales("boundedBlend", a0, a1, a2, a3);
  return Shape(boundedBlendExpr(a.function(), b.function(), bound.function(), a0, a1, a2, a3),
    a.domain(), "boundedBlend(" + a.label() + ", " + b.label() + "; " + bound.label() + ")");
}

Shape offset(const Shape& a, double d)
{
  requireFinite("offset", "d", d);
  return Shape(a.function() + d, a.domain(), unaryLabel("offset", a));
}

// --- space mappings ------------------------------------------------------------------------------

Shape shift(const Shape& a, const Vec3& v)
{
  for (double c : v)
  {
    requireFinite("shift", "v", c);
  }
  // A shift along an axis the shape does not have would be silently lost.
  requireAxes("shift", a, axesOfNonDefault(v, 0.0));
  auto map = identityMap();
  for (int i = 0; i < 3; ++i)
  {
    if (v[i] != 0.0)
    {
      // hfShift3D: x' = x - dx.
      map[i] = Expr::variable(static_cast<Axis>(i)) - v[i];
    }
  }
  return mapped(a, map, "shift");
}

Shape scale(const Shape& a, const Vec3& s)
{
  for (double c : s)
  {
    requireNonZero("scale", "s", c);
  }
  requireAxes("scale", a, axesOfNonDefault(s, 1.0));
  auto map = identityMap();
  for (int i = 0; i < 3; ++i)
  {
    if (s[i] != 1.0)
    {
      // hfScale3D: x' = x / sx.
      map[i] = Expr::variable(static_cast<Axis>(i)) / s[i];
    }
  }
  return mapped(a, map, "scale");
}

Shape rotate(const Shape& a, Axis axis, double angleRadians)
{
  requireFinite("rotate", "angleRadians", angleRadians);
  const auto [p, q] = planeOf("rotate", axis);
  requireAxes("rotate", a, static_cast<std::uint8_t>(bit(p) | bit(q)));
  // hfRotate3DX/Y/Z: the query point is turned back by the angle, p' = p c + q s,
  // q' = -p s + q c, so the object turns by +angle (right-handed about `axis`).
  const double c = std::cos(angleRadians);
  const double s = std::sin(angleRadians);
  const Expr P = Expr::variable(p);
  const Expr Q = Expr::variable(q);
  auto map = identityMap();
  map[static_cast<int>(p)] = P * c + Q * s;
  map[static_cast<int>(q)] = -(P * s) + Q * c;
  return mapped(a, map, "rotate");
}

Shape affine(const Shape& a, const std::array<double, 12>& matrix)
{
  for (double c : matrix)
  {
    requireFinite("affine", "matrix", c);
  }
  auto A = [&](int r, int c)
  {
    return matrix[static_cast<std::size_t>(4 * r + c)];
  };
  // An axis the shape lacks must be left fixed and uncoupled by the map, or the result would need a
  // coordinate the domain does not have.
  const std::uint8_t have = domainAxes(a.domain());
  for (int k = 0; k < 3; ++k)
  {
    if (have & (1u << k))
    {
      continue;
    }
    bool fixed = A(k, 3) == 0.0;
    for (int j = 0; j < 3; ++j)
    {
      fixed = fixed && A(k, j) == (j == k ? 1.0 : 0.0) && (j == k || A(j, k) == 0.0);
    }
    if (!fixed)
    {
      throw DomainError(std::string("affine: ") + a.describe() + " has no coordinate " +
        axisName(static_cast<Axis>(k)) + " but the matrix moves or couples it");
    }
  }
  // Inverse of the 3x3 part by cofactors.
  std::array<std::array<double, 3>, 3> inv{};
  for (int r = 0; r < 3; ++r)
  {
    for (int c = 0; c < 3; ++c)
    {
      // Cofactor C(c, r) (transposed) gives the adjugate entry (r, c).
      const int r1 = (c + 1) % 3, r2 = (c + 2) % 3;
      const int c1 = (r + 1) % 3, c2 = (r + 2) % 3;
      inv[r][c] = A(r1, c1) * A(r2, c2) - A(r1, c2) * A(r2, c1);
    }
  }
  const double det = A(0, 0) * inv[0][0] + A(0, 1) * inv[1][0] + A(0, 2) * inv[2][0];
  double largest = 0.0;
  for (int r = 0; r < 3; ++r)
  {
    for (int c = 0; c < 3; ++c)
    {
      largest = std::max(largest, std::fabs(A(r, c)));
    }
  }
  // Relative test: det scales with the cube of the entries.
  if (!(std::fabs(det) > 1e-12 * largest * largest * largest))
  {
    invalid("affine", "parameter matrix has a singular 3x3 part (det = " + number(det) + ")");
  }
  for (auto& row : inv)
  {
    for (double& v : row)
    {
      v /= det;
    }
  }
  // p = A^-1 (p' - b) = A^-1 p' + c with c = -A^-1 b.
  auto map = identityMap();
  for (int r = 0; r < 3; ++r)
  {
    if (!(have & (1u << r)))
    {
      continue;
    }
    double c = 0.0;
    for (int j = 0; j < 3; ++j)
    {
      c -= inv[r][j] * A(j, 3);
    }
    Expr e(c);
    for (int j = 0; j < 3; ++j)
    {
      if (inv[r][j] != 0.0)
      {
        e = e + inv[r][j] * Expr::variable(static_cast<Axis>(j));
      }
    }
    map[r] = e;
  }
  return mapped(a, map, "affine");
}

Shape twist(const Shape& a, Axis axis, double z1, double z2, double theta1, double theta2)
{
  requireFinite("twist", "z1", z1);
  requireFinite("twist", "z2", z2);
  requireFinite("twist", "theta1", theta1);
  requireFinite("twist", "theta2", theta2);
  if (z1 == z2)
  {
    invalid("twist", "parameters z1 and z2 must differ (both " + number(z1) + ")");
  }
  const auto [p, q] = planeOf("twist", axis);
  requireAxes("twist", a, xyzBits);
  // hftwistx/y/z.c: t = (u - z1)/(z2 - z1) (not clamped), theta = (1 - t) theta1 + t theta2, and
  // the plane is turned back by theta as in rotate().
  const Expr t = (Expr::variable(axis) - z1) / (z2 - z1);
  const Expr theta = (1.0 - t) * theta1 + t * theta2;
  const Expr c = cos(theta);
  const Expr s = sin(theta);
  const Expr P = Expr::variable(p);
  const Expr Q = Expr::variable(q);
  auto map = identityMap();
  map[static_cast<int>(p)] = P * c + Q * s;
  map[static_cast<int>(q)] = -(P * s) + Q * c;
  return mapped(a, map, "twist");
}

Shape taper(const Shape& a, Axis axis, double z1, double z2, double s1, double s2)
{
  requireFinite("taper", "z1", z1);
  requireFinite("taper", "z2", z2);
  requireFinite("taper", "s1", s1);
  requireFinite("taper", "s2", s2);
  if (!(z1 < z2))
  {
    invalid(
      "taper", "parameters must satisfy z1 < z2, got z1 = " + number(z1) + ", z2 = " + number(z2));
  }
  // HyperFun's R_hfTaper* rejects non-positive factors; a zero scale has no inverse.
  if (!(s1 > 0.0))
  {
    invalid("taper", "parameter s1 must be > 0, got " + number(s1));
  }
  if (!(s2 > 0.0))
  {
    invalid("taper", "parameter s2 must be > 0, got " + number(s2));
  }
  const auto [p, q] = planeOf("taper", axis);
  requireAxes("taper", a, xyzBits);
  // hftaperx/y/z.c: scale = s1 below z1, s2 above z2, linear in between. Clamping t to [0, 1]
  // gives the same three cases, continuously, without branches: (1 - 0) s1 + 0 s2 = s1 exactly.
  const Expr t = min(max((Expr::variable(axis) - z1) / (z2 - z1), Expr(0.0)), Expr(1.0));
  const Expr factor = (1.0 - t) * s1 + t * s2;
  auto map = identityMap();
  map[static_cast<int>(p)] = Expr::variable(p) / factor;
  map[static_cast<int>(q)] = Expr::variable(q) / factor;
  return mapped(a, map, "taper");
}

Shape bend(const Shape& a, Axis axis, double curvature)
{
  requireFinite("bend", "curvature", curvature);
  const auto [p, q] = planeOf("bend", axis);
  requireAxes("bend", a, static_cast<std::uint8_t>(bit(p) | bit(q)));
  if (curvature == 0.0)
  {
    return a.withLabel(unaryLabel("bend", a));
  }
  // Barr 1984, bend of the whole space (no bounded region, centre 0). Forward map of the length
  // coordinate u and the bending-direction coordinate v with R = 1/k:
  //   theta = k u,  U = -sin(theta) (v - R),  V = cos(theta) (v - R) + R.
  // Inverting with sg = sign(R): R - v = sg * |(U, R - V)|, theta = atan2(sg U, sg (R - V)), hence
  //   u = theta / k,  v = R - sg sqrt(U^2 + (R - V)^2).
  // atan2 covers (-pi, pi], so the bent object wraps at most once around the circle.
  const double R = 1.0 / curvature;
  const double sg = curvature > 0.0 ? 1.0 : -1.0;
  const Expr U = Expr::variable(p);
  const Expr V = Expr::variable(q);
  const Expr towardCentre = R - V;
  auto map = identityMap();
  map[static_cast<int>(p)] = atan2(sg * U, sg * towardCentre) * R;
  map[static_cast<int>(q)] = R - sg * sqrt(square(U) + square(towardCentre));
  return mapped(a, map, "bend");
}

Shape stretch(const Shape& a, const Vec3& center, const Vec3& factors)
{
  for (double c : center)
  {
    requireFinite("stretch", "center", c);
  }
  for (double f : factors)
  {
    requireNonZero("stretch", "factors", f);
  }
  requireAxes("stretch", a, axesOfNonDefault(factors, 1.0));
  auto map = identityMap();
  for (int i = 0; i < 3; ++i)
  {
    if (factors[i] != 1.0)
    {
      // hfstretch3d.c: x' = x0 + (x - x0) / s.
      map[i] = center[i] + (Expr::variable(static_cast<Axis>(i)) - center[i]) / factors[i];
    }
  }
  return mapped(a, map, "stretch");
}

namespace
{
enum class Falloff
{
  Cubic,
  Exp
};

// hfSpaceMapCubic.c / hfSpaceMapExp.c: HyperFun walks the control points in order and moves its
// coordinate array in place, so step i sees the point produced by step i - 1. Here the point is a
// triple of Exprs and each step rewrites it, which composes the steps in the same order.
Shape controlPointMap(const char* op, Falloff falloff, const Shape& a,
  const std::vector<Vec3>& source, const std::vector<Vec3>& target,
  const std::vector<Vec3>& influence)
{
  if (target.size() != source.size())
  {
    invalid(op,
      "parameters source and target must have the same length, got " +
        std::to_string(source.size()) + " and " + std::to_string(target.size()));
  }
  if (influence.size() != source.size())
  {
    invalid(op,
      "parameters source and influence must have the same length, got " +
        std::to_string(source.size()) + " and " + std::to_string(influence.size()));
  }
  for (std::size_t i = 0; i < source.size(); ++i)
  {
    for (int k = 0; k < 3; ++k)
    {
      requireFinite(op, "source", source[i][k]);
      requireFinite(op, "target", target[i][k]);
      requireNonZero(op, "influence", influence[i][k]);
    }
  }
  requireAxes(op, a, xyzBits);
  std::array<Expr, 3> p = { Expr::x(), Expr::y(), Expr::z() };
  for (std::size_t i = 0; i < source.size(); ++i)
  {
    Vec3 d;
    for (int k = 0; k < 3; ++k)
    {
      d[k] = target[i][k] - source[i][k];
    }
    if (d[0] == 0.0 && d[1] == 0.0 && d[2] == 0.0)
    {
      continue; // w is finite, so p - w * 0 = p: the step is the identity.
    }
    Expr r2;
    for (int k = 0; k < 3; ++k)
    {
      // The ellipsoid of influence grows with the displacement along each axis.
      const double radius = influence[i][k] * (1.0 + std::fabs(d[k]));
      const Expr u = (p[k] - target[i][k]) / radius;
      r2 = k == 0 ? square(u) : r2 + square(u);
    }
    Expr w;
    if (falloff == Falloff::Cubic)
    {
      // (1 - r)^3 / (1 + r) for r <= 1; clamping r at 1 makes it exactly 0 beyond, continuously.
      const Expr r = min(sqrt(r2), Expr(1.0));
      const Expr oneMinus = 1.0 - r;
      w = square(oneMinus) * oneMinus / (1.0 + r);
    }
    else
    {
      w = exp(-r2);
    }
    std::array<Expr, 3> next = p;
    for (int k = 0; k < 3; ++k)
    {
      if (d[k] != 0.0)
      {
        next[k] = p[k] - w * d[k];
      }
    }
    p = next;
  }
  auto map = identityMap();
  for (int k = 0; k < 3; ++k)
  {
    map[k] = p[k];
  }
  return mapped(a, map, op);
}
} // namespace

Shape spaceMapCubic(const Shape& a, const std::vector<Vec3>& source,
  const std::vector<Vec3>& target, const std::vector<Vec3>& influence)
{
  return controlPointMap("spaceMapCubic", Falloff::Cubic, a, source, target, influence);
}

Shape spaceMapExp(const Shape& a, const std::vector<Vec3>& source, const std::vector<Vec3>& target,
  const std::vector<Vec3>& influence)
{
  return controlPointMap("spaceMapExp", Falloff::Exp, a, source, target, influence);
}

// --- dimension and time --------------------------------------------------------------------------

Shape cartesianProduct(const Shape& a, const Shape& b)
{
  const std::uint8_t aa = domainAxes(a.domain());
  const std::uint8_t bb = domainAxes(b.domain());
  if (aa & bb)
  {
    throw DomainError("cartesianProduct: " + a.describe() + " and " + b.describe() +
      " share coordinates; a Cartesian product needs disjoint coordinate sets (place them with the "
      "axis-map overload)");
  }
  const auto d = domainFromAxes(static_cast<std::uint8_t>(aa | bb));
  if (!d)
  {
    throw DomainError("cartesianProduct: the coordinates of " + a.describe() + " and " +
      b.describe() + " together are not a modelling domain of Table 1");
  }
  // thesis_ch2_3.md 1.7 [EXT]: f(x, y) = f1(x) R-intersect f2(y); the operands already read
  // disjoint variables, so no substitution is needed.
  return Shape(rIntersection(a.function(), b.function(), 0.0), *d, binaryLabel("product", a, b));
}

Shape cartesianProduct(
  const Shape& a, const std::vector<Axis>& aAxes, const Shape& b, const std::vector<Axis>& bAxes)
{
  const std::uint8_t aa = axesOfList("cartesianProduct", aAxes);
  const std::uint8_t bb = axesOfList("cartesianProduct", bAxes);
  if (aa & bb)
  {
    throw DomainError("cartesianProduct: " + a.describe() + " and " + b.describe() +
      " are placed on overlapping coordinates");
  }
  const auto d = domainFromAxes(static_cast<std::uint8_t>(aa | bb));
  if (!d)
  {
    throw DomainError("cartesianProduct: the placed coordinates of " + a.describe() + " and " +
      b.describe() + " are not a modelling domain of Table 1");
  }
  // L1139: transfer each operand to its axes of the target domain, then R-intersect.
  const Shape pa = reproject(a, *d, aAxes);
  const Shape pb = reproject(b, *d, bAxes);
  return Shape(rIntersection(pa.function(), pb.function(), 0.0), *d, binaryLabel("product", a, b));
}

Shape project(const Shape& a, Axis axis, double lo, double hi, int samples)
{
  requireFinite("project", "lo", lo);
  requireFinite("project", "hi", hi);
  if (!(lo < hi))
  {
    invalid("project",
      "parameters must satisfy lo < hi, got lo = " + number(lo) + ", hi = " + number(hi));
  }
  if (samples < 2 || samples > 4096)
  {
    invalid("project", "parameter samples must lie in [2, 4096], got " + std::to_string(samples));
  }
  requireAxes("project", a, bit(axis));
  const auto d = domainFromAxes(static_cast<std::uint8_t>(domainAxes(a.domain()) & ~bit(axis)));
  if (!d)
  {
    throw DomainError("project: dropping coordinate " + std::string(axisName(axis)) + " from " +
      a.describe() + " leaves no modelling domain of Table 1");
  }
  // thesis_ch2_3.md 1.7 [EXT]: f_proj = max over the axis, replaced by a maximum over samples.
  std::vector<Expr> values;
  values.reserve(static_cast<std::size_t>(samples));
  auto map = identityMap();
  for (int i = 0; i < samples; ++i)
  {
    // lo + (hi - lo) i / (n - 1) hits both ends exactly.
    const double u = i == samples - 1 ? hi : lo + (hi - lo) * i / (samples - 1);
    map[static_cast<int>(axis)] = Expr(u);
    values.push_back(a.function().substitute(map));
  }
  return Shape(maxTree(std::move(values)), *d, unaryLabel("projection", a));
}

Shape metamorphosis(const Shape& a, const Shape& b, double s)
{
  requireSameDomain("metamorphosis", a, b);
  if (!(s >= 0.0 && s <= 1.0))
  {
    invalid("metamorphosis", "parameter s must lie in [0, 1], got " + number(s));
  }
  return Shape(
    (1.0 - s) * a.function() + s * b.function(), a.domain(), binaryLabel("metamorphosis", a, b));
}

Shape metamorphosis(const Shape& a, const Shape& b, double t0, double t1)
{
  requireSameDomain("metamorphosis", a, b);
  requireFinite("metamorphosis", "t0", t0);
  requireFinite("metamorphosis", "t1", t1);
  if (!(t0 < t1))
  {
    invalid("metamorphosis",
      "parameters must satisfy t0 < t1, got t0 = " + number(t0) + ", t1 = " + number(t1));
  }
  const Domain d = withTime("metamorphosis", a);
  const Expr s = min(max((Expr::t() - t0) / (t1 - t0), Expr(0.0)), Expr(1.0));
  return Shape((1.0 - s) * a.function() + s * b.function(), d, binaryLabel("metamorphosis", a, b));
}

void validateSpaceTimeBlend(const char* operation, const SpaceTimeBlendParameters& p)
{
  requireFinite(operation, "t0", p.t0);
  requireFinite(operation, "t1", p.t1);
  if (!(p.t0 < p.t1))
  {
    invalid(operation,
      "parameters must satisfy t0 < t1, got t0 = " + number(p.t0) + ", t1 = " + number(p.t1));
  }
  if (!(p.overlap > 0.0 && p.overlap <= 0.5))
  {
    invalid(operation, "parameter overlap must lie in (0, 0.5], got " + number(p.overlap));
  }
  requireBoundedBlendScales(operation, p.a0, p.a1, p.a2, p.a3);
}

Expr spaceTimeBlendExpr(
  const Expr& f1, const Expr& f2, const Expr& t, const SpaceTimeBlendParameters& p)
{
  validateSpaceTimeBlend("spaceTimeBlend", p);
  // Half-cylinders and bounding slab after thesis_ch5_6.md [EXT] "Space-time blending construction"
  // (F1 = f1 & (t0 - t), F2 = f2 & (t - t1), F3 = (t - t0) & (t1 - t)), with one change: the cuts
  // are moved into the slab by overlap (t1 - t0). With the cuts exactly on the slab faces, r -> 1
  // at the faces kills the displacement there, so just after t0 the slice would be empty (F1 < 0,
  // no material yet) and the morph would jump. With the cuts inside, F3 <= 0 for t <= t0 gives F =
  // R-union(F1, F2) with F2 < 0 and tA - t > 0, whose sign is exactly sign(f1) (and likewise
  // sign(f2) for t >= t1).
  const double tA = p.t0 + p.overlap * (p.t1 - p.t0);
  const double tB = p.t1 - p.overlap * (p.t1 - p.t0);
  const Expr F1 = rIntersection(f1, tA - t, 0.0);
  const Expr F2 = rIntersection(f2, t - tB, 0.0);
  const Expr F3 = rIntersection(t - p.t0, p.t1 - t, 0.0);
  return boundedBlendExpr(F1, F2, F3, p.a0, p.a1, p.a2, p.a3);
}

Shape spaceTimeBlend(const Shape& a, const Shape& b, const SpaceTimeBlendParameters& p)
{
  requireSameDomain("spaceTimeBlend", a, b);
  validateSpaceTimeBlend("spaceTimeBlend", p);
  const Domain d = withTime("spaceTimeBlend", a);
  return Shape(spaceTimeBlendExpr(a.function(), b.function(), Expr::t(), p), d,
    binaryLabel("spaceTimeBlend", a, b));
}

Shape spaceTimeBlend(const Shape& a, const Shape& b, double t0, double t1, double a0, double a1,
  double a2, double a3, double overlap)
{
  return spaceTimeBlend(a, b, SpaceTimeBlendParameters{ t0, t1, a0, a1, a2, a3, overlap });
}

} // namespace ictk::frep
