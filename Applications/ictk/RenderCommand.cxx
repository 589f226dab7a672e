// SPDX-License-Identifier: BSD-3-Clause
// `ictk render`: pictures drawn by the core (Render/): an FRep model (a registered name, .hf,
// .xml, .vm) ray cast; a complex (.json) or a dynamic model (.icm at --time) with its cells of
// every dimension composed through one depth buffer (Render/ComplexRender.h); a tetrahedral mesh
// (.vtu) by the faces of its elements, cut open by --cut (Render/TetCut.h), rasterised or, with
// --mode mesh, through VTK's OpenGL pipeline; and with --frames,
// a range of frames of an XYZT model or a .icm model as numbered PNGs or an .mp4 film. This
// file resolves the input, the camera and the colours; Pictures.h writes the results.
#include "Command.h"
#include "MeshPicture.h"
#include "Models.h"
#include "Options.h"
#include "Pictures.h"
#include "ProgressDisplay.h"
#include "VtkMessages.h"

#include "Complex/Discretization.h"
#include "Engine/FrameSequence.h"
#include "Render/ComplexRender.h"
#include "Render/RayCast.h"
#include "Render/TetCut.h"
#include "ictkComplexToVTK.h"
#include "ictkSolverResults.h"

#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkUnstructuredGrid.h>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>

namespace ictk::cli
{
namespace
{

using Clock = std::chrono::steady_clock;

/// One picture drawn, whatever drew it: its buffers and what the summary and warnings say.
struct Drawn
{
  int Width = 0;
  int Height = 0;
  std::vector<std::uint8_t> Colour;
  std::vector<double> Depth;
  /// The surfaces' normals, 3 a pixel (empty when the renderer gives none: --mode mesh).
  std::vector<float> Normal;
  std::int64_t Covered = 0;
  std::int64_t Unresolved = 0;
  std::int64_t Cut = 0;
  double IntervalsPerPixel = 0;
  /// Complexes: pixels showing cells of each dimension.
  std::optional<std::array<std::int64_t, 4>> ByDimension;
  std::array<double, 2> ScalarRange{ std::numeric_limits<double>::quiet_NaN(),
    std::numeric_limits<double>::quiet_NaN() };
  bool Mesh = false; ///< drawn by VTK's polygon pipeline (--mode mesh)

