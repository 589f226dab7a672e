// SPDX-License-Identifier: BSD-3-Clause
// Narrow-band sampling into a sparse OpenVDB grid (Voxel/NarrowBand.h): the active voxels of a
// distance sphere's band against the analytic shell volume, every active value against dense
// sampling at the same point, the active set against the dense points with |f| <= band (the
// interval culling loses none), thread-count independence, the written file, and the errors.

#include "FRep/BundledModels.h"
#include "FRep/Expr.h"
#include "FRep/Sampling.h"
#include "FRep/Tape.h"
#include "TempDir.h"
#include "Voxel/NarrowBand.h"

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <iostream>
#include <map>

using namespace ictk;
using ::testing::HasSubstr;

namespace
{

frep::TapePtr distanceSphere(double r)
{
  using frep::Expr;
  const Expr x = Expr::x(), y = Expr::y(), z = Expr::z();
  return frep::Tape::compile(Expr::constant(r) - frep::sqrt(x * x + y * y + z * z));
}

bool sameBits(float a, float b)
{
  return std::memcmp(&a, &b, sizeof a) == 0;
}

/// Checks `band` against dense sampling of the same grid: the active voxels are exactly the
/// points with |f| <= band, each with sampleGrid's value bit for bit. Returns the dense count.
std::int64_t expectEqualToDense(
  const frep::TapePtr& tape, const frep::Grid& grid, const voxel::NarrowBandGrid& band)
{
  std::vector<float> dense(static_cast<std::size_t>(grid.pointCount()));
  frep::SampleOptions options;
  options.threads = 1;
  frep::sampleGrid(tape, grid, dense.data(), options);
  const auto& d = grid.dimensions;
  std::int64_t inBand = 0, mismatched = 0;
  for (std::int64_t k = 0; k < d[2]; ++k)
  {
    for (std::int64_t j = 0; j < d[1]; ++j)
    {
      for (std::int64_t i = 0; i < d[0]; ++i)
      {
        const float v = dense[static_cast<std::size_t>((k * d[1] + j) * d[0] + i)];
        bool active = false;
        const float s = band.value({ i, j, k }, &active);
        const bool expected = std::abs(v) <= static_cast<float>(band.band());
        inBand += expected;
        if (active != expected || (active && !sameBits(s, v)))
        {
          if (++mismatched <= 5)
          {
            ADD_FAILURE() << "point " << i << " " << j << " " << k << ": dense " << v << ", band "
                          << s << (active ? " (active)" : " (inactive)");
          }
        }
      }
    }
  }
  EXPECT_EQ(mismatched, 0);
  EXPECT_EQ(band.activeVoxelCount(), inBand);
  return inBand;
}

} // namespace

TEST(NarrowBand, SphereBandMatchesTheShellVolume)
{
  const double R = 0.8;
  const frep::TapePtr tape = distanceSphere(R);
  const frep::Grid grid = frep::gridOverBox({ -1, -1, -1 }, { 1, 1, 1 }, { 160, 160, 160 });
  const double h = grid.spacing[0];
  voxel::NarrowBandOptions options;
  options.band = 2 * h;
  const voxel::NarrowBandGrid band = voxel::sampleNarrowBand(tape, grid, options);

  // The lattice points of the shell R - b <= |p| <= R + b: its volume over a voxel's.
  const double b = options.band;
  const double pi = std::acos(-1.0);
  const double shell = 4.0 / 3.0 * pi * (std::pow(R + b, 3) - std::pow(R - b, 3)) / (h * h * h);
  const auto active = static_cast<double>(band.activeVoxelCount());
  EXPECT_NEAR(active / shell, 1.0, 0.02) << active << " active voxels, shell " << shell;

  expectEqualToDense(tape, grid, band);

  // Outside the band: +band inside the sphere, -band outside, both inactive.
  bool on = true;
  EXPECT_FLOAT_EQ(band.value({ 80, 80, 80 }, &on), static_cast<float>(b));
  EXPECT_FALSE(on);
  EXPECT_FLOAT_EQ(band.value({ 0, 0, 0 }, &on), static_cast<float>(-b));
  EXPECT_FALSE(on);
  EXPECT_FLOAT_EQ(band.value({ 5000, 0, 0 }, &on), static_cast<float>(-b));

  // Memory follows the band: 8^3 leaves of floats around the shell, not the 160^3 volume.
  const double bytesPerActive = static_cast<double>(band.memoryBytes()) / active;
  std::cout << "[ sphere 160^3, band 2 voxels ] " << band.activeVoxelCount() << " active voxels ("
            << active / shell << " of the shell), " << band.memoryBytes() << " bytes ("
            << bytesPerActive << " per active voxel; dense: " << 4 * 160 * 160 * 160
            << "), leaves kept " << band.stats().leavesKept << " of " << band.stats().leavesSampled
            << " sampled\n";
  // A kept leaf is 512 floats (2 KiB) with its masks; the inner nodes of a 160^3 grid (one
  // 4096^3 node, eight 128^3 ones) add well under 1 MB.
  const auto leaves = static_cast<double>(band.stats().leavesKept);
  EXPECT_GT(static_cast<double>(band.memoryBytes()), leaves * 2048);
  EXPECT_LT(static_cast<double>(band.memoryBytes()), leaves * 2200 + 1e6);
  EXPECT_LT(band.memoryBytes(), std::size_t(4) * 160 * 160 * 160 / 4);
  // Each kept leaf holds a band point, and the culling samples few leaves that hold none.
  EXPECT_GT(band.stats().leavesKept, 0.9 * band.stats().leavesSampled);
}

