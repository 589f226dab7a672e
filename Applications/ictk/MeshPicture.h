// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// `ictk render --mode mesh`: the polygonal scene of a complex (every cell from its discretisation:
// triangles, curves through vtkTubeFilter, points as sphere glyphs; Render/ComplexRender.h's
// scenePrimitives) drawn by VTK's OpenGL pipeline offscreen, with the core's camera, and read back
// as the core's buffers: colours, and depths turned from the z-buffer into distances along each
// pixel's ray, so that the two modes can be compared pixel by pixel. It needs an X display (an
// Xvfb where there is none: xvfb-run).

#include "Render/Camera.h"
#include "Render/Canvas.h"
#include "Render/ComplexRender.h"

#include <array>

namespace ictk::cli
{

/// Throws UserError when there is no X display to render with.
void CheckMeshDisplay();

/// The values at the colour map's ends when the scene is painted by a scalar: --range's, or the
/// range of the scene's paints (not only of those in view, unlike the ray caster's).
std::array<double, 2> MeshColourRange(
  const render::ScenePrimitives& scene, const render::ColourOptions& colours);

/// Draws the scene (CheckMeshDisplay first).
render::Canvas DrawMeshes(const render::ScenePrimitives& scene, const render::Camera& camera,
  const render::ColourOptions& colours);

} // namespace ictk::cli
