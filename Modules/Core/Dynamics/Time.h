// SPDX-License-Identifier: BSD-3-Clause
// Time spans and life spans of the dynamic implicit complex (thesis L992-1002, Table 2 L4076-4079).
//
// A time span is T_i = U_j (t_a_j, t_d_j) |_St_i: a union of intervals with a time scale St_i, the
// rate at which time advances inside the span (L994-996). The thesis leaves the end points open or
// closed unspecified ("( , )"); here every interval is closed, [start, end], so an instantaneous
// span [t, t] is representable (the tangency instance of thesis 5.1 lives at one instant).
//
// Three clocks (Table 2 L4078, thesis L1000):
//  - global time t: the model's time;
//  - local time: (t - start of the current interval) * scale, i.e. it restarts in each interval;
//  - life time: the scaled time spent inside the span up to t (the sum over earlier intervals plus
//    the part of the current one), i.e. the age of an entity whose life span this is.
// An interval unbounded below has no start; its local time is measured from t = 0.
#pragma once

#include <cstddef>
#include <limits>
#include <optional>
#include <vector>

namespace ictk::dyn
{

constexpr double kInfinity = std::numeric_limits<double>::infinity();

/// A closed interval of global time, [start, end]; start <= end; either end may be infinite.
struct TimeInterval
{
  double start = 0.0;
  double end = 0.0;
  bool contains(double t) const { return start <= t && t <= end; }
  double length() const { return end - start; }
  bool operator==(const TimeInterval& o) const { return start == o.start && end == o.end; }
};

class TimeSpan
{
public:
  /// The empty span (never active), scale 1.
  TimeSpan() = default;
  /// The union of `intervals` (sorted, overlapping or touching ones merged). Throws
  /// std::invalid_argument for NaN ends, start > end, or a scale that is not finite and > 0.
  explicit TimeSpan(std::vector<TimeInterval> intervals, double scale = 1.0);

  /// (-inf, +inf) with the given scale: a TIMESPAN declared without arguments (ch4 feature 22).
  static TimeSpan infinite(double scale = 1.0);
  static TimeSpan interval(double start, double end, double scale = 1.0);
  static TimeSpan instant(double t) { return interval(t, t); }

  const std::vector<TimeInterval>& intervals() const { return intervals_; }
  double scale() const { return scale_; }
  bool empty() const { return intervals_.empty(); }
  /// First start / last end (throws std::logic_error when empty).
  double start() const;
  double end() const;
  /// Total length of the intervals (global time, unscaled).
  double duration() const;

  bool contains(double t) const;
  /// Index of the interval containing t, if any.
  std::optional<std::size_t> intervalIndex(double t) const;

  /// (t - start of the current interval) * scale, or nothing outside the span (L4078).
  std::optional<double> localTime(double globalT) const;
  /// Inverse of localTime within interval `index`: start + local / scale (not clipped).
  double globalTime(double localT, std::size_t index) const;
  /// Scaled time spent inside the span up to t, defined for every t (0 before the span, the whole
  /// scaled duration after it).
  double elapsed(double globalT) const;
  /// elapsed(t) when t is inside the span, nothing outside (a life time only exists while alive).
  std::optional<double> lifeTime(double globalT) const;
  /// The earliest global time at which elapsed() reaches `lifeT` (nothing if it never does).
  std::optional<double> globalTimeOfLife(double lifeT) const;

  /// The part of the span inside [window.start, window.end]; keeps the scale.
  TimeSpan clipped(TimeInterval window) const;

  bool operator==(const TimeSpan& o) const
  {
    return scale_ == o.scale_ && intervals_ == o.intervals_;
  }

private:
  std::vector<TimeInterval> intervals_;
  double scale_ = 1.0;
};

/// Set union; the result takes the scale of `a` (a scale is a property of one span; combining
/// spans of different scales is the caller's decision).
TimeSpan unite(const TimeSpan& a, const TimeSpan& b);
/// Set intersection (closed intervals, so [0,1] and [1,2] meet in the instant [1,1]); scale of `a`.
TimeSpan intersect(const TimeSpan& a, const TimeSpan& b);

} // namespace ictk::dyn
