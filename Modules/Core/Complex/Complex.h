// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The implicit complex K = <G, Rb, Rc> (thesis L830; seed 001 L85-102, L221): enumerated cells of
// dimension 0..3, the boundary relations Rb^{ps} (s < p), the containment relations Rc^{ps}
// (s <= p), and the derived relations. A pair never belongs to both Rb and Rc (thesis L1233).

#include "Complex/Cell.h"

#include <map>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace ictk::complex
{

/// Raised for an invalid relation or cell; the message names the cells.
class ComplexError : public std::invalid_argument
{
public:
  using std::invalid_argument::invalid_argument;
};

/// A set of pairs (g^p, g^s) of cell ids (seed 001 L221: add, delete, related indices).
class Relation
{
public:
  bool add(CellId first, CellId second) { return pairs_.emplace(first, second).second; }
  bool erase(CellId first, CellId second) { return pairs_.erase({ first, second }) > 0; }
  bool contains(CellId first, CellId second) const { return pairs_.count({ first, second }) > 0; }
  /// { s : (first, s) in R }, ascending.
  std::vector<CellId> related(CellId first) const;
  /// { p : (p, second) in R }, ascending.
  std::vector<CellId> inverse(CellId second) const;
  const std::set<std::pair<CellId, CellId>>& pairs() const { return pairs_; }
  std::size_t size() const { return pairs_.size(); }
  bool empty() const { return pairs_.empty(); }

private:
  std::set<std::pair<CellId, CellId>> pairs_;
};

enum class RelationKind
{
  Boundary,    ///< Rb^{ps}, s < p
  Containment, ///< Rc^{ps}, s <= p
};

/// Default attribute values where no cell gives one (thesis L715): theta1 inside some cell that
/// has no binding for the attribute, theta0 outside every cell.
struct AttributeDefaults
{
  int components = 1;
  std::vector<double> inside;  ///< theta1
  std::vector<double> outside; ///< theta0
};

class Complex
{
public:
  std::string name;

  /// Checks the cell (checkCell), gives it the next id and stores it. Names are unique.
  CellId addCell(Cell cell);
  /// Removes a cell and every pair it takes part in. The other ids are unchanged.
  void removeCell(CellId id);

  std::size_t cellCount() const { return live_; }
  bool hasCell(CellId id) const { return id < cells_.size() && cells_[id].has_value(); }
  /// Throws ComplexError when the id names no cell.
  const Cell& cell(CellId id) const;
  Cell& cell(CellId id);
  /// nullptr when no cell has that name.
  const Cell* findCell(const std::string& name) const;
  /// Throws ComplexError naming the missing cell.
  CellId idOf(const std::string& name) const;
  /// All cell ids, ascending.
  std::vector<CellId> cellIds() const;
  /// G^p: the cells of dimension p, ascending ids.
  std::vector<CellId> cellsOfDimension(int p) const;
  /// The maximal dimension of the cells (thesis L832); -1 when empty.
  int dimension() const;

  /// Adds (p-cell, s-cell) to Rb^{ps}. Throws ComplexError for a missing cell, s >= p, or a pair
  /// already in a containment relation.
  void addBoundary(CellId cell, CellId boundaryCell);
  /// Adds (p-cell, s-cell) to Rc^{ps}. Throws ComplexError for a missing cell, s > p, the cell
  /// itself, an explicit container (explicit cells contain no other cells, seed 001 L91), or a
  /// pair already in a boundary relation.
  void addContainment(CellId container, CellId contained);
  bool removeRelation(RelationKind kind, CellId first, CellId second);

  /// Rb^{ps} (p in 1..3, s < p) and Rc^{ps} (s <= p): the six and ten relation slots.
  const Relation& boundary(int p, int s) const;
  const Relation& containment(int p, int s) const;
  const Relation& relation(RelationKind kind, int p, int s) const;
  bool hasBoundary(CellId cell, CellId boundaryCell) const;
  bool hasContainment(CellId container, CellId contained) const;
  std::size_t boundaryPairCount() const;
  std::size_t containmentPairCount() const;

  // Derived relations (seed 001 L102, thesis L828), ascending ids.
  /// { s : (c, s) in Rb }: the cells on the boundary of c.
  std::vector<CellId> boundaryOf(CellId c) const;
  /// { p : (p, c) in Rb }: the co-boundary of c.
  std::vector<CellId> coboundaryOf(CellId c) const;
  /// { s : (c, s) in Rc }: what c contains.
  std::vector<CellId> contentsOf(CellId c) const;
  /// { p : (p, c) in Rc }: "to be contained": the cells that contain c.
  std::vector<CellId> containersOf(CellId c) const;
  /// Cells incident to c: boundaryOf(c) and coboundaryOf(c).
  std::vector<CellId> incidentTo(CellId c) const;
  /// Cells of the same dimension as c sharing a boundary cell with it (Rb o Rb^T minus identity).
  std::vector<CellId> adjacentTo(CellId c) const;

  /// Declares an attribute's component count and defaults. Bindings must match the count.
  void declareAttribute(const std::string& attribute, AttributeDefaults defaults);
  const std::map<std::string, AttributeDefaults>& attributes() const { return attributes_; }
  /// Binds an attribute function to a cell (the attribute relation Rs, thesis L864).
  void bindAttribute(CellId cell, AttributeBinding binding);

private:
  const Cell& checkedCell(CellId id, const char* role) const;
  static std::size_t slot(int p, int s) { return static_cast<std::size_t>(p * 4 + s); }

  std::vector<std::optional<Cell>> cells_;
  std::size_t live_ = 0;
  std::map<std::string, CellId> names_;
  std::array<Relation, 16> boundary_;
  std::array<Relation, 16> containment_;
  std::map<std::string, AttributeDefaults> attributes_;
};

} // namespace ictk::complex
