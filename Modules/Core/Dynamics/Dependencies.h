// SPDX-License-Identifier: BSD-3-Clause
// Dependency relations and the evaluation order (thesis §3.5 L1177-1225, §4.3.3 L1902-2044,
// footnotes 27/28 at L3495-3497 and L3697).
//
// Relations are master -> dependent pairs of entities (cells or attributes), optionally naming the
// parameters they connect, with a kind (the five of §3.5 plus the hierarchical one of L1225) and a
// priority (default 1.0, L1733).
//
// plan() computes the order:
//  1. Cut cycles (L2028-2030): relations are visited by priority, descending, ties by definition
//     order ("a higher priority value is assigned to the dependency relation which was defined
//     first", L2016); a relation is kept unless its dependent already reaches its master through
//     kept relations, in which case it is cut. So each cycle loses its lowest-priority relation.
//  2. Topological sort of the kept DAG into concurrency lists (L1925-1927): an entity's depth is
//     the longest kept path from a root; entities of equal depth form one list (they may be
//     evaluated concurrently); inside a list entities are sorted by entity priority, descending,
//     ties by definition order (Table 2 L4097).
//  3. A user-given order replaces the lists by one singleton list per entity in that order; any
//     relation whose master comes at or after its dependent is then treated as cut.
// How cut relations are read is the cycle policy (the thesis gives two options, L2000/L2018-2030):
//  - PreviousState (default, L2000): every relation inside a cycle (both ends in one strongly
//    connected component of the full graph) reads the master's value from the previous frame.
//    Reading only the cut relation from the previous frame does not swap the velocities of
//    Newton's cradle (L1989-1991): the second ball would read the first ball's new value. Both
//    balls must see previous states, so the whole cycle reads the snapshot.
//  - CutEdgePrevious: only cut relations read the previous frame (kept for comparison; it gives
//    (0, 0) instead of a swap in the cradle).
//  - Reevaluate (L2018-2026, footnote 27): relations read current values; after the lists, each
//    cut relation, highest priority first (footnote 28), re-evaluates its dependent with the
//    up-to-date master; entities whose relations are all valid are not re-evaluated.
// Everything is ordered by definition indices: no hashing, so the plan is deterministic.
#pragma once

#include <cstddef>
#include <functional>
#include <map>
#include <string>
#include <vector>

namespace ictk::dyn
{

enum class DependencyKind
{
  Parametric,          ///< Rd_p: a parameter of the dependent is defined by the master's (L1181)
  Geometric,           ///< Rd_g: the master's geometry modifies the dependent's (L1189)
  AttributeAttribute,  ///< Rd_a: compound attributes (L1197)
  GeometryToAttribute, ///< Rd_ga (L1203)
  AttributeToGeometry, ///< Rd_ag (L1209)
  Hierarchical         ///< the child's transform follows the parent's (L1225)
};

const char* dependencyKindName(DependencyKind k);

enum class CyclePolicy
{
  PreviousState,
  CutEdgePrevious,
  Reevaluate
};

struct DependencyRelation
{
  std::string master, dependent;
  /// Optional parameter names: when both are set, evaluation copies master.masterParam into
  /// dependent.dependentParam (through `map` when given) before the dependent is updated.
  std::string masterParam, dependentParam;
  DependencyKind kind = DependencyKind::Parametric;
  double priority = 1.0;
  std::function<double(double)> map;
};

struct EvaluationPlan
{
  std::vector<std::string> entities;           ///< definition order
  std::vector<std::vector<std::size_t>> lists; ///< concurrency lists of entity indices
  std::vector<std::size_t> kept, cut;          ///< relation indices (ascending)
  std::vector<bool> inCycle;                   ///< per relation: both ends in one SCC
  std::vector<std::size_t> reevaluations;      ///< cut relations, priority desc, then definition
  bool userOrder = false;

  /// The lists flattened.
  std::vector<std::size_t> order() const;
  /// The lists as names, for tests and diagnostics.
  std::vector<std::vector<std::string>> listNames() const;
  /// Per relation: whether it reads the master's previous-frame value under `policy`.
  std::vector<bool> readsPrevious(CyclePolicy policy) const;
};

class DependencyGraph
{
public:
  /// Adds an entity (or updates the priority of an existing one); returns its index.
  std::size_t addEntity(const std::string& name, double priority = 1.0);
  /// Adds a relation; unknown entities are added in order of appearance. A relation with a
  /// non-finite priority throws std::invalid_argument.
  std::size_t addRelation(DependencyRelation r);
  /// Convenience: "Master.param Dependent.param priority" as in the .icm dependency blocks.
  std::size_t addRelation(const std::string& masterDotParam, const std::string& dependentDotParam,
    double priority = 1.0, DependencyKind kind = DependencyKind::Parametric);
  /// A user order overriding the topological one (must name every entity exactly once, else
  /// std::invalid_argument). An empty vector restores the automatic order.
  void setUserOrder(std::vector<std::string> order);

  std::size_t entityCount() const { return entities_.size(); }
  const std::string& entityName(std::size_t i) const { return entities_.at(i).name; }
  double entityPriority(std::size_t i) const { return entities_.at(i).priority; }
  std::size_t entityIndex(const std::string& name) const;
  const std::vector<DependencyRelation>& relations() const { return relations_; }

  EvaluationPlan plan() const;

private:
  struct Entity
  {
    std::string name;
    double priority = 1.0;
  };
  std::vector<Entity> entities_;
  std::map<std::string, std::size_t> index_;
  std::vector<DependencyRelation> relations_;
  std::vector<std::string> userOrder_;
};

} // namespace ictk::dyn
