// SPDX-License-Identifier: BSD-3-Clause
#include "Engine/Interpreter.h"

#include "Engine/Builtins.h"

#include "FRep/Vector.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

namespace ictk::engine
{

using geometry::Vec3;
using lang::icm::Expr;
using lang::icm::Pos;
using lang::icm::Procedure;
using lang::icm::Stmt;
using lang::icm::StmtPtr;

namespace
{

std::string where(const std::string& file, Pos pos)
{
  return file + ":" + std::to_string(pos.line) + ":" + std::to_string(pos.column);
}

std::string jsonNumber(double v)
{
  if (!std::isfinite(v))
    return "null"; // JSON has no inf/nan; traces mark them as null
  std::ostringstream s;
  s << std::setprecision(17) << v;
  return s.str();
}

std::string quoted(const std::string& text)
{
  std::string out = "\"";
  for (const char c : text)
  {
    if (c == '"' || c == '\\')
      out += '\\';
    if (static_cast<unsigned char>(c) < 0x20)
    {
      out += ' ';
      continue;
    }
    out += c;
  }
  return out + "\"";
}

int component(const std::string& m)
{
  if (m == "x" || m == "X")
    return 0;
  if (m == "y" || m == "Y")
    return 1;
  if (m == "z" || m == "Z")
    return 2;
  return -1;
}

} // namespace

ModelError::ModelError(const std::string& f, Pos p, const std::string& m)
  : std::runtime_error(where(f, p) + ": error: " + m)
  , file(f)
  , pos(p)
  , message(m)
{
}

Value Value::real(double v)
{
  Value r;
  r.type = Type::Real;
  r.number = v;
  return r;
}

Value Value::integer(double v)
{
  Value r;
  r.type = Type::Int;
  r.number = std::trunc(v);
  return r;
}

Value Value::boolean(bool v)
{
  Value r;
  r.type = Type::Bool;
  r.number = v ? 1.0 : 0.0;
  return r;
}

Value Value::vector(const Vec3& v)
{
  Value r;
  r.type = Type::Vec3;
  r.vec = v;
  return r;
}

Value Value::string(std::string s)
{
  Value r;
  r.type = Type::String;
  r.text = std::move(s);
  return r;
}

Value Value::cell(std::string name)
{
  Value r;
  r.type = Type::Cell;
  r.text = std::move(name);
  return r;
}

Value Value::transformArray(std::vector<geometry::Affine> matrices)
{
  Value r;
  r.type = Type::Transforms;
  r.transforms = std::make_shared<const std::vector<geometry::Affine>>(std::move(matrices));
  return r;
}

std::string Value::toJson() const
{
  switch (type)
  {
    case Type::Real:
    case Type::Int:
      return jsonNumber(number);
    case Type::Bool:
      return this->number != 0.0 ? "true" : "false";
    case Type::Vec3:
      return "[" + jsonNumber(vec[0]) + ", " + jsonNumber(vec[1]) + ", " + jsonNumber(vec[2]) + "]";
    case Type::String:
    case Type::Cell:
      return quoted(text);
    case Type::Shape:
      return quoted("shape");
    case Type::Event:
      return quoted("event");
    case Type::Transforms:
      return quoted(std::to_string(transforms ? transforms->size() : 0) + " transforms");
    case Type::None:
      break;
  }
  return "null";
}

const char* typeName(Value::Type t)
{
  switch (t)
  {
    case Value::Type::None:
      return "nothing";
    case Value::Type::Real:
      return "real";
    case Value::Type::Int:
      return "int";
    case Value::Type::Bool:
      return "bool";
    case Value::Type::Vec3:
      return "vec3";
    case Value::Type::String:
      return "string";
    case Value::Type::Shape:
      return "shape";
    case Value::Type::Cell:
      return "cell";
    case Value::Type::Event:
      return "event";
    case Value::Type::Transforms:
      return "array of TRANSFORM";
  }
  return "?";
}

struct Interpreter::Frame
{
  Scope& scope;
  std::map<std::string, Value> locals;
  long long iterations = 0;
  int depth = 0; ///< model-function calls (bounded: functions call only earlier ones)
  Value result;
};

Interpreter::Interpreter(std::string fileName, const std::vector<Procedure>* functions)
  : file_(std::move(fileName))
  , functions_(functions)
{
}

void Interpreter::fail(Pos pos, const std::string& message) const
{
  throw ModelError(file_, pos, message);
}

Value Interpreter::run(const Procedure& p, const std::vector<Value>& args, Scope& scope) const
{
  Frame f{ scope, {}, 0, 0, {} };
  for (std::size_t i = 0; i < p.formals.size(); ++i)
    f.locals[p.formals[i].name] = i < args.size() ? args[i] : Value{};
  exec(p.body, f);
  return f.result;
}

Value Interpreter::evaluate(const Expr& e, Scope& scope) const
{
  Frame f{ scope, {}, 0, 0, {} };
  return eval(e, f);
}

namespace
{

double asNumber(const Value& v, bool& ok)
{
  ok = v.isNumber() || v.type == Value::Type::Bool;
  return v.number;
}

} // namespace

Value Interpreter::eval(const Expr& e, Frame& f) const
{
  auto need = [&](const Value& v, Value::Type t, const Expr& at, const char* what)
  {
    if (v.type != t && !(t == Value::Type::Real && v.isNumber()))
      fail(at.pos, std::string(what) + " must be a " + typeName(t) + ", not a " + typeName(v.type));
  };
  switch (e.kind)
  {
    case Expr::Kind::Number:
    {
      const bool integral = e.text.find_first_of(".eE") == std::string::npos;
      return integral ? Value::integer(e.number) : Value::real(e.number);
    }
    case Expr::Kind::Bool:
      return Value::boolean(e.text == "true" || e.number != 0.0);
    case Expr::Kind::String:
      return Value::string(e.text);
    case Expr::Kind::CellType:
    case Expr::Kind::Dim:
      return Value::string(e.text);
    case Expr::Kind::Name:
    {
      if (auto it = f.locals.find(e.text); it != f.locals.end())
        return it->second;
      if (e.text == "pi")
        return Value::real(3.14159265358979323846);
      if (e.text == "true" || e.text == "false")
        return Value::boolean(e.text == "true");
      Value v;
      if (f.scope.lookup(e.text, v))
        return v;
      fail(e.pos, "unknown name '" + e.text + "'");
    }
    case Expr::Kind::Member:
    {
      const Value base = eval(*e.kids[0], f);
      if (base.type == Value::Type::Vec3)
      {
        const int c = component(e.text);
        if (c < 0)
          fail(e.pos, "a vec3 has the members x, y and z, not '" + e.text + "'");
        return Value::real(base.vec[c]);
      }
      if (base.type == Value::Type::Event)
      {
        auto it = base.fields.find(e.text);
        if (it == base.fields.end())
          fail(e.pos, "the event " + base.text + " has no parameter '" + e.text + "'");
        return Value::real(it->second);
      }
      Value v;
      try
      {
        if (f.scope.member(base, e.text, v))
          return v;
      }
      catch (const ModelError&)
      {
        throw;
      }
      catch (const std::exception& x)
      {
        fail(e.pos, x.what());
      }
      fail(e.pos,
        base.type == Value::Type::Cell
          ? "the cell " + base.text + " has no parameter or property '" + e.text + "'"
          : std::string("a ") + typeName(base.type) + " has no member '" + e.text + "'");
    }
    case Expr::Kind::Index:
      fail(e.pos,
        "indexed parameters (arrays) cannot be read in code; they only order "
        "dependencies");
    case Expr::Kind::Call:
    {
      std::vector<Value> args;
      for (std::size_t i = 1; i < e.kids.size(); ++i)
      {
        const Expr& a = *e.kids[i];
        // An event name is not a value: fireEvent's first argument is passed by name.
        if (i == 1 && lang::icm::calledName(e.text) == "fireEvent" && a.kind == Expr::Kind::Name &&
          !f.locals.count(a.text))
          args.push_back(Value::string(a.text));
        else
          args.push_back(eval(a, f));
      }
      return callFunction(e, std::move(args), f);
    }
    case Expr::Kind::Unary:
    {
      const Value v = eval(*e.kids[0], f);
      if (e.text == "!")
      {
        need(v, Value::Type::Bool, *e.kids[0], "the operand of '!'");
        return Value::boolean(v.number == 0.0);
      }
      if (v.type == Value::Type::Vec3)
        return Value::vector(e.text == "-" ? Vec3{ -v.vec[0], -v.vec[1], -v.vec[2] } : v.vec);
      if (!v.isNumber())
        fail(e.pos,
          std::string("'") + e.text + "' needs a number or a vec3, not a " + typeName(v.type));
      Value r = v;
      if (e.text == "-")
        r.number = -r.number;
      return r;
    }
    case Expr::Kind::Binary:
    {
      const std::string& op = e.text;
      if (op == "&&" || op == "||")
      {
        const Value a = eval(*e.kids[0], f);
        need(a, Value::Type::Bool, *e.kids[0], ("the left operand of '" + op + "'").c_str());
        if ((op == "&&") == (a.number == 0.0))
          return Value::boolean(op == "||");
        const Value b = eval(*e.kids[1], f);
        need(b, Value::Type::Bool, *e.kids[1], ("the right operand of '" + op + "'").c_str());
        return Value::boolean(b.number != 0.0);
      }
      const Value a = eval(*e.kids[0], f);
      const Value b = eval(*e.kids[1], f);
      if (op == "==" || op == "!=")
      {
        bool equal = false;
        if (a.type == Value::Type::Vec3 && b.type == Value::Type::Vec3)
          equal = a.vec == b.vec;
        else if ((a.isNumber() || a.type == Value::Type::Bool) &&
          (b.isNumber() || b.type == Value::Type::Bool) &&
          (a.type == Value::Type::Bool) == (b.type == Value::Type::Bool))
          equal = a.number == b.number;
        else if ((a.type == Value::Type::String || a.type == Value::Type::Cell) && a.type == b.type)
          equal = a.text == b.text;
        else
          fail(e.pos,
            std::string("cannot compare a ") + typeName(a.type) + " with a " + typeName(b.type));
        return Value::boolean((op == "==") == equal);
      }
      if (op == "<" || op == "<=" || op == ">" || op == ">=")
      {
        if (!a.isNumber() || !b.isNumber())
          fail(e.pos,
            "'" + op + "' compares numbers, not a " + typeName(a.type) + " and a " +
              typeName(b.type));
        const double x = a.number, y = b.number;
        return Value::boolean(op == "<" ? x < y : op == "<=" ? x <= y : op == ">" ? x > y : x >= y);
      }
      // Arithmetic on numbers and vectors.
      if (a.type == Value::Type::Vec3 || b.type == Value::Type::Vec3)
      {
        if (a.type == Value::Type::Vec3 && b.type == Value::Type::Vec3 && (op == "+" || op == "-"))
        {
          const double s = op == "+" ? 1.0 : -1.0;
          return Value::vector(
            { a.vec[0] + s * b.vec[0], a.vec[1] + s * b.vec[1], a.vec[2] + s * b.vec[2] });
        }
        if (op == "*" && a.type == Value::Type::Vec3 && b.isNumber())
          return Value::vector({ a.vec[0] * b.number, a.vec[1] * b.number, a.vec[2] * b.number });
        if (op == "*" && b.type == Value::Type::Vec3 && a.isNumber())
          return Value::vector({ b.vec[0] * a.number, b.vec[1] * a.number, b.vec[2] * a.number });
        if (op == "/" && a.type == Value::Type::Vec3 && b.isNumber())
          return Value::vector({ a.vec[0] / b.number, a.vec[1] / b.number, a.vec[2] / b.number });
        fail(e.pos,
          std::string("cannot apply '") + op + "' to a " + typeName(a.type) + " and a " +
            typeName(b.type));
      }
      if (op == "+" && a.type == Value::Type::String && b.type == Value::Type::String)
        return Value::string(a.text + b.text);
      if (!a.isNumber() || !b.isNumber())
        fail(e.pos,
          std::string("cannot apply '") + op + "' to a " + typeName(a.type) + " and a " +
            typeName(b.type));
      const bool ints = a.type == Value::Type::Int && b.type == Value::Type::Int;
      double r = 0.0;
      if (op == "+")
        r = a.number + b.number;
      else if (op == "-")
        r = a.number - b.number;
      else if (op == "*")
        r = a.number * b.number;
      else if (op == "/")
        return Value::real(a.number / b.number); // always real: no silent integer division
      else
        fail(e.pos, "unknown operator '" + op + "'");
      return ints ? Value::integer(r) : Value::real(r);
    }
    case Expr::Kind::Brace:
    {
      if (e.kids.size() != 3)
        fail(e.pos, "a braced value in code must be a vector of three numbers {x, y, z}");
      Vec3 v{};
      for (int i = 0; i < 3; ++i)
      {
        const Value c = eval(*e.kids[i], f);
        need(c, Value::Type::Real, *e.kids[i], "a vector component");
        v[i] = c.number;
      }
      return Value::vector(v);
    }
    case Expr::Kind::Placeholder:
      fail(e.pos, "'...' is a placeholder of the thesis' notation, not a value");
  }
  fail(e.pos, "unsupported expression");
}

namespace
{

/// A call of a Math built-in: its arguments, with the checks every implementation shares.
struct MathCall
{
  lang::icm::BuiltinId id;
  const std::string& file;
  const Expr& call;
  const std::string& name;
  const std::vector<Value>& args;

