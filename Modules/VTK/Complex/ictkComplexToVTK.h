// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The VTK form of a discretised implicit complex, in one place (not wrapped: it takes core
// types). ictkComplexSource (a .json complex or one built in C++), ictkDynamicComplexSource (every
// frame of a running model) and the CLI's `mesh COMPLEX.json` (through ictkComplexSource) all give
// a complex this one form, so a frame of a dynamic complex and a static complex look alike
// downstream (ParaView's block selector, ictkTetrahedralize, the XML writers):
//
// - a vtkPartitionedDataSetCollection with one partitioned dataset per cell, holding a
//   vtkPolyData (points, traced polylines or triangles, by the cell's dimension) whose point data
//   carries every attribute of the complex, and, on request, the cell's field sampled on a
//   vtkImageData (array "f") as partition 1 of an implicit 3D cell;
// - on each partitioned dataset and its polydata the field data CellId, CellName, CellKind,
//   CellDimension and CellDescription (the XML writers keep only the leaves' field data);
// - a vtkDataAssembly rooted at the complex's name: /dimension_0 .. /dimension_3 (the cells by
//   dimension), /relations/{boundary,containment,coboundary,contained_in}/<cell> (the cells
//   related to <cell>), every node carrying its cell's name in the attribute "cell" (node names
//   are made XML-valid).

#include "ictkFiltersComplexModule.h" // export macro

#include "Complex/Cell.h"
#include "vtkSmartPointer.h"

#include <vector>

#include <string>

class vtkDataAssembly;
class vtkMultiBlockDataSet;
class vtkPartitionedDataSetCollection;
class vtkUnstructuredGrid;

namespace ictk
{
namespace complex
{
class Complex;
struct ComplexMesh;
} // namespace complex

namespace vtk
{

/// Replaces `output` with the VTK form of `mesh`, a discretisation of `complex`. `layout`: the
/// cells that get a partitioned dataset, in order (null: the mesh's cells); a cell of the layout
/// that the mesh lacks gets an empty one, so that every piece of a distributed complex has the
/// same structure. `volumeResolution` > 1: implicit 3D cells also get their field sampled at that
/// many points per axis over their bounds.
ICTKFILTERSCOMPLEX_EXPORT void complexToVTK(const complex::Complex& complex,
  const complex::ComplexMesh& mesh, vtkPartitionedDataSetCollection* output,
  int volumeResolution = 0, const std::vector<complex::CellId>* layout = nullptr);

/// The assembly of `complex` for a collection whose datasets are the cells of `layout`, in order
/// (what complexToVTK attaches; a source can build it before any discretisation, for choosing).
ICTKFILTERSCOMPLEX_EXPORT vtkSmartPointer<vtkDataAssembly> complexAssembly(
  const complex::Complex& complex, const std::vector<complex::CellId>& layout);

/// The cells of a collection made by complexToVTK as a vtkMultiBlockDataSet (blocks per
/// dimension, then one per cell, named), for consumers that do not read partitioned dataset
/// collections (.vtm files).
ICTKFILTERSCOMPLEX_EXPORT void complexToMultiBlock(
  vtkPartitionedDataSetCollection* input, vtkMultiBlockDataSet* output);

/// A VTK XML unstructured grid (.vtu) read the one way ICTK reads them: a complex's mesh cells
/// (ictkComplexSource), `ictk render` and `ictk solve`. VTK's own reports are caught, not printed;
/// a file that cannot be read throws std::invalid_argument, one line naming the file and what
/// was wrong ("cannot read 'bar.vtu': it has no points").
ICTKFILTERSCOMPLEX_EXPORT vtkSmartPointer<vtkUnstructuredGrid> readUnstructuredGrid(
  const std::string& path);

} // namespace vtk
} // namespace ictk
