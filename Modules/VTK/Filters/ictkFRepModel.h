// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The model an ICTK FRep algorithm works on (ictkFRepSampler, ictkFRepEvaluator): a registered
// model by name, a model file (.hf, .xml, .vm) or a hypervolume given in C++, resolved in one
// place so that every algorithm reads, caches and reports errors the same way. C++ only.

#include "FRep/Hypervolume.h"

#include <array>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

struct ictkFRepModel
{
  /// Set by SetHypervolume(); wins over names while set.
  std::unique_ptr<ictk::frep::Hypervolume> Explicit;
  /// The model last resolved from a name or file (built once: building a large model costs
  /// more than looking it up), and a box that holds it.
  std::string ResolvedName;
  std::unique_ptr<ictk::frep::Hypervolume> Resolved;
  std::array<double, 3> ResolvedLo{ 0, 0, 0 };
  std::array<double, 3> ResolvedHi{ 0, 0, 0 };
  /// Values of the model's parameters; a HyperFun file is specialised to them when read.
  std::vector<double> Parameters;
  /// The model file last read, and when it was modified then (a changed file is read again);
  /// clear ReadPath to force a new read.
  std::string ReadPath;
  std::filesystem::file_time_type ReadTime{};

  /// The hypervolume: Explicit, else the file, else the registered model; null with `error`
  /// set (for a file: every diagnostic, "file:line:col: error: ...").
  const ictk::frep::Hypervolume* Resolve(
    const char* modelName, const char* fileName, std::string& error);

  /// The name and file setters of the algorithms that own modelName and fileName (char*
  /// properties): setting one clears the other and a hypervolume; true when the algorithm
  /// changed (call Modified()). A file whose name did not change is read again only when it
  /// changed on disk (Resolve compares its time).
  bool SelectModelName(char*& modelName, char*& fileName, const char* name);
  bool SelectFileName(char*& modelName, char*& fileName, const char* name);

private:
  const ictk::frep::Hypervolume* ResolveFile(const std::string& path, std::string& error);
};

/// Replaces a char* property of an algorithm (new[]-allocated, as vtkSetStringMacro keeps them);
/// true when the value changed.
bool ictkReplaceString(char*& member, const char* value);