  PictureBuffers Buffers() const { return { Width, Height, &Colour, &Depth, &Normal }; }
};

Drawn FromRayCast(render::RayCastResult&& r)
{
  Drawn d;
  d.Width = r.width;
  d.Height = r.height;
  d.Colour = std::move(r.colour);
  d.Depth = std::move(r.depth);
  d.Normal = std::move(r.normal);
  d.Covered = r.coveredPixels;
  d.Unresolved = r.unresolvedPixels;
  d.Cut = r.cutPixels;
  d.IntervalsPerPixel = static_cast<double>(r.intervalEvaluations) / (double(r.width) * r.height);
  d.ScalarRange = r.scalarRange;
  return d;
}

Drawn FromComplex(render::ComplexRenderResult&& r)
{
  Drawn d;
  d.Width = r.canvas.width;
  d.Height = r.canvas.height;
  d.Colour = std::move(r.canvas.colour);
  d.Depth = std::move(r.canvas.depth);
  d.Normal = std::move(r.canvas.normal);
  d.Covered = r.pixelsByDimension[0] + r.pixelsByDimension[1] + r.pixelsByDimension[2] +
    r.pixelsByDimension[3];
  d.Unresolved = r.unresolvedPixels;
  d.Cut = r.eyeInsidePixels; // a cell's box is part of the cell: only the camera's cut warns
  d.IntervalsPerPixel = static_cast<double>(r.intervalEvaluations) / (double(d.Width) * d.Height);
  d.ByDimension = r.pixelsByDimension;
  d.ScalarRange = r.scalarRange;
  return d;
}

/// A picture drawn by VTK's polygon pipeline (--mode mesh) or the rasteriser alone.
Drawn FromCanvas(render::Canvas&& c)
{
  Drawn d;
  d.Width = c.width;
  d.Height = c.height;
  d.Covered = c.covered();
  d.Colour = std::move(c.colour);
  d.Depth = std::move(c.depth);
  d.Normal = std::move(c.normal); // empty for VTK's pictures
  d.Mesh = true;                  // no interval evaluations to report
  return d;
}

class RenderCommand final : public Command
{
public:
  CLI::App* add(CLI::App& app) override
  {
    CLI::App* render = app.add_subcommand("render",
      "Draw an FRep model, a complex or a dynamic model into a PNG picture (or, with --frames, "
      "numbered PNGs or an .mp4 film), see docs/render.md");
    AddModel(render, this->Model,
      "Model name (see `ictk models`), a .hf / .xml / .vm / .blob file, a .json complex, a .icm "
      "dynamic model or a .vtu tetrahedral mesh");
    AddOutput(render, this->Output,
      "Output picture (.png); with --frames a pattern (frames/%04d.png) or an .mp4 film");
    render->add_option(
      "--size", this->Size, "Image size W,H in pixels, 1..4096 each (default 800,600)");
    render->add_option("--bounds", this->Bounds,
      "x0,x1,y0,y1,z0,z1: the box an FRep model is drawn in, which cuts it open where it is "
      "smaller than the model (default: the model's bounds)");
    this->ViewOption = render->add_option("--view", this->View,
      "Camera: azimuth,elevation[,distance]: degrees about +z from +x, degrees above the "
      "xy-plane, distance from the centre of the model's box (default 30,20 and 2.5 times the "
      "box's half-diagonal)");
    this->ProjectionOption = render->add_option(
      "--projection", this->Projection, "perspective (default; 30 degrees high) or orthographic");
    render->add_option("--camera", this->CameraFile,
      "A camera file (JSON, VTK's conventions): position, focal_point, up (default 0,0,1), "
      "projection (perspective or orthographic), view_angle (degrees, default 30) or "
      "parallel_scale (half the height seen); instead of --view and --projection");
    this->TimeOption = AddTime(render, this->Time);
    this->TimeOption->description(
      "Time t of an XYZT model, an animated .blob or a .icm model (default 0; a .icm model's "
      "start; an animated .blob needs it)");
    AddFrames(render, this->Frames,
      "Frames T0:T1:DT of an XYZT model, an animated .blob or a .icm model, one picture each (-o "
      "a pattern or an .mp4)");
    render->add_option("--fps", this->Fps, "Frames per second of an .mp4 film (default 1/DT)");
    AddThreads(render, this->Threads);
    AddParams(render, this->Params);
    render->add_option("--colour-by", this->ColourBy,
      "The attribute that colours the picture: a colour (3 components) or a scalar drawn "
      "through --colour-map (default: the attribute `colour`, if any); for a .vtu mesh a cell "
      "or point array of 1 component (MaterialId, youngs_modulus, von_mises, ...; default: the "
      "cell array MaterialId or label, if any)");
    render->add_option("--cut", this->Cut,
      "nx,ny,nz,d: a .vtu tetrahedral mesh cut open by the plane n . x = d: the tetrahedra "
      "whose centroid has n . x > d are left out, the others kept whole and seen by their "
      "faces");
    render->add_option("--colour-map", this->ColourMapName,
      "Colour map of a scalar attribute: cool-warm (default), rainbow, grey");
    render->add_option("--range", this->Range,
      "lo,hi: the scalar values at the colour map's ends (default: the range in the picture, "
      "the first frame's for --frames)");
    render->add_option("--tube-radius", this->TubeRadius,
      "Radius of the tubes drawn for 1D cells (default 1/200 of the complex box's "
      "half-diagonal)");
    render->add_option("--point-radius", this->PointRadius,
      "Radius of the spheres drawn for 0D cells (default 2.5 tube radii)");
    render->add_option("--feature-size", this->FeatureSize,
      "Edge length of the discretisation of a complex's cells that are not ray cast (default "
      "1/64 of the complex's largest side)");
    render->add_option("--mode", this->Mode,
      "raycast (default: solids ray cast exactly, meshed cells rasterised exactly) or mesh "
      "(a model's dual-contoured surface, every cell's discretisation, a .vtu mesh's faces, "
      "through VTK's OpenGL pipeline offscreen; needs an X display or xvfb-run)");
    render->add_option("--pick", this->PickAt,
      "X,Y: also print what the picture shows at pixel column X (from the left) and row Y (from "
      "the top): the surface point, its depth and, for a scene (.scn), the id of the frontmost "
      "object (FRep models)");
    render->add_option("--depth", this->Depth,
      "Also write the depth buffer (distance along each pixel's ray, inf where nothing is hit) "
      "as .vti");
    return render;
  }

