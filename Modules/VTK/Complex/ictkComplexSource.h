// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class ictkComplexSource
 * @brief The reader of implicit complexes: discretises a complex and outputs it as a
 * vtkPartitionedDataSetCollection.
 *
 * The complex comes from a .json complex file (SetFileName; cells may name VTK mesh and image
 * files, see ReadComplexFile) or, in C++, from SetComplex(). Every
 * cell is discretised by its dimension (points, traced polylines, trimmed or mapped triangle
 * patches, boundary surfaces of solids) at FeatureSize, and becomes one partitioned dataset
 * holding a vtkPolyData whose point data carries every attribute of the complex.
 *
 * With VolumeResolution > 0, the partitioned dataset of every implicit 3D cell also holds the
 * cell's field sampled on a vtkImageData (array "f").
 *
 * The output is the VTK form of a complex that ictkComplexToVTK.h describes and makes (shared with
 * ictkDynamicComplexSource): each partitioned dataset's field data holds CellId, CellName,
 * CellKind, CellDimension and CellDescription; the collection's vtkDataAssembly has the nodes
 *   /dimension_0 .. /dimension_3: the cells by dimension;
 *   /relations/boundary/<cell>: the cells on the boundary of <cell> (Rb);
 *   /relations/containment/<cell>: the cells <cell> contains (Rc);
 *   /relations/coboundary/<cell>, /relations/contained_in/<cell>: the derived inverses;
 * each node carrying the cell name in its "cell" attribute (node names are made XML-valid).
 *
 * The complex itself rides along with the output (COMPLEX(), GetComplex()), so that filters
 * downstream (ictkTetrahedralize, ictkComplexValidator) can use its fields, not only its
 * discretisation; ictkDynamicComplexSource attaches its frames' complexes the same way.
 *
 * Selectors (AddSelector; vtkDataAssembly paths, which start at the root node named after the
 * complex: "/flower/dimension_2", or anywhere with "//dimension_2", "//petal_1",
 * "//containment/Stem") choose the cells that are discretised; the output keeps a
 * partitioned dataset for every cell, empty for the cells not chosen. The default, no selector,
 * chooses every cell. GetAssembly() gives the assembly after UpdateInformation(), before any
 * discretisation, so that a user (or ParaView's block selector) can choose.
 *
 * Pieces: under MPI (UPDATE_NUMBER_OF_PIECES > 1) the chosen cells are dealt to the pieces in
 * turn (cell i of the chosen ones to piece i mod N); every piece has the same collection and
 * assembly, with data only for its own cells, each equal to the one-process result.
 *
 * Progress is reported per cell; AbortExecute cancels and leaves an empty output. Errors (a bad
 * file, an invalid relation, a cell that cannot be discretised) are reported with vtkErrorMacro
 * and the request fails.
 */
#pragma once

#include "ictkFiltersComplexModule.h" // export macro
#include "vtkPartitionedDataSetCollectionAlgorithm.h"

#include <functional> // for std::function
#include <memory>     // for std::shared_ptr
#include <string>     // for std::string
#include <vector>     // for std::vector

class vtkDataAssembly;
class vtkDataObject;
class vtkInformationObjectBaseKey;
class vtkPartitionedDataSetCollection;

#ifndef __VTK_WRAP__
namespace ictk
{
namespace complex
{
class Complex;
} // namespace complex
namespace voxel
{
struct VoxelGrid;
} // namespace voxel
} // namespace ictk
#endif

class ICTKFILTERSCOMPLEX_EXPORT ictkComplexSource : public vtkPartitionedDataSetCollectionAlgorithm
{
public:
  static ictkComplexSource* New();
  vtkTypeMacro(ictkComplexSource, vtkPartitionedDataSetCollectionAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// A .json complex file.
  vtkSetStdStringFromCharMacro(FileName);
  vtkGetCharFromStdStringMacro(FileName);

  /// Mesh edge length and curve step in model units; 0 (default) = 1/64 of the complex's size.
  vtkSetClampMacro(FeatureSize, double, 0.0, VTK_DOUBLE_MAX);
  vtkGetMacro(FeatureSize, double);

  /// When > 0, every implicit 3D cell also gets a vtkImageData of its field f (f >= 0 inside)
  /// sampled at this many points per axis over its bounds, as partition 1 of its dataset.
  vtkSetClampMacro(VolumeResolution, int, 0, 2048);
  vtkGetMacro(VolumeResolution, int);

  /// Threads for the discretisers; 0 = TBB's default. Results do not depend on it.
  vtkSetClampMacro(NumberOfThreads, int, 0, 1024);
  vtkGetMacro(NumberOfThreads, int);

  ///@{
  /// vtkDataAssembly selectors of the cells to discretise (none: every cell).
  void AddSelector(const char* selector);
  void ClearSelectors();
  int GetNumberOfSelectors() const { return static_cast<int>(this->Selectors.size()); }
  const char* GetSelector(int i) const;
  ///@}

  /// The complex's assembly (cells by dimension, relations), known after UpdateInformation().
  vtkDataAssembly* GetAssembly();
  /// Changes whenever GetAssembly() is rebuilt (ParaView's block selector fetches it then).
  int GetAssemblyTag() const { return this->AssemblyTag; }

  /// 1 when `name` is a .json file whose top-level object has a "cells" list (a complex), so
  /// that other JSON files are left to other readers.
  static int CanReadFile(const char* name);

  /// The information key that carries a complex with its VTK form: set on the output's
  /// information, and on the information of its field array "ICTKComplex" (whose value is the
  /// number of cells), so that shallow copies, such as ParaView's vtkPVPostFilter, keep it. Its
  /// value is an opaque holder of the shared complex: read it with GetComplex(), set it with
  /// AttachComplex(). It lives on this class because the sources of complexes (this one and
  /// ictkDynamicComplexSource) and the filters that use them (ictkTetrahedralize,
  /// ictkComplexValidator) all depend on this module.
  static vtkInformationObjectBaseKey* COMPLEX();

#ifndef __VTK_WRAP__
  /// Reads a .json complex with VTK's readers for the cells' files: explicit cells from .vtp,
  /// .vtu, .stl, .ply, .obj; voxel cells from .vti, .mha/.mhd, .nii/.nii.gz, .nrrd/.nhdr (and
  /// .vdb through the core). Throws ictk::lang::ParseError. `scanRead`, when set, is told each
  /// voxel cell's grid as the cell reads it (ictk::lang::ComplexFileReaders::scanRead).
  static ictk::complex::Complex ReadComplexFile(const std::string& path,
    std::function<void(const std::string&, std::shared_ptr<const ictk::voxel::VoxelGrid>)>
      scanRead = {});
  /// The complex a dataset made by this source carries (COMPLEX()), or nullptr.
  static std::shared_ptr<const ictk::complex::Complex> GetComplex(vtkDataObject* data);
  /// Sets COMPLEX() on a dataset's information, as this source does on its output (for other
  /// sources of complexes, such as ictkDynamicComplexSource).
  static void AttachComplex(
    vtkDataObject* data, std::shared_ptr<const ictk::complex::Complex> complex);
  /// A complex built in C++; used instead of FileName when set.
  void SetComplex(std::shared_ptr<const ictk::complex::Complex> complex);
#endif

protected:
  ictkComplexSource();
  ~ictkComplexSource() override;

  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  std::string FileName;
  std::vector<std::string> Selectors;
  int AssemblyTag = 0;
  double FeatureSize = 0;
  int VolumeResolution = 0;
  int NumberOfThreads = 0;

private:
  ictkComplexSource(const ictkComplexSource&) = delete;
  void operator=(const ictkComplexSource&) = delete;

  std::shared_ptr<const ictk::complex::Complex> Complex;
  struct Internals;
  std::unique_ptr<Internals> Internal;
#ifndef __VTK_WRAP__
  /// The complex given in C++, else the one read from FileName (read again when the file changed).
  std::shared_ptr<const ictk::complex::Complex> LoadComplex();
#endif
};
