// SPDX-License-Identifier: BSD-3-Clause
#include "VtkMessages.h"

#include "Command.h"

#include "ictkErrorCapture.h"

#include <vtkLogger.h>
#include <vtkObjectFactory.h>
#include <vtkSmartPointer.h>

namespace ictk::cli
{

vtkStandardNewMacro(ictkCaptureOutputWindow);

void ictkCaptureOutputWindow::DisplayErrorText(const char* text)
{
  this->Errors.push_back(ictk::vtk::vtkMessageText(text));
}

void ictkCaptureOutputWindow::DisplayWarningText(const char* text)
{
  this->Warnings.push_back(ictk::vtk::vtkMessageText(text));
}

void ictkCaptureOutputWindow::DisplayGenericWarningText(const char* text)
{
  this->Warnings.push_back(ictk::vtk::vtkMessageText(text));
}

ictkCaptureOutputWindow* CaptureVtkMessages(bool verbose)
{
  static vtkSmartPointer<ictkCaptureOutputWindow> window;
  if (!window)
  {
    window = vtkSmartPointer<ictkCaptureOutputWindow>::New();
    vtkOutputWindow::SetInstance(window);
    // VTK >= 9.1 also logs every error through vtkLogger to stderr, besides the output window:
    // that log is VTK's text, shown only when asked for.
    vtkLogger::SetStderrVerbosity(verbose ? ictk::vtk::ReportVerbosity : vtkLogger::VERBOSITY_OFF);
  }
  return window;
}

std::string ictkCaptureOutputWindow::FirstCause(std::size_t before) const
{
  if (this->Errors.size() <= before)
  {
    return {};
  }
  const std::string cause = ictk::vtk::firstCause(std::vector<std::string>(
    this->Errors.begin() + static_cast<std::ptrdiff_t>(before), this->Errors.end()));
  return cause.empty() ? "VTK failed without saying why (--verbose shows its report)" : cause;
}

void ThrowIfVtkFailed(
  const ictkCaptureOutputWindow* window, std::size_t before, const std::string& what)
{
  if (window->Errors.size() > before)
  {
    throw UserError(what + ": " + window->FirstCause(before));
  }
}

} // namespace ictk::cli
