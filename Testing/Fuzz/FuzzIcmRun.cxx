// SPDX-License-Identifier: BSD-3-Clause
// Fuzz target for the engine: any input that reads as a model must either build and run for a
// few frames or raise ModelError (with its place). Anything else escaping (another exception, a
// crash, a sanitizer report, a hang) is a bug. The replay test runs it on the corpus and on
// Data/Models/icm.
#include "Engine/DynamicModel.h"
#include "Lang/Icm.h"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  ictk::lang::Limits limits;
  limits.maxSyntaxNodes = 100000;
  limits.maxNesting = 100;
  const std::string text(reinterpret_cast<const char*>(data), size);
  ictk::lang::IcmModel model;
  try
  {
    model = ictk::lang::readIcm(text, "fuzz.icm", limits);
  }
  catch (const ictk::lang::ParseError&)
  {
    return 0;
  }
  try
  {
    ictk::engine::DynamicModel m(std::move(model));
    const double start = m.timeRange().first;
    // A short run: the first frames, with the instance search, the queries and the events.
    m.advanceTo(start + 1.0, 0.25);
    (void)m.complex();
  }
  catch (const ictk::engine::ModelError&)
  {
  }
  return 0;
}
