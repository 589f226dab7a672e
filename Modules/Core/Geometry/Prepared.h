// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Internal to the Geometry library: a placed shape prepared for one query (Prepared: the inverse
// placement, one field evaluator per Field part, the world pieces of its analytic parts) with its
// world field, interval enclosure and gradient, and the helpers the query files share (boxes,
// interval arithmetic for the analytic parts, checks, the branch and bound over boxes, the local
// searches of Distance.cxx). Each declaration says which file defines it.

#include "Geometry/CurvePieces.h"
#include "Geometry/PlacedShape.h"

#include "FRep/Field.h"
#include "FRep/Interval.h"

#include <algorithm>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace ictk::geometry::detail
{

using frep::Box3;
using frep::Interval;

// ---------------------------------------------------------------------------------------------
// Interval arithmetic for the analytic parts, on the kernel's frep::Interval but not with the
// kernel's operations (IntervalEvaluator's per-instruction code in FRep/Evaluators.cxx): those
// round outward by one ulp and handle NaN, empty and infinite operands, which these enclosures
// of boxes, disks and half-planes never meet. Rounding is not directed here; the boxes pruned
// with these bounds are never closer than a tolerance to a decision, so the last bits do not
// matter (the tape fields round outward themselves). Calling the kernel's instead gave the same
// results in every test but 29% more instructions on TestGeometry's Timings and
// EggAndLiquidModel (callgrind; the field disk/rectangle area 20 -> 37 us).

inline Interval iv(double lo, double hi)
{
  return Interval{ lo, hi, false };
}
inline Interval ivAdd(Interval a, Interval b)
{
  return iv(a.lo + b.lo, a.hi + b.hi);
}
inline Interval ivNeg(Interval a)
{
  return iv(-a.hi, -a.lo);
}
inline Interval ivMin(Interval a, Interval b)
{
  return iv(std::min(a.lo, b.lo), std::min(a.hi, b.hi));
}
inline Interval ivMax(Interval a, Interval b)
{
  return iv(std::max(a.lo, b.lo), std::max(a.hi, b.hi));
}
inline Interval ivAbs(Interval a)
{
  if (a.lo >= 0)
  {
    return a;
  }
  if (a.hi <= 0)
  {
    return ivNeg(a);
  }
  return iv(0, std::max(-a.lo, a.hi));
}
inline Interval ivSquare(Interval a)
{
  const Interval m = ivAbs(a);
  return iv(m.lo * m.lo, m.hi * m.hi);
}
inline Interval ivScale(double s, Interval a)
{
  return s >= 0 ? iv(s * a.lo, s * a.hi) : iv(s * a.hi, s * a.lo);
}

// ---------------------------------------------------------------------------------------------
// Boxes (Prepared.cxx).

double boxDiagonal(const Box3& b);
Box3 joinBoxes(const Box3& a, const Box3& b);
Box3 meetBoxes(const Box3& a, const Box3& b);
Box3 flatten(Box3 b, bool flat);
Box3 padded(Box3 b, double pad);

// ---------------------------------------------------------------------------------------------
// Placed shapes: dimensions, domains, checks (PlacedShape.cxx).

int partDimension(const ShapePart& p);
int shapeDimension(const PlacedShape& s);
[[noreturn]] void fail(const PlacedShape& s, const std::string& what);
[[noreturn]] void failPair(const PlacedShape& a, const PlacedShape& b, const std::string& what);
bool finite3(const Vec3& v);

/// A Field part's domain; an unset (empty) one is the [-10, 10]^3 that model files without
/// bounds get.
Box3 fieldDomain(const ShapePart& p);

/// The image of a box under an affine map, enclosed in a box (interval arithmetic on the map).
Box3 mapBox(const Affine& m, const Box3& b);

/// Throws std::invalid_argument naming the cell when the shape cannot be queried (no parts,
/// non-finite or negative sizes, missing points, fields or operands; nested too deeply).
void validate(const PlacedShape& s, int depth = 0);

// ---------------------------------------------------------------------------------------------
// A shape prepared for one query (Prepared.cxx).

struct Prepared;

struct PreparedPart
{
  const ShapePart* part = nullptr;
  int dim = 0;
  Affine toLocal;
  /// Shared by a shape narrowed to a box (Prepared's narrowing constructor) where a field does
  /// not narrow further: both are used by one thread, one call at a time.
  std::shared_ptr<frep::FieldEvaluator> eval;
  Box3 domain;
  std::unique_ptr<Prepared> a, b;
  double hx = 0, hy = 0, hd = 0; // CircularSegment: the chord's half-plane hx x + hy y >= hd
};

struct Prepared
{
  const PlacedShape* shape = nullptr;
  int dim = 0;
  bool flat = true;     ///< lies in z = 0 (dimension <= 2)
  bool analytic = true; ///< every part has world pieces (no fields, blends, 3D parts)
  std::vector<PreparedPart> parts;
  std::vector<Piece> pieces;
  Box3 bounds;
  double scale = 1; ///< the bounds' diagonal, for relative steps

  explicit Prepared(const PlacedShape& s);
  /// `parent` with the fields of its Field parts, and of its blends' and unions' operands,
  /// narrowed to the world box `w` (FieldEvaluator::narrowed): the same values, enclosures and
  /// gradients inside w, cheaper, and independent of what changes only outside w (a parameter
  /// of a term pruned away there). `changed` is set when some field narrowed.
  Prepared(const Prepared& parent, const Box3& w, bool& changed);
  /// Appends the words that determine its world field (FieldEvaluator::fingerprint): the parts'
  /// kinds, placements, sizes and domains, their fields' fingerprints, the blends' amounts and
  /// operands. false for a part it cannot describe (a space-time blend).
  bool fingerprint(std::vector<std::uint64_t>& out) const;

  V2 world2(double x, double y) const;
  void addPieces(const ShapePart& part);
  double partValue(const PreparedPart& pp, Vec3 w) const;
  /// The world field (>= 0 inside; the max over the 2D/3D parts).
  double value(Vec3 w) const;
  /// value() at n points given as coordinate arrays, a Field part's field evaluated in one
  /// FieldEvaluator::values call (batched, several times cheaper than point by point; the values
  /// may differ from value()'s in the last bits, as the batch and gradient evaluators do).
  void values(const double* x, const double* y, const double* z, double* out, std::size_t n) const;
  void partValues(const PreparedPart& pp, const double* x, const double* y, const double* z,
    double* out, std::size_t n) const;
  Interval partBound(const PreparedPart& pp, const Box3& w) const;
  /// An enclosure of value() over a world box.
  Interval bound(Box3 w) const;
  /// A part's value and its world gradient (the chain rule through the placement: the local
  /// gradient times the inverse's linear part).
  double partGradient(const PreparedPart& pp, Vec3 w, Vec3& g) const;
  /// The value and its world gradient (of the part that gives the max).
  double gradient(Vec3 w, Vec3& g) const;
  /// |f| / |grad f|: the first-order distance to the boundary.
  double boundaryDistance(const Vec3& w) const;
  bool solid() const { return dim >= 2; }
  /// Centres of a 32 x 32 (16^3) grid over the bounds where the shape is inside, computed on
  /// first use: starting points for projections onto fields.
  const std::vector<Vec3>& insideSamples() const;

private:
  mutable bool sampled_ = false;
  mutable std::vector<Vec3> inside_;
};

/// The query tolerance: QueryOptions::tolerance, or 1e-9 x the diagonal of the joint bounds.
double defaultTolerance(const Prepared& a, const Prepared& b, const QueryOptions& o);

/// Checks the options and validates both shapes.
void checkOptions(const PlacedShape& a, const PlacedShape& b, const QueryOptions& o);

// ---------------------------------------------------------------------------------------------
// Branch and bound over boxes with the shapes' interval enclosures (Prepared.cxx).

/// Searches `box` for a point where `witness` holds. `promise` bounds from above, by interval
/// arithmetic, how well a box can do; a negative promise proves there is no witness in the box.
/// The most promising box is split first, so that an existing witness is met early. Boxes
/// smaller than `minSize` are decided by their centre only, and at most `budget` boxes are
/// visited; both limits are where a "no" stops being a proof. `leaves`, when given, receives
/// the boxes left undecided at `minSize` (up to 4096), for the caller to refine locally.
bool searchBoxes(const Box3& box, bool flat, double minSize,
  const std::function<double(const Box3&)>& promise,
  const std::function<bool(const Vec3&)>& witness, int budget = 200000,
  std::vector<Box3>* leaves = nullptr);

// ---------------------------------------------------------------------------------------------
// Local searches shared by distance, containment and measure (Distance.cxx).

/// Newton steps towards {f >= 0} along grad f, each at most `maxStep` long (none from inside).
Vec3 intoShape(const Prepared& s, Vec3 x, double maxStep);

/// A local minimum of sign x fA over {fB >= 0} from x (left where it ends): steps along the
/// descent direction, tangent to B's boundary where they would leave B, pulled back onto B by
/// Newton steps, the step length doubled after a success and halved after a failure, down to
/// 1e-9 of the size (the value then varies by ~curvature x step^2 at most). `inB` is how far
/// outside B (first order) a point may be and still count as B's (rounding of the Newton
/// steps). Stops early once the objective < `stop`. Returns the objective there (+inf when x
/// could not be brought into B).
double lowestInside(const Prepared& a, const Prepared& b, Vec3& x, double step, double inB,
  double stop, double sign = 1);

/// The distance between two shapes, one number for distance() and intersects() (which compares
/// it with the tolerance), so that the two never disagree: exact for analytic pairs and
/// similar spheres; otherwise alternating projections from the centres, 0 when the boxes find
/// a point inside both, and the alternating projections again from the most promising leaves
/// (where the boundaries nearly touch). Returns as soon as it is known to be <= `enough`.
double separation(const Prepared& a, const Prepared& b, double enough);

/// A single sphere placed by a similarity: its world centre and radius.
bool sphereSphere(const Prepared& s, Vec3& centre, double& radius);

} // namespace ictk::geometry::detail
