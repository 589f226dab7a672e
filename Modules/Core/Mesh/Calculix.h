// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// CalculiX analyses of tetrahedral meshes (issue 15), without VTK: the compression case of a
// specimen between two frictionless platens, its Voigt and Reuss bounds from the written deck,
// running ccx in a folder, and the apparent modulus from the reactions it prints. The results
// file (.frd) is read by Mesh/Frd.h; the VTK layer turns both into a .vtu.
//
// The compression case. The platens are the planes z = z_min and z = z_max of the mesh's
// bounds: the nodes on them get u_z = 0 (bottom) and u_z = -d (top) and nothing else, so the
// specimen slides on them (frictionless) and expands laterally. What is left free is rigid motion
// in the platens' plane: x and y translation and rotation about z. Three constraints remove it
// and nothing more (they are statically determinate, so their reactions are zero): the anchor,
// the bottom node nearest the bottom face's centre, gets u_x = u_y = 0; the roller, the bottom
// node farthest from the anchor, gets no displacement across the line from the anchor to it
// (n . u = 0 with n perpendicular to that line; u_y = 0 or u_x = 0 when the line is along x or
// y, an *EQUATION otherwise). Free lateral expansion moves the roller along that line, so it is
// not restrained; a rotation about z would move it across.
//
// Bounds. For a prism between the platens with one Poisson ratio, the apparent modulus
// E_app = F H / (A d) (F the total platen reaction, H the height, A = V / H the cross-section)
// lies between the Reuss bound V / sum(V_i / E_i) (iso-stress: the complementary energy of a
// uniform sigma_zz) and the Voigt bound sum(E_i V_i) / V (iso-strain: the potential energy of the
// uniform uniaxial strain, which linear tetrahedra represent exactly, so the bound holds for the
// discrete solution too). Both are computed from the deck's materials, i.e. the binned moduli
// the solver sees.

#include "FRep/Progress.h"
#include "Mesh/TetMesh.h"
#include "Mesh/Writers.h"

#include <array>
#include <cstddef>
#include <map>
#include <string>
#include <vector>

namespace ictk::mesh
{

struct CompressionOptions
{
  /// How far the top platen moves down (model units), > 0.
  double displacement = 0;
  /// A node within this distance of the z_min or z_max plane is on a platen; 0: 1e-6 of the
  /// height.
  double tolerance = 0;
  /// The width of a modulus bin in ln E (AbaqusOptions::modulusBinWidth).
  double modulusBinWidth = 0.01;
  /// The deck's *HEADING (default: counts).
  std::string heading;
};

/// What a written compression deck holds.
struct CompressionCase
{
  double zMin = 0;
  double zMax = 0;
  /// H = z_max - z_min.
  double height = 0;
  /// The mesh's volume V.
  double volume = 0;
  /// A = V / H: the cross-section of a prism.
  double area = 0;
  /// d, the top platen's displacement (downwards).
  double displacement = 0;
  /// 1-based node ids (ccx numbers) on each platen.
  std::vector<std::size_t> bottomNodes;
  std::vector<std::size_t> topNodes;
  /// The nodes that hold the rigid motion in the platens' plane (1-based).
  std::size_t anchorNode = 0;
  std::size_t rollerNode = 0;
  /// The in-plane direction (n_x, n_y) the roller is held in: perpendicular to the line from the
  /// anchor.
  std::array<double, 2> rollerNormal{};
  /// sum(E_i V_i) / V and V / sum(V_i / E_i) over the deck's materials.
  double voigtModulus = 0;
  double reussModulus = 0;
  std::vector<DeckMaterial> materials;
};

/// Node set names of the deck (ccx keeps node and element sets apart, so no cell clashes).
inline constexpr const char* bottomPlatenSet = "PLATEN_BOTTOM";
inline constexpr const char* topPlatenSet = "PLATEN_TOP";

/// The .inp text after the model for the compression case (node sets, *STEP with *STATIC, the
/// platens' and the rigid-motion *BOUNDARY, *NODE FILE U, RF and *EL FILE S to the .frd,
/// *NODE PRINT RF with TOTALS=YES per platen to the .dat), and the case's figures. Throws
/// std::invalid_argument for a displacement that is not positive and finite, a mesh of no
/// height, or a platen with fewer than three nodes.
CompressionCase compressionCase(
  const TetMesh& mesh, const CompressionOptions& options, std::string* appendix);

/// Writes the compression deck to `path` (writeAbaqus with the appendix) and returns its case.
CompressionCase writeCompressionDeck(
  const TetMesh& mesh, const std::string& path, const CompressionOptions& options);

/// E_app = F H / (A d) for the magnitude F of the total platen reaction.
double apparentModulus(const CompressionCase& c, double force);

/// The sum(E V) / V and V / sum(V / E) of deck materials.
std::array<double, 2> voigtReuss(const std::vector<DeckMaterial>& materials);

struct CalculixOptions
{
  /// The ccx executable: a path, or a name looked up on PATH.
  std::string executable = "ccx";
  /// OMP_NUM_THREADS and CCX_NPROC_EQUATION_SOLVER of the run, >= 1.
  int threads = 1;
  /// Polled while ccx runs (the fraction stays 0 until it ends); false stops ccx (SIGTERM) and
  /// throws ictk::Cancelled.
  Progress progress;
};

struct CalculixRun
{
  /// The deck's folder and job name: ccx wrote <folder>/<job>.frd, .dat, .sta...
  std::string folder;
  std::string job;
  /// <folder>/<job>.log: ccx's standard output and error.
  std::string log;
  std::string frd;
  std::string dat;
  double seconds = 0;
};

/// Runs ccx on the deck (a .inp file) in the deck's folder: `ccx -i <job>`, its output kept in
/// <job>.log. Throws std::runtime_error naming the deck when ccx is not found (with the Debian
/// package to install), cannot be started, fails (non-zero exit, "*ERROR" in its log, no "Job
/// finished") or leaves no .frd: the message quotes the last lines of the log.
CalculixRun runCalculix(const std::string& deck, const CalculixOptions& options = {});

/// The "total force (fx,fy,fz) for set NAME" tables of a ccx .dat file (*NODE PRINT ... TOTALS),
/// by set name (as ccx prints it, upper case), the last time of each. Throws std::runtime_error
/// naming the file (and line) when it cannot be read or a table is malformed.
std::map<std::string, std::array<double, 3>> readDatTotalForces(const std::string& path);

struct CompressionResult
{
  CompressionCase compression;
  CalculixRun run;
  /// The total reactions (ccx's RF sums) on the top and bottom platens.
  std::array<double, 3> topForce{};
  std::array<double, 3> bottomForce{};
  /// F H / (A d) with F = -topForce[2] (the top platen pushes the specimen down, so ccx's
  /// reaction there is negative).
  double apparentModulus = 0;
};

/// The whole case: writes <folder>/<job>.inp, runs ccx there and reads the platens' reactions.
/// The .frd (per-node displacement and stress) is run.frd, for readFrd (Mesh/Frd.h).
CompressionResult solveCompression(const TetMesh& mesh, const std::string& folder,
  const CompressionOptions& options, const CalculixOptions& calculix = {},
  const std::string& job = "compression");

} // namespace ictk::mesh
