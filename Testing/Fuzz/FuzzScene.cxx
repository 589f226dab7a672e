// SPDX-License-Identifier: BSD-3-Clause
// libFuzzer target for the .scn scene language (Lang/Scene.h): any input must either read, build
// into a hypervolume, write back as a scene that reads and builds to the same field at a point,
// and evaluate with its attributes, or raise ParseError. `object` references are refused (no
// loader): the target reads no file. Anything else escaping (another exception, a crash, a
// sanitizer report, a timeout or running out of memory) is a bug.
#include "FRep/Evaluators.h"
#include "FRep/Tape.h"
#include "Lang/Scene.h"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  ictk::lang::Limits limits;
  limits.maxSyntaxNodes = 2000;
  limits.maxNesting = 50;
  const std::string text(reinterpret_cast<const char*>(data), size);
  try
  {
    const ictk::lang::Scene scene = ictk::lang::parseScene(text, "fuzz.scn", nullptr, limits);
    const ictk::lang::BuiltScene built = ictk::lang::buildScene(scene);
    ictk::frep::HypervolumeEvaluator evaluator(built.model);
    std::vector<double> attributes(built.model.attributeComponentCount());
    double f = 0;
    evaluator.eval({ 0.25, -0.5, 0.75, 0 }, f, attributes.data());
    // The written scene is the same scene.
    const std::string written = ictk::lang::writeScene(scene);
    const ictk::lang::BuiltScene again =
      ictk::lang::buildScene(ictk::lang::parseScene(written, "written.scn", nullptr, limits));
    ictk::frep::HypervolumeEvaluator second(again.model);
    double g = 0;
    second.eval({ 0.25, -0.5, 0.75, 0 }, g, attributes.data());
    if (!(f == g || (std::isnan(f) && std::isnan(g))))
    {
      std::abort();
    }
  }
  catch (const ictk::lang::ParseError&)
  {
  }
  return 0;
}
