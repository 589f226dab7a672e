// SPDX-License-Identifier: BSD-3-Clause
// `ictk eval`: a model's value at a point, and with --json its gradient, outward normal,
// membership and attributes.
#include "Command.h"
#include "Models.h"
#include "Options.h"

#include "FRep/Evaluators.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cmath>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>

namespace ictk::cli
{
namespace
{

struct EvalOptions
{
  std::string Model;
  std::string At;
  double Time = 0;
  std::string Params;
  bool Json = false;
};

class EvalCommand final : public Command
{
public:
  CLI::App* add(CLI::App& app) override
  {
    CLI::App* eval = app.add_subcommand("eval", "Evaluate a model at a point");
    AddModel(eval, o.Model, "Model name (see `ictk models`) or a .hf / .xml / .vm / .blob file");
    eval->add_option("--at", o.At, "The point: x,y,z or x,y,z,t")->required();
    this->TimeOption =
      eval->add_option("--time", o.Time, "Time t (default 0), for a point given as x,y,z");
    AddParams(eval, o.Params);
    AddJson(
      eval, o.Json, "Print a JSON object with value, gradient, normal, membership and attributes");
    return eval;
  }

  int run() override
  {
    const std::vector<double> at =
      ParseNumbers(o.At, "--at", { "x", "y", "z", "t" }, 3, 4, "x,y,z or x,y,z,t");
    std::array<double, 4> p{ at[0], at[1], at[2], at.size() > 3 ? at[3] : 0.0 };
    if (this->TimeOption->count() > 0)
    {
      if (at.size() > 3)
      {
        throw UserError("--time: the point already has a time (--at x,y,z,t); give one of them");
      }
      if (!std::isfinite(o.Time))
      {
        throw UserError("--time must be a finite number");
      }
      p[3] = o.Time;
    }
    const std::vector<double> params = ParseParameters(o.Params);
    // An animated .blob is instantiated at the point's time, when the command gives one.
    const bool timed = at.size() > 3 || this->TimeOption->count() > 0;
    const ResolvedModel model =
      ResolveModel(o.Model, params, timed ? std::optional<double>(p[3]) : std::nullopt);

    const frep::Hypervolume& hv = model.Model;
    std::vector<double> attributes(hv.attributeComponentCount());
    double value = 0;
    std::unique_ptr<frep::HypervolumeEvaluator> evaluator;
    try
    {
      evaluator = std::make_unique<frep::HypervolumeEvaluator>(hv, params);
    }
    catch (const std::invalid_argument& e)
    {
      throw UserError(std::string("--params: ") + e.what());
    }
    evaluator->eval(p, value, attributes.data());
    if (!o.Json)
    {
      std::cout << std::setprecision(17) << value << "\n";
      return 0;
    }

    frep::GradientEvaluator gradient(frep::Tape::compile(hv.geometry().function()), params);
    const frep::ValueGradient vg = gradient.eval(p[0], p[1], p[2], p[3]);
    const std::array<double, 3> normal = frep::outwardNormal(vg);

    nlohmann::ordered_json out;
    out["model"] = model.Name;
    out["point"] = p;
    out["value"] = value;
    out["gradient"] = vg.gradient;
    out["normal"] = normal;
    out["membership"] = evaluator->membership(p);
    nlohmann::ordered_json attributeValues = nlohmann::ordered_json::object();
    std::size_t k = 0;
    for (const frep::Attribute& a : hv.attributes())
    {
      if (a.components.size() == 1)
      {
        attributeValues[a.name] = attributes[k++];
      }
      else
      {
        nlohmann::ordered_json values = nlohmann::ordered_json::array();
        for (std::size_t c = 0; c < a.components.size(); ++c)
        {
          values.push_back(attributes[k++]);
        }
        attributeValues[a.name] = values;
      }
    }
    out["attributes"] = attributeValues;
    // NaN and infinities have no JSON spelling: nlohmann writes them as null.
    std::cout << out.dump(2) << "\n";
    return 0;
  }

private:
  EvalOptions o;
  CLI::Option* TimeOption = nullptr;
};

} // namespace

std::unique_ptr<Command> evalCommand()
{
  return std::make_unique<EvalCommand>();
}

} // namespace ictk::cli
