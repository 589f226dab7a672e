// SPDX-License-Identifier: BSD-3-Clause
// The .blob reader: a hand-written lexer and recursive descent over nodes. Syntax errors stop
// the parse; a node whose values the BlobTree rejects is reported at its keyword and the parse
// goes on, so one run names every bad node (up to limits.maxDiagnostics).
#include "Lang/BlobReader.h"

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string_view>

namespace ictk::lang
{

namespace
{
using frep::blob::Animation;
using frep::blob::BlobTree;
using frep::blob::Kind;

constexpr double degree = 3.14159265358979323846 / 180.0;

struct Token
{
  enum Type
  {
    End,
    Word,
    Number,
    Symbol
  } type = End;
  std::string_view text;
  double number = 0;
  int line = 1, column = 1;
};

// A value of a node: a constant or an animation, where it was written.
struct Value
{
  double constant = 0;
  std::optional<Animation> animation;
};

class Parser
{
public:
  Parser(
    const std::string& text, const std::string& file, const Limits& limits, BlobOrigins* origins)
    : text_(text)
    , file_(file)
    , limits_(limits)
    , origins_(origins)
  {
    advance();
  }

  BlobTree parse()
  {
    std::optional<std::uint32_t> root;
    while (current_.type != Token::End)
    {
      if (current_.type == Token::Word && current_.text == "threshold")
      {
        const Token at = current_;
        advance();
        Value v = value();
        if (v.animation)
        {
          try
          {
            tree_.animateThreshold(*v.animation);
            if (origins_)
            {
              origins_->threshold = origin(at);
            }
          }
          catch (const std::invalid_argument& e)
          {
            report(at, e.what());
          }
        }
        try
        {
          tree_.setThreshold(v.animation ? v.animation->eval(0) : v.constant);
        }
        catch (const std::invalid_argument& e)
        {
          report(at, e.what());
        }
        continue;
      }
      if (root)
      {
        syntax(current_, "a .blob file holds one root node (wrap several in blend { ... })");
      }
      root = node(0);
    }
    if (!root)
    {
      syntax(current_, "the file holds no node");
    }
    if (!diagnostics_.empty())
    {
      throw ParseError(diagnostics_);
    }
    if (*root != invalid)
    {
      tree_.setRoot(*root);
    }
    return std::move(tree_);
  }

private:
  static constexpr std::uint32_t invalid = 0xffffffffu;

  std::string lineText(int line) const
  {
    std::size_t start = 0;
    for (int l = 1; l < line && start != std::string::npos; ++l)
    {
      start = text_.find('\n', start);
      start = start == std::string::npos ? start : start + 1;
    }
    if (start == std::string::npos || start > text_.size())
    {
      return {};
    }
    const std::size_t end = text_.find('\n', start);
    return text_.substr(start, end == std::string::npos ? std::string::npos : end - start);
  }

  Diagnostic origin(const Token& at) const
  {
    Diagnostic d;
    d.where = SourceLocation{ file_, at.line, at.column };
    d.sourceLine = lineText(at.line);
    return d;
  }

  void report(const Token& at, const std::string& message)
  {
    Diagnostic d;
    d.where = SourceLocation{ file_, at.line, at.column };
    d.message = message;
    d.sourceLine = lineText(at.line);
    diagnostics_.push_back(std::move(d));
    if (diagnostics_.size() >= limits_.maxDiagnostics)
    {
      throw ParseError(diagnostics_);
    }
  }

  [[noreturn]] void syntax(const Token& at, const std::string& message)
  {
    Diagnostic d;
    d.where = SourceLocation{ file_, at.line, at.column };
    d.message = message;
    d.sourceLine = lineText(at.line);
    diagnostics_.push_back(std::move(d));
    throw ParseError(diagnostics_);
  }

  std::string describe(const Token& t) const
  {
    return t.type == Token::End ? std::string("the end of the file")
                                : "'" + std::string(t.text.substr(0, 40)) + "'";
  }

