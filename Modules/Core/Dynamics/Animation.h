// SPDX-License-Identifier: BSD-3-Clause
// The animation entity (thesis §3.9 L1461-1465 and Appendix A Table 3, L4150-4162):
//   A_i(t) = { U (t_j, v_j), U (t_Ej, v_Ej), T^i, F_in(t), F_out(t) }
// keyframes (t_j, v_j); "additional values" v_Ej per key for interpolation kinds that need them
// (tangents, L1465 and L4155); the time range T^i = [first key, last key] (L4156); the in-range
// interpolation F_in ("Linear, various cubic curves", L4159, or a custom procedure, L1465); the
// out-of-range function F_out ("Constant, Linear, Mirror, Loop,...", L4160, or custom).
//
// Kinds implemented:
//  - Interpolation::Step       v(t) = v_j for t_j <= t < t_j+1 (the "constant" polynomial);
//  - Interpolation::Linear     v_j + (v_j+1 - v_j) s, s = (t - t_j) / (t_j+1 - t_j);
//  - Interpolation::CatmullRom cubic Hermite with tangents m_j = (v_j+1 - v_j-1)/(t_j+1 - t_j-1)
//                              (one-sided differences at the ends);
//  - Interpolation::Hermite    cubic Hermite whose tangents are the keys' additional values
//                              (dv/dt); a key without one falls back to the Catmull-Rom tangent;
//  - Interpolation::Custom     a user procedure F_in(curve, t).
// Cubic Hermite on [t_j, t_j+1], h = t_j+1 - t_j:
//   v = h00(s) v_j + h10(s) h m_j + h01(s) v_j+1 + h11(s) h m_j+1,
//   h00 = 2s^3-3s^2+1, h10 = s^3-2s^2+s, h01 = -2s^3+3s^2, h11 = s^3-s^2.
// Out-of-range modes (before the first key and after the last one, chosen separately):
//  - OutOfRange::Constant  the nearest end value;
//  - OutOfRange::Linear    the end value plus (t - t_end) times the curve's end slope (the last
//                          segment's slope for Linear, the end tangent for the cubic kinds, 0 for
//                          Step);
//  - OutOfRange::Loop      t is wrapped into [t_first, t_last) with period L = t_last - t_first;
//  - OutOfRange::Mirror    ping-pong: period 2L, the second half played backwards;
//  - OutOfRange::Custom    a user procedure F_out(curve, t).
// Values are scalars; a vector parameter is animated by one curve per component.
#pragma once

#include <functional>
#include <optional>
#include <vector>

namespace ictk::dyn
{

enum class Interpolation
{
  Step,
  Linear,
  CatmullRom,
  Hermite,
  Custom
};

enum class OutOfRange
{
  Constant,
  Linear,
  Loop,
  Mirror,
  Custom
};

struct Key
{
  Key() = default;
  Key(double t, double v, std::optional<double> tangentValue = std::nullopt)
    : time(t)
    , value(v)
    , tangent(tangentValue)
  {
  }
  double time = 0.0;
  double value = 0.0;
  /// The additional value of Table 3 (L4155): the tangent dv/dt for Interpolation::Hermite.
  std::optional<double> tangent;
};

class AnimationCurve
{
public:
  using Procedure = std::function<double(const AnimationCurve&, double)>;

  AnimationCurve() = default;
  /// Keys are sorted by time; two keys at the same time, or none, throw std::invalid_argument.
  explicit AnimationCurve(std::vector<Key> keys, Interpolation in = Interpolation::Linear,
    OutOfRange before = OutOfRange::Constant, OutOfRange after = OutOfRange::Constant);

  void setInterpolation(Interpolation k, Procedure custom = {});
  void setOutOfRange(OutOfRange before, OutOfRange after, Procedure custom = {});

  const std::vector<Key>& keys() const { return keys_; }
  Interpolation interpolation() const { return in_; }
  /// Table 3 "Time range" (L4156): [first key, last key].
  double rangeStart() const { return keys_.front().time; }
  double rangeEnd() const { return keys_.back().time; }
  double duration() const { return rangeEnd() - rangeStart(); }

  /// The value at global/local time t (the caller chooses the clock, L4157).
  double evaluate(double t) const;
  /// The in-range value (t clamped into the range): F_in.
  double evaluateInRange(double t) const;
  /// dv/dt of the in-range curve at the first (end = false) or last key (end = true).
  double endSlope(bool end) const;

private:
  double tangentAt(std::size_t j) const;
  double outOfRange(OutOfRange mode, double t, bool after) const;

  std::vector<Key> keys_;
  Interpolation in_ = Interpolation::Linear;
  OutOfRange before_ = OutOfRange::Constant, after_ = OutOfRange::Constant;
  Procedure customIn_, customOut_;
};

} // namespace ictk::dyn
