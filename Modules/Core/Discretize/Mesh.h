// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Plain discretisation results (OpenVDB tools style: data in, data out, no VTK). Points carry
// optional per-point attribute arrays so that cell attributes survive to every output point.

#include "FRep/Field.h"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace ictk::discretize
{

using frep::Box3;
using frep::Point3;

/// Named values per element (point, triangle, tetrahedron) with a fixed component count,
/// interleaved: one type for every mesh of the toolkit, as vtkDataArray is for VTK's.
struct DataArray
{
  std::string name;
  int components = 1;
  std::vector<double> values;
};
/// Values per point.
using PointArray = DataArray;

/// A triangle surface (2D cells, boundaries of 3D cells).
struct SurfaceMesh
{
  std::vector<Point3> points;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  std::vector<PointArray> pointData;
};

/// Polylines (1D cells); a closed curve repeats its first point index at the end.
struct CurveSet
{
  std::vector<Point3> points;
  std::vector<std::vector<std::uint32_t>> lines;
  std::vector<PointArray> pointData;
};

/// Points (0D cells).
struct PointSet
{
  std::vector<Point3> points;
  std::vector<PointArray> pointData;
};

/// Combinatorial facts about a triangle mesh, for tests and validation reports.
struct MeshTopology
{
  std::size_t vertices = 0; ///< vertices used by at least one triangle
  std::size_t edges = 0;
  std::size_t triangles = 0;
  std::size_t boundaryEdges = 0;       ///< edges with one triangle
  std::size_t nonManifoldEdges = 0;    ///< edges with three or more triangles
  std::size_t nonManifoldVertices = 0; ///< vertices whose triangle fan is not one disc or half-disc
  std::size_t inconsistentEdges = 0; ///< interior edges whose two triangles disagree on orientation
  std::size_t degenerateTriangles = 0; ///< triangles with a repeated vertex index
  std::size_t components = 0;          ///< connected components (by shared edges)
  long eulerCharacteristic = 0;        ///< V - E + F
  bool manifold() const
  {
    return nonManifoldEdges == 0 && nonManifoldVertices == 0 && inconsistentEdges == 0 &&
      degenerateTriangles == 0;
  }
  bool closed() const { return boundaryEdges == 0; }
};

MeshTopology analyzeTopology(const SurfaceMesh& mesh);

/// Total area and, for a closed consistently oriented mesh, the enclosed signed volume.
double surfaceArea(const SurfaceMesh& mesh);
double enclosedVolume(const SurfaceMesh& mesh);

/// Instrumentation: how many meshes (surfaces, trimmed patches, curve sets) this module's
/// algorithms have made in the process so far. Seed 003 item 36 asks that editing a scene and
/// ray casting it again makes none; the counter is how a test sees that. Thread safe.
std::int64_t meshesMade();

namespace detail
{
/// Counts one mesh made; called once by every public function of the module that makes one.
void countMeshMade();
} // namespace detail

} // namespace ictk::discretize
