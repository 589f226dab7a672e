// SPDX-License-Identifier: BSD-3-Clause
// Tests of metamorphosis between animated BlobTrees (FRep/BlobMorph.h; papers.md 3.7, items
// 60-65): the spec's numbers for key-frame merging and the interpolation graph, correspondence
// splitting that keeps both fields, the morph's end points and mean, texture morphing of one type
// and across types, and the bundled morph model.
#include "FRep/BlobMorph.h"
#include "FRep/BlobTree.h"
#include "Lang/BlobReader.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>
#include <string>

using namespace ictk;
using namespace ictk::frep::blob;
namespace morph = ictk::frep::blob::morph;

namespace
{
const std::string Models = std::string(ICTK_DATA_DIR) + "/Models/blob/";

Animation keys(int order, std::vector<std::vector<double>> k)
{
  Animation a;
  a.type = Animation::Type::Keys;
  a.order = order;
  a.keys = std::move(k);
  return a;
}

// s(t): 0 at 0, 0.5 at 0.5, 1 at 1, flat at both ends. Merged key-frames are exact at the
// knots, and every merged parameter of the morph has one at 0.5, where the tests look.
const Animation S = keys(2, { { 0, 0, 0 }, { 0.5, 0.5, 1.5 }, { 1, 1, 0 } });
// The spec's s of item 61: knots {0, 1}.
const Animation S2 = keys(2, { { 0, 0, 0 }, { 1, 1, 0 } });

// The links of the bundled morph, by the reader's node numbers (children first):
// A: 0 point left, 1 point right, 2 translate, 3 blend, 4 marble;
// B: 0 cylinder, 1 segment, 2 translate, 3 point knob, 4 blend, 5 wood.
// The left ball becomes the breathing cylinder and the knob (split in two), the bobbing ball
// the segment.
const std::vector<morph::Link> Links = { { 0, 0 }, { 0, 3 }, { 2, 2 } };

double field(const BlobTree& generic, double t, const Vec3& p)
{
  return evaluate(generic.instantiate(t), p);
}
} // namespace

// Item 60 (line 284): p_C = (1 - s) p_A + s p_B: p_A where s = 0, p_B where s = 1, the mean at
// s = 0.5.
TEST(BlobMorph, ParameterInterpolation)
{
  const Animation pA = keys(2, { { 0, 1, 0 }, { 1, 3, 2 } });
  Animation pB;
  pB.base = 5;
  pB.amplitude = 1;
  pB.period = 4;
  EXPECT_DOUBLE_EQ(morph::interpolate(pA, pB, S, 0), pA.eval(0));
  EXPECT_DOUBLE_EQ(morph::interpolate(pA, pB, S, 1), pB.eval(1));
  EXPECT_DOUBLE_EQ(morph::interpolate(pA, pB, S, 0.5), 0.5 * (pA.eval(0.5) + pB.eval(0.5)));
}

// Item 61 (lines 304-317) with the spec's knots: {0, 0.5, 1}, {0, 0.25, 0.75, 1} and {0, 1}
// merge into {0, 0.25, 0.5, 0.75, 1}, 5 <= 3 + 4 + 2 keys, exact at every knot.
TEST(BlobMorph, MergeKeyframes)
{
  const Animation pA = keys(2, { { 0, 1, 0 }, { 0.5, 2, 1 }, { 1, 0, -1 } });
  const Animation pB =
    keys(3, { { 0, 4, 0, 0 }, { 0.25, 3, 1, 0 }, { 0.75, 5, 0, 2 }, { 1, 6, 1, 0 } });
  const Animation c = morph::mergeKeyframes(pA, pB, S2);
  EXPECT_EQ(morph::knots(c), (std::vector<double>{ 0, 0.25, 0.5, 0.75, 1 }));
  EXPECT_LE(c.keys.size(), 3u + 4u + 2u);
  EXPECT_EQ(c.order, 3);
  for (const double t : morph::knots(c))
  {
    const double s = S2.eval(t);
    EXPECT_NEAR(c.eval(t), (1 - s) * pA.eval(t) + s * pB.eval(t), 1e-14) << t;
    // The slope by the product rule: p_C' = (1 - s) p_A' + s p_B' + s' (p_B - p_A).
    const double slope = (1 - s) * pA.derivative(t, 1) + s * pB.derivative(t, 1) +
      S2.derivative(t, 1) * (pB.eval(t) - pA.eval(t));
    EXPECT_NEAR(c.derivative(t, 1), slope, 1e-12) << t;
  }
  // Between knots the merged curve is Hermite's, near the product but not equal to it.
  const double s = S2.eval(0.4);
  EXPECT_NEAR(c.eval(0.4), (1 - s) * pA.eval(0.4) + s * pB.eval(0.4), 0.05);
  // Derivatives of key-frames by hand: on [0, 0.5] pA is cubic Hermite from (1, 0) to (2, 1).
  // With u = t / 0.5: P = 1 + (3u^2 - 2u^3) + 0.5 (u^3 - u^2), so P'(t) at u = 0.5 is
  // (6u - 6u^2 + 0.5 (3u^2 - 2u)) / 0.5 = (1.5 - 0.125) / 0.5 = 2.75.
  EXPECT_NEAR(pA.derivative(0.25, 1), 2.75, 1e-12);
  // A wave's derivatives: A w cos(w t + phase).
  Animation w;
  w.amplitude = 2;
  w.period = 3;
  EXPECT_NEAR(w.derivative(0.7, 1), 2 * (2 * M_PI / 3) * std::cos(2 * M_PI * 0.7 / 3), 1e-12);
  EXPECT_THROW(morph::mergeKeyframes(pA, pB, w), std::invalid_argument);
}

