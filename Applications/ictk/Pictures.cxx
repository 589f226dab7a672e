// SPDX-License-Identifier: BSD-3-Clause
#include "Pictures.h"

#include "Command.h"
#include "Options.h"
#include "ProgressDisplay.h"
#include "VtkMessages.h"

#include "FRep/Progress.h"

#include <vtkDoubleArray.h>
#include <vtkFloatArray.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGWriter.h>
#include <vtkPointData.h>
#include <vtkUnsignedCharArray.h>
#include <vtkXMLImageDataWriter.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <sstream>

namespace fs = std::filesystem;

namespace ictk::cli
{
namespace
{

/// An image of width x height pixels, one point per pixel, row 0 at the bottom (the core's order).
vtkSmartPointer<vtkImageData> PixelImage(int width, int height)
{
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->SetDimensions(width, height, 1);
  return image;
}

/// Runs a VTK writer on `path` (a temporary file); a failure is a UserError naming `shown`.
template <typename Writer>
void Run(Writer* writer, vtkImageData* image, const std::string& path, const std::string& shown)
{
  ictkCaptureOutputWindow* messages = CaptureVtkMessages();
  const std::size_t errorsBefore = messages->Errors.size();
  writer->SetInputData(image);
  writer->SetFileName(path.c_str());
  writer->Write();
  ThrowIfVtkFailed(messages, errorsBefore, "cannot write '" + shown + "'");
  if (writer->GetErrorCode() != 0)
  {
    throw UserError("cannot write '" + shown + "'");
  }
}

void Png(const PictureBuffers& picture, const std::string& path, const std::string& shown)
{
  vtkSmartPointer<vtkImageData> image = PixelImage(picture.Width, picture.Height);
  vtkNew<vtkUnsignedCharArray> rgba;
  rgba->SetName("colour");
  rgba->SetNumberOfComponents(4);
  rgba->SetNumberOfTuples(static_cast<vtkIdType>(picture.Width) * picture.Height);
  std::copy(picture.Colour->begin(), picture.Colour->end(), rgba->GetPointer(0));
  image->GetPointData()->SetScalars(rgba);
  vtkNew<vtkPNGWriter> png;
  Run(png.Get(), image, path, shown);
}

/// The one integer conversion of a frame pattern (and its position), or a UserError.
void CheckPattern(const std::string& pattern)
{
  int conversions = 0;
  for (std::size_t i = 0; i < pattern.size(); ++i)
  {
    if (pattern[i] != '%')
    {
      continue;
    }
    if (i + 1 < pattern.size() && pattern[i + 1] == '%')
    {
      ++i;
      continue;
    }
    std::size_t k = i + 1;
    while (k < pattern.size() && std::isdigit(static_cast<unsigned char>(pattern[k])))
    {
      ++k;
    }
    if (k >= pattern.size() || pattern[k] != 'd' || k - i > 4)
    {
      throw UserError("-o: '" + pattern +
        "': a frame pattern has one integer conversion such as %04d (and %% for a percent sign)");
    }
    ++conversions;
    i = k;
  }
  if (conversions != 1)
  {
    throw UserError("-o: '" + pattern +
      "': with --frames, give a pattern with one integer conversion (frames/%04d.png) or an .mp4 "
      "file");
  }
  if (!HasExtension(pattern, ".png"))
  {
    throw UserError("-o: '" + pattern + "' is not a .png pattern or an .mp4 file");
  }
}

/// The full path of `program` on the PATH; empty when it is not there.
std::string FindProgram(const std::string& program)
{
  const char* path = std::getenv("PATH");
  std::stringstream folders(path ? path : "");
  std::string folder;
  while (std::getline(folders, folder, ':'))
  {
    const fs::path candidate = fs::path(folder.empty() ? "." : folder) / program;
    if (::access(candidate.c_str(), X_OK) == 0)
    {
      return candidate.string();
    }
  }
  return {};
}

/// Runs a program with its arguments (no shell) and returns its exit status (-1: did not run).
int RunProgram(const std::vector<std::string>& arguments)
{
  std::vector<char*> argv;
  for (const std::string& a : arguments)
  {
    argv.push_back(const_cast<char*>(a.c_str()));
  }
  argv.push_back(nullptr);
  const pid_t child = ::fork();
  if (child < 0)
  {
    return -1;
  }
  if (child == 0)
  {
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  int status = 0;
  while (::waitpid(child, &status, 0) < 0)
  {
    if (errno != EINTR)
    {
      return -1;
    }
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

} // namespace

void WritePng(const PictureBuffers& picture, AtomicOutput& file, const std::string& path)
{
  Png(picture, file.Path(), path);
  file.Commit();
}

void WriteDepth(const PictureBuffers& picture, AtomicOutput& file)
{
  vtkSmartPointer<vtkImageData> image = PixelImage(picture.Width, picture.Height);
  vtkNew<vtkDoubleArray> depth;
  depth->SetName("depth");
  depth->SetNumberOfTuples(static_cast<vtkIdType>(picture.Width) * picture.Height);
  std::copy(picture.Depth->begin(), picture.Depth->end(), depth->GetPointer(0));
  image->GetPointData()->SetScalars(depth);
  if (picture.Normal && !picture.Normal->empty())
  {
    vtkNew<vtkFloatArray> normal;
    normal->SetName("normal");
    normal->SetNumberOfComponents(3);
    normal->SetNumberOfTuples(static_cast<vtkIdType>(picture.Width) * picture.Height);
    std::copy(picture.Normal->begin(), picture.Normal->end(), normal->GetPointer(0));
    image->GetPointData()->SetNormals(normal);
  }
  vtkNew<vtkXMLImageDataWriter> xml;
  xml->SetDataModeToAppended();
  xml->EncodeAppendedDataOff();
  WriteXml(xml.Get(), image, file);
  file.Commit();
}

bool FrameOutput::IsFilm(const std::string& output)
{
  return HasExtension(output, ".mp4");
}

FrameOutput::FrameOutput(const std::string& output, double framesPerSecond)
  : Output(output)
  , Film(IsFilm(output))
  , FramesPerSecond(framesPerSecond)
{
  std::error_code ec;
  if (this->Film)
  {
    if (FindProgram("ffmpeg").empty())
    {
      throw UserError("-o: writing an .mp4 film needs ffmpeg (the Debian package ffmpeg), which "
                      "is not on the PATH; write frames/%04d.png instead");
    }
    if (!(framesPerSecond > 0) || !std::isfinite(framesPerSecond))
    {
      throw UserError("--fps must be a positive number");
    }
    // The film's destination is checked now; its frames wait in a hidden folder beside it.
    AtomicOutput check(output);
    const fs::path folder = fs::absolute(output).parent_path();
    std::string staging =
      (folder / ("." + fs::path(output).stem().string() + ".frames-XXXXXX")).string();
    if (!::mkdtemp(staging.data()))
    {
      throw UserError("cannot write '" + output + "': " + std::strerror(errno));
    }
    this->StagingFolder = staging;
    return;
  }
  CheckPattern(output);
  const fs::path folder =
    fs::path(output).has_parent_path() ? fs::path(output).parent_path() : fs::path(".");
  if (!fs::is_directory(folder, ec))
  {
    const fs::path parent = fs::absolute(folder).parent_path();
    if (!fs::is_directory(parent, ec) || !fs::create_directory(folder, ec))
    {
      throw UserError("cannot write '" + output + "': folder '" + folder.string() +
        "' does not exist and cannot be made");
    }
    this->MadeFolder = folder.string();
  }
}

FrameOutput::~FrameOutput()
{
  this->Frames.clear(); // removes the temporary frames that were not committed
  std::error_code ec;
  if (!this->StagingFolder.empty())
  {
    fs::remove_all(this->StagingFolder, ec);
  }
  if (!this->Committed && !this->MadeFolder.empty())
  {
    fs::remove(this->MadeFolder, ec); // only when empty
  }
}

std::string FrameOutput::FrameName(std::size_t k) const
{
  const std::string pattern =
    this->Film ? (fs::path(this->StagingFolder) / "%06d.png").string() : this->Output;
  const int n = std::snprintf(nullptr, 0, pattern.c_str(), static_cast<int>(k));
  std::string name(static_cast<std::size_t>(std::max(n, 0)) + 1, '\0');
  std::snprintf(name.data(), name.size(), pattern.c_str(), static_cast<int>(k));
  name.resize(name.size() - 1);
  return name;
}

void FrameOutput::Write(std::size_t k, const PictureBuffers& picture)
{
  const std::string name = this->FrameName(k);
  if (this->Film)
  {
    Png(picture, name, name); // inside the staging folder, removed unless the film is made
    return;
  }
  auto file = std::make_unique<AtomicOutput>(name);
  Png(picture, file->Path(), name);
  this->Frames.push_back(std::move(file));
  this->Names.push_back(name);
}

std::string FrameOutput::Commit()
{
  if (this->Film)
  {
    AtomicOutput film(this->Output);
    std::ostringstream rate;
    rate.precision(17);
    rate << this->FramesPerSecond;
    // Even sides for yuv420p (which every player reads), padded with the background's white.
    const int status = RunProgram({ FindProgram("ffmpeg"), "-nostdin", "-y", "-loglevel", "error",
      "-framerate", rate.str(), "-i", (fs::path(this->StagingFolder) / "%06d.png").string(), "-vf",
      "pad=ceil(iw/2)*2:ceil(ih/2)*2:color=white", "-c:v", "libx264", "-pix_fmt", "yuv420p", "-f",
      "mp4", film.Path() });
    if (Interrupted())
    {
      throw Cancelled();
    }
    if (status != 0)
    {
      throw UserError("ffmpeg could not encode '" + this->Output + "' (exit status " +
        std::to_string(status) + ")");
    }
    film.Commit();
    this->Committed = true;
    return this->Output;
  }
  // Every frame is known complete before the first one replaces a file of the same name.
  for (auto& frame : this->Frames)
  {
    frame->Verify();
  }
  for (auto& frame : this->Frames)
  {
    frame->Commit();
  }
  this->Committed = true;
  if (this->Names.empty())
  {
    return {};
  }
  return this->Names.size() == 1 ? this->Names.front()
                                 : this->Names.front() + " .. " + this->Names.back();
}

} // namespace ictk::cli
