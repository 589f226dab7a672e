// SPDX-License-Identifier: BSD-3-Clause
// Building a running model from the checked syntax tree (ModelState.h): time spans, animation
// curves, events, cells (their shapes in ModelShapes.cxx), attributes, instances with the cells and
// relations they derive, parameters, the dependency graph of an instance and the stepper with its
// reactions.
#include "Engine/ModelState.h"
#include "Lang/HyperFun.h"

#include <algorithm>
#include <cmath>
#include <cstring>

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
  checkSpaceTimeBlends();
  fitStandIns();
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
  // Shapes whose constructors read parameters, now that the parameters exist.
  for (CellSpec& c : cells)
    if (c.shapeExpression)
      buildShapeParts(c, *c.shapeExpression, kNone);
  // The blend-like shapes' numbers at the start; refused here, at their place, when wrong.
  for (CellSpec& c : cells)
    if (c.operands)
      c.operands->atStart = evaluateOperands(c, kNone);
}

OperandNumbers ModelState::evaluateOperands(const CellSpec& c, std::size_t instance)
{
  OperandNumbers out;
  const CellSpec::Operands& o = *c.operands;
  const bool spaceTimeBlend = o.kind == ShapePart::Kind::SpaceTimeBlend;
  double* slots[] = { &out.spaceTime.t0, &out.spaceTime.t1, &out.spaceTime.a0, &out.spaceTime.a1,
    &out.spaceTime.a2, &out.spaceTime.a3 };
  EngineScope scope(*this, c.name, instance);
  std::vector<Value> warpArguments;
  for (std::size_t i = 0; i < o.numbers.size(); ++i)
  {
    const Expr& e = *o.numbers[i];
    const Value v = interpreter.evaluate(e, scope);
    if (spaceTimeBlend && i >= 7)
    {
      warpArguments.push_back(v);
      continue;
    }
    if (!v.isNumber() || !std::isfinite(v.number))
      fail(e.pos,
        "argument " + std::to_string(i + 3) + " of the shape of " + c.name +
          " must be a finite number");
    if (spaceTimeBlend && i < 6)
      *slots[i] = v.number;
    else if (spaceTimeBlend && i == 6)
    {
      if (!(v.number >= 0 && v.number <= 1))
        fail(e.pos,
          "the alignment of " + c.name + " is a fraction from 0 (none) to 1 (the operands meet " +
            "halfway), it is " + std::to_string(v.number));
      out.align = v.number;
    }
    else if (!spaceTimeBlend && i == 0)
    {
      if (v.number < 0)
        fail(e.pos,
          "the blend amount of " + c.name + " must not be negative, it is " +
            std::to_string(v.number));
      out.amount = v.number;
    }
    else if (!spaceTimeBlend)
    {
      // a1 and a2 divide the operands' values (thesis L645): a scale, so > 0 (a negative one
      // would be the same as its opposite, and 0 has no meaning).
      if (!(v.number > 0))
        fail(e.pos,
          std::string("the blend scale a") + (i == 1 ? "1" : "2") + " of " + c.name +
            " (how far the blend reaches into " + (i == 1 ? "cellA" : "cellB") +
            ") must be positive, it is " + std::to_string(v.number));
      (i == 1 ? out.a1 : out.a2) = v.number;
    }
  }
  if (!warpArguments.empty())
    warpOf(c, warpArguments, out);
  if (spaceTimeBlend)
  {
    try
    {
      frep::validateSpaceTimeBlend("spaceTimeBlendCells", out.spaceTime);
    }
    catch (const std::exception& e)
    {
      fail(o.pos, std::string("the shape of ") + c.name + ": " + e.what());
    }
  }
  return out;
}

void ModelState::warpOf(
  const CellSpec& c, const std::vector<Value>& args, OperandNumbers& out) const
{
  // spaceTimeBlendCells' arguments after `align` (thesis 5.3.3): vec3 source, destination pairs,
  // or the count and separation of the automatic control points.
  const CellSpec::Operands& o = *c.operands;
  const Pos at = o.numbers[7]->pos;
  const std::string whose =
    "the warp of " + c.name + " (spaceTimeBlendCells' arguments after align): ";
  if (out.align > 0)
    fail(at, whose + "a warp and an alignment both move the operands; give align = 0 with a warp");
  if (args[0].type == Value::Type::Vec3)
  {
    if (args.size() % 2 != 0 || args.size() < 4)
      fail(at,
        whose + "control points come in pairs, source then destination, 2 pairs or more; " +
          "there are " + std::to_string(args.size()) + " points");
    for (std::size_t i = 0; i < args.size(); i += 2)
    {
      for (std::size_t k = i; k < i + 2; ++k)
        if (args[k].type != Value::Type::Vec3 || !std::isfinite(args[k].vec[0]) ||
          !std::isfinite(args[k].vec[1]) || !std::isfinite(args[k].vec[2]))
          fail(o.numbers[7 + k]->pos,
            whose + "argument " + std::to_string(k + 10) +
              " must be a finite point vec3(x, y, z) like the others");
      out.pairs.push_back({ args[i].vec, args[i + 1].vec });
    }
    return;
  }
  if (args.size() != 2 || !args[0].isNumber() || !args[1].isNumber())
    fail(at,
      whose + "either vec3 source, destination pairs or two numbers, the count and the " +
        "separation of the automatic control points");
  const double count = args[0].number, separation = args[1].number;
  if (!(count >= 1 && count <= geometry::kMaxControlPoints) || count != std::floor(count))
    fail(at,
      whose + "the number of automatic control points is a whole number from 1 to " +
        std::to_string(geometry::kMaxControlPoints) + ", it is " + std::to_string(count));
  if (!(separation >= 0) || !std::isfinite(separation))
    fail(o.numbers[8]->pos,
      whose + "the separation of the control points is a length >= 0, it is " +
        std::to_string(separation));
  out.warpCount = static_cast<int>(count);
  out.warpSeparation = separation;
}

