// SPDX-License-Identifier: BSD-3-Clause
// `ictk convert`: a model translated between HyperFun (.hf) and FRep XML (.xml); a registered
// model or a scene (.scn) can be exported too, and a scene written as one self-contained scene.
#include "Command.h"
#include "Models.h"

#include <CLI/CLI.hpp>

#include <iostream>

namespace ictk::cli
{
namespace
{

class ConvertCommand final : public Command
{
public:
  CLI::App* add(CLI::App& app) override
  {
    CLI::App* convert = app.add_subcommand("convert",
      "Translate a model between HyperFun (.hf) and FRep XML (.xml); write a scene (.scn) as one "
      "file");
    convert->add_option("input", this->Input, "A .hf or .xml file, or a registered model")
      ->required();
    convert
      ->add_option("output", this->Output,
        "The .hf or .xml file to write (or a .scn from a .scn: object references inlined)")
      ->required();
    return convert;
  }

  int run() override
  {
    if (!lang::isModelFile(this->Output))
    {
      throw UserError(
        "convert: '" + this->Output + "' is not a .hf or .xml file (or a .scn scene, from a .scn)");
    }
    auto open = [&]() -> lang::ModelFile
    {
      if (lang::isModelFile(this->Input))
      {
        return OpenModelFile(this->Input);
      }
      const frep::ModelInfo& info = FindModel(this->Input);
      return { info.name, 0, info.build(),
        std::array<double, 6>{ info.boundsLo[0], info.boundsHi[0], info.boundsLo[1],
          info.boundsHi[1], info.boundsLo[2], info.boundsHi[2] } };
    };
    if (lang::isSceneFile(this->Output))
    {
      // A scene is written from a scene, as one file: its `object` references inlined.
      if (!lang::isSceneFile(this->Input))
      {
        throw UserError("convert: a scene (" + this->Output + ") is written only from a scene");
      }
      try
      {
        lang::saveSceneFile(this->Input, this->Output);
      }
      catch (const lang::ParseError& e)
      {
        throw AsModelFileError(e);
      }
      catch (const std::exception& e)
      {
        throw UserError(e.what());
      }
      std::cout << "wrote " << this->Output << " (one self-contained scene)\n";
      return 0;
    }
    const lang::ModelFile model = open();
    try
    {
      lang::saveModelFile(model, this->Output);
    }
    catch (const std::exception& e)
    {
      throw UserError(e.what());
    }
    std::cout << "wrote " << this->Output << " (model '" << model.name << "')\n";
    return 0;
  }

private:
  std::string Input;
  std::string Output;
};

} // namespace

std::unique_ptr<Command> convertCommand()
{
  return std::make_unique<ConvertCommand>();
}

} // namespace ictk::cli
