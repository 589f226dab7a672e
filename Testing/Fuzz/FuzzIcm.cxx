// SPDX-License-Identifier: BSD-3-Clause
// libFuzzer target: any input must either give a model or raise ParseError, in both the model
// language and the thesis' notation mode. Anything else escaping (another exception, a crash, a
// sanitizer report, a timeout or running out of memory) is a bug.
#include "Lang/Icm.h"

#include <cstddef>
#include <cstdint>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  ictk::lang::Limits limits;
  // Small budgets keep every run fast; the limits themselves are what is being exercised.
  limits.maxSyntaxNodes = 100000;
  limits.maxNesting = 100;
  const std::string text(reinterpret_cast<const char*>(data), size);
  try
  {
    (void)ictk::lang::readIcm(text, "fuzz.icm", limits);
  }
  catch (const ictk::lang::ParseError&)
  {
  }
  try
  {
    (void)ictk::lang::parseIcmNotation(text, "fuzz.icm", limits);
  }
  catch (const ictk::lang::ParseError&)
  {
  }
  return 0;
}
