// SPDX-License-Identifier: BSD-3-Clause
// Events (thesis L1327-1333), reactions and the stepper with TIME_REJECTED (§4.4.2 L2061-2082),
// and the stepper stopping at a located transition (FRep/RootFinding.h, tested in
// TestRootFinding.cxx). Hand-derived values in the comments.

#include "Dynamics/Events.h"
#include "Dynamics/Stepper.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <any>
#include <cmath>

using namespace ictk::dyn;
using ::testing::ElementsAre;
using ::testing::HasSubstr;

TEST(DynamicsEvents, QueueOrderIsTimePriorityNameInsertion)
{
  EventQueue q;
  q.push(Event::at("b", 1.0, 1.0));
  q.push(Event::at("z", 1.0, 2.0));
  q.push(Event::at("early", 0.5, 0.0));
  q.push(Event::at("a", 1.0, 1.0, { { "k", 1.0 } }));
  q.push(Event::at("a", 1.0, 1.0, { { "k", 2.0 } }));
  q.push(Event::at("later", 2.0, 9.0));
  // t = 0.5 first; at t = 1 the higher priority z (L1333); then a before b by name; the two a's
  // in insertion order. "later" (t = 2) is not due at t = 1.
  std::vector<std::string> order;
  std::vector<double> ks;
  for (const Event& e : q.popUntil(1.0))
  {
    order.push_back(e.name);
    if (e.name == "a")
      ks.push_back(e.parameters.at("k"));
  }
  EXPECT_THAT(order, ElementsAre("early", "z", "a", "a", "b"));
  EXPECT_THAT(ks, ElementsAre(1.0, 2.0));
  ASSERT_EQ(q.size(), 1u);
  EXPECT_EQ(q.top().name, "later");
}

TEST(DynamicsEvents, ReactionsReceiveEventsAndFireNewOnes)
{
  // R1 reacts to HIT (priority 2) and LOW (priority 1), both fired for t = 0.25 (ch4 feature 66:
  // HIT first), records HIT's parameter and fires ECHO; R2 reacts to ECHO in the same frame
  // (feature 67). An event for t = 2 stays queued.
  ParameterTable p;
  p.add("R1", "seen", Scope::Global, 0.0);
  p.add("R2", "echoes", Scope::Global, 0.0);
  Stepper s(p);
  Reaction r1;
  r1.name = "R1";
  r1.reactsTo = { "HIT", "LOW" };
  r1.react = [](StepContext& c, const Event& e)
  {
    if (e.name == "HIT")
    {
      c.set("R1.seen", e.parameters.at("force"));
      c.fireEvent(Event{ "ECHO", {}, {}, 1.0 });
    }
  };
  Reaction r2;
  r2.name = "R2";
  r2.reactsTo = { "ECHO" };
  r2.react = [](StepContext& c, const Event&)
  {
    c.set("R2.echoes", c.get("R2.echoes") + 1);
  };
  s.addReaction(r1);
  s.addReaction(r2);
  s.fireEvent(Event::at("LOW", 0.25, 1.0));
  s.fireEvent(Event::at("HIT", 0.25, 2.0, { { "force", 7.5 } }));
  s.fireEvent(Event::at("HIT", 2.0, 2.0, { { "force", 1.0 } }));
  s.step(0.5);
  EXPECT_EQ(s.params().value("R1.seen"), 7.5);
  EXPECT_EQ(s.params().value("R2.echoes"), 1.0);
  std::vector<std::string> names;
  for (const Event& e : s.processedEvents())
    names.push_back(e.name);
  // ECHO was fired at t = 0.5 (the frame's time), after HIT and LOW at 0.25.
  EXPECT_THAT(names, ElementsAre("HIT", "LOW", "ECHO"));
  std::vector<std::string> reacts;
  for (const std::string& l : s.log())
    if (l.find(".react:") != std::string::npos)
      reacts.push_back(l);
  EXPECT_THAT(reacts, ElementsAre("R1.react:HIT", "R1.react:LOW", "R2.react:ECHO"));
}

