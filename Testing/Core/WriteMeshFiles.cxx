// SPDX-License-Identifier: BSD-3-Clause
// Writes the two-material bar (plus a cell without tetrahedra) in every format of ictkMesh and a
// manifest of what the files must hold, for mesh_files_check.py to read back with independent
// readers (meshio, gmsh).
//
// Usage: WriteMeshFiles FOLDER

#include "Mesh/Quality.h"
#include "Mesh/Writers.h"
#include "MeshTestModels.h"

#include <cstdio>
#include <exception>
#include <fstream>

int main(int argc, char** argv)
{
  if (argc != 2)
  {
    std::fprintf(stderr, "usage: WriteMeshFiles FOLDER\n");
    return 2;
  }
  try
  {
    using namespace ictk;
    const std::string dir = argv[1];
    // Cell names the formats must carry or sanitise; E varies along the steel part.
    const auto k = lang::readComplexJson(
      ictk::testing::barJson("t_0^3 steel", "alu", "200000 + 1000 * x[1]", /*spare=*/true),
      "bar.json");
    const mesh::TetMesh m = ictk::testing::barMesh(k, 10, 2);
    mesh::writeGmsh(m, dir + "/bar22.msh", mesh::GmshVersion::V22);
    mesh::writeGmsh(m, dir + "/bar41.msh", mesh::GmshVersion::V41);
    mesh::writeAbaqus(m, dir + "/bar.inp");
    mesh::writeMedit(m, dir + "/bar.mesh");

    const auto q = mesh::measureQuality(m);
    const auto materials = mesh::solidMaterials(m);
    const auto setNames = mesh::abaqusSetNames(m);
    std::ofstream out(dir + "/manifest.txt");
    // points tetrahedra, then one line per material with tetrahedra:
    // id tetrahedra volume youngs_modulus set_name name...
    out.precision(17);
    out << q.points << " " << q.tetrahedra << "\n";
    for (const auto& s : materials)
    {
      const auto& mq = q.materials[static_cast<std::size_t>(s.material - 1)];
      out << s.material << " " << mq.tetrahedra << " " << mq.volume << " " << s.youngsModulus << " "
          << s.setName << " " << s.name << "\n";
    }
    if (!out.flush())
    {
      throw std::runtime_error("cannot write the manifest");
    }
    std::printf("%s", mesh::formatQualityReport(q).c_str());
    return 0;
  }
  catch (const std::exception& e)
  {
    std::fprintf(stderr, "WriteMeshFiles: %s\n", e.what());
    return 1;
  }
}
