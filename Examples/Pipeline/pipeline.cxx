// SPDX-License-Identifier: BSD-3-Clause
// A VTK pipeline over an installed ICTK: model -> sampler -> contour -> writer.
//   pipeline MODEL OUTPUT.vtp [RESOLUTION]     (MODEL: a registered name or a .hf/.xml/.vm file)
#include <ictkFRepSampler.h>
#include <vtkFlyingEdges3D.h>
#include <vtkNew.h>
#include <vtkXMLPolyDataWriter.h>

#include <cstdlib>
#include <iostream>
#include <string>

int main(int argc, char* argv[])
{
  if (argc < 3)
  {
    std::cerr << "usage: pipeline MODEL OUTPUT.vtp [RESOLUTION]\n";
    return 2;
  }
  const std::string model = argv[1];
  const int n = argc > 3 ? std::atoi(argv[3]) : 64;
  vtkNew<ictkFRepSampler> sampler;
  if (ictkFRepSampler::CanReadFile(model.c_str()))
  {
    sampler->SetFileName(model.c_str());
  }
  else
  {
    sampler->SetModelName(model.c_str());
  }
  sampler->SetSampleDimensions(n, n, n);
  vtkNew<vtkFlyingEdges3D> contour; // the surface f = 0 (f >= 0 inside)
  contour->SetInputConnection(sampler->GetOutputPort());
  contour->SetValue(0, 0.0);
  vtkNew<vtkXMLPolyDataWriter> writer;
  writer->SetInputConnection(contour->GetOutputPort());
  writer->SetFileName(argv[2]);
  if (writer->Write() != 1)
  {
    return 1;
  }
  std::cout << contour->GetOutput()->GetNumberOfCells() << " triangles\n";
  return 0;
}
