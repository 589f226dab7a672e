// SPDX-License-Identifier: BSD-3-Clause
#include "ictkComplexSource.h"

#include "Complex/Discretization.h"
#include "FRep/Sampling.h"
#include "Lang/ComplexFile.h"

#include "vtkCellArray.h"
#include "vtkDataAssembly.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkInformation.h"
#include "vtkIntArray.h"
#include "vtkMultiBlockDataSet.h"
#include "vtkObjectFactory.h"
#include "vtkPartitionedDataSet.h"
#include "vtkPartitionedDataSetCollection.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSmartPointer.h"
#include "vtkStringArray.h"

#include <map>

vtkStandardNewMacro(ictkComplexSource);

namespace
{
using namespace ictk;

vtkSmartPointer<vtkPolyData> toPolyData(const complex::CellMesh& m)
{
  auto pd = vtkSmartPointer<vtkPolyData>::New();
  auto points = vtkSmartPointer<vtkPoints>::New();
  points->SetDataTypeToDouble();
  const auto& vertices = m.vertices();
  points->SetNumberOfPoints(static_cast<vtkIdType>(vertices.size()));
  for (std::size_t i = 0; i < vertices.size(); ++i)
  {
    points->SetPoint(static_cast<vtkIdType>(i), vertices[i].data());
  }
  pd->SetPoints(points);
  auto cells = vtkSmartPointer<vtkCellArray>::New();
  switch (m.dimension)
  {
    case 0:
      for (vtkIdType i = 0; i < points->GetNumberOfPoints(); ++i)
      {
        cells->InsertNextCell(1, &i);
      }
      pd->SetVerts(cells);
      break;
    case 1:
      for (const auto& line : m.curves.lines)
      {
        cells->InsertNextCell(static_cast<vtkIdType>(line.size()));
        for (auto i : line)
        {
          cells->InsertCellPoint(i);
        }
      }
      pd->SetLines(cells);
      break;
    default:
      for (const auto& t : m.surface.triangles)
      {
        const vtkIdType ids[3] = { t[0], t[1], t[2] };
        cells->InsertNextCell(3, ids);
      }
      pd->SetPolys(cells);
  }
  const std::vector<discretize::PointArray>& arrays = m.dimension == 0 ? m.points.pointData
    : m.dimension == 1                                                 ? m.curves.pointData
                                                                       : m.surface.pointData;
  for (const auto& a : arrays)
  {
    auto array = vtkSmartPointer<vtkDoubleArray>::New();
    array->SetName(a.name.c_str());
    array->SetNumberOfComponents(a.components);
    array->SetNumberOfTuples(static_cast<vtkIdType>(vertices.size()));
    std::copy(a.values.begin(), a.values.end(), array->GetPointer(0));
    pd->GetPointData()->AddArray(array);
  }
  return pd;
}

template <typename T, typename V>
void addField(vtkFieldData* fd, const char* name, V value)
{
  auto a = vtkSmartPointer<T>::New();
  a->SetName(name);
  a->InsertNextValue(value);
  fd->AddArray(a);
}

} // namespace

ictkComplexSource::ictkComplexSource()
{
  this->SetNumberOfInputPorts(0);
}

ictkComplexSource::~ictkComplexSource() = default;

void ictkComplexSource::SetComplex(std::shared_ptr<const ictk::complex::Complex> complex)
{
  this->Complex = std::move(complex);
  this->Modified();
}

