// SPDX-License-Identifier: BSD-3-Clause
// `ictk bench --scaling` (issue 7, "Scaling"): time and work counters of
//   - dense sampling (frep::sampleGrid), with and without interval pruning,
//   - the pruned sign render (frep::renderSign2D / renderSign3D),
//   - dual contouring (discretize::contourSurface),
// against the model size (bundled::randomCsgRecipe with about 100, 1k, 10k, 100k tape
// instructions) and against the resolution (a fixed model, random1000). The counters come from
// RenderStats, SampleStats and, for contouring, a field wrapper that counts the points and boxes
// the contourer asks for. Pruned work should grow with the surface (r^2 in 3D, r in 2D), not with
// the volume.
#include "BenchScaling.h"
#include "BenchDynamics.h"
#include "Command.h"
#include "ProgressDisplay.h"

#include "Discretize/Surface.h"
#include "FRep/BundledModels.h"
#include "FRep/Field.h"
#include "FRep/Render.h"
#include "FRep/Sampling.h"
#include "Voxel/NarrowBand.h"

#include <nlohmann/json.hpp>

#include <sys/resource.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <functional>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <unistd.h>

namespace ictk::cli
{

namespace
{
namespace frep = ictk::frep;
namespace bundled = ictk::frep::bundled;

bool Scaling = false;
std::string ScalePoint; // --scale-point KIND=VALUE
// Primitive counts of the model-size table: about 100, 1k, 10k and 100k tape instructions.
std::vector<int> PrimitiveCounts{ 6, 62, 628, 7940 };
constexpr std::uint32_t ScalingSeed = 20240611u; // random1000's seed
constexpr double BoxHalf = 1.2;                  // the models' box: [-1.2, 1.2]^3

struct Timing
{
  double wall = 0; ///< seconds, median
  double cpu = 0;  ///< process CPU seconds, median
  int runs = 0;
};

/// A first run; when it took more than a second it is the only one, otherwise it is a warm-up
/// and `runs` timed runs follow (medians reported).
Timing Measure(int runs, const std::function<void()>& f)
{
  std::vector<double> wall, cpu;
  auto once = [&]
  {
    const double c0 = CpuSeconds();
    const auto t0 = std::chrono::steady_clock::now();
    f();
    wall.push_back(Seconds(t0));
    cpu.push_back(CpuSeconds() - c0);
  };
  once();
  if (wall.front() <= 1.0)
  {
    wall.clear();
    cpu.clear();
    for (int i = 0; i < runs; ++i)
    {
      once();
    }
  }
  return { Median(wall), Median(cpu), static_cast<int>(wall.size()) };
}

// --- counting field (what the contourer asks for) ------------------------------------------------

struct FieldCounters
{
  std::atomic<std::int64_t> points{ 0 };    ///< values() points
  std::atomic<std::int64_t> gradients{ 0 }; ///< gradient() calls
  std::atomic<std::int64_t> bounds{ 0 };    ///< bound() calls (interval evaluations)
  std::atomic<std::int64_t> narrowed{ 0 };  ///< pruned evaluators made
};

class CountingEvaluator : public frep::FieldEvaluator
{
public:
  CountingEvaluator(std::unique_ptr<frep::FieldEvaluator> inner, FieldCounters* counters)
    : inner_(std::move(inner))
    , counters_(counters)
  {
  }
  void values(
    const double* x, const double* y, const double* z, double* out, std::size_t n) override
  {
    counters_->points += static_cast<std::int64_t>(n);
    inner_->values(x, y, z, out, n);
  }
  frep::Interval bound(const frep::Box3& box) override
  {
    ++counters_->bounds;
    return inner_->bound(box);
  }
  double gradient(const frep::Point3& p, frep::Point3& grad) override
  {
    ++counters_->gradients;
    return inner_->gradient(p, grad);
  }
  std::unique_ptr<frep::FieldEvaluator> narrowed(const frep::Box3& box) override
  {
    std::unique_ptr<frep::FieldEvaluator> n = inner_->narrowed(box);
    if (!n)
    {
      return nullptr;
    }
    ++counters_->narrowed;
    return std::make_unique<CountingEvaluator>(std::move(n), counters_);
  }

private:
  std::unique_ptr<frep::FieldEvaluator> inner_;
  FieldCounters* counters_;
};

class CountingField : public frep::Field
{
public:
  CountingField(frep::FieldPtr inner, FieldCounters* counters)
    : inner_(std::move(inner))
    , counters_(counters)
  {
  }
  std::unique_ptr<frep::FieldEvaluator> evaluator() const override
  {
    return std::make_unique<CountingEvaluator>(inner_->evaluator(), counters_);
  }

private:
  frep::FieldPtr inner_;
  FieldCounters* counters_;
};

// --- tables
// ----------------------------------------------------------------------------------------

struct Table
{
  Table(std::string t, std::vector<std::string> c)
    : title(std::move(t))
    , columns(std::move(c))
  {
  }
  std::string title;
  std::vector<std::string> columns;
  std::vector<std::vector<std::string>> rows;
  nlohmann::json json = nlohmann::json::array();
};

std::string Fixed(double v, int digits)
{
  std::ostringstream os;
  os.setf(std::ios::fixed);
  os.precision(digits);
  os << v;
  return os.str();
}

std::string Ms(double seconds)
{
  return Fixed(seconds * 1e3, seconds < 0.01 ? 2 : 1);
}

std::string Ratio(double now, double before)
{
  return before > 0 ? Fixed(now / before, 2) : "";
}

void Print(const Table& t)
{
  std::cout << "\n" << t.title << "\n\n|";
  for (const std::string& c : t.columns)
  {
    std::cout << " " << c << " |";
  }
  std::cout << "\n|";
  for (std::size_t i = 0; i < t.columns.size(); ++i)
  {
    std::cout << "---|";
  }
  std::cout << "\n";
  for (const auto& row : t.rows)
  {
    std::cout << "|";
    for (const std::string& cell : row)
    {
      std::cout << " " << cell << " |";
    }
    std::cout << "\n";
  }
  std::cout << std::flush;
}

frep::TapePtr RandomCsgTape(int primitives)
{
  return frep::Tape::compile(bundled::csgField(bundled::randomCsgRecipe(primitives, ScalingSeed)));
}

const frep::Box3 ModelBox{ { -BoxHalf, -BoxHalf, -BoxHalf }, { BoxHalf, BoxHalf, BoxHalf } };

struct SampleRun
{
  Timing timing;
  frep::SampleStats stats;
};

SampleRun Sample(const frep::TapePtr& tape, int resolution, bool prune, int threads, int runs)
{
  const frep::Grid grid =
    frep::gridOverBox(ModelBox.lo, ModelBox.hi, { resolution, resolution, resolution });
  std::vector<float> out(static_cast<std::size_t>(grid.pointCount()));
  frep::SampleOptions options;
  options.threads = threads;
  options.prune = prune;
  SampleRun r;
  options.stats = &r.stats; // the counters cost one atomic add per brick
  r.timing = Measure(runs, [&] { frep::sampleGrid(tape, grid, out.data(), options); });
  return r;
}

struct RenderRun
{
  Timing timing;
  frep::RenderStats stats;
  std::int64_t inside = 0;
};

const std::vector<int> Tiles3D{ 32, 8 };

RenderRun Render(const frep::TapePtr& tape, int resolution, int dimensions, int threads, int runs)
{
  frep::RenderRegion region;
  region.lo = { -BoxHalf, -BoxHalf, dimensions == 2 ? 0.0 : -BoxHalf };
  region.hi = { BoxHalf, BoxHalf, dimensions == 2 ? 0.0 : BoxHalf };
  frep::RenderOptions options;
  options.threads = threads;
  if (dimensions == 3)
  {
    options.tileSizes = Tiles3D;
  }
  std::vector<std::uint8_t> image;
  auto render = [&]
  {
    image = dimensions == 2
      ? frep::renderSign2D(tape, region, resolution, resolution, options)
      : frep::renderSign3D(tape, region, { resolution, resolution, resolution }, options);
  };
  RenderRun r;
  options.stats = &r.stats; // summed once per render
  r.timing = Measure(runs, render);
  for (std::uint8_t v : image)
  {
    r.inside += v;
  }
  return r;
}

struct ContourRun
{
  Timing timing;
  std::int64_t points = 0, gradients = 0, bounds = 0, narrowed = 0;
  std::size_t triangles = 0;
};

ContourRun Contour(const frep::TapePtr& tape, double featureSize, int threads, int runs)
{
  const frep::FieldPtr field = frep::tapeField(tape);
  discretize::SurfaceOptions options;
  options.featureSize = featureSize;
  options.threads = threads;
  ContourRun r;
  discretize::SurfaceMesh mesh;
  r.timing = Measure(runs, [&] { mesh = discretize::contourSurface(*field, ModelBox, options); });
  FieldCounters counters;
  const CountingField counting(field, &counters);
  mesh = discretize::contourSurface(counting, ModelBox, options);
  r.points = counters.points;
  r.gradients = counters.gradients;
  r.bounds = counters.bounds;
  r.narrowed = counters.narrowed;
  r.triangles = mesh.triangles.size();
  return r;
}

std::string Count(std::int64_t v)
{
  return std::to_string(v);
}

std::string PerPoint(std::int64_t instructions, std::int64_t points)
{
  return points > 0 ? Fixed(static_cast<double>(instructions) / static_cast<double>(points), 1)
                    : "";
}

// --- the tables ----------------------------------------------------------------------------------

std::vector<Table> ModelSizeTables(const std::vector<int>& primitives, int sampleSize,
  int renderSize, double featureSize, int threads, int runs)
{
  Table models{ "Models: bundled::randomCsgRecipe(primitives, 20240611)",
    { "primitives", "tape instructions", "min/max (choices)" } };
  Table sampling{ "Dense sampling, frep::sampleGrid at " + std::to_string(sampleSize) +
      "^3 (float), [-1.2,1.2]^3",
    { "instructions", "full ms", "full CPU ms", "pruned ms", "pruned CPU ms",
      "pruned instructions/point", "speed-up" } };
  Table render{ "Pruned 2D sign render, frep::renderSign2D at " + std::to_string(renderSize) +
      "^2 (tiles 128, 32), z = 0",
    { "instructions", "ms", "CPU ms", "pixels evaluated", "% of pixels", "leaf tiles",
      "mean leaf tape" } };
  std::ostringstream fs;
  fs << featureSize;
  Table contour{ "Dual contouring, discretize::contourSurface at feature size " + fs.str() +
      " over [-1.2,1.2]^3",
    { "instructions", "ms", "CPU ms", "points evaluated", "interval bounds", "gradients",
      "triangles" } };
  for (int p : primitives)
  {
    const frep::TapePtr tape = RandomCsgTape(p);
    const std::int64_t n = static_cast<std::int64_t>(tape->instructions().size());
    std::cerr << "scaling: " << p << " primitives, " << n << " instructions\n";
    models.rows.push_back(
      { Count(p), Count(n), Count(static_cast<std::int64_t>(tape->choiceCount())) });
    models.json.push_back(
      { { "primitives", p }, { "tape_instructions", n }, { "choices", tape->choiceCount() } });

    const SampleRun full = Sample(tape, sampleSize, false, threads, runs);
    const SampleRun pruned = Sample(tape, sampleSize, true, threads, runs);
    sampling.rows.push_back({ Count(n), Ms(full.timing.wall), Ms(full.timing.cpu),
      Ms(pruned.timing.wall), Ms(pruned.timing.cpu),
      PerPoint(pruned.stats.instructionEvaluations, pruned.stats.pointsEvaluated),
      Fixed(full.timing.cpu / pruned.timing.cpu, 1) + "x" });
    sampling.json.push_back({ { "tape_instructions", n }, { "resolution", sampleSize },
      { "full_seconds", full.timing.wall }, { "full_cpu_seconds", full.timing.cpu },
      { "pruned_seconds", pruned.timing.wall }, { "pruned_cpu_seconds", pruned.timing.cpu },
      { "points", pruned.stats.pointsEvaluated },
      { "full_instruction_evaluations", full.stats.instructionEvaluations },
      { "pruned_instruction_evaluations", pruned.stats.instructionEvaluations } });

    const RenderRun r2 = Render(tape, renderSize, 2, threads, runs);
    const double pixels = static_cast<double>(renderSize) * renderSize;
    render.rows.push_back(
      { Count(n), Ms(r2.timing.wall), Ms(r2.timing.cpu), Count(r2.stats.pixelsEvaluated),
        Fixed(100.0 * static_cast<double>(r2.stats.pixelsEvaluated) / pixels, 1),
        Count(r2.stats.tilesEvaluated),
        PerPoint(r2.stats.leafInstructions, r2.stats.tilesEvaluated) });
    render.json.push_back({ { "tape_instructions", n }, { "resolution", renderSize },
      { "seconds", r2.timing.wall }, { "cpu_seconds", r2.timing.cpu },
      { "pixels_evaluated", r2.stats.pixelsEvaluated }, { "tiles_filled", r2.stats.tilesFilled },
      { "leaf_tiles_evaluated", r2.stats.tilesEvaluated },
      { "leaf_instructions", r2.stats.leafInstructions } });

    const ContourRun c = Contour(tape, featureSize, threads, runs);
    contour.rows.push_back({ Count(n), Ms(c.timing.wall), Ms(c.timing.cpu), Count(c.points),
      Count(c.bounds), Count(c.gradients), Count(static_cast<std::int64_t>(c.triangles)) });
    contour.json.push_back(
      { { "tape_instructions", n }, { "feature_size", featureSize }, { "seconds", c.timing.wall },
        { "cpu_seconds", c.timing.cpu }, { "points_evaluated", c.points },
        { "interval_bounds", c.bounds }, { "gradients", c.gradients },
        { "pruned_evaluators", c.narrowed }, { "triangles", c.triangles } });
  }
  return { models, sampling, render, contour };
}

std::vector<Table> ResolutionTables(const std::vector<int>& sampleSizes,
  const std::vector<int>& renderSizes, const std::vector<double>& featureSizes, int threads,
  int runs)
{
  const frep::TapePtr tape = frep::Tape::compile(bundled::csgField(bundled::random1000Recipe()));
  const std::string model =
    "random1000 (" + std::to_string(tape->instructions().size()) + " tape instructions)";
  Table sampling{ "Dense sampling of " + model + " vs resolution (float, bricks 64x16x16)",
    { "r", "points (r^3)", "full ms", "full CPU ms", "pruned ms", "pruned CPU ms",
      "full instr. evals", "pruned instr. evals", "pruned / previous", "pruned instr./point" } };
  Table occupancy{ "Pruned 3D sign (occupancy), frep::renderSign3D of " + model +
      " vs resolution (tiles 32, 8)",
    { "r", "voxels (r^3)", "ms", "CPU ms", "voxels evaluated", "% of voxels",
      "evaluated / previous", "leaf tiles", "mean leaf tape" } };
  Table render{ "Pruned 2D sign, frep::renderSign2D of " + model + " vs resolution (tiles 128, 32)",
    { "r", "pixels (r^2)", "ms", "CPU ms", "pixels evaluated", "% of pixels",
      "evaluated / previous" } };
  Table contour{ "Dual contouring of " + model + " vs feature size, [-1.2,1.2]^3",
    { "feature size", "cells (dense)", "ms", "CPU ms", "points evaluated", "evaluated / previous",
      "interval bounds", "triangles", "triangles / previous" } };

  std::int64_t previous = 0;
  for (int r : sampleSizes)
  {
    std::cerr << "scaling: sampling and occupancy at " << r << "^3\n";
    const SampleRun full = Sample(tape, r, false, threads, runs);
    const SampleRun pruned = Sample(tape, r, true, threads, runs);
    const std::int64_t evals = pruned.stats.instructionEvaluations;
    sampling.rows.push_back(
      { Count(r), Count(pruned.stats.pointsEvaluated), Ms(full.timing.wall), Ms(full.timing.cpu),
        Ms(pruned.timing.wall), Ms(pruned.timing.cpu), Count(full.stats.instructionEvaluations),
        Count(evals), Ratio(static_cast<double>(evals), static_cast<double>(previous)),
        PerPoint(evals, pruned.stats.pointsEvaluated) });
    sampling.json.push_back({ { "resolution", r }, { "points", pruned.stats.pointsEvaluated },
      { "full_seconds", full.timing.wall }, { "full_cpu_seconds", full.timing.cpu },
      { "pruned_seconds", pruned.timing.wall }, { "pruned_cpu_seconds", pruned.timing.cpu },
      { "full_instruction_evaluations", full.stats.instructionEvaluations },
      { "pruned_instruction_evaluations", evals } });
    previous = evals;
  }
  previous = 0;
  for (int r : sampleSizes)
  {
    const RenderRun o = Render(tape, r, 3, threads, runs);
    const double voxels = static_cast<double>(r) * r * r;
    occupancy.rows.push_back({ Count(r), Count(static_cast<std::int64_t>(voxels)),
      Ms(o.timing.wall), Ms(o.timing.cpu), Count(o.stats.pixelsEvaluated),
      Fixed(100.0 * static_cast<double>(o.stats.pixelsEvaluated) / voxels, 2),
      Ratio(static_cast<double>(o.stats.pixelsEvaluated), static_cast<double>(previous)),
      Count(o.stats.tilesEvaluated), PerPoint(o.stats.leafInstructions, o.stats.tilesEvaluated) });
    occupancy.json.push_back({ { "resolution", r }, { "seconds", o.timing.wall },
      { "cpu_seconds", o.timing.cpu }, { "voxels_evaluated", o.stats.pixelsEvaluated },
      { "tiles_filled", o.stats.tilesFilled }, { "leaf_tiles_evaluated", o.stats.tilesEvaluated },
      { "leaf_instructions", o.stats.leafInstructions }, { "inside_voxels", o.inside } });
    previous = o.stats.pixelsEvaluated;
  }
  previous = 0;
  for (int r : renderSizes)
  {
    std::cerr << "scaling: 2D render at " << r << "^2\n";
    const RenderRun o = Render(tape, r, 2, threads, runs);
    const double pixels = static_cast<double>(r) * r;
    render.rows.push_back({ Count(r), Count(static_cast<std::int64_t>(pixels)), Ms(o.timing.wall),
      Ms(o.timing.cpu), Count(o.stats.pixelsEvaluated),
      Fixed(100.0 * static_cast<double>(o.stats.pixelsEvaluated) / pixels, 2),
      Ratio(static_cast<double>(o.stats.pixelsEvaluated), static_cast<double>(previous)) });
    render.json.push_back({ { "resolution", r }, { "seconds", o.timing.wall },
      { "cpu_seconds", o.timing.cpu }, { "pixels_evaluated", o.stats.pixelsEvaluated },
      { "leaf_tiles_evaluated", o.stats.tilesEvaluated } });
    previous = o.stats.pixelsEvaluated;
  }
  previous = 0;
  std::size_t previousTriangles = 0;
  for (double fs : featureSizes)
  {
    std::cerr << "scaling: contouring at feature size " << fs << "\n";
    const ContourRun c = Contour(tape, fs, threads, runs);
    const double cellsPerAxis = std::ceil(2 * BoxHalf / fs);
    std::ostringstream name;
    name << fs;
    contour.rows.push_back(
      { name.str(), Count(static_cast<std::int64_t>(cellsPerAxis * cellsPerAxis * cellsPerAxis)),
        Ms(c.timing.wall), Ms(c.timing.cpu), Count(c.points),
        Ratio(static_cast<double>(c.points), static_cast<double>(previous)), Count(c.bounds),
        Count(static_cast<std::int64_t>(c.triangles)),
        Ratio(static_cast<double>(c.triangles), static_cast<double>(previousTriangles)) });
    contour.json.push_back({ { "feature_size", fs }, { "seconds", c.timing.wall },
      { "cpu_seconds", c.timing.cpu }, { "points_evaluated", c.points },
      { "interval_bounds", c.bounds }, { "gradients", c.gradients },
      { "pruned_evaluators", c.narrowed }, { "triangles", c.triangles } });
    previous = c.points;
    previousTriangles = c.triangles;
  }
  return { sampling, occupancy, render, contour };
}

// --- one point of Scripts/scale-plots ------------------------------------------------------------

/// The process's resident set now (bytes), from /proc/self/statm.
double ResidentBytes()
{
  std::ifstream statm("/proc/self/statm");
  double size = 0, resident = 0;
  statm >> size >> resident;
  return resident * static_cast<double>(sysconf(_SC_PAGESIZE));
}

double PeakResidentBytes()
{
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) * 1024.0; // Linux: kilobytes
}

/// Runs `f` once and returns its wall and CPU seconds with the memory figures.
nlohmann::json MeasureOnce(const std::function<void(nlohmann::json&)>& f)
{
  nlohmann::json j;
  j["rss_before_bytes"] = ResidentBytes();
  const double c0 = CpuSeconds();
  const auto t0 = std::chrono::steady_clock::now();
  f(j);
  j["wall_seconds"] = Seconds(t0);
  j["cpu_seconds"] = CpuSeconds() - c0;
  j["peak_rss_bytes"] = PeakResidentBytes();
  return j;
}

int RunScalePointNow(int threads)
{
  const std::size_t eq = ScalePoint.find('=');
  if (eq == std::string::npos)
  {
    throw UserError("--scale-point: expected KIND=VALUE, got '" + ScalePoint + "'");
  }
  const std::string kind = ScalePoint.substr(0, eq);
  char* end = nullptr;
  const std::string number = ScalePoint.substr(eq + 1);
  const double value = std::strtod(number.c_str(), &end);
  if (number.empty() || *end != '\0' || !(value > 0) || !std::isfinite(value))
  {
    throw UserError("--scale-point: the value of '" + ScalePoint + "' is not a positive number");
  }
  const auto resolution = static_cast<std::int64_t>(value);
  nlohmann::json j;
  if (kind == "sample-dense" || kind == "sample-band")
  {
    const frep::TapePtr tape = frep::Tape::compile(bundled::csgField(bundled::random1000Recipe()));
    const frep::Grid grid =
      frep::gridOverBox(ModelBox.lo, ModelBox.hi, { resolution, resolution, resolution });
    if (kind == "sample-dense")
    {
      j = MeasureOnce(
        [&](nlohmann::json& out)
        {
          std::vector<float> values(static_cast<std::size_t>(grid.pointCount()));
          frep::SampleOptions options;
          options.threads = threads;
          frep::sampleGrid(tape, grid, values.data(), options);
          out["values_bytes"] = values.size() * sizeof(float);
        });
    }
    else
    {
      j = MeasureOnce(
        [&](nlohmann::json& out)
        {
          voxel::NarrowBandOptions options;
          options.threads = threads;
          const voxel::NarrowBandGrid band = voxel::sampleNarrowBand(tape, grid, options);
          out["active_voxels"] = band.activeVoxelCount();
          out["grid_bytes"] = band.memoryBytes();
          out["band"] = band.band();
          out["leaves_sampled"] = band.stats().leavesSampled;
          out["leaves_kept"] = band.stats().leavesKept;
          out["interval_evaluations"] = band.stats().intervalEvaluations;
        });
    }
    j["points"] = grid.pointCount();
    j["tape_instructions"] = tape->instructions().size();
  }
  else if (kind == "contour")
  {
    const frep::TapePtr tape = frep::Tape::compile(bundled::csgField(bundled::random1000Recipe()));
    const frep::FieldPtr field = frep::tapeField(tape);
    j = MeasureOnce(
      [&](nlohmann::json& out)
      {
        discretize::SurfaceOptions options;
        options.featureSize = value;
        options.threads = threads;
        const discretize::SurfaceMesh mesh = discretize::contourSurface(*field, ModelBox, options);
        out["triangles"] = mesh.triangles.size();
        out["vertices"] = mesh.points.size();
      });
    j["cells_per_axis"] = std::ceil(2 * BoxHalf / value);
  }
  else if (kind == "primitives")
  {
    const int primitives = static_cast<int>(value);
    const double c0 = CpuSeconds();
    const frep::TapePtr tape = RandomCsgTape(primitives);
    const double compileSeconds = CpuSeconds() - c0;
    constexpr int Size = 1024;
    j = MeasureOnce(
      [&](nlohmann::json& out)
      {
        frep::RenderRegion region;
        region.lo = { -BoxHalf, -BoxHalf, 0.0 };
        region.hi = { BoxHalf, BoxHalf, 0.0 };
        frep::RenderOptions options;
        options.threads = threads;
        frep::RenderStats stats;
        options.stats = &stats;
        const std::vector<std::uint8_t> image =
          frep::renderSign2D(tape, region, Size, Size, options);
        out["pixels_evaluated"] = stats.pixelsEvaluated;
        out["leaf_tiles"] = stats.tilesEvaluated;
        out["leaf_instructions"] = stats.leafInstructions;
      });
    j["pixels"] = Size * Size;
    j["compile_cpu_seconds"] = compileSeconds;
    j["tape_instructions"] = tape->instructions().size();
    j["choices"] = tape->choiceCount();
  }
  else if (kind == "frames" || kind == "frames-full")
  {
    // The Andyhausen film from its start, one frame per 0.1 s, meshed at 1/48 of its size.
    const int steps = static_cast<int>(value);
    const std::string path = std::string(ICTK_DATA_DIR) + "/Models/icm/andyhausen.icm";
    DynamicRunTiming timing;
    j = MeasureOnce(
      [&](nlohmann::json& out)
      {
        timing = TimeDynamicRun(path, 0.1 * steps, steps, 48, kind == "frames", 1, threads);
        out["mesh_seconds"] = timing.meshSeconds;
        out["points"] = timing.points;
        out["cells_computed"] = timing.computed;
        out["cells_moved"] = timing.moved;
        out["cells_reused"] = timing.reused;
      });
    j["frames"] = timing.frames;
  }
  else
  {
    throw UserError("--scale-point: unknown kind '" + kind +
      "' (sample-dense, sample-band, contour, primitives, frames, frames-full)");
  }
  j["kind"] = kind;
  j["value"] = value;
  j["threads"] = threads;
  std::cout << j.dump() << "\n";
  return 0;
}
} // namespace

