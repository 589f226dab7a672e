// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The one way a core operation runs its TBB work on the threads its options ask for: `threads` >
// 0 runs it in an arena of exactly that many threads, 0 on TBB's default (every core). The
// operations' results never depend on the count (each writes its own slots and merges in a fixed
// order), only their speed; the VTK layer and the CLI pass their NumberOfThreads / --threads here.

#include <tbb/task_arena.h>

#include <utility>

namespace ictk
{

/// Calls `work()` (which runs TBB's parallel algorithms) on `threads` threads (0: TBB's default).
template <class Work>
void runOnThreads(int threads, Work&& work)
{
  if (threads > 0)
  {
    tbb::task_arena arena(threads);
    arena.execute(std::forward<Work>(work));
  }
  else
  {
    std::forward<Work>(work)();
  }
}

} // namespace ictk
