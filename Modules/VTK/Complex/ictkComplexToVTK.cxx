// SPDX-License-Identifier: BSD-3-Clause
#include "ictkComplexToVTK.h"

#include "Complex/Discretization.h"
#include "Voxel/VoxelGrid.h"

#include "vtkCellArray.h"
#include "vtkCompositeDataSet.h"
#include "vtkDataAssembly.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkIntArray.h"
#include "vtkMultiBlockDataSet.h"
#include "vtkNew.h"
#include "vtkPartitionedDataSet.h"
#include "vtkPartitionedDataSetCollection.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkStringArray.h"

#include <algorithm>
#include <map>
#include <string>

namespace ictk::vtk
{
namespace
{

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
    // A mesh's vertex normals (a skinned B-cell's) are the polydata's normals.
    if (a.name == "Normals" && a.components == 3)
    {
      pd->GetPointData()->SetNormals(array);
    }
    else
    {
      pd->GetPointData()->AddArray(array);
    }
  }
  return pd;
}

/// A cell's solid field sampled on an image over its bounds.
vtkSmartPointer<vtkImageData> sampleVolume(const complex::ImplicitGeometry& g, int resolution)
{
  const frep::FieldPtr field = g.inside.size() == 1 ? g.inside[0] : frep::minField(g.inside);
  const voxel::VoxelGrid grid =
    voxel::sampleToGrid(*field, g.bounds, { resolution, resolution, resolution });
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->SetDimensions(static_cast<int>(grid.dimensions[0]), static_cast<int>(grid.dimensions[1]),
    static_cast<int>(grid.dimensions[2]));
  image->SetOrigin(grid.origin.data());
  image->SetSpacing(grid.spacing.data());
  auto f = vtkSmartPointer<vtkFloatArray>::New();
  f->SetName("f");
  f->SetNumberOfTuples(static_cast<vtkIdType>(grid.values.size()));
  std::copy(grid.values.begin(), grid.values.end(), f->GetPointer(0));
  image->GetPointData()->SetScalars(f);
  return image;
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

vtkSmartPointer<vtkDataAssembly> complexAssembly(
  const complex::Complex& k, const std::vector<complex::CellId>& layout)
{
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
  for (unsigned int i = 0; i < layout.size(); ++i)
  {
    const complex::Cell& c = k.cell(layout[i]);
    const int node = assembly->AddNode(
      vtkDataAssembly::MakeValidNodeName(c.name.c_str()).c_str(), dimensionNodes[c.dimension]);
    assembly->SetAttribute(node, "cell", c.name.c_str());
    assembly->AddDataSetIndex(node, i);
    index[c.id] = i;
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
      std::vector<complex::CellId> related = (k.*d.related)(id);
      related.erase(std::remove_if(related.begin(), related.end(),
                      [&](complex::CellId r) { return !index.count(r); }),
        related.end());
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
  return assembly;
}

void complexToVTK(const complex::Complex& k, const complex::ComplexMesh& mesh,
  vtkPartitionedDataSetCollection* output, int volumeResolution,
  const std::vector<complex::CellId>* layout)
{
  output->Initialize();
  std::vector<complex::CellId> cells;
  if (layout)
  {
    cells.assign(layout->begin(), layout->end());
  }
  else
  {
    for (const complex::CellMesh& m : mesh.cells)
    {
      cells.push_back(m.cell);
    }
  }
  std::map<complex::CellId, const complex::CellMesh*> meshes;
  for (const complex::CellMesh& m : mesh.cells)
  {
    meshes[m.cell] = &m;
  }
  for (unsigned int next = 0; next < cells.size(); ++next)
  {
    const complex::Cell& c = k.cell(cells[next]);
    auto part = vtkSmartPointer<vtkPartitionedDataSet>::New();
    vtkFieldData* fd = part->GetFieldData();
    addField<vtkIntArray>(fd, "CellId", static_cast<int>(c.id));
    addField<vtkStringArray>(fd, "CellName", c.name);
    addField<vtkStringArray>(fd, "CellKind", std::string(complex::kindCode(c.kind)));
    addField<vtkIntArray>(fd, "CellDimension", c.dimension);
    addField<vtkStringArray>(fd, "CellDescription", c.description);
    const auto found = meshes.find(c.id);
    if (found != meshes.end())
    {
      vtkSmartPointer<vtkPolyData> leaf = toPolyData(*found->second);
      part->SetPartition(0, leaf);
      const auto* implicit = std::get_if<complex::ImplicitGeometry>(&c.geometry);
      if (volumeResolution > 1 && c.dimension == 3 && implicit)
      {
        part->SetPartition(1, sampleVolume(*implicit, volumeResolution));
      }
      // The XML writers keep only the leaves' field data: copy it there too.
      leaf->GetFieldData()->ShallowCopy(fd);
    }
    output->SetPartitionedDataSet(next, part);
    output->GetMetaData(next)->Set(vtkCompositeDataSet::NAME(), c.name.c_str());
  }
  output->SetDataAssembly(complexAssembly(k, cells));
}

void complexToMultiBlock(vtkPartitionedDataSetCollection* input, vtkMultiBlockDataSet* output)
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

} // namespace ictk::vtk