  int run() override
  {
    this->CheckOptions();
    const bool complexFile = IsComplexInput(this->Model);
    const bool dynamic = HasExtension(this->Model, ".icm");
    const bool tetMesh = HasExtension(this->Model, ".vtu");
    if (tetMesh)
    {
      if (!this->Bounds.empty() || this->TimeOption->count() > 0 || !this->Frames.empty() ||
        !this->PickAt.empty())
      {
        throw UserError("render: '" + this->Model +
          "' is a tetrahedral mesh: --bounds, --time, --frames and --pick are for models and "
          "complexes (a mesh is cut open by --cut)");
      }
      InterruptScope interrupts;
      try
      {
        return this->RunTetMesh();
      }
      catch (const Cancelled&)
      {
        std::cerr << "ictk: interrupted; nothing written\n";
        return ExitInterrupted;
      }
    }
    if (!this->Cut.empty())
    {
      throw UserError("--cut cuts a tetrahedral mesh (.vtu) open; an FRep model is cut by its "
                      "box (--bounds)");
    }
    if ((complexFile || dynamic) && !this->Bounds.empty())
    {
      throw UserError("--bounds: the box to draw in is for FRep models; a complex's cells have "
                      "their own boxes");
    }
    if (complexFile && (this->TimeOption->count() > 0 || !this->Frames.empty()))
    {
      throw UserError("render: '" + this->Model +
        "' is a .json complex, which has no time: --time and --frames are for XYZT models and "
        ".icm models");
    }
    InterruptScope interrupts;
    try
    {
      if (!this->Frames.empty())
      {
        return this->RunFrames(dynamic);
      }
      return this->RunPicture(complexFile, dynamic);
    }
    catch (const Cancelled&)
    {
      std::cerr << "ictk: interrupted; nothing written\n";
      return ExitInterrupted;
    }
    catch (const engine::ModelError& e)
    {
      throw AsParseError(e);
    }
  }

private:
  void CheckOptions()
  {
    const std::vector<std::int64_t> size = ParseIntegers(this->Size, "--size", { "W", "H" }, "W,H");
    for (int a = 0; a < 2; ++a)
    {
      if (size[a] < 1 || size[a] > render::MaxImageSize)
      {
        throw UserError(std::string("--size: ") + (a == 0 ? "W" : "H") + " must be in 1.." +
          std::to_string(render::MaxImageSize) + ", got " + std::to_string(size[a]));
      }
    }
    this->Width = static_cast<int>(size[0]);
    this->Height = static_cast<int>(size[1]);
    if (!this->View.empty())
    {
      const std::vector<double> v =
        ParseNumbers(this->View, "--view", { "azimuth", "elevation", "distance" }, 2, 3,
          "azimuth,elevation or azimuth,elevation,distance");
      this->Orbit.azimuth = v[0];
      this->Orbit.elevation = v[1];
      if (v.size() == 3)
      {
        if (!(v[2] > 0))
        {
          throw UserError("--view: the distance must be positive, got " + std::to_string(v[2]));
        }
        this->Orbit.distance = v[2];
      }
    }
    if (this->Projection == "orthographic")
    {
      this->Kind = render::Projection::Orthographic;
    }
    else if (this->Projection != "perspective")
    {
      throw UserError(
        "--projection must be perspective or orthographic, got '" + this->Projection + "'");
    }
    if (!this->CameraFile.empty())
    {
      if (this->ViewOption->count() > 0 || this->ProjectionOption->count() > 0)
      {
        throw UserError("--camera and --view/--projection: the camera file says where it is");
      }
      this->ReadCamera();
    }
    if (this->Mode != "raycast" && this->Mode != "mesh")
    {
      throw UserError("--mode must be raycast or mesh, got '" + this->Mode + "'");
    }
    if (this->Mode == "mesh")
    {
      CheckMeshDisplay();
    }
    if (!std::isfinite(this->Time))
    {
      throw UserError("--time must be a finite number");
    }
    CheckThreads(this->Threads);
    CheckSize(this->FeatureSize);
    for (const auto& [value, name] :
      { std::pair{ this->TubeRadius, "--tube-radius" }, { this->PointRadius, "--point-radius" } })
    {
      if (!std::isfinite(value) || value < 0)
      {
        throw UserError(std::string(name) + " must be a finite number >= 0 (0: the default)");
      }
    }
    try
    {
      render::ColourMap::named(this->ColourMapName);
    }
    catch (const std::invalid_argument& e)
    {
      throw UserError(std::string("--colour-map: ") + e.what());
    }
    this->Colours.attribute = this->ColourBy;
    this->Colours.map = this->ColourMapName;
    if (!this->Range.empty())
    {
      const std::vector<double> r =
        ParseNumbers(this->Range, "--range", { "lo", "hi" }, 2, 2, "lo,hi");
      if (r[0] > r[1])
      {
        throw UserError("--range: lo > hi");
      }
      this->Colours.range = { r[0], r[1] };
    }
    if (!this->Frames.empty())
    {
      if (this->TimeOption->count() > 0)
      {
        throw UserError("--time and --frames: give one instant or one range of frames");
      }
      if (!this->Depth.empty())
      {
        throw UserError("--depth: a depth buffer is written for one picture, not with --frames");
      }
      if (!std::isfinite(this->Fps) || this->Fps < 0)
      {
        throw UserError("--fps must be a finite number >= 0 (0: 1/DT)");
      }
    }
    else
    {
      if (!HasExtension(this->Output, ".png"))
      {
        throw UserError("-o: '" + this->Output + "' is not a .png file" +
          (FrameOutput::IsFilm(this->Output) ? " (an .mp4 film needs --frames)" : ""));
      }
      if (!this->Depth.empty() && !HasExtension(this->Depth, ".vti"))
      {
        throw UserError("--depth: '" + this->Depth + "' is not a .vti file");
      }
    }
  }

