// SPDX-License-Identifier: BSD-3-Clause
#include "Lang/HyperFunParser.h"

#include <cmath>

namespace ictk::lang::hf
{

namespace
{
// Thrown after a syntax error has been recorded: unwinds to the statement (or function) being
// parsed, which resynchronises.
struct SyntaxError
{};
// Thrown when parsing cannot usefully go on (limits, too many errors).
struct Fatal
{};

class Parser
{
public:
  Parser(const SourceText& source, DiagnosticSink& sink, const Limits& limits)
    : sink_(sink)
    , lexer_(source, sink)
    , limits_(limits)
  {
    cur_ = lexer_.next();
  }

  Program run()
  {
    try
    {
      while (cur_.kind != TokenKind::End)
      {
        parseFunction();
      }
    }
    catch (const Fatal&)
    {
    }
    return std::move(program_);
  }

private:
  DiagnosticSink& sink_;
  Lexer lexer_;
  const Limits& limits_;
  Token cur_;
  Program program_;
  int depth_ = 0;
  std::size_t nodes_ = 0;

  struct DepthGuard
  {
    Parser& p;
    explicit DepthGuard(Parser& parser)
      : p(parser)
    {
      if (++p.depth_ > p.limits_.maxNesting)
      {
        p.sink_.error(p.cur_.line, p.cur_.column,
          "nesting deeper than the limit of " + std::to_string(p.limits_.maxNesting) +
            " (brackets, calls, unary operators and blocks)");
        throw Fatal{};
      }
    }
    ~DepthGuard() { --p.depth_; }
    DepthGuard(const DepthGuard&) = delete;
    DepthGuard& operator=(const DepthGuard&) = delete;
  };

  void advance()
  {
    cur_ = lexer_.next();
    if (sink_.full())
    {
      throw Fatal{};
    }
  }

  [[noreturn]] void fail(const Token& at, const std::string& message)
  {
    if (!sink_.error(at.line, at.column, message))
    {
      throw Fatal{};
    }
    throw SyntaxError{};
  }

  std::string describe(const Token& t) const
  {
    if (t.kind == TokenKind::Identifier || t.kind == TokenKind::Number)
    {
      return "'" + t.spelling + "'";
    }
    return tokenKindName(t.kind);
  }

  void expect(TokenKind k, const char* context)
  {
    if (cur_.kind != k)
    {
      fail(cur_,
        std::string("expected ") + tokenKindName(k) + " " + context + ", found " + describe(cur_));
    }
    advance();
  }

  void countNode()
  {
    if (++nodes_ > limits_.maxSyntaxNodes)
    {
      sink_.error(cur_.line, cur_.column,
        "the model is too large: more than " + std::to_string(limits_.maxSyntaxNodes) +
          " syntax nodes");
      throw Fatal{};
    }
  }

  int addExpr(ExprNode n)
  {
    countNode();
    program_.exprs.push_back(std::move(n));
    return static_cast<int>(program_.exprs.size() - 1);
  }

  int addStatement(Statement s)
  {
    countNode();
    program_.statements.push_back(std::move(s));
    return static_cast<int>(program_.statements.size() - 1);
  }

  int parseSize(const char* what)
  {
    if (cur_.kind != TokenKind::Number)
    {
      fail(cur_,
        std::string("expected the size of ") + what + " (a positive integer), found " +
          describe(cur_));
    }
    const double v = cur_.number;
    if (!(v >= 1) || v != std::floor(v) || v > 1000000)
    {
      fail(cur_,
        std::string("the size of ") + what +
          " must be a positive integer of at most 1000000, got " + cur_.spelling);
    }
    advance();
    return static_cast<int>(v);
  }

  // Skips to the end of the current statement (after ';'), stopping before a token that closes
  // a block.
  void skipStatement()
  {
    while (cur_.kind != TokenKind::End && cur_.kind != TokenKind::RightBrace)
    {
      if (cur_.kind == TokenKind::Semicolon)
      {
        advance();
        return;
      }
      advance();
    }
  }

