// SPDX-License-Identifier: BSD-3-Clause
// FRep DAG -> HyperFun text.
//
// What is written:
// * `name(x[n], a[m])`, or `name(x[n], a[m], s[3])` when the model has a colour. The coordinate
//   array is the smallest of x[2], x[3], x[4] that holds the domain's axes, with the fixed mapping
//   x[1] = x, x[2] = y, x[3] = z, x[4] = t (so domain X is written with x[2], T, XT and XYT with
//   x[4]; reading back gives XY or XYZT, the same field on a larger domain). HyperFun arrays are
//   1-based: parameter slot i is a[i + 1]. HyperFun refuses `a[0]`, so m is at least 1, and m is
//   raised to cover every slot the model reads.
// * Every node with several parents, every select and every node that would nest too deeply is a
//   local variable assigned once, in post-order, so the text is linear in the DAG size and its
//   brackets stay well under Limits::maxNesting.
// * Constants with 17 significant digits (exact round trip), in the number syntax of the original
//   HyperFun scanner (no sign, no '+' or leading zero in the exponent); negative ones as `-c`.
// * An attribute named "colour" with 3 components, no tensor shape and a partition that is a
//   non-negative constant (so its defaults never apply) becomes HyperFun's colour: s[1], s[2],
//   s[3]. HyperFun has no notion of other attributes, partitions, defaults or a threshold: they
//   are listed in a comment block and otherwise left out. FRep XML carries everything.
// * What HyperFun cannot express throws std::invalid_argument: NaN or infinite constants, and a
//   division by a constant smaller than HyperFun's EPS (1e-6) in magnitude.
// * Pow with a constant exponent (only Expr::make builds one: frep::pow lowers integer exponents)
//   is written as `a^c`; HyperFun reads an integer (or within EPS above an integer) exponent as
//   a product, so that node reads back as frep::pow's lowering, not as Pow.
#include "Lang/HyperFun.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <stdexcept>
#include <unordered_map>
#include <unordered_set>