// Item 63 (lines 272-278): Dijkstra over the degeneration arcs.
TEST(BlobMorph, InterpolationGraph)
{
  const morph::InterpolationGraph g = morph::InterpolationGraph::standard();
  double cost = 0;
  // The deforming cylinder-box primitive (8) weighs more than cylinder -> segment (3) plus
  // segment -> box (4): the path goes through the simpler segment (line 274).
  EXPECT_EQ(g.shortestPath("cylinder", "box", &cost),
    (std::vector<std::string>{ "cylinder", "segment", "box" }));
  EXPECT_EQ(cost, 7);
  bool radius = false;
  for (const auto& arc : g.arcs())
  {
    radius = radius || (arc.from == "cylinder" && arc.to == "segment" && arc.how == "radius -> 0");
  }
  EXPECT_TRUE(radius);
  // Made cheaper than the detour, the direct arc wins.
  morph::InterpolationGraph h;
  h.addArc("cylinder", "segment", 3, "radius -> 0");
  h.addArc("segment", "box", 4, "two sides grow");
  h.addArc("cylinder", "box", 6, "cylinder-box");
  EXPECT_EQ(
    h.shortestPath("box", "cylinder", &cost), (std::vector<std::string>{ "box", "cylinder" }));
  EXPECT_EQ(cost, 6);
  // Longer chains, both ways; no path between unconnected types.
  EXPECT_EQ(g.shortestPath("conesphere", "point"),
    (std::vector<std::string>{ "conesphere", "cylinder", "segment", "point" }));
  EXPECT_EQ(g.shortestPath("torus", "disc"),
    (std::vector<std::string>{ "torus", "circle", "point", "disc" }));
  EXPECT_TRUE(g.shortestPath("torus", "nothing").empty());
  EXPECT_THROW(h.addArc("a", "b", 0, ""), std::invalid_argument);
}

// Item 62 (lines 258-268): the split trees pair bijectively, keep their fields, and copy the
// operators' parameters.
TEST(BlobMorph, CorrespondenceSplitting)
{
  const BlobTree A = lang::readBlobFile(Models + "morph_a.blob");
  const BlobTree B = lang::readBlobFile(Models + "morph_b.blob");
  const morph::SplitTrees split = morph::splitCorrespondences(A, B, Links);
  EXPECT_EQ(split.a.nodes().size(), split.b.nodes().size());
  EXPECT_EQ(split.pairs.size(), split.a.nodes().size());
  std::set<std::uint32_t> seenA, seenB;
  for (const auto& [a, b] : split.pairs)
  {
    EXPECT_TRUE(seenA.insert(a).second);
    EXPECT_TRUE(seenB.insert(b).second);
  }
  EXPECT_EQ(seenA.size(), split.a.nodes().size());
  EXPECT_EQ(seenB.size(), split.b.nodes().size());
  // A's left ball holds two links: two copies of intensity 1/2; B gains nothing but its own.
  EXPECT_EQ(split.a.count(Kind::Point), 3u);
  EXPECT_EQ(split.b.count(Kind::Point), 1u);
  // The split trees are equivalent to A and B: the same field at every time.
  std::mt19937 rng(62);
  std::uniform_real_distribution<double> x(-3, 3);
  for (const double t : { 0.0, 0.3, 0.75 })
  {
    for (int k = 0; k < 200; ++k)
    {
      const Vec3 p{ x(rng), x(rng), x(rng) };
      ASSERT_NEAR(field(split.a, t, p), field(A, t, p), 1e-12);
      ASSERT_NEAR(field(split.b, t, p), field(B, t, p), 1e-12);
    }
  }
  // The translate of A' carries A's animated parameter.
  for (std::uint32_t i = 0; i < split.a.nodes().size(); ++i)
  {
    if (split.a.node(i).kind == Kind::Translate)
    {
      ASSERT_NE(split.a.animation(i, 2), nullptr);
      EXPECT_EQ(split.a.animation(i, 2)->amplitude, 0.3);
    }
  }
  // Linked operators must be of one kind; ordered children must correspond in place.
  BlobTree u, v;
  u.add(Kind::Union, {}, { u.add(Kind::Point, { 1, 1, 0, 0, 0 }) });
  v.add(Kind::Blend, {}, { v.add(Kind::Point, { 1, 1, 0, 0, 0 }) });
  EXPECT_THROW(morph::splitCorrespondences(u, v, {}), std::invalid_argument);
}