  void advance()
  {
    // Skip blanks and comments.
    while (pos_ < text_.size())
    {
      const char c = text_[pos_];
      if (c == '#')
      {
        while (pos_ < text_.size() && text_[pos_] != '\n')
        {
          ++pos_;
        }
      }
      else if (c == '\n')
      {
        ++pos_;
        ++line_;
        lineStart_ = pos_;
      }
      else if (c == ' ' || c == '\t' || c == '\r')
      {
        ++pos_;
      }
      else
      {
        break;
      }
    }
    current_ = Token{};
    current_.line = line_;
    current_.column = static_cast<int>(pos_ - lineStart_) + 1;
    if (pos_ >= text_.size())
    {
      return;
    }
    const std::size_t start = pos_;
    const auto u = static_cast<unsigned char>(text_[pos_]);
    if (std::isalpha(u) || text_[pos_] == '_')
    {
      while (pos_ < text_.size() &&
        (std::isalnum(static_cast<unsigned char>(text_[pos_])) || text_[pos_] == '_'))
      {
        ++pos_;
      }
      current_.type = Token::Word;
    }
    else if (std::isdigit(u) || text_[pos_] == '-' || text_[pos_] == '+' || text_[pos_] == '.')
    {
      // A number: sign, digits, point, exponent; nothing else (no inf, nan or hex).
      if (text_[pos_] == '-' || text_[pos_] == '+')
      {
        ++pos_;
      }
      bool digits = false;
      while (pos_ < text_.size() && std::isdigit(static_cast<unsigned char>(text_[pos_])))
      {
        ++pos_;
        digits = true;
      }
      if (pos_ < text_.size() && text_[pos_] == '.')
      {
        ++pos_;
        while (pos_ < text_.size() && std::isdigit(static_cast<unsigned char>(text_[pos_])))
        {
          ++pos_;
          digits = true;
        }
      }
      if (digits && pos_ < text_.size() && (text_[pos_] == 'e' || text_[pos_] == 'E'))
      {
        std::size_t e = pos_ + 1;
        if (e < text_.size() && (text_[e] == '-' || text_[e] == '+'))
        {
          ++e;
        }
        if (e < text_.size() && std::isdigit(static_cast<unsigned char>(text_[e])))
        {
          pos_ = e;
          while (pos_ < text_.size() && std::isdigit(static_cast<unsigned char>(text_[pos_])))
          {
            ++pos_;
          }
        }
      }
      current_.text = std::string_view(text_).substr(start, pos_ - start);
      if (!digits)
      {
        syntax(current_, "expected a number, got " + describe(current_));
      }
      const std::string s(current_.text);
      current_.number = std::strtod(s.c_str(), nullptr);
      if (!std::isfinite(current_.number))
      {
        syntax(current_, "the number " + s + " is out of range");
      }
      current_.type = Token::Number;
      return;
    }
    else
    {
      ++pos_;
      current_.type = Token::Symbol;
      if (std::string_view("{}[](),").find(text_[start]) == std::string_view::npos)
      {
        current_.text = std::string_view(text_).substr(start, 1);
        syntax(current_, "unexpected character " + describe(current_));
      }
    }
    current_.text = std::string_view(text_).substr(start, pos_ - start);
  }

  bool isSymbol(char c) const { return current_.type == Token::Symbol && current_.text[0] == c; }

  void expect(char c)
  {
    if (!isSymbol(c))
    {
      syntax(current_, std::string("expected '") + c + "', got " + describe(current_));
    }
    advance();
  }

  double number()
  {
    if (current_.type != Token::Number)
    {
      syntax(current_, "expected a number, got " + describe(current_));
    }
    const double v = current_.number;
    advance();
    return v;
  }

  // number | wave(b a p phase) | keys(n, t v ..., t v ...)
  Value value()
  {
    Value v;
    if (current_.type == Token::Word && current_.text == "wave")
    {
      advance();
      expect('(');
      Animation a;
      a.base = number();
      a.amplitude = number();
      a.period = number();
      a.phase = number();
      expect(')');
      v.animation = a;
      return v;
    }
    if (current_.type == Token::Word && current_.text == "keys")
    {
      advance();
      expect('(');
      Animation a;
      a.type = Animation::Type::Keys;
      const Token orderAt = current_;
      const double order = number();
      if (!(order >= 1 && order <= 4 && order == std::floor(order)))
      {
        syntax(orderAt, "the key-frame order n must be 1, 2, 3 or 4");
      }
      a.order = static_cast<int>(order);
      while (isSymbol(','))
      {
        advance();
        std::vector<double> key;
        for (int k = 0; k <= a.order; ++k)
        {
          key.push_back(number());
        }
        a.keys.push_back(std::move(key));
        if (a.keys.size() > 100000)
        {
          syntax(current_, "too many key-frames");
        }
      }
      if (a.keys.empty())
      {
        syntax(current_, "key-frames need at least one key: keys(n, t v ..., ...)");
      }
      for (std::size_t k = 1; k < a.keys.size(); ++k)
      {
        if (!(a.keys[k][0] > a.keys[k - 1][0]))
        {
          syntax(current_, "key times must increase");
        }
      }
      expect(')');
      v.animation = std::move(a);
      return v;
    }
    v.constant = number();
    return v;
  }

  static std::optional<Kind> kindOf(std::string_view word)
  {
    for (int k = 0; k <= static_cast<int>(Kind::Twist); ++k)
    {
      if (word == frep::blob::kindName(static_cast<Kind>(k)))
      {
        return static_cast<Kind>(k);
      }
    }
    return std::nullopt;
  }

