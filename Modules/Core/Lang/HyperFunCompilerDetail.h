// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Internal to the Lang library: the HyperFun compiler (HyperFunCompiler.h) shared by its two
// files: HyperFunCompiler.cxx (values, expressions, user calls, statements, the model's entry
// point) and HyperFunLibrary.cxx (the built-in math functions and the hf* library table). Not
// installed (PRIVATE_HEADERS in CMakeLists.txt): its declarations may change freely.

#include "Lang/HyperFunCompiler.h"

#include "FRep/Domain.h"
#include "FRep/Expr.h"
#include "FRep/Primitives.h"

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

namespace ictk::lang::hf::detail
{

using frep::Axis;
using frep::Expr;
using frep::Shape;

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

inline std::string fmt(double v)
{
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

inline int hfRound(double d)
{
  // HF_round (int_parse_N.c): nearest, halves upwards.
  const double c = std::ceil(d);
  return static_cast<int>((c - d > 0.5) ? (c - 1) : c);
}

/// Compiles one program (one per compile() call): symbolic interpretation of the syntax tree.
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

  [[noreturn]] void fail(int line, int column, const std::string& message);
  void report(const CompileError& e);
  void count(std::size_t n, const ExprNode& at);

  const ExprNode& node(int i) const { return p_.exprs[static_cast<std::size_t>(i)]; }
  const Statement& stmt(int i) const { return p_.statements[static_cast<std::size_t>(i)]; }

  // --- values --------------------------------------------------------------------------------
  static Val plain(Expr e);
  static Val boolean(Expr margin, bool negated);
  /// 1 where the value is true, 0 elsewhere.
  static Expr truth(const Val& v);
  static std::pair<Expr, bool> condition(const Val& v);
  static Expr choose(const std::pair<Expr, bool>& c, const Expr& ifTrue, const Expr& ifFalse);
  std::string dependsOn(const Expr& e) const;
  double constant(const Val& v, const ExprNode& at, const std::string& what);

  // --- expressions ---------------------------------------------------------------------------
  Var& lookup(Frame& f, const ExprNode& n);
  int indexOf(Frame& f, int indexExpr, const Var& v, const std::string& spelling);
  const std::vector<Expr>& arrayArgument(Frame& f, int arg, const std::string& fn, int position);
  Val eval(Frame& f, int index);
  static Expr rUnion(const Expr& a, const Expr& b);
  static Expr rIntersection(const Expr& a, const Expr& b);
  Val binary(TokenKind op, const Val& a, const Val& b, const ExprNode& at);
  Val power(const Expr& base, const Expr& exponent, const ExprNode& at);

  // --- calls ---------------------------------------------------------------------------------
  void arity(const ExprNode& n, std::size_t expected);
  Val call(Frame& f, const ExprNode& n);
  /// A built-in math function (HyperFunLibrary.cxx), or nothing when `n` names none.
  std::optional<Val> mathFunction(Frame& f, const ExprNode& n);
  Val callUser(Frame& caller, const ExprNode& n, const Function& g);
  /// The function's value and s array, folding the returns taken on some paths only.
  Expr finish(Frame& f, std::vector<Expr>& s, const ExprNode& at);

  // --- library (HyperFunLibrary.cxx) -------------------------------------------------------
  using Handler = std::function<Val(Frame&, const ExprNode&)>;
  const std::unordered_map<std::string, Handler>& library();
  std::unordered_map<std::string, Handler> library_;
  std::vector<double> constants(Frame& f, const ExprNode& n, std::size_t k);
  double number(Frame& f, const ExprNode& n, std::size_t k);
  frep::Vec3 vec3(Frame& f, const ExprNode& n, std::size_t k);
  /// The substitution that evaluates a kernel shape at the (mapped) coordinates of array k.
  std::array<Expr, frep::AxisCount> coordinates(Frame& f, const ExprNode& n, std::size_t k);
  Val place(const Expr& e, const std::array<Expr, frep::AxisCount>& map, const ExprNode& n);
  /// Runs a kernel constructor, turning its std::invalid_argument into a diagnostic.
  template <typename Build>
  Expr kernel(const ExprNode& n, Build build);
  std::vector<frep::Vec3> points(Frame& f, const ExprNode& n, std::size_t k, std::size_t count3);
  std::vector<double> firstN(Frame& f, const ExprNode& n, std::size_t k, std::size_t count);
  /// Applies a space map in place to the coordinate array argument 0: item i becomes the map's
  /// component i (got by mapping the probe shape "coordinate i") evaluated at the old items.
  Val spaceMap(Frame& f, const ExprNode& n, const std::function<Shape(const Shape&)>& op);

  // --- statements ----------------------------------------------------------------------------
  void execute(Frame& f, const std::vector<int>& body);
  void assignScalar(Frame& f, const Statement& s, const Val& v);
  /// The array an item or list assignment `s` writes into; an error when it is none, whose hint
  /// declares it with `size` items.
  Var& declaredArray(Frame& f, const Statement& s, const std::string& size);
  void executeOne(Frame& f, const Statement& s);
  void executeIf(Frame& f, const Statement& s);
  void executeWhile(Frame& f, const Statement& s);
};

} // namespace ictk::lang::hf::detail
