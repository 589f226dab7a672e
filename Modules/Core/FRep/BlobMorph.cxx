// SPDX-License-Identifier: BSD-3-Clause
// Metamorphosis between animated BlobTrees (papers.md 3.7): see BlobMorph.h.
#include "FRep/BlobMorph.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <queue>
#include <stdexcept>

namespace ictk::frep::blob::morph
{

double interpolate(const Animation& pA, const Animation& pB, const Animation& s, double t)
{
  const double w = s.eval(t);
  return (1 - w) * pA.eval(t) + w * pB.eval(t);
}

std::vector<double> knots(const Animation& a)
{
  std::vector<double> out;
  if (a.type == Animation::Type::Keys)
  {
    for (const auto& key : a.keys)
    {
      out.push_back(key[0]);
    }
  }
  return out;
}

Animation constant(double v)
{
  Animation a;
  a.type = Animation::Type::Keys;
  a.order = 1;
  a.keys = { { 0.0, v } };
  return a;
}

namespace
{
bool isConstant(const Animation& a)
{
  return a.type == Animation::Type::Keys && a.keys.size() == 1;
}

double binomial(int n, int k)
{
  double b = 1;
  for (int i = 1; i <= k; ++i)
  {
    b = b * (n - k + i) / i;
  }
  return b;
}
} // namespace

Animation mergeKeyframes(const Animation& pA, const Animation& pB, const Animation& s)
{
  if (s.type != Animation::Type::Keys || s.keys.empty())
  {
    throw std::invalid_argument("morph: the evolution function s(t) must be key-frames");
  }
  const double t0 = s.keys.front()[0], t1 = s.keys.back()[0];
  std::vector<double> ts;
  for (const Animation* a : { &s, &pA, &pB })
  {
    for (double t : knots(*a))
    {
      if (t >= t0 && t <= t1)
      {
        ts.push_back(t);
      }
    }
  }
  std::sort(ts.begin(), ts.end());
  ts.erase(std::unique(ts.begin(), ts.end()), ts.end());
  int order = 2;
  for (const Animation* a : { &s, &pA, &pB })
  {
    if (a->type == Animation::Type::Keys && !isConstant(*a))
    {
      order = std::max(order, a->order);
    }
  }
  // p_C = p_A + s (p_B - p_A): p_C^(j) = p_A^(j) + sum_i C(j, i) s^(i) (p_B - p_A)^(j - i).
  Animation c;
  c.type = Animation::Type::Keys;
  c.order = order;
  for (double t : ts)
  {
    std::vector<double> key{ t };
    for (int j = 0; j < order; ++j)
    {
      double v = pA.derivative(t, j);
      for (int i = 0; i <= j; ++i)
      {
        v +=
          binomial(j, i) * s.derivative(t, i) * (pB.derivative(t, j - i) - pA.derivative(t, j - i));
      }
      key.push_back(v);
    }
    c.keys.push_back(std::move(key));
  }
  return c;
}

// --- the skeleton interpolation graph (item 63) --------------------------------------------------

void InterpolationGraph::addArc(
  const std::string& from, const std::string& to, double weight, std::string how)
{
  if (!(weight > 0) || !std::isfinite(weight))
  {
    throw std::invalid_argument("morph: an arc's weight must be positive and finite");
  }
  arcs_.push_back({ from, to, weight, std::move(how) });
}

std::vector<std::string> InterpolationGraph::shortestPath(
  const std::string& from, const std::string& to, double* cost) const
{
  std::map<std::string, double> distance;
  std::map<std::string, std::string> previous;
  using Entry = std::pair<double, std::string>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> queue;
  distance[from] = 0;
  queue.push({ 0.0, from });
  while (!queue.empty())
  {
    const auto [d, node] = queue.top();
    queue.pop();
    if (d > distance[node])
    {
      continue; // a stale entry
    }
    if (node == to)
    {
      break;
    }
    for (const Arc& arc : arcs_)
    {
      // Both ways: a morph may run from either end of an arc.
      const std::string* next = arc.from == node ? &arc.to : (arc.to == node ? &arc.from : nullptr);
      if (!next)
      {
        continue;
      }
      const double nd = d + arc.weight;
      const auto known = distance.find(*next);
      if (known == distance.end() || nd < known->second)
      {
        distance[*next] = nd;
        previous[*next] = node;
        queue.push({ nd, *next });
      }
    }
  }
  if (distance.find(to) == distance.end())
  {
    return {};
  }
  std::vector<std::string> path{ to };
  while (path.back() != from)
  {
    path.push_back(previous.at(path.back()));
  }
  std::reverse(path.begin(), path.end());
  if (cost)
  {
    *cost = distance.at(to);
  }
  return path;
}

InterpolationGraph InterpolationGraph::standard()
{
  const std::map<std::string, double> complexity = { { "point", 1 }, { "segment", 2 },
    { "circle", 2 }, { "cylinder", 3 }, { "disc", 3 }, { "rectangle", 3 }, { "torus", 3 },
    { "triangle", 3 }, { "conesphere", 4 }, { "box", 4 }, { "prism", 5 }, { "cylinder-box", 8 } };
  InterpolationGraph g;
  auto arc = [&](const std::string& a, const std::string& b, const std::string& how,
               const std::string& through = {})
  {
    const double w =
      through.empty() ? std::max(complexity.at(a), complexity.at(b)) : complexity.at(through);
    g.addArc(a, b, w, how);
  };
  arc("cylinder", "segment", "radius -> 0");
  arc("conesphere", "cylinder", "r0 -> r1");
  arc("segment", "point", "length -> 0");
  arc("circle", "point", "radius -> 0");
  arc("disc", "point", "radius -> 0");
  arc("torus", "circle", "minor radius -> 0");
  arc("box", "rectangle", "thickness -> 0");
  arc("prism", "triangle", "thickness -> 0");
  arc("box", "segment", "two sides -> 0");
  arc("cylinder", "box", "the deforming cylinder-box primitive", "cylinder-box");
  return g;
}

// --- correspondence splitting (item 62) ----------------------------------------------------------

namespace
{
// The chain of skeletal kinds each of which degenerates into the one before it.
int generality(Kind kind)
{
  switch (kind)
  {
    case Kind::Point:
      return 0;
    case Kind::Segment:
      return 1;
    case Kind::Cylinder:
      return 2;
    case Kind::ConeSphere:
      return 3;
    default:
      return -1;
  }
}

// An animation times a constant factor.
Animation scaled(Animation a, double f)
{
  if (a.type == Animation::Type::Wave)
  {
    a.base *= f;
    a.amplitude *= f;
    return a;
  }
  for (auto& key : a.keys)
  {
    for (std::size_t k = 1; k < key.size(); ++k)
    {
      key[k] *= f;
    }
  }
  return a;
}

// The values of a node as animations (constants where not animated).
std::vector<Animation> valuesOf(const BlobTree& t, std::uint32_t i)
{
  std::vector<Animation> out;
  for (std::uint32_t k = 0; k < t.node(i).valueCount; ++k)
  {
    const Animation* a = t.animation(i, k);
    out.push_back(a ? *a : constant(t.values(i)[k]));
  }
  return out;
}

// Adds a node with animated values to `t`.
std::uint32_t addAnimated(BlobTree& t, Kind kind, const std::vector<Animation>& values,
  const std::vector<std::uint32_t>& children)
{
  std::vector<double> v;
  for (const Animation& a : values)
  {
    v.push_back(a.eval(0.0));
  }
  const std::uint32_t index = t.add(kind, v, children);
  for (std::uint32_t k = 0; k < values.size(); ++k)
  {
    if (!isConstant(values[k]))
    {
      t.animate(index, k, values[k]);
    }
  }
  return index;
}

bool ordered(Kind kind)
{
  return kind == Kind::LocalBlend || kind == Kind::Difference || isWarp(kind) || isTexture(kind);
}

struct Splitter
{
  const BlobTree& A;
  const BlobTree& B;
  std::map<Link, int> links; // the correspondence graph
  SplitTrees out;