void AddScalingOptions(CLI::App& bench)
{
  bench.add_flag("--scaling", Scaling,
    "Instead of the workloads: time and work counters against the model size (random CSG of "
    "about 100 to 100k instructions) and the resolution (docs/performance.md, Scaling); 1 "
    "thread unless --threads");
  bench.add_option("--scaling-primitives", PrimitiveCounts,
    "Primitive counts of the model-size table (default 6 62 628 7940: 99, 1016, 10019, 100161 "
    "instructions)");
  bench.add_option("--scale-point", ScalePoint,
    "One measurement for Scripts/scale-plots, run once in this process and printed as one JSON "
    "line with its CPU time and the process's peak RSS: sample-dense=R, sample-band=R (random1000 "
    "at R^3, dense or narrow band), contour=FEATURE_SIZE, primitives=N (pruned 1024^2 render of a "
    "random CSG of N primitives), frames=N or frames-full=N (the Andyhausen film over N frames "
    "of 0.1 s, coherent or re-meshed); 1 thread unless --threads");
}

bool ScalePointRequested()
{
  return !ScalePoint.empty();
}

int RunScalePoint(int threads)
{
  return RunScalePointNow(threads > 0 ? threads : 1);
}

bool ScalingRequested()
{
  return Scaling;
}

int RunScalingBench(int runs, int threads, bool json, bool quick)
{
  threads = threads > 0 ? threads : 1;
  if (quick)
  {
    runs = 1;
  }
  const std::vector<int> primitives = quick ? std::vector<int>{ 6, 62 } : PrimitiveCounts;
  const std::vector<int> sampleSizes =
    quick ? std::vector<int>{ 32, 64 } : std::vector<int>{ 64, 128, 256, 512 };
  const std::vector<int> renderSizes =
    quick ? std::vector<int>{ 128, 256 } : std::vector<int>{ 256, 512, 1024, 2048, 4096 };
  const std::vector<double> featureSizes =
    quick ? std::vector<double>{ 0.1, 0.05 } : std::vector<double>{ 0.1, 0.05, 0.025, 0.0125 };

  std::vector<Table> tables = ModelSizeTables(
    primitives, quick ? 32 : 128, quick ? 128 : 1024, quick ? 0.1 : 0.025, threads, runs);
  for (Table& t : ResolutionTables(sampleSizes, renderSizes, featureSizes, threads, runs))
  {
    tables.push_back(std::move(t));
  }
  if (json)
  {
    nlohmann::json all = nlohmann::json::object();
    const char* keys[] = { "models", "size_sampling", "size_render2d", "size_contour",
      "resolution_sampling", "resolution_occupancy3d", "resolution_render2d",
      "resolution_contour" };
    for (std::size_t i = 0; i < tables.size(); ++i)
    {
      all[keys[i]] = tables[i].json;
    }
    all["threads"] = threads;
    all["runs"] = runs;
    std::cout << all.dump(2) << "\n";
    return 0;
  }
  std::cout << "ictk bench --scaling: " << threads << " thread" << (threads == 1 ? "" : "s")
            << ", median of " << runs
            << " runs after a warm-up (one run when the first takes over 1 s)\n";
  for (const Table& t : tables)
  {
    Print(t);
  }
  return 0;
}

} // namespace ictk::cli
