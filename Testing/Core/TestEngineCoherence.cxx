// SPDX-License-Identifier: BSD-3-Clause
// Time-coherent re-meshing (thesis 4.6.8, Modules/Core/Engine/CoherentDiscretizer): the meshes
// kept across frames and moved by the cells' placements are the meshes a full re-meshing gives,
// and the kept ones are really reused.
#include "Complex/Discretization.h"
#include "Discretize/Mesh.h"
#include "Engine/CoherentDiscretizer.h"
#include "Engine/DynamicModel.h"
#include "Lang/Icm.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace
{
using namespace ictk;
using engine::CellWork;
using engine::CoherenceOptions;
using engine::CoherentDiscretizer;
using engine::DynamicModel;

std::string ModelPath(const std::string& name)
{
  return std::string(ICTK_DATA_DIR) + "/Models/icm/" + name;
}

/// Same cells, same connectivity, points and attribute values within `tolerance`.
void ExpectSameMeshes(
  const complex::ComplexMesh& a, const complex::ComplexMesh& b, double tolerance, double time)
{
  ASSERT_EQ(a.cells.size(), b.cells.size()) << "t = " << time;
  EXPECT_EQ(a.featureSize, b.featureSize);
  for (std::size_t i = 0; i < a.cells.size(); ++i)
  {
    const complex::CellMesh& ma = a.cells[i];
    const complex::CellMesh& mb = b.cells[i];
    ASSERT_EQ(ma.cell, mb.cell);
    ASSERT_EQ(ma.dimension, mb.dimension);
    ASSERT_EQ(ma.vertices().size(), mb.vertices().size()) << "cell " << i << ", t = " << time;
    double worst = 0;
    for (std::size_t v = 0; v < ma.vertices().size(); ++v)
    {
      for (int k = 0; k < 3; ++k)
      {
        worst = std::max(worst, std::abs(ma.vertices()[v][k] - mb.vertices()[v][k]));
      }
    }
    EXPECT_LE(worst, tolerance) << "cell " << i << ", t = " << time;
    EXPECT_EQ(ma.surface.triangles, mb.surface.triangles) << "cell " << i;
    EXPECT_EQ(ma.curves.lines, mb.curves.lines) << "cell " << i;
    const auto& pa = const_cast<complex::CellMesh&>(ma).pointData();
    const auto& pb = const_cast<complex::CellMesh&>(mb).pointData();
    ASSERT_EQ(pa.size(), pb.size());
    for (std::size_t k = 0; k < pa.size(); ++k)
    {
      EXPECT_EQ(pa[k].name, pb[k].name);
      ASSERT_EQ(pa[k].values.size(), pb[k].values.size());
      for (std::size_t v = 0; v < pa[k].values.size(); ++v)
      {
        if (std::isnan(pa[k].values[v]))
        {
          EXPECT_TRUE(std::isnan(pb[k].values[v]));
          continue;
        }
        EXPECT_NEAR(pa[k].values[v], pb[k].values[v], tolerance);
      }
    }
  }
}

frep::Point3 Centroid(const std::vector<frep::Point3>& points)
{
  frep::Point3 c{ 0, 0, 0 };
  for (const auto& p : points)
  {
    for (int k = 0; k < 3; ++k)
    {
      c[k] += p[k] / static_cast<double>(points.size());
    }
  }
  return c;
}

std::size_t IndexOf(const std::vector<engine::CellState>& cells, const std::string& name)
{
  for (std::size_t i = 0; i < cells.size(); ++i)
  {
    if (cells[i].name == name)
    {
      return i;
    }
  }
  ADD_FAILURE() << "no cell " << name;
  return 0;
}

CellWork WorkOf(const CoherentDiscretizer& d, const std::string& name)
{
  for (const auto& [cell, work] : d.lastCells())
  {
    if (cell == name)
    {
      return work;
    }
  }
  ADD_FAILURE() << "no cell " << name << " in the last frame";
  return CellWork::Computed;
}

// Two balls of radius 0.5 (newtons_cradle.icm): B1 from x = -1.5 at speed 1 towards B2 resting at
// x = 0; they touch when the centres are 1 apart, at t = 0.5, and swap velocities. Only the
// placements change, so each ball is meshed once and moved (or left) afterwards.
TEST(EngineCoherence, NewtonsCradleMeshesEachBallOnce)
{
  // One run, meshed by both: they see the same shapes and versions.
  DynamicModel a = DynamicModel::load(ModelPath("newtons_cradle.icm"));
  const DynamicModel& b = a;
  CoherenceOptions options;
  options.featureSize = 0.05;
  CoherentDiscretizer coherent(options);
  options.coherent = false;
  CoherentDiscretizer full(options);
  a.start();
  const double pi = std::acos(-1.0);
  const double ballVolume = 4.0 / 3.0 * pi * 0.125; // r = 0.5
  int frames = 0;
  for (int k = 0; k <= 8; ++k)
  {
    const double t = 0.25 * k;
    if (t > a.time())
    {
      a.advanceTo(t, 0.05);
    }
    const complex::ComplexMesh ma = coherent.discretize(a);
    const complex::ComplexMesh mb = full.discretize(b);
    ++frames;
    ExpectSameMeshes(ma, mb, 1e-9, t);

    const auto cells = a.cells();
    ASSERT_EQ(cells.size(), 2u);
    for (const char* ball : { "B1", "B2" })
    {
      const complex::CellMesh& m = ma.of(static_cast<complex::CellId>(IndexOf(cells, ball)));
      ASSERT_EQ(m.dimension, 3);
      // The local mesh is centred on the ball's own origin: after placement, on its translation.
      const frep::Point3 c = Centroid(m.vertices());
      const geometry::Vec3 at = a.value(std::string(ball) + ".translation").vec;
      EXPECT_NEAR(c[0], at[0], 5e-3) << ball << " t = " << t;
      EXPECT_NEAR(c[1], at[1], 5e-3) << ball << " t = " << t;
      EXPECT_NEAR(std::abs(discretize::enclosedVolume(m.surface)), ballVolume, 0.02 * ballVolume);
    }
    if (k == 1)
    {
      // Before the collision B1 is at -1.5 + t and B2 at rest.
      const complex::CellMesh& m1 = ma.of(static_cast<complex::CellId>(IndexOf(cells, "B1")));
      EXPECT_NEAR(Centroid(m1.vertices())[0], -1.25, 5e-3);
      EXPECT_EQ(WorkOf(coherent, "B1"), CellWork::Moved);
      EXPECT_EQ(WorkOf(coherent, "B2"), CellWork::Reused);
    }
    if (k == 4)
    {
      // The same cells as complex::discretizeComplex meshes in world space, up to the grid: the
      // balls' volumes and boxes agree.
      complex::DiscretizationOptions worldOptions;
      worldOptions.featureSize = 0.05;
      const complex::ComplexMesh world = complex::discretizeComplex(a.complex(), worldOptions);
      ASSERT_EQ(world.cells.size(), ma.cells.size());
      for (std::size_t i = 0; i < world.cells.size(); ++i)
      {
        EXPECT_NEAR(std::abs(discretize::enclosedVolume(world.cells[i].surface)),
          std::abs(discretize::enclosedVolume(ma.cells[i].surface)), 0.02 * ballVolume);
        const frep::Point3 cw = Centroid(world.cells[i].vertices());
        const frep::Point3 cc = Centroid(ma.cells[i].vertices());
        for (int axis = 0; axis < 3; ++axis)
        {
          EXPECT_NEAR(cw[axis], cc[axis], 0.05);
        }
      }
    }
  }
  EXPECT_EQ(coherent.total().frames, 9u);
  EXPECT_EQ(coherent.total().computed, 2u);
  EXPECT_EQ(coherent.total().cells(), 18u);
  EXPECT_GE(coherent.total().moved, 9u);  // B1 moves until 0.5, B2 from then on
  EXPECT_GE(coherent.total().reused, 4u); // B2 rests until 0.5, B1 from then on
  EXPECT_EQ(full.total().computed, 18u);
  EXPECT_EQ(full.total().moved + full.total().reused, 0u);

  // Forgetting the kept meshes makes the next frame mesh everything again, the same way.
  coherent.reset();
  const complex::ComplexMesh again = coherent.discretize(a);
  EXPECT_EQ(coherent.lastFrame().computed, 2u);
  ExpectSameMeshes(again, full.discretize(b), 1e-9, a.time());
}

// The Andyhausen model over its three instances: moving handles and egg, a static liquid, an
// eroding shell whose shape changes every frame and a blend whose operands move.
TEST(EngineCoherence, AndyhausenCoherentEqualsFullRemeshing)
{
  DynamicModel a = DynamicModel::load(ModelPath("andyhausen.icm"));
  const DynamicModel& b = a;
  a.start();
  CoherenceOptions options;
  options.featureSize = ictk::complex::defaultFeatureSize(a.complex());
  CoherentDiscretizer coherent(options);
  options.coherent = false;
  CoherentDiscretizer full(options);
  std::vector<std::string> instances;
  for (int k = 0; k <= 20; ++k)
  {
    const double t = 0.5 * k;
    if (t > a.time())
    {
      a.advanceTo(t, 0.1);
    }
    if (instances.empty() || instances.back() != a.activeInstance())
    {
      instances.push_back(a.activeInstance());
    }
    const complex::ComplexMesh ma = coherent.discretize(a);
    const complex::ComplexMesh mb = full.discretize(b);
    // Identical, bit for bit: kept meshes, moved meshes and the liquid's blocks kept from its
    // previous meshing are what meshing from scratch gives.
    ExpectSameMeshes(ma, mb, 0.0, t);
    if (k > 0)
    {
      // The barrel never moves nor changes: its first mesh serves every frame. The liquid's
      // noise changes its phase every frame (thesis L3627-L3633): it is meshed again, and as
      // its '&' is an R-function (f1 + f2 - sqrt(f1^2 + f2^2)), the noise term reaches every
      // block of it: its walls' vertices move too, and no block of it can be reused but those
      // known to be inside (which never evaluate the field).
      EXPECT_EQ(WorkOf(coherent, "Barrel"), CellWork::Reused) << "t = " << t;
      EXPECT_EQ(WorkOf(coherent, "Liquid"), CellWork::Computed) << "t = " << t;
    }
  }
  EXPECT_EQ(instances, (std::vector<std::string>{ "EGG_GOING_DOWN", "EGG_ERODING", "ANDY_OUT" }));
  const engine::CoherenceStats& s = coherent.total();
  EXPECT_EQ(s.frames, 21u);
  EXPECT_EQ(s.cells(), full.total().computed);
  EXPECT_GE(s.reused, 20u);
  EXPECT_GT(s.moved, 0u);
  EXPECT_LT(s.computed, s.cells() / 2);
}

// A pool like Andyhausen's liquid, but cut by min instead of HyperFun's '&': the noise on its
// top, whose phase a[1] = 2t changes every frame, is pruned away by interval arithmetic
// wherever the top cannot be the nearer side (min's other operand always smaller), so the
// blocks of its walls and bottom have pruned tapes that do not read a[1].
const char* kPool = R"(
name = POOL;
TIMESPANS { film : TIMESPAN(0, 2); }
CELLS {
  Pool {
    type = F-CELL;
    shape = hyperfun {
      pool(x[3], a[1])
      {
        pool = min(-0.5 - x[2] + 0.05 * sin(a[1]) * sin(4 * x[1]) * sin(4 * x[3]),
          1 - x[1]^2 - x[3]^2);
      }
    }
    dim = 3D;
    domain = { -1.1, -2, -1.1, 1.1, -0.25, 1.1 };
    parameters {
      phase : REAL(0.0);
    }
    REACTIONS {
      update(REAL globalT, REAL localT, REAL lifeT, REAL dt)
      {
        phase = 2.0 * globalT;
        setShapeParameter(Pool, "a[1]", phase);
      }
    }
  }
  Ball {
    type = F-CELL;
    shape = hyperfun {
      ball(x[3], a[1]) { ball = 0.09 - x[1]^2 - x[2]^2 - x[3]^2; }
    }
    dim = 3D;
    domain = { -0.3, -0.3, -0.3, 0.3, 0.3, 0.3 };
  }
}
K { CELLS { Pool Ball; } }
)";

