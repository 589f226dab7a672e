// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// What every ICTK algorithm does around its work, in one place (not wrapped, not installed):
// progress goes to UpdateProgress, AbortExecute is the cancel request, and the outcome of the
// work becomes VTK's: a cancellation leaves an empty output and succeeds (as VTK's own filters
// do on abort), an error is reported with vtkErrorMacro's text and fails the request, leaving an
// empty output rather than a half-made one.

#include "FRep/Sampling.h" // ictk::frep::Cancelled

#include "vtkAlgorithm.h"
#include "vtkDataObject.h"
#include "vtkSetGet.h"

#include <functional>
#include <new>
#include <stdexcept>

namespace ictk::vtk
{

/// A progress callback for the core's option structs: the core's fraction in [0, 1] is reported
/// as lo + (hi - lo) * fraction; it returns false (cancel) once AbortExecute is set.
inline std::function<bool(double)> progressOf(vtkAlgorithm* self, double lo = 0, double hi = 1)
{
  return [self, lo, hi](double fraction)
  {
    self->UpdateProgress(lo + (hi - lo) * fraction);
    return !self->GetAbortExecute();
  };
}

/// Runs `work` (returning 1 or 0, as RequestData does) with the outcomes above.
template <typename Work>
int runRequest(vtkAlgorithm* self, vtkDataObject* output, Work&& work)
{
  try
  {
    return work();
  }
  catch (const ictk::frep::Cancelled&)
  {
    if (output)
    {
      output->Initialize();
    }
    return 1;
  }
  catch (const std::bad_alloc&)
  {
    vtkErrorWithObjectMacro(self, "out of memory");
  }
  catch (const std::exception& e)
  {
    vtkErrorWithObjectMacro(self, "" << e.what());
  }
  if (output)
  {
    output->Initialize();
  }
  return 0;
}

} // namespace ictk::vtk
