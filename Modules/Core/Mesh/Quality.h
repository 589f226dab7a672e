// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Quality and volume checks of tetrahedral meshes (issue 6): element shape measures (dihedral
// angles, radius-edge ratio), counts and volumes per material, and the exact volume of a 3D
// implicit cell (interval subdivision of its solid field) to compare the mesh against.

#include "Complex/Complex.h"
#include "Mesh/TetMesh.h"

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace ictk::mesh
{

/// Shape measures of one tetrahedron.
struct TetShape
{
  /// Signed: positive for a positively oriented tetrahedron.
  double volume = 0;
  double minDihedralDegrees = 0;
  double maxDihedralDegrees = 0;
  /// Circumradius / shortest edge: sqrt(6)/4 = 0.6124 for a regular tetrahedron (the least
  /// possible); +inf for a flat one.
  double radiusEdgeRatio = 0;
};
TetShape tetShape(const Point3& a, const Point3& b, const Point3& c, const Point3& d);

struct MaterialQuality
{
  std::int32_t material = 0;
  std::string name;
  std::size_t tetrahedra = 0;
  double volume = 0;
  /// NaN when the material has no tetrahedra.
  double minDihedralDegrees = 0;
};

struct QualityReport
{
  std::size_t points = 0;
  std::size_t tetrahedra = 0;
  /// One entry per material name (index = material id - 1), in order.
  std::vector<MaterialQuality> materials;
  double volume = 0;
  /// Over all tetrahedra. With no tetrahedra the angles and ratios are NaN.
  double minDihedralDegrees = 0;
  double maxDihedralDegrees = 0;
  /// The 1st percentile of the tetrahedra's smallest dihedral angles (nearest rank): 99% of the
  /// tetrahedra have no angle below it.
  double minDihedralPercentile1Degrees = 0;
  double maxRadiusEdgeRatio = 0;
  double meanRadiusEdgeRatio = 0;
  /// Tetrahedra with volume <= 0 (validate() rejects them).
  std::size_t nonPositive = 0;
};

/// Counts, volumes and shape measures of the mesh. Tetrahedra whose material is not a valid id
/// count in the totals only.
QualityReport measureQuality(const TetMesh& mesh);
/// A few lines of text: counts, angles, ratios, volume per material.
std::string formatQualityReport(const QualityReport& report);

/// The volume of a solid {f >= 0} inside `bounds`, by adaptive interval subdivision: boxes the
/// field's interval bound proves inside add their volume, boxes proven outside nothing, undecided
/// boxes are bisected (longest edge first) until their longest edge is at most `tolerance`, and
/// then counted by sampling 4 x 4 x 4 points. The zero set {f = 0} is taken to have no volume
/// (boxes with f <= 0 add nothing), as for every non-degenerate FRep solid.
struct VolumeEstimate
{
  double volume = 0;
  /// The volume of the boxes proven inside (a lower bound of the exact volume).
  double provenInside = 0;
  /// The volume of the undecided leaf boxes (provenInside + undecided is an upper bound).
  double undecided = 0;
  /// A guaranteed bound of |volume - exact| (each sampled box can be wrong by at most the larger of
  /// its counted and uncounted parts); the actual error is usually far smaller.
  double errorBound = 0;
  std::size_t sampledBoxes = 0;
};
/// Throws std::invalid_argument for a tolerance that is not positive or is below 1/4096 of the
/// box's longest edge (too many boxes), or for an invalid box.
VolumeEstimate integrateVolume(
  const frep::Field& solid, const frep::Box3& bounds, double tolerance);

/// The volume of a 3D cell: implicit cells (F, C, V: no carriers) by integrateVolume on the
/// intersection of their inside fields over their bounds; explicit solids (B) exactly from their
/// tetrahedra. Throws std::invalid_argument naming the cell for other cells.
VolumeEstimate cellVolumeEstimate(const complex::Cell& cell, double tolerance);
double cellVolume(const complex::Cell& cell, double tolerance);

/// The mesh's volume per material against its cell's volume.
struct VolumeComparison
{
  std::int32_t material = 0;
  std::string name;
  complex::CellId cell = 0;
  double meshVolume = 0;
  double cellVolume = 0;
  double cellErrorBound = 0;
  /// (meshVolume - cellVolume) / cellVolume.
  double relativeDifference = 0;
};
/// One entry per material; the cell of a material is the complex's cell of the same name. Where
/// 3D cells overlap, the lower-priority cell's material holds less than its cell's volume.
/// Throws std::invalid_argument when a material has no cell of its name in the complex.
std::vector<VolumeComparison> compareVolumes(
  const TetMesh& mesh, const complex::Complex& complex, double tolerance);
std::string formatVolumeComparison(const std::vector<VolumeComparison>& comparison);

} // namespace ictk::mesh
