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
  /// Throws ComplexError for an attribute the complex does not declare.
  Result value(const std::string& attribute, const Point3& p);

private:
  const Complex& complex_;
  double tolerance_;
  std::map<CellId, CellLocator> locators_;
};

/// Evaluates the attribute function at the given points, appending a point array named after
/// the attribute. Values that are not finite are kept (NaN marks "undefined here").
void appendAttribute(const AttributeBinding& binding, const std::vector<Point3>& points,
  std::vector<discretize::PointArray>& arrays);

} // namespace ictk::complex