  void parseFunction()
  {
    Function f;
    try
    {
      if (cur_.kind != TokenKind::Identifier)
      {
        fail(cur_,
          "expected a function definition such as 'my_model(x[3], a[1]) { ... }', found " +
            describe(cur_));
      }
      f.name = cur_.text;
      f.spelling = cur_.spelling;
      f.line = cur_.line;
      f.column = cur_.column;
      for (const Function& g : program_.functions)
      {
        if (g.name == f.name)
        {
          fail(cur_,
            "function '" + f.spelling + "' is defined twice (first at line " +
              std::to_string(g.line) + ")");
        }
      }
      advance();
      expect(TokenKind::LeftParen, "after the function name");
      for (;;)
      {
        Function::Param p;
        if (cur_.kind != TokenKind::Identifier)
        {
          fail(cur_, "expected a parameter array such as 'x[3]', found " + describe(cur_));
        }
        p.name = cur_.text;
        p.spelling = cur_.spelling;
        p.line = cur_.line;
        p.column = cur_.column;
        advance();
        expect(TokenKind::LeftBracket, "after the parameter name");
        p.size = parseSize("a parameter array");
        expect(TokenKind::RightBracket, "after the parameter size");
        for (const auto& q : f.params)
        {
          if (q.name == p.name)
          {
            sink_.error(p.line, p.column, "parameter '" + p.spelling + "' is declared twice");
          }
        }
        f.params.push_back(std::move(p));
        if (cur_.kind != TokenKind::Comma)
        {
          break;
        }
        advance();
      }
      if (f.params.size() > 3)
      {
        sink_.error(f.params[3].line, f.params[3].column,
          "a HyperFun function has at most three parameter arrays (x, a, s)");
      }
      expect(TokenKind::RightParen, "after the parameters");
      expect(TokenKind::LeftBrace, "to open the function body");
    }
    catch (const SyntaxError&)
    {
      // Resynchronise on the body's closing brace (or the next function header).
      int braces = 0;
      while (cur_.kind != TokenKind::End)
      {
        if (cur_.kind == TokenKind::LeftBrace)
        {
          ++braces;
        }
        else if (cur_.kind == TokenKind::RightBrace && --braces <= 0)
        {
          advance();
          return;
        }
        advance();
      }
      return;
    }
    f.body = parseStatements(true);
    f.endLine = cur_.line;
    f.endColumn = cur_.column;
    if (cur_.kind != TokenKind::RightBrace)
    {
      sink_.error(cur_.line, cur_.column,
        std::string("expected '}' to close function '") + f.spelling + "', found " +
          describe(cur_));
    }
    else
    {
      advance();
    }
    program_.functions.push_back(std::move(f));
  }

  bool closesBlock(TokenKind k) const
  {
    return k == TokenKind::End || k == TokenKind::RightBrace || k == TokenKind::KwElse ||
      k == TokenKind::KwEndIf || k == TokenKind::KwEndLoop;
  }

  std::vector<int> parseStatements(bool functionLevel)
  {
    std::vector<int> body;
    for (;;)
    {
      if (closesBlock(cur_.kind))
      {
        if (!functionLevel || cur_.kind == TokenKind::End || cur_.kind == TokenKind::RightBrace)
        {
          return body;
        }
        // A stray else/endif/endloop at function level: report it and go on.
        try
        {
          fail(cur_,
            std::string("unexpected ") + tokenKindName(cur_.kind) + " without a matching " +
              (cur_.kind == TokenKind::KwEndLoop ? "'while'" : "'if'"));
        }
        catch (const SyntaxError&)
        {
          advance();
          if (cur_.kind == TokenKind::Semicolon)
          {
            advance();
          }
        }
        continue;
      }
      try
      {
        const int s = parseStatement();
        if (s >= 0)
        {
          body.push_back(s);
        }
      }
      catch (const SyntaxError&)
      {
        skipStatement();
      }
    }
  }

