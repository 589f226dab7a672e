// SPDX-License-Identifier: BSD-3-Clause
// The checks of a model's structure: cells (their sources, properties, parameters and shapes) and
// attributes.
#include "Lang/IcmChecker.h"
#include "Lang/MeshFile.h"
#include "Skin/SkinFile.h"

#include "Complex/Cell.h"

#include <optional>

namespace ictk::lang::icmcheck
{

namespace
{

/// A number written out (`0.5`, `-2`): the shape numbers the checker can judge before the
/// engine evaluates them.
std::optional<double> writtenNumber(const Expr& e)
{
  if (e.kind == Expr::Kind::Number)
  {
    return e.number;
  }
  if (e.kind == Expr::Kind::Unary && (e.text == "-" || e.text == "+") && e.kids.size() == 1 &&
    e.kids[0]->kind == Expr::Kind::Number)
  {
    return e.text == "-" ? -e.kids[0]->number : e.kids[0]->number;
  }
  return std::nullopt;
}

} // namespace

const std::set<std::string>& Checker::paramsOf(const CellDef* c, int depth) const
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

std::set<std::string> Checker::paramsOfImpl(const CellDef* c, int depth) const
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

void Checker::cellMember(const Expr& path, const CellMap& cells)
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

void Checker::cell(const CellDef& c, const CellMap& cells, const Instance* in)
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
    property(p, cells, &c, in);
  }
  std::map<std::string, const ParamDecl*> ps;
  params(c.parameters, ps, &cells, "parameter");
  reactionsOf(c.reactions, cells, in, &c);
}

void Checker::property(
  const Property& p, const CellMap& cells, const CellDef* owner, const Instance* in)
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
      if (v->kind != Expr::Kind::Brace || v->kids.size() != 2 || !constantNumber(v->kids[0], lo) ||
        !constantNumber(v->kids[1], hi))
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
      shape(v, cells, owner, in);
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

void Checker::hyperFun(const Property& p)
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

