// SPDX-License-Identifier: BSD-3-Clause
// Semantic checks of an IC model: names (undefined, duplicate), relation ends, properties,
// USE targets, reaction and predicate signatures, and the code of reactions, predicates and
// functions (scopes, types where they are known, the built-in library and its argument counts,
// loop bounds).
#include "Lang/HyperFun.h"
#include "Lang/Icm.h"
#include "Lang/IcmBuiltins.h"
#include "Lang/IcmLexer.h"

#include <cmath>
#include <map>
#include <set>

namespace ictk::lang
{

namespace
{

using namespace icm;

enum class Ty
{
  Unknown,
  Real,
  Int,
  Bool,
  Vec3,
  String,
  Shape,
  Void,
  Cell,
  Event
};

const char* tyName(Ty t)
{
  switch (t)
  {
    case Ty::Real:
      return "real";
    case Ty::Int:
      return "int";
    case Ty::Bool:
      return "bool";
    case Ty::Vec3:
      return "vec3";
    case Ty::String:
      return "string";
    case Ty::Shape:
      return "shape";
    case Ty::Void:
      return "nothing";
    case Ty::Cell:
      return "cell";
    case Ty::Event:
      return "event";
    default:
      return "unknown";
  }
}

/// The value types of code (as written in the thesis or in lower case).
bool valueType(const std::string& s, Ty& t)
{
  static const std::map<std::string, Ty> types = { { "real", Ty::Real }, { "REAL", Ty::Real },
    { "int", Ty::Int }, { "INT", Ty::Int }, { "bool", Ty::Bool }, { "BOOL", Ty::Bool },
    { "vec3", Ty::Vec3 }, { "VEC3", Ty::Vec3 }, { "VECTOR3", Ty::Vec3 }, { "string", Ty::String },
    { "STRING", Ty::String } };
  const auto it = types.find(s);
  if (it == types.end())
  {
    return false;
  }
  t = it->second;
  return true;
}

Ty resultType(const std::string& r)
{
  static const std::map<std::string, Ty> m = { { "real", Ty::Real }, { "int", Ty::Int },
    { "bool", Ty::Bool }, { "vec3", Ty::Vec3 }, { "string", Ty::String }, { "shape", Ty::Shape },
    { "void", Ty::Void } };
  const auto it = m.find(r);
  return it == m.end() ? Ty::Unknown : it->second;
}

bool numeric(Ty t)
{
  return t == Ty::Real || t == Ty::Int;
}

/// Properties every cell has (the built-in transform, geometry and bookkeeping).
const std::set<std::string>& cellProperties()
{
  static const std::set<std::string> p = { "translation", "rotation", "scale", "transform", "shape",
    "domain", "curDomain", "center", "dim", "type", "lifespan", "priority", "attributes",
    "radius" };
  return p;
}

/// Where an expression starts (its leftmost token).
Pos start(const Expr& e)
{
  const Expr* x = &e;
  while ((x->kind == Expr::Kind::Binary || x->kind == Expr::Kind::Member ||
           x->kind == Expr::Kind::Index || x->kind == Expr::Kind::Call) &&
    !x->kids.empty())
  {
    x = x->kids[0].get();
  }
  return x->pos;
}

std::string lineOf(Pos p)
{
  return "line " + std::to_string(p.line);
}

// A constant number: 1.5, -2, or a braced list of them.
bool constantNumber(const ExprPtr& e, double& v)
{
  if (e->kind == Expr::Kind::Number)
  {
    v = e->number;
    return true;
  }
  if (e->kind == Expr::Kind::Unary && e->text == "-" && constantNumber(e->kids[0], v))
  {
    v = -v;
    return true;
  }
  return false;
}

using CellMap = std::map<std::string, const CellDef*>;

struct Code
{
  const Instance* instance = nullptr;
  const CellDef* cell = nullptr;
  const CellMap* cells = nullptr;
  std::set<std::string> vars;     ///< parameters and state parameters in scope
  std::map<std::string, Ty> args; ///< formals (read-only)
  std::map<std::string, const Event*> eventArgs;
  std::vector<std::map<std::string, Ty>> locals;
  std::set<std::string> loopVars;
  bool predicate = false;
  bool function = false;
  std::size_t functionIndex = 0; ///< of the function being checked (calls go to earlier ones)
};

class Checker
{
public:
  Checker(const Model& m, hf::DiagnosticSink& sink, const Limits& limits)
    : m_(m)
    , sink_(sink)
    , limits_(limits)
  {
  }