  [[noreturn]] void fail(Pos pos, const std::string& message) const
  {
    throw ModelError(file, pos, message);
  }
  double num(std::size_t i) const
  {
    bool ok = false;
    const double v = asNumber(args.at(i), ok);
    if (!ok || args[i].type == Value::Type::Bool)
      fail(call.kids[i + 1]->pos,
        "argument " + std::to_string(i + 1) + " of " + name + " must be a number, not a " +
          typeName(args[i].type));
    return v;
  }
  Vec3 vec(std::size_t i) const
  {
    if (args.at(i).type != Value::Type::Vec3)
      fail(call.kids[i + 1]->pos,
        "argument " + std::to_string(i + 1) + " of " + name + " must be a vec3, not a " +
          typeName(args[i].type));
    return args[i].vec;
  }
  bool ints() const { return args[0].type == Value::Type::Int && args[1].type == Value::Type::Int; }
};

using MathFunction = Value (*)(const MathCall&);

using lang::icm::BuiltinId;

/// The functions of one real argument.
Value elementary(const MathCall& c)
{
  const double x = c.num(0);
  switch (c.id)
  {
    case BuiltinId::Abs:
      return Value::real(std::fabs(x));
    case BuiltinId::Sqrt:
      return Value::real(std::sqrt(x));
    case BuiltinId::Sin:
      return Value::real(std::sin(x));
    case BuiltinId::Cos:
      return Value::real(std::cos(x));
    case BuiltinId::Tan:
      return Value::real(std::tan(x));
    case BuiltinId::Asin:
      return Value::real(std::asin(x));
    case BuiltinId::Acos:
      return Value::real(std::acos(x));
    case BuiltinId::Atan:
      return Value::real(std::atan(x));
    case BuiltinId::Exp:
      return Value::real(std::exp(x));
    case BuiltinId::Log:
      return Value::real(std::log(x));
    default:
      c.fail(c.call.pos, c.name + ": not a function of one real");
  }
}

/// The interpreter's half of the built-in library (the Math entries of lang::icm::builtins()).
const std::pair<BuiltinId, MathFunction> kMath[] = {
  { BuiltinId::Vec3,
    [](const MathCall& c)
    {
      return Value::vector({ c.num(0), c.num(1), c.num(2) });
    } },
  { BuiltinId::Length,
    [](const MathCall& c)
    {
      return Value::real(frep::norm(c.vec(0)));
    } },
  { BuiltinId::Dot,
    [](const MathCall& c)
    {
      return Value::real(frep::dot(c.vec(0), c.vec(1)));
    } },
  { BuiltinId::Cross,
    [](const MathCall& c)
    {
      return Value::vector(frep::cross(c.vec(0), c.vec(1)));
    } },
  { BuiltinId::Normalize,
    [](const MathCall& c)
    {
      const Vec3 v = c.vec(0);
      const double n = frep::norm(v);
      if (n == 0.0)
        c.fail(c.call.pos, "normalize of a zero vector");
      return Value::vector({ v[0] / n, v[1] / n, v[2] / n });
    } },
  { BuiltinId::Abs, elementary },
  { BuiltinId::Sqrt, elementary },
  { BuiltinId::Sin, elementary },
  { BuiltinId::Cos, elementary },
  { BuiltinId::Tan, elementary },
  { BuiltinId::Asin, elementary },
  { BuiltinId::Acos, elementary },
  { BuiltinId::Atan, elementary },
  { BuiltinId::Exp, elementary },
  { BuiltinId::Log, elementary },
  { BuiltinId::Atan2,
    [](const MathCall& c)
    {
      const double a = c.num(0), b = c.num(1);
      return Value::real(std::atan2(a, b));
    } },
  { BuiltinId::Pow,
    [](const MathCall& c)
    {
      const double a = c.num(0), b = c.num(1);
      return Value::real(std::pow(a, b));
    } },
  { BuiltinId::Min,
    [](const MathCall& c)
    {
      const double a = c.num(0), b = c.num(1);
      return c.ints() ? Value::integer(std::min(a, b)) : Value::real(std::min(a, b));
    } },
  { BuiltinId::Max,
    [](const MathCall& c)
    {
      const double a = c.num(0), b = c.num(1);
      return c.ints() ? Value::integer(std::max(a, b)) : Value::real(std::max(a, b));
    } },
  { BuiltinId::Clamp,
    [](const MathCall& c)
    {
      const double lo = c.num(1), hi = c.num(2);
      if (!(lo <= hi))
        c.fail(c.call.pos, "clamp: the lower bound is above the upper bound");
      return Value::real(std::clamp(c.num(0), lo, hi));
    } },
  { BuiltinId::Floor,
    [](const MathCall& c)
    {
      return Value::integer(std::floor(c.num(0)));
    } },
  { BuiltinId::Ceil,
    [](const MathCall& c)
    {
      return Value::integer(std::ceil(c.num(0)));
    } },
};

/// kMath by BuiltinId (nullptr for the Library entries).
const std::vector<MathFunction>& mathById()
{
  static const std::vector<MathFunction> byId = []
  {
    std::vector<MathFunction> v(static_cast<std::size_t>(BuiltinId::Count), nullptr);
    for (const auto& [id, fn] : kMath)
      v.at(static_cast<std::size_t>(id)) = fn;
    return v;
  }();
  return byId;
}

} // namespace

std::vector<lang::icm::BuiltinId> interpreterBuiltins()
{
  return idsOf(kMath);
}

Value Interpreter::callFunction(const Expr& call, std::vector<Value> args, Frame& f) const
{
  const std::string name = lang::icm::calledName(call.text);
  const lang::icm::Builtin* builtin = lang::icm::findBuiltin(name);
  if (builtin && builtin->layer == lang::icm::BuiltinLayer::Math)
  {
    const std::size_t n = static_cast<std::size_t>(builtin->call.minArgs);
    if (args.size() != n)
      fail(call.pos,
        name + " takes " + std::to_string(n) + " argument(s), got " + std::to_string(args.size()));
    const MathFunction fn = mathById()[static_cast<std::size_t>(builtin->id)];
    if (!fn)
      fail(call.pos, name + ": no implementation of this built-in");
    return fn(MathCall{ builtin->id, file_, call, name, args });
  }
  if (functions_)
    for (const Procedure& p : *functions_)
      if (p.name.text == name)
      {
        if (args.size() != p.formals.size())
          fail(call.pos,
            name + " takes " + std::to_string(p.formals.size()) + " argument(s), got " +
              std::to_string(args.size()));
        // The checker allows calls only to earlier functions, so the depth is bounded by the
        // number of functions; the guard protects models built without the checker.
        if (f.depth > static_cast<int>(functions_->size()))
          fail(call.pos, "function calls nest deeper than the number of functions (recursion?)");
        Frame inner{ f.scope, {}, f.iterations, f.depth + 1, {} };
        for (std::size_t i = 0; i < p.formals.size(); ++i)
          inner.locals[p.formals[i].name] = args[i];
        exec(p.body, inner);
        f.iterations = inner.iterations;
        return inner.result;
      }
  if (!builtin)
    fail(call.pos, name + ": unknown function '" + name + "'");
  try
  {
    return f.scope.call(*builtin, args);
  }
  catch (const ModelError&)
  {
    throw;
  }
  catch (const std::exception& x)
  {
    fail(call.pos, name + ": " + x.what());
  }
}

bool Interpreter::exec(const std::vector<StmtPtr>& body, Frame& f) const
{
  for (const StmtPtr& s : body)
    if (exec(*s, f))
      return true;
  return false;
}

bool Interpreter::exec(const Stmt& s, Frame& f) const
{
  switch (s.kind)
  {
    case Stmt::Kind::Block:
      return exec(s.body, f);
    case Stmt::Kind::Local:
    {
      Value v = eval(*s.value, f);
      const std::string& t = s.type;
      Value::Type want = Value::Type::None;
      if (t == "real" || t == "REAL" || t == "float" || t == "double")
        want = Value::Type::Real;
      else if (t == "int" || t == "INT")
        want = Value::Type::Int;
      else if (t == "bool" || t == "BOOL")
        want = Value::Type::Bool;
      else if (t == "vec3" || t == "VECTOR3")
        want = Value::Type::Vec3;
      else if (t == "string" || t == "STRING")
        want = Value::Type::String;
      else if (t == "shape" || t == "SHAPE")
        want = Value::Type::Shape;
      if (want == Value::Type::Real && v.isNumber())
        v = Value::real(v.number);
      else if (want == Value::Type::Int && v.isNumber())
        v = Value::integer(v.number);
      else if (want != Value::Type::None && v.type != want)
        fail(
          s.pos, "'" + s.name + "' is a " + t + " but is initialised with a " + typeName(v.type));
      f.locals[s.name] = v;
      return false;
    }
    case Stmt::Kind::Assign:
      assign(*s.target, s.op, eval(*s.value, f), f);
      return false;
    case Stmt::Kind::Eval:
      eval(*s.value, f);
      return false;
    case Stmt::Kind::If:
    {
      const Value c = eval(*s.cond, f);
      if (c.type != Value::Type::Bool)
        fail(s.cond->pos, std::string("the condition must be a bool, not a ") + typeName(c.type));
      return c.number != 0.0 ? exec(s.body, f) : exec(s.elseBody, f);
    }
    case Stmt::Kind::For:
    {
      const Value a = eval(*s.from, f), b = eval(*s.to, f);
      if (!a.isNumber() || !b.isNumber())
        fail(s.pos, "loop bounds must be numbers");
      const double from = std::ceil(a.number), to = std::ceil(b.number);
      if (to - from > static_cast<double>(maxIterations - f.iterations))
        fail(s.pos,
          "the loop would run more than " + std::to_string(maxIterations) +
            " iterations in one reaction");
      for (double i = from; i < to; ++i)
      {
        f.locals[s.name] = Value::integer(i);
        ++f.iterations;
        if (exec(s.body, f))
          return true;
      }
      return false;
    }
    case Stmt::Kind::Return:
      f.result = s.value ? eval(*s.value, f) : Value{};
      return true;
    case Stmt::Kind::Placeholder:
      fail(s.pos, "'...' is a placeholder of the thesis' notation, not a statement");
  }
  return false;
}

void Interpreter::assign(const Expr& target, const std::string& op, Value v, Frame& f) const
{
  // The target is a name, name.member or name.member.component; vector components are read,
  // modified and written back whole.
  std::vector<const Expr*> chain;
  const Expr* e = &target;
  while (e->kind == Expr::Kind::Member)
  {
    chain.push_back(e);
    e = e->kids[0].get();
  }
  if (e->kind != Expr::Kind::Name)
    fail(target.pos, "only names and their members can be assigned");
  std::reverse(chain.begin(), chain.end());
  const std::string& root = e->text;
  const bool local = f.locals.count(root) > 0;

  // Split off a trailing vector component (translation.x, w.y).
  int comp = -1;
  if (!chain.empty() && component(chain.back()->text) >= 0)
  {
    // `Cell.x` would be a parameter named x: only treat it as a component when what it is taken
    // from is a vector.
    Value base;
    const Expr& baseExpr = chain.size() == 1 ? *e : *chain[chain.size() - 2];
    base = eval(baseExpr, f);
    if (base.type == Value::Type::Vec3)
    {
      comp = component(chain.back()->text);
      chain.pop_back();
    }
  }
  if (chain.size() > 1)
    fail(target.pos, "cannot assign to '" + chain.back()->text + "' of a property");
  const std::string member = chain.empty() ? std::string() : chain[0]->text;
  const Expr& whole = chain.empty() ? *e : *chain[0];

  Value current;
  if (op != "=" || comp >= 0)
    current = eval(whole, f);
  Value next = v;
  if (comp >= 0)
  {
    if (!v.isNumber() && op == "=")
      fail(target.pos, std::string("a vector component takes a number, not a ") + typeName(v.type));
    Value c = Value::real(current.vec[comp]);
    if (op != "=")
    {
      if (!v.isNumber())
        fail(target.pos, std::string("'") + op + "' needs a number");
      const double x = v.number;
      c.number = op == "+=" ? c.number + x
        : op == "-="        ? c.number - x
        : op == "*="        ? c.number * x
                            : c.number / x;
    }
    else
      c.number = v.number;
    next = current;
    next.vec[comp] = c.number;
  }
  else if (op != "=")
  {
    const bool vecs = current.type == Value::Type::Vec3;
    if (vecs && (op == "+=" || op == "-="))
    {
      if (v.type != Value::Type::Vec3)
        fail(target.pos, std::string("'") + op + "' on a vec3 needs a vec3");
      const double s = op == "+=" ? 1.0 : -1.0;
      next = Value::vector({ current.vec[0] + s * v.vec[0], current.vec[1] + s * v.vec[1],
        current.vec[2] + s * v.vec[2] });
    }
    else if (vecs)
    {
      if (!v.isNumber())
        fail(target.pos, std::string("'") + op + "' on a vec3 needs a number");
      const double k = op == "*=" ? v.number : 1.0 / v.number;
      next = Value::vector({ current.vec[0] * k, current.vec[1] * k, current.vec[2] * k });
    }
    else
    {
      if (!current.isNumber() || !v.isNumber())
        fail(target.pos,
          std::string("'") + op + "' needs numbers, not a " + typeName(current.type) + " and a " +
            typeName(v.type));
      const double x = op == "+=" ? current.number + v.number
        : op == "-="              ? current.number - v.number
        : op == "*="              ? current.number * v.number
                                  : current.number / v.number;
      next = current.type == Value::Type::Int && v.type == Value::Type::Int && op != "/="
        ? Value::integer(x)
        : Value::real(x);
    }
  }

  if (local && member.empty())
  {
    Value& slot = f.locals[root];
    if (slot.type != Value::Type::None && slot.type != next.type &&
      !(slot.isNumber() && next.isNumber()))
      fail(target.pos,
        "'" + root + "' is a " + typeName(slot.type) + ", not a " + typeName(next.type));
    if (slot.type == Value::Type::Int && next.isNumber())
      next = Value::integer(next.number);
    else if (slot.type == Value::Type::Real && next.isNumber())
      next = Value::real(next.number);
    slot = next;
    return;
  }
  if (local)
    fail(target.pos,
      "'" + root + "' is a local " + typeName(f.locals[root].type) + "; it has no member '" +
        member + "' to assign");
  try
  {
    if (!f.scope.assign(root, member, next))
      fail(target.pos,
        "cannot assign to '" + (member.empty() ? root : root + "." + member) +
          "': not a parameter or property that code can set");
  }
  catch (const ModelError&)
  {
    throw;
  }
  catch (const std::exception& x)
  {
    fail(target.pos, x.what());
  }
}

} // namespace ictk::engine