  int parseStatement()
  {
    Statement s;
    s.line = cur_.line;
    s.column = cur_.column;
    switch (cur_.kind)
    {
      case TokenKind::Semicolon:
        advance();
        return -1;
      case TokenKind::KwArray:
      {
        s.kind = Statement::Kind::ArrayDecl;
        advance();
        for (;;)
        {
          Statement::Declared d;
          if (cur_.kind != TokenKind::Identifier)
          {
            fail(cur_, "expected an array name after 'array', found " + describe(cur_));
          }
          d.name = cur_.text;
          d.spelling = cur_.spelling;
          d.line = cur_.line;
          d.column = cur_.column;
          advance();
          expect(TokenKind::LeftBracket, "after the array name");
          d.size = parseSize("an array");
          expect(TokenKind::RightBracket, "after the array size");
          s.declared.push_back(std::move(d));
          if (cur_.kind != TokenKind::Comma)
          {
            break;
          }
          advance();
        }
        expect(TokenKind::Semicolon, "after the array declaration");
        return addStatement(std::move(s));
      }
      case TokenKind::KwIf:
      {
        DepthGuard guard(*this);
        s.kind = Statement::Kind::If;
        advance();
        s.expr = parseExpression();
        expect(TokenKind::KwThen, "after the condition of 'if'");
        s.thenBody = parseStatements(false);
        if (cur_.kind == TokenKind::KwElse)
        {
          advance();
          s.elseBody = parseStatements(false);
        }
        if (cur_.kind != TokenKind::KwEndIf)
        {
          sink_.error(s.line, s.column, "this 'if' is not closed by 'endif'");
          fail(cur_, std::string("expected 'endif', found ") + describe(cur_));
        }
        advance();
        expect(TokenKind::Semicolon, "after 'endif'");
        return addStatement(std::move(s));
      }
      case TokenKind::KwWhile:
      {
        DepthGuard guard(*this);
        s.kind = Statement::Kind::While;
        advance();
        s.expr = parseExpression();
        expect(TokenKind::KwLoop, "after the condition of 'while'");
        s.thenBody = parseStatements(false);
        if (cur_.kind != TokenKind::KwEndLoop)
        {
          sink_.error(s.line, s.column, "this 'while' is not closed by 'endloop'");
          fail(cur_, std::string("expected 'endloop', found ") + describe(cur_));
        }
        advance();
        expect(TokenKind::Semicolon, "after 'endloop'");
        return addStatement(std::move(s));
      }
      case TokenKind::Identifier:
      {
        s.name = cur_.text;
        s.spelling = cur_.spelling;
        const Token nameToken = cur_;
        advance();
        if (cur_.kind == TokenKind::LeftBracket)
        {
          s.kind = Statement::Kind::AssignIndex;
          advance();
          s.index = parseExpression();
          expect(TokenKind::RightBracket, "after the index");
          expect(TokenKind::Assign, "in the assignment");
          s.expr = parseExpression();
        }
        else if (cur_.kind == TokenKind::LeftParen)
        {
          s.kind = Statement::Kind::Call;
          s.expr = parseCall(nameToken);
        }
        else
        {
          expect(TokenKind::Assign, "after the variable name");
          if (cur_.kind == TokenKind::LeftBracket)
          {
            s.kind = Statement::Kind::AssignList;
            advance();
            for (;;)
            {
              s.list.push_back(parseExpression());
              if (cur_.kind != TokenKind::Comma)
              {
                break;
              }
              advance();
            }
            expect(TokenKind::RightBracket, "to close the list of array items");
          }
          else
          {
            s.kind = Statement::Kind::Assign;
            s.expr = parseExpression();
          }
        }
        expect(TokenKind::Semicolon, "at the end of the statement");
        return addStatement(std::move(s));
      }
      default:
        fail(cur_,
          "expected a statement (an assignment, 'array', 'if' or 'while'), found " +
            describe(cur_));
    }
  }

  int parseExpression()
  {
    DepthGuard guard(*this);
    return parseLogic();
  }

  // One left-associative level: operands from `operand`, operators accepted by `isOp`.
  template <typename Operand, typename IsOp>
  int parseChain(Operand operand, IsOp isOp)
  {
    int first = operand();
    if (!isOp(cur_.kind))
    {
      return first;
    }
    ExprNode n;
    n.kind = ExprNode::Kind::Chain;
    n.line = program_.exprs[static_cast<std::size_t>(first)].line;
    n.column = program_.exprs[static_cast<std::size_t>(first)].column;
    n.kids.push_back(first);
    while (isOp(cur_.kind))
    {
      n.ops.push_back(cur_.kind);
      n.opPositions.emplace_back(cur_.line, cur_.column);
      advance();
      n.kids.push_back(operand());
      countNode();
    }
    return addExpr(std::move(n));
  }

  int parseLogic()
  {
    return parseChain([this] { return parseNot(); },
      [](TokenKind k)
      { return k == TokenKind::KwAnd || k == TokenKind::KwOr || k == TokenKind::KwXor; });
  }