  void run()
  {
    for (const Timespan& t : m_.timespans)
    {
      declare(timespans_, t.name, &t, "time span");
      timespan(t);
    }
    for (const Event& e : m_.events)
    {
      declare(events_, e.name, &e, "event");
      event(e);
    }
    for (const CellDef& a : m_.animations)
    {
      declare(animations_, a.name, &a, "animation");
      animation(a);
    }
    if (!m_.cycles.text.empty() && m_.cycles.text != "previous" && m_.cycles.text != "reevaluate" &&
      m_.cycles.text != "cut")
    {
      err(m_.cycles.pos,
        "unknown cycle policy '" + m_.cycles.text + "' (previous, reevaluate or cut)");
    }
    for (const CellsSection& s : m_.cells)
    {
      for (const CellDef& c : s.defs)
      {
        declare(globalCells_, c.name, &c, "cell");
      }
    }
    allCells_ = globalCells_;
    for (const Instance& in : m_.instances)
    {
      for (const CellsSection& s : in.cells)
      {
        for (const CellDef& c : s.defs)
        {
          allCells_.emplace(c.name.text, &c);
        }
      }
    }
    for (const AttributesSection& s : m_.attributes)
    {
      collectAttributes(s, globalAttributes_);
    }
    for (const Instance& in : m_.instances)
    {
      declare(instances_, in.name, &in, in.isTemplate ? "template" : "instance");
    }
    for (const Procedure& f : m_.functions)
    {
      declare(functions_, f.name, &f, "function");
    }
    std::map<std::string, const ParamDecl*> globals;
    params(m_.parameters, globals, nullptr, "model parameter");
    params(m_.stateParameters, globals, nullptr, "state parameter");
    for (const auto& g : globals)
    {
      globalVars_.insert(g.first);
    }
    for (const CellsSection& s : m_.cells)
    {
      for (const Name& r : s.refs)
      {
        if (globalCells_.count(r.text) == 0)
        {
          err(r.pos, "undefined cell '" + r.text + "'");
        }
      }
      for (const Use& u : s.uses)
      {
        err(u.pos, "USE belongs in a template or an instance");
      }
      for (const CellDef& c : s.defs)
      {
        cell(c, globalCells_, nullptr);
      }
      for (const Procedure& r : s.reactions)
      {
        err(r.pos, "custom reactions of cells belong in an instance's CELLS");
      }
    }
    for (const AttributesSection& s : m_.attributes)
    {
      attributes(s, globalCells_, nullptr);
    }
    for (const Instance& in : m_.instances)
    {
      instance(in);
    }
    for (std::size_t i = 0; i < m_.functions.size(); ++i)
    {
      Code c;
      c.cells = &globalCells_;
      c.vars = globalVars_;
      c.function = true;
      c.functionIndex = i;
      procedure(m_.functions[i], c);
    }
  }

private:
  const Model& m_;
  hf::DiagnosticSink& sink_;
  const Limits& limits_;
  std::map<std::string, const Timespan*> timespans_;
  std::map<std::string, const CellDef*> animations_;
  std::map<std::string, const Event*> events_;
  CellMap globalCells_;
  std::map<std::string, const Instance*> instances_;
  std::map<std::string, const Procedure*> functions_;
  std::set<std::string> globalVars_;
  std::set<std::string> globalAttributes_;
  std::map<std::string, const CellDef*> allCells_; ///< global and instance cells, first wins
  // Memoised closures over USE, bases and '<-' (with guards against cycles).
  mutable std::map<const CellDef*, std::set<std::string>> paramsCache_;
  mutable std::set<const CellDef*> paramsBusy_;
  mutable std::map<const Instance*, CellMap> cellsCache_;
  mutable std::set<const Instance*> cellsBusy_;
  mutable std::map<const Instance*, std::set<std::string>> attributesCache_;
  mutable std::set<const Instance*> attributesBusy_;
  using RelationKey = std::pair<const Instance*, std::string>;
  mutable std::map<RelationKey, std::set<std::string>> relationsCache_;
  mutable std::set<RelationKey> relationsBusy_;

  void err(Pos p, const std::string& message) { sink_.error(p.line, p.column, message); }

  template <class T>
  bool declare(
    std::map<std::string, const T*>& table, const Name& n, const T* what, const std::string& kind)
  {
    const auto it = table.find(n.text);
    if (it != table.end())
    {
      err(n.pos,
        "duplicate " + kind + " '" + n.text + "' (first defined at " + lineOf(it->second->pos) +
          ")");
      return false;
    }
    table.emplace(n.text, what);
    return true;
  }

  // ---- declarations -------------------------------------------------------------------------
  void timespan(const Timespan& t)
  {
    std::size_t intervals = 0;
    std::vector<double> plain;
    for (const ExprPtr& a : t.args)
    {
      double v = 0;
      if (a->kind == Expr::Kind::Brace)
      {
        double lo = 0;
        double hi = 0;
        if (a->kids.size() != 2 || !constantNumber(a->kids[0], lo) ||
          !constantNumber(a->kids[1], hi))
        {
          err(a->pos, "an interval is '{start, end}' with two numbers");
        }
        else if (hi < lo)
        {
          err(a->pos, "the interval ends before it starts");
        }
        if (!plain.empty())
        {
          err(a->pos, "the time scale comes after the intervals");
        }
        ++intervals;
      }
      else if (constantNumber(a, v))
      {
        plain.push_back(v);
      }
      else
      {
        err(a->pos, "TIMESPAN takes numbers: (start, end [, scale]) or ({s, e}, ... [, scale])");
      }
    }
    if (intervals == 0 && !(plain.empty() || plain.size() == 2 || plain.size() == 3))
    {
      err(t.name.pos,
        "TIMESPAN takes (start, end [, scale]), found " + std::to_string(plain.size()) +
          " number(s)");
    }
    else if (intervals > 0 && plain.size() > 1)
    {
      err(t.name.pos, "after the intervals, TIMESPAN takes at most one number (the time scale)");
    }
    else if (intervals == 0 && plain.size() >= 2 && plain[1] < plain[0])
    {
      err(t.name.pos, "time span '" + t.name.text + "' ends before it starts");
    }
    if ((intervals == 0 && plain.size() == 3 && plain[2] <= 0) ||
      (intervals > 0 && plain.size() == 1 && plain[0] <= 0))
    {
      err(t.name.pos, "the time scale must be positive");
    }
  }

  // keys = {t, v} or {t, x, y, z}, ...; interpolation = step | linear | catmullrom | hermite;
  // before / after = constant | linear | loop | mirror.
  void animation(const CellDef& a)
  {
    if (!a.parameters.empty() || !a.reactions.empty() || !a.source.text.empty())
    {
      err(a.pos, "an animation has only the properties keys, interpolation, before and after");
    }
    bool hasKeys = false;
    for (const Property& p : a.properties)
    {
      if (p.name == "keys")
      {
        hasKeys = true;
        std::size_t width = 0;
        for (const ExprPtr& k : p.values)
        {
          if (k->kind != Expr::Kind::Brace || (k->kids.size() != 2 && k->kids.size() != 4))
          {
            err(k->pos, "a key is {time, value} or {time, x, y, z}");
            continue;
          }
          if (width != 0 && k->kids.size() != width)
          {
            err(k->pos, "every key of an animation has the same number of values");
          }
          width = k->kids.size();
          for (const ExprPtr& v : k->kids)
          {
            constant(v);
          }
        }
      }
      else if (p.name == "interpolation" || p.name == "before" || p.name == "after")
      {
        static const std::set<std::string> inKinds = { "step", "linear", "catmullrom", "hermite" };
        static const std::set<std::string> outKinds = { "constant", "linear", "loop", "mirror" };
        const auto& kinds = p.name == "interpolation" ? inKinds : outKinds;
        if (p.values.size() != 1 || p.values[0]->kind != Expr::Kind::Name ||
          kinds.count(p.values[0]->text) == 0)
        {
          err(p.pos,
            "unknown " + p.name + " (" +
              (p.name == "interpolation" ? "step, linear, catmullrom or hermite"
                                         : "constant, linear, loop or mirror") +
              ")");
        }
      }
      else
      {
        err(p.pos,
          "unknown animation property '" + p.name + "' (keys, interpolation, before, after)");
      }
    }
    if (!hasKeys)
    {
      err(a.pos, "the animation '" + a.name.text + "' has no keys");
    }
  }