  /// Reads --camera's file into LookAt (UserErrors name the file and the key).
  void ReadCamera()
  {
    const std::string& file = this->CameraFile;
    std::ifstream in(file);
    if (!in)
    {
      throw UserError("--camera: cannot read '" + file + "'");
    }
    nlohmann::json j;
    try
    {
      in >> j;
    }
    catch (const nlohmann::json::exception& e)
    {
      throw UserError("--camera: '" + file + "' is not JSON: " + e.what());
    }
    if (!j.is_object())
    {
      throw UserError("--camera: '" + file + "' is not a JSON object");
    }
    static const std::vector<std::string> keys{ "position", "focal_point", "up", "projection",
      "view_angle", "parallel_scale" };
    for (const auto& item : j.items())
    {
      if (std::find(keys.begin(), keys.end(), item.key()) == keys.end())
      {
        throw UserError("--camera: '" + file + "': unknown key '" + item.key() +
          "' (known: position, focal_point, up, projection, view_angle, parallel_scale)");
      }
    }
    auto point = [&](const char* key, std::optional<frep::Point3> fallback)
    {
      if (!j.contains(key))
      {
        if (!fallback)
        {
          throw UserError("--camera: '" + file + "' has no '" + key + "'");
        }
        return *fallback;
      }
      const nlohmann::json& v = j[key];
      if (!v.is_array() || v.size() != 3 ||
        !std::all_of(v.begin(), v.end(), [](const nlohmann::json& x) { return x.is_number(); }))
      {
        throw UserError("--camera: '" + file + "': '" + key + "' must be 3 numbers");
      }
      return frep::Point3{ v[0].get<double>(), v[1].get<double>(), v[2].get<double>() };
    };
    auto number = [&](const char* key, double fallback)
    {
      if (!j.contains(key))
      {
        return fallback;
      }
      if (!j[key].is_number())
      {
        throw UserError("--camera: '" + file + "': '" + key + "' must be a number");
      }
      return j[key].get<double>();
    };
    CameraSpec c;
    c.Position = point("position", std::nullopt);
    c.FocalPoint = point("focal_point", std::nullopt);
    c.Up = point("up", frep::Point3{ 0, 0, 1 });
    const std::string projection = j.value("projection", std::string("perspective"));
    if (projection == "orthographic")
    {
      c.Kind = render::Projection::Orthographic;
      if (!j.contains("parallel_scale"))
      {
        throw UserError("--camera: '" + file + "': an orthographic camera needs 'parallel_scale'");
      }
    }
    else if (projection != "perspective")
    {
      throw UserError("--camera: '" + file + "': projection must be perspective or orthographic");
    }
    c.ViewAngle = number("view_angle", render::PerspectiveFieldOfView);
    c.ParallelScale = number("parallel_scale", 0);
    this->LookAt = c;
    this->MakeCamera({}); // checks the values now, before any work
  }

  render::Camera MakeCamera(const frep::Box3& box) const
  {
    try
    {
      if (this->LookAt)
      {
        const CameraSpec& c = *this->LookAt;
        return render::Camera::lookAt(c.Position, c.FocalPoint, c.Up, c.Kind, c.ViewAngle,
          c.ParallelScale, this->Width, this->Height);
      }
      return render::Camera::orbit(box, this->Orbit, this->Kind, this->Width, this->Height);
    }
    catch (const std::invalid_argument& e)
    {
      throw UserError(std::string("cannot render '") + this->Model + "': " + e.what());
    }
  }

  /// Runs `draw`, turning the core's refusals into this command's errors.
  template <typename Draw>
  Drawn Guarded(Draw&& draw) const
  {
    try
    {
      return draw();
    }
    catch (const std::invalid_argument& e)
    {
      throw UserError(std::string("cannot render '") + this->Model + "': " + e.what());
    }
  }

  /// The FRep model to ray cast, in its box or --bounds'. An animated .blob is resolved at
  /// `times`' first (--time, or the first frame), its box then the union of its boxes at all.
  ResolvedModel ModelToDraw(const std::vector<double>& times) const
  {
    ResolvedModel model = ResolveModel(this->Model, ParseParameters(this->Params),
      times.empty() ? std::nullopt : std::optional<double>(times.front()));
    for (std::size_t k = 1; model.Animated && k < times.size(); ++k)
    {
      const ResolvedModel at = model.At(times[k]);
      for (int a = 0; a < 3; ++a)
      {
        model.Lo[a] = std::min(model.Lo[a], at.Lo[a]);
        model.Hi[a] = std::max(model.Hi[a], at.Hi[a]);
      }
    }
    if (!this->Bounds.empty())
    {
      ParseBounds(this->Bounds, model.Lo, model.Hi);
    }
    return model;
  }

  Drawn DrawModel(const ResolvedModel& model, const render::Camera& camera, double time,
    const Progress& progress) const
  {
    render::RayCastOptions options;
    options.parameters = ParseParameters(this->Params);
    options.time = time;
    options.threads = this->Threads;
    options.colours = this->Colours;
    options.progress = progress;
    const frep::Box3 box{ model.Lo, model.Hi };
    if (this->Mode == "mesh")
    {
      return Guarded(
        [&]
        {
          return FromCanvas(
            DrawMeshes(render::modelScene(model.Model, box, this->FeatureSize, options), camera,
              this->Colours));
        });
    }
    return Guarded([&] { return FromRayCast(render::rayCast(model.Model, box, camera, options)); });
  }

