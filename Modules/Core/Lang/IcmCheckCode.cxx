// SPDX-License-Identifier: BSD-3-Clause
// The checks of the imperative code of reactions, predicates and functions: signatures, scopes,
// types where they are known, assignments, bounded loops, and calls (model functions defined
// earlier, the built-in library with the signatures of Lang/IcmBuiltins.h).
#include "Lang/IcmChecker.h"
#include "Skin/SkinnedMesh.h"

#include <cmath>

namespace ictk::lang::icmcheck
{

void Checker::reactionsOf(
  const std::vector<Procedure>& rs, const CellMap& cells, const Instance* in, const CellDef* owner)
{
  std::map<std::string, Pos> seen;
  for (const Procedure& r : rs)
  {
    std::string key = r.cell.text + "." + r.name.text;
    if (r.name.text == "react" && !r.formals.empty())
    {
      key += "." + r.formals[0].type;
    }
    const auto it = seen.find(key);
    if (it != seen.end())
    {
      err(r.name.pos,
        "reaction '" + (r.cell.text.empty() ? "" : r.cell.text + ".") + r.name.text +
          "' defined twice (first at " + lineOf(it->second) + ")");
    }
    seen.emplace(key, r.name.pos);
    Code c;
    c.instance = in;
    c.cells = &cells;
    c.vars = in ? instanceVars_ : globalVars_;
    c.cell = owner;
    if (!r.cell.text.empty())
    {
      const auto cit = cells.find(r.cell.text);
      if (cit == cells.end())
      {
        err(r.cell.pos, "undefined cell '" + r.cell.text + "'");
      }
      else
      {
        c.cell = cit->second;
      }
    }
    if (c.cell)
    {
      for (const std::string& p : paramsOf(c.cell))
      {
        c.vars.insert(p);
      }
      for (const std::string& p : cellProperties())
      {
        c.vars.insert(p);
      }
    }
    procedure(r, c);
  }
}

void Checker::procedure(const Procedure& p, Code& c)
{
  const std::string& n = p.name.text;
  std::size_t want = 0;
  const char* signature = "";
  if (c.function)
  {
    want = p.formals.size();
  }
  else if (c.predicate)
  {
    if (p.resultType != "bool" && p.resultType != "BOOL")
    {
      err(p.pos, "a predicate is 'bool evaluate(REAL globalT, REAL localT, REAL dt)'");
    }
    if (n != "evaluate")
    {
      err(p.name.pos, "the predicate's function is 'evaluate', not '" + n + "'");
    }
    want = 3;
    signature = "(REAL globalT, REAL localT, REAL dt)";
  }
  else if (n == "init" || n == "terminate")
  {
    want = 1;
    signature = "(REAL globalT)";
  }
  else if (n == "update" || n == "updatePost")
  {
    want = 4;
    signature = "(REAL globalT, REAL localT, REAL lifeT, REAL dt)";
  }
  else if (n == "react")
  {
    want = 4;
    signature = "(EVENT e, REAL globalT, REAL localT, REAL lifeT)";
  }
  else
  {
    err(p.name.pos, "unknown reaction '" + n + "': init, terminate, update, updatePost or react");
    want = p.formals.size();
  }
  if (p.formals.size() != want)
  {
    err(p.name.pos,
      "'" + n + "' takes " + std::to_string(want) + " parameter(s) " + signature + ", found " +
        std::to_string(p.formals.size()));
  }
  for (std::size_t i = 0; i < p.formals.size(); ++i)
  {
    const Formal& f = p.formals[i];
    Ty t = Ty::Unknown;
    if (!c.function && !c.predicate && n == "react" && i == 0)
    {
      const auto e = events_.find(f.type);
      if (e == events_.end() && f.type != "TIME_REJECTED")
      {
        err(f.pos, "undefined event '" + f.type + "'");
      }
      else
      {
        c.eventArgs[f.name] = e == events_.end() ? nullptr : e->second;
      }
      t = Ty::Event;
    }
    else if (!valueType(f.type, t))
    {
      err(f.pos, "unknown type '" + f.type + "': real, int, bool, vec3 or string");
    }
    else if (!c.function && t != Ty::Real)
    {
      err(f.pos, "the time arguments are REAL");
    }
    if (c.args.count(f.name) > 0)
    {
      err(f.pos, "duplicate parameter '" + f.name + "'");
    }
    c.args[f.name] = t;
  }
  c.locals.emplace_back();
  statements(p.body, c);
  c.locals.pop_back();
  if (c.predicate && !returns(p.body))
  {
    err(p.pos, "the predicate must return a bool");
  }
}

bool Checker::returns(const std::vector<StmtPtr>& body)
{
  for (const StmtPtr& s : body)
  {
    if (s->kind == Stmt::Kind::Return)
    {
      return true;
    }
    if (s->kind == Stmt::Kind::Block && returns(s->body))
    {
      return true;
    }
    if (s->kind == Stmt::Kind::If && returns(s->body) && returns(s->elseBody))
    {
      return true;
    }
  }
  return false;
}

void Checker::statements(const std::vector<StmtPtr>& body, Code& c)
{
  for (const StmtPtr& s : body)
  {
    statement(*s, c);
  }
}

bool Checker::isLocal(const Code& c, const std::string& n, Ty* t) const
{
  for (auto it = c.locals.rbegin(); it != c.locals.rend(); ++it)
  {
    const auto f = it->find(n);
    if (f != it->end())
    {
      if (t)
      {
        *t = f->second;
      }
      return true;
    }
  }
  return false;
}

void Checker::statement(const Stmt& s, Code& c)
{
  switch (s.kind)
  {
    case Stmt::Kind::Block:
      c.locals.emplace_back();
      statements(s.body, c);
      c.locals.pop_back();
      return;
    case Stmt::Kind::Local:
    {
      Ty t = Ty::Unknown;
      if (!valueType(s.type, t))
      {
        err(s.pos, "unknown type '" + s.type + "': real, int, bool, vec3, string or shape");
      }
      const Ty v = expr(s.value, c);
      if (t != Ty::Unknown && !assignable(t, v))
      {
        err(s.value->pos, std::string("cannot initialise a ") + tyName(t) + " with a " + tyName(v));
      }
      if (c.locals.back().count(s.name) > 0)
      {
        err(s.pos, "duplicate local '" + s.name + "'");
      }
      else if (c.args.count(s.name) > 0 || c.loopVars.count(s.name) > 0 ||
        (c.cells && c.cells->count(s.name) > 0))
      {
        err(s.pos, "local '" + s.name + "' hides a parameter or a cell of the same name");
      }
      c.locals.back()[s.name] = t;
      return;
    }
    case Stmt::Kind::Assign:
      assign(s, c);
      return;
    case Stmt::Kind::Eval:
      if (s.value->kind != Expr::Kind::Call)
      {
        err(s.pos, "this statement has no effect (only calls stand alone)");
      }
      expr(s.value, c);
      return;
    case Stmt::Kind::If:
    {
      const Ty t = expr(s.cond, c);
      if (t != Ty::Bool && t != Ty::Unknown)
      {
        err(s.cond->pos, std::string("the condition is a ") + tyName(t) + ", not a bool");
      }
      c.locals.emplace_back();
      statements(s.body, c);
      c.locals.pop_back();
      c.locals.emplace_back();
      statements(s.elseBody, c);
      c.locals.pop_back();
      return;
    }
    case Stmt::Kind::For:
    {
      bound(s.from, c);
      bound(s.to, c);
      double lo = 0;
      double hi = 0;
      if (constantNumber(s.from, lo) && constantNumber(s.to, hi) && hi - lo > 1e7)
      {
        err(s.to->pos, "the loop runs more than 10000000 times");
      }
      if (c.loopVars.count(s.name) > 0 || isLocal(c, s.name))
      {
        err(s.pos, "the loop variable '" + s.name + "' is already in use");
      }
      c.locals.emplace_back();
      c.locals.back()[s.name] = Ty::Int;
      const bool added = c.loopVars.insert(s.name).second;
      statements(s.body, c);
      if (added)
      {
        c.loopVars.erase(s.name);
      }
      c.locals.pop_back();
      return;
    }
    case Stmt::Kind::Return:
      if (c.predicate)
      {
        if (!s.value)
        {
          err(s.pos, "the predicate returns a bool");
          return;
        }
        const Ty t = expr(s.value, c);
        if (t != Ty::Bool && t != Ty::Unknown)
        {
          err(s.value->pos, std::string("the predicate returns a bool, not a ") + tyName(t));
        }
      }
      else if (s.value)
      {
        expr(s.value, c);
        if (!c.function)
        {
          err(s.pos, "a reaction returns no value");
        }
      }
      return;
    case Stmt::Kind::Placeholder:
      return;
  }
}

void Checker::bound(const ExprPtr& e, Code& c)
{
  const Ty t = expr(e, c);
  if (t != Ty::Int && t != Ty::Unknown && t != Ty::Real)
  {
    err(e->pos, std::string("a loop bound is a number, not a ") + tyName(t));
  }
  double v = 0;
  if (constantNumber(e, v) && v != std::floor(v))
  {
    err(e->pos, "a loop bound is a whole number");
  }
}

bool Checker::assignable(Ty to, Ty from)
{
  return from == Ty::Unknown || to == Ty::Unknown || to == from ||
    (to == Ty::Real && from == Ty::Int);
}

void Checker::assign(const Stmt& s, Code& c)
{
  const Expr* root = s.target.get();
  while (!root->kids.empty())
  {
    root = root->kids[0].get();
  }
  const std::string& n = root->text;
  Ty t = Ty::Unknown;
  const bool whole = s.target.get() == root;
  if (c.loopVars.count(n) > 0)
  {
    err(root->pos, "cannot assign to the loop variable '" + n + "'");
  }
  else if (isLocal(c, n, &t))
  {
  }
  else if (c.args.count(n) > 0)
  {
    err(root->pos, "cannot assign to the argument '" + n + "' (read-only)");
  }
  else if (c.vars.count(n) > 0)
  {
  }
  else if (c.cells && c.cells->count(n) > 0)
  {
    if (whole)
    {
      err(root->pos, "cannot assign to the cell '" + n + "': assign to one of its parameters");
    }
    else
    {
      cellMember(*s.target, *c.cells);
    }
  }
  else
  {
    err(root->pos, "undefined name '" + n + "'");
  }
  if (!whole)
  {
    t = Ty::Unknown;
    // The indices in the path are expressions too.
    for (const Expr* e = s.target.get(); !e->kids.empty(); e = e->kids[0].get())
    {
      if (e->kind == Expr::Kind::Index)
      {
        expr(e->kids[1], c);
      }
    }
  }
  const Ty v = expr(s.value, c);
  if (s.op == "=")
  {
    if (!assignable(t, v))
    {
      err(s.value->pos, std::string("cannot assign a ") + tyName(v) + " to a " + tyName(t));
    }
    return;
  }
  for (Ty x : { t, v })
  {
    if (x == Ty::Bool || x == Ty::String || x == Ty::Shape || x == Ty::Void)
    {
      err(s.pos, "'" + s.op + "' needs numbers or vectors, found a " + tyName(x));
      return;
    }
  }
}

Ty Checker::name(const Expr& e, Code& c)
{
  Ty t = Ty::Unknown;
  const std::string& n = e.text;
  if (isLocal(c, n, &t))
  {
    return t;
  }
  const auto a = c.args.find(n);
  if (a != c.args.end())
  {
    return a->second;
  }
  if (c.vars.count(n) > 0)
  {
    return Ty::Unknown;
  }
  if (c.cells && c.cells->count(n) > 0)
  {
    return Ty::Cell;
  }
  if (n == "shape" && c.cell)
  {
    return Ty::Shape; // the cell's own shape (thesis L3160: makeCrossSection(shape, globalT))
  }
  if (globalCells_.count(n) > 0)
  {
    err(e.pos,
      "cell '" + n + "' is not in " +
        (c.instance ? "instance '" + c.instance->name.text + "'" : std::string("scope")));
    return Ty::Cell;
  }
  if (n == "pi")
  {
    return Ty::Real;
  }
  if (events_.count(n) > 0 || n == "TIME_REJECTED")
  {
    return Ty::Event;
  }
  if (functions_.count(n) > 0 || findBuiltin(n))
  {
    err(e.pos, "function '" + n + "' used without a call");
    return Ty::Unknown;
  }
  err(e.pos, "undefined name '" + n + "'");
  return Ty::Unknown;
}

Ty Checker::expr(const ExprPtr& ep, Code& c)
{
  const Expr& e = *ep;
  switch (e.kind)
  {
    case Expr::Kind::Number:
      return e.text.find_first_of(".eE") == std::string::npos ? Ty::Int : Ty::Real;
    case Expr::Kind::Bool:
      return Ty::Bool;
    case Expr::Kind::String:
      return Ty::String;
    case Expr::Kind::Name:
    {
      const Ty t = name(e, c);
      if (t == Ty::Event)
      {
        err(e.pos, "an event is only a value in fireEvent(" + e.text + ", ...)");
        return Ty::Unknown;
      }
      return t;
    }
    case Expr::Kind::Member:
    {
      const Expr& k = *e.kids[0];
      if (k.kind == Expr::Kind::Name)
      {
        const auto ev = c.eventArgs.find(k.text);
        if (ev != c.eventArgs.end() && !isLocal(c, k.text))
        {
          if (ev->second)
          {
            bool found = false;
            for (const ParamDecl& p : ev->second->parameters)
            {
              found = found || p.name.text == e.text;
            }
            if (!found)
            {
              err(e.pos, "event '" + ev->second->name.text + "' has no parameter '" + e.text + "'");
            }
          }
          return Ty::Unknown;
        }
        const Ty t = name(k, c);
        if (t == Ty::Cell)
        {
          cellMember(e, *c.cells);
          return e.text == "translation" || e.text == "center" ? Ty::Vec3 : Ty::Unknown;
        }
        return member(e, t);
      }
      return member(e, expr(e.kids[0], c));
    }
    case Expr::Kind::Index:
      expr(e.kids[0], c);
      expr(e.kids[1], c);
      return Ty::Unknown;
    case Expr::Kind::Call:
      return call(e, c);
    case Expr::Kind::Unary:
    {
      const Ty t = expr(e.kids[0], c);
      if (e.text == "!")
      {
        if (t != Ty::Bool && t != Ty::Unknown)
        {
          err(e.pos, std::string("'!' needs a bool, found a ") + tyName(t));
        }
        return Ty::Bool;
      }
      if (t != Ty::Unknown && !numeric(t) && t != Ty::Vec3)
      {
        err(e.pos, std::string("'-' needs a number or a vector, found a ") + tyName(t));
        return Ty::Unknown;
      }
      return t;
    }
    case Expr::Kind::Binary:
      return binary(e, c);
    case Expr::Kind::Brace:
    case Expr::Kind::CellType:
    case Expr::Kind::Dim:
      err(e.pos, "not a value in code");
      return Ty::Unknown;
    case Expr::Kind::Placeholder:
      return Ty::Unknown;
  }
  return Ty::Unknown;
}

Ty Checker::member(const Expr& e, Ty of)
{
  if (of == Ty::Vec3)
  {
    if (e.text != "x" && e.text != "y" && e.text != "z")
    {
      err(e.pos, "a vec3 has x, y and z, not '" + e.text + "'");
    }
    return Ty::Real;
  }
  if (of != Ty::Unknown)
  {
    err(e.pos, std::string("a ") + tyName(of) + " has no member '" + e.text + "'");
  }
  return Ty::Unknown;
}

Ty Checker::binary(const Expr& e, Code& c)
{
  const Ty a = expr(e.kids[0], c);
  const Ty b = expr(e.kids[1], c);
  const std::string& op = e.text;
  if (op == "&&" || op == "||")
  {
    for (Ty t : { a, b })
    {
      if (t != Ty::Bool && t != Ty::Unknown)
      {
        err(e.pos, "'" + op + "' needs bools, found a " + tyName(t));
        break;
      }
    }
    return Ty::Bool;
  }
  if (op == "==" || op == "!=")
  {
    return Ty::Bool;
  }
  for (Ty t : { a, b })
  {
    if (t == Ty::Bool || t == Ty::String || t == Ty::Shape || t == Ty::Void || t == Ty::Cell)
    {
      err(e.pos,
        "'" + op + "' needs numbers" +
          (op.size() == 1 && op != "<" && op != ">" ? std::string(" or vectors") : std::string()) +
          ", found a " + tyName(t));
      return op == "<" || op == ">" || op == "<=" || op == ">=" ? Ty::Bool : Ty::Unknown;
    }
  }
  if (op == "<" || op == ">" || op == "<=" || op == ">=")
  {
    if (a == Ty::Vec3 || b == Ty::Vec3)
    {
      err(e.pos, "vectors are not ordered: compare their lengths");
    }
    return Ty::Bool;
  }
  if (a == Ty::Vec3 || b == Ty::Vec3)
  {
    if ((op == "+" || op == "-") && a != b && a != Ty::Unknown && b != Ty::Unknown)
    {
      err(e.pos, "'" + op + "' between a vector and a number");
    }
    if (op == "/" && b == Ty::Vec3)
    {
      err(e.pos, "cannot divide by a vector");
    }
    return Ty::Vec3;
  }
  if (a == Ty::Unknown || b == Ty::Unknown)
  {
    return Ty::Unknown;
  }
  return a == Ty::Int && b == Ty::Int && op != "/" ? Ty::Int : Ty::Real;
}

Ty Checker::call(const Expr& e, Code& c)
{
  const std::size_t n = e.kids.size() - 1;
  if (e.text.empty())
  {
    err(e.pos, "only built-in functions and model functions can be called (no methods)");
    for (std::size_t i = 1; i < e.kids.size(); ++i)
    {
      expr(e.kids[i], c);
    }
    return Ty::Unknown;
  }
  const std::string fn = calledName(e.text);
  const auto uf = functions_.find(fn);
  if (uf != functions_.end())
  {
    // A function calls only the functions defined before it: no recursion, so every call
    // ends.
    if (c.function && uf->second >= &m_.functions[c.functionIndex])
    {
      err(e.pos, "function '" + fn + "' is called before its definition ends (no recursion)");
    }
    if (n != uf->second->formals.size())
    {
      err(e.pos,
        "function '" + fn + "' takes " + std::to_string(uf->second->formals.size()) +
          " argument(s), found " + std::to_string(n));
    }
    for (std::size_t i = 1; i < e.kids.size(); ++i)
    {
      expr(e.kids[i], c);
    }
    Ty t = Ty::Unknown;
    valueType(uf->second->resultType, t);
    return t;
  }
  const Builtin* builtin = findBuiltin(fn);
  if (!builtin)
  {
    err(e.pos, "unknown function '" + e.text + "' (not a built-in nor a model function)");
    for (std::size_t i = 1; i < e.kids.size(); ++i)
    {
      expr(e.kids[i], c);
    }
    return Ty::Unknown;
  }
  const Signature* b = &builtin->call;
  if (static_cast<int>(n) < b->minArgs || (b->maxArgs >= 0 && static_cast<int>(n) > b->maxArgs))
  {
    err(e.pos,
      "'" + fn + "' takes " + arity(*b) + " argument(s) (" + b->signature + "), found " +
        std::to_string(n));
  }
  if ((fn == "animation" || fn == "animationValue" || fn == "animationDuration") && n >= 1 &&
    e.kids[1]->kind == Expr::Kind::String && animations_.count(e.kids[1]->text) == 0)
  {
    err(e.kids[1]->pos, "undefined animation \"" + e.kids[1]->text + "\"");
  }
  const std::string sig = b->signature;
  std::size_t first = 1;
  if (fn == "fireEvent" && n >= 1)
  {
    first = 2;
    const Expr& ev = *e.kids[1];
    if (ev.kind != Expr::Kind::Name)
    {
      err(ev.pos, "fireEvent's first argument is an event name");
    }
    else if (ev.text == "TIME_REJECTED")
    {
      if (n != 2)
      {
        err(e.pos,
          "fireEvent(TIME_REJECTED, step) takes the step to retry with, from the "
          "last accepted time");
      }
    }
    else
    {
      const auto it = events_.find(ev.text);
      if (it == events_.end())
      {
        err(ev.pos, "undefined event '" + ev.text + "'");
      }
      else
      {
        std::size_t want = 0;
        for (const ParamDecl& p : it->second->parameters)
        {
          want += p.kind == ParamDecl::Kind::Typed ? 1 : 0;
        }
        if (n - 1 != want)
        {
          err(e.pos,
            "event '" + ev.text + "' has " + std::to_string(want) +
              " parameter(s), fireEvent gives " + std::to_string(n - 1));
        }
      }
    }
  }
  // Arguments named cellA/cellB/cell are cells.
  std::size_t cellArgs = 0;
  if (sig.find("(cellA, cellB") != std::string::npos)
  {
    cellArgs = 2;
  }
  else if (sig.find("(cell,") != std::string::npos || sig.find("(cell)") != std::string::npos)
  {
    cellArgs = 1;
  }
  for (std::size_t i = first; i < e.kids.size(); ++i)
  {
    const Ty t = expr(e.kids[i], c);
    if (i <= cellArgs && t != Ty::Cell)
    {
      err(e.kids[i]->pos, "argument " + std::to_string(i) + " of '" + fn + "' is a cell name");
    }
    else if (cellArgs == 2 && i <= cellArgs && e.kids[i]->kind == Expr::Kind::Name &&
      isMeshCell(e.kids[i]->text, c.cells))
    {
      // The queries work on fields and analytic shapes; an explicit surface has neither.
      err(e.kids[i]->pos,
        "'" + fn + "' does not take meshes yet, and cell '" + e.kids[i]->text +
          "' is a mesh (.obj/.off, loadMesh)");
    }
    else if (i > cellArgs && t == Ty::Cell)
    {
      err(e.kids[i]->pos,
        "argument " + std::to_string(i) + " of '" + fn + "' is a value, not a cell (" +
          b->signature + ")");
    }
  }
  const bool skeletal = builtin->id == BuiltinId::JointPosition ||
    builtin->id == BuiltinId::JointTransforms || builtin->id == BuiltinId::SetDeformation;
  if (skeletal && e.kids.size() == 3)
  {
    jointPosition(e, c.cells);
  }
  const bool projection = builtin->id == BuiltinId::SetProjection ||
    builtin->id == BuiltinId::ProjectionResidual || builtin->id == BuiltinId::ProjectionAngle;
  if (projection && e.kids.size() >= 2)
  {
    projectionCall(e, c.cells);
  }
  return resultType(b->result);
}

void Checker::projectionCall(const Expr& call, const CellMap* cells)
{
  const ExprPtr& cell = call.kids[1];
  if (cell->kind != Expr::Kind::Name)
  {
    return;
  }
  const Expr* load = loadMeshOf(cell->text, cells);
  if (!load || load->text != "loadMesh")
  {
    err(cell->pos,
      call.text + " takes a skinned mesh cell, and cell '" + cell->text +
        "' is not one (shape = loadMesh(...))");
    return;
  }
  // The vertices are projected onto the stand-in of the cell: some cell must be it.
  bool standIn = false;
  for (const auto& named : allCells_)
  {
    const Property* p = shapeOf(named.first, &allCells_);
    if (!p)
    {
      continue;
    }
    for (const ExprPtr& v : p->values)
    {
      standIn = standIn ||
        (v->kind == Expr::Kind::Call && v->text == "standIn" && v->kids.size() == 2 &&
          v->kids[1]->kind == Expr::Kind::Name && v->kids[1]->text == cell->text);
    }
  }
  if (!standIn)
  {
    err(cell->pos,
      call.text + ": no cell is the stand-in of '" + cell->text + "' (shape = standIn(" +
        cell->text + "))");
  }
  if (call.text != "setProjection" || call.kids.size() < 4)
  {
    return;
  }
  // The weight map: a model function of the bind-pose position.
  const ExprPtr& weights = call.kids[3];
  if (weights->kind != Expr::Kind::String)
  {
    err(weights->pos,
      "setProjection's weight map is the name of a model function, in quotes "
      "(\"name\" of function name(real x, real y, real z))");
  }
  else if (const auto f = functions_.find(weights->text); f == functions_.end())
  {
    err(weights->pos,
      "setProjection: no model function named '" + weights->text +
        "' (a weight map is a function(real x, real y, real z) of the bind-pose position)");
  }
  else if (f->second->formals.size() != 3)
  {
    err(weights->pos,
      "setProjection: function '" + weights->text + "' takes " +
        std::to_string(f->second->formals.size()) +
        " argument(s), and a weight map takes the bind-pose position (x, y, z)");
  }
  double spread = 0;
  if (call.kids.size() >= 5 && constantNumber(call.kids[4], spread) && !(spread >= 0 && spread < 1))
  {
    err(call.kids[4]->pos, "setProjection: the spread of the delays is in [0, 1)");
  }
}

void Checker::jointPosition(const Expr& call, const CellMap* cells)
{
  const ExprPtr& cell = call.kids[1];
  const ExprPtr& joint = call.kids[2];
  if (cell->kind != Expr::Kind::Name)
  {
    return;
  }
  const Expr* load = loadMeshOf(cell->text, cells);
  if (!load)
  {
    err(cell->pos,
      call.text + " takes a skinned cell, and cell '" + cell->text +
        "' is not one (shape = loadMesh(...) or loadSegmentsHierarchy(...))");
    return;
  }
  if (call.text != "jointPosition" || joint->kind != Expr::Kind::String || load->kids.size() != 3 ||
    load->kids[1]->kind != Expr::Kind::String)
  {
    return;
  }
  // The file's own problems are reported at the loadMesh call.
  const skin::SkinnedMesh* mesh = skinnedMesh(*load->kids[1], false);
  if (!mesh)
  {
    return;
  }
  for (const skin::Node& n : mesh->nodes)
  {
    if (n.name == joint->text)
    {
      return;
    }
  }
  err(joint->pos, "no joint named '" + joint->text + "' in " + mesh->file);
}

} // namespace ictk::lang::icmcheck