void Checker::shape(
  const ExprPtr& v, const CellMap& cells, const CellDef* owner, const Instance* in)
{
  if (v->kind != Expr::Kind::Call || v->text.empty())
  {
    err(v->pos,
      "shape = hyperfun { ... }, file(\"model.hf\") or a shape constructor such as "
      "disk(r)");
    return;
  }
  const ShapeBuiltin* shape = findShapeBuiltin(v->text);
  const int n = static_cast<int>(v->kids.size()) - 1;
  if (!shape)
  {
    err(v->pos, "unknown shape constructor '" + v->text + "'");
    return;
  }
  const Signature& b = shape->call;
  if (n < b.minArgs || (b.maxArgs >= 0 && n > b.maxArgs))
  {
    err(v->pos,
      "'" + v->text + "' takes " + arity(b) + " argument(s) (" + b.signature + "), found " +
        std::to_string(n));
    return;
  }
  if ((shape->id == ShapeId::Blend || shape->id == ShapeId::BlendCells) && n == 4)
  {
    err(v->kids[4]->pos,
      "'" + v->text + "' takes the scales a1 and a2 together, after the amount (" + b.signature +
        "), or neither");
    return;
  }
  if (shape->id == ShapeId::File)
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
    if (ext != ".hf" && ext != ".xml" && ext != ".obj" && ext != ".off" && ext != ".ply" &&
      ext != ".stl")
    {
      // .vtp (VTK's XML polydata) is named: it is VTK's own format, which the VTK-free engine
      // does not read.
      err(a->pos,
        "file \"" + path + "\": the shape files are .hf, .xml, .obj, .off, .ply or .stl" +
          (ext == ".vtp" ? " (save a .vtp surface as .ply or .stl, e.g. with ParaView)" : ""));
    }
    return;
  }
  if (shape->id == ShapeId::LoadMesh || shape->id == ShapeId::LoadSegmentsHierarchy)
  {
    // A skeleton's segments need no manifold surface.
    loadMesh(*v, shape->id == ShapeId::LoadMesh);
    return;
  }
  if (shape->id == ShapeId::StandIn)
  {
    standIn(*v, cells);
    return;
  }
  if (shape->cellArguments > 0)
  {
    for (std::size_t i = 1;
         i < v->kids.size() && i <= static_cast<std::size_t>(shape->cellArguments); ++i)
    {
      const ExprPtr& a = v->kids[i];
      if (a->kind == Expr::Kind::Name && isMeshCell(a->text, &cells))
      {
        err(a->pos,
          "'" + v->text + "' takes fields, and cell '" + a->text +
            "' is a mesh (.obj/.off, loadMesh)");
      }
    }
  }
  // The leading arguments that name cells (blend, union), then constants.
  const std::size_t cellArguments = static_cast<std::size_t>(shape->cellArguments);
  for (std::size_t i = 1; i <= cellArguments; ++i)
  {
    const ExprPtr& a = v->kids[i];
    if (a->kind != Expr::Kind::Name ||
      (cells.count(a->text) == 0 && globalCells_.count(a->text) == 0))
    {
      err(a->pos,
        a->kind == Expr::Kind::Name ? "undefined cell '" + a->text + "'" : "expected a cell name");
    }
  }
  // The numbers of a shape are evaluated every step: they may read the cell's parameters and
  // the model's (a blend's amount, a space-time blend's parameters, a rope's length).
  for (std::size_t i = cellArguments + 1; i < v->kids.size(); ++i)
  {
    if (!owner)
    {
      constant(v->kids[i]);
      continue;
    }
    Code code;
    code.instance = in;
    code.cells = &cells;
    code.cell = owner;
    code.vars = in ? instanceVars_ : globalVars_;
    for (const std::string& name : paramsOf(owner))
    {
      code.vars.insert(name);
    }
    const Ty t = expr(v->kids[i], code);
    const bool vector = std::string(b.signature).find("vec3") != std::string::npos;
    if (t != Ty::Unknown && !numeric(t) && !(vector && t == Ty::Vec3))
    {
      err(v->kids[i]->pos,
        "argument " + std::to_string(i) + " of '" + v->text + "' must be a number" +
          (vector ? " or a vec3" : ""));
    }
  }
  // A blend's numbers written out are judged here; expressions when the engine evaluates them
  // (at load and every step, at the same place).
  if (shape->id == ShapeId::Blend || shape->id == ShapeId::BlendCells)
  {
    for (std::size_t i = 3; i < v->kids.size(); ++i)
    {
      const std::optional<double> x = writtenNumber(*v->kids[i]);
      if (i == 3 && x && *x < 0)
      {
        err(v->kids[i]->pos, "the blend amount (a0) must not be negative");
      }
      else if (i > 3 && x && !(*x > 0))
      {
        err(v->kids[i]->pos,
          std::string("the blend scale ") + (i == 4 ? "a1" : "a2") + " must be positive");
      }
    }
  }
}

const Property* Checker::shapeOf(const std::string& name, const CellMap* cells, int depth) const
{
  const CellDef* def = nullptr;
  if (cells && cells->count(name))
  {
    def = cells->at(name);
  }
  else if (globalCells_.count(name))
  {
    def = globalCells_.at(name);
  }
  if (!def || depth > 64)
  {
    return nullptr;
  }
  const Property* p = def->property("shape");
  if (!p && !def->source.text.empty())
  {
    // A copy `B <- A` has A's shape unless it gives its own.
    return shapeOf(def->source.text, cells, depth + 1);
  }
  return p;
}

bool Checker::isMeshCell(const std::string& name, const CellMap* cells) const
{
  const Property* p = shapeOf(name, cells);
  if (!p)
  {
    return false;
  }
  for (const ExprPtr& v : p->values)
  {
    if (v->kind == Expr::Kind::Call && v->text == "file" && v->kids.size() == 2 &&
      v->kids[1]->kind == Expr::Kind::String && isMeshFile(v->kids[1]->text))
    {
      return true;
    }
  }
  return loadMeshOf(name, cells) != nullptr;
}

