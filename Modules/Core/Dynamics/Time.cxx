// SPDX-License-Identifier: BSD-3-Clause
#include "Dynamics/Time.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace ictk::dyn
{

TimeSpan::TimeSpan(std::vector<TimeInterval> intervals, double scale)
  : scale_(scale)
{
  if (!(std::isfinite(scale) && scale > 0.0))
    throw std::invalid_argument("TimeSpan: the time scale must be finite and > 0");
  for (const TimeInterval& i : intervals)
  {
    if (std::isnan(i.start) || std::isnan(i.end))
      throw std::invalid_argument("TimeSpan: NaN interval end");
    if (i.start > i.end)
      throw std::invalid_argument("TimeSpan: interval start after its end");
  }
  std::sort(intervals.begin(), intervals.end(),
    [](const TimeInterval& a, const TimeInterval& b)
    { return a.start < b.start || (a.start == b.start && a.end < b.end); });
  for (const TimeInterval& i : intervals)
  {
    if (!intervals_.empty() && i.start <= intervals_.back().end)
      intervals_.back().end = std::max(intervals_.back().end, i.end);
    else
      intervals_.push_back(i);
  }
}

TimeSpan TimeSpan::infinite(double scale)
{
  return TimeSpan({ { -kInfinity, kInfinity } }, scale);
}

TimeSpan TimeSpan::interval(double start, double end, double scale)
{
  return TimeSpan({ { start, end } }, scale);
}

double TimeSpan::start() const
{
  if (intervals_.empty())
    throw std::logic_error("TimeSpan::start of an empty span");
  return intervals_.front().start;
}

double TimeSpan::end() const
{
  if (intervals_.empty())
    throw std::logic_error("TimeSpan::end of an empty span");
  return intervals_.back().end;
}

double TimeSpan::duration() const
{
  double d = 0.0;
  for (const TimeInterval& i : intervals_)
    d += i.length();
  return d;
}

std::optional<std::size_t> TimeSpan::intervalIndex(double t) const
{
  // The intervals are sorted and disjoint: the candidate is the last one starting at or before t.
  auto it = std::upper_bound(intervals_.begin(), intervals_.end(), t,
    [](double v, const TimeInterval& i) { return v < i.start; });
  if (it == intervals_.begin())
    return std::nullopt;
  --it;
  if (!it->contains(t))
    return std::nullopt;
  return static_cast<std::size_t>(it - intervals_.begin());
}

bool TimeSpan::contains(double t) const
{
  return intervalIndex(t).has_value();
}

std::optional<double> TimeSpan::localTime(double globalT) const
{
  const auto k = intervalIndex(globalT);
  if (!k)
    return std::nullopt;
  const double origin = std::isfinite(intervals_[*k].start) ? intervals_[*k].start : 0.0;
  return (globalT - origin) * scale_;
}

double TimeSpan::globalTime(double localT, std::size_t index) const
{
  const double s = intervals_.at(index).start;
  const double origin = std::isfinite(s) ? s : 0.0;
  return origin + localT / scale_;
}

double TimeSpan::elapsed(double globalT) const
{
  double e = 0.0;
  for (const TimeInterval& i : intervals_)
  {
    if (globalT < i.start)
      break;
    const double origin = std::isfinite(i.start) ? i.start : 0.0;
    e += (std::min(globalT, i.end) - origin);
  }
  return e * scale_;
}

std::optional<double> TimeSpan::lifeTime(double globalT) const
{
  if (!contains(globalT))
    return std::nullopt;
  return elapsed(globalT);
}

std::optional<double> TimeSpan::globalTimeOfLife(double lifeT) const
{
  double before = 0.0; // unscaled time spent in earlier intervals
  const double target = lifeT / scale_;
  for (const TimeInterval& i : intervals_)
  {
    const double origin = std::isfinite(i.start) ? i.start : 0.0;
    const double t = origin + (target - before);
    if (t >= i.start && t <= i.end)
      return t;
    before += i.end - origin;
  }
  return std::nullopt;
}

TimeSpan TimeSpan::clipped(TimeInterval window) const
{
  return intersect(*this, TimeSpan({ window }, 1.0));
}

TimeSpan unite(const TimeSpan& a, const TimeSpan& b)
{
  std::vector<TimeInterval> all = a.intervals();
  all.insert(all.end(), b.intervals().begin(), b.intervals().end());
  return TimeSpan(std::move(all), a.scale());
}

TimeSpan intersect(const TimeSpan& a, const TimeSpan& b)
{
  std::vector<TimeInterval> out;
  std::size_t i = 0, j = 0;
  const auto& x = a.intervals();
  const auto& y = b.intervals();
  while (i < x.size() && j < y.size())
  {
    const double s = std::max(x[i].start, y[j].start);
    const double e = std::min(x[i].end, y[j].end);
    if (s <= e)
      out.push_back({ s, e });
    if (x[i].end < y[j].end)
      ++i;
    else
      ++j;
  }
  return TimeSpan(std::move(out), a.scale());
}

} // namespace ictk::dyn
