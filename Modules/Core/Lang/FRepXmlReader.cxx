// SPDX-License-Identifier: BSD-3-Clause
// Reading the FRep XML interchange format (docs/frep-xml.md); FRepXmlWriter.cxx writes it.
//
// Reading uses pugixml (whose parser is iterative, so deep documents cannot overflow the stack)
// and walks the document with an explicit stack for the same reason. Every error is reported with
// its file:line:col, and reading goes on to collect the others (up to Limits).
#include "Lang/FRepXml.h"

#include <pugixml.hpp>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstring>
#include <optional>
#include <stdexcept>
#include <unordered_map>

namespace ictk::lang
{

namespace
{
using frep::Axis;
using frep::Domain;
using frep::Expr;
using frep::Opcode;

// Parameter slots above this are refused: the evaluators allocate one value per slot.
constexpr std::uint32_t kMaxParameterSlot = 1u << 20;
// Attribute component counts above this are refused (a 256 x 256 tensor is already absurd).
constexpr std::uint64_t kMaxComponents = 1u << 16;

// Thrown internally to stop reading once the diagnostics are complete (or too many).
struct StopReading
{};

bool isXmlSpace(char c)
{
  return c == ' ' || c == '\t' || c == '\n' || c == '\r';
}

class XmlReader
{
public:
  XmlReader(const std::string& text, const std::string& fileName, const Limits& limits)
    : text_(text)
    , file_(fileName)
    , limits_(limits)
  {
  }

private:
  // ----- diagnostics

  SourceLocation locate(std::ptrdiff_t offset, std::string* sourceLine) const
  {
    SourceLocation where;
    where.file = file_;
    if (offset < 0)
    {
      return where;
    }
    const auto off = std::min(static_cast<std::size_t>(offset), text_.size());
    int line = 1;
    std::size_t lineStart = 0;
    for (std::size_t i = 0; i < off; ++i)
    {
      if (text_[i] == '\n')
      {
        ++line;
        lineStart = i + 1;
      }
    }
    where.line = line;
    where.column = static_cast<int>(off - lineStart) + 1;
    std::size_t lineEnd = text_.find('\n', lineStart);
    if (lineEnd == std::string::npos)
    {
      lineEnd = text_.size();
    }
    if (lineEnd > lineStart && text_[lineEnd - 1] == '\r')
    {
      --lineEnd;
    }
    // A minified document is one huge line: printing it under the message helps nobody.
    if (lineEnd - lineStart <= 512)
    {
      *sourceLine = text_.substr(lineStart, lineEnd - lineStart);
    }
    return where;
  }

  // Offset of an element's '<' (pugixml reports the offset of its name).
  std::ptrdiff_t offsetOf(const pugi::xml_node& n) const
  {
    std::ptrdiff_t off = n.offset_debug();
    if (off > 0 && static_cast<std::size_t>(off) <= text_.size() && text_[off - 1] == '<')
    {
      --off;
    }
    return off;
  }

  void error(std::ptrdiff_t offset, std::string message)
  {
    Diagnostic d;
    d.where = locate(offset, &d.sourceLine);
    d.message = std::move(message);
    diagnostics_.push_back(std::move(d));
    if (diagnostics_.size() >= std::max<std::size_t>(limits_.maxDiagnostics, 1))
    {
      throw StopReading{};
    }
  }
  void error(const pugi::xml_node& n, std::string message)
  {
    error(offsetOf(n), std::move(message));
  }
  [[noreturn]] void fatal(const pugi::xml_node& n, std::string message)
  {
    error(n, std::move(message));
    throw StopReading{};
  }

  // ----- values

  static std::string tag(const pugi::xml_node& n) { return std::string("<") + n.name() + ">"; }

  std::optional<double> parseNumber(const char* s) const
  {
    const char* end = s + std::strlen(s);
    double v = 0;
    auto r = std::from_chars(s, end, v);
    if (r.ec != std::errc() || r.ptr != end || s == end)
    {
      return std::nullopt;
    }
    return v;
  }

  template <typename T>
  std::optional<T> parseInteger(const char* s) const
  {
    const char* end = s + std::strlen(s);
    T v = 0;
    auto r = std::from_chars(s, end, v);
    if (r.ec != std::errc() || r.ptr != end || s == end)
    {
      return std::nullopt;
    }
    return v;
  }

