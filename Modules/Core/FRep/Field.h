// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// A scalar field of E^3 at a fixed time, whatever represents it (a compiled FRep tape, a voxel
// grid, a combination of cells). Discretisers and validators are written against this interface,
// so every cell kind gets the same meshing, tracing and checking code (libfive's split of a shape
// from its per-thread evaluators).
//
// A Field is immutable and shared between threads. Each thread asks it for its own
// FieldEvaluator, which holds scratch memory and is not thread safe.

#include "FRep/Interval.h"
#include "FRep/Tape.h"
#include "FRep/Vector.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

namespace ictk::frep
{

/// An axis-aligned box of E^3.
struct Box3
{
  Point3 lo{ 0, 0, 0 };
  Point3 hi{ 0, 0, 0 };
  Point3 centre() const
  {
    return { 0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2]) };
  }
  bool valid() const { return lo[0] <= hi[0] && lo[1] <= hi[1] && lo[2] <= hi[2]; }
};

class FieldEvaluator
{
public:
  virtual ~FieldEvaluator() = default;
  /// f at n points given as separate coordinate arrays.
  virtual void values(
    const double* x, const double* y, const double* z, double* out, std::size_t n) = 0;
  double value(const Point3& p)
  {
    double v = 0;
    values(&p[0], &p[1], &p[2], &v, 1);
    return v;
  }
  /// An enclosure of f over the box (every non-NaN value lies in it; maybeNaN as Interval says).
  virtual Interval bound(const Box3& box) = 0;
  /// f and its gradient at p.
  virtual double gradient(const Point3& p, Point3& grad) = 0;
  /// An evaluator that gives the same values as this one inside `box` and may be cheaper there
  /// (a tape pruned by interval arithmetic). nullptr when nothing is gained: keep using this one.
  virtual std::unique_ptr<FieldEvaluator> narrowed(const Box3& box)
  {
    (void)box;
    return nullptr;
  }
  /// Appends to `out` words that determine what this evaluator computes: two evaluators whose
  /// fingerprints are equal give bit-identical values, bounds, gradients and narrowed evaluators
  /// for identical calls (a tape's instructions, constants and the parameter values and time it
  /// reads, an operation and its operands' fingerprints, a placement's coefficients). Time
  /// coherence relies on it to reuse the work done on a region whose field did not change
  /// (discretize::SurfaceMemory), so it must describe everything the results depend on; words
  /// that do not matter only cost reuse. Returns false, leaving `out` in an unspecified state,
  /// when the evaluator cannot describe itself (the default): then nothing may be reused.
  virtual bool fingerprint(std::vector<std::uint64_t>& out) const
  {
    (void)out;
    return false;
  }
};

/// Fingerprint words (FieldEvaluator::fingerprint): a double by its bits, so that equal words mean
/// equal values (and -0 differs from 0, NaNs by payload: only reuse is lost).
std::uint64_t fingerprintWord(double v);
/// Appends `tape`'s fingerprint: its instructions, outputs, constants, and the values of the
/// parameters and of t it reads (a parameter no instruction reads does not change the results).
void appendTapeFingerprint(const Tape& tape, double time, const std::vector<double>& parameters,
  std::vector<std::uint64_t>& out);

class Field;
using FieldPtr = std::shared_ptr<const Field>;

/// A field that is the min or max of two fields: the intersection or union of their solids.
struct FieldSplit
{
  /// true: min (intersection); false: max (union).
  bool minimum = true;
  FieldPtr a;
  FieldPtr b;
};

class Field
{
public:
  virtual ~Field() = default;
  virtual std::unique_ptr<FieldEvaluator> evaluator() const = 0;
  /// The min or max at the root of this field, when it is one: the solid's sharp edges lie where
  /// two of the operands vanish, which no sampling of the field itself pins down.
  virtual std::optional<FieldSplit> split() const { return std::nullopt; }
};

/// The field of a tape's first output at time `time` (x, y, z vary; t fixed) with the given
/// parameter values. The evaluators prune the tape by interval arithmetic in narrowed().
FieldPtr tapeField(TapePtr tape, double time = 0, std::vector<double> parameters = {});

/// g(x) = -f(x): the complement of a solid, or a cell's inside flipped.
FieldPtr negatedField(FieldPtr f);
/// min / max of several fields: the intersection / union of their solids (exact in intervals).
FieldPtr minField(std::vector<FieldPtr> fields);
FieldPtr maxField(std::vector<FieldPtr> fields);

} // namespace ictk::frep
