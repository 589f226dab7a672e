// SPDX-License-Identifier: BSD-3-Clause
#include "Output.h"

#include "Command.h"

#include "ictkTetrahedralize.h"

#include <vtkDataObject.h>
#include <vtkNew.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridWriter.h>
#include <vtkXMLWriterBase.h>

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
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

void AtomicOutput::Commit()
{
  if (std::rename(this->Temporary.c_str(), this->Destination.c_str()) != 0)
  {
    throw UserError("cannot write '" + this->Destination + "': " + std::strerror(errno));
  }
  this->Temporary.clear();
}

void WriteComposite(vtkXMLWriterBase* writer, vtkDataObject* data, const std::string& output)
{
  const fs::path target = fs::absolute(output);
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

void WriteUnstructuredGrid(
  vtkUnstructuredGrid* grid, AtomicOutput& file, const std::string& destination)
{
  vtkNew<vtkXMLUnstructuredGridWriter> writer;
  writer->SetInputData(grid);
  writer->SetFileName(file.Path().c_str());
  writer->SetDataModeToAppended();
  if (writer->Write() != 1 || writer->GetErrorCode() != 0)
  {
    throw UserError("cannot write '" + destination + "'");
  }
  file.Commit();
}

void WriteTetMeshVtu(const mesh::TetMesh& m, const std::string& path)
{
  vtkNew<vtkUnstructuredGrid> grid;
  ictkTetrahedralize::Convert(m, grid);
  AtomicOutput file(path);
  WriteUnstructuredGrid(grid, file, path);
}

} // namespace ictk::cli