namespace ictk::lang
{

namespace
{
using frep::Expr;
using frep::Opcode;

// Deepest inline nesting of a statement's expression before a sub-expression becomes a local.
constexpr int kMaxInlineDepth = 24;
// The original HyperFun scanner refuses comment lines and identifiers of 256 characters or more.
constexpr std::size_t kMaxCommentText = 200;
// HyperFun's EPS (int_global.c): a constant divisor smaller than this is a division by zero.
constexpr double kHyperFunEps = 1e-6;

bool isReservedName(const std::string& lower)
{
  static const std::unordered_set<std::string> reserved = { "x", "a", "s", "and", "or", "not",
    "xor", "array", "if", "then", "else", "endif", "while", "loop", "endloop",
    // HyperFun's built-in functions
    "sqrt", "exp", "log", "logd", "sin", "cos", "tan", "asin", "acos", "atan", "abs", "sinh",
    "cosh", "tanh", "sign", "mod", "max", "min", "atan2", "ceil", "floor", "int", "frac" };
  if (reserved.count(lower))
  {
    return true;
  }
  // The HyperFun library (hfSphere, hfBlock, ...): a body cannot share a library name.
  if (lower.compare(0, 2, "hf") == 0)
  {
    return true;
  }
  // Our own local variables, v1, v2, ...
  return lower.size() > 1 && lower[0] == 'v' &&
    std::all_of(lower.begin() + 1, lower.end(),
      [](char c) { return std::isdigit(static_cast<unsigned char>(c)); });
}

void checkName(const std::string& name)
{
  bool ok = !name.empty() && name.size() < 200 && std::isalpha(static_cast<unsigned char>(name[0]));
  std::string lower;
  for (char c : name)
  {
    const auto u = static_cast<unsigned char>(c);
    ok = ok && (std::isalnum(u) || c == '_') && u < 0x80;
    lower += static_cast<char>(std::tolower(u));
  }
  if (!ok)
  {
    throw std::invalid_argument("writeHyperFun: '" + name +
      "' is not a HyperFun name (a letter, then letters, digits or '_', fewer than 200)");
  }
  if (isReservedName(lower))
  {
    throw std::invalid_argument("writeHyperFun: '" + name +
      "' is reserved in HyperFun (keyword, built-in or library function) or by the writer (v<n>)");
  }
}

// A double in the number syntax of the HyperFun scanner: digits[.digits][e[-]digits], the
// exponent without '+' or leading zeros. Non-negative values only.
std::string hyperFunNumber(double v)
{
  char buf[64];
  auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, 17);
  std::string s(buf, r.ptr);
  const auto e = s.find('e');
  if (e == std::string::npos)
  {
    return s;
  }
  std::string mantissa = s.substr(0, e);
  std::size_t i = e + 1;
  bool negative = false;
  if (s[i] == '+' || s[i] == '-')
  {
    negative = s[i] == '-';
    ++i;
  }
  while (i + 1 < s.size() && s[i] == '0')
  {
    ++i;
  }
  return mantissa + (negative ? "e-" : "e") + s.substr(i);
}

// Keeps a comment on one line, short enough for the original scanner.
std::string commentSafe(const std::string& text)
{
  std::string s;
  for (char c : text)
  {
    s += static_cast<unsigned char>(c) < 0x20 ? '?' : c;
  }
  if (s.size() > kMaxCommentText)
  {
    s = s.substr(0, kMaxCommentText) + "...";
  }
  return s;
}

std::string joinNumbers(const std::vector<double>& v)
{
  std::string s;
  for (std::size_t i = 0; i < v.size(); ++i)
  {
    char buf[64];
    auto r = std::to_chars(buf, buf + sizeof buf, v[i], std::chars_format::general, 17);
    s += (i ? " " : "") + std::string(buf, r.ptr);
  }
  return s;
}

const char* functionName(Opcode op)
{
  switch (op)
  {
    case Opcode::Abs:
      return "abs";
    case Opcode::Sqrt:
      return "sqrt";
    case Opcode::Exp:
      return "exp";
    case Opcode::Log:
      return "log";
    case Opcode::Sin:
      return "sin";
    case Opcode::Cos:
      return "cos";
    case Opcode::Tan:
      return "tan";
    case Opcode::Asin:
      return "asin";
    case Opcode::Acos:
      return "acos";
    case Opcode::Atan:
      return "atan";
    case Opcode::Sign:
      return "sign";
    case Opcode::Floor:
      return "floor";
    case Opcode::Min:
      return "min";
    case Opcode::Max:
      return "max";
    case Opcode::Atan2:
      return "atan2";
    default:
      return nullptr;
  }
}

const char* infixOperator(Opcode op)
{
  switch (op)
  {
    case Opcode::Add:
      return " + ";
    case Opcode::Sub:
      return " - ";
    case Opcode::Mul:
      return " * ";
    case Opcode::Div:
      return " / ";
    case Opcode::Pow:
      return "^";
    default:
      return nullptr;
  }
}

class HyperFunWriter
{
public:
  std::string write(const frep::Hypervolume& hv, const std::string& name, int parameterCount)
  {
    checkName(name);
    const frep::Domain domain = hv.geometry().domain();
    const std::uint8_t axes = frep::domainAxes(domain);
    const int xSize = (axes & ~0x3u) == 0 ? 2 : (axes & ~0x7u) == 0 ? 3 : 4;

    const frep::Attribute* colour = nullptr;
    std::vector<const frep::Attribute*> dropped;
    for (const frep::Attribute& a : hv.attributes())
    {
      const bool everywhere = a.partition.isConstant() && a.partition.constantValue() >= 0;
      if (!colour && a.name == "colour" && a.components.size() == 3 && a.tensorRows == 0 &&
        everywhere)
      {
        colour = &a;
      }
      else
      {
        dropped.push_back(&a);
      }
    }

    std::vector<Expr> roots{ hv.geometry().function() };
    if (colour)
    {
      roots.insert(roots.end(), colour->components.begin(), colour->components.end());
    }
    countUses(roots);
    for (const Expr& r : roots)
    {
      emitAll(r);
    }
    const int aSize = std::max({ parameterCount, static_cast<int>(maxSlot_ + 1), 1 });

    std::string out;
    out += "-- " + name + ": written by ICTK (ictk::lang::writeHyperFun)\n";
    out += std::string("-- domain ") + frep::domainName(domain) +
      "; coordinates x[1] = x, x[2] = y, x[3] = z, x[4] = t\n";
    if (hv.threshold() != 0.0 || !dropped.empty())
    {
      out += "-- Not expressible in HyperFun, left out (FRep XML keeps them):\n";
      if (hv.threshold() != 0.0)
      {
        out += "--   threshold " + joinNumbers({ hv.threshold() }) +
          " (the function below is unchanged: its surface is at that value, not 0)\n";
      }
      for (const frep::Attribute* a : dropped)
      {
        out += "--   attribute '" + commentSafe(a->name) +
          "': " + std::to_string(a->components.size()) + " component(s)";
        if (a->tensorRows > 0)
        {
          out += ", tensor with " + std::to_string(a->tensorRows) + " row(s)";
        }
        out += '\n';
        if (a->components.size() <= 16)
        {
          out += "--     inside default  " + joinNumbers(a->insideDefault) + "\n";
          out += "--     outside default " + joinNumbers(a->outsideDefault) + "\n";
        }
      }
    }
    out += name + "(x[" + std::to_string(xSize) + "], a[" + std::to_string(aSize) + "]" +
      (colour ? ", s[3]" : "") + ")\n{\n";
    out += body_;
    if (colour)
    {
      for (int i = 0; i < 3; ++i)
      {
        out += "  s[" + std::to_string(i + 1) + "] = " + take(colour->components[i]).text + ";\n";
      }
    }
    out += "  " + name + " = " + take(hv.geometry().function()).text + ";\n}\n";
    return out;
  }

private:
  // Binding strength of a text, for bracketing. HyperFun's grammar (the original parser): '+' '-'
  // below '*' '/' below '^', all left-associative, and unary minus binding tighter than '^'. A
  // unary minus is bracketed wherever it is an operand, and '^' and unary minus only take atoms,
  // so that no reader can disagree on `-a^b` or `a^b^c`.
  enum Precedence
  {
    Unary = 1,
    Sum = 2,
    Product = 3,
    Power = 4,
    Atom = 5
  };
  struct Text
  {
    std::string text;
    int precedence = Atom;
    int depth = 0; // bracket and call nesting
  };