  Drawn DrawComplex(const complex::Complex& complex, const complex::ComplexMesh& mesh,
    const render::Camera& camera, const Progress& progress) const
  {
    render::ComplexRenderOptions options;
    options.threads = this->Threads;
    options.tubeRadius = this->TubeRadius;
    options.pointRadius = this->PointRadius;
    options.colours = this->Colours;
    options.progress = progress;
    if (this->Mode == "mesh")
    {
      return Guarded(
        [&]
        {
          return FromCanvas(DrawMeshes(
            render::scenePrimitives(complex, mesh, options, true), camera, this->Colours));
        });
    }
    return Guarded(
      [&] { return FromComplex(render::renderComplex(complex, mesh, camera, options)); });
  }

  engine::FrameSequenceOptions SequenceOptions(std::vector<double> times) const
  {
    engine::FrameSequenceOptions o;
    o.times = std::move(times);
    o.discretization.featureSize = this->FeatureSize;
    o.discretization.threads = this->Threads;
    if (this->Mode != "mesh")
    {
      // The solids given by fields are ray cast: their surfaces would be meshed for nothing.
      o.cells = render::meshedCells;
    }
    return o;
  }

  int RunPicture(bool complexFile, bool dynamic)
  {
    AtomicOutput picture(this->Output);
    std::optional<AtomicOutput> depthFile;
    if (!this->Depth.empty())
    {
      depthFile.emplace(this->Depth);
    }
    const auto t0 = Clock::now();
    Drawn drawn;
    std::string name = this->Model;
    if (complexFile || dynamic)
    {
      ProgressBar bar("rendering " + this->Model, true);
      auto show = [&](double lo, double hi)
      {
        return [&bar, lo, hi](double f)
        {
          bar.Show(lo + (hi - lo) * f);
          return !Interrupted();
        };
      };
      complex::Complex loaded;
      complex::ComplexMesh mesh;
      std::optional<engine::Frame> frame;
      if (dynamic)
      {
        const bool at = this->TimeOption->count() > 0;
        engine::FrameSequenceOptions o =
          this->SequenceOptions(at ? std::vector{ this->Time } : std::vector<double>{});
        o.progress = show(0, 0.5);
        engine::FrameSequence sequence(this->Model, std::move(o));
        if (at && this->Time < sequence.startTime())
        {
          std::ostringstream os;
          os << "--time: " << this->Time << " is before the model's start (" << sequence.startTime()
             << ")";
          throw UserError(os.str());
        }
        frame = sequence.frame(0);
      }
      else
      {
        loaded = LoadComplex(this->Model);
        this->Guarded(
          [&]
          {
            render::checkColours(loaded, this->Colours);
            return Drawn{};
          });
        complex::DiscretizationOptions o;
        o.featureSize = this->FeatureSize;
        o.threads = this->Threads;
        o.cells = render::meshedCells(loaded);
        if (this->Mode == "mesh")
        {
          o.cells = loaded.cellIds(); // the solids are drawn from their boundary meshes too
        }
        o.progress = show(0, 0.5);
        if (!o.cells.empty())
        {
          mesh = complex::discretizeComplex(loaded, o);
        }
      }
      const complex::Complex& scene = frame ? *frame->complex : loaded;
      const render::Camera camera = this->MakeCamera(complex::complexBounds(scene));
      drawn = this->DrawComplex(scene, frame ? frame->mesh : mesh, camera, show(0.5, 1));
      bar.End();
    }
    else
    {
      const ResolvedModel model = this->ModelToDraw(
        this->TimeOption->count() > 0 ? std::vector<double>{ this->Time } : std::vector<double>{});
      name = model.Name;
      const render::Camera camera = this->MakeCamera({ model.Lo, model.Hi });
      ProgressBar bar("rendering " + model.Name, true);
      drawn = this->DrawModel(model, camera, this->Time,
        [&](double f)
        {
          bar.Show(f);
          return !Interrupted();
        });
      bar.End();
      if (!this->PickAt.empty())
      {
        this->PrintPick(model, camera);
      }
    }
    const double seconds = Seconds(t0);
    WritePng(drawn.Buffers(), picture, this->Output);
    if (depthFile)
    {
      WriteDepth(drawn.Buffers(), *depthFile);
    }
    std::cout << "wrote " << this->Output << (depthFile ? " and " + this->Depth : std::string())
              << " (" << drawn.Width << " x " << drawn.Height << ", " << Describe(drawn) << ") in "
              << std::fixed << std::setprecision(3) << seconds << " s\n";
    Warn(drawn, name);
    return 0;
  }

