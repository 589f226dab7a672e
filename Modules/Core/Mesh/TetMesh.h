// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Tetrahedral meshes of implicit complexes for FEA (issue 6): every tetrahedron knows the 3D cell
// it belongs to, its material, and the attribute values of the complex at it. The backends
// (CGAL Mesh_3, TetGen) live in their own optional libraries; this library holds the mesh, its
// checks, its quality report and the writers, all permissively licensed.

#include "Complex/Complex.h"
#include "Discretize/Mesh.h"
#include "FRep/Progress.h"

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace ictk::mesh
{

using frep::Point3;

/// Values per tetrahedron.
using TetArray = discretize::DataArray;

struct TetMesh
{
  std::vector<Point3> points;
  /// Positively oriented: (b - a) . ((c - a) x (d - a)) > 0.
  std::vector<std::array<std::uint32_t, 4>> tetrahedra;
  /// Per tetrahedron: the id of the complex's 3D cell it lies in.
  std::vector<complex::CellId> cells;
  /// Per tetrahedron: its material, 1-based, one per 3D cell in ascending cell id
  /// (materialNames[materialId - 1] is the cell's name).
  std::vector<std::int32_t> materials;
  std::vector<std::string> materialNames;
  /// Attribute values per tetrahedron (sampled at centroids).
  std::vector<TetArray> cellData;
  /// The element size it was made for (TetraOptions::size); 0 when unknown. The validity check's
  /// limits are relative to it.
  double size = 0;
};

/// Options shared by the backends.
struct TetraOptions
{
  /// Target edge length (model units), > 0.
  double size = 0;
  /// Identical output run to run (no random perturbation, fixed seeds).
  bool deterministic = false;
  /// Refuse meshes estimated above this many tetrahedra (the estimate is in the message).
  double maxTetrahedra = 2e7;
  /// Minimum dihedral angle the quality steps aim at (degrees), where the backend supports it.
  double minDihedralDegrees = 12;
  int threads = 0;
  /// Called with the completed fraction; return false to cancel (throws frep::Cancelled).
  Progress progress;
};

/// The number of tetrahedra a mesh of the given total volume and edge length will have, about
/// (regular tetrahedra of edge `size`, volume size^3 / (6 sqrt 2)).
double estimateTetrahedra(double volume, double size);

/// 6 x the signed volume of (a, b, c, d), (b - a) . ((c - a) x (d - a)): positive for a
/// positively oriented tetrahedron.
double orientation(const Point3& a, const Point3& b, const Point3& c, const Point3& d);

/// Checks indices, materials and the per-tetrahedron arrays; throws std::invalid_argument naming
/// the first problem.
void validateStructure(const TetMesh& mesh);
/// validateStructure, and every tetrahedron positively oriented. What a solver needs beyond that
/// is checkValidity's (Validity.h).
void validate(const TetMesh& mesh);

} // namespace ictk::mesh
