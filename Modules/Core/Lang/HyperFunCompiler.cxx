// SPDX-License-Identifier: BSD-3-Clause
// HyperFun -> FRep DAG: values, expressions, calls of the model's own functions, statements and
// the model's entry point; the built-in math functions and the hf* library are in
// HyperFunLibrary.cxx (both share the Compiler of HyperFunCompilerDetail.h). The semantics follow
// HyperFun's interpreter (pmur002/hyperfun, files src/interpreter_lib/int_calc.c, int_global.c,
// int_parse_N.c, int_scanner.c and the library in src/hflibrary_lib):
//  - '|' '&' '\' '@' are the alpha-system R-functions with HyperFun's default ALPHA = 0
//    (int_global.c): f1 + f2 +- sqrt(f1^2 + f2^2); '\' is f1 & -f2 and '@' is '&' (HyperFun
//    evaluates every operand in the same x space, so the product is an intersection). '~' is -f.
//  - Truth: a value is true when |v| >= EPS = 1e-6; comparisons give 1 or 0, '=' and '/=' compare
//    with the same EPS; and/or/xor/not work on truth values (int_calc.c FUNC_bool_*).
//  - '^': an exponent within EPS above an integer is that integer (repeated product, reciprocal
//    for a negative one); otherwise a real power (int_calc.c FUNC_binary_power).
//  - Assigning to the function's own name returns from it (CODE_body_assignment).
// Where ICTK differs it says so: a division by zero is an error only when the divisor is a
// compile-time constant.
#include "Lang/HyperFunCompilerDetail.h"

#include "FRep/Operations.h"
#include "FRep/Primitives.h"

#include <algorithm>
#include <cmath>
#include <iterator>

