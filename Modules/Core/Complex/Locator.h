// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Distance queries against one cell and its boundary, the geometric predicates behind relation
// validation, attachment and attribute lookup. Implicit cells are measured on their fields
// (first-order distance |f| / |grad f|, accurate near the set, where the predicates are decided);
// explicit and mapped cells on their discretisation.

#include "Complex/Discretization.h"

#include <limits>
#include <memory>

namespace ictk::complex
{

class CellLocator
{
public:
  /// `mesh` must be the discretisation of `cell` and outlive the locator. Not thread safe (it
  /// holds field evaluators); make one per thread.
  CellLocator(const Cell& cell, const CellMesh& mesh);
  ~CellLocator();
  CellLocator(CellLocator&&) noexcept;

  const Cell& cell() const { return *cell_; }
  /// An estimate of the distance from p to the cell's point set (0 inside a solid).
  double distance(const Point3& p);
  /// An estimate of the distance from p to the cell's boundary; +inf for 0D cells, which have
  /// none. A closed curve has no end points; any of its points may be the vertex it is attached
  /// by (a CW 1-cell), so for it this is the distance to the curve.
  double boundaryDistance(const Point3& p);
  /// Sample points of the cell: up to `maxCount` vertices of its discretisation, evenly strided.
  std::vector<Point3> samples(std::size_t maxCount) const;

private:
  struct Impl;
  const Cell* cell_;
  std::unique_ptr<Impl> impl_;
};

/// Distance from p to a segment / triangle.
double segmentDistance(const Point3& p, const Point3& a, const Point3& b);
double triangleDistance(const Point3& p, const Point3& a, const Point3& b, const Point3& c);

} // namespace ictk::complex
