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
  auto fail = [&](const std::string& message)
  {
    Diagnostic d;
    d.where.file = path;
    d.message = message;
    return ParseError({ d });
  };
  std::ifstream in(path, std::ios::binary);
  if (!in)
  {
    throw fail("cannot open the file");
  }
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  if (size < 0)
  {
    throw fail("cannot read the file");
  }
  // Refuse before reading, so that a huge file costs no memory.
  if (static_cast<std::uint64_t>(size) > limits.maxFileBytes)
  {
    throw fail("file is too large: " + std::to_string(size) + " bytes, the limit is " +
      std::to_string(limits.maxFileBytes));
  }
  in.seekg(0, std::ios::beg);
  std::string text(static_cast<std::size_t>(size), '\0');
  if (size > 0 && !in.read(text.data(), size))
  {
    throw fail("cannot read the file");
  }
  return readHyperFun(text, path, function, limits, parameterValues);
}

} // namespace ictk::lang