  // KIND values... [ { node... } ]; returns the node, or `invalid` after a reported error.
  std::uint32_t node(int depth)
  {
    if (depth >= limits_.maxNesting)
    {
      syntax(
        current_, "nodes are nested more than " + std::to_string(limits_.maxNesting) + " deep");
    }
    if (++nodeCount_ > limits_.maxSyntaxNodes)
    {
      syntax(
        current_, "the file has more than " + std::to_string(limits_.maxSyntaxNodes) + " nodes");
    }
    const Token at = current_;
    if (current_.type != Token::Word)
    {
      syntax(current_,
        "expected a node (point, segment, blend, union, rotate, ...), got " + describe(current_));
    }
    const std::optional<Kind> kind = kindOf(current_.text);
    if (!kind)
    {
      syntax(current_, "unknown node " + describe(current_));
    }
    advance();
    std::vector<double> values;
    std::vector<std::pair<std::uint32_t, Animation>> animations;
    int open = 0;
    while (current_.type == Token::Number || isSymbol('[') || isSymbol(']') ||
      (current_.type == Token::Word && (current_.text == "wave" || current_.text == "keys")))
    {
      if (isSymbol('['))
      {
        ++open;
        advance();
        continue;
      }
      if (isSymbol(']'))
      {
        if (open == 0)
        {
          syntax(current_, "']' without '['");
        }
        --open;
        advance();
        continue;
      }
      Value v = value();
      if (v.animation)
      {
        animations.emplace_back(static_cast<std::uint32_t>(values.size()), *v.animation);
        v.constant = v.animation->eval(0);
      }
      values.push_back(v.constant);
      if (values.size() > 4 * 1000000)
      {
        syntax(current_, "too many values for one node");
      }
    }
    if (open != 0)
    {
      syntax(current_, "expected ']', got " + describe(current_));
    }
    std::vector<std::uint32_t> children;
    bool childFailed = false;
    if (isSymbol('{'))
    {
      advance();
      while (!isSymbol('}'))
      {
        if (current_.type == Token::End)
        {
          syntax(current_,
            "expected '}' closing the " + std::string(frep::blob::kindName(*kind)) + " at " +
              std::to_string(at.line) + ":" + std::to_string(at.column));
        }
        const std::uint32_t child = node(depth + 1);
        childFailed = childFailed || child == invalid;
        children.push_back(child);
      }
      advance();
    }
    if (childFailed)
    {
      return invalid;
    }
    // Angles are degrees in the file.
    if (*kind == Kind::Rotate && values.size() == 4)
    {
      values[3] *= degree;
    }
    if (*kind == Kind::Twist && values.size() == 1)
    {
      values[0] *= degree;
    }
    // Every skeletal element lowers to some 64 expression nodes: bound them before building.
    std::size_t elements = frep::blob::isSkeletal(*kind) ? 1 : 0;
    if (*kind == Kind::Curve && values.size() >= 8)
    {
      elements = (values.size() - 5) / 3;
    }
    if (frep::blob::isComplexPrimitive(*kind) && *kind != Kind::ThickSurface &&
      values.size() >= 3 && values[2] >= 1 && values[2] <= 100000)
    {
      elements = static_cast<std::size_t>(values[2]);
    }
    if (*kind == Kind::ThickSurface && values.size() >= 2)
    {
      elements = (values.size() - 2) / 12; // a triangle each
    }
    // A solid texture's noise lowers to some 150 expression nodes an octave.
    if (frep::blob::isTexture(*kind) && *kind != Kind::Material && values.size() == 12 &&
      values[11] >= 1 && values[11] <= 8)
    {
      elements = 1 + 3 * static_cast<std::size_t>(values[11]);
    }
    expandedLeaves_ += elements;
    if (expandedLeaves_ * 64 > limits_.maxExpressionNodes)
    {
      report(at,
        "the tree expands to more than " + std::to_string(limits_.maxExpressionNodes / 64) +
          " skeletal elements");
      return invalid;
    }
    try
    {
      const std::uint32_t index = tree_.add(*kind, values, children);
      for (auto& [slot, animation] : animations)
      {
        if ((*kind == Kind::Rotate && slot == 3) || (*kind == Kind::Twist && slot == 0))
        {
          animation.base *= degree;
          animation.amplitude *= degree;
          for (auto& key : animation.keys)
          {
            for (std::size_t k = 1; k < key.size(); ++k)
            {
              key[k] *= degree;
            }
          }
        }
        tree_.animate(index, slot, std::move(animation));
      }
      if (origins_ && !animations.empty())
      {
        origins_->nodes[index] = origin(at);
      }
      return index;
    }
    catch (const std::invalid_argument& e)
    {
      report(at, e.what());
      return invalid;
    }
  }

