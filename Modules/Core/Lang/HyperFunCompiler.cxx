// SPDX-License-Identifier: BSD-3-Clause
// HyperFun -> FRep DAG. The semantics follow HyperFun's interpreter (pmur002/hyperfun, files
// src/interpreter_lib/int_calc.c, int_global.c, int_parse_N.c, int_scanner.c and the library in
// src/hflibrary_lib):
//  - '|' '&' '\' '@' are the alpha-system R-functions with HyperFun's default ALPHA = 0
//    (int_global.c): f1 + f2 +- sqrt(f1^2 + f2^2); '\' is f1 & -f2 and '@' is '&' (HyperFun
//    evaluates every operand in the same x space, so the product is an intersection). '~' is -f.
//  - Truth: a value is true when |v| >= EPS = 1e-6; comparisons give 1 or 0, '=' and '/=' compare
//    with the same EPS; and/or/xor/not work on truth values (int_calc.c FUNC_bool_*).
//  - '^': an exponent within EPS above an integer is that integer (repeated product, reciprocal
//    for a negative one); otherwise a real power (int_calc.c FUNC_binary_power).
//  - Assigning to the function's own name returns from it (CODE_body_assignment).
//  - The third parameter array s carries attributes; hfA_SetColor(f, s, r, g, b) writes
//    s[1..3] = (r, g, b) where f >= 0 (hfA_SetColor.c); s[1..3] at return become the "colour"
//    attribute.
//  - Library space maps change their array argument in place (hfShift3D.c, ...).
// Where ICTK differs it says so: sign() is the true sign (HyperFun's FUNC_sign always returns 1,
// a bug), and a division by zero is an error only when the divisor is a compile-time constant.
#include "Lang/HyperFunCompiler.h"

#include "FRep/Operations.h"
#include "FRep/Primitives.h"

#include <array>
#include <cmath>
#include <functional>
#include <map>
#include <optional>
#include <unordered_map>

