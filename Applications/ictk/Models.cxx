// SPDX-License-Identifier: BSD-3-Clause
#include "Models.h"

#include "Command.h"
#include "Options.h"

#include "FRep/Bounds.h"
#include "FRep/Sampling.h"
#include "Lang/ComplexFile.h"
#include "Lang/Diagnostics.h"
#include "ictkComplexSource.h"

#include <fstream>
#include <stdexcept>

namespace ictk::cli
{

const frep::ModelInfo& FindModel(const std::string& name)
{
  try
  {
    return frep::findModel(name);
  }
  catch (const std::invalid_argument& e)
  {
    throw UserError(e.what());
  }
}

ModelFileError AsModelFileError(const lang::ParseError& e)
{
  // Every diagnostic, each "file:line:col: error: ..." with its source line and caret.
  std::string text = e.what();
  while (!text.empty() && text.back() == '\n')
  {
    text.pop_back();
  }
  return ModelFileError(text);
}

namespace
{
bool strictHyperFun = false;
}

void ReadHyperFunStrictly(bool strict)
{
  strictHyperFun = strict;
}

lang::ModelFile OpenModelFile(const std::string& path, const std::vector<double>& params)
{
  try
  {
    lang::Limits limits;
    limits.strictHyperFun = strictHyperFun;
    return lang::loadModelFile(path, limits, params);
  }
  catch (const lang::ParseError& e)
  {
    throw AsModelFileError(e);
  }
  catch (const std::invalid_argument& e)
  {
    throw UserError(e.what());
  }
}

ResolvedModel ResolvedModel::At(double t) const
{
  if (!this->Animated)
  {
    return *this;
  }
  lang::ModelFile file = this->Animated->at(t);
  const std::array<double, 6> b = *file.bounds;
  return { file.name, std::move(file.model), { b[0], b[2], b[4] }, { b[1], b[3], b[5] },
    this->Animated };
}

ResolvedModel ResolveModel(
  const std::string& nameOrPath, const std::vector<double>& params, std::optional<double> time)
{
  // A complex or a dynamic model is not one FRep model: say which commands take it rather than
  // "unknown model".
  if (IsComplexInput(nameOrPath) || HasExtension(nameOrPath, ".icm"))
  {
    throw UserError("'" + nameOrPath + "' is " +
      (IsComplexInput(nameOrPath) ? "a complex (.json): `ictk mesh`, `tetra`, `info`, `validate` "
                                    "and `render` take complexes"
                                  : "a dynamic model (.icm): `ictk run` and `render` take .icm "
                                    "models") +
      "; this command takes one FRep model (a registered name, a .hf or a .xml file)");
  }
  if (!lang::isModelFile(nameOrPath))
  {
    const frep::ModelInfo& info = FindModel(nameOrPath);
    return { info.name, info.build(), info.boundsLo, info.boundsHi, nullptr };
  }
  if (lang::isBlobFile(nameOrPath))
  {
    std::shared_ptr<const lang::BlobModelFile> blob;
    try
    {
      blob = std::make_shared<const lang::BlobModelFile>(lang::loadBlobModelFile(nameOrPath));
    }
    catch (const lang::ParseError& e)
    {
      throw AsModelFileError(e);
    }
    if (blob->animated())
    {
      // Reading an animated tree at t = 0 for want of a time would answer a question about
      // another time: the time must be given.
      if (!time)
      {
        throw UserError("'" + nameOrPath +
          "' is an animated BlobTree: give the time to instantiate it at, --time t (or --frames "
          "T0:T1:DT where the command takes it; docs/blobtree.md)");
      }
      lang::ModelFile file = blob->at(*time);
      const std::array<double, 6> b = *file.bounds;
      return { file.name, std::move(file.model), { b[0], b[2], b[4] }, { b[1], b[3], b[5] }, blob };
    }
    lang::ModelFile file = blob->at(0.0);
    const std::array<double, 6> b = *file.bounds;
    return { file.name, std::move(file.model), { b[0], b[2], b[4] }, { b[1], b[3], b[5] },
      nullptr };
  }
  lang::ModelFile file = OpenModelFile(nameOrPath, params);
  const std::array<double, 6> b = lang::modelFileBounds(file, params);
  return { file.name, std::move(file.model), { b[0], b[2], b[4] }, { b[1], b[3], b[5] }, nullptr };
}

bool IsComplexInput(const std::string& path)
{
  return lang::isComplexFile(path);
}

bool IsComplexOutput(const std::string& path)
{
  return HasExtension(path, ".vtpc") || HasExtension(path, ".vtm");
}

complex::Complex LoadComplex(const std::string& path)
{
  if (IsComplexInput(path))
  {
    return ictkComplexSource::ReadComplexFile(path);
  }
  if (!lang::isModelFile(path))
  {
    throw UserError("'" + path + "' is not a .json complex or a .hf / .xml / .vm / .blob model");
  }
  const lang::ModelFile model = OpenModelFile(path);
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
      throw UserError("'" + path + "' is empty in [-100, 100]^3");
    }
    box = { found->lo, found->hi };
  }
  complex::Complex k;
  k.name = model.name;
  k.addCell(complex::frepCell(model.name, {}, { model.model.geometry().function() }, box));
  return k;
}

lang::ParseError AsParseError(const engine::ModelError& e)
{
  lang::Diagnostic d;
  d.where.file = e.file;
  d.where.line = e.pos.line;
  d.where.column = e.pos.column;
  d.message = e.message;
  std::ifstream in(e.file);
  std::string line;
  for (int i = 0; i < e.pos.line && std::getline(in, line); ++i)
  {
  }
  if (e.pos.line > 0 && in)
  {
    d.sourceLine = line;
  }
  return lang::ParseError({ d });
}

} // namespace ictk::cli
