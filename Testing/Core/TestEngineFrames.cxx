// SPDX-License-Identifier: BSD-3-Clause
// The frame loop without VTK (Engine/FrameSequence) on thesis 5.1
// (Data/Models/icm/ch5_1_disk_rectangle.icm): a disk of radius 1 whose centre is at x = -2 + t
// touches a rectangle's left side x = 2 at t = 3; instance K1 (2 cells) before, K2 at the
// tangency, K3 (7 cells) after. And the rule of a T0:T1:DT range.

#include "Engine/FrameSequence.h"

#include <gtest/gtest.h>

#include <cstddef>
#include <string>
#include <vector>

namespace
{
namespace engine = ictk::engine;

std::string DiskRectangle()
{
  return std::string(ICTK_DATA_DIR) + "/Models/icm/ch5_1_disk_rectangle.icm";
}

engine::FrameSequenceOptions DiskOptions()
{
  engine::FrameSequenceOptions options;
  options.times = engine::frameTimes(0, 6, 0.5);
  options.discretization.featureSize = 0.1;
  return options;
}

std::size_t Points(const ictk::complex::ComplexMesh& mesh)
{
  std::size_t n = 0;
  for (const auto& cell : mesh.cells)
  {
    n += cell.vertices().size();
  }
  return n;
}

} // namespace

TEST(FrameTimes, StepsByMultiplicationAndJoinsARoundingRemainderToT1)
{
  const std::vector<double> halves = engine::frameTimes(0, 6, 0.5);
  ASSERT_EQ(halves.size(), 13u);
  for (std::size_t k = 0; k < halves.size(); ++k)
  {
    EXPECT_EQ(halves[k], 0.5 * static_cast<double>(k));
  }
  // 3 x 0.1 is 0.30000000000000004: that is T1, not a frame before a fourth one.
  const std::vector<double> tenths = engine::frameTimes(0, 0.3, 0.1);
  ASSERT_EQ(tenths.size(), 4u);
  EXPECT_EQ(tenths[3], 0.3);
  // 0.3 does not divide 1: 0, 0.3, 0.6, 0.9 and then 1 itself.
  const std::vector<double> uneven = engine::frameTimes(0, 1, 0.3);
  ASSERT_EQ(uneven.size(), 5u);
  EXPECT_EQ(uneven[4], 1.0);
  EXPECT_EQ(engine::frameTimes(2, 2, 0.5), std::vector<double>{ 2.0 });
  EXPECT_EQ(engine::frameCount(0, 6, 0.5), 13.0);
  EXPECT_GT(engine::frameCount(0, 10, 1e-6), engine::MaxFrames);
}

TEST(FrameSequence, GivesEachFrameWithTheRecordsOnTheWay)
{
  engine::FrameSequence frames(DiskRectangle(), DiskOptions());
  EXPECT_EQ(frames.startTime(), 0.0);
  EXPECT_EQ(frames.maxStep(), 0.5); // the frames' spacing
  ASSERT_EQ(frames.times().size(), 13u);
  std::vector<engine::FrameRecord> records;
  std::vector<std::size_t> points;
  for (std::size_t i = 0; i < frames.times().size(); ++i)
  {
    engine::Frame f = frames.frame(i);
    EXPECT_EQ(f.time, 0.5 * static_cast<double>(i));
    ASSERT_FALSE(f.records.empty()) << "frame " << i;
    EXPECT_EQ(f.records.back().time, f.time);
    EXPECT_EQ(f.mesh.cells.size(), f.complex->cellCount());
    // K2 holds at the tangency itself, the frame t = 3.
    EXPECT_EQ(f.instance, i < 6 ? "K1" : i == 6 ? "K2" : "K3") << "t = " << f.time;
    if (i != 6)
    {
      EXPECT_EQ(f.complex->cellCount(), i < 6 ? 2u : 7u) << "t = " << f.time;
    }
    records.insert(records.end(), f.records.begin(), f.records.end());
    points.push_back(Points(f.mesh));
  }
  // The start record (the choice of the initial instance), one per frame after it and the two
  // located transitions (K2 at the tangency, then K3), as `ictk run --trace` writes them.
  ASSERT_EQ(records.size(), 15u);
  EXPECT_EQ(records.front().time, 0.0);
  EXPECT_EQ(records.front().instance, "K1");
  std::vector<std::string> transitions;
  for (const engine::FrameRecord& r : records)
  {
    if (r.transition && r.time > 0)
    {
      transitions.push_back(r.instance);
      EXPECT_NEAR(r.time, 3.0, 1e-6);
    }
  }
  EXPECT_EQ(transitions, (std::vector<std::string>{ "K2", "K3" }));

  // Back in time: the model starts again, and the frame is the one computed on the way forwards.
  engine::Frame again = frames.frame(4);
  ASSERT_FALSE(again.records.empty());
  EXPECT_EQ(again.records.front().time, 0.0);
  EXPECT_EQ(again.records.back().time, 2.0);
  EXPECT_EQ(Points(again.mesh), points[4]);
}

