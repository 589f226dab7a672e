// SPDX-License-Identifier: BSD-3-Clause
#include "Lang/HyperFunLexer.h"

#include <algorithm>
#include <cctype>
#include <charconv>

namespace ictk::lang::hf
{

const char* tokenKindName(TokenKind k)
{
  switch (k)
  {
    case TokenKind::End:
      return "end of file";
    case TokenKind::Identifier:
      return "identifier";
    case TokenKind::Number:
      return "number";
    case TokenKind::String:
      return "string";
    case TokenKind::Plus:
      return "'+'";
    case TokenKind::Minus:
      return "'-'";
    case TokenKind::Star:
      return "'*'";
    case TokenKind::Slash:
      return "'/'";
    case TokenKind::Caret:
      return "'^'";
    case TokenKind::Tilde:
      return "'~'";
    case TokenKind::Ampersand:
      return "'&'";
    case TokenKind::Bar:
      return "'|'";
    case TokenKind::Backslash:
      return "'\\'";
    case TokenKind::At:
      return "'@'";
    case TokenKind::Comma:
      return "','";
    case TokenKind::Semicolon:
      return "';'";
    case TokenKind::Assign:
      return "'='";
    case TokenKind::NotEqual:
      return "'/='";
    case TokenKind::Less:
      return "'<'";
    case TokenKind::LessEqual:
      return "'<='";
    case TokenKind::Greater:
      return "'>'";
    case TokenKind::GreaterEqual:
      return "'>='";
    case TokenKind::LeftParen:
      return "'('";
    case TokenKind::RightParen:
      return "')'";
    case TokenKind::LeftBracket:
      return "'['";
    case TokenKind::RightBracket:
      return "']'";
    case TokenKind::LeftBrace:
      return "'{'";
    case TokenKind::RightBrace:
      return "'}'";
    case TokenKind::KwArray:
      return "'array'";
    case TokenKind::KwIf:
      return "'if'";
    case TokenKind::KwThen:
      return "'then'";
    case TokenKind::KwElse:
      return "'else'";
    case TokenKind::KwEndIf:
      return "'endif'";
    case TokenKind::KwWhile:
      return "'while'";
    case TokenKind::KwLoop:
      return "'loop'";
    case TokenKind::KwEndLoop:
      return "'endloop'";
    case TokenKind::KwAnd:
      return "'and'";
    case TokenKind::KwOr:
      return "'or'";
    case TokenKind::KwNot:
      return "'not'";
    case TokenKind::KwXor:
      return "'xor'";
    case TokenKind::Invalid:
      return "invalid token";
  }
  return "token";
}

SourceText::SourceText(const std::string& text, std::string fileName)
  : text_(text)
  , fileName_(std::move(fileName))
{
  lineStarts_.push_back(0);
  for (std::size_t i = 0; i < text_.size(); ++i)
  {
    if (text_[i] == '\n')
    {
      lineStarts_.push_back(i + 1);
    }
  }
}

std::string SourceText::lineText(int line) const
{
  if (line < 1 || static_cast<std::size_t>(line) > lineStarts_.size())
  {
    return {};
  }
  const std::size_t begin = lineStarts_[static_cast<std::size_t>(line - 1)];
  std::size_t end = text_.find('\n', begin);
  if (end == std::string::npos)
  {
    end = text_.size();
  }
  if (end > begin && text_[end - 1] == '\r')
  {
    --end;
  }
  // A pathological single-line file must not make every diagnostic megabytes long.
  constexpr std::size_t maxShown = 400;
  std::string l = text_.substr(begin, std::min(end - begin, maxShown));
  // Keep the display printable (the caret line copies tabs, nothing else).
  for (char& c : l)
  {
    if (static_cast<unsigned char>(c) < 32 && c != '\t')
    {
      c = ' ';
    }
  }
  return l;
}

Diagnostic SourceText::diagnostic(int line, int column, std::string message) const
{
  Diagnostic d;
  d.where.file = fileName_;
  d.where.line = line;
  d.where.column = column;
  d.message = std::move(message);
  d.sourceLine = lineText(line);
  if (column > 400)
  {
    d.sourceLine.clear(); // the caret could not point into the truncated line
  }
  return d;
}

bool DiagnosticSink::error(int line, int column, const std::string& message)
{
  if (full())
  {
    return false;
  }
  for (const Diagnostic& d : diagnostics_)
  {
    if (d.where.line == line && d.where.column == column && d.message == message)
    {
      return true;
    }
  }
  diagnostics_.push_back(source_.diagnostic(line, column, message));
  return !full();
}

Lexer::Lexer(const SourceText& source, DiagnosticSink& sink)
  : s_(source.text())
  , sink_(sink)
{
}

void Lexer::advance()
{
  if (pos_ < s_.size())
  {
    if (s_[pos_] == '\n')
    {
      ++line_;
      column_ = 1;
    }
    else
    {
      ++column_;
    }
    ++pos_;
  }
}

namespace
{
bool isIdentStart(char c)
{
  return std::isalpha(static_cast<unsigned char>(c)) || c == '_';
}
bool isIdentChar(char c)
{
  return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
}
bool isDigit(char c)
{
  return c >= '0' && c <= '9';
}

TokenKind keyword(const std::string& w)
{
  static const std::pair<const char*, TokenKind> words[] = { { "array", TokenKind::KwArray },
    { "if", TokenKind::KwIf }, { "then", TokenKind::KwThen }, { "else", TokenKind::KwElse },
    { "endif", TokenKind::KwEndIf }, { "while", TokenKind::KwWhile }, { "loop", TokenKind::KwLoop },
    { "endloop", TokenKind::KwEndLoop }, { "and", TokenKind::KwAnd }, { "or", TokenKind::KwOr },
    { "not", TokenKind::KwNot }, { "xor", TokenKind::KwXor } };
  for (const auto& [text, kind] : words)
  {
    if (w == text)
    {
      return kind;
    }
  }
  return TokenKind::Identifier;
}
} // namespace

Token Lexer::next()
{
  for (;;)
  {
    // Whitespace and "--" comments.
    while (pos_ < s_.size())
    {
      const char c = s_[pos_];
      if (c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v')
      {
        advance();
      }
      else if (c == '-' && peek(1) == '-')
      {
        while (pos_ < s_.size() && s_[pos_] != '\n')
        {
          advance();
        }
      }
      else
      {
        break;
      }
    }
    Token t;
    t.line = line_;
    t.column = column_;
    if (pos_ >= s_.size())
    {
      t.kind = TokenKind::End;
      return t;
    }
    const std::size_t start = pos_;
    const char c = s_[pos_];
    auto single = [&](TokenKind k)
    {
      advance();
      t.kind = k;
      t.spelling = s_.substr(start, pos_ - start);
      return t;
    };
    auto withEqual = [&](TokenKind plain, TokenKind eq)
    {
      advance();
      if (peek() == '=')
      {
        advance();
        t.kind = eq;
      }
      else
      {
        t.kind = plain;
      }
      t.spelling = s_.substr(start, pos_ - start);
      return t;
    };
    switch (c)
    {
      case '+':
        return single(TokenKind::Plus);
      case '-':
        return single(TokenKind::Minus);
      case '*':
        return single(TokenKind::Star);
      case '^':
        return single(TokenKind::Caret);
      case '~':
        return single(TokenKind::Tilde);
      case '&':
        return single(TokenKind::Ampersand);
      case '|':
        return single(TokenKind::Bar);
      case '\\':
        return single(TokenKind::Backslash);
      case '@':
        return single(TokenKind::At);
      case ',':
        return single(TokenKind::Comma);
      case ';':
        return single(TokenKind::Semicolon);
      case '=':
        return single(TokenKind::Assign);
      case '(':
        return single(TokenKind::LeftParen);
      case ')':
        return single(TokenKind::RightParen);
      case '[':
        return single(TokenKind::LeftBracket);
      case ']':
        return single(TokenKind::RightBracket);
      case '{':
        return single(TokenKind::LeftBrace);
      case '}':
        return single(TokenKind::RightBrace);
      case '/':
        return withEqual(TokenKind::Slash, TokenKind::NotEqual);
      case '<':
        return withEqual(TokenKind::Less, TokenKind::LessEqual);
      case '>':
        return withEqual(TokenKind::Greater, TokenKind::GreaterEqual);
      default:
        break;
    }
    if (c == '"')
    {
      advance();
      while (pos_ < s_.size() && s_[pos_] != '"' && s_[pos_] != '\n')
      {
        advance();
      }
      if (peek() != '"')
      {
        sink_.error(t.line, t.column, "missing closing quotation mark");
        t.kind = TokenKind::Invalid;
        return t;
      }
      advance();
      t.kind = TokenKind::String;
      t.spelling = s_.substr(start, pos_ - start);
      t.text = t.spelling.substr(1, t.spelling.size() - 2);
      return t;
    }
    if (isDigit(c) || (c == '.' && isDigit(peek(1))))
    {
      // Integer[.Integer][(E|e)[+|-]Integer], as HyperFun's scanner.
      while (isDigit(peek()))
      {
        advance();
      }
      if (peek() == '.')
      {
        advance();
        while (isDigit(peek()))
        {
          advance();
        }
      }
      bool bad = false;
      if (peek() == 'e' || peek() == 'E')
      {
        advance();
        if (peek() == '+' || peek() == '-')
        {
          advance();
        }
        if (!isDigit(peek()))
        {
          bad = true;
        }
        while (isDigit(peek()))
        {
          advance();
        }
      }
      if (isIdentStart(peek()))
      {
        bad = true;
        while (isIdentChar(peek()))
        {
          advance();
        }
      }
      t.spelling = s_.substr(start, pos_ - start);
      double v = 0;
      const auto r = std::from_chars(t.spelling.data(), t.spelling.data() + t.spelling.size(), v);
      if (bad || r.ec == std::errc::invalid_argument ||
        r.ptr != t.spelling.data() + t.spelling.size())
      {
        sink_.error(t.line, t.column, "malformed number '" + t.spelling + "'");
        t.kind = TokenKind::Invalid;
        return t;
      }
      if (r.ec == std::errc::result_out_of_range)
      {
        sink_.error(t.line, t.column, "number '" + t.spelling + "' is out of range");
        t.kind = TokenKind::Invalid;
        return t;
      }
      t.kind = TokenKind::Number;
      t.number = v;
      return t;
    }
    if (isIdentStart(c))
    {
      while (isIdentChar(peek()))
      {
        advance();
      }
      t.spelling = s_.substr(start, pos_ - start);
      t.text = t.spelling;
      for (char& ch : t.text)
      {
        ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
      }
      t.kind = keyword(t.text);
      return t;
    }
    // An unknown character: report it and carry on with the next one.
    advance();
    std::string shown;
    if (static_cast<unsigned char>(c) >= 32 && static_cast<unsigned char>(c) < 127)
    {
      shown = std::string("'") + c + "'";
    }
    else
    {
      static const char* hex = "0123456789abcdef";
      const auto u = static_cast<unsigned char>(c);
      shown = std::string("byte 0x") + hex[u >> 4] + hex[u & 15];
    }
    if (!sink_.error(t.line, t.column, "unexpected character " + shown))
    {
      t.kind = TokenKind::End;
      return t;
    }
  }
}

} // namespace ictk::lang::hf