  /// A .vtu tetrahedral mesh, cut open by --cut, coloured by --colour-by's cell or point array.
  int RunTetMesh()
  {
    std::optional<render::CutPlane> cut;
    if (!this->Cut.empty())
    {
      const std::vector<double> c =
        ParseNumbers(this->Cut, "--cut", { "nx", "ny", "nz", "d" }, 4, 4, "nx,ny,nz,d");
      if (c[0] == 0 && c[1] == 0 && c[2] == 0)
      {
        throw UserError("--cut: the plane's normal nx,ny,nz is zero");
      }
      cut = render::CutPlane{ { c[0], c[1], c[2] }, c[3] };
    }
    std::error_code ec;
    if (!std::filesystem::is_regular_file(this->Model, ec))
    {
      throw UserError("cannot read '" + this->Model + "'");
    }
    AtomicOutput picture(this->Output);
    std::optional<AtomicOutput> depthFile;
    if (!this->Depth.empty())
    {
      depthFile.emplace(this->Depth);
    }
    const auto t0 = Clock::now();
    vtkSmartPointer<vtkUnstructuredGrid> grid;
    try
    {
      grid = ictk::vtk::readUnstructuredGrid(this->Model);
    }
    catch (const std::invalid_argument& e)
    {
      throw UserError(e.what());
    }
    mesh::TetMesh m;
    try
    {
      m = ictk::vtk::tetMeshFromVTK(grid, this->Model);
    }
    catch (const std::invalid_argument& e)
    {
      throw UserError(std::string("render: ") + e.what());
    }
    render::TetPaint paint;
    // Without --colour-by, a mesh shows its materials: what a user opens a mesh of several to see.
    std::string colourBy = this->ColourBy;
    if (colourBy.empty())
    {
      for (const char* label : { "MaterialId", "label" })
      {
        vtkDataArray* a = grid->GetCellData()->GetArray(label);
        if (a && a->GetNumberOfComponents() == 1)
        {
          colourBy = label;
          break;
        }
      }
    }
    if (!colourBy.empty())
    {
      vtkDataArray* a = grid->GetCellData()->GetArray(colourBy.c_str());
      const bool perTetrahedron = a != nullptr;
      if (!a)
      {
        a = grid->GetPointData()->GetArray(colourBy.c_str());
      }
      if (!a)
      {
        std::string known;
        for (vtkDataSetAttributes* d : { static_cast<vtkDataSetAttributes*>(grid->GetCellData()),
               static_cast<vtkDataSetAttributes*>(grid->GetPointData()) })
        {
          for (int i = 0; i < d->GetNumberOfArrays(); ++i)
          {
            if (d->GetArray(i) && d->GetArrayName(i))
            {
              known += (known.empty() ? "" : ", ") + std::string(d->GetArrayName(i));
            }
          }
        }
        throw UserError("--colour-by: '" + this->Model + "' has no cell or point array '" +
          colourBy + "' (it has: " + (known.empty() ? std::string("none") : known) + ")");
      }
      if (a->GetNumberOfComponents() != 1)
      {
        throw UserError("--colour-by: the array '" + colourBy + "' of '" + this->Model + "' has " +
          std::to_string(a->GetNumberOfComponents()) +
          " components; a mesh is coloured by a scalar (1 component)");
      }
      std::vector<double>& values = perTetrahedron ? paint.perTetrahedron : paint.perPoint;
      values.resize(static_cast<std::size_t>(a->GetNumberOfTuples()));
      for (vtkIdType i = 0; i < a->GetNumberOfTuples(); ++i)
      {
        values[static_cast<std::size_t>(i)] = a->GetTuple1(i);
      }
    }
    // The camera looks at the whole mesh's box, so a cut does not move it.
    frep::Box3 box{ m.points[0], m.points[0] };
    for (const frep::Point3& p : m.points)
    {
      for (int a = 0; a < 3; ++a)
      {
        box.lo[a] = std::min(box.lo[a], p[a]);
        box.hi[a] = std::max(box.hi[a], p[a]);
      }
    }
    const render::Camera camera = this->MakeCamera(box);
    ProgressBar bar("rendering " + this->Model, true);
    Drawn drawn = this->Guarded(
      [&]
      {
        const render::TetFaces faces = render::tetrahedronFaces(m.points, m.tetrahedra, cut);
        this->KeptTetrahedra = faces.keptTetrahedra;
        const bool scalar = !paint.perPoint.empty() || !paint.perTetrahedron.empty();
        if (this->Mode == "mesh")
        {
          // The same faces and paints, drawn by VTK's OpenGL pipeline (the reference picture).
          render::ScenePrimitives scene;
          scene.scalar = scalar;
          scene.meshed.push_back(render::tetrahedronFacePrimitives(m.points, faces, paint));
          Drawn d = FromCanvas(DrawMeshes(scene, camera, this->Colours));
          if (scalar)
          {
            d.ScalarRange = MeshColourRange(scene, this->Colours);
          }
          return d;
        }
        render::Canvas canvas(this->Width, this->Height,
          scalar ? render::Canvas::Colouring::Scalar : render::Canvas::Colouring::Rgb);
        render::RasterOptions options;
        options.threads = this->Threads;
        options.progress = [&bar](double f)
        {
          bar.Show(f);
          return !Interrupted();
        };
        render::rasterize(
          canvas, camera, render::tetrahedronFacePrimitives(m.points, faces, paint), options);
        std::array<double, 2> range{ std::numeric_limits<double>::quiet_NaN(),
          std::numeric_limits<double>::quiet_NaN() };
        if (scalar)
        {
          range = render::finishColours(canvas, this->Colours);
        }
        Drawn d = FromCanvas(std::move(canvas));
        d.ScalarRange = range;
        return d;
      });
    bar.End();
    const double seconds = Seconds(t0);
    WritePng(drawn.Buffers(), picture, this->Output);
    if (depthFile)
    {
      WriteDepth(drawn.Buffers(), *depthFile);
    }
    std::cout << "wrote " << this->Output << (depthFile ? " and " + this->Depth : std::string())
              << " (" << drawn.Width << " x " << drawn.Height << ", " << this->KeptTetrahedra
              << " of " << m.tetrahedra.size() << " tetrahedra kept, " << Describe(drawn) << ") in "
              << std::fixed << std::setprecision(3) << seconds << " s\n";
    if (this->KeptTetrahedra == 0)
    {
      std::cerr << "ictk: warning: --cut leaves no tetrahedron of '" << this->Model
                << "'; the picture is empty (background only)\n";
    }
    else
    {
      Warn(drawn, this->Model);
    }
    return 0;
  }

