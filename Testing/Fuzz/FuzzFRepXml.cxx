// SPDX-License-Identifier: BSD-3-Clause
// libFuzzer target for the FRep XML reader: any input must either read or raise ParseError (no
// crash, hang, other exception or sanitizer report). What reads must also write and read back.
#include "Lang/FRepXml.h"

#include <cstddef>
#include <cstdint>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  const std::string text(reinterpret_cast<const char*>(data), size);
  ictk::lang::Limits limits;
  // Small limits keep each run fast; the limits themselves are part of what is tested.
  limits.maxFileBytes = 1u << 16;
  limits.maxExpressionNodes = 20000;
  try
  {
    const ictk::frep::Hypervolume hv = ictk::lang::readFRepXml(text, "fuzz.xml", limits);
    std::string written;
    try
    {
      written = ictk::lang::writeFRepXml(hv, "fuzz");
    }
    catch (const std::invalid_argument&)
    {
      // An attribute name with a control character (read from a character reference) cannot be
      // written back as XML 1.0.
      return 0;
    }
    const ictk::frep::Hypervolume back = ictk::lang::readFRepXml(written, "written.xml");
    if (ictk::lang::writeFRepXml(back, "fuzz") != written)
    {
      __builtin_trap();
    }
  }
  catch (const ictk::lang::ParseError&)
  {
  }
  return 0;
}
