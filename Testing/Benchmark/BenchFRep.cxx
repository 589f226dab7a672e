// SPDX-License-Identifier: BSD-3-Clause
// ICTK's grid sampling (sampleGrid, float output, all threads) against VTK's vtkSampleFunction on
// the same models, bounds and dimensions. sphere, csg3 and random1000 are built in VTK from the
// very recipes the ICTK models come from (vtkSphere, vtkBox, vtkCylinder, vtkImplicitBoolean);
// blend100 has no VTK equivalent. Before timing, both fields are sampled once and compared (ICTK =
// -VTK), so that the two sides compute the same thing.
//
//   ictkBenchFRep             all models at 128^3 and 256^3
//   ictkBenchFRep --quick     128^3 only, two iterations per case
//   ictkBenchFRep --benchmark_filter=csg3   (any Google Benchmark flag)
#include "FRep/BundledModels.h"
#include "FRep/ModelRegistry.h"
#include "FRep/Render.h"
#ifdef ICTK_HAVE_JIT
#include "FRep/Jit.h"
#endif
#include "FRep/Sampling.h"
#include "Lang/VmReader.h"

#include <benchmark/benchmark.h>
#include <tbb/info.h>

#include "ictkCsgRecipeToVtk.h"

#include <vtkDataArray.h>
#include <vtkImageData.h>
#include <vtkImplicitFunction.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkSMPTools.h>
#include <vtkSampleFunction.h>
#include <vtkSmartPointer.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

using namespace ictk::frep;
using bundled::CsgNode;
using bundled::CsgRecipe;

