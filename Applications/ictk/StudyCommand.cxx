// SPDX-License-Identifier: BSD-3-Clause
// `ictk study`: a medical study in one line (issue 15, docs/medical.md): a complex whose voxel
// cell is a scan clipped to a specimen and whose other cells are implants placed in it, meshed
// into labelled tetrahedra by the CGAL backend, every tetrahedron given a material (from the scan
// under it, or fixed by its cell), written as a .vtu and a CalculiX/Abaqus .inp. The study's
// settings are the complex file's "study" object; everything is checked before anything is
// written, and the two files appear together or not at all. With a compression (--solve or the
// study's "solve") the mesh is also solved by CalculiX (Compression.h) before either is written.
#include "Command.h"
#include "Compression.h"
#include "Models.h"
#include "Options.h"
#include "Output.h"
#include "ProgressDisplay.h"
#include "Study.h"

#include "ictkComplexSource.h"

#include "Mesh/Backends/Backends.h"
#include "Mesh/Quality.h"
#include "Mesh/ScanMaterials.h"
#include "Mesh/Writers.h"
#include "Voxel/VoxelField.h"
#ifdef ICTK_HAVE_MESH_CGAL
#include "Mesh/CGAL/MeshCgal.h"
#endif

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <sstream>

namespace ictk::cli
{
namespace
{

using Json = nlohmann::json;
namespace fs = std::filesystem;

/// The smallest gap between protected curves a study accepts, relative to the size (the
/// example's 0.5 mm shell at size 1 is 0.5; a 0.1 mm one, refused, is 0.1).
constexpr double kSmallestGap = 0.25;

/// The "study" object of a complex file, with the defaults of docs/medical.md.
struct StudySettings
{
  double size = 1;
  std::string scan;
  std::vector<std::string> implants;
  mesh::ScanMaterialOptions materials;
  /// The deck's modulus bins, in ln E (Writers.h deckMaterials).
  double binWidth = 0.01;
  /// The top platen's displacement of the compression case; 0: no solve.
  double compression = 0;
};

/// A study object's keys must be ones docs/medical.md lists: a misspelt "modulus_lwa" would
/// otherwise leave the default law in force without a word.
void checkObject(const Json& j, std::initializer_list<const char*> known, const std::string& where)
{
  if (!j.is_object())
  {
    throw UserError(where + " must be a JSON object");
  }
  for (const auto& item : j.items())
  {
    if (std::none_of(known.begin(), known.end(), [&](const char* k) { return item.key() == k; }))
    {
      std::string list;
      for (const char* k : known)
      {
        list += (list.empty() ? "\"" : ", \"") + std::string(k) + "\"";
      }
      throw UserError(where + ": unknown key \"" + item.key() + "\" (known: " + list + ")");
    }
  }
}

double numberAt(const Json& j, const char* key, double fallback, const std::string& where)
{
  if (!j.contains(key))
  {
    return fallback;
  }
  if (!j[key].is_number() || !std::isfinite(j[key].get<double>()))
  {
    throw UserError(where + ": \"" + key + "\" must be a number");
  }
  return j[key].get<double>();
}

std::string stringAt(const Json& j, const char* key, const std::string& where)
{
  if (!j.contains(key))
  {
    return {};
  }
  if (!j[key].is_string())
  {
    throw UserError(where + ": \"" + key + "\" must be a string (a cell's name)");
  }
  return j[key].get<std::string>();
}

std::vector<std::string> stringsAt(
  const Json& j, const char* key, std::vector<std::string> fallback, const std::string& where)
{
  if (!j.contains(key))
  {
    return fallback;
  }
  const Json& list = j[key];
  if (!list.is_array() ||
    !std::all_of(list.begin(), list.end(), [](const Json& e) { return e.is_string(); }))
  {
    throw UserError(where + ": \"" + key + "\" must be a list of cell names");
  }
  return list.get<std::vector<std::string>>();
}

StudySettings readSettings(const std::string& path)
{
  std::ifstream in(path);
  if (!in)
  {
    throw UserError("cannot read '" + path + "'");
  }
  Json doc;
  try
  {
    doc = Json::parse(in);
  }
  catch (const std::exception& e)
  {
    throw UserError("'" + path + "': " + e.what());
  }
  const std::string where = "'" + path + "': study";
  if (!doc.contains("study") || !doc["study"].is_object())
  {
    throw UserError("'" + path + "' has no \"study\" object (docs/medical.md)");
  }
  const Json& s = doc["study"];
  checkObject(s,
    { "size", "scan", "scan_cells", "implants", "density_law", "modulus_law", "sampling",
      "bin_width", "poisson_ratio", "minimum_modulus", "fixed", "solve" },
    where);
  StudySettings out;
  out.size = numberAt(s, "size", 1, where);
  if (!(out.size > 0))
  {
    throw UserError(where + ": \"size\" must be a positive element size (mm)");
  }
  out.scan = stringAt(s, "scan", where);
  std::vector<std::string> cellNames;
  bool scanIsVoxelCell = false;
  if (doc.contains("cells") && doc["cells"].is_array())
  {
    for (const Json& cell : doc["cells"])
    {
      if (cell.is_object() && cell.contains("name") && cell["name"].is_string())
      {
        cellNames.push_back(cell["name"].get<std::string>());
        scanIsVoxelCell =
          scanIsVoxelCell || (cellNames.back() == out.scan && cell.value("kind", Json()) == "V");
      }
    }
  }
  const auto isCell = [&](const std::string& name)
  {
    return std::find(cellNames.begin(), cellNames.end(), name) != cellNames.end();
  };
  if (!scanIsVoxelCell)
  {
    throw UserError(where + ": \"scan\" must name a voxel (V) cell of the complex");
  }
  const auto namesCells = [&](const std::vector<std::string>& names, const char* key)
  {
    for (const std::string& name : names)
    {
      if (!isCell(name))
      {
        throw UserError(
          where + ": \"" + key + "\" names '" + name + "', which is not a cell of the complex");
      }
    }
  };
  out.implants = stringsAt(s, "implants", {}, where);
  namesCells(out.implants, "implants");
  auto& m = out.materials;
  const std::vector<std::string> scanCells = stringsAt(s, "scan_cells", { out.scan }, where);
  namesCells(scanCells, "scan_cells");
  m.scanCells.insert(scanCells.begin(), scanCells.end());
  if (s.contains("density_law"))
  {
    const Json& law = s["density_law"];
    checkObject(law, { "a", "b" }, where + ".density_law");
    m.density.a = numberAt(law, "a", m.density.a, where + ".density_law");
    m.density.b = numberAt(law, "b", m.density.b, where + ".density_law");
  }
  if (s.contains("modulus_law"))
  {
    const Json& law = s["modulus_law"];
    checkObject(law, { "a", "b", "c" }, where + ".modulus_law");
    m.modulus.a = numberAt(law, "a", m.modulus.a, where + ".modulus_law");
    m.modulus.b = numberAt(law, "b", m.modulus.b, where + ".modulus_law");
    m.modulus.c = numberAt(law, "c", m.modulus.c, where + ".modulus_law");
  }
  if (s.contains("sampling") && !s["sampling"].is_string())
  {
    throw UserError(where + ": \"sampling\" must be \"integrated\" or \"centroid\"");
  }
  const std::string sampling = s.value("sampling", std::string("integrated"));
  if (sampling != "integrated" && sampling != "centroid")
  {
    throw UserError(where + ": \"sampling\" must be \"integrated\" or \"centroid\"");
  }
  m.sampling =
    sampling == "centroid" ? mesh::ScanSampling::Centroid : mesh::ScanSampling::Integrated;
  out.binWidth = numberAt(s, "bin_width", out.binWidth, where);
  if (!(out.binWidth > 0))
  {
    throw UserError(where + ": \"bin_width\" must be positive");
  }
  m.poissonRatio = numberAt(s, "poisson_ratio", m.poissonRatio, where);
  m.minimumModulus = numberAt(s, "minimum_modulus", m.minimumModulus, where);
  if (s.contains("solve"))
  {
    checkObject(s["solve"], { "compression" }, where + ".solve");
    out.compression = numberAt(s["solve"], "compression", 0, where + ".solve");
    if (!(out.compression > 0))
    {
      throw UserError(where + ".solve: \"compression\" must be a positive displacement");
    }
  }
  if (s.contains("fixed") && !s["fixed"].is_object())
  {
    throw UserError(where + ".fixed must be a JSON object of cells' materials");
  }
  const Json fixed = s.value("fixed", Json::object());
  for (const auto& [name, f] : fixed.items())
  {
    const std::string at = where + ".fixed." + name;
    if (!isCell(name))
    {
      throw UserError(at + ": '" + name + "' is not a cell of the complex");
    }
    checkObject(f, { "youngs_modulus", "poisson_ratio", "density" }, at);
    mesh::FixedMaterial fm;
    fm.youngsModulus = numberAt(f, "youngs_modulus", 0, at);
    fm.poissonRatio = numberAt(f, "poisson_ratio", 0.3, at);
    fm.density = numberAt(f, "density", 1, at);
    m.fixed[name] = fm;
  }
  return out;
}

/// An implant must lie in the specimen: its cell's box inside the scan cell's (the clip).
void checkImplants(const complex::Complex& k, const StudySettings& s)
{
  auto boundsOf = [&](const std::string& name) -> frep::Box3
  {
    for (complex::CellId id : k.cellsOfDimension(3))
    {
      const complex::Cell& c = k.cell(id);
      if (c.name == name)
      {
        if (const auto* g = std::get_if<complex::ImplicitGeometry>(&c.geometry))
        {
          return g->bounds;
        }
      }
    }
    throw UserError("study: no implicit solid cell named '" + name + "'");
  };
  const frep::Box3 specimen = boundsOf(s.scan);
  for (const auto& name : s.implants)
  {
    const frep::Box3 b = boundsOf(name);
    for (int a = 0; a < 3; ++a)
    {
      const double slack = 1e-9 * (specimen.hi[a] - specimen.lo[a]);
      if (b.lo[a] < specimen.lo[a] - slack || b.hi[a] > specimen.hi[a] + slack)
      {
        std::ostringstream m;
        m << "study: implant '" << name << "' reaches outside the specimen on axis "
          << "xyz"[a] << ": [" << b.lo[a] << ", " << b.hi[a] << "] is not within ["
          << specimen.lo[a] << ", " << specimen.hi[a] << "]";
        throw UserError(m.str());
      }
    }
  }
}

/// The smallest distance between two of the curves the CGAL backend protects, away from the
/// corners they share (points within `size` of the other curve's ends are not compared).
struct CurveGap
{
  double distance = std::numeric_limits<double>::infinity();
  frep::Point3 at{};
};

CurveGap closestCurves(const std::vector<std::vector<frep::Point3>>& curves, double size)
{
  auto distance = [](const frep::Point3& a, const frep::Point3& b)
  {
    return std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
  };
  auto toSegment = [&](const frep::Point3& p, const frep::Point3& a, const frep::Point3& b)
  {
    const frep::Point3 ab{ b[0] - a[0], b[1] - a[1], b[2] - a[2] };
    const double length2 = ab[0] * ab[0] + ab[1] * ab[1] + ab[2] * ab[2];
    const double t = length2 > 0
      ? std::clamp(
          ((p[0] - a[0]) * ab[0] + (p[1] - a[1]) * ab[1] + (p[2] - a[2]) * ab[2]) / length2, 0.0,
          1.0)
      : 0.0;
    return distance(p, { a[0] + t * ab[0], a[1] + t * ab[1], a[2] + t * ab[2] });
  };
  CurveGap gap;
  for (std::size_t i = 0; i < curves.size(); ++i)
  {
    for (std::size_t j = 0; j < curves.size(); ++j)
    {
      const auto& b = curves[j];
      if (i == j || b.size() < 2)
      {
        continue;
      }
      for (const auto& p : curves[i])
      {
        if (distance(p, b.front()) < size || distance(p, b.back()) < size)
        {
          continue;
        }
        for (std::size_t k = 1; k < b.size(); ++k)
        {
          const double d = toSegment(p, b[k - 1], b[k]);
          if (d < gap.distance)
          {
            gap = { d, p };
          }
        }
      }
    }
  }
  return gap;
}

/// The curves on an implant's boundary (every point where one of the implants' fields, the min
/// of its inside fields, vanishes): the thin layers the study makes are between these.
std::vector<std::vector<frep::Point3>> implantCurves(const complex::Complex& k,
  const StudySettings& s, const std::vector<std::vector<frep::Point3>>& curves, double size)
{
  std::vector<std::unique_ptr<frep::FieldEvaluator>> fields;
  for (complex::CellId id : k.cellsOfDimension(3))
  {
    const complex::Cell& c = k.cell(id);
    const auto* g = std::get_if<complex::ImplicitGeometry>(&c.geometry);
    if (g && std::find(s.implants.begin(), s.implants.end(), c.name) != s.implants.end())
    {
      fields.push_back(frep::minField(g->inside)->evaluator());
    }
  }
  std::vector<std::vector<frep::Point3>> out;
  for (const auto& line : curves)
  {
    const bool onImplant = std::all_of(line.begin(), line.end(),
      [&](const frep::Point3& p)
      {
        return std::any_of(fields.begin(), fields.end(),
          [&](const auto& f) { return std::abs(f->value(p)) < 1e-4 * size; });
      });
    if (onImplant)
    {
      out.push_back(line);
    }
  }
  return out;
}

struct StudyOptions
{
  std::string Model;
  std::string Output;
  std::string Inp;
  double Size = 0;
  double Solve = 0;
  std::string Ccx = "ccx";
  bool Deterministic = false;
  bool Json = false;
  int Threads = 0;
};

class StudyCommand final : public Command
{
public:
  CLI::App* add(CLI::App& app) override;
  int run() override;

private:
  StudyOptions o;
};

CLI::App* StudyCommand::add(CLI::App& app)
{
  CLI::App* study = app.add_subcommand("study",
    "A scan-and-implant study (docs/medical.md): labelled tetrahedra with materials from the "
    "scan, written as .vtu and .inp");
  AddModel(study, o.Model, "A .json complex with a \"study\" object");
  AddOutput(study, o.Output, "Output: the labelled mesh (.vtu)");
  study->add_option("--inp", o.Inp, "The CalculiX/Abaqus deck (default: the output with .inp)");
  AddSize(study, o.Size, "Target edge length (default: the study's \"size\")");
  study->add_option("--solve", o.Solve,
    "Also compress the specimen by this displacement with CalculiX (default: the study's "
    "\"solve\"); the results go to OUTPUT-solved.vtu, CalculiX's files to OUTPUT-ccx/");
  study->add_option("--ccx", o.Ccx, "The CalculiX executable (default: ccx on PATH)");
  study->add_flag("--deterministic", o.Deterministic, "Identical output run to run");
  AddThreads(study, o.Threads);
  AddJson(study, o.Json, "Print the report as JSON");
  return study;
}

int StudyCommand::run()
{
  if (!HasExtension(o.Output, ".vtu"))
  {
    throw UserError("-o: '" + o.Output + "' is not a .vtu file");
  }
  const std::string inp =
    o.Inp.empty() ? fs::path(o.Output).replace_extension(".inp").string() : o.Inp;
  if (!HasExtension(inp, ".inp"))
  {
    throw UserError("--inp: '" + inp + "' is not a .inp file");
  }
  CheckThreads(o.Threads);
  if (o.Solve != 0 && (!(o.Solve > 0) || !std::isfinite(o.Solve)))
  {
    throw UserError("--solve must be a positive displacement");
  }
  const auto t0 = std::chrono::steady_clock::now();
  StudyRequest request;
  request.model = o.Model;
  request.size = o.Size;
  request.threads = o.Threads;
  request.deterministic = o.Deterministic;
  request.progress = !o.Json;
  StudyMesh study = MakeStudyMesh(request);
  const mesh::TetMesh& m = study.mesh;
  mesh::AbaqusOptions abaqus;
  abaqus.modulusBinWidth = study.binWidth;
  const std::size_t deckMaterials = mesh::deckMaterials(m, study.binWidth).size();
  // The solve first (its own files), then both study files or neither: the deck into its
  // temporary file, the .vtu, then the deck's rename.
  const double compression = o.Solve > 0 ? o.Solve : study.compression;
  const std::string stem = o.Output.substr(0, o.Output.size() - std::string(".vtu").size());
  std::optional<CompressionReport> solved;
  double solveSeconds = 0;
  if (compression > 0)
  {
    const auto t2 = std::chrono::steady_clock::now();
    CompressionSettings c;
    c.displacement = compression;
    c.binWidth = study.binWidth;
    c.work = stem + "-ccx";
    c.ccx = o.Ccx;
    c.threads = o.Threads > 0 ? o.Threads : 1;
    c.progress = !o.Json;
    c.heading = "ictk study " + o.Model + ": compression by " + std::to_string(compression);
    AtomicOutput results(stem + "-solved.vtu");
    solved = SolveCompression(m, c, results);
    if (!solved)
    {
      std::cerr << "ictk: interrupted; nothing written\n";
      return ExitInterrupted;
    }
    solveSeconds = Seconds(t2);
  }
  AtomicOutput deck(inp);
  mesh::writeAbaqus(m, deck.Path(), abaqus);
  WriteTetMeshVtu(m, o.Output);
  deck.Commit();
  const mesh::QualityReport q = mesh::measureQuality(m);
  if (o.Json)
  {
    Json j;
    j["output"] = o.Output;
    j["inp"] = inp;
    j["size"] = study.size;
    j["read_seconds"] = study.readSeconds;
    j["mesh_seconds"] = study.meshSeconds;
    j["material_seconds"] = study.materialSeconds;
    j["points"] = q.points;
    j["tetrahedra"] = q.tetrahedra;
    j["min_dihedral_degrees"] = q.minDihedralDegrees;
    j["min_dihedral_percentile1_degrees"] = q.minDihedralPercentile1Degrees;
    j["deck_materials"] = deckMaterials;
    j["min_modulus"] = study.minModulus;
    j["max_modulus"] = study.maxModulus;
    if (solved)
    {
      const auto& r = solved->result;
      j["solved"] = stem + "-solved.vtu";
      j["compression"] = compression;
      j["apparent_modulus"] = r.apparentModulus;
      j["voigt_modulus"] = r.compression.voigtModulus;
      j["reuss_modulus"] = r.compression.reussModulus;
      j["max_von_mises"] = solved->largestVonMises;
      j["ccx_seconds"] = r.run.seconds;
      j["solve_seconds"] = solveSeconds;
    }
    j["seconds"] = Seconds(t0);
    j["materials"] = Json::array();
    for (const auto& mq : q.materials)
    {
      j["materials"].push_back(
        { { "name", mq.name }, { "tetrahedra", mq.tetrahedra }, { "volume", mq.volume } });
    }
    std::cout << j.dump(2) << "\n";
    return 0;
  }
  std::cout << "wrote " << o.Output << " and " << inp << " (" << q.tetrahedra
            << " tetrahedra, size " << study.size << "; scan read in " << study.readSeconds
            << " s, meshed in " << study.meshSeconds << " s)\n"
            << "scan moduli " << study.minModulus << " to " << study.maxModulus << " MPa; "
            << deckMaterials << " materials in the deck (" << 100 * study.binWidth
            << " % bins in ln E)\n"
            << mesh::formatQualityReport(q);
  if (solved)
  {
    const auto& r = solved->result;
    std::cout << "compressed by " << compression << ": apparent modulus " << r.apparentModulus
              << " MPa (Reuss " << r.compression.reussModulus << ", Voigt "
              << r.compression.voigtModulus << "), largest von Mises " << solved->largestVonMises
              << "; ccx " << r.run.seconds << " s; results in " << stem << "-solved.vtu\n";
  }
  std::cout << "total " << Seconds(t0) << " s\n";
  return 0;
}

} // namespace

StudyMesh MakeStudyMesh(const StudyRequest& r)
{
  if (!mesh::hasBackend(mesh::Backend::Cgal))
  {
    throw UserError(
      "the study needs the CGAL backend (configure with ICTK_ENABLE_GPL_BACKENDS=ON)");
  }
  StudyMesh out;
  const auto t0 = std::chrono::steady_clock::now();
  const StudySettings settings = readSettings(r.model);
  // The scan's Hounsfield units for the materials: the scan cell's own grid, as its field reads
  // it (after its stamps), so the materials see what was meshed and the scan is read once.
  std::shared_ptr<const voxel::VoxelGrid> grid;
  const complex::Complex k = ictkComplexSource::ReadComplexFile(r.model,
    [&](const std::string& cell, std::shared_ptr<const voxel::VoxelGrid> g)
    {
      if (cell == settings.scan)
      {
        grid = std::move(g);
      }
    });
  if (!grid)
  {
    throw UserError("'" + r.model + "': study: \"scan\" names no voxel cell that was read ('" +
      settings.scan + "')");
  }
  checkImplants(k, settings);
  std::vector<std::string> cells;
  for (complex::CellId id : k.cellsOfDimension(3))
  {
    cells.push_back(k.cell(id).name);
  }
  try
  {
    mesh::checkScanMaterials(settings.materials, cells);
  }
  catch (const std::exception& e)
  {
    throw UserError("'" + r.model + "': study: " + e.what());
  }
  out.readSeconds = Seconds(t0);
  // CGAL 5.5 cannot resolve two protected curves closer than about its protecting balls (the
  // size): issue 15 met runs that never finish, and here a 0.1 mm shell at size 1 came out with
  // 8 % of its volume. Refuse such a study rather than write a wrong mesh.
  const double size = r.size > 0 ? r.size : settings.size;
  CheckSize(size);
#ifdef ICTK_HAVE_MESH_CGAL
  {
    mesh::TetraOptions trace;
    trace.size = size;
    trace.threads = r.threads;
    const CurveGap gap =
      closestCurves(implantCurves(k, settings, mesh::cgalFeatureCurves(k, trace), size), size);
    if (gap.distance < kSmallestGap * size)
    {
      std::ostringstream m;
      m << "study: the implants' protected curves come " << gap.distance << " apart near ("
        << gap.at[0] << ", " << gap.at[1] << ", " << gap.at[2] << "), under " << kSmallestGap
        << " of the size " << size << ": the CGAL backend would lose the layer between them or "
        << "not finish; use --size " << gap.distance / kSmallestGap << " or less";
      throw UserError(m.str());
    }
  }
#endif
  mesh::TetraOptions options;
  options.size = size;
  options.deterministic = r.deterministic;
  options.threads = r.threads;
  ProgressBar bar("study", false, r.progress);
  options.progress = [&](double fraction)
  {
    bar.Show(fraction);
    return true;
  };
  mesh::ValidityReport validity;
  const auto t1 = std::chrono::steady_clock::now();
  out.mesh = [&]
  {
    try
    {
      return mesh::tetrahedralize(k, mesh::Backend::Cgal, options, &validity);
    }
    catch (...)
    {
      bar.End();
      throw;
    }
  }();
  bar.End();
  out.meshSeconds = Seconds(t1);
  const auto t2 = std::chrono::steady_clock::now();
  const mesh::ScanMaterialSummary moduli =
    mesh::assignScanMaterials(out.mesh, *voxel::voxelField(grid, 0), settings.materials);
  out.materialSeconds = Seconds(t2);
  out.minModulus = moduli.minModulus;
  out.maxModulus = moduli.maxModulus;
  out.size = size;
  out.binWidth = settings.binWidth;
  out.compression = settings.compression;
  return out;
}

std::unique_ptr<Command> studyCommand()
{
  return std::make_unique<StudyCommand>();
}

} // namespace ictk::cli
