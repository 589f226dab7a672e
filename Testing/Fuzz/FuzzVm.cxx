// SPDX-License-Identifier: BSD-3-Clause
// libFuzzer target for Fidget's .vm format: any input must either read, compile and evaluate at a
// point, or raise ParseError. Anything else escaping (another exception, a crash, a sanitizer
// report, a timeout or running out of memory) is a bug.
#include "FRep/Evaluators.h"
#include "FRep/Tape.h"
#include "Lang/VmReader.h"

#include <cstddef>
#include <cstdint>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  ictk::lang::Limits limits;
  limits.maxExpressionNodes = 200000;
  const std::string text(reinterpret_cast<const char*>(data), size);
  try
  {
    const ictk::lang::VmModel model = ictk::lang::readVm(text, "fuzz.vm", limits);
    ictk::frep::PointEvaluator evaluator(ictk::frep::Tape::compile(model.function));
    (void)evaluator.eval(0.25, -0.5, 0.75, 0);
  }
  catch (const ictk::lang::ParseError&)
  {
  }
  return 0;
}
