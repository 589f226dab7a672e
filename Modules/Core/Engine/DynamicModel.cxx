// SPDX-License-Identifier: BSD-3-Clause
#include "Engine/DynamicModel.h"

#include "Engine/Builtins.h"
#include "Engine/ModelState.h"
#include "Geometry/Queries.h"
#include "Geometry/ShapeCells.h"
#include "Lang/FRepXml.h"
#include "Lang/HyperFun.h"

#include <algorithm>
#include <any>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <map>
#include <optional>
#include <set>

namespace ictk::engine
{

namespace
{

std::string reactionKey(const Procedure& p)
{
  if (p.name.text == "react" && !p.formals.empty())
    return "react:" + p.formals[0].type;
  return p.name.text;
}

Value::Type typeOf(const std::string& t)
{
  if (t == "REAL" || t == "real" || t == "FLOAT" || t == "DOUBLE")
    return Value::Type::Real;
  if (t == "INT" || t == "int" || t == "INTEGER")
    return Value::Type::Int;
  if (t == "BOOL" || t == "bool" || t == "BOOLEAN")
    return Value::Type::Bool;
  if (t == "VECTOR3" || t == "VECTOR2" || t == "vec3" || t == "REAL3" || t == "POINT3")
    return Value::Type::Vec3;
  if (t == "STRING" || t == "string")
    return Value::Type::String;
  return Value::Type::None; // arrays, TRANSFORM, VECTOR4: not values of the imperative core
}

/// Flattens `a.b.c` (Name and Member nodes) into names; false for anything else.
bool pathOf(const Expr& e, std::vector<std::string>& out)
{
  if (e.kind == Expr::Kind::Name)
  {
    out.push_back(e.text);
    return true;
  }
  if (e.kind == Expr::Kind::Member && pathOf(*e.kids[0], out))
  {
    out.push_back(e.text);
    return true;
  }
  if (e.kind == Expr::Kind::Index && pathOf(*e.kids[0], out))
    return true; // Andy.skeleton["hand"]: the array as a whole
  return false;
}

std::uint64_t mix(std::uint64_t h, std::uint64_t v)
{
  h ^= v + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2);
  return h;
}

std::uint64_t bitsOf(double d)
{
  std::uint64_t u = 0;
  std::memcpy(&u, &d, sizeof u);
  return u;
}

} // namespace

// ---- building -----------------------------------------------------------------------------

void ModelState::build()
{
  buildTimespans();
  buildAnimations();
  buildEvents();
  for (const auto& section : model.cells)
    for (const CellDef& def : section.defs)
      buildCell(def);
  for (const Instance& in : model.instances)
    for (const auto& section : in.cells)
      for (const CellDef& def : section.defs)
        if (!cellIndex.count(def.name.text))
          buildCell(def);
  for (const ParamDecl& p : model.stateParameters)
    if (p.kind == ParamDecl::Kind::Typed)
    {
      modelParams.push_back({ p.pos, p.name.text, initialValue(p) });
      modelStateNames.push_back(p.name.text);
    }
  for (const ParamDecl& p : model.parameters)
    if (p.kind == ParamDecl::Kind::Typed)
      modelParams.push_back({ p.pos, p.name.text, initialValue(p) });
  for (const auto& section : model.attributes)
    buildAttributes(section);
  for (const Instance& in : model.instances)
    for (const auto& section : in.attributes)
      buildAttributes(section);
  for (const Instance& in : model.instances)
    buildInstance(in);
  // Cell parameters (they may be read by instances' initial values, so after the cells).
  for (CellSpec& c : cells)
  {
    for (const char* prop : { "translation", "rotation", "scale" })
    {
      bool given = false;
      for (const ParamSpec& p : c.params)
        given = given || p.name == prop;
      if (!given)
        c.params.insert(c.params.begin(),
          ParamSpec{ c.pos, prop,
            Value::vector(std::strcmp(prop, "scale") == 0 ? Vec3{ 1, 1, 1 } : Vec3{ 0, 0, 0 }) });
    }
  }
  for (const CellSpec& c : cells)
    for (const ParamSpec& p : c.params)
      addParam(c.name, p);
  for (const InstanceSpec& in : instances)
    for (const ParamSpec& p : in.params)
      addParam(in.name, p);
  for (const ParamSpec& p : modelParams)
    addParam({}, p);
  if (!model.cycles.text.empty())
    options.cycles = model.cycles.text == "reevaluate" ? dyn::CyclePolicy::Reevaluate
      : model.cycles.text == "cut"                     ? dyn::CyclePolicy::CutEdgePrevious
                                                       : dyn::CyclePolicy::PreviousState;
  // Dependencies must connect parameters of one type; checked once for every instance.
  for (std::size_t i = 0; i < instances.size(); ++i)
    if (!instances[i].isTemplate)
      (void)graph(i);
  bool any = false;
  for (const InstanceSpec& in : instances)
    any = any || !in.isTemplate;
  if (!any)
    fail({ 1, 1 }, "the model has no IC instance (only templates)");
  buildStepper();
}

void ModelState::buildTimespans()
{
  EngineScope scope(*this, {}, kNone);
  for (const auto& t : model.timespans)
  {
    std::vector<dyn::TimeInterval> intervals;
    std::vector<double> plain;
    for (const ExprPtr& a : t.args)
    {
      if (a->kind == Expr::Kind::Brace && a->kids.size() == 2)
        intervals.push_back({ interpreter.evaluate(*a->kids[0], scope).number,
          interpreter.evaluate(*a->kids[1], scope).number });
      else
        plain.push_back(interpreter.evaluate(*a, scope).number);
    }
    double scale = 1.0;
    if (intervals.empty() && plain.size() >= 2)
    {
      intervals.push_back({ plain[0], plain[1] });
      if (plain.size() >= 3)
        scale = plain[2];
    }
    else if (!plain.empty())
      scale = plain.back();
    try
    {
      timespans[t.name.text] =
        intervals.empty() ? dyn::TimeSpan::infinite(scale) : dyn::TimeSpan(intervals, scale);
    }
    catch (const std::exception& e)
    {
      fail(t.pos, std::string("time span ") + t.name.text + ": " + e.what());
    }
  }
}

void ModelState::buildAnimations()
{
  EngineScope scope(*this, {}, kNone);
  for (const CellDef& a : model.animations)
  {
    std::vector<std::vector<double>> keys;
    dyn::Interpolation in = dyn::Interpolation::Linear;
    dyn::OutOfRange before = dyn::OutOfRange::Constant, after = dyn::OutOfRange::Constant;
    auto outOf = [](const std::string& t)
    {
      return t == "linear" ? dyn::OutOfRange::Linear
        : t == "loop"      ? dyn::OutOfRange::Loop
        : t == "mirror"    ? dyn::OutOfRange::Mirror
                           : dyn::OutOfRange::Constant;
    };
    for (const Property& p : a.properties)
    {
      if (p.name == "keys")
        for (const ExprPtr& k : p.values)
        {
          std::vector<double> row;
          for (const ExprPtr& v : k->kids)
            row.push_back(interpreter.evaluate(*v, scope).number);
          keys.push_back(row);
        }
      else if (!p.values.empty())
      {
        const std::string& t = p.values[0]->text;
        if (p.name == "interpolation")
          in = t == "step"      ? dyn::Interpolation::Step
            : t == "catmullrom" ? dyn::Interpolation::CatmullRom
            : t == "hermite"    ? dyn::Interpolation::Hermite
                                : dyn::Interpolation::Linear;
        else if (p.name == "before")
          before = outOf(t);
        else if (p.name == "after")
          after = outOf(t);
      }
    }
    const std::size_t width = keys.empty() ? 0 : keys[0].size();
    try
    {
      for (std::size_t c = 1; c < width; ++c)
      {
        std::vector<dyn::Key> k;
        for (const auto& row : keys)
          k.emplace_back(row[0], row[c]);
        // Components x, y, z for {t, x, y, z}; slot 3 holds a scalar curve {t, v}.
        curves[width == 2 ? 3 : c - 1][a.name.text] = dyn::AnimationCurve(k, in, before, after);
      }
    }
    catch (const std::exception& e)
    {
      fail(a.pos, "animation " + a.name.text + ": " + e.what());
    }
    curveNames.insert(a.name.text);
    curveWidth[a.name.text] = width;
  }
}

void ModelState::buildEvents()
{
  for (const auto& e : model.events)
  {
    eventNames.insert(e.name.text);
    std::vector<std::string> names;
    for (const ParamDecl& p : e.parameters)
      if (p.kind == ParamDecl::Kind::Typed)
        names.push_back(p.name.text);
    eventParams[e.name.text] = names;
    double priority = 1.0;
    for (const Property& p : e.properties)
      if (p.name == "priority" && !p.values.empty())
        priority = p.values[0]->number;
      else if (p.name == "timespan" && !p.values.empty())
        eventSpans[e.name.text] = timespans.at(p.values[0]->text);
    eventPriority[e.name.text] = priority;
  }
}

