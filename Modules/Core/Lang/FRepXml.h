// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The FRep XML interchange format (thesis 4.6.5, L2245-L2272): one element per entity, typed
// parameters as attributes, children in order.

#include "FRep/Hypervolume.h"
#include "Lang/Diagnostics.h"

#include <array>
#include <optional>
#include <string>

namespace ictk::lang
{

/// Everything an FRep XML file carries: the model and, optionally, its name, the size of its
/// parameter array and a box that holds it ({xmin, xmax, ymin, ymax, zmin, zmax}).
struct FRepXmlDocument
{
  std::string name;
  int parameterCount = 0;
  std::optional<frep::Hypervolume> model;
  std::optional<std::array<double, 6>> bounds;
};
FRepXmlDocument readFRepXmlDocument(
  const std::string& text, const std::string& fileName, const Limits& limits = {});
std::string writeFRepXmlDocument(const frep::Hypervolume& model, const std::string& name,
  int parameterCount, const std::optional<std::array<double, 6>>& bounds);

/// Reads a model; throws ParseError with file:line:col diagnostics.
frep::Hypervolume readFRepXml(
  const std::string& text, const std::string& fileName, const Limits& limits = {});
frep::Hypervolume readFRepXmlFile(const std::string& path, const Limits& limits = {});
/// Writes a model. Deterministic: the same model gives the same bytes.
std::string writeFRepXml(const frep::Hypervolume& model, const std::string& name = "model");

} // namespace ictk::lang
