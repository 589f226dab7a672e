// SPDX-License-Identifier: BSD-3-Clause
#include "Output.h"

#include "Command.h"

#include "ictkFileWriting.h"
#include "ictkTetrahedralize.h"

#include <vtkDataObject.h>
#include <vtkNew.h>
#include <vtkSmartPointer.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridWriter.h>
#include <vtkXMLWriter.h>
#include <vtkXMLWriterBase.h>

#include <fcntl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <stdexcept>

namespace fs = std::filesystem;

namespace ictk::cli
{

AtomicOutput::AtomicOutput(const std::string& destination)
  : Destination(destination)
{
  if (destination.empty())
  {
    throw UserError("the output path is empty");
  }
  const fs::path path(destination);
  std::error_code ec;
  if (fs::is_directory(path, ec))
  {
    throw UserError("cannot write '" + destination + "': it is a directory");
  }
  const fs::path folder = path.has_parent_path() ? path.parent_path() : fs::path(".");
  if (!fs::is_directory(folder, ec))
  {
    throw UserError(
      "cannot write '" + destination + "': folder '" + folder.string() + "' does not exist");
  }
  // The temporary name keeps the extension: some writers (vtkPLYWriter) append theirs
  // to a file name that does not end with it.
  const std::string extension = path.extension().string();
  std::string pattern =
    (folder / ("." + path.stem().string() + ".tmp-XXXXXX" + extension)).string();
  const int fd = mkstemps(pattern.data(), static_cast<int>(extension.size()));
  if (fd < 0)
  {
    throw UserError("cannot write '" + destination + "': " + std::strerror(errno));
  }
  // mkstemp creates the file 0600; give the result the permissions a plain create would.
  const mode_t mask = umask(0);
  umask(mask);
  fchmod(fd, 0666 & ~mask);
  close(fd);
  this->Temporary = pattern;
}

AtomicOutput::~AtomicOutput()
{
  if (!this->Temporary.empty())
  {
    std::remove(this->Temporary.c_str());
  }
}

void AtomicOutput::Fail(const std::string& why) const
{
  throw UserError("cannot write '" + this->Destination + "': " + why + "; nothing written");
}

void AtomicOutput::Write(const std::string& bytes)
{
  try
  {
    vtk::writeWholeFile(this->Temporary, bytes);
  }
  catch (const std::runtime_error& e)
  {
    this->Fail(e.what());
  }
}

void AtomicOutput::Commit()
{
  this->Verify();
  if (std::rename(this->Temporary.c_str(), this->Destination.c_str()) != 0)
  {
    throw UserError("cannot write '" + this->Destination + "': " + std::strerror(errno));
  }
  this->Temporary.clear();
}

void AtomicOutput::Verify() const
{
  const int fd = ::open(this->Temporary.c_str(), O_RDONLY);
  struct stat st
  {};
  if (fd < 0 || ::fsync(fd) != 0 || ::fstat(fd, &st) != 0)
  {
    const int error = errno;
    if (fd >= 0)
    {
      ::close(fd);
    }
    this->Fail(std::strerror(error));
  }
  // A write cut short leaves the file exactly at the size limit, or the disk without a free
  // block; a file that happens to fill either exactly is refused too (it may be complete, but
  // that cannot be told).
  struct rlimit limit
  {};
  struct statvfs disk
  {};
  const bool full =
    ::fstatvfs(fd, &disk) == 0 && (disk.f_bavail == 0 && (::geteuid() != 0 || disk.f_bfree == 0));
  ::close(fd);
  if (::getrlimit(RLIMIT_FSIZE, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY &&
    static_cast<rlim_t>(st.st_size) >= limit.rlim_cur)
  {
    this->Fail("the file reached the file size limit (ulimit -f) of " +
      std::to_string(limit.rlim_cur) + " bytes");
  }
  if (full)
  {
    this->Fail(std::strerror(ENOSPC));
  }
}

void WriteXml(vtkXMLWriter* writer, vtkDataObject* data, AtomicOutput& file)
{
  writer->SetInputDataObject(data);
  writer->WriteToOutputStringOn();
  if (writer->Write() != 1 || writer->GetErrorCode() != 0)
  {
    file.Fail("VTK's XML writer failed");
  }
  file.Write(writer->GetOutputString());
}

namespace
{
/// Refuses, before writing, a composite whose pieces may not fit (ictkFileWriting.h): the pieces
/// are written by VTK's composite writers themselves, which can crash when a stream fails.
void CheckRoomForPieces(vtkDataObject* data, const fs::path& folder, const std::string& output)
{
  const std::string why = vtk::piecesDoNotFit(data, folder.string());
  if (!why.empty())
  {
    throw UserError("cannot write '" + output + "': " + why + "; nothing written");
  }
}
} // namespace

void WriteComposite(vtkXMLWriterBase* writer, vtkDataObject* data, const std::string& output)
{
  const fs::path target = fs::absolute(output);
  CheckRoomForPieces(data, target.parent_path(), output);
  // The pieces folder is named after the file's stem, so x.vtpc, x.vtm and x.pvd (ictk run's
  // frames) would share it, and writing one would replace the pieces of another.
  const fs::path folder = target.parent_path() / target.stem();
  for (const char* other : { ".vtpc", ".vtm", ".pvd" })
  {
    const fs::path sibling = fs::path(target).replace_extension(other);
    std::error_code ec;
    if (sibling != target && fs::exists(sibling, ec) && fs::exists(folder, ec))
    {
      throw UserError("cannot write '" + output + "': the folder '" + folder.string() +
        "' holds the pieces of '" + sibling.string() + "'; choose another name");
    }
  }
  const fs::path staging = target.parent_path() /
    (".ictk-" + target.filename().string() + "-" + std::to_string(::getpid()));
  fs::remove_all(staging);
  fs::create_directories(staging);
  const fs::path stagedFile = staging / target.filename();
  writer->SetInputDataObject(data);
  writer->SetFileName(stagedFile.string().c_str());
  const int ok = writer->Write();
  if (ok != 1 || writer->GetErrorCode() != 0)
  {
    fs::remove_all(staging);
    throw UserError("cannot write '" + output + "'");
  }
  const fs::path pieces = staging / target.stem();
  const fs::path targetPieces = target.parent_path() / target.stem();
  if (fs::exists(pieces))
  {
    if (fs::exists(targetPieces))
    {
      const std::string prefix = target.stem().string() + "_";
      for (const auto& entry : fs::directory_iterator(targetPieces))
      {
        const std::string name = entry.path().filename().string();
        if (!entry.is_regular_file() || name.rfind(prefix, 0) != 0 ||
          entry.path().extension().string().rfind(".vt", 0) != 0)
        {
          fs::remove_all(staging);
          throw UserError("cannot write '" + output + "': the folder '" + targetPieces.string() +
            "' holds other files ('" + name + "'); move them or choose another name");
        }
      }
      fs::remove_all(targetPieces);
    }
    fs::rename(pieces, targetPieces);
  }
  fs::rename(stagedFile, target);
  fs::remove_all(staging);
}

void WriteUnstructuredGrid(vtkUnstructuredGrid* grid, AtomicOutput& file)
{
  vtkNew<vtkXMLUnstructuredGridWriter> writer;
  writer->SetDataModeToAppended();
  WriteXml(writer, grid, file);
  file.Commit();
}

void WriteTetMeshVtu(const mesh::TetMesh& m, const std::string& path)
{
  vtkNew<vtkUnstructuredGrid> grid;
  ictkTetrahedralize::Convert(m, grid);
  AtomicOutput file(path);
  WriteUnstructuredGrid(grid, file);
}

} // namespace ictk::cli
