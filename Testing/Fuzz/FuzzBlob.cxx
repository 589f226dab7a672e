// SPDX-License-Identifier: BSD-3-Clause
// libFuzzer target for the .blob BlobTree format: any input must either read, instantiate, lower
// and evaluate at a point (both the tree traversal and the compiled tape), or raise ParseError.
// Anything else escaping (another exception, a crash, a sanitizer report, a timeout or running
// out of memory) is a bug.
#include "FRep/BlobTree.h"
#include "FRep/Evaluators.h"
#include "FRep/Tape.h"
#include "Lang/BlobReader.h"

#include <cstddef>
#include <cstdint>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  ictk::lang::Limits limits;
  // Small, so that every run is fast: the bundled T-Rex (1,848 elements) is refused here.
  limits.maxExpressionNodes = 20000;
  limits.maxSyntaxNodes = 20000;
  const std::string text(reinterpret_cast<const char*>(data), size);
  try
  {
    const ictk::frep::blob::BlobTree generic = ictk::lang::readBlob(text, "fuzz.blob", limits);
    const ictk::frep::blob::BlobTree tree = generic.instantiate(0.5);
    (void)ictk::frep::blob::evaluate(tree, { 0.25, -0.5, 0.75 });
    (void)ictk::frep::blob::supportBox(tree);
    ictk::frep::PointEvaluator evaluator(
      ictk::frep::Tape::compile(ictk::frep::blob::shape(tree).function()));
    (void)evaluator.eval(0.25, -0.5, 0.75, 0);
  }
  catch (const ictk::lang::ParseError&)
  {
  }
  return 0;
}
