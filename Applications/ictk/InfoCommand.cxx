// SPDX-License-Identifier: BSD-3-Clause
// `ictk info`: the cells, relations and attributes of a complex (.json) or of a model file taken
// as a complex of one 3D cell.
#include "Command.h"
#include "Models.h"
#include "Options.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <iomanip>
#include <iostream>

namespace ictk::cli
{
namespace
{

using Json = nlohmann::json;

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

class InfoCommand final : public Command
{
public:
  CLI::App* add(CLI::App& app) override
  {
    CLI::App* info = app.add_subcommand(
      "info", "List the cells, relations and attributes of a complex (.json) or model");
    AddModel(info, o.Model, "A .json complex or a .hf / .xml / .vm / .blob model");
    AddJson(info, o.Json, "Print a JSON object");
    return info;
  }

  int run() override
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
        std::cout << " (" << pair[0].get<std::string>() << ", " << pair[1].get<std::string>()
                  << ")";
      }
      std::cout << "\n";
    }
    for (const auto& [name, d] : k.attributes())
    {
      std::cout << "attribute " << name << " (" << d.components << " components)\n";
    }
    return 0;
  }

private:
  struct
  {
    std::string Model;
    bool Json = false;
  } o;
};

} // namespace

std::unique_ptr<Command> infoCommand()
{
  return std::make_unique<InfoCommand>();
}

} // namespace ictk::cli