void ModelState::checkSpaceTimeBlends() const
{
  // A space-time blend of two k-dimensional cells is a (k + 1)-dimensional T-cell (thesis 5.3.1:
  // "two 3D cells used as input, result is 4D").
  for (const CellSpec& c : cells)
  {
    if (!c.operands || c.operands->kind != ShapePart::Kind::SpaceTimeBlend)
      continue;
    for (const std::string& name : { c.operands->a, c.operands->b })
    {
      const auto it = cellIndex.find(name);
      if (it == cellIndex.end())
        fail(c.operands->pos, "spaceTimeBlendCells: no cell named " + name);
      const CellSpec& o = cells[it->second];
      const int k = spaceDimension(o);
      if (k < 2 || c.dimension != k + 1)
        fail(c.operands->pos,
          "the cell " + c.name + " blends " + name + ", a " + std::to_string(k) +
            "D cell, in space-time" +
            (k < 2 ? ": its operands must be 2D or 3D cells"
                   : ", so it is dim = " + std::to_string(k + 1) + "D, its cross-sections " +
                  std::to_string(k) + "D"));
    }
  }
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
  Pos dimPos = def.pos;
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
    {
      c.dimension = static_cast<int>(v->number);
      dimPos = p.pos;
    }
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
    ParamSpec spec{ p.pos, p.name.text, initialValue(p) };
    // A skinned cell's `array of TRANSFORM` holds one transform per joint (Appendix B's
    // matrices and transforms), the bind pose's identities to start with; elsewhere an array
    // only orders dependencies.
    if (p.array && p.type.text == "TRANSFORM" && c.skinned)
      spec.initial = Value::transformArray(std::vector<Affine>(c.skinned->joints.size()));
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
  // A space-time cell (thesis 5.3) has one dimension more than its cross-sections: 4D for a
  // field of x, y, z and t, 3D for one of x, y and t. Anything else declared 4D would be a 3D
  // shape that no time moves, which is not what the model says.
  if (c.spaceTime && c.operands)
  {
    // spaceTimeBlendCells: its operands' dimensions are checked once every cell is built.
  }
  else if (c.spaceTime)
  {
    const int expected = c.parts[c.fieldPart].fieldDimension + 1;
    if (c.dimension != expected)
      fail(dimPos,
        "the cell " + c.name + " has a space-time shape (" +
          (expected == 4 ? "XYZT: hyperfun x[4] or an .xml of domain XYZT"
                         : "XYT: an .xml of domain XYT") +
          "), so it is dim = " + std::to_string(expected) + "D, its cross-sections " +
          std::to_string(expected - 1) + "D");
  }
  else if (std::any_of(c.parts.begin(), c.parts.end(),
             [](const ShapePart& part) { return part.kind == ShapePart::Kind::Mesh; }) &&
    c.dimension != 2)
    fail(
      dimPos, "the cell " + c.name + "'s shape is a mesh file, a triangle surface: it is dim = 2D");
  else if (c.dimension > 3)
    fail(dimPos,
      "the cell " + c.name +
        " is dim = 4D, a space-time cell, but its shape is not a field of x, y, z and t "
        "(hyperfun x[4], or an .xml of domain XYZT)");
  for (const Procedure& r : def.reactions)
    c.reactions[reactionKey(r)] = &r;
  if (c.operands && !c.parts.empty())
    c.parts.clear();
  cellIndex[c.name] = cells.size();
  cells.push_back(std::move(c));
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
          const frep::Domain domain = hf.model.geometry().domain();
          a.dimension = domain == frep::Domain::XY || domain == frep::Domain::XYT ? 2 : 3;
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
    case Value::Type::Transforms:
    {
      transformCounts[q] = p.initial.transforms->size();
      std::size_t k = 0;
      for (const Affine& m : *p.initial.transforms)
      {
        for (double x : m.a)
          table.add(owner, p.name + "." + std::to_string(k++), dyn::Scope::Global, x);
        for (double x : m.b)
          table.add(owner, p.name + "." + std::to_string(k++), dyn::Scope::Global, x);
      }
      break;
    }
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
        b != Value::Type::String && a != Value::Type::Transforms && b != Value::Type::Transforms;
      if (a == Value::Type::Transforms && b == Value::Type::Transforms)
      {
        // Joint by joint, number by number: both skeletons must have as many joints.
        const std::size_t n = transformCounts.at(mq);
        if (transformCounts.at(dq) != n)
          fail(r.pos,
            "the dependency " + mq + " -> " + dq + " connects " + std::to_string(n) +
              " transforms to " + std::to_string(transformCounts.at(dq)) +
              " (the joints of the two cells' skeletons)");
        for (std::size_t k = 0; k < 12 * n; ++k)
        {
          dyn::DependencyRelation c = d;
          c.masterParam = r.masterMember + "." + std::to_string(k);
          c.dependentParam = r.dependentMember + "." + std::to_string(k);
          g.addRelation(c);
        }
        continue;
      }
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
  so.growRefinedSteps = model.steps.text == "grow";
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
      // A blend's numbers follow the parameters its update changed.
      const CellSpec& spec = cells[cellIndex.at(n)];
      if (spec.operands)
        s.operandNumbers[n] = evaluateOperands(spec, s.active);
      if (spec.shapeExpression)
        rebuildShape(spec);
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

} // namespace ictk::engine