TEST(NarrowBand, PrunedCsgEqualsDenseSamplingOnAnyThreadCount)
{
  // random1000: 48 primitives under min/max, so the descent prunes its tape level by level. An
  // odd grid that is no multiple of 8 and starts inside a larger one (grid.first).
  const frep::TapePtr tape =
    frep::Tape::compile(frep::bundled::csgField(frep::bundled::random1000Recipe()));
  ASSERT_GT(tape->choiceCount(), 0u);
  frep::Grid grid = frep::gridOverBox({ -1.2, -1.2, -1.2 }, { 1.2, 1.2, 1.2 }, { 131, 131, 131 });
  grid.first = { 3, 20, 11 };
  grid.dimensions = { 117, 97, 109 };
  voxel::NarrowBandOptions options;
  options.band = 0.02;
  std::map<int, std::vector<std::pair<std::array<std::int64_t, 3>, float>>> voxels;
  for (int threads : { 1, 2 })
  {
    options.threads = threads;
    const voxel::NarrowBandGrid band = voxel::sampleNarrowBand(tape, grid, options);
    const std::int64_t inBand = expectEqualToDense(tape, grid, band);
    EXPECT_GT(inBand, 10000);
    band.forEachActive([&](const std::array<std::int64_t, 3>& ijk, float v)
      { voxels[threads].emplace_back(ijk, v); });
  }
  ASSERT_EQ(voxels[1].size(), voxels[2].size());
  for (std::size_t n = 0; n < voxels[1].size(); ++n)
  {
    ASSERT_EQ(voxels[1][n].first, voxels[2][n].first);
    ASSERT_TRUE(sameBits(voxels[1][n].second, voxels[2][n].second));
  }
}

TEST(NarrowBand, WrittenFileHoldsTheBandAndTheGridsTransform)
{
  ictk::test_support::TempDir dir;
  const frep::Grid grid = frep::gridOverBox({ -1, -0.5, 0 }, { 1, 1.5, 2 }, { 41, 41, 41 });
  voxel::NarrowBandOptions options;
  options.band = 0.1;
  const frep::TapePtr tape = distanceSphere(0.7);
  frep::Grid shifted = grid;
  // Centre the sphere in the box: sample f(p - (0, 0.5, 1)) by moving the grid instead.
  shifted.origin = { -1, -1, -1 };
  const voxel::NarrowBandGrid band = voxel::sampleNarrowBand(tape, shifted, options);
  const std::string path = (dir.path() / "band.vdb").string();
  band.write(path, "f");

  openvdb::initialize();
  openvdb::io::File file(path);
  file.open();
  openvdb::GridBase::Ptr base = file.readGrid("f");
  file.close();
  auto vdb = openvdb::gridPtrCast<openvdb::FloatGrid>(base);
  ASSERT_TRUE(vdb);
  EXPECT_EQ(static_cast<std::int64_t>(vdb->activeVoxelCount()), band.activeVoxelCount());
  EXPECT_DOUBLE_EQ(vdb->metaValue<double>("ictk_band"), 0.1);
  EXPECT_FLOAT_EQ(vdb->background(), -0.1f);
  const openvdb::Vec3d p = vdb->transform().indexToWorld(openvdb::Coord(20, 10, 30));
  EXPECT_NEAR(p.x(), -1 + 20 * 0.05, 1e-12);
  EXPECT_NEAR(p.y(), -1 + 10 * 0.05, 1e-12);
  EXPECT_NEAR(p.z(), -1 + 30 * 0.05, 1e-12);
  // Index (20, 34, 20) is at (0, 0.7, 0): on the sphere.
  bool on = false;
  EXPECT_NEAR(vdb->tree().getValue(openvdb::Coord(20, 34, 20)), 0.0f, 1e-6);
  on = vdb->tree().isValueOn(openvdb::Coord(20, 34, 20));
  EXPECT_TRUE(on);
}

TEST(NarrowBand, RefusesBadBandsGridsAndMissingParameters)
{
  const frep::TapePtr tape = distanceSphere(0.5);
  const frep::Grid grid = frep::gridOverBox({ -1, -1, -1 }, { 1, 1, 1 }, { 16, 16, 16 });
  voxel::NarrowBandOptions options;
  options.band = -1;
  try
  {
    voxel::sampleNarrowBand(tape, grid, options);
    ADD_FAILURE() << "a negative band was accepted";
  }
  catch (const std::invalid_argument& e)
  {
    EXPECT_THAT(e.what(), HasSubstr("band must be finite and positive"));
  }
  options.band = std::nan("");
  EXPECT_THROW(voxel::sampleNarrowBand(tape, grid, options), std::invalid_argument);
  options.band = 0; // the default: three voxels
  EXPECT_DOUBLE_EQ(voxel::sampleNarrowBand(tape, grid, options).band(), 3 * 2.0 / 15);
  frep::Grid empty = grid;
  empty.dimensions = { 0, 16, 16 };
  EXPECT_THROW(voxel::sampleNarrowBand(tape, empty, options), std::invalid_argument);
  const frep::TapePtr withParameter =
    frep::Tape::compile(frep::Expr::parameter(0) - frep::sqrt(frep::Expr::x() * frep::Expr::x()));
  try
  {
    voxel::sampleNarrowBand(withParameter, grid, options);
    ADD_FAILURE() << "a missing parameter was accepted";
  }
  catch (const std::invalid_argument& e)
  {
    EXPECT_THAT(e.what(), HasSubstr("1 parameter(s) but 0"));
  }
}