namespace ictk::lang::hf
{
namespace detail
{

void Compiler::fail(int line, int column, const std::string& message)
{
  throw CompileError{ line, column, message };
}

void Compiler::report(const CompileError& e)
{
  if (!sink_.error(e.line, e.column, e.message))
  {
    throw Fatal{};
  }
}

void Compiler::count(std::size_t n, const ExprNode& at)
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

Val Compiler::plain(Expr e)
{
  Val v;
  v.e = std::move(e);
  return v;
}

Val Compiler::boolean(Expr margin, bool negated)
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

Expr Compiler::truth(const Val& v)
{
  if (v.isBool)
  {
    return v.e;
  }
  return frep::select(frep::abs(v.e) - Eps, Expr(1.0), Expr(0.0));
}

std::pair<Expr, bool> Compiler::condition(const Val& v)
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

Expr Compiler::choose(const std::pair<Expr, bool>& c, const Expr& ifTrue, const Expr& ifFalse)
{
  return c.second ? frep::select(c.first, ifFalse, ifTrue) : frep::select(c.first, ifTrue, ifFalse);
}

std::string Compiler::dependsOn(const Expr& e) const
{
  if (e.axesUsed() != 0)
  {
    return "the coordinates";
  }
  return "model parameters, which are not known at compile time (give their values when reading "
         "the model, e.g. `ictk ... --params`, to specialise it)";
}

double Compiler::constant(const Val& v, const ExprNode& at, const std::string& what)
{
  if (!v.e.isConstant())
  {
    fail(at.line, at.column,
      what + " must be known at compile time, but it depends on " + dependsOn(v.e));
  }
  return v.e.constantValue();
}

Var& Compiler::lookup(Frame& f, const ExprNode& n)
{
  auto it = f.vars.find(n.name);
  if (it == f.vars.end())
  {
    fail(n.line, n.column, "unknown variable '" + n.spelling + "'");
  }
  return it->second;
}

int Compiler::indexOf(Frame& f, int indexExpr, const Var& v, const std::string& spelling)
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

const std::vector<Expr>& Compiler::arrayArgument(
  Frame& f, int arg, const std::string& fn, int position)
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

Val Compiler::eval(Frame& f, int index)
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

Expr Compiler::rUnion(const Expr& a, const Expr& b)
{
  // = frep::unite(alpha 0), HyperFun FUNC_binary_union with ALPHA = 0.
  return frep::rUnion(a, b);
}

Expr Compiler::rIntersection(const Expr& a, const Expr& b)
{
  return frep::rIntersection(a, b);
}

Val Compiler::binary(TokenKind op, const Val& a, const Val& b, const ExprNode& at)
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

Val Compiler::power(const Expr& base, const Expr& exponent, const ExprNode& at)
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

void Compiler::arity(const ExprNode& n, std::size_t expected)
{
  if (n.kids.size() != expected)
  {
    fail(n.line, n.column,
      n.spelling + " takes " + std::to_string(expected) + " argument" + (expected == 1 ? "" : "s") +
        ", got " + std::to_string(n.kids.size()));
  }
}

Val Compiler::call(Frame& f, const ExprNode& n)
{
  if (const auto math = mathFunction(f, n))
  {
    return *math;
  }
  const auto lib = library().find(n.name);
  if (lib != library().end())
  {
    // ICTK's own library functions (docs/hyperfun.md), which HyperFun's interpreter lacks.
    static const char* const ictkOwn[] = { "hfpin", "hfscrew", "hfplate", "hfgyroid",
      "hfspacetimeblend" };
    if (limits_.strictHyperFun &&
      std::find(std::begin(ictkOwn), std::end(ictkOwn), n.name) != std::end(ictkOwn))
    {
      fail(n.line, n.column,
        "'" + n.spelling + "' is ICTK's own, not in HyperFun's library (refused by --strict)");
    }
    return lib->second(f, n);
  }
  for (const Function& g : p_.functions)
  {
    if (g.name == n.name)
    {
      // HyperFun calls only the functions defined before the caller in the file.
      if (limits_.strictHyperFun && f.fn && &g > f.fn)
      {
        fail(n.line, n.column,
          "'" + g.spelling + "' is defined after '" + f.fn->spelling +
            "': HyperFun calls only functions defined before the caller (refused by --strict)");
      }
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

Val Compiler::callUser(Frame& caller, const ExprNode& n, const Function& g)
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

Expr Compiler::finish(Frame& f, std::vector<Expr>& s, const ExprNode& at)
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

void Compiler::execute(Frame& f, const std::vector<int>& body)
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

void Compiler::assignScalar(Frame& f, const Statement& s, const Val& v)
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

Var& Compiler::declaredArray(Frame& f, const Statement& s, const std::string& size)
{
  auto it = f.vars.find(s.name);
  if (it == f.vars.end() || !it->second.isArray)
  {
    fail(s.line, s.column,
      "'" + s.spelling + "' is not a declared array (declare it with 'array " + s.spelling + "[" +
        size + "];')");
  }
  return it->second;
}

void Compiler::executeOne(Frame& f, const Statement& s)
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
      const int i = indexOf(f, s.index, declaredArray(f, s, "n"), s.spelling);
      const Val v = eval(f, s.expr);
      Var& target = f.vars[s.name];
      target.items[static_cast<std::size_t>(i)] = v.e;
      target.set[static_cast<std::size_t>(i)] = 1;
      return;
    }
    case Statement::Kind::AssignList:
    {
      const Var& array = declaredArray(f, s, std::to_string(s.list.size()));
      if (s.list.size() != array.items.size())
      {
        fail(s.line, s.column,
          "wrong number of items for '" + s.spelling + "': " + std::to_string(s.list.size()) +
            " given, the array has " + std::to_string(array.items.size()));
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

void Compiler::executeIf(Frame& f, const Statement& s)
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

void Compiler::executeWhile(Frame& f, const Statement& s)
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

HyperFunModel Compiler::run(const std::string& function)
{
  HyperFunModel out{ {}, 0, frep::Hypervolume(Shape(Expr(-1.0), frep::Domain::XYZ)) };
  if (p_.functions.empty())
  {
    sink_.error(1, 1, "no function is defined (expected 'my_model(x[3], a[1]) { ... }')");
    return out;
  }
  // HyperFun's own interpreter (hfp's -o, default my_model) evaluates `my_model`, else the
  // file's first function.
  const Function* model = &p_.functions.front();
  for (const Function& g : p_.functions)
  {
    if (g.name == "my_model")
    {
      model = &g;
    }
  }
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

} // namespace detail

HyperFunModel compile(const Program& program, DiagnosticSink& sink, const std::string& function,
  const Limits& limits, const std::vector<double>& parameterValues)
{
  detail::Compiler c(program, sink, limits, parameterValues);
  return c.run(function);
}

} // namespace ictk::lang::hf
