// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The built-in library of the IC model language (docs/icm.md "Built-in library"), in one table:
// each entry names a built-in, its arguments and result, a line of documentation, and the layer
// that computes it. Everything else comes from this table: the checker's signatures and argument
// counts (IcmCheck), the engine's dispatch (the interpreter computes the pure math; the running
// model computes the library calls: geometry between cells, events, animation curves, shapes of
// T-cells), and the table of docs/icm.md, which a test compares with builtinsMarkdown(). The
// constructors of a cell's `shape =` have a table of their own below, used the same way.
//
// The table lives here, below the engine, so that the checker needs no engine; the engine keeps
// one implementation per BuiltinId and a test fails when an entry has no implementation or an
// implementation has no entry (Engine/Builtins.h).

#include <string>
#include <vector>

namespace ictk::lang::icm
{

/// One per built-in of the reaction library, in the table's order.
enum class BuiltinId
{
  Distance,
  Intersects,
  Contains,
  IntersectionCount,
  IntersectionPoint,
  IntersectionArea,
  FireEvent,
  Animation,
  AnimationValue,
  AnimationDuration,
  Segment,
  Arc,
  CircularSegment,
  SetShapeParameter,
  MakeCrossSection,
  GetVolume,
  JointPosition,
  JointTransforms,
  SetDeformation,
  SetProjection,
  ProjectionResidual,
  ProjectionAngle,
  Vec3,
  Length,
  Dot,
  Cross,
  Normalize,
  Abs,
  Sqrt,
  Sin,
  Cos,
  Tan,
  Asin,
  Acos,
  Atan,
  Atan2,
  Exp,
  Log,
  Pow,
  Min,
  Max,
  Clamp,
  Floor,
  Ceil,
  Count ///< not a built-in: the number of them
};

/// Who computes a built-in.
enum class BuiltinLayer
{
  Math,   ///< the interpreter, from its arguments alone
  Library ///< the running model (geometry between cells, events, animation, shapes)
};

/// A call's shape: what the checker needs.
struct Signature
{
  const char* name;
  int minArgs;
  int maxArgs; ///< -1: any number
  const char* signature;
  const char* result; ///< real, int, bool, vec3, string, shape or void
};

/// One function of the built-in library callable from reactions, predicates and functions.
struct Builtin
{
  BuiltinId id;
  BuiltinLayer layer;
  Signature call;
  const char* doc; ///< one line for docs/icm.md
};

/// The name a call refers to: the thesis writes the library's calls `IC::fireEvent(...)`, which is
/// `fireEvent(...)` (and `IC::f` of a model function, `f`).
inline std::string calledName(const std::string& text)
{
  return text.rfind("IC::", 0) == 0 ? text.substr(4) : text;
}

/// The reaction library, indexed by BuiltinId.
const std::vector<Builtin>& builtins();
/// nullptr when `name` is not one of the built-ins.
const Builtin* findBuiltin(const std::string& name);
/// The rows of docs/icm.md's table of built-ins ("| `signature` | result: doc |"), one per entry.
std::string builtinsMarkdown();

/// One per constructor of a cell's `shape =`, in the table's order.
enum class ShapeId
{
  File,
  Point,
  Segment,
  Arc,
  CircularSegment,
  Polyline,
  Rectangle,
  Disk,
  Box,
  Sphere,
  Blend,
  BlendCells,
  Union,
  SpaceTimeBlend,
  LoadMesh,
  LoadSegmentsHierarchy,
  StandIn,
  Count ///< not a constructor: the number of them
};

/// A constructor of a cell's `shape =`, computed when the model is built (not in code): the
/// checker checks its arity and arguments, the engine builds it by id (Engine/Builtins.h checks
/// that every entry has one builder) and docs/icm.md lists it (shapeBuiltinsMarkdown()).
struct ShapeBuiltin
{
  ShapeId id;
  Signature call;
  /// How many leading arguments name cells (blend, union, spaceTimeBlendCells): the checker
  /// requires cell names there and the engine passes them on as cells instead of evaluating them.
  int cellArguments;
  const char* doc; ///< one line for docs/icm.md
};

/// The shape constructors, indexed by ShapeId.
const std::vector<ShapeBuiltin>& shapeBuiltins();
/// nullptr when `name` is not a shape constructor (`IC::name` is `name`, as for calls).
const ShapeBuiltin* findShapeBuiltin(const std::string& name);
/// The rows of docs/icm.md's table of shape constructors ("| `signature` | doc |"), one per entry.
std::string shapeBuiltinsMarkdown();

} // namespace ictk::lang::icm