  void event(const Event& e)
  {
    std::map<std::string, const ParamDecl*> ps;
    params(e.parameters, ps, nullptr, "event parameter");
    std::set<std::string> seen;
    for (const Property& p : e.properties)
    {
      if (!seen.insert(p.name).second)
      {
        err(p.pos, "property '" + p.name + "' given twice");
      }
      if (p.name == "priority")
      {
        priority(p);
      }
      else if (p.name == "timespan")
      {
        timespanRef(p);
      }
      else
      {
        err(p.pos, "unknown event property '" + p.name + "': priority or timespan");
      }
    }
  }

  void priority(const Property& p)
  {
    double v = 0;
    if (p.isHyperFun || p.values.size() != 1 || !constantNumber(p.values[0], v))
    {
      err(p.values.empty() ? p.pos : p.values[0]->pos, "the priority must be a number");
    }
  }

  void timespanRef(const Property& p)
  {
    if (p.isHyperFun || p.values.size() != 1 || p.values[0]->kind != Expr::Kind::Name)
    {
      err(p.pos, "timespan = the name of a time span");
    }
    else if (timespans_.count(p.values[0]->text) == 0)
    {
      err(p.values[0]->pos, "undefined time span '" + p.values[0]->text + "'");
    }
  }

  void params(const std::vector<ParamDecl>& ps, std::map<std::string, const ParamDecl*>& seen,
    const CellMap* cells, const std::string& kind,
    const std::set<std::string>* aliasRoots = nullptr)
  {
    for (const ParamDecl& p : ps)
    {
      if (p.kind == ParamDecl::Kind::Typed)
      {
        declare(seen, p.name, &p, kind);
        paramType(p);
      }
      else if (p.kind == ParamDecl::Kind::Init)
      {
        declare(seen, p.name, &p, kind);
        const std::string& n = p.name.text;
        if (n != "translation" && n != "rotation" && n != "scale")
        {
          err(
            p.name.pos, "unknown predefined parameter '" + n + "': translation, rotation or scale");
        }
        else if (!(p.args.size() == 3 || (n == "scale" && p.args.size() == 1)))
        {
          err(p.name.pos,
            "'" + n + "' takes 3 numbers" + (n == "scale" ? " (or 1)" : "") + ", found " +
              std::to_string(p.args.size()));
        }
        for (const ExprPtr& a : p.args)
        {
          constant(a);
        }
      }
      else if (p.kind == ParamDecl::Kind::Alias)
      {
        declare(seen, p.name, &p, kind);
        const Expr* root = p.alias.get();
        while (!root->kids.empty())
        {
          root = root->kids[0].get();
        }
        const bool known = (cells && cells->count(root->text) > 0) ||
          (aliasRoots && aliasRoots->count(root->text) > 0) || globalVars_.count(root->text) > 0;
        if (!known)
        {
          err(root->pos, "undefined name '" + root->text + "' in the alias");
        }
        else if (cells && cells->count(root->text) > 0)
        {
          cellMember(*p.alias, *cells);
        }
      }
    }
  }

  void paramType(const ParamDecl& p)
  {
    static const std::map<std::string, int> types = { { "REAL", 1 }, { "real", 1 }, { "INT", 1 },
      { "int", 1 }, { "BOOL", 1 }, { "bool", 1 }, { "VECTOR2", 2 }, { "VECTOR3", 3 }, { "vec3", 3 },
      { "VECTOR4", 4 }, { "STRING", 1 }, { "string", 1 }, { "TRANSFORM", 0 } };
    const auto it = types.find(p.type.text);
    if (it == types.end())
    {
      err(p.type.pos,
        "unknown parameter type '" + p.type.text +
          "': REAL, INT, BOOL, VECTOR2, VECTOR3, VECTOR4, STRING or TRANSFORM");
      return;
    }
    if (p.array)
    {
      if (!p.args.empty())
      {
        err(p.type.pos, "an array parameter starts empty: no initial value");
      }
      return;
    }
    const int want = it->second;
    if (!p.args.empty() && static_cast<int>(p.args.size()) != want)
    {
      err(p.type.pos,
        p.type.text + " takes " + std::to_string(want) + " value(s), found " +
          std::to_string(p.args.size()));
    }
    const bool isBool = p.type.text == "BOOL" || p.type.text == "bool";
    const bool isString = p.type.text == "STRING" || p.type.text == "string";
    for (const ExprPtr& a : p.args)
    {
      if (isBool)
      {
        if (a->kind != Expr::Kind::Bool)
        {
          err(a->pos, "a BOOL is true or false");
        }
      }
      else if (isString)
      {
        if (a->kind != Expr::Kind::String)
        {
          err(a->pos, "a STRING is a quoted text");
        }
      }
      else
      {
        constant(a);
      }
    }
  }

  // A constant in a declaration: numbers, + - * /, pi and vec3(...).
  void constant(const ExprPtr& e)
  {
    switch (e->kind)
    {
      case Expr::Kind::Number:
        return;
      case Expr::Kind::Name:
        if (e->text != "pi")
        {
          err(e->pos, "expected a constant, found '" + e->text + "'");
        }
        return;
      case Expr::Kind::Unary:
      case Expr::Kind::Binary:
        if (e->text == "!" || e->text == "&&" || e->text == "||")
        {
          err(e->pos, "expected a number");
        }
        for (const ExprPtr& k : e->kids)
        {
          constant(k);
        }
        return;
      case Expr::Kind::Call:
        if (e->text == "vec3" && e->kids.size() == 4)
        {
          for (std::size_t i = 1; i < e->kids.size(); ++i)
          {
            constant(e->kids[i]);
          }
          return;
        }
        err(e->pos, "expected a constant (numbers, + - * /, pi, vec3(x, y, z))");
        return;
      default:
        err(e->pos, "expected a constant number");
    }
  }