  int parseNot()
  {
    if (cur_.kind == TokenKind::KwNot)
    {
      DepthGuard guard(*this);
      ExprNode n;
      n.kind = ExprNode::Kind::Unary;
      n.line = cur_.line;
      n.column = cur_.column;
      n.ops.push_back(TokenKind::KwNot);
      advance();
      n.kids.push_back(parseNot());
      return addExpr(std::move(n));
    }
    return parseComparison();
  }

  int parseComparison()
  {
    return parseChain([this] { return parseSum(); },
      [](TokenKind k)
      {
        return k == TokenKind::Assign || k == TokenKind::NotEqual || k == TokenKind::Less ||
          k == TokenKind::LessEqual || k == TokenKind::Greater || k == TokenKind::GreaterEqual;
      });
  }

  int parseSum()
  {
    return parseChain([this] { return parseProduct(); },
      [](TokenKind k)
      {
        return k == TokenKind::Plus || k == TokenKind::Minus || k == TokenKind::Bar ||
          k == TokenKind::Ampersand || k == TokenKind::Backslash || k == TokenKind::At;
      });
  }

  int parseProduct()
  {
    return parseChain([this] { return parsePower(); },
      [](TokenKind k) { return k == TokenKind::Star || k == TokenKind::Slash; });
  }

  int parsePower()
  {
    return parseChain(
      [this] { return parseUnary(); }, [](TokenKind k) { return k == TokenKind::Caret; });
  }

  int parseUnary()
  {
    if (cur_.kind == TokenKind::Plus || cur_.kind == TokenKind::Minus ||
      cur_.kind == TokenKind::Tilde)
    {
      DepthGuard guard(*this);
      ExprNode n;
      n.kind = ExprNode::Kind::Unary;
      n.line = cur_.line;
      n.column = cur_.column;
      n.ops.push_back(cur_.kind);
      advance();
      n.kids.push_back(parseUnary());
      return addExpr(std::move(n));
    }
    return parsePrimary();
  }

  int parseCall(const Token& nameToken)
  {
    ExprNode n;
    n.kind = ExprNode::Kind::Call;
    n.line = nameToken.line;
    n.column = nameToken.column;
    n.name = nameToken.text;
    n.spelling = nameToken.spelling;
    expect(TokenKind::LeftParen, "after the function name");
    if (cur_.kind != TokenKind::RightParen)
    {
      for (;;)
      {
        n.kids.push_back(parseExpression());
        if (cur_.kind != TokenKind::Comma)
        {
          break;
        }
        advance();
      }
    }
    expect(TokenKind::RightParen, "to close the argument list");
    return addExpr(std::move(n));
  }

  int parsePrimary()
  {
    switch (cur_.kind)
    {
      case TokenKind::Number:
      {
        ExprNode n;
        n.kind = ExprNode::Kind::Number;
        n.line = cur_.line;
        n.column = cur_.column;
        n.number = cur_.number;
        n.spelling = cur_.spelling;
        advance();
        return addExpr(std::move(n));
      }
      case TokenKind::LeftParen:
      {
        advance();
        const int e = parseExpression();
        expect(TokenKind::RightParen, "to close '('");
        return e;
      }
      case TokenKind::Identifier:
      {
        const Token nameToken = cur_;
        advance();
        if (cur_.kind == TokenKind::LeftParen)
        {
          DepthGuard guard(*this);
          return parseCall(nameToken);
        }
        ExprNode n;
        n.line = nameToken.line;
        n.column = nameToken.column;
        n.name = nameToken.text;
        n.spelling = nameToken.spelling;
        if (cur_.kind == TokenKind::LeftBracket)
        {
          n.kind = ExprNode::Kind::Index;
          advance();
          n.kids.push_back(parseExpression());
          expect(TokenKind::RightBracket, "after the index");
        }
        else
        {
          n.kind = ExprNode::Kind::Variable;
        }
        return addExpr(std::move(n));
      }
      case TokenKind::String:
        fail(cur_, "strings are not supported by ICTK's HyperFun reader");
      default:
        fail(cur_, "expected an expression, found " + describe(cur_));
    }
  }
};
} // namespace

Program parse(const SourceText& source, DiagnosticSink& sink, const Limits& limits)
{
  Parser p(source, sink, limits);
  return p.run();
}

} // namespace ictk::lang::hf
