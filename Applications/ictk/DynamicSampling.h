// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// `ictk sample MODEL.icm`: a dynamic model's cells sampled on a grid. The engine runs the model
// to --time as `ictk run` does, then every cell of the active instance that has a field is
// sampled (a space-time cell at its cross-section there), one array per cell and their union
// `f` (with --frames, at every time: a .pvd series); or, with --space-time, one 2D cell over the
// time range as a 3D volume whose z is t (the thesis's figures 93-95 of space-time objects).
// docs/icm.md, "Sampling a model".

#include <cstdint>
#include <string>

namespace ictk::cli
{

struct DynamicSampleOptions
{
  std::string Model;  ///< the .icm file
  std::string Output; ///< a .vti (a .pvd with --frames)
  std::string Cell;   ///< --cell: only this cell (empty: every cell with a field)
  std::string Bounds; ///< --bounds x0,x1,y0,y1,z0,z1 (z0,z1 the time range with --space-time)
  std::string Dims;   ///< --dims NX,NY,NZ
  std::string Frames; ///< --frames T0:T1:DT: a .pvd series of the cells at every time
  std::int64_t Resolution = 64;
  double Time = 0;
  bool TimeGiven = false; ///< without --time: the model's start
  bool SpaceTime = false;
  bool Double = false;
  double MaxStep = 0; ///< the engine's largest step; 0: the rule of `ictk run`
  int Threads = 0;    ///< the sampling's threads (0: the machine's)
};

/// Samples and writes the .vti; returns the exit code (UserError, lang::ParseError for the
/// model's errors with file:line:col).
int SampleDynamicModel(const DynamicSampleOptions& o);

} // namespace ictk::cli
