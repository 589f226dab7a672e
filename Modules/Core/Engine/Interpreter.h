// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The interpreter of the model language's imperative core (docs/icm.md "The imperative core"):
// reactions, predicates and functions run over typed values. Names, members and the reaction
// library are resolved through a Scope the engine implements, so the interpreter knows nothing of
// cells or instances. Every loop is bounded and every call goes to a built-in or to a function
// defined earlier, so all code ends; errors are ModelError with the file, line and column.

#include "Geometry/PlacedShape.h"
#include "Lang/IcmAst.h"
#include "Lang/IcmBuiltins.h"

#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace ictk::engine
{

/// An error found while building or running a model, with its place in the model text.
class ModelError : public std::runtime_error
{
public:
  ModelError(const std::string& file, lang::icm::Pos pos, const std::string& message);
  std::string file;
  lang::icm::Pos pos;
  std::string message; ///< without the place
};

struct Value
{
  enum class Type
  {
    None,
    Real,
    Int,
    Bool,
    Vec3,
    String,
    Shape, ///< shape parts in local coordinates (segment(...), arc(...))
    Cell,  ///< a reference to a cell (text = its name)
    Event, ///< an event with its parameters (react's argument)
    /// An `array of TRANSFORM`: the skinning matrices of a skeleton's joints (jointTransforms).
    Transforms
  };
  Type type = Type::None;
  double number = 0.0;
  geometry::Vec3 vec{ 0, 0, 0 };
  std::string text;
  std::shared_ptr<const std::vector<geometry::ShapePart>> shape;
  std::map<std::string, double> fields;                            ///< Event parameters
  std::shared_ptr<const std::vector<geometry::Affine>> transforms; ///< Transforms

  static Value real(double v);
  static Value integer(double v);
  static Value boolean(bool v);
  static Value vector(const geometry::Vec3& v);
  static Value string(std::string s);
  static Value cell(std::string name);
  static Value transformArray(std::vector<geometry::Affine> matrices);
  bool isNumber() const { return type == Type::Real || type == Type::Int; }
  /// For traces: 1.5, 3, true, [1, 2, 3], "text".
  std::string toJson() const;
};

const char* typeName(Value::Type t);

/// What code can see; implemented by the engine.
class Scope
{
public:
  virtual ~Scope() = default;
  /// A bare name that is not a local or argument (a parameter, a cell, a constant). Nothing when
  /// unknown.
  virtual bool lookup(const std::string& name, Value& out) = 0;
  /// `base.member` where base is a cell reference (Cell.param, Cell.translation).
  virtual bool member(const Value& base, const std::string& member, Value& out) = 0;
  /// Assigns to a bare name or to Cell.member (member empty for a bare name); false = unknown.
  virtual bool assign(const std::string& name, const std::string& member, const Value& v) = 0;
  /// A built-in of the Library layer (Lang/IcmBuiltins.h: geometry between cells, events,
  /// animation curves, shapes of T-cells, setShapeParameter), which the interpreter does not
  /// compute itself. Throws std::runtime_error on bad arguments (the interpreter adds the place).
  virtual Value call(const lang::icm::Builtin& builtin, const std::vector<Value>& args) = 0;
};

class Interpreter
{
public:
  /// `functions` are the model's functions (callable from any code).
  Interpreter(std::string fileName, const std::vector<lang::icm::Procedure>* functions);

  /// Runs a procedure with its formals bound to `args` (missing ones are None); returns the value
  /// of `return` (None without).
  Value run(const lang::icm::Procedure& p, const std::vector<Value>& args, Scope& scope) const;
  /// Evaluates an expression outside code (parameter initial values, shape constructors' args).
  Value evaluate(const lang::icm::Expr& e, Scope& scope) const;

  /// Loop iterations allowed in one run (all loops together).
  static constexpr long long maxIterations = 10'000'000;

private:
  struct Frame;
  Value eval(const lang::icm::Expr& e, Frame& f) const;
  bool exec(const std::vector<lang::icm::StmtPtr>& body, Frame& f) const;
  bool exec(const lang::icm::Stmt& s, Frame& f) const;
  void assign(const lang::icm::Expr& target, const std::string& op, Value v, Frame& f) const;
  Value callFunction(const lang::icm::Expr& call, std::vector<Value> args, Frame& f) const;
  [[noreturn]] void fail(lang::icm::Pos pos, const std::string& message) const;

  std::string file_;
  const std::vector<lang::icm::Procedure>* functions_;
};

} // namespace ictk::engine
