// SPDX-License-Identifier: BSD-3-Clause
#include "ictkComplexSource.h"
#include "ictkComplexToVTK.h"
#include "ictkErrorCapture.h"
#include "ictkRequest.h"

#include "Complex/Discretization.h"
#include "FRep/Sampling.h"
#include "Lang/ComplexFile.h"
#include "Voxel/VolumeFile.h"
#include "Voxel/VoxelGrid.h"

#include "vtkCellArray.h"
#include "vtkCellType.h"
#include "vtkDataAssembly.h"
#include "vtkFieldData.h"
#include "vtkImageData.h"
#include "vtkImageReader2.h"
#include "vtkInformation.h"
#include "vtkInformationObjectBaseKey.h"
#include "vtkInformationVector.h"
#include "vtkIntArray.h"
#include "vtkMatrix3x3.h"
#include "vtkMetaImageReader.h"
#include "vtkNIFTIImageReader.h"
#include "vtkNew.h"
#include "vtkNrrdReader.h"
#include "vtkOBJReader.h"
#include "vtkObjectFactory.h"
#include "vtkPLYReader.h"
#include "vtkPartitionedDataSetCollection.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkSTLReader.h"
#include "vtkSmartPointer.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkTriangleFilter.h"
#include "vtkUnstructuredGrid.h"
#include "vtkXMLImageDataReader.h"
#include "vtkXMLPolyDataReader.h"
#include "vtkXMLReader.h"
#include "vtkXMLUnstructuredGridReader.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <type_traits>

vtkStandardNewMacro(ictkComplexSource);
vtkInformationKeyMacro(ictkComplexSource, COMPLEX, ObjectBase);

namespace
{
/// Holds the complex in a vtkObject, the form information keys carry.
class ictkComplexHolder : public vtkObject
{
public:
  static ictkComplexHolder* New();
  vtkTypeMacro(ictkComplexHolder, vtkObject);
  std::shared_ptr<const ictk::complex::Complex> Complex;

protected:
  ictkComplexHolder() = default;
  ~ictkComplexHolder() override = default;
};
vtkStandardNewMacro(ictkComplexHolder);
} // namespace

namespace
{
/// The field array that carries the complex through shallow copies: ParaView puts a
/// vtkPVPostFilter after every output, whose ShallowCopy keeps field arrays (the same objects)
/// but not the data object's information keys.
constexpr const char* ComplexArrayName = "ICTKComplex";
} // namespace

std::shared_ptr<const ictk::complex::Complex> ictkComplexSource::GetComplex(vtkDataObject* data)
{
  if (!data)
  {
    return nullptr;
  }
  if (auto* holder = ictkComplexHolder::SafeDownCast(data->GetInformation()->Get(COMPLEX())))
  {
    return holder->Complex;
  }
  vtkFieldData* fd = data->GetFieldData();
  vtkAbstractArray* marker = fd ? fd->GetAbstractArray(ComplexArrayName) : nullptr;
  auto* holder =
    marker ? ictkComplexHolder::SafeDownCast(marker->GetInformation()->Get(COMPLEX())) : nullptr;
  return holder ? holder->Complex : nullptr;
}

void ictkComplexSource::AttachComplex(
  vtkDataObject* data, std::shared_ptr<const ictk::complex::Complex> complex)
{
  if (!data)
  {
    return;
  }
  vtkNew<ictkComplexHolder> holder;
  const int cells = complex ? static_cast<int>(complex->cellIds().size()) : 0;
  holder->Complex = std::move(complex);
  data->GetInformation()->Set(COMPLEX(), holder);
  // The same holder on a field array (its value: the number of cells), which shallow copies
  // share; see ComplexArrayName.
  vtkNew<vtkIntArray> marker;
  marker->SetName(ComplexArrayName);
  marker->InsertNextValue(cells);
  marker->GetInformation()->Set(COMPLEX(), holder);
  data->GetFieldData()->AddArray(marker);
}

