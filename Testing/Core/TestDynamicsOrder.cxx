// SPDX-License-Identifier: BSD-3-Clause
// Dependency relations and evaluation order (thesis §3.5 L1177-1225, §4.3.3 L1902-2044,
// footnotes 27/28 L3495-3497, L3697; ch4 features 52-62), run through the Stepper.

#include "Dynamics/Animation.h"
#include "Dynamics/Dependencies.h"
#include "Dynamics/Stepper.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>

using namespace ictk::dyn;
using ::testing::ElementsAre;
using Lists = std::vector<std::vector<std::string>>;

namespace
{

/// Adds cells in definition order, then "Master.param Dependent.param priority" relations.
DependencyGraph graph(const std::vector<std::string>& cells,
  const std::vector<std::tuple<std::string, std::string, double>>& relations)
{
  DependencyGraph g;
  for (const std::string& c : cells)
    g.addEntity(c);
  for (const auto& [m, d, p] : relations)
    g.addRelation(m, d, p);
  return g;
}

/// The entries of the log that are evaluations (update / reevaluate), in order.
std::vector<std::string> evaluations(const std::vector<std::string>& log, std::size_t from = 0)
{
  std::vector<std::string> out;
  for (std::size_t i = from; i < log.size(); ++i)
    if (log[i].find(".update") != std::string::npos && log[i].find("Post") == std::string::npos)
      out.push_back(log[i].substr(0, log[i].find('.')));
    else if (log[i].find(".reevaluate") != std::string::npos)
      out.push_back(log[i].substr(0, log[i].find('.')) + "*");
  return out;
}

} // namespace

TEST(DynamicsOrder, SixCellsConcurrencyLists)
{
  // ch4_13 fixture (L1944-1951): 1->2, 3->2, 4->1, 4->2, 4->3, 5->6. No cycle, nothing cut.
  // Depth (longest kept path from a root): cell_4 = cell_5 = 0; cell_1 = cell_3 = 1 (after 4),
  // cell_6 = 1 (after 5); cell_2 = 2 (after 1 and 3). Inside a list: definition order.
  DependencyGraph g = graph({ "cell_1", "cell_2", "cell_3", "cell_4", "cell_5", "cell_6" },
    { { "cell_1.param", "cell_2.param", 1.0 }, { "cell_3.param", "cell_2.param", 1.0 },
      { "cell_4.param", "cell_1.param", 1.0 }, { "cell_4.param", "cell_2.param", 1.0 },
      { "cell_4.param", "cell_3.param", 1.0 }, { "cell_5.param", "cell_6.param", 1.0 } });
  EvaluationPlan p = g.plan();
  EXPECT_EQ(p.listNames(),
    (Lists{ { "cell_4", "cell_5" }, { "cell_1", "cell_3", "cell_6" }, { "cell_2" } }));
  EXPECT_TRUE(p.cut.empty());
  EXPECT_EQ(p.kept.size(), 6u);
  // ch4 feature 53: entity priority 2 puts cell_3 before cell_1 inside its list (Table 2 L4097).
  g.addEntity("cell_3", 2.0);
  EXPECT_EQ(g.plan().listNames(),
    (Lists{ { "cell_4", "cell_5" }, { "cell_3", "cell_1", "cell_6" }, { "cell_2" } }));
}

TEST(DynamicsOrder, KeptRelationsGoForwardOnRandomGraphs)
{
  // ch4 feature 54, a property test over deterministic pseudo-random graphs (with cycles): every
  // kept relation m -> d has m in an earlier list than d, and every relation is kept or cut.
  unsigned s = 12345u;
  auto next = [&]()
  {
    return s = s * 1103515245u + 12345u, (s >> 16) & 0x7fffu;
  };
  for (int round = 0; round < 50; ++round)
  {
    DependencyGraph g;
    const unsigned n = 2 + next() % 8;
    for (unsigned i = 0; i < n; ++i)
      g.addEntity("c" + std::to_string(i), 1.0 + next() % 3);
    const unsigned m = next() % 20;
    for (unsigned r = 0; r < m; ++r)
      g.addRelation("c" + std::to_string(next() % n) + ".p",
        "c" + std::to_string(next() % n) + ".p", 0.25 * (next() % 5));
    const EvaluationPlan p = g.plan();
    std::vector<std::size_t> listOf(n);
    for (std::size_t l = 0; l < p.lists.size(); ++l)
      for (std::size_t e : p.lists[l])
        listOf[e] = l;
    EXPECT_EQ(p.kept.size() + p.cut.size(), m);
    for (std::size_t r : p.kept)
      EXPECT_LT(listOf[g.entityIndex(g.relations()[r].master)],
        listOf[g.entityIndex(g.relations()[r].dependent)]);
  }
}

