// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Per-element materials from a CT scan (issue 15): the tetrahedra of the cells that come from the
// scan get a density and a Young's modulus from the Hounsfield units under them, the others (an
// implant, an interface shell, soft tissue) a fixed material by their cell's name. This is the
// one place the laws live; docs/medical.md describes them and their defaults.
//
// The laws, chosen by the user:
//     density  rho = a + b HU                (g/cm^3)
//     modulus  E   = a + b rho^c             (MPa; rho below 0 counts as 0; at least a floor)
// Defaults: rho = 1 + 0.001 HU (the water-equivalent scale that defines HU: water 1 g/cm^3 at
// 0 HU; uncalibrated, a phantom calibration of the scanner should replace it) and
// E = 6850 rho^1.49 (Morgan, Bayraktar and Keaveny 2003, J. Biomech. 36:897, trabecular bone,
// all anatomic sites pooled, rho the apparent density).
//
// Sampling: at the element's centroid, or Bonemat-style, E integrated over the element (its
// mean over the tetrahedron: the 4-point degree-2 rule on each of the 8 equal-volume tetrahedra
// of one midpoint subdivision, 32 points of equal weight; Bonemat's default integrates E rather
// than HU, so does this).
//
// Binning, so that a solver deck has a few materials and not one per element, is the deck's
// (Writers.h deckMaterials, 1 % in ln E by default): the arrays here keep every element's own
// values. A density below 0.001 g/cm^3 (air) is written as 0.001, so a solver accepts it.

#include "FRep/Field.h"
#include "Mesh/TetMesh.h"

#include <map>
#include <set>
#include <string>

namespace ictk::mesh
{

struct DensityLaw
{
  double a = 1.0;
  double b = 0.001;
  double operator()(double hu) const { return a + b * hu; }
};

struct ModulusLaw
{
  double a = 0;
  double b = 6850;
  double c = 1.49;
  double operator()(double rho) const;
  /// The density giving modulus E (NaN when E <= a).
  double density(double modulus) const;
};

/// A fixed material (an implant, a shell, soft tissue). Units as the laws': MPa and g/cm^3.
struct FixedMaterial
{
  double youngsModulus = 0;
  double poissonRatio = 0.3;
  double density = 1;
};

enum class ScanSampling
{
  Centroid,
  Integrated
};

struct ScanMaterialOptions
{
  DensityLaw density;
  ModulusLaw modulus;
  /// Poisson ratio of the scan's elements.
  double poissonRatio = 0.3;
  ScanSampling sampling = ScanSampling::Integrated;
  /// The lowest modulus a scan element gets (air and fat give rho <= 0), MPa.
  double minimumModulus = 1;
  /// The names of the cells (TetMesh::materialNames) whose elements come from the scan.
  std::set<std::string> scanCells;
  /// The material of every other cell, by name.
  std::map<std::string, FixedMaterial> fixed;
};

struct ScanMaterialSummary
{
  /// The scan elements' moduli (0 when there are none).
  double minModulus = 0;
  double maxModulus = 0;
};

/// Adds (replacing arrays of these names) the per-tetrahedron arrays "label" (the material id,
/// 1-based, TetMesh::materials), "density", "youngs_modulus" and "poisson_ratio". `hu` is the
/// scan's field (Hounsfield units at a point; voxel::voxelField(grid, 0) gives it). Throws
/// std::invalid_argument for a cell that is neither a scan cell nor a fixed one (naming it), a
/// name in the options that is no cell of the mesh, bad options (a non-positive minimum modulus,
/// a Poisson ratio outside (-1, 0.5)), or a HU value that is NaN (naming the
/// element and the point).
ScanMaterialSummary assignScanMaterials(
  TetMesh& mesh, const frep::Field& hu, const ScanMaterialOptions& options);

/// The checks of assignScanMaterials that need no mesh (a study runs them before meshing):
/// `materialNames` as TetMesh::materialNames.
void checkScanMaterials(
  const ScanMaterialOptions& options, const std::vector<std::string>& materialNames);

/// The modulus of one HU value under the options' laws and floor (what assignScanMaterials gives
/// an element whose sampled HU is `hu`, in centroid mode).
double scanModulus(double hu, const ScanMaterialOptions& options);

} // namespace ictk::mesh
