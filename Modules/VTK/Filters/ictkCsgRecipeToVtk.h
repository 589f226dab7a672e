// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// VTK's own form of a bundled CSG recipe (not wrapped): vtkSphere, vtkBox and vtkCylinder
// combined by vtkImplicitBoolean, negative inside as VTK's implicit functions are. It is the
// baseline the benchmarks time ICTK's sampling against in the same process.

#include "FRep/BundledModels.h"
#include "ictkFiltersFRepModule.h" // export macro
#include "vtkSmartPointer.h"

class vtkImplicitFunction;

/// The recipe's root as a native VTK implicit function.
ICTKFILTERSFREP_EXPORT vtkSmartPointer<vtkImplicitFunction> ictkCsgRecipeToVtk(
  const ictk::frep::bundled::CsgRecipe& recipe);
