// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The projection of a skinned mesh onto its implicit stand-in (issue 17; thesis 5.5, L3409-3422):
// the first and last steps of a controlled metamorphosis between animated meshes. Every vertex
// gets an offset dp_i in the bind pose that takes it onto the stand-in's surface, and the mesh is
// then posed by skinning the moved vertices, p'_i(t) = sum_j w_ij M_j(t) f_alpha(p_i, p_i + dp_i)
// (SkinnedMesh.h's skin with other rest points), with f_alpha the straight line
// (1 - alpha) p_i + alpha (p_i + dp_i): at alpha = 1 the mesh lies on the stand-in, and the model
// can switch from the mesh (B-cell) to the stand-in (F-cell) without a jump; the way back is the
// same with alpha falling to 0. Normals are skinned by the inverse transpose as always (thesis'
// g_alpha is not used: the moved mesh's own normals are the stand-in's at alpha = 1 only as far as
// its triangles follow the surface).
//
// The projection is Newton's along the gradient, p <- p - F(p) grad F / |grad F|^2, each step
// halved while it does not lower |F|, until |F| < epsilon (the stand-in's F is dimensionless: 0 on
// the surface, -1 far away).

#include "Skin/StandIn.h"

#include <vector>

namespace ictk::skin
{

struct ProjectionOptions
{
  double epsilon = 1e-9; ///< |F| below which a vertex is on the stand-in
  int maxIterations = 100;
};

struct Projection
{
  std::vector<Vec3> offsets; ///< dp_i, in the bind pose
  double maxResidual = 0;    ///< max |F(p_i + dp_i)|
  int iterations = 0;        ///< the most any vertex took
  int failures = 0;          ///< vertices left with |F| >= epsilon
};

/// Projects the rest mesh's vertices onto `standIn` (in the rest frame).
Projection projectOntoStandIn(
  const SkinnedMesh& mesh, const StandIn& standIn, const ProjectionOptions& options = {});

/// The rest points moved a fraction alpha (clamped to [0, 1]) of the way to their projections.
std::vector<Vec3> projectedRestPoints(
  const SkinnedMesh& mesh, const Projection& projection, double alpha);

} // namespace ictk::skin
