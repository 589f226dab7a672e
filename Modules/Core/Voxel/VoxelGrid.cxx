// SPDX-License-Identifier: BSD-3-Clause
#include "Voxel/VoxelGrid.h"

#include "FRep/Sampling.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cfloat>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace ictk::voxel
{

frep::Box3 VoxelGrid::bounds() const
{
  frep::Box3 b;
  for (int a = 0; a < 3; ++a)
  {
    b.lo[a] = origin[a];
    b.hi[a] = origin[a] + static_cast<double>(dimensions[a] - 1) * spacing[a];
  }
  return b;
}

void validate(const VoxelGrid& grid, const std::string& what)
{
  static const char* names[] = { "x", "y", "z" };
  long double count = 1;
  for (int a = 0; a < 3; ++a)
  {
    if (grid.dimensions[a] < 2)
    {
      throw std::invalid_argument(what + ": " + std::to_string(grid.dimensions[a]) +
        " points along " + names[a] + "; a voxel grid needs at least 2 along each axis");
    }
    count *= static_cast<long double>(grid.dimensions[a]);
    const double far =
      grid.origin[a] + static_cast<double>(grid.dimensions[a] - 1) * grid.spacing[a];
    if (!std::isfinite(grid.origin[a]) || !std::isfinite(grid.spacing[a]) ||
      !(grid.spacing[a] > 0) || !std::isfinite(far))
    {
      std::ostringstream os;
      os << what << ": origin " << grid.origin[a] << " and spacing " << grid.spacing[a] << " along "
         << names[a] << " must be finite, with a positive spacing and a finite far corner";
      throw std::invalid_argument(os.str());
    }
  }
  if (count > static_cast<long double>(std::numeric_limits<std::int64_t>::max() / 8))
  {
    throw std::invalid_argument(what + ": the point count overflows");
  }
  if (static_cast<std::int64_t>(grid.values.size()) != grid.pointCount())
  {
    throw std::invalid_argument(what + ": " + std::to_string(grid.values.size()) + " values for " +
      std::to_string(grid.dimensions[0]) + " x " + std::to_string(grid.dimensions[1]) + " x " +
      std::to_string(grid.dimensions[2]) + " = " + std::to_string(grid.pointCount()) + " points");
  }
  std::int64_t first = -1;
  std::int64_t bad = 0;
  for (std::int64_t n = 0; n < grid.pointCount(); ++n)
  {
    if (!std::isfinite(grid.values[static_cast<std::size_t>(n)]))
    {
      if (first < 0)
      {
        first = n;
      }
      ++bad;
    }
  }
  if (bad > 0)
  {
    const std::int64_t i = first % grid.dimensions[0];
    const std::int64_t j = (first / grid.dimensions[0]) % grid.dimensions[1];
    const std::int64_t k = first / (grid.dimensions[0] * grid.dimensions[1]);
    std::ostringstream os;
    os << what << ": value " << grid.values[static_cast<std::size_t>(first)] << " at point (" << i
       << ", " << j << ", " << k << ") (index " << first << ") is not finite";
    if (bad > 1)
    {
      os << " (" << bad << " non-finite values in all)";
    }
    os << "; NaN and infinite values are not allowed";
    throw std::invalid_argument(os.str());
  }
}

VoxelGrid sampleToGrid(
  const frep::Field& field, const frep::Box3& box, std::array<std::int64_t, 3> resolution)
{
  static const char* names[] = { "x", "y", "z" };
  VoxelGrid grid;
  for (int a = 0; a < 3; ++a)
  {
    if (resolution[a] < 2)
    {
      throw std::invalid_argument("sampleToGrid: resolution " + std::to_string(resolution[a]) +
        " along " + names[a] + "; at least 2 points per axis are needed");
    }
    if (!std::isfinite(box.lo[a]) || !std::isfinite(box.hi[a]) || !(box.lo[a] < box.hi[a]))
    {
      std::ostringstream os;
      os << "sampleToGrid: the box [" << box.lo[a] << ", " << box.hi[a] << "] along " << names[a]
         << " must be finite and not empty";
      throw std::invalid_argument(os.str());
    }
  }
  const frep::Grid g = frep::gridOverBox(box.lo, box.hi, resolution);
  frep::checkGrid(g, sizeof(float));
  grid.dimensions = resolution;
  grid.origin = box.lo;
  grid.spacing = g.spacing;
  grid.values.resize(static_cast<std::size_t>(grid.pointCount()));

  const std::int64_t nx = resolution[0];
  const std::int64_t rows = resolution[1] * resolution[2];
  std::atomic<std::int64_t> firstNaN{ std::numeric_limits<std::int64_t>::max() };
  tbb::parallel_for(tbb::blocked_range<std::int64_t>(0, rows, 16),
    [&](const tbb::blocked_range<std::int64_t>& r)
    {
      // An evaluator is not thread safe: one per task.
      auto eval = field.evaluator();
      std::vector<double> x(static_cast<std::size_t>(nx)), y(x.size()), z(x.size()), v(x.size());
      for (std::int64_t i = 0; i < nx; ++i)
      {
        // Exactly VoxelGrid::point(), so the grid's points are where the field was sampled.
        x[static_cast<std::size_t>(i)] = grid.origin[0] + static_cast<double>(i) * grid.spacing[0];
      }
      for (std::int64_t row = r.begin(); row != r.end(); ++row)
      {
        const std::int64_t j = row % resolution[1];
        const std::int64_t k = row / resolution[1];
        const double yj = grid.origin[1] + static_cast<double>(j) * grid.spacing[1];
        const double zk = grid.origin[2] + static_cast<double>(k) * grid.spacing[2];
        std::fill(y.begin(), y.end(), yj);
        std::fill(z.begin(), z.end(), zk);
        eval->values(x.data(), y.data(), z.data(), v.data(), x.size());
        float* out = grid.values.data() + row * nx;
        for (std::int64_t i = 0; i < nx; ++i)
        {
          const double d = v[static_cast<std::size_t>(i)];
          if (std::isnan(d))
          {
            std::int64_t n = row * nx + i;
            std::int64_t cur = firstNaN.load();
            while (n < cur && !firstNaN.compare_exchange_weak(cur, n))
            {
            }
            out[i] = 0;
            continue;
          }
          out[i] = static_cast<float>(std::clamp(d, -double(FLT_MAX), double(FLT_MAX)));
        }
      }
    });
  if (firstNaN.load() != std::numeric_limits<std::int64_t>::max())
  {
    const std::int64_t n = firstNaN.load();
    const std::int64_t i = n % nx;
    const std::int64_t j = (n / nx) % resolution[1];
    const std::int64_t k = n / (nx * resolution[1]);
    const Point3 p = grid.point(i, j, k);
    std::ostringstream os;
    os << "sampleToGrid: the field is NaN at grid point (" << i << ", " << j << ", " << k
       << "), position (" << p[0] << ", " << p[1] << ", " << p[2] << ")";
    throw std::runtime_error(os.str());
  }
  return grid;
}

std::int64_t stamp(VoxelGrid& grid, const frep::Field& region, double value)
{
  if (!std::isfinite(value))
  {
    throw std::invalid_argument("stamp: the stamped value must be finite");
  }
  const std::int64_t nx = grid.dimensions[0];
  auto eval = region.evaluator();
  std::vector<double> x(static_cast<std::size_t>(nx)), y(x.size()), z(x.size()), v(x.size());
  for (std::int64_t i = 0; i < nx; ++i)
  {
    x[static_cast<std::size_t>(i)] = grid.point(i, 0, 0)[0];
  }
  std::int64_t stamped = 0;
  for (std::int64_t k = 0; k < grid.dimensions[2]; ++k)
  {
    for (std::int64_t j = 0; j < grid.dimensions[1]; ++j)
    {
      const Point3 first = grid.point(0, j, k);
      const Point3 last = grid.point(nx - 1, j, k);
      const frep::Interval b = eval->bound(frep::Box3{ first, last });
      if (b.negative() && !b.maybeNaN)
      {
        continue;
      }
      std::fill(y.begin(), y.end(), first[1]);
      std::fill(z.begin(), z.end(), first[2]);
      eval->values(x.data(), y.data(), z.data(), v.data(), x.size());
      float* row = grid.values.data() + grid.index(0, j, k);
      for (std::int64_t i = 0; i < nx; ++i)
      {
        if (v[static_cast<std::size_t>(i)] >= 0)
        {
          row[i] = static_cast<float>(value);
          ++stamped;
        }
      }
    }
  }
  return stamped;
}

} // namespace ictk::voxel