namespace
{
const char* const Models[] = { "sphere", "csg3", "blend100", "random1000" };

// The VTK side exists only for the models that VTK can express.
bool hasVtkRecipe(const std::string& model)
{
  return model == "sphere" || model == "csg3" || model == "random1000";
}

CsgRecipe recipeFor(const std::string& model)
{
  if (model == "sphere")
  {
    return bundled::sphereRecipe();
  }
  if (model == "csg3")
  {
    return bundled::csg3Recipe();
  }
  return bundled::random1000Recipe();
}

vtkSmartPointer<vtkSampleFunction> vtkSampler(const std::string& model, std::int64_t n)
{
  const ModelInfo& info = findModel(model);
  auto sample = vtkSmartPointer<vtkSampleFunction>::New();
  const CsgRecipe recipe = recipeFor(model);
  sample->SetImplicitFunction(ictkCsgRecipeToVtk(recipe));
  sample->SetModelBounds(info.boundsLo[0], info.boundsHi[0], info.boundsLo[1], info.boundsHi[1],
    info.boundsLo[2], info.boundsHi[2]);
  sample->SetSampleDimensions(static_cast<int>(n), static_cast<int>(n), static_cast<int>(n));
  sample->SetOutputScalarTypeToFloat();
  sample->ComputeNormalsOff();
  sample->CappingOff();
  return sample;
}

Grid ictkGrid(const std::string& model, std::int64_t n)
{
  const ModelInfo& info = findModel(model);
  return gridOverBox(info.boundsLo, info.boundsHi, { n, n, n });
}

TapePtr ictkTape(const std::string& model)
{
  return Tape::compile(findModel(model).build().geometry().function());
}

void benchIctk(benchmark::State& state, const std::string& model, std::int64_t n)
{
  const TapePtr tape = ictkTape(model);
  const Grid grid = ictkGrid(model, n);
  std::vector<float> out(static_cast<std::size_t>(grid.pointCount()));
  for (auto _ : state)
  {
    sampleGrid(tape, grid, out.data());
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  state.counters["points/s"] = benchmark::Counter(
    static_cast<double>(grid.pointCount()) * static_cast<double>(state.iterations()),
    benchmark::Counter::kIsRate);
}

void benchVtk(benchmark::State& state, const std::string& model, std::int64_t n)
{
  vtkSmartPointer<vtkSampleFunction> sample = vtkSampler(model, n);
  for (auto _ : state)
  {
    sample->Modified(); // force re-execution
    sample->Update();
    benchmark::DoNotOptimize(sample->GetOutput()->GetScalarPointer());
  }
  state.counters["points/s"] =
    benchmark::Counter(static_cast<double>(n * n * n) * static_cast<double>(state.iterations()),
      benchmark::Counter::kIsRate);
}

// ICTK's float field must be minus VTK's at the grid points. Returns false on a mismatch.
bool verify(const std::string& model, std::int64_t n)
{
  const Grid grid = ictkGrid(model, n);
  std::vector<float> ictk(static_cast<std::size_t>(grid.pointCount()));
  sampleGrid(ictkTape(model), grid, ictk.data());

  vtkSmartPointer<vtkSampleFunction> sample = vtkSampler(model, n);
  sample->Update();
  vtkImageData* image = sample->GetOutput();
  vtkDataArray* scalars = image->GetPointData()->GetScalars();
  if (!scalars || scalars->GetDataType() != VTK_FLOAT ||
    scalars->GetNumberOfTuples() != grid.pointCount())
  {
    std::printf("verify %-10s %lld^3: VTK output is not a float array of the grid's size\n",
      model.c_str(), static_cast<long long>(n));
    return false;
  }
  double geometry = 0; // largest difference between the two grids' point coordinates
  for (int a = 0; a < 3; ++a)
  {
    geometry = std::max(geometry, std::abs(image->GetOrigin()[a] - grid.origin[a]));
    geometry = std::max(geometry, std::abs(image->GetSpacing()[a] - grid.spacing[a]));
  }
  const float* vtk = static_cast<const float*>(scalars->GetVoidPointer(0));
  // Every 7th point (7 is prime to the row length, so all x positions are covered).
  double worst = 0, range = 0;
  std::int64_t worstIndex = 0, compared = 0;
  for (std::int64_t i = 0; i < grid.pointCount(); i += 7, ++compared)
  {
    const double d = std::abs(static_cast<double>(ictk[i]) + static_cast<double>(vtk[i]));
    range = std::max(range, std::abs(static_cast<double>(vtk[i])));
    if (!(d <= worst)) // also catches NaN
    {
      worst = d;
      worstIndex = i;
    }
  }
  // Both sides round to float; ICTK also computes in float. A few float ulps of the largest
  // intermediate (|p|^2 ~ 4 here) is the expected disagreement.
  const double tolerance = 1e-5 * std::max(1.0, range);
  const bool ok = worst <= tolerance && geometry < 1e-12;
  std::printf(
    "verify %-10s %lld^3: ICTK = -VTK at %lld points, max |ICTK + VTK| = %.3g at point %lld "
    "(|field| <= %.3g, tolerance %.3g), grid geometry difference %.3g: %s\n",
    model.c_str(), static_cast<long long>(n), static_cast<long long>(compared), worst,
    static_cast<long long>(worstIndex), range, tolerance, geometry, ok ? "OK" : "MISMATCH");
  return ok;
}

// The workloads of `ictk bench` (issue 7), for profiling: prospero.vm rendered at 1024^2 by brute
// force (1 thread) and by interval pruning (2 threads), when Fidget's models are found
// ($ICTK_BENCH_MODELS, else ICTK_BENCH_MODELS_DIR); csg3 sampled at 512^3 (ICTK only).
void registerPerformanceWorkloads(bool quick)
{
  const char* env = std::getenv("ICTK_BENCH_MODELS");
  const std::filesystem::path file =
    std::filesystem::path(env ? env : ICTK_BENCH_MODELS_DIR) / "prospero.vm";
  if (std::filesystem::exists(file))
  {
    const TapePtr tape = Tape::compile(ictk::lang::readVmFile(file.string()).function);
    for (const bool prune : { false, true })
    {
      const std::string name =
        std::string("ictk/prospero-") + (prune ? "pruned" : "brute") + "/1024";
      benchmark::RegisterBenchmark(name.c_str(),
        [tape, prune](benchmark::State& state)
        {
          RenderOptions options;
          options.prune = prune;
          options.threads = prune ? 2 : 1;
          for (auto _ : state)
          {
            benchmark::DoNotOptimize(renderSign2D(tape, RenderRegion{}, 1024, 1024, options));
          }
        })
        ->UseRealTime()
        ->Unit(benchmark::kMillisecond);
    }
    // Tile sizes of the pruned render by measured cost (issue 20), 1 thread, the interpreter and
    // the JIT: ictk/prospero-pruned-tiles/<sizes>/<interpreter|jit>, with the leaves and their
    // mean tape length as counters.
    const std::vector<std::vector<int>> tilings{ { 128, 32 }, { 256, 64 }, { 256, 128 },
      { 128, 64 }, { 64, 16 }, { 256, 64, 16 }, { 128, 32, 8 } };
    for (const auto& tiles : tilings)
    {
      for (const bool jit : { false, true })
      {
#ifdef ICTK_HAVE_JIT
        if (jit && !ictk::frep::JitEvaluator::available())
        {
          continue;
        }
#else
        if (jit)
        {
          continue;
        }
#endif
        std::string name = "ictk/prospero-pruned-tiles/";
        for (std::size_t i = 0; i < tiles.size(); ++i)
        {
          name += (i ? "," : "") + std::to_string(tiles[i]);
        }
        name += jit ? "/jit" : "/interpreter";
        benchmark::RegisterBenchmark(name.c_str(),
          [tape, tiles, jit](benchmark::State& state)
          {
            RenderOptions options;
            options.threads = 1;
            options.tileSizes = tiles;
#ifdef ICTK_HAVE_JIT
            if (jit)
            {
              options.rowEvaluator = ictk::frep::jitRowEvaluatorFactory();
            }
#endif
            for (auto _ : state)
            {
              benchmark::DoNotOptimize(renderSign2D(tape, RenderRegion{}, 1024, 1024, options));
            }
            RenderStats stats;
            options.stats = &stats;
            renderSign2D(tape, RenderRegion{}, 1024, 1024, options);
            state.counters["leaves"] = static_cast<double>(stats.tilesEvaluated);
            state.counters["leafTape"] = stats.tilesEvaluated
              ? static_cast<double>(stats.leafInstructions) /
                static_cast<double>(stats.tilesEvaluated)
              : 0.0;
          })
          ->Unit(benchmark::kMillisecond);
      }
    }
  }
  else
  {
    std::printf("%s not found: the prospero workloads are skipped\n", file.string().c_str());
  }
  if (!quick)
  {
    benchmark::RegisterBenchmark(
      "ictk/csg3/512", [](benchmark::State& s) { benchIctk(s, "csg3", 512); })
      ->UseRealTime()
      ->Unit(benchmark::kMillisecond);
  }
}

/// Passes everything to the console and keeps the real time of each case for the final table.
class TableReporter : public benchmark::ConsoleReporter
{
public:
  explicit TableReporter(bool colour)
    : ConsoleReporter(colour ? OO_ColorTabular : OO_Tabular)
  {
  }

  struct Key
  {
    std::string model;
    std::int64_t n;
    bool operator<(const Key& o) const { return model != o.model ? model < o.model : n < o.n; }
  };
  struct Row
  {
    double ictk = -1; // Mpts/s, -1 = not run
    double vtk = -1;
  };

  void ReportRuns(const std::vector<Run>& runs) override
  {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& run : runs)
    {
      if (run.error_occurred || run.run_type != Run::RT_Iteration || run.iterations == 0)
      {
        continue;
      }
      // Names are "<impl>/<model>/<n>[/real_time]".
      std::istringstream name(run.benchmark_name());
      std::string impl, model, size;
      std::getline(name, impl, '/');
      std::getline(name, model, '/');
      std::getline(name, size, '/');
      const std::int64_t n = std::stoll(size);
      const double seconds = run.real_accumulated_time / static_cast<double>(run.iterations);
      const double mpts = static_cast<double>(n * n * n) / seconds * 1e-6;
      Row& row = rows[Key{ model, n }];
      double& slot = impl == "ictk" ? row.ictk : row.vtk;
      slot = std::max(slot, mpts); // with repetitions, keep the best run
    }
  }

  std::map<Key, Row> rows;
};

void printTable(const TableReporter& reporter)
{
  std::printf("\n%-12s %10s %14s %14s %12s\n", "model", "resolution", "ICTK Mpts/s", "VTK Mpts/s",
    "ICTK/VTK");
  for (const char* model : Models)
  {
    for (const auto& entry : reporter.rows)
    {
      if (entry.first.model != model)
      {
        continue;
      }
      const TableReporter::Row& r = entry.second;
      const std::string res = std::to_string(entry.first.n) + "^3";
      char ictk[32] = "-", vtk[32] = "n/a", ratio[32] = "-";
      if (r.ictk >= 0)
      {
        std::snprintf(ictk, sizeof ictk, "%.1f", r.ictk);
      }
      if (r.vtk >= 0)
      {
        std::snprintf(vtk, sizeof vtk, "%.1f", r.vtk);
      }
      else if (hasVtkRecipe(model))
      {
        std::snprintf(vtk, sizeof vtk, "-");
      }
      if (r.ictk >= 0 && r.vtk > 0)
      {
        std::snprintf(ratio, sizeof ratio, "%.1fx", r.ictk / r.vtk);
      }
      std::printf("%-12s %10s %14s %14s %12s\n", model, res.c_str(), ictk, vtk, ratio);
    }
  }
}
} // namespace

