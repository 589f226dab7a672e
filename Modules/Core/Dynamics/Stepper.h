// SPDX-License-Identifier: BSD-3-Clause
// The stepping skeleton of the IC engine (thesis §4.3.3 L1867-1894, §4.4.2 L2061-2082, §3.7
// L1309-1382): reactions run in dependency order, events are dispatched, and a reaction may
// reject the time (TIME_REJECTED), in which case the state is restored and the step retried with
// a smaller step.
//
// One frame at the new time t' (relative to the accepted time t, h = t' - t):
//  1. previous <- the parameter values at t (read by relations that read previous-frame values,
//     Dependencies.h);
//  2. life spans: a reaction whose life span starts to contain t' gets `init`, one whose life span
//     stops containing t' gets `terminate` (L1583); a reaction outside its life span is skipped;
//  3. the expression parameters are evaluated (Parameters.h);
//  4. for every concurrency list of the dependency plan, for every entity in it: the relations
//     into it copy their master values into its parameters (in relation definition order; a
//     relation whose two ends are not both parameters of the table only orders the evaluation),
//     then its `update` (pre-update) runs;
//     reactions whose name is not an entity of the graph run afterwards, in definition order;
//  5. CyclePolicy::Reevaluate only: each cut relation (highest priority first) is pulled again
//     with current values and its dependent's `reevaluate` runs (footnote 27);
//  6. the expression parameters are evaluated again, then every `updatePost` runs (L2541);
//  7. events due at t' (time <= t') are dispatched in queue order (Events.h) to every alive
//     reaction that lists the event's name, in evaluation order; events fired while reacting are
//     dispatched in the same frame when due (bounded by maxEventsPerFrame).
// If any callback called rejectTime() (or fired TIME_REJECTED), the whole state (parameters,
// event queue, life flags, logs) is restored to t and the frame is retried at t + h', where h' is
// the step the reaction requested (relative to t) when it is smaller than h, else h / 2. After
// maxHalvings rejections of one attempt, StepRejectedError. A requested step <= 0 would go back
// before the last correctly evaluated time, which makes the model invalid (L2082): SteppingError.
// An exception thrown by a callback also restores the state before it propagates.
// After an accepted sub-step the stepper continues with steps of the accepted size (or, with
// StepperOptions::growRefinedSteps, twice that size) until the requested time is reached, so the
// caller always gets the state at the time it asked for (fig. 56b, L2070).
//
// Callbacks must keep their state in the ParameterTable (or in events): the stepper re-runs frames
// after restoring it, and stepUntil() re-runs a step several times to locate a transition.
#pragma once

#include "Dynamics/Dependencies.h"
#include "Dynamics/Events.h"
#include "Dynamics/Parameters.h"
#include "Dynamics/Time.h"
#include "FRep/RootFinding.h"

