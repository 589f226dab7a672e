// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Geometric validation of the relations of a complex: every declared pair of Rb and Rc is checked
// against the cells' geometry, and pairs that hold geometrically without being declared are
// reported. Each finding names the cells and gives a witness point.

#include "Complex/Locator.h"

#include <string>

namespace ictk::complex
{

struct ValidationOptions
{
  /// Distance within which a point counts as on a set; 0 = a quarter of the mesh feature size.
  double tolerance = 0;
  /// Samples taken from each cell's discretisation.
  std::size_t samplesPerCell = 256;
  /// Also search the pairs that hold geometrically but are not declared.
  bool findUndeclared = true;
  /// Subdivision depth of the interval proof of solid-in-solid containment.
  int intervalDepth = 7;
};

struct RelationFinding
{
  RelationKind kind = RelationKind::Boundary;
  CellId first = 0;  ///< the p-cell
  CellId second = 0; ///< the s-cell
  /// The largest distance of a sample of `second` from the set it must lie on (the boundary of
  /// `first` for Rb; `first` for Rc), and the sample where it is reached.
  double deviation = 0;
  Point3 witness{ 0, 0, 0 };
  std::string reason;
};

struct ValidationReport
{
  double tolerance = 0;
  std::vector<RelationFinding> satisfied;  ///< declared and holding
  std::vector<RelationFinding> violated;   ///< declared but not holding
  std::vector<RelationFinding> undeclared; ///< holding but not declared
  bool ok() const { return violated.empty(); }
  /// A readable report, one line per finding.
  std::string text(const Complex& complex) const;
};

ValidationReport validateComplex(
  const Complex& complex, const ComplexMesh& mesh, const ValidationOptions& options = {});

/// The geometric predicates of the relations, for one pair; `finding` gets the deviation and
/// witness. Rb: every sample of s lies on the boundary of p. Rc: every sample of s lies in p and
/// some sample lies off p's boundary (seed 001 L102: g^s in g^p and g^s not within its boundary).
bool boundaryHolds(CellLocator& p, CellLocator& s, double tolerance, std::size_t samples,
  RelationFinding* finding = nullptr);
bool containmentHolds(CellLocator& p, CellLocator& s, double tolerance, std::size_t samples,
  RelationFinding* finding = nullptr, int intervalDepth = 7);

} // namespace ictk::complex