  // Pairs node a of `ta` with node b of `tb`; intensities scaled by wa and wb. Linked children
  // are read from `links` for A and B themselves; a subtree paired with itself (a fading copy)
  // pairs its children with themselves.
  Link pair(
    const BlobTree& ta, std::uint32_t a, const BlobTree& tb, std::uint32_t b, double wa, double wb)
  {
    const Node& na = ta.node(a);
    const Node& nb = tb.node(b);
    const bool leafA = na.childCount == 0, leafB = nb.childCount == 0;
    if (leafA != leafB)
    {
      throw std::invalid_argument(std::string("morph: ") + kindName(na.kind) + " is linked to " +
        kindName(nb.kind) + ": a leaf corresponds to a leaf");
    }
    std::vector<std::uint32_t> childrenA, childrenB;
    if (!leafA)
    {
      if (na.kind != nb.kind && !(isTexture(na.kind) && isTexture(nb.kind)))
      {
        throw std::invalid_argument(std::string("morph: ") + kindName(na.kind) + " is linked to " +
          kindName(nb.kind) + ": linked operators must be of one kind");
      }
      const bool self = &ta == &tb && a == b;
      const bool linked = &ta == &A && &tb == &B;
      const std::uint32_t* ca = ta.children(a);
      const std::uint32_t* cb = tb.children(b);
      std::vector<std::vector<std::uint32_t>> ofA(na.childCount), ofB(nb.childCount);
      for (std::uint32_t i = 0; i < na.childCount; ++i)
      {
        for (std::uint32_t j = 0; j < nb.childCount; ++j)
        {
          const bool link = self ? i == j
                                 : (linked && links.count({ ca[i], cb[j] }) > 0) ||
              (na.childCount == 1 && nb.childCount == 1);
          if (link)
          {
            ofA[i].push_back(j);
            ofB[j].push_back(i);
          }
        }
      }
      if (ordered(na.kind))
      {
        for (std::uint32_t i = 0; i < na.childCount; ++i)
        {
          if (na.childCount != nb.childCount || ofA[i].size() != 1 || ofA[i][0] != i)
          {
            throw std::invalid_argument(std::string("morph: the children of ") + kindName(na.kind) +
              " are ordered: link each to the one in its place");
          }
        }
      }
      for (std::uint32_t i = 0; i < na.childCount; ++i)
      {
        if (ofA[i].empty()) // fades out: paired with a copy of itself of intensity 0
        {
          const Link p = pair(ta, ca[i], ta, ca[i], wa, 0.0);
          childrenA.push_back(p.first);
          childrenB.push_back(p.second);
        }
        for (std::uint32_t j : ofA[i])
        {
          const Link p = pair(ta, ca[i], tb, cb[j], wa / static_cast<double>(ofA[i].size()),
            wb / static_cast<double>(ofB[j].size()));
          childrenA.push_back(p.first);
          childrenB.push_back(p.second);
        }
      }
      for (std::uint32_t j = 0; j < nb.childCount; ++j)
      {
        if (ofB[j].empty()) // fades in
        {
          const Link p = pair(tb, cb[j], tb, cb[j], 0.0, wb);
          childrenA.push_back(p.first);
          childrenB.push_back(p.second);
        }
      }
    }
    auto copy = [](const BlobTree& t, std::uint32_t i, double w, BlobTree& into,
                  const std::vector<std::uint32_t>& children)
    {
      std::vector<Animation> values = valuesOf(t, i);
      const Kind kind = t.node(i).kind;
      if (isSkeletal(kind) || isComplexPrimitive(kind))
      {
        values[1] = scaled(values[1], w); // the intensity: the shared field's part
      }
      return addAnimated(into, kind, values, children);
    };
    const Link made{ copy(ta, a, wa, out.a, childrenA), copy(tb, b, wb, out.b, childrenB) };
    out.pairs.push_back(made);
    return made;
  }
};

// A skeletal element's values (animations) in the more general kind `to` of the chain
// point -> segment -> cylinder -> cone-sphere: the degenerate form of the same skeleton.
std::vector<Animation> promote(std::vector<Animation> v, Kind from, Kind to)
{
  int level = generality(from);
  while (level < generality(to))
  {
    if (level == 0) // point c -> segment (c, c)
    {
      const std::vector<Animation> c(v.begin() + 2, v.begin() + 5);
      v.insert(v.end(), c.begin(), c.end());
    }
    else if (level == 1) // segment -> cylinder of radius 0
    {
      v.push_back(constant(0.0));
    }
    else // cylinder r -> cone-sphere (r, r)
    {
      const Animation r = v.back();
      v.push_back(r);
    }
    ++level;
  }
  return v;
}
// A point, segment or cylinder (after promote(), a cylinder R i a b r with constant ends) as the
// rounded box of half-sides (L/2, 0, 0) and rounding r along b - a, its second axis the box's
// e2 made orthogonal to it (any normal where they are parallel), so that the morph turns no more
// than it must. The ends must be constant: the box's centre and axis are not animations of them.
std::vector<Animation> cylinderAsBox(
  const std::vector<Animation>& v, const std::vector<Animation>& box, double t0)
{
  double a[3], b[3];
  for (int k = 0; k < 3; ++k)
  {
    if (!isConstant(v[2 + k]) || !isConstant(v[5 + k]))
    {
      throw std::invalid_argument(
        "morph: a cylinder with animated ends does not morph into a box (item 63's path)");
    }
    a[k] = v[2 + k].keys[0][1];
    b[k] = v[5 + k].keys[0][1];
  }
  double e1[3] = { b[0] - a[0], b[1] - a[1], b[2] - a[2] };
  double l = std::sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
  if (l == 0) // a point: the box's own axis
  {
    for (int k = 0; k < 3; ++k)
    {
      e1[k] = box[5 + k].eval(t0);
    }
  }
  const double n1 = std::sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
  double e2[3];
  for (int k = 0; k < 3; ++k)
  {
    e2[k] = box[8 + k].eval(t0);
  }
  const double along = (e2[0] * e1[0] + e2[1] * e1[1] + e2[2] * e1[2]) / (n1 * n1);
  double w2 = 0;
  for (int k = 0; k < 3; ++k)
  {
    e2[k] -= along * e1[k];
    w2 += e2[k] * e2[k];
  }
  if (!(w2 > 1e-24 * n1 * n1))
  {
    const int m = std::fabs(e1[0]) <= std::fabs(e1[1]) && std::fabs(e1[0]) <= std::fabs(e1[2])
      ? 0
      : (std::fabs(e1[1]) <= std::fabs(e1[2]) ? 1 : 2);
    double axis[3] = { 0, 0, 0 };
    axis[m] = 1; // the world axis least along e1: e2 = e1 x axis
    e2[0] = e1[1] * axis[2] - e1[2] * axis[1];
    e2[1] = e1[2] * axis[0] - e1[0] * axis[2];
    e2[2] = e1[0] * axis[1] - e1[1] * axis[0];
  }
  std::vector<Animation> out{ v[0], v[1] };
  for (int k = 0; k < 3; ++k)
  {
    out.push_back(constant(0.5 * (a[k] + b[k])));
  }
  for (const double x : { e1[0], e1[1], e1[2], e2[0], e2[1], e2[2], 0.5 * l, 0.0, 0.0 })
  {
    out.push_back(constant(x));
  }
  out.push_back(v[8]); // r
  return out;
}

// The two stages of a path through a degenerate intermediate as evolution functions:
// clamp(2 s, 0, 1) (first) or clamp(2 s - 1, 0, 1), as key-frames at the knots of s on their side
// of the time where s = 1/2 and there (exact: a span of s cut there is the same polynomial).
Animation stage(const Animation& s, bool first)
{
  double lo = s.keys.front()[0], hi = s.keys.back()[0];
  for (int k = 0; k < 200 && hi - lo > 0; ++k) // s is increasing from 0 to 1
  {
    const double mid = 0.5 * (lo + hi);
    (s.eval(mid) < 0.5 ? lo : hi) = mid;
  }
  const double half = hi;
  Animation out;
  out.type = Animation::Type::Keys;
  out.order = s.order;
  auto key = [&](double t)
  {
    std::vector<double> k{ t, first ? 2 * s.eval(t) : 2 * s.eval(t) - 1 };
    for (int j = 1; j < s.order; ++j)
    {
      k.push_back(2 * s.derivative(t, j));
    }
    k[1] = std::min(std::max(k[1], 0.0), 1.0);
    out.keys.push_back(std::move(k));
  };
  if (!first)
  {
    key(half);
  }
  for (const auto& k : s.keys)
  {
    if (first ? k[0] < half : k[0] > half)
    {
      key(k[0]);
    }
  }
  if (first)
  {
    key(half);
  }
  return out;
}
} // namespace

SplitTrees splitCorrespondences(
  const BlobTree& A, const BlobTree& B, const std::vector<Link>& links)
{
  if (A.empty() || B.empty())
  {
    throw std::invalid_argument("morph: both trees must have a root");
  }
  Splitter s{ A, B, {}, SplitTrees{ BlobTree(), BlobTree(), {} } };
  for (const Link& l : links)
  {
    if (l.first >= A.nodes().size() || l.second >= B.nodes().size())
    {
      throw std::invalid_argument("morph: a link names a node that is not in its tree");
    }
    s.links[l] = 1;
  }
  s.out.a.setThreshold(A.threshold());
  s.out.b.setThreshold(B.threshold());
  s.pair(A, A.root(), B, B.root(), 1.0, 1.0);
  return std::move(s.out);
}

BlobTree morph(
  const BlobTree& A, const BlobTree& B, const std::vector<Link>& links, const Animation& s)
{
  const SplitTrees split = splitCorrespondences(A, B, links);
  const BlobTree& a = split.a;
  const BlobTree& b = split.b;
  // Both split trees were built pair by pair, children first: node i of one pairs with node i of
  // the other, and so does node i of C.
  BlobTree c;
  auto thresholdOf = [](const BlobTree& t)
  {
    return t.thresholdAnimation() ? *t.thresholdAnimation() : constant(t.threshold());
  };
  const Animation ta = thresholdOf(a), tb = thresholdOf(b);
  if (isConstant(ta) && isConstant(tb) && ta.keys[0][1] == tb.keys[0][1])
  {
    c.setThreshold(ta.keys[0][1]);
  }
  else
  {
    const Animation tc = mergeKeyframes(ta, tb, s);
    c.setThreshold(tc.eval(0.0));
    c.animateThreshold(tc);
  }
  auto mergeAll = [&s](const std::vector<Animation>& va, const std::vector<Animation>& vb)
  {
    std::vector<Animation> out;
    for (std::size_t k = 0; k < va.size(); ++k)
    {
      const bool same =
        isConstant(va[k]) && isConstant(vb[k]) && va[k].keys[0][1] == vb[k].keys[0][1];
      out.push_back(same ? va[k] : mergeKeyframes(va[k], vb[k], s));
    }
    return out;
  };
  // The intensity of every element below node i multiplied by the animation `factor` (1 - s or
  // s): a copy of C's subtree for a cross-dissolve.
  std::function<std::uint32_t(std::uint32_t, const Animation&, const Animation&)> fade =
    [&](std::uint32_t i, const Animation& from, const Animation& to) -> std::uint32_t
  {
    std::vector<std::uint32_t> children;
    for (std::uint32_t k = 0; k < c.node(i).childCount; ++k)
    {
      children.push_back(fade(c.children(i)[k], from, to));
    }
    std::vector<Animation> values = valuesOf(c, i);
    const Kind kind = c.node(i).kind;
    if (isSkeletal(kind) || isComplexPrimitive(kind))
    {
      // (1 - s) i(t) + s * 0 (fading out) or (1 - s) * 0 + s i(t) (fading in).
      values[1] =
        mergeKeyframes(from.type == Animation::Type::Keys && from.keys.empty() ? values[1] : from,
          to.type == Animation::Type::Keys && to.keys.empty() ? values[1] : to, s);
    }
    if (kind == Kind::Union || kind == Kind::Intersection || kind == Kind::Difference)
    {
      throw std::invalid_argument("morph: a texture changes type above a Boolean node, which "
                                  "a cross-dissolve's blend would turn into an R-function");
    }
    return addAnimated(c, kind, values, children);
  };
  std::vector<std::uint32_t> map(a.nodes().size());
  for (std::uint32_t i = 0; i < a.nodes().size(); ++i)
  {
    const Node& na = a.node(i);
    const Node& nb = b.node(i);
    std::vector<std::uint32_t> children;
    for (std::uint32_t k = 0; k < na.childCount; ++k)
    {
      children.push_back(map[a.children(i)[k]]);
    }
    std::vector<Animation> va = valuesOf(a, i), vb = valuesOf(b, i);
    Kind kind = na.kind;
    const bool toBox = na.kind != nb.kind && !na.childCount &&
      (na.kind == Kind::Box || nb.kind == Kind::Box) &&
      generality(na.kind == Kind::Box ? nb.kind : na.kind) >= 0 &&
      generality(na.kind == Kind::Box ? nb.kind : na.kind) <= 2;
    if (toBox)
    {
      // Item 63's path cylinder -> segment -> box (a point or segment enters it on the way): the
      // cylinder as the box of half-sides (L/2, 0, 0) rounded by r; the geometry (centre, axes,
      // first half-side) moves with s throughout, the rounding and the two other half-sides in
      // two stages, so that at s = 1/2 the element is the degenerate intermediate, a segment
      // (for a sharp box). The cylinder's side shrinks first, the box's side grows second.
      const bool boxIsB = nb.kind == Kind::Box;
      const Kind other = boxIsB ? na.kind : nb.kind;
      std::vector<Animation>& cyl = boxIsB ? va : vb;
      cyl = cylinderAsBox(promote(cyl, other, Kind::Cylinder), boxIsB ? vb : va, s.keys[0][0]);
      const Animation first = stage(s, true), second = stage(s, false);
      std::vector<Animation> values;
      for (std::size_t k = 0; k < va.size(); ++k)
      {
        const bool rounding = k == 14, sides = k == 12 || k == 13;
        const Animation& e = !(rounding || sides) ? s : ((rounding == boxIsB) ? first : second);
        const bool same =
          isConstant(va[k]) && isConstant(vb[k]) && va[k].keys[0][1] == vb[k].keys[0][1];
        values.push_back(same ? va[k] : mergeKeyframes(va[k], vb[k], e));
      }
      map[i] = addAnimated(c, Kind::Box, values, children);
      continue;
    }
    if (na.kind != nb.kind && !na.childCount)
    {
      // Skeletal elements of two kinds meet in the more general one (item 63's chain).
      if (generality(na.kind) < 0 || generality(nb.kind) < 0)
      {
        throw std::invalid_argument(std::string("morph: no interpolation from ") +
          kindName(na.kind) + " to " + kindName(nb.kind) +
          " (skeletal elements morph along point -> segment -> cylinder -> conesphere, and "
          "from a point, segment or cylinder into a box)");
      }
      kind = generality(na.kind) > generality(nb.kind) ? na.kind : nb.kind;
      va = promote(va, na.kind, kind);
      vb = promote(vb, nb.kind, kind);
    }
    if (na.kind != nb.kind && na.childCount)
    {
      // Item 65: textures of two types cross-dissolve. Below C's morphed child, two copies: one
      // under A's texture fading out, one under B's fading in; their blend has the field of
      // one and Phi = (1 - s) Phi_A + s Phi_B.
      const Animation none{ Animation::Type::Keys, 0, 0, 1, 0, 1, {} };
      const std::uint32_t child = children[0];
      const std::uint32_t out = fade(child, none, constant(0.0));
      const std::uint32_t in = fade(child, constant(0.0), none);
      const std::uint32_t texA = addAnimated(c, na.kind, va, { out });
      const std::uint32_t texB = addAnimated(c, nb.kind, vb, { in });
      // The morphed child itself is left unreferenced (dropped below): its copies replace it.
      map[i] = c.add(Kind::Blend, {}, { texA, texB });
      continue;
    }
    if (va.size() != vb.size())
    {
      throw std::invalid_argument(std::string("morph: ") + kindName(kind) +
        " has a different number of values in A and B (control points must correspond)");
    }
    map[i] = addAnimated(c, kind, mergeAll(va, vb), children);
  }
  c.setRoot(map[a.root()]);
  // Only what the root reaches: a cross-dissolve left the morphed subtree it copied behind.
  BlobTree out(c.threshold());
  if (c.thresholdAnimation())
  {
    out.animateThreshold(*c.thresholdAnimation());
  }
  std::function<std::uint32_t(std::uint32_t)> copy = [&](std::uint32_t i) -> std::uint32_t
  {
    std::vector<std::uint32_t> children;
    for (std::uint32_t k = 0; k < c.node(i).childCount; ++k)
    {
      children.push_back(copy(c.children(i)[k]));
    }
    return addAnimated(out, c.node(i).kind, valuesOf(c, i), children);
  };
  out.setRoot(copy(c.root()));
  return out;
}

} // namespace ictk::frep::blob::morph
