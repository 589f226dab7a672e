// SPDX-License-Identifier: BSD-3-Clause
// IC templates, IC instances and the active instance (thesis §3.8-3.9 L1384-1459, §4.3.3 step 7,
// Table 2 L4114-4137).
//
// An instance derives from a template by removing and adding cells and relations,
// I_j = TI \ {...} U {...} (L1459), and has a validity predicate F^{I_j}(t) (L1392) and an optional
// life span. "Only one IC instance can be valid at any given instance in time" (L1394-1396): the
// active instance at t is the unique valid one; zero or several valid instances are an error
// (InstanceError) that names them. Predicates are functions of global time; they read whatever
// model state the caller binds into them.
//
// trace() walks [t0, t1] with step dt and records the transitions between instances with their
// times. Instants where the structure changes are located with locateCrossing (FRep/RootFinding.h)
// on the caller's guards (scalar state functions whose zeros are the structural events, e.g. the
// signed distance between two cells), so an instance valid only at an instant (a tangency) is
// found and reported: the transition into it and the one out of it share the same time (within
// the predicates' own tolerance). A change of the active instance that no guard explains is
// located by bisection on the identity of the active instance to LocateOptions::timeTolerance;
// bisection alone cannot see an instance valid on an interval shorter than that tolerance (or at
// a single instant), which is why the guards exist.
#pragma once

#include "Dynamics/Time.h"
#include "FRep/RootFinding.h"

#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace ictk::dyn
{

class InstanceError : public std::runtime_error
{
public:
  InstanceError(const std::string& what, double time, std::vector<std::string> names)
    : std::runtime_error(what)
    , time(time)
    , valid(std::move(names))
  {
  }
  double time;
  std::vector<std::string> valid; ///< the instances valid at `time` (empty: none)
};

struct IcTemplate
{
  std::string name;
  std::vector<std::string> cells;     ///< in definition order
  std::vector<std::string> relations; ///< relation names, in definition order
};

struct IcInstance
{
  std::string name;
  std::string templateName; ///< "" = no template
  std::vector<std::string> removeCells, addCells, removeRelations, addRelations;
  std::function<bool(double)> predicate; ///< F^{I_j}(t); empty = always true inside `life`
  TimeSpan life = TimeSpan::infinite();
};

struct Transition
{
  double time = 0.0;
  std::string from, to; ///< from "" = the first instance
};

class InstanceSet
{
public:
  void addTemplate(IcTemplate t);
  /// The template must exist (std::invalid_argument naming it otherwise).
  std::size_t addInstance(IcInstance i);

  std::size_t size() const { return instances_.size(); }
  const IcInstance& instance(std::size_t i) const { return instances_.at(i); }
  std::size_t index(const std::string& name) const;

  /// Template cells minus removed plus added (template order, then added order). Removing a cell
  /// the template does not have is reported in `warnings` (ch4 feature 26), not silently ignored.
  std::vector<std::string> cells(std::size_t i, std::vector<std::string>* warnings = nullptr) const;
  std::vector<std::string> relations(
    std::size_t i, std::vector<std::string>* warnings = nullptr) const;

  bool isValid(std::size_t i, double t) const;
  /// Indices of the instances valid at t, in definition order.
  std::vector<std::size_t> validAt(double t) const;
  /// The unique valid instance at t, else InstanceError.
  std::size_t activeAt(double t) const;

  /// The transitions over [t0, t1] (see the file comment); the first entry is the instance active
  /// at t0 (from = ""). Throws InstanceError when no or several instances are valid at a probed
  /// time.
  std::vector<Transition> trace(double t0, double t1, double dt,
    const std::vector<std::function<double(double)>>& guards = {},
    const frep::LocateOptions& options = {}) const;

private:
  const IcTemplate* templateOf(const IcInstance& i) const;
  std::vector<IcTemplate> templates_;
  std::vector<IcInstance> instances_;
};

} // namespace ictk::dyn
