// SPDX-License-Identifier: BSD-3-Clause
// Roots of a scalar function of one variable: refineRoot() (Illinois), locateCrossing()
// (sampling, Illinois, golden section for touches) and the golden-section minimiser
// goldenSection() that locateCrossing and Geometry's nearest points share (Geometry/Curves.h
// goldenMinimum). Numerics, not time or geometry, so it sits in
// the kernel below both of its users: Dynamics locates transitions in time with it (issue 5:
// "transitions located in time ... so that instantaneous states such as the tangency in thesis 5.1
// are found, not skipped by a coarse step"), and Geometry refines meeting points along a curve's
// parameter (Geometry/MeetingPoints.cxx). The variable is called t and "time" below, as in its
// first use.
//
// Given a scalar g(t) over the model state (a signed distance, an overlap area minus a target...)
// and a step [t0, t1], locateCrossing() returns the earliest time in (t0, t1] where g reaches 0:
//  1. Sampling: g is evaluated at n + 1 equally spaced times t0 = s_0 < ... < s_n = t1
//     (LocateOptions::samples = n), because two end samples cannot see a touch inside the step.
//  2. Sign change: at the first pair with g(s_i) g(s_i+1) < 0 (or an exact zero), the root is
//     refined by the Illinois variant of regula falsi (secant steps that keep a bracket; the
//     retained end's value is halved when it is kept twice, which restores superlinear
//     convergence; a secant point within timeTolerance / 2 of an end is moved that far inside,
//     so that the step after a converged one closes the bracket) until the bracket is shorter
//     than `timeTolerance` or |g| <= `valueTolerance`. A linear g is solved by the first secant
//     step exactly (up to rounding).
//  3. Touch (an instantaneous tangency, g >= 0 touching 0 without changing sign): if no sign
//     change precedes it and an interior sample s_i is a local minimum of |g| (|g(s_i)| <=
//     |g(s_i-1)| and |g(s_i)| <= |g(s_i+1)|), |g| is minimised on [s_i-1, s_i+1] by golden-section
//     search to `timeTolerance`. If the minimum is <= `touchTolerance` a Touch is reported at its
//     argument; if a sample of opposite sign is met on the way, the search becomes a bracket and
//     step 2 runs. The end sample s_n counts as a touch when |g(s_n)| <= touchTolerance.
//     Near a tangency g ~ c (t - t*)^2, so rounding makes |g| flat (exactly 0) within about
//     sqrt(machine epsilon / c) of t* (~1e-8 for c ~ 1) and the golden section stops anywhere on
//     that plateau. The result is then corrected by the vertex of the parabola through g at
//     tm - h, tm, tm + h, h = 1e-4 of the bracket (exact for a quadratic g; for a smooth
//     symmetric touch the error is far below the plateau width).
// A step that starts on a zero (|g(t0)| <= touchTolerance) does not report it again: that event
// was the end of the previous step (so a stepper can resume from a located transition).
// Limitations: a touch whose |g| minimum is not bracketed by the samples (a narrower dip than the
// sample spacing) is missed; raise `samples` for such models.
#pragma once

#include <functional>
#include <optional>

namespace ictk::frep
{

struct LocateOptions
{
  int samples = 8;
  double timeTolerance = 1e-12;
  double valueTolerance = 0.0;
  double touchTolerance = 1e-9;
  int maxIterations = 200;
};

struct Crossing
{
  enum class Kind
  {
    SignChange,
    Touch
  };
  Kind kind = Kind::SignChange;
  double time = 0.0;
  double value = 0.0; ///< g(time)
  int evaluations = 0;
};

/// How goldenSection() searches.
struct GoldenSectionOptions
{
  int maxIterations = 80;
  /// The search stops once the bracket [a, b] is no wider than `tolerance`, or with `relative`
  /// than tolerance * (1 + |a| + |b|).
  double tolerance = 1e-15;
  bool relative = true;
  /// Minimise |f| instead of f (the values reported are still f's).
  bool magnitude = false;
  /// Asked of both inner points, (x, f(x)), before each step; true ends the search at that point
  /// (locateCrossing stops where |g| is minimised as soon as g changes sign: a bracket).
  std::function<bool(double, double)> stop;
};

/// The result of goldenSection().
struct GoldenSection
{
  double x = 0.0;       ///< the inner point with the smaller value, or the one `stop` held at
  double value = 0.0;   ///< f(x)
  bool stopped = false; ///< `stop` held at x
  int evaluations = 0;  ///< of f
};

/// A minimum of f (or of |f|) on [a, b] by golden-section search; f is assumed unimodal there.
GoldenSection goldenSection(const std::function<double(double)>& f, double a, double b,
  const GoldenSectionOptions& options = {});

/// Refines a root of g in [a, b] where g(a) and g(b) have opposite signs (Illinois).
double refineRoot(const std::function<double(double)>& g, double a, double ga, double b, double gb,
  const LocateOptions& options, int* evaluations = nullptr);

/// The earliest zero of g in (t0, t1] (see the file comment), or nothing.
std::optional<Crossing> locateCrossing(
  const std::function<double(double)>& g, double t0, double t1, const LocateOptions& options = {});

} // namespace ictk::frep
