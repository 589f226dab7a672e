// SPDX-License-Identifier: BSD-3-Clause
#include "VtkMessages.h"

#include "Command.h"

#include <vtkObjectFactory.h>
#include <vtkSmartPointer.h>

namespace ictk::cli
{
namespace
{

/// "ERROR: In file, line N\nClass (0x...): message\n\n" -> "message".
std::string Message(const char* text)
{
  std::string s = text ? text : "";
  const auto header = s.find('\n');
  if (s.rfind("ERROR: In ", 0) == 0 || s.rfind("Warning: In ", 0) == 0)
  {
    s = header == std::string::npos ? s : s.substr(header + 1);
  }
  const auto object = s.find("): ");
  if (object != std::string::npos && s.find(" (") < object)
  {
    s = s.substr(object + 3);
  }
  while (!s.empty() && (s.back() == '\n' || s.back() == ' '))
  {
    s.pop_back();
  }
  return s;
}

} // namespace

vtkStandardNewMacro(ictkCaptureOutputWindow);

void ictkCaptureOutputWindow::DisplayErrorText(const char* text)
{
  this->Errors.push_back(Message(text));
}

void ictkCaptureOutputWindow::DisplayWarningText(const char* text)
{
  this->Warnings.push_back(Message(text));
}

void ictkCaptureOutputWindow::DisplayGenericWarningText(const char* text)
{
  this->Warnings.push_back(Message(text));
}

ictkCaptureOutputWindow* CaptureVtkMessages()
{
  static vtkSmartPointer<ictkCaptureOutputWindow> window;
  if (!window)
  {
    window = vtkSmartPointer<ictkCaptureOutputWindow>::New();
    vtkOutputWindow::SetInstance(window);
  }
  return window;
}

void ThrowIfVtkFailed(
  const ictkCaptureOutputWindow* window, std::size_t before, const std::string& what)
{
  if (window->Errors.size() > before)
  {
    throw UserError(what + ": " + window->Errors[before]);
  }
}

} // namespace ictk::cli