void ModelState::buildCell(const CellDef& def)
{
  CellSpec c;
  // `B <- A`: a copy of A's properties, parameters and reactions, then B's own.
  if (!def.source.text.empty())
  {
    auto it = cellIndex.find(def.source.text);
    if (it == cellIndex.end())
    {
      const CellDef* src = model.cell(def.source.text);
      if (!src)
        fail(def.source.pos, "unknown source cell '" + def.source.text + "'");
      buildCell(*src);
      it = cellIndex.find(def.source.text);
    }
    c = cells[it->second];
  }
  c.name = def.name.text;
  c.pos = def.pos;
  EngineScope scope(*this, {}, kNone);
  for (const Property& p : def.properties)
  {
    const Expr* v = p.values.empty() ? nullptr : p.values[0].get();
    if (p.name == "type" && v)
    {
      static const std::map<std::string, complex::CellKind> kinds = {
        { "P-CELL", complex::CellKind::Point },
        { "B-CELL", complex::CellKind::BRep },
        { "F-CELL", complex::CellKind::FRep },
        { "C-CELL", complex::CellKind::Composite },
        { "T-CELL", complex::CellKind::Computed },
      };
      auto k = kinds.find(v->text);
      if (k == kinds.end())
        fail(p.pos, "unknown cell type '" + v->text + "'");
      c.kind = k->second;
    }
    else if (p.name == "dim" && v)
      c.dimension = static_cast<int>(v->number);
    else if (p.name == "domain")
    {
      std::vector<double> d;
      for (const ExprPtr& e : p.values)
      {
        if (e->kind == Expr::Kind::Brace)
          for (const ExprPtr& k : e->kids)
            d.push_back(interpreter.evaluate(*k, scope).number);
        else
          d.push_back(interpreter.evaluate(*e, scope).number);
      }
      if (d.size() == 4)
        c.domain = frep::Box3{ { d[0], d[1], 0.0 }, { d[2], d[3], 0.0 } };
      else if (d.size() == 6)
        c.domain = frep::Box3{ { d[0], d[1], d[2] }, { d[3], d[4], d[5] } };
      else
        fail(p.pos, "a domain is {xmin, ymin, xmax, ymax} or {xmin, ymin, zmin, xmax, ymax, zmax}");
      c.hasDomain = true;
    }
    else if (p.name == "priority" && v)
      c.priority = interpreter.evaluate(*v, scope).number;
    else if ((p.name == "timespan" || p.name == "lifespan") && v)
    {
      dyn::TimeSpan span;
      if (v->kind == Expr::Kind::Name)
        span = timespans.at(v->text);
      else
      {
        std::vector<dyn::TimeInterval> in;
        for (const ExprPtr& e : p.values)
          if (e->kind == Expr::Kind::Brace && e->kids.size() == 2)
            in.push_back({ interpreter.evaluate(*e->kids[0], scope).number,
              interpreter.evaluate(*e->kids[1], scope).number });
        span = dyn::TimeSpan(in);
      }
      if (p.name == "timespan")
      {
        c.clock = span;
        c.hasClock = true;
      }
      else
      {
        c.life = span;
        c.hasLifespan = true;
      }
    }
    else if (p.name == "shape")
      buildShape(c, p);
  }
  // Parameters: a copy's own declarations replace the source's of the same name.
  for (const ParamDecl& p : def.parameters)
  {
    if (p.kind != ParamDecl::Kind::Init && p.kind != ParamDecl::Kind::Typed)
      continue;
    const ParamSpec spec{ p.pos, p.name.text, initialValue(p) };
    auto same = std::find_if(
      c.params.begin(), c.params.end(), [&](const ParamSpec& q) { return q.name == spec.name; });
    if (same != c.params.end())
      *same = spec;
    else
      c.params.push_back(spec);
  }
  // Properties come in any order: the domain bounds the fields however late it is given.
  for (ShapePart& part : c.parts)
    if (part.kind == ShapePart::Kind::Field)
    {
      if (!c.hasDomain)
        fail(def.pos, "the cell " + c.name + " has a field shape but no domain (its bounds)");
      part.bounds = c.domain;
    }
  for (const Procedure& r : def.reactions)
    c.reactions[reactionKey(r)] = &r;
  if (c.operands && !c.parts.empty())
    c.parts.clear();
  cellIndex[c.name] = cells.size();
  cells.push_back(std::move(c));
}

void ModelState::buildShape(CellSpec& c, const Property& p)
{
  c.parts.clear();
  c.tape.reset();
  c.operands.reset();
  c.fieldPart = kNone;
  auto addField = [&](const frep::Hypervolume& model, int parameterCount)
  {
    ShapePart part;
    part.kind = ShapePart::Kind::Field;
    part.fieldDimension = model.geometry().domain() == frep::Domain::XY ? 2 : 3;
    c.tape = frep::Tape::compile(model.geometry().function());
    c.parameterCount = parameterCount;
    part.field = frep::tapeField(
      c.tape, 0.0, std::vector<double>(static_cast<std::size_t>(parameterCount), 0.0));
    part.bounds = c.domain;
    c.fieldPart = c.parts.size();
    c.parts.push_back(part);
  };
  if (p.isHyperFun)
  {
    try
    {
      const lang::HyperFunModel hf = lang::readHyperFun(p.hyperFunText, file);
      addField(hf.model, hf.parameterCount);
    }
    catch (const lang::ParseError& e)
    {
      fail(p.hyperFunPos, std::string("in the hyperfun shape: ") + e.what());
    }
    return;
  }
  EngineScope scope(*this, {}, kNone);
  for (const ExprPtr& v : p.values)
  {
    if (v->kind != Expr::Kind::Call)
      fail(v->pos, "a shape is hyperfun { ... }, file(\"...\") or a constructor such as disk(r)");
    const std::string& f = v->text;
    std::vector<Value> args;
    for (std::size_t i = 1; i < v->kids.size(); ++i)
    {
      const Expr& a = *v->kids[i];
      if ((f == "blend" || f == "union") && i <= 2 && a.kind == Expr::Kind::Name)
        args.push_back(Value::cell(a.text));
      else
        args.push_back(interpreter.evaluate(a, scope));
    }
    auto num = [&](std::size_t i)
    {
      if (i >= args.size() || !args[i].isNumber() || !std::isfinite(args[i].number))
        fail(v->pos, f + ": argument " + std::to_string(i + 1) + " must be a finite number");
      return args[i].number;
    };
    // Sizes, radii and blend amounts.
    auto size = [&](std::size_t i)
    {
      const double x = num(i);
      if (x < 0.0)
        fail(v->pos, f + ": argument " + std::to_string(i + 1) + " must not be negative");
      return x;
    };
    auto point = [&](std::size_t i)
    {
      if (i >= args.size() || args[i].type != Value::Type::Vec3)
        fail(v->pos, f + ": argument " + std::to_string(i + 1) + " must be a point vec3(x, y, z)");
      return args[i].vec;
    };
    ShapePart part;
    if (f == "file")
    {
      if (args.empty() || args[0].type != Value::Type::String)
        fail(v->pos, "file(\"name\") takes the file's name");
      const std::string path = model.directory.empty() || args[0].text.rfind('/', 0) == 0
        ? args[0].text
        : model.directory + "/" + args[0].text;
      const bool xml = path.size() > 4 && path.substr(path.size() - 4) == ".xml";
      try
      {
        if (xml)
          addField(lang::readFRepXmlFile(path), 0);
        else
        {
          const lang::HyperFunModel hf = lang::readHyperFunFile(path);
          addField(hf.model, hf.parameterCount);
        }
      }
      catch (const std::exception& e)
      {
        fail(v->pos, "cannot read the shape file '" + path + "': " + e.what());
      }
      continue;
    }
    if (f == "point")
    {
      part.kind = ShapePart::Kind::Point;
      part.points = { { num(0), num(1), args.size() > 2 ? num(2) : 0.0 } };
    }
    else if (f == "segment")
    {
      part.kind = ShapePart::Kind::Segment;
      part.points = { point(0), point(1) };
    }
    else if (f == "polyline")
    {
      part.kind = ShapePart::Kind::Polyline;
      for (std::size_t i = 0; i < args.size(); ++i)
        part.points.push_back(point(i));
    }
    else if (f == "arc" || f == "circularSegment")
    {
      part.kind = f == "arc" ? ShapePart::Kind::Arc : ShapePart::Kind::CircularSegment;
      part.points = { point(0), point(1) };
      part.radius = size(2);
    }
    else if (f == "rectangle")
    {
      part.kind = ShapePart::Kind::Rectangle;
      part.size = { size(0), size(1), 0.0 };
    }
    else if (f == "disk" || f == "sphere")
    {
      part.kind = f == "disk" ? ShapePart::Kind::Disk : ShapePart::Kind::Sphere;
      part.radius = size(0);
    }
    else if (f == "box")
    {
      part.kind = ShapePart::Kind::Box;
      part.size = { size(0), size(1), size(2) };
    }
    else if (f == "blend" || f == "union")
    {
      if (args.size() < 2 || args[0].type != Value::Type::Cell || args[1].type != Value::Type::Cell)
        fail(v->pos, f + " takes two cells");
      c.operands =
        CellSpec::Operands{ f == "blend" ? ShapePart::Kind::Blend : ShapePart::Kind::Union,
          args[0].text, args[1].text, f == "blend" ? size(2) : 0.0 };
      continue;
    }
    else
      fail(v->pos, "unknown shape constructor '" + f + "'");
    c.parts.push_back(part);
  }
}

