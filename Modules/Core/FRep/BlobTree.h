// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The BlobTree of seed 004 (Barbier, Galin & Akkouche; papers.md section 3): skeletal elements
// with compact-support fields f = i g(d(p)), combined by blend, Boolean and warp nodes. The tree is
// kept as a structure (flat arrays, children before parents) because the paper counts, expands,
// animates and instantiates it; it is lowered to the expression DAG (potential(), shape()) so that
// every evaluator (point, batch, interval, gradient, JIT) supports it, and evaluated directly by
// evaluate() with the bounding-box short-circuit taken literally.
//
// Threshold convention (the ONE place it is mapped; papers.md section 0.6): a BlobTree field is a
// potential, >= T inside and 0 far away, with T = 0.5 by default; an ICTK shape is f >= 0 inside.
// shape() returns potential - T, nothing else converts. Operators that need T (difference
// 2T - f_B, the T-normalised R-functions) read the tree's threshold.
//
// Kernel (papers.md E15: the paper gives none): Wyvill's soft-object kernel, the same as
// frep::softObject, g(d) = 1 - 22/9 q + 17/9 q^2 - 4/9 q^3 with q = d^2 / R^2 for d <= R and 0
// beyond, so g(0) = 1, g(R/2) = 1/2, g(R) = 0 with zero slope. With T = 0.5 and intensity 1 the
// surface lies at distance R/2 from the skeleton.

#include "FRep/Domain.h"
#include "FRep/Hypervolume.h"

