// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class ictkTetrahedralize
 * @brief Tetrahedral mesh of an implicit complex for FEA: every tetrahedron labelled.
 *
 * Input: the output of ictkComplexSource (which carries the complex itself under
 * ictkComplexSource::COMPLEX()). Output: a vtkUnstructuredGrid of linear tetrahedra with the
 * cell data MaterialId (1-based, one per 3D cell in ascending id), CellId (the complex's cell
 * id) and one array per attribute of the complex, sampled at the tetrahedra's centroids; the
 * field data MaterialNames lists the cells' names by material, and the quality report
 * (ictk::mesh::measureQuality) is in the field data too: MinDihedralAngle, MaxDihedralAngle,
 * MinDihedralAngle1Percentile (degrees), MaxRadiusEdgeRatio, MeanRadiusEdgeRatio, Volume,
 * NonPositiveTetrahedra, and per material MaterialVolume, MaterialTetrahedra and
 * MaterialMinDihedralAngle.
 *
 * Backend: CGAL Mesh_3 (labelled domain from the cells' fields, 1D cells and cell-cell curves
 * protected) or TetGen (from conforming multi-material boundary surfaces); both are optional
 * (GPL-3+ / AGPL-3+, ICTK_ENABLE_GPL_BACKENDS). Deterministic gives identical output run to run.
 * Errors (no complex on the input, a backend not built, a mesh over MaxTetrahedra, overlapping
 * cells of equal priority) are reported with vtkErrorMacro and the request fails.
 */
#pragma once

#include "ictkFiltersMeshModule.h" // export macro
#include "vtkUnstructuredGridAlgorithm.h"

class vtkFieldData;
class vtkUnstructuredGrid;

#ifndef __VTK_WRAP__
namespace ictk
{
namespace mesh
{
struct TetMesh;
struct QualityReport;
struct ValidityReport;
} // namespace mesh
} // namespace ictk
#endif

class ICTKFILTERSMESH_EXPORT ictkTetrahedralize : public vtkUnstructuredGridAlgorithm
{
public:
  static ictkTetrahedralize* New();
  vtkTypeMacro(ictkTetrahedralize, vtkUnstructuredGridAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  enum BackendType
  {
    CGAL = 0,
    TETGEN = 1
  };
  vtkSetClampMacro(Backend, int, CGAL, TETGEN);
  vtkGetMacro(Backend, int);
  void SetBackendToCGAL() { this->SetBackend(CGAL); }
  void SetBackendToTetGen() { this->SetBackend(TETGEN); }
  /// True when the backend was built into this library.
  static bool HasBackend(int backend);

  /// Target edge length in model units (required, > 0).
  vtkSetClampMacro(Size, double, 0.0, VTK_DOUBLE_MAX);
  vtkGetMacro(Size, double);

  vtkSetMacro(Deterministic, bool);
  vtkGetMacro(Deterministic, bool);
  vtkBooleanMacro(Deterministic, bool);

  /// Refuse meshes estimated above this many tetrahedra.
  vtkSetClampMacro(MaxTetrahedra, double, 1.0, VTK_DOUBLE_MAX);
  vtkGetMacro(MaxTetrahedra, double);

  vtkSetClampMacro(NumberOfThreads, int, 0, 1024);
  vtkGetMacro(NumberOfThreads, int);

#ifndef __VTK_WRAP__
  /// The VTK form of a tetrahedral mesh.
  static void Convert(const ictk::mesh::TetMesh& mesh, vtkUnstructuredGrid* output);
  /// The quality report as one-value field arrays (names in the class comment).
  static void AddQualityFields(const ictk::mesh::QualityReport& report, vtkFieldData* fd);
  /// The validity check's figures (ictk::mesh::checkValidity): MinEdgeLength(Relative),
  /// MinTetrahedronVolume(Relative), DuplicatePoints, NonConformingFaces, StrayBoundaryFaces.
  static void AddValidityFields(const ictk::mesh::ValidityReport& report, vtkFieldData* fd);
#endif

protected:
  ictkTetrahedralize();
  ~ictkTetrahedralize() override;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  int Backend = CGAL;
  double Size = 0;
  bool Deterministic = false;
  double MaxTetrahedra = 2e7;
  int NumberOfThreads = 0;

private:
  ictkTetrahedralize(const ictkTetrahedralize&) = delete;
  void operator=(const ictkTetrahedralize&) = delete;
};
