// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Closed real intervals with outward rounding, for certified inside/outside classification.

#include <array>

namespace ictk::frep
{

/// Every non-NaN value lies in [lo, hi]; `maybeNaN` says some points may give NaN (sqrt of a
/// negative, 0/0...). An empty interval (lo > hi) with maybeNaN means "NaN everywhere".
struct Interval
{
  double lo = 0;
  double hi = 0;
  bool maybeNaN = false;
  bool empty() const { return !(lo <= hi); }
  bool contains(double v) const { return lo <= v && v <= hi; }
  /// Entirely inside (f > 0 everywhere) / outside (f < 0 everywhere).
  bool positive() const { return lo > 0; }
  bool negative() const { return hi < 0; }
};

/// An axis-aligned box of the modelling space (x, y, z, t).
struct Region
{
  std::array<Interval, 4> axes;
};

} // namespace ictk::frep
