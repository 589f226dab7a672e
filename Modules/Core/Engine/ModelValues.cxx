// SPDX-License-Identifier: BSD-3-Clause
// Resolving values and placements in a running model (ModelState.h): parameters by qualified
// name, value paths (Cell.translation.x), the placement and placed shape of a cell, the version
// that tells when a shape changed, and the scope through which code sees names and members.
#include "Engine/ModelState.h"
#include "FRep/Vector.h"

#include <algorithm>
#include <cstring>
#include <functional>

namespace ictk::engine
{

namespace
{

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
    case Value::Type::Transforms:
    {
      std::vector<Affine> m(transformCounts.at(q));
      std::size_t k = 0;
      for (Affine& a : m)
      {
        for (double& x : a.a)
          x = p.value(q + "." + std::to_string(k++));
        for (double& x : a.b)
          x = p.value(q + "." + std::to_string(k++));
      }
      return Value::transformArray(std::move(m));
    }
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
    case Value::Type::Transforms:
    {
      const std::size_t n = transformCounts.at(q);
      if (v.type != t)
        bad();
      if (v.transforms->size() != n)
        throw std::runtime_error(q + " holds " + std::to_string(n) +
          " transforms (the joints of its skeleton), not " + std::to_string(v.transforms->size()));
      std::size_t k = 0;
      for (const Affine& a : *v.transforms)
        for (int i = 0; i < 12; ++i)
        {
          const double x = i < 9 ? a.a[static_cast<std::size_t>(i)] : a.b[i - 9];
          if (!std::isfinite(x))
            throw std::runtime_error(q + " would hold a number that is not finite");
          p.setValue(q + "." + std::to_string(k++), x);
        }
      break;
    }
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
  if (c.skinned)
  {
    // A skinned mesh or skeleton posed at the cell's time or by its deformation; the queries of
    // a frame ask for it many times.
    const double t = animationTime(c);
    const auto deformation = s.deformations.find(c.name);
    const void* by = deformation == s.deformations.end() ? nullptr : deformation->second.get();
    const auto projection = s.projections.find(c.name);
    const ProjectionSetting setting =
      projection == s.projections.end() ? ProjectionSetting{} : projection->second;
    if (!c.posed || !(c.posedAt == t) || c.posedBy != by || !(c.posedProjection == setting))
    {
      const std::vector<Affine> matrices = skinningMatrices(c);
      auto posed = std::make_shared<std::vector<ShapePart>>(c.parts);
      const CellSpec* standIn = setting.alpha > 0 ? standInOf(c.name) : nullptr;
      if (c.meshPart != kNone)
      {
        const skin::SkinnedMesh& mesh = *c.skinned;
        ShapePart& part = (*posed)[c.meshPart];
        skin::Posed pose;
        if (standIn)
        {
          // Thesis 5.5's K2 / K4: on the way to the stand-in posed by the same matrices (its
          // cell's field, in this cell's frame).
          std::vector<double> alphas(mesh.vertexCount(), setting.alpha);
          if (!setting.weights.empty())
          {
            const std::vector<double> delays =
              skin::projectionDelays(c.weightMaps.at(setting.weights), setting.spread);
            for (std::size_t i = 0; i < alphas.size(); ++i)
              alphas[i] = skin::delayedAlpha(setting.alpha, delays[i], setting.spread);
          }
          pose = skin::poseOnStandIn(
            mesh, *standIn->projection, matrices, alphas, *(*partsOf(*standIn))[0].field)
                   .posed;
        }
        else
          pose = skin::skin(mesh, matrices, mesh.restPoints, skin::restNormalsOf(mesh));
        part.points = std::move(pose.points);
        // The vertex normals go with the points (the polydata's normals).
        discretize::PointArray normals{ "Normals", 3, {} };
        normals.values.reserve(3 * pose.normals.size());
        for (const Vec3& n : pose.normals)
          normals.values.insert(normals.values.end(), n.begin(), n.end());
        part.pointData.push_back(std::move(normals));
      }
      for (std::size_t i = 0; i < c.bones.size(); ++i)
      {
        // A bone's segment moves with its two joints.
        std::vector<Vec3>& ends = (*posed)[i].points;
        ends[0] = matrices[static_cast<std::size_t>(c.bones[i].parentJoint)].apply(ends[0]);
        ends[1] = matrices[static_cast<std::size_t>(c.bones[i].joint)].apply(ends[1]);
      }
      c.posed = std::move(posed);
      c.posedAt = t;
      c.posedBy = by;
      c.posedProjection = setting;
    }
    return c.posed;
  }
  if (c.standIn)
  {
    // The stand-in posed by its mesh cell's skinning matrices, in that cell's local frame.
    const CellSpec& mesh = cells[cellIndex.at(c.standInOf)];
    const std::uint64_t version = versionOf(mesh.name);
    if (!c.standInParts || c.standInVersion != version)
    {
      const skin::StandIn posed = skin::poseStandIn(*c.standIn, skinningMatrices(mesh));
      ShapePart part;
      part.kind = ShapePart::Kind::Field;
      part.field = frep::tapeField(c.standInField->tape(), 0.0, c.standInField->parameters(posed));
      part.bounds = c.hasDomain ? c.domain : skin::standInBounds(posed);
      c.standInParts = std::make_shared<const std::vector<ShapePart>>(1, part);
      c.standInVersion = version;
    }
    return c.standInParts;
  }
  auto parts = std::make_shared<std::vector<ShapePart>>(c.parts);
  if (c.fieldPart == kNone)
    return parts;
  auto it = s.shapeParameters.find(c.name);
  if (it != s.shapeParameters.end() || c.spaceTime)
  {
    // A space-time cell's cross-section at the model's time; the other fields have no time.
    const std::vector<double> parameters = it != s.shapeParameters.end()
      ? it->second
      : std::vector<double>(static_cast<std::size_t>(c.parameterCount), 0.0);
    (*parts)[c.fieldPart].field =
      frep::tapeField(c.tape, c.spaceTime ? shapeTime() : 0.0, parameters);
  }
  return parts;
}

std::vector<Affine> ModelState::skinningMatrices(const CellSpec& c) const
{
  if (const auto it = s.deformations.find(c.name); it != s.deformations.end())
    return *it->second;
  return skin::jointMatrices(
    *c.skinned, skin::poseNodes(*c.skinned, c.skinAnimation, animationTime(c)));
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

std::string ModelState::hierarchicalParent(const std::string& cell, std::size_t instance) const
{
  if (instance == kNone)
    return {};
  // The first hierarchical parent in the instance carries the cell.
  for (const RelationSpec& r : instances[instance].dependency)
    if (r.hierarchical && r.dependent == cell && cellIndex.count(r.master))
      return r.master;
  return {};
}

Affine ModelState::carrier(const std::string& cell, int depth) const
{
  if (depth > static_cast<int>(cells.size()))
    throw std::runtime_error("HIERARCHICAL dependencies form a cycle through " + cell);
  const std::string parent = hierarchicalParent(cell, s.active);
  const Affine byParent = parent.empty() ? Affine{} : place(parent, depth + 1);
  const auto kept = s.keptPlacements.find(cell);
  return kept == s.keptPlacements.end() ? byParent : byParent * kept->second;
}

Affine ModelState::place(const std::string& cell, int depth) const
{
  return carrier(cell, depth) * localPlace(cell);
}

void ModelState::keepPlacementsAcross(std::size_t from, std::size_t to)
{
  if (from == kNone)
    return;
  // A cell that stays while its hierarchical parent changes (thesis App. C: ANDY_OUT drops
  // Eggshell -> Egg_contents) keeps where it is in the world, as a scene graph re-parents a node:
  // its carrier before the switch becomes its new parent's placement times a kept offset, so
  // only later motion of the new parent (or of its own transform) moves it.
  const auto& before = instances[from].cells;
  std::map<std::string, Affine> carried;
  for (const std::string& cell : instances[to].cells)
  {
    if (std::find(before.begin(), before.end(), cell) == before.end())
      s.keptPlacements.erase(cell); // a cell that enters is placed afresh
    else if (hierarchicalParent(cell, from) != hierarchicalParent(cell, to))
      carried[cell] = carrier(cell);
  }
  const std::size_t saved = s.active;
  s.active = to;
  std::set<std::string> done;
  // Parents first: a re-parented parent's kept offset is part of its child's new carrier.
  std::function<void(const std::string&, int)> keep = [&](const std::string& cell, int depth)
  {
    if (done.count(cell) || depth > static_cast<int>(cells.size()))
      return;
    done.insert(cell);
    const std::string parent = hierarchicalParent(cell, to);
    if (!parent.empty() && carried.count(parent))
      keep(parent, depth + 1);
    s.keptPlacements.erase(cell);
    const Affine byParent = parent.empty() ? Affine{} : place(parent);
    try
    {
      s.keptPlacements[cell] = byParent.inverse() * carried.at(cell);
    }
    catch (const std::invalid_argument&)
    {
      // A parent scaled to nothing has no frame to keep the cell in: it follows the parent.
    }
  };
  for (const auto& entry : carried)
    keep(entry.first, 0);
  s.active = saved;
}

namespace
{

/// The affine map taking box `from` onto box `to` (centre onto centre, each extent scaled; an axis
/// on which either box is flat keeps its scale, a 2D shape's z).
Affine boxOntoBox(const frep::Box3& from, const frep::Box3& to)
{
  Affine m;
  for (int k = 0; k < 3; ++k)
  {
    const double e = from.hi[k] - from.lo[k], f = to.hi[k] - to.lo[k];
    const double s = (e > 1e-12 && f > 1e-12) ? f / e : 1.0;
    m.a[static_cast<std::size_t>(4 * k)] = s;
    m.b[k] = 0.5 * (to.lo[k] + to.hi[k]) - s * 0.5 * (from.lo[k] + from.hi[k]);
  }
  return m;
}

frep::Box3 lerpBox(const frep::Box3& a, const frep::Box3& b, double u)
{
  return { frep::lerp(a.lo, b.lo, u), frep::lerp(a.hi, b.hi, u) };
}

} // namespace

void ModelState::alignInSpaceTime(
  PlacedShapePtr& a, PlacedShapePtr& b, const OperandNumbers& n, double t) const
{
  // Thesis 5.3.2 (L3098-L3108): time-dependent affine maps of the operands in space-time, made
  // from their bounding domains. With u the transition's progress, A's extrusion is carried from
  // its own box toward B's (a fraction align * u of the way) and B's from A's toward its own, so
  // halfway through (align = 1) both sit on the middle box and overlap instead of thinning into
  // separate components. Only the slice at t is ever evaluated, so mapping the operands as they
  // are at t is the map of the space-time operands (before t0 A is unmoved, after t1 B is).
  const frep::Box3 boxA = a->worldBounds(), boxB = b->worldBounds();
  const double u = std::clamp((t - n.spaceTime.t0) / (n.spaceTime.t1 - n.spaceTime.t0), 0.0, 1.0);
  auto moved = [](const PlacedShapePtr& s, const Affine& m)
  {
    auto c = std::make_shared<PlacedShape>(*s);
    c->place = m * s->place;
    return PlacedShapePtr(std::move(c));
  };
  const PlacedShapePtr movedA = moved(a, boxOntoBox(boxA, lerpBox(boxA, boxB, n.align * u)));
  b = moved(b, boxOntoBox(boxB, lerpBox(boxB, boxA, n.align * (1 - u))));
  a = movedA;
}

std::vector<geometry::ControlPair> ModelState::controlPairs(const CellSpec& c,
  const OperandNumbers& n, const PlacedShapePtr& a, const PlacedShapePtr& b, int depth) const
{
  if (n.warpCount == 0)
    return n.pairs;
  // The thick features depend on the operands' shapes and placements only, not on time: found
  // again only when those change.
  std::uint64_t key = mix(bitsOf(n.warpCount), bitsOf(n.warpSeparation));
  for (const std::string& o : { c.operands->a, c.operands->b })
  {
    key = mix(key, versionOf(o, depth + 1));
    const Affine placed = place(o);
    for (double d : placed.a)
      key = mix(key, bitsOf(d));
    for (double d : placed.b)
      key = mix(key, bitsOf(d));
  }
  key |= 1; // never 0, the unset key
  if (key != c.operands->pairedFor)
  {
    c.operands->autoPairs =
      geometry::pairControlPoints(geometry::thickFeatures(*a, n.warpCount, n.warpSeparation),
        geometry::thickFeatures(*b, n.warpCount, n.warpSeparation));
    c.operands->pairedFor = key;
  }
  return c.operands->autoPairs;
}

PlacedShapePtr ModelState::shapeOf(const std::string& cell, int depth) const
{
  if (depth > static_cast<int>(cells.size()))
    throw std::runtime_error("the shapes of blend/union cells refer to each other in a cycle");
  const CellSpec& c = cells[cellIndex.at(cell)];
  auto shape = std::make_shared<PlacedShape>();
  shape->cell = c.name;
  shape->dimension = spaceDimension(c);
  shape->place = place(cell);
  // A stand-in is placed with its mesh cell, then by its own placement.
  if (c.standIn)
    shape->place = shape->place * place(c.standInOf);
  if (c.operands && !s.shapes.count(cell))
  {
    ShapePart part;
    PlacedShapePtr a = shapeOf(c.operands->a, depth + 1), b = shapeOf(c.operands->b, depth + 1);
    const OperandNumbers n = operandNumbersOf(c);
    if (c.operands->kind == ShapePart::Kind::SpaceTimeBlend)
    {
      if (n.align > 0)
        alignInSpaceTime(a, b, n, shapeTime());
      part = geometry::spaceTimeBlendPart(
        a, b, n.spaceTime, shapeTime(), controlPairs(c, n, a, b, depth));
    }
    part.kind = c.operands->kind;
    part.operandA = a;
    part.operandB = b;
    part.amount = n.amount;
    part.a1 = n.a1;
    part.a2 = n.a2;
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
  // A space-time cell's cross-section changes with time.
  if (c.spaceTime)
    v = mix(v, bitsOf(shapeTime()));
  // A skinned mesh changes with its animation's time.
  if (c.skinned)
    v = mix(v, bitsOf(animationTime(c)));
  // A stand-in changes with its mesh cell's pose (its placement moves it whole).
  if (c.standIn)
    v = mix(v, versionOf(c.standInOf, depth + 1));
  if (!c.operands || s.shapes.count(cell) || depth > static_cast<int>(cells.size()))
    return v;
  // A blend or union lives in world coordinates: it changes when an operand moves, and when its
  // numbers change.
  const OperandNumbers n = operandNumbersOf(c);
  for (double d :
    { n.amount, n.a1, n.a2, n.spaceTime.t0, n.spaceTime.t1, n.spaceTime.a0, n.spaceTime.a1,
      n.spaceTime.a2, n.spaceTime.a3, n.align, n.warpSeparation, static_cast<double>(n.warpCount) })
    v = mix(v, bitsOf(d));
  for (const geometry::ControlPair& p : n.pairs)
    for (int k = 0; k < 3; ++k)
      v = mix(mix(v, bitsOf(p.source[k])), bitsOf(p.destination[k]));
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
  // A cell's code names its own shape bare (thesis L3160: makeCrossSection(shape, globalT)).
  if (name == "shape" && !cell_.empty())
    return member(Value::cell(cell_), name, out);
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
    out.text = spec.name; // whose shape: makeCrossSection and getVolume place it as that cell
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

// ---- DynamicModel::value ------------------------------------------------------------------

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

} // namespace ictk::engine
