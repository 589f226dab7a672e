// SPDX-License-Identifier: BSD-3-Clause
// The reaction library's geometric queries (Geometry/Queries.h) on the shapes of the thesis
// exemplars: analytic disk/rectangle pairs, HyperFun-style field disks and spheres, and the egg
// sinking into the liquid of Data/Models/icm/andyhausen.icm. These ran as wall-clock checks inside
// TestGeometry before; a timing on a shared machine is not a pass/fail test, so they are reported
// here (`ictkBenchGeometry`, never run by ctest).
#include "GeometryTestShapes.h"

#include "Geometry/Queries.h"

#include <benchmark/benchmark.h>

#include <cmath>

namespace
{

using namespace ictk;
using namespace ictk::geometry::testing;
using frep::Expr;
using geometry::PlacedShape;
using geometry::ShapePart;

const PlacedShape& diskNearRectangle()
{
  static const PlacedShape s = disk(1, at(1 + 1e-3, 0));
  return s;
}
const PlacedShape& fieldDiskNearRectangle()
{
  static const PlacedShape s = fieldDisk(1, at(1 + 1e-3, 0));
  return s;
}
const PlacedShape& rectangleBeside()
{
  static const PlacedShape s = rectangle(2, 2, at(3, 0));
  return s;
}

void AnalyticIntersectionPoints(benchmark::State& state)
{
  for (auto _ : state)
    benchmark::DoNotOptimize(geometry::intersectionPoints(diskNearRectangle(), rectangleBeside()));
}
BENCHMARK(AnalyticIntersectionPoints)->Unit(benchmark::kMicrosecond);

void AnalyticDistance(benchmark::State& state)
{
  for (auto _ : state)
    benchmark::DoNotOptimize(geometry::distance(diskNearRectangle(), rectangleBeside()));
}
BENCHMARK(AnalyticDistance)->Unit(benchmark::kMicrosecond);

void AnalyticIntersectionArea(benchmark::State& state)
{
  for (auto _ : state)
    benchmark::DoNotOptimize(geometry::intersectionMeasure(diskNearRectangle(), rectangleBeside()));
}
BENCHMARK(AnalyticIntersectionArea)->Unit(benchmark::kMicrosecond);

void FieldIntersectionPoints(benchmark::State& state)
{
  for (auto _ : state)
    benchmark::DoNotOptimize(
      geometry::intersectionPoints(fieldDiskNearRectangle(), rectangleBeside()));
}
BENCHMARK(FieldIntersectionPoints)->Unit(benchmark::kMicrosecond);

void FieldIntersects(benchmark::State& state)
{
  for (auto _ : state)
    benchmark::DoNotOptimize(geometry::intersects(fieldDiskNearRectangle(), rectangleBeside()));
}
BENCHMARK(FieldIntersects)->Unit(benchmark::kMicrosecond);

void FieldIntersectionArea(benchmark::State& state)
{
  for (auto _ : state)
    benchmark::DoNotOptimize(
      geometry::intersectionMeasure(fieldDiskNearRectangle(), rectangleBeside()));
}
BENCHMARK(FieldIntersectionArea)->Unit(benchmark::kMicrosecond);

void FieldFieldIntersectionPoints(benchmark::State& state)
{
  const PlacedShape a = fieldDisk(1, {}), b = fieldDisk(1, at(1, 0));
  for (auto _ : state)
    benchmark::DoNotOptimize(geometry::intersectionPoints(a, b));
}
BENCHMARK(FieldFieldIntersectionPoints)->Unit(benchmark::kMicrosecond);

void FieldSpheresDistance(benchmark::State& state)
{
  const PlacedShape a = fieldSphere(0.5, at(-0.75, 0, 0)), b = fieldSphere(0.5, at(0.75, 0, 0));
  for (auto _ : state)
    benchmark::DoNotOptimize(geometry::distance(a, b));
}
BENCHMARK(FieldSpheresDistance)->Unit(benchmark::kMicrosecond);

void FieldContains(benchmark::State& state)
{
  const PlacedShape a = fieldDisk(1, {}), b = fieldDisk(0.5, at(0.4, 0));
  for (auto _ : state)
    benchmark::DoNotOptimize(geometry::contains(a, b));
}
BENCHMARK(FieldContains)->Unit(benchmark::kMicrosecond);

// The liquid of andyhausen.icm and its egg (semi-axes 0.5, 0.7, 0.5, eroded by 0.2 a) with the
// centre at height c; the liquid holds the egg once its top c + 0.7 sqrt(1 - 0.2 a) <= -3.2.
PlacedShape liquid()
{
  const Expr x = Expr::x(), y = Expr::y(), z = Expr::z();
  ShapePart p;
  p.kind = ShapePart::Kind::Field;
  p.field = fieldOf(min(-3.2 - y, 4 - x * x - z * z));
  p.bounds = { { -2, -5, -2 }, { 2, -3.2, 2 } };
  return shapeOf("Liquid", 3, p);
}
PlacedShape egg(double c, double a = 0)
{
  const Expr x = Expr::x(), y = Expr::y(), z = Expr::z();
  ShapePart p;
  p.kind = ShapePart::Kind::Field;
  p.field = fieldOf(1 - square(x / 0.5) - square(y / 0.7) - square(z / 0.5) - 0.2 * a);
  p.bounds = { { -0.5, -0.7, -0.5 }, { 0.5, 0.7, 0.5 } };
  return shapeOf("Eggshell", 3, p, at(0, c, 0));
}

void EggLiquidVolume(benchmark::State& state)
{
  const PlacedShape pool = liquid(), half = egg(-3.2);
  for (auto _ : state)
    benchmark::DoNotOptimize(geometry::intersectionMeasure(pool, half));
}
BENCHMARK(EggLiquidVolume)->Unit(benchmark::kMillisecond);

void EggLiquidQueries(benchmark::State& state)
{
  const PlacedShape pool = liquid(), above = egg(-2), below = egg(-4);
  for (auto _ : state)
  {
    benchmark::DoNotOptimize(geometry::distance(pool, above));
    benchmark::DoNotOptimize(geometry::intersects(pool, above));
    benchmark::DoNotOptimize(geometry::contains(pool, below));
  }
}
BENCHMARK(EggLiquidQueries)->Unit(benchmark::kMicrosecond);

// contains() just inside and just outside the exact flip (1e-7 away), where the proof is hardest.
void EggContainsNearFlip(benchmark::State& state)
{
  const double a = 0.8, exact = -3.2 - 0.7 * std::sqrt(1 - 0.2 * a);
  const PlacedShape pool = liquid(), in = egg(exact - 1e-7, a), out = egg(exact + 1e-7, a);
  for (auto _ : state)
  {
    benchmark::DoNotOptimize(geometry::contains(pool, in));
    benchmark::DoNotOptimize(geometry::contains(pool, out));
  }
}
BENCHMARK(EggContainsNearFlip)->Unit(benchmark::kMicrosecond);

} // namespace

BENCHMARK_MAIN();
