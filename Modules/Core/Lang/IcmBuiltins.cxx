// SPDX-License-Identifier: BSD-3-Clause
#include "Lang/IcmBuiltins.h"

namespace ictk::lang::icm
{

namespace
{

/// The entry called `name` of a table (built-ins, shape constructors); nullptr when none is.
template <class Entry>
const Entry* entryNamed(const std::vector<Entry>& table, const std::string& name)
{
  for (const Entry& e : table)
    if (name == e.call.name)
      return &e;
  return nullptr;
}

/// A row of docs/icm.md: "| `signature` | what |".
std::string row(const Signature& call, const std::string& what)
{
  return std::string("| `") + call.signature + "` | " + what + " |\n";
}

} // namespace

const std::vector<Builtin>& builtins()
{
  using Id = BuiltinId;
  constexpr BuiltinLayer math = BuiltinLayer::Math;
  constexpr BuiltinLayer library = BuiltinLayer::Library;
  static const std::vector<Builtin> table = {
    // Geometry between cells (their current domains, in global coordinates).
    { Id::Distance, library, { "distance", 2, 2, "distance(cellA, cellB)", "real" },
      "the distance between the cells' current domains" },
    { Id::Intersects, library, { "intersects", 2, 2, "intersects(cellA, cellB)", "bool" },
      "whether the cells meet" },
    { Id::Contains, library, { "contains", 2, 2, "contains(cellA, cellB)", "bool" }, "B inside A" },
    { Id::IntersectionCount, library,
      { "intersectionCount", 2, 2, "intersectionCount(cellA, cellB)", "int" },
      "the number of intersection points" },
    { Id::IntersectionPoint, library,
      { "intersectionPoint", 3, 3, "intersectionPoint(cellA, cellB, int i)", "vec3" },
      "the i-th intersection point (from 0)" },
    { Id::IntersectionArea, library,
      { "intersectionArea", 2, 2, "intersectionArea(cellA, cellB)", "real" },
      "the measure of the cells' overlap" },
    // Events.
    { Id::FireEvent, library, { "fireEvent", 1, -1, "fireEvent(EVENT, args...)", "void" },
      "one argument per event parameter; `fireEvent(TIME_REJECTED, dt)` retries the frame with "
      "the step dt" },
    // Animation curves (thesis Table 3) by name.
    { Id::Animation, library, { "animation", 2, 2, "animation(string curve, real t)", "vec3" },
      "a vector curve of ANIMATIONS at t" },
    { Id::AnimationValue, library,
      { "animationValue", 2, 2, "animationValue(string curve, real t)", "real" },
      "a scalar curve of ANIMATIONS at t" },
    { Id::AnimationDuration, library,
      { "animationDuration", 1, 1, "animationDuration(string curve)", "real" },
      "the duration of a curve" },
    // Shapes computed in reactions (T-cells) and FRep parameters.
    { Id::Segment, library, { "segment", 2, 2, "segment(vec3 p, vec3 q)", "shape" },
      "for T-cells: `KL_segment.shape = segment(p, q)`" },
    { Id::Arc, library, { "arc", 3, 3, "arc(vec3 p, vec3 q, real radius)", "shape" },
      "counter-clockwise from p to q about the origin" },
    { Id::CircularSegment, library,
      { "circularSegment", 3, 3, "circularSegment(vec3 p, vec3 q, real radius)", "shape" },
      "the region between that arc and its chord" },
    { Id::SetShapeParameter, library,
      { "setShapeParameter", 3, 3, "setShapeParameter(cell, string name, real value)", "void" },
      "sets an FRep parameter (`a[1]`...) of an F-cell's HyperFun or XML shape" },
    // Space-time cells (thesis 5.3.4, L3160-L3162).
    { Id::MakeCrossSection, library,
      { "makeCrossSection", 2, 2, "makeCrossSection(shape s, real t)", "shape" },
      "the cross-section at t of a space-time cell's shape (`makeCrossSection(shape, globalT)`); "
      "t is the time being evaluated" },
    { Id::GetVolume, library, { "getVolume", 1, 1, "getVolume(shape s)", "real" },
      "the volume (3D) or area (2D) of a cell's shape or cross-section, as placed now" },
    // The skeletons of skinned meshes (loadMesh cells).
    { Id::JointPosition, library,
      { "jointPosition", 2, 2, "jointPosition(cell, string joint)", "vec3" },
      "where a joint (a node of the skeleton, by name) of a skinned cell (`loadMesh`, "
      "`loadSegmentsHierarchy`) is now, in world coordinates" },
    { Id::JointTransforms, library,
      { "jointTransforms", 2, 2, "jointTransforms(cell, real t)", "transforms" },
      "the skinning matrices M_j = G_j(t) offset_j of a skinned cell's joints (`loadMesh`, "
      "`loadSegmentsHierarchy`) played by its animation at t seconds: the value of an "
      "`array of TRANSFORM` parameter (thesis Appendix B's `Skeleton.matrices`)" },
    { Id::SetDeformation, library,
      { "setDeformation", 2, 2, "setDeformation(cell, transforms)", "void" },
      "poses a skinned cell by these skinning matrices (one per joint of its skeleton) instead "
      "of its animation, from now on (Appendix B's `brepCell.setDeformation(transforms)`)" },
    { Id::SetProjection, library,
      { "setProjection", 2, 4, "setProjection(cell, real alpha [, string weights [, real spread]])",
        "void" },
      "moves the vertices of a `loadMesh` cell and turns their normals the fraction alpha (0..1) "
      "of the way onto its stand-in (the `standIn(cell)` cell of it): thesis 5.5's K2 and K4, "
      "p'_i = sum_j w_ij M_j (p_i + alpha_i dp_i) + alpha_i c_i and n'_i = slerp(A_i^-T "
      "slerp(n_i, N_i, alpha_i), N'_i, alpha_i), with the offsets dp_i and the stand-in's normals "
      "N_i found in the bind pose, c_i the posed remainder onto the posed stand-in and N'_i its "
      "normal there (so alpha = 1 lies on it in every pose). `weights` names "
      "a model function `(real x, real y, real z)` of the bind-pose position (the file's "
      "coordinates): its higher values are projected first, over windows of alpha of length "
      "1 - spread (default 0.5): alpha_i = clamp((alpha - spread (1 - u_i)) / (1 - spread), 0, 1), "
      "u_i the weight scaled to [0, 1]" },
    { Id::ProjectionResidual, library,
      { "projectionResidual", 1, 1, "projectionResidual(cell)", "real" },
      "how far the posed vertices of a `setProjection` cell are from its posed stand-in: the "
      "largest abs(F) / length(grad F) over them, in world units (the K2 -> K3 switch of thesis "
      "L3420: "
      "every vertex within epsilon when it is below epsilon)" },
    { Id::ProjectionAngle, library, { "projectionAngle", 1, 1, "projectionAngle(cell)", "real" },
      "the largest angle, in degrees, between a posed vertex normal of a `setProjection` cell and "
      "its posed stand-in's outward normal there (-grad F, made unit)" },
    // Vectors.
    { Id::Vec3, math, { "vec3", 3, 3, "vec3(real x, real y, real z)", "vec3" }, "a vector" },
    { Id::Length, math, { "length", 1, 1, "length(vec3 v)", "real" }, "the Euclidean norm" },
    { Id::Dot, math, { "dot", 2, 2, "dot(vec3 a, vec3 b)", "real" }, "the dot product" },
    { Id::Cross, math, { "cross", 2, 2, "cross(vec3 a, vec3 b)", "vec3" }, "the cross product" },
    { Id::Normalize, math, { "normalize", 1, 1, "normalize(vec3 v)", "vec3" },
      "v / length(v) (an error for the zero vector)" },
    // Scalars.
    { Id::Abs, math, { "abs", 1, 1, "abs(real x)", "real" }, "the absolute value" },
    { Id::Sqrt, math, { "sqrt", 1, 1, "sqrt(real x)", "real" }, "the square root" },
    { Id::Sin, math, { "sin", 1, 1, "sin(real x)", "real" }, "radians" },
    { Id::Cos, math, { "cos", 1, 1, "cos(real x)", "real" }, "radians" },
    { Id::Tan, math, { "tan", 1, 1, "tan(real x)", "real" }, "radians" },
    { Id::Asin, math, { "asin", 1, 1, "asin(real x)", "real" }, "radians" },
    { Id::Acos, math, { "acos", 1, 1, "acos(real x)", "real" }, "radians" },
    { Id::Atan, math, { "atan", 1, 1, "atan(real x)", "real" }, "radians" },
    { Id::Atan2, math, { "atan2", 2, 2, "atan2(real y, real x)", "real" }, "the angle of (x, y)" },
    { Id::Exp, math, { "exp", 1, 1, "exp(real x)", "real" }, "e^x" },
    { Id::Log, math, { "log", 1, 1, "log(real x)", "real" }, "the natural logarithm" },
    { Id::Pow, math, { "pow", 2, 2, "pow(real x, real y)", "real" }, "x^y" },
    { Id::Min, math, { "min", 2, 2, "min(real a, real b)", "real" },
      "the smaller (an int for two ints)" },
    { Id::Max, math, { "max", 2, 2, "max(real a, real b)", "real" },
      "the larger (an int for two ints)" },
    { Id::Clamp, math, { "clamp", 3, 3, "clamp(real x, real lo, real hi)", "real" },
      "x limited to [lo, hi] (an error when lo > hi)" },
    { Id::Floor, math, { "floor", 1, 1, "floor(real x)", "int" }, "rounded down" },
    { Id::Ceil, math, { "ceil", 1, 1, "ceil(real x)", "int" }, "rounded up" },
  };
  return table;
}

const Builtin* findBuiltin(const std::string& name)
{
  return entryNamed(builtins(), name);
}

std::string builtinsMarkdown()
{
  std::string out;
  for (const Builtin& b : builtins())
    out += row(b.call, std::string(b.call.result) + ": " + b.doc);
  return out;
}

const std::vector<ShapeBuiltin>& shapeBuiltins()
{
  using Id = ShapeId;
  static const std::vector<ShapeBuiltin> table = {
    { Id::File, { "file", 1, 1, "file(string path)", "shape" }, 0,
      "relative to the model's folder: an FRep shape, `.hf` HyperFun or `.xml` FRep; or a "
      "triangle mesh, `.obj`, `.off`, `.ply` or `.stl` (a B-cell surface, `dim = 2D`, placed by "
      "the cell; the "
      "queries, `blend` and `union` do not take it)" },
    { Id::Point, { "point", 3, 3, "point(real x, real y, real z)", "shape" }, 0, "a point" },
    { Id::Segment, { "segment", 2, 2, "segment(vec3 p, vec3 q)", "shape" }, 0,
      "the segment from p to q" },
    { Id::Arc, { "arc", 3, 3, "arc(vec3 p, vec3 q, real radius)", "shape" }, 0,
      "counter-clockwise from p to q about the origin" },
    { Id::CircularSegment,
      { "circularSegment", 3, 3, "circularSegment(vec3 p, vec3 q, real radius)", "shape" }, 0,
      "the region between that arc and its chord" },
    { Id::Polyline, { "polyline", 2, -1, "polyline(vec3 p0, vec3 p1, ...)", "shape" }, 0,
      "the open polyline through the points" },
    { Id::Rectangle, { "rectangle", 2, 2, "rectangle(real width, real height)", "shape" }, 0,
      "centred on the origin" },
    { Id::Disk, { "disk", 1, 1, "disk(real radius)", "shape" }, 0, "centred on the origin" },
    { Id::Box, { "box", 3, 3, "box(real sx, real sy, real sz)", "shape" }, 0,
      "centred on the origin" },
    { Id::Sphere, { "sphere", 1, 1, "sphere(real radius)", "shape" }, 0, "centred on the origin" },
    { Id::Blend, { "blend", 3, 5, "blend(cellA, cellB, real amount, real a1, real a2)", "shape" },
      2,
      "the blending union of two cells' shapes (thesis 2.2.3, L643-L647): f1 + f2 + "
      "sqrt(f1^2 + f2^2) + amount / (1 + (f1/a1)^2 + (f2/a2)^2), with f1, f2 the cells' fields; "
      "`amount` (a0 >= 0) is the material added where both are near (0: the R-union, the same "
      "solid as `union`), a1, a2 (> 0, optional, both or neither, 1 when not given) how far it "
      "reaches into cellA and cellB; the numbers may read the cell's and the model's "
      "parameters: they are evaluated at every step" },
    { Id::BlendCells,
      { "blendCells", 3, 5, "blendCells(cellA, cellB, real a0, real a1, real a2)", "shape" }, 2,
      "the thesis's name for `blend` (Appendix B's `IC::blendCells(Box, Liquid_Andy, "
      "blendDensity, ...)`): the same blending union, the same numbers" },
    { Id::Union, { "union", 2, 2, "union(cellA, cellB)", "shape" }, 2,
      "the union of two cells' shapes" },
    { Id::SpaceTimeBlend,
      { "spaceTimeBlendCells", 8, -1,
        "spaceTimeBlendCells(cellA, cellB, real t0, real t1, real a0, real a1, real a2, real a3, "
        "real align, vec3 source, vec3 destination, ...)",
        "shape" },
      2,
      "the space-time blend (thesis 5.3.1) of two cells' shapes of dimension k, a T-cell of "
      "`dim` k + 1: at global time t its cross-section, cellA's shape until t0, cellB's from t1, "
      "a blend of the two between, with the bounded blend's added material a0 and scales a1, a2 "
      "(the operands') and a3 (the time slab's); no defaults: they depend on the shapes' "
      "sizes and the interval's length. `align` (optional, 0 to 1; thesis 5.3.2) moves each "
      "operand's extrusion toward the other's bounding domain during the transition, so that "
      "at 1 they meet halfway. The warp (optional, after align = 0; thesis 5.3.3) deforms the "
      "operands so that features travel along t: 2 or more pairs `source, destination` (a "
      "feature of cellA at source becomes one of cellB at destination), or in their place "
      "`int n, real separation`: n automatic control points of each operand (eq. 4: maxima of "
      "its distance transform, at least separation apart; n from 1 to 8), paired by least total "
      "distance" },
    { Id::LoadMesh, { "loadMesh", 2, 2, "loadMesh(string path, string animation)", "shape" }, 0,
      "a skinned, animated mesh (.x, .gltf, .fbx... read with Assimp; relative to the model's "
      "folder) played by the named animation at the cell's time: a B-cell surface, `dim = 2D`, "
      "placed by the cell; the queries, `blend` and `union` do not take it" },
    { Id::LoadSegmentsHierarchy,
      { "loadSegmentsHierarchy", 2, 2, "loadSegmentsHierarchy(string path, string animation)",
        "shape" },
      0,
      "the rigging skeleton of a skinned mesh file (Appendix B's `Skeleton`): one segment per "
      "bone between its two joints' origins, posed like `loadMesh`'s mesh: a C-cell, `dim = 1D`, "
      "placed by the cell; the queries, `blend` and `union` do not take it" },
    { Id::StandIn, { "standIn", 1, 1, "standIn(cell)", "shape" }, 1,
      "the implicit stand-in (thesis 5.4) of a `loadMesh` cell: one Cauchy convolution segment "
      "per bone, the radii fitted to the mesh in its bind pose once at load, the segments posed "
      "at every step by the cell's skinning matrices and placed with it (then by this cell's own "
      "placement): an F-cell field, `dim = 3D`, that `blend`, `spaceTimeBlendCells` and the "
      "queries take" },
  };
  return table;
}

const ShapeBuiltin* findShapeBuiltin(const std::string& name)
{
  // The thesis writes `IC::blendCells(...)`, `IC::spaceTimeBlendCells(...)`.
  return entryNamed(shapeBuiltins(), calledName(name));
}

std::string shapeBuiltinsMarkdown()
{
  std::string out;
  for (const ShapeBuiltin& b : shapeBuiltins())
    out += row(b.call, b.doc);
  return out;
}

} // namespace ictk::lang::icm
