// SPDX-License-Identifier: BSD-3-Clause
// Running a model (ModelState.h): reactions of cells and instances with their clocks, the
// choice of the valid instance and its activation, frames through the stepper, and
// DynamicModel::start and advanceTo, which locate every change of instance in time.
#include "Engine/ModelState.h"

#include <algorithm>
#include <cmath>

namespace ictk::engine
{

// ---- running --------------------------------------------------------------------------------

const Procedure* ModelState::procedureFor(const std::string& cell, const std::string& key) const
{
  if (s.active != kNone)
  {
    const auto& over = instances[s.active].cellReactions;
    if (auto c = over.find(cell); c != over.end())
      if (auto p = c->second.find(key); p != c->second.end())
        return p->second;
  }
  const auto& own = cells[cellIndex.at(cell)].reactions;
  auto p = own.find(key);
  return p == own.end() ? nullptr : p->second;
}

namespace
{

std::vector<Value> timeArgs(
  const Procedure& p, double globalT, double localT, double lifeT, double dt, const dyn::Event* ev)
{
  std::vector<Value> args;
  std::size_t k = 0;
  if (ev)
  {
    Value e;
    e.type = Value::Type::Event;
    e.text = ev->name;
    e.fields = ev->parameters;
    args.push_back(e);
    k = 1;
  }
  const double times[] = { globalT, localT, lifeT, dt };
  // react(E e, globalT, localT, lifeT); update(globalT, localT, lifeT, dt); init(globalT);
  // evaluate(globalT, localT, dt).
  for (std::size_t i = k; i < p.formals.size(); ++i)
  {
    const std::size_t j = i - k;
    double v = j < 4 ? times[j] : 0.0;
    if (p.name.text == "evaluate" && j == 2)
      v = dt;
    args.push_back(Value::real(v));
  }
  return args;
}

} // namespace

void ModelState::runCell(
  const std::string& cell, const std::string& key, dyn::StepContext& c, const dyn::Event* ev)
{
  const Procedure* p = procedureFor(cell, key);
  if (!p)
    return;
  const CellSpec& spec = cells[cellIndex.at(cell)];
  double localT = 0.0, lifeT = 0.0;
  const auto& own = spec.reactions;
  if (own.find(key) == own.end() || own.at(key) != p)
  {
    // A reaction the active instance gives the cell lives on the instance's clock.
    localT = lifeT = c.globalT - s.activatedAt;
  }
  else
  {
    const double since = s.presentSince.count(cell) ? s.presentSince.at(cell) : 0.0;
    localT = lifeT = c.globalT - since;
    if (spec.hasClock)
      localT = spec.clock.localTime(c.globalT).value_or(kNaN);
    if (spec.hasLifespan)
      lifeT = spec.life.lifeTime(c.globalT).value_or(kNaN);
  }
  EngineScope scope(*this, cell, s.active);
  context = &c;
  interpreter.run(*p, timeArgs(*p, c.globalT, localT, lifeT, c.dt, ev), scope);
  context = nullptr;
}

void ModelState::runInstance(
  std::size_t i, const std::string& key, dyn::StepContext& c, const dyn::Event* ev)
{
  auto it = instances[i].reactions.find(key);
  if (it == instances[i].reactions.end())
    return;
  const double local = c.globalT - s.activatedAt;
  EngineScope scope(*this, {}, i);
  context = &c;
  interpreter.run(*it->second, timeArgs(*it->second, c.globalT, local, local, c.dt, ev), scope);
  context = nullptr;
}

void ModelState::activate(dyn::StepContext& c)
{
  if (!s.justActivated)
    return;
  s.justActivated = false;
  if (s.previous != kNone)
  {
    // The cells that leave, then the instance that ends (its terminate), then the new one.
    const auto& now = instances[s.active].cells;
    for (const std::string& cell : instances[s.previous].cells)
      if (std::find(now.begin(), now.end(), cell) == now.end())
        runCell(cell, "terminate", c);
    runInstance(s.previous, "terminate", c);
  }
  runInstance(s.active, "init", c);
  // The first instance's cells get their init from the stepper (their life spans begin).
  if (s.previous == kNone)
    return;
  const auto& before = instances[s.previous].cells;
  for (const std::string& cell : instances[s.active].cells)
    if (std::find(before.begin(), before.end(), cell) == before.end())
      runCell(cell, "init", c);
}

std::vector<std::size_t> ModelState::validInstances(double t)
{
  std::vector<std::size_t> valid;
  for (std::size_t i = 0; i < instances.size(); ++i)
  {
    const InstanceSpec& in = instances[i];
    if (in.isTemplate)
      continue;
    if (!in.predicate)
    {
      valid.push_back(i);
      continue;
    }
    // An instance that is not active has not started: its local time is 0.
    const double local = s.active == i ? t - s.activatedAt : 0.0;
    EngineScope scope(*this, {}, i);
    const Value r =
      interpreter.run(*in.predicate, timeArgs(*in.predicate, t, local, local, 0.0, nullptr), scope);
    if (r.type != Value::Type::Bool)
      fail(in.predicate->pos,
        "the predicate of " + in.name + " returned a " + typeName(r.type) + ", not a bool");
    if (r.number != 0.0)
      valid.push_back(i);
  }
  return valid;
}

void ModelState::setActive(std::size_t i, double t)
{
  keepPlacementsAcross(s.active, i);
  s.previous = s.active;
  const auto* before = s.active != kNone ? &instances[s.active].cells : nullptr;
  for (const std::string& cell : instances[i].cells)
    if (!before || std::find(before->begin(), before->end(), cell) == before->end())
      s.presentSince[cell] = t;
  s.active = i;
  s.activatedAt = t;
  s.justActivated = true;
  stepper->setDependencies(graph(i));
  graphInstance = i;
}

FrameRecord ModelState::record(double t, bool transition)
{
  FrameRecord r;
  r.time = t;
  r.instance = s.active == kNone ? std::string() : instances[s.active].name;
  r.transition = transition;
  const auto& processed = stepper->processedEvents();
  for (std::size_t i = processedSeen; i < processed.size(); ++i)
    r.events.push_back(processed[i].name);
  processedSeen = processed.size();
  const auto& accepted = stepper->acceptedTimes();
  // A transition is located by re-running steps from a saved state: what it saw of them is not
  // history, so only the accepted times up to this record's time count.
  for (std::size_t i = std::min(acceptedSeen, accepted.size()); i < accepted.size(); ++i)
    if (accepted[i] <= t)
      r.steps.push_back(accepted[i]);
  acceptedSeen = accepted.size();
  r.rejectedSteps = std::max(0, stepper->rejections() - rejectionsSeen);
  rejectionsSeen = stepper->rejections();
  for (const std::string& n : modelStateNames)
    r.state.emplace_back(n, get(n));
  if (s.active != kNone)
  {
    const InstanceSpec& in = instances[s.active];
    EngineScope scope(*this, {}, s.active);
    for (const std::string& n : in.stateNames)
    {
      Value v;
      if (!scope.lookup(n, v))
        v = Value{};
      r.state.emplace_back(n, v);
    }
  }
  return r;
}

void ModelState::step(double dt)
{
  try
  {
    stepper->step(dt);
  }
  catch (const dyn::SteppingError& e)
  {
    fail({ 0, 0 }, e.what());
  }
  catch (const dyn::StepRejectedError& e)
  {
    fail({ 0, 0 }, e.what());
  }
}

void ModelState::settle()
{
  try
  {
    stepper->settle();
  }
  catch (const dyn::SteppingError& e)
  {
    fail(instances[s.active].pos, e.what());
  }
}

// ---- DynamicModel::start, advanceTo -------------------------------------------------------

FrameRecord DynamicModel::start()
{
  ModelState& m = *impl_;
  if (m.started)
    return m.record(time(), false);
  m.started = true;
  const double t = time();
  auto unique = [&](const std::vector<std::size_t>& valid)
  {
    if (valid.size() == 1)
      return valid[0];
    std::string names;
    for (std::size_t i : valid)
      names += (names.empty() ? "" : ", ") + m.instances[i].name;
    m.fail(m.instances[m.s.active == kNone ? 0 : m.s.active].pos,
      "at t = " + std::to_string(t) + " " +
        (valid.empty() ? std::string("no instance is valid")
                       : "several instances are valid: " + names) +
        " (exactly one must be, thesis L1394)");
  };
  // The first instance is chosen on the state its own settling frame gives (animations placed,
  // relations evaluated); if that state makes another instance the valid one, start again
  // with that one.
  const dyn::Stepper::Snapshot initial = m.stepper->save();
  std::size_t chosen = unique(m.validInstances(t));
  for (int attempt = 0;; ++attempt)
  {
    m.stepper->restore(initial);
    m.s.active = kNone;
    m.setActive(chosen, t);
    m.settle();
    const std::size_t now = unique(m.validInstances(t));
    if (now == chosen)
      break;
    if (attempt > 16)
      m.fail(m.instances[chosen].pos,
        "no instance stays valid when the model settles at t = " + std::to_string(t));
    chosen = now;
  }
  return m.record(t, true);
}

std::vector<FrameRecord> DynamicModel::advanceTo(double t, double maxStep)
{
  ModelState& m = *impl_;
  if (!std::isfinite(t) || !(maxStep > 0.0) || !std::isfinite(maxStep))
    throw std::invalid_argument("advanceTo: the time and the step must be finite, the step > 0");
  if (t < time())
    throw std::invalid_argument("advanceTo: " + std::to_string(t) + " is before the model's time " +
      std::to_string(time()) + " (reload the model to go back)");
  std::vector<FrameRecord> out;
  if (!m.started)
    out.push_back(start());
  const double t0 = time();
  ProgressScope progress(m.options.progress);
  while (time() < t)
  {
    const double now = time();
    // A remainder below 1e-9 of the step (6 x 0.1 is 0.6000000000000001) joins this step
    // instead of becoming a frame of its own.
    const double target = (now + maxStep >= t - 1e-9 * maxStep) ? t : now + maxStep;
    const dyn::Stepper::Snapshot snap = m.stepper->save();
    m.step(target - now);
    auto valid = m.validInstances(target);
    const std::size_t active = m.s.active;
    if (valid.size() == 1 && valid[0] == active)
    {
      out.push_back(m.record(target, false));
    }
    else
    {
      // The first time the active instance stops being the only valid one, by bisection on the
      // identity of the valid set, re-running the frame from `now` to each probe.
      double lo = now, hi = target;
      auto probe = [&](double tau)
      {
        m.stepper->restore(snap);
        m.step(tau - now);
        return m.validInstances(tau);
      };
      while (hi - lo > m.options.timeTolerance)
      {
        const double mid = lo + 0.5 * (hi - lo);
        if (!(mid > lo && mid < hi))
          break;
        const auto v = probe(mid);
        if (v.size() == 1 && v[0] == active)
          lo = mid;
        else
          hi = mid;
      }
      valid = probe(hi);
      if (valid.size() != 1)
      {
        // Predicates are numerical: where two of them flip within the geometric tolerance of
        // each other (a query that says "touching" a little before another counts the point)
        // no instance, or two, may be valid for a moment. Look a little later for the first
        // time with exactly one, up to 1e3 x the time tolerance.
        const double reach = std::min(target, hi + 1e3 * m.options.timeTolerance);
        double a = hi, b = hi;
        bool found = false;
        for (double d = m.options.timeTolerance; !found && b < reach; d *= 2.0)
        {
          b = std::min(hi + d, reach);
          found = probe(b).size() == 1;
          if (!found)
            a = b;
        }
        if (found)
        {
          while (b - a > m.options.timeTolerance * 1e-3 && a + 0.5 * (b - a) > a)
          {
            const double mid = a + 0.5 * (b - a);
            if (probe(mid).size() == 1)
              b = mid;
            else
              a = mid;
          }
          hi = b;
        }
        valid = probe(hi);
      }
      // A transition at `hi`: the state is the one the old instance's frame reached (what its
      // reactions decided, e.g. a latch, is kept); the new instance then settles at that time
      // (its init, its relations, its updates with dt = 0, its updatePost), so the state
      // recorded at hi is the new instance's. If that makes yet another instance the valid one
      // (an instance valid only at an instant: the tangency of thesis 5.1, Newton's cradle's
      // contact), it follows at the same time.
      for (int hop = 0;; ++hop)
      {
        if (valid.size() != 1)
        {
          std::string names;
          for (std::size_t i : valid)
            names += (names.empty() ? "" : ", ") + m.instances[i].name;
          m.fail(m.instances[m.s.active].pos,
            "at t = " + std::to_string(hi) + " after " + m.instances[m.s.active].name + ", " +
              (valid.empty() ? std::string("no instance is valid")
                             : "several instances are valid: " + names) +
              " (exactly one must be, thesis L1394)");
        }
        if (valid[0] == m.s.active)
          break;
        if (hop > 16)
          m.fail(m.instances[m.s.active].pos,
            "at t = " + std::to_string(hi) + " the instances keep switching without time passing");
        m.setActive(valid[0], hi);
        m.settle();
        out.push_back(m.record(hi, true));
        valid = m.validInstances(hi);
      }
    }
    if (t > t0)
      progress.report(std::min(1.0, (time() - t0) / (t - t0)),
        [&] { return "the run was cancelled at t = " + std::to_string(time()); });
  }
  return out;
}

} // namespace ictk::engine