int main(int argc, char** argv)
{
  bool quick = false;
  // A reporter passed to RunSpecifiedBenchmarks ignores --benchmark_color, so honour it here
  // (default "auto": colour only on a terminal).
  bool colour = isatty(STDOUT_FILENO) != 0;
  std::vector<char*> args;
  for (int i = 0; i < argc; ++i)
  {
    const std::string arg = argv[i];
    if (arg == "--quick")
    {
      quick = true;
      continue;
    }
    if (arg.rfind("--benchmark_color=", 0) == 0)
    {
      const std::string v = arg.substr(std::strlen("--benchmark_color="));
      colour = v == "auto" ? colour : (v == "true" || v == "yes" || v == "1");
    }
    args.push_back(argv[i]);
  }
  int count = static_cast<int>(args.size());
  benchmark::Initialize(&count, args.data());
  if (benchmark::ReportUnrecognizedArguments(count, args.data()))
  {
    return 1;
  }

  vtkSMPTools::Initialize(0); // all threads, like sampleGrid's default
  std::printf("threads: ICTK (TBB) %d, VTK (vtkSMPTools backend %s) %d\n",
    tbb::info::default_concurrency(), vtkSMPTools::GetBackend(),
    vtkSMPTools::GetEstimatedNumberOfThreads());
  for (const char* model : Models)
  {
    const Expr f = findModel(model).build().geometry().function();
    std::printf("model %-10s %5zu DAG nodes, %5zu tape instructions\n", model, f.nodeCount(),
      Tape::compile(f)->instructions().size());
  }

  // Apples to apples: the fields agree before anything is timed.
  bool agree = true;
  for (const char* model : Models)
  {
    if (hasVtkRecipe(model))
    {
      agree = verify(model, quick ? 64 : 128) && agree;
    }
  }

  const std::vector<std::int64_t> sizes =
    quick ? std::vector<std::int64_t>{ 128 } : std::vector<std::int64_t>{ 128, 256 };
  for (const char* model : Models)
  {
    for (std::int64_t n : sizes)
    {
      const std::string suffix = std::string(model) + "/" + std::to_string(n);
      std::vector<benchmark::internal::Benchmark*> cases;
      cases.push_back(benchmark::RegisterBenchmark(
        ("ictk/" + suffix).c_str(), [model, n](benchmark::State& s) { benchIctk(s, model, n); }));
      if (hasVtkRecipe(model))
      {
        cases.push_back(benchmark::RegisterBenchmark(
          ("vtk/" + suffix).c_str(), [model, n](benchmark::State& s) { benchVtk(s, model, n); }));
      }
      for (benchmark::internal::Benchmark* b : cases)
      {
        // Real time: both sides run on several threads, CPU time of the main thread means nothing.
        b->UseRealTime()->Unit(benchmark::kMillisecond);
        if (quick)
        {
          b->Iterations(2);
        }
      }
    }
  }

  registerPerformanceWorkloads(quick);

  TableReporter reporter(colour);
  benchmark::RunSpecifiedBenchmarks(&reporter);
  printTable(reporter);
  benchmark::Shutdown();
  if (!agree)
  {
    std::printf("\nWARNING: ICTK and VTK fields disagree (see the verify lines above)\n");
    return 2;
  }
  return 0;
}
