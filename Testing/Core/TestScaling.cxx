// SPDX-License-Identifier: BSD-3-Clause
// Issue 7, "Scaling": pruned work grows with the surface, not the volume. The checks use the
// work counters (RenderStats, SampleStats), never timings: doubling the resolution of a fixed
// model should multiply the pruned evaluation count by about 4 in 3D (8 would be the volume) and
// about 2 in 2D (4 would be the area).
#include "FRep/BundledModels.h"
#include "FRep/Render.h"
#include "FRep/Sampling.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <string>

using namespace ictk;
using namespace ictk::frep;

namespace
{
TapePtr random1000()
{
  return Tape::compile(bundled::csgField(bundled::random1000Recipe()));
}

RenderRegion modelBox(bool threeD)
{
  RenderRegion region;
  region.lo = { -1.2, -1.2, threeD ? -1.2 : 0.0 };
  region.hi = { 1.2, 1.2, threeD ? 1.2 : 0.0 };
  return region;
}

std::int64_t voxelsEvaluated(const TapePtr& tape, int resolution)
{
  RenderStats stats;
  RenderOptions options;
  options.threads = 2;
  options.tileSizes = { 16, 4 };
  options.stats = &stats;
  renderSign3D(tape, modelBox(true), { resolution, resolution, resolution }, options);
  return stats.pixelsEvaluated;
}
} // namespace

TEST(Scaling, RandomCsgRecipeGeneralisesRandom1000)
{
  const bundled::CsgRecipe a = bundled::random1000Recipe();
  const bundled::CsgRecipe b = bundled::randomCsgRecipe(48, 20240611u);
  ASSERT_EQ(a.nodes.size(), b.nodes.size());
  EXPECT_EQ(a.root, b.root);
  for (std::size_t i = 0; i < a.nodes.size(); ++i)
  {
    EXPECT_EQ(a.nodes[i].kind, b.nodes[i].kind);
    EXPECT_EQ(a.nodes[i].p, b.nodes[i].p);
    EXPECT_EQ(a.nodes[i].a, b.nodes[i].a);
    EXPECT_EQ(a.nodes[i].b, b.nodes[i].b);
  }
  // The tape grows about linearly with the primitive count; the seed changes the model.
  const std::size_t n48 = Tape::compile(bundled::csgField(a))->instructions().size();
  const std::size_t n480 =
    Tape::compile(bundled::csgField(bundled::randomCsgRecipe(480, 20240611u)))
      ->instructions()
      .size();
  EXPECT_GT(n480, 8 * n48);
  EXPECT_LT(n480, 12 * n48);
  EXPECT_FALSE(bundled::csgField(bundled::randomCsgRecipe(48, 1u)).identical(bundled::csgField(a)));
  EXPECT_THROW(bundled::randomCsgRecipe(0, 1u), std::invalid_argument);
}

TEST(Scaling, PrunedOccupancyGrowsWithTheSurface)
{
  const TapePtr tape = random1000();
  const std::int64_t coarse = voxelsEvaluated(tape, 64);
  const std::int64_t fine = voxelsEvaluated(tape, 128);
  ASSERT_GT(coarse, 0);
  const double ratio = static_cast<double>(fine) / static_cast<double>(coarse);
  RecordProperty("voxels_evaluated_64", std::to_string(coarse));
  RecordProperty("voxels_evaluated_128", std::to_string(fine));
  // Surface: ~4x; volume: 8x.
  EXPECT_LT(ratio, 6.0) << coarse << " -> " << fine;
  EXPECT_GT(ratio, 2.0) << coarse << " -> " << fine;
  // And far fewer than every voxel.
  EXPECT_LT(fine, std::int64_t(128) * 128 * 128 / 2);
}

TEST(Scaling, PrunedSignImageGrowsWithTheBoundary)
{
  const TapePtr tape = random1000();
  std::int64_t counts[2];
  const int sizes[2] = { 512, 1024 };
  for (int i = 0; i < 2; ++i)
  {
    RenderStats stats;
    RenderOptions options;
    options.threads = 2;
    options.stats = &stats;
    renderSign2D(tape, modelBox(false), sizes[i], sizes[i], options);
    counts[i] = stats.pixelsEvaluated;
  }
  ASSERT_GT(counts[0], 0);
  const double ratio = static_cast<double>(counts[1]) / static_cast<double>(counts[0]);
  RecordProperty("pixels_evaluated_512", std::to_string(counts[0]));
  RecordProperty("pixels_evaluated_1024", std::to_string(counts[1]));
  // Boundary: ~2x; area: 4x.
  EXPECT_LT(ratio, 3.0) << counts[0] << " -> " << counts[1];
}

TEST(Scaling, SampleStatsCountPrunedInstructions)
{
  const TapePtr tape = random1000();
  const Grid grid = gridOverBox({ -1.2, -1.2, -1.2 }, { 1.2, 1.2, 1.2 }, { 64, 64, 64 });
  std::vector<float> out(static_cast<std::size_t>(grid.pointCount()));
  SampleStats full, pruned;
  SampleOptions options;
  options.threads = 2;
  options.prune = false;
  options.stats = &full;
  sampleGrid(tape, grid, out.data(), options);
  options.prune = true;
  options.stats = &pruned;
  sampleGrid(tape, grid, out.data(), options);
  // Dense sampling evaluates every point either way; pruning shortens the tapes.
  EXPECT_EQ(full.pointsEvaluated, grid.pointCount());
  EXPECT_EQ(pruned.pointsEvaluated, grid.pointCount());
  EXPECT_EQ(full.bricks, pruned.bricks);
  EXPECT_EQ(full.instructionEvaluations,
    grid.pointCount() * static_cast<std::int64_t>(tape->instructions().size()));
  // At 64^3 a brick (64 x 16 x 16 points) spans the whole x range: pruning saves ~40 %.
  EXPECT_LT(pruned.instructionEvaluations, full.instructionEvaluations * 3 / 4);
  EXPECT_GT(pruned.instructionEvaluations, 0);
}
