// SPDX-License-Identifier: BSD-3-Clause
// Space-time cells in the engine (thesis 5.3, issue 16): a cell whose field has time (XYZT, or
// XYT for the 2D exemplars) is, at global time t, its cross-section there. A 4D sphere whose
// radius grows with t, r(t) = 0.5 + 0.5 t, is run at three times: the cross-section's volume
// (Geometry's measure) is 4/3 pi r^3, the discretised surface's area 4 pi r^2 and its enclosed
// volume 4/3 pi r^3, through the engine (DynamicModel) and through the frame loop that `ictk run`
// and ictkDynamicComplexSource share (FrameSequence). A `dim = 4D` cell whose shape has no time
// is refused at its place.

#include "Discretize/Mesh.h"
#include "Engine/FrameSequence.h"
#include "Geometry/Queries.h"
#include "Lang/Icm.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

namespace
{
namespace engine = ictk::engine;
constexpr double Pi = 3.14159265358979323846;

const char* kGrowingSphere = R"(
name = GROWING;
TIMESPANS { film : TIMESPAN(0, 1); }
CELLS {
  Ball {
    type = F-CELL;
    shape = hyperfun {
      ball(x[4], a[1]) { ball = (0.5 + 0.5 * x[4])^2 - x[1]^2 - x[2]^2 - x[3]^2; }
    }
    dim = 4D;
    domain = { -1.2, -1.2, -1.2, 1.2, 1.2, 1.2 };
    parameters { translation(0.25, 0, 0); }
  }
}
K { CELLS { Ball; } }
)";

double Radius(double t)
{
  return 0.5 + 0.5 * t;
}

engine::DynamicModel Growing(engine::RunOptions options = {})
{
  return engine::DynamicModel(ictk::lang::readIcm(kGrowingSphere, "growing.icm"), options);
}

} // namespace

TEST(SpaceTime, A4DCellIsItsCrossSectionAtTheModelsTime)
{
  engine::DynamicModel m = Growing();
  m.start();
  for (double t : { 0.0, 0.5, 1.0 })
  {
    m.advanceTo(t, 0.25);
    const std::vector<engine::CellState> cells = m.cells();
    ASSERT_EQ(cells.size(), 1u);
    EXPECT_EQ(cells[0].dimension, 3); // the cross-section of a 4D cell
    const double r = Radius(t);
    // Geometry's measure of the cross-section, placed by the cell's translation.
    EXPECT_NEAR(ictk::geometry::measure(*cells[0].shape), 4.0 / 3.0 * Pi * r * r * r, 2e-3)
      << "t = " << t;
    EXPECT_GT(cells[0].shape->value({ 0.25 + r - 0.01, 0, 0 }), 0.0) << "t = " << t;
    EXPECT_LT(cells[0].shape->value({ 0.25 + r + 0.01, 0, 0 }), 0.0) << "t = " << t;
    // The complex's cell is the same cross-section.
    const ictk::complex::Complex cx = m.complex();
    ASSERT_EQ(cx.cellCount(), 1u);
  }
}

TEST(SpaceTime, FramesMeshTheCrossSections)
{
  engine::FrameSequenceOptions options;
  options.times = { 0.0, 0.5, 1.0 };
  options.discretization.featureSize = 0.03;
  options.run = engine::RunOptions{};
  engine::FrameSequence frames(
    [](engine::RunOptions run) { return Growing(std::move(run)); }, options);
  for (std::size_t i = 0; i < 3; ++i)
  {
    const engine::Frame f = frames.frame(i);
    ASSERT_EQ(f.mesh.cells.size(), 1u);
    const auto& surface = f.mesh.cells[0].surface;
    const double r = Radius(f.time);
    // Dual contouring at h = 0.03: area and volume within 2% of the sphere's.
    EXPECT_NEAR(ictk::discretize::surfaceArea(surface), 4 * Pi * r * r, 0.02 * 4 * Pi * r * r)
      << "t = " << f.time;
    EXPECT_NEAR(ictk::discretize::enclosedVolume(surface), 4.0 / 3.0 * Pi * r * r * r,
      0.02 * 4.0 / 3.0 * Pi * r * r * r)
      << "t = " << f.time;
    // Time coherence does not keep the mesh of another time: every frame is meshed anew.
    EXPECT_EQ(frames.discretizer().lastFrame().computed, 1u) << "t = " << f.time;
  }
}

TEST(SpaceTime, AnXYTCellIsAPlaneCrossSection)
{
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / "ictk_spacetime_xyt";
  fs::create_directories(dir);
  // A disk whose radius is 1 + t, on XYT (the 2D exemplars' space-time, thesis 5.3.1).
  std::ofstream(dir / "disk.xml") << R"(<?xml version="1.0"?>
<frep version="1" name="disk">
  <geometry domain="XYT" threshold="0">
    <sub>
      <square><add><const value="1"/><var axis="t"/></add></square>
      <add><square><var axis="x"/></square><square><var axis="y"/></square></add>
    </sub>
  </geometry>
</frep>
)";
  std::ofstream(dir / "disk.icm") << R"(
name = GROWING_DISK;
TIMESPANS { film : TIMESPAN(0, 2); }
CELLS {
  Disk { type = F-CELL; shape = file("disk.xml"); dim = 3D; domain = { -3, -3, 3, 3 }; }
}
K { CELLS { Disk; } }
)";
  engine::DynamicModel m = engine::DynamicModel::load((dir / "disk.icm").string());
  m.start();
  for (double t : { 0.0, 1.0, 2.0 })
  {
    m.advanceTo(t, 0.5);
    const std::vector<engine::CellState> cells = m.cells();
    ASSERT_EQ(cells.size(), 1u);
    EXPECT_EQ(cells[0].dimension, 2);
    const double r = 1 + t;
    EXPECT_NEAR(ictk::geometry::measure(*cells[0].shape), Pi * r * r, 1e-3 * Pi * r * r)
      << "t = " << t;
  }
}

TEST(SpaceTime, A4DCellWithoutTimeIsRefusedAtItsPlace)
{
  const char* text = R"(name = BAD;
CELLS {
  Ball {
    type = F-CELL;
    shape = sphere(1);
    dim = 4D;
  }
}
K { CELLS { Ball; } }
)";
  try
  {
    engine::DynamicModel m(ictk::lang::readIcm(text, "bad.icm"));
    FAIL() << "a 4D sphere was accepted";
  }
  catch (const engine::ModelError& e)
  {
    EXPECT_EQ(e.pos.line, 6);
    EXPECT_EQ(e.pos.column, 5);
    EXPECT_NE(e.message.find("space-time"), std::string::npos) << e.message;
  }
}