  // ---- cells --------------------------------------------------------------------------------
  // Memoised: a model may have many cells copied from one another.
  const std::set<std::string>& paramsOf(const CellDef* c, int depth = 0) const
  {
    static const std::set<std::string> none;
    if (!c || depth > 64)
    {
      return none;
    }
    const auto it = paramsCache_.find(c);
    if (it != paramsCache_.end())
    {
      return it->second;
    }
    if (!paramsBusy_.insert(c).second)
    {
      return none; // a cycle of '<-'
    }
    std::set<std::string> out = paramsOfImpl(c, depth);
    paramsBusy_.erase(c);
    return paramsCache_.emplace(c, std::move(out)).first->second;
  }

  std::set<std::string> paramsOfImpl(const CellDef* c, int depth) const
  {
    std::set<std::string> out;
    for (const ParamDecl& p : c->parameters)
    {
      out.insert(p.name.text);
    }
    if (!c->source.text.empty())
    {
      const auto found = allCells_.find(c->source.text);
      const CellDef* src = found == allCells_.end() ? nullptr : found->second;
      if (src != c)
      {
        for (const std::string& s : paramsOf(src, depth + 1))
        {
          out.insert(s);
        }
      }
    }
    return out;
  }

  /// `Cell.member...`: the first member must be a parameter or a property of the cell.
  void cellMember(const Expr& path, const CellMap& cells)
  {
    // Find the member right after the root.
    const Expr* e = &path;
    const Expr* first = nullptr;
    while (!e->kids.empty())
    {
      if (e->kind == Expr::Kind::Member)
      {
        first = e;
      }
      else
      {
        first = nullptr; // an index right after the root
      }
      e = e->kids[0].get();
    }
    const auto it = cells.find(e->text);
    if (first == nullptr || it == cells.end() || it->second == nullptr)
    {
      return;
    }
    if (first->kids[0].get() != e)
    {
      return;
    }
    if (cellProperties().count(first->text) == 0 && paramsOf(it->second).count(first->text) == 0)
    {
      err(first->pos, "cell '" + e->text + "' has no parameter '" + first->text + "'");
    }
  }

  void cell(const CellDef& c, const CellMap& cells, const Instance* in)
  {
    if (!c.source.text.empty())
    {
      if (c.source.text == c.name.text)
      {
        err(c.source.pos, "cell '" + c.name.text + "' cannot be a copy of itself");
      }
      else if (cells.count(c.source.text) == 0 && globalCells_.count(c.source.text) == 0)
      {
        err(c.source.pos, "undefined cell '" + c.source.text + "' after '<-'");
      }
      else
      {
        // The chain of copies must not come back to this cell.
        const CellDef* x = &c;
        for (int step = 0; step < 64 && x && !x->source.text.empty(); ++step)
        {
          const auto it = allCells_.find(x->source.text);
          x = it == allCells_.end() ? nullptr : it->second;
          if (x == &c)
          {
            err(c.source.pos,
              "cell '" + c.name.text + "' is a copy of itself (through '" + c.source.text + "')");
            break;
          }
        }
      }
    }
    std::set<std::string> seen;
    for (const Property& p : c.properties)
    {
      if (!seen.insert(p.name).second)
      {
        err(p.pos, "property '" + p.name + "' given twice");
      }
      property(p, cells);
    }
    std::map<std::string, const ParamDecl*> ps;
    params(c.parameters, ps, &cells, "parameter");
    reactionsOf(c.reactions, cells, in, &c);
  }

  void property(const Property& p, const CellMap& cells)
  {
    const auto single = [&](Expr::Kind kind, const char* what)
    {
      if (p.isHyperFun || p.values.size() != 1 || p.values[0]->kind != kind)
      {
        err(p.values.empty() ? p.pos : start(*p.values[0]), std::string(what));
        return false;
      }
      return true;
    };
    if (p.name == "type")
    {
      single(Expr::Kind::CellType, "type = P-CELL, F-CELL, C-CELL, B-CELL or T-CELL");
    }
    else if (p.name == "dim")
    {
      single(Expr::Kind::Dim, "dim = 0D, 1D, 2D, 3D or 4D");
    }
    else if (p.name == "priority")
    {
      priority(p);
    }
    else if (p.name == "timespan")
    {
      timespanRef(p);
    }
    else if (p.name == "lifespan")
    {
      if (p.values.size() == 1 && p.values[0]->kind == Expr::Kind::Name)
      {
        timespanRef(p);
        return;
      }
      for (const ExprPtr& v : p.values)
      {
        double lo = 0;
        double hi = 0;
        if (v->kind != Expr::Kind::Brace || v->kids.size() != 2 ||
          !constantNumber(v->kids[0], lo) || !constantNumber(v->kids[1], hi))
        {
          err(v->pos, "lifespan = a time span name or intervals '{start, end}, {start, end}'");
        }
        else if (hi < lo)
        {
          err(v->pos, "the interval ends before it starts");
        }
      }
    }
    else if (p.name == "domain")
    {
      if (!single(Expr::Kind::Brace,
            "domain = { xmin, ymin, xmax, ymax } or { xmin, ymin, zmin, xmax, ymax, zmax }"))
      {
        return;
      }
      const ExprPtr& b = p.values[0];
      std::vector<double> v;
      for (const ExprPtr& k : b->kids)
      {
        double x = 0;
        if (!constantNumber(k, x))
        {
          err(k->pos, "the domain's bounds are numbers");
          return;
        }
        v.push_back(x);
      }
      if (v.size() != 4 && v.size() != 6)
      {
        err(b->pos, "a domain has 4 numbers (2D) or 6 (3D), found " + std::to_string(v.size()));
        return;
      }
      const std::size_t n = v.size() / 2;
      for (std::size_t i = 0; i < n; ++i)
      {
        if (v[i] > v[i + n])
        {
          err(b->kids[i]->pos, "the domain's minimum is above its maximum");
        }
      }
    }
    else if (p.name == "shape")
    {
      if (p.isHyperFun)
      {
        if (p.hyperFunText.find_first_not_of(" \t\r\n") == std::string::npos)
        {
          err(p.pos, "empty hyperfun block");
          return;
        }
        hyperFun(p);
        return;
      }
      for (const ExprPtr& v : p.values)
      {
        shape(v, cells);
      }
    }
    else if (p.name == "mapping" && p.isHyperFun)
    {
      // an attribute function written in HyperFun
      hyperFun(p);
    }
    else if (p.name == "mapping" || p.name == "deformation")
    {
      for (const ExprPtr& v : p.values)
      {
        if (v->kind == Expr::Kind::Call && v->text == "file")
        {
          shape(v, cells);
        }
        else if (v->kind != Expr::Kind::Name && v->kind != Expr::Kind::String)
        {
          err(v->pos, p.name + " = the name of an external mapping, a string or file(\"...\")");
        }
      }
    }
    else
    {
      err(p.pos,
        "unknown property '" + p.name +
          "': type, shape, dim, domain, lifespan, priority, timespan, mapping or deformation");
    }
  }

