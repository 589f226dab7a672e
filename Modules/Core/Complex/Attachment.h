// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Constructive building of a complex (seed 001 L120-128): cell attachment, which adds a cell and
// derives its boundary and containment pairs from geometry, and complex attachment, which joins
// a complex along a shared subcomplex through an attachment map psi.

#include "Complex/Validation.h"

#include <map>

namespace ictk::complex
{

struct AttachOptions
{
  DiscretizationOptions discretization;
  /// Distance within which a point counts as on a set; 0 = a quarter of the feature size.
  double tolerance = 0;
  std::size_t samplesPerCell = 256;
};

struct AttachResult
{
  CellId id = 0;
  std::vector<std::pair<CellId, CellId>> boundaryPairs;    ///< added to Rb
  std::vector<std::pair<CellId, CellId>> containmentPairs; ///< added to Rc
};

/// Cell attachment (seed 001 L124): adds `cell` to `complex`, then (1) for every cell c of lower
/// dimension on the boundary of the new cell g adds (g, c) to Rb; (2) for every implicit cell c
/// of dimension >= dim g that contains g adds (c, g) to Rc; (3) when g is implicit, for every
/// cell c of dimension <= dim g inside g adds (g, c) to Rc. A pair found by (1) is never also
/// added by (3). Explicit cells contain nothing. Beyond the seed, which attaches cells in
/// increasing dimension, (c, g) is added to Rb when g lies on the boundary of an existing
/// higher-dimensional cell c, so the order of attachment does not matter.
AttachResult attachCell(Complex& complex, Cell cell, const AttachOptions& options = {});

/// Complex attachment (seed 001 L126-128): K_i = K_{i-1} u L / ~psi. `psi` maps cells of the
/// shared subcomplex C in `part` to their equivalent cells in `complex`; every other cell of
/// `part` is added, in increasing dimension, and the relations of `part` are carried over through
/// the map. Returns the map from every cell of `part` to its cell in `complex`. Throws
/// ComplexError when psi names a missing cell, maps cells of different dimensions, or when a new
/// cell's name is already taken.
std::map<CellId, CellId> attachComplex(
  Complex& complex, const Complex& part, const std::map<CellId, CellId>& psi);

} // namespace ictk::complex
