// SPDX-License-Identifier: BSD-3-Clause
#include "FRep/Progress.h"

#include <algorithm>
#include <utility>

namespace ictk
{

ProgressScope::ProgressScope(Progress progress)
  : progress_(std::move(progress))
  , caller_(std::this_thread::get_id())
{
}

bool ProgressScope::ask(double fraction)
{
  if (cancelled())
  {
    return false;
  }
  if (std::this_thread::get_id() != caller_)
  {
    return true;
  }
  if (!progress_(fraction))
  {
    cancelled_ = true;
    return false;
  }
  return true;
}

Progress ProgressScope::range(double lo, double hi)
{
  if (!progress_)
  {
    return {};
  }
  return [this, lo, hi](double fraction)
  {
    return ask(lo + (hi - lo) * fraction);
  };
}

ProgressScope::Items ProgressScope::items(std::int64_t count, double lo, double hi)
{
  return Items(*this, count, lo, hi);
}

ProgressScope::Items::Items(ProgressScope& scope, std::int64_t count, double lo, double hi)
  : scope_(scope)
  , total_(std::max<std::int64_t>(1, count))
  , every_(std::max<std::int64_t>(1, count / 100))
  , lo_(lo)
  , hi_(hi)
{
}

void ProgressScope::Items::count()
{
  const std::int64_t n = done_.fetch_add(1, std::memory_order_relaxed) + 1;
  if (std::this_thread::get_id() != scope_.caller_ || n - reported_ < every_)
  {
    return;
  }
  reported_ = n;
  scope_.ask(lo_ + (hi_ - lo_) * (static_cast<double>(n) / static_cast<double>(total_)));
}

} // namespace ictk
