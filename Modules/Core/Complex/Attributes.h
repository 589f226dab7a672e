// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Attribute values of a complex at any point (seed 001 L114-116, thesis L858-866 and the
// defaults rule of L715): among the cells that hold the point and bind the attribute, the binding
// of highest priority wins (ties: the lower-dimensional cell, whose own attribute describes the
// shared boundary, then the lower id); a point in some cell without a binding gets theta1, a
// point in no cell theta0.

#include "Complex/Locator.h"

#include <map>
#include <optional>
#include <string>

namespace ictk::complex
{

class AttributeLookup
{
public:
  /// The complex and mesh must outlive the lookup. Not thread safe; make one per thread.
  AttributeLookup(const Complex& complex, const ComplexMesh& mesh, double tolerance);

  struct Result
  {
    std::vector<double> value;
    /// The cell whose binding gave the value; empty for a default.
    std::optional<CellId> cell;
  };
  /// Throws ComplexError for an attribute the complex does not declare. `on`: a cell the point
  /// is known to lie on (a vertex of its discretisation), which spares locating it when no
  /// binding applies (the inside default then holds).
  Result value(const std::string& attribute, const Point3& p, std::optional<CellId> on = {});

private:
  bool holds(CellId id, const Point3& p);

  const Complex& complex_;
  const ComplexMesh& mesh_;
  double tolerance_;
  std::map<CellId, CellLocator> locators_; ///< built when a point first falls in the cell's box
  std::map<CellId, Box3> boxes_; ///< cell bounds grown by the tolerance: a cheap first test
};

/// Gives every cell's discretisation the declared attributes the cell does not bind, resolved
/// at its vertices by the bindings of the cells that hold them (priority) or the defaults, so
/// that every output point carries every attribute.
/// `targets`: only these cells' discretisations get the arrays (empty: all); the other cells of
/// `mesh` only serve to locate points.
void appendUnboundAttributes(const Complex& complex, ComplexMesh& mesh, double tolerance,
  const std::vector<CellId>& targets = {});
/// The cells whose discretisations appendUnboundAttributes may consult for the vertices of
/// `targets`, besides the targets themselves: cells that bind an attribute some target does not
/// bind, with bounds within `tolerance` of that target's.
std::vector<CellId> attributeSupport(
  const Complex& complex, const std::vector<CellId>& targets, double tolerance);

/// Evaluates the attribute function at the given points, appending a point array named after
/// the attribute. Values that are not finite are kept (NaN marks "undefined here").
void appendAttribute(const AttributeBinding& binding, const std::vector<Point3>& points,
  std::vector<discretize::PointArray>& arrays);

} // namespace ictk::complex