  // Compiles an inline HyperFun shape; its errors are placed in the model text.
  void hyperFun(const Property& p)
  {
    try
    {
      (void)readHyperFun(p.hyperFunText, m_.fileName, {}, limits_);
    }
    catch (const ParseError& e)
    {
      for (const Diagnostic& d : e.diagnostics())
      {
        Pos at = p.hyperFunPos;
        if (d.where.line > 1)
        {
          at.line += d.where.line - 1;
          at.column = d.where.column;
        }
        else if (d.where.line == 1)
        {
          at.column += d.where.column - 1;
        }
        else
        {
          at = p.pos;
        }
        err(at, "in the hyperfun shape: " + d.message);
      }
    }
  }

  void shape(const ExprPtr& v, const CellMap& cells)
  {
    if (v->kind != Expr::Kind::Call || v->text.empty())
    {
      err(v->pos,
        "shape = hyperfun { ... }, file(\"model.hf\") or a shape constructor such as "
        "disk(r)");
      return;
    }
    const Signature* b = findShapeBuiltin(v->text);
    const int n = static_cast<int>(v->kids.size()) - 1;
    if (!b)
    {
      err(v->pos, "unknown shape constructor '" + v->text + "'");
      return;
    }
    if (n < b->minArgs || (b->maxArgs >= 0 && n > b->maxArgs))
    {
      err(v->pos,
        "'" + v->text + "' takes " + arity(*b) + " argument(s) (" + b->signature + "), found " +
          std::to_string(n));
      return;
    }
    if (v->text == "file")
    {
      const ExprPtr& a = v->kids[1];
      if (a->kind != Expr::Kind::String)
      {
        err(a->pos, "file(\"path\") takes a quoted path");
        return;
      }
      const std::string& path = a->text;
      const auto dot = path.rfind('.');
      const std::string ext = dot == std::string::npos ? std::string() : path.substr(dot);
      if (ext != ".hf" && ext != ".xml" && ext != ".obj" && ext != ".off")
      {
        err(a->pos, "file \"" + path + "\": the shape files are .hf, .xml, .obj or .off");
      }
      return;
    }
    if (v->text == "blend" || v->text == "union")
    {
      for (std::size_t i = 1; i <= 2; ++i)
      {
        const ExprPtr& a = v->kids[i];
        if (a->kind != Expr::Kind::Name ||
          (cells.count(a->text) == 0 && globalCells_.count(a->text) == 0))
        {
          err(a->pos,
            a->kind == Expr::Kind::Name ? "undefined cell '" + a->text + "'"
                                        : "expected a cell name");
        }
      }
      if (v->kids.size() > 3)
      {
        constant(v->kids[3]);
      }
      return;
    }
    for (std::size_t i = 1; i < v->kids.size(); ++i)
    {
      constant(v->kids[i]);
    }
  }

  static std::string arity(const Signature& b)
  {
    if (b.maxArgs < 0)
    {
      return "at least " + std::to_string(b.minArgs);
    }
    if (b.minArgs == b.maxArgs)
    {
      return std::to_string(b.minArgs);
    }
    return std::to_string(b.minArgs) + " to " + std::to_string(b.maxArgs);
  }

  // ---- attributes ---------------------------------------------------------------------------
  void collectAttributes(const AttributesSection& s, std::set<std::string>& out) const
  {
    for (const auto& b : s.bindings)
    {
      out.insert(b.first.text);
    }
    for (const CellDef& d : s.defs)
    {
      out.insert(d.name.text);
    }
  }

  void attributesOf(const Instance& in, std::set<std::string>& out, int depth) const
  {
    const auto it = attributesCache_.find(&in);
    if (it != attributesCache_.end())
    {
      out.insert(it->second.begin(), it->second.end());
      return;
    }
    if (depth > 64 || !attributesBusy_.insert(&in).second)
    {
      return;
    }
    std::set<std::string> mine;
    attributesOfImpl(in, mine, depth);
    attributesBusy_.erase(&in);
    out.insert(mine.begin(), mine.end());
    attributesCache_.emplace(&in, std::move(mine));
  }

  void attributesOfImpl(const Instance& in, std::set<std::string>& out, int depth) const
  {
    for (const AttributesSection& s : in.attributes)
    {
      collectAttributes(s, out);
      for (const Use& u : s.uses)
      {
        const Instance* t = useTarget(u);
        if (t && t != &in)
        {
          attributesOf(*t, out, depth + 1);
        }
      }
    }
    for (const CellsSection& c : in.cells)
    {
      for (const AttributesSection& s : c.attributes)
      {
        collectAttributes(s, out);
      }
    }
    if (!in.base.text.empty())
    {
      const auto it = instances_.find(in.base.text);
      if (it != instances_.end() && it->second != &in)
      {
        attributesOf(*it->second, out, depth + 1);
      }
    }
  }

