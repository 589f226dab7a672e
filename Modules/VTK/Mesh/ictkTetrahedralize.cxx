// SPDX-License-Identifier: BSD-3-Clause
#include "ictkTetrahedralize.h"

#include "FRep/Sampling.h"
#include "Mesh/Backends/Backends.h"
#include "Mesh/Quality.h"
#include "Mesh/TetMesh.h"
#include "ictkComplexSource.h"
#include "ictkRequest.h"

#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkCellType.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkIdTypeArray.h"
#include "vtkInformation.h"
#include "vtkIntArray.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPartitionedDataSetCollection.h"
#include "vtkPoints.h"
#include "vtkSmartPointer.h"
#include "vtkStringArray.h"
#include "vtkUnsignedCharArray.h"
#include "vtkUnstructuredGrid.h"

vtkStandardNewMacro(ictkTetrahedralize);

ictkTetrahedralize::ictkTetrahedralize() = default;
ictkTetrahedralize::~ictkTetrahedralize() = default;

namespace
{
ictk::mesh::Backend BackendOf(int backend)
{
  return backend == ictkTetrahedralize::CGAL ? ictk::mesh::Backend::Cgal
                                             : ictk::mesh::Backend::TetGen;
}
} // namespace

bool ictkTetrahedralize::HasBackend(int backend)
{
  return ictk::mesh::hasBackend(BackendOf(backend));
}

int ictkTetrahedralize::FillInputPortInformation(int, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkPartitionedDataSetCollection");
  return 1;
}

void ictkTetrahedralize::Convert(const ictk::mesh::TetMesh& mesh, vtkUnstructuredGrid* output)
{
  output->Initialize();
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(static_cast<vtkIdType>(mesh.points.size()));
  for (std::size_t i = 0; i < mesh.points.size(); ++i)
  {
    points->SetPoint(static_cast<vtkIdType>(i), mesh.points[i].data());
  }
  output->SetPoints(points);
  vtkNew<vtkCellArray> cells;
  cells->AllocateExact(static_cast<vtkIdType>(mesh.tetrahedra.size()),
    4 * static_cast<vtkIdType>(mesh.tetrahedra.size()));
  for (const auto& t : mesh.tetrahedra)
  {
    const vtkIdType ids[4] = { t[0], t[1], t[2], t[3] };
    cells->InsertNextCell(4, ids);
  }
  output->SetCells(VTK_TETRA, cells);
  vtkNew<vtkIntArray> material;
  material->SetName("MaterialId");
  vtkNew<vtkIntArray> cellId;
  cellId->SetName("CellId");
  material->SetNumberOfTuples(static_cast<vtkIdType>(mesh.tetrahedra.size()));
  cellId->SetNumberOfTuples(static_cast<vtkIdType>(mesh.tetrahedra.size()));
  for (std::size_t t = 0; t < mesh.tetrahedra.size(); ++t)
  {
    material->SetValue(static_cast<vtkIdType>(t), mesh.materials[t]);
    cellId->SetValue(static_cast<vtkIdType>(t), static_cast<int>(mesh.cells[t]));
  }
  output->GetCellData()->AddArray(material);
  output->GetCellData()->AddArray(cellId);
  output->GetCellData()->SetActiveScalars("MaterialId");
  for (const auto& a : mesh.cellData)
  {
    vtkNew<vtkDoubleArray> array;
    array->SetName(a.name.c_str());
    array->SetNumberOfComponents(a.components);
    array->SetNumberOfTuples(static_cast<vtkIdType>(mesh.tetrahedra.size()));
    std::copy(a.values.begin(), a.values.end(), array->GetPointer(0));
    output->GetCellData()->AddArray(array);
  }
  vtkNew<vtkStringArray> names;
  names->SetName("MaterialNames");
  for (const auto& n : mesh.materialNames)
  {
    names->InsertNextValue(n);
  }
  output->GetFieldData()->AddArray(names);
}

namespace
{
void AddNumber(vtkFieldData* fd, const char* name, double value)
{
  vtkNew<vtkDoubleArray> a;
  a->SetName(name);
  a->InsertNextValue(value);
  fd->AddArray(a);
}
} // namespace