TEST(DynamicsOrder, TwoBodyCycleIsCutAtTheLowestPriority)
{
  // ch4_14 fixture (L2009-2012): B1.paramX B2.paramY p1; B2.paramV B1.paramW p2.
  auto cradle = [](double p1, double p2)
  {
    return graph(
      { "B1", "B2" }, { { "B1.paramX", "B2.paramY", p1 }, { "B2.paramV", "B1.paramW", p2 } })
      .plan();
  };
  // p1 > p2: relation 1 (B2 -> B1) is cut; order B1, B2.
  EvaluationPlan a = cradle(1.0, 0.5);
  EXPECT_EQ(a.listNames(), (Lists{ { "B1" }, { "B2" } }));
  EXPECT_THAT(a.cut, ElementsAre(1u));
  // p1 < p2: relation 0 (B1 -> B2) is cut; order B2, B1.
  EvaluationPlan b = cradle(0.5, 1.0);
  EXPECT_EQ(b.listNames(), (Lists{ { "B2" }, { "B1" } }));
  EXPECT_THAT(b.cut, ElementsAre(0u));
  // Equal priorities: the relation defined first wins (L2016), so the second one is cut.
  EvaluationPlan c = cradle(1.0, 1.0);
  EXPECT_EQ(c.listNames(), (Lists{ { "B1" }, { "B2" } }));
  EXPECT_THAT(c.cut, ElementsAre(1u));
  EXPECT_THAT(c.inCycle, ElementsAre(true, true));
}

TEST(DynamicsOrder, UserOrderOverrides)
{
  DependencyGraph g =
    graph({ "B1", "B2" }, { { "B1.paramX", "B2.paramY", 1.0 }, { "B2.paramV", "B1.paramW", 0.5 } });
  g.setUserOrder({ "B2", "B1" });
  const EvaluationPlan p = g.plan();
  EXPECT_TRUE(p.userOrder);
  EXPECT_EQ(p.listNames(), (Lists{ { "B2" }, { "B1" } }));
  // Now B1 -> B2 runs backwards against the order: it is the one treated as cut.
  EXPECT_THAT(p.cut, ElementsAre(0u));
  EXPECT_THROW(g.setUserOrder({ "B1" }), std::invalid_argument);       // omits B2
  EXPECT_THROW(g.setUserOrder({ "B1", "B1" }), std::invalid_argument); // twice
  EXPECT_THROW(g.setUserOrder({ "B1", "X" }), std::invalid_argument);  // unknown
}

TEST(DynamicsOrder, NewtonsCradleSwapsVelocities)
{
  // Two equal balls collide elastically (thesis §4.4.1 L1989-2026, ch4 feature 60). Momentum
  // m v1 + m v2 and energy m v1^2/2 + m v2^2/2 are conserved only by v1' = v2, v2' = v1: with
  // (v1, v2) = (0.8, -0.3) the frame must give (-0.3, 0.8). Each ball's update sets v = vin, and
  // vin is pulled from the other ball: B1.v -> B2.vin, B2.v -> B1.vin (equal priorities, so the
  // second relation is cut and B1 is evaluated first).
  auto run = [](CyclePolicy policy)
  {
    ParameterTable p;
    p.add("B1", "v", Scope::Global, 0.8);
    p.add("B1", "vin", Scope::Global, 0.0);
    p.add("B2", "v", Scope::Global, -0.3);
    p.add("B2", "vin", Scope::Global, 0.0);
    Stepper s(p);
    for (const char* b : { "B1", "B2" })
    {
      Reaction r;
      r.name = b;
      const std::string n = b;
      r.update = [n](StepContext& c)
      {
        c.set(n + ".v", c.get(n + ".vin"));
      };
      s.addReaction(r);
    }
    DependencyGraph g;
    g.addRelation("B1.v", "B2.vin");
    g.addRelation("B2.v", "B1.vin");
    s.setDependencies(g);
    StepperOptions o;
    o.cycles = policy;
    s.setOptions(o);
    s.step(0.01);
    EXPECT_THAT(evaluations(s.log()), ElementsAre("B1", "B2"));
    return std::make_pair(s.params().value("B1.v"), s.params().value("B2.v"));
  };
  // PreviousState: both relations lie on the cycle, both read the previous frame: a swap.
  EXPECT_EQ(run(CyclePolicy::PreviousState), std::make_pair(-0.3, 0.8));
  // Reading only the cut relation from the previous frame is not enough: B1 gets -0.3 (previous
  // B2), then B2 reads B1's new -0.3: (-0.3, -0.3), momentum 0.5 -> -0.6 is not conserved.
  EXPECT_EQ(run(CyclePolicy::CutEdgePrevious), std::make_pair(-0.3, -0.3));
}

