// SPDX-License-Identifier: BSD-3-Clause
#include "BenchDynamics.h"
#include "ProgressDisplay.h"

#include "Engine/CoherentDiscretizer.h"
#include "Engine/DynamicModel.h"

#include <chrono>

namespace ictk::cli
{
DynamicRunTiming TimeDynamicRun(const std::string& path, double t1, int steps, int divisions,
  bool coherent, int runs, int threads)
{
  DynamicRunTiming out;
  for (int run = 0; run < runs; ++run)
  {
    const double c0 = CpuSeconds();
    const auto t0 = std::chrono::steady_clock::now();
    double engineSeconds = 0;
    auto mark = std::chrono::steady_clock::now();
    engine::DynamicModel model = engine::DynamicModel::load(path);
    model.start();
    engine::CoherenceOptions options;
    options.coherent = coherent;
    options.threads = threads;
    // defaultFeatureSize is 1/64 of the largest side.
    options.featureSize = complex::defaultFeatureSize(model.complex()) * 64.0 / divisions;
    engine::CoherentDiscretizer mesher(options);
    const double start = model.time();
    engineSeconds += Seconds(mark);
    std::size_t points = 0;
    std::vector<std::string> instances;
    for (int k = 0; k <= steps; ++k)
    {
      mark = std::chrono::steady_clock::now();
      const double t = start + (t1 - start) * k / steps;
      if (t > model.time())
      {
        model.advanceTo(t, (t1 - start) / steps);
      }
      engineSeconds += Seconds(mark);
      if (instances.empty() || instances.back() != model.activeInstance())
      {
        instances.push_back(model.activeInstance());
      }
      const complex::ComplexMesh mesh = mesher.discretize(model);
      for (const complex::CellMesh& m : mesh.cells)
      {
        points += m.vertices().size();
      }
    }
    out.seconds.push_back(Seconds(t0));
    out.cpuSeconds.push_back(CpuSeconds() - c0);
    out.engineSeconds = engineSeconds;
    out.meshSeconds = mesher.total().seconds;
    out.frames = static_cast<std::size_t>(steps) + 1;
    out.points = points;
    out.computed = mesher.total().computed;
    out.moved = mesher.total().moved;
    out.reused = mesher.total().reused;
    out.blocksContoured = mesher.total().blocksContoured;
    out.blocksReused = mesher.total().blocksReused;
    out.featureSize = mesher.featureSize();
    out.instances = instances;
  }
  return out;
}

} // namespace ictk::cli