  std::optional<std::vector<double>> parseNumberList(const char* s) const
  {
    std::vector<double> values;
    const std::string text(s);
    std::size_t i = 0;
    while (true)
    {
      while (i < text.size() && isXmlSpace(text[i]))
      {
        ++i;
      }
      if (i == text.size())
      {
        break;
      }
      std::size_t j = i;
      while (j < text.size() && !isXmlSpace(text[j]))
      {
        ++j;
      }
      auto v = parseNumber(text.substr(i, j - i).c_str());
      if (!v)
      {
        return std::nullopt;
      }
      values.push_back(*v);
      i = j;
    }
    return values;
  }

  // Reports attributes other than `allowed`.
  void checkAttributes(const pugi::xml_node& n, std::initializer_list<const char*> allowed)
  {
    for (const pugi::xml_attribute& a : n.attributes())
    {
      bool ok = false;
      for (const char* name : allowed)
      {
        ok = ok || std::strcmp(a.name(), name) == 0;
      }
      if (!ok)
      {
        error(n, "unknown attribute '" + std::string(a.name()) + "' on " + tag(n));
      }
    }
  }

  bool requireAttribute(const pugi::xml_node& n, const char* name)
  {
    if (!n.attribute(name))
    {
      error(n, tag(n) + " needs the attribute '" + name + "'");
      return false;
    }
    return true;
  }

  // Text that is not white space (pugixml drops white-space-only text already).
  void rejectText(const pugi::xml_node& child, const pugi::xml_node& parent)
  {
    error(child, "unexpected text in " + tag(parent));
  }

  /// The element children of `parent`, in order; text among them is reported.
  std::vector<pugi::xml_node> elementChildren(const pugi::xml_node& parent)
  {
    std::vector<pugi::xml_node> elements;
    for (pugi::xml_node c : parent.children())
    {
      if (c.type() == pugi::node_pcdata || c.type() == pugi::node_cdata)
      {
        rejectText(c, parent);
      }
      else if (c.type() == pugi::node_element)
      {
        elements.push_back(c);
      }
    }
    return elements;
  }

  // ----- document

  void readDocument(FRepXmlDocument& result)
  {
    if (text_.size() > limits_.maxFileBytes)
    {
      error(-1,
        "the file has " + std::to_string(text_.size()) + " bytes, more than the limit of " +
          std::to_string(limits_.maxFileBytes));
      throw StopReading{};
    }
    pugi::xml_document doc;
    const pugi::xml_parse_result parsed =
      doc.load_buffer(text_.data(), text_.size(), pugi::parse_default, pugi::encoding_utf8);
    if (!parsed)
    {
      error(parsed.offset, std::string("malformed XML: ") + parsed.description());
      throw StopReading{};
    }
    pugi::xml_node root;
    for (pugi::xml_node n : doc.children())
    {
      if (n.type() == pugi::node_element)
      {
        if (root)
        {
          fatal(n, "a second top-level element " + tag(n) + " (the document is one <frep>)");
        }
        root = n;
      }
      else if (n.type() == pugi::node_pcdata || n.type() == pugi::node_cdata)
      {
        fatal(n, "text outside the <frep> element");
      }
    }
    if (!root)
    {
      error(0, "no <frep> element");
      throw StopReading{};
    }
    if (std::strcmp(root.name(), "frep") != 0)
    {
      fatal(root, "the top-level element is " + tag(root) + ", not <frep>");
    }
    checkAttributes(root, { "version", "name", "parameters" });
    if (requireAttribute(root, "version") &&
      std::strcmp(root.attribute("version").value(), "1") != 0)
    {
      fatal(root,
        "unsupported FRep XML version '" + std::string(root.attribute("version").value()) +
          "' (this reader knows version 1)");
    }
    result.name = root.attribute("name").value();
    int declaredParameters = 0;
    if (pugi::xml_attribute p = root.attribute("parameters"))
    {
      auto v = parseInteger<std::uint32_t>(p.value());
      if (!v || *v > kMaxParameterSlot)
      {
        error(root, "bad parameter count '" + std::string(p.value()) + "'");
      }
      else
      {
        declaredParameters = static_cast<int>(*v);
      }
    }

    pugi::xml_node geometry;
    for (pugi::xml_node n : elementChildren(root))
    {
      const std::string name = n.name();
      if (name == "bounds")
      {
        if (result.bounds)
        {
          error(n, "a second <bounds>");
        }
        readBounds(n, result);
      }
      else if (name == "geometry")
      {
        if (geometry)
        {
          error(n, "a second <geometry>");
          continue;
        }
        geometry = n;
        readGeometry(n, result);
      }
      else if (name == "attribute")
      {
        if (!geometry)
        {
          error(n, "<attribute> before <geometry> (its domain is the geometry's)");
          continue;
        }
        readAttribute(n, result);
      }
      else
      {
        error(n, "unknown element " + tag(n) + " in <frep>");
      }
    }
    if (!geometry)
    {
      error(root, "<frep> has no <geometry>");
    }
    if (maxSlot_ >= declaredParameters && root.attribute("parameters") && diagnostics_.empty())
    {
      error(root,
        "the model uses parameter slot " + std::to_string(maxSlot_) + " but declares " +
          std::to_string(declaredParameters) + " parameter(s)");
    }
    result.parameterCount = std::max<int>(declaredParameters, static_cast<int>(maxSlot_ + 1));
  }

