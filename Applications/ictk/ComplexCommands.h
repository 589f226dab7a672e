// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The complex commands of the ictk tool: info, validate, and mesh into .vtpc / .vtm.

#include "Complex/Complex.h"

#include <string>

namespace ictk::cli
{

struct ComplexOptions
{
  std::string Model;
  std::string Output;
  bool Json = false;
  double FeatureSize = 0;
  double Tolerance = 0;
  int VolumeResolution = 0;
  int Threads = 0;
};

/// True when the command should treat the input as a complex (a .json file) or write a complex
/// format (.vtpc, .vtm).
bool IsComplexInput(const std::string& path);
/// A .json complex (with VTK's readers for its cells' files), or a .hf / .xml model as a complex
/// of one 3D cell.
complex::Complex LoadComplex(const std::string& path);
bool IsComplexOutput(const std::string& path);

int RunInfo(const ComplexOptions& o);
int RunValidate(const ComplexOptions& o);
int RunComplexMesh(const ComplexOptions& o);

} // namespace ictk::cli