RelationSpec ModelState::relationSpec(const Relation& r) const
{
  RelationSpec s;
  s.pos = r.pos;
  s.name = r.name.text;
  s.priority = r.hasPriority ? r.priority : 1.0;
  s.hierarchical = r.hierarchical;
  auto split = [&](const Expr& e, std::string& head, std::string& rest)
  {
    std::vector<std::string> path;
    if (!pathOf(e, path) || path.empty())
      fail(e.pos, "a relation end is a cell or a path Cell.parameter");
    head = path[0];
    for (std::size_t i = 1; i < path.size(); ++i)
    {
      // `transform.translation` names the translation itself; `transform` alone the placement.
      if (path[i] == "transform" && i + 1 < path.size())
        continue;
      rest += (rest.empty() ? "" : ".") + path[i];
    }
  };
  if (r.ends.size() != 2)
    fail(r.pos, "a relation has two ends");
  split(*r.ends[0], s.master, s.masterMember);
  split(*r.ends[1], s.dependent, s.dependentMember);
  return s;
}

std::vector<std::string> ModelState::cellsOf(const Instance& in, int depth) const
{
  if (depth > 64)
    fail(in.pos, "templates derive from each other in a cycle");
  std::vector<std::string> out;
  auto add = [&](const std::string& n)
  {
    if (std::find(out.begin(), out.end(), n) == out.end())
      out.push_back(n);
  };
  if (!in.base.text.empty() && in.base.text != "TEMPLATE_IC")
  {
    const Instance* base = model.instance(in.base.text);
    if (!base)
      fail(in.base.pos, "unknown template '" + in.base.text + "'");
    for (const std::string& n : cellsOf(*base, depth + 1))
      add(n);
  }
  for (const auto& section : in.cells)
  {
    for (const auto& u : section.uses)
    {
      std::vector<std::string> path;
      if (!pathOf(*u.what, path) || path.size() != 2 || path[1] != "CELLS")
        fail(u.pos, "USE in CELLS takes T.CELLS");
      const Instance* src = model.instance(path[0]);
      if (!src)
        fail(u.pos, "unknown template '" + path[0] + "'");
      for (const std::string& n : cellsOf(*src, depth + 1))
      {
        const bool minus = std::any_of(
          u.minus.begin(), u.minus.end(), [&](const lang::icm::Name& m) { return m.text == n; });
        if (!minus)
          add(n);
      }
      for (const auto& p : u.plus)
        add(p.text);
    }
    for (const auto& r : section.refs)
      add(r.text);
    for (const CellDef& d : section.defs)
      add(d.name.text);
  }
  return out;
}

std::vector<RelationSpec> ModelState::relationsOf(
  const Instance& in, const std::string& kind, int depth) const
{
  if (depth > 64)
    fail(in.pos, "templates derive from each other in a cycle");
  std::vector<RelationSpec> out;
  if (!in.base.text.empty() && in.base.text != "TEMPLATE_IC")
    if (const Instance* base = model.instance(in.base.text))
      out = relationsOf(*base, kind, depth + 1);
  for (const auto& section : in.relations)
  {
    const auto& uses = kind == "dependency" ? section.dependencyUses
      : kind == "boundary"                  ? section.boundaryUses
                                            : section.containmentUses;
    for (const auto& u : uses)
    {
      std::vector<std::string> path;
      if (!pathOf(*u.what, path) || path.size() != 3 || path[1] != "RELATIONS")
        fail(u.pos, "USE in relations takes T.RELATIONS." + kind);
      const Instance* src = model.instance(path[0]);
      if (!src)
        fail(u.pos, "unknown template or instance '" + path[0] + "'");
      for (RelationSpec& r : relationsOf(*src, kind, depth + 1))
      {
        const bool minus = std::any_of(u.minus.begin(), u.minus.end(),
          [&](const lang::icm::Name& m) { return !r.name.empty() && m.text == r.name; });
        if (!minus)
          out.push_back(std::move(r));
      }
    }
    const auto& list = kind == "dependency" ? section.dependency
      : kind == "boundary"                  ? section.boundary
                                            : section.containment;
    for (const Relation& r : list)
      out.push_back(relationSpec(r));
  }
  return out;
}

void ModelState::buildAttributes(const lang::icm::AttributesSection& section)
{
  for (const CellDef& d : section.defs)
  {
    AttributeSpec a;
    a.name = d.name.text;
    for (const Property& p : d.properties)
      if (p.name == "mapping" && p.isHyperFun)
      {
        try
        {
          const lang::HyperFunModel hf = lang::readHyperFun(p.hyperFunText, file);
          a.tape = frep::Tape::compile(hf.model.geometry().function());
          a.dimension = hf.model.geometry().domain() == frep::Domain::XY ? 2 : 3;
          a.text = hf.name;
        }
        catch (const lang::ParseError& e)
        {
          fail(p.hyperFunPos, std::string("in the hyperfun mapping: ") + e.what());
        }
      }
    if (!attributes.count(a.name) || a.tape)
      attributes[a.name] = a;
  }
  for (const auto& b : section.bindings)
    if (!attributes.count(b.first.text))
      attributes[b.first.text] = AttributeSpec{ b.first.text, nullptr, 3, b.second.text };
}

std::vector<std::pair<std::string, std::string>> ModelState::attributeLinksOf(
  const Instance& in, int depth) const
{
  if (depth > 64)
    fail(in.pos, "templates derive from each other in a cycle");
  std::vector<std::pair<std::string, std::string>> out;
  auto add = [&](const std::pair<std::string, std::string>& l)
  {
    if (std::find(out.begin(), out.end(), l) == out.end())
      out.push_back(l);
  };
  if (!in.base.text.empty() && in.base.text != "TEMPLATE_IC")
    if (const Instance* base = model.instance(in.base.text))
      for (const auto& l : attributeLinksOf(*base, depth + 1))
        add(l);
  for (const auto& section : in.attributes)
  {
    for (const auto& u : section.uses)
    {
      std::vector<std::string> path;
      if (pathOf(*u.what, path) && path.size() == 2 && path[1] == "ATTRIBUTES")
        if (const Instance* src = model.instance(path[0]))
          for (const auto& l : attributeLinksOf(*src, depth + 1))
            add(l);
    }
    for (const Relation& r : section.links)
    {
      std::vector<std::string> cell;
      if (r.ends.size() == 2 && pathOf(*r.ends[0], cell) && !cell.empty())
        add({ cell[0], r.ends[1]->text });
    }
  }
  return out;
}

void ModelState::buildInstance(const Instance& in)
{
  InstanceSpec s;
  s.name = in.name.text;
  s.pos = in.pos;
  s.isTemplate = in.isTemplate;
  s.cells = cellsOf(in, 0);
  for (const std::string& c : s.cells)
    if (!cellIndex.count(c))
      fail(in.pos, "the instance " + s.name + " uses the undefined cell '" + c + "'");
  s.boundary = relationsOf(in, "boundary", 0);
  s.containment = relationsOf(in, "containment", 0);
  s.dependency = relationsOf(in, "dependency", 0);
  s.attributeLinks = attributeLinksOf(in, 0);
  EngineScope scope(*this, {}, kNone);
  // Inherited from the template: parameters, reactions and the predicate, overridden by the
  // instance's own.
  if (!in.base.text.empty() && in.base.text != "TEMPLATE_IC")
  {
    auto b = instanceIndex.find(in.base.text);
    if (b != instanceIndex.end())
    {
      const InstanceSpec& base = instances[b->second];
      s.reactions = base.reactions;
      s.cellReactions = base.cellReactions;
      s.predicate = base.predicate;
      s.reactsTo = base.reactsTo;
    }
  }
  for (const ParamDecl& p : in.stateParameters)
  {
    if (p.kind == ParamDecl::Kind::Typed)
    {
      s.params.push_back({ p.pos, p.name.text, initialValue(p) });
      s.stateNames.push_back(p.name.text);
    }
    else if (p.kind == ParamDecl::Kind::Alias)
    {
      s.aliases.push_back({ p.name.text, p.alias });
      s.stateNames.push_back(p.name.text);
    }
  }
  for (const ParamDecl& p : in.parameters)
    if (p.kind == ParamDecl::Kind::Typed)
      s.params.push_back({ p.pos, p.name.text, initialValue(p) });
  for (const Procedure& r : in.reactions)
  {
    s.reactions[reactionKey(r)] = &r;
    if (r.name.text == "react" && !r.formals.empty())
      s.reactsTo.insert(r.formals[0].type);
  }
  for (const auto& section : in.cells)
    for (const Procedure& r : section.reactions)
      if (!r.cell.text.empty())
        s.cellReactions[r.cell.text][reactionKey(r)] = &r;
  for (const Procedure& p : in.predicates)
    s.predicate = &p;
  instanceIndex[s.name] = instances.size();
  instances.push_back(std::move(s));
}