// Items 60, 64 and 65 on the bundled morph: C(0) is A(0), C(1) is B(1), its parameters are the
// mean at s = 0.5, and the marble cross-dissolves into the wood.
TEST(BlobMorph, MorphModel)
{
  const BlobTree A = lang::readBlobFile(Models + "morph_a.blob");
  const BlobTree B = lang::readBlobFile(Models + "morph_b.blob");
  const BlobTree C = morph::morph(A, B, Links, S);
  EXPECT_TRUE(C.animated());
  std::mt19937 rng(60);
  std::uniform_real_distribution<double> x(-3, 3);
  for (int k = 0; k < 300; ++k)
  {
    const Vec3 p{ x(rng), x(rng), x(rng) };
    ASSERT_NEAR(field(C, 0, p), field(A, 0, p), 1e-12);
    ASSERT_NEAR(field(C, 1, p), field(B, 1, p), 1e-12);
  }
  // At t = 0.5 (s = 0.5) the left ball (a point, promoted to a cylinder of radius 0 from -1 to
  // -1) meets the cylinder from -1.5 to 0 of radius 0.4 (B's key at 0.5): the mean, a cylinder
  // from -1.25 to -0.5 of radius 0.2, of intensity the mean of A's half share and B's 1, 0.75.
  // The cross-dissolve holds it twice, under each texture, at (1 - s) and s of that.
  const BlobTree half = C.instantiate(0.5);
  int found = 0;
  for (std::uint32_t i = 0; i < half.nodes().size(); ++i)
  {
    const double* v = half.values(i);
    if (half.node(i).kind == Kind::Cylinder && std::fabs(v[2] + 1.25) < 1e-12)
    {
      ++found;
      EXPECT_NEAR(v[5], -0.5, 1e-12);
      EXPECT_NEAR(v[8], 0.2, 1e-12);
      EXPECT_NEAR(v[1], 0.5 * 0.75, 1e-12);
    }
  }
  EXPECT_EQ(found, 2);
  // Item 65 (line 352): marble -> wood, Phi_C = (1 - s) Phi_A + s Phi_B inside, at 100 points.
  auto textureOf = [](Kind kind, const BlobTree& from, std::uint32_t node, const Vec3& p)
  {
    BlobTree probe;
    const double* v = from.values(node);
    probe.add(
      kind, std::vector<double>(v, v + 12), { probe.add(Kind::Point, { 100, 1, 0, 0, 0 }) });
    std::array<double, MaterialSize> phi{};
    evaluateTextured(probe, p, phi);
    return phi;
  };
  int inside = 0;
  for (int k = 0; inside < 100 && k < 100000; ++k)
  {
    const Vec3 p{ x(rng), x(rng), x(rng) };
    std::array<double, MaterialSize> phi{};
    if (evaluateTextured(half, p, phi) <= 0.01)
    {
      continue;
    }
    ++inside;
    const auto a = textureOf(Kind::Marble, A, A.root(), p);
    const auto b = textureOf(Kind::Wood, B, B.root(), p);
    for (int m = 0; m < MaterialSize; ++m)
    {
      ASSERT_NEAR(phi[m], 0.5 * a[m] + 0.5 * b[m], 1e-9);
    }
  }
  EXPECT_EQ(inside, 100);
  // Item 64 (line 341): marble -> marble interpolates the parameters: the mean at s = 0.5.
  BlobTree ma, mb;
  ma.add(Kind::Marble, { 1, 1, 1, 0, 0, 0, 0.1, 0, 1, 1, 0.5, 2 },
    { ma.add(Kind::Point, { 1, 1, 0, 0, 0 }) });
  mb.add(Kind::Marble, { 0, 0.5, 1, 1, 0, 0, 0.3, 0.2, 1.4, 2, 0.1, 2 },
    { mb.add(Kind::Point, { 1, 1, 0, 0, 0 }) });
  const BlobTree mc = morph::morph(ma, mb, {}, S).instantiate(0.5);
  const double* va = ma.values(1);
  const double* vb = mb.values(1);
  const double* vc = mc.values(mc.root());
  ASSERT_EQ(mc.node(mc.root()).kind, Kind::Marble);
  for (int k = 0; k < 12; ++k)
  {
    EXPECT_NEAR(vc[k], 0.5 * (va[k] + vb[k]), 1e-15) << k;
  }
}

