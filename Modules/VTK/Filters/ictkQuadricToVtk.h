// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// A seed 003 quadric (eq. 1, frep::quadric's ten coefficients) as VTK's vtkQuadric (not wrapped),
// papers.md 5.B item 25: VTK orders the cross terms xy, yz, xz (seed 003: xy, xz, yz) and is
// negative inside (FRep: F >= 0 inside), so a0..a9 = -(A11, A22, A33, A12, A23, A13, A14, A24,
// A34, A44) and the VTK value is -F.

#include "ictkFiltersFRepModule.h" // export macro
#include "vtkSmartPointer.h"

#include <array>

class vtkQuadric;

ICTKFILTERSFREP_EXPORT vtkSmartPointer<vtkQuadric> ictkQuadricToVtk(
  const std::array<double, 10>& coefficients);
