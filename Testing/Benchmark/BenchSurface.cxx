// SPDX-License-Identifier: BSD-3-Clause
// Dual contouring (Discretize/Surface.h) of libfive's mesh benchmark "sphereGyroid" over
// [-5, 5]^3 at feature sizes 0.1, 0.05 and 0.025, on 2 threads (libfive: 4.74 s at 0.025 on this
// class of machine). Each case reports the triangle and point counts and whether the mesh is a
// closed manifold (checked once, outside the timed loop).
//
//   ictkBenchSurface                                  all three sizes
//   ictkBenchSurface --benchmark_filter=0.025         (any Google Benchmark flag)
//   ICTK_BENCH_THREADS=1 ictkBenchSurface             another thread count
#include "Discretize/Surface.h"
#include "FRep/BundledModels.h"
#include "FRep/Field.h"
#include "FRep/Tape.h"

#include <benchmark/benchmark.h>

#include <cstdlib>

using namespace ictk;

namespace
{

int threads()
{
  const char* env = std::getenv("ICTK_BENCH_THREADS");
  return env ? std::atoi(env) : 2;
}

void sphereGyroid(benchmark::State& state, double featureSize)
{
  const frep::FieldPtr field =
    frep::tapeField(frep::Tape::compile(frep::bundled::sphereGyroidField()));
  const frep::Box3 box{ { -5, -5, -5 }, { 5, 5, 5 } };
  discretize::SurfaceOptions options;
  options.featureSize = featureSize;
  options.threads = threads();
  discretize::SurfaceMesh mesh;
  for (auto _ : state)
  {
    mesh = discretize::contourSurface(*field, box, options);
    benchmark::DoNotOptimize(mesh.triangles.data());
  }
  const discretize::MeshTopology t = discretize::analyzeTopology(mesh);
  state.counters["threads"] = options.threads;
  state.counters["triangles"] = static_cast<double>(mesh.triangles.size());
  state.counters["points"] = static_cast<double>(mesh.points.size());
  state.counters["manifold"] = t.manifold() ? 1 : 0;
  state.counters["closed"] = t.closed() ? 1 : 0;
  state.counters["euler"] = static_cast<double>(t.eulerCharacteristic);
}

} // namespace

BENCHMARK_CAPTURE(sphereGyroid, 0.1, 0.1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(sphereGyroid, 0.05, 0.05)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(sphereGyroid, 0.025, 0.025)
  ->Unit(benchmark::kMillisecond)
  ->UseRealTime()
  ->MinTime(3.0);

BENCHMARK_MAIN();