  void attributes(const AttributesSection& s, const CellMap& cells, const Instance* in)
  {
    std::set<std::string> known = globalAttributes_;
    if (in)
    {
      attributesOf(*in, known, 0);
    }
    std::map<std::string, Pos> local;
    const auto add = [&](const Name& n)
    {
      const auto it = local.find(n.text);
      if (it != local.end())
      {
        err(n.pos,
          "duplicate attribute '" + n.text + "' (first defined at " + lineOf(it->second) + ")");
      }
      local.emplace(n.text, n.pos);
    };
    for (const auto& b : s.bindings)
    {
      add(b.first);
    }
    for (const CellDef& d : s.defs)
    {
      add(d.name);
      std::set<std::string> seen;
      for (const Property& p : d.properties)
      {
        if (!seen.insert(p.name).second)
        {
          err(p.pos, "property '" + p.name + "' given twice");
        }
        if (p.name == "mapping" || p.name == "dim" || p.name == "priority" ||
          p.name == "lifespan" || p.name == "timespan")
        {
          property(p, cells);
        }
        else
        {
          err(p.pos,
            "unknown attribute property '" + p.name +
              "': mapping, dim, lifespan, "
              "priority or timespan");
        }
      }
    }
    for (const Use& u : s.uses)
    {
      use(u, "ATTRIBUTES", in);
    }
    if (!s.defaultAttribute.text.empty() && known.count(s.defaultAttribute.text) == 0)
    {
      err(s.defaultAttribute.pos, "undefined attribute '" + s.defaultAttribute.text + "'");
    }
    for (const Relation& r : s.links)
    {
      const ExprPtr& c = r.ends[0];
      const Expr* root = c.get();
      while (!root->kids.empty())
      {
        root = root->kids[0].get();
      }
      if (cells.count(root->text) == 0)
      {
        err(root->pos, "undefined cell '" + root->text + "'");
      }
      else if (c->kind == Expr::Kind::Member && c->text != "attributes")
      {
        err(c->pos, "an attribute link is 'Cell attr;' or 'Cell.attributes = attr;'");
      }
      if (known.count(r.ends[1]->text) == 0)
      {
        err(r.ends[1]->pos, "undefined attribute '" + r.ends[1]->text + "'");
      }
    }
    reactionsOf(s.reactions, cells, in, nullptr);
  }

  // ---- templates and instances --------------------------------------------------------------
  const Instance* useTarget(const Use& u) const
  {
    const Expr* root = u.what.get();
    while (!root->kids.empty())
    {
      root = root->kids[0].get();
    }
    const auto it = instances_.find(root->text);
    return it == instances_.end() ? nullptr : it->second;
  }

  // The cells of an instance: its base template's, USEd ones, listed ones and its own.
  void cellsOf(const Instance& in, CellMap& out, int depth) const
  {
    const auto it = cellsCache_.find(&in);
    if (it != cellsCache_.end())
    {
      out.insert(it->second.begin(), it->second.end());
      return;
    }
    if (depth > 64 || !cellsBusy_.insert(&in).second)
    {
      return; // a cycle of USE or bases
    }
    CellMap mine;
    cellsOfImpl(in, mine, depth);
    cellsBusy_.erase(&in);
    out.insert(mine.begin(), mine.end());
    cellsCache_.emplace(&in, std::move(mine));
  }

  void cellsOfImpl(const Instance& in, CellMap& out, int depth) const
  {
    if (!in.base.text.empty())
    {
      const auto it = instances_.find(in.base.text);
      if (it != instances_.end() && it->second != &in)
      {
        cellsOf(*it->second, out, depth + 1);
      }
    }
    for (const CellsSection& s : in.cells)
    {
      for (const Use& u : s.uses)
      {
        const Instance* t = useTarget(u);
        if (!t || t == &in)
        {
          continue;
        }
        CellMap used;
        cellsOf(*t, used, depth + 1);
        for (const Name& n : u.minus)
        {
          used.erase(n.text);
        }
        for (const Name& n : u.plus)
        {
          const auto g = globalCells_.find(n.text);
          used.emplace(n.text, g == globalCells_.end() ? nullptr : g->second);
        }
        out.insert(used.begin(), used.end());
      }
      for (const Name& r : s.refs)
      {
        const auto g = globalCells_.find(r.text);
        if (g != globalCells_.end())
        {
          out.emplace(r.text, g->second);
        }
      }
      for (const CellDef& d : s.defs)
      {
        out.emplace(d.name.text, &d);
      }
    }
  }

  // Relation names of an instance's section ("dependency", "containment", "boundary").
  void relationNames(
    const Instance& in, const std::string& section, std::set<std::string>& out, int depth) const
  {
    const auto key = std::make_pair(&in, section);
    const auto it = relationsCache_.find(key);
    if (it != relationsCache_.end())
    {
      out.insert(it->second.begin(), it->second.end());
      return;
    }
    if (depth > 64 || !relationsBusy_.insert(key).second)
    {
      return;
    }
    std::set<std::string> mine;
    relationNamesImpl(in, section, mine, depth);
    relationsBusy_.erase(key);
    out.insert(mine.begin(), mine.end());
    relationsCache_.emplace(key, std::move(mine));
  }

  void relationNamesImpl(
    const Instance& in, const std::string& section, std::set<std::string>& out, int depth) const
  {
    for (const RelationsSection& s : in.relations)
    {
      const std::vector<Relation>& rs = section == "dependency" ? s.dependency
        : section == "containment"                              ? s.containment
                                                                : s.boundary;
      for (const Relation& r : rs)
      {
        if (!r.name.text.empty())
        {
          out.insert(r.name.text);
        }
      }
      const std::vector<Use>& us = section == "dependency" ? s.dependencyUses
        : section == "containment"                         ? s.containmentUses
                                                           : s.boundaryUses;
      for (const Use& u : us)
      {
        const Instance* t = useTarget(u);
        if (t && t != &in)
        {
          relationNames(*t, section, out, depth + 1);
        }
      }
    }
    if (!in.base.text.empty())
    {
      const auto it = instances_.find(in.base.text);
      if (it != instances_.end() && it->second != &in)
      {
        relationNames(*it->second, section, out, depth + 1);
      }
    }
  }

  // The instances that `in` takes something from (its base and its USE targets).
  std::vector<const Instance*> sources(const Instance& in) const
  {
    std::vector<const Instance*> out;
    const auto add = [&](const Use& u)
    {
      if (const Instance* t = useTarget(u))
      {
        out.push_back(t);
      }
    };
    if (!in.base.text.empty())
    {
      const auto it = instances_.find(in.base.text);
      if (it != instances_.end())
      {
        out.push_back(it->second);
      }
    }
    for (const CellsSection& s : in.cells)
    {
      for (const Use& u : s.uses)
      {
        add(u);
      }
      for (const AttributesSection& a : s.attributes)
      {
        for (const Use& u : a.uses)
        {
          add(u);
        }
      }
    }
    for (const RelationsSection& s : in.relations)
    {
      for (const auto* us : { &s.containmentUses, &s.boundaryUses, &s.dependencyUses })
      {
        for (const Use& u : *us)
        {
          add(u);
        }
      }
    }
    for (const AttributesSection& a : in.attributes)
    {
      for (const Use& u : a.uses)
      {
        add(u);
      }
    }
    return out;
  }

