// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Models built in C++ and registered by name, so that applications (ictk eval, ictk sample, the
// benchmarks) can open them before the language front ends exist.

#include "FRep/Hypervolume.h"

#include <array>
#include <functional>
#include <string>
#include <vector>

namespace ictk::frep
{

struct ModelInfo
{
  std::string name;
  std::string description;
  /// A box that contains the model (for sampling and meshing).
  std::array<double, 3> boundsLo;
  std::array<double, 3> boundsHi;
  std::function<Hypervolume()> build;
};

/// Registers a model; throws std::invalid_argument if the name is taken (the models shipped with
/// ICTK are registered from the start).
void registerModel(ModelInfo info);
/// Returns the model or throws std::invalid_argument("unknown model 'name'; known models: ...").
const ModelInfo& findModel(const std::string& name);
std::vector<std::string> modelNames();

} // namespace ictk::frep
