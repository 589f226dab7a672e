// SPDX-License-Identifier: BSD-3-Clause
#include "Mesh/Backends/Backends.h"

#ifdef ICTK_HAVE_MESH_CGAL
#include "Mesh/CGAL/MeshCgal.h"
#endif
#ifdef ICTK_HAVE_MESH_TETGEN
#include "Mesh/TetGen/MeshTetGen.h"
#endif

#include <algorithm>
#include <cctype>
#include <stdexcept>

namespace ictk::mesh
{

const char* backendName(Backend backend)
{
  return backend == Backend::Cgal ? "cgal" : "tetgen";
}

std::optional<Backend> backendFromName(const std::string& name)
{
  std::string lower = name;
  std::transform(lower.begin(), lower.end(), lower.begin(),
    [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (lower == "cgal")
  {
    return Backend::Cgal;
  }
  if (lower == "tetgen")
  {
    return Backend::TetGen;
  }
  return std::nullopt;
}

std::vector<Backend> availableBackends()
{
  std::vector<Backend> backends;
#ifdef ICTK_HAVE_MESH_CGAL
  backends.push_back(Backend::Cgal);
#endif
#ifdef ICTK_HAVE_MESH_TETGEN
  backends.push_back(Backend::TetGen);
#endif
  return backends;
}

bool hasBackend(Backend backend)
{
  const std::vector<Backend> built = availableBackends();
  return std::find(built.begin(), built.end(), backend) != built.end();
}

std::optional<Backend> defaultBackend()
{
  const std::vector<Backend> built = availableBackends();
  return built.empty() ? std::nullopt : std::optional<Backend>(built.front());
}

namespace
{
TetMesh run(const complex::Complex& complex, Backend backend, const TetraOptions& options)
{
#ifdef ICTK_HAVE_MESH_CGAL
  if (backend == Backend::Cgal)
  {
    return tetrahedralizeCgal(complex, options);
  }
#endif
#ifdef ICTK_HAVE_MESH_TETGEN
  if (backend == Backend::TetGen)
  {
    return tetrahedralizeTetGen(complex, options);
  }
#endif
  (void)complex;
  (void)options;
  throw std::invalid_argument(std::string("the ") + backendName(backend) +
    " backend was not built (configure with ICTK_ENABLE_GPL_BACKENDS=ON and its library)");
}
} // namespace

TetMesh tetrahedralize(const complex::Complex& complex, Backend backend,
  const TetraOptions& options, ValidityReport* validity)
{
  TetMesh mesh = run(complex, backend, options);
  mesh.size = options.size;
  removeFlatBoundaryTetrahedra(mesh, options.size);
  const ValidityReport report = checkValidity(mesh, options.size, &complex);
  requireValid(report, std::string("the ") + backendName(backend) + " backend's mesh");
  if (validity)
  {
    *validity = report;
  }
  return mesh;
}

} // namespace ictk::mesh
