// SPDX-License-Identifier: BSD-3-Clause
#include "FRep/Bounds.h"

#include <algorithm>
#include <stdexcept>
#include <vector>

namespace ictk::frep
{

std::optional<Box> boundingBox(const TapePtr& tape, const Box& search, int depth, double time,
  const std::vector<double>& parameters)
{
  if (depth < 0 || depth > 12)
  {
    throw std::invalid_argument("boundingBox: depth must be in [0, 12]");
  }
  IntervalEvaluator interval(tape, parameters);
  struct Cell
  {
    Box box;
    int level;
  };
  std::vector<Cell> stack{ { search, 0 } };
  std::optional<Box> result;
  while (!stack.empty())
  {
    const Cell cell = stack.back();
    stack.pop_back();
    Region region;
    for (int a = 0; a < 3; ++a)
    {
      region.axes[a] = { cell.box.lo[a], cell.box.hi[a] };
    }
    region.axes[3] = { time, time };
    const Interval f = interval.eval(region);
    if (f.hi < 0 && !f.maybeNaN)
    {
      continue; // certainly outside
    }
    // A cell already inside the current result cannot grow it: skip its refinement.
    if (result)
    {
      bool contained = true;
      for (int a = 0; a < 3; ++a)
      {
        contained = contained && result->lo[a] <= cell.box.lo[a] && cell.box.hi[a] <= result->hi[a];
      }
      if (contained)
      {
        continue;
      }
    }
    if (cell.level == depth)
    {
      if (!result)
      {
        result = cell.box;
      }
      for (int a = 0; a < 3; ++a)
      {
        result->lo[a] = std::min(result->lo[a], cell.box.lo[a]);
        result->hi[a] = std::max(result->hi[a], cell.box.hi[a]);
      }
      continue;
    }
    for (int k = 0; k < 8; ++k)
    {
      Cell child{ cell.box, cell.level + 1 };
      for (int a = 0; a < 3; ++a)
      {
        const double mid = 0.5 * (cell.box.lo[a] + cell.box.hi[a]);
        (k >> a & 1 ? child.box.lo[a] : child.box.hi[a]) = mid;
      }
      stack.push_back(child);
    }
  }
  return result;
}

} // namespace ictk::frep