// Coherence below the cell: the pool is meshed again in every frame (its shape version changes),
// but from its second meshing on it keeps its blocks, and the blocks whose pruned field does not
// read the phase (the walls and the bottom) are copied; the meshes stay those of a full
// re-meshing, bit for bit.
TEST(EngineCoherence, AParameterChangingCellReusesTheBlocksItCannotReach)
{
  DynamicModel a(lang::readIcm(kPool, "pool.icm"));
  const DynamicModel& b = a;
  a.start();
  CoherenceOptions options;
  options.featureSize = 0.05;
  CoherentDiscretizer coherent(options);
  options.coherent = false;
  CoherentDiscretizer full(options);
  std::size_t visited = 0;
  for (int k = 0; k <= 10; ++k)
  {
    const double t = 0.1 * k;
    if (t > a.time())
    {
      a.advanceTo(t, 0.1);
    }
    const complex::ComplexMesh ma = coherent.discretize(a);
    const complex::ComplexMesh mb = full.discretize(b);
    ExpectSameMeshes(ma, mb, 0.0, t);
    const engine::CoherenceStats& s = coherent.lastFrame();
    if (k == 0)
    {
      // Nothing is kept at the first meshing of a cell.
      EXPECT_EQ(s.computed, 2u);
      EXPECT_EQ(s.blocksContoured + s.blocksReused, 0u);
      continue;
    }
    EXPECT_EQ(WorkOf(coherent, "Pool"), CellWork::Computed) << "t = " << t;
    EXPECT_EQ(WorkOf(coherent, "Ball"), CellWork::Reused) << "t = " << t;
    if (k == 1)
    {
      // The second meshing keeps its blocks, with nothing to reuse yet.
      EXPECT_EQ(s.blocksReused, 0u);
      EXPECT_GT(s.blocksContoured, 0u);
      visited = s.blocksContoured;
      continue;
    }
    // The phase changes every frame: the top's blocks are contoured again, the rest copied.
    EXPECT_GT(s.blocksContoured, 0u) << "t = " << t;
    EXPECT_GT(s.blocksReused, s.blocksContoured) << "t = " << t;
    EXPECT_EQ(s.blocksContoured + s.blocksReused, visited) << "t = " << t;
    EXPECT_EQ(full.lastFrame().blocksContoured + full.lastFrame().blocksReused, 0u);
  }
}

