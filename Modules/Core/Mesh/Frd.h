// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// CalculiX's ASCII results file (.frd) read without VTK (issue 15): the nodes, the elements and
// the nodal result blocks ccx writes for *NODE FILE / *EL FILE (DISP, STRESS, FORC; others are
// kept by name), the last increment of each. The format is fixed-width (values touch: "-1.0E+00
// -2.0E+00" is written "-1.00000E+00-2.00000E+00"), so lines are cut by column, not by spaces:
// a key of 3 characters, a node or element number of 5 (format 0) or 10 (format 1) characters,
// then values of 12, six a record (a node's further values continue on ' -2' records whose
// number columns are blank). Errors name the file and the line.

#include "Mesh/TetMesh.h"

#include <array>
#include <cstddef>
#include <map>
#include <string>
#include <vector>

namespace ictk::mesh
{

struct FrdElement
{
  std::size_t id = 0;
  /// The .frd element type: 3 = 4-node tetrahedron (C3D4), 6 = 10-node tetrahedron, 1 = 8-node
  /// hexahedron...
  int type = 0;
  std::vector<std::size_t> nodes;
};

/// One nodal result block (the last of its name): values per node in node order.
struct FrdBlock
{
  std::string name;
  std::vector<std::string> components;
  /// The step time of its increment.
  double time = 0;
  /// nodes() x components.size() values; NaN for a node the block leaves out.
  std::vector<double> values;
};

struct FrdResults
{
  /// Node numbers and coordinates, in file order.
  std::vector<std::size_t> nodeIds;
  std::vector<Point3> points;
  std::vector<FrdElement> elements;
  /// By block name ("DISP", "STRESS", "FORC", "ERROR"...).
  std::map<std::string, FrdBlock> blocks;
  /// Per node (as nodeIds) from DISP; empty when the file has none.
  std::vector<std::array<double, 3>> displacement;
  /// Per node from STRESS: xx, yy, zz, xy, yz, zx (ccx's SXX...SZX); empty when none.
  std::vector<std::array<double, 6>> stress;
  /// Per node from FORC (reaction forces, *NODE FILE RF); empty when none.
  std::vector<std::array<double, 3>> force;

  std::size_t nodes() const { return nodeIds.size(); }
  /// The index of node `id`; throws std::out_of_range naming it.
  std::size_t index(std::size_t id) const;

  /// Node id -> index (dense when the ids are 1..n).
  std::vector<std::size_t> indexOfId;
};

/// Reads a .frd file. Throws std::runtime_error "<path>:<line>: <what>" for a malformed file, and
/// naming the file when it cannot be opened or has no nodes.
FrdResults readFrd(const std::string& path);

/// The von Mises stress of a symmetric tensor (xx, yy, zz, xy, yz, zx):
/// sqrt(((sxx - syy)^2 + (syy - szz)^2 + (szz - sxx)^2) / 2 + 3 (sxy^2 + syz^2 + szx^2)).
double vonMises(const std::array<double, 6>& s);

/// The results on the mesh's points: node i + 1 of the .frd is mesh point i (as writeAbaqus
/// numbers them). Throws std::invalid_argument when the node count or a node's position (beyond
/// 1e-4 relative to the mesh's size, the .frd's 5 digits) differs.
struct PointResults
{
  std::vector<std::array<double, 3>> displacement;
  std::vector<std::array<double, 6>> stress;
  std::vector<double> vonMises;
  /// The reaction forces (FORC), zero where nothing is held.
  std::vector<std::array<double, 3>> force;
};
PointResults resultsOnMesh(const TetMesh& mesh, const FrdResults& results);

} // namespace ictk::mesh
