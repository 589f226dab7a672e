// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The common z-buffer of a picture (seed 001, papers.md 1.9: explicit and implicit cells "combined
// using a common Z-buffer"): every renderer of the library writes into one Canvas, the ray caster
// of FRep and voxel solids (RayCast.h) and the exact rasteriser of triangles, tubes and spheres
// (Rasterize.h), and a surface is kept at a pixel only when it is nearer than what is there. So
// the cells of a complex, drawn one after another in any order, give the picture a single pass
// over all of them would.
//
// A surface brings its depth (the distance along the pixel's ray, Camera.h), the light it gets
// (Lambert with an ambient term, lit by a headlight: headlight()) and its paint: an RGB colour
// (an attribute of 3 components in [0, 1], such as the flower's colours) or the value of a scalar
// attribute (the walnut's material), which a colour map turns into a colour once every surface
// is in, over the range of the values seen or a given one.

#include "FRep/Vector.h"
#include "Render/Camera.h"

#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace ictk::render
{

/// The colour of a surface with no colour of its own (or an undefined scalar).
constexpr double NeutralGrey = 0.8;

/// What a surface shows at a point, before shading.
struct Paint
{
  std::array<double, 3> rgb{ NeutralGrey, NeutralGrey, NeutralGrey };
  /// The scalar attribute's value (NaN: undefined here, drawn in neutral grey).
  double scalar = std::numeric_limits<double>::quiet_NaN();
};

/// The light a surface gets from a headlight: 0.25 + 0.75 |cos|, the cosine between the outward
/// normal -gradient / |gradient| and the ray's `direction` (of length `length`); a gradient that
/// is zero or not finite (a flat spot, a cut) is lit as if facing the eye.
double headlight(const frep::Point3& gradient, const frep::Point3& direction, double length);

/// A colour map: piecewise linear in RGB between a few named points.
class ColourMap
{
public:
  /// "cool-warm" (blue, light grey, red: the default), "rainbow" (blue, cyan, green, yellow,
  /// red) or "grey" (dark to light). Throws std::invalid_argument naming the known maps.
  static ColourMap named(const std::string& name);
  static const std::vector<std::string>& names();
  /// The colour at t in [0, 1] (clamped; NaN gives neutral grey).
  std::array<double, 3> at(double t) const;

private:
  std::vector<std::array<double, 4>> points_; // t, r, g, b
};

/// How surfaces are coloured.
struct ColourOptions
{
  /// The attribute that colours them: 3 (or 4) components are a colour in [0, 1], 1 a scalar
  /// drawn through `map`. Empty: the attribute named "colour" (or "color") when there is one,
  /// else neutral grey.
  std::string attribute;
  /// The colour map of a scalar (ColourMap::named).
  std::string map = "cool-warm";
  /// The scalar values at its ends; NaN: the smallest and largest value in the picture.
  std::array<double, 2> range{ std::numeric_limits<double>::quiet_NaN(),
    std::numeric_limits<double>::quiet_NaN() };
};

/// The buffers of a picture, pixel (i, j) at index j * width + i, row 0 at the bottom (VTK's
/// order).
struct Canvas
{
  enum class Colouring
  {
    Rgb,   ///< paints are colours, shaded as they come
    Scalar ///< paints are scalars, coloured by applyColourMap() at the end
  };

  Canvas() = default;
  /// An empty picture: background transparent white (255, 255, 255, 0), depth +infinity.
  Canvas(int width, int height, Colouring colouring = Colouring::Rgb);

  int width = 0;
  int height = 0;
  Colouring colouring = Colouring::Rgb;
  /// Distance along each pixel's ray from the eye (perspective) or image plane (orthographic) to
  /// the nearest surface; +infinity where there is none.
  std::vector<double> depth;
  /// RGBA, 8 bits each.
  std::vector<std::uint8_t> colour;
  /// Who drew each pixel (a cell id, or 0 for a lone model); -1: background.
  std::vector<std::int32_t> owner;
  /// The unit normal of the surface at each pixel, in model coordinates, turned to face the
  /// camera (3 values a pixel; 0, 0, 0 for the background or a surface with no normal there):
  /// seed 003's normal buffer (papers.md 5.B item 37).
  std::vector<float> normal;
  /// Colouring by a scalar: its value and the light per pixel.
  std::vector<float> scalar;
  std::vector<float> light;

  std::size_t index(int i, int j) const
  {
    return static_cast<std::size_t>(j) * static_cast<std::size_t>(width) +
      static_cast<std::size_t>(i);
  }
  /// Whether the buffers are those of `camera`'s picture: its width and height, each buffer of
  /// that many pixels (seed 003's IsValidFor). Every renderer checks it before writing.
  bool isValidFor(const Camera& camera) const;
  /// Records a surface at pixel `index` when it is nearer than what is there (ties keep the
  /// first); returns whether it was recorded. `normal` is the surface's normal (any length and
  /// side; zero or not finite when it has none), `direction` the pixel's ray, which it is turned
  /// against. Pixels are written by one thread each.
  bool put(std::size_t index, double depth, double light, const Paint& paint, std::int32_t owner,
    const frep::Point3& normal, const frep::Point3& direction);
  /// The pixels covered by a surface.
  std::int64_t covered() const;
  /// The smallest and largest scalar of the covered pixels (NaN, NaN when there is none).
  std::pair<double, double> scalarRange() const;
  /// Colouring by a scalar: every covered pixel's colour from `map` over [lo, hi] (lo == hi:
  /// the middle of the map), shaded by its light; undefined values are neutral grey.
  void applyColourMap(const ColourMap& map, double lo, double hi);
};

/// A depth buffer (distances along the pixels' rays, as Canvas::depth) in OpenGL's convention
/// (seed 003 item 37): window depth in [0, 1], less is nearer, for near and far planes at depths
/// `near` and `far` along the camera's viewing axis. With z a surface's depth along that axis,
/// a perspective camera gives far (z - near) / (z (far - near)) (0 < near < far), an orthographic
/// one (z - near) / (far - near) (near < far); the background is 1 (the cleared buffer), and a
/// surface in front of near or behind far is clamped to 0 or 1 (OpenGL's depth clamping).
/// Throws std::invalid_argument for planes out of range or a buffer not of the camera's size.
std::vector<double> windowDepth(
  const std::vector<double>& depth, const Camera& camera, double near, double far);
/// The inverse of windowDepth: distances along the pixels' rays from OpenGL window depths (a
/// z-buffer read back from VTK or OpenGL with the same planes); +infinity where the window depth
/// is 1 or more (the cleared buffer). Throws as windowDepth.
std::vector<double> depthFromWindow(
  const std::vector<double>& window, const Camera& camera, double near, double far);

/// Colours a picture coloured by a scalar with the options' map over their range (its NaN ends
/// from the values seen; [0, 1] when none is seen) and returns that range. Throws
/// std::invalid_argument for an unknown map or a range whose low end is above its high end.
std::array<double, 2> finishColours(Canvas& canvas, const ColourOptions& colours);

} // namespace ictk::render