// `name : TYPE(value)` or `translation(x, y, z)`: the initial value, of the declared type.
// Arrays and transforms have none (they only order dependencies).
Value ModelState::initialValue(const ParamDecl& p)
{
  EngineScope scope(*this, {}, kNone);
  auto number = [&](std::size_t i)
  {
    const Value v = interpreter.evaluate(*p.args[i], scope);
    if (!(v.isNumber() || v.type == Value::Type::Bool) || !std::isfinite(v.number))
      fail(p.args[i]->pos, "the initial value of " + p.name.text + " must be a finite number");
    return v.number;
  };
  const Value::Type t = p.kind == ParamDecl::Kind::Init ? Value::Type::Vec3
    : p.array                                           ? Value::Type::None
                                                        : typeOf(p.type.text);
  switch (t)
  {
    case Value::Type::Vec3:
    {
      Vec3 x{ 0, 0, 0 };
      for (std::size_t i = 0; i < p.args.size() && i < 3; ++i)
        x[i] = number(i);
      return Value::vector(x);
    }
    case Value::Type::Real:
      return Value::real(p.args.empty() ? 0.0 : number(0));
    case Value::Type::Int:
      return Value::integer(p.args.empty() ? 0.0 : number(0));
    case Value::Type::Bool:
      return Value::boolean(!p.args.empty() && number(0) != 0.0);
    case Value::Type::String:
      return Value::string(
        p.args.empty() ? std::string() : interpreter.evaluate(*p.args[0], scope).text);
    default:
      return Value{};
  }
}

void ModelState::addParam(const std::string& owner, const ParamSpec& p)
{
  const std::string q = qualified(owner, p.name);
  if (types.count(q))
    fail(p.pos, "the parameter " + q + " is defined twice");
  types[q] = p.initial.type;
  switch (p.initial.type)
  {
    case Value::Type::Vec3:
      for (int i = 0; i < 3; ++i)
        table.add(owner, p.name + "." + "xyz"[i], dyn::Scope::Global, p.initial.vec[i]);
      break;
    case Value::Type::Real:
    case Value::Type::Int:
    case Value::Type::Bool:
      table.add(owner, p.name, dyn::Scope::Global, p.initial.number);
      break;
    default:
      s.texts[q] = p.initial;
      break;
  }
}

dyn::DependencyGraph ModelState::graph(std::size_t i) const
{
  const InstanceSpec& in = instances[i];
  dyn::DependencyGraph g;
  g.addEntity(in.name, kInstancePriority);
  for (const std::string& c : in.cells)
    g.addEntity(c, cells[cellIndex.at(c)].priority);
  for (const RelationSpec& r : in.dependency)
  {
    dyn::DependencyRelation d;
    d.master = r.master;
    d.dependent = r.dependent;
    d.priority = r.priority;
    if (r.hierarchical)
    {
      d.kind = dyn::DependencyKind::Hierarchical;
      g.addRelation(d);
      continue;
    }
    const std::string mq = qualified(r.master, r.masterMember);
    const std::string dq = qualified(r.dependent, r.dependentMember);
    const bool bothParams =
      !r.masterMember.empty() && !r.dependentMember.empty() && hasParam(mq) && hasParam(dq);
    if (bothParams)
    {
      const Value::Type a = types.at(mq), b = types.at(dq);
      const bool numbers = a != Value::Type::Vec3 && b != Value::Type::Vec3 &&
        a != Value::Type::None && b != Value::Type::None && a != Value::Type::String &&
        b != Value::Type::String;
      if (a == Value::Type::Vec3 && b == Value::Type::Vec3)
      {
        for (const char* axis : { ".x", ".y", ".z" })
        {
          dyn::DependencyRelation c = d;
          c.masterParam = r.masterMember + axis;
          c.dependentParam = r.dependentMember + axis;
          g.addRelation(c);
        }
        continue;
      }
      if (!numbers)
        fail(r.pos,
          "the dependency " + mq + " -> " + dq + " connects a " + typeName(a) + " to a " +
            typeName(b) + "; name a component (" + mq +
            ".x) or a parameter of the "
            "same type");
      d.masterParam = r.masterMember;
      d.dependentParam = r.dependentMember;
    }
    // Otherwise (shapes, arrays, skeletons): the relation orders the evaluation only.
    g.addRelation(d);
  }
  return g;
}

void ModelState::buildStepper()
{
  stepper = std::make_unique<dyn::Stepper>(table, 0.0);
  dyn::StepperOptions so;
  so.cycles = options.cycles;
  so.pullChangedOnly = true;
  stepper->setOptions(so);
  for (const CellSpec& c : cells)
  {
    dyn::Reaction r;
    r.name = c.name;
    r.life = c.life;
    for (const auto& [key, proc] : c.reactions)
      if (key.rfind("react:", 0) == 0)
        r.reactsTo.push_back(key.substr(6));
    for (const InstanceSpec& in : instances)
      for (const auto& [cell, procs] : in.cellReactions)
        if (cell == c.name)
          for (const auto& [key, proc] : procs)
            if (key.rfind("react:", 0) == 0)
              r.reactsTo.push_back(key.substr(6));
    const std::string n = c.name;
    r.enabled = [this, n]
    {
      return present(n);
    };
    r.update = [this, n](dyn::StepContext& ctx)
    {
      runCell(n, "update", ctx);
    };
    r.updatePost = [this, n](dyn::StepContext& ctx)
    {
      runCell(n, "updatePost", ctx);
    };
    r.init = [this, n](dyn::StepContext& ctx)
    {
      runCell(n, "init", ctx);
    };
    r.terminate = [this, n](dyn::StepContext& ctx)
    {
      runCell(n, "terminate", ctx);
    };
    // Re-evaluation (CyclePolicy::Reevaluate) pulls the cut relation again; it does not re-run
    // the cell's update, which would integrate twice (translation += v * dt).
    r.react = [this, n](dyn::StepContext& ctx, const dyn::Event& e)
    {
      runCell(n, "react:" + e.name, ctx, &e);
    };
    stepper->addReaction(std::move(r));
  }
  for (std::size_t i = 0; i < instances.size(); ++i)
  {
    if (instances[i].isTemplate)
      continue;
    dyn::Reaction r;
    r.name = instances[i].name;
    r.reactsTo.assign(instances[i].reactsTo.begin(), instances[i].reactsTo.end());
    r.enabled = [this, i]
    {
      return s.active == i;
    };
    r.update = [this, i](dyn::StepContext& ctx)
    {
      activate(ctx);
      runInstance(i, "update", ctx);
    };
    r.updatePost = [this, i](dyn::StepContext& ctx)
    {
      runInstance(i, "updatePost", ctx);
    };
    r.react = [this, i](dyn::StepContext& ctx, const dyn::Event& e)
    {
      runInstance(i, "react:" + e.name, ctx, &e);
    };
    stepper->addReaction(std::move(r));
  }
  stepper->setExternalState([this] { return std::any(s); },
    [this](const std::any& a)
    {
      s = std::any_cast<const Structure&>(a);
      if (s.active != graphInstance && s.active != kNone)
      {
        // Only the plan is replaced here; the stepper restores the relations' validity after.
        stepper->setDependencies(graph(s.active));
        graphInstance = s.active;
      }
    });
}

// ---- values ---------------------------------------------------------------------------------

Value ModelState::get(const std::string& q) const
{
  auto t = types.find(q);
  if (t == types.end())
    throw std::out_of_range("no parameter " + q);
  const dyn::ParameterTable& p = stepper ? stepper->params() : table;
  switch (t->second)
  {
    case Value::Type::Vec3:
      return Value::vector({ p.value(q + ".x"), p.value(q + ".y"), p.value(q + ".z") });
    case Value::Type::Real:
      return Value::real(p.value(q));
    case Value::Type::Int:
      return Value::integer(p.value(q));
    case Value::Type::Bool:
      return Value::boolean(p.value(q) != 0.0);
    default:
    {
      auto it = s.texts.find(q);
      return it == s.texts.end() ? Value{} : it->second;
    }
  }
}

