// SPDX-License-Identifier: BSD-3-Clause
// Writing the FRep XML interchange format (docs/frep-xml.md); FRepXmlReader.cxx reads it.
//
// Written by hand rather than through a pugixml DOM: the output is then deterministic to the byte,
// and linear in the DAG size. Shared sub-expressions get an id and are written once; a
// sub-expression nested deeper than kMaxInlineDepth moves to <defs>, so that what is written
// reads back under Limits::maxNesting.
#include "Lang/FRepXml.h"
#include "Lang/XmlText.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <optional>
#include <stdexcept>
#include <unordered_map>
#include <unordered_set>

namespace ictk::lang
{

namespace
{
using frep::Expr;
using frep::Opcode;

// Writer nesting budget: a sub-expression deeper than this moves to <defs> and is referenced, so
// that a long chain (a union of thousands of shapes) still reads back under Limits::maxNesting.
constexpr int kMaxInlineDepth = 48;

std::string formatNumber(double v)
{
  // 17 significant digits: every double reads back exactly. to_chars ignores the C locale.
  char buf[64];
  auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, 17);
  return std::string(buf, r.ptr);
}

std::string numberList(const std::vector<double>& values)
{
  std::string s;
  for (std::size_t i = 0; i < values.size(); ++i)
  {
    if (i)
    {
      s += ' ';
    }
    s += formatNumber(values[i]);
  }
  return s;
}

class XmlWriter
{
public:
  std::string write(const frep::Hypervolume& hv, const std::string& name, int parameterCount,
    const std::optional<std::array<double, 6>>& bounds)
  {
    std::vector<Expr> roots;
    roots.push_back(hv.geometry().function());
    for (const frep::Attribute& a : hv.attributes())
    {
      roots.push_back(a.partition);
      roots.insert(roots.end(), a.components.begin(), a.components.end());
    }
    analyse(roots);
    // The a parameter array must cover every slot the model reads.
    parameterCount = std::max(parameterCount, static_cast<int>(maxSlot_ + 1));

    out_ += "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
    out_ += "<frep version=\"1\" name=\"" + xmlAttribute(name, "writeFRepXml: the model name") +
      "\" parameters=\"" + std::to_string(parameterCount) + "\">\n";
    if (bounds)
    {
      const auto& b = *bounds;
      out_ += "  <bounds lo=\"" + numberList({ b[0], b[2], b[4] }) + "\" hi=\"" +
        numberList({ b[1], b[3], b[5] }) + "\"/>\n";
    }
    out_ += std::string("  <geometry domain=\"") + frep::domainName(hv.geometry().domain()) +
      "\" threshold=\"" + formatNumber(hv.threshold()) + "\">\n";
    if (!spilledOrder_.empty())
    {
      out_ += "    <defs>\n";
      for (const Expr& e : spilledOrder_)
      {
        writeExpr(e, 3, true);
      }
      out_ += "    </defs>\n";
    }
    writeExpr(hv.geometry().function(), 2, false);
    out_ += "  </geometry>\n";
    for (const frep::Attribute& a : hv.attributes())
    {
      out_ += "  <attribute name=\"" + xmlAttribute(a.name, "writeFRepXml: the attribute name") +
        "\" components=\"" + std::to_string(a.components.size()) + "\" tensorRows=\"" +
        std::to_string(a.tensorRows) + "\">\n";
      out_ += "    <partition>\n";
      writeExpr(a.partition, 3, false);
      out_ += "    </partition>\n";
      for (const Expr& c : a.components)
      {
        out_ += "    <component>\n";
        writeExpr(c, 3, false);
        out_ += "    </component>\n";
      }
      out_ += "    <inside>" + numberList(a.insideDefault) + "</inside>\n";
      out_ += "    <outside>" + numberList(a.outsideDefault) + "</outside>\n";
      out_ += "  </attribute>\n";
    }
    out_ += "</frep>\n";
    return std::move(out_);
  }

private:
  // Counts the parents of every node over all roots, finds the nodes that must move to <defs>
  // (in post-order, so that each is defined before use) and the largest parameter slot.
  void analyse(const std::vector<Expr>& roots)
  {
    std::unordered_map<const frep::Node*, int> depth;
    std::unordered_set<const frep::Node*> done;
    for (const Expr& root : roots)
    {
      ++uses_[root.id()];
      if (done.count(root.id()))
      {
        continue;
      }
      std::vector<std::pair<Expr, int>> stack;
      stack.emplace_back(root, 0);
      while (!stack.empty())
      {
        auto& [e, next] = stack.back();
        if (next < e.arity())
        {
          Expr c = e.child(next++);
          ++uses_[c.id()];
          if (!done.count(c.id()))
          {
            done.insert(c.id());
            stack.emplace_back(std::move(c), 0);
          }
          continue;
        }
        done.insert(e.id());
        int d = 1;
        for (int i = 0; i < e.arity(); ++i)
        {
          const frep::Node* c = e.child(i).id();
          d = std::max(d, 1 + (spilled_.count(c) ? 1 : depth.at(c)));
        }
        if (e.opcode() == Opcode::Parameter)
        {
          maxSlot_ = std::max<long long>(maxSlot_, e.parameterSlot());
        }
        if (d > kMaxInlineDepth)
        {
          spilled_.insert(e.id());
          spilledOrder_.push_back(e);
        }
        depth[e.id()] = d;
        stack.pop_back();
      }
    }
  }

