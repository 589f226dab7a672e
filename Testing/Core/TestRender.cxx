// SPDX-License-Identifier: BSD-3-Clause
// Pruned rendering (recursive interval subdivision) against brute force: the same image, bit for
// bit, on prospero.vm (when Fidget's models are present), on bundled CSG models, in 2D and 3D.
#include "FRep/ModelRegistry.h"
#include "FRep/Render.h"
#include "Lang/VmReader.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>

using namespace ictk;
using namespace ictk::frep;

namespace
{
std::filesystem::path benchModels()
{
  if (const char* env = std::getenv("ICTK_BENCH_MODELS"))
  {
    return env;
  }
  return ICTK_BENCH_MODELS_DIR;
}

TapePtr bundled(const char* name)
{
  return Tape::compile(findModel(name).build().geometry().function());
}

// Pruned (default tiles, and another tiling) and brute force agree; returns the inside count.
std::int64_t expectSameImages(const TapePtr& tape, const RenderRegion& region, int w, int h,
  bool singlePrecision, int threads = 2)
{
  RenderOptions brute;
  brute.prune = false;
  brute.threads = 1;
  brute.singlePrecision = singlePrecision;
  const std::vector<std::uint8_t> reference = renderSign2D(tape, region, w, h, brute);

  RenderStats stats;
  RenderOptions pruned;
  pruned.threads = threads;
  pruned.singlePrecision = singlePrecision;
  pruned.stats = &stats;
  const std::vector<std::uint8_t> image = renderSign2D(tape, region, w, h, pruned);
  EXPECT_GT(stats.tilesFilled, 0);
  EXPECT_LT(stats.pixelsEvaluated, static_cast<std::int64_t>(w) * h);

  RenderOptions other = pruned;
  other.tileSizes = { 128, 32, 4 };
  other.threads = 1;
  const std::vector<std::uint8_t> image2 = renderSign2D(tape, region, w, h, other);

  std::int64_t inside = 0, differ = 0, differ2 = 0;
  for (std::size_t i = 0; i < reference.size(); ++i)
  {
    inside += reference[i];
    differ += reference[i] != image[i];
    differ2 += reference[i] != image2[i];
  }
  EXPECT_EQ(differ, 0);
  EXPECT_EQ(differ2, 0);
  return inside;
}
} // namespace

TEST(Render, ProsperoPrunedEqualsBruteForce)
{
  const std::filesystem::path file = benchModels() / "prospero.vm";
  if (!std::filesystem::exists(file))
  {
    GTEST_SKIP() << file << " is absent (set ICTK_BENCH_MODELS to Fidget's models folder)";
  }
  const TapePtr tape = Tape::compile(lang::readVmFile(file.string()).function);
  const std::int64_t inside = expectSameImages(tape, RenderRegion{}, 512, 512, true);
  // Text on a page: some ink, mostly paper.
  EXPECT_GT(inside, 512 * 512 / 50);
  EXPECT_LT(inside, 512 * 512 / 2);
}

TEST(Render, CsgPrunedEqualsBruteForce)
{
  RenderRegion region;
  region.lo = { -1.2, -1.2, 0.1 };
  region.hi = { 1.2, 1.2, 0.1 };
  for (const char* model : { "csg3", "random1000", "blend100" })
  {
    SCOPED_TRACE(model);
    const TapePtr tape = bundled(model);
    EXPECT_GT(expectSameImages(tape, region, 300, 257, true), 0);
    EXPECT_GT(expectSameImages(tape, region, 300, 257, false), 0);
  }
}

TEST(Render, ThreeDimensions)
{
  const TapePtr tape = bundled("csg3");
  RenderRegion region;
  region.lo = { -1.2, -1.2, -1.2 };
  region.hi = { 1.2, 1.2, 1.2 };
  RenderOptions brute;
  brute.prune = false;
  const auto reference = renderSign3D(tape, region, { 70, 64, 50 }, brute);
  RenderOptions pruned;
  pruned.tileSizes = { 32, 8, 2 };
  const auto image = renderSign3D(tape, region, { 70, 64, 50 }, pruned);
  EXPECT_EQ(reference, image);
  // The voxel at the centre is in the cylinder's hole; one at (0.7, 0, 0) is in the solid.
  const auto voxel = [&](double x, double y, double z)
  {
    const auto idx = [&](double c, int n)
    {
      return static_cast<int>((c + 1.2) / 2.4 * n);
    };
    return reference[(static_cast<std::size_t>(idx(z, 50)) * 64 + idx(y, 64)) * 70 + idx(x, 70)];
  };
  EXPECT_EQ(voxel(0, 0, 0), 0);
  EXPECT_EQ(voxel(0.7, 0.01, 0.01), 1);
  EXPECT_EQ(voxel(1.1, 1.1, 1.1), 0);
}

TEST(Render, BadArguments)
{
  const TapePtr tape = bundled("csg3");
  EXPECT_THROW(renderSign2D(tape, RenderRegion{}, 0, 10), std::invalid_argument);
  RenderOptions o;
  o.tileSizes = { 64, 7 };
  EXPECT_THROW(renderSign2D(tape, RenderRegion{}, 10, 10, o), std::invalid_argument);
  RenderRegion r;
  r.hi[0] = r.lo[0];
  EXPECT_THROW(renderSign2D(tape, r, 10, 10), std::invalid_argument);
}