  void countUses(const std::vector<Expr>& roots)
  {
    std::unordered_set<const frep::Node*> seen;
    for (const Expr& root : roots)
    {
      ++uses_[root.id()];
      if (!seen.insert(root.id()).second)
      {
        continue;
      }
      root.visitPostOrder(
        [&](const Expr& e)
        {
          seen.insert(e.id());
          for (int i = 0; i < e.arity(); ++i)
          {
            ++uses_[e.child(i).id()];
          }
        });
    }
  }

  // Builds the texts of every node under `root` not yet done, in post-order; nodes that must be
  // locals are assigned in body_ on the way.
  void emitAll(const Expr& root)
  {
    if (done_.count(root.id()))
    {
      return;
    }
    root.visitPostOrder(
      [&](const Expr& e)
      {
        if (!done_.insert(e.id()).second)
        {
          return;
        }
        emit(e);
      });
  }

  // The text of a child for its (single) parent. Local and leaf texts are kept (they may be used
  // again); an inline text is moved out, which keeps the memory linear.
  Text take(const Expr& e)
  {
    auto it = texts_.find(e.id());
    if (it == texts_.end())
    {
      throw std::logic_error("writeHyperFun: node used before it was written");
    }
    if (e.arity() == 0 || locals_.count(e.id()))
    {
      return it->second;
    }
    Text t = std::move(it->second);
    texts_.erase(it);
    return t;
  }

  static std::string operand(const Text& t, int precedence)
  {
    return t.precedence >= precedence ? t.text : "(" + t.text + ")";
  }

