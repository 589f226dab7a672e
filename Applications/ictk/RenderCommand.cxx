// SPDX-License-Identifier: BSD-3-Clause
// `ictk render`: a picture of an FRep model (a registered name, .hf, .xml, .vm) ray-cast by the
// core (Render/RayCast.h) and written as PNG through VTK's writer, with its depth buffer as .vti
// on request. Complexes (.json, .icm) are refused until their rendering exists (issue 14).
#include "Command.h"
#include "Models.h"
#include "Options.h"
#include "Output.h"
#include "ProgressDisplay.h"
#include "VtkMessages.h"

#include "Render/RayCast.h"

#include <vtkDoubleArray.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGWriter.h>
#include <vtkPointData.h>
#include <vtkUnsignedCharArray.h>
#include <vtkXMLImageDataWriter.h>

#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
#include <type_traits>

namespace ictk::cli
{
namespace
{

/// An image of width x height pixels, one point per pixel, row 0 at the bottom (the core's order).
vtkSmartPointer<vtkImageData> PixelImage(int width, int height)
{
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->SetDimensions(width, height, 1);
  return image;
}

/// Runs a VTK writer on `file`'s temporary path and commits it; a failure is a UserError.
template <typename Writer>
void Write(Writer* writer, vtkImageData* image, AtomicOutput& file, const std::string& path)
{
  ictkCaptureOutputWindow* messages = CaptureVtkMessages();
  const std::size_t errorsBefore = messages->Errors.size();
  if constexpr (std::is_base_of_v<vtkXMLWriter, Writer>)
  {
    WriteXml(writer, image, file);
  }
  else
  {
    writer->SetInputData(image);
    writer->SetFileName(file.Path().c_str());
    writer->Write();
  }
  ThrowIfVtkFailed(messages, errorsBefore, "cannot write '" + path + "'");
  if (writer->GetErrorCode() != 0)
  {
    throw UserError("cannot write '" + path + "'");
  }
  file.Commit();
}

class RenderCommand final : public Command
{
public:
  CLI::App* add(CLI::App& app) override
  {
    CLI::App* render = app.add_subcommand("render",
      "Ray-cast an FRep model into a PNG picture (and its depth buffer), see docs/render.md");
    AddModel(render, this->Model, "Model name (see `ictk models`) or a .hf / .xml / .vm file");
    AddOutput(render, this->Output, "Output picture (.png)");
    render->add_option(
      "--size", this->Size, "Image size W,H in pixels, 1..4096 each (default 800,600)");
    render->add_option("--view", this->View,
      "Camera: azimuth,elevation[,distance]: degrees about +z from +x, degrees above the "
      "xy-plane, distance from the centre of the model's box (default 30,20 and 2.5 times the "
      "box's half-diagonal)");
    render->add_option(
      "--projection", this->Projection, "perspective (default; 30 degrees high) or orthographic");
    AddTime(render, this->Time);
    AddThreads(render, this->Threads);
    AddParams(render, this->Params);
    render->add_option("--depth", this->Depth,
      "Also write the depth buffer (distance along each pixel's ray, inf where nothing is hit) "
      "as .vti");
    return render;
  }