namespace
{
using namespace ictk;

/// The type="..." of a VTK XML file's root element ("PolyData"), or "" when there is none.
std::string xmlFileType(const std::string& path)
{
  std::ifstream in(path, std::ios::binary);
  std::string head(4096, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  const std::size_t root = head.find("<VTKFile");
  const std::size_t type = root == std::string::npos ? root : head.find("type=\"", root);
  const std::size_t end = type == std::string::npos ? type : head.find('"', type + 6);
  return end == std::string::npos ? std::string() : head.substr(type + 6, end - type - 6);
}

/// What a reader's errors mean, in the user's words where VTK's are obscure: the XML parser's
/// "Error parsing XML in stream at line 1, column 0, byte index 0: syntax error" is a file that
/// is not XML at all, a missing element a VTK file of another kind, an unreadable extent data
/// cut short. The executive's "returned failure for request" (with its vtkInformation listing)
/// only repeats that the reader failed.
std::string readFailure(
  const std::string& path, const std::vector<std::string>& errors, const std::string& expected)
{
  const std::string e = ictk::vtk::firstCause(errors);
  if (e.empty())
  {
    return "VTK's reader failed without saying why";
  }
  std::error_code ec;
  if (std::filesystem::file_size(path, ec) == 0 && !ec)
  {
    return "the file is empty";
  }
  const std::string xml = "Error parsing XML in stream at ";
  if (e.rfind(xml, 0) == 0)
  {
    const std::size_t colon = e.find(": ", xml.size());
    const std::string where = e.substr(xml.size(), colon - xml.size());
    const std::string why = colon == std::string::npos ? std::string() : e.substr(colon + 2);
    if (where.find("byte index 0") != std::string::npos)
    {
      return "not an XML file";
    }
    // "line L, column C, byte index B": expat counts columns from 0, ICTK's diagnostics from 1.
    int line = 0;
    int column = 0;
    if (std::sscanf(where.c_str(), "line %d, column %d", &line, &column) == 2)
    {
      return "not well-formed XML (line " + std::to_string(line) + ", column " +
        std::to_string(column + 1) + ": " + why + ")";
    }
    return "not well-formed XML (" + where + ": " + why + ")";
  }
  if (e.rfind("Cannot find ", 0) == 0 && e.find(" element in file") != std::string::npos)
  {
    const std::string type = xmlFileType(path);
    return type.empty() ? "not a VTK XML " + expected + " file"
                        : "a VTK " + type + " file, not " + expected;
  }
  // vtkImageReader2 (NRRD's raw data): the data file ended before the header's sizes did.
  if (e.rfind("File operation failed", 0) == 0)
  {
    return "its data holds fewer values than its header's size says; the data file is "
           "truncated or the header is wrong";
  }
  const std::string stl = "STLReader error reading file: " + path + " ";
  if (e.rfind(stl, 0) == 0)
  {
    return e.substr(stl.size());
  }
  // vtkXMLUnstructuredDataReader: a piece without its <Points> element, which VTK's writers
  // leave out of a grid that has no points object, and VTK follows with "Reading file may fail".
  if (e.rfind("No Points element", 0) == 0)
  {
    return "it has no points";
  }
  if (e.rfind("Error reading extent", 0) == 0)
  {
    return "its data is cut short or corrupt (" + e + ")";
  }
  return e;
}

bool endsWith(std::string s, const std::string& suffix)
{
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s.size() >= suffix.size() &&
    s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

/// Runs a VTK reader and fails with the file's name and what was wrong when it reports an error
/// or reads nothing; VTK's own reports are captured (ictkErrorCapture.h), not printed. `format`
/// names what the file should be ("ImageData", "MetaImage"). Readers that can tell their format
/// are asked first: MetaImage's library prints its complaints to stderr itself.
template <typename Reader>
vtkSmartPointer<Reader> readWith(const std::string& path, const std::string& format)
{
  if (FILE* f = std::fopen(path.c_str(), "rb"))
  {
    std::fclose(f);
  }
  else
  {
    throw std::invalid_argument("cannot open '" + path + "'");
  }
  auto reader = vtkSmartPointer<Reader>::New();
  bool known = true;
  if constexpr (std::is_base_of_v<vtkImageReader2, Reader>)
  {
    known = reader->CanReadFile(path.c_str()) != 0;
  }
  else if constexpr (std::is_same_v<vtkPLYReader, Reader>)
  {
    known = vtkPLYReader::CanReadFile(path.c_str()) != 0;
  }
  if (!known)
  {
    throw std::invalid_argument("cannot read '" + path + "': not a " + format + " file");
  }
  ictk::vtk::ErrorCapture capture;
  capture.WatchAlgorithm(reader);
  if constexpr (std::is_base_of_v<vtkXMLReader, Reader>)
  {
    reader->SetParserErrorObserver(capture.Observer());
    reader->SetReaderErrorObserver(capture.Observer());
  }
  reader->SetFileName(path.c_str());
  {
    // MetaImage's library (vtkmetaio) reports a data file shorter than its header's DimSize only
    // on std::cerr ("M_ReadElementsData: data not read completely") and VTK then hands on the
    // image with the missing values zero: a silent wrong scan. Its stream is taken for the read.
    std::ostringstream metaio;
    std::streambuf* cerr = std::cerr.rdbuf(metaio.rdbuf());
    try
    {
      reader->Update();
    }
    catch (...)
    {
      std::cerr.rdbuf(cerr);
      throw;
    }
    std::cerr.rdbuf(cerr);
    const std::string said = metaio.str();
    if (said.find("not read completely") != std::string::npos)
    {
      const std::size_t ideal = said.find("ideal");
      std::string detail = ideal == std::string::npos ? std::string() : said.substr(ideal);
      detail.erase(std::remove(detail.begin(), detail.end(), '\n'), detail.end());
      throw std::invalid_argument("cannot read '" + path +
        "': its data holds fewer values than its header's size says" +
        (detail.empty() ? std::string() : " (" + detail + " bytes)") +
        "; the data file is truncated or the header is wrong");
    }
    if (!said.empty() && capture.Errors.empty() && reader->GetErrorCode() == 0)
    {
      std::cerr << said; // nothing this reader refuses: let it be seen as before
    }
    else if (!said.empty())
    {
      capture.Errors.push_back(said);
    }
  }
  if (!capture.Errors.empty() || reader->GetErrorCode() != 0 || !reader->GetOutputDataObject(0))
  {
    throw std::invalid_argument("cannot read '" + path + "'" +
      (capture.Errors.empty() ? std::string() : ": " + readFailure(path, capture.Errors, format)));
  }
  return reader;
}

} // namespace

vtkSmartPointer<vtkUnstructuredGrid> ictk::vtk::readUnstructuredGrid(const std::string& path)
{
  return readWith<vtkXMLUnstructuredGridReader>(path, "UnstructuredGrid")->GetOutput();
}

namespace
{
using namespace ictk;

complex::ExplicitGeometry readMesh(const std::string& path)
{
  vtkSmartPointer<vtkDataSet> data;
  if (endsWith(path, ".vtu"))
  {
    data = ictk::vtk::readUnstructuredGrid(path);
  }
  else if (endsWith(path, ".vtp"))
  {
    data = readWith<vtkXMLPolyDataReader>(path, "PolyData")->GetOutput();
  }
  else if (endsWith(path, ".stl"))
  {
    data = readWith<vtkSTLReader>(path, "STL")->GetOutput();
  }
  else if (endsWith(path, ".ply"))
  {
    data = readWith<vtkPLYReader>(path, "PLY")->GetOutput();
  }
  else if (endsWith(path, ".obj"))
  {
    data = readWith<vtkOBJReader>(path, "OBJ")->GetOutput();
  }
  else
  {
    throw std::invalid_argument(
      "'" + path + "': explicit cells are read from .vtp, .vtu, .stl, .ply or .obj files");
  }
  if (data->GetNumberOfPoints() == 0)
  {
    throw std::invalid_argument("'" + path + "' has no points");
  }
  complex::ExplicitGeometry g;
  g.points.resize(static_cast<std::size_t>(data->GetNumberOfPoints()));
  for (vtkIdType i = 0; i < data->GetNumberOfPoints(); ++i)
  {
    data->GetPoint(i, g.points[static_cast<std::size_t>(i)].data());
  }
  if (auto* grid = vtkUnstructuredGrid::SafeDownCast(data))
  {
    for (vtkIdType c = 0; c < grid->GetNumberOfCells(); ++c)
    {
      if (grid->GetCellType(c) != VTK_TETRA)
      {
        throw std::invalid_argument("'" + path + "': cell " + std::to_string(c) +
          " is not a tetrahedron (an explicit solid is a tetrahedral mesh)");
      }
      vtkIdType n = 0;
      const vtkIdType* ids = nullptr;
      grid->GetCellPoints(c, n, ids);
      g.tetrahedra.push_back(
        { static_cast<std::uint32_t>(ids[0]), static_cast<std::uint32_t>(ids[1]),
          static_cast<std::uint32_t>(ids[2]), static_cast<std::uint32_t>(ids[3]) });
    }
    return g;
  }
  // Polygons are triangulated; the highest dimension present makes the cell.
  vtkNew<vtkTriangleFilter> triangles;
  triangles->SetInputData(data);
  triangles->PassVertsOn();
  triangles->PassLinesOn();
  triangles->Update();
  vtkPolyData* pd = triangles->GetOutput();
  vtkIdType n = 0;
  const vtkIdType* ids = nullptr;
  vtkCellArray* polys = pd->GetPolys();
  for (polys->InitTraversal(); polys->GetNextCell(n, ids);)
  {
    g.triangles.push_back({ static_cast<std::uint32_t>(ids[0]), static_cast<std::uint32_t>(ids[1]),
      static_cast<std::uint32_t>(ids[2]) });
  }
  if (g.triangles.empty())
  {
    vtkCellArray* lines = pd->GetLines();
    for (lines->InitTraversal(); lines->GetNextCell(n, ids);)
    {
      g.polylines.emplace_back(ids, ids + n);
    }
  }
  return g;
}

std::shared_ptr<voxel::VoxelGrid> readVolume(const std::string& path, const std::string& array)
{
  if (voxel::isCoreVolume(path))
  {
    return voxel::readCoreVolume(path, array);
  }
  vtkSmartPointer<vtkImageData> image;
  if (endsWith(path, ".vti"))
  {
    image = readWith<vtkXMLImageDataReader>(path, "ImageData")->GetOutput();
  }
  else if (endsWith(path, ".mha") || endsWith(path, ".mhd"))
  {
    image = readWith<vtkMetaImageReader>(path, "MetaImage")->GetOutput();
  }
  else if (endsWith(path, ".nii") || endsWith(path, ".nii.gz"))
  {
    image = readWith<vtkNIFTIImageReader>(path, "NIfTI")->GetOutput();
  }
  else if (endsWith(path, ".nrrd") || endsWith(path, ".nhdr"))
  {
    image = readWith<vtkNrrdReader>(path, "NRRD")->GetOutput();
  }
  else
  {
    throw std::invalid_argument("'" + path +
      "': voxel cells are read from .vdb, .inv3, .vti, .mha/.mhd, .nii/.nii.gz or .nrrd/.nhdr "
      "files");
  }
  vtkDataArray* scalars = array.empty() ? image->GetPointData()->GetScalars()
                                        : image->GetPointData()->GetArray(array.c_str());
  if (!scalars && array.empty() && image->GetPointData()->GetNumberOfArrays() > 0)
  {
    scalars = image->GetPointData()->GetArray(0);
  }
  if (!scalars)
  {
    throw std::invalid_argument("'" + path + "' has no point array" +
      (array.empty() ? std::string() : " named '" + array + "'"));
  }
  if (vtkMatrix3x3* d = image->GetDirectionMatrix())
  {
    if (!d->IsIdentity())
    {
      throw std::invalid_argument(
        "'" + path + "' has a rotated grid (direction matrix); resample it to the axes first");
    }
  }
  auto grid = std::make_shared<voxel::VoxelGrid>();
  int dims[3];
  image->GetDimensions(dims);
  for (int a = 0; a < 3; ++a)
  {
    grid->dimensions[a] = dims[a];
    grid->origin[a] = image->GetOrigin()[a];
    grid->spacing[a] = image->GetSpacing()[a];
  }
  const vtkIdType count = image->GetNumberOfPoints();
  grid->values.resize(static_cast<std::size_t>(count));
  for (vtkIdType i = 0; i < count; ++i)
  {
    grid->values[static_cast<std::size_t>(i)] = static_cast<float>(scalars->GetComponent(i, 0));
  }
  return grid;
}

} // namespace

struct ictkComplexSource::Internals
{
  /// The complex last read from FileName, and the file's time then (a changed file is read again).
  std::string ReadPath;
  std::filesystem::file_time_type ReadTime{};
  std::shared_ptr<const complex::Complex> Read;
  vtkSmartPointer<vtkDataAssembly> Assembly;
  /// The complex Assembly was built from.
  std::shared_ptr<const complex::Complex> AssemblyOf;
};

ictkComplexSource::ictkComplexSource()
  : Internal(new Internals)
{
  this->SetNumberOfInputPorts(0);
}

ictkComplexSource::~ictkComplexSource() = default;

void ictkComplexSource::SetComplex(std::shared_ptr<const ictk::complex::Complex> complex)
{
  this->Complex = std::move(complex);
  this->Modified();
}

complex::Complex ictkComplexSource::ReadComplexFile(const std::string& path,
  std::function<void(const std::string&, std::shared_ptr<const voxel::VoxelGrid>)> scanRead)
{
  lang::ComplexFileReaders readers;
  readers.mesh = readMesh;
  readers.volume = readVolume;
  readers.scanRead = std::move(scanRead);
  return lang::readComplexFile(path, {}, readers);
}

std::shared_ptr<const complex::Complex> ictkComplexSource::LoadComplex()
{
  const std::shared_ptr<const complex::Complex>& given = this->Complex;
  const std::string& fileName = this->FileName;
  Internals& internal = *this->Internal;
  if (given)
  {
    return given;
  }
  if (fileName.empty())
  {
    throw std::invalid_argument("no complex: set FileName (a .json complex) or a complex in C++");
  }
  std::error_code ec;
  const auto modified = std::filesystem::last_write_time(fileName, ec);
  if (!internal.Read || internal.ReadPath != fileName || ec || modified != internal.ReadTime)
  {
    internal.Read.reset();
    internal.Read =
      std::make_shared<const complex::Complex>(ictkComplexSource::ReadComplexFile(fileName));
    internal.ReadPath = fileName;
    internal.ReadTime = modified;
  }
  return internal.Read;
}

void ictkComplexSource::AddSelector(const char* selector)
{
  if (selector && *selector)
  {
    this->Selectors.emplace_back(selector);
    this->Modified();
  }
}

void ictkComplexSource::ClearSelectors()
{
  if (!this->Selectors.empty())
  {
    this->Selectors.clear();
    this->Modified();
  }
}

const char* ictkComplexSource::GetSelector(int i) const
{
  return i >= 0 && i < static_cast<int>(this->Selectors.size())
    ? this->Selectors[static_cast<std::size_t>(i)].c_str()
    : nullptr;
}

vtkDataAssembly* ictkComplexSource::GetAssembly()
{
  return this->Internal->Assembly;
}

int ictkComplexSource::CanReadFile(const char* name)
{
  if (!name || !endsWith(name, ".json"))
  {
    return 0;
  }
  // A complex is a JSON object with a "cells" key; reading the head of the file is enough to
  // tell it from other JSON files (ParaView offers every reader of an extension).
  std::ifstream in(name, std::ios::binary);
  std::string head(1 << 16, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  const auto first = head.find_first_not_of(" \t\r\n");
  return first != std::string::npos && head[first] == '{' &&
      head.find("\"cells\"") != std::string::npos
    ? 1
    : 0;
}

int ictkComplexSource::RequestInformation(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  try
  {
    const auto k = LoadComplex();
    this->Internal->Assembly = ictk::vtk::complexAssembly(*k, k->cellIds());
    this->Internal->AssemblyOf = k;
    ++this->AssemblyTag;
  }
  catch (const std::exception& e)
  {
    this->Internal->Assembly = nullptr;
    vtkErrorMacro("" << e.what());
    return 0;
  }
  outputVector->GetInformationObject(0)->Set(CAN_HANDLE_PIECE_REQUEST(), 1);
  return 1;
}

int ictkComplexSource::RequestData(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  vtkPartitionedDataSetCollection* output = vtkPartitionedDataSetCollection::GetData(outputVector);
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  return ictk::vtk::runRequest(this, output,
    [&]
    {
      const std::shared_ptr<const complex::Complex> k = LoadComplex();
      const std::vector<complex::CellId> all = k->cellIds();
      // The chosen cells, in the order of the collection.
      std::vector<complex::CellId> chosen = all;
      if (!this->Selectors.empty())
      {
        // RequestInformation built the assembly of this complex (all cells, in order).
        const vtkSmartPointer<vtkDataAssembly> assembly = this->Internal->AssemblyOf == k
          ? this->Internal->Assembly
          : ictk::vtk::complexAssembly(*k, all);
        const std::vector<int> nodes = assembly->SelectNodes(this->Selectors);
        std::vector<unsigned int> indices = assembly->GetDataSetIndices(nodes, true);
        std::sort(indices.begin(), indices.end());
        indices.erase(std::unique(indices.begin(), indices.end()), indices.end());
        chosen.clear();
        for (unsigned int i : indices)
        {
          chosen.push_back(all[i]);
        }
      }
      const int pieces =
        std::max(1, outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES()));
      const int piece = outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER());
      std::vector<complex::CellId> share;
      for (std::size_t i = 0; i < chosen.size(); ++i)
      {
        if (static_cast<int>(i % static_cast<std::size_t>(pieces)) == piece)
        {
          share.push_back(chosen[i]);
        }
      }
      complex::DiscretizationOptions options;
      // The feature size of the whole complex, whatever part of it is discretised here.
      options.featureSize =
        this->FeatureSize > 0 ? this->FeatureSize : complex::defaultFeatureSize(*k);
      options.threads = this->NumberOfThreads;
      options.progress = ictk::vtk::progressOf(this);
      complex::ComplexMesh mesh;
      if (share.size() == all.size())
      {
        mesh = complex::discretizeComplex(*k, options);
      }
      else if (!share.empty())
      {
        options.cells = share;
        mesh = complex::discretizeComplex(*k, options);
      }
      ictk::vtk::complexToVTK(*k, mesh, output, this->VolumeResolution, &all);
      AttachComplex(output, k);
      return 1;
    });
}

void ictkComplexSource::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FileName: " << this->FileName << "\n";
  os << indent << "Selectors:";
  for (const std::string& selector : this->Selectors)
  {
    os << " " << selector;
  }
  os << (this->Selectors.empty() ? " (none: every cell)\n" : "\n");
  os << indent << "FeatureSize: " << this->FeatureSize << "\n";
  os << indent << "VolumeResolution: " << this->VolumeResolution << "\n";
  os << indent << "NumberOfThreads: " << this->NumberOfThreads << "\n";
}
