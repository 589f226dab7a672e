// SPDX-License-Identifier: BSD-3-Clause
#include "ictkFRepModel.h"

#include "FRep/ModelRegistry.h"
#include "Lang/ModelFile.h"

#include <cstring>
#include <stdexcept>

namespace frep = ictk::frep;

const frep::Hypervolume* ictkFRepModel::Resolve(
  const char* modelName, const char* fileName, std::string& error)
{
  if (this->Explicit)
  {
    return this->Explicit.get();
  }
  if (fileName && *fileName)
  {
    return this->ResolveFile(fileName, error);
  }
  if (!modelName || !*modelName)
  {
    error = "no model: set ModelName or FileName, or call SetHypervolume()";
    return nullptr;
  }
  if (this->Resolved && this->ResolvedName == modelName)
  {
    return this->Resolved.get();
  }
  this->Resolved.reset();
  this->ReadPath.clear();
  try
  {
    const frep::ModelInfo& info = frep::findModel(modelName);
    this->Resolved = std::make_unique<frep::Hypervolume>(info.build());
    this->ResolvedName = modelName;
    this->ResolvedLo = info.boundsLo;
    this->ResolvedHi = info.boundsHi;
    return this->Resolved.get();
  }
  catch (const std::exception& e)
  {
    error = e.what();
    return nullptr;
  }
}

const frep::Hypervolume* ictkFRepModel::ResolveFile(const std::string& path, std::string& error)
{
  std::error_code ec;
  const auto modified = std::filesystem::last_write_time(path, ec);
  if (this->Resolved && this->ReadPath == path && !ec && modified == this->ReadTime)
  {
    return this->Resolved.get();
  }
  this->Resolved.reset();
  this->ReadPath.clear();
  this->ResolvedName.clear();
  try
  {
    ictk::lang::ModelFile file = ictk::lang::loadModelFile(path, {}, this->Parameters);
    const std::array<double, 6> b = ictk::lang::modelFileBounds(file, this->Parameters);
    this->ResolvedLo = { b[0], b[2], b[4] };
    this->ResolvedHi = { b[1], b[3], b[5] };
    this->Resolved = std::make_unique<frep::Hypervolume>(std::move(file.model));
    this->ReadPath = path;
    this->ReadTime = modified;
    return this->Resolved.get();
  }
  catch (const std::exception& e)
  {
    // ParseError's text is every diagnostic with its place; drop the trailing newline.
    error = e.what();
    while (!error.empty() && error.back() == '\n')
    {
      error.pop_back();
    }
    return nullptr;
  }
}

bool ictkFRepModel::SelectModelName(char*& modelName, char*& fileName, const char* name)
{
  const bool changed = ictkReplaceString(modelName, name);
  if (!changed && !this->Explicit && !(name && fileName))
  {
    return false;
  }
  if (name)
  {
    ictkReplaceString(fileName, nullptr);
  }
  this->Explicit.reset();
  return true;
}

bool ictkFRepModel::SelectFileName(char*& modelName, char*& fileName, const char* name)
{
  const bool changed = ictkReplaceString(fileName, name && *name ? name : nullptr);
  if (!changed && !this->Explicit)
  {
    return false;
  }
  if (fileName)
  {
    ictkReplaceString(modelName, nullptr);
  }
  this->Explicit.reset();
  this->ReadPath.clear();
  return true;
}

bool ictkReplaceString(char*& member, const char* value)
{
  if ((!value && !member) || (value && member && std::strcmp(value, member) == 0))
  {
    return false;
  }
  delete[] member;
  member = nullptr;
  if (value)
  {
    member = new char[std::strlen(value) + 1];
    std::strcpy(member, value);
  }
  return true;
}
