// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Writing files that survive a full disk (issue 19), shared by `ictk`'s single outputs
// (Applications/ictk/Output.h) and the frames of ictkTimeSeriesWriter. VTK's XML writers can
// crash when their stream fails mid-file, so a single XML file is made in memory and written
// here with every write checked; the pieces of a composite file, which VTK's composite writers
// write themselves, are first checked to fit. Not wrapped, not installed: part of
// ICTK::VTKRequest.

#include "vtkDataObject.h"
#include "vtkDataObjectTree.h"
#include "vtkDataObjectTreeIterator.h"
#include "vtkSmartPointer.h"

#include <fcntl.h>
#include <sys/resource.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>

namespace ictk::vtk
{

/// Writes `bytes` as the whole file `path` (created or truncated) and flushes it to the disk,
/// checking every step; throws std::runtime_error whose message is the system's reason ("File
/// too large" past `ulimit -f`, "No space left on device").
inline void writeWholeFile(const std::string& path, const std::string& bytes)
{
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd < 0)
  {
    throw std::runtime_error(std::strerror(errno));
  }
  std::size_t done = 0;
  while (done < bytes.size())
  {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR)
    {
      continue;
    }
    if (n <= 0)
    {
      const int error = n < 0 ? errno : ENOSPC;
      ::close(fd);
      throw std::runtime_error(std::strerror(error));
    }
    done += static_cast<std::size_t>(n);
  }
  // A disk that fills may only say so when the data is flushed.
  if (::fsync(fd) != 0)
  {
    const int error = errno;
    ::close(fd);
    throw std::runtime_error(std::strerror(error));
  }
  if (::close(fd) != 0)
  {
    throw std::runtime_error(std::strerror(errno));
  }
}

/// Why the pieces of `data` (a composite dataset, or one dataset) may not fit as files in
/// `folder`, or "" when they may: each piece's size in memory bounds its compressed file, the
/// largest against the file size limit (ulimit -f), their sum against the disk's free space.
inline std::string piecesDoNotFit(vtkDataObject* data, const std::string& folder)
{
  std::uint64_t total = 0;
  std::uint64_t largest = 0;
  auto add = [&](vtkDataObject* piece)
  {
    const std::uint64_t bytes =
      piece ? static_cast<std::uint64_t>(piece->GetActualMemorySize()) * 1024 : 0;
    total += bytes;
    largest = std::max(largest, bytes);
  };
  if (auto* tree = vtkDataObjectTree::SafeDownCast(data))
  {
    vtkSmartPointer<vtkDataObjectTreeIterator> it;
    it.TakeReference(tree->NewTreeIterator());
    for (it->InitTraversal(); !it->IsDoneWithTraversal(); it->GoToNextItem())
    {
      add(it->GetCurrentDataObject());
    }
  }
  else
  {
    add(data);
  }
  struct rlimit limit
  {};
  if (::getrlimit(RLIMIT_FSIZE, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY &&
    largest > limit.rlim_cur)
  {
    return "a piece may need up to " + std::to_string(largest) +
      " bytes, over the file size limit (ulimit -f) of " + std::to_string(limit.rlim_cur) +
      " bytes";
  }
  auto megabytes = [](std::uint64_t bytes)
  {
    return std::to_string((bytes + (1u << 20) - 1) >> 20) + " MB";
  };
  struct statvfs disk
  {};
  if (::statvfs(folder.c_str(), &disk) == 0)
  {
    const std::uint64_t free = static_cast<std::uint64_t>(disk.f_bavail) * disk.f_frsize;
    if (total > free)
    {
      return "its pieces may need up to " + megabytes(total) + " and the disk has " +
        megabytes(free) + " free";
    }
  }
  return {};
}

} // namespace ictk::vtk
