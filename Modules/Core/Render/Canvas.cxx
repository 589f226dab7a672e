// SPDX-License-Identifier: BSD-3-Clause
#include "Render/Canvas.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace ictk::render
{

namespace
{
constexpr double Ambient = 0.25;
constexpr double Diffuse = 0.75;

std::uint8_t byte(double c, double light)
{
  return static_cast<std::uint8_t>(std::lround(255 * std::clamp(c * light, 0.0, 1.0)));
}
} // namespace

double headlight(const frep::Point3& gradient, const frep::Point3& direction, double length)
{
  const double n =
    std::sqrt(gradient[0] * gradient[0] + gradient[1] * gradient[1] + gradient[2] * gradient[2]);
  if (!(n > 0) || !std::isfinite(n))
  {
    return Ambient + Diffuse; // no gradient (a flat spot, or a cut by a box)
  }
  const frep::Point3 outward{ -gradient[0] / n, -gradient[1] / n, -gradient[2] / n };
  return Ambient + Diffuse * (std::abs(frep::dot(outward, direction)) / length);
}

const std::vector<std::string>& ColourMap::names()
{
  static const std::vector<std::string> known{ "cool-warm", "rainbow", "grey" };
  return known;
}

ColourMap ColourMap::named(const std::string& name)
{
  ColourMap map;
  if (name == "cool-warm")
  {
    // Moreland's diverging map's end and middle colours (the interpolation between them is
    // linear in RGB here, not in his Msh space).
    map.points_ = { { 0, 0.230, 0.299, 0.754 }, { 0.5, 0.865, 0.865, 0.865 },
      { 1, 0.706, 0.016, 0.150 } };
  }
  else if (name == "rainbow")
  {
    map.points_ = { { 0, 0, 0, 1 }, { 0.25, 0, 1, 1 }, { 0.5, 0, 1, 0 }, { 0.75, 1, 1, 0 },
      { 1, 1, 0, 0 } };
  }
  else if (name == "grey")
  {
    map.points_ = { { 0, 0.15, 0.15, 0.15 }, { 1, 1, 1, 1 } };
  }
  else
  {
    std::string list;
    for (const std::string& n : names())
    {
      list += (list.empty() ? "" : ", ") + n;
    }
    throw std::invalid_argument("unknown colour map '" + name + "' (known: " + list + ")");
  }
  return map;
}

std::array<double, 3> ColourMap::at(double t) const
{
  if (std::isnan(t))
  {
    return { NeutralGrey, NeutralGrey, NeutralGrey };
  }
  t = std::clamp(t, 0.0, 1.0);
  std::size_t k = 1;
  while (k + 1 < points_.size() && points_[k][0] < t)
  {
    ++k;
  }
  const auto& a = points_[k - 1];
  const auto& b = points_[k];
  const double w = (t - a[0]) / (b[0] - a[0]);
  return { a[1] + w * (b[1] - a[1]), a[2] + w * (b[2] - a[2]), a[3] + w * (b[3] - a[3]) };
}

Canvas::Canvas(int w, int h, Colouring c)
  : width(w)
  , height(h)
  , colouring(c)
{
  if (w < 0 || h < 0)
  {
    throw std::invalid_argument("Canvas: a negative size");
  }
  const std::size_t pixels = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  depth.assign(pixels, std::numeric_limits<double>::infinity());
  colour.assign(4 * pixels, 255);
  for (std::size_t p = 0; p < pixels; ++p)
  {
    colour[4 * p + 3] = 0;
  }
  owner.assign(pixels, -1);
  normal.assign(3 * pixels, 0.0f);
  if (c == Colouring::Scalar)
  {
    scalar.assign(pixels, std::numeric_limits<float>::quiet_NaN());
    light.assign(pixels, 0.0f);
  }
}

bool Canvas::isValidFor(const Camera& camera) const
{
  const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  const bool scalars =
    colouring != Colouring::Scalar || (scalar.size() == pixels && light.size() == pixels);
  return width == camera.width() && height == camera.height() && depth.size() == pixels &&
    colour.size() == 4 * pixels && owner.size() == pixels && normal.size() == 3 * pixels && scalars;
}

bool Canvas::put(std::size_t p, double d, double l, const Paint& paint, std::int32_t who,
  const frep::Point3& n, const frep::Point3& direction)
{
  if (!(d < depth[p]))
  {
    return false;
  }
  depth[p] = d;
  owner[p] = who;
  const double length = frep::norm(n);
  const double side = frep::dot(n, direction) > 0 ? -1 : 1;
  for (int c = 0; c < 3; ++c)
  {
    normal[3 * p + static_cast<std::size_t>(c)] = length > 0 && std::isfinite(length)
      ? static_cast<float>(side * n[static_cast<std::size_t>(c)] / length)
      : 0.0f;
  }
  std::uint8_t* rgba = &colour[4 * p];
  if (colouring == Colouring::Scalar)
  {
    scalar[p] = static_cast<float>(paint.scalar);
    light[p] = static_cast<float>(l);
    rgba[0] = rgba[1] = rgba[2] = byte(NeutralGrey, l);
  }
  else
  {
    for (int c = 0; c < 3; ++c)
    {
      rgba[c] = byte(paint.rgb[c], l);
    }
  }
  rgba[3] = 255;
  return true;
}

namespace
{
/// Checks the planes and the buffer's size for windowDepth and depthFromWindow.
void checkDepthPlanes(
  const char* what, std::size_t pixels, const Camera& camera, double near, double far)
{
  const bool perspective = camera.projection() == Projection::Perspective;
  if (!std::isfinite(near) || !std::isfinite(far) || !(near < far) || (perspective && !(near > 0)))
  {
    throw std::invalid_argument(std::string(what) +
      (perspective ? ": the planes must be finite with 0 < near < far"
                   : ": the planes must be finite with near < far"));
  }
  if (pixels !=
    static_cast<std::size_t>(camera.width()) * static_cast<std::size_t>(camera.height()))
  {
    throw std::invalid_argument(std::string(what) + ": the buffer is not of the camera's size");
  }
}

/// The length of pixel p's ray direction: its distance is its depth along the viewing axis times
/// this (Camera.h: the direction has a unit component along the axis; 1 for an orthographic ray).
double rayStretch(const Camera& camera, std::size_t p)
{
  const std::size_t w = static_cast<std::size_t>(camera.width());
  return frep::norm(
    camera.direction(camera.u(static_cast<double>(p % w)), camera.v(static_cast<double>(p / w))));
}
} // namespace

std::vector<double> windowDepth(
  const std::vector<double>& depth, const Camera& camera, double near, double far)
{
  checkDepthPlanes("windowDepth", depth.size(), camera, near, far);
  const bool perspective = camera.projection() == Projection::Perspective;
  std::vector<double> window(depth.size(), 1.0);
  for (std::size_t p = 0; p < depth.size(); ++p)
  {
    if (std::isfinite(depth[p]))
    {
      const double z = depth[p] / rayStretch(camera, p);
      const double d =
        perspective ? far * (z - near) / (z * (far - near)) : (z - near) / (far - near);
      window[p] = std::clamp(d, 0.0, 1.0);
    }
  }
  return window;
}

std::vector<double> depthFromWindow(
  const std::vector<double>& window, const Camera& camera, double near, double far)
{
  checkDepthPlanes("depthFromWindow", window.size(), camera, near, far);
  const bool perspective = camera.projection() == Projection::Perspective;
  std::vector<double> depth(window.size(), std::numeric_limits<double>::infinity());
  for (std::size_t p = 0; p < window.size(); ++p)
  {
    const double d = window[p];
    if (d < 1)
    {
      const double z =
        perspective ? far * near / (far - d * (far - near)) : near + d * (far - near);
      depth[p] = z * rayStretch(camera, p);
    }
  }
  return depth;
}

std::int64_t Canvas::covered() const
{
  return std::count_if(depth.begin(), depth.end(), [](double d) { return std::isfinite(d); });
}

std::pair<double, double> Canvas::scalarRange() const
{
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (std::size_t p = 0; p < scalar.size(); ++p)
  {
    if (std::isfinite(depth[p]) && std::isfinite(scalar[p]))
    {
      lo = std::min(lo, static_cast<double>(scalar[p]));
      hi = std::max(hi, static_cast<double>(scalar[p]));
    }
  }
  if (lo > hi)
  {
    return { std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN() };
  }
  return { lo, hi };
}

void Canvas::applyColourMap(const ColourMap& map, double lo, double hi)
{
  if (colouring != Colouring::Scalar)
  {
    throw std::invalid_argument("Canvas: a colour map needs a picture coloured by a scalar");
  }
  if (!std::isfinite(lo) || !std::isfinite(hi) || lo > hi)
  {
    throw std::invalid_argument("Canvas: the colour map's range must be finite with lo <= hi");
  }
  for (std::size_t p = 0; p < scalar.size(); ++p)
  {
    if (!std::isfinite(depth[p]))
    {
      continue;
    }
    const double v = scalar[p];
    const double t = std::isfinite(v) ? (hi > lo ? (v - lo) / (hi - lo) : 0.5)
                                      : std::numeric_limits<double>::quiet_NaN();
    const std::array<double, 3> rgb = map.at(t);
    for (int c = 0; c < 3; ++c)
    {
      colour[4 * p + c] = byte(rgb[c], light[p]);
    }
  }
}

std::array<double, 2> finishColours(Canvas& canvas, const ColourOptions& colours)
{
  std::array<double, 2> range = colours.range;
  if (std::isnan(range[0]) || std::isnan(range[1]))
  {
    const auto seen = canvas.scalarRange();
    range = { std::isnan(range[0]) ? seen.first : range[0],
      std::isnan(range[1]) ? seen.second : range[1] };
  }
  if (std::isnan(range[0]) || std::isnan(range[1]))
  {
    range = { 0, 1 }; // no value seen: nothing to colour
  }
  if (range[0] > range[1])
  {
    throw std::invalid_argument("the colour range's low end " + std::to_string(range[0]) +
      " is above its high end " + std::to_string(range[1]));
  }
  canvas.applyColourMap(ColourMap::named(colours.map), range[0], range[1]);
  return range;
}

} // namespace ictk::render