const Expr* Checker::loadMeshOf(const std::string& name, const CellMap* cells) const
{
  const Property* p = shapeOf(name, cells);
  if (!p)
  {
    return nullptr;
  }
  for (const ExprPtr& v : p->values)
  {
    if (v->kind == Expr::Kind::Call &&
      (v->text == "loadMesh" || v->text == "loadSegmentsHierarchy"))
    {
      return v.get();
    }
  }
  return nullptr;
}

const skin::SkinnedMesh* Checker::skinnedMesh(const Expr& path, bool report)
{
  const std::string file = modelFilePath(m_, path.text);
  auto it = skinned_.find(file);
  if (it == skinned_.end())
  {
    std::shared_ptr<const skin::SkinnedMesh> mesh;
    std::string problem;
    try
    {
      skin::SkinnedMesh read = skin::readSkinnedMesh(file);
      skin::splitNonManifoldVertices(read);
      mesh = std::make_shared<const skin::SkinnedMesh>(std::move(read));
    }
    catch (const std::exception& e)
    {
      problem = e.what();
    }
    it = skinned_.emplace(file, std::make_pair(mesh, problem)).first;
  }
  if (!it->second.first && report)
  {
    err(path.pos, "loadMesh: " + it->second.second);
  }
  return it->second.first.get();
}

void Checker::standIn(const Expr& call, const CellMap& cells)
{
  const ExprPtr& cell = call.kids[1];
  const Expr* load = cell->kind == Expr::Kind::Name ? loadMeshOf(cell->text, &cells) : nullptr;
  if (!load || load->text != "loadMesh")
  {
    err(cell->pos,
      "standIn takes a skinned mesh cell, and '" + cell->text +
        "' is not one (shape = loadMesh(...))");
  }
}

void Checker::loadMesh(const Expr& call, bool surface)
{
  const ExprPtr& path = call.kids[1];
  const ExprPtr& animation = call.kids[2];
  bool strings = true;
  for (const ExprPtr& a : { path, animation })
  {
    if (a->kind != Expr::Kind::String)
    {
      err(a->pos, call.text + "(\"path\", \"animation\") takes quoted strings");
      strings = false;
    }
  }
  if (!strings)
  {
    return;
  }
  const skin::SkinnedMesh* mesh = skinnedMesh(*path);
  if (!mesh)
  {
    return;
  }
  // A B-cell's surface must be a manifold (complex::checkCell): corners where patches touch are
  // split when the file is read (skinnedMesh), edges of three or more triangles are refused here.
  // A skeleton's segments need no surface.
  try
  {
    if (surface)
    {
      complex::ExplicitGeometry cellSurface;
      cellSurface.points = mesh->restPoints;
      for (const auto& t : mesh->triangles)
      {
        cellSurface.triangles.push_back({ static_cast<std::uint32_t>(t[0]),
          static_cast<std::uint32_t>(t[1]), static_cast<std::uint32_t>(t[2]) });
      }
      complex::checkCell(complex::explicitCell(mesh->file, 2, std::move(cellSurface)));
    }
  }
  catch (const std::exception& e)
  {
    err(path->pos, call.text + ": " + e.what());
  }
  try
  {
    mesh->animation(animation->text);
  }
  catch (const std::exception& e)
  {
    err(animation->pos, call.text + ": " + e.what());
  }
}

std::string Checker::arity(const Signature& b)
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

void Checker::collectAttributes(const AttributesSection& s, std::set<std::string>& out) const
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

void Checker::attributesOf(const Instance& in, std::set<std::string>& out, int depth) const
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

void Checker::attributesOfImpl(const Instance& in, std::set<std::string>& out, int depth) const
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

void Checker::attributes(const AttributesSection& s, const CellMap& cells, const Instance* in)
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
      if (p.name == "mapping" || p.name == "dim" || p.name == "priority" || p.name == "lifespan" ||
        p.name == "timespan")
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

} // namespace ictk::lang::icmcheck
