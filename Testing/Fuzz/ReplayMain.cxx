// SPDX-License-Identifier: BSD-3-Clause
// Runs a fuzz target's LLVMFuzzerTestOneInput on every file of the folders given, without
// libFuzzer: the corpus (and every crash a fuzzing campaign finds, once added to it) becomes a
// regression test in the ordinary build.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

int main(int argc, char** argv)
{
  std::size_t count = 0;
  for (int i = 1; i < argc; ++i)
  {
    for (const auto& entry : std::filesystem::directory_iterator(argv[i]))
    {
      if (!entry.is_regular_file())
      {
        continue;
      }
      std::ifstream in(entry.path(), std::ios::binary);
      const std::vector<char> bytes(
        (std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
      LLVMFuzzerTestOneInput(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
      ++count;
    }
  }
  std::cout << "replayed " << count << " input(s)\n";
  return count > 0 ? 0 : 1;
}