  /// --pick: what the picture shows at one pixel (seed 003 item 38: the frontmost object's id).
  void PrintPick(const ResolvedModel& model, const render::Camera& camera) const
  {
    const std::vector<std::int64_t> xy = ParseIntegers(this->PickAt, "--pick", { "X", "Y" }, "X,Y");
    if (xy[0] < 0 || xy[0] >= this->Width || xy[1] < 0 || xy[1] >= this->Height)
    {
      throw UserError("--pick: " + this->PickAt + " is outside the " + std::to_string(this->Width) +
        " x " + std::to_string(this->Height) + " picture");
    }
    const bool scene = model.Model.findAttribute("object") != nullptr;
    render::RayCastOptions options;
    options.parameters = ParseParameters(this->Params);
    options.time = this->Time;
    options.threads = this->Threads;
    // Rows of the PNG count from the top; the core's from the bottom.
    const int i = static_cast<int>(xy[0]);
    const int j = this->Height - 1 - static_cast<int>(xy[1]);
    render::Pick p;
    try
    {
      p = render::pick(model.Model, { model.Lo, model.Hi }, camera, i, j,
        scene ? "object" : std::string(), options);
    }
    catch (const std::invalid_argument& e)
    {
      throw UserError(std::string("--pick: ") + e.what());
    }
    std::cout << "pick " << xy[0] << "," << xy[1] << ": ";
    if (!p.hit)
    {
      std::cout << "nothing (background)\n";
      return;
    }
    std::cout << std::setprecision(9) << "point " << p.point[0] << "," << p.point[1] << ","
              << p.point[2] << ", depth " << p.depth;
    if (scene && !p.values.empty())
    {
      std::cout << ", object " << p.values[0];
    }
    if (model.Model.findAttribute("perturbation"))
    {
      // Seed 003's Ctrl-click: the perturbation under the cursor (0: none).
      const render::Pick q =
        render::pick(model.Model, { model.Lo, model.Hi }, camera, i, j, "perturbation", options);
      std::cout << ", perturbation " << (q.values.empty() ? 0.0 : q.values[0]);
    }
    std::cout << "\n";
  }

  int RunFrames(bool dynamic)
  {
    const std::vector<double> times = ParseFrames(this->Frames);
    const double dt = times.size() > 1 ? times[1] - times[0] : 1.0;
    FrameOutput output(this->Output, this->Fps > 0 ? this->Fps : 1 / dt);
    const auto t0 = Clock::now();
    ProgressBar bar("rendering " + this->Model, true);
    std::size_t k = 0;
    auto show = [&](double lo, double hi)
    {
      return [&bar, &k, &times, lo, hi](double f)
      {
        bar.Show((double(k) + lo + (hi - lo) * f) / double(times.size()),
          "frame " + std::to_string(k + 1) + "/" + std::to_string(times.size()));
        return !Interrupted();
      };
    };
    std::size_t empty = 0;
    std::int64_t cut = 0;
    // A film's colours mean the same in every frame: the first frame's range, unless given.
    auto fixRange = [&](const Drawn& d)
    {
      if (k == 0 && std::isnan(this->Colours.range[0]) && !std::isnan(d.ScalarRange[0]))
      {
        this->Colours.range = d.ScalarRange;
      }
    };
    auto done = [&](const Drawn& d)
    {
      output.Write(k, d.Buffers());
      fixRange(d);
      empty += d.Covered == 0 ? 1 : 0;
      cut += d.Cut;
    };
    if (dynamic)
    {
      engine::FrameSequenceOptions o = this->SequenceOptions(times);
      o.progress = show(0, 0.5);
      engine::FrameSequence sequence(this->Model, std::move(o));
      if (times.front() < sequence.startTime())
      {
        std::ostringstream os;
        os << "--frames: T0 = " << times.front() << " is before the model's start ("
           << sequence.startTime() << ")";
        throw UserError(os.str());
      }
      // One camera for the whole film: it looks at the box of every frame's complex, found by
      // running the engine alone through the frames first (cheap beside their discretisation).
      engine::DynamicModel model = engine::DynamicModel::load(this->Model);
      frep::Box3 box = complex::complexBounds(model.complex());
      for (double t : times)
      {
        model.advanceTo(std::max(t, model.time()), sequence.maxStep());
        const frep::Box3 b = complex::complexBounds(model.complex());
        for (int a = 0; a < 3; ++a)
        {
          box.lo[a] = std::min(box.lo[a], b.lo[a]);
          box.hi[a] = std::max(box.hi[a], b.hi[a]);
        }
        if (Interrupted())
        {
          throw Cancelled();
        }
      }
      const render::Camera camera = this->MakeCamera(box);
      for (k = 0; k < times.size(); ++k)
      {
        const engine::Frame frame = sequence.frame(k);
        done(this->DrawComplex(*frame.complex, frame.mesh, camera, show(0.5, 1)));
      }
    }
    else
    {
      // One camera for the whole film: an animated .blob's box holds it at every frame.
      const ResolvedModel model = this->ModelToDraw(times);
      const render::Camera camera = this->MakeCamera({ model.Lo, model.Hi });
      for (k = 0; k < times.size(); ++k)
      {
        ResolvedModel frame = k > 0 ? model.At(times[k]) : model;
        frame.Lo = model.Lo;
        frame.Hi = model.Hi;
        done(this->DrawModel(frame, camera, times[k], show(0, 1)));
      }
    }
    const std::string written = output.Commit();
    bar.End();
    std::cout << "wrote " << written << " (" << times.size() << " frame(s), " << this->Width
              << " x " << this->Height << ") in " << std::fixed << std::setprecision(3)
              << Seconds(t0) << " s\n";
    if (cut > 0)
    {
      std::cerr << "ictk: warning: " << cut
                << " pixel(s) of the frames see the model cut open: their rays start inside a "
                   "solid (the camera is inside it, or a box cuts it)\n";
    }
    if (empty > 0)
    {
      std::cerr << "ictk: warning: " << empty
                << " frame(s) have nothing in view (background only)\n";
    }
    return 0;
  }

