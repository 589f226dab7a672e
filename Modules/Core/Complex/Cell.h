// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Cells of an implicit complex (seed 001 sections 1.3-1.4; thesis 2.3.2, cell types L834-840).
//
// Every cell is a closed point set of E^3 of dimension 0 to 3, described in one of three ways:
//  - implicitly: the points where carrier fields vanish and inside fields are non-negative, so an
//    FRep solid is {F >= 0} and a trimmed surface patch is {G = 0, H >= 0}. Seed 001 writes the
//    latter as -G^2 AND H >= 0, a set sign-change contouring cannot see; keeping G and H apart lets
//    each dimension get the right discretiser (surface contouring, curve tracing, point solving);
//  - as a mapped FRep (MappedFCell): a 2D FRep in the (u, v) plane pushed into E^3 by h;
//  - explicitly: points, polylines, triangles or tetrahedra (a characteristic map, sampled).

#include "Discretize/Mesh.h"
#include "FRep/Expr.h"
#include "FRep/Field.h"

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <variant>
#include <vector>

namespace ictk::complex
{

using frep::Box3;
using frep::FieldPtr;
using frep::Point3;

using CellId = std::uint32_t;

/// What a cell is made of (thesis L834-840, seed 001 L181-185).
enum class CellKind
{
  Point,      ///< P: explicit point(s), given by coordinates
  BRep,       ///< B: explicit polyline, spline curve, triangle or quad mesh, tetrahedral solid
  FRep,       ///< F: carrier and inside fields in E^3 (FrepCell)
  MappedFRep, ///< F in E^2 mapped by h: E^2 -> E^3 (MappedFCell)
  Voxel,      ///< V: a sampled scalar field read by trilinear interpolation
  Composite,  ///< C: a set operation on other cells
  Computed,   ///< T: computed from other cells (an intersection curve, point or patch)
};

/// One-letter code used in files and reports: P, B, F, MF, V, C, T.
const char* kindCode(CellKind kind);
/// Inverse of kindCode; throws std::invalid_argument naming the bad code.
CellKind kindFromCode(const std::string& code);

/// {X : G_i(X) = 0 for every carrier, H_k(X) >= 0 for every inside field}, inside `bounds`.
/// Its dimension is 3 minus the number of carriers.
struct ImplicitGeometry
{
  std::vector<FieldPtr> carriers;
  std::vector<FieldPtr> inside;
  Box3 bounds;
  /// The model text of each carrier and inside field, for reports and files.
  std::vector<std::string> carrierText;
  std::vector<std::string> insideText;
};

/// {h(u, v) : G_i(u, v) = 0, H_k(u, v) >= 0}: fields of (u, v) = (x, y) (z ignored), mapped by
/// h = (hx, hy, hz). Its dimension is 2 minus the number of carriers.
struct MappedGeometry
{
  std::vector<FieldPtr> carriers;
  std::vector<FieldPtr> inside;
  std::array<FieldPtr, 3> map;
  /// The (u, v) rectangle the cell lies in (z ignored).
  Box3 uvBounds;
  std::vector<std::string> carrierText;
  std::vector<std::string> insideText;
  std::array<std::string, 3> mapText;
};

/// Points, polylines, triangles or tetrahedra over one point list.
struct ExplicitGeometry
{
  std::vector<Point3> points;
  std::vector<std::vector<std::uint32_t>> polylines;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  std::vector<std::array<std::uint32_t, 4>> tetrahedra;
  /// Values given per point with the geometry (a skinned mesh's dominant joint), carried to the
  /// cell's discretisation as point arrays (2D and lower; a 3D cell's boundary has new points).
  std::vector<discretize::PointArray> pointData;
};

using CellGeometry = std::variant<ImplicitGeometry, MappedGeometry, ExplicitGeometry>;

/// An attribute function S: E^3 -> R^m (seed 001 L114-116), one field per component.
struct AttributeFunction
{
  std::string name;
  std::vector<FieldPtr> components;
  std::vector<std::string> text;
};
using AttributeFunctionPtr = std::shared_ptr<const AttributeFunction>;

/// (cell, S) in the attribute relation Rs (thesis L864): the attribute `attribute` of the cell is
/// given by `function`; where cells overlap, the binding of highest priority wins.
struct AttributeBinding
{
  std::string attribute;
  AttributeFunctionPtr function;
  double priority = 0;
};

struct Cell
{
  CellId id = 0; ///< assigned by Complex::addCell: cells are enumerated
  std::string name;
  /// What the cell stands for ("receptacle"), for reports and viewers.
  std::string description;
  CellKind kind = CellKind::FRep;
  int dimension = 3;
  /// Where 3D cells overlap, the region belongs to the cell of highest priority (material
  /// assignment for meshing); overlapping cells of equal priority are an error there.
  double priority = 0;
  CellGeometry geometry;
  /// Cells a composite (C) or computed (T) cell is built from.
  std::vector<CellId> operands;
  std::vector<AttributeBinding> attributes;

  bool isExplicit() const { return std::holds_alternative<ExplicitGeometry>(geometry); }
  /// Implicit cells may contain other cells; explicit cells are indivisible (seed 001 L91).
  bool isImplicit() const { return !isExplicit(); }
  /// The box the cell lies in (explicit cells: their points' box).
  Box3 bounds() const;
};

/// An F cell from FRep expressions of (x, y, z) at time `time`: {carriers = 0, inside >= 0}.
Cell frepCell(const std::string& name, const std::vector<frep::Expr>& carriers,
  const std::vector<frep::Expr>& inside, const Box3& bounds, double time = 0);
/// An explicit cell: points (P, 0D) or polylines / triangles / tetrahedra (B).
Cell explicitCell(const std::string& name, int dimension, ExplicitGeometry geometry);

/// Checks that the cell's geometry matches its kind and dimension; throws std::invalid_argument
/// naming the cell and the problem (a 2-carrier F cell declared 2D, a triangle index out of
/// range, an empty cell, a non-manifold explicit surface, a null field...).
void checkCell(const Cell& cell);

} // namespace ictk::complex
