// SPDX-License-Identifier: BSD-3-Clause
#include "ictkTimeSeriesWriter.h"
#include "ictkComplexSource.h"
#include "ictkFileWriting.h"
#include "ictkRequest.h"

#include "Lang/XmlText.h"

#include "vtkAbstractArray.h"
#include "vtkAlgorithmOutput.h"
#include "vtkCommand.h"
#include "vtkDataObject.h"
#include "vtkFieldData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkMultiBlockDataSet.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPartitionedDataSet.h"
#include "vtkPartitionedDataSetCollection.h"
#include "vtkSmartPointer.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkTable.h"
#include "vtkUniformGridAMR.h"
#include "vtkXMLDataObjectWriter.h"
#include "vtkXMLMultiBlockDataWriter.h"
#include "vtkXMLPartitionedDataSetCollectionWriter.h"
#include "vtkXMLPartitionedDataSetWriter.h"
#include "vtkXMLTableWriter.h"
#include "vtkXMLUniformGridAMRWriter.h"
#include "vtkXMLWriter.h"

#include <nlohmann/json.hpp>

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <iomanip>
#include <sstream>
#include <stdexcept>
#include <vector>

vtkStandardNewMacro(ictkTimeSeriesWriter);

namespace
{
namespace fs = std::filesystem;

std::string Lower(std::string s)
{
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

/// The extensions of VTK's XML files: the frames, and what an earlier series' folder may hold.
bool IsXmlExtension(const std::string& extension)
{
  static const char* const known[] = { ".vtp", ".vtu", ".vti", ".vtr", ".vts", ".vtm", ".vtpc",
    ".vtpd", ".vthb", ".vth", ".vtt", ".htg" };
  return std::find(std::begin(known), std::end(known), Lower(extension)) != std::end(known);
}

/// An entry of a frames folder this writer makes: <stem>_<digits>.<xml extension> and the
/// pieces folders <stem>_<digits> of the composite writers.
bool IsFrameEntry(const fs::directory_entry& entry, const std::string& stem)
{
  const fs::path path = entry.path();
  std::string name = path.filename().string();
  if (entry.is_regular_file() && IsXmlExtension(path.extension().string()))
  {
    name = path.stem().string();
  }
  else if (!entry.is_directory())
  {
    return false;
  }
  const std::string prefix = stem + "_";
  if (name.rfind(prefix, 0) != 0 || name.size() == prefix.size())
  {
    return false;
  }
  return std::all_of(name.begin() + static_cast<std::ptrdiff_t>(prefix.size()), name.end(),
    [](unsigned char c) { return std::isdigit(c); });
}

/// Where a series goes, checked before any frame is computed: the .pvd, its frames folder (named
/// after its stem, beside it), and the staging folder everything is written into first; the
/// staging folder goes when this does, so that an error leaves what was there untouched.
struct Destination
{
  std::string Name; ///< as the user gave it, for messages
  fs::path Pvd;
  fs::path Frames;
  std::string Stem;
  fs::path Staging;

  explicit Destination(const std::string& name)
    : Name(name)
  {
    if (name.empty())
    {
      throw std::invalid_argument("no file name: set FileName (a .pvd file)");
    }
    if (Lower(fs::path(name).extension().string()) != ".pvd")
    {
      throw std::invalid_argument("'" + name + "' is not a .pvd file");
    }
    Pvd = fs::absolute(name);
    Stem = Pvd.stem().string();
    Frames = Pvd.parent_path() / Stem;
    std::error_code ec;
    if (!fs::is_directory(Pvd.parent_path(), ec))
    {
      throw std::invalid_argument(
        "cannot write '" + name + "': folder '" + Pvd.parent_path().string() + "' does not exist");
    }
    if (fs::is_directory(Pvd, ec))
    {
      throw std::invalid_argument("cannot write '" + name + "': it is a directory");
    }
    if (fs::exists(Frames, ec))
    {
      if (!fs::is_directory(Frames, ec))
      {
        throw std::invalid_argument("cannot write the frames of '" + name + "': '" +
          Frames.string() + "' is a file; move it or choose another name");
      }
      // Replace an earlier series' frames, never anything else.
      for (const auto& entry : fs::directory_iterator(Frames))
      {
        if (!IsFrameEntry(entry, Stem))
        {
          throw std::invalid_argument("cannot write the frames of '" + name + "': the folder '" +
            Frames.string() + "' holds other files ('" + entry.path().filename().string() +
            "'); move them or choose another name");
        }
      }
    }
    Staging = Pvd.parent_path() / (".ictk-series-" + Stem + "-" + std::to_string(::getpid()));
    fs::remove_all(Staging, ec);
    if (!fs::create_directory(Staging, ec) || !fs::create_directory(Staging / Stem, ec))
    {
      const std::string why = ec.message();
      fs::remove_all(Staging, ec);
      throw std::invalid_argument("cannot write '" + name + "': " + why);
    }
  }
  Destination(const Destination&) = delete;
  Destination& operator=(const Destination&) = delete;
  ~Destination()
  {
    std::error_code ec;
    fs::remove_all(Staging, ec);
  }

  /// Moves the series into place; an earlier series' frames are replaced only once the new ones
  /// are there to take their place.
  void commit()
  {
    const fs::path old = Staging / ".previous";
    const bool hadFrames = fs::exists(Frames);
    if (hadFrames)
    {
      fs::rename(Frames, old);
    }
    try
    {
      fs::rename(Staging / Stem, Frames);
    }
    catch (...)
    {
      if (hadFrames)
      {
        std::error_code ec;
        fs::rename(old, Frames, ec);
      }
      throw;
    }
    fs::rename(Staging / (Stem + ".pvd"), Pvd);
  }
};

/// VTK's XML writer for a data object of this type (nullptr: none).
vtkSmartPointer<vtkXMLWriterBase> NewFrameWriter(vtkDataObject* data)
{
  vtkSmartPointer<vtkXMLWriterBase> writer;
  if (vtkPartitionedDataSetCollection::SafeDownCast(data))
  {
    writer = vtkSmartPointer<vtkXMLPartitionedDataSetCollectionWriter>::New();
  }
  else if (vtkPartitionedDataSet::SafeDownCast(data))
  {
    writer = vtkSmartPointer<vtkXMLPartitionedDataSetWriter>::New();
  }
  else if (vtkUniformGridAMR::SafeDownCast(data))
  {
    writer = vtkSmartPointer<vtkXMLUniformGridAMRWriter>::New();
  }
  else if (vtkMultiBlockDataSet::SafeDownCast(data))
  {
    writer = vtkSmartPointer<vtkXMLMultiBlockDataWriter>::New();
  }
  else if (vtkTable::SafeDownCast(data))
  {
    writer = vtkSmartPointer<vtkXMLTableWriter>::New();
  }
  else if (data)
  {
    writer.TakeReference(vtkXMLDataObjectWriter::NewWriter(data->GetDataObjectType()));
  }
  return writer;
}

/// A frame as it is saved: a shallow copy without what only lives in memory, its DATA_TIME_STEP
/// (which VTK's writers would save as a "TimeValue" array; the .pvd holds the times) and the field
/// arrays that carry a complex (ictkComplexSource::COMPLEX()).
vtkSmartPointer<vtkDataObject> WhatIsSaved(vtkDataObject* data)
{
  auto saved = vtk::TakeSmartPointer(data->NewInstance());
  saved->ShallowCopy(data);
  saved->GetInformation()->Remove(vtkDataObject::DATA_TIME_STEP());
  if (vtkFieldData* fd = saved->GetFieldData())
  {
    for (int a = fd->GetNumberOfArrays() - 1; a >= 0; --a)
    {
      vtkAbstractArray* array = fd->GetAbstractArray(a);
      if (array && array->HasInformation() &&
        array->GetInformation()->Has(ictkComplexSource::COMPLEX()))
      {
        fd->RemoveArray(a);
      }
    }
  }
  return saved;
}

} // namespace

ictkTimeSeriesWriter::ictkTimeSeriesWriter()
{
  this->SetNumberOfInputPorts(1);
  this->SetNumberOfOutputPorts(0);
}

ictkTimeSeriesWriter::~ictkTimeSeriesWriter() = default;

int ictkTimeSeriesWriter::FillInputPortInformation(int, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkDataObject");
  return 1;
}

int ictkTimeSeriesWriter::FillOutputPortInformation(int, vtkInformation*)
{
  return 1;
}

int ictkTimeSeriesWriter::Write()
{
  this->SetAbortExecute(0);
  this->FramesWritten = 0;
  this->InvokeEvent(vtkCommand::StartEvent);
  this->UpdateProgress(0.0);
  // WriteSeries() meets a cancellation between frames and returns 0; runRequest reports its errors.
  const int result = ictk::vtk::runRequest(this, nullptr, [this] { return this->WriteSeries(); });
  if (!result)
  {
    this->FramesWritten = 0;
  }
  this->InvokeEvent(vtkCommand::EndEvent);
  return result;
}

int ictkTimeSeriesWriter::WriteSeries()
{
  vtkAlgorithmOutput* connection =
    this->GetNumberOfInputConnections(0) > 0 ? this->GetInputConnection(0, 0) : nullptr;
  vtkAlgorithm* producer = connection ? connection->GetProducer() : nullptr;
  if (!producer)
  {
    throw std::invalid_argument("no input: connect the pipeline to write");
  }
  const int port = connection->GetIndex();
  // Refused before the input computes anything.
  Destination out(this->FileName);

  auto* executive = vtkStreamingDemandDrivenPipeline::SafeDownCast(producer->GetExecutive());
  if (!executive || !executive->UpdateInformation())
  {
    throw std::runtime_error("cannot write '" + out.Name + "': the input has no information");
  }
  vtkInformation* info = producer->GetOutputInformation(port);
  // The chosen time steps; none: one frame, no time asked for.
  std::vector<double> times;
  const bool temporal = info->Has(vtkStreamingDemandDrivenPipeline::TIME_STEPS()) &&
    info->Length(vtkStreamingDemandDrivenPipeline::TIME_STEPS()) > 0;
  if (temporal)
  {
    const int n = info->Length(vtkStreamingDemandDrivenPipeline::TIME_STEPS());
    const double* steps = info->Get(vtkStreamingDemandDrivenPipeline::TIME_STEPS());
    const int last = this->LastTimeStep < 0 ? n - 1 : std::min(this->LastTimeStep, n - 1);
    for (int i = this->FirstTimeStep; i <= last; i += this->TimeStepStride)
    {
      times.push_back(steps[i]);
    }
    if (times.empty())
    {
      throw std::invalid_argument("cannot write '" + out.Name + "': no time step chosen (" +
        std::to_string(n) + " time steps, first " + std::to_string(this->FirstTimeStep) +
        ", last " + std::to_string(this->LastTimeStep) + ")");
    }
  }
  const std::size_t frames = temporal ? times.size() : 1;
  const std::size_t digits = std::max<std::size_t>(4, std::to_string(frames - 1).size());

  std::ostringstream pvd;
  pvd << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
      << "  <Collection>\n";
  vtkSmartPointer<vtkXMLWriterBase> writer;
  int writerType = -1; ///< the data object type it writes
  for (std::size_t frame = 0; frame < frames; ++frame)
  {
    vtkNew<vtkInformationVector> requests;
    requests->SetNumberOfInformationObjects(producer->GetNumberOfOutputPorts());
    if (temporal)
    {
      requests->GetInformationObject(port)->Set(
        vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP(), times[frame]);
    }
    const bool updated = producer->Update(port, requests) != 0;
    if (this->GetAbortExecute() || producer->GetAbortExecute())
    {
      return 0;
    }
    vtkDataObject* data = producer->GetOutputDataObject(port);
    if (!updated || !data)
    {
      std::ostringstream os;
      os << "cannot write frame " << frame << " of '" << out.Name << "': the input failed";
      if (temporal)
      {
        os << " at t = " << times[frame];
      }
      throw std::runtime_error(os.str());
    }
    double time = temporal ? times[frame] : 0.0;
    if (!temporal && data->GetInformation()->Has(vtkDataObject::DATA_TIME_STEP()))
    {
      time = data->GetInformation()->Get(vtkDataObject::DATA_TIME_STEP());
    }
    const vtkSmartPointer<vtkDataObject> saved = WhatIsSaved(data);
    if (!writer || data->GetDataObjectType() != writerType)
    {
      writer = NewFrameWriter(data);
      writerType = data->GetDataObjectType();
      if (!writer)
      {
        throw std::invalid_argument(
          "cannot write '" + out.Name + "': VTK has no XML writer for " + data->GetClassName());
      }
      writer->SetDataMode(this->DataMode);
      writer->SetEncodeAppendedData(this->EncodeAppendedData);
      writer->SetCompressorType(this->CompressorType);
    }
    std::ostringstream name;
    name << out.Stem << "_" << std::setw(static_cast<int>(digits)) << std::setfill('0') << frame
         << "." << writer->GetDefaultFileExtension();
    this->WriteFrame(writer, saved, out.Staging / out.Stem / name.str(),
      "cannot write frame " + std::to_string(frame) + " of '" + out.Name + "' (" +
        (fs::path(out.Name).parent_path() / out.Stem / name.str()).string() + ")");
    // The shortest text that reads back as the same double.
    pvd << "    <DataSet timestep=\"" << nlohmann::json(time).dump() << "\" file=\""
        << ictk::lang::xmlAttribute(out.Stem + "/" + name.str(), "the frame file name") << "\"/>\n";
    this->FramesWritten = static_cast<int>(frame + 1);
    this->UpdateProgress(double(frame + 1) / double(frames));
    if (this->GetAbortExecute())
    {
      return 0;
    }
  }
  pvd << "  </Collection>\n</VTKFile>\n";
  try
  {
    ictk::vtk::writeWholeFile((out.Staging / (out.Stem + ".pvd")).string(), pvd.str());
  }
  catch (const std::runtime_error& e)
  {
    throw std::runtime_error("cannot write '" + out.Name + "': " + e.what() + "; nothing written");
  }
  out.commit();
  return 1;
}

void ictkTimeSeriesWriter::WriteFrame(
  vtkXMLWriterBase* writer, vtkDataObject* data, const fs::path& path, const std::string& failure)
{
  // A full disk fails the frame with the system's reason, and the staging folder goes (the
  // earlier series stays): a single XML file is made in memory and written with checked writes,
  // the pieces of a composite are first checked to fit (ictkFileWriting.h: VTK's XML writers can
  // crash when their stream fails mid-file).
  auto* single = vtkXMLWriter::SafeDownCast(writer);
  if (!single)
  {
    const std::string why = ictk::vtk::piecesDoNotFit(data, path.parent_path().string());
    if (!why.empty())
    {
      throw std::runtime_error(failure + ": " + why + "; nothing written");
    }
  }
  writer->SetInputDataObject(data);
  if (single)
  {
    single->WriteToOutputStringOn();
  }
  else
  {
    writer->SetFileName(path.string().c_str());
  }
  const int written = writer->Write();
  writer->SetInputDataObject(nullptr);
  if (written != 1 || writer->GetErrorCode() != 0)
  {
    throw std::runtime_error(failure + ": VTK's XML writer failed; nothing written");
  }
  if (single)
  {
    try
    {
      ictk::vtk::writeWholeFile(path.string(), single->GetOutputString());
    }
    catch (const std::runtime_error& e)
    {
      throw std::runtime_error(failure + ": " + e.what() + "; nothing written");
    }
  }
}

void ictkTimeSeriesWriter::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FileName: " << this->FileName << "\n";
  os << indent << "FirstTimeStep: " << this->FirstTimeStep << "\n";
  os << indent << "LastTimeStep: " << this->LastTimeStep << "\n";
  os << indent << "TimeStepStride: " << this->TimeStepStride << "\n";
  os << indent << "DataMode: " << this->DataMode << "\n";
  os << indent << "EncodeAppendedData: " << this->EncodeAppendedData << "\n";
  os << indent << "CompressorType: " << this->CompressorType << "\n";
  os << indent << "FramesWritten: " << this->FramesWritten << "\n";
}