  void readBounds(const pugi::xml_node& n, FRepXmlDocument& result)
  {
    checkAttributes(n, { "lo", "hi" });
    expectEmpty(n);
    if (!requireAttribute(n, "lo") || !requireAttribute(n, "hi"))
    {
      return;
    }
    auto lo = parseNumberList(n.attribute("lo").value());
    auto hi = parseNumberList(n.attribute("hi").value());
    if (!lo || !hi || lo->size() != 3 || hi->size() != 3)
    {
      error(n, "<bounds> needs three numbers in 'lo' and three in 'hi'");
      return;
    }
    std::array<double, 6> b{};
    for (int i = 0; i < 3; ++i)
    {
      if (!std::isfinite((*lo)[i]) || !std::isfinite((*hi)[i]) || (*lo)[i] > (*hi)[i])
      {
        error(n, "<bounds> needs finite numbers with lo <= hi on every axis");
        return;
      }
      b[2 * i] = (*lo)[i];
      b[2 * i + 1] = (*hi)[i];
    }
    result.bounds = b;
  }

  void expectEmpty(const pugi::xml_node& n)
  {
    for (pugi::xml_node c : n.children())
    {
      if (c.type() == pugi::node_element)
      {
        error(c, tag(n) + " takes no child element, found " + tag(c));
      }
      else if (c.type() == pugi::node_pcdata || c.type() == pugi::node_cdata)
      {
        rejectText(c, n);
      }
    }
  }

  void readGeometry(const pugi::xml_node& n, FRepXmlDocument& result)
  {
    checkAttributes(n, { "domain", "threshold" });
    domain_ = Domain::XYZ;
    if (requireAttribute(n, "domain"))
    {
      if (auto d = frep::domainFromName(n.attribute("domain").value()))
      {
        domain_ = *d;
      }
      else
      {
        error(n,
          "unknown domain '" + std::string(n.attribute("domain").value()) +
            "' (X, T, XY, XT, XYZ, XYT or XYZT)");
      }
    }
    double threshold = 0;
    if (pugi::xml_attribute t = n.attribute("threshold"))
    {
      auto v = parseNumber(t.value());
      if (!v || !std::isfinite(*v))
      {
        error(n, "bad threshold '" + std::string(t.value()) + "' (a finite number)");
      }
      else
      {
        threshold = *v;
      }
    }
    std::optional<Expr> f;
    bool first = true;
    for (pugi::xml_node c : elementChildren(n))
    {
      if (std::strcmp(c.name(), "defs") == 0)
      {
        if (!first)
        {
          error(c, "<defs> must come first in <geometry>");
        }
        readDefs(c);
      }
      else if (f)
      {
        error(c, "<geometry> holds one expression; found another, " + tag(c));
      }
      else
      {
        f = readExpr(c, 3);
      }
      first = false;
    }
    if (!f)
    {
      error(n, "<geometry> has no expression");
      return;
    }
    try
    {
      result.model.emplace(frep::Shape(*f, domain_), threshold);
    }
    catch (const std::exception& e)
    {
      // Only reachable after an error was reported (the domain check is done per <var>).
      error(n, e.what());
    }
  }

