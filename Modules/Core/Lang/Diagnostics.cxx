// SPDX-License-Identifier: BSD-3-Clause
#include "Lang/Diagnostics.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstring>

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
  auto tooLarge = [&](std::uint64_t size)
  {
    return fail("the file is too large: " + std::to_string(size) +
      " bytes, more than the limit of " + std::to_string(limits.maxFileBytes));
  };
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0)
  {
    throw fail("cannot open the file: " + std::string(std::strerror(errno)));
  }
  struct Closer
  {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{ fd };
  struct stat st
  {};
  if (::fstat(fd, &st) != 0)
  {
    throw fail("cannot read the file: " + std::string(std::strerror(errno)));
  }
  // A regular file's size is known before reading (and a file over the limit costs nothing); a
  // pipe or a /proc file is read to its end, up to the limit.
  const bool regular = S_ISREG(st.st_mode);
  const auto opened = static_cast<std::uint64_t>(st.st_size);
  if (regular && opened > limits.maxFileBytes)
  {
    throw tooLarge(opened);
  }
  std::string text(regular ? static_cast<std::size_t>(opened) : std::size_t(0), '\0');
  std::size_t done = 0;
  for (;;)
  {
    if (done == text.size())
    {
      if (done > limits.maxFileBytes)
      {
        throw tooLarge(done);
      }
      // One byte past the size at opening tells a file that grew from one read to its end.
      text.resize(done + (regular ? 1 : 65536));
    }
    const ssize_t n = ::read(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR)
    {
      continue;
    }
    if (n < 0)
    {
      throw fail("cannot read the file: " + std::string(std::strerror(errno)));
    }
    if (n == 0)
    {
      break;
    }
    done += static_cast<std::size_t>(n);
    if (regular && done > opened)
    {
      break; // it grew: refused below
    }
  }
  text.resize(done);
  // Another program replacing or cutting the file while it is read (a copy in progress, an
  // editor saving) would give a text that was never the file's: refused rather than half-read.
  if (regular && done != opened)
  {
    throw fail("the file changed while it was read: it had " + std::to_string(opened) +
      " bytes when opened, " + std::to_string(done) + " were read");
  }
  return text;
}

} // namespace ictk::lang
