// SPDX-License-Identifier: BSD-3-Clause
// `ictk solve`: a labelled tetrahedral mesh (.vtu of `ictk tetra`) compressed between two
// frictionless platens by CalculiX (issue 15): the deck with one material per modulus bin, the
// solve, the results as a .vtu (displacement, stress, von Mises) and the apparent modulus
// between its Voigt and Reuss bounds.
#include "Command.h"
#include "Compression.h"
#include "Options.h"
#include "Output.h"
#include "ProgressDisplay.h"

#include "Mesh/Calculix.h"
#include "Mesh/Frd.h"
#include "ictkComplexToVTK.h"
#include "ictkSolverResults.h"

#include <vtkNew.h>
#include <vtkUnstructuredGrid.h>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <thread>

namespace ictk::cli
{
namespace
{

struct SolveOptions
{
  std::string Mesh;
  std::string Output;
  double Compression = 0;
  double BinWidth = 0.01;
  std::string Work;
  std::string Ccx = "ccx";
  int Threads = 1;
  bool Json = false;
};

class SolveCommand final : public Command
{
public:
  CLI::App* add(CLI::App& app) override;
  int run() override;

private:
  SolveOptions o;
};

CLI::App* SolveCommand::add(CLI::App& app)
{
  CLI::App* solve = app.add_subcommand("solve",
    "Compress a tetrahedral mesh (.vtu of `ictk tetra`, per-tetrahedron youngs_modulus) between "
    "frictionless platens with CalculiX; results as .vtu");
  AddModel(solve, o.Mesh, "The mesh: a .vtu of tetrahedra");
  AddOutput(solve, o.Output, "Output .vtu: the mesh with displacement, stress, von_mises");
  solve
    ->add_option("--compression", o.Compression,
      "Displacement of the top platen (z max) towards the bottom one (z min), model units")
    ->required();
  solve->add_option("--bin-width", o.BinWidth,
    "Modulus bin width in ln E (default 0.01: 1 %; inf: one material per cell)");
  solve->add_option("--work", o.Work,
    "Folder for the deck and CalculiX's files (default: OUTPUT without .vtu, plus '-ccx')");
  solve->add_option("--ccx", o.Ccx, "The CalculiX executable (default: ccx on PATH)");
  AddThreads(solve, o.Threads, "CalculiX's threads (default 1; 0: all cores)");
  AddJson(solve, o.Json, "Print the figures as JSON");
  return solve;
}

int SolveCommand::run()
{
  if (!HasExtension(o.Mesh, ".vtu"))
  {
    throw UserError("'" + o.Mesh + "' is not a .vtu mesh (write one with `ictk tetra`)");
  }
  if (!HasExtension(o.Output, ".vtu"))
  {
    throw UserError("-o: '" + o.Output + "' is not a .vtu file");
  }
  if (!(o.Compression > 0) || !std::isfinite(o.Compression))
  {
    throw UserError("--compression must be a positive displacement");
  }
  if (!(o.BinWidth > 0))
  {
    throw UserError("--bin-width must be positive (inf: one material per cell)");
  }
  CheckThreads(o.Threads);
  std::error_code ec;
  if (!std::filesystem::is_regular_file(o.Mesh, ec))
  {
    throw UserError("cannot read '" + o.Mesh + "'");
  }
  const auto t0 = std::chrono::steady_clock::now();
  vtkSmartPointer<vtkUnstructuredGrid> grid;
  try
  {
    grid = ictk::vtk::readUnstructuredGrid(o.Mesh);
  }
  catch (const std::invalid_argument& e)
  {
    throw UserError(e.what());
  }
  const mesh::TetMesh m = ictk::vtk::tetMeshFromVTK(grid, o.Mesh);
  AtomicOutput file(o.Output);
  CompressionSettings settings;
  settings.work = o.Work.empty()
    ? o.Output.substr(0, o.Output.size() - std::string(".vtu").size()) + "-ccx"
    : o.Work;
  const std::string& work = settings.work;
  settings.displacement = o.Compression;
  settings.binWidth = o.BinWidth;
  settings.heading = "ictk solve " + o.Mesh + ": compression by " + std::to_string(o.Compression);
  settings.ccx = o.Ccx;
  settings.threads =
    o.Threads > 0 ? o.Threads : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  settings.progress = !o.Json;
  const std::optional<CompressionReport> report = SolveCompression(m, settings, file);
  if (!report)
  {
    std::cerr << "ictk: interrupted; nothing written\n";
    return ExitInterrupted;
  }
  const mesh::CompressionResult& r = report->result;
  const double seconds = Seconds(t0);
  const auto& c = r.compression;
  const double largest = report->largestVonMises;
  if (o.Json)
  {
    nlohmann::json j;
    j["output"] = o.Output;
    j["work"] = work;
    j["deck"] = (std::filesystem::path(work) / (r.run.job + ".inp")).string();
    j["tetrahedra"] = m.tetrahedra.size();
    j["materials"] = c.materials.size();
    j["height"] = c.height;
    j["area"] = c.area;
    j["displacement"] = c.displacement;
    j["force"] = -r.topForce[2];
    j["apparent_modulus"] = r.apparentModulus;
    j["voigt_modulus"] = c.voigtModulus;
    j["reuss_modulus"] = c.reussModulus;
    j["max_von_mises"] = largest;
    j["ccx_seconds"] = r.run.seconds;
    j["seconds"] = seconds;
    std::cout << j.dump(2) << "\n";
    return 0;
  }
  std::cout << "wrote " << o.Output << " (" << m.tetrahedra.size() << " tetrahedra, "
            << c.materials.size() << " materials; CalculiX files in " << work << ")\n"
            << "compression by " << c.displacement << " over height " << c.height << ", area "
            << c.area << ": force " << -r.topForce[2] << "\n"
            << "apparent modulus " << r.apparentModulus << " (Reuss " << c.reussModulus
            << ", Voigt " << c.voigtModulus << "), largest von Mises " << largest << "\n"
            << "ccx " << r.run.seconds << " s, total " << seconds << " s\n";
  return 0;
}

} // namespace

std::optional<CompressionReport> SolveCompression(
  const mesh::TetMesh& m, const CompressionSettings& settings, AtomicOutput& file)
{
  mesh::CompressionOptions compression;
  compression.displacement = settings.displacement;
  compression.modulusBinWidth = settings.binWidth;
  compression.heading = settings.heading;
  mesh::CalculixOptions calculix;
  calculix.executable = settings.ccx;
  calculix.threads = settings.threads;
  InterruptScope interrupts;
  ProgressBar bar("ccx", false, settings.progress);
  calculix.progress = [&](double fraction)
  {
    bar.Show(fraction);
    return !Interrupted();
  };
  CompressionReport report;
  try
  {
    report.result = mesh::solveCompression(m, settings.work, compression, calculix);
  }
  catch (const Cancelled&)
  {
    bar.End();
    return std::nullopt;
  }
  bar.End();
  const mesh::PointResults results = mesh::resultsOnMesh(m, mesh::readFrd(report.result.run.frd));
  vtkNew<vtkUnstructuredGrid> grid;
  ictk::vtk::solverResultsToVTK(m, results, report.result.compression.materials, grid);
  WriteUnstructuredGrid(grid, file);
  for (const double v : results.vonMises)
  {
    report.largestVonMises = std::max(report.largestVonMises, v);
  }
  return report;
}

std::unique_ptr<Command> solveCommand()
{
  return std::make_unique<SolveCommand>();
}

} // namespace ictk::cli
