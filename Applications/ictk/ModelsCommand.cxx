// SPDX-License-Identifier: BSD-3-Clause
// `ictk models`: the registered models with their bounds and descriptions.
#include "Command.h"
#include "Options.h"

#include "FRep/ModelRegistry.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <iomanip>
#include <iostream>
#include <sstream>

namespace ictk::cli
{
namespace
{

std::string FormatBounds(const std::array<double, 3>& lo, const std::array<double, 3>& hi)
{
  std::ostringstream os;
  os << "[" << lo[0] << "," << hi[0] << "]x[" << lo[1] << "," << hi[1] << "]x[" << lo[2] << ","
     << hi[2] << "]";
  return os.str();
}

class ModelsCommand final : public Command
{
public:
  CLI::App* add(CLI::App& app) override
  {
    CLI::App* models =
      app.add_subcommand("models", "List the registered models (name, bounds, description)");
    AddJson(models, this->Json, "Print a JSON array");
    return models;
  }

  int run() override
  {
    nlohmann::ordered_json list = nlohmann::ordered_json::array();
    std::size_t width = 4;
    for (const std::string& name : frep::modelNames())
    {
      width = std::max(width, name.size());
    }
    for (const std::string& name : frep::modelNames())
    {
      const frep::ModelInfo& info = frep::findModel(name);
      if (this->Json)
      {
        list.push_back({ { "name", info.name }, { "description", info.description },
          { "bounds",
            { info.boundsLo[0], info.boundsHi[0], info.boundsLo[1], info.boundsHi[1],
              info.boundsLo[2], info.boundsHi[2] } } });
      }
      else
      {
        std::cout << std::left << std::setw(static_cast<int>(width)) << info.name << "  "
                  << FormatBounds(info.boundsLo, info.boundsHi) << "\n"
                  << std::string(width + 2, ' ') << info.description << "\n";
      }
    }
    if (this->Json)
    {
      std::cout << list.dump(2) << "\n";
    }
    return 0;
  }

private:
  bool Json = false;
};

} // namespace

std::unique_ptr<Command> modelsCommand()
{
  return std::make_unique<ModelsCommand>();
}

} // namespace ictk::cli
