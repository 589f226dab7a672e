// SPDX-License-Identifier: BSD-3-Clause
// Semantic checks of an IC model: names (undefined, duplicate), relation ends, properties,
// USE targets, reaction and predicate signatures, and the code of reactions, predicates and
// functions (scopes, types where they are known, the built-in library and its argument counts,
// loop bounds). This file holds the walk over the model and the checks of its declarations; the
// others are in IcmCheckStructure.cxx, IcmCheckInstances.cxx and IcmCheckCode.cxx (IcmChecker.h).
#include "Lang/IcmChecker.h"

namespace ictk::lang::icmcheck
{

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

bool valueType(const std::string& s, Ty& t)
{
  static const std::map<std::string, Ty> types = { { "real", Ty::Real }, { "REAL", Ty::Real },
    { "int", Ty::Int }, { "INT", Ty::Int }, { "bool", Ty::Bool }, { "BOOL", Ty::Bool },
    { "vec3", Ty::Vec3 }, { "VEC3", Ty::Vec3 }, { "VECTOR3", Ty::Vec3 }, { "string", Ty::String },
    { "STRING", Ty::String }, { "shape", Ty::Shape }, { "SHAPE", Ty::Shape } };
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

const std::set<std::string>& cellProperties()
{
  static const std::set<std::string> p = { "translation", "rotation", "scale", "transform", "shape",
    "domain", "curDomain", "center", "dim", "type", "lifespan", "priority", "attributes",
    "radius" };
  return p;
}

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

void Checker::run()
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
    err(
      m_.cycles.pos, "unknown cycle policy '" + m_.cycles.text + "' (previous, reevaluate or cut)");
  }
  if (!m_.steps.text.empty() && m_.steps.text != "keep" && m_.steps.text != "grow")
  {
    err(m_.steps.pos, "unknown step policy '" + m_.steps.text + "' (keep or grow)");
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

void Checker::timespan(const Timespan& t)
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
      if (a->kids.size() != 2 || !constantNumber(a->kids[0], lo) || !constantNumber(a->kids[1], hi))
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

void Checker::animation(const CellDef& a)
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
      err(
        p.pos, "unknown animation property '" + p.name + "' (keys, interpolation, before, after)");
    }
  }
  if (!hasKeys)
  {
    err(a.pos, "the animation '" + a.name.text + "' has no keys");
  }
}

void Checker::event(const Event& e)
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

void Checker::priority(const Property& p)
{
  double v = 0;
  if (p.isHyperFun || p.values.size() != 1 || !constantNumber(p.values[0], v))
  {
    err(p.values.empty() ? p.pos : p.values[0]->pos, "the priority must be a number");
  }
}

void Checker::timespanRef(const Property& p)
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

void Checker::params(const std::vector<ParamDecl>& ps,
  std::map<std::string, const ParamDecl*>& seen, const CellMap* cells, const std::string& kind,
  const std::set<std::string>* aliasRoots)
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
        err(p.name.pos, "unknown predefined parameter '" + n + "': translation, rotation or scale");
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

void Checker::paramType(const ParamDecl& p)
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

void Checker::constant(const ExprPtr& e)
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

} // namespace ictk::lang::icmcheck

namespace ictk::lang
{

void checkIcm(const IcmModel& model, const std::string& text, std::vector<Diagnostic>& out,
  const Limits& limits)
{
  hf::SourceText source(text, model.fileName);
  hf::DiagnosticSink sink(source, limits.maxDiagnostics > 0 ? limits.maxDiagnostics : 1);
  icmcheck::Checker checker(model, sink, limits);
  checker.run();
  for (Diagnostic& d : sink.diagnostics())
  {
    out.push_back(std::move(d));
  }
}

} // namespace ictk::lang