void ModelState::set(const std::string& q, const Value& v)
{
  const Value::Type t = types.at(q);
  // std::runtime_error, not ModelError: the interpreter adds the place of the assignment.
  auto bad = [&]
  {
    throw std::runtime_error(
      q + " is a " + std::string(typeName(t)) + "; it cannot take a " + typeName(v.type));
  };
  if (std::isnan(v.number) && v.isNumber())
    throw std::runtime_error(q + " would become NaN");
  dyn::ParameterTable& p = stepper ? stepper->params() : table;
  switch (t)
  {
    case Value::Type::Vec3:
      if (v.type != Value::Type::Vec3)
        bad();
      for (int i = 0; i < 3; ++i)
      {
        if (!std::isfinite(v.vec[i]))
          throw std::runtime_error(q + " would become " + std::to_string(v.vec[i]));
        p.setValue(q + "." + "xyz"[i], v.vec[i]);
      }
      break;
    case Value::Type::Real:
    case Value::Type::Int:
      if (!v.isNumber() && v.type != Value::Type::Bool)
        bad();
      p.setValue(q, t == Value::Type::Int ? std::trunc(v.number) : v.number);
      break;
    case Value::Type::Bool:
      if (v.type != Value::Type::Bool)
        bad();
      p.setValue(q, v.number);
      break;
    default:
      if (t != Value::Type::None && v.type != t)
        bad();
      s.texts[q] = v;
      break;
  }
}

// ---- shapes ---------------------------------------------------------------------------------

std::shared_ptr<const std::vector<ShapePart>> ModelState::partsOf(const CellSpec& c) const
{
  if (auto it = s.shapes.find(c.name); it != s.shapes.end())
    return it->second;
  auto parts = std::make_shared<std::vector<ShapePart>>(c.parts);
  if (c.fieldPart != kNone)
    if (auto it = s.shapeParameters.find(c.name); it != s.shapeParameters.end())
      (*parts)[c.fieldPart].field = frep::tapeField(c.tape, 0.0, it->second);
  return parts;
}

Affine ModelState::localPlace(const std::string& cell) const
{
  const dyn::ParameterTable& p = stepper->params();
  auto v = [&](const char* prop)
  {
    const std::string q = cell + "." + prop;
    return Vec3{ p.value(q + ".x"), p.value(q + ".y"), p.value(q + ".z") };
  };
  return Affine::fromTransform(v("translation"), v("rotation"), v("scale"));
}

Affine ModelState::place(const std::string& cell, int depth) const
{
  if (depth > static_cast<int>(cells.size()))
    throw std::runtime_error("HIERARCHICAL dependencies form a cycle through " + cell);
  Affine local = localPlace(cell);
  if (s.active == kNone)
    return local;
  // The first hierarchical parent in the active instance carries the cell.
  for (const RelationSpec& r : instances[s.active].dependency)
    if (r.hierarchical && r.dependent == cell && cellIndex.count(r.master))
      return place(r.master, depth + 1) * local;
  return local;
}

PlacedShapePtr ModelState::shapeOf(const std::string& cell, int depth) const
{
  if (depth > static_cast<int>(cells.size()))
    throw std::runtime_error("the shapes of blend/union cells refer to each other in a cycle");
  const CellSpec& c = cells[cellIndex.at(cell)];
  auto shape = std::make_shared<PlacedShape>();
  shape->cell = c.name;
  shape->dimension = c.dimension;
  shape->place = place(cell);
  if (c.operands && !s.shapes.count(cell))
  {
    ShapePart part;
    part.kind = c.operands->kind;
    part.operandA = shapeOf(c.operands->a, depth + 1);
    part.operandB = shapeOf(c.operands->b, depth + 1);
    part.amount = c.operands->amount;
    part.bounds = c.domain;
    shape->parts.push_back(part);
    return shape;
  }
  shape->parts = *partsOf(c);
  return shape;
}

std::uint64_t ModelState::versionOf(const std::string& cell, int depth) const
{
  const CellSpec& c = cells[cellIndex.at(cell)];
  std::uint64_t v = 0;
  if (auto it = s.versions.find(cell); it != s.versions.end())
    v = it->second;
  if (!c.operands || s.shapes.count(cell) || depth > static_cast<int>(cells.size()))
    return v;
  // A blend or union lives in world coordinates: it changes when an operand moves.
  for (const std::string& o : { c.operands->a, c.operands->b })
  {
    v = mix(v, versionOf(o, depth + 1));
    const Affine a = place(o);
    for (double d : a.a)
      v = mix(v, bitsOf(d));
    for (double d : a.b)
      v = mix(v, bitsOf(d));
  }
  return v;
}

// ---- running --------------------------------------------------------------------------------

const Procedure* ModelState::procedureFor(const std::string& cell, const std::string& key) const
{
  if (s.active != kNone)
  {
    const auto& over = instances[s.active].cellReactions;
    if (auto c = over.find(cell); c != over.end())
      if (auto p = c->second.find(key); p != c->second.end())
        return p->second;
  }
  const auto& own = cells[cellIndex.at(cell)].reactions;
  auto p = own.find(key);
  return p == own.end() ? nullptr : p->second;
}

namespace
{

std::vector<Value> timeArgs(
  const Procedure& p, double globalT, double localT, double lifeT, double dt, const dyn::Event* ev)
{
  std::vector<Value> args;
  std::size_t k = 0;
  if (ev)
  {
    Value e;
    e.type = Value::Type::Event;
    e.text = ev->name;
    e.fields = ev->parameters;
    args.push_back(e);
    k = 1;
  }
  const double times[] = { globalT, localT, lifeT, dt };
  // react(E e, globalT, localT, lifeT); update(globalT, localT, lifeT, dt); init(globalT);
  // evaluate(globalT, localT, dt).
  for (std::size_t i = k; i < p.formals.size(); ++i)
  {
    const std::size_t j = i - k;
    double v = j < 4 ? times[j] : 0.0;
    if (p.name.text == "evaluate" && j == 2)
      v = dt;
    args.push_back(Value::real(v));
  }
  return args;
}

} // namespace

void ModelState::runCell(
  const std::string& cell, const std::string& key, dyn::StepContext& c, const dyn::Event* ev)
{
  const Procedure* p = procedureFor(cell, key);
  if (!p)
    return;
  const CellSpec& spec = cells[cellIndex.at(cell)];
  double localT = 0.0, lifeT = 0.0;
  const auto& own = spec.reactions;
  if (own.find(key) == own.end() || own.at(key) != p)
  {
    // A reaction the active instance gives the cell lives on the instance's clock.
    localT = lifeT = c.globalT - s.activatedAt;
  }
  else
  {
    const double since = s.presentSince.count(cell) ? s.presentSince.at(cell) : 0.0;
    localT = lifeT = c.globalT - since;
    if (spec.hasClock)
      localT = spec.clock.localTime(c.globalT).value_or(kNaN);
    if (spec.hasLifespan)
      lifeT = spec.life.lifeTime(c.globalT).value_or(kNaN);
  }
  EngineScope scope(*this, cell, s.active);
  context = &c;
  interpreter.run(*p, timeArgs(*p, c.globalT, localT, lifeT, c.dt, ev), scope);
  context = nullptr;
}

void ModelState::runInstance(
  std::size_t i, const std::string& key, dyn::StepContext& c, const dyn::Event* ev)
{
  auto it = instances[i].reactions.find(key);
  if (it == instances[i].reactions.end())
    return;
  const double local = c.globalT - s.activatedAt;
  EngineScope scope(*this, {}, i);
  context = &c;
  interpreter.run(*it->second, timeArgs(*it->second, c.globalT, local, local, c.dt, ev), scope);
  context = nullptr;
}

void ModelState::activate(dyn::StepContext& c)
{
  if (!s.justActivated)
    return;
  s.justActivated = false;
  if (s.previous != kNone)
  {
    // The cells that leave, then the instance that ends (its terminate), then the new one.
    const auto& now = instances[s.active].cells;
    for (const std::string& cell : instances[s.previous].cells)
      if (std::find(now.begin(), now.end(), cell) == now.end())
        runCell(cell, "terminate", c);
    runInstance(s.previous, "terminate", c);
  }
  runInstance(s.active, "init", c);
  // The first instance's cells get their init from the stepper (their life spans begin).
  if (s.previous == kNone)
    return;
  const auto& before = instances[s.previous].cells;
  for (const std::string& cell : instances[s.active].cells)
    if (std::find(before.begin(), before.end(), cell) == before.end())
      runCell(cell, "init", c);
}

std::vector<std::size_t> ModelState::validInstances(double t)
{
  std::vector<std::size_t> valid;
  for (std::size_t i = 0; i < instances.size(); ++i)
  {
    const InstanceSpec& in = instances[i];
    if (in.isTemplate)
      continue;
    if (!in.predicate)
    {
      valid.push_back(i);
      continue;
    }
    // An instance that is not active has not started: its local time is 0.
    const double local = s.active == i ? t - s.activatedAt : 0.0;
    EngineScope scope(*this, {}, i);
    const Value r =
      interpreter.run(*in.predicate, timeArgs(*in.predicate, t, local, local, 0.0, nullptr), scope);
    if (r.type != Value::Type::Bool)
      fail(in.predicate->pos,
        "the predicate of " + in.name + " returned a " + typeName(r.type) + ", not a bool");
    if (r.number != 0.0)
      valid.push_back(i);
  }
  return valid;
}

