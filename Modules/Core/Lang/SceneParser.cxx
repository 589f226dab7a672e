// SPDX-License-Identifier: BSD-3-Clause
// The .scn scene language (Lang/Scene.h): tokens, the recursive-descent parser with its
// diagnostics, the reading of `object` references, and the writer of self-contained files.
#include "Lang/Scene.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <system_error>
#include <utility>

namespace ictk::lang
{

namespace
{

/// The transformations' keywords, for the parser and the writer.
constexpr std::pair<const char*, SceneTransform::Kind> TransformKeywords[] = {
  { "move", SceneTransform::Kind::Move }, { "rotate", SceneTransform::Kind::Rotate },
  { "scale", SceneTransform::Kind::Scale }, { "skewx", SceneTransform::Kind::SkewX },
  { "skewy", SceneTransform::Kind::SkewY }, { "skewz", SceneTransform::Kind::SkewZ },
  { "matrix", SceneTransform::Kind::Matrix }
};

enum class TokenKind
{
  End,
  Word,
  Number,
  String,
  LeftBrace,
  RightBrace,
  Bad
};

struct Token
{
  TokenKind kind = TokenKind::End;
  std::string text;
  double number = 0;
  int line = 1;
  int column = 1;
};

/// Raised inside the parser when the diagnostics are at their limit.
struct TooManyErrors
{};

class Parser
{
public:
  Parser(const std::string& text, const std::string& file, const SceneLoader& loader,
    const Limits& limits, std::vector<std::string>& stack)
    : text_(text)
    , file_(file)
    , loader_(loader)
    , limits_(limits)
    , stack_(stack)
  {
    advance();
  }