  // Whether `target` is reachable from `from` through bases and USE.
  bool reaches(const Instance* from, const Instance* target) const
  {
    std::set<const Instance*> seen;
    std::vector<const Instance*> todo = { from };
    while (!todo.empty())
    {
      const Instance* x = todo.back();
      todo.pop_back();
      if (x == target)
      {
        return true;
      }
      if (seen.insert(x).second)
      {
        for (const Instance* y : sources(*x))
        {
          todo.push_back(y);
        }
      }
    }
    return false;
  }

  // USE T.CELLS / T.ATTRIBUTES / T.RELATIONS.<section>.
  void use(const Use& u, const std::string& section, const Instance* in)
  {
    std::vector<const Expr*> chain;
    for (const Expr* e = u.what.get(); e; e = e->kids.empty() ? nullptr : e->kids[0].get())
    {
      chain.insert(chain.begin(), e);
    }
    const Expr* root = chain.front();
    const auto it = instances_.find(root->text);
    if (it == instances_.end())
    {
      err(root->pos, "undefined template or instance '" + root->text + "'");
      return;
    }
    const Instance& t = *it->second;
    if (&t == in)
    {
      err(root->pos, "'" + root->text + "' cannot USE itself");
      return;
    }
    if (in && reaches(&t, in))
    {
      err(root->pos, "USE cycle: '" + root->text + "' takes from '" + in->name.text + "'");
      return;
    }
    std::string want = root->text + "." + section;
    std::string got = root->text;
    for (std::size_t i = 1; i < chain.size(); ++i)
    {
      got += chain[i]->kind == Expr::Kind::Member ? "." + chain[i]->text : "[...]";
    }
    if (section == "RELATIONS.dependency" && chain.size() == 3 && chain[1]->text == "Rd" &&
      chain[2]->kind == Expr::Kind::Index)
    {
      // USE inst.Rd[cellA, cellB]: the unnamed dependencies between two cells of inst.
      CellMap cs;
      cellsOf(t, cs, 0);
      const Expr& ix = *chain[2];
      if (ix.kids.size() != 3)
      {
        err(ix.pos, "Rd[cellA, cellB] names two cells");
      }
      for (std::size_t i = 1; i < ix.kids.size(); ++i)
      {
        if (ix.kids[i]->kind != Expr::Kind::Name || cs.count(ix.kids[i]->text) == 0)
        {
          err(ix.kids[i]->pos, "'" + ix.kids[i]->text + "' is not a cell of " + root->text);
        }
      }
      return;
    }
    if (got != want)
    {
      err(root->pos, "expected USE " + want + ", found " + got);
      return;
    }
    std::set<std::string> names;
    std::string what;
    if (section == "CELLS")
    {
      CellMap cs;
      cellsOf(t, cs, 0);
      for (const auto& c : cs)
      {
        names.insert(c.first);
      }
      what = "a cell of";
    }
    else if (section == "ATTRIBUTES")
    {
      attributesOf(t, names, 0);
      what = "an attribute of";
    }
    else
    {
      relationNames(t, section.substr(section.find('.') + 1), names, 0);
      what = "a named relation of";
    }
    for (const Name& n : u.minus)
    {
      if (names.count(n.text) == 0)
      {
        err(n.pos, "'" + n.text + "' is not " + what + " " + root->text);
      }
    }
    if (section == "CELLS")
    {
      for (const Name& n : u.plus)
      {
        if (globalCells_.count(n.text) == 0)
        {
          err(n.pos, "undefined cell '" + n.text + "'");
        }
      }
    }
  }

  void instance(const Instance& in)
  {
    if (!in.base.text.empty())
    {
      const auto it = instances_.find(in.base.text);
      if (it == instances_.end())
      {
        err(in.base.pos, "undefined template '" + in.base.text + "'");
      }
      else if (!it->second->isTemplate)
      {
        err(in.base.pos, "'" + in.base.text + "' is an instance, not a template");
      }
      else if (reaches(it->second, &in))
      {
        err(
          in.base.pos, "cycle: template '" + in.base.text + "' takes from '" + in.name.text + "'");
      }
    }
    CellMap cells;
    cellsOf(in, cells, 0);
    // Cells listed, defined and used.
    std::map<std::string, Pos> listed;
    CellMap inherited;
    if (!in.base.text.empty())
    {
      const auto it = instances_.find(in.base.text);
      if (it != instances_.end() && it->second != &in)
      {
        cellsOf(*it->second, inherited, 0);
      }
    }
    // Parameters.
    std::map<std::string, const ParamDecl*> vars;
    params(in.parameters, vars, &cells, "parameter");
    std::set<std::string> roots;
    for (const auto& v : vars)
    {
      roots.insert(v.first);
    }
    std::map<std::string, const ParamDecl*> state;
    params(in.stateParameters, state, &cells, "state parameter", &roots);
    for (const auto& s : state)
    {
      if (globalVars_.count(s.first) > 0)
      {
        err(s.second->name.pos,
          "duplicate state parameter '" + s.first + "' (also a model-wide state parameter)");
      }
      if (vars.count(s.first) > 0 && s.second->kind != ParamDecl::Kind::Alias)
      {
        err(s.second->name.pos, "'" + s.first + "' is already a parameter of " + in.name.text);
      }
    }
    std::set<std::string> scope = globalVars_;
    for (const auto& v : vars)
    {
      scope.insert(v.first);
    }
    for (const auto& v : state)
    {
      scope.insert(v.first);
    }
    instanceVars_ = scope;
    for (const CellsSection& s : in.cells)
    {
      for (const Use& u : s.uses)
      {
        use(u, "CELLS", &in);
      }
    }
    for (const CellsSection& s : in.cells)
    {
      for (const Name& r : s.refs)
      {
        if (globalCells_.count(r.text) == 0)
        {
          err(r.pos, "undefined cell '" + r.text + "'");
        }
        else if (!listed.emplace(r.text, r.pos).second || inherited.count(r.text) > 0)
        {
          err(r.pos, "cell '" + r.text + "' is already in " + in.name.text);
        }
      }
      for (const CellDef& d : s.defs)
      {
        const auto g = globalCells_.find(d.name.text);
        if (g != globalCells_.end())
        {
          err(d.name.pos,
            "duplicate cell '" + d.name.text + "' (first defined at " + lineOf(g->second->pos) +
              ")");
        }
        else if (!listed.emplace(d.name.text, d.name.pos).second)
        {
          err(d.name.pos, "cell '" + d.name.text + "' is already in " + in.name.text);
        }
        cell(d, cells, &in);
      }
      reactionsOf(s.reactions, cells, &in, nullptr);
      for (const AttributesSection& a : s.attributes)
      {
        attributes(a, cells, &in);
      }
    }
    // Relations.
    std::map<std::string, Pos> relationNames;
    std::set<std::string> attrs = globalAttributes_;
    attributesOf(in, attrs, 0);
    for (const RelationsSection& s : in.relations)
    {
      for (const Use& u : s.containmentUses)
      {
        use(u, "RELATIONS.containment", &in);
      }
      for (const Use& u : s.boundaryUses)
      {
        use(u, "RELATIONS.boundary", &in);
      }
      for (const Use& u : s.dependencyUses)
      {
        use(u, "RELATIONS.dependency", &in);
      }
      for (const auto* rs : { &s.containment, &s.boundary, &s.dependency })
      {
        const bool dependency = rs == &s.dependency;
        for (const Relation& r : *rs)
        {
          relation(r, dependency, cells, attrs);
          if (!r.name.text.empty())
          {
            const auto it = relationNames.find(r.name.text);
            if (it != relationNames.end())
            {
              err(r.name.pos,
                "duplicate relation '" + r.name.text + "' (first defined at " + lineOf(it->second) +
                  ")");
            }
            relationNames.emplace(r.name.text, r.name.pos);
          }
        }
      }
    }
    for (const AttributesSection& a : in.attributes)
    {
      attributes(a, cells, &in);
    }
    // Code.
    reactionsOf(in.reactions, cells, &in, nullptr);
    std::size_t predicates = 0;
    for (const Procedure& p : in.predicates)
    {
      if (++predicates == 2)
      {
        err(p.pos,
          (in.isTemplate ? "template '" : "instance '") + in.name.text +
            "' has more than one predicate");
      }
      Code c;
      c.instance = &in;
      c.cells = &cells;
      c.vars = scope;
      c.predicate = true;
      procedure(p, c);
    }
    instanceVars_.clear();
  }

