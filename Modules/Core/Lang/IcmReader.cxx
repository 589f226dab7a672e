// SPDX-License-Identifier: BSD-3-Clause
#include "Lang/Icm.h"
#include "Lang/IcmParser.h"

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>

namespace ictk::lang
{

namespace
{

ParseError single(const std::string& file, int line, const std::string& message)
{
  Diagnostic d;
  d.where.file = file;
  d.where.line = line;
  d.message = message;
  return ParseError({ d });
}

IcmModel read(
  const std::string& text, const std::string& fileName, const Limits& limits, bool notation)
{
  if (text.size() > limits.maxFileBytes)
  {
    throw single(fileName, 1,
      "file is too large: " + std::to_string(text.size()) + " bytes, the limit is " +
        std::to_string(limits.maxFileBytes));
  }
  const std::size_t maxDiagnostics = limits.maxDiagnostics > 0 ? limits.maxDiagnostics : 1;
  hf::SourceText source(text, fileName);
  hf::DiagnosticSink sink(source, maxDiagnostics);
  IcmModel model = icm::parse(source, sink, limits, notation);
  if (!sink.empty())
  {
    throw ParseError(std::move(sink.diagnostics()));
  }
  if (!notation)
  {
    std::vector<Diagnostic> diagnostics;
    checkIcm(model, text, diagnostics, limits);
    if (!diagnostics.empty())
    {
      std::stable_sort(diagnostics.begin(), diagnostics.end(),
        [](const Diagnostic& a, const Diagnostic& b)
        {
          return a.where.line != b.where.line ? a.where.line < b.where.line
                                              : a.where.column < b.where.column;
        });
      throw ParseError(std::move(diagnostics));
    }
  }
  return model;
}

} // namespace

IcmModel readIcm(const std::string& text, const std::string& fileName, const Limits& limits)
{
  return read(text, fileName, limits, false);
}

IcmModel parseIcmNotation(
  const std::string& text, const std::string& fileName, const Limits& limits)
{
  return read(text, fileName, limits, true);
}

std::string modelFilePath(const IcmModel& model, const std::string& path)
{
  const std::filesystem::path p(path);
  if (p.is_absolute())
    return path;
  const std::filesystem::path folder = model.directory.empty()
    ? std::filesystem::path(model.fileName).parent_path()
    : std::filesystem::path(model.directory);
  return (folder / p).string();
}

IcmModel readIcmFile(const std::string& path, const Limits& limits)
{
  const std::string text = readSourceFile(path, limits);
  IcmModel model = readIcm(text, path, limits);
  model.directory = std::filesystem::path(path).parent_path().string();
  return model;
}

} // namespace ictk::lang
