// SPDX-License-Identifier: BSD-3-Clause
#include "Voxel/VoxelField.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace ictk::voxel
{
namespace
{

constexpr std::int64_t kBlock = 8; // cells per block edge at each pyramid level

struct MinMax
{
  float lo = std::numeric_limits<float>::infinity();
  float hi = -std::numeric_limits<float>::infinity();
  void add(float v)
  {
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  void add(const MinMax& o)
  {
    lo = std::min(lo, o.lo);
    hi = std::max(hi, o.hi);
  }
};

/// Min/max of the vertex values of blocks of cells: level m has blocks of 8^(m+1) cells per axis
/// (fewer at the far end); the last level is a single block.
class Pyramid
{
public:
  explicit Pyramid(const VoxelGrid& grid)
    : grid_(grid)
  {
    for (int a = 0; a < 3; ++a)
    {
      cells_[a] = grid.dimensions[a] - 1;
    }
    std::int64_t size = kBlock;
    while (true)
    {
      Level level;
      level.size = size;
      for (int a = 0; a < 3; ++a)
      {
        level.dims[a] = (cells_[a] + size - 1) / size;
      }
      level.data.resize(static_cast<std::size_t>(level.dims[0] * level.dims[1] * level.dims[2]));
      if (levels_.empty())
      {
        buildFromValues(level);
      }
      else
      {
        buildFromLevel(levels_.back(), level);
      }
      levels_.push_back(std::move(level));
      const Level& top = levels_.back();
      if (top.dims[0] == 1 && top.dims[1] == 1 && top.dims[2] == 1)
      {
        break;
      }
      size *= kBlock;
    }
  }

  /// A block of level 0 that a query covers only in part: cells lo..hi of block b.
  struct Partial
  {
    std::array<std::int64_t, 3> b, lo, hi;
  };

  /// Boxes of cells with at most this many vertices get the exact min/max; larger ones take the
  /// 8^3 blocks they cover only in part whole (an enclosure, looser by the values within 8 cells
  /// of the box), so that a query costs about the number of blocks touched.
  static constexpr std::int64_t kExactVertices = 64 * 64 * 64;

  /// Min/max of the vertex values of cells c0[a]..c1[a] (inclusive, valid cell indices): exact
  /// up to kExactVertices vertices, an enclosure above. `partials` is scratch space.
  MinMax query(const std::array<std::int64_t, 3>& c0, const std::array<std::int64_t, 3>& c1,
    std::vector<Partial>& partials) const
  {
    MinMax r;
    const std::int64_t vertices = (c1[0] - c0[0] + 2) * (c1[1] - c0[1] + 2) * (c1[2] - c0[2] + 2);
    if (vertices <= kBlock * kBlock * kBlock)
    {
      scan(c0, c1, r);
      return r;
    }
    partials.clear();
    visit(levels_.size() - 1, { 0, 0, 0 }, c0, c1, vertices <= kExactVertices, r, partials);
    // The covered blocks are in r; a partly covered block needs scanning only when its whole
    // range is not already inside r (rarely, for smooth data).
    for (const Partial& p : partials)
    {
      const MinMax& m = levels_[0].at(p.b);
      if (m.lo < r.lo || m.hi > r.hi)
      {
        scan(p.lo, p.hi, r);
      }
    }
    return r;
  }

private:
  struct Level
  {
    std::int64_t size = 0; // cells per block edge
    std::array<std::int64_t, 3> dims{ 0, 0, 0 };
    std::vector<MinMax> data;
    const MinMax& at(const std::array<std::int64_t, 3>& b) const
    {
      return data[static_cast<std::size_t>(b[0] + dims[0] * (b[1] + dims[1] * b[2]))];
    }
  };

  void scan(
    const std::array<std::int64_t, 3>& c0, const std::array<std::int64_t, 3>& c1, MinMax& r) const
  {
    const std::int64_t nx = grid_.dimensions[0];
    const std::int64_t nxy = nx * grid_.dimensions[1];
    const float* v = grid_.values.data();
    for (std::int64_t k = c0[2]; k <= c1[2] + 1; ++k)
    {
      for (std::int64_t j = c0[1]; j <= c1[1] + 1; ++j)
      {
        const float* row = v + k * nxy + j * nx;
        float lo = r.lo;
        float hi = r.hi;
        for (std::int64_t i = c0[0]; i <= c1[0] + 1; ++i)
        {
          lo = std::min(lo, row[i]);
          hi = std::max(hi, row[i]);
        }
        r.lo = lo;
        r.hi = hi;
      }
    }
  }

  void buildFromValues(Level& level) const
  {
    tbb::parallel_for(tbb::blocked_range<std::int64_t>(0, level.dims[1] * level.dims[2]),
      [&](const tbb::blocked_range<std::int64_t>& range)
      {
        for (std::int64_t jk = range.begin(); jk != range.end(); ++jk)
        {
          const std::int64_t bj = jk % level.dims[1];
          const std::int64_t bk = jk / level.dims[1];
          for (std::int64_t bi = 0; bi < level.dims[0]; ++bi)
          {
            std::array<std::int64_t, 3> c0{ bi * kBlock, bj * kBlock, bk * kBlock };
            std::array<std::int64_t, 3> c1;
            for (int a = 0; a < 3; ++a)
            {
              c1[a] = std::min(c0[a] + kBlock, cells_[a]) - 1;
            }
            MinMax m;
            scan(c0, c1, m);
            level.data[static_cast<std::size_t>(bi + level.dims[0] * jk)] = m;
          }
        }
      });
  }

  static void buildFromLevel(const Level& fine, Level& coarse)
  {
    tbb::parallel_for(tbb::blocked_range<std::int64_t>(0, coarse.dims[1] * coarse.dims[2]),
      [&](const tbb::blocked_range<std::int64_t>& range)
      {
        for (std::int64_t jk = range.begin(); jk != range.end(); ++jk)
        {
          const std::int64_t bj = jk % coarse.dims[1];
          const std::int64_t bk = jk / coarse.dims[1];
          for (std::int64_t bi = 0; bi < coarse.dims[0]; ++bi)
          {
            const std::array<std::int64_t, 3> b{ bi, bj, bk };
            MinMax m;
            for (std::int64_t k = b[2] * kBlock; k < std::min((b[2] + 1) * kBlock, fine.dims[2]);
                 ++k)
            {
              for (std::int64_t j = b[1] * kBlock; j < std::min((b[1] + 1) * kBlock, fine.dims[1]);
                   ++j)
              {
                for (std::int64_t i = b[0] * kBlock;
                     i < std::min((b[0] + 1) * kBlock, fine.dims[0]); ++i)
                {
                  m.add(fine.at({ i, j, k }));
                }
              }
            }
            coarse.data[static_cast<std::size_t>(bi + coarse.dims[0] * jk)] = m;
          }
        }
      });
  }

  void visit(std::size_t li, const std::array<std::int64_t, 3>& b,
    const std::array<std::int64_t, 3>& c0, const std::array<std::int64_t, 3>& c1, bool exact,
    MinMax& r, std::vector<Partial>& partials) const
  {
    const Level& level = levels_[li];
    std::array<std::int64_t, 3> lo;
    std::array<std::int64_t, 3> hi;
    bool inside = true;
    for (int a = 0; a < 3; ++a)
    {
      const std::int64_t first = b[a] * level.size;
      const std::int64_t last = std::min(first + level.size, cells_[a]) - 1;
      lo[a] = std::max(first, c0[a]);
      hi[a] = std::min(last, c1[a]);
      inside = inside && lo[a] == first && hi[a] == last;
    }
    if (inside)
    {
      r.add(level.at(b));
      return;
    }
    if (li == 0)
    {
      if (exact)
      {
        partials.push_back({ b, lo, hi });
      }
      else
      {
        r.add(level.at(b));
      }
      return;
    }
    const std::int64_t child = levels_[li - 1].size;
    for (std::int64_t k = lo[2] / child; k <= hi[2] / child; ++k)
    {
      for (std::int64_t j = lo[1] / child; j <= hi[1] / child; ++j)
      {
        for (std::int64_t i = lo[0] / child; i <= hi[0] / child; ++i)
        {
          visit(li - 1, { i, j, k }, lo, hi, exact, r, partials);
        }
      }
    }
  }

  const VoxelGrid& grid_;
  std::array<std::int64_t, 3> cells_{ 0, 0, 0 };
  std::vector<Level> levels_;
};

/// Largest |difference| between neighbouring values along each axis, divided by the spacing.
double lipschitzOf(const VoxelGrid& g)
{
  const std::int64_t nx = g.dimensions[0];
  const std::int64_t ny = g.dimensions[1];
  const std::int64_t nz = g.dimensions[2];
  using D3 = std::array<double, 3>;
  const D3 d = tbb::parallel_reduce(
    tbb::blocked_range<std::int64_t>(0, nz), D3{ 0, 0, 0 },
    [&](const tbb::blocked_range<std::int64_t>& r, D3 m)
    {
      const float* v = g.values.data();
      for (std::int64_t k = r.begin(); k != r.end(); ++k)
      {
        for (std::int64_t j = 0; j < ny; ++j)
        {
          const float* row = v + nx * (j + ny * k);
          const float* rowY = j + 1 < ny ? row + nx : nullptr;
          const float* rowZ = k + 1 < nz ? row + nx * ny : nullptr;
          double mx = 0, my = 0, mz = 0;
          for (std::int64_t i = 0; i + 1 < nx; ++i)
          {
            mx = std::max(mx, std::abs(double(row[i + 1]) - double(row[i])));
          }
          if (rowY)
          {
            for (std::int64_t i = 0; i < nx; ++i)
            {
              my = std::max(my, std::abs(double(rowY[i]) - double(row[i])));
            }
          }
          if (rowZ)
          {
            for (std::int64_t i = 0; i < nx; ++i)
            {
              mz = std::max(mz, std::abs(double(rowZ[i]) - double(row[i])));
            }
          }
          m = { std::max(m[0], mx), std::max(m[1], my), std::max(m[2], mz) };
        }
      }
      return m;
    },
    [](const D3& a, const D3& b) {
      return D3{ std::max(a[0], b[0]), std::max(a[1], b[1]), std::max(a[2], b[2]) };
    });
  const double lx = d[0] / g.spacing[0];
  const double ly = d[1] / g.spacing[1];
  const double lz = d[2] / g.spacing[2];
  return std::sqrt(lx * lx + ly * ly + lz * lz);
}

double boxScale(const VoxelGrid& grid, double iso, double lipschitz)
{
  if (lipschitz > 0)
  {
    return lipschitz;
  }
  // A constant grid: any positive scale keeps f continuous and negative outside.
  const double minSpacing = std::min({ grid.spacing[0], grid.spacing[1], grid.spacing[2] });
  return std::max(std::abs(double(grid.values[0]) - iso), 1.0) / minSpacing;
}

/// Everything an evaluator reads; immutable once built.
struct VoxelData
{
  std::shared_ptr<const VoxelGrid> grid;
  double iso = 0;
  bool above = true;
  double scale = 1; // L
  std::array<double, 3> lo{};
  std::array<double, 3> hi{};
  std::array<double, 3> mid{};
  std::array<double, 3> umax{}; // n - 1 per axis
  std::unique_ptr<Pyramid> pyramid;

  double F(double v) const { return above ? v - iso : iso - v; }

  /// Index coordinate of x along axis a, clamped to [0, n - 1].
  double u(int a, double x) const
  {
    const double t = (x - grid->origin[a]) / grid->spacing[a];
    return std::min(std::max(t, 0.0), umax[a]);
  }
  std::int64_t cell(int a, double u) const
  {
    return std::min(static_cast<std::int64_t>(std::floor(u)), grid->dimensions[a] - 2);
  }
  /// min(x - lo, hi - x): the depth along axis a (negative outside the slab).
  double h(int a, double x) const { return std::min(x - lo[a], hi[a] - x); }
  /// The signed distance to the box from the per-axis depths (nondecreasing in each).
  static double G(double hx, double hy, double hz)
  {
    if (hx >= 0 && hy >= 0 && hz >= 0)
    {
      return std::min({ hx, hy, hz });
    }
    const double ex = std::min(hx, 0.0);
    const double ey = std::min(hy, 0.0);
    const double ez = std::min(hz, 0.0);
    return -std::sqrt(ex * ex + ey * ey + ez * ez);
  }
};

class VoxelFieldEvaluator final : public frep::FieldEvaluator
{
public:
  explicit VoxelFieldEvaluator(std::shared_ptr<const VoxelData> data)
    : d_(std::move(data))
  {
  }

  void values(
    const double* x, const double* y, const double* z, double* out, std::size_t n) override
  {
    for (std::size_t q = 0; q < n; ++q)
    {
      out[q] = valueAt(x[q], y[q], z[q], nullptr);
    }
  }

  frep::Interval bound(const frep::Box3& box) override
  {
    const double inf = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a)
    {
      if (!(box.lo[a] <= box.hi[a]))
      {
        return frep::Interval{ -inf, inf, true };
      }
    }
    const VoxelData& d = *d_;
    std::array<std::int64_t, 3> c0;
    std::array<std::int64_t, 3> c1;
    std::array<double, 3> hl;
    std::array<double, 3> hu;
    for (int a = 0; a < 3; ++a)
    {
      c0[a] = d.cell(a, d.u(a, box.lo[a]));
      c1[a] = d.cell(a, d.u(a, box.hi[a]));
      // valueAt computes h = min(x - lo, hi - x) with monotone rounding in x, so over
      // [box.lo, box.hi] it is at least min(box.lo - lo, hi - box.hi) and at most the value of
      // the rising (falling) branch at the highest (lowest) point on its side of `mid`.
      hl[a] = std::min(box.lo[a] - d.lo[a], d.hi[a] - box.hi[a]);
      double up = std::min(box.hi[a] - d.lo[a], d.hi[a] - box.lo[a]);
      if (box.lo[a] <= d.mid[a] && d.mid[a] <= box.hi[a])
      {
        up = std::min(up, std::max(d.mid[a] - d.lo[a], d.hi[a] - d.mid[a]));
      }
      hu[a] = up;
    }
    const MinMax m = d.pyramid->query(c0, c1, partials_);
    const double flo = d.above ? d.F(m.lo) : d.F(m.hi);
    const double fhi = d.above ? d.F(m.hi) : d.F(m.lo);
    const double glo = d.scale * VoxelData::G(hl[0], hl[1], hl[2]);
    const double ghi = d.scale * VoxelData::G(hu[0], hu[1], hu[2]);
    return frep::Interval{ std::min(flo, glo), std::min(fhi, ghi), false };
  }

  double gradient(const frep::Point3& p, frep::Point3& grad) override
  {
    return valueAt(p[0], p[1], p[2], &grad);
  }

private:
  double valueAt(double x, double y, double z, frep::Point3* grad) const
  {
    const VoxelData& d = *d_;
    if (std::isnan(x) || std::isnan(y) || std::isnan(z))
    {
      if (grad)
      {
        *grad = { NAN, NAN, NAN };
      }
      return NAN;
    }
    const VoxelGrid& g = *d.grid;
    const double p[3] = { x, y, z };
    std::int64_t c[3];
    double t[3];
    for (int a = 0; a < 3; ++a)
    {
      const double ua = d.u(a, p[a]);
      c[a] = d.cell(a, ua);
      t[a] = ua - static_cast<double>(c[a]);
    }
    const std::int64_t nx = g.dimensions[0];
    const std::int64_t nxy = nx * g.dimensions[1];
    const float* v0 = g.values.data() + c[0] + nx * c[1] + nxy * c[2];
    const double v000 = v0[0], v100 = v0[1], v010 = v0[nx], v110 = v0[nx + 1];
    const double v001 = v0[nxy], v101 = v0[nxy + 1], v011 = v0[nxy + nx], v111 = v0[nxy + nx + 1];
    const double tx = t[0], ty = t[1], tz = t[2];
    const double a00 = v000 + tx * (v100 - v000);
    const double a10 = v010 + tx * (v110 - v010);
    const double a01 = v001 + tx * (v101 - v001);
    const double a11 = v011 + tx * (v111 - v011);
    const double b0 = a00 + ty * (a10 - a00);
    const double b1 = a01 + ty * (a11 - a01);
    double v = b0 + tz * (b1 - b0);
    // Rounding may step out of the convex hull of the corner values: clamp it back, so that
    // bound() is an enclosure without slack.
    const double vlo = std::min({ v000, v100, v010, v110, v001, v101, v011, v111 });
    const double vhi = std::max({ v000, v100, v010, v110, v001, v101, v011, v111 });
    v = std::min(std::max(v, vlo), vhi);
    const double F = d.F(v);

    const double hx = d.h(0, x), hy = d.h(1, y), hz = d.h(2, z);
    const double Gs = d.scale * VoxelData::G(hx, hy, hz);
    const double f = std::min(F, Gs);
    if (grad)
    {
      if (F <= Gs)
      {
        const double s = d.above ? 1.0 : -1.0;
        // Derivatives of the trilinear interpolant in index space, zero along clamped axes.
        const double dx = (1 - tz) * ((1 - ty) * (v100 - v000) + ty * (v110 - v010)) +
          tz * ((1 - ty) * (v101 - v001) + ty * (v111 - v011));
        const double dy = (1 - tz) * (a10 - a00) + tz * (a11 - a01);
        const double dz = b1 - b0;
        const double di[3] = { dx, dy, dz };
        for (int a = 0; a < 3; ++a)
        {
          const double ua = (p[a] - g.origin[a]) / g.spacing[a];
          const bool clamped = ua < 0 || ua > d.umax[a];
          (*grad)[a] = clamped ? 0.0 : s * di[a] / g.spacing[a];
        }
      }
      else
      {
        const double h3[3] = { hx, hy, hz };
        frep::Point3 gg{ 0, 0, 0 };
        if (hx >= 0 && hy >= 0 && hz >= 0)
        {
          int am = 0;
          for (int a = 1; a < 3; ++a)
          {
            if (h3[a] < h3[am])
            {
              am = a;
            }
          }
          gg[am] = (p[am] - d.lo[am] <= d.hi[am] - p[am]) ? 1.0 : -1.0;
        }
        else
        {
          const double dist = -VoxelData::G(hx, hy, hz);
          for (int a = 0; a < 3; ++a)
          {
            if (h3[a] < 0 && dist > 0)
            {
              // Below lo: moving up brings p closer; above hi: moving up takes it away.
              const double e = -h3[a] / dist;
              gg[a] = p[a] < d.lo[a] ? e : -e;
            }
          }
        }
        *grad = { d.scale * gg[0], d.scale * gg[1], d.scale * gg[2] };
      }
    }
    return f;
  }

  std::shared_ptr<const VoxelData> d_;
  std::vector<Pyramid::Partial> partials_;
};

class VoxelFieldImpl final : public frep::Field
{
public:
  explicit VoxelFieldImpl(std::shared_ptr<const VoxelData> data)
    : d_(std::move(data))
  {
  }
  std::unique_ptr<frep::FieldEvaluator> evaluator() const override
  {
    return std::make_unique<VoxelFieldEvaluator>(d_);
  }

private:
  std::shared_ptr<const VoxelData> d_;
};

} // namespace

double lipschitzBound(const VoxelGrid& grid, double isoValue)
{
  validate(grid);
  return boxScale(grid, isoValue, lipschitzOf(grid));
}

frep::FieldPtr voxelField(std::shared_ptr<const VoxelGrid> grid, double isoValue, bool insideAbove)
{
  if (!grid)
  {
    throw std::invalid_argument("voxelField: null grid");
  }
  validate(*grid, "voxelField: grid");
  if (!std::isfinite(isoValue))
  {
    throw std::invalid_argument("voxelField: the iso-value must be finite");
  }
  auto data = std::make_shared<VoxelData>();
  data->grid = grid;
  data->iso = isoValue;
  data->above = insideAbove;
  data->scale = boxScale(*grid, isoValue, lipschitzOf(*grid));
  const frep::Box3 b = grid->bounds();
  for (int a = 0; a < 3; ++a)
  {
    data->lo[a] = b.lo[a];
    data->hi[a] = b.hi[a];
    data->mid[a] = 0.5 * (b.lo[a] + b.hi[a]);
    data->umax[a] = static_cast<double>(grid->dimensions[a] - 1);
  }
  data->pyramid = std::make_unique<Pyramid>(*grid);
  return std::make_shared<VoxelFieldImpl>(std::move(data));
}

} // namespace ictk::voxel
