// SPDX-License-Identifier: BSD-3-Clause
#include "Render/Camera.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace ictk::render
{

using frep::add;
using frep::cross;
using frep::norm;
using frep::Point3;
using frep::scale;
using frep::sub;

namespace
{
constexpr double Pi = 3.14159265358979323846;

Point3 unit(const Point3& a)
{
  return scale(a, 1 / norm(a));
}
} // namespace

Camera Camera::orbit(
  const frep::Box3& box, const View& view, Projection projection, int width, int height)
{
  if (width < 1 || width > MaxImageSize || height < 1 || height > MaxImageSize)
  {
    throw std::invalid_argument("image size " + std::to_string(width) + " x " +
      std::to_string(height) + " is outside 1.." + std::to_string(MaxImageSize) + " per side");
  }
  if (!std::isfinite(view.azimuth) || !std::isfinite(view.elevation) ||
    !std::isfinite(view.distance) || view.distance < 0)
  {
    throw std::invalid_argument("the view must be finite with a distance >= 0");
  }
  for (int a = 0; a < 3; ++a)
  {
    if (!std::isfinite(box.lo[a]) || !std::isfinite(box.hi[a]) || box.lo[a] > box.hi[a])
    {
      throw std::invalid_argument("the box to look at must be finite with lo <= hi");
    }
  }
  const double halfDiagonal = 0.5 * norm(sub(box.hi, box.lo));
  if (!(halfDiagonal > 0))
  {
    throw std::invalid_argument("the box to look at is a point");
  }
  Camera c;
  c.width_ = width;
  c.height_ = height;
  c.projection_ = projection;
  const double distance = view.distance > 0 ? view.distance : DefaultDistance * halfDiagonal;
  const double az = view.azimuth * Pi / 180, el = view.elevation * Pi / 180;
  const Point3 toEye{ std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el) };
  c.eye_ = add(box.centre(), scale(toEye, distance));
  c.forward_ = scale(toEye, -1);
  // Looking (nearly) along z, +z cannot be up: +y is.
  const Point3 worldUp = std::abs(std::cos(el)) < 1e-9 ? Point3{ 0, 1, 0 } : Point3{ 0, 0, 1 };
  c.right_ = unit(cross(c.forward_, worldUp));
  c.up_ = cross(c.right_, c.forward_);
  const double planeHeight = projection == Projection::Perspective
    ? 2 * std::tan(0.5 * PerspectiveFieldOfView * Pi / 180)
    : OrthographicHeight * halfDiagonal;
  c.pixelSize_ = planeHeight / height;
  return c;
}

Camera Camera::lookAt(const Point3& position, const Point3& focalPoint, const Point3& up,
  Projection projection, double viewAngle, double parallelScale, int width, int height)
{
  if (width < 1 || width > MaxImageSize || height < 1 || height > MaxImageSize)
  {
    throw std::invalid_argument("image size " + std::to_string(width) + " x " +
      std::to_string(height) + " is outside 1.." + std::to_string(MaxImageSize) + " per side");
  }
  for (int a = 0; a < 3; ++a)
  {
    if (!std::isfinite(position[a]) || !std::isfinite(focalPoint[a]) || !std::isfinite(up[a]))
    {
      throw std::invalid_argument("the camera's position, focal point and up must be finite");
    }
  }
  const Point3 toFocus = sub(focalPoint, position);
  if (!(norm(toFocus) > 0))
  {
    throw std::invalid_argument("the camera's position is its focal point");
  }
  Camera c;
  c.width_ = width;
  c.height_ = height;
  c.projection_ = projection;
  c.eye_ = position;
  c.forward_ = unit(toFocus);
  const Point3 side = cross(c.forward_, up);
  if (!(norm(side) > 1e-9 * norm(up)) || !(norm(up) > 0))
  {
    throw std::invalid_argument("the camera's up is zero or along its view direction");
  }
  c.right_ = unit(side);
  c.up_ = cross(c.right_, c.forward_);
  if (projection == Projection::Perspective)
  {
    if (!(viewAngle > 0 && viewAngle < 180))
    {
      throw std::invalid_argument("the view angle must be between 0 and 180 degrees");
    }
    c.pixelSize_ = 2 * std::tan(0.5 * viewAngle * Pi / 180) / height;
  }
  else
  {
    if (!(parallelScale > 0) || !std::isfinite(parallelScale))
    {
      throw std::invalid_argument("the parallel scale must be positive and finite");
    }
    c.pixelSize_ = 2 * parallelScale / height;
  }
  return c;
}

double Camera::viewAngle() const
{
  return 2 * std::atan(0.5 * pixelSize_ * height_) * 180 / Pi;
}

Point3 Camera::origin(double u, double v) const
{
  if (projection_ == Projection::Perspective)
  {
    return eye_;
  }
  return add(eye_, add(scale(right_, u), scale(up_, v)));
}

Point3 Camera::direction(double u, double v) const
{
  if (projection_ == Projection::Orthographic)
  {
    return forward_;
  }
  return add(forward_, add(scale(right_, u), scale(up_, v)));
}

Point3 Camera::point(double u, double v, double s) const
{
  return add(origin(u, v), scale(direction(u, v), s));
}

} // namespace ictk::render