void ModelState::setActive(std::size_t i, double t)
{
  s.previous = s.active;
  const auto* before = s.active != kNone ? &instances[s.active].cells : nullptr;
  for (const std::string& cell : instances[i].cells)
    if (!before || std::find(before->begin(), before->end(), cell) == before->end())
      s.presentSince[cell] = t;
  s.active = i;
  s.activatedAt = t;
  s.justActivated = true;
  stepper->setDependencies(graph(i));
  graphInstance = i;
}

FrameRecord ModelState::record(double t, bool transition)
{
  FrameRecord r;
  r.time = t;
  r.instance = s.active == kNone ? std::string() : instances[s.active].name;
  r.transition = transition;
  const auto& processed = stepper->processedEvents();
  for (std::size_t i = processedSeen; i < processed.size(); ++i)
    r.events.push_back(processed[i].name);
  processedSeen = processed.size();
  for (const std::string& n : modelStateNames)
    r.state.emplace_back(n, get(n));
  if (s.active != kNone)
  {
    const InstanceSpec& in = instances[s.active];
    EngineScope scope(*this, {}, s.active);
    for (const std::string& n : in.stateNames)
    {
      Value v;
      if (!scope.lookup(n, v))
        v = Value{};
      r.state.emplace_back(n, v);
    }
  }
  return r;
}

void ModelState::step(double dt)
{
  try
  {
    stepper->step(dt);
  }
  catch (const dyn::SteppingError& e)
  {
    fail({ 0, 0 }, e.what());
  }
  catch (const dyn::StepRejectedError& e)
  {
    fail({ 0, 0 }, e.what());
  }
}

void ModelState::settle()
{
  try
  {
    stepper->settle();
  }
  catch (const dyn::SteppingError& e)
  {
    fail(instances[s.active].pos, e.what());
  }
}

// ---- EngineScope ----------------------------------------------------------------------------

std::string EngineScope::resolve(const std::string& name) const
{
  if (!cell_.empty() && m_.hasParam(cell_ + "." + name))
    return cell_ + "." + name;
  if (instance_ != kNone && m_.hasParam(m_.instances[instance_].name + "." + name))
    return m_.instances[instance_].name + "." + name;
  if (m_.hasParam(name))
    return name;
  return {};
}

const AliasSpec* EngineScope::alias(const std::string& name) const
{
  if (instance_ == kNone)
    return nullptr;
  for (const AliasSpec& a : m_.instances[instance_].aliases)
    if (a.name == name)
      return &a;
  return nullptr;
}

bool EngineScope::lookup(const std::string& name, Value& out)
{
  if (const std::string q = resolve(name); !q.empty())
  {
    out = m_.get(q);
    return true;
  }
  if (const AliasSpec* a = alias(name))
  {
    out = m_.interpreter.evaluate(*a->path, *this);
    return true;
  }
  if (m_.cellIndex.count(name))
  {
    out = Value::cell(name);
    return true;
  }
  if (m_.curveNames.count(name))
  {
    out = Value::string(name);
    return true;
  }
  return false;
}

bool EngineScope::member(const Value& base, const std::string& member, Value& out)
{
  if (base.type != Value::Type::Cell)
    return false;
  const std::string& c = base.text;
  const std::string q = c + "." + member;
  if (m_.hasParam(q))
  {
    out = m_.get(q);
    return true;
  }
  const CellSpec& spec = m_.cells[m_.cellIndex.at(c)];
  if (member == "center")
  {
    out = Value::vector(m_.place(c).apply({ 0, 0, 0 }));
    return true;
  }
  if (member == "curDomain" || member == "domain")
  {
    frep::Box3 b = spec.domain;
    if (member == "curDomain")
      b = m_.shapeOf(c)->worldBounds();
    out = Value::vector({ b.hi[0] - b.lo[0], b.hi[1] - b.lo[1], b.hi[2] - b.lo[2] });
    return true;
  }
  if (member == "dim")
  {
    out = Value::integer(spec.dimension);
    return true;
  }
  if (member == "type")
  {
    out = Value::string(complex::kindCode(spec.kind));
    return true;
  }
  if (member == "priority")
  {
    out = Value::real(spec.priority);
    return true;
  }
  if (member == "shape")
  {
    out.type = Value::Type::Shape;
    out.shape = m_.partsOf(spec);
    return true;
  }
  if (member == "radius")
  {
    for (const ShapePart& p : *m_.partsOf(spec))
      if (p.radius > 0.0)
      {
        out = Value::real(p.radius);
        return true;
      }
  }
  return false;
}

bool EngineScope::assign(const std::string& name, const std::string& member, const Value& v)
{
  if (member.empty())
  {
    if (const std::string q = resolve(name); !q.empty())
    {
      m_.set(q, v);
      return true;
    }
    if (const AliasSpec* a = alias(name))
    {
      std::vector<std::string> path;
      if (!pathOf(*a->path, path) || path.size() > 2)
        throw std::runtime_error("the alias " + name + " names a path code cannot set");
      return path.size() == 1 ? assign(path[0], {}, v) : assign(path[0], path[1], v);
    }
    return false;
  }
  if (!m_.cellIndex.count(name))
  {
    // instance.parameter or model parameter with a member: not assignable
    return false;
  }
  const std::string q = name + "." + member;
  if (m_.hasParam(q))
  {
    m_.set(q, v);
    return true;
  }
  if (member == "shape")
  {
    if (v.type != Value::Type::Shape)
      throw std::runtime_error(std::string("a shape takes segment(...), arc(...) or "
                                           "circularSegment(...), not a ") +
        typeName(v.type));
    m_.s.shapes[name] = v.shape;
    m_.bumpVersion(name);
    return true;
  }
  return false;
}

PlacedShapePtr EngineScope::cellShape(const Value& v) const
{
  if (v.type != Value::Type::Cell)
    throw std::runtime_error(std::string("expected a cell, got a ") + typeName(v.type));
  const CellSpec& c = m_.cells[m_.cellIndex.at(v.text)];
  if (!c.operands && m_.partsOf(c)->empty())
    throw std::runtime_error("the cell " + v.text + " has no shape yet");
  return m_.shapeOf(v.text);
}

