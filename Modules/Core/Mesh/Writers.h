// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Solver file formats for tetrahedral meshes (issue 6), plain C++: Gmsh .msh 2.2 and 4.1
// (ASCII), Abaqus / CalculiX .inp, MEDIT .mesh. Every material becomes a labelled group named
// after its cell (Gmsh physical group, Abaqus element set, MEDIT reference = material id).
//
// Each writer writes a temporary file next to the target and renames it into place once
// everything is written, so a failure never leaves a partial file. Errors are
// std::invalid_argument (a mesh the format cannot take) or std::runtime_error (I/O), both naming
// the file.

#include "Mesh/TetMesh.h"

#include <cstdint>
#include <string>
#include <vector>

namespace ictk::mesh
{

enum class GmshVersion
{
  V22, ///< MSH 2.2 ASCII: $PhysicalNames, elements tagged (physical, elementary) = material id
  V41, ///< MSH 4.1 ASCII: one volume entity per material, tagged with its physical group
};

/// Physical tags are the material ids; a physical group's name is its cell's name. Materials
/// without tetrahedra are left out. Point and element tags are 1-based indices into the mesh.
void writeGmsh(
  const TetMesh& mesh, const std::string& path, GmshVersion version = GmshVersion::V41);

/// MEDIT .mesh (MeshVersionFormatted 2): Vertices (reference 0) and Tetrahedra with reference =
/// material id.
void writeMedit(const TetMesh& mesh, const std::string& path);

/// The elastic material of one mesh material, from the per-tetrahedron arrays
/// "youngs_modulus", "poisson_ratio" and "density" (volume-weighted means over its tetrahedra).
struct SolidMaterial
{
  std::int32_t material = 0;
  /// The cell's name.
  std::string name;
  /// Its element set / material name in .inp files (letters, digits and '_', unique).
  std::string setName;
  std::size_t tetrahedra = 0;
  double youngsModulus = 0;
  /// 0 when the mesh has no "poisson_ratio" array.
  double poissonRatio = 0;
  /// NaN when the mesh has no "density" array.
  double density = 0;
};
/// One entry per material with tetrahedra. Throws std::invalid_argument naming the cell, "a
/// solver-unfriendly material", when a material has no finite positive Young's modulus (no
/// "youngs_modulus" array, or a NaN / non-positive value on one of its tetrahedra), a Poisson
/// ratio outside (-1, 0.5) or a non-positive density.
std::vector<SolidMaterial> solidMaterials(const TetMesh& mesh);

/// One *MATERIAL of an .inp deck with the elements it is given to (issue 15). A cell whose
/// moduli lie within one bin is one material, as solidMaterials gives it; a cell whose
/// "youngs_modulus" varies more (a CT-mapped bone) is split into bins of equal width in ln E,
/// counted from its smallest modulus: bin k (1-based) holds the tetrahedra with
/// (k - 1) w <= ln(E / E_min) < k w. A bin's E, nu and density are the volume-weighted means over
/// its tetrahedra, so every element's written E lies within one bin width (in ln E) of its own,
/// and the deck keeps the cell's stiffness sum(E V) (the Voigt bound) exactly.
struct DeckMaterial
{
  /// The mesh material (cell) it belongs to, 1-based.
  std::int32_t material = 0;
  /// Its *MATERIAL name and the ELSET of its *SOLID SECTION: the cell's set name
  /// (abaqusSetNames) for a cell of one bin, else that name with "_E<bin>", kept unique.
  std::string setName;
  /// 0 for a cell written as one material, else its bin k >= 1.
  int bin = 0;
  /// Its tetrahedra (0-based, ascending).
  std::vector<std::size_t> tetrahedra;
  double volume = 0;
  double youngsModulus = 0;
  /// 0 when the mesh has no "poisson_ratio" array.
  double poissonRatio = 0;
  /// NaN when the mesh has no "density" array.
  double density = 0;
};
/// The materials writeAbaqus writes, cell by cell in material order, bins in ascending E.
/// `binWidth` is the width of a bin in ln E (0.01: 1 %), > 0; +infinity writes one material per
/// cell. Throws std::invalid_argument as solidMaterials does, and for a bin width that is not
/// positive.
std::vector<DeckMaterial> deckMaterials(const TetMesh& mesh, double binWidth = 0.01);

/// The .inp set name of each material (index = material id - 1): the cell's name with characters
/// other than letters, digits and '_' replaced by '_', starting with a letter, at most 80
/// characters, made unique (case-insensitively) by a numeric suffix.
std::vector<std::string> abaqusSetNames(const TetMesh& mesh);

struct AbaqusOptions
{
  /// The *HEADING line (default: counts).
  std::string heading;
  /// Written verbatim after the model: the *BOUNDARY, *STEP... lines of an analysis.
  std::string appendix;
  /// Write *MATERIAL, *ELASTIC, *DENSITY and *SOLID SECTION per material (needs the arrays of
  /// solidMaterials). Off: the mesh and its element sets only.
  bool materials = true;
  /// The width of a modulus bin in ln E (deckMaterials): 0.01 (1 %); +infinity: one material per
  /// cell, its E the volume-weighted mean.
  double modulusBinWidth = 0.01;
};
/// Abaqus / CalculiX input: *NODE (NSET=NALL), one *ELEMENT, TYPE=C3D4 block per material with
/// ELSET = its set name (element ids = tetrahedron index + 1), and per deck material
/// (deckMaterials) *MATERIAL, *ELASTIC (E, nu), *DENSITY (when known) and *SOLID SECTION; a
/// binned cell's bins are *ELSETs of its elements. Numbers are written as %.12e (ccx reads at
/// most 20 characters per number).
void writeAbaqus(const TetMesh& mesh, const std::string& path, const AbaqusOptions& options = {});

/// By extension: .msh (4.1), .inp, .mesh. Throws std::invalid_argument for another extension.
void writeTetMesh(const TetMesh& mesh, const std::string& path);

} // namespace ictk::mesh
