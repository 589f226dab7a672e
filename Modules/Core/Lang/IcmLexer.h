// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Tokens of the IC model language (.icm). Words are case-sensitive and contextual (CELLS, USE,
// if, for ... are reserved only where the grammar expects them), `//` and `/* */` are comments,
// `B-CELL` and `2D` are single tokens, and `hyperfun { ... }` is one token holding the HyperFun
// text between its braces verbatim.

#include "Lang/Diagnostics.h"
#include "Lang/HyperFunLexer.h"

#include <cstdint>
#include <string>
#include <vector>

namespace ictk::lang::icm
{

enum class Tok : std::uint8_t
{
  End,
  Ident,
  Number,
  String,
  CellType, ///< P-CELL F-CELL C-CELL B-CELL T-CELL
  Dim,      ///< 0D .. 4D
  HyperFun, ///< hyperfun { text }
  LBrace,
  RBrace,
  LParen,
  RParen,
  LBracket,
  RBracket,
  Semi,
  Comma,
  Dot,
  DotDot,
  Ellipsis,
  Colon,
  Scope,  ///< ::
  Assign, ///< = or ::=
  PlusAssign,
  MinusAssign,
  StarAssign,
  SlashAssign,
  Eq,
  Ne,
  Lt,
  Le,
  Gt,
  Ge,
  Plus,
  Minus,
  Star,
  Slash,
  Not,
  And,
  Or,
  Arrow, ///< <-
  Backslash,
  Invalid
};

const char* tokName(Tok t);

struct Token
{
  Tok kind = Tok::End;
  std::string text; ///< identifier, number spelling, string contents, HyperFun text
  double number = 0;
  int line = 1;
  int column = 1;
  int textLine = 0; ///< HyperFun: where the text after '{' starts
  int textColumn = 0;
};

/// Splits the whole text into tokens (ending with End). Stops with a diagnostic when more than
/// `maxTokens` tokens would be made; lexical errors are reported and give Invalid tokens.
std::vector<Token> tokenize(
  const hf::SourceText& source, hf::DiagnosticSink& sink, std::size_t maxTokens);

} // namespace ictk::lang::icm