  void readDefs(const pugi::xml_node& n)
  {
    checkAttributes(n, {});
    for (pugi::xml_node c : elementChildren(n))
    {
      if (!c.attribute("id"))
      {
        error(c, "a definition in <defs> needs an 'id'");
      }
      readExpr(c, 4);
    }
  }

  // <partition> and <component>: exactly one expression.
  std::optional<Expr> readSlot(const pugi::xml_node& n)
  {
    checkAttributes(n, {});
    std::optional<Expr> e;
    for (pugi::xml_node c : elementChildren(n))
    {
      if (e)
      {
        error(c, tag(n) + " holds one expression; found another, " + tag(c));
        continue;
      }
      e = readExpr(c, 4);
    }
    if (!e)
    {
      error(n, tag(n) + " has no expression");
    }
    return e;
  }

  void readAttribute(const pugi::xml_node& n, FRepXmlDocument& result)
  {
    checkAttributes(n, { "name", "components", "tensorRows" });
    frep::Attribute a;
    bool ok = requireAttribute(n, "name") && requireAttribute(n, "components");
    a.name = n.attribute("name").value();
    std::uint64_t declared = 0;
    if (pugi::xml_attribute c = n.attribute("components"))
    {
      auto v = parseInteger<std::uint64_t>(c.value());
      if (!v || *v == 0 || *v > kMaxComponents)
      {
        error(n, "bad component count '" + std::string(c.value()) + "'");
        ok = false;
      }
      else
      {
        declared = *v;
      }
    }
    if (pugi::xml_attribute r = n.attribute("tensorRows"))
    {
      auto v = parseInteger<int>(r.value());
      if (!v || *v < 0)
      {
        error(n, "bad tensorRows '" + std::string(r.value()) + "'");
        ok = false;
      }
      else
      {
        a.tensorRows = *v;
      }
    }
    bool havePartition = false, haveInside = false, haveOutside = false;
    for (pugi::xml_node c : elementChildren(n))
    {
      const std::string name = c.name();
      if (name == "partition")
      {
        if (havePartition)
        {
          error(c, "a second <partition>");
        }
        havePartition = true;
        if (auto e = readSlot(c))
        {
          a.partition = *e;
        }
        else
        {
          ok = false;
        }
      }
      else if (name == "component")
      {
        if (auto e = readSlot(c))
        {
          a.components.push_back(*e);
        }
        else
        {
          ok = false;
        }
      }
      else if (name == "inside" || name == "outside")
      {
        bool& have = name == "inside" ? haveInside : haveOutside;
        if (have)
        {
          error(c, "a second " + tag(c));
        }
        have = true;
        checkAttributes(c, {});
        for (pugi::xml_node k : c.children())
        {
          if (k.type() == pugi::node_element)
          {
            error(k, tag(c) + " holds numbers, not " + tag(k));
            ok = false;
          }
        }
        auto values = parseNumberList(c.text().get());
        if (!values)
        {
          error(c, "bad number in " + tag(c));
          ok = false;
        }
        else if (values->size() != declared)
        {
          error(c,
            tag(c) + " has " + std::to_string(values->size()) + " value(s) for " +
              std::to_string(declared) + " component(s)");
          ok = false;
        }
        else
        {
          (name == "inside" ? a.insideDefault : a.outsideDefault) = std::move(*values);
        }
      }
      else
      {
        error(c, "unknown element " + tag(c) + " in <attribute>");
        ok = false;
      }
    }
    if (declared && a.components.size() != declared)
    {
      error(n,
        "<attribute> declares " + std::to_string(declared) + " component(s) but has " +
          std::to_string(a.components.size()));
      ok = false;
    }
    if (!ok || !result.model)
    {
      return;
    }
    try
    {
      result.model->addAttribute(std::move(a));
    }
    catch (const std::invalid_argument& e)
    {
      error(n, e.what());
    }
  }

  // ----- expressions

  struct Frame
  {
    pugi::xml_node node;
    Opcode op = Opcode::Constant;
    std::vector<Expr> args;
    pugi::xml_node next; // the next child to look at
    bool ok = true;
    std::optional<Expr> value; // set for leaves
  };

