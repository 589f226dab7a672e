// SPDX-License-Identifier: BSD-3-Clause
#include "Lang/VmReader.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <optional>
#include <string_view>
#include <unordered_map>
#include <vector>

namespace ictk::lang
{

namespace
{
using frep::Expr;
using frep::Opcode;

enum class Kind
{
  Constant,
  Variable,
  Unary,
  Binary
};

struct OpInfo
{
  const char* name;
  Kind kind;
  Opcode op;
  frep::Axis axis;
};

// clang-format off
const OpInfo Ops[] = {
  { "const", Kind::Constant, Opcode::Constant, frep::Axis::X },
  { "var-x", Kind::Variable, Opcode::Variable, frep::Axis::X },
  { "var-y", Kind::Variable, Opcode::Variable, frep::Axis::Y },
  { "var-z", Kind::Variable, Opcode::Variable, frep::Axis::Z },
  { "add", Kind::Binary, Opcode::Add, frep::Axis::X },
  { "sub", Kind::Binary, Opcode::Sub, frep::Axis::X },
  { "mul", Kind::Binary, Opcode::Mul, frep::Axis::X },
  { "div", Kind::Binary, Opcode::Div, frep::Axis::X },
  { "min", Kind::Binary, Opcode::Min, frep::Axis::X },
  { "max", Kind::Binary, Opcode::Max, frep::Axis::X },
  { "neg", Kind::Unary, Opcode::Neg, frep::Axis::X },
  { "square", Kind::Unary, Opcode::Square, frep::Axis::X },
  { "sqrt", Kind::Unary, Opcode::Sqrt, frep::Axis::X },
  { "abs", Kind::Unary, Opcode::Abs, frep::Axis::X },
  { "exp", Kind::Unary, Opcode::Exp, frep::Axis::X },
  { "ln", Kind::Unary, Opcode::Log, frep::Axis::X },
  { "sin", Kind::Unary, Opcode::Sin, frep::Axis::X },
  { "cos", Kind::Unary, Opcode::Cos, frep::Axis::X },
};
// clang-format on

const OpInfo* findOp(std::string_view name)
{
  for (const OpInfo& op : Ops)
  {
    if (name == op.name)
    {
      return &op;
    }
  }
  return nullptr;
}

int operandCount(Kind k)
{
  switch (k)
  {
    case Kind::Constant:
    case Kind::Unary:
      return 1;
    case Kind::Variable:
      return 0;
    case Kind::Binary:
      return 2;
  }
  return 0;
}

struct Token
{
  std::string_view text;
  int column; // 1-based
};

bool isSpace(char c)
{
  return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

// Long lines are shown without their text (a caret under a megabyte of text helps nobody).
constexpr std::size_t MaxShownLine = 400;

// Displayed names are cut short and stripped of control characters.
std::string quoted(std::string_view s)
{
  std::string out = "'";
  for (std::size_t i = 0; i < s.size() && i < 40; ++i)
  {
    const auto c = static_cast<unsigned char>(s[i]);
    out += (c < 0x20 || c == 0x7f) ? '?' : static_cast<char>(c);
  }
  if (s.size() > 40)
  {
    out += "...";
  }
  return out + "'";
}

class Parser
{
public:
  Parser(const std::string& fileName, const Limits& limits)
    : fileName_(fileName)
    , limits_(limits)
  {
  }

  VmModel parse(std::string_view text)
  {
    if (text.size() > limits_.maxFileBytes)
    {
      error(1, 0, {},
        "file is too large: " + std::to_string(text.size()) + " bytes, the limit is " +
          std::to_string(limits_.maxFileBytes));
      throw ParseError(std::move(diagnostics_));
    }
    std::size_t start = 0;
    int lineNumber = 0;
    while (start <= text.size() && !full() && !stopped_)
    {
      std::size_t end = text.find('\n', start);
      if (end == std::string_view::npos)
      {
        end = text.size();
      }
      ++lineNumber;
      std::string_view line = text.substr(start, end - start);
      if (!line.empty() && line.back() == '\r')
      {
        line.remove_suffix(1);
      }
      parseLine(line, lineNumber);
      if (end == text.size())
      {
        break;
      }
      start = end + 1;
    }
    if (diagnostics_.empty() && model_.instructionCount == 0)
    {
      error(0, 0, {}, "the file has no instructions (expected lines '_ID OPCODE ARGS...')");
    }
    if (!diagnostics_.empty())
    {
      throw ParseError(std::move(diagnostics_));
    }
    model_.raw = *last_;
    model_.function = -*last_;
    return std::move(model_);
  }

private:
  bool full() const
  {
    return diagnostics_.size() >= std::max<std::size_t>(1, limits_.maxDiagnostics);
  }

  void error(int line, int column, std::string_view source, std::string message)
  {
    if (full())
    {
      return;
    }
    Diagnostic d;
    d.where.file = fileName_;
    d.where.line = line;
    d.where.column = column;
    d.message = std::move(message);
    if (source.size() <= MaxShownLine)
    {
      d.sourceLine = std::string(source);
    }
    diagnostics_.push_back(std::move(d));
  }

  void parseLine(std::string_view line, int lineNumber)
  {
    // Up to five tokens: id, opcode, at most two operands, and one too many.
    std::vector<Token> tokens;
    std::size_t i = 0;
    while (i < line.size() && tokens.size() < 5)
    {
      while (i < line.size() && isSpace(line[i]))
      {
        ++i;
      }
      if (i == line.size())
      {
        break;
      }
      const std::size_t b = i;
      while (i < line.size() && !isSpace(line[i]))
      {
        ++i;
      }
      tokens.push_back({ line.substr(b, i - b), static_cast<int>(b + 1) });
    }
    if (tokens.empty() || tokens[0].text[0] == '#')
    {
      return;
    }
    ++model_.instructionCount;
    if (model_.instructionCount > limits_.maxExpressionNodes)
    {
      error(lineNumber, tokens[0].column, line,
        "more than " + std::to_string(limits_.maxExpressionNodes) + " instructions");
      stopped_ = true; // nothing later can be read
      return;
    }
    const Token& id = tokens[0];
    // Whatever goes wrong below, the name is defined (as unusable), so that later lines naming
    // it do not report again.
    std::optional<Expr> value = define(tokens, line, lineNumber);
    auto [it, inserted] = values_.try_emplace(std::string(id.text), Entry{ value, lineNumber });
    if (!inserted)
    {
      error(lineNumber, id.column, line,
        quoted(id.text) + " is already defined at line " + std::to_string(it->second.line));
      it->second.value.reset();
    }
    last_ = inserted ? value : std::nullopt;
  }

  std::optional<Expr> define(const std::vector<Token>& tokens, std::string_view line, int lineNo)
  {
    const Token& id = tokens[0];
    if (tokens.size() < 2)
    {
      error(lineNo, static_cast<int>(id.column + id.text.size()), line,
        "expected an opcode after " + quoted(id.text));
      return std::nullopt;
    }
    const Token& opToken = tokens[1];
    const OpInfo* op = findOp(opToken.text);
    if (!op)
    {
      error(lineNo, opToken.column, line,
        "unknown opcode " + quoted(opToken.text) +
          " (expected const, var-x, var-y, var-z, add, sub, mul, div, neg, square, sqrt, abs, "
          "min, max, exp, ln, sin or cos)");
      return std::nullopt;
    }
    const int expected = operandCount(op->kind);
    const int given = static_cast<int>(tokens.size()) - 2;
    if (given < expected)
    {
      const Token& lastToken = tokens.back();
      error(lineNo, static_cast<int>(lastToken.column + lastToken.text.size()), line,
        std::string("'") + op->name + "' expects " +
          (op->kind == Kind::Constant ? std::string("a number")
                                      : std::to_string(expected) + " operand(s)") +
          ", got " + std::to_string(given));
      return std::nullopt;
    }
    if (given > expected)
    {
      error(lineNo, tokens[2 + expected].column, line,
        "unexpected " + quoted(tokens[2 + expected].text) + ": '" + op->name + "' expects " +
          (op->kind == Kind::Constant ? std::string("one number")
                                      : std::to_string(expected) + " operand(s)"));
      return std::nullopt;
    }
    switch (op->kind)
    {
      case Kind::Constant:
      {
        const Token& t = tokens[2];
        double v = 0;
        const char* first = t.text.data();
        const char* last = first + t.text.size();
        const auto [end, ec] = std::from_chars(first, last, v);
        if (ec == std::errc::result_out_of_range)
        {
          error(lineNo, t.column, line, "the number " + quoted(t.text) + " is out of range");
          return std::nullopt;
        }
        if (ec != std::errc() || end != last)
        {
          error(lineNo, t.column, line, quoted(t.text) + " is not a number");
          return std::nullopt;
        }
        if (std::isnan(v))
        {
          error(lineNo, t.column, line, "the constant is NaN");
          return std::nullopt;
        }
        return Expr::constant(v);
      }
      case Kind::Variable:
        model_.axesUsed |= static_cast<std::uint8_t>(1u << static_cast<int>(op->axis));
        return Expr::variable(op->axis);
      case Kind::Unary:
      case Kind::Binary:
      {
        std::optional<Expr> operands[2];
        bool ok = true;
        for (int k = 0; k < expected; ++k)
        {
          const Token& t = tokens[2 + k];
          auto it = values_.find(std::string(t.text));
          if (it == values_.end())
          {
            error(lineNo, t.column, line,
              quoted(t.text) + " is not defined (operands name earlier instructions)");
            ok = false;
            continue;
          }
          operands[k] = it->second.value;
          ok = ok && operands[k].has_value(); // an earlier error: already reported
        }
        if (!ok)
        {
          return std::nullopt;
        }
        if (op->kind == Kind::Unary)
        {
          return Expr::make(op->op, *operands[0]);
        }
        return Expr::make(op->op, *operands[0], *operands[1]);
      }
    }
    return std::nullopt;
  }

  struct Entry
  {
    std::optional<Expr> value;
    int line;
  };

  std::string fileName_;
  const Limits& limits_;
  std::vector<Diagnostic> diagnostics_;
  std::unordered_map<std::string, Entry> values_;
  std::optional<Expr> last_;
  VmModel model_;
  bool stopped_ = false;
};
} // namespace

VmModel readVm(const std::string& text, const std::string& fileName, const Limits& limits)
{
  return Parser(fileName, limits).parse(text);
}

VmModel readVmFile(const std::string& path, const Limits& limits)
{
  const std::string text = readSourceFile(path, limits);
  return readVm(text, path, limits);
}

} // namespace ictk::lang