namespace
{

/// A call of a Library built-in: the model it runs in, through the calling code's scope.
struct LibraryCall
{
  const lang::icm::Builtin& builtin;
  EngineScope& scope;
  ModelState& m;
  const std::vector<Value>& args;
};

using LibraryFunction = Value (*)(const LibraryCall&);
using lang::icm::BuiltinId;

Value distanceOf(const LibraryCall& c)
{
  return Value::real(geometry::distance(
    *c.scope.cellShape(c.args.at(0)), *c.scope.cellShape(c.args.at(1)), c.m.options.geometry));
}

Value intersectsOf(const LibraryCall& c)
{
  return Value::boolean(geometry::intersects(
    *c.scope.cellShape(c.args.at(0)), *c.scope.cellShape(c.args.at(1)), c.m.options.geometry));
}

Value containsOf(const LibraryCall& c)
{
  return Value::boolean(geometry::contains(
    *c.scope.cellShape(c.args.at(0)), *c.scope.cellShape(c.args.at(1)), c.m.options.geometry));
}

Value intersectionCountOf(const LibraryCall& c)
{
  return Value::integer(static_cast<double>(intersectionPoints(
    *c.scope.cellShape(c.args.at(0)), *c.scope.cellShape(c.args.at(1)), c.m.options.geometry)
                                              .size()));
}

Value intersectionPointOf(const LibraryCall& c)
{
  const auto pts = intersectionPoints(
    *c.scope.cellShape(c.args.at(0)), *c.scope.cellShape(c.args.at(1)), c.m.options.geometry);
  const double i = c.args.at(2).number;
  if (!(i >= 0) || i >= static_cast<double>(pts.size()))
    throw std::runtime_error("index " + std::to_string(static_cast<long long>(i)) +
      " out of range: the cells meet in " + std::to_string(pts.size()) + " point(s)");
  return Value::vector(pts[static_cast<std::size_t>(i)]);
}

Value intersectionAreaOf(const LibraryCall& c)
{
  return Value::real(intersectionMeasure(
    *c.scope.cellShape(c.args.at(0)), *c.scope.cellShape(c.args.at(1)), c.m.options.geometry));
}

/// segment(p, q), arc(p, q, r), circularSegment(p, q, r): a shape part in local coordinates.
Value shapePartOf(const LibraryCall& c)
{
  const BuiltinId id = c.builtin.id;
  ShapePart p;
  p.kind = id == BuiltinId::Segment ? ShapePart::Kind::Segment
    : id == BuiltinId::Arc          ? ShapePart::Kind::Arc
                                    : ShapePart::Kind::CircularSegment;
  for (std::size_t i = 0; i < 2; ++i)
    if (c.args.at(i).type != Value::Type::Vec3)
      throw std::runtime_error("argument " + std::to_string(i + 1) + " must be a vec3");
  p.points = { c.args[0].vec, c.args[1].vec };
  if (id != BuiltinId::Segment)
    p.radius = c.args.at(2).number;
  Value v;
  v.type = Value::Type::Shape;
  v.shape = std::make_shared<const std::vector<ShapePart>>(std::vector<ShapePart>{ p });
  return v;
}

Value setShapeParameter(const LibraryCall& call)
{
  ModelState& m = call.m;
  const std::vector<Value>& args = call.args;
  const Value& cell = args.at(0);
  if (cell.type != Value::Type::Cell)
    throw std::runtime_error("the first argument is a cell");
  const CellSpec& c = m.cells[m.cellIndex.at(cell.text)];
  if (!c.tape)
    throw std::runtime_error("the cell " + cell.text + " has no HyperFun or XML shape");
  // "a[2]" or "a2": HyperFun's parameter array, counted from 1.
  std::string key = args.at(1).text;
  key.erase(std::remove_if(
              key.begin(), key.end(), [](char ch) { return ch == '[' || ch == ']' || ch == 'a'; }),
    key.end());
  char* end = nullptr;
  const long index = std::strtol(key.c_str(), &end, 10);
  if (key.empty() || *end != '\0' || index < 1 || index > c.parameterCount)
    throw std::runtime_error("the shape of " + cell.text + " has the parameters a[1] to a[" +
      std::to_string(c.parameterCount) + "], not '" + args.at(1).text + "'");
  auto& values = m.s.shapeParameters[cell.text];
  if (values.empty())
    values.assign(static_cast<std::size_t>(c.parameterCount), 0.0);
  const double v = args.at(2).number;
  if (!std::isfinite(v))
    throw std::runtime_error("the value is not finite");
  if (values[static_cast<std::size_t>(index - 1)] != v)
  {
    values[static_cast<std::size_t>(index - 1)] = v;
    m.bumpVersion(cell.text);
  }
  return {};
}

Value fireEvent(const LibraryCall& call)
{
  ModelState& m = call.m;
  const std::vector<Value>& args = call.args;
  const std::string ev = args.at(0).text;
  if (ev == "TIME_REJECTED")
  {
    if (!m.context)
      throw std::runtime_error("TIME_REJECTED outside a frame (in a predicate?)");
    m.context->rejectTime(args.size() > 1 ? args[1].number : kNaN);
    return {};
  }
  if (!m.eventNames.count(ev))
    throw std::runtime_error("unknown event " + ev);
  const auto& names = m.eventParams.at(ev);
  if (args.size() - 1 != names.size())
    throw std::runtime_error(ev + " has " + std::to_string(names.size()) + " parameter(s)");
  std::map<std::string, double> params;
  for (std::size_t i = 0; i < names.size(); ++i)
    params[names[i]] = args[i + 1].number;
  const double now = m.context ? m.context->globalT : m.stepper->time();
  dyn::Event e = dyn::Event::at(ev, now, m.eventPriority.at(ev), params);
  if (m.context)
    m.context->fireEvent(e);
  else
    m.stepper->fireEvent(e);
  return {};
}

/// animation(curve, t), animationValue(curve, t), animationDuration(curve).
Value animationOf(const LibraryCall& call)
{
  ModelState& m = call.m;
  const BuiltinId id = call.builtin.id;
  const std::string curve = call.args.at(0).text;
  if (!m.curveNames.count(curve))
    throw std::runtime_error("unknown animation \"" + curve + "\"");
  const std::size_t width = m.curveWidth.at(curve);
  if (id == BuiltinId::AnimationDuration)
  {
    const auto& c = width == 2 ? m.curves[3].at(curve) : m.curves[0].at(curve);
    return Value::real(c.duration());
  }
  const double t = call.args.at(1).number;
  if (id == BuiltinId::AnimationValue)
  {
    if (width != 2)
      throw std::runtime_error("\"" + curve + "\" is a vector animation: use animation()");
    return Value::real(m.curves[3].at(curve).evaluate(t));
  }
  if (width != 4)
    throw std::runtime_error("\"" + curve + "\" is a scalar animation: use animationValue()");
  return Value::vector({ m.curves[0].at(curve).evaluate(t), m.curves[1].at(curve).evaluate(t),
    m.curves[2].at(curve).evaluate(t) });
}

/// The running model's half of the built-in library (the Library entries of
/// lang::icm::builtins()).
const std::pair<BuiltinId, LibraryFunction> kLibrary[] = {
  { BuiltinId::Distance, distanceOf },
  { BuiltinId::Intersects, intersectsOf },
  { BuiltinId::Contains, containsOf },
  { BuiltinId::IntersectionCount, intersectionCountOf },
  { BuiltinId::IntersectionPoint, intersectionPointOf },
  { BuiltinId::IntersectionArea, intersectionAreaOf },
  { BuiltinId::FireEvent, fireEvent },
  { BuiltinId::Animation, animationOf },
  { BuiltinId::AnimationValue, animationOf },
  { BuiltinId::AnimationDuration, animationOf },
  { BuiltinId::Segment, shapePartOf },
  { BuiltinId::Arc, shapePartOf },
  { BuiltinId::CircularSegment, shapePartOf },
  { BuiltinId::SetShapeParameter, setShapeParameter },
};

} // namespace

std::vector<lang::icm::BuiltinId> libraryBuiltins()
{
  return idsOf(kLibrary);
}

Value EngineScope::call(const lang::icm::Builtin& builtin, const std::vector<Value>& args)
{
  for (const auto& [id, fn] : kLibrary)
    if (id == builtin.id)
      return fn(LibraryCall{ builtin, *this, m_, args });
  throw std::runtime_error(std::string("unknown function '") + builtin.call.name + "'");
}

// ---- DynamicModel ---------------------------------------------------------------------------

DynamicModel DynamicModel::load(const std::string& path, RunOptions options)
{
  return DynamicModel(lang::readIcmFile(path), std::move(options));
}

DynamicModel::DynamicModel(lang::IcmModel model, RunOptions options)
  : impl_(std::make_unique<ModelState>(std::move(model), std::move(options)))
{
  impl_->build();
}

DynamicModel::~DynamicModel() = default;
DynamicModel::DynamicModel(DynamicModel&&) noexcept = default;
DynamicModel& DynamicModel::operator=(DynamicModel&&) noexcept = default;

const std::string& DynamicModel::name() const
{
  return impl_->model.name.text;
}

std::pair<double, double> DynamicModel::timeRange() const
{
  double lo = dyn::kInfinity, hi = -dyn::kInfinity;
  for (const auto& [n, span] : impl_->timespans)
    for (const dyn::TimeInterval& i : span.intervals())
    {
      if (std::isfinite(i.start))
        lo = std::min(lo, i.start);
      if (std::isfinite(i.end))
        hi = std::max(hi, i.end);
    }
  if (!std::isfinite(lo) || !std::isfinite(hi))
    return { 0.0, 0.0 };
  return { lo, hi };
}

double DynamicModel::time() const
{
  return impl_->stepper->time();
}

const std::string& DynamicModel::activeInstance() const
{
  static const std::string none;
  return impl_->s.active == kNone ? none : impl_->instances[impl_->s.active].name;
}

FrameRecord DynamicModel::start()
{
  ModelState& m = *impl_;
  if (m.started)
    return m.record(time(), false);
  m.started = true;
  const double t = time();
  auto unique = [&](const std::vector<std::size_t>& valid)
  {
    if (valid.size() == 1)
      return valid[0];
    std::string names;
    for (std::size_t i : valid)
      names += (names.empty() ? "" : ", ") + m.instances[i].name;
    m.fail(m.instances[m.s.active == kNone ? 0 : m.s.active].pos,
      "at t = " + std::to_string(t) + " " +
        (valid.empty() ? std::string("no instance is valid")
                       : "several instances are valid: " + names) +
        " (exactly one must be, thesis L1394)");
  };
  // The first instance is chosen on the state its own settling frame gives (animations placed,
  // relations evaluated); if that state makes another instance the valid one, start again
  // with that one.
  const dyn::Stepper::Snapshot initial = m.stepper->save();
  std::size_t chosen = unique(m.validInstances(t));
  for (int attempt = 0;; ++attempt)
  {
    m.stepper->restore(initial);
    m.s.active = kNone;
    m.setActive(chosen, t);
    m.settle();
    const std::size_t now = unique(m.validInstances(t));
    if (now == chosen)
      break;
    if (attempt > 16)
      m.fail(m.instances[chosen].pos,
        "no instance stays valid when the model settles at t = " + std::to_string(t));
    chosen = now;
  }
  return m.record(t, true);
}

