// SPDX-License-Identifier: BSD-3-Clause
// A cell's `shape =` built into its parts (ModelState.h): inline HyperFun, or the shape
// constructors of Lang/IcmBuiltins.h's table, one builder per entry in kShapes, found by the
// table's id (Engine/Builtins.h checks that every entry has exactly one builder).
#include "Engine/Builtins.h"
#include "Engine/ModelState.h"
#include "Lang/FRepXml.h"
#include "Lang/HyperFun.h"
#include "Lang/MeshFile.h"
#include "Skin/SkinFile.h"
#include "Skin/StandIn.h"

#include "FRep/Operations.h"

#include <cmath>
#include <functional>

namespace ictk::engine
{

namespace
{

using lang::icm::ShapeId;

/// A constructor's call in `shape =`: its evaluated arguments and the cell it builds into.
struct ShapeCall
{
  ModelState& m;
  CellSpec& c;
  const Expr& expr;
  const std::string& name;
  const std::vector<Value>& args;

  [[noreturn]] void fail(const std::string& message) const { m.fail(expr.pos, message); }
  double num(std::size_t i) const
  {
    if (i >= args.size() || !args[i].isNumber() || !std::isfinite(args[i].number))
      fail(name + ": argument " + std::to_string(i + 1) + " must be a finite number");
    return args[i].number;
  }
  /// Sizes, radii and blend amounts.
  double size(std::size_t i) const
  {
    const double x = num(i);
    if (x < 0.0)
      fail(name + ": argument " + std::to_string(i + 1) + " must not be negative");
    return x;
  }
  Vec3 point(std::size_t i) const
  {
    if (i >= args.size() || args[i].type != Value::Type::Vec3)
      fail(name + ": argument " + std::to_string(i + 1) + " must be a point vec3(x, y, z)");
    return args[i].vec;
  }
  void add(ShapePart part) const { c.parts.push_back(std::move(part)); }
};

using ShapeConstructor = void (*)(const ShapeCall&);

/// Makes a HyperFun or XML model the cell's field part, kept as a tape so that
/// setShapeParameter can rebind its parameters.
void addField(CellSpec& c, const frep::Hypervolume& model, int parameterCount)
{
  ShapePart part;
  part.kind = ShapePart::Kind::Field;
  const frep::Domain domain = model.geometry().domain();
  // XYT is a 2D exemplar's space-time: its cross-sections lie in the plane.
  part.fieldDimension = domain == frep::Domain::XY || domain == frep::Domain::XYT ? 2 : 3;
  c.spaceTime = (frep::domainAxes(domain) & (1u << static_cast<int>(frep::Axis::T))) != 0;
  c.tape = frep::Tape::compile(model.geometry().function());
  c.parameterCount = parameterCount;
  part.field = frep::tapeField(
    c.tape, 0.0, std::vector<double>(static_cast<std::size_t>(parameterCount), 0.0));
  part.bounds = c.domain;
  c.fieldPart = c.parts.size();
  c.parts.push_back(part);
}

void fileShape(const ShapeCall& s)
{
  if (s.args.empty() || s.args[0].type != Value::Type::String)
    s.fail("file(\"name\") takes the file's name");
  const std::string& directory = s.m.model.directory;
  const std::string path = directory.empty() || s.args[0].text.rfind('/', 0) == 0
    ? s.args[0].text
    : directory + "/" + s.args[0].text;
  const bool xml = path.size() > 4 && path.substr(path.size() - 4) == ".xml";
  try
  {
    if (lang::isMeshFile(path))
    {
      // An explicit triangle surface in the cell's local coordinates (a B-cell, thesis loadMesh).
      const complex::ExplicitGeometry mesh = lang::readMeshFile(path);
      ShapePart part;
      part.kind = ShapePart::Kind::Mesh;
      part.points = mesh.points;
      part.triangles = mesh.triangles;
      s.add(std::move(part));
    }
    else if (xml)
      addField(s.c, lang::readFRepXmlFile(path), 0);
    else
    {
      const lang::HyperFunModel hf = lang::readHyperFunFile(path);
      addField(s.c, hf.model, hf.parameterCount);
    }
  }
  catch (const std::exception& e)
  {
    s.fail("cannot read the shape file '" + path + "': " + e.what());
  }
}

/// Reads the skinned mesh of loadMesh / loadSegmentsHierarchy("file", "animation") into the cell
/// with the animation it plays.
std::shared_ptr<const skin::SkinnedMesh> readSkinned(const ShapeCall& s)
{
  for (std::size_t i = 0; i < 2; ++i)
    if (i >= s.args.size() || s.args[i].type != Value::Type::String)
      s.fail(s.name + "(\"path\", \"animation\") takes two strings");
  const std::string path = lang::modelFilePath(s.m.model, s.args[0].text);
  try
  {
    // A surface whose patches touch at corners becomes a B-cell with those corners split
    // (skin::splitNonManifoldVertices), as the checker reads it.
    skin::SkinnedMesh read = skin::readSkinnedMesh(path);
    skin::splitNonManifoldVertices(read);
    auto mesh = std::make_shared<const skin::SkinnedMesh>(std::move(read));
    s.c.skinAnimation = &mesh->animation(s.args[1].text);
    s.c.skinned = mesh;
    return mesh;
  }
  catch (const std::exception& e)
  {
    s.fail(s.name + ": " + e.what());
  }
}

/// loadMesh("file", "animation"): a skinned mesh (thesis Appendix B's Andy), its mesh part posed
/// at the cell's time by partsOf.
void loadMeshShape(const ShapeCall& s)
{
  const auto mesh = readSkinned(s);
  ShapePart part;
  part.kind = ShapePart::Kind::Mesh;
  part.points = mesh->restPoints;
  for (const auto& t : mesh->triangles)
    part.triangles.push_back({ static_cast<std::uint32_t>(t[0]), static_cast<std::uint32_t>(t[1]),
      static_cast<std::uint32_t>(t[2]) });
  // The joint that weighs most on each vertex, for colouring a frame by its skeleton.
  ictk::discretize::PointArray joint{ "DominantJoint", 1, {} },
    weight{ "DominantJointWeight", 1, {} };
  for (const skin::Influence& f : mesh->dominantInfluences())
  {
    joint.values.push_back(f.joint);
    weight.values.push_back(f.weight);
  }
  part.pointData = { std::move(joint), std::move(weight) };
  s.c.meshPart = s.c.parts.size();
  s.add(std::move(part));
}

/// loadSegmentsHierarchy("file", "animation"): the skeleton of a skinned mesh (Appendix B's
/// Skeleton C-cell), a segment per bone, posed at the cell's time by partsOf.
void loadSegmentsHierarchyShape(const ShapeCall& s)
{
  const auto mesh = readSkinned(s);
  s.c.bones = skin::bonesOf(*mesh);
  if (s.c.bones.empty())
    s.fail(s.name + ": " + mesh->file + " has no bone (a joint with a parent joint)");
  for (const skin::Bone& b : s.c.bones)
  {
    ShapePart part;
    part.kind = ShapePart::Kind::Segment;
    part.points = { skin::jointMarker(*mesh, b.parentJoint), skin::jointMarker(*mesh, b.joint) };
    s.add(std::move(part));
  }
}

/// standIn(cell): the cell's field is the stand-in of a skinned mesh cell, fitted once the cells
/// are built (ModelState::fitStandIns) and posed by partsOf.
void standInShape(const ShapeCall& s)
{
  if (s.args.empty() || s.args[0].type != Value::Type::Cell)
    s.fail("standIn takes a cell");
  s.c.standInOf = s.args[0].text;
  s.c.standInPos = s.expr.pos;
}

void pointShape(const ShapeCall& s)
{
  ShapePart part;
  part.kind = ShapePart::Kind::Point;
  part.points = { { s.num(0), s.num(1), s.args.size() > 2 ? s.num(2) : 0.0 } };
  s.add(part);
}

void segmentShape(const ShapeCall& s)
{
  ShapePart part;
  part.kind = ShapePart::Kind::Segment;
  part.points = { s.point(0), s.point(1) };
  s.add(part);
}

void polylineShape(const ShapeCall& s)
{
  ShapePart part;
  part.kind = ShapePart::Kind::Polyline;
  for (std::size_t i = 0; i < s.args.size(); ++i)
    part.points.push_back(s.point(i));
  s.add(part);
}

template <ShapePart::Kind kind>
void arcShape(const ShapeCall& s)
{
  ShapePart part;
  part.kind = kind;
  part.points = { s.point(0), s.point(1) };
  part.radius = s.size(2);
  s.add(part);
}

void rectangleShape(const ShapeCall& s)
{
  ShapePart part;
  part.kind = ShapePart::Kind::Rectangle;
  part.size = { s.size(0), s.size(1), 0.0 };
  s.add(part);
}

template <ShapePart::Kind kind>
void roundShape(const ShapeCall& s)
{
  ShapePart part;
  part.kind = kind;
  part.radius = s.size(0);
  s.add(part);
}

void boxShape(const ShapeCall& s)
{
  ShapePart part;
  part.kind = ShapePart::Kind::Box;
  part.size = { s.size(0), s.size(1), s.size(2) };
  s.add(part);
}

/// blend(cellA, cellB, amount), union(cellA, cellB): the cell's shape is made of other cells'.
template <ShapePart::Kind kind>
void operandsShape(const ShapeCall& s)
{
  const std::vector<Value>& args = s.args;
  if (args.size() < 2 || args[0].type != Value::Type::Cell || args[1].type != Value::Type::Cell)
    s.fail(s.name + " takes two cells");
  CellSpec::Operands o;
  o.kind = kind;
  o.a = args[0].text;
  o.b = args[1].text;
  o.pos = s.expr.pos;
  // The numbers are evaluated at every step (ModelState::evaluateOperands).
  for (std::size_t i = 3; i < s.expr.kids.size(); ++i)
    o.numbers.push_back(s.expr.kids[i].get());
  if (kind == ShapePart::Kind::Blend && o.numbers.size() == 2)
    s.fail(s.name + ": the scales a1 and a2 come together, after the amount");
  s.c.operands = std::move(o);
}

/// spaceTimeBlendCells(A, B, t0, t1, a0, a1, a2, a3): a space-time cell (thesis 5.3.1) whose
/// cross-section at global time t is the blend's slice there.
void spaceTimeBlendShape(const ShapeCall& s)
{
  operandsShape<ShapePart::Kind::SpaceTimeBlend>(s);
  s.c.spaceTime = true;
}

/// Whether a `shape =` of constructors reads names (parameters) in the arguments it evaluates
/// itself: the numbers after a blend's cells are evaluated every step anyway (evaluateOperands).
bool readsParameters(const Property& p)
{
  std::function<bool(const Expr&)> reads = [&](const Expr& e)
  {
    if (e.kind == Expr::Kind::Name || e.kind == Expr::Kind::Member)
      return e.text != "pi";
    // A call's first kid is the function's name.
    for (std::size_t i = e.kind == Expr::Kind::Call ? 1 : 0; i < e.kids.size(); ++i)
      if (e.kids[i] && reads(*e.kids[i]))
        return true;
    return false;
  };
  if (p.isHyperFun)
    return false;
  for (const ExprPtr& v : p.values)
  {
    const lang::icm::ShapeBuiltin* shape =
      v->kind == Expr::Kind::Call ? lang::icm::findShapeBuiltin(v->text) : nullptr;
    if (!shape || shape->cellArguments > 0)
      continue;
    for (std::size_t i = 1; i < v->kids.size(); ++i)
      if (reads(*v->kids[i]))
        return true;
  }
  return false;
}

/// The engine's builders of the shape constructors (lang::icm::shapeBuiltins()).
const std::pair<ShapeId, ShapeConstructor> kShapes[] = {
  { ShapeId::File, fileShape },
  { ShapeId::Point, pointShape },
  { ShapeId::Segment, segmentShape },
  { ShapeId::Arc, arcShape<ShapePart::Kind::Arc> },
  { ShapeId::CircularSegment, arcShape<ShapePart::Kind::CircularSegment> },
  { ShapeId::Polyline, polylineShape },
  { ShapeId::Rectangle, rectangleShape },
  { ShapeId::Disk, roundShape<ShapePart::Kind::Disk> },
  { ShapeId::Box, boxShape },
  { ShapeId::Sphere, roundShape<ShapePart::Kind::Sphere> },
  { ShapeId::Blend, operandsShape<ShapePart::Kind::Blend> },
  { ShapeId::BlendCells, operandsShape<ShapePart::Kind::Blend> },
  { ShapeId::Union, operandsShape<ShapePart::Kind::Union> },
  { ShapeId::SpaceTimeBlend, spaceTimeBlendShape },
  { ShapeId::LoadMesh, loadMeshShape },
  { ShapeId::LoadSegmentsHierarchy, loadSegmentsHierarchyShape },
  { ShapeId::StandIn, standInShape },
};

} // namespace

void ModelState::fitStandIns()
{
  for (CellSpec& c : cells)
  {
    if (c.standInOf.empty())
      continue;
    const auto it = cellIndex.find(c.standInOf);
    if (it == cellIndex.end())
      fail(c.standInPos, "standIn: no cell named '" + c.standInOf + "'");
    const CellSpec& mesh = cells[it->second];
    if (!mesh.skinned || mesh.meshPart == kNone)
      fail(c.standInPos,
        "standIn takes a skinned mesh cell, and '" + c.standInOf +
          "' is not one (shape = loadMesh(...))");
    try
    {
      skin::StandIn standIn = skin::fittedStandIn(*mesh.skinned);
      c.projection =
        std::make_shared<const skin::Projection>(skin::projectOntoStandIn(*mesh.skinned, standIn));
      c.standInField = std::make_shared<const skin::StandInField>(standIn.segments.size());
      c.standIn = std::make_shared<const skin::StandIn>(std::move(standIn));
    }
    catch (const std::exception& e)
    {
      fail(c.standInPos, std::string("standIn: ") + e.what());
    }
  }
}

std::vector<ShapeId> shapeConstructors()
{
  return idsOf(kShapes);
}

void ModelState::buildShape(CellSpec& c, const Property& p)
{
  c.parts.clear();
  c.tape.reset();
  c.operands.reset();
  c.fieldPart = kNone;
  c.spaceTime = false;
  c.skinned.reset();
  c.skinAnimation = nullptr;
  c.meshPart = kNone;
  c.bones.clear();
  c.posed.reset();
  c.standInOf.clear();
  c.standIn.reset();
  c.standInField.reset();
  c.standInParts.reset();
  if (p.isHyperFun)
  {
    try
    {
      const lang::HyperFunModel hf = lang::readHyperFun(p.hyperFunText, file);
      addField(c, hf.model, hf.parameterCount);
    }
    catch (const lang::ParseError& e)
    {
      fail(p.hyperFunPos, std::string("in the hyperfun shape: ") + e.what());
    }
    return;
  }
  c.shapeExpression = nullptr;
  if (readsParameters(p))
  {
    c.shapeExpression = &p; // built by buildModel once the parameter table exists
    return;
  }
  buildShapeParts(c, p, kNone);
}

void ModelState::buildShapeParts(CellSpec& c, const Property& p, std::size_t instance)
{
  EngineScope scope(*this, c.name, instance);
  for (const ExprPtr& v : p.values)
  {
    if (v->kind != Expr::Kind::Call)
      fail(v->pos, "a shape is hyperfun { ... }, file(\"...\") or a constructor such as disk(r)");
    const std::string& f = v->text;
    const lang::icm::ShapeBuiltin* shape = lang::icm::findShapeBuiltin(f);
    // The leading arguments that name cells are passed on as cells (blend, union); the numbers
    // after them are evaluated at every step, in the cell's scope (evaluateOperands).
    const std::size_t cellArguments = shape ? static_cast<std::size_t>(shape->cellArguments) : 0;
    std::vector<Value> args;
    for (std::size_t i = 1; i < v->kids.size(); ++i)
    {
      const Expr& a = *v->kids[i];
      if (i <= cellArguments && a.kind == Expr::Kind::Name)
        args.push_back(Value::cell(a.text));
      else if (cellArguments == 0)
        args.push_back(interpreter.evaluate(a, scope));
    }
    ShapeConstructor build = nullptr;
    if (shape)
      for (const auto& [id, fn] : kShapes)
        if (id == shape->id)
          build = fn;
    if (!build)
      fail(v->pos, "unknown shape constructor '" + f + "'");
    build(ShapeCall{ *this, c, *v, f, args });
  }
}

void ModelState::rebuildShape(const CellSpec& c)
{
  CellSpec now;
  now.name = c.name;
  now.dimension = c.dimension;
  buildShapeParts(now, *c.shapeExpression, s.active);
  const std::shared_ptr<const std::vector<ShapePart>> before = partsOf(c);
  const std::vector<ShapePart>& was = *before;
  bool same = was.size() == now.parts.size();
  for (std::size_t i = 0; same && i < was.size(); ++i)
    same = was[i].kind == now.parts[i].kind && was[i].points == now.parts[i].points &&
      was[i].size == now.parts[i].size && was[i].radius == now.parts[i].radius;
  if (same)
    return; // the discretisation of the shape stays valid (time coherence)
  s.shapes[c.name] = std::make_shared<const std::vector<ShapePart>>(std::move(now.parts));
  bumpVersion(c.name);
}

} // namespace ictk::engine
