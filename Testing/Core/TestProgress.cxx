// SPDX-License-Identifier: BSD-3-Clause
// ProgressScope (FRep/Progress.h), the one progress and cancellation mechanism of the core's long
// operations: shares of the range, one Cancelled per stop request, the callback only on the
// calling thread, nothing at all for an empty callback.

#include "FRep/Progress.h"

#include <gtest/gtest.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <thread>
#include <vector>

using ictk::Cancelled;
using ictk::Progress;
using ictk::ProgressScope;

TEST(Progress, RangesMapToTheirShareOfTheParent)
{
  std::vector<double> seen;
  ProgressScope outer(
    [&](double f)
    {
      seen.push_back(f);
      return true;
    });
  outer.report(0.1);
  // A nested operation filling [0.2, 0.6] of the outer one, and one nested in it filling the
  // second half of that: 0.2 + 0.4 * (0.5 + 0.5 * f).
  Progress middle = outer.range(0.2, 0.6);
  middle(0.5);
  {
    ProgressScope inner(middle);
    Progress innermost = inner.range(0.5, 1);
    innermost(0);
    innermost(0.5);
    innermost(1);
  }
  outer.report(1);
  const std::vector<double> expected{ 0.1, 0.4, 0.4, 0.5, 0.6, 1 };
  ASSERT_EQ(seen.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i)
  {
    EXPECT_DOUBLE_EQ(seen[i], expected[i]) << i;
  }
}

TEST(Progress, AFalseAnswerThrowsCancelledOnce)
{
  int calls = 0;
  ProgressScope scope(
    [&](double f)
    {
      ++calls;
      return f < 0.5;
    });
  EXPECT_NO_THROW(scope.report(0.25));
  EXPECT_FALSE(scope.cancelled());
  EXPECT_THROW(scope.report(0.5), Cancelled);
  EXPECT_TRUE(scope.cancelled());
  EXPECT_EQ(calls, 2);
  // The stop request stands: later reports and nested callbacks do not ask again.
  EXPECT_THROW(scope.report(0.75), Cancelled);
  EXPECT_FALSE(scope.range(0.5, 1)(0));
  ProgressScope::Items items = scope.items(10, 0, 1);
  for (int i = 0; i < 10; ++i)
  {
    items.finished();
  }
  EXPECT_EQ(calls, 2);
  // The text of the Cancelled, made only when the operation stops.
  int made = 0;
  ProgressScope run([](double f) { return f < 0.5; });
  run.report(0.25,
    [&]
    {
      ++made;
      return std::string("never");
    });
  EXPECT_EQ(made, 0);
  try
  {
    run.report(0.5, [] { return std::string("the run was cancelled at t = 2"); });
    FAIL();
  }
  catch (const Cancelled& e)
  {
    EXPECT_STREQ(e.what(), "the run was cancelled at t = 2");
  }
}

TEST(Progress, TheEmptyCallbackReportsNothingAndNeverCancels)
{
  ProgressScope scope{ Progress{} };
  EXPECT_FALSE(scope.range(0, 0.5)); // nested operations get no callback either
  EXPECT_NO_THROW(scope.report(0.5));
  ProgressScope::Items items = scope.items(3, 0, 1);
  items.finished();
  EXPECT_FALSE(scope.cancelled());
  EXPECT_NO_THROW(scope.report(1));
}

TEST(Progress, WorkerThreadsNeverCallTheCallback)
{
  const std::thread::id caller = std::this_thread::get_id();
  std::atomic<int> foreign{ 0 };
  std::vector<double> seen;
  ProgressScope scope(
    [&](double f)
    {
      if (std::this_thread::get_id() != caller)
      {
        ++foreign;
      }
      seen.push_back(f); // unsynchronised on purpose: only the calling thread may get here
      return true;
    });
  constexpr std::int64_t count = 20000;
  ProgressScope::Items items = scope.items(count, 0, 0.9);
  std::atomic<std::int64_t> done{ 0 };
  tbb::task_arena arena(4);
  arena.execute(
    [&]
    {
      tbb::parallel_for(tbb::blocked_range<std::int64_t>(0, count, 1),
        [&](const tbb::blocked_range<std::int64_t>& range)
        {
          for (std::int64_t i = range.begin(); i != range.end(); ++i)
          {
            ++done;
            items.finished();
            // A report from a worker only polls the stop request.
            scope.report(0.5);
          }
        });
    });
  scope.report(0.9);
  EXPECT_EQ(done, count);
  EXPECT_EQ(foreign, 0);
  ASSERT_GE(seen.size(), 2u);
  EXPECT_DOUBLE_EQ(seen.back(), 0.9);
  for (double f : seen)
  {
    EXPECT_GE(f, 0);
    EXPECT_LE(f, 0.9);
  }
}

TEST(Progress, AStopRequestReachesTheWorkers)
{
  // The calling thread's report answered false: the workers see cancelled() and stop taking
  // items; only the report after the loop throws.
  std::atomic<bool> sawStop{ false };
  ProgressScope scope([](double) { return false; });
  ProgressScope::Items items = scope.items(100000, 0, 1);
  tbb::task_arena arena(4);
  std::atomic<std::int64_t> ran{ 0 };
  arena.execute(
    [&]
    {
      tbb::parallel_for(tbb::blocked_range<std::int64_t>(0, 100000, 1),
        [&](const tbb::blocked_range<std::int64_t>& range)
        {
          for (std::int64_t i = range.begin(); i != range.end(); ++i)
          {
            if (scope.cancelled())
            {
              sawStop = true;
              return;
            }
            ++ran;
            items.finished();
          }
        });
    });
  EXPECT_TRUE(sawStop);
  EXPECT_LT(ran, 100000);
  EXPECT_THROW(scope.report(1), Cancelled);
}