  const std::string& text_;
  std::string file_;
  Limits limits_;
  BlobOrigins* origins_;
  std::size_t pos_ = 0, lineStart_ = 0;
  int line_ = 1;
  Token current_;
  BlobTree tree_;
  std::vector<Diagnostic> diagnostics_;
  std::size_t nodeCount_ = 0;
  std::size_t expandedLeaves_ = 0;
};

} // namespace

frep::blob::BlobTree readBlob(
  const std::string& text, const std::string& fileName, const Limits& limits, BlobOrigins* origins)
{
  if (origins)
  {
    *origins = {};
  }
  if (text.size() > limits.maxFileBytes)
  {
    Diagnostic d;
    d.where.file = fileName;
    d.message = "the text has " + std::to_string(text.size()) + " bytes, more than the limit of " +
      std::to_string(limits.maxFileBytes);
    throw ParseError({ d });
  }
  return Parser(text, fileName, limits, origins).parse();
}

frep::blob::BlobTree readBlobFile(
  const std::string& path, const Limits& limits, BlobOrigins* origins)
{
  return readBlob(readSourceFile(path, limits), path, limits, origins);
}

frep::blob::BlobTree instantiateBlob(
  const frep::blob::BlobTree& tree, const BlobOrigins& origins, double t)
{
  try
  {
    return tree.instantiate(t);
  }
  catch (const frep::blob::InstanceError& e)
  {
    const Diagnostic* at = nullptr;
    if (e.node() == frep::blob::InstanceError::Threshold)
    {
      at = origins.threshold ? &*origins.threshold : nullptr;
    }
    else if (const auto found = origins.nodes.find(e.node()); found != origins.nodes.end())
    {
      at = &found->second;
    }
    if (!at)
    {
      throw;
    }
    Diagnostic d = *at;
    std::ostringstream time;
    time.precision(12);
    time << e.time();
    d.message = e.reason() + " at t = " + time.str();
    throw ParseError({ d });
  }
}

namespace
{
// The shortest decimal form that reads back to the same double.
void appendNumber(std::string& out, double v)
{
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, v);
  out.append(buffer, result.ptr);
}

// Rotate's angle and twist's rate are degrees in the file (the reader's conversion, undone).
bool isAngle(Kind kind, std::uint32_t slot)
{
  return (kind == Kind::Rotate && slot == 3) || (kind == Kind::Twist && slot == 0);
}

void appendAnimation(std::string& out, const Animation& a, double scale)
{
  if (a.type == Animation::Type::Wave)
  {
    out += "wave(";
    appendNumber(out, a.base * scale);
    out += ' ';
    appendNumber(out, a.amplitude * scale);
    out += ' ';
    appendNumber(out, a.period);
    out += ' ';
    appendNumber(out, a.phase); // radians, as read
    out += ')';
    return;
  }
  out += "keys(" + std::to_string(a.order);
  for (const auto& key : a.keys)
  {
    out += ',';
    for (std::size_t k = 0; k < key.size(); ++k)
    {
      out += ' ';
      appendNumber(out, k == 0 ? key[k] : key[k] * scale); // the time is not an angle
    }
  }
  out += ')';
}

void appendNode(std::string& out, const frep::blob::BlobTree& tree, std::uint32_t index, int depth)
{
  constexpr double toDegrees = 180.0 / 3.14159265358979323846;
  const frep::blob::Node& node = tree.node(index);
  out.append(2 * static_cast<std::size_t>(depth), ' ');
  out += frep::blob::kindName(node.kind);
  const double* values = tree.values(index);
  for (std::uint32_t k = 0; k < node.valueCount; ++k)
  {
    out += ' ';
    const double scale = isAngle(node.kind, k) ? toDegrees : 1.0;
    if (const Animation* a = tree.animation(index, k))
    {
      appendAnimation(out, *a, scale);
    }
    else
    {
      appendNumber(out, values[k] * scale);
    }
  }
  if (node.childCount == 0)
  {
    out += '\n';
    return;
  }
  out += " {\n";
  const std::uint32_t* children = tree.children(index);
  for (std::uint32_t k = 0; k < node.childCount; ++k)
  {
    appendNode(out, tree, children[k], depth + 1);
  }
  out.append(2 * static_cast<std::size_t>(depth), ' ');
  out += "}\n";
}
} // namespace

std::string writeBlob(const frep::blob::BlobTree& tree)
{
  if (tree.empty())
  {
    throw std::invalid_argument("writeBlob: the tree is empty");
  }
  std::string out = "# A BlobTree (docs/blobtree.md), written by ICTK\nthreshold ";
  if (const Animation* a = tree.thresholdAnimation())
  {
    appendAnimation(out, *a, 1.0);
  }
  else
  {
    appendNumber(out, tree.threshold());
  }
  out += '\n';
  appendNode(out, tree, tree.root(), 0);
  return out;
}

} // namespace ictk::lang
