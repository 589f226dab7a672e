// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// VTK's errors caught where they happen, so that a reader or filter that fails inside VTK becomes
// one ICTK message naming the file and what was wrong, instead of VTK's multi-line reports (the
// object's address, the source line, the executive's vtkInformation listing) on stderr. An object
// with an ErrorEvent observer does not print its errors (vtkOutputWindowDisplayErrorText invokes
// the event instead), so observing the algorithm, its executive and any helper it reports through
// is enough. Not wrapped, not installed: part of ICTK::VTKRequest.

#include "vtkAlgorithm.h"
#include "vtkCallbackCommand.h"
#include "vtkCommand.h"
#include "vtkExecutive.h"
#include "vtkLogger.h"
#include "vtkNew.h"
#include "vtkObject.h"
#include "vtkSmartPointer.h"

#include <string>
#include <utility>
#include <vector>

namespace ictk::vtk
{

/// VTK's report "ERROR: In file, line N\nClass (0x...): message\n\n" as its message alone.
inline std::string vtkMessageText(const char* text)
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

/// The first of `errors` that says what went wrong, "" when none does: the executive's
/// follow-up ("Algorithm X (0x...) returned failure for request: vtkInformation ...") only
/// repeats that an algorithm failed, and a writer's "; deleting file: <path>" tail names the
/// temporary file ICTK wrote through, which the user never sees.
inline std::string firstCause(const std::vector<std::string>& errors)
{
  for (const std::string& e : errors)
  {
    if (e.find("returned failure for request") == std::string::npos)
    {
      return e.substr(0, e.find("; deleting file"));
    }
  }
  return {};
}

/// The vtkLogger verbosity at which captured reports are logged: off by default, shown by
/// `ictk --verbose` (VTK's pipeline traces, at VERBOSITY_TRACE, stay hidden).
constexpr vtkLogger::Verbosity ReportVerbosity = vtkLogger::VERBOSITY_5;

/// Collects the errors and warnings of the watched objects while it lives (their full reports in
/// Reports, for a --verbose display). Observers are removed on destruction.
class ErrorCapture
{
public:
  ErrorCapture()
  {
    this->Callback->SetClientData(this);
    this->Callback->SetCallback(
      [](vtkObject*, unsigned long event, void* self, void* text)
      {
        auto* capture = static_cast<ErrorCapture*>(self);
        const char* report = static_cast<const char*>(text);
        capture->Reports.emplace_back(report ? report : "");
        // Kept for whoever asks for VTK's own text (`ictk --verbose` raises stderr's verbosity).
        vtkVLog(ReportVerbosity, << capture->Reports.back());
        (event == vtkCommand::ErrorEvent ? capture->Errors : capture->Warnings)
          .push_back(vtkMessageText(report));
      });
  }
  ErrorCapture(const ErrorCapture&) = delete;
  ErrorCapture& operator=(const ErrorCapture&) = delete;
  ~ErrorCapture()
  {
    for (auto& [object, tags] : this->Watched)
    {
      object->RemoveObserver(tags.first);
      object->RemoveObserver(tags.second);
    }
  }

  /// Observes `object`'s errors and warnings.
  void Watch(vtkObject* object)
  {
    if (object)
    {
      this->Watched.emplace_back(object,
        std::make_pair(object->AddObserver(vtkCommand::ErrorEvent, this->Callback),
          object->AddObserver(vtkCommand::WarningEvent, this->Callback)));
    }
  }

  /// Observes an algorithm and its executive (which reports "returned failure for request").
  void WatchAlgorithm(vtkAlgorithm* algorithm)
  {
    this->Watch(algorithm);
    this->Watch(algorithm->GetExecutive());
  }

  /// The command that records into this capture, for APIs that take an observer
  /// (vtkXMLReader::SetParserErrorObserver).
  vtkCommand* Observer() { return this->Callback; }

  std::vector<std::string> Errors;
  std::vector<std::string> Warnings;
  /// VTK's reports as it made them, in order.
  std::vector<std::string> Reports;

private:
  vtkNew<vtkCallbackCommand> Callback;
  std::vector<std::pair<vtkSmartPointer<vtkObject>, std::pair<unsigned long, unsigned long>>>
    Watched;
};

} // namespace ictk::vtk
