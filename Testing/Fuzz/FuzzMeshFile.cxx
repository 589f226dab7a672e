// SPDX-License-Identifier: BSD-3-Clause
// libFuzzer target for ICTK's own mesh file reader (Lang/MeshFile.h: the .obj and .off files of
// an .icm B-cell's `file(...)`): the input, written to a file (.off when it starts with 'O',
// .obj otherwise), must either read as a triangle surface whose every index is in range, or
// raise ParseError. Anything else escaping (another exception, a crash, a sanitizer report, a
// timeout or running out of memory) is a bug.
#include "Lang/Diagnostics.h"
#include "Lang/MeshFile.h"

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <string>

namespace
{
/// This process's scratch file of the given extension (readMeshFile reads a path).
std::string scratch(const char* extension)
{
  return "/tmp/ictk-fuzz-mesh-" + std::to_string(::getpid()) + extension;
}
} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  const std::string path = scratch(size > 0 && data[0] == 'O' ? ".off" : ".obj");
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  try
  {
    const ictk::complex::ExplicitGeometry mesh = ictk::lang::readMeshFile(path);
    for (const auto& t : mesh.triangles)
    {
      for (std::uint32_t corner : t)
      {
        if (corner >= mesh.points.size())
        {
          std::abort(); // a triangle outside the points the reader returned
        }
      }
    }
  }
  catch (const ictk::lang::ParseError&)
  {
  }
  ::unlink(path.c_str());
  return 0;
}
