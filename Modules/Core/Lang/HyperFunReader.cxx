// SPDX-License-Identifier: BSD-3-Clause
#include "Lang/HyperFun.h"
#include "Lang/HyperFunCompiler.h"

#include <fstream>
#include <sstream>

namespace ictk::lang
{

HyperFunModel readHyperFun(const std::string& text, const std::string& fileName,
  const std::string& function, const Limits& limits, const std::vector<double>& parameterValues)
{
  hf::SourceText source(text, fileName);
  hf::DiagnosticSink sink(source, limits.maxDiagnostics > 0 ? limits.maxDiagnostics : 1);
  if (text.size() > limits.maxFileBytes)
  {
    Diagnostic d;
    d.where.file = fileName;
    d.where.line = 1;
    d.message = "file is too large: " + std::to_string(text.size()) + " bytes, the limit is " +
      std::to_string(limits.maxFileBytes);
    throw ParseError({ d });
  }
  const hf::Program program = hf::parse(source, sink, limits);
  if (!sink.empty())
  {
    throw ParseError(std::move(sink.diagnostics()));
  }
  HyperFunModel model = hf::compile(program, sink, function, limits, parameterValues);
  if (!sink.empty())
  {
    throw ParseError(std::move(sink.diagnostics()));
  }
  return model;
}

HyperFunModel readHyperFunFile(const std::string& path, const std::string& function,
  const Limits& limits, const std::vector<double>& parameterValues)
{
  const std::string text = readSourceFile(path, limits);
  return readHyperFun(text, path, function, limits, parameterValues);
}

} // namespace ictk::lang
