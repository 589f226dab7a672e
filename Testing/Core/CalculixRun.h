// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// A real solver for the mesh tests (issues 6 and 21): writes a mesh as a CalculiX deck with an
// analysis appended, runs ccx on it and reads the node tables of its .dat file. Tests that use it
// fail, not skip, when ccx is missing: Scripts/setup installs calculix-ccx, so a missing solver is
// a broken install.

#include "Mesh/Calculix.h"
#include "Mesh/TetMesh.h"
#include "Mesh/Writers.h"

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>

namespace ictk::testing
{

struct CalculixRun
{
  int status = -1;
  std::string log;
  std::string dat;
  /// Per table title (the .dat's "displacements", "forces"): node id -> the three values.
  std::map<std::string, std::map<std::size_t, std::array<double, 3>>> tables;
};

/// Writes `mesh` with `appendix` (the *BOUNDARY, *STEP... lines) to a fresh folder and runs
/// `ccx` there (mesh::runCalculix, one thread; a failure is status 1 with its message after the
/// log). Throws std::runtime_error when ccx is not an existing file.
inline CalculixRun runCalculix(
  const mesh::TetMesh& mesh, const std::string& appendix, const std::string& ccx)
{
  namespace fs = std::filesystem;
  if (ccx.empty() || !fs::exists(ccx))
  {
    throw std::runtime_error("ccx (Debian package calculix-ccx) is not installed: run "
                             "Scripts/setup, which installs it");
  }
  std::random_device random;
  const fs::path dir = fs::temp_directory_path() / ("ictk-ccx-" + std::to_string(random()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  mesh::AbaqusOptions options;
  options.heading = "ICTK mesh test";
  options.appendix = appendix;
  mesh::writeAbaqus(mesh, (dir / "job.inp").string(), options);
  CalculixRun run;
  mesh::CalculixOptions calculix;
  calculix.executable = ccx;
  std::string failure;
  try
  {
    mesh::runCalculix((dir / "job.inp").string(), calculix);
    run.status = 0;
  }
  catch (const std::runtime_error& e)
  {
    run.status = 1;
    failure = std::string("\n") + e.what();
  }
  auto slurp = [](const fs::path& p)
  {
    std::ifstream in(p);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  };
  run.log = slurp(dir / "job.log") + failure;
  run.dat = slurp(dir / "job.dat");
  // " displacements (vx,vy,vz) for set NALL and time  0.1000000E+01", a blank line, then rows
  // "node v1 v2 v3" up to the next blank line after some rows.
  std::istringstream in(run.dat);
  std::string line, title;
  bool rows = false;
  while (std::getline(in, line))
  {
    std::istringstream fields(line);
    std::size_t node;
    std::array<double, 3> v{};
    if (fields >> node >> v[0] >> v[1] >> v[2])
    {
      run.tables[title][node] = v;
      rows = true;
      continue;
    }
    std::istringstream words(line);
    std::string first;
    if (words >> first)
    {
      title = first;
      rows = false;
    }
    else if (rows)
    {
      title.clear();
    }
  }
  fs::remove_all(dir);
  return run;
}

/// The 1-based ids (ccx node numbers) of the mesh's points with coordinate `axis` within
/// `tolerance` of `value`.
inline std::vector<std::size_t> nodesOnPlane(
  const mesh::TetMesh& m, int axis, double value, double tolerance)
{
  std::vector<std::size_t> ids;
  for (std::size_t i = 0; i < m.points.size(); ++i)
  {
    if (std::abs(m.points[i][std::size_t(axis)] - value) <= tolerance)
    {
      ids.push_back(i + 1);
    }
  }
  return ids;
}

/// The 1-based id of the point nearest to p.
inline std::size_t nearestNode(const mesh::TetMesh& m, const frep::Point3& p)
{
  std::size_t best = 0;
  double d = 1e300;
  for (std::size_t i = 0; i < m.points.size(); ++i)
  {
    const double dx = m.points[i][0] - p[0], dy = m.points[i][1] - p[1], dz = m.points[i][2] - p[2];
    if (dx * dx + dy * dy + dz * dz < d)
    {
      d = dx * dx + dy * dy + dz * dz;
      best = i + 1;
    }
  }
  return best;
}

/// The bar [0, 2] x [0, 0.2]^2 pulled by `force` at x = 2 (a pressure on the element faces there),
/// held at x = 0 in x only (one node also in y and z, another in z: free to contract). Returns
/// the appendix and the ids of the tip nodes.
inline std::string barPullDeck(
  const mesh::TetMesh& m, double force, std::vector<std::size_t>& tipNodes)
{
  const double tolerance = 1e-7, area = 0.2 * 0.2;
  std::ostringstream deck;
  deck << "*NSET, NSET=XFIX\n";
  for (const std::size_t id : nodesOnPlane(m, 0, 0, tolerance))
  {
    deck << id << ",\n";
  }
  deck << "*BOUNDARY\nXFIX, 1, 1\n"
       << nearestNode(m, { 0, 0, 0 }) << ", 2, 3\n"
       << nearestNode(m, { 0, 0.2, 0 }) << ", 3, 3\n";
  // C3D4 faces: S1 = 1-2-3, S2 = 1-4-2, S3 = 2-4-3, S4 = 3-4-1.
  static const int faceNodes[4][3] = { { 0, 1, 2 }, { 0, 3, 1 }, { 1, 3, 2 }, { 2, 3, 0 } };
  deck << "*SURFACE, NAME=TIP, TYPE=ELEMENT\n";
  for (std::size_t t = 0; t < m.tetrahedra.size(); ++t)
  {
    for (int f = 0; f < 4; ++f)
    {
      bool onTip = true;
      for (int n : faceNodes[f])
      {
        onTip = onTip &&
          std::abs(m.points[m.tetrahedra[t][static_cast<std::size_t>(n)]][0] - 2) <= tolerance;
      }
      if (onTip)
      {
        deck << t + 1 << ", S" << f + 1 << "\n";
      }
    }
  }
  char pressure[64];
  std::snprintf(pressure, sizeof pressure, "%.12e", -force / area);
  deck << "*STEP\n*STATIC\n*DLOAD\nTIP, P, " << pressure
       << "\n*NODE PRINT, NSET=NALL\nU\n*END STEP\n";
  tipNodes = nodesOnPlane(m, 0, 2, tolerance);
  return deck.str();
}

} // namespace ictk::testing
