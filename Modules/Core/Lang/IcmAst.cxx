// SPDX-License-Identifier: BSD-3-Clause
#include "Lang/IcmAst.h"

namespace ictk::lang::icm
{

const Property* CellDef::property(const std::string& n) const
{
  for (const Property& p : properties)
  {
    if (p.name == n)
    {
      return &p;
    }
  }
  return nullptr;
}

const CellDef* Model::cell(const std::string& n) const
{
  for (const CellsSection& s : cells)
  {
    for (const CellDef& c : s.defs)
    {
      if (c.name.text == n)
      {
        return &c;
      }
    }
  }
  for (const Instance& in : instances)
  {
    for (const CellsSection& s : in.cells)
    {
      for (const CellDef& c : s.defs)
      {
        if (c.name.text == n)
        {
          return &c;
        }
      }
    }
  }
  return nullptr;
}

const Instance* Model::instance(const std::string& n) const
{
  for (const Instance& in : instances)
  {
    if (in.name.text == n)
    {
      return &in;
    }
  }
  return nullptr;
}

const Event* Model::event(const std::string& n) const
{
  for (const Event& e : events)
  {
    if (e.name.text == n)
    {
      return &e;
    }
  }
  return nullptr;
}

const CellDef* Model::animation(const std::string& n) const
{
  for (const CellDef& a : animations)
  {
    if (a.name.text == n)
    {
      return &a;
    }
  }
  return nullptr;
}

const std::vector<Builtin>& builtins()
{
  static const std::vector<Builtin> table = {
    // Geometry between cells (their current domains, in global coordinates).
    { "distance", 2, 2, "distance(cellA, cellB)", "real" },
    { "intersects", 2, 2, "intersects(cellA, cellB)", "bool" },
    { "contains", 2, 2, "contains(cellA, cellB)", "bool" },
    { "intersectionCount", 2, 2, "intersectionCount(cellA, cellB)", "int" },
    { "intersectionPoint", 3, 3, "intersectionPoint(cellA, cellB, int i)", "vec3" },
    { "intersectionArea", 2, 2, "intersectionArea(cellA, cellB)", "real" },
    // Events.
    { "fireEvent", 1, -1, "fireEvent(EVENT, args...)", "void" },
    // Animation curves (thesis Table 3) by name.
    { "animation", 2, 2, "animation(string curve, real t)", "vec3" },
    { "animationValue", 2, 2, "animationValue(string curve, real t)", "real" },
    { "animationDuration", 1, 1, "animationDuration(string curve)", "real" },
    // Shapes computed in reactions (T-cells) and FRep parameters.
    { "segment", 2, 2, "segment(vec3 p, vec3 q)", "shape" },
    { "arc", 3, 3, "arc(vec3 p, vec3 q, real radius)", "shape" },
    { "circularSegment", 3, 3, "circularSegment(vec3 p, vec3 q, real radius)", "shape" },
    { "setShapeParameter", 3, 3, "setShapeParameter(cell, string name, real value)", "void" },
    // Vectors.
    { "vec3", 3, 3, "vec3(real x, real y, real z)", "vec3" },
    { "length", 1, 1, "length(vec3 v)", "real" },
    { "dot", 2, 2, "dot(vec3 a, vec3 b)", "real" },
    { "cross", 2, 2, "cross(vec3 a, vec3 b)", "vec3" },
    { "normalize", 1, 1, "normalize(vec3 v)", "vec3" },
    // Scalars.
    { "abs", 1, 1, "abs(real x)", "real" },
    { "sqrt", 1, 1, "sqrt(real x)", "real" },
    { "sin", 1, 1, "sin(real x)", "real" },
    { "cos", 1, 1, "cos(real x)", "real" },
    { "tan", 1, 1, "tan(real x)", "real" },
    { "asin", 1, 1, "asin(real x)", "real" },
    { "acos", 1, 1, "acos(real x)", "real" },
    { "atan", 1, 1, "atan(real x)", "real" },
    { "atan2", 2, 2, "atan2(real y, real x)", "real" },
    { "exp", 1, 1, "exp(real x)", "real" },
    { "log", 1, 1, "log(real x)", "real" },
    { "pow", 2, 2, "pow(real x, real y)", "real" },
    { "min", 2, 2, "min(real a, real b)", "real" },
    { "max", 2, 2, "max(real a, real b)", "real" },
    { "clamp", 3, 3, "clamp(real x, real lo, real hi)", "real" },
    { "floor", 1, 1, "floor(real x)", "int" },
    { "ceil", 1, 1, "ceil(real x)", "int" },
  };
  return table;
}

const std::vector<Builtin>& shapeBuiltins()
{
  static const std::vector<Builtin> table = {
    { "file", 1, 1, "file(string path)  .hf or .xml (FRep), .obj or .off (mesh)", "shape" },
    { "point", 3, 3, "point(real x, real y, real z)", "shape" },
    { "segment", 2, 2, "segment(vec3 p, vec3 q)", "shape" },
    { "arc", 3, 3, "arc(vec3 p, vec3 q, real radius)", "shape" },
    { "polyline", 2, -1, "polyline(vec3 p0, vec3 p1, ...)", "shape" },
    { "rectangle", 2, 2, "rectangle(real width, real height)", "shape" },
    { "disk", 1, 1, "disk(real radius)", "shape" },
    { "box", 3, 3, "box(real sx, real sy, real sz)", "shape" },
    { "sphere", 1, 1, "sphere(real radius)", "shape" },
    { "blend", 3, 3, "blend(cellA, cellB, real amount)", "shape" },
    { "union", 2, 2, "union(cellA, cellB)", "shape" },
    { "vec3", 3, 3, "vec3(real x, real y, real z)", "vec3" },
  };
  return table;
}

namespace
{
const Builtin* find(const std::vector<Builtin>& table, const std::string& name)
{
  for (const Builtin& b : table)
  {
    if (name == b.name)
    {
      return &b;
    }
  }
  return nullptr;
}
} // namespace

const Builtin* findBuiltin(const std::string& name)
{
  return find(builtins(), name);
}

const Builtin* findShapeBuiltin(const std::string& name)
{
  return find(shapeBuiltins(), name);
}

} // namespace ictk::lang::icm
