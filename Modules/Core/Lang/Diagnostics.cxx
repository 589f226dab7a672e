// SPDX-License-Identifier: BSD-3-Clause
#include "Lang/Diagnostics.h"

#include <cerrno>
#include <cstring>
#include <fstream>

namespace ictk::lang
{

namespace
{
std::string joinAll(const std::vector<Diagnostic>& diagnostics)
{
  std::string all;
  for (const Diagnostic& d : diagnostics)
  {
    if (!all.empty())
    {
      all += '\n';
    }
    all += formatDiagnostic(d);
  }
  return all.empty() ? std::string("error") : all;
}
} // namespace

std::string formatDiagnostic(const Diagnostic& d)
{
  std::string out = d.where.file.empty() ? std::string("<input>") : d.where.file;
  if (d.where.line > 0)
  {
    out += ':' + std::to_string(d.where.line);
    if (d.where.column > 0)
    {
      out += ':' + std::to_string(d.where.column);
    }
  }
  out += ": error: " + d.message;
  if (d.where.line > 0 && d.where.column > 0 && !d.sourceLine.empty())
  {
    out += '\n' + d.sourceLine + '\n';
    // Tabs are copied so that the caret lines up however the terminal expands them.
    const auto col = static_cast<std::size_t>(d.where.column);
    for (std::size_t i = 0; i + 1 < col; ++i)
    {
      out += (i < d.sourceLine.size() && d.sourceLine[i] == '\t') ? '\t' : ' ';
    }
    out += '^';
  }
  return out;
}

ParseError::ParseError(std::vector<Diagnostic> diagnostics)
  : std::runtime_error(joinAll(diagnostics))
  , diagnostics_(std::move(diagnostics))
{
}

std::string readSourceFile(const std::string& path, const Limits& limits)
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
    throw fail("cannot open the file: " + std::string(std::strerror(errno)));
  }
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  if (size < 0)
  {
    throw fail("cannot read the file");
  }
  if (static_cast<std::uint64_t>(size) > limits.maxFileBytes)
  {
    throw fail("the file is too large: " + std::to_string(size) +
      " bytes, more than the limit of " + std::to_string(limits.maxFileBytes));
  }
  in.seekg(0, std::ios::beg);
  std::string text(static_cast<std::size_t>(size), '\0');
  if (size > 0 && !in.read(text.data(), size))
  {
    throw fail("cannot read the file");
  }
  return text;
}

} // namespace ictk::lang
