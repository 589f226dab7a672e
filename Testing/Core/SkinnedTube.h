// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The skinned tube of the Skin tests (TestSkin.cxx, TestProjection.cxx): small enough to work out
// by hand.

#include "Skin/SkinnedMesh.h"

#include <cmath>

namespace ictk::skin::fixtures
{

/// An open tube of radius 0.3 around the z axis for |z| <= 0.6 (`sides` x `rings` vertices, no
/// normals in the file), every vertex on the hip joint; the bone goes from the hip (0, 0, -1.5) to
/// the knee (0, 0, 1.5), and the joints' offsets are the translations that bring their markers to
/// the origin.
inline SkinnedMesh skinnedTube(int sides, int rings)
{
  const double pi = std::acos(-1.0);
  SkinnedMesh m;
  m.file = "tube";
  Affine hip, knee, toHip, toKnee;
  hip.b = { 0, 0, -1.5 };
  knee.b = { 0, 0, 3 };
  toHip.b = { 0, 0, 1.5 };
  toKnee.b = { 0, 0, -1.5 };
  m.nodes = { { "root", -1, {} }, { "hip", 0, hip }, { "knee", 1, knee } };
  m.joints = { { 1, toHip }, { 2, toKnee } };
  for (int k = 0; k < rings; ++k)
  {
    for (int i = 0; i < sides; ++i)
    {
      const double a = 2 * pi * i / sides;
      m.restPoints.push_back(
        { 0.3 * std::cos(a), 0.3 * std::sin(a), -0.6 + 1.2 * k / (rings - 1) });
      m.influences.push_back({ 0, 1.0 });
      m.influenceStart.push_back(m.influences.size());
    }
  }
  for (int k = 0; k + 1 < rings; ++k)
  {
    for (int i = 0; i < sides; ++i)
    {
      const int p = k * sides + i, q = k * sides + (i + 1) % sides;
      m.triangles.push_back({ p, q, q + sides });
      m.triangles.push_back({ p, q + sides, p + sides });
    }
  }
  m.validate();
  return m;
}

} // namespace ictk::skin::fixtures