void ictkComplexSource::Convert(const complex::Complex& k, const complex::ComplexMesh& mesh,
  vtkPartitionedDataSetCollection* output)
{
  output->Initialize();
  auto assembly = vtkSmartPointer<vtkDataAssembly>::New();
  assembly->Initialize();
  assembly->SetRootNodeName(
    vtkDataAssembly::MakeValidNodeName(k.name.empty() ? "complex" : k.name.c_str()).c_str());
  int dimensionNodes[4];
  for (int p = 0; p <= 3; ++p)
  {
    dimensionNodes[p] = assembly->AddNode(("dimension_" + std::to_string(p)).c_str());
  }
  std::map<complex::CellId, unsigned int> index;
  unsigned int next = 0;
  for (const complex::CellMesh& m : mesh.cells)
  {
    const complex::Cell& c = k.cell(m.cell);
    auto part = vtkSmartPointer<vtkPartitionedDataSet>::New();
    vtkSmartPointer<vtkPolyData> leaf = toPolyData(m);
    part->SetPartition(0, leaf);
    output->SetPartitionedDataSet(next, part);
    output->GetMetaData(next)->Set(vtkCompositeDataSet::NAME(), c.name.c_str());
    vtkFieldData* fd = part->GetFieldData();
    addField<vtkIntArray>(fd, "CellId", static_cast<int>(c.id));
    addField<vtkStringArray>(fd, "CellName", c.name);
    addField<vtkStringArray>(fd, "CellKind", std::string(complex::kindCode(c.kind)));
    addField<vtkIntArray>(fd, "CellDimension", c.dimension);
    addField<vtkStringArray>(fd, "CellDescription", c.description);
    // The XML writers keep only the leaves' field data: copy it there too.
    leaf->GetFieldData()->ShallowCopy(fd);
    const int node = assembly->AddNode(
      vtkDataAssembly::MakeValidNodeName(c.name.c_str()).c_str(), dimensionNodes[c.dimension]);
    assembly->SetAttribute(node, "cell", c.name.c_str());
    assembly->AddDataSetIndex(node, next);
    index[c.id] = next++;
  }
  // The relations: for each cell, a node listing the datasets of the related cells.
  const int relations = assembly->AddNode("relations");
  struct Derived
  {
    const char* name;
    std::vector<complex::CellId> (complex::Complex::*related)(complex::CellId) const;
  };
  const Derived kinds[] = {
    { "boundary", &complex::Complex::boundaryOf },
    { "containment", &complex::Complex::contentsOf },
    { "coboundary", &complex::Complex::coboundaryOf },
    { "contained_in", &complex::Complex::containersOf },
  };
  for (const Derived& d : kinds)
  {
    const int kindNode = assembly->AddNode(d.name, relations);
    for (const auto& [id, dataset] : index)
    {
      (void)dataset;
      const std::vector<complex::CellId> related = (k.*d.related)(id);
      if (related.empty())
      {
        continue;
      }
      const std::string& name = k.cell(id).name;
      const int node =
        assembly->AddNode(vtkDataAssembly::MakeValidNodeName(name.c_str()).c_str(), kindNode);
      assembly->SetAttribute(node, "cell", name.c_str());
      for (complex::CellId r : related)
      {
        assembly->AddDataSetIndex(node, index.at(r));
      }
    }
  }
  output->SetDataAssembly(assembly);
}

void ictkComplexSource::ToMultiBlock(
  vtkPartitionedDataSetCollection* input, vtkMultiBlockDataSet* output)
{
  output->Initialize();
  vtkNew<vtkMultiBlockDataSet> byDimension[4];
  for (unsigned int i = 0; i < input->GetNumberOfPartitionedDataSets(); ++i)
  {
    vtkPartitionedDataSet* part = input->GetPartitionedDataSet(i);
    auto* dimension = vtkIntArray::SafeDownCast(part->GetFieldData()->GetArray("CellDimension"));
    const int p = dimension ? dimension->GetValue(0) : 0;
    vtkMultiBlockDataSet* block = byDimension[std::clamp(p, 0, 3)];
    const unsigned int b = block->GetNumberOfBlocks();
    block->SetBlock(b, part->GetPartition(0));
    if (input->HasMetaData(i))
    {
      block->GetMetaData(b)->Set(
        vtkCompositeDataSet::NAME(), input->GetMetaData(i)->Get(vtkCompositeDataSet::NAME()));
    }
  }
  for (int p = 0; p <= 3; ++p)
  {
    output->SetBlock(p, byDimension[p]);
    output->GetMetaData(static_cast<unsigned int>(p))
      ->Set(vtkCompositeDataSet::NAME(), (std::to_string(p) + "D cells").c_str());
  }
}

int ictkComplexSource::RequestData(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  vtkPartitionedDataSetCollection* output = vtkPartitionedDataSetCollection::GetData(outputVector);
  try
  {
    std::shared_ptr<const complex::Complex> k = this->Complex;
    if (!k)
    {
      if (this->FileName.empty())
      {
        vtkErrorMacro("no complex: set FileName (a .json complex) or a complex in C++");
        return 0;
      }
      k = std::make_shared<const complex::Complex>(lang::readComplexFile(this->FileName));
    }
    complex::DiscretizationOptions options;
    options.featureSize = this->FeatureSize;
    options.threads = this->NumberOfThreads;
    options.progress = [this](double fraction)
    {
      this->UpdateProgress(fraction);
      return !this->GetAbortExecute();
    };
    const complex::ComplexMesh mesh = complex::discretizeComplex(*k, options);
    Convert(*k, mesh, output);
    return 1;
  }
  catch (const frep::Cancelled&)
  {
    output->Initialize();
    return 1;
  }
  catch (const std::exception& e)
  {
    vtkErrorMacro("" << e.what());
    output->Initialize();
    return 0;
  }
}

void ictkComplexSource::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FileName: " << this->FileName << "\n";
  os << indent << "FeatureSize: " << this->FeatureSize << "\n";
  os << indent << "NumberOfThreads: " << this->NumberOfThreads << "\n";
}
