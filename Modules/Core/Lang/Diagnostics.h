// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Diagnostics shared by the front ends (HyperFun, FRep XML, later the IC model notation):
// "file:line:col: error: message", the source line and a caret, several per run.

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace ictk::lang
{

struct SourceLocation
{
  std::string file;
  int line = 0;   ///< 1-based; 0 when unknown
  int column = 0; ///< 1-based, in bytes; 0 when unknown
};

struct Diagnostic
{
  SourceLocation where;
  std::string message;
  std::string sourceLine; ///< the text of the line, for the caret display
};

/// "file:line:col: error: message\n<source line>\n<spaces>^".
std::string formatDiagnostic(const Diagnostic& d);

/// Raised by a front end with every error it found (at least one). what() is all of them
/// formatted, one after the other.
class ParseError : public std::runtime_error
{
public:
  explicit ParseError(std::vector<Diagnostic> diagnostics);
  const std::vector<Diagnostic>& diagnostics() const { return diagnostics_; }

private:
  std::vector<Diagnostic> diagnostics_;
};

/// Resource limits, so that no input can make a front end hang or exhaust memory.
struct Limits
{
  std::size_t maxFileBytes = 16u << 20;       ///< larger files are refused
  int maxNesting = 200;                       ///< brackets, blocks and calls nested deeper
  std::uint64_t maxLoopIterations = 10000000; ///< total over a compilation
  std::size_t maxExpressionNodes = 20000000;  ///< DAG nodes created by one compilation
  std::size_t maxDiagnostics = 20;            ///< stop after this many errors
  std::size_t maxSyntaxNodes = 1000000;       ///< syntax tree nodes of one file (bounds memory)
  /// HyperFun read as HyperFun's own interpreter reads it (`ictk --strict`): what ICTK accepts
  /// beyond it (docs/hyperfun.md) is an error at its place.
  bool strictHyperFun = false;
};

/// The whole text of a source file; throws ParseError naming the file when it cannot be opened
/// or read, is larger than limits.maxFileBytes (refused before reading, so it costs no memory),
/// or changes while it is read (cut short or grown by another program: its size when opened
/// and the bytes read differ). Pipes and /proc files are read to their end.
std::string readSourceFile(const std::string& path, const Limits& limits);

} // namespace ictk::lang