void ictkTetrahedralize::AddQualityFields(const ictk::mesh::QualityReport& report, vtkFieldData* fd)
{
  AddNumber(fd, "MinDihedralAngle", report.minDihedralDegrees);
  AddNumber(fd, "MaxDihedralAngle", report.maxDihedralDegrees);
  AddNumber(fd, "MinDihedralAngle1Percentile", report.minDihedralPercentile1Degrees);
  AddNumber(fd, "MaxRadiusEdgeRatio", report.maxRadiusEdgeRatio);
  AddNumber(fd, "MeanRadiusEdgeRatio", report.meanRadiusEdgeRatio);
  AddNumber(fd, "Volume", report.volume);
  AddNumber(fd, "NonPositiveTetrahedra", static_cast<double>(report.nonPositive));
  // Per material, in MaterialId order (MaterialNames names them).
  vtkNew<vtkDoubleArray> volume;
  volume->SetName("MaterialVolume");
  vtkNew<vtkDoubleArray> count;
  count->SetName("MaterialTetrahedra");
  vtkNew<vtkDoubleArray> angle;
  angle->SetName("MaterialMinDihedralAngle");
  for (const auto& m : report.materials)
  {
    volume->InsertNextValue(m.volume);
    count->InsertNextValue(static_cast<double>(m.tetrahedra));
    angle->InsertNextValue(m.minDihedralDegrees);
  }
  fd->AddArray(volume);
  fd->AddArray(count);
  fd->AddArray(angle);
}

void ictkTetrahedralize::AddValidityFields(
  const ictk::mesh::ValidityReport& report, vtkFieldData* fd)
{
  AddNumber(fd, "MinEdgeLength", report.minEdge);
  AddNumber(fd, "MinEdgeLengthRelative", report.minEdgeRelative);
  AddNumber(fd, "MinTetrahedronVolume", report.minVolume);
  AddNumber(fd, "MinTetrahedronVolumeRelative", report.minVolumeRelative);
  AddNumber(fd, "DuplicatePoints", static_cast<double>(report.duplicatePoints));
  AddNumber(fd, "NonConformingFaces", static_cast<double>(report.nonConformingFaces));
  AddNumber(fd, "StrayBoundaryFaces", static_cast<double>(report.strayBoundaryFaces));
}

int ictkTetrahedralize::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkUnstructuredGrid* output = vtkUnstructuredGrid::GetData(outputVector);
  vtkDataObject* input = vtkDataObject::GetData(inputVector[0]);
  const auto complex = ictkComplexSource::GetComplex(input);
  if (!complex)
  {
    vtkErrorMacro("the input carries no complex: connect an ictkComplexSource");
    return 0;
  }
  if (!HasBackend(this->Backend))
  {
    vtkErrorMacro("the " << (this->Backend == CGAL ? "CGAL" : "TetGen")
                         << " backend was not built (ICTK_ENABLE_GPL_BACKENDS, and its library)");
    return 0;
  }
  ictk::mesh::TetraOptions options;
  options.size = this->Size;
  options.deterministic = this->Deterministic;
  options.maxTetrahedra = this->MaxTetrahedra;
  options.threads = this->NumberOfThreads;
  options.progress = ictk::vtk::progressOf(this);
  return ictk::vtk::runRequest(this, output,
    [&]
    {
      ictk::mesh::ValidityReport validity;
      const ictk::mesh::TetMesh mesh =
        ictk::mesh::tetrahedralize(*complex, BackendOf(this->Backend), options, &validity);
      Convert(mesh, output);
      AddQualityFields(ictk::mesh::measureQuality(mesh), output->GetFieldData());
      AddValidityFields(validity, output->GetFieldData());
      return 1;
    });
}

void ictkTetrahedralize::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Backend: " << (this->Backend == CGAL ? "CGAL" : "TetGen") << "\n";
  os << indent << "Size: " << this->Size << "\n";
  os << indent << "Deterministic: " << this->Deterministic << "\n";
  os << indent << "MaxTetrahedra: " << this->MaxTetrahedra << "\n";
  os << indent << "NumberOfThreads: " << this->NumberOfThreads << "\n";
}
