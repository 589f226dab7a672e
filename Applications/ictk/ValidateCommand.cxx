// SPDX-License-Identifier: BSD-3-Clause
// `ictk validate`: every declared boundary and containment pair of a complex checked against the
// geometry (exit 1 when one is violated), and the pairs that hold without being declared.
#include "Command.h"
#include "Models.h"
#include "Options.h"

#include "Complex/Validation.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <iostream>

namespace ictk::cli
{
namespace
{

using Json = nlohmann::json;

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

class ValidateCommand final : public Command
{
public:
  CLI::App* add(CLI::App& app) override
  {
    CLI::App* validate = app.add_subcommand("validate",
      "Check every declared boundary and containment pair against the geometry; exit 1 when one "
      "is violated");
    AddModel(validate, o.Model, "A .json complex");
    AddSize(validate, o.FeatureSize, "Discretisation step (default: 1/64 of the complex's size)");
    validate->add_option("--tolerance", o.Tolerance,
      "Distance within which a point counts as on a set (default: a quarter of the step)");
    AddThreads(validate, o.Threads);
    AddJson(validate, o.Json, "Print a JSON report");
    return validate;
  }

  int run() override
  {
    CheckSize(o.FeatureSize);
    CheckThreads(o.Threads);
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

private:
  struct
  {
    std::string Model;
    double FeatureSize = 0;
    double Tolerance = 0;
    int Threads = 0;
    bool Json = false;
  } o;
};

} // namespace

std::unique_ptr<Command> validateCommand()
{
  return std::make_unique<ValidateCommand>();
}

} // namespace ictk::cli