TEST(DynamicsEvents, InitAndTerminateFollowTheLifeSpan)
{
  // A reaction alive on [0.5, 1.5] (ch4 feature 34): init at the first frame inside, terminate at
  // the first frame after; no update outside. Frames at 0.25, 0.5, ..., 2.
  ParameterTable p;
  p.add("C", "updates", Scope::Global, 0.0);
  p.add("C", "lifeAtInit", Scope::Global, -1.0);
  Stepper s(p);
  Reaction r;
  r.name = "C";
  r.life = TimeSpan::interval(0.5, 1.5);
  r.init = [](StepContext& c)
  {
    c.set("C.lifeAtInit", c.lifeT);
  };
  r.update = [](StepContext& c)
  {
    c.set("C.updates", c.get("C.updates") + 1);
  };
  s.addReaction(r);
  for (int i = 0; i < 8; ++i)
    s.step(0.25);
  // Alive at 0.5, 0.75, 1.0, 1.25, 1.5: five updates; life time 0 at activation.
  EXPECT_EQ(s.params().value("C.updates"), 5.0);
  EXPECT_EQ(s.params().value("C.lifeAtInit"), 0.0);
  EXPECT_EQ(std::count(s.log().begin(), s.log().end(), "C.init"), 1);
  EXPECT_EQ(std::count(s.log().begin(), s.log().end(), "C.terminate"), 1);
}

namespace
{
// A reaction that accepts steps of at most 0.3 (like STB_CELL, L3136-3164) and counts its
// updates in the state, so that a rejected attempt must not leave a trace (ch4 feature 68).
Stepper limited(double requestedStep)
{
  ParameterTable p;
  p.add("Guard", "count", Scope::Global, 0.0);
  Stepper s(p);
  Reaction r;
  r.name = "Guard";
  r.update = [requestedStep](StepContext& c)
  {
    c.set("Guard.count", c.get("Guard.count") + 1);
    if (c.dt > 0.3)
      c.rejectTime(requestedStep);
  };
  s.addReaction(r);
  return s;
}
} // namespace

TEST(DynamicsEvents, TimeRejectedHalvesTheStepAndRestoresTheState)
{
  // step(1): h = 1 rejected, 0.5 rejected, 0.25 accepted; then 0.25 steps up to exactly 1
  // (fig. 56b: the requested time is still delivered). Frames at 0.25, 0.5, 0.75, 1: count = 4
  // (the two rejected attempts were rolled back, otherwise it would be 6).
  Stepper s = limited(std::nan(""));
  EXPECT_EQ(s.step(1.0), 4);
  EXPECT_THAT(s.acceptedTimes(), ElementsAre(0.25, 0.5, 0.75, 1.0));
  EXPECT_EQ(s.rejections(), 2);
  EXPECT_EQ(s.time(), 1.0);
  EXPECT_EQ(s.params().value("Guard.count"), 4.0);
}

TEST(DynamicsEvents, TimeRejectedWithARequestedStep)
{
  // IC::fireEvent(TIME_REJECTED, 0.2) (L2075): retried with h = 0.2: frames at 0.2, 0.4, 0.6,
  // 0.8 and exactly 1.0 (the last sub-step lands on the target), one rejection.
  Stepper s = limited(0.2);
  EXPECT_EQ(s.step(1.0), 5);
  ASSERT_EQ(s.acceptedTimes().size(), 5u);
  EXPECT_NEAR(s.acceptedTimes()[2], 0.6, 1e-15);
  EXPECT_EQ(s.acceptedTimes().back(), 1.0);
  EXPECT_EQ(s.rejections(), 1);
  EXPECT_EQ(s.params().value("Guard.count"), 5.0);
}