TEST(FrameSequence, SharesCellsAmongPiecesAndStartsAgainAfterACancel)
{
  engine::FrameSequence whole(DiskRectangle(), DiskOptions());
  const engine::Frame all = whole.frame(10);
  ASSERT_EQ(all.mesh.cells.size(), 7u);

  std::size_t cells = 0, points = 0;
  for (int piece = 0; piece < 2; ++piece)
  {
    engine::FrameSequence part(DiskRectangle(), DiskOptions());
    const engine::Frame f = part.frame(10, { piece, 2 });
    EXPECT_EQ(f.complex->cellCount(), 7u);
    cells += f.mesh.cells.size();
    points += Points(f.mesh);
  }
  EXPECT_EQ(cells, 7u);
  EXPECT_EQ(points, Points(all.mesh));

  // A cancel in the middle of the run: ictk::Cancelled, then the same frame as without it.
  engine::FrameSequenceOptions options = DiskOptions();
  bool cancel = true;
  int reports = 0;
  options.progress = [&](double fraction)
  {
    ++reports;
    return !(cancel && fraction > 0.2);
  };
  engine::FrameSequence frames(DiskRectangle(), options);
  EXPECT_THROW(frames.frame(10), ictk::Cancelled);
  cancel = false;
  const engine::Frame f = frames.frame(10);
  EXPECT_GT(reports, 2);
  EXPECT_EQ(f.records.front().time, 0.0);
  EXPECT_EQ(Points(f.mesh), Points(all.mesh));
  EXPECT_EQ(f.instance, "K3");
}

// FrameSequenceOptions::cells: only the cells it picks are discretised (ictk render asks for the
// ones it does not ray cast), within the share of a piece; the others have no mesh.
TEST(FrameSequence, DiscretisesTheCellsTheOptionsPick)
{
  engine::FrameSequence whole(DiskRectangle(), DiskOptions());
  const engine::Frame all = whole.frame(10);
  ASSERT_EQ(all.mesh.cells.size(), 7u);

  engine::FrameSequenceOptions options = DiskOptions();
  options.cells = [](const ictk::complex::Complex& complex)
  {
    std::vector<ictk::complex::CellId> even;
    for (std::size_t i = 0; i < complex.cellIds().size(); i += 2)
    {
      even.push_back(complex.cellIds()[i]);
    }
    return even;
  };
  engine::FrameSequence picked(DiskRectangle(), options);
  const engine::Frame f = picked.frame(10);
  EXPECT_EQ(f.complex->cellCount(), 7u);
  EXPECT_EQ(f.mesh.cells.size(), 4u);
  // The same cells as piece 0 of 2 (cell i goes to piece i mod 2), with the same points.
  engine::FrameSequence part(DiskRectangle(), DiskOptions());
  EXPECT_EQ(Points(f.mesh), Points(part.frame(10, { 0, 2 }).mesh));
  // Piece 1 of 2 has none of the even cells.
  engine::FrameSequence other(DiskRectangle(), options);
  EXPECT_TRUE(other.frame(10, { 1, 2 }).mesh.cells.empty());

  options.cells = [](const ictk::complex::Complex&)
  {
    return std::vector<ictk::complex::CellId>{};
  };
  engine::FrameSequence none(DiskRectangle(), options);
  EXPECT_TRUE(none.frame(10).mesh.cells.empty());
}