// Thesis 5.1 (ch5_1_disk_rectangle.icm): in K3 the rectangle rests, the disk moves, and the chord,
// arc and half-disk are new shapes every frame.
TEST(EngineCoherence, DiskRectangleReusesWhatDidNotChange)
{
  DynamicModel m = DynamicModel::load(ModelPath("ch5_1_disk_rectangle.icm"));
  CoherenceOptions options;
  options.featureSize = 0.05;
  CoherentDiscretizer coherent(options);
  m.advanceTo(4.0, 0.1);
  ASSERT_EQ(m.activeInstance(), "K3");
  coherent.discretize(m);
  EXPECT_EQ(coherent.lastFrame().computed, coherent.lastFrame().cells());
  m.advanceTo(4.5, 0.1);
  const complex::ComplexMesh mesh = coherent.discretize(m);
  EXPECT_EQ(WorkOf(coherent, "DEQS"), CellWork::Reused);
  EXPECT_EQ(WorkOf(coherent, "LHKF"), CellWork::Moved);
  EXPECT_EQ(WorkOf(coherent, "KFL_arc"), CellWork::Computed);
  EXPECT_EQ(WorkOf(coherent, "KFL_half_disk"), CellWork::Computed);
  // The disk (radius 1) is centred at x = -2 + t = 2.5.
  const auto cells = m.cells();
  const complex::CellMesh& disk = mesh.of(static_cast<complex::CellId>(IndexOf(cells, "LHKF")));
  const frep::Point3 c = Centroid(disk.vertices());
  EXPECT_NEAR(c[0], 2.5, 0.02);
  EXPECT_NEAR(c[1], 0.0, 0.02);
  const double pi = std::acos(-1.0);
  EXPECT_NEAR(discretize::surfaceArea(disk.surface), pi, 0.02 * pi);
}

} // namespace