TEST(DynamicsEvents, RefinedStepsGrowAgainWhenAsked)
{
  // A reaction that needs steps of at most 0.1 across t = 0.3 (and halves otherwise). Keeping the
  // refined size: 0.25, then 0.3125 after two halvings, then steps of 0.0625 up to 1 (13 frames).
  // Growing: 0.25, 0.3125, then 0.125, 0.25 and the rest: 0.4375, 0.6875, 1 (5 frames).
  for (const bool grow : { false, true })
  {
    ParameterTable p;
    p.add("Guard", "count", Scope::Global, 0.0);
    Stepper s(p);
    StepperOptions o;
    o.growRefinedSteps = grow;
    s.setOptions(o);
    Reaction r;
    r.name = "Guard";
    r.update = [](StepContext& c)
    {
      c.set("Guard.count", c.get("Guard.count") + 1);
      if (c.dt > 0.1 && c.globalT - c.dt < 0.3 && c.globalT >= 0.3)
        c.rejectTime();
    };
    s.addReaction(r);
    if (grow)
    {
      EXPECT_EQ(s.step(1.0), 5);
      EXPECT_THAT(s.acceptedTimes(), ElementsAre(0.25, 0.3125, 0.4375, 0.6875, 1.0));
      EXPECT_EQ(s.rejections(), 5); // 1, 0.5, then 0.5, 0.25, 0.125 from 0.25
    }
    else
    {
      EXPECT_EQ(s.step(1.0), 13);
      EXPECT_EQ(s.acceptedTimes()[1], 0.3125);
      EXPECT_EQ(s.acceptedTimes()[2], 0.375);
      EXPECT_EQ(s.rejections(), 4); // 1, 0.5, then 0.25, 0.125 from 0.25
    }
    EXPECT_EQ(s.acceptedTimes().back(), 1.0);
    EXPECT_EQ(s.params().value("Guard.count"), static_cast<double>(s.acceptedTimes().size()));
  }
}

TEST(DynamicsEvents, TimeRejectedLimits)
{
  // A step back before the last correctly evaluated time makes the model invalid (L2082).
  Stepper back = limited(-0.1);
  try
  {
    back.step(1.0);
    FAIL();
  }
  catch (const SteppingError& e)
  {
    EXPECT_THAT(e.what(), HasSubstr("L2082"));
  }
  // A reaction that never accepts: bounded by maxHalvings.
  ParameterTable p;
  Stepper never(p);
  Reaction r;
  r.name = "Never";
  r.update = [](StepContext& c)
  {
    c.fireEvent(Event{ events::TimeRejected, {}, {}, 1.0 });
  };
  never.addReaction(r);
  StepperOptions o;
  o.maxHalvings = 5;
  never.setOptions(o);
  EXPECT_THROW(never.step(1.0), StepRejectedError);
  EXPECT_EQ(never.rejections(), 6);
  EXPECT_EQ(never.time(), 0.0); // nothing accepted, state at the last valid time
}

TEST(DynamicsRootFinding, StepperStopsAtTheCrossing)
{
  // The disk of thesis 5.1 moves by a time reaction (L1345): x = -2 + 0.5 t; radius 0.75; the
  // rectangle's left side is x = 0.25. Gap g = 0.25 - (x + 0.75) = 1.5 - 0.5 t: zero at t = 3.
  ParameterTable p;
  p.add("LHKF", "x", Scope::Global, -2.0);
  Stepper s(p, 2.8);
  Reaction r;
  r.name = "LHKF";
  r.update = [](StepContext& c)
  {
    c.set("LHKF.x", -2.0 + 0.5 * c.globalT);
  };
  s.addReaction(r);
  auto gap = [](const ParameterTable& q, double)
  {
    return 0.25 - (q.value("LHKF.x") + 0.75);
  };
  auto c = s.stepUntil(0.4, gap);
  ASSERT_TRUE(c);
  EXPECT_NEAR(c->time, 3.0, 1e-9);
  EXPECT_EQ(s.time(), c->time); // the state is delivered at the transition
  EXPECT_NEAR(s.params().value("LHKF.x"), -0.5, 1e-9);
  // The next step has no crossing and ends at 3.4.
  EXPECT_FALSE(s.stepUntil(0.4 - (c->time - 2.8), gap));
  EXPECT_NEAR(s.time(), 3.2, 1e-12);
}

