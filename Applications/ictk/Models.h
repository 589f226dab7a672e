// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// What the commands' `model` argument names, resolved in one place: a registered model (`ictk
// models`), a model file (.hf, .xml) or a complex (.json). Failures are UserErrors; a model file's
// diagnostics are a ModelFileError (printed as they are: file:line:col, source line, caret).

#include "Command.h"

#include "Complex/Complex.h"
#include "Engine/DynamicModel.h"
#include "FRep/Hypervolume.h"
#include "FRep/ModelRegistry.h"
#include "Lang/Diagnostics.h"
#include "Lang/ModelFile.h"

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace ictk::cli
{

/// A registered model, by name.
const frep::ModelInfo& FindModel(const std::string& name);

/// A front end's diagnostics as the error `ictk` prints as they are.
ModelFileError AsModelFileError(const lang::ParseError& e);

/// Opens a model file (.hf, .xml), specialised to `params` (a HyperFun file's library may need
/// them where it wants numbers).
/// `ictk --strict` (main's, set once at start): model files' HyperFun read as HyperFun's own
/// interpreter reads it (lang::Limits::strictHyperFun).
void ReadHyperFunStrictly(bool strict);

lang::ModelFile OpenModelFile(const std::string& path, const std::vector<double>& params = {});

/// A model ready to sample: its hypervolume and a box that holds it.
struct ResolvedModel
{
  std::string Name;
  frep::Hypervolume Model;
  std::array<double, 3> Lo;
  std::array<double, 3> Hi;
  /// An animated .blob (docs/blobtree.md), which changes with time outside its domain: Model,
  /// Lo and Hi are then its instance at the time it was resolved at, and At() gives the others.
  std::shared_ptr<const lang::BlobModelFile> Animated;
  /// The model at time t: the instance of an animated .blob at t; any other model as it is (an
  /// XYZT model takes t at evaluation).
  ResolvedModel At(double t) const;
};

/// A registered model's name or a model file (.hf, .xml, .scn, .vm, .blob). An animated .blob is
/// instantiated at `time`; without one it is refused (a UserError saying to give --time or
/// --frames), never read at t = 0.
ResolvedModel ResolveModel(const std::string& nameOrPath, const std::vector<double>& params,
  std::optional<double> time = std::nullopt);

/// True for a complex (.json) input.
bool IsComplexInput(const std::string& path);
/// True for a complex output format (.vtpc, .vtm).
bool IsComplexOutput(const std::string& path);
/// A .json complex (with VTK's readers for its cells' files), or a .hf / .xml / .vm / .blob model
/// as a complex of one 3D cell.
complex::Complex LoadComplex(const std::string& path);

/// The engine's errors (a .icm model that reads but does not build) in the front ends' form
/// (file:line:col, the source line and a caret), so that they report like a model that does
/// not read.
lang::ParseError AsParseError(const engine::ModelError& e);

} // namespace ictk::cli