  Scene parse()
  {
    Scene scene;
    scene.file = file_;
    try
    {
      while (token_.kind != TokenKind::End)
      {
        if (token_.kind == TokenKind::RightBrace)
        {
          error(token_, "'}' without a matching '{'");
          advance();
          continue;
        }
        if (std::optional<SceneNode> node = object(0))
        {
          scene.objects.push_back(std::move(*node));
        }
      }
      if (scene.objects.empty() && diagnostics_.empty())
      {
        error(token_, "the scene has no object");
      }
    }
    catch (const TooManyErrors&)
    {
    }
    if (!diagnostics_.empty())
    {
      throw ParseError(std::move(diagnostics_));
    }
    return scene;
  }

private:
  // --- tokens -----------------------------------------------------------------------------------
  char peek(std::size_t ahead = 0) const
  {
    return pos_ + ahead < text_.size() ? text_[pos_ + ahead] : '\0';
  }
  void bump()
  {
    if (text_[pos_] == '\n')
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
  static bool wordStart(char c) { return std::isalpha(static_cast<unsigned char>(c)) || c == '_'; }
  static bool wordPart(char c)
  {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '.' || c == '-' ||
      c == '/';
  }
  static bool digit(char c) { return std::isdigit(static_cast<unsigned char>(c)) != 0; }

  void advance()
  {
    // Blanks and comments: // to the end of the line, /* ... */.
    while (pos_ < text_.size())
    {
      const char c = peek();
      if (std::isspace(static_cast<unsigned char>(c)))
      {
        bump();
      }
      else if (c == '/' && peek(1) == '/')
      {
        while (pos_ < text_.size() && peek() != '\n')
        {
          bump();
        }
      }
      else if (c == '/' && peek(1) == '*')
      {
        Token open{ TokenKind::Bad, "", 0, line_, column_ };
        bump();
        bump();
        while (pos_ < text_.size() && !(peek() == '*' && peek(1) == '/'))
        {
          bump();
        }
        if (pos_ >= text_.size())
        {
          error(open, "unterminated comment");
          break;
        }
        bump();
        bump();
      }
      else
      {
        break;
      }
    }
    token_ = Token{};
    token_.line = line_;
    token_.column = column_;
    if (pos_ >= text_.size())
    {
      return;
    }
    const std::size_t start = pos_;
    const char c = peek();
    if (c == '{' || c == '}')
    {
      token_.kind = c == '{' ? TokenKind::LeftBrace : TokenKind::RightBrace;
      token_.text = std::string(1, c);
      bump();
      return;
    }
    if (wordStart(c))
    {
      while (pos_ < text_.size() && wordPart(peek()))
      {
        bump();
      }
      token_.kind = TokenKind::Word;
      token_.text = text_.substr(start, pos_ - start);
      return;
    }
    if (digit(c) || ((c == '-' || c == '+' || c == '.') && (digit(peek(1)) || peek(1) == '.')))
    {
      if (c == '-' || c == '+')
      {
        bump();
      }
      while (digit(peek()))
      {
        bump();
      }
      if (peek() == '.')
      {
        bump();
        while (digit(peek()))
        {
          bump();
        }
      }
      if ((peek() == 'e' || peek() == 'E') &&
        (digit(peek(1)) || ((peek(1) == '-' || peek(1) == '+') && digit(peek(2)))))
      {
        bump();
        bump();
        while (digit(peek()))
        {
          bump();
        }
      }
      token_.text = text_.substr(start, pos_ - start);
      errno = 0;
      char* end = nullptr;
      token_.number = std::strtod(token_.text.c_str(), &end);
      token_.kind = TokenKind::Number;
      if (end != token_.text.c_str() + token_.text.size() || !std::isfinite(token_.number))
      {
        token_.kind = TokenKind::Bad;
        error(token_, "'" + token_.text + "' is not a finite number");
      }
      return;
    }
    if (c == '"')
    {
      bump();
      while (pos_ < text_.size() && peek() != '"' && peek() != '\n')
      {
        bump();
      }
      if (peek() != '"')
      {
        token_.kind = TokenKind::Bad;
        error(token_, "unterminated string");
        return;
      }
      token_.kind = TokenKind::String;
      token_.text = text_.substr(start + 1, pos_ - start - 1);
      bump();
      return;
    }
    // One character, or a whole UTF-8 sequence, that starts nothing.
    bump();
    while (pos_ < text_.size() && (static_cast<unsigned char>(peek()) & 0xC0) == 0x80)
    {
      bump();
    }
    token_.kind = TokenKind::Bad;
    token_.text = text_.substr(start, pos_ - start);
    error(token_, "unexpected character '" + token_.text + "'");
  }

  // --- diagnostics ------------------------------------------------------------------------------
  SourceLocation at(const Token& t) const { return { file_, t.line, t.column }; }

  std::string lineText(int line) const
  {
    std::size_t begin = 0;
    for (int l = 1; l < line && begin != std::string::npos; ++l)
    {
      begin = text_.find('\n', begin);
      begin = begin == std::string::npos ? begin : begin + 1;
    }
    if (begin == std::string::npos)
    {
      return {};
    }
    const std::size_t end = text_.find('\n', begin);
    std::string s = text_.substr(begin, end == std::string::npos ? end : end - begin);
    if (!s.empty() && s.back() == '\r')
    {
      s.pop_back();
    }
    return s;
  }

  void error(const Token& t, const std::string& message)
  {
    diagnostics_.push_back({ at(t), message, lineText(t.line) });
    if (diagnostics_.size() >= limits_.maxDiagnostics)
    {
      throw TooManyErrors{};
    }
  }

  void countNode(const Token& t)
  {
    if (++nodes_ > limits_.maxSyntaxNodes)
    {
      error(t, "the scene has more than " + std::to_string(limits_.maxSyntaxNodes) + " objects");
      throw TooManyErrors{};
    }
  }

  // --- grammar ----------------------------------------------------------------------------------
  /// n numbers after a keyword; false (and a diagnostic) when they are not there.
  bool numbers(const Token& keyword, std::size_t n, std::vector<double>& out)
  {
    for (std::size_t i = 0; i < n; ++i)
    {
      if (token_.kind != TokenKind::Number)
      {
        error(keyword,
          "'" + keyword.text + "' takes " + std::to_string(n) + " number" + (n == 1 ? "" : "s") +
            (i == 0 ? std::string() : ", found " + std::to_string(i)));
        return false;
      }
      out.push_back(token_.number);
      advance();
    }
    return true;
  }

  /// An object starting at the current token (a keyword), or nullopt after an error (the token
  /// was skipped).
  std::optional<SceneNode> object(int depth)
  {
    const Token keyword = token_;
    if (keyword.kind != TokenKind::Word)
    {
      if (keyword.kind != TokenKind::Bad)
      {
        error(keyword,
          "expected an object (a quadric type, torus, cube, union, intersection, "
          "inter or object), found '" +
            keyword.text + "'");
      }
      advance();
      return std::nullopt;
    }
    SceneNode node;
    node.where = at(keyword);
    const std::string& w = keyword.text;
    if (std::optional<frep::QuadricType> q = frep::quadricTypeFromKeyword(w))
    {
      node.kind = SceneNode::Kind::Quadric;
      node.quadric = *q;
    }
    else if (w == "torus")
    {
      node.kind = SceneNode::Kind::Torus;
    }
    else if (w == "cube")
    {
      node.kind = SceneNode::Kind::Cube;
    }
    else if (w == "union")
    {
      node.kind = SceneNode::Kind::Union;
    }
    else if (w == "intersection" || w == "inter")
    {
      node.kind = SceneNode::Kind::Intersection;
    }
    else if (w == "object")
    {
      node.kind = SceneNode::Kind::Object;
    }
    else
    {
      error(keyword,
        "unknown object '" + w +
          "' (expected a quadric type, torus, cube, union, intersection, inter or object)");
      advance();
      return std::nullopt;
    }
    countNode(keyword);
    advance();
    if (depth > limits_.maxNesting)
    {
      error(keyword, "objects nested deeper than " + std::to_string(limits_.maxNesting));
      throw TooManyErrors{};
    }
    bool ok = true;
    if (node.kind == SceneNode::Kind::Object)
    {
      ok = reference(keyword, node);
    }
    if (token_.kind == TokenKind::LeftBrace)
    {
      block(node, depth);
    }
    const bool compound =
      node.kind == SceneNode::Kind::Union || node.kind == SceneNode::Kind::Intersection;
    if (compound && node.children.empty())
    {
      error(keyword, "'" + w + "' holds no object");
      ok = false;
    }
    return ok ? std::optional<SceneNode>(std::move(node)) : std::nullopt;
  }

  bool reference(const Token& keyword, SceneNode& node)
  {
    if (token_.kind != TokenKind::Word && token_.kind != TokenKind::String)
    {
      error(token_.kind == TokenKind::End ? keyword : token_,
        "'object' takes the name of a scene file");
      return false;
    }
    const Token name = token_;
    advance();
    node.reference = name.text;
    if (!loader_)
    {
      error(name, "'object " + name.text + "': references to files are not read here");
      return false;
    }
    std::optional<std::pair<std::string, std::string>> found = loader_(name.text, file_);
    if (!found)
    {
      error(name,
        "'object " + name.text + "': no file " + name.text + ", " + name.text + ".scn or " +
          name.text + ".scene");
      return false;
    }
    node.referencedFile = found->first;
    if (std::find(stack_.begin(), stack_.end(), found->first) != stack_.end())
    {
      error(name,
        "'object " + name.text + "' refers to '" + found->first +
          "', which is being read: the references form a cycle");
      return false;
    }
    if (static_cast<int>(stack_.size()) > limits_.maxNesting)
    {
      error(name, "object references nested deeper than " + std::to_string(limits_.maxNesting));
      return false;
    }
    stack_.push_back(found->first);
    try
    {
      Scene inner = Parser(found->second, found->first, loader_, limits_, stack_).parse();
      stack_.pop_back();
      node.children = std::move(inner.objects);
      return true;
    }
    catch (const ParseError& e)
    {
      stack_.pop_back();
      for (const Diagnostic& d : e.diagnostics())
      {
        diagnostics_.push_back(d);
      }
      error(name, "in the scene 'object " + name.text + "' refers to");
      return false;
    }
  }

  void block(SceneNode& node, int depth)
  {
    const Token open = token_;
    advance();
    const bool compound =
      node.kind == SceneNode::Kind::Union || node.kind == SceneNode::Kind::Intersection;
    const bool primitive = node.kind == SceneNode::Kind::Quadric ||
      node.kind == SceneNode::Kind::Torus || node.kind == SceneNode::Kind::Cube;
    while (token_.kind != TokenKind::RightBrace)
    {
      if (token_.kind == TokenKind::End)
      {
        error(open, "'{' is not closed");
        return;
      }
      if (token_.kind != TokenKind::Word)
      {
        if (token_.kind != TokenKind::Bad)
        {
          error(token_, "unexpected '" + token_.text + "' in a block");
        }
        advance();
        continue;
      }
      const Token item = token_;
      if (this->item(node, item))
      {
        continue;
      }
      if (item.text == "perturb")
      {
        advance();
        if (!primitive)
        {
          error(item, "'perturb' applies to a quadric, torus or cube, not to a group");
        }
        perturbation(node, item, depth);
        continue;
      }
      if (item.text == "radii")
      {
        advance();
        std::vector<double> r;
        if (node.kind != SceneNode::Kind::Torus)
        {
          error(item, "'radii' applies to a torus");
        }
        if (numbers(item, 2, r))
        {
          if (!(r[0] > 0) || !(r[1] > 0))
          {
            error(item, "a torus' radii must be positive");
          }
          node.radii = { r[0], r[1] };
          node.hasRadii = true;
        }
        continue;
      }
      if (!compound)
      {
        error(item,
          "'" + item.text + "' is not an item of " +
            std::string(node.kind == SceneNode::Kind::Object ? "an object reference"
                                                             : "a primitive's block") +
            (primitive || node.kind == SceneNode::Kind::Object
                ? " (objects go in a union or intersection block)"
                : ""));
        advance();
        continue;
      }
      if (std::optional<SceneNode> child = object(depth + 1))
      {
        node.children.push_back(std::move(*child));
      }
    }
    advance();
  }

  /// The items every object takes: inverse, transformations, color. False: not one of them.
  bool item(SceneNode& node, const Token& item)
  {
    if (item.text == "inverse")
    {
      advance();
      node.inverse = !node.inverse;
      return true;
    }
    if (item.text == "color")
    {
      advance();
      std::vector<double> c;
      if (numbers(item, 3, c))
      {
        if (token_.kind == TokenKind::Number)
        {
          error(token_, "'color' takes 3 numbers (red, green, blue), found more");
          while (token_.kind == TokenKind::Number)
          {
            advance();
          }
          return true;
        }
        for (double v : c)
        {
          if (v < 0 || v > 1)
          {
            error(item, "a colour's components lie in [0, 1]");
            return true;
          }
        }
        if (node.colour)
        {
          error(item, "a second 'color' for one object");
        }
        node.colour = std::array<double, 3>{ c[0], c[1], c[2] };
      }
      return true;
    }
    for (const auto& [word, kind] : TransformKeywords)
    {
      if (item.text != word)
      {
        continue;
      }
      advance();
      SceneTransform t;
      t.kind = kind;
      t.where = at(item);
      std::size_t n = 3;
      if (kind == SceneTransform::Kind::Scale)
      {
        n = 1;
      }
      else if (kind == SceneTransform::Kind::SkewX || kind == SceneTransform::Kind::SkewY ||
        kind == SceneTransform::Kind::SkewZ)
      {
        n = 2;
      }
      else if (kind == SceneTransform::Kind::Matrix)
      {
        n = 12;
      }
      if (!numbers(item, n, t.values))
      {
        return true;
      }
      if (kind == SceneTransform::Kind::Scale && token_.kind == TokenKind::Number &&
        !numbers(item, 2, t.values))
      {
        return true;
      }
      if (kind == SceneTransform::Kind::Scale)
      {
        for (double v : t.values)
        {
          if (v == 0)
          {
            error(item, "a scale factor must not be 0");
            return true;
          }
        }
      }
      node.transforms.push_back(std::move(t));
      return true;
    }
    return false;
  }

  void perturbation(SceneNode& node, const Token& item, int depth)
  {
    std::vector<double> k;
    if (!numbers(item, 1, k))
    {
      return;
    }
    const Token q = token_;
    if (q.kind != TokenKind::Word || !frep::quadricTypeFromKeyword(q.text))
    {
      error(q.kind == TokenKind::End ? item : q,
        "'perturb' takes a factor and a perturbing quadric (ell, seat, ...)");
      return;
    }
    std::optional<SceneNode> quadric = object(depth + 1);
    if (!quadric)
    {
      return;
    }
    if (quadric->inverse || quadric->colour || !quadric->perturbations.empty())
    {
      error(q, "a perturbing quadric takes transformations only");
      return;
    }
    node.perturbations.push_back({ k[0], std::move(*quadric) });
  }

  const std::string& text_;
  std::string file_;
  const SceneLoader& loader_;
  const Limits& limits_;
  std::vector<std::string>& stack_;
  std::size_t pos_ = 0;
  int line_ = 1;
  int column_ = 1;
  Token token_;
  std::vector<Diagnostic> diagnostics_;
  std::size_t nodes_ = 0;
};

// --- writing
// --------------------------------------------------------------------------------------

std::string number(double v)
{
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  // The shortest form that reads back to the same double.
  for (int precision = 1; precision < 17; ++precision)
  {
    char shorter[32];
    std::snprintf(shorter, sizeof shorter, "%.*g", precision, v);
    if (std::strtod(shorter, nullptr) == v)
    {
      return shorter;
    }
  }
  return buf;
}

const char* transformKeyword(SceneTransform::Kind kind)
{
  for (const auto& [word, k] : TransformKeywords)
  {
    if (k == kind)
    {
      return word;
    }
  }
  return "move";
}

// A name in a comment: no line break or control character may end the comment early.
std::string printable(std::string s)
{
  for (char& c : s)
  {
    c = static_cast<unsigned char>(c) < 0x20 ? '?' : c;
  }
  return s;
}

void write(const SceneNode& node, int indent, std::string& out)
{
  const std::string pad(static_cast<std::size_t>(2 * indent), ' ');
  switch (node.kind)
  {
    case SceneNode::Kind::Quadric:
      out += pad + frep::quadricTypeInfo(node.quadric).keyword;
      break;
    case SceneNode::Kind::Torus:
      out += pad + "torus";
      break;
    case SceneNode::Kind::Cube:
      out += pad + "cube";
      break;
    case SceneNode::Kind::Union:
      out += pad + "union";
      break;
    case SceneNode::Kind::Intersection:
      out += pad + "intersection";
      break;
    case SceneNode::Kind::Object:
      // Inlined: the referenced file's objects, united, with the reference's own items.
      out += pad + "// object " + printable(node.reference) + " (" +
        printable(node.referencedFile) + ")\n" + pad + "union";
      break;
  }
  std::vector<std::string> items;
  if (node.inverse)
  {
    items.push_back("inverse");
  }
  if (node.hasRadii)
  {
    items.push_back("radii " + number(node.radii[0]) + " " + number(node.radii[1]));
  }
  for (const SceneTransform& t : node.transforms)
  {
    std::string s = transformKeyword(t.kind);
    for (double v : t.values)
    {
      s += " " + number(v);
    }
    items.push_back(s);
  }
  if (node.colour)
  {
    items.push_back("color " + number((*node.colour)[0]) + " " + number((*node.colour)[1]) + " " +
      number((*node.colour)[2]));
  }
  if (items.empty() && node.children.empty() && node.perturbations.empty())
  {
    out += "\n";
    return;
  }
  out += "\n" + pad + "{\n";
  for (const std::string& s : items)
  {
    out += pad + "  " + s + "\n";
  }
  for (const ScenePerturbation& p : node.perturbations)
  {
    out += pad + "  perturb " + number(p.factor) + "\n";
    write(p.quadric, indent + 2, out);
  }
  for (const SceneNode& child : node.children)
  {
    write(child, indent + 1, out);
  }
  out += pad + "}\n";
}

} // namespace

Scene parseScene(
  const std::string& text, const std::string& file, const SceneLoader& loader, const Limits& limits)
{
  std::vector<std::string> stack{ file };
  return Parser(text, file, loader, limits, stack).parse();
}

Scene readSceneFile(const std::string& path, const Limits& limits)
{
  const std::string text = readSourceFile(path, limits);
  SceneLoader loader =
    [&limits](const std::string& name,
      const std::string& from) -> std::optional<std::pair<std::string, std::string>>
  {
    const std::filesystem::path dir = std::filesystem::path(from).parent_path();
    for (const std::string& candidate : { name, name + ".scn", name + ".scene" })
    {
      const std::filesystem::path p = dir / candidate;
      std::error_code ec;
      if (std::filesystem::is_regular_file(p, ec))
      {
        const std::string found = std::filesystem::weakly_canonical(p, ec).string();
        return std::make_pair(
          found.empty() ? p.string() : found, readSourceFile(p.string(), limits));
      }
    }
    return std::nullopt;
  };
  std::error_code ec;
  const std::string self = std::filesystem::weakly_canonical(path, ec).string();
  std::vector<std::string> stack{ self.empty() ? path : self };
  return Parser(text, path, loader, limits, stack).parse();
}

std::string writeScene(const Scene& scene)
{
  std::string out = "// " +
    (scene.file.empty() ? std::string("a scene")
                        : std::filesystem::path(scene.file).filename().string()) +
    ", written by ICTK as one file (object references inlined)\n";
  for (const SceneNode& node : scene.objects)
  {
    write(node, 0, out);
  }
  return out;
}

} // namespace ictk::lang
