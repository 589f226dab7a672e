// SPDX-License-Identifier: BSD-3-Clause
// `ictk mesh`: a model's surface f = 0 extracted on a uniform grid (Flying Edges) as .vtp, .stl,
// .ply or .obj; or a complex (.json, or any input written as .vtpc / .vtm) discretised cell by
// cell, by dimension.
#include "Command.h"
#include "GridSampling.h"
#include "Models.h"
#include "Options.h"
#include "Output.h"
#include "ProgressDisplay.h"
#include "VtkMessages.h"

#include "ictkComplexSource.h"
#include "ictkComplexToVTK.h"

#include <vtkImageData.h>
#include <vtkMultiBlockDataSet.h>
#include <vtkNew.h>
#include <vtkPartitionedDataSetCollection.h>
#include <vtkPolyData.h>
#include <vtkXMLMultiBlockDataWriter.h>
#include <vtkXMLPartitionedDataSetCollectionWriter.h>

#include <CLI/CLI.hpp>

#include <chrono>
#include <iomanip>
#include <iostream>
#include <memory>

namespace ictk::cli
{
namespace
{

class MeshCommand final : public Command
{
public:
  CLI::App* add(CLI::App& app) override
  {
    CLI::App* mesh = app.add_subcommand("mesh",
      "Extract the surface f = 0 on a uniform grid (Flying Edges) as .vtp, .stl, .ply or .obj, "
      "or discretise a complex (.json) by cell dimension into .vtpc or .vtm");
    o.AddTo(mesh, 128);
    AddOutput(mesh, o.Output, "Output surface (.vtp, .stl, .ply, .obj) or complex (.vtpc, .vtm)");
    AddSize(mesh, this->Size,
      "Complexes: mesh edge length and curve step (default: 1/64 of the complex's size)");
    mesh->add_option("--volume-resolution", this->VolumeResolution,
      "Complexes: also sample each implicit 3D cell's field on N^3 points (vtkImageData)");
    return mesh;
  }

  int run() override
  {
    if (IsComplexInput(o.Model) || IsComplexOutput(o.Output))
    {
      return this->MeshComplex();
    }
    return this->MeshSurface();
  }

private:
  int MeshSurface()
  {
    if (!IsSurfaceFormat(o.Output))
    {
      throw UserError("-o: '" + o.Output + "' is not a " + SurfaceFormats + " file");
    }
    const GridPlan plan = PlanGrid(o, sizeof(float));
    CheckSurfaceGrid(plan, o.Output, "-o");
    InterruptScope interrupts;
    AtomicOutput file(o.Output);
    ictkCaptureOutputWindow* messages = CaptureVtkMessages();
    const auto t0 = std::chrono::steady_clock::now();
    // The attributes are evaluated on the surface itself; the grid needs only f.
    vtkSmartPointer<vtkImageData> image = SampleImage(plan, o.Threads, false, false, messages);
    if (!image)
    {
      std::cerr << "ictk: interrupted; nothing written\n";
      return ExitInterrupted;
    }
    vtkSmartPointer<vtkPolyData> surface = ExtractSurface(image, plan, messages);
    WriteSurface(surface, file, o.Output, messages);
    std::cout << "wrote " << o.Output << " (" << SurfaceSummary(surface) << " from a "
              << plan.Dims[0] << " x " << plan.Dims[1] << " x " << plan.Dims[2] << " grid) in "
              << std::fixed << std::setprecision(3) << Seconds(t0) << " s\n";
    return 0;
  }

  int MeshComplex()
  {
    if (!IsComplexOutput(o.Output))
    {
      throw UserError("-o: a complex is written as .vtpc or .vtm, not '" + o.Output + "'");
    }
    CheckSize(this->Size);
    CheckThreads(o.Threads);
    const auto t0 = std::chrono::steady_clock::now();
    auto k = std::make_shared<const complex::Complex>(LoadComplex(o.Model));
    vtkNew<ictkComplexSource> source;
    source->SetComplex(k);
    source->SetFeatureSize(this->Size);
    source->SetNumberOfThreads(o.Threads);
    source->SetVolumeResolution(this->VolumeResolution);
    // The source reports failures as VTK errors; the first one becomes our own error line.
    ictkCaptureOutputWindow* messages = CaptureVtkMessages();
    const std::size_t errorsBefore = messages->Errors.size();
    source->Update();
    if (messages->Errors.size() > errorsBefore ||
      source->GetOutput()->GetNumberOfPartitionedDataSets() == 0)
    {
      const std::string failure = messages->FirstCause(errorsBefore);
      throw UserError("cannot discretise '" + o.Model + "'" +
        (failure.empty() ? std::string() : ": " + failure) + "; nothing written");
    }
    vtkPartitionedDataSetCollection* pdc = source->GetOutput();
    if (HasExtension(o.Output, ".vtpc"))
    {
      vtkNew<vtkXMLPartitionedDataSetCollectionWriter> writer;
      WriteComposite(writer, pdc, o.Output);
    }
    else
    {
      vtkNew<vtkMultiBlockDataSet> blocks;
      ictk::vtk::complexToMultiBlock(pdc, blocks);
      vtkNew<vtkXMLMultiBlockDataWriter> writer;
      WriteComposite(writer, blocks, o.Output);
    }
    std::cout << "wrote " << o.Output << " (" << pdc->GetNumberOfPartitionedDataSets()
              << " cells) in " << std::fixed << std::setprecision(3) << Seconds(t0) << " s\n";
    return 0;
  }

  GridCommandOptions o;
  double Size = 0;
  int VolumeResolution = 0;
};

} // namespace

std::unique_ptr<Command> meshCommand()
{
  return std::make_unique<MeshCommand>();
}

} // namespace ictk::cli