  static std::optional<Opcode> opcodeFromName(const char* name)
  {
    for (int i = 0; i < static_cast<int>(Opcode::Count_); ++i)
    {
      if (std::strcmp(frep::opcodeName(static_cast<Opcode>(i)), name) == 0)
      {
        return static_cast<Opcode>(i);
      }
    }
    return std::nullopt;
  }

  // Validates one element and, for a leaf, computes its value.
  Frame open(const pugi::xml_node& n)
  {
    Frame f;
    f.node = n;
    f.next = n.first_child();
    if (++nodeCount_ > limits_.maxExpressionNodes)
    {
      fatal(n,
        "the model has more than " + std::to_string(limits_.maxExpressionNodes) +
          " expression nodes");
    }
    if (std::strcmp(n.name(), "ref") == 0)
    {
      checkAttributes(n, { "id" });
      f.value = Expr(0.0);
      if (requireAttribute(n, "id"))
      {
        const std::string id = n.attribute("id").value();
        auto it = defined_.find(id);
        if (it != defined_.end())
        {
          f.value = it->second;
        }
        else
        {
          // Forward (or cyclic) or dangling: told apart once the whole document is read.
          pendingRefs_.emplace_back(id, offsetOf(n));
        }
      }
      expectEmpty(n);
      return f;
    }
    auto op = opcodeFromName(n.name());
    if (!op)
    {
      error(n, "unknown element " + tag(n) + " in an expression");
      f.value = Expr(0.0);
      f.ok = false;
      return f;
    }
    f.op = *op;
    switch (*op)
    {
      case Opcode::Constant:
      {
        checkAttributes(n, { "value", "id" });
        f.value = Expr(0.0);
        if (requireAttribute(n, "value"))
        {
          if (auto v = parseNumber(n.attribute("value").value()))
          {
            f.value = Expr::constant(*v);
          }
          else
          {
            error(n, "bad number '" + std::string(n.attribute("value").value()) + "'");
          }
        }
        expectEmpty(n);
        break;
      }
      case Opcode::Variable:
      {
        checkAttributes(n, { "axis", "id" });
        f.value = Expr(0.0);
        if (requireAttribute(n, "axis"))
        {
          const std::string axis = n.attribute("axis").value();
          std::optional<Axis> a;
          for (int i = 0; i < frep::AxisCount; ++i)
          {
            if (axis == frep::axisName(static_cast<Axis>(i)))
            {
              a = static_cast<Axis>(i);
            }
          }
          if (!a)
          {
            error(n, "unknown axis '" + axis + "' (x, y, z or t)");
          }
          else if (!(frep::domainAxes(domain_) & (1u << static_cast<int>(*a))))
          {
            error(
              n, "coordinate '" + axis + "' is outside the domain " + frep::domainName(domain_));
          }
          else
          {
            f.value = Expr::variable(*a);
          }
        }
        expectEmpty(n);
        break;
      }
      case Opcode::Parameter:
      {
        checkAttributes(n, { "slot", "id" });
        f.value = Expr(0.0);
        if (requireAttribute(n, "slot"))
        {
          auto slot = parseInteger<std::uint32_t>(n.attribute("slot").value());
          if (!slot || *slot >= kMaxParameterSlot)
          {
            error(n,
              "bad parameter slot '" + std::string(n.attribute("slot").value()) +
                "' (an integer from 0 to " + std::to_string(kMaxParameterSlot - 1) + ")");
          }
          else
          {
            f.value = Expr::parameter(*slot);
            maxSlot_ = std::max<long long>(maxSlot_, *slot);
          }
        }
        expectEmpty(n);
        break;
      }
      default:
        checkAttributes(n, { "id" });
        break;
    }
    return f;
  }

  // Gives a finished element its value and registers its id.
  Expr close(Frame& f)
  {
    Expr value;
    if (f.value)
    {
      value = *f.value;
    }
    else
    {
      const int arity = frep::opcodeArity(f.op);
      if (static_cast<int>(f.args.size()) != arity)
      {
        error(f.node,
          tag(f.node) + " takes " + std::to_string(arity) + " operand(s), found " +
            std::to_string(f.args.size()));
        f.ok = false;
      }
      if (f.ok)
      {
        switch (arity)
        {
          case 1:
            value = Expr::make(f.op, f.args[0]);
            break;
          case 2:
            value = Expr::make(f.op, f.args[0], f.args[1]);
            break;
          default:
            value = Expr::make(f.op, f.args[0], f.args[1], f.args[2]);
            break;
        }
      }
    }
    if (pugi::xml_attribute id = f.node.attribute("id"); id && std::strcmp(f.node.name(), "ref"))
    {
      const std::string name = id.value();
      if (name.empty())
      {
        error(f.node, "empty id");
      }
      else if (!defined_.emplace(name, value).second)
      {
        error(f.node, "duplicate id '" + name + "'");
      }
      else
      {
        definedAt_.emplace(name, offsetOf(f.node));
      }
    }
    return value;
  }

