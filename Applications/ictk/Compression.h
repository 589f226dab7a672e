// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The compression case run by CalculiX and written as a .vtu: the one step `ictk solve` and
// `ictk study --solve` share (SolveCommand.cxx), so a study's E_app is computed exactly as a
// solved mesh's.

#include "Output.h"

#include "Mesh/Calculix.h"

#include <optional>
#include <string>

namespace ictk::cli
{

struct CompressionSettings
{
  double displacement = 0;
  double binWidth = 0.01;
  /// The folder of the deck and CalculiX's files.
  std::string work;
  std::string ccx = "ccx";
  /// CalculiX's threads (>= 1).
  int threads = 1;
  bool progress = true;
  /// The deck's heading.
  std::string heading;
};

struct CompressionReport
{
  mesh::CompressionResult result;
  double largestVonMises = 0;
};

/// Compresses `mesh` between frictionless platens with CalculiX and writes the mesh with its
/// displacement, stress and von Mises stress through `file` (committed). nullopt when the
/// user interrupted ccx (Ctrl-C); errors of the deck or of ccx are thrown.
std::optional<CompressionReport> SolveCompression(
  const mesh::TetMesh& mesh, const CompressionSettings& settings, AtomicOutput& file);

} // namespace ictk::cli
