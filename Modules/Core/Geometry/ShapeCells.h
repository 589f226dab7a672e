// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Placed shapes as cells of an implicit complex, for discretising a running model's instant.
// The one part of Geometry that knows cells: Geometry depends on Complex for it (see its
// CMakeLists.txt).

#include "Complex/Cell.h"
#include "Geometry/PlacedShape.h"

namespace ictk::geometry
{

/// The cell of an implicit complex that the placed shape stands for at this instant: implicit
/// geometry for fields, disks, spheres, sectors, blends and unions (2D ones carried by z = 0);
/// explicit points, polylines (arcs sampled with QueryOptions::arcSegments), triangles
/// (rectangles, and meshes: a B-cell surface of dimension 2) or tetrahedra (boxes). `kind` and the
/// name/dimension are copied to the cell.
complex::Cell toComplexCell(
  const PlacedShape& s, complex::CellKind kind, const QueryOptions& o = {});

} // namespace ictk::geometry