#include <any>
#include <functional>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace ictk::dyn
{

class StepRejectedError : public std::runtime_error
{
public:
  using std::runtime_error::runtime_error;
};

/// The model cannot be stepped on: a requested time before the last correct one, more events in
/// a frame than allowed, a rejection while the model settles. (engine::ModelError is the .icm
/// runtime's error with a place in the model text.)
class SteppingError : public std::runtime_error
{
public:
  using std::runtime_error::runtime_error;
};

class StepContext
{
public:
  double globalT = 0.0; ///< the time being evaluated
  double dt = 0.0;      ///< the step from the last accepted time
  double localT = 0.0;  ///< local time in the reaction's life span (NaN outside)
  double lifeT = 0.0;   ///< life time of the reaction's entity (NaN outside)
  ParameterTable* params = nullptr;

  /// Queues an event; an event without a time span occurs now (globalT).
  void fireEvent(Event e);
  /// TIME_REJECTED (L2075): the frame is retried; `relStep` > 0 is the requested step from the
  /// last accepted time, NaN (default) halves the step.
  void rejectTime(double relStep = std::numeric_limits<double>::quiet_NaN());

  /// Shorthands for params->value(name) and params->setValue(name, v).
  double get(const std::string& qualifiedName) const { return params->value(qualifiedName); }
  void set(const std::string& qualifiedName, double v) { params->setValue(qualifiedName, v); }

private:
  friend class Stepper;
  EventQueue* queue_ = nullptr;
  bool* rejected_ = nullptr;
  double* requested_ = nullptr;
};

struct Reaction
{
  std::string name; ///< the entity (cell, attribute, instance) it belongs to
  TimeSpan life = TimeSpan::infinite();
  std::vector<std::string> reactsTo; ///< event names for `react`
  std::function<void(StepContext&)> init, terminate, update, updatePost, reevaluate;
  std::function<void(StepContext&, const Event&)> react;
  /// While this returns false the reaction takes no part in frames (no init, update, updatePost
  /// or react), e.g. a cell that is not in the active IC instance. Empty = always.
  std::function<bool()> enabled;
};

struct StepperOptions
{
  int maxHalvings = 30;
  CyclePolicy cycles = CyclePolicy::PreviousState;
  int maxEventsPerFrame = 10000;
  /// A relation copies its master's value only when that value differs from the one it copied
  /// last, i.e. when the relation is invalid (thesis footnote 27: relations are marked valid once
  /// evaluated). The dependent then keeps what its own reactions wrote while its master is
  /// unchanged, which a bidirectional pair (Andyhausen's handles) needs. Off: every frame copies.
  bool pullChangedOnly = false;
  /// After a sub-step refined by TIME_REJECTED is accepted, the next one is twice as long (up to
  /// what is left of the requested step) instead of keeping the refined size: the steps follow
  /// how fast the model changes (thesis 5.3.4's non-linear sampling) rather than staying at the
  /// smallest size until the requested time.
  bool growRefinedSteps = false;
};

class Stepper
{
public:
  explicit Stepper(ParameterTable params, double t0 = 0.0);

  std::size_t addReaction(Reaction r);
  /// The evaluation order and the value-pulling relations (Dependencies.h).
  void setDependencies(DependencyGraph graph);
  void setOptions(StepperOptions o) { options_ = o; }
  /// State the callbacks keep outside the parameter table (structural state of a model): `save`
  /// is called with every snapshot and `restore` when the stepper steps back, so a rejected
  /// frame or a probe of stepUntil() leaves no trace in it either.
  void setExternalState(
    std::function<std::any()> save, std::function<void(const std::any&)> restore);
  /// Queues an event from outside the model.
  void fireEvent(Event e) { queue_.push(std::move(e)); }

  double time() const { return t_; }
  ParameterTable& params() { return params_; }
  const ParameterTable& params() const { return params_; }
  /// "Entity.update", "Entity.updatePost", "Entity.react:EVENT", "Entity.init", ... of the
  /// accepted frames, in call order.
  const std::vector<std::string>& log() const { return log_; }
  /// Events dispatched in accepted frames, in order.
  const std::vector<Event>& processedEvents() const { return processed_; }
  /// The times of accepted frames (sub-steps included).
  const std::vector<double>& acceptedTimes() const { return accepted_; }
  int rejections() const { return rejections_; }

  /// Advances to time() + dt (dt > 0) and returns the number of accepted frames it took.
  int step(double dt);
  /// Evaluates one frame at time() without advancing it (dt = 0): every relation is evaluated
  /// once, so the model starts from a consistent state. A reaction that rejects the time there
  /// is a SteppingError.
  void settle();

  /// Advances by dt unless guard(params, t) reaches 0 inside the step (locateCrossing); then
  /// stops exactly at the located time and returns the crossing. The guard is probed by
  /// re-running the step from the saved state to each probe time.
  std::optional<frep::Crossing> stepUntil(double dt,
    const std::function<double(const ParameterTable&, double)>& guard,
    const frep::LocateOptions& options = {});

  struct Snapshot
  {
    ParameterTable params;
    EventQueue queue;
    double t = 0.0;
    std::vector<bool> alive;
    std::size_t logSize = 0, processedSize = 0, acceptedSize = 0;
    std::vector<double> lastPulled;
    std::any external;
  };
  Snapshot save() const;
  void restore(const Snapshot& s);

private:
  bool frame(double tNew, double h, double& requested);
  StepContext context(
    std::size_t reaction, double tNew, double h, bool& rejected, double& requested);
  void pull(std::size_t relation, const std::vector<double>& previous, bool usePrevious);
  bool takesPart(std::size_t reaction) const;

  ParameterTable params_;
  double t_ = 0.0;
  std::vector<Reaction> reactions_;
  std::vector<bool> alive_;
  DependencyGraph graph_;
  EvaluationPlan plan_;
  std::vector<std::size_t> reactionOrder_;                 // reaction indices in evaluation order
  std::vector<std::vector<std::size_t>> incoming_;         // per graph entity: relation indices
  std::vector<std::optional<std::size_t>> entityReaction_; // per graph entity
  EventQueue queue_;
  StepperOptions options_;
  std::vector<std::string> log_;
  std::vector<Event> processed_;
  std::vector<double> accepted_;
  int rejections_ = 0;
  std::vector<double> lastPulled_; // per relation: the value it copied last (NaN: never)
  std::function<std::any()> saveExternal_;
  std::function<void(const std::any&)> restoreExternal_;
};

} // namespace ictk::dyn
