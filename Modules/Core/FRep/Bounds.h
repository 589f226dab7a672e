// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// A box that holds a model, found by interval arithmetic: every sub-box where the interval of f
// is certainly negative is outside, so the union of the other sub-boxes holds the solid.

#include "FRep/Evaluators.h"
#include "FRep/Field.h"

#include <array>
#include <optional>

namespace ictk::frep
{

/// The boxes of Field.h (one box type for the kernel).
using Box = Box3;

/// A box inside `search` that contains every point of `search` where f may be >= 0 (at time
/// `time`), refined by `depth` octree subdivisions; nullopt when the model is certainly empty
/// there. Conservative: the solid never extends beyond it inside `search` (a solid that is
/// unbounded gives the search box on the unbounded sides).
std::optional<Box> boundingBox(const TapePtr& tape, const Box& search, int depth = 6,
  double time = 0, const std::vector<double>& parameters = {});

} // namespace ictk::frep
