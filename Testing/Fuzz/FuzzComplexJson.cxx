// SPDX-License-Identifier: BSD-3-Clause
// libFuzzer target for complex JSON files (docs/complex-json.md), read by the core alone (no VTK
// readers: a cell's "file" is refused, or read as .vdb): any input must either read as a complex
// or raise ParseError. Anything else escaping (another exception, a crash, a sanitizer report, a
// timeout or running out of memory) is a bug.
#include "FuzzLimits.h"
#include "Lang/ComplexFile.h"

#include <cstddef>
#include <cstdint>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  const ictk::lang::Limits limits = hyperFunFuzzLimits();
  const std::string text(reinterpret_cast<const char*>(data), size);
  try
  {
    (void)ictk::lang::readComplexJson(text, "fuzz.json", limits);
  }
  catch (const ictk::lang::ParseError&)
  {
  }
  return 0;
}
