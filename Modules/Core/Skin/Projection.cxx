// SPDX-License-Identifier: BSD-3-Clause
#include "Skin/Projection.h"

#include "FRep/Field.h"
#include "FRep/Tape.h"

#include <algorithm>
#include <cmath>

namespace ictk::skin
{

Projection projectOntoStandIn(
  const SkinnedMesh& mesh, const StandIn& standIn, const ProjectionOptions& options)
{
  const auto field =
    frep::tapeField(frep::Tape::compile(standInShape(standIn).function()), 0.0, {});
  const auto evaluator = field->evaluator();
  Projection out;
  out.offsets.resize(mesh.vertexCount());
  for (std::size_t i = 0; i < mesh.vertexCount(); ++i)
  {
    Vec3 p = mesh.restPoints[i];
    Vec3 g{ 0, 0, 0 };
    double f = evaluator->gradient(p, g);
    int it = 0;
    for (; it < options.maxIterations && !(std::abs(f) < options.epsilon); ++it)
    {
      const double g2 = frep::dot(g, g);
      if (!(g2 > 0) || !std::isfinite(f))
        break;
      Vec3 step = frep::scale(g, -f / g2);
      // Halve the step while it does not bring F nearer 0 (far from the surface F is flat).
      bool better = false;
      for (int h = 0; h < 60 && !better; ++h, step = frep::scale(step, 0.5))
      {
        Vec3 gq{ 0, 0, 0 };
        const Vec3 q = frep::add(p, step);
        const double fq = evaluator->gradient(q, gq);
        if (std::abs(fq) < std::abs(f))
        {
          p = q;
          f = fq;
          g = gq;
          better = true;
        }
      }
      if (!better)
        break;
    }
    out.offsets[i] = frep::sub(p, mesh.restPoints[i]);
    out.iterations = std::max(out.iterations, it);
    out.maxResidual = std::max(out.maxResidual, std::abs(f));
    if (!(std::abs(f) < options.epsilon))
      ++out.failures;
  }
  return out;
}

std::vector<Vec3> projectedRestPoints(
  const SkinnedMesh& mesh, const Projection& projection, double alpha)
{
  const double a = std::clamp(alpha, 0.0, 1.0);
  std::vector<Vec3> out(mesh.restPoints);
  for (std::size_t i = 0; i < out.size(); ++i)
    out[i] = frep::add(out[i], frep::scale(projection.offsets[i], a));
  return out;
}

} // namespace ictk::skin
