// SPDX-License-Identifier: BSD-3-Clause
#include "Render/ComplexRender.h"

#include "Complex/Attributes.h"
#include "Render/Rasterize.h"
#include "Render/RayCaster.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>

namespace ictk::render
{

using complex::Cell;
using complex::CellId;
using frep::Point3;

namespace
{

/// The attribute that colours the picture: its name and whether it is a scalar; no name: none.
struct Colouring
{
  std::string name;
  bool scalar = false;
  std::vector<double> insideDefault; ///< theta1, for cells that do not bind it
};

Colouring colouringOf(const complex::Complex& complex, const std::string& requested)
{
  Colouring c;
  for (const auto& [name, defaults] : complex.attributes())
  {
    const int n = defaults.components;
    const bool wanted = requested.empty()
      ? (name == "colour" || name == "color") && (n == 3 || n == 4)
      : name == requested;
    if (!wanted)
    {
      continue;
    }
    if (n != 1 && n != 3 && n != 4)
    {
      throw std::invalid_argument("the attribute '" + name + "' has " + std::to_string(n) +
        " components: a colour has 3 (or 4), a scalar 1");
    }
    c.name = name;
    c.scalar = n == 1;
    c.insideDefault = defaults.inside;
    return c;
  }
  if (!requested.empty())
  {
    std::string known;
    for (const auto& entry : complex.attributes())
    {
      known += (known.empty() ? "" : ", ") + entry.first;
    }
    throw std::invalid_argument("the complex declares no attribute '" + requested +
      "' (it declares: " + (known.empty() ? std::string("none") : known) + ")");
  }
  return c;
}

/// The paint of `values` (the attribute's components).
Paint paintOf(const Colouring& c, const double* values, std::size_t count)
{
  Paint paint;
  if (c.name.empty() || count == 0)
  {
    return paint;
  }
  if (c.scalar)
  {
    paint.scalar = values[0];
    return paint;
  }
  for (std::size_t k = 0; k < 3 && k < count; ++k)
  {
    paint.rgb[k] = std::isfinite(values[k]) ? std::clamp(values[k], 0.0, 1.0) : NeutralGrey;
  }
  return paint;
}

const complex::AttributeBinding* bindingOf(const Cell& cell, const std::string& attribute)
{
  for (const auto& b : cell.attributes)
  {
    if (b.attribute == attribute)
    {
      return &b;
    }
  }
  return nullptr;
}

/// A ray-cast cell's paint: its binding evaluated where the ray enters it, or a constant.
class BindingPainter final : public detail::Painter
{
public:
  BindingPainter(const complex::AttributeBinding* binding, const Colouring& colouring)
    : colouring_(colouring)
  {
    if (binding)
    {
      for (const auto& f : binding->function->components)
      {
        evaluators_.push_back(f->evaluator());
      }
    }
    values_.resize(evaluators_.empty() ? colouring.insideDefault.size() : evaluators_.size());
    std::copy(colouring.insideDefault.begin(),
      colouring.insideDefault.begin() +
        static_cast<std::ptrdiff_t>(std::min(values_.size(), colouring.insideDefault.size())),
      values_.begin());
  }
  Paint at(const Point3& p) override
  {
    for (std::size_t k = 0; k < evaluators_.size(); ++k)
    {
      values_[k] = evaluators_[k]->value(p);
    }
    return paintOf(colouring_, values_.data(), values_.size());
  }

private:
  const Colouring& colouring_;
  std::vector<std::unique_ptr<frep::FieldEvaluator>> evaluators_;
  std::vector<double> values_;
};

/// The per-point paints of a meshed cell (see the header's comment).
std::vector<Paint> vertexPaints(
  const Cell& cell, const complex::CellMesh& mesh, const Colouring& colouring)
{
  const std::vector<Point3>& points = mesh.vertices();
  if (colouring.name.empty())
  {
    return {};
  }
  const discretize::PointArray* array = nullptr;
  std::vector<discretize::PointArray> own;
  for (const auto& a : mesh.pointData())
  {
    if (a.name == colouring.name)
    {
      array = &a;
    }
  }
  if (!array)
  {
    if (const auto* binding = bindingOf(cell, colouring.name))
    {
      complex::appendAttribute(*binding, points, own);
      array = &own.back();
    }
  }
  std::vector<Paint> paints(points.size());
  if (!array)
  {
    std::fill(paints.begin(), paints.end(),
      paintOf(colouring, colouring.insideDefault.data(), colouring.insideDefault.size()));
    return paints;
  }
  const auto n = static_cast<std::size_t>(array->components);
  for (std::size_t i = 0; i < points.size(); ++i)
  {
    paints[i] = paintOf(colouring, array->values.data() + i * n, n);
  }
  return paints;
}

/// The primitives of a meshed cell.
Primitives primitivesOf(const Cell& cell, const complex::CellMesh& mesh, const Colouring& colouring,
  double tubeRadius, double pointRadius)
{
  Primitives p;
  p.owner = static_cast<std::int32_t>(cell.id);
  p.tubeRadius = tubeRadius;
  p.sphereRadius = pointRadius;
  p.points = mesh.vertices();
  p.paints = vertexPaints(cell, mesh, colouring);
  switch (mesh.dimension)
  {
    case 0:
      for (std::uint32_t i = 0; i < p.points.size(); ++i)
      {
        p.spheres.push_back(i);
      }
      break;
    case 1:
      for (const auto& line : mesh.curves.lines)
      {
        for (std::size_t k = 1; k < line.size(); ++k)
        {
          p.segments.push_back({ line[k - 1], line[k] });
        }
        if (line.size() == 1)
        {
          p.segments.push_back({ line[0], line[0] });
        }
      }
      break;
    default:
      p.triangles = mesh.surface.triangles;
      p.normals = vertexNormals(p.points, p.triangles);
      // A mesh that brings its vertex normals (a skinned B-cell's, turned towards its stand-in
      // by setProjection) is shaded with them.
      for (const auto& a : mesh.pointData())
      {
        if (a.name == "Normals" && a.components == 3 && a.values.size() == 3 * p.points.size())
        {
          for (std::size_t i = 0; i < p.points.size(); ++i)
          {
            p.normals[i] = { a.values[3 * i], a.values[3 * i + 1], a.values[3 * i + 2] };
          }
        }
      }
  }
  return p;
}

/// A 3D cell's solid: the min of its inside fields.
frep::FieldPtr solidOf(const complex::ImplicitGeometry& g)
{
  return g.inside.size() == 1 ? g.inside[0] : frep::minField(g.inside);
}

} // namespace

bool isRayCast(const Cell& cell)
{
  const auto* g = std::get_if<complex::ImplicitGeometry>(&cell.geometry);
  return cell.dimension == 3 && g && g->carriers.empty() && !g->inside.empty();
}

std::vector<CellId> meshedCells(const complex::Complex& complex)
{
  std::vector<CellId> ids;
  for (CellId id : complex.cellIds())
  {
    if (!isRayCast(complex.cell(id)))
    {
      ids.push_back(id);
    }
  }
  return ids;
}

void checkColours(const complex::Complex& complex, const ColourOptions& colours)
{
  colouringOf(complex, colours.attribute);
  ColourMap::named(colours.map);
}

ScenePrimitives scenePrimitives(const complex::Complex& complex, const complex::ComplexMesh& mesh,
  const ComplexRenderOptions& options, bool everyCell)
{
  checkColours(complex, options.colours);
  const Colouring colouring = colouringOf(complex, options.colours.attribute);
  for (double r : { options.tubeRadius, options.pointRadius })
  {
    if (!std::isfinite(r) || r < 0)
    {
      throw std::invalid_argument("the tube and point radii must be finite and >= 0 (0: default)");
    }
  }
  ScenePrimitives scene;
  scene.scalar = colouring.scalar;
  const frep::Box3 box = complex::complexBounds(complex);
  const double halfDiagonal = 0.5 * frep::norm(frep::sub(box.hi, box.lo));
  scene.tubeRadius = options.tubeRadius > 0
    ? options.tubeRadius
    : (std::isfinite(halfDiagonal) && halfDiagonal > 0 ? halfDiagonal / 200 : 0.005);
  scene.pointRadius = options.pointRadius > 0 ? options.pointRadius : 2.5 * scene.tubeRadius;
  for (CellId id : complex.cellIds())
  {
    const Cell& cell = complex.cell(id);
    if (!everyCell && isRayCast(cell))
    {
      scene.rayCast.push_back(id);
      continue;
    }
    const complex::CellMesh* cellMesh = nullptr;
    try
    {
      cellMesh = &mesh.of(id);
    }
    catch (const complex::ComplexError&)
    {
      throw std::invalid_argument("renderComplex: no discretisation of cell '" + cell.name + "'");
    }
    scene.meshed.push_back(
      primitivesOf(cell, *cellMesh, colouring, scene.tubeRadius, scene.pointRadius));
  }
  return scene;
}

ComplexRenderResult renderComplex(const complex::Complex& complex, const complex::ComplexMesh& mesh,
  const Camera& camera, const ComplexRenderOptions& options)
{
  const Colouring colouring = colouringOf(complex, options.colours.attribute);
  const ScenePrimitives scene = scenePrimitives(complex, mesh, options, false);
  ComplexRenderResult result;
  result.tubeRadius = scene.tubeRadius;
  result.pointRadius = scene.pointRadius;
  result.canvas = Canvas(camera.width(), camera.height(),
    scene.scalar ? Canvas::Colouring::Scalar : Canvas::Colouring::Rgb);
  Canvas& canvas = result.canvas;
  const std::vector<CellId>& rayCast = scene.rayCast;
  const std::vector<Primitives>& meshed = scene.meshed;

  ProgressScope progress(options.progress);
  progress.report(0);
  const double passA = rayCast.empty() ? 1.0 : 0.1;
  for (std::size_t k = 0; k < meshed.size(); ++k)
  {
    RasterOptions raster;
    raster.threads = options.threads;
    raster.progress = progress.range(passA * static_cast<double>(k) / meshed.size(),
      passA * static_cast<double>(k + 1) / meshed.size());
    rasterize(canvas, camera, meshed[k], raster);
  }
  for (std::size_t k = 0; k < rayCast.size(); ++k)
  {
    const Cell& cell = complex.cell(rayCast[k]);
    const frep::FieldPtr field = solidOf(std::get<complex::ImplicitGeometry>(cell.geometry));
    const complex::AttributeBinding* binding =
      colouring.name.empty() ? nullptr : bindingOf(cell, colouring.name);
    detail::Solid solid;
    solid.box = cell.bounds();
    solid.owner = static_cast<std::int32_t>(cell.id);
    solid.stage = [&]
    {
      return detail::fieldStage(*field);
    };
    if (!colouring.name.empty())
    {
      solid.painter = [&]
      {
        return std::make_unique<BindingPainter>(binding, colouring);
      };
    }
    RayCastOptions cast;
    cast.threads = options.threads;
    cast.depthTolerance = options.depthTolerance;
    const double share = (1 - passA) / static_cast<double>(rayCast.size());
    cast.progress = progress.range(passA + share * k, passA + share * (k + 1));
    const detail::CastCounts counts = detail::cast(canvas, solid, camera, cast);
    result.unresolvedPixels += counts.unresolved;
    result.cutPixels += counts.cut;
    result.eyeInsidePixels += counts.eyeInside;
    result.intervalEvaluations += counts.intervals;
  }
  progress.report(1);

  for (std::int32_t who : canvas.owner)
  {
    if (who >= 0)
    {
      ++result.pixelsByDimension[static_cast<std::size_t>(
        complex.cell(static_cast<CellId>(who)).dimension)];
    }
  }
  if (colouring.scalar)
  {
    result.scalarRange = finishColours(canvas, options.colours);
  }
  return result;
}

} // namespace ictk::render
