// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Discretisation of every cell by its dimension (seed 001 L93: every implicit cell must be
// discretisable): 3D cells by their boundary surface, 2D cells as trimmed or mapped triangle
// patches, 1D cells as traced polylines, 0D cells as points. Attribute values of the cell are
// evaluated at every output point.

#include "Complex/Complex.h"
#include "Discretize/Mesh.h"
#include "Discretize/Surface.h"
#include "FRep/Progress.h"

#include <functional>

namespace ictk::complex
{

struct DiscretizationOptions
{
  /// Target edge length of the meshes and step of the traced curves (model units); 0 = 1/64 of
  /// the largest side of the complex's bounding box.
  double featureSize = 0;
  /// Tolerance of point projections onto carriers and trims.
  double tolerance = 1e-7;
  /// 0 = TBB's default.
  int threads = 0;
  /// Called with the completed fraction; return false to cancel (throws frep::Cancelled).
  Progress progress;
  /// discretizeComplex: only these cells (a selection, or one MPI rank's share); empty = every
  /// cell. Their meshes equal those of a whole discretisation, attributes included.
  std::vector<CellId> cells;
  /// discretizeCell of a 3D implicit cell: the work of the previous discretisation of the same
  /// cell, reused where its field did not change, and this one's kept for the next
  /// (discretize::SurfaceMemory; time-coherent re-meshing). The mesh is the same without it.
  /// discretizeComplex ignores it (one memory is for one cell).
  discretize::SurfaceMemory* surfaceMemory = nullptr;
};

/// The discretisation of one cell. Exactly one of the members is filled, by dimension: points
/// (0D), curves (1D), surface (2D patch, or the boundary of a 3D cell).
struct CellMesh
{
  CellId cell = 0;
  int dimension = 0;
  discretize::PointSet points;
  discretize::CurveSet curves;
  discretize::SurfaceMesh surface;
  /// Points of the discretisation (whichever member holds them).
  const std::vector<Point3>& vertices() const;
  std::vector<discretize::PointArray>& pointData();
  const std::vector<discretize::PointArray>& pointData() const;
};

struct ComplexMesh
{
  double featureSize = 0;
  std::vector<CellMesh> cells; ///< in ascending cell id
  const CellMesh& of(CellId id) const;
};

/// The box that holds every cell (explicit cells by their points, implicit by their bounds,
/// mapped cells by a coarse sample of their map).
Box3 complexBounds(const Complex& complex);

/// The default feature size: 1/64 of the largest side of complexBounds.
double defaultFeatureSize(const Complex& complex);

CellMesh discretizeCell(
  const Complex& complex, CellId id, const DiscretizationOptions& options = {});
ComplexMesh discretizeComplex(const Complex& complex, const DiscretizationOptions& options = {});

} // namespace ictk::complex
