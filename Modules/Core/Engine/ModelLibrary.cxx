// SPDX-License-Identifier: BSD-3-Clause
// The running model's half of the built-in library (Lang/IcmBuiltins.h, the Library layer):
// geometry between cells, events, animation curves, shapes of T-cells and FRep shape parameters,
// one function per entry in kLibrary (Engine/Builtins.h checks it against the table).
#include "Engine/Builtins.h"
#include "Engine/ModelState.h"
#include "Geometry/Queries.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace ictk::engine
{

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

/// The cell whose `shape` a shape value is (Cell.shape, makeCrossSection(...)); the shapes code
/// builds (segment(...), arc(...)) belong to no cell yet.
const CellSpec& shapeOwner(const LibraryCall& call, const char* what)
{
  const Value& v = call.args.at(0);
  if (v.type != Value::Type::Shape || v.text.empty())
    throw std::runtime_error(
      std::string(what) + " takes a cell's shape (`shape` in its reactions)");
  return call.m.cells[call.m.cellIndex.at(v.text)];
}

/// makeCrossSection(shape, t) (thesis L3160): the engine already sees a space-time cell as its
/// cross-section at the time being evaluated, so this names that slice and refuses any other
/// time rather than silently slicing somewhere else.
Value makeCrossSection(const LibraryCall& call)
{
  const CellSpec& c = shapeOwner(call, "makeCrossSection");
  if (!c.spaceTime)
    throw std::runtime_error("makeCrossSection: " + c.name +
      " is not a space-time cell (its shape has no time to cut at)");
  const double t = call.args.at(1).number, now = call.m.shapeTime();
  if (!(std::abs(t - now) <= 1e-12 * std::max(1.0, std::abs(now))))
    throw std::runtime_error("makeCrossSection: the shape of " + c.name +
      " is cut at t = " + std::to_string(t) +
      ", but the model is evaluating t = " + std::to_string(now) + " (pass globalT)");
  return call.args[0];
}

/// getVolume(shape) (thesis L3162): the measure of the cell's shape as placed now.
Value getVolume(const LibraryCall& call)
{
  const CellSpec& c = shapeOwner(call, "getVolume");
  return Value::real(geometry::measure(*call.m.shapeOf(c.name), call.m.options.geometry));
}

/// The skinned cell a library call's first argument names.
const CellSpec& skinnedCell(const LibraryCall& call)
{
  const Value& cell = call.args.at(0);
  if (cell.type != Value::Type::Cell)
    throw std::runtime_error("the first argument is a cell");
  const CellSpec& c = call.m.cells[call.m.cellIndex.at(cell.text)];
  if (!c.skinned)
    throw std::runtime_error(
      "the cell " + cell.text + " is not a skinned cell (loadMesh, loadSegmentsHierarchy)");
  return c;
}

/// jointPosition(cell, "joint"): the joint's origin posed now, placed by the cell.
Value jointPosition(const LibraryCall& call)
{
  ModelState& m = call.m;
  const CellSpec& c = skinnedCell(call);
  const std::string& joint = call.args.at(1).text;
  const auto& nodes = c.skinned->nodes;
  const auto it =
    std::find_if(nodes.begin(), nodes.end(), [&](const skin::Node& n) { return n.name == joint; });
  if (it == nodes.end())
    throw std::runtime_error("no joint named '" + joint + "' in " + c.skinned->file);
  const int node = static_cast<int>(it - nodes.begin());
  if (m.s.deformations.count(c.name))
  {
    // Posed by setDeformation: only the joints have matrices; a joint's origin is its marker
    // carried by its own.
    const auto& joints = c.skinned->joints;
    const auto j = std::find_if(
      joints.begin(), joints.end(), [&](const skin::Joint& x) { return x.node == node; });
    if (j == joints.end())
      throw std::runtime_error("'" + joint + "' of " + c.skinned->file +
        " is a node but not a joint, and the cell is posed by setDeformation");
    const int index = static_cast<int>(j - joints.begin());
    return Value::vector(
      m.place(c.name).apply(m.skinningMatrices(c)[static_cast<std::size_t>(index)].apply(
        skin::jointMarker(*c.skinned, index))));
  }
  const std::vector<Affine> globals =
    skin::poseNodes(*c.skinned, c.skinAnimation, m.animationTime(c));
  return Value::vector(m.place(c.name).apply(globals[static_cast<std::size_t>(node)].b));
}

/// jointTransforms(cell, t): the skinning matrices of the cell's animation at t seconds.
Value jointTransforms(const LibraryCall& call)
{
  const CellSpec& c = skinnedCell(call);
  const double t = call.args.at(1).number;
  if (!call.args.at(1).isNumber() || !std::isfinite(t))
    throw std::runtime_error("the time is not a finite number");
  return Value::transformArray(
    skin::jointMatrices(*c.skinned, skin::poseNodes(*c.skinned, c.skinAnimation, t)));
}

/// setDeformation(cell, transforms): the cell is posed by these matrices from now on.
Value setDeformation(const LibraryCall& call)
{
  ModelState& m = call.m;
  const CellSpec& c = skinnedCell(call);
  const Value& v = call.args.at(1);
  if (v.type != Value::Type::Transforms)
    throw std::runtime_error(
      std::string("setDeformation takes an array of TRANSFORM, not a ") + typeName(v.type));
  if (v.transforms->size() != c.skinned->joints.size())
    throw std::runtime_error("setDeformation: " + std::to_string(v.transforms->size()) +
      " transforms for the " + std::to_string(c.skinned->joints.size()) + " joints of " +
      c.skinned->file);
  auto& current = m.s.deformations[c.name];
  const auto same = [](const Affine& a, const Affine& b)
  {
    return a.a == b.a && a.b == b.b;
  };
  if (!current ||
    !std::equal(current->begin(), current->end(), v.transforms->begin(), v.transforms->end(), same))
  {
    current = v.transforms;
    m.bumpVersion(c.name);
  }
  return {};
}

/// The loadMesh cell of a projection built-in and the cell of its stand-in.
std::pair<const CellSpec*, const CellSpec*> projectedCell(const LibraryCall& call)
{
  const CellSpec& c = skinnedCell(call);
  const CellSpec* standIn = c.meshPart == kNone ? nullptr : call.m.standInOf(c.name);
  if (!standIn)
    throw std::runtime_error(
      "no cell has the stand-in of " + c.name + " (shape = standIn(" + c.name + "))");
  return { &c, standIn };
}

/// The weight map `name` (a model function of x, y, z) at the cell's rest points.
std::vector<double> weightMapOf(const LibraryCall& call, const CellSpec& c, const std::string& name)
{
  const auto& functions = call.m.model.functions;
  const auto f = std::find_if(
    functions.begin(), functions.end(), [&](const Procedure& p) { return p.name.text == name; });
  if (f == functions.end())
    throw std::runtime_error("no model function named '" + name +
      "' (a weight map is a function(real x, real y, real z) of the bind-pose position)");
  if (f->formals.size() != 3)
    throw std::runtime_error("function '" + name + "' takes " + std::to_string(f->formals.size()) +
      " argument(s), and a weight map takes the bind-pose position (x, y, z)");
  std::vector<double> out;
  out.reserve(c.skinned->vertexCount());
  for (const Vec3& p : c.skinned->restPoints)
  {
    const Value v = call.m.interpreter.run(
      *f, { Value::real(p[0]), Value::real(p[1]), Value::real(p[2]) }, call.scope);
    if (!v.isNumber() || !std::isfinite(v.number))
      throw std::runtime_error("the weight map '" + name + "' gives the vertex at (" +
        std::to_string(p[0]) + ", " + std::to_string(p[1]) + ", " + std::to_string(p[2]) +
        ") no finite number");
    out.push_back(v.number);
  }
  return out;
}

/// setProjection(cell, alpha [, "weights" [, spread]]): how far the mesh's vertices have moved
/// to their projections, delayed per vertex by a weight map.
Value setProjection(const LibraryCall& call)
{
  ModelState& m = call.m;
  const auto [cell, standIn] = projectedCell(call);
  const CellSpec& c = *cell;
  const skin::Projection& projection = *standIn->projection;
  if (projection.failures > 0)
    throw std::runtime_error(std::to_string(projection.failures) + " of the " +
      std::to_string(c.skinned->vertexCount()) + " vertices of " + c.name + " (the first: vertex " +
      std::to_string(projection.firstFailure) + ") do not reach its stand-in " + standIn->name +
      " within " + std::to_string(skin::ProjectionOptions{}.maxIterations) +
      " Newton steps (|F| up to " + std::to_string(projection.maxResidual) + ")");
  const Value& v = call.args.at(1);
  if (!v.isNumber() || !std::isfinite(v.number))
    throw std::runtime_error("alpha is not a finite number");
  ProjectionSetting setting;
  setting.alpha = std::clamp(v.number, 0.0, 1.0);
  if (call.args.size() >= 3)
  {
    const Value& w = call.args[2];
    if (w.type != Value::Type::String)
      throw std::runtime_error("the weight map is the name of a model function, in quotes");
    setting.weights = w.text;
    if (!c.weightMaps.count(w.text))
      c.weightMaps[w.text] = weightMapOf(call, c, w.text);
  }
  if (call.args.size() >= 4)
  {
    const Value& spread = call.args[3];
    if (!spread.isNumber() || !(spread.number >= 0 && spread.number < 1))
      throw std::runtime_error("the spread of the delays is in [0, 1)");
    setting.spread = spread.number;
  }
  const auto it = m.s.projections.find(c.name);
  if (it == m.s.projections.end() || !(it->second == setting))
  {
    m.s.projections[c.name] = setting;
    m.bumpVersion(c.name);
  }
  return {};
}

/// projectionResidual(cell), projectionAngle(cell): how far the posed mesh is from its posed
/// stand-in, in world units and degrees.
Value projectionResidualOf(const LibraryCall& call)
{
  ModelState& m = call.m;
  const auto [cell, standIn] = projectedCell(call);
  const auto parts = m.partsOf(*cell);
  const ShapePart& part = (*parts)[cell->meshPart];
  skin::Posed posed;
  posed.points = part.points;
  for (const discretize::PointArray& a : part.pointData)
    if (a.name == "Normals")
      for (std::size_t i = 0; i + 2 < a.values.size(); i += 3)
        posed.normals.push_back({ a.values[i], a.values[i + 1], a.values[i + 2] });
  const skin::ProjectionResidual r =
    skin::projectionResidual(posed, *(*m.partsOf(*standIn))[0].field, m.place(cell->name));
  return Value::real(call.builtin.id == BuiltinId::ProjectionAngle ? r.degrees : r.distance);
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
  { BuiltinId::MakeCrossSection, makeCrossSection },
  { BuiltinId::GetVolume, getVolume },
  { BuiltinId::JointPosition, jointPosition },
  { BuiltinId::JointTransforms, jointTransforms },
  { BuiltinId::SetDeformation, setDeformation },
  { BuiltinId::SetProjection, setProjection },
  { BuiltinId::ProjectionResidual, projectionResidualOf },
  { BuiltinId::ProjectionAngle, projectionResidualOf },
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

} // namespace ictk::engine