std::vector<FrameRecord> DynamicModel::advanceTo(double t, double maxStep)
{
  ModelState& m = *impl_;
  if (!std::isfinite(t) || !(maxStep > 0.0) || !std::isfinite(maxStep))
    throw std::invalid_argument("advanceTo: the time and the step must be finite, the step > 0");
  if (t < time())
    throw std::invalid_argument("advanceTo: " + std::to_string(t) + " is before the model's time " +
      std::to_string(time()) + " (reload the model to go back)");
  std::vector<FrameRecord> out;
  if (!m.started)
    out.push_back(start());
  const double t0 = time();
  while (time() < t)
  {
    const double now = time();
    // A remainder below 1e-9 of the step (6 x 0.1 is 0.6000000000000001) joins this step
    // instead of becoming a frame of its own.
    const double target = (now + maxStep >= t - 1e-9 * maxStep) ? t : now + maxStep;
    const dyn::Stepper::Snapshot snap = m.stepper->save();
    m.step(target - now);
    auto valid = m.validInstances(target);
    const std::size_t active = m.s.active;
    if (valid.size() == 1 && valid[0] == active)
    {
      out.push_back(m.record(target, false));
    }
    else
    {
      // The first time the active instance stops being the only valid one, by bisection on the
      // identity of the valid set, re-running the frame from `now` to each probe.
      double lo = now, hi = target;
      auto probe = [&](double tau)
      {
        m.stepper->restore(snap);
        m.step(tau - now);
        return m.validInstances(tau);
      };
      while (hi - lo > m.options.timeTolerance)
      {
        const double mid = lo + 0.5 * (hi - lo);
        if (!(mid > lo && mid < hi))
          break;
        const auto v = probe(mid);
        if (v.size() == 1 && v[0] == active)
          lo = mid;
        else
          hi = mid;
      }
      valid = probe(hi);
      if (valid.size() != 1)
      {
        // Predicates are numerical: where two of them flip within the geometric tolerance of
        // each other (a query that says "touching" a little before another counts the point)
        // no instance, or two, may be valid for a moment. Look a little later for the first
        // time with exactly one, up to 1e3 x the time tolerance.
        const double reach = std::min(target, hi + 1e3 * m.options.timeTolerance);
        double a = hi, b = hi;
        bool found = false;
        for (double d = m.options.timeTolerance; !found && b < reach; d *= 2.0)
        {
          b = std::min(hi + d, reach);
          found = probe(b).size() == 1;
          if (!found)
            a = b;
        }
        if (found)
        {
          while (b - a > m.options.timeTolerance * 1e-3 && a + 0.5 * (b - a) > a)
          {
            const double mid = a + 0.5 * (b - a);
            if (probe(mid).size() == 1)
              b = mid;
            else
              a = mid;
          }
          hi = b;
        }
        valid = probe(hi);
      }
      // A transition at `hi`: the state is the one the old instance's frame reached (what its
      // reactions decided, e.g. a latch, is kept); the new instance then settles at that time
      // (its init, its relations, its updates with dt = 0, its updatePost), so the state
      // recorded at hi is the new instance's. If that makes yet another instance the valid one
      // (an instance valid only at an instant: the tangency of thesis 5.1, Newton's cradle's
      // contact), it follows at the same time.
      for (int hop = 0;; ++hop)
      {
        if (valid.size() != 1)
        {
          std::string names;
          for (std::size_t i : valid)
            names += (names.empty() ? "" : ", ") + m.instances[i].name;
          m.fail(m.instances[m.s.active].pos,
            "at t = " + std::to_string(hi) + " after " + m.instances[m.s.active].name + ", " +
              (valid.empty() ? std::string("no instance is valid")
                             : "several instances are valid: " + names) +
              " (exactly one must be, thesis L1394)");
        }
        if (valid[0] == m.s.active)
          break;
        if (hop > 16)
          m.fail(m.instances[m.s.active].pos,
            "at t = " + std::to_string(hi) + " the instances keep switching without time passing");
        m.setActive(valid[0], hi);
        m.settle();
        out.push_back(m.record(hi, true));
        valid = m.validInstances(hi);
      }
    }
    if (m.options.progress && t > t0 &&
      !m.options.progress(std::min(1.0, (time() - t0) / (t - t0))))
      throw Cancelled("the run was cancelled at t = " + std::to_string(time()));
  }
  return out;
}

std::vector<CellState> DynamicModel::cells() const
{
  const ModelState& m = *impl_;
  std::vector<CellState> out;
  if (m.s.active == kNone)
    return out;
  for (const std::string& n : m.instances[m.s.active].cells)
  {
    const CellSpec& c = m.cells[m.cellIndex.at(n)];
    if (!c.operands && m.partsOf(c)->empty())
      continue;
    CellState st;
    st.name = n;
    st.kind = c.kind;
    st.dimension = c.dimension;
    st.shape = m.shapeOf(n);
    st.shapeVersion = m.versionOf(n);
    out.push_back(std::move(st));
  }
  return out;
}

complex::Complex DynamicModel::complex() const
{
  const ModelState& m = *impl_;
  complex::Complex cx;
  std::map<std::string, complex::CellId> ids;
  for (const CellState& c : cells())
  {
    complex::Cell cell;
    try
    {
      cell = toComplexCell(*c.shape, c.kind, m.options.geometry);
    }
    catch (const std::exception& e)
    {
      m.fail(m.cells[m.cellIndex.at(c.name)].pos, "the cell " + c.name + ": " + e.what());
    }
    cell.name = c.name;
    cell.priority = m.cells[m.cellIndex.at(c.name)].priority;
    ids[c.name] = cx.addCell(std::move(cell));
  }
  if (m.s.active == kNone)
    return cx;
  const InstanceSpec& in = m.instances[m.s.active];
  for (const RelationSpec& r : in.boundary)
    if (ids.count(r.master) && ids.count(r.dependent))
    {
      try
      {
        cx.addBoundary(ids[r.dependent], ids[r.master]);
      }
      catch (const std::exception& e)
      {
        m.fail(r.pos, std::string("boundary relation: ") + e.what());
      }
    }
  // Attributes with a function follow their cell: evaluated in its local coordinates.
  for (const auto& [cell, name] : in.attributeLinks)
  {
    auto a = m.attributes.find(name);
    if (a == m.attributes.end() || !a->second.tape || !ids.count(cell))
      continue;
    PlacedShape local;
    local.cell = cell;
    local.dimension = 3;
    local.place = m.place(cell);
    ShapePart part;
    part.kind = ShapePart::Kind::Field;
    part.field = frep::tapeField(a->second.tape);
    part.fieldDimension = a->second.dimension;
    // unbounded: the attribute is defined wherever its cell is
    part.bounds = frep::Box3{ { -1e30, -1e30, -1e30 }, { 1e30, 1e30, 1e30 } };
    local.parts.push_back(part);
    auto fn = std::make_shared<complex::AttributeFunction>();
    fn->name = name;
    fn->components.push_back(worldField(local));
    fn->text.push_back(a->second.text);
    if (!cx.attributes().count(name))
      cx.declareAttribute(name, complex::AttributeDefaults{ 1, { 0.0 }, { 0.0 } });
    cx.bindAttribute(ids[cell], complex::AttributeBinding{ name, fn, 0.0 });
  }
  for (const RelationSpec& r : in.containment)
    if (ids.count(r.master) && ids.count(r.dependent))
    {
      try
      {
        cx.addContainment(ids[r.master], ids[r.dependent]);
      }
      catch (const std::exception& e)
      {
        m.fail(r.pos, std::string("containment relation: ") + e.what());
      }
    }
  return cx;
}

Value DynamicModel::value(const std::string& path) const
{
  ModelState& m = *impl_;
  if (m.hasParam(path))
    return m.get(path);
  const auto dot = path.find('.');
  EngineScope scope(m, {}, m.s.active);
  Value v;
  if (dot == std::string::npos)
  {
    if (scope.lookup(path, v))
      return v;
    throw std::out_of_range("no parameter '" + path + "'");
  }
  const std::string head = path.substr(0, dot);
  std::string rest = path.substr(dot + 1);
  if (!scope.lookup(head, v))
    throw std::out_of_range("no cell or parameter '" + head + "'");
  while (!rest.empty())
  {
    const auto d = rest.find('.');
    const std::string member = rest.substr(0, d);
    rest = d == std::string::npos ? std::string() : rest.substr(d + 1);
    if (v.type == Value::Type::Vec3)
    {
      const int c = member == "x" ? 0 : member == "y" ? 1 : member == "z" ? 2 : -1;
      if (c < 0)
        throw std::out_of_range("a vec3 has no member '" + member + "'");
      v = Value::real(v.vec[c]);
      continue;
    }
    Value next;
    if (!scope.member(v, member, next))
      throw std::out_of_range("'" + path + "': no member '" + member + "'");
    v = next;
  }
  return v;
}

const std::vector<std::string>& DynamicModel::log() const
{
  return impl_->stepper->log();
}

std::vector<std::vector<std::string>> DynamicModel::evaluationOrder() const
{
  const ModelState& m = *impl_;
  if (m.s.active == kNone)
    return {};
  dyn::DependencyGraph g = m.graph(m.s.active);
  return g.plan().listNames();
}

} // namespace ictk::engine