  static std::string Describe(const Drawn& d)
  {
    std::ostringstream os;
    os << d.Covered << " pixels covered";
    if (d.ByDimension)
    {
      const auto& n = *d.ByDimension;
      os << ": " << n[0] << " by 0D cells, " << n[1] << " 1D, " << n[2] << " 2D, " << n[3] << " 3D";
    }
    if (d.Unresolved > 0)
    {
      os << " (" << d.Unresolved << " unresolved)";
    }
    if (!d.Mesh)
    {
      os << ", " << std::fixed << std::setprecision(1) << d.IntervalsPerPixel
         << " interval evaluations per pixel";
    }
    if (!std::isnan(d.ScalarRange[0]))
    {
      os << std::defaultfloat << std::setprecision(6) << ", colour map over [" << d.ScalarRange[0]
         << ", " << d.ScalarRange[1] << "]";
    }
    return os.str();
  }

  static void Warn(const Drawn& d, const std::string& name)
  {
    if (d.Cut > 0 && d.ByDimension)
    {
      std::cerr << "ictk: warning: " << d.Cut << " pixel(s) see '" << name
                << "' from inside a 3D cell: the camera is inside its solid (move it with "
                   "--view's distance)\n";
    }
    else if (d.Cut > 0)
    {
      std::cerr << "ictk: warning: " << d.Cut << " pixel(s) see '" << name
                << "' cut open: their rays start inside the solid (the camera is inside it, or "
                   "the model's box cuts it)\n";
    }
    if (d.Covered == 0)
    {
      std::cerr << "ictk: warning: no surface of '" << name
                << "' is in view; the picture is empty (background only)\n";
    }
  }

  std::string Model;
  std::string Output;
  std::string Size = "800,600";
  std::string View;
  std::string Projection = "perspective";
  double Time = 0;
  CLI::Option* TimeOption = nullptr;
  std::string Frames;
  double Fps = 0;
  int Threads = 0;
  std::string Params;
  std::string ColourBy;
  std::string ColourMapName = "cool-warm";
  std::string Range;
  double TubeRadius = 0;
  double PointRadius = 0;
  double FeatureSize = 0;
  std::string Mode = "raycast";
  std::string Bounds;
  std::string Cut;
  std::int64_t KeptTetrahedra = 0;
  std::string CameraFile;
  CLI::Option* ViewOption = nullptr;
  CLI::Option* ProjectionOption = nullptr;
  struct CameraSpec
  {
    frep::Point3 Position{};
    frep::Point3 FocalPoint{};
    frep::Point3 Up{};
    render::Projection Kind = render::Projection::Perspective;
    double ViewAngle = 0;
    double ParallelScale = 0;
  };
  std::optional<CameraSpec> LookAt;
  std::string Depth;
  std::string PickAt;
  // Checked values.
  int Width = 0;
  int Height = 0;
  render::View Orbit;
  render::Projection Kind = render::Projection::Perspective;
  render::ColourOptions Colours;
};

} // namespace

std::unique_ptr<Command> renderCommand()
{
  return std::make_unique<RenderCommand>();
}

} // namespace ictk::cli
