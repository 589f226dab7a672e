// SPDX-License-Identifier: BSD-3-Clause
#include "Lang/IcmLexer.h"

#include <cctype>
#include <cstdlib>

namespace ictk::lang::icm
{

const char* tokName(Tok t)
{
  switch (t)
  {
    case Tok::End:
      return "end of file";
    case Tok::Ident:
      return "identifier";
    case Tok::Number:
      return "number";
    case Tok::String:
      return "string";
    case Tok::CellType:
      return "cell type";
    case Tok::Dim:
      return "dimension";
    case Tok::HyperFun:
      return "hyperfun block";
    case Tok::LBrace:
      return "'{'";
    case Tok::RBrace:
      return "'}'";
    case Tok::LParen:
      return "'('";
    case Tok::RParen:
      return "')'";
    case Tok::LBracket:
      return "'['";
    case Tok::RBracket:
      return "']'";
    case Tok::Semi:
      return "';'";
    case Tok::Comma:
      return "','";
    case Tok::Dot:
      return "'.'";
    case Tok::DotDot:
      return "'..'";
    case Tok::Ellipsis:
      return "'...'";
    case Tok::Colon:
      return "':'";
    case Tok::Scope:
      return "'::'";
    case Tok::Assign:
      return "'='";
    case Tok::PlusAssign:
      return "'+='";
    case Tok::MinusAssign:
      return "'-='";
    case Tok::StarAssign:
      return "'*='";
    case Tok::SlashAssign:
      return "'/='";
    case Tok::Eq:
      return "'=='";
    case Tok::Ne:
      return "'!='";
    case Tok::Lt:
      return "'<'";
    case Tok::Le:
      return "'<='";
    case Tok::Gt:
      return "'>'";
    case Tok::Ge:
      return "'>='";
    case Tok::Plus:
      return "'+'";
    case Tok::Minus:
      return "'-'";
    case Tok::Star:
      return "'*'";
    case Tok::Slash:
      return "'/'";
    case Tok::Not:
      return "'!'";
    case Tok::And:
      return "'&&'";
    case Tok::Or:
      return "'||'";
    case Tok::Arrow:
      return "'<-'";
    case Tok::Backslash:
      return "'\\'";
    case Tok::Invalid:
      return "invalid token";
  }
  return "token";
}

namespace
{

bool identStart(char c)
{
  return std::isalpha(static_cast<unsigned char>(c)) != 0 || c == '_';
}

bool identChar(char c)
{
  return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_';
}

class Scanner
{
public:
  Scanner(const hf::SourceText& source, hf::DiagnosticSink& sink)
    : s_(source.text())
    , sink_(sink)
  {
  }

  std::vector<Token> run(std::size_t maxTokens)
  {
    std::vector<Token> out;
    for (;;)
    {
      Token t = next();
      const bool end = t.kind == Tok::End;
      if (!end && out.size() + 1 >= maxTokens)
      {
        sink_.error(t.line, t.column, "the model is too large (more than the token limit)");
        t.kind = Tok::End;
        out.push_back(std::move(t));
        break;
      }
      out.push_back(std::move(t));
      if (end)
      {
        break;
      }
    }
    return out;
  }

private:
  const std::string& s_;
  hf::DiagnosticSink& sink_;
  std::size_t pos_ = 0;
  int line_ = 1;
  int column_ = 1;

  char peek(std::size_t ahead = 0) const
  {
    return pos_ + ahead < s_.size() ? s_[pos_ + ahead] : '\0';
  }
  void advance()
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

