// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// `ictk bench`: the performance workloads of issue 7 (prospero rendering, dense sampling against
// VTK), timed in this process; see docs/performance.md.

#include <CLI/CLI.hpp>

namespace ictk::app
{

/// Registers the `bench` subcommand (its options live in Bench.cxx).
CLI::App* AddBenchCommand(CLI::App& app);
/// Runs it with the parsed options; returns the exit code. Throws std::exception on a user error.
int RunBenchCommand();

} // namespace ictk::app
