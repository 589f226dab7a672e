// SPDX-License-Identifier: BSD-3-Clause
#include "ictkQuadricToVtk.h"

#include "vtkQuadric.h"

vtkSmartPointer<vtkQuadric> ictkQuadricToVtk(const std::array<double, 10>& a)
{
  // Seed 003's order: A11 A22 A33 A12 A13 A23 A14 A24 A34 A44; VTK's: x2 y2 z2 xy yz xz x y z 1.
  static constexpr std::size_t order[10] = { 0, 1, 2, 3, 5, 4, 6, 7, 8, 9 };
  double v[10];
  for (std::size_t i = 0; i < 10; ++i)
  {
    v[i] = -a[order[i]];
  }
  auto quadric = vtkSmartPointer<vtkQuadric>::New();
  quadric->SetCoefficients(v);
  return quadric;
}