namespace
{

// The Andyhausen machine (Appendix C L4521-4525, thesis 5.6): the handle turns the barrel, the
// barrel winds the rope, the hook hangs at the rope's end. Numbers: omega = 0.5 rad/s, barrel
// radius 0.2, rope length 3, rope top at height 5.
//   Handle1.alpha += omega dt          (its update reaction)
//   Handle1.alpha -> Handle2.alpha     (1.0)
//   Handle2.alpha -> Handle1.alpha     (0.5, the cut one)
//   Handle1.alpha -> Barrel.alpha; Barrel.distTravelled = alpha * radius
//   Barrel.distTravelled -> Rope.inactiveLength; Rope.curLength = length - inactiveLength;
//   Rope.endPoint = 5 - curLength
//   Rope.endPoint -> Hook.y
const std::vector<std::string> kTemplateCells = { "Handle1", "Handle2", "Barrel", "Rope", "Hook",
  "Egg_contents", "Liquid", "Melting_egg" };

void addTemplateRelations(DependencyGraph& g)
{
  g.addRelation("Handle1.alpha", "Handle2.alpha");
  g.addRelation("Handle2.alpha", "Handle1.alpha", 0.5);
  g.addRelation("Handle1.alpha", "Barrel.alpha");
  g.addRelation("Barrel.distTravelled", "Rope.inactiveLength");
  g.addRelation("Rope.endPoint", "Hook.y");
}

Stepper machine(const std::vector<std::string>& cells, DependencyGraph g)
{
  ParameterTable p;
  p.add("", "omega", Scope::Global, 0.5);
  p.add("Handle1", "alpha", Scope::Global, 0.0);
  p.add("Handle2", "alpha", Scope::Global, 0.0);
  p.add("Barrel", "alpha", Scope::Global, 0.0);
  p.add("Barrel", "radius", Scope::Global, 0.2);
  p.add("Barrel", "distTravelled", Scope::Global, 0.0);
  p.add("Rope", "inactiveLength", Scope::Global, 0.0);
  p.add("Rope", "length", Scope::Global, 3.0);
  p.add("Rope", "curLength", Scope::Global, 3.0);
  p.add("Rope", "endPoint", Scope::Global, 2.0);
  p.add("Hook", "y", Scope::Global, 2.0);
  p.add("Skeleton", "y", Scope::Global, 2.0);
  p.add("Andy", "rotationZ", Scope::Global, 0.0);
  Stepper s(p);
  for (const std::string& c : cells)
  {
    Reaction r;
    r.name = c;
    if (c == "Handle1")
      r.update = [](StepContext& x)
      {
        x.set("Handle1.alpha", x.get("Handle1.alpha") + x.get("omega") * x.dt);
      };
    else if (c == "Barrel")
      r.update = [](StepContext& x)
      {
        x.set("Barrel.distTravelled", x.get("Barrel.alpha") * x.get("Barrel.radius"));
      };
    else if (c == "Rope")
      r.update = [](StepContext& x)
      {
        x.set("Rope.curLength", x.get("Rope.length") - x.get("Rope.inactiveLength"));
        x.set("Rope.endPoint", 5.0 - x.get("Rope.curLength"));
      };
    else if (c == "Andy")
      // The hand's rotation follows an animation: keys (0, 0), (2, 1), linear.
      r.update = [](StepContext& x)
      {
        x.set("Andy.rotationZ", AnimationCurve({ { 0, 0 }, { 2, 1 } }).evaluate(x.globalT));
      };
    s.addReaction(r);
  }
  s.setDependencies(std::move(g));
  StepperOptions o;
  o.cycles = CyclePolicy::Reevaluate; // footnote 27
  s.setOptions(o);
  return s;
}

} // namespace

