// SPDX-License-Identifier: BSD-3-Clause
// `ictk tetra`: a tetrahedral mesh of a complex for FEA, every tetrahedron labelled by cell and
// material, with a quality, validity and volume report.
#include "Command.h"
#include "Models.h"
#include "Options.h"
#include "Output.h"
#include "ProgressDisplay.h"

#include "Complex/Discretization.h"
#include "FRep/Sampling.h"
#include "Mesh/Backends/Backends.h"
#include "Mesh/Quality.h"
#include "Mesh/TetAttributes.h"
#include "Mesh/Validity.h"
#include "Mesh/Writers.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <optional>

namespace ictk::cli
{
namespace
{

struct TetraOptions
{
  std::string Model;
  std::string Output;
  std::string Backend;
  double Size = 0;
  bool Deterministic = false;
  bool Json = false;
  std::string MshVersion = "4.1";
  double MaxTetrahedra = 2e7;
  int Threads = 0;
};

class TetraCommand final : public Command
{
public:
  CLI::App* add(CLI::App& app) override;
  int run() override;

private:
  TetraOptions o;
};

CLI::App* TetraCommand::add(CLI::App& app)
{
  CLI::App* tetra = app.add_subcommand("tetra",
    "Tetrahedral mesh of a complex for FEA (.vtu, .msh, .inp, .mesh), every tetrahedron labelled "
    "by cell and material, with a quality report");
  AddModel(tetra, o.Model, "A .json complex or a .hf / .xml / .vm / .blob model");
  AddOutput(tetra, o.Output, "Output: .vtu, .msh (Gmsh 4.1), .inp, .mesh");
  tetra->add_option("--backend", o.Backend, "cgal or tetgen (default: cgal when built)");
  AddSize(tetra, o.Size, "Target edge length (default: 1/32 of the complex's size)");
  tetra->add_flag("--deterministic", o.Deterministic, "Identical output run to run");
  tetra->add_option("--max-tets", o.MaxTetrahedra, "Refuse meshes estimated above this");
  AddThreads(tetra, o.Threads);
  AddJson(tetra, o.Json, "Print the report as JSON");
  tetra->add_option("--msh-version", o.MshVersion, "Gmsh file format: 4.1 (default) or 2.2")
    ->check(CLI::IsMember({ "4.1", "2.2" }));
  return tetra;
}

int TetraCommand::run()
{
  if (!(HasExtension(o.Output, ".vtu") || HasExtension(o.Output, ".msh") ||
        HasExtension(o.Output, ".inp") || HasExtension(o.Output, ".mesh")))
  {
    throw UserError("-o: '" + o.Output + "' is not a .vtu, .msh, .inp or .mesh file");
  }
  CheckSize(o.Size);
  CheckThreads(o.Threads);
  const std::optional<mesh::Backend> chosen =
    o.Backend.empty() ? mesh::defaultBackend() : mesh::backendFromName(o.Backend);
  if (!chosen)
  {
    throw UserError(o.Backend.empty()
        ? std::string(
            "no tetrahedral backend was built (configure with ICTK_ENABLE_GPL_BACKENDS=ON)")
        : "--backend must be cgal or tetgen, not '" + o.Backend + "'");
  }
  const std::string backend = mesh::backendName(*chosen);
  if (!mesh::hasBackend(*chosen))
  {
    throw UserError("the " + backend +
      " backend was not built (configure with ICTK_ENABLE_GPL_BACKENDS=ON and its library)");
  }
  const auto t0 = std::chrono::steady_clock::now();
  const complex::Complex k = LoadComplex(o.Model);
  mesh::TetraOptions options;
  options.size = o.Size;
  if (!(options.size > 0))
  {
    const frep::Box3 b = complex::complexBounds(k);
    const double side = std::max({ b.hi[0] - b.lo[0], b.hi[1] - b.lo[1], b.hi[2] - b.lo[2] });
    options.size = side / 32;
  }
  options.deterministic = o.Deterministic;
  options.maxTetrahedra = o.MaxTetrahedra;
  options.threads = o.Threads;
  ProgressBar bar("tetra", false, !o.Json);
  options.progress = [&](double fraction)
  {
    bar.Show(fraction);
    return true;
  };
  mesh::ValidityReport validity;
  mesh::TetMesh m = [&]
  {
    try
    {
      return mesh::tetrahedralize(k, *chosen, options, &validity);
    }
    catch (...)
    {
      bar.End();
      throw;
    }
  }();
  bar.End();
  mesh::assignAttributes(m, k);
  const double meshSeconds = Seconds(t0);
  if (HasExtension(o.Output, ".vtu"))
  {
    WriteTetMeshVtu(m, o.Output);
  }
  else if (HasExtension(o.Output, ".msh"))
  {
    mesh::writeGmsh(
      m, o.Output, o.MshVersion == "2.2" ? mesh::GmshVersion::V22 : mesh::GmshVersion::V41);
  }
  else
  {
    mesh::writeTetMesh(m, o.Output);
  }
  const mesh::QualityReport q = mesh::measureQuality(m);
  const frep::Box3 b = complex::complexBounds(k);
  const double side = std::max({ b.hi[0] - b.lo[0], b.hi[1] - b.lo[1], b.hi[2] - b.lo[2] });
  const auto volumes = mesh::compareVolumes(m, k, std::max(options.size / 4, side / 2048));
  if (o.Json)
  {
    nlohmann::json j;
    j["output"] = o.Output;
    j["backend"] = backend;
    j["size"] = options.size;
    j["seconds"] = meshSeconds;
    j["points"] = q.points;
    j["tetrahedra"] = q.tetrahedra;
    j["min_dihedral_degrees"] = q.minDihedralDegrees;
    j["min_dihedral_percentile1_degrees"] = q.minDihedralPercentile1Degrees;
    j["max_radius_edge_ratio"] = q.maxRadiusEdgeRatio;
    j["validity"] = { { "valid", validity.valid() }, { "min_edge", validity.minEdge },
      { "min_edge_relative", validity.minEdgeRelative }, { "min_volume", validity.minVolume },
      { "min_volume_relative", validity.minVolumeRelative },
      { "non_positive", validity.nonPositive }, { "duplicate_points", validity.duplicatePoints },
      { "interior_faces", validity.interiorFaces }, { "boundary_faces", validity.boundaryFaces },
      { "non_conforming_faces", validity.nonConformingFaces },
      { "stray_boundary_faces", validity.strayBoundaryFaces },
      { "unchecked_boundary_faces", validity.uncheckedBoundaryFaces } };
    j["materials"] = nlohmann::json::array();
    for (const auto& v : volumes)
    {
      j["materials"].push_back(
        { { "material", v.material }, { "name", v.name }, { "mesh_volume", v.meshVolume },
          { "cell_volume", v.cellVolume }, { "relative_difference", v.relativeDifference } });
    }
    std::cout << j.dump(2) << "\n";
    return 0;
  }
  std::cout << "wrote " << o.Output << " (" << q.tetrahedra << " tetrahedra, " << backend
            << ", size " << options.size << ") in " << meshSeconds << " s\n"
            << mesh::formatQualityReport(q) << mesh::formatValidityReport(validity)
            << mesh::formatVolumeComparison(volumes);
  return 0;
}

} // namespace

std::unique_ptr<Command> tetraCommand()
{
  return std::make_unique<TetraCommand>();
}

} // namespace ictk::cli
