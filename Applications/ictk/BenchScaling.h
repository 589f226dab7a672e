// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// `ictk bench --scaling`: how the cost of sampling, pruned rendering and dual contouring grows
// with the model size (random CSG of 100 to 100k tape instructions) and with the resolution;
// see docs/performance.md, section Scaling.

#include <CLI/CLI.hpp>

namespace ictk::cli
{

/// Adds --scaling (and its options) to the `bench` subcommand.
void AddScalingOptions(CLI::App& bench);
/// True when --scaling was given.
bool ScalingRequested();
/// True when --scale-point was given.
bool ScalePointRequested();
/// Runs the one measurement --scale-point names and prints it as one JSON line; returns the exit
/// code. `threads` 0 means 1 thread.
int RunScalePoint(int threads);
/// Prints the scaling tables (or JSON); returns the exit code. `threads` 0 means 1 thread.
int RunScalingBench(int runs, int threads, bool json, bool quick);

} // namespace ictk::cli
