// SPDX-License-Identifier: BSD-3-Clause
#include "Dynamics/Stepper.h"

#include <algorithm>
#include <cmath>

namespace ictk::dyn
{

void StepContext::fireEvent(Event e)
{
  if (e.name == events::TimeRejected)
  {
    auto it = e.parameters.find("step");
    rejectTime(it == e.parameters.end() ? std::numeric_limits<double>::quiet_NaN() : it->second);
    return;
  }
  if (e.span.empty())
    e.span = TimeSpan::interval(globalT, kInfinity);
  queue_->push(std::move(e));
}

void StepContext::rejectTime(double relStep)
{
  *rejected_ = true;
  // Several rejections in one frame: the smallest requested step wins (NaN = halve).
  if (!std::isnan(relStep) && (std::isnan(*requested_) || relStep < *requested_))
    *requested_ = relStep;
}

Stepper::Stepper(ParameterTable params, double t0)
  : params_(std::move(params))
  , t_(t0)
{
  plan_ = graph_.plan();
}

std::size_t Stepper::addReaction(Reaction r)
{
  reactions_.push_back(std::move(r));
  alive_.push_back(false);
  setDependencies(graph_);
  return reactions_.size() - 1;
}

void Stepper::setDependencies(DependencyGraph graph)
{
  // A relation the new plan shares with the old one (same ends and parameters) keeps its
  // validity: only relations that are new, or whose master changed, copy values.
  std::map<std::string, double> kept;
  for (std::size_t r = 0; r < graph_.relations().size() && r < lastPulled_.size(); ++r)
  {
    const DependencyRelation& d = graph_.relations()[r];
    kept[d.master + "." + d.masterParam + ">" + d.dependent + "." + d.dependentParam] =
      lastPulled_[r];
  }
  graph_ = std::move(graph);
  plan_ = graph_.plan();
  lastPulled_.assign(graph_.relations().size(), std::numeric_limits<double>::quiet_NaN());
  for (std::size_t r = 0; r < graph_.relations().size(); ++r)
  {
    const DependencyRelation& d = graph_.relations()[r];
    const auto it =
      kept.find(d.master + "." + d.masterParam + ">" + d.dependent + "." + d.dependentParam);
    if (it != kept.end())
      lastPulled_[r] = it->second;
  }
  const std::size_t n = graph_.entityCount();
  entityReaction_.assign(n, std::nullopt);
  incoming_.assign(n, {});
  for (std::size_t r = 0; r < graph_.relations().size(); ++r)
    incoming_[graph_.entityIndex(graph_.relations()[r].dependent)].push_back(r);
  std::vector<bool> inGraph(reactions_.size(), false);
  for (std::size_t i = 0; i < reactions_.size(); ++i)
    for (std::size_t e = 0; e < n; ++e)
      if (graph_.entityName(e) == reactions_[i].name && !entityReaction_[e])
      {
        entityReaction_[e] = i;
        inGraph[i] = true;
      }
  reactionOrder_.clear();
  for (std::size_t e : plan_.order())
    if (entityReaction_[e])
      reactionOrder_.push_back(*entityReaction_[e]);
  for (std::size_t i = 0; i < reactions_.size(); ++i)
    if (!inGraph[i])
      reactionOrder_.push_back(i);
}

void Stepper::setExternalState(
  std::function<std::any()> save, std::function<void(const std::any&)> restore)
{
  saveExternal_ = std::move(save);
  restoreExternal_ = std::move(restore);
}

Stepper::Snapshot Stepper::save() const
{
  return Snapshot{ params_, queue_, t_, alive_, log_.size(), processed_.size(), accepted_.size(),
    lastPulled_, saveExternal_ ? saveExternal_() : std::any() };
}

bool Stepper::takesPart(std::size_t i) const
{
  return alive_[i] && (!reactions_[i].enabled || reactions_[i].enabled());
}

void Stepper::restore(const Snapshot& s)
{
  params_ = s.params;
  queue_ = s.queue;
  t_ = s.t;
  alive_ = s.alive;
  log_.resize(s.logSize);
  processed_.resize(s.processedSize);
  accepted_.resize(s.acceptedSize);
  // The external state may replace the dependency plan (which resets the relations' validity),
  // so it goes first.
  if (restoreExternal_)
    restoreExternal_(s.external);
  lastPulled_ = s.lastPulled;
}

StepContext Stepper::context(
  std::size_t reaction, double tNew, double h, bool& rejected, double& requested)
{
  StepContext c;
  c.globalT = tNew;
  c.dt = h;
  const TimeSpan& life = reactions_[reaction].life;
  c.localT = life.localTime(tNew).value_or(std::numeric_limits<double>::quiet_NaN());
  c.lifeT = life.lifeTime(tNew).value_or(std::numeric_limits<double>::quiet_NaN());
  c.params = &params_;
  c.queue_ = &queue_;
  c.rejected_ = &rejected;
  c.requested_ = &requested;
  return c;
}

void Stepper::pull(std::size_t relation, const std::vector<double>& previous, bool usePrevious)
{
  const DependencyRelation& r = graph_.relations()[relation];
  if (r.masterParam.empty() || r.dependentParam.empty())
    return;
  // A relation between properties that are not parameters (shapes, transforms handled by the
  // cells) only orders the evaluation.
  const auto from = params_.find(r.master + "." + r.masterParam);
  const auto to = params_.find(r.dependent + "." + r.dependentParam);
  if (!from || !to)
    return;
  double v = usePrevious ? previous[*from] : params_.value(*from);
  if (options_.pullChangedOnly)
  {
    if (v == lastPulled_[relation])
      return;
    lastPulled_[relation] = v;
  }
  if (r.map)
    v = r.map(v);
  params_.setValue(*to, v);
}

bool Stepper::frame(double tNew, double h, double& requested)
{
  bool rejected = false;
  requested = std::numeric_limits<double>::quiet_NaN();
  const std::vector<double> previous = params_.values();
  const std::vector<bool> readsPrev = plan_.readsPrevious(options_.cycles);

  for (std::size_t i : reactionOrder_)
  {
    const bool nowAlive = reactions_[i].life.contains(tNew);
    if (nowAlive == alive_[i])
      continue;
    alive_[i] = nowAlive;
    if (reactions_[i].enabled && !reactions_[i].enabled())
      continue;
    StepContext c = context(i, tNew, h, rejected, requested);
    auto& fn = nowAlive ? reactions_[i].init : reactions_[i].terminate;
    log_.push_back(reactions_[i].name + (nowAlive ? ".init" : ".terminate"));
    if (fn)
      fn(c);
  }
  params_.evaluate();

  auto update = [&](std::size_t i)
  {
    if (!takesPart(i))
      return;
    StepContext c = context(i, tNew, h, rejected, requested);
    log_.push_back(reactions_[i].name + ".update");
    if (reactions_[i].update)
      reactions_[i].update(c);
  };
  std::vector<bool> done(reactions_.size(), false);
  for (const auto& list : plan_.lists)
    for (std::size_t e : list)
    {
      for (std::size_t r : incoming_[e])
        pull(r, previous, readsPrev[r]);
      if (entityReaction_[e])
      {
        update(*entityReaction_[e]);
        done[*entityReaction_[e]] = true;
      }
    }
  for (std::size_t i : reactionOrder_)
    if (!done[i])
      update(i);
  if (options_.cycles == CyclePolicy::Reevaluate)
    for (std::size_t r : plan_.reevaluations)
    {
      pull(r, previous, false);
      const std::size_t e = graph_.entityIndex(graph_.relations()[r].dependent);
      log_.push_back(graph_.entityName(e) + ".reevaluate");
      if (entityReaction_[e] && takesPart(*entityReaction_[e]) &&
        reactions_[*entityReaction_[e]].reevaluate)
      {
        StepContext c = context(*entityReaction_[e], tNew, h, rejected, requested);
        reactions_[*entityReaction_[e]].reevaluate(c);
      }
    }
  params_.evaluate();

  for (std::size_t i : reactionOrder_)
    if (takesPart(i))
    {
      StepContext c = context(i, tNew, h, rejected, requested);
      log_.push_back(reactions_[i].name + ".updatePost");
      if (reactions_[i].updatePost)
        reactions_[i].updatePost(c);
    }

  int dispatched = 0;
  while (!queue_.empty() && queue_.top().time() <= tNew)
  {
    const Event ev = queue_.pop();
    if (++dispatched > options_.maxEventsPerFrame)
      throw SteppingError("more than maxEventsPerFrame events in the frame at t = " +
        std::to_string(tNew) + " (an event loop?)");
    for (std::size_t i : reactionOrder_)
    {
      const Reaction& r = reactions_[i];
      if (!takesPart(i) ||
        std::find(r.reactsTo.begin(), r.reactsTo.end(), ev.name) == r.reactsTo.end())
        continue;
      StepContext c = context(i, tNew, h, rejected, requested);
      log_.push_back(r.name + ".react:" + ev.name);
      if (r.react)
        r.react(c, ev);
    }
    processed_.push_back(ev);
  }
  return !rejected;
}

void Stepper::settle()
{
  const Snapshot s = save();
  double requested = 0.0;
  bool accepted = false;
  try
  {
    accepted = frame(t_, 0.0, requested);
  }
  catch (...)
  {
    restore(s);
    throw;
  }
  if (!accepted)
  {
    restore(s);
    throw SteppingError("a reaction rejected the time while the model settled at t = " +
      std::to_string(t_) + " (there is no earlier time to go back to)");
  }
}

int Stepper::step(double dt)
{
  if (!(dt > 0.0) || !std::isfinite(dt))
    throw std::invalid_argument("Stepper::step: dt must be finite and > 0");
  const double target = t_ + dt;
  double h = dt;
  int frames = 0;
  while (t_ < target)
  {
    h = std::min(h, target - t_);
    int halvings = 0;
    for (;;)
    {
      const Snapshot s = save();
      double requested = 0.0;
      // The last sub-step lands exactly on the target (no rounding drift); a remainder below
      // 1e-9 of the step (sums of 0.1 that fall short of 1 by 1e-16) joins the step before it
      // instead of becoming a frame of its own.
      const double tNew = (t_ + h >= target - 1e-9 * h) ? target : t_ + h;
      if (!(tNew > t_))
        throw StepRejectedError("the step from t = " + std::to_string(t_) +
          " has become smaller than the resolution of time");
      bool accepted = false;
      try
      {
        accepted = frame(tNew, tNew - t_, requested);
      }
      catch (...)
      {
        restore(s); // a failing callback leaves the state at the last valid time
        throw;
      }
      if (accepted)
      {
        t_ = tNew;
        accepted_.push_back(tNew);
        ++frames;
        if (options_.growRefinedSteps)
          h = std::min(2 * h, dt);
        break;
      }
      restore(s);
      ++rejections_;
      if (!std::isnan(requested) && requested <= 0.0)
        throw SteppingError("TIME_REJECTED requests a time before the last correctly evaluated "
                            "time " +
          std::to_string(t_) + ": the model is invalid (thesis L2082)");
      h = (!std::isnan(requested) && requested < h) ? requested : 0.5 * h;
      if (++halvings > options_.maxHalvings)
        throw StepRejectedError("the step from t = " + std::to_string(t_) + " was rejected " +
          std::to_string(halvings) + " times");
    }
  }
  return frames;
}

std::optional<frep::Crossing> Stepper::stepUntil(double dt,
  const std::function<double(const ParameterTable&, double)>& guard,
  const frep::LocateOptions& options)
{
  const Snapshot start = save();
  const double t0 = t_;
  auto g = [&](double tau)
  {
    restore(start);
    if (tau > t0)
      step(tau - t0);
    return guard(params_, tau);
  };
  std::optional<frep::Crossing> c = frep::locateCrossing(g, t0, t0 + dt, options);
  restore(start);
  const double to = c ? c->time : t0 + dt;
  if (to > t0)
    step(to - t0);
  return c;
}

} // namespace ictk::dyn