  std::set<std::string> instanceVars_;

  void relation(
    const Relation& r, bool dependency, const CellMap& cells, const std::set<std::string>& attrs)
  {
    std::string texts[2];
    for (int i = 0; i < 2; ++i)
    {
      const ExprPtr& e = r.ends[static_cast<std::size_t>(i)];
      const Expr* root = e.get();
      while (!root->kids.empty())
      {
        root = root->kids[0].get();
      }
      if (cells.count(root->text) > 0)
      {
        if (dependency)
        {
          cellMember(*e, cells);
        }
      }
      else if (!(dependency && attrs.count(root->text) > 0))
      {
        err(root->pos,
          "undefined cell '" + root->text + "' in a " +
            std::string(dependency ? "dependency" : "relation") + " (not in this instance)");
      }
      texts[i] = pathText(*e);
    }
    if (texts[0] == texts[1])
    {
      err(r.pos,
        dependency ? "'" + texts[0] + "' cannot depend on itself"
                   : "a cell cannot be related to itself");
    }
    if (r.hasPriority && r.priority <= 0)
    {
      err(r.pos, "a dependency's priority must be positive");
    }
  }

  static std::string pathText(const Expr& e)
  {
    if (e.kind == Expr::Kind::Member)
    {
      return pathText(*e.kids[0]) + "." + e.text;
    }
    if (e.kind == Expr::Kind::Index)
    {
      return pathText(*e.kids[0]) + "[" + e.kids[1]->text + "]";
    }
    return e.text;
  }

  // ---- code ---------------------------------------------------------------------------------
  void reactionsOf(const std::vector<Procedure>& rs, const CellMap& cells, const Instance* in,
    const CellDef* owner)
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

  void procedure(const Procedure& p, Code& c)
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

  static bool returns(const std::vector<StmtPtr>& body)
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

  void statements(const std::vector<StmtPtr>& body, Code& c)
  {
    for (const StmtPtr& s : body)
    {
      statement(*s, c);
    }
  }

  bool isLocal(const Code& c, const std::string& n, Ty* t = nullptr) const
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

  void statement(const Stmt& s, Code& c)
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
          err(s.pos, "unknown type '" + s.type + "': real, int, bool, vec3 or string");
        }
        const Ty v = expr(s.value, c);
        if (t != Ty::Unknown && !assignable(t, v))
        {
          err(
            s.value->pos, std::string("cannot initialise a ") + tyName(t) + " with a " + tyName(v));
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

  void bound(const ExprPtr& e, Code& c)
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

  static bool assignable(Ty to, Ty from)
  {
    return from == Ty::Unknown || to == Ty::Unknown || to == from ||
      (to == Ty::Real && from == Ty::Int);
  }

  void assign(const Stmt& s, Code& c)
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

  Ty name(const Expr& e, Code& c)
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

  Ty expr(const ExprPtr& ep, Code& c)
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
                err(
                  e.pos, "event '" + ev->second->name.text + "' has no parameter '" + e.text + "'");
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

  Ty member(const Expr& e, Ty of)
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

  Ty binary(const Expr& e, Code& c)
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
            (op.size() == 1 && op != "<" && op != ">" ? std::string(" or vectors")
                                                      : std::string()) +
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

  Ty call(const Expr& e, Code& c)
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
    std::string fn = e.text;
    if (fn.rfind("IC::", 0) == 0)
    {
      fn = fn.substr(4);
    }
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
    else if (sig.find("(cell,") != std::string::npos)
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
      else if (i > cellArgs && t == Ty::Cell)
      {
        err(e.kids[i]->pos,
          "argument " + std::to_string(i) + " of '" + fn + "' is a value, not a cell (" +
            b->signature + ")");
      }
    }
    return resultType(b->result);
  }
};

} // namespace

void checkIcm(const IcmModel& model, const std::string& text, std::vector<Diagnostic>& out,
  const Limits& limits)
{
  hf::SourceText source(text, model.fileName);
  hf::DiagnosticSink sink(source, limits.maxDiagnostics > 0 ? limits.maxDiagnostics : 1);
  Checker checker(model, sink, limits);
  checker.run();
  for (Diagnostic& d : sink.diagnostics())
  {
    out.push_back(std::move(d));
  }
}

} // namespace ictk::lang
