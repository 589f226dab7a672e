// SPDX-License-Identifier: BSD-3-Clause
// libFuzzer target for ICTK's own InVesalius project reader (Voxel/VolumeFile.h readInv3: gzip,
// tar, the main.plist property list, the raw scan). An input whose first byte is odd is the
// archive before compression (the rest, gzipped here, so that mutations reach the tar and plist
// readers rather than break the gzip checksum); an even first byte gives the rest as the file's
// bytes (the gzip layer itself). Any input must either read as a valid grid or raise
// std::runtime_error naming the file (std::invalid_argument for NaN or infinite values). Anything
// else escaping (another exception, a crash, a sanitizer report, a timeout or running out of
// memory) is a bug.
#include "Voxel/VolumeFile.h"

#include <unistd.h>
#include <zlib.h>

#include <cstddef>
#include <cstdint>
#include <fstream>
#include <stdexcept>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  if (size == 0)
  {
    return 0;
  }
  const std::string path = "/tmp/ictk-fuzz-" + std::to_string(::getpid()) + ".inv3";
  std::string bytes(reinterpret_cast<const char*>(data) + 1, size - 1);
  if (data[0] & 1)
  {
    // gzip's framing (windowBits 16 + 15), fastest level: the reader sees a well-formed stream.
    z_stream z{};
    if (deflateInit2(&z, 1, Z_DEFLATED, 16 + MAX_WBITS, 8, Z_DEFAULT_STRATEGY) != Z_OK)
    {
      return 0;
    }
    std::string packed(deflateBound(&z, static_cast<uLong>(bytes.size())), '\0');
    z.next_in = reinterpret_cast<Bytef*>(bytes.data());
    z.avail_in = static_cast<uInt>(bytes.size());
    z.next_out = reinterpret_cast<Bytef*>(packed.data());
    z.avail_out = static_cast<uInt>(packed.size());
    deflate(&z, Z_FINISH);
    packed.resize(z.total_out);
    deflateEnd(&z);
    bytes = std::move(packed);
  }
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  }
  try
  {
    (void)ictk::voxel::readInv3(path);
  }
  catch (const std::runtime_error&)
  {
  }
  catch (const std::invalid_argument&)
  {
    // validate()'s refusal of NaN or infinite values (VdbIO.h), which names the file too.
  }
  ::unlink(path.c_str());
  return 0;
}