TEST(DynamicsOrder, AndyhausenTemplateChain)
{
  DependencyGraph g;
  for (const std::string& c : kTemplateCells)
    g.addEntity(c);
  addTemplateRelations(g);
  const EvaluationPlan p = g.plan();
  // The priority-0.5 relation Handle2 -> Handle1 closes the only cycle: it is cut (L4521-4522,
  // ch4 feature 58). Depths: Handle1 and the unrelated cells 0; Handle2, Barrel 1; Rope 2; Hook 3.
  EXPECT_THAT(p.cut, ElementsAre(1u));
  EXPECT_EQ(p.listNames(),
    (Lists{ { "Handle1", "Egg_contents", "Liquid", "Melting_egg" }, { "Handle2", "Barrel" },
      { "Rope" }, { "Hook" } }));

  // Ten frames of dt = 0.1 (footnote 27's re-evaluation): Handle1.alpha = 10 * 0.5 * 0.1 = 0.5;
  // Handle2.alpha = Barrel.alpha = 0.5; distTravelled = 0.5 * 0.2 = 0.1 = inactiveLength;
  // curLength = 3 - 0.1 = 2.9; endPoint = 5 - 2.9 = 2.1 = Hook.y.
  Stepper s = machine(kTemplateCells, g);
  std::size_t frameStart = 0;
  for (int i = 0; i < 10; ++i)
  {
    frameStart = s.log().size();
    s.step(0.1);
  }
  EXPECT_NEAR(s.time(), 1.0, 1e-15);
  EXPECT_NEAR(s.params().value("Handle1.alpha"), 0.5, 1e-12);
  EXPECT_NEAR(s.params().value("Handle2.alpha"), 0.5, 1e-12);
  EXPECT_NEAR(s.params().value("Barrel.distTravelled"), 0.1, 1e-12);
  EXPECT_NEAR(s.params().value("Rope.curLength"), 2.9, 1e-12);
  EXPECT_NEAR(s.params().value("Hook.y"), 2.1, 1e-12);
  // The last frame (ch4 feature 61): Handle1, then its list, then {Handle2, Barrel}, Rope, Hook,
  // then Handle1 again through the cut relation; Barrel is evaluated exactly once.
  EXPECT_THAT(evaluations(s.log(), frameStart),
    ElementsAre("Handle1", "Egg_contents", "Liquid", "Melting_egg", "Handle2", "Barrel", "Rope",
      "Hook", "Handle1*"));
}

TEST(DynamicsOrder, AndyhausenEggGoingDownInstance)
{
  // EGG_GOING_DOWN = TEMPLATE_IC1.CELLS \ { Melting_egg } + Eggshell, with the template relations
  // plus Hook -> Eggshell and Eggshell -> Egg_contents (both HIERARCHICAL, App. C).
  // The instance's cells (their derivation from the template is tested on andyhausen.icm in
  // TestEngine, EngineInstances.CellsDeriveFromTheTemplate).
  const std::vector<std::string> cells = { "Handle1", "Handle2", "Barrel", "Rope", "Hook",
    "Egg_contents", "Liquid", "Eggshell" };
  DependencyGraph g;
  for (const std::string& c : cells)
    g.addEntity(c);
  addTemplateRelations(g);
  g.addRelation("Hook.transform", "Eggshell.transform", 1.0, DependencyKind::Hierarchical);
  g.addRelation("Eggshell.transform", "Egg_contents.transform", 1.0, DependencyKind::Hierarchical);
  // Egg_contents now hangs below Eggshell (depth 5), so it leaves the first list.
  EXPECT_EQ(g.plan().listNames(),
    (Lists{ { "Handle1", "Liquid" }, { "Handle2", "Barrel" }, { "Rope" }, { "Hook" },
      { "Eggshell" }, { "Egg_contents" } }));
  EXPECT_EQ(g.relations()[5].kind, DependencyKind::Hierarchical);
}