  void skipSpaceAndComments()
  {
    for (;;)
    {
      const char c = peek();
      if (c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v')
      {
        advance();
      }
      else if (c == '/' && peek(1) == '/')
      {
        while (pos_ < s_.size() && peek() != '\n')
        {
          advance();
        }
      }
      else if (c == '/' && peek(1) == '*')
      {
        const int l = line_;
        const int col = column_;
        advance();
        advance();
        while (pos_ < s_.size() && !(peek() == '*' && peek(1) == '/'))
        {
          advance();
        }
        if (pos_ >= s_.size())
        {
          sink_.error(l, col, "unterminated comment");
          return;
        }
        advance();
        advance();
      }
      else
      {
        return;
      }
    }
  }

  // `hyperfun` then optional blanks then '{': the text up to the matching '}' (HyperFun's
  // "--" comments and strings may hold braces).
  bool hyperFunBlock(Token& t)
  {
    std::size_t p = pos_ + 8;
    while (p < s_.size() && (s_[p] == ' ' || s_[p] == '\t' || s_[p] == '\r' || s_[p] == '\n'))
    {
      ++p;
    }
    if (p >= s_.size() || s_[p] != '{')
    {
      return false;
    }
    while (pos_ <= p)
    {
      advance();
    }
    t.textLine = line_;
    t.textColumn = column_;
    const std::size_t begin = pos_;
    int depth = 1;
    while (pos_ < s_.size())
    {
      const char c = peek();
      if (c == '-' && peek(1) == '-')
      {
        while (pos_ < s_.size() && peek() != '\n')
        {
          advance();
        }
        continue;
      }
      if (c == '"')
      {
        advance();
        while (pos_ < s_.size() && peek() != '"' && peek() != '\n')
        {
          advance();
        }
        advance();
        continue;
      }
      if (c == '{')
      {
        ++depth;
      }
      else if (c == '}' && --depth == 0)
      {
        t.text = s_.substr(begin, pos_ - begin);
        advance();
        t.kind = Tok::HyperFun;
        return true;
      }
      advance();
    }
    sink_.error(t.line, t.column, "unterminated hyperfun block: '{' without a matching '}'");
    t.kind = Tok::Invalid;
    return true;
  }

  Token next()
  {
    skipSpaceAndComments();
    Token t;
    t.line = line_;
    t.column = column_;
    if (pos_ >= s_.size())
    {
      t.kind = Tok::End;
      return t;
    }
    const char c = peek();
    // P-CELL ... T-CELL
    if ((c == 'P' || c == 'F' || c == 'C' || c == 'B' || c == 'T') &&
      s_.compare(pos_ + 1, 5, "-CELL") == 0 && !identChar(peek(6)))
    {
      t.kind = Tok::CellType;
      t.text = s_.substr(pos_, 6);
      for (int i = 0; i < 6; ++i)
      {
        advance();
      }
      return t;
    }
    if (identStart(c))
    {
      const std::size_t begin = pos_;
      while (identChar(peek()))
      {
        advance();
      }
      t.kind = Tok::Ident;
      t.text = s_.substr(begin, pos_ - begin);
      if (t.text == "hyperfun")
      {
        pos_ = begin; // rescan from the word, keeping line and column consistent
        column_ = t.column;
        line_ = t.line;
        if (!hyperFunBlock(t))
        {
          for (int i = 0; i < 8; ++i)
          {
            advance();
          }
        }
      }
      return t;
    }
    if (std::isdigit(static_cast<unsigned char>(c)) != 0)
    {
      // 0D .. 4D
      if (c >= '0' && c <= '4' && peek(1) == 'D' && !identChar(peek(2)))
      {
        t.kind = Tok::Dim;
        t.number = c - '0';
        t.text = s_.substr(pos_, 2);
        advance();
        advance();
        return t;
      }
      const std::size_t begin = pos_;
      while (std::isdigit(static_cast<unsigned char>(peek())) != 0)
      {
        advance();
      }
      if (peek() == '.' && std::isdigit(static_cast<unsigned char>(peek(1))) != 0)
      {
        advance();
        while (std::isdigit(static_cast<unsigned char>(peek())) != 0)
        {
          advance();
        }
      }
      if ((peek() == 'e' || peek() == 'E') &&
        (std::isdigit(static_cast<unsigned char>(peek(1))) != 0 ||
          ((peek(1) == '+' || peek(1) == '-') &&
            std::isdigit(static_cast<unsigned char>(peek(2))) != 0)))
      {
        advance();
        advance();
        while (std::isdigit(static_cast<unsigned char>(peek())) != 0)
        {
          advance();
        }
      }
      t.text = s_.substr(begin, pos_ - begin);
      if (identChar(peek()))
      {
        sink_.error(t.line, t.column, "malformed number '" + t.text + "'");
        while (identChar(peek()))
        {
          advance();
        }
        t.kind = Tok::Invalid;
        return t;
      }
      t.kind = Tok::Number;
      t.number = std::strtod(t.text.c_str(), nullptr);
      return t;
    }
    if (c == '"')
    {
      advance();
      const std::size_t begin = pos_;
      while (pos_ < s_.size() && peek() != '"' && peek() != '\n')
      {
        advance();
      }
      if (peek() != '"')
      {
        sink_.error(t.line, t.column, "unterminated string");
        t.kind = Tok::Invalid;
        return t;
      }
      t.text = s_.substr(begin, pos_ - begin);
      advance();
      t.kind = Tok::String;
      return t;
    }
    struct Op
    {
      const char* text;
      Tok kind;
    };
    // Longest first.
    static const Op ops[] = { { "::=", Tok::Assign }, { "...", Tok::Ellipsis },
      { "::", Tok::Scope }, { "..", Tok::DotDot }, { "<-", Tok::Arrow }, { "+=", Tok::PlusAssign },
      { "-=", Tok::MinusAssign }, { "*=", Tok::StarAssign }, { "/=", Tok::SlashAssign },
      { "==", Tok::Eq }, { "!=", Tok::Ne }, { "<=", Tok::Le }, { ">=", Tok::Ge },
      { "&&", Tok::And }, { "||", Tok::Or }, { "{", Tok::LBrace }, { "}", Tok::RBrace },
      { "(", Tok::LParen }, { ")", Tok::RParen }, { "[", Tok::LBracket }, { "]", Tok::RBracket },
      { ";", Tok::Semi }, { ",", Tok::Comma }, { ".", Tok::Dot }, { ":", Tok::Colon },
      { "=", Tok::Assign }, { "<", Tok::Lt }, { ">", Tok::Gt }, { "+", Tok::Plus },
      { "-", Tok::Minus }, { "*", Tok::Star }, { "/", Tok::Slash }, { "!", Tok::Not },
      { "\\", Tok::Backslash } };
    for (const Op& op : ops)
    {
      const std::size_t n = std::char_traits<char>::length(op.text);
      if (s_.compare(pos_, n, op.text) == 0)
      {
        t.kind = op.kind;
        t.text = op.text;
        for (std::size_t i = 0; i < n; ++i)
        {
          advance();
        }
        return t;
      }
    }
    const auto byte = static_cast<unsigned char>(c);
    sink_.error(t.line, t.column,
      byte >= 0x20 && byte < 0x7f ? std::string("unexpected character '") + c + "'"
                                  : "unexpected byte " + std::to_string(byte));
    advance();
    t.kind = Tok::Invalid;
    return t;
  }
};

} // namespace

std::vector<Token> tokenize(
  const hf::SourceText& source, hf::DiagnosticSink& sink, std::size_t maxTokens)
{
  Scanner scanner(source, sink);
  return scanner.run(maxTokens < 2 ? 2 : maxTokens);
}

} // namespace ictk::lang::icm
