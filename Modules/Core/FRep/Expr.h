// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The FRep expression DAG.
//
// An Expr is a handle to an immutable node. Nodes are hash-consed process-wide: building the same
// operation on the same children twice returns the same node, so equal sub-trees are one node and a
// model is a DAG, however it was written. Nodes are freed when the last handle goes away.

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace ictk::frep
{

/// Coordinate axes of the modelling space (thesis Table 1: x, y, z and explicit time t).
enum class Axis : std::uint8_t
{
  X = 0,
  Y = 1,
  Z = 2,
  T = 3
};
constexpr int AxisCount = 4;
const char* axisName(Axis a);

/// The operations of the DAG. Everything in the FRep library lowers to these, so that every
/// evaluator (point, batch, interval, gradient) supports every model.
enum class Opcode : std::uint8_t
{
  // leaves
  Constant,
  Variable,  ///< a coordinate (Axis)
  Parameter, ///< a model parameter read from a slot at evaluation time

  // unary
  Neg,
  Abs,
  Sqrt,
  Square,
  Exp,
  Log,
  Sin,
  Cos,
  Tan,
  Asin,
  Acos,
  Atan,
  Sign,  ///< -1, 0 or 1
  Floor, ///< the largest integer <= a

  // binary
  Add,
  Sub,
  Mul,
  Div,
  Min,
  Max,
  Pow,   ///< real power a^b (NaN for a < 0 and non-integer b, as std::pow)
  Atan2, ///< atan2(a, b)

  // ternary
  Select, ///< a >= 0 ? b : c
          /// The Cauchy kernel 1 / (1 + b + tau^2)^2 integrated over tau in [-a, c - a]: a segment
          /// of length c / s along a convolution skeleton, seen from a point at s^2 b squared
          /// distance from its line and at a / s along it from its start, gives this / s
          /// (Primitives.h cauchySegmentField). One opcode so that its interval bound is tight: it
          /// decreases in b, increases in c, and rises in a up to c / 2 and falls after, so the
          /// extremes over a box of operands are at known corners, where the sum of its terms
          /// bounds them far too loosely.
  CauchySegment,
  Count_
};

int opcodeArity(Opcode op);
const char* opcodeName(Opcode op);

class Node;

class Expr
{
public:
  /// The constant 0.
  Expr();
  /// A constant (implicit so that `2.0 * x` reads naturally).
  Expr(double value); // NOLINT(google-explicit-constructor)

  static Expr constant(double value);
  static Expr variable(Axis axis);
  static Expr x() { return variable(Axis::X); }
  static Expr y() { return variable(Axis::Y); }
  static Expr z() { return variable(Axis::Z); }
  static Expr t() { return variable(Axis::T); }
  /// A parameter slot. Its value is supplied at evaluation time (see Tape::parameterCount), so a
  /// model can change without being recompiled. Parameters are treated like constants by the
  /// evaluators (uniform across all points).
  static Expr parameter(std::uint32_t slot);

  /// Builds op(children...) through the hash-consing table, folding constants.
  static Expr make(Opcode op, const Expr& a);
  static Expr make(Opcode op, const Expr& a, const Expr& b);
  static Expr make(Opcode op, const Expr& a, const Expr& b, const Expr& c);

  Opcode opcode() const;
  int arity() const;
  const Expr& child(int i) const;
  /// The value of a Constant node.
  double constantValue() const;
  Axis axis() const;
  std::uint32_t parameterSlot() const;
  bool isConstant() const { return opcode() == Opcode::Constant; }
  bool isConstant(double v) const { return isConstant() && constantValue() == v; }

  /// Bit i is set when the expression depends on Axis(i).
  std::uint8_t axesUsed() const;
  /// Number of distinct nodes reachable from this one (the DAG size).
  std::size_t nodeCount() const;
  /// Identity of the node (equal sub-trees have equal ids thanks to hash-consing).
  const Node* id() const { return node_.get(); }
  bool identical(const Expr& other) const { return node_ == other.node_; }

  /// Replaces every Variable(a) by map[a] (space mappings, domain re-projection). Shared
  /// sub-trees are rewritten once.
  Expr substitute(const std::array<Expr, AxisCount>& map) const;

  /// Replaces every occurrence of the sub-tree `from` by `to` (thesis L2198, L2208-L2213: subtree
  /// replacement). The original expression is unchanged; shared parts are reused.
  Expr replace(const Expr& from, const Expr& to) const;

  /// Visits every distinct node once, children before parents.
  void visitPostOrder(const std::function<void(const Expr&)>& visit) const;

  /// Instrumentation: the expression nodes alive in the process. Nodes are shared by reference
  /// counting and a node is destroyed when the last Expr holding it goes (seed 003 item 39's
  /// AddRef/Release, as std::shared_ptr); a test sees a model's nodes go with it. Thread safe,
  /// linear in the number of nodes.
  static std::size_t liveNodeCount();

private:
  explicit Expr(std::shared_ptr<const Node> n)
    : node_(std::move(n))
  {
  }
  friend class Node;
  std::shared_ptr<const Node> node_;
};

// Arithmetic (all fold constants and hash-cons).
Expr operator+(const Expr& a, const Expr& b);
Expr operator-(const Expr& a, const Expr& b);
Expr operator*(const Expr& a, const Expr& b);
Expr operator/(const Expr& a, const Expr& b);
Expr operator-(const Expr& a);
Expr min(const Expr& a, const Expr& b);
Expr max(const Expr& a, const Expr& b);
Expr abs(const Expr& a);
Expr sqrt(const Expr& a);
Expr square(const Expr& a);
Expr exp(const Expr& a);
Expr log(const Expr& a);
Expr sin(const Expr& a);
Expr cos(const Expr& a);
Expr tan(const Expr& a);
Expr asin(const Expr& a);
Expr acos(const Expr& a);
Expr atan(const Expr& a);
Expr atan2(const Expr& a, const Expr& b);
Expr sign(const Expr& a);
Expr floor(const Expr& a);
/// a^b. An integer constant exponent lowers to a product of squares (exact, and tight under
/// interval arithmetic); any other exponent becomes a Pow node.
Expr pow(const Expr& a, const Expr& b);
/// condition >= 0 ? ifTrue : ifFalse. A branch on coordinates stays a node, so interval and
/// batch evaluation keep working on models with branches.
Expr select(const Expr& condition, const Expr& ifTrue, const Expr& ifFalse);

/// Evaluates an expression directly on the DAG (slow, recursive, uncached): the reference that the
/// compiled evaluators are tested against. `params` gives the Parameter slots.
double evaluateReference(
  const Expr& e, const std::array<double, AxisCount>& p, const std::vector<double>& params = {});

/// A readable prefix form, e.g. "(sub (mul x x) 1)", for diagnostics and tests.
std::string toString(const Expr& e);

} // namespace ictk::frep