// The bundled morph model is the morph of morph_a.blob into morph_b.blob, written by the writer.
TEST(BlobMorph, BundledModelIsTheMorph)
{
  const BlobTree C = morph::morph(lang::readBlobFile(Models + "morph_a.blob"),
    lang::readBlobFile(Models + "morph_b.blob"), Links, S);
  const BlobTree file = lang::readBlobFile(Models + "morph.blob");
  std::mt19937 rng(65);
  std::uniform_real_distribution<double> x(-3, 3);
  for (const double t : { 0.0, 0.2, 0.5, 0.9, 1.0 })
  {
    for (int k = 0; k < 100; ++k)
    {
      const Vec3 p{ x(rng), x(rng), x(rng) };
      ASSERT_NEAR(field(file, t, p), field(C, t, p), 1e-12);
    }
  }
}

// Item 63's path realised: a cylinder morphs into a box through the segment, the degenerate
// intermediate at s = 1/2 (the radius shrinks to 0 in the first half, the box's two other sides
// grow from 0 in the second); both ways.
TEST(BlobMorph, CylinderToBoxThroughSegment)
{
  BlobTree A, B;
  A.add(Kind::Cylinder, { 1.5, 1, 0, 0, 0, 2, 0, 0, 0.3 });
  B.add(Kind::Box, { 1.5, 1, 1, 0, 0, 1, 0, 0, 0, 1, 0, 1, 0.5, 0.25, 0 });
  BlobTree segment;
  segment.add(Kind::Segment, { 1.5, 1, 0, 0, 0, 2, 0, 0 });
  for (const bool forward : { true, false })
  {
    SCOPED_TRACE(forward ? "cylinder -> box" : "box -> cylinder");
    const BlobTree C =
      forward ? morph::morph(A, B, { { 0, 0 } }, S) : morph::morph(B, A, { { 0, 0 } }, S);
    ASSERT_EQ(C.count(Kind::Box), 1u);
    const BlobTree start = C.instantiate(0), middle = C.instantiate(0.5), end = C.instantiate(1);
    // At s = 1/2 the half-sides are (1, 0, 0) and the rounding 0: the segment, exactly.
    const double* m = middle.values(middle.root());
    EXPECT_EQ(m[11], 1.0);
    EXPECT_EQ(m[12], 0.0);
    EXPECT_EQ(m[13], 0.0);
    EXPECT_EQ(m[14], 0.0);
    // One stage at a time: before s = 1/2 only the cylinder's side has moved, after it only the
    // box's (this S is 0.15625 at t = 0.25 and 0.84375 at t = 0.75).
    const BlobTree quarter = C.instantiate(forward ? 0.25 : 0.75);
    const BlobTree threeQuarters = C.instantiate(forward ? 0.75 : 0.25);
    EXPECT_EQ(quarter.values(0)[12], 0.0);
    EXPECT_GT(quarter.values(0)[14], 0.0);
    EXPECT_LT(quarter.values(0)[14], 0.3);
    EXPECT_EQ(threeQuarters.values(0)[14], 0.0);
    EXPECT_GT(threeQuarters.values(0)[12], 0.0);
    EXPECT_LT(threeQuarters.values(0)[12], 0.5);
    std::mt19937 rng(63);
    std::uniform_real_distribution<double> x(-1.5, 3.5);
    for (int k = 0; k < 500; ++k)
    {
      const Vec3 p{ x(rng), x(rng) - 1, x(rng) - 1 };
      ASSERT_NEAR(evaluate(start, p), evaluate(forward ? A : B, p), 1e-12);
      ASSERT_NEAR(evaluate(middle, p), evaluate(segment, p), 1e-12);
      ASSERT_NEAR(evaluate(end, p), evaluate(forward ? B : A, p), 1e-12);
    }
  }
  // A point enters the path too (a segment from c to c, then a cylinder of radius 0); a disc
  // does not.
  BlobTree point;
  point.add(Kind::Point, { 1.5, 1, 1, 0, 0 });
  EXPECT_EQ(morph::morph(point, B, { { 0, 0 } }, S).count(Kind::Box), 1u);
  BlobTree disc;
  disc.add(Kind::Disc, { 1.5, 1, 0, 0, 0, 0, 0, 1, 1 });
  EXPECT_THROW(morph::morph(disc, B, { { 0, 0 } }, S), std::invalid_argument);
}