#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace ictk::frep::blob
{
using Vec3 = std::array<double, 3>;

/// The threshold T of the paper (papers.md 3.2 [EXT] convention).
constexpr double DefaultThreshold = 0.5;

/// The material parameters Phi of the TextureTree (papers.md 3.5, line 177): colour r, g, b,
/// reflection rho, transmittance tau, index of refraction sigma.
constexpr int MaterialSize = 6;
/// The material of elements with no material node above them: light grey, opaque, sigma 1.
constexpr double DefaultMaterial[MaterialSize] = { 0.8, 0.8, 0.8, 0.0, 0.0, 1.0 };
/// The texture hyper-blend (line 195). As printed it does not tend to the sharp union as n grows
/// (erratum E11: it tends to max(f_A Phi_A, f_B Phi_B) / max(f_A, f_B)); the corrected form
/// sum f_i^n Phi_i / sum f_i^n equals the blend at n = 1 and tends to the dominant child's Phi.
enum class TextureHyperBlend : std::uint8_t
{
  Corrected,
  Verbatim
};

/// Node kinds and their values (in order). Every skeletal element starts with R (radius of
/// influence, > 0) and i (intensity, finite); points are three values x y z.
enum class Kind : std::uint8_t
{
  // --- skeletal elements (leaves) ---
  Point,      ///< R i | c
  Segment,    ///< R i | a b
  Circle,     ///< R i | c n r        (n the plane normal, r > 0)
  Disc,       ///< R i | c n r
  Triangle,   ///< R i | a b c        (non-degenerate)
  Curve,      ///< R i | v0 v1 ...    (a polyline, >= 2 vertices)
  Cylinder,   ///< R i | a b r        (line-swept sphere: the segment thickened by r >= 0)
  ConeSphere, ///< R i | a b r0 r1    (hull of the spheres (a, r0) and (b, r1), r0, r1 >= 0)
              /// R i | c n rho0 h0 t0 rho1 h1 t1: a hollow cone of varying thickness
              /// (papers.md 3.4, line 155), the profile segment from (rho0, h0) to (rho1, h1) (rho
              /// the distance to the axis through c along n, h the height along it; rho >= 0)
              /// thickened from t0 to t1 (>= 0) and revolved about the axis. In the meridian
              /// half-plane it is the 2D cone-sphere, so its ends are the junction tori of line 155
              /// (major radius rho_i, minor t_i), rho0 = rho1 gives the cylinder of line 159 and t0
              /// = t1 = 0 the plain hollow cone.
  HollowCone,
  /// R i | a b c ta tb tc: a triangle with a thickness at each vertex (>= 0; papers.md 3.4, lines
  /// 127-140): d = |h| - t(q) over the triangle (h the height, t interpolated at the foot q), and
  /// |p - q| - t(q) from the nearest point q of an edge beyond it. Its top and bottom are the
  /// planes through v +- t n; its sides are rounded (the paper's polyhedron has flat sides), so
  /// that neighbouring triangles of a surface meet without cracks. Null thickness: the triangle.
  ThickTriangle,
  /// R i | c e1 e2 a b c r: a rounded box, the points within r (>= 0) of the box of half-sides
  /// (a, b, c) (>= 0) about the centre c in the frame of the axes e1, e2 (e2 made orthogonal to
  /// e1, the third axis e1 x e2): d = |max(|q| - h, 0)| - r with q the point in that frame. With r
  /// = 0 the paper's box (item 49); half-sides (a, b, 0) and r = t are the two halves of a thick
  /// rectangle (two ThickTriangles of equal thickness t) merged, half-sides (a, 0, 0) a cylinder
  /// of radius r (a segment for r = 0), the degenerate forms of the morph's path (item 63).
  Box,
  // --- complex skeletal primitive (expanded into leaves by expand(), papers.md 3.4)
  // ---
  GeneralisedCylinder, ///< R i n | (v r)...  (control points with radii, >= 2; n >= 1 segments)
                       /// R i n c axis | (rho h t)...: a surface of revolution with variable
                       /// thickness (papers.md 3.4, lines 142-159): a Catmull-Rom profile through
                       /// the control points (rho >= 0 the distance to the axis through c along
                       /// `axis`, h the height, t >= 0 the thickness), sampled into n segments (the
                       /// level of detail), each a HollowCone, joined by max nodes (no bulging).
  SurfaceOfRevolution,
  /// R i | (a ta b tb c tc)...: a surface with variable thickness (papers.md 3.4, lines 127-140),
  /// a triangle mesh given triangle by triangle, each vertex with its thickness: one ThickTriangle
  /// per triangle (a Triangle where all three thicknesses are null), joined by max nodes; two
  /// successive triangles that are the halves of a rectangle with one thickness t at their six
  /// vertices are one Box (half-sides (a, b, 0), r = t; line 140), unless the surface is animated.
  ThickSurface,
  // --- operators ---
  Blend,        ///< sum of >= 1 children (papers.md 3.3, line 66)
  HyperBlend,   ///< n | (sum f^n)^(1/n) of >= 1 children, n > 0 (line 70)
  LocalBlend,   ///< three children A, B, R (line 74), f_R clamped to [0, 1]
  Union,        ///< >= 1 children (max, or the R-function under a blend: line 92)
  Intersection, ///< >= 1 children (min, or the R-function under a blend)
  Difference,   ///< two children: A \ B = A intersect (2T - f_B) (line 84)
                /// The max of >= 1 children in every context: the union that joins the pieces of a
                /// complex primitive (papers.md 3.4, line 114: no bulging). Below a blend, a union
                /// node becomes the R-function, whose value inside grows by up to (2 + sqrt 2)/(2 -
                /// sqrt 2) = 5.83 per level (same surface); max keeps deep hierarchies well scaled.
  Max,
  /// r g b rho tau sigma | one child: the material of the subtree (a texture node, papers.md
  /// 3.5, line 165); the field is the child's. Values >= 0.
  Material,
  /// colourA colourB rho tau sigma lambda a n | one child: a procedural solid texture (papers.md
  /// 3.5; FRep/SolidTexture.h): the subtree's Phi is ((1 - s) colourA + s colourB, rho, tau,
  /// sigma) with s the pattern at the point in this node's frame: marble veins across x of
  /// period lambda, wood rings about z of period lambda, granite speckles of scale lambda; a the
  /// turbulence amplitude, n its octaves (1..8). Colours and optics >= 0, lambda > 0.
  Marble,
  Wood,
  Granite,
  // --- warps and frame nodes (one child; f_w(A)(p) = f_A(w^-1(p)), line 96) ---
  Translate, ///< t
  Rotate,    ///< axis angle (radians, right-handed, the axis non-zero)
  Scale,     ///< s (three non-zero factors; the field is not rescaled)
  Twist,     ///< rate (radians per unit length, about z: the slice at height z turns by rate z)
};

const char* kindName(Kind kind);
bool isSkeletal(Kind kind);
/// Generalised cylinders and surfaces of revolution: expanded into elements by instantiate().
bool isComplexPrimitive(Kind kind);
bool isWarp(Kind kind);
/// Material, marble, wood and granite: the nodes that give their subtree its material Phi.
bool isTexture(Kind kind);
/// Blend, hyper-blend and local blend: the nodes below which Booleans become R-functions.
bool isBlend(Kind kind);

struct Node
{
  Kind kind;
  std::uint32_t firstValue;
  std::uint32_t valueCount;
  std::uint32_t firstChild;
  std::uint32_t childCount;
};

/// A value of a node that changes with time (papers.md 3.6): a periodic function (line 243)
/// v(t) = base + amplitude sin(2 pi t / period + phase), or piecewise Hermite-Ferguson key-frames
/// of degree n (line 236): keys[k] holds (t_k, v, v', ..., v^(n-1)), so each span is the
/// polynomial of degree 2n - 1 matching the n derivatives at both ends (clamped outside).
struct Animation
{
  enum class Type : std::uint8_t
  {
    Wave,
    Keys
  };
  Type type = Type::Wave;
  double base = 0, amplitude = 0, period = 1, phase = 0;
  int order = 2; ///< n: values per key after its time (Keys)
  std::vector<std::vector<double>> keys;
  double eval(double t) const;
  /// The j-th time derivative at t (j = 0 is eval; 0 for j >= 1 where key-frames are clamped).
  double derivative(double t, int j) const;
};

/// A value of an animated tree out of its range at a time t: instantiate(t) applies add()'s
/// checks to the values at t of the nodes with an animated value (and to the threshold), since a
/// wave or key-frames may drive a radius below 0 at some t. what() is the reason, t and the node.
class InstanceError : public std::invalid_argument
{
public:
  /// node() for the threshold.
  static constexpr std::uint32_t Threshold = 0xffffffffu;
  InstanceError(std::uint32_t node, double time, const std::string& reason);
  /// The node of the generic tree (its index in nodes()), or Threshold.
  std::uint32_t node() const { return node_; }
  double time() const { return time_; }
  /// add()'s message for the value, e.g. "blobtree: point: the radius of influence R must be
  /// positive (got -0.25)".
  const std::string& reason() const { return reason_; }

private:
  std::uint32_t node_;
  double time_;
  std::string reason_;
};

class BlobTree
{
public:
  explicit BlobTree(double threshold = DefaultThreshold);

  /// Adds a node whose children are already in the tree; returns its index, which becomes the
  /// root. Throws std::invalid_argument naming the node kind and the value for a wrong count of
  /// values or children, a non-finite value, a non-positive radius of influence, ...
  std::uint32_t add(
    Kind kind, const std::vector<double>& values, const std::vector<std::uint32_t>& children = {});
  /// Makes `node` the root (add() makes the last node the root).
  void setRoot(std::uint32_t node);
  /// Attaches an animation to value `index` of `node` (its constant value is then ignored by
  /// instantiate()). Throws std::invalid_argument for a bad index or animation.
  void animate(std::uint32_t node, std::uint32_t index, Animation animation);
  /// The threshold as a function of time (papers.md 3.6, line 222).
  void animateThreshold(Animation animation);

  double threshold() const { return threshold_; }
  void setThreshold(double threshold);
  std::uint32_t root() const { return root_; }
  bool empty() const { return nodes_.empty(); }
  const std::vector<Node>& nodes() const { return nodes_; }
  const Node& node(std::uint32_t i) const { return nodes_[i]; }
  const double* values(std::uint32_t i) const { return values_.data() + nodes_[i].firstValue; }
  const std::uint32_t* children(std::uint32_t i) const
  {
    return links_.data() + nodes_[i].firstChild;
  }
  bool animated() const { return !animations_.empty() || thresholdAnimation_.size() == 1; }
  /// The animation of value `index` of `node` (the last one attached, which instantiate()
  /// applies), or null for a constant value.
  const Animation* animation(std::uint32_t node, std::uint32_t index) const;
  /// The threshold's animation, or null for a constant threshold.
  const Animation* thresholdAnimation() const
  {
    return thresholdAnimation_.empty() ? nullptr : &thresholdAnimation_[0];
  }

  /// Nodes reachable from the root of each kind class.
  std::size_t leafCount() const;
  std::size_t operatorCount() const; ///< blends and Booleans
  std::size_t warpCount() const;
  std::size_t count(Kind kind) const;

  /// The static tree at time t (papers.md 3.6, lines 227-229): every animated value evaluated,
  /// complex primitives expanded into skeletal elements (expand()). `out` (not this tree) is
  /// overwritten; when it already holds an instance of this structure only its values are
  /// rewritten, so instantiating many times allocates nothing. Throws InstanceError, leaving
  /// `out` unchanged, where an animated value at t fails the checks of add().
  void instantiate(double t, BlobTree& out) const;
  BlobTree instantiate(double t) const;
  /// The same tree with complex primitives expanded (a static tree: animations are dropped).
  BlobTree expand() const { return instantiate(0.0); }

  /// Clears the tree, keeping its memory.
  void clear();

private:
  void touch(); // the structure changed
  // add()'s checks on the animated nodes' values at t (values: all of the tree's, at t).
  void checkAt(double t, const double* values, double threshold) const;
  double threshold_;
  std::uint32_t root_ = 0;
  std::vector<Node> nodes_;
  std::vector<double> values_;
  std::vector<std::uint32_t> links_;
  struct Animated
  {
    std::uint32_t value; // index into values_
    Animation animation;
  };
  std::vector<Animated> animations_;
  std::vector<Animation> thresholdAnimation_; // empty or one
  std::vector<std::uint32_t> animatedNodes_;  // the nodes with an animated value, once each
  std::vector<bool> parented_;                // add(): which nodes already have a parent
  std::vector<double> scratch_;               // instantiate(): the values at t
  std::vector<std::uint32_t> map_;            // instantiate(): node of the source -> node here
  std::vector<std::uint32_t> pieces_;         // instantiate(): the elements of the cylinders
  std::uint64_t structure_ = 0;               // this structure's number
  std::uint64_t instanceOf_ = 0;              // instantiate(): the structure laid out here
  std::vector<double> tangents_;              // instantiate(): a curve's control tangents
  std::vector<double> profile_;               // instantiate(): a revolution's profile as curves
};

/// The paper's field f(p) (>= T inside) as an expression of x, y, z. Booleans follow the context
/// rule (papers.md 3.3, line 92): min/max unless a blend node is an ancestor, R-functions below
/// one. Every skeletal element is select(inside its bounding box bbox(skeleton) + R,
/// i g(d(p)), 0), so that interval evaluation answers exactly 0 over regions outside the box and
/// the simplified tape drops the element there. Complex primitives are expanded. Throws
/// std::invalid_argument for an empty tree.
Expr potential(const BlobTree& tree);
/// The ICTK shape of the tree: potential - T on domain XYZ (the threshold mapping).
Shape shape(const BlobTree& tree);

/// Direct evaluation of the paper's f(p) by traversing the tree (papers.md 3.1, line 56), with
/// the same formulas as potential(). A skeletal element whose box does not hold p returns 0
/// without evaluating its distance or kernel; `kernelEvaluations`, when given, counts those that
/// were evaluated.
double evaluate(const BlobTree& tree, const Vec3& p, std::size_t* kernelEvaluations = nullptr);

/// The TextureTree (papers.md 3.5): the material Phi(p) of the tree, as expressions of x, y, z.
/// A material node gives its subtree's Phi; blends weight the children's Phi by their fields
/// (line 191; the mean where every field is 0), Booleans take one child's (line 203: the union
/// Phi_A iff f_A > f_B, the intersection iff f_A < f_B, the difference iff f_A < 2T - f_B; ties
/// to B), the local blend mixes both (line 199), warps move it with the geometry (line 207).
std::array<Expr, MaterialSize> material(
  const BlobTree& tree, TextureHyperBlend mode = TextureHyperBlend::Corrected);
/// Direct evaluation of f and Phi.
double evaluateTextured(const BlobTree& tree, const Vec3& p, std::array<double, MaterialSize>& phi,
  TextureHyperBlend mode = TextureHyperBlend::Corrected);
/// shape() with Phi as attributes "colour" (r, g, b) and "optics" (rho, tau, sigma), so that the
/// materials flow into sampled volumes, meshes and labelled tets like any attribute.
Hypervolume texturedHypervolume(
  const BlobTree& tree, TextureHyperBlend mode = TextureHyperBlend::Corrected);

/// The axis-aligned box outside which the tree's potential is 0 (the union of its elements'
/// boxes through the warps; a twist or scale widens conservatively). {lo, hi}.
std::array<Vec3, 2> supportBox(const BlobTree& tree);

// --- the operators on values (papers.md 3.3), shared by both evaluations and the tests ----------
/// Wyvill's kernel on d^2: i g(sqrt(d2)) for a radius of influence R.
double kernel(double d2, double R, double intensity = 1.0);
double hyperBlend(double a, double b, double n);
double localBlend(double a, double b, double r);
double differenceMinMax(double a, double b, double T);
/// T-normalised R-functions (lines 88, 90).
double unionR(double a, double b, double T);
double intersectionR(double a, double b, double T);

} // namespace ictk::frep::blob
