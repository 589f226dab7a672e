// SPDX-License-Identifier: BSD-3-Clause
// libFuzzer target: any input must either compile or raise ParseError. Anything else escaping
// (another exception, a crash, a sanitizer report, a timeout or running out of memory) is a bug.
#include "FuzzLimits.h"
#include "Lang/HyperFun.h"

#include <cstddef>
#include <cstdint>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  const ictk::lang::Limits limits = hyperFunFuzzLimits();
  const std::string text(reinterpret_cast<const char*>(data), size);
  try
  {
    const auto model = ictk::lang::readHyperFun(text, "fuzz.hf", {}, limits);
    (void)model.model.compile();
  }
  catch (const ictk::lang::ParseError&)
  {
  }
  return 0;
}