TEST(DynamicsOrder, AndyhausenAndyOutLastEvaluationIsHandle1)
{
  // ANDY_OUT (App. C, L3682-3705): the template cells plus Skeleton, Andy, Liquid_Andy,
  // Liquid_on_Andy. Relations: the template's; Hook -> Skeleton (HIERARCHICAL); Skeleton -> Andy;
  // Skeleton -> Liquid_Andy; Andy.rotationZ -> Handle2.alpha; and the implicit operand relations
  // of the blends (L1249): Liquid, Egg_contents -> Melting_egg; Melting_egg, Liquid_Andy ->
  // Liquid_on_Andy. The composite cycle Handle1 -> Barrel -> Rope -> Hook -> Skeleton -> Andy ->
  // Handle2 -> Handle1 is cut at its priority-0.5 relation.
  std::vector<std::string> cells = kTemplateCells;
  for (const char* c : { "Skeleton", "Andy", "Liquid_Andy", "Liquid_on_Andy" })
    cells.push_back(c);
  DependencyGraph g;
  for (const std::string& c : cells)
    g.addEntity(c);
  addTemplateRelations(g);
  g.addRelation("Hook.y", "Skeleton.y", 1.0, DependencyKind::Hierarchical);
  g.addRelation("Skeleton.shape", "Andy.skeleton", 1.0, DependencyKind::Geometric);
  g.addRelation("Skeleton.shape", "Liquid_Andy.skeleton", 1.0, DependencyKind::Geometric);
  g.addRelation("Andy.rotationZ", "Handle2.alpha");
  g.addRelation("Liquid", "Melting_egg");
  g.addRelation("Egg_contents", "Melting_egg");
  g.addRelation("Melting_egg", "Liquid_on_Andy");
  g.addRelation("Liquid_Andy", "Liquid_on_Andy");
  const EvaluationPlan p = g.plan();
  EXPECT_THAT(p.cut, ElementsAre(1u));
  // Depths: Barrel 1, Rope 2, Hook 3, Skeleton 4, Andy = Liquid_Andy 5, Handle2 6 (after Andy),
  // Melting_egg 1, Liquid_on_Andy 6 (after Liquid_Andy).
  EXPECT_EQ(p.listNames(),
    (Lists{ { "Handle1", "Egg_contents", "Liquid" }, { "Barrel", "Melting_egg" }, { "Rope" },
      { "Hook" }, { "Skeleton" }, { "Andy", "Liquid_Andy" }, { "Handle2", "Liquid_on_Andy" } }));
  // Footnote 28 / ch4 feature 62: in every frame the last evaluation is Handle1 <- Handle2, so at
  // the end of the frame Handle1.alpha = Handle2.alpha = Andy's hand rotation. Four frames of 0.25:
  // at t = 1 the animation (0,0)-(2,1) gives 0.5.
  Stepper s = machine(cells, g);
  std::size_t frameStart = 0;
  for (int i = 0; i < 4; ++i)
  {
    frameStart = s.log().size();
    s.step(0.25);
  }
  EXPECT_DOUBLE_EQ(s.params().value("Andy.rotationZ"), 0.5);
  EXPECT_DOUBLE_EQ(s.params().value("Handle2.alpha"), 0.5);
  EXPECT_DOUBLE_EQ(s.params().value("Handle1.alpha"), 0.5);
  EXPECT_EQ(evaluations(s.log(), frameStart).back(), "Handle1*");
}

TEST(DynamicsOrder, RunsAreBitIdentical)
{
  // Determinism (issue 5): the same model and steps give identical logs and values; nothing
  // depends on addresses, hashing or threads.
  auto run = []()
  {
    DependencyGraph g;
    for (const std::string& c : kTemplateCells)
      g.addEntity(c);
    addTemplateRelations(g);
    Stepper s = machine(kTemplateCells, g);
    for (int i = 0; i < 7; ++i)
      s.step(0.13);
    return std::make_pair(s.log(), s.params().values());
  };
  const auto a = run();
  const auto b = run();
  EXPECT_EQ(a.first, b.first);
  EXPECT_EQ(a.second, b.second);
}
