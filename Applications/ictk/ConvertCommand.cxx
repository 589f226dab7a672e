// SPDX-License-Identifier: BSD-3-Clause
// `ictk convert`: a model translated between HyperFun (.hf) and FRep XML (.xml); a registered
// model, a scene (.scn) or a BlobTree (.blob, an animated one at --time) can be exported too, a
// scene written as one self-contained scene and a BlobTree as a .blob (whole, or its instance at
// --time).
#include "Command.h"
#include "Models.h"

#include <CLI/CLI.hpp>

#include <cmath>
#include <iostream>
#include <optional>

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
      "file, a BlobTree (.blob) whole or at a time");
    convert
      ->add_option(
        "input", this->Input, "A .hf, .xml, .vm, .scn or .blob file, or a registered model")
      ->required();
    convert
      ->add_option("output", this->Output,
        "The .hf or .xml file to write (or a .scn from a .scn: object references inlined; a .blob "
        "from a .blob)")
      ->required();
    convert->add_option("--time", this->Time,
      "A .blob's instance at time t (its static tree, or its model as .hf/.xml); an animated "
      ".blob written as .hf or .xml needs it");
    return convert;
  }

  int run() override
  {
    if (!lang::isModelFile(this->Output))
    {
      throw UserError("convert: '" + this->Output +
        "' is not a .hf or .xml file (or a .scn scene, from a .scn; a .blob, from a .blob)");
    }
    if (this->Time && !lang::isBlobFile(this->Input))
    {
      // An XYZT model keeps its time dimension in either form; freezing it is not a conversion.
      throw UserError("convert: --time instantiates a .blob; '" + this->Input +
        "' is converted whole (an XYZT model keeps its time dimension)");
    }
    if (lang::isBlobFile(this->Input))
    {
      return this->convertBlob();
    }
    if (lang::isBlobFile(this->Output))
    {
      throw UserError("convert: a BlobTree (" + this->Output +
        ") is written only from a .blob: a hypervolume's expression has no skeletal elements and "
        "operators to recover");
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
  /// A .blob read once: written as a .blob (whole, or its instance at --time), or its model at
  /// --time (without one: when it is static) as .hf or .xml.
  int convertBlob()
  {
    if (lang::isSceneFile(this->Output))
    {
      throw UserError("convert: a scene (" + this->Output + ") is written only from a scene");
    }
    lang::BlobModelFile blob;
    try
    {
      blob = lang::loadBlobModelFile(this->Input);
    }
    catch (const lang::ParseError& e)
    {
      throw AsModelFileError(e);
    }
    if (this->Time && !std::isfinite(*this->Time))
    {
      throw UserError("--time must be a finite number");
    }
    try
    {
      if (lang::isBlobFile(this->Output))
      {
        lang::saveBlobFile(blob, this->Output, this->Time);
        std::cout << "wrote " << this->Output << " (BlobTree '" << blob.name << "'";
        if (this->Time)
        {
          std::cout << ", its instance at t = " << *this->Time;
        }
        std::cout << (!this->Time && blob.animated() ? ", animated)\n" : ")\n");
        return 0;
      }
      if (blob.animated() && !this->Time)
      {
        // Its t = 0 instance would be a silent answer about another time.
        throw UserError("'" + this->Input +
          "' is an animated BlobTree: give the time to instantiate it at, --time t (a .blob "
          "output keeps its animations; docs/blobtree.md)");
      }
      lang::saveModelFile(blob.at(this->Time.value_or(0.0)), this->Output);
    }
    catch (const UserError&)
    {
      throw;
    }
    catch (const std::exception& e)
    {
      throw UserError(e.what());
    }
    std::cout << "wrote " << this->Output << " (model '" << blob.name << "'";
    if (this->Time)
    {
      std::cout << " at t = " << *this->Time;
    }
    std::cout << ")\n";
    return 0;
  }

  std::string Input;
  std::string Output;
  std::optional<double> Time;
};

} // namespace

std::unique_ptr<Command> convertCommand()
{
  return std::make_unique<ConvertCommand>();
}

} // namespace ictk::cli
