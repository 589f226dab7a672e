// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class ictkTimeSeriesWriter
 * @brief Writes every time step of a temporal pipeline as a ParaView time series: a .pvd file and
 * one VTK XML file per frame.
 *
 * Write() updates the input at each of its TIME_STEPS (or the ones FirstTimeStep, LastTimeStep
 * and TimeStepStride choose), in order, and writes each frame with the XML writer of its type
 * (.vtpc for a vtkPartitionedDataSetCollection, .vtm, .vtp, .vti, .vtu, ...) into a folder named
 * after the .pvd's stem, beside it: for "out/disk.pvd", "out/disk/disk_0000.vtpc" and on (four
 * digits at least, more when there are more frames), and "out/disk.pvd" listing them with their
 * times. An input without time steps is written as one frame, at its DATA_TIME_STEP or 0. A
 * frame is saved without what only lives in memory: its information (DATA_TIME_STEP; the .pvd
 * holds the times) and the field arrays that carry a complex (ictkComplexSource::COMPLEX()).
 *
 * Writing is atomic: everything goes into a staging folder beside the .pvd, moved into place once
 * every frame is written, so a failure or a cancellation leaves an earlier series of the same name
 * as it was. The frames folder of an earlier series is replaced only when it holds nothing but
 * frames ("<stem>_<digits>" files of the XML writers' extensions and their pieces folders); a
 * folder holding anything else is refused before any frame is computed, as are a .pvd that is a
 * folder, a missing parent folder and a file where the frames folder would go.
 *
 * Progress is the share of frames written; AbortExecute, on this writer or on the algorithm that
 * produces its input, cancels between frames (Write() returns 0, nothing is written, no error).
 * Errors (of the input at a time step or of the writing) are reported with vtkErrorMacro and
 * Write() returns 0; a frame that cannot be written (a full disk, the file size limit) is named
 * with its file: "cannot write frame 3 of 'out/disk.pvd' (out/disk/disk_0003.vtpc): File too
 * large; nothing written". A single XML frame is made in memory and written with checked writes,
 * a composite frame's pieces are first checked to fit (ictkFileWriting.h): VTK's XML writers can
 * crash when their stream fails mid-file. The frames are written by one process.
 *
 * With ictkDynamicComplexSource as the input this is `ictk run` without its trace:
 *   source->SetFileName("disk.icm"); writer->SetInputConnection(source->GetOutputPort());
 *   writer->SetFileName("disk.pvd"); writer->Write();
 */
#pragma once

#include "ictkFiltersDynamicsModule.h" // export macro
#include "vtkAlgorithm.h"

#include <filesystem> // for std::filesystem::path
#include <string>     // for std::string

class vtkXMLWriterBase;

class ICTKFILTERSDYNAMICS_EXPORT ictkTimeSeriesWriter : public vtkAlgorithm
{
public:
  static ictkTimeSeriesWriter* New();
  vtkTypeMacro(ictkTimeSeriesWriter, vtkAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// The .pvd file.
  vtkSetStdStringFromCharMacro(FileName);
  vtkGetCharFromStdStringMacro(FileName);

  ///@{
  /// The time steps written: the input's time steps FirstTimeStep .. LastTimeStep (indices; -1,
  /// the default, is the last one), every TimeStepStride-th.
  vtkSetClampMacro(FirstTimeStep, int, 0, VTK_INT_MAX);
  vtkGetMacro(FirstTimeStep, int);
  vtkSetClampMacro(LastTimeStep, int, -1, VTK_INT_MAX);
  vtkGetMacro(LastTimeStep, int);
  vtkSetClampMacro(TimeStepStride, int, 1, VTK_INT_MAX);
  vtkGetMacro(TimeStepStride, int);
  ///@}

  ///@{
  /// The frames' XML form, as vtkXMLWriterBase's settings. The defaults (appended raw data, LZ4)
  /// write a frame in less time than most inputs take to compute it.
  vtkSetClampMacro(DataMode, int, 0, 2);
  vtkGetMacro(DataMode, int);
  vtkSetMacro(EncodeAppendedData, bool);
  vtkGetMacro(EncodeAppendedData, bool);
  vtkBooleanMacro(EncodeAppendedData, bool);
  vtkSetClampMacro(CompressorType, int, 0, 3);
  vtkGetMacro(CompressorType, int);
  ///@}

  /// Writes the series; 1 on success, 0 on an error or a cancellation.
  int Write();

  /// After Write(): the number of frames written (0 when nothing was).
  int GetNumberOfFramesWritten() const { return this->FramesWritten; }

protected:
  ictkTimeSeriesWriter();
  ~ictkTimeSeriesWriter() override;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  int FillOutputPortInformation(int port, vtkInformation* info) override;

  std::string FileName;
  int FirstTimeStep = 0;
  int LastTimeStep = -1;
  int TimeStepStride = 1;
  int DataMode = 2; // vtkXMLWriterBase::Appended
  bool EncodeAppendedData = false;
  int CompressorType = 2; // vtkXMLWriterBase::LZ4
  int FramesWritten = 0;

private:
  ictkTimeSeriesWriter(const ictkTimeSeriesWriter&) = delete;
  void operator=(const ictkTimeSeriesWriter&) = delete;

  /// The series, or 0 when cancelled; throws std::exception on an error.
  int WriteSeries();
  /// Writes one frame's file at `path` (in the staging folder); throws std::runtime_error
  /// "<failure>: <why>; nothing written" when it cannot.
  void WriteFrame(vtkXMLWriterBase* writer, vtkDataObject* data, const std::filesystem::path& path,
    const std::string& failure);
};
