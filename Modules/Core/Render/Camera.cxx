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
