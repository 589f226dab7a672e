// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Tokens of the HyperFun language, produced on demand (the parser pulls them one at a time, so a
// large file never exists as a token array in memory).
//
// As in HyperFun's scanner (interpreter_lib/int_scanner.c): identifiers are case-insensitive
// (kept lower-cased in `text`, as written in `spelling`), "--" starts a comment to the end of the
// line, "/=" is "not equal", and the words and/or/not/xor/array/if/then/else/endif/while/loop/
// endloop are reserved.

#include "Lang/Diagnostics.h"

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace ictk::lang::hf
{

enum class TokenKind : std::uint8_t
{
  End,
  Identifier,
  Number,
  String,
  Plus,
  Minus,
  Star,
  Slash,
  Caret,
  Tilde,
  Ampersand,
  Bar,
  Backslash,
  At,
  Comma,
  Semicolon,
  Assign, ///< '=': assignment in statements, equality inside expressions (as HyperFun)
  NotEqual,
  Less,
  LessEqual,
  Greater,
  GreaterEqual,
  LeftParen,
  RightParen,
  LeftBracket,
  RightBracket,
  LeftBrace,
  RightBrace,
  KwArray,
  KwIf,
  KwThen,
  KwElse,
  KwEndIf,
  KwWhile,
  KwLoop,
  KwEndLoop,
  KwAnd,
  KwOr,
  KwNot,
  KwXor,
  Invalid ///< a character or number the language does not have (already diagnosed)
};

const char* tokenKindName(TokenKind k);

struct Token
{
  TokenKind kind = TokenKind::End;
  std::string text;     ///< identifiers lower-cased; string contents
  std::string spelling; ///< the source text of the token
  double number = 0;
  int line = 1;
  int column = 1;
};

/// The source text with its file name, for diagnostics with the line and a caret.
class SourceText
{
public:
  SourceText(const std::string& text, std::string fileName);
  const std::string& text() const { return text_; }
  const std::string& fileName() const { return fileName_; }
  std::string lineText(int line) const;
  Diagnostic diagnostic(int line, int column, std::string message) const;

private:
  const std::string& text_;
  std::string fileName_;
  std::vector<std::size_t> lineStarts_;
};

/// Collects diagnostics up to Limits::maxDiagnostics, dropping exact duplicates (a loop body
/// would otherwise report one mistake once per iteration).
class DiagnosticSink
{
public:
  DiagnosticSink(const SourceText& source, std::size_t maxDiagnostics)
    : source_(source)
    , max_(maxDiagnostics)
  {
  }
  /// Records an error; returns false once the maximum is reached (the caller should stop).
  bool error(int line, int column, const std::string& message);
  bool full() const { return diagnostics_.size() >= max_; }
  bool empty() const { return diagnostics_.empty(); }
  std::vector<Diagnostic>& diagnostics() { return diagnostics_; }
  const SourceText& source() const { return source_; }

private:
  const SourceText& source_;
  std::size_t max_;
  std::vector<Diagnostic> diagnostics_;
};

class Lexer
{
public:
  Lexer(const SourceText& source, DiagnosticSink& sink);
  /// The next token (End forever at the end of the text).
  Token next();

private:
  const std::string& s_;
  DiagnosticSink& sink_;
  std::size_t pos_ = 0;
  int line_ = 1;
  int column_ = 1;

  void advance();
  char peek(std::size_t ahead = 0) const
  {
    return pos_ + ahead < s_.size() ? s_[pos_ + ahead] : '\0';
  }
};

} // namespace ictk::lang::hf
