// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Progress and cancellation, the same for every long operation of the core (sampling, meshing,
// discretisation, tetrahedralisation, a dynamic model's run): OpenVDB's one-interrupter idea as a
// callback. The callback gets the done fraction in [0, 1], on the thread that called the
// operation; a false answer asks it to stop, and it then throws Cancelled, leaving what the caller
// passed in unchanged. The VTK layer maps it to UpdateProgress/AbortExecute
// (Modules/VTK/Common/ictkRequest.h); the CLI to its progress display and Ctrl-C.
//
// Users only set a Progress in an option struct. Operations never call it themselves: each wraps
// it in a ProgressScope, the one place that keeps the thread rule (the callback runs only on the
// thread that started the operation, since VTK's UpdateProgress/AbortExecute and GUIs are not for
// worker threads), maps nested work to its share of the range and turns a false answer into
// Cancelled. An empty callback costs nothing: no report, no cancellation.

#include <atomic>
#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <thread>

namespace ictk
{

/// The progress callback of every option struct; empty: no reports, no cancellation.
using Progress = std::function<bool(double)>;

/// Thrown by an operation whose progress callback asked it to stop.
class Cancelled : public std::runtime_error
{
public:
  explicit Cancelled(const std::string& what = "cancelled")
    : std::runtime_error(what)
  {
  }
};

/// One call of a long operation: built from its option struct's Progress on the thread that
/// called the operation (the calling thread), and alive for the whole call.
///
/// Sequential work calls report(fraction). A nested operation gets range(lo, hi) in its option
/// struct. A parallel loop takes items(count, lo, hi): every thread polls cancelled() before an
/// item and counts it with finished() after; the calling thread, which works in the loop too,
/// reports between its own items, and its report(hi) after the loop throws if the loop was
/// cancelled. finished() never throws, so a loop's body needs no exception to stop.
class ProgressScope
{
public:
  class Items;

  explicit ProgressScope(Progress progress);
  ProgressScope(const ProgressScope&) = delete;
  ProgressScope& operator=(const ProgressScope&) = delete;

  /// Reports that `fraction` of the operation is done; throws Cancelled if the callback answers
  /// false, or answered false before (the callback is then not asked again). On a thread other
  /// than the calling one it only throws if the operation was cancelled.
  void report(double fraction)
  {
    if (progress_ && !ask(fraction))
    {
      throw Cancelled();
    }
  }

  /// The same, with the text of the Cancelled made by what() (only when the operation stops).
  template <typename What>
  void report(double fraction, What&& what)
  {
    if (progress_ && !ask(fraction))
    {
      throw Cancelled(what());
    }
  }

  /// The callback for a nested operation's option struct: its fraction f is reported as
  /// lo + (hi - lo) f of this operation, and its stop request is this operation's. Empty when this
  /// scope's callback is; valid while this scope lives.
  Progress range(double lo, double hi);

  /// Whether the operation was asked to stop: any thread may poll it (one atomic read).
  bool cancelled() const noexcept { return cancelled_.load(std::memory_order_relaxed); }

  /// A parallel loop of `count` items that fills [lo, hi] of the operation (called on the
  /// calling thread, before the loop).
  Items items(std::int64_t count, double lo, double hi);

private:
  /// Asks the callback on the calling thread; false when the operation is (now) cancelled.
  bool ask(double fraction);

  Progress progress_;
  std::thread::id caller_;
  std::atomic<bool> cancelled_{ false };
};

/// The finished items of one parallel loop (see ProgressScope::items).
class ProgressScope::Items
{
public:
  Items(const Items&) = delete;
  Items& operator=(const Items&) = delete;

  /// Counts one finished item, from any thread. On the calling thread, once about 1% more of the
  /// loop is done since its last report, reports the loop's share; a false answer makes
  /// cancelled() true (the body then stops taking items; the report after the loop throws).
  void finished()
  {
    if (scope_.progress_)
    {
      count();
    }
  }

private:
  friend class ProgressScope;
  Items(ProgressScope& scope, std::int64_t count, double lo, double hi);
  void count();

  ProgressScope& scope_;
  std::int64_t total_;
  std::int64_t every_;
  double lo_;
  double hi_;
  std::atomic<std::int64_t> done_{ 0 };
  std::int64_t reported_ = 0; // read and written by the calling thread only
};

namespace frep
{
// The kernel's historical names, the same types.
using ictk::Cancelled;
using ictk::Progress;
} // namespace frep

} // namespace ictk
