// SPDX-License-Identifier: BSD-3-Clause
#include "ComplexCommands.h"

#include "Complex/Validation.h"
#include "FRep/Bounds.h"
#include "FRep/Sampling.h"
#include "Lang/ComplexFile.h"
#include "Lang/ModelFile.h"
#include "ictkComplexSource.h"
#include "ictkComplexToVTK.h"

#include <nlohmann/json.hpp>

#include "vtkCallbackCommand.h"
#include "vtkCommand.h"
#include "vtkMultiBlockDataSet.h"
#include "vtkNew.h"
#include "vtkPartitionedDataSetCollection.h"
#include "vtkXMLMultiBlockDataWriter.h"
#include "vtkXMLPartitionedDataSetCollectionWriter.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <stdexcept>
#include <unistd.h>

namespace ictk::cli
{
namespace
{

namespace fs = std::filesystem;
using Json = nlohmann::json;

bool EndsWith(std::string s, const std::string& suffix)
{
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s.size() >= suffix.size() &&
    s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

} // namespace

complex::Complex LoadComplex(const std::string& path)
{
  if (IsComplexInput(path))
  {
    return ictkComplexSource::ReadComplexFile(path);
  }
  if (!lang::isModelFile(path))
  {
    throw std::invalid_argument("'" + path + "' is not a .json complex or a .hf / .xml model");
  }
  const lang::ModelFile model = lang::loadModelFile(path);
  frep::Box3 box;
  if (model.bounds)
  {
    const auto& b = *model.bounds;
    box = { { b[0], b[2], b[4] }, { b[1], b[3], b[5] } };
  }
  else
  {
    const double h = 100; // the search box for models that do not state their bounds
    const auto found = frep::boundingBox(
      frep::Tape::compile(model.model.geometry().function()), { { -h, -h, -h }, { h, h, h } });
    if (!found)
    {
      throw std::invalid_argument("'" + path + "' is empty in [-100, 100]^3");
    }
    box = { found->lo, found->hi };
  }
  complex::Complex k;
  k.name = model.name;
  k.addCell(complex::frepCell(model.name, {}, { model.model.geometry().function() }, box));
  return k;
}

namespace
{

std::string Domain(const complex::Cell& c)
{
  if (std::holds_alternative<complex::MappedGeometry>(c.geometry))
  {
    return "XY->XYZ";
  }
  return c.isExplicit() ? "explicit" : "XYZ";
}

Json BoxJson(const frep::Box3& b)
{
  if (!(b.lo[0] <= b.hi[0]))
  {
    return nullptr;
  }
  return Json::array(
    { Json::array({ b.lo[0], b.lo[1], b.lo[2] }), Json::array({ b.hi[0], b.hi[1], b.hi[2] }) });
}

Json FindingJson(const complex::Complex& k, const complex::RelationFinding& f)
{
  const auto& p = k.cell(f.first);
  const auto& s = k.cell(f.second);
  return { { "relation", f.kind == complex::RelationKind::Boundary ? "boundary" : "containment" },
    { "cells", { p.name, s.name } },
    { "symbol",
      std::string(f.kind == complex::RelationKind::Boundary ? "Rb" : "Rc") +
        std::to_string(p.dimension) + std::to_string(s.dimension) },
    { "deviation", f.deviation }, { "witness", { f.witness[0], f.witness[1], f.witness[2] } },
    { "reason", f.reason } };
}

/// Writes a composite dataset file and its folder of pieces into a temporary folder beside the
/// destination, then moves both into place: a failure leaves what was there untouched.
void WriteComposite(vtkXMLWriterBase* writer, vtkDataObject* data, const std::string& output)
{
  const fs::path target = fs::absolute(output);
  const fs::path staging = target.parent_path() /
    (".ictk-" + target.filename().string() + "-" + std::to_string(::getpid()));
  fs::remove_all(staging);
  fs::create_directories(staging);
  const fs::path stagedFile = staging / target.filename();
  writer->SetInputDataObject(data);
  writer->SetFileName(stagedFile.string().c_str());
  const int ok = writer->Write();
  if (ok != 1 || writer->GetErrorCode() != 0)
  {
    fs::remove_all(staging);
    throw std::runtime_error("cannot write '" + output + "'");
  }
  // The pieces folder is named after the file's stem.
  const fs::path pieces = staging / target.stem();
  const fs::path targetPieces = target.parent_path() / target.stem();
  if (fs::exists(pieces))
  {
    // Replace an earlier pieces folder only when it holds nothing but pieces of this file.
    if (fs::exists(targetPieces))
    {
      const std::string prefix = target.stem().string() + "_";
      for (const auto& entry : fs::directory_iterator(targetPieces))
      {
        const std::string name = entry.path().filename().string();
        if (!entry.is_regular_file() || name.rfind(prefix, 0) != 0 ||
          entry.path().extension().string().rfind(".vt", 0) != 0)
        {
          fs::remove_all(staging);
          throw std::runtime_error("cannot write '" + output + "': the folder '" +
            targetPieces.string() + "' holds other files ('" + name +
            "'); move them or choose another name");
        }
      }
      fs::remove_all(targetPieces);
    }
    fs::rename(pieces, targetPieces);
  }
  fs::rename(stagedFile, target);
  fs::remove_all(staging);
}

} // namespace

bool IsComplexInput(const std::string& path)
{
  return lang::isComplexFile(path);
}

bool IsComplexOutput(const std::string& path)
{
  return EndsWith(path, ".vtpc") || EndsWith(path, ".vtm");
}

int RunInfo(const ComplexOptions& o)
{
  const complex::Complex k = LoadComplex(o.Model);
  Json out;
  out["name"] = k.name;
  out["dimension"] = k.dimension();
  Json cells = Json::array();
  Json counts = Json::array({ 0, 0, 0, 0 });
  for (complex::CellId id : k.cellIds())
  {
    const complex::Cell& c = k.cell(id);
    counts[c.dimension] = counts[c.dimension].get<int>() + 1;
    Json attributes = Json::array();
    for (const auto& b : c.attributes)
    {
      attributes.push_back({ { "attribute", b.attribute }, { "function", b.function->name },
        { "priority", b.priority } });
    }
    cells.push_back({ { "id", c.id }, { "name", c.name }, { "kind", complex::kindCode(c.kind) },
      { "dimension", c.dimension }, { "domain", Domain(c) }, { "bounds", BoxJson(c.bounds()) },
      { "description", c.description }, { "attributes", attributes } });
  }
  out["cells"] = cells;
  out["cells_per_dimension"] = counts;
  Json relations = { { "boundary", Json::array() }, { "containment", Json::array() } };
  for (int p = 0; p <= 3; ++p)
  {
    for (int s = 0; s <= p; ++s)
    {
      if (s < p)
      {
        for (const auto& [a, b] : k.boundary(p, s).pairs())
        {
          relations["boundary"].push_back({ k.cell(a).name, k.cell(b).name });
        }
      }
      for (const auto& [a, b] : k.containment(p, s).pairs())
      {
        relations["containment"].push_back({ k.cell(a).name, k.cell(b).name });
      }
    }
  }
  out["relations"] = relations;
  Json attributes = Json::object();
  for (const auto& [name, d] : k.attributes())
  {
    attributes[name] = { { "components", d.components }, { "inside", d.inside },
      { "outside", d.outside } };
  }
  out["attributes"] = attributes;
  if (o.Json)
  {
    std::cout << out.dump(2) << "\n";
    return 0;
  }
  std::cout << "complex '" << k.name << "': " << k.cellCount() << " cells (0D " << counts[0]
            << ", 1D " << counts[1] << ", 2D " << counts[2] << ", 3D " << counts[3] << "), "
            << k.boundaryPairCount() << " boundary and " << k.containmentPairCount()
            << " containment pairs\n";
  for (const auto& c : out["cells"])
  {
    std::cout << "  " << std::setw(3) << c["id"].get<int>() << "  " << std::left << std::setw(8)
              << c["name"].get<std::string>() << std::right << " " << c["kind"].get<std::string>()
              << " " << c["dimension"].get<int>() << "D " << c["domain"].get<std::string>();
    if (!c["bounds"].is_null())
    {
      std::cout << " bounds " << c["bounds"].dump();
    }
    if (!c["description"].get<std::string>().empty())
    {
      std::cout << "  " << c["description"].get<std::string>();
    }
    std::cout << "\n";
  }
  for (const auto& kind : { "boundary", "containment" })
  {
    std::cout << kind << ":";
    for (const auto& pair : relations[kind])
    {
      std::cout << " (" << pair[0].get<std::string>() << ", " << pair[1].get<std::string>() << ")";
    }
    std::cout << "\n";
  }
  for (const auto& [name, d] : k.attributes())
  {
    std::cout << "attribute " << name << " (" << d.components << " components)\n";
  }
  return 0;
}

int RunValidate(const ComplexOptions& o)
{
  const complex::Complex k = LoadComplex(o.Model);
  complex::DiscretizationOptions d;
  d.featureSize = o.FeatureSize;
  d.threads = o.Threads;
  const complex::ComplexMesh mesh = complex::discretizeComplex(k, d);
  complex::ValidationOptions v;
  v.tolerance = o.Tolerance;
  const complex::ValidationReport report = complex::validateComplex(k, mesh, v);
  if (o.Json)
  {
    Json out;
    out["tolerance"] = report.tolerance;
    out["ok"] = report.ok();
    for (const char* key : { "satisfied", "violated", "undeclared" })
    {
      out[key] = Json::array();
    }
    for (const auto& f : report.satisfied)
    {
      out["satisfied"].push_back(FindingJson(k, f));
    }
    for (const auto& f : report.violated)
    {
      out["violated"].push_back(FindingJson(k, f));
    }
    for (const auto& f : report.undeclared)
    {
      out["undeclared"].push_back(FindingJson(k, f));
    }
    std::cout << out.dump(2) << "\n";
  }
  else
  {
    std::cout << report.text(k);
  }
  return report.ok() ? 0 : 1;
}

int RunComplexMesh(const ComplexOptions& o)
{
  if (!IsComplexOutput(o.Output))
  {
    throw std::invalid_argument(
      "-o: a complex is written as .vtpc or .vtm, not '" + o.Output + "'");
  }
  const auto t0 = std::chrono::steady_clock::now();
  auto k = std::make_shared<const complex::Complex>(LoadComplex(o.Model));
  vtkNew<ictkComplexSource> source;
  source->SetComplex(k);
  source->SetFeatureSize(o.FeatureSize);
  source->SetNumberOfThreads(o.Threads);
  source->SetVolumeResolution(o.VolumeResolution);
  // The source reports failures as VTK errors; keep the message for our own error line.
  std::string failure;
  vtkNew<vtkCallbackCommand> onError;
  onError->SetClientData(&failure);
  onError->SetCallback(
    [](vtkObject*, unsigned long, void* clientData, void* callData) {
      *static_cast<std::string*>(clientData) = callData ? static_cast<const char*>(callData) : "";
    });
  source->AddObserver(vtkCommand::ErrorEvent, onError);
  source->Update();
  if (!failure.empty() || source->GetOutput()->GetNumberOfPartitionedDataSets() == 0)
  {
    const auto at = failure.find("): ");
    throw std::runtime_error("cannot discretise '" + o.Model + "'" +
      (failure.empty() ? std::string()
                       : ": " + failure.substr(at == std::string::npos ? 0 : at + 3)) +
      "; nothing written");
  }
  vtkPartitionedDataSetCollection* pdc = source->GetOutput();
  if (EndsWith(o.Output, ".vtpc"))
  {
    vtkNew<vtkXMLPartitionedDataSetCollectionWriter> writer;
    WriteComposite(writer, pdc, o.Output);
  }
  else
  {
    vtkNew<vtkMultiBlockDataSet> blocks;
    ictk::vtk::complexToMultiBlock(pdc, blocks);
    vtkNew<vtkXMLMultiBlockDataWriter> writer;
    WriteComposite(writer, blocks, o.Output);
  }
  const double seconds =
    std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::cout << "wrote " << o.Output << " (" << pdc->GetNumberOfPartitionedDataSets()
            << " cells) in " << std::fixed << std::setprecision(3) << seconds << " s\n";
  return 0;
}

} // namespace ictk::cli
