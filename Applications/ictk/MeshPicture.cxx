// SPDX-License-Identifier: BSD-3-Clause
#include "MeshPicture.h"

#include "Command.h"

#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkDoubleArray.h>
#include <vtkFloatArray.h>
#include <vtkGlyph3D.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkSphereSource.h>
#include <vtkTubeFilter.h>
#include <vtkUnsignedCharArray.h>
#include <vtkWindowToImageFilter.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>

namespace ictk::cli
{
namespace
{

/// The paints of a scene's points as 8-bit RGB (scalars through the map over `range`).
vtkSmartPointer<vtkUnsignedCharArray> Colours(const render::Primitives& p, bool scalar,
  const render::ColourMap& map, const std::array<double, 2>& range)
{
  auto colours = vtkSmartPointer<vtkUnsignedCharArray>::New();
  colours->SetName("colour");
  colours->SetNumberOfComponents(3);
  colours->SetNumberOfTuples(static_cast<vtkIdType>(p.points.size()));
  for (std::size_t i = 0; i < p.points.size(); ++i)
  {
    const render::Paint paint = p.paints.empty() ? render::Paint{} : p.paints[i];
    std::array<double, 3> rgb = paint.rgb;
    if (scalar)
    {
      const double t =
        range[1] > range[0] ? (paint.scalar - range[0]) / (range[1] - range[0]) : 0.5;
      rgb = map.at(std::isfinite(paint.scalar) ? t : std::numeric_limits<double>::quiet_NaN());
    }
    for (int c = 0; c < 3; ++c)
    {
      colours->SetComponent(
        static_cast<vtkIdType>(i), c, std::lround(255 * std::clamp(rgb[c], 0.0, 1.0)));
    }
  }
  return colours;
}

void AddActor(vtkRenderer* renderer, vtkAlgorithmOutput* port, vtkPolyData* data)
{
  vtkNew<vtkPolyDataMapper> mapper;
  if (port)
  {
    mapper->SetInputConnection(port);
  }
  else
  {
    mapper->SetInputData(data);
  }
  mapper->SetScalarModeToUsePointFieldData();
  mapper->SelectColorArray("colour");
  mapper->SetColorModeToDirectScalars();
  mapper->ScalarVisibilityOn();
  vtkNew<vtkActor> actor;
  actor->SetMapper(mapper);
  actor->GetProperty()->SetAmbient(0.25);
  actor->GetProperty()->SetDiffuse(0.75);
  actor->GetProperty()->SetSpecular(0);
  renderer->AddActor(actor);
}

} // namespace

void CheckMeshDisplay()
{
  if (!std::getenv("DISPLAY") || !*std::getenv("DISPLAY"))
  {
    throw UserError("--mode mesh renders with OpenGL and needs an X display; run it under "
                    "xvfb-run (the Debian package xvfb) where there is none");
  }
}

std::array<double, 2> MeshColourRange(
  const render::ScenePrimitives& scene, const render::ColourOptions& colours)
{
  std::array<double, 2> range = colours.range;
  if (scene.scalar && (std::isnan(range[0]) || std::isnan(range[1])))
  {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const auto& p : scene.meshed)
    {
      for (const auto& paint : p.paints)
      {
        if (std::isfinite(paint.scalar))
        {
          lo = std::min(lo, paint.scalar);
          hi = std::max(hi, paint.scalar);
        }
      }
    }
    range = { std::isnan(range[0]) ? (lo <= hi ? lo : 0.0) : range[0],
      std::isnan(range[1]) ? (lo <= hi ? hi : 1.0) : range[1] };
  }
  return range;
}