namespace ictk::lang::hf
{

using frep::Axis;
using frep::Expr;
using frep::Shape;

namespace
{
constexpr double Eps = 1e-6; // HyperFun's EPS (int_global.c: 0.1e-5)

struct CompileError
{
  int line, column;
  std::string message;
};
struct Fatal
{};

/// A compiled value. `isBool`: the value is exactly 0 or 1 (a comparison or logic result).
/// `margin`/`negated` (when hasMargin): the condition holds exactly when (margin >= 0) != negated,
/// which keeps comparisons exact at ties (a < b is "not (a - b >= 0)").
struct Val
{
  Expr e;
  bool isBool = false;
  bool hasMargin = false;
  Expr margin;
  bool negated = false;
};

struct Var
{
  bool isArray = false;
  bool isBool = false;
  std::vector<Expr> items;
  std::vector<char> set;
};

/// A return taken on some paths only: the function's value is `value` where guard01 = 1.
struct Pending
{
  Expr guard01;
  Expr value;
  std::vector<Expr> s;
};

struct Frame
{
  const Function* fn = nullptr;
  std::map<std::string, Var> vars;
  bool returned = false;
  Expr result;
  std::vector<Expr> sAtReturn;
  std::vector<Pending> pending;
};

std::string fmt(double v)
{
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

/// Rounding towards zero, as modf's integral part (constant arguments fold).
Expr truncate(const Expr& v)
{
  return frep::select(v, frep::floor(v), -frep::floor(-v));
}

int hfRound(double d)
{
  // HF_round (int_parse_N.c): nearest, halves upwards.
  const double c = std::ceil(d);
  return static_cast<int>((c - d > 0.5) ? (c - 1) : c);
}

class Compiler
{
public:
  Compiler(const Program& program, DiagnosticSink& sink, const Limits& limits,
    const std::vector<double>& parameterValues)
    : p_(program)
    , sink_(sink)
    , limits_(limits)
    , parameterValues_(parameterValues)
  {
  }

  HyperFunModel run(const std::string& function);

private:
  const Program& p_;
  DiagnosticSink& sink_;
  const Limits& limits_;
  const std::vector<double>& parameterValues_;
  std::uint64_t iterations_ = 0;
  std::size_t ops_ = 0;
  std::vector<const Function*> callStack_;

  [[noreturn]] void fail(int line, int column, const std::string& message)
  {
    throw CompileError{ line, column, message };
  }
  void report(const CompileError& e)
  {
    if (!sink_.error(e.line, e.column, e.message))
    {
      throw Fatal{};
    }
  }
  void count(std::size_t n, const ExprNode& at)
  {
    ops_ += n;
    if (ops_ > limits_.maxExpressionNodes)
    {
      sink_.error(at.line, at.column,
        "the model is too large: more than " + std::to_string(limits_.maxExpressionNodes) +
          " expression nodes");
      throw Fatal{};
    }
  }

  const ExprNode& node(int i) const { return p_.exprs[static_cast<std::size_t>(i)]; }
  const Statement& stmt(int i) const { return p_.statements[static_cast<std::size_t>(i)]; }

  // --- values --------------------------------------------------------------------------------
  static Val plain(Expr e)
  {
    Val v;
    v.e = std::move(e);
    return v;
  }
  static Val boolean(Expr margin, bool negated)
  {
    Val v;
    v.e = negated ? frep::select(margin, Expr(0.0), Expr(1.0))
                  : frep::select(margin, Expr(1.0), Expr(0.0));
    v.isBool = true;
    v.hasMargin = true;
    v.margin = std::move(margin);
    v.negated = negated;
    return v;
  }
  /// 1 where the value is true, 0 elsewhere.
  static Expr truth(const Val& v)
  {
    if (v.isBool)
    {
      return v.e;
    }
    return frep::select(frep::abs(v.e) - Eps, Expr(1.0), Expr(0.0));
  }
  static std::pair<Expr, bool> condition(const Val& v)
  {
    if (v.hasMargin)
    {
      return { v.margin, v.negated };
    }
    if (v.isBool)
    {
      return { v.e - 0.5, false };
    }
    return { frep::abs(v.e) - Eps, false };
  }
  static Expr choose(const std::pair<Expr, bool>& c, const Expr& ifTrue, const Expr& ifFalse)
  {
    return c.second ? frep::select(c.first, ifFalse, ifTrue)
                    : frep::select(c.first, ifTrue, ifFalse);
  }

  std::string dependsOn(const Expr& e) const
  {
    if (e.axesUsed() != 0)
    {
      return "the coordinates";
    }
    return "model parameters, which are not known at compile time (give their values when reading "
           "the model, e.g. `ictk ... --params`, to specialise it)";
  }

  double constant(const Val& v, const ExprNode& at, const std::string& what)
  {
    if (!v.e.isConstant())
    {
      fail(at.line, at.column,
        what + " must be known at compile time, but it depends on " + dependsOn(v.e));
    }
    return v.e.constantValue();
  }

  // --- expressions ---------------------------------------------------------------------------
  Var& lookup(Frame& f, const ExprNode& n)
  {
    auto it = f.vars.find(n.name);
    if (it == f.vars.end())
    {
      fail(n.line, n.column, "unknown variable '" + n.spelling + "'");
    }
    return it->second;
  }

  int indexOf(Frame& f, int indexExpr, const Var& v, const std::string& spelling)
  {
    const ExprNode& in = node(indexExpr);
    const Val iv = eval(f, indexExpr);
    const double d = constant(iv, in, "the index into '" + spelling + "'");
    const int i = std::isfinite(d) && std::fabs(d) < 1e9 ? hfRound(d) : -1;
    if (i < 1 || static_cast<std::size_t>(i) > v.items.size())
    {
      fail(in.line, in.column,
        "index " + fmt(d) + " is out of range for '" + spelling + "' (1.." +
          std::to_string(v.items.size()) + ")");
    }
    return i - 1;
  }

  const std::vector<Expr>& arrayArgument(Frame& f, int arg, const std::string& fn, int position)
  {
    const ExprNode& n = node(arg);
    if (n.kind != ExprNode::Kind::Variable)
    {
      fail(n.line, n.column,
        "argument " + std::to_string(position) + " of " + fn + " must be the name of an array");
    }
    Var& v = lookup(f, n);
    if (!v.isArray)
    {
      fail(n.line, n.column,
        "argument " + std::to_string(position) + " of " + fn + ": '" + n.spelling +
          "' is not an array");
    }
    for (std::size_t i = 0; i < v.items.size(); ++i)
    {
      if (!v.set[i])
      {
        fail(n.line, n.column,
          "argument " + std::to_string(position) + " of " + fn + ": item " + std::to_string(i + 1) +
            " of '" + n.spelling + "' is used before it is assigned");
      }
    }
    return v.items;
  }

  Val eval(Frame& f, int index)
  {
    const ExprNode& n = node(index);
    switch (n.kind)
    {
      case ExprNode::Kind::Number:
        return plain(Expr(n.number));
      case ExprNode::Kind::Variable:
      {
        Var& v = lookup(f, n);
        if (v.isArray)
        {
          fail(n.line, n.column,
            "'" + n.spelling + "' is an array; use one item, as " + n.spelling + "[1]");
        }
        if (!v.set[0])
        {
          fail(n.line, n.column, "variable '" + n.spelling + "' is used before it is assigned");
        }
        Val r = plain(v.items[0]);
        r.isBool = v.isBool;
        return r;
      }
      case ExprNode::Kind::Index:
      {
        Var& v = lookup(f, n);
        if (!v.isArray)
        {
          fail(n.line, n.column, "'" + n.spelling + "' is not an array");
        }
        const int i = indexOf(f, n.kids[0], v, n.spelling);
        if (!v.set[static_cast<std::size_t>(i)])
        {
          fail(n.line, n.column,
            "item " + std::to_string(i + 1) + " of '" + n.spelling +
              "' is used before it is assigned");
        }
        return plain(v.items[static_cast<std::size_t>(i)]);
      }
      case ExprNode::Kind::Unary:
      {
        const Val a = eval(f, n.kids[0]);
        count(1, n);
        switch (n.ops[0])
        {
          case TokenKind::Plus:
            return a;
          case TokenKind::KwNot:
          {
            if (a.hasMargin)
            {
              return boolean(a.margin, !a.negated);
            }
            Val r = plain(1.0 - truth(a));
            r.isBool = true;
            return r;
          }
          default: // '-' and '~' (complement) are both -f
            return plain(-a.e);
        }
      }
      case ExprNode::Kind::Chain:
      {
        Val acc = eval(f, n.kids[0]);
        for (std::size_t k = 1; k < n.kids.size(); ++k)
        {
          const Val b = eval(f, n.kids[k]);
          count(4, n);
          ExprNode at = n;
          at.line = n.opPositions[k - 1].first;
          at.column = n.opPositions[k - 1].second;
          acc = binary(n.ops[k - 1], acc, b, at);
        }
        return acc;
      }
      case ExprNode::Kind::Call:
        return call(f, n);
    }
    fail(n.line, n.column, "internal error: unknown expression");
  }

  static Expr rUnion(const Expr& a, const Expr& b)
  {
    // = frep::unite(alpha 0) (Operations.cxx rUnion), HyperFun FUNC_binary_union with ALPHA = 0.
    return a + b + frep::sqrt(frep::square(a) + frep::square(b));
  }
  static Expr rIntersection(const Expr& a, const Expr& b)
  {
    return a + b - frep::sqrt(frep::square(a) + frep::square(b));
  }

  Val binary(TokenKind op, const Val& a, const Val& b, const ExprNode& at)
  {
    switch (op)
    {
      case TokenKind::Plus:
        return plain(a.e + b.e);
      case TokenKind::Minus:
        return plain(a.e - b.e);
      case TokenKind::Star:
        return plain(a.e * b.e);
      case TokenKind::Slash:
        if (b.e.isConstant() && std::fabs(b.e.constantValue()) < Eps)
        {
          fail(at.line, at.column, "division by zero");
        }
        return plain(a.e / b.e);
      case TokenKind::Caret:
        return power(a.e, b.e, at);
      case TokenKind::Bar:
        return plain(rUnion(a.e, b.e));
      case TokenKind::Ampersand:
      case TokenKind::At:
        return plain(rIntersection(a.e, b.e));
      case TokenKind::Backslash:
        return plain(rIntersection(a.e, -b.e));
      case TokenKind::LessEqual:
        return boolean(b.e - a.e, false);
      case TokenKind::GreaterEqual:
        return boolean(a.e - b.e, false);
      case TokenKind::Less:
        return boolean(a.e - b.e, true);
      case TokenKind::Greater:
        return boolean(b.e - a.e, true);
      case TokenKind::Assign: // equality within EPS, as FUNC_bool_equal
        return boolean(frep::abs(a.e - b.e) - Eps, true);
      case TokenKind::NotEqual:
        return boolean(frep::abs(a.e - b.e) - Eps, false);
      case TokenKind::KwAnd:
      {
        Val r = plain(frep::min(truth(a), truth(b)));
        r.isBool = true;
        return r;
      }
      case TokenKind::KwOr:
      {
        Val r = plain(frep::max(truth(a), truth(b)));
        r.isBool = true;
        return r;
      }
      case TokenKind::KwXor:
      {
        Val r = plain(frep::abs(truth(a) - truth(b)));
        r.isBool = true;
        return r;
      }
      default:
        fail(at.line, at.column, "internal error: unknown operator");
    }
  }

  Val power(const Expr& base, const Expr& exponent, const ExprNode& at)
  {
    if (exponent.isConstant())
    {
      const double e = exponent.constantValue();
      if (base.isConstant() && std::fabs(base.constantValue()) < Eps && e <= Eps)
      {
        fail(at.line, at.column, "zero raised to a negative or zero power");
      }
      if (std::isfinite(e) && e - std::floor(e) < Eps)
      {
        const double n = std::floor(e);
        if (std::fabs(n) > 1e6)
        {
          fail(at.line, at.column, "integer exponent " + fmt(n) + " is too large");
        }
        return plain(frep::pow(base, Expr(n)));
      }
      if (base.isConstant() && base.constantValue() < 0)
      {
        fail(at.line, at.column, "negative value raised to a non-integer power");
      }
    }
    return plain(frep::pow(base, exponent));
  }

  // --- calls ---------------------------------------------------------------------------------
  void arity(const ExprNode& n, std::size_t expected)
  {
    if (n.kids.size() != expected)
    {
      fail(n.line, n.column,
        n.spelling + " takes " + std::to_string(expected) + " argument" +
          (expected == 1 ? "" : "s") + ", got " + std::to_string(n.kids.size()));
    }
  }

  Val call(Frame& f, const ExprNode& n)
  {
    if (const auto math = mathFunction(f, n))
    {
      return *math;
    }
    const auto lib = library().find(n.name);
    if (lib != library().end())
    {
      return lib->second(f, n);
    }
    for (const Function& g : p_.functions)
    {
      if (g.name == n.name)
      {
        return callUser(f, n, g);
      }
    }
    if (n.name.rfind("hf", 0) == 0)
    {
      fail(n.line, n.column,
        "unknown library function '" + n.spelling +
          "' (not in the HyperFun library supported by ICTK)");
    }
    fail(n.line, n.column, "unknown function '" + n.spelling + "'");
  }

  std::optional<Val> mathFunction(Frame& f, const ExprNode& n)
  {
    using Unary = Expr (*)(const Expr&);
    static const std::unordered_map<std::string, Unary> unary = {
      { "sqrt",
        [](const Expr& a)
        {
          return frep::sqrt(a);
        } },
      { "exp",
        [](const Expr& a)
        {
          return frep::exp(a);
        } },
      { "log",
        [](const Expr& a)
        {
          return frep::log(a);
        } },
      { "logd",
        [](const Expr& a)
        {
          return frep::log(a) / std::log(10.0);
        } },
      { "sin",
        [](const Expr& a)
        {
          return frep::sin(a);
        } },
      { "cos",
        [](const Expr& a)
        {
          return frep::cos(a);
        } },
      { "tan",
        [](const Expr& a)
        {
          return frep::tan(a);
        } },
      { "asin",
        [](const Expr& a)
        {
          return frep::asin(a);
        } },
      { "acos",
        [](const Expr& a)
        {
          return frep::acos(a);
        } },
      { "atan",
        [](const Expr& a)
        {
          return frep::atan(a);
        } },
      { "abs",
        [](const Expr& a)
        {
          return frep::abs(a);
        } },
      { "sign",
        [](const Expr& a)
        {
          return frep::sign(a);
        } },
      { "sinh",
        [](const Expr& a)
        {
          return (frep::exp(a) - frep::exp(-a)) / 2.0;
        } },
      { "cosh",
        [](const Expr& a)
        {
          return (frep::exp(a) + frep::exp(-a)) / 2.0;
        } },
      // 1 - 2 / (e^2a + 1) stays finite for large |a| (no inf / inf).
      { "tanh",
        [](const Expr& a)
        {
          return 1.0 - 2.0 / (frep::exp(2.0 * a) + 1.0);
        } },
    };
    auto u = unary.find(n.name);
    if (u != unary.end())
    {
      arity(n, 1);
      const Val a = eval(f, n.kids[0]);
      count(4, n);
      if (a.e.isConstant())
      {
        // HyperFun stops with a run-time error on these; a constant one is certainly wrong.
        const double v = a.e.constantValue();
        if (n.name == "sqrt" && v < 0)
        {
          fail(n.line, n.column, "square root of a negative number (" + fmt(v) + ")");
        }
        if ((n.name == "log" || n.name == "logd") && !(v > 0))
        {
          fail(n.line, n.column, "logarithm of a non-positive number (" + fmt(v) + ")");
        }
        if ((n.name == "asin" || n.name == "acos") && std::fabs(v) > 1)
        {
          fail(n.line, n.column, n.spelling + " argument must lie in [-1, 1] (got " + fmt(v) + ")");
        }
      }
      return plain(u->second(a.e));
    }
    if (n.name == "max" || n.name == "min" || n.name == "atan2" || n.name == "mod")
    {
      arity(n, 2);
      const Val a = eval(f, n.kids[0]);
      const Val b = eval(f, n.kids[1]);
      count(1, n);
      if (n.name == "max")
      {
        return plain(frep::max(a.e, b.e));
      }
      if (n.name == "min")
      {
        return plain(frep::min(a.e, b.e));
      }
      if (n.name == "atan2")
      {
        return plain(frep::atan2(a.e, b.e));
      }
      if (a.e.isConstant() && b.e.isConstant())
      {
        const double x = a.e.constantValue(), y = b.e.constantValue();
        if (!std::isfinite(x) || !std::isfinite(y) || std::fabs(x) > 2e9 || std::fabs(y) > 2e9 ||
          hfRound(y) == 0)
        {
          fail(n.line, n.column, "invalid arguments of mod");
        }
        // FUNC_mod: fmod of the rounded arguments.
        return plain(Expr(std::fmod(static_cast<double>(hfRound(x)), hfRound(y))));
      }
      // The same on expressions: HF_round(d) = floor(d + 0.5) and fmod(p, q) = p - q trunc(p / q),
      // exact for the integers HyperFun allows (|p|, |q| < 2^26 keep p / q away from an integer
      // by more than its rounding error). A divisor that rounds to 0 gives NaN where HyperFun
      // stops.
      const Expr p = frep::floor(a.e + 0.5), q = frep::floor(b.e + 0.5);
      return plain(p - q * truncate(p / q));
    }
    if (n.name == "ceil" || n.name == "floor" || n.name == "int" || n.name == "frac")
    {
      arity(n, 1);
      const Expr v = eval(f, n.kids[0]).e;
      count(3, n);
      if (n.name == "floor")
      {
        return plain(frep::floor(v));
      }
      if (n.name == "ceil")
      {
        return plain(-frep::floor(-v));
      }
      // modf: the integral part truncates towards zero; the fraction keeps the sign of v.
      return plain(n.name == "int" ? truncate(v) : v - truncate(v));
    }
    return std::nullopt;
  }

  Val callUser(Frame& caller, const ExprNode& n, const Function& g)
  {
    for (const Function* active : callStack_)
    {
      if (active == &g)
      {
        fail(n.line, n.column, "recursive call of '" + g.spelling + "'");
      }
    }
    if (static_cast<int>(callStack_.size()) >= limits_.maxNesting)
    {
      fail(n.line, n.column,
        "calls nested deeper than the limit of " + std::to_string(limits_.maxNesting));
    }
    if (n.kids.size() != g.params.size())
    {
      fail(n.line, n.column,
        "'" + g.spelling + "' takes " + std::to_string(g.params.size()) + " array arguments, got " +
          std::to_string(n.kids.size()));
    }
    Frame callee;
    callee.fn = &g;
    for (std::size_t k = 0; k < g.params.size(); ++k)
    {
      const std::vector<Expr>& items =
        arrayArgument(caller, n.kids[k], g.spelling, static_cast<int>(k + 1));
      const auto size = static_cast<std::size_t>(g.params[k].size);
      if (items.size() < size)
      {
        const ExprNode& an = node(n.kids[k]);
        fail(an.line, an.column,
          "argument " + std::to_string(k + 1) + " of '" + g.spelling + "' has " +
            std::to_string(items.size()) + " items, the function reads " + std::to_string(size));
      }
      Var v;
      v.isArray = true;
      v.items.assign(items.begin(), items.begin() + static_cast<std::ptrdiff_t>(size));
      v.set.assign(size, 1);
      callee.vars[g.params[k].name] = std::move(v);
    }
    callStack_.push_back(&g);
    const std::size_t errorsBefore = sink_.diagnostics().size();
    execute(callee, g.body);
    callStack_.pop_back();
    if (sink_.diagnostics().size() != errorsBefore)
    {
      fail(n.line, n.column, "in the call of '" + g.spelling + "' (errors above)");
    }
    if (!callee.returned && callee.pending.empty())
    {
      fail(n.line, n.column,
        "'" + g.spelling + "' does not assign its result ('" + g.spelling + " = ...;')");
    }
    std::vector<Expr> s;
    const Expr value = finish(callee, s, n);
    // HyperFun copies the callee's s array back into the caller's (int_calc.c I_EXTERN_CALL).
    if (g.params.size() >= 3)
    {
      const ExprNode& sn = node(n.kids[2]);
      Var& target = lookup(caller, sn);
      for (std::size_t i = 0; i < s.size() && i < target.items.size(); ++i)
      {
        target.items[i] = s[i];
        target.set[i] = 1;
      }
    }
    return plain(value);
  }

  /// The function's value and s array, folding the returns taken on some paths only.
  Expr finish(Frame& f, std::vector<Expr>& s, const ExprNode& at)
  {
    Expr value;
    if (f.returned)
    {
      value = f.result;
      s = f.sAtReturn;
    }
    else
    {
      // Reached only when every path returned through `pending`: the last one decides.
      Pending last = f.pending.back();
      f.pending.pop_back();
      value = last.value;
      s = last.s;
    }
    for (auto it = f.pending.rbegin(); it != f.pending.rend(); ++it)
    {
      count(1 + s.size(), at);
      value = frep::select(it->guard01 - 0.5, it->value, value);
      for (std::size_t i = 0; i < s.size() && i < it->s.size(); ++i)
      {
        s[i] = frep::select(it->guard01 - 0.5, it->s[i], s[i]);
      }
    }
    return value;
  }

  // --- library -------------------------------------------------------------------------------
  using Handler = std::function<Val(Frame&, const ExprNode&)>;
  const std::unordered_map<std::string, Handler>& library();
  std::unordered_map<std::string, Handler> library_;

  std::vector<double> constants(Frame& f, const ExprNode& n, std::size_t k)
  {
    const std::vector<Expr>& items =
      arrayArgument(f, n.kids[k], n.spelling, static_cast<int>(k + 1));
    std::vector<double> out;
    out.reserve(items.size());
    for (std::size_t i = 0; i < items.size(); ++i)
    {
      if (!items[i].isConstant())
      {
        const ExprNode& an = node(n.kids[k]);
        fail(an.line, an.column,
          "argument " + std::to_string(k + 1) + " of " + n.spelling + " (item " +
            std::to_string(i + 1) + ") must be known at compile time, but it depends on " +
            dependsOn(items[i]));
      }
      out.push_back(items[i].constantValue());
    }
    return out;
  }
  double number(Frame& f, const ExprNode& n, std::size_t k)
  {
    const Val v = eval(f, n.kids[k]);
    return constant(v, node(n.kids[k]), "argument " + std::to_string(k + 1) + " of " + n.spelling);
  }
  frep::Vec3 vec3(Frame& f, const ExprNode& n, std::size_t k)
  {
    const auto v = constants(f, n, k);
    if (v.size() < 3)
    {
      const ExprNode& an = node(n.kids[k]);
      fail(an.line, an.column,
        "argument " + std::to_string(k + 1) + " of " + n.spelling + " must have 3 items");
    }
    return { v[0], v[1], v[2] };
  }
  /// The substitution that evaluates a kernel shape at the (mapped) coordinates of array k.
  std::array<Expr, frep::AxisCount> coordinates(Frame& f, const ExprNode& n, std::size_t k)
  {
    const std::vector<Expr>& xt = arrayArgument(f, n.kids[k], n.spelling, static_cast<int>(k + 1));
    if (xt.size() < 3)
    {
      const ExprNode& an = node(n.kids[k]);
      fail(an.line, an.column,
        n.spelling + " needs a coordinate array of 3 items (x, y, z), '" + an.spelling + "' has " +
          std::to_string(xt.size()));
    }
    return { xt[0], xt[1], xt[2], xt.size() > 3 ? xt[3] : Expr::t() };
  }
  Val place(const Expr& e, const std::array<Expr, frep::AxisCount>& map, const ExprNode& n)
  {
    count(e.nodeCount(), n);
    return plain(e.substitute(map));
  }
  /// Runs a kernel constructor, turning its std::invalid_argument into a diagnostic.
  template <typename Build>
  Expr kernel(const ExprNode& n, Build build)
  {
    try
    {
      return build();
    }
    catch (const std::exception& e)
    {
      fail(n.line, n.column, n.spelling + ": " + e.what());
    }
  }
  std::vector<frep::Vec3> points(Frame& f, const ExprNode& n, std::size_t k, std::size_t count3)
  {
    const auto v = constants(f, n, k);
    if (v.size() < 3 * count3)
    {
      const ExprNode& an = node(n.kids[k]);
      fail(an.line, an.column,
        "argument " + std::to_string(k + 1) + " of " + n.spelling + " must have " +
          std::to_string(3 * count3) + " items (3 per point)");
    }
    std::vector<frep::Vec3> out(count3);
    for (std::size_t i = 0; i < count3; ++i)
    {
      out[i] = { v[3 * i], v[3 * i + 1], v[3 * i + 2] };
    }
    return out;
  }
  std::vector<double> firstN(Frame& f, const ExprNode& n, std::size_t k, std::size_t count)
  {
    auto v = constants(f, n, k);
    if (v.size() < count)
    {
      const ExprNode& an = node(n.kids[k]);
      fail(an.line, an.column,
        "argument " + std::to_string(k + 1) + " of " + n.spelling + " must have at least " +
          std::to_string(count) + " items");
    }
    v.resize(count);
    return v;
  }
  /// Applies a space map in place to the coordinate array argument 0: item i becomes the map's
  /// component i (got by mapping the probe shape "coordinate i") evaluated at the old items.
  Val spaceMap(Frame& f, const ExprNode& n, const std::function<Shape(const Shape&)>& op)
  {
    const auto map = coordinates(f, n, 0);
    std::array<Expr, 3> next;
    for (int i = 0; i < 3; ++i)
    {
      const Shape probe(Expr::variable(static_cast<Axis>(i)), frep::Domain::XYZ);
      const Expr component = kernel(n, [&] { return op(probe).function(); });
      count(component.nodeCount(), n);
      next[static_cast<std::size_t>(i)] = component.substitute(map);
    }
    Var& target = lookup(f, node(n.kids[0]));
    for (std::size_t i = 0; i < 3; ++i)
    {
      target.items[i] = next[i];
    }
    return plain(Expr(1.0)); // the HyperFun space maps return 1
  }

  // --- statements ----------------------------------------------------------------------------
  void execute(Frame& f, const std::vector<int>& body)
  {
    for (int s : body)
    {
      if (f.returned)
      {
        return;
      }
      try
      {
        executeOne(f, stmt(s));
      }
      catch (const CompileError& e)
      {
        report(e);
      }
    }
  }

  void assignScalar(Frame& f, const Statement& s, const Val& v)
  {
    auto it = f.vars.find(s.name);
    if (it != f.vars.end() && it->second.isArray)
    {
      fail(s.line, s.column,
        "'" + s.spelling + "' is an array; assign its items (" + s.spelling +
          "[1] = ...) or a list ([...])");
    }
    Var& var = f.vars[s.name];
    var.isArray = false;
    var.isBool = v.isBool;
    var.items.assign(1, v.e);
    var.set.assign(1, 1);
  }

  void executeOne(Frame& f, const Statement& s)
  {
    switch (s.kind)
    {
      case Statement::Kind::ArrayDecl:
        for (const auto& d : s.declared)
        {
          if (f.vars.count(d.name))
          {
            fail(d.line, d.column, "'" + d.spelling + "' is already declared");
          }
          Var v;
          v.isArray = true;
          v.items.assign(static_cast<std::size_t>(d.size), Expr(0.0));
          v.set.assign(static_cast<std::size_t>(d.size), 0);
          ops_ += static_cast<std::size_t>(d.size);
          f.vars[d.name] = std::move(v);
        }
        return;
      case Statement::Kind::Assign:
      {
        const ExprNode& rhs = node(s.expr);
        if (s.name == f.fn->name)
        {
          const Val v = eval(f, s.expr);
          f.returned = true;
          f.result = v.e;
          f.sAtReturn.clear();
          if (f.fn->params.size() >= 3)
          {
            f.sAtReturn = f.vars[f.fn->params[2].name].items;
          }
          return;
        }
        auto it = f.vars.find(s.name);
        if (rhs.kind == ExprNode::Kind::Variable && it != f.vars.end() && it->second.isArray)
        {
          // Whole-array copy, `xt = x;`.
          const std::vector<Expr> items = arrayArgument(f, s.expr, "the assignment", 1);
          Var& target = it->second;
          if (items.size() != target.items.size())
          {
            fail(rhs.line, rhs.column,
              "cannot assign '" + rhs.spelling + "' (" + std::to_string(items.size()) +
                " items) to '" + s.spelling + "' (" + std::to_string(target.items.size()) +
                " items)");
          }
          target.items = items;
          target.set.assign(items.size(), 1);
          return;
        }
        assignScalar(f, s, eval(f, s.expr));
        return;
      }
      case Statement::Kind::AssignIndex:
      {
        auto it = f.vars.find(s.name);
        if (it == f.vars.end() || !it->second.isArray)
        {
          fail(s.line, s.column,
            "'" + s.spelling +
              "' is not a declared array (declare it with "
              "'array " +
              s.spelling + "[n];')");
        }
        const int i = indexOf(f, s.index, it->second, s.spelling);
        const Val v = eval(f, s.expr);
        Var& target = f.vars[s.name];
        target.items[static_cast<std::size_t>(i)] = v.e;
        target.set[static_cast<std::size_t>(i)] = 1;
        return;
      }
      case Statement::Kind::AssignList:
      {
        auto it = f.vars.find(s.name);
        if (it == f.vars.end() || !it->second.isArray)
        {
          fail(s.line, s.column,
            "'" + s.spelling +
              "' is not a declared array (declare it with "
              "'array " +
              s.spelling + "[" + std::to_string(s.list.size()) + "];')");
        }
        if (s.list.size() != it->second.items.size())
        {
          fail(s.line, s.column,
            "wrong number of items for '" + s.spelling + "': " + std::to_string(s.list.size()) +
              " given, the array has " + std::to_string(it->second.items.size()));
        }
        std::vector<Expr> items;
        for (int e : s.list)
        {
          items.push_back(eval(f, e).e);
        }
        Var& target = f.vars[s.name];
        target.items = std::move(items);
        target.set.assign(target.items.size(), 1);
        return;
      }
      case Statement::Kind::Call:
        eval(f, s.expr);
        return;
      case Statement::Kind::If:
        executeIf(f, s);
        return;
      case Statement::Kind::While:
        executeWhile(f, s);
        return;
    }
  }

  void executeIf(Frame& f, const Statement& s)
  {
    const Val c = eval(f, s.expr);
    const auto cond = condition(c);
    if (cond.first.isConstant())
    {
      const bool holds = (cond.first.constantValue() >= 0) != cond.second;
      execute(f, holds ? s.thenBody : s.elseBody);
      return;
    }
    // A branch on coordinates or parameters: run both, then merge with select nodes.
    Frame t;
    t.fn = f.fn;
    t.vars = f.vars;
    Frame e;
    e.fn = f.fn;
    e.vars = f.vars;
    execute(t, s.thenBody);
    execute(e, s.elseBody);
    const ExprNode& at = node(s.expr);
    const Expr c01 = choose(cond, Expr(1.0), Expr(0.0));
    auto foldReturn = [&](Frame& b, std::vector<Expr>& sv)
    {
      return finish(b, sv, at);
    };
    auto guarded = [&](Frame& b, const Expr& g)
    {
      for (Pending& p : b.pending)
      {
        f.pending.push_back({ frep::min(g, p.guard01), p.value, p.s });
      }
    };
    const bool tDone = t.returned;
    const bool eDone = e.returned;
    if (tDone && eDone)
    {
      std::vector<Expr> st, se;
      const Expr vt = foldReturn(t, st);
      const Expr ve = foldReturn(e, se);
      f.returned = true;
      f.result = choose(cond, vt, ve);
      f.sAtReturn = st;
      for (std::size_t i = 0; i < st.size() && i < se.size(); ++i)
      {
        f.sAtReturn[i] = choose(cond, st[i], se[i]);
      }
      return;
    }
    if (tDone || eDone)
    {
      Frame& done = tDone ? t : e;
      Frame& open = tDone ? e : t;
      std::vector<Expr> sv;
      const Expr v = foldReturn(done, sv);
      const Expr g = tDone ? c01 : 1.0 - c01;
      f.pending.push_back({ g, v, sv });
      guarded(open, tDone ? 1.0 - c01 : c01);
      f.vars = std::move(open.vars);
      return;
    }
    guarded(t, c01);
    guarded(e, 1.0 - c01);
    std::map<std::string, Var> merged;
    for (auto& [name, tv] : t.vars)
    {
      auto ev = e.vars.find(name);
      Var m = tv;
      if (ev == e.vars.end() || ev->second.isArray != tv.isArray ||
        ev->second.items.size() != tv.items.size())
      {
        m.set.assign(m.items.size(), 0); // assigned on one path only
      }
      else
      {
        m.isBool = tv.isBool && ev->second.isBool;
        for (std::size_t i = 0; i < m.items.size(); ++i)
        {
          if (!tv.set[i] || !ev->second.set[i])
          {
            m.set[i] = 0;
          }
          else if (!tv.items[i].identical(ev->second.items[i]))
          {
            count(1, at);
            m.items[i] = choose(cond, tv.items[i], ev->second.items[i]);
          }
        }
      }
      merged[name] = std::move(m);
    }
    for (auto& [name, ev] : e.vars)
    {
      if (!merged.count(name))
      {
        Var m = ev;
        m.set.assign(m.items.size(), 0);
        merged[name] = std::move(m);
      }
    }
    f.vars = std::move(merged);
  }

  void executeWhile(Frame& f, const Statement& s)
  {
    const ExprNode& at = node(s.expr);
    for (;;)
    {
      const Val c = eval(f, s.expr);
      const auto cond = condition(c);
      if (!cond.first.isConstant())
      {
        fail(at.line, at.column,
          "the condition of 'while' must be known at compile time, but it "
          "depends on " +
            dependsOn(cond.first));
      }
      if ((cond.first.constantValue() >= 0) == cond.second)
      {
        return;
      }
      if (++iterations_ > limits_.maxLoopIterations)
      {
        sink_.error(s.line, s.column,
          "loops ran more than the limit of " + std::to_string(limits_.maxLoopIterations) +
            " iterations");
        throw Fatal{};
      }
      const std::size_t before = sink_.diagnostics().size();
      execute(f, s.thenBody);
      if (f.returned || sink_.diagnostics().size() != before)
      {
        return; // an error would repeat on every iteration
      }
    }
  }
};

const std::unordered_map<std::string, Compiler::Handler>& Compiler::library()
{
  if (!library_.empty())
  {
    return library_;
  }
  auto& L = library_;
  using frep::Vec3;
  auto args = [this](const ExprNode& n, std::size_t k)
  {
    arity(n, k);
  };
  // Primitives called as hfName(x, centre, scalars...): `build(centre, scalars)` makes the shape.
  using Scalars = std::array<double, 5>;
  auto centred = [=](
                   std::size_t scalarCount, std::function<Shape(const Vec3&, const Scalars&)> build)
  {
    return [=](Frame& f, const ExprNode& n)
    {
      args(n, 2 + scalarCount);
      const auto m = coordinates(f, n, 0);
      const Vec3 c = vec3(f, n, 1);
      Scalars v{};
      for (std::size_t i = 0; i < scalarCount; ++i)
      {
        v[i] = number(f, n, 2 + i);
      }
      return place(kernel(n, [&] { return build(c, v).function(); }), m, n);
    };
  };
  L["hfsphere"] = centred(1, [](const Vec3& c, const Scalars& v) { return frep::sphere(c, v[0]); });
  L["hfellipsoid"] = centred(
    3, [](const Vec3& c, const Scalars& v) { return frep::ellipsoid(c, v[0], v[1], v[2]); });
  // hfBlock.c uses the global ALPHA, 0 by default: the R-function block, not the min form.
  L["hfblock"] = centred(3,
    [](const Vec3& vertex, const Scalars& v)
    { return frep::blockRFunction(vertex, v[0], v[1], v[2], 0.0); });
  L["hfsuperell"] = centred(5,
    [](const Vec3& c, const Scalars& v)
    { return frep::superellipsoid(c, v[0], v[1], v[2], v[3], v[4]); });
  const std::pair<const char*, Axis> axes[] = { { "x", Axis::X }, { "y", Axis::Y },
    { "z", Axis::Z } };
  for (const auto& [suffix, axis] : axes)
  {
    const Axis ax = axis;
    L[std::string("hfcylinder") + suffix] =
      centred(1, [=](const Vec3& c, const Scalars& v) { return frep::cylinder(ax, c, v[0]); });
    L[std::string("hfellcyl") + suffix] = centred(2,
      [=](const Vec3& c, const Scalars& v) { return frep::ellipticCylinder(ax, c, v[0], v[1]); });
    L[std::string("hfcone") + suffix] =
      centred(1, [=](const Vec3& c, const Scalars& v) { return frep::cone(ax, c, v[0]); });
    L[std::string("hfellcone") + suffix] = centred(
      2, [=](const Vec3& c, const Scalars& v) { return frep::ellipticCone(ax, c, v[0], v[1]); });
    L[std::string("hftorus") + suffix] =
      centred(2, [=](const Vec3& c, const Scalars& v) { return frep::torus(ax, c, v[0], v[1]); });
    L[std::string("hfrotate3d") + suffix] = [=](Frame& f, const ExprNode& n)
    {
      args(n, 2);
      const double theta = number(f, n, 1);
      return spaceMap(f, n, [&](const Shape& s) { return frep::rotate(s, ax, theta); });
    };
    L[std::string("hftwist") + suffix] = [=](Frame& f, const ExprNode& n)
    {
      args(n, 5);
      const double z1 = number(f, n, 1), z2 = number(f, n, 2), t1 = number(f, n, 3),
                   t2 = number(f, n, 4);
      return spaceMap(f, n, [&](const Shape& s) { return frep::twist(s, ax, z1, z2, t1, t2); });
    };
    L[std::string("hftaper") + suffix] = [=](Frame& f, const ExprNode& n)
    {
      args(n, 5);
      const double z1 = number(f, n, 1), z2 = number(f, n, 2), s1 = number(f, n, 3),
                   s2 = number(f, n, 4);
      return spaceMap(f, n, [&](const Shape& s) { return frep::taper(s, ax, z1, z2, s1, s2); });
    };
  }
  // hfBlobby(x, x0, y0, z0, a, b, T), hfMetaBall(x, x0, y0, z0, b, d, T), hfSoft(x, x0, y0, z0,
  // d, T): centres given as three coordinate arrays.
  auto centres = [this](Frame& f, const ExprNode& n, std::size_t& count)
  {
    const auto xs = constants(f, n, 1);
    const auto ys = constants(f, n, 2);
    const auto zs = constants(f, n, 3);
    count = std::min(xs.size(), std::min(ys.size(), zs.size()));
    std::vector<Vec3> c(count);
    for (std::size_t i = 0; i < count; ++i)
    {
      c[i] = { xs[i], ys[i], zs[i] };
    }
    return c;
  };
  L["hfblobby"] = [=](Frame& f, const ExprNode& n)
  {
    args(n, 7);
    const auto m = coordinates(f, n, 0);
    std::size_t k = 0;
    const auto c = centres(f, n, k);
    const auto a = firstN(f, n, 4, k), b = firstN(f, n, 5, k);
    const double T = number(f, n, 6);
    return place(kernel(n, [&] { return frep::blobby(c, a, b, T).function(); }), m, n);
  };
  L["hfmetaball"] = [=](Frame& f, const ExprNode& n)
  {
    args(n, 7);
    const auto m = coordinates(f, n, 0);
    std::size_t k = 0;
    const auto c = centres(f, n, k);
    const auto b = firstN(f, n, 4, k), d = firstN(f, n, 5, k);
    const double T = number(f, n, 6);
    return place(kernel(n, [&] { return frep::metaball(c, b, d, T).function(); }), m, n);
  };
  L["hfsoft"] = [=](Frame& f, const ExprNode& n)
  {
    args(n, 6);
    const auto m = coordinates(f, n, 0);
    std::size_t k = 0;
    const auto c = centres(f, n, k);
    const auto d = firstN(f, n, 4, k);
    const double T = number(f, n, 5);
    return place(kernel(n, [&] { return frep::softObject(c, d, T).function(); }), m, n);
  };
  L["hfconvpoint"] = [=](Frame& f, const ExprNode& n)
  {
    args(n, 4);
    const auto m = coordinates(f, n, 0);
    const auto s = constants(f, n, 2);
    const auto pts = points(f, n, 1, s.size());
    const double T = number(f, n, 3);
    return place(kernel(n, [&] { return frep::convolutionPoints(pts, s, T).function(); }), m, n);
  };
  L["hfconvline"] = [=](Frame& f, const ExprNode& n)
  {
    args(n, 5);
    const auto m = coordinates(f, n, 0);
    const auto s = constants(f, n, 3);
    const auto b = points(f, n, 1, s.size());
    const auto e = points(f, n, 2, s.size());
    const double T = number(f, n, 4);
    std::vector<std::array<Vec3, 2>> segs(s.size());
    for (std::size_t i = 0; i < s.size(); ++i)
    {
      segs[i] = { b[i], e[i] };
    }
    return place(kernel(n, [&] { return frep::convolutionSegments(segs, s, T).function(); }), m, n);
  };
  L["hfconvliner"] = [=](Frame& f, const ExprNode& n)
  {
    // hfConvLineR(x, begin, end, R): the end array sets the number of segments.
    args(n, 4);
    const auto m = coordinates(f, n, 0);
    const std::size_t k = constants(f, n, 2).size() / 3;
    const auto b = points(f, n, 1, k);
    const auto e = points(f, n, 2, k);
    const double R = number(f, n, 3);
    std::vector<std::array<Vec3, 2>> segs(k);
    for (std::size_t i = 0; i < k; ++i)
    {
      segs[i] = { b[i], e[i] };
    }
    return place(
      kernel(n, [&] { return frep::convolutionSegmentsRadius(segs, R).function(); }), m, n);
  };
  L["hfconvarc"] = [=](Frame& f, const ExprNode& n)
  {
    // hfConvArc(x, center, radius, theta, axis, angle, S, T); its field is integrated over the
    // angle, i.e. ICTK's arc-length field divided by the radius (Primitives.h).
    args(n, 8);
    const auto m = coordinates(f, n, 0);
    const auto s = constants(f, n, 6);
    const std::size_t k = s.size();
    const auto c = points(f, n, 1, k);
    const auto r = firstN(f, n, 2, k), th = firstN(f, n, 3, k);
    const auto ax = points(f, n, 4, k);
    const auto an = firstN(f, n, 5, k);
    const double T = number(f, n, 7);
    const Expr sum = kernel(n,
      [&]
      {
        Expr acc;
        for (std::size_t i = 0; i < k; ++i)
        {
          const Expr term = frep::cauchyArcField(c[i], r[i], th[i], ax[i], an[i], s[i]) / r[i];
          acc = i == 0 ? term : acc + term;
        }
        return acc - T;
      });
    return place(sum, m, n);
  };
  L["hfconvtriangle"] = [=](Frame& f, const ExprNode& n)
  {
    // hfConvTriangle returns s^3 times the area integral (Primitives.h).
    args(n, 4);
    const auto m = coordinates(f, n, 0);
    const auto s = constants(f, n, 2);
    const auto v = points(f, n, 1, 3 * s.size());
    const double T = number(f, n, 3);
    const Expr sum = kernel(n,
      [&]
      {
        Expr acc;
        for (std::size_t i = 0; i < s.size(); ++i)
        {
          const Expr term = (s[i] * s[i] * s[i]) *
            frep::cauchyTriangleField({ v[3 * i], v[3 * i + 1], v[3 * i + 2] }, s[i]);
          acc = i == 0 ? term : acc + term;
        }
        return acc - T;
      });
    return place(sum, m, n);
  };
  L["hfconvcurve"] = [=](Frame& f, const ExprNode& n)
  {
    args(n, 4);
    const auto m = coordinates(f, n, 0);
    const auto all = constants(f, n, 1);
    const auto pts = points(f, n, 1, all.size() / 3);
    const double s = firstN(f, n, 2, 1)[0];
    const double T = number(f, n, 3);
    return place(kernel(n, [&] { return frep::convolutionCurve(pts, s, T).function(); }), m, n);
  };
  L["hfconvmesh"] = [=](Frame& f, const ExprNode& n)
  {
    args(n, 5);
    const auto m = coordinates(f, n, 0);
    const auto all = constants(f, n, 1);
    const auto verts = points(f, n, 1, all.size() / 3);
    const auto idx = constants(f, n, 2);
    std::vector<std::array<int, 3>> tris(idx.size() / 3);
    for (std::size_t i = 0; i < tris.size(); ++i)
    {
      for (std::size_t j = 0; j < 3; ++j)
      {
        const double d = idx[3 * i + j];
        // hfConvMesh's indices are 1-based.
        tris[i][j] = std::isfinite(d) && std::fabs(d) < 1e9 ? hfRound(d) - 1 : -1;
      }
    }
    const double s = firstN(f, n, 3, 1)[0];
    const double T = number(f, n, 4);
    return place(
      kernel(n, [&] { return frep::convolutionMesh(verts, tris, s, T).function(); }), m, n);
  };
  L["hfnoiseg"] = [=](Frame& f, const ExprNode& n)
  {
    args(n, 4);
    const auto m = coordinates(f, n, 0);
    const double a = number(f, n, 1), w = number(f, n, 2), ph = number(f, n, 3);
    return place(kernel(n, [&] { return frep::gardnerNoise(a, w, ph); }), m, n);
  };
  auto blend = [=](bool unionBlend)
  {
    return [=](Frame& f, const ExprNode& n)
    {
      // hfBlendUni/Int(f1, f2, a0, a1, a2): Operations.h blendUnion / blendIntersection.
      args(n, 5);
      const Expr f1 = eval(f, n.kids[0]).e;
      const Expr f2 = eval(f, n.kids[1]).e;
      const Expr a0 = eval(f, n.kids[2]).e;
      const Expr a1 = eval(f, n.kids[3]).e;
      const Expr a2 = eval(f, n.kids[4]).e;
      for (const Expr* a : { &a1, &a2 })
      {
        if (a->isConstant() && a->constantValue() == 0)
        {
          fail(n.line, n.column, n.spelling + ": a1 and a2 must be non-zero");
        }
      }
      count(16, n);
      const Expr base = unionBlend ? rUnion(f1, f2) : rIntersection(f1, f2);
      return plain(base + a0 / (1.0 + frep::square(f1 / a1) + frep::square(f2 / a2)));
    };
  };
  L["hfblenduni"] = blend(true);
  L["hfblendint"] = blend(false);
  L["hfshift3d"] = [=](Frame& f, const ExprNode& n)
  {
    args(n, 4);
    const Vec3 v = { number(f, n, 1), number(f, n, 2), number(f, n, 3) };
    return spaceMap(f, n, [&](const Shape& s) { return frep::shift(s, v); });
  };
  L["hfscale3d"] = [=](Frame& f, const ExprNode& n)
  {
    args(n, 4);
    const Vec3 v = { number(f, n, 1), number(f, n, 2), number(f, n, 3) };
    return spaceMap(f, n, [&](const Shape& s) { return frep::scale(s, v); });
  };
  L["hfstretch3d"] = [=](Frame& f, const ExprNode& n)
  {
    args(n, 5);
    const Vec3 c = vec3(f, n, 1);
    const Vec3 v = { number(f, n, 2), number(f, n, 3), number(f, n, 4) };
    return spaceMap(f, n, [&](const Shape& s) { return frep::stretch(s, c, v); });
  };
  // hfSpaceMapCubic/Exp(xt, source, target, b) (int_global.c): the number of control points is
  // set by the source array (3 items each); target and b are read for as many.
  auto controlPoints = [=](bool cubic)
  {
    return [=](Frame& f, const ExprNode& n)
    {
      args(n, 4);
      const auto all = constants(f, n, 1);
      if (all.size() % 3 != 0)
      {
        const ExprNode& an = node(n.kids[1]);
        fail(an.line, an.column,
          "argument 2 of " + n.spelling + " must have 3 items per control point, it has " +
            std::to_string(all.size()));
      }
      const std::size_t k = all.size() / 3;
      const auto src = points(f, n, 1, k);
      const auto dst = points(f, n, 2, k);
      const auto b = points(f, n, 3, k);
      return spaceMap(f, n,
        [&](const Shape& s) {
          return cubic ? frep::spaceMapCubic(s, src, dst, b) : frep::spaceMapExp(s, src, dst, b);
        });
    };
  };
  L["hfspacemapcubic"] = controlPoints(true);
  L["hfspacemapexp"] = controlPoints(false);
  // Attributes: hfA_SetColor(f, s, r, g, b) and hfA_SetAttributes(f, s, s1) write into s where
  // f >= 0 (hfA_SetColor.c, hfA_SetAttributes.c).
  L["hfa_setcolor"] = [=](Frame& f, const ExprNode& n)
  {
    args(n, 5);
    const Expr field = eval(f, n.kids[0]).e;
    arrayArgument(f, n.kids[1], n.spelling, 2);
    Var& s = lookup(f, node(n.kids[1]));
    if (s.items.size() < 3)
    {
      fail(n.line, n.column, n.spelling + ": the attribute array must have 3 items");
    }
    const Expr rgb[3] = { eval(f, n.kids[2]).e, eval(f, n.kids[3]).e, eval(f, n.kids[4]).e };
    count(3, n);
    for (std::size_t i = 0; i < 3; ++i)
    {
      s.items[i] = frep::select(field, rgb[i], s.items[i]);
    }
    return plain(Expr(1.0));
  };
  L["hfa_setattributes"] = [=](Frame& f, const ExprNode& n)
  {
    args(n, 3);
    const Expr field = eval(f, n.kids[0]).e;
    arrayArgument(f, n.kids[1], n.spelling, 2);
    const std::vector<Expr> src = arrayArgument(f, n.kids[2], n.spelling, 3);
    Var& s = lookup(f, node(n.kids[1]));
    count(src.size(), n);
    for (std::size_t i = 0; i < s.items.size() && i < src.size(); ++i)
    {
      s.items[i] = frep::select(field, src[i], s.items[i]);
    }
    return plain(Expr(1.0));
  };
  return library_;
}

HyperFunModel Compiler::run(const std::string& function)
{
  HyperFunModel out{ {}, 0, frep::Hypervolume(Shape(Expr(-1.0), frep::Domain::XYZ)) };
  if (p_.functions.empty())
  {
    sink_.error(1, 1, "no function is defined (expected 'my_model(x[3], a[1]) { ... }')");
    return out;
  }
  const Function* model = &p_.functions.back();
  if (!function.empty())
  {
    std::string wanted = function;
    for (char& c : wanted)
    {
      c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    }
    model = nullptr;
    for (const Function& g : p_.functions)
    {
      if (g.name == wanted)
      {
        model = &g;
      }
    }
    if (!model)
    {
      sink_.error(1, 1, "no function named '" + function + "' in the file");
      return out;
    }
  }
  const int dim = model->params[0].size;
  static const frep::Domain domains[] = { frep::Domain::X, frep::Domain::XY, frep::Domain::XYZ,
    frep::Domain::XYZT };
  if (dim < 1 || dim > 4)
  {
    sink_.error(model->params[0].line, model->params[0].column,
      "the coordinate array of the model must have 1 to 4 items (x, y, z, t), not " +
        std::to_string(dim));
    return out;
  }
  Frame f;
  f.fn = model;
  {
    Var x;
    x.isArray = true;
    for (int i = 0; i < dim; ++i)
    {
      x.items.push_back(Expr::variable(static_cast<Axis>(i)));
    }
    x.set.assign(x.items.size(), 1);
    f.vars[model->params[0].name] = std::move(x);
  }
  if (model->params.size() >= 2)
  {
    Var a;
    a.isArray = true;
    // With values given, the parameters are constants: the model is specialised, and parameters
    // may then stand where HyperFun's library needs numbers (a radius, a centre).
    const bool specialise = !parameterValues_.empty();
    if (specialise && parameterValues_.size() < static_cast<std::size_t>(model->params[1].size))
    {
      sink_.error(model->params[1].line, model->params[1].column,
        "the model has " + std::to_string(model->params[1].size) + " parameter(s) but " +
          std::to_string(parameterValues_.size()) + " value(s) were given");
      return out;
    }
    for (int i = 0; i < model->params[1].size; ++i)
    {
      a.items.push_back(specialise ? Expr(parameterValues_[static_cast<std::size_t>(i)])
                                   : Expr::parameter(static_cast<std::uint32_t>(i)));
    }
    a.set.assign(a.items.size(), 1);
    f.vars[model->params[1].name] = std::move(a);
    out.parameterCount = model->params[1].size;
  }
  if (model->params.size() >= 3)
  {
    Var s;
    s.isArray = true;
    s.items.assign(static_cast<std::size_t>(model->params[2].size), Expr(0.0));
    s.set.assign(s.items.size(), 1);
    f.vars[model->params[2].name] = std::move(s);
  }
  try
  {
    callStack_.push_back(model);
    execute(f, model->body);
    if (!sink_.empty())
    {
      return out;
    }
    if (!f.returned && f.pending.empty())
    {
      sink_.error(model->endLine, model->endColumn,
        "the model '" + model->spelling + "' never assigns its result ('" + model->spelling +
          " = ...;')");
      return out;
    }
    if (!f.returned)
    {
      sink_.error(model->endLine, model->endColumn,
        "the model '" + model->spelling + "' does not assign its result on every path");
      return out;
    }
    ExprNode at;
    at.line = model->endLine;
    at.column = model->endColumn;
    std::vector<Expr> s;
    const Expr value = finish(f, s, at);
    out.name = model->spelling;
    out.model = frep::Hypervolume(Shape(value, domains[dim - 1], model->spelling));
    if (s.size() >= 3)
    {
      frep::Attribute colour;
      colour.name = "colour";
      colour.components.assign(s.begin(), s.begin() + 3);
      out.model.addAttribute(colour);
    }
  }
  catch (const Fatal&)
  {
  }
  catch (const CompileError& e)
  {
    sink_.error(e.line, e.column, e.message);
  }
  catch (const std::exception& e)
  {
    sink_.error(model->line, model->column, std::string("cannot build the model: ") + e.what());
  }
  return out;
}

} // namespace

HyperFunModel compile(const Program& program, DiagnosticSink& sink, const std::string& function,
  const Limits& limits, const std::vector<double>& parameterValues)
{
  Compiler c(program, sink, limits, parameterValues);
  return c.run(function);
}

} // namespace ictk::lang::hf