  void indent(int level) { out_.append(static_cast<std::size_t>(level) * 2, ' '); }

  // Recursion is bounded by kMaxInlineDepth thanks to the spilling above.
  void writeExpr(const Expr& e, int level, bool define)
  {
    indent(level);
    switch (e.opcode())
    {
      case Opcode::Constant:
        out_ += "<const value=\"" + formatNumber(e.constantValue()) + "\"/>\n";
        return;
      case Opcode::Variable:
        out_ += std::string("<var axis=\"") + frep::axisName(e.axis()) + "\"/>\n";
        return;
      case Opcode::Parameter:
        out_ += "<param slot=\"" + std::to_string(e.parameterSlot()) + "\"/>\n";
        return;
      default:
        break;
    }
    // A spilled node is defined in <defs> (in post-order) before anything refers to it, so it
    // is always found here when not being defined.
    auto written = ids_.find(e.id());
    if (written != ids_.end())
    {
      out_ += "<ref id=\"" + written->second + "\"/>\n";
      return;
    }
    out_ += '<';
    out_ += frep::opcodeName(e.opcode());
    if (define || uses_.at(e.id()) > 1)
    {
      std::string id = "n" + std::to_string(nextId_++);
      out_ += " id=\"" + id + "\"";
      ids_.emplace(e.id(), std::move(id));
    }
    out_ += ">\n";
    for (int i = 0; i < e.arity(); ++i)
    {
      writeExpr(e.child(i), level + 1, false);
    }
    indent(level);
    out_ += "</";
    out_ += frep::opcodeName(e.opcode());
    out_ += ">\n";
  }

  std::string out_;
  std::unordered_map<const frep::Node*, int> uses_;
  std::unordered_set<const frep::Node*> spilled_;
  std::vector<Expr> spilledOrder_;
  std::unordered_map<const frep::Node*, std::string> ids_;
  int nextId_ = 1;
  long long maxSlot_ = -1;
};

} // namespace

std::string writeFRepXmlDocument(const frep::Hypervolume& model, const std::string& name,
  int parameterCount, const std::optional<std::array<double, 6>>& bounds)
{
  return XmlWriter().write(model, name, parameterCount, bounds);
}

std::string writeFRepXml(const frep::Hypervolume& model, const std::string& name)
{
  return writeFRepXmlDocument(model, name, 0, std::nullopt);
}

} // namespace ictk::lang