render::Canvas DrawMeshes(const render::ScenePrimitives& scene, const render::Camera& camera,
  const render::ColourOptions& colours)
{
  CheckMeshDisplay();
  const render::ColourMap map = render::ColourMap::named(colours.map);
  const std::array<double, 2> range = MeshColourRange(scene, colours);

  vtkNew<vtkRenderer> renderer;
  renderer->SetBackground(1, 1, 1);
  for (const render::Primitives& p : scene.meshed)
  {
    vtkNew<vtkPoints> points;
    points->SetDataTypeToDouble();
    for (const auto& q : p.points)
    {
      points->InsertNextPoint(q[0], q[1], q[2]);
    }
    const auto colour = Colours(p, scene.scalar, map, range);
    if (!p.triangles.empty())
    {
      vtkNew<vtkPolyData> surface;
      surface->SetPoints(points);
      vtkNew<vtkCellArray> polys;
      for (const auto& t : p.triangles)
      {
        const vtkIdType ids[3] = { t[0], t[1], t[2] };
        polys->InsertNextCell(3, ids);
      }
      surface->SetPolys(polys);
      surface->GetPointData()->AddArray(colour);
      if (!p.normals.empty())
      {
        vtkNew<vtkDoubleArray> normals;
        normals->SetNumberOfComponents(3);
        for (const auto& n : p.normals)
        {
          const double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
          const double k = length > 0 ? 1 / length : 0;
          normals->InsertNextTuple3(n[0] * k, n[1] * k, n[2] * k);
        }
        surface->GetPointData()->SetNormals(normals);
      }
      AddActor(renderer, nullptr, surface);
    }
    if (!p.segments.empty())
    {
      vtkNew<vtkPolyData> curves;
      curves->SetPoints(points);
      vtkNew<vtkCellArray> lines;
      for (const auto& s : p.segments)
      {
        const vtkIdType ids[2] = { s[0], s[1] };
        lines->InsertNextCell(2, ids);
      }
      curves->SetLines(lines);
      curves->GetPointData()->AddArray(colour);
      vtkNew<vtkTubeFilter> tubes;
      tubes->SetInputData(curves);
      tubes->SetRadius(p.tubeRadius);
      tubes->SetNumberOfSides(24);
      tubes->CappingOn();
      AddActor(renderer, tubes->GetOutputPort(), nullptr);
    }
    if (!p.spheres.empty())
    {
      vtkNew<vtkPoints> centres;
      vtkNew<vtkUnsignedCharArray> centreColours;
      centreColours->SetName("colour");
      centreColours->SetNumberOfComponents(3);
      for (std::uint32_t i : p.spheres)
      {
        centres->InsertNextPoint(p.points[i][0], p.points[i][1], p.points[i][2]);
        centreColours->InsertNextTuple(colour->GetTuple(i));
      }
      vtkNew<vtkPolyData> at;
      at->SetPoints(centres);
      at->GetPointData()->AddArray(centreColours);
      vtkNew<vtkSphereSource> ball;
      ball->SetRadius(p.sphereRadius);
      ball->SetThetaResolution(32);
      ball->SetPhiResolution(32);
      vtkNew<vtkGlyph3D> glyphs;
      glyphs->SetInputData(at);
      glyphs->SetSourceConnection(ball->GetOutputPort());
      glyphs->ScalingOff();
      glyphs->OrientOff();
      glyphs->SetColorModeToColorByScalar();
      glyphs->SetInputArrayToProcess(3, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, "colour");
      AddActor(renderer, glyphs->GetOutputPort(), nullptr);
    }
  }

  // The core's camera (Camera.h): eye, forward, up; 30 degrees high or the orthographic height.
  vtkCamera* view = renderer->GetActiveCamera();
  const auto& eye = camera.eye();
  const auto& forward = camera.forward();
  const auto& up = camera.up();
  view->SetPosition(eye[0], eye[1], eye[2]);
  view->SetFocalPoint(eye[0] + forward[0], eye[1] + forward[1], eye[2] + forward[2]);
  view->SetViewUp(up[0], up[1], up[2]);
  const bool perspective = camera.projection() == render::Projection::Perspective;
  if (perspective)
  {
    view->SetViewAngle(camera.viewAngle());
  }
  else
  {
    view->ParallelProjectionOn();
    view->SetParallelScale(0.5 * camera.pixelSize() * camera.height());
  }
  renderer->ResetCameraClippingRange();

  vtkNew<vtkRenderWindow> window;
  window->SetOffScreenRendering(1);
  window->SetMultiSamples(0);
  window->SetSize(camera.width(), camera.height());
  window->AddRenderer(renderer);
  window->Render();
  double clip[2];
  view->GetClippingRange(clip);

  vtkNew<vtkWindowToImageFilter> rgba;
  rgba->SetInput(window);
  rgba->SetInputBufferTypeToRGBA();
  rgba->ReadFrontBufferOff();
  rgba->Update();
  vtkNew<vtkWindowToImageFilter> z;
  z->SetInput(window);
  z->SetInputBufferTypeToZBuffer();
  z->ReadFrontBufferOff();
  z->Update();
  vtkDataArray* pixels = rgba->GetOutput()->GetPointData()->GetScalars();
  vtkDataArray* depths = z->GetOutput()->GetPointData()->GetScalars();

  // VTK's z-buffer holds OpenGL window depths for the clipping range: back to distances along
  // the rays (render::depthFromWindow, the inverse of the convention windowDepth writes).
  render::Canvas canvas(camera.width(), camera.height());
  std::vector<double> windowDepths(canvas.depth.size());
  for (std::size_t p = 0; p < windowDepths.size(); ++p)
  {
    windowDepths[p] = depths->GetComponent(static_cast<vtkIdType>(p), 0);
  }
  canvas.depth = render::depthFromWindow(windowDepths, camera, clip[0], clip[1]);
  canvas.normal.clear(); // VTK's pipeline gives no normal buffer: none rather than zeros
  for (std::size_t p = 0; p < windowDepths.size(); ++p)
  {
    if (!std::isfinite(canvas.depth[p]))
    {
      continue; // the far plane: background
    }
    canvas.owner[p] = 0;
    for (int c = 0; c < 4; ++c)
    {
      canvas.colour[4 * p + static_cast<std::size_t>(c)] =
        static_cast<std::uint8_t>(pixels->GetComponent(static_cast<vtkIdType>(p), c));
    }
    canvas.colour[4 * p + 3] = 255;
  }
  return canvas;
}

} // namespace ictk::cli