  void emit(const Expr& e)
  {
    Text t;
    switch (e.opcode())
    {
      case Opcode::Constant:
      {
        const double v = e.constantValue();
        if (!std::isfinite(v))
        {
          throw std::invalid_argument(
            std::string("writeHyperFun: the model contains the constant ") +
            (std::isnan(v) ? "NaN"
                : v > 0    ? "+infinity"
                           : "-infinity") +
            ", which HyperFun cannot express");
        }
        t.text = v < 0 ? "-" + hyperFunNumber(-v) : hyperFunNumber(v);
        t.precedence = v < 0 ? Unary : Atom;
        texts_.emplace(e.id(), std::move(t));
        return;
      }
      case Opcode::Variable:
        t.text = "x[" + std::to_string(static_cast<int>(e.axis()) + 1) + "]";
        texts_.emplace(e.id(), std::move(t));
        return;
      case Opcode::Parameter:
        maxSlot_ = std::max<long long>(maxSlot_, e.parameterSlot());
        t.text = "a[" + std::to_string(static_cast<long long>(e.parameterSlot()) + 1) + "]";
        texts_.emplace(e.id(), std::move(t));
        return;
      default:
        break;
    }

    if (e.opcode() == Opcode::Select)
    {
      // HyperFun has no conditional expression: a statement assigns a local in both branches.
      Text c = take(e.child(0));
      if (c.text[0] == '(')
      {
        // HyperFun reads a condition that opens with '(' as a bracketed condition, so
        // `(p + q) * r >= 0` would not parse: such a condition goes through a local.
        const std::string v = newLocal(e.child(0));
        body_ += "  " + v + " = " + c.text + ";\n";
        c = Text{ v, Atom, 0 };
      }
      const Text a = take(e.child(1));
      const Text b = take(e.child(2));
      const std::string v = newLocal(e);
      body_ += "  if (" + c.text + " >= 0) then\n    " + v + " = " + a.text + ";\n  else\n    " +
        v + " = " + b.text + ";\n  endif;\n";
      return;
    }

    if (e.opcode() == Opcode::CauchySegment)
    {
      // HyperFun has no such function: the kernel's terms (FRep/Kernels.h cauchySegment), over
      // locals since each operand occurs several times.
      const std::string u = atomOf(e.child(0)), v = atomOf(e.child(1)), l = atomOf(e.child(2));
      const std::string p2 = "v" + std::to_string(++localCount_);
      const std::string p = "v" + std::to_string(++localCount_);
      const std::string w = "v" + std::to_string(++localCount_);
      body_ += "  " + p2 + " = 1 + " + v + ";\n  " + p + " = sqrt(" + p2 + ");\n  " + w + " = " +
        l + " - " + u + ";\n";
      const std::string r = newLocal(e);
      body_ += "  " + r + " = " + u + " / (2 * " + p2 + " * (" + p2 + " + " + u + "^2)) + " + w +
        " / (2 * " + p2 + " * (" + p2 + " + " + w + "^2)) + (atan(" + u + " / " + p + ") + atan(" +
        w + " / " + p + ")) / (2 * " + p2 + " * " + p + ");\n";
      return;
    }

    if (e.arity() == 1)
    {
      const Text c = take(e.child(0));
      t.depth = c.depth + 1;
      if (e.opcode() == Opcode::Neg)
      {
        t.text = "-" + operand(c, Atom);
        t.precedence = Unary;
      }
      else if (e.opcode() == Opcode::Square)
      {
        t.text = operand(c, Atom) + "^2";
        t.precedence = Power;
      }
      else
      {
        t.text = std::string(functionName(e.opcode())) + "(" + c.text + ")";
      }
    }
    else
    {
      if (e.opcode() == Opcode::Div && e.child(1).isConstant() &&
        std::fabs(e.child(1).constantValue()) < kHyperFunEps)
      {
        throw std::invalid_argument("writeHyperFun: the model divides by the constant " +
          joinNumbers({ e.child(1).constantValue() }) +
          ", which HyperFun refuses as a division by zero (|divisor| < 1e-6)");
      }
      const Text a = take(e.child(0));
      const Text b = take(e.child(1));
      t.depth = std::max(a.depth, b.depth) + 1;
      if (const char* name = functionName(e.opcode()))
      {
        t.text = std::string(name) + "(" + a.text + ", " + b.text + ")";
      }
      else
      {
        const Opcode op = e.opcode();
        t.precedence = op == Opcode::Pow           ? Power
          : op == Opcode::Mul || op == Opcode::Div ? Product
                                                   : Sum;
        // Left-associative: the left operand may be of the same level, the right one not.
        const int left = t.precedence == Power ? Atom : t.precedence;
        const int right = t.precedence == Power ? Atom : t.precedence + 1;
        t.text = operand(a, left) + infixOperator(op) + operand(b, right);
      }
    }

    if (uses_.at(e.id()) > 1 || t.depth >= kMaxInlineDepth)
    {
      const std::string v = newLocal(e);
      body_ += "  " + v + " = " + t.text + ";\n";
      return;
    }
    texts_.emplace(e.id(), std::move(t));
  }

  // A child's text as an atom that may be repeated: a leaf or a local as it is, a negative
  // number bracketed, anything else through a local of its own.
  std::string atomOf(const Expr& e)
  {
    const Text t = take(e);
    if (t.precedence == Atom)
    {
      return t.text;
    }
    if (e.isConstant())
    {
      return "(" + t.text + ")";
    }
    const std::string v = "v" + std::to_string(++localCount_);
    body_ += "  " + v + " = " + t.text + ";\n";
    return v;
  }

  std::string newLocal(const Expr& e)
  {
    std::string v = "v" + std::to_string(++localCount_);
    locals_.insert(e.id());
    texts_[e.id()] = Text{ v, Atom, 0 };
    return v;
  }

  std::unordered_map<const frep::Node*, int> uses_;
  std::unordered_set<const frep::Node*> done_;
  std::unordered_set<const frep::Node*> locals_;
  std::unordered_map<const frep::Node*, Text> texts_;
  std::string body_;
  int localCount_ = 0;
  long long maxSlot_ = -1;
};

} // namespace

std::string writeHyperFun(
  const frep::Hypervolume& model, const std::string& name, int parameterCount)
{
  return HyperFunWriter().write(model, name, parameterCount);
}

} // namespace ictk::lang
