// SPDX-License-Identifier: BSD-3-Clause
#include "Dynamics/Animation.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace ictk::dyn
{

AnimationCurve::AnimationCurve(
  std::vector<Key> keys, Interpolation in, OutOfRange before, OutOfRange after)
  : keys_(std::move(keys))
  , in_(in)
  , before_(before)
  , after_(after)
{
  if (keys_.empty())
    throw std::invalid_argument("AnimationCurve: no keys");
  std::stable_sort(
    keys_.begin(), keys_.end(), [](const Key& a, const Key& b) { return a.time < b.time; });
  for (std::size_t j = 0; j < keys_.size(); ++j)
  {
    if (!std::isfinite(keys_[j].time))
      throw std::invalid_argument("AnimationCurve: key time is not finite");
    if (j > 0 && keys_[j].time == keys_[j - 1].time)
      throw std::invalid_argument("AnimationCurve: two keys at the same time");
  }
  if (in == Interpolation::Custom)
    throw std::invalid_argument("AnimationCurve: use setInterpolation for a custom procedure");
}

void AnimationCurve::setInterpolation(Interpolation k, Procedure custom)
{
  if (k == Interpolation::Custom && !custom)
    throw std::invalid_argument("AnimationCurve: custom interpolation without a procedure");
  in_ = k;
  customIn_ = std::move(custom);
}

void AnimationCurve::setOutOfRange(OutOfRange before, OutOfRange after, Procedure custom)
{
  if ((before == OutOfRange::Custom || after == OutOfRange::Custom) && !custom)
    throw std::invalid_argument("AnimationCurve: custom out-of-range mode without a procedure");
  before_ = before;
  after_ = after;
  customOut_ = std::move(custom);
}

double AnimationCurve::tangentAt(std::size_t j) const
{
  const std::size_t n = keys_.size();
  if (in_ == Interpolation::Hermite && keys_[j].tangent)
    return *keys_[j].tangent;
  if (n < 2)
    return 0.0;
  const std::size_t a = j == 0 ? 0 : j - 1;
  const std::size_t b = j + 1 == n ? n - 1 : j + 1;
  return (keys_[b].value - keys_[a].value) / (keys_[b].time - keys_[a].time);
}

double AnimationCurve::evaluateInRange(double t) const
{
  if (in_ == Interpolation::Custom)
    return customIn_(*this, t);
  const std::size_t n = keys_.size();
  if (t <= keys_.front().time || n == 1)
    return keys_.front().value;
  if (t >= keys_.back().time)
    return keys_.back().value;
  // Segment j: t_j <= t < t_j+1.
  auto it = std::upper_bound(
    keys_.begin(), keys_.end(), t, [](double v, const Key& k) { return v < k.time; });
  const std::size_t j = static_cast<std::size_t>(it - keys_.begin()) - 1;
  const Key& a = keys_[j];
  const Key& b = keys_[j + 1];
  const double h = b.time - a.time;
  const double s = (t - a.time) / h;
  switch (in_)
  {
    case Interpolation::Step:
      return a.value;
    case Interpolation::Linear:
      return a.value + (b.value - a.value) * s;
    case Interpolation::CatmullRom:
    case Interpolation::Hermite:
    {
      const double s2 = s * s, s3 = s2 * s;
      const double h00 = 2 * s3 - 3 * s2 + 1, h10 = s3 - 2 * s2 + s;
      const double h01 = -2 * s3 + 3 * s2, h11 = s3 - s2;
      return h00 * a.value + h10 * h * tangentAt(j) + h01 * b.value + h11 * h * tangentAt(j + 1);
    }
    case Interpolation::Custom:
      break;
  }
  return a.value;
}

double AnimationCurve::endSlope(bool end) const
{
  const std::size_t n = keys_.size();
  if (n < 2 || in_ == Interpolation::Step)
    return 0.0;
  if (in_ == Interpolation::Linear || in_ == Interpolation::Custom)
  {
    const Key& a = end ? keys_[n - 2] : keys_[0];
    const Key& b = end ? keys_[n - 1] : keys_[1];
    return (b.value - a.value) / (b.time - a.time);
  }
  return tangentAt(end ? n - 1 : 0);
}

double AnimationCurve::outOfRange(OutOfRange mode, double t, bool after) const
{
  const double t0 = rangeStart(), t1 = rangeEnd(), len = t1 - t0;
  switch (mode)
  {
    case OutOfRange::Constant:
      return after ? keys_.back().value : keys_.front().value;
    case OutOfRange::Linear:
      return after ? keys_.back().value + (t - t1) * endSlope(true)
                   : keys_.front().value + (t - t0) * endSlope(false);
    case OutOfRange::Loop:
    {
      if (len <= 0.0)
        return keys_.front().value;
      double u = std::fmod(t - t0, len);
      if (u < 0.0)
        u += len;
      return evaluateInRange(t0 + u);
    }
    case OutOfRange::Mirror:
    {
      if (len <= 0.0)
        return keys_.front().value;
      double u = std::fmod(t - t0, 2.0 * len);
      if (u < 0.0)
        u += 2.0 * len;
      return evaluateInRange(u <= len ? t0 + u : t0 + 2.0 * len - u);
    }
    case OutOfRange::Custom:
      return customOut_(*this, t);
  }
  return keys_.front().value;
}

double AnimationCurve::evaluate(double t) const
{
  if (keys_.empty())
    throw std::logic_error("AnimationCurve::evaluate on an empty curve");
  if (t < rangeStart())
    return outOfRange(before_, t, false);
  if (t > rangeEnd())
    return outOfRange(after_, t, true);
  return evaluateInRange(t);
}

} // namespace ictk::dyn