  // Reads the expression rooted at element `root`, which sits at XML depth `depth` (the <frep>
  // element is depth 1). Iterative, so that nesting is limited by Limits::maxNesting only.
  Expr readExpr(const pugi::xml_node& root, int depth)
  {
    std::vector<Frame> stack;
    auto push = [&](const pugi::xml_node& n)
    {
      if (depth + static_cast<int>(stack.size()) > limits_.maxNesting)
      {
        fatal(n, "elements nested deeper than " + std::to_string(limits_.maxNesting));
      }
      stack.push_back(open(n));
    };
    push(root);
    Expr result;
    while (!stack.empty())
    {
      Frame& f = stack.back();
      if (!f.value && f.ok)
      {
        // Find the next operand element.
        pugi::xml_node c = f.next;
        while (c && c.type() != pugi::node_element)
        {
          if (c.type() == pugi::node_pcdata || c.type() == pugi::node_cdata)
          {
            rejectText(c, f.node);
          }
          c = c.next_sibling();
        }
        if (c)
        {
          f.next = c.next_sibling();
          push(c);
          continue;
        }
      }
      Expr value = close(f);
      stack.pop_back();
      if (stack.empty())
      {
        result = value;
      }
      else
      {
        stack.back().args.push_back(value);
      }
    }
    return result;
  }

public:
  // Called after the document: refs that never resolved.
  void reportPendingRefs()
  {
    for (const auto& [id, offset] : pendingRefs_)
    {
      auto at = definedAt_.find(id);
      if (at != definedAt_.end())
      {
        error(offset,
          "reference to '" + id + "' before its definition (at line " +
            std::to_string(locate(at->second, &scratch_).line) + ")");
      }
      else
      {
        error(offset, "reference to an undefined id '" + id + "'");
      }
    }
    pendingRefs_.clear();
  }

private:
  const std::string& text_;
  std::string file_;
  Limits limits_;
  std::vector<Diagnostic> diagnostics_;
  Domain domain_ = Domain::XYZ;
  std::unordered_map<std::string, Expr> defined_;
  std::unordered_map<std::string, std::ptrdiff_t> definedAt_;
  std::vector<std::pair<std::string, std::ptrdiff_t>> pendingRefs_;
  std::size_t nodeCount_ = 0;
  long long maxSlot_ = -1;
  std::string scratch_;

  friend FRepXmlDocument ictk::lang::readFRepXmlDocument(
    const std::string&, const std::string&, const Limits&);
};

} // namespace

FRepXmlDocument readFRepXmlDocument(
  const std::string& text, const std::string& fileName, const Limits& limits)
{
  XmlReader reader(text, fileName, limits);
  FRepXmlDocument result;
  std::vector<Diagnostic> diagnostics;
  try
  {
    reader.readDocument(result);
    reader.reportPendingRefs();
  }
  catch (const StopReading&)
  {
  }
  if (!reader.diagnostics_.empty())
  {
    std::stable_sort(reader.diagnostics_.begin(), reader.diagnostics_.end(),
      [](const Diagnostic& a, const Diagnostic& b)
      {
        return std::make_pair(a.where.line, a.where.column) <
          std::make_pair(b.where.line, b.where.column);
      });
    throw ParseError(std::move(reader.diagnostics_));
  }
  return result;
}

frep::Hypervolume readFRepXml(
  const std::string& text, const std::string& fileName, const Limits& limits)
{
  return std::move(*readFRepXmlDocument(text, fileName, limits).model);
}

frep::Hypervolume readFRepXmlFile(const std::string& path, const Limits& limits)
{
  return readFRepXml(readSourceFile(path, limits), path, limits);
}

} // namespace ictk::lang
