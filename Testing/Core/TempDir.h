// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// A fresh folder under the system's temporary folder for a test's files, removed at the end of
// the test (shared by the voxel and scan tests).

#include <unistd.h>

#include <filesystem>
#include <string>

namespace ictk::test_support
{

class TempDir
{
public:
  TempDir()
  {
    static int counter = 0;
    path_ = std::filesystem::temp_directory_path() /
      ("ictk-voxel-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
    std::filesystem::create_directories(path_);
  }
  ~TempDir()
  {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  std::string file(const std::string& name) const { return (path_ / name).string(); }
  const std::filesystem::path& path() const { return path_; }

private:
  std::filesystem::path path_;
};

} // namespace ictk::test_support
