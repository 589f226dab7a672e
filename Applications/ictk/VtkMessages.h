// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// VTK's error and warning texts collected instead of printed, so that a failure inside a VTK
// filter or writer becomes one "ictk: error:" line rather than VTK's multi-line reports (and the
// executive's follow-ups). Installed by main before any command runs; the readers of the VTK
// layer catch their own errors where they happen (Modules/VTK/Common/ictkErrorCapture.h).

#include <vtkOutputWindow.h>

#include <string>
#include <vector>

namespace ictk::cli
{

class ictkCaptureOutputWindow : public vtkOutputWindow
{
public:
  static ictkCaptureOutputWindow* New();
  vtkTypeMacro(ictkCaptureOutputWindow, vtkOutputWindow);

  void DisplayErrorText(const char* text) override;
  void DisplayWarningText(const char* text) override;
  void DisplayGenericWarningText(const char* text) override;
  void DisplayText(const char*) override {}

  /// The messages alone ("ERROR: In file, line N\nClass (0x...): message" -> "message").
  std::vector<std::string> Errors;
  std::vector<std::string> Warnings;

  /// What the errors recorded after the first `before` say went wrong (ictk::vtk::firstCause),
  /// "" when there are none.
  std::string FirstCause(std::size_t before) const;
};

/// Installs the capturing window (once) as VTK's output window and returns it. `verbose` (main's
/// --verbose, given once at start) also shows VTK's reports as VTK writes them, on stderr: those
/// that reach the window and those that ICTK's readers capture (ictkErrorCapture.h).
ictkCaptureOutputWindow* CaptureVtkMessages(bool verbose = false);

/// Throws a UserError "<what>: <message>" when VTK errors were recorded after the first `before`
/// ones (take `before` from Errors.size() ahead of the work), with the message of FirstCause.
void ThrowIfVtkFailed(
  const ictkCaptureOutputWindow* window, std::size_t before, const std::string& what);

} // namespace ictk::cli
