// SPDX-License-Identifier: BSD-3-Clause
// libFuzzer target for the .blob BlobTree format: any input must either read, instantiate, lower
// and evaluate at a point (both the tree traversal and the compiled tape, the field and the
// TextureTree's material), and write back to a text that reads to the same field, or raise
// ParseError. Anything else escaping (another exception, a crash, a sanitizer report, a timeout,
// running out of memory, or a written tree that differs) is a bug.
#include "FRep/BlobTree.h"
#include "FRep/Evaluators.h"
#include "FRep/Tape.h"
#include "Lang/BlobReader.h"

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
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
    ictk::lang::BlobOrigins origins;
    const ictk::frep::blob::BlobTree generic =
      ictk::lang::readBlob(text, "fuzz.blob", limits, &origins);
    // A value out of its range at t = 0.5 is a ParseError at its node.
    const ictk::frep::blob::BlobTree tree = ictk::lang::instantiateBlob(generic, origins, 0.5);
    (void)ictk::frep::blob::evaluate(tree, { 0.25, -0.5, 0.75 });
    (void)ictk::frep::blob::supportBox(tree);
    ictk::frep::PointEvaluator evaluator(
      ictk::frep::Tape::compile(ictk::frep::blob::shape(tree).function()));
    (void)evaluator.eval(0.25, -0.5, 0.75, 0);
    std::array<double, ictk::frep::blob::MaterialSize> phi{};
    const double g = ictk::frep::blob::evaluateTextured(tree, { 0.25, -0.5, 0.75 }, phi);
    ictk::frep::PointEvaluator colour(
      ictk::frep::Tape::compile(ictk::frep::blob::material(tree)[0]));
    (void)colour.eval(0.25, -0.5, 0.75, 0);
    // The writer's text reads back to the same tree (angles through degrees: an ulp apart).
    const ictk::frep::blob::BlobTree again =
      ictk::lang::readBlob(ictk::lang::writeBlob(generic), "written.blob", limits);
    const double h = ictk::frep::blob::evaluate(again.instantiate(0.5), { 0.25, -0.5, 0.75 });
    if (again.nodes().size() != generic.nodes().size() ||
      !(std::fabs(h - g) <= 1e-9 * (1 + std::fabs(g)) || (std::isnan(h) && std::isnan(g))))
    {
      std::fprintf(stderr, "written tree differs: %.17g against %.17g\n", h, g);
      std::abort();
    }
  }
  catch (const ictk::lang::ParseError&)
  {
  }
  return 0;
}
