// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// `ictk tetra`: a tetrahedral mesh of a complex for FEA, every tetrahedron labelled by cell and
// material, with a quality report.

#include <string>

namespace CLI
{
class App;
}

namespace ictk::cli
{

struct TetraOptions
{
  std::string Model;
  std::string Output;
  std::string Backend;
  double Size = 0;
  bool Deterministic = false;
  bool Json = false;
  std::string MshVersion = "4.1";
  double MaxTetrahedra = 2e7;
  int Threads = 0;
};

CLI::App* AddTetraCommand(CLI::App& app, TetraOptions& options);
int RunTetra(const TetraOptions& options);

} // namespace ictk::cli