  int run() override
  {
    if (IsComplexInput(this->Model) || HasExtension(this->Model, ".icm"))
    {
      throw UserError("render: '" + this->Model +
        "' is a complex; rendering complexes (.json, .icm) is not implemented yet: give an FRep "
        "model (a registered name, .hf, .xml or .vm)");
    }
    if (!HasExtension(this->Output, ".png"))
    {
      throw UserError("-o: '" + this->Output + "' is not a .png file");
    }
    if (!this->Depth.empty() && !HasExtension(this->Depth, ".vti"))
    {
      throw UserError("--depth: '" + this->Depth + "' is not a .vti file");
    }
    const std::vector<std::int64_t> size = ParseIntegers(this->Size, "--size", { "W", "H" }, "W,H");
    for (int a = 0; a < 2; ++a)
    {
      if (size[a] < 1 || size[a] > render::MaxImageSize)
      {
        throw UserError(std::string("--size: ") + (a == 0 ? "W" : "H") + " must be in 1.." +
          std::to_string(render::MaxImageSize) + ", got " + std::to_string(size[a]));
      }
    }
    render::View view;
    if (!this->View.empty())
    {
      const std::vector<double> v =
        ParseNumbers(this->View, "--view", { "azimuth", "elevation", "distance" }, 2, 3,
          "azimuth,elevation or azimuth,elevation,distance");
      view.azimuth = v[0];
      view.elevation = v[1];
      if (v.size() == 3)
      {
        if (!(v[2] > 0))
        {
          throw UserError("--view: the distance must be positive, got " + std::to_string(v[2]));
        }
        view.distance = v[2];
      }
    }
    render::Projection projection = render::Projection::Perspective;
    if (this->Projection == "orthographic")
    {
      projection = render::Projection::Orthographic;
    }
    else if (this->Projection != "perspective")
    {
      throw UserError(
        "--projection must be perspective or orthographic, got '" + this->Projection + "'");
    }
    if (!std::isfinite(this->Time))
    {
      throw UserError("--time must be a finite number");
    }
    CheckThreads(this->Threads);

    render::RayCastOptions options;
    options.parameters = ParseParameters(this->Params);
    options.time = this->Time;
    options.threads = this->Threads;
    const ResolvedModel model = ResolveModel(this->Model, options.parameters);
    const frep::Box3 box{ model.Lo, model.Hi };
    const int width = static_cast<int>(size[0]), height = static_cast<int>(size[1]);
    std::optional<render::Camera> camera;
    try
    {
      camera = render::Camera::orbit(box, view, projection, width, height);
    }
    catch (const std::invalid_argument& e)
    {
      throw UserError(std::string("cannot render '") + this->Model + "': " + e.what());
    }

    AtomicOutput picture(this->Output);
    std::optional<AtomicOutput> depthFile;
    if (!this->Depth.empty())
    {
      depthFile.emplace(this->Depth);
    }
    InterruptScope interrupts;
    ProgressBar progress("rendering " + model.Name, true);
    options.progress = [&](double fraction)
    {
      progress.Show(fraction);
      return !Interrupted();
    };
    const auto t0 = std::chrono::steady_clock::now();
    render::RayCastResult result;
    try
    {
      result = render::rayCast(model.Model, box, *camera, options);
    }
    catch (const Cancelled&)
    {
      progress.End();
      std::cerr << "ictk: interrupted; nothing written\n";
      return ExitInterrupted;
    }
    catch (const std::invalid_argument& e)
    {
      progress.End();
      throw UserError(std::string("cannot render '") + this->Model + "': " + e.what());
    }
    progress.End();
    const double seconds = Seconds(t0);

    vtkSmartPointer<vtkImageData> image = PixelImage(width, height);
    vtkNew<vtkUnsignedCharArray> rgba;
    rgba->SetName("colour");
    rgba->SetNumberOfComponents(4);
    rgba->SetNumberOfTuples(static_cast<vtkIdType>(width) * height);
    std::copy(result.colour.begin(), result.colour.end(), rgba->GetPointer(0));
    image->GetPointData()->SetScalars(rgba);
    vtkNew<vtkPNGWriter> png;
    Write(png.Get(), image, picture, this->Output);
    if (depthFile)
    {
      vtkSmartPointer<vtkImageData> depthImage = PixelImage(width, height);
      vtkNew<vtkDoubleArray> depth;
      depth->SetName("depth");
      depth->SetNumberOfTuples(static_cast<vtkIdType>(width) * height);
      std::copy(result.depth.begin(), result.depth.end(), depth->GetPointer(0));
      depthImage->GetPointData()->SetScalars(depth);
      vtkNew<vtkXMLImageDataWriter> xml;
      xml->SetDataModeToAppended();
      xml->EncodeAppendedDataOff();
      Write(xml.Get(), depthImage, *depthFile, this->Depth);
    }

    const double pixels = static_cast<double>(width) * height;
    std::cout << "wrote " << this->Output << (depthFile ? " and " + this->Depth : std::string())
              << " (" << width << " x " << height << ", " << result.coveredPixels
              << " pixels covered"
              << (result.unresolvedPixels > 0
                     ? " (" + std::to_string(result.unresolvedPixels) + " unresolved)"
                     : std::string())
              << ", " << std::fixed << std::setprecision(1) << result.intervalEvaluations / pixels
              << " interval evaluations per pixel) in " << std::setprecision(3) << seconds
              << " s\n";
    if (result.cutPixels > 0)
    {
      std::cerr << "ictk: warning: " << result.cutPixels << " pixel(s) see '" << model.Name
                << "' cut open: their rays start inside the solid (the camera is inside it, or "
                   "the model's box cuts it)\n";
    }
    if (result.coveredPixels == 0)
    {
      std::cerr << "ictk: warning: no surface of '" << model.Name
                << "' is in view; the picture is empty (background only)\n";
    }
    return 0;
  }

private:
  std::string Model;
  std::string Output;
  std::string Size = "800,600";
  std::string View;
  std::string Projection = "perspective";
  double Time = 0;
  int Threads = 0;
  std::string Params;
  std::string Depth;
};

} // namespace

std::unique_ptr<Command> renderCommand()
{
  return std::make_unique<RenderCommand>();
}

} // namespace ictk::cli
