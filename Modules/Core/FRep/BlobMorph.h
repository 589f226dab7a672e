// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Metamorphosis between two animated BlobTrees (seed 004, papers.md 3.7, items 60-65): the
// correspondence splitting that pairs the nodes of A and B bijectively, the skeleton
// interpolation graph searched by Dijkstra, the parameters of the generic morph C interpolated by
// an evolution function s(t) and merged into key-frames, and texture morphing.

#include "FRep/BlobTree.h"

#include <string>
#include <utility>
#include <vector>

namespace ictk::frep::blob::morph
{

/// Item 60 (line 284): p_C(t) = (1 - s(t)) p_A(t) + s(t) p_B(t).
double interpolate(const Animation& pA, const Animation& pB, const Animation& s, double t);

/// The knots of an animation: its key times; a wave has none.
std::vector<double> knots(const Animation& a);

/// An animation that is the constant v.
Animation constant(double v);

/// Item 61, mergeKeyframes (lines 304-317): p_C as key-frames at the union of the knots of s, p_A
/// and p_B within s's key range, each key p_C(t_i) = (1 - s) p_A + s p_B with its derivatives by
/// Leibniz's rule (order n the largest of the key-frame orders, at least 2), interpolated by
/// Hermite-Ferguson between them. Exact at the knots; between them it is the Hermite curve of
/// those keys, not the product (papers.md 3.7). `s` must be key-frames.
Animation mergeKeyframes(const Animation& pA, const Animation& pB, const Animation& s);

/// Item 63 (lines 272-278): skeleton types linked by "degenerates to" arcs, each weighted by the
/// complexity of the shapes the transformation passes through.
class InterpolationGraph
{
public:
  struct Arc
  {
    std::string from, to;
    double weight;
    std::string how; ///< the parameter change that realises it ("radius -> 0")
  };
  /// An arc, usable both ways (a morph runs either way). Weights are positive.
  void addArc(const std::string& from, const std::string& to, double weight, std::string how);
  const std::vector<Arc>& arcs() const { return arcs_; }
  /// The path of least total weight from `from` to `to` (Dijkstra), as the types visited, both
  /// ends included; empty when they are not connected.
  std::vector<std::string> shortestPath(
    const std::string& from, const std::string& to, double* cost = nullptr) const;
  /// The arcs of the paper (line 274 and papers.md 3.7): cylinder -> segment (radius -> 0),
  /// cone-sphere -> cylinder (r0 -> r1), segment -> point (length -> 0), circle -> point and
  /// disc -> point (radius -> 0), torus -> circle (minor radius -> 0), box -> rectangle
  /// (thickness -> 0), prism -> triangle (thickness -> 0), box -> segment (two sides -> 0), and
  /// the deforming cylinder-box primitive, cylinder -> box directly. An arc weighs the complexity
  /// (dimension and cost of d(p)) of the more complex shape it deforms through:
  /// point 1, segment 2, circle 2, cylinder 3, disc 3, rectangle 3, torus 3, triangle 3,
  /// cone-sphere 4, box 4, prism 5, cylinder-box 8.
  static InterpolationGraph standard();

private:
  std::vector<Arc> arcs_;
};

/// A link of the graph of correspondences G_C(A -> B) (line 253): node `a` of A matches node `b`
/// of B. Links join nodes at the same depth whose parents are linked; the roots are linked.
using Link = std::pair<std::uint32_t, std::uint32_t>;

/// Item 62 (lines 258-268): A' and B', equivalent to A and B, whose nodes pair bijectively. From
/// the roots down, a child of a linked pair that holds k links is split into k copies, one per
/// link (an operator's copy keeps its parent's parameters; a skeletal element's copies share its
/// field, intensity / k each, which keeps the field of a sum-blend); a child without a link is
/// paired with a copy of itself of intensity 0 in the other tree, so it fades in or out. Paired
/// operators must be of one kind (std::invalid_argument otherwise).
struct SplitTrees
{
  BlobTree a, b;
  /// pairs[i] = (node of a, node of b), every node of either in exactly one pair.
  std::vector<Link> pairs;
};
SplitTrees splitCorrespondences(
  const BlobTree& A, const BlobTree& B, const std::vector<Link>& links);

/// Items 60-62 and 64-65: the generic morph C(t) = {C, P_C(t)} between A and B (generic, maybe
/// animated) under the evolution function s (key-frames over [0, 1] from 0 to 1): the split
/// trees' structure, every value of a pair interpolated by mergeKeyframes, the threshold too.
/// Skeletal elements of different kinds meet in the more general kind of the chain
/// point -> segment -> cylinder -> cone-sphere (each degenerates into the one before; the path
/// of the standard InterpolationGraph); a point, segment or cylinder (constant ends) and a box
/// take the path cylinder -> segment -> box, the cylinder's rounding shrinking while s < 1/2 and
/// the box's two other half-sides growing after, so that the element is a segment at s = 1/2;
/// other kinds throw. Texture nodes of one type interpolate
/// their parameters (item 64); of different types, their subtree is cross-dissolved (item 65):
/// a blend of the two textured copies with intensities scaled by 1 - s and s, so that
/// Phi_C = (1 - s) Phi_A + s Phi_B and f_C is the morphed field (line 352), exactly at the knots
/// of the merged key-frames (a product of animations is re-interpolated between them); such a
/// subtree must not hold a union, intersection or difference (the blend would make them
/// R-functions).
BlobTree morph(
  const BlobTree& A, const BlobTree& B, const std::vector<Link>& links, const Animation& s);

} // namespace ictk::frep::blob::morph
