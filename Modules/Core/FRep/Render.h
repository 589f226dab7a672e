// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Sign images and voxel occupancy by recursive interval subdivision (the libfive/Fidget rendering
// scheme): interval bounds decide whole tiles that are certainly inside or outside; the tape is
// pruned for the remaining tiles, which are subdivided with the pruned tape; the smallest tiles
// are evaluated pixel by pixel (BatchEvaluator::evalRowX). Multithreaded over the top-level tiles
// with TBB; the image does not depend on the thread count.

#include "FRep/Evaluators.h"

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

namespace ictk::frep
{

/// Counts of what a render did (for benchmarks and tuning).
struct RenderStats
{
  std::int64_t tilesFilled = 0;      ///< tiles decided by interval arithmetic, all levels
  std::int64_t tilesEvaluated = 0;   ///< leaf tiles evaluated pixel by pixel
  std::int64_t leafInstructions = 0; ///< sum over evaluated leaf tiles of their tape length
  std::int64_t pixelsEvaluated = 0;
};

/// A float evaluator of grid rows other than BatchEvaluator<float> (the JIT, FRep/Jit.h): what the
/// renderer asks of it. It must give the values BatchEvaluator<float>::evalRowX gives.
class RowEvaluator
{
public:
  virtual ~RowEvaluator() = default;
  virtual void evalRowX(double x0, double dx, std::int64_t first, double y, double z, double t,
    float* out, std::size_t n) = 0;
  virtual const TapePtr& tape() const = 0;
};
using RowEvaluatorFactory = std::function<std::unique_ptr<RowEvaluator>(
  const TapePtr& tape, const std::vector<double>& parameters)>;

struct RenderOptions
{
  /// Threads to use; 0 = TBB's default.
  int threads = 0;
  /// false: evaluate every pixel with the full tape (the brute-force reference).
  bool prune = true;
  /// Tile edges, coarse to fine, each a multiple of the next: tiles of tileSizes[0] are bounded
  /// with the full tape, then split into tiles of tileSizes[1] bounded with the pruned tape, and so
  /// on; the pixels of the last level's undecided tiles are evaluated. Along z (3D) the same edges
  /// are used. The default was the fastest on prospero.vm at 1024^2 (docs/performance.md): below
  /// 32 pixels, pruning costs more than the instructions it removes.
  std::vector<int> tileSizes{ 128, 32 };
  /// Evaluate pixels in float (true) or double. Interval decisions are made in double either
  /// way: in double the pruned image equals the brute-force one exactly; in float they agree
  /// except where a pixel's value is within float rounding of 0 or of a pruned min/max tie.
  bool singlePrecision = true;
  std::vector<double> parameters;
  /// When set (and singlePrecision), pixels are evaluated by evaluators it makes instead of
  /// BatchEvaluator<float>, e.g. frep::jitRowEvaluatorFactory() (FRep/Jit.h).
  RowEvaluatorFactory rowEvaluator;
  /// When set, receives the counts of the render.
  RenderStats* stats = nullptr;
};

/// The box rendered: pixel (voxel) centres are spread evenly over it, half a pixel in from its
/// faces. A 2D image is the plane z = lo[2].
struct RenderRegion
{
  std::array<double, 3> lo{ -1, -1, 0 };
  std::array<double, 3> hi{ 1, 1, 0 };
  double time = 0;
};

/// width x height pixels, 1 where f >= 0 (inside) and 0 elsewhere (NaN included); pixel (i, j)
/// is out[j * width + i], centred at x = lo + (i + 1/2) (hi - lo) / width (likewise y), so row 0
/// is the bottom of the picture. Throws std::invalid_argument on a non-positive size, a bad region
/// or bad tile sizes.
std::vector<std::uint8_t> renderSign2D(const TapePtr& tape, const RenderRegion& region, int width,
  int height, const RenderOptions& options = {});

/// The same in 3D: dims[0] x dims[1] x dims[2] voxels, x fastest (VTK's point order).
std::vector<std::uint8_t> renderSign3D(const TapePtr& tape, const RenderRegion& region,
  const std::array<int, 3>& dims, const RenderOptions& options = {});

} // namespace ictk::frep