// Structural state outside the parameter table rides along in snapshots: a frame rejected once
// leaves no trace in it (the external counter sees 4 accepted frames, not 6 attempts).
TEST(DynamicsStepper, ExternalStateIsRestoredWithTheFrame)
{
  ParameterTable p;
  p.add("A", "x", Scope::Global, 0.0);
  Stepper s(p);
  int frames = 0;
  bool rejectOnce = true;
  s.setExternalState(
    [&] { return std::any(frames); }, [&](const std::any& a) { frames = std::any_cast<int>(a); });
  Reaction r;
  r.name = "A";
  r.update = [&](StepContext& c)
  {
    ++frames;
    if (rejectOnce)
    {
      rejectOnce = false; // outside the snapshot on purpose: reject only the first attempt
      c.rejectTime();
    }
  };
  s.addReaction(r);
  // h = 1 rejected, then 0.5 twice... the first attempt at 1 is rolled back, 0.5 + 0.5 accepted.
  EXPECT_EQ(s.step(1.0), 2);
  EXPECT_EQ(frames, 2);
}

// A disabled reaction takes no part: no update, no log entry, no event.
TEST(DynamicsStepper, DisabledReactionsAreSkipped)
{
  ParameterTable p;
  p.add("A", "n", Scope::Global, 0.0);
  Stepper s(p);
  bool on = false;
  Reaction r;
  r.name = "A";
  r.enabled = [&]
  {
    return on;
  };
  r.update = [](StepContext& c)
  {
    c.set("A.n", c.get("A.n") + 1);
  };
  s.addReaction(r);
  s.step(1.0);
  EXPECT_EQ(s.params().value("A.n"), 0.0);
  EXPECT_TRUE(s.log().empty());
  on = true;
  s.step(1.0);
  EXPECT_EQ(s.params().value("A.n"), 1.0);
}

// Thesis footnote 27: with pullChangedOnly a relation copies only when its master changed, so a
// dependent may drive its own value while the master rests; a plain pull copies every frame.
TEST(DynamicsStepper, RelationsCopyOnlyWhenInvalid)
{
  auto run = [](bool changedOnly)
  {
    ParameterTable p;
    p.add("M", "v", Scope::Global, 1.0);
    p.add("D", "v", Scope::Global, 1.0);
    Stepper s(p);
    StepperOptions o;
    o.pullChangedOnly = changedOnly;
    s.setOptions(o);
    Reaction d;
    d.name = "D";
    d.update = [](StepContext& c)
    {
      c.set("D.v", c.get("D.v") + 10);
    };
    s.addReaction(d);
    DependencyGraph g;
    g.addRelation("M.v", "D.v");
    s.setDependencies(g);
    s.step(1.0); // first frame: the new relation is invalid, copies 1, then D adds 10: 11
    s.step(1.0); // M unchanged: the relation stays valid (21) or copies again (11)
    return s.params().value("D.v");
  };
  EXPECT_EQ(run(true), 21.0);
  EXPECT_EQ(run(false), 11.0);
}

// settle() evaluates one frame at the current time: relations and updates with dt = 0.
TEST(DynamicsStepper, SettleEvaluatesAFrameWithoutTime)
{
  ParameterTable p;
  p.add("M", "v", Scope::Global, 3.0);
  p.add("D", "v", Scope::Global, 0.0);
  Stepper s(p, 2.0);
  Reaction d;
  d.name = "D";
  double seenDt = -1.0;
  d.update = [&](StepContext& c)
  {
    seenDt = c.dt;
  };
  s.addReaction(d);
  DependencyGraph g;
  g.addRelation("M.v", "D.v");
  s.setDependencies(g);
  s.settle();
  EXPECT_EQ(s.time(), 2.0);
  EXPECT_EQ(s.params().value("D.v"), 3.0);
  EXPECT_EQ(seenDt, 0.0);
  EXPECT_TRUE(s.acceptedTimes().empty());
}
