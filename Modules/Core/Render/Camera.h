// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The camera of a picture: where the eye is, where it looks and how pixels map to rays, for the
// ray caster (RayCast.h) and for whatever composites into its depth buffer later. It orbits the
// centre of a box (the model's bounds), so that `--view azimuth,elevation,distance` means the
// same thing for every model:
//   * azimuth: degrees about +z, measured from +x towards +y;
//   * elevation: degrees above the xy-plane (90 looks straight down);
//   * distance: from the box's centre to the eye, in model units (default 2.5 times the box's
//     half-diagonal).
// Up is +z, or +y when the eye looks (nearly) straight down or up. A perspective camera has a
// vertical field of view of 30 degrees; an orthographic one sees a height of 2.2 times the
// half-diagonal (the box's bounding sphere with a margin), whatever the distance. Pixels are
// square.
//
// Pixel (i, j) is centred at image-plane coordinates u(i), v(j); row j = 0 is the bottom of the
// picture (VTK's image order). The ray of (u, v) is p(s) = origin(u, v) + s direction(u, v),
// where s is the depth along the viewing axis (direction has a unit component along forward), so
// a piece of the view between two depths is a convex box or frustum whose corners bound it. The
// distance along the ray is s |direction|.

#include "FRep/Field.h"
#include "FRep/Vector.h"

namespace ictk::render
{

enum class Projection
{
  Perspective,
  Orthographic
};

/// Where the camera is, about the centre of a box (see the file comment).
struct View
{
  double azimuth = 30;   ///< degrees about +z from +x
  double elevation = 20; ///< degrees above the xy-plane
  double distance = 0;   ///< from the box's centre; 0: 2.5 times the box's half-diagonal
};

/// The largest image side, in pixels.
constexpr int MaxImageSize = 4096;
/// The vertical field of view of a perspective camera, in degrees.
constexpr double PerspectiveFieldOfView = 30;
/// The default distance and the orthographic height, in half-diagonals of the box.
constexpr double DefaultDistance = 2.5;
constexpr double OrthographicHeight = 2.2;

class Camera
{
public:
  /// A camera looking at the centre of `box` from `view`, for a width x height image. Throws
  /// std::invalid_argument on a size outside 1..MaxImageSize, a non-finite or negative view
  /// value, an invalid or flat (all sides 0) box.
  static Camera orbit(
    const frep::Box3& box, const View& view, Projection projection, int width, int height);

  /// A camera at `position` looking at `focalPoint`, `up` pointing up on the picture (made
  /// orthogonal to the view direction), VTK's conventions: perspective with a vertical
  /// `viewAngle` in degrees (0 < viewAngle < 180), or orthographic showing a height of twice
  /// `parallelScale`. Throws std::invalid_argument on a size outside 1..MaxImageSize, values
  /// that are not finite, a position at the focal point, an up along the view direction, or an
  /// angle or scale out of range.
  static Camera lookAt(const frep::Point3& position, const frep::Point3& focalPoint,
    const frep::Point3& up, Projection projection, double viewAngle, double parallelScale,
    int width, int height);

  int width() const { return width_; }
  int height() const { return height_; }
  Projection projection() const { return projection_; }
  const frep::Point3& eye() const { return eye_; }
  const frep::Point3& forward() const { return forward_; }
  const frep::Point3& right() const { return right_; }
  const frep::Point3& up() const { return up_; }
  /// The vertical field of view of a perspective camera, in degrees.
  double viewAngle() const;
  /// The side of a pixel on the image plane: at depth s = 1 (perspective) or in model units
  /// (orthographic). At depth s a perspective pixel covers pixelSize() * s.
  double pixelSize() const { return pixelSize_; }

  /// Image-plane coordinates of the centre of column i and of row j.
  double u(double i) const { return (i + 0.5 - 0.5 * width_) * pixelSize_; }
  double v(double j) const { return (j + 0.5 - 0.5 * height_) * pixelSize_; }
  /// The ray of the image-plane point (u, v): p(s) = origin + s direction.
  frep::Point3 origin(double u, double v) const;
  frep::Point3 direction(double u, double v) const;
  /// The point at depth s on the ray of (u, v).
  frep::Point3 point(double u, double v, double s) const;

private:
  int width_ = 1;
  int height_ = 1;
  Projection projection_ = Projection::Perspective;
  frep::Point3 eye_{};
  frep::Point3 forward_{};
  frep::Point3 right_{};
  frep::Point3 up_{};
  double pixelSize_ = 1;
};

} // namespace ictk::render
