// SPDX-License-Identifier: BSD-3-Clause
#include "Complex/Attachment.h"

#include <algorithm>

namespace ictk::complex
{

AttachResult attachCell(Complex& complex, Cell cell, const AttachOptions& options)
{
  std::vector<CellId> existing = complex.cellIds();
  AttachResult result;
  result.id = complex.addCell(std::move(cell));
  const Cell& g = complex.cell(result.id);

  DiscretizationOptions discretization = options.discretization;
  if (discretization.featureSize <= 0)
  {
    const Box3 b = complexBounds(complex);
    double side = 0;
    for (int a = 0; a < 3; ++a)
    {
      side = std::max(side, b.hi[a] - b.lo[a]);
    }
    discretization.featureSize = side > 0 ? side / 64 : 1.0 / 64;
  }
  const double tol = options.tolerance > 0 ? options.tolerance : 0.25 * discretization.featureSize;

  CellMesh gMesh = discretizeCell(complex, result.id, discretization);
  CellLocator gLocator(g, gMesh);
  for (CellId id : existing)
  {
    const Cell& c = complex.cell(id);
    CellMesh cMesh = discretizeCell(complex, id, discretization);
    CellLocator cLocator(c, cMesh);
    bool onBoundary = false;
    if (c.dimension < g.dimension && boundaryHolds(gLocator, cLocator, tol, options.samplesPerCell))
    {
      complex.addBoundary(result.id, id);
      result.boundaryPairs.emplace_back(result.id, id);
      onBoundary = true;
    }
    // Beyond seed 001 (which attaches in increasing dimension only): a new cell on the
    // boundary of an existing higher-dimensional cell is recorded too, so the order of
    // attachment does not change the complex.
    bool onItsBoundary = false;
    if (c.dimension > g.dimension && boundaryHolds(cLocator, gLocator, tol, options.samplesPerCell))
    {
      complex.addBoundary(id, result.id);
      result.boundaryPairs.emplace_back(id, result.id);
      onItsBoundary = true;
    }
    if (!onItsBoundary && c.isImplicit() && c.dimension >= g.dimension &&
      containmentHolds(cLocator, gLocator, tol, options.samplesPerCell))
    {
      complex.addContainment(id, result.id);
      result.containmentPairs.emplace_back(id, result.id);
    }
    if (!onBoundary && g.isImplicit() && c.dimension <= g.dimension &&
      containmentHolds(gLocator, cLocator, tol, options.samplesPerCell))
    {
      complex.addContainment(result.id, id);
      result.containmentPairs.emplace_back(result.id, id);
    }
  }
  return result;
}

std::map<CellId, CellId> attachComplex(
  Complex& complex, const Complex& part, const std::map<CellId, CellId>& psi)
{
  // Check the whole map before changing anything, so a bad map leaves the complex as it was.
  for (const auto& [from, to] : psi)
  {
    if (!part.hasCell(from))
    {
      throw ComplexError(
        "attachment map: the attached complex has no cell with id " + std::to_string(from));
    }
    if (!complex.hasCell(to))
    {
      throw ComplexError("attachment map: the complex has no cell with id " + std::to_string(to) +
        " (the image of '" + part.cell(from).name + "')");
    }
    if (part.cell(from).dimension != complex.cell(to).dimension)
    {
      throw ComplexError("attachment map: '" + part.cell(from).name + "' (" +
        std::to_string(part.cell(from).dimension) + "D) cannot be identified with '" +
        complex.cell(to).name + "' (" + std::to_string(complex.cell(to).dimension) + "D)");
    }
  }
  std::vector<CellId> added;
  for (int p = 0; p <= 3; ++p)
  {
    for (CellId id : part.cellsOfDimension(p))
    {
      if (!psi.count(id) && complex.findCell(part.cell(id).name))
      {
        throw ComplexError("attachment: a cell named '" + part.cell(id).name +
          "' is already in the complex; rename it or map it through psi");
      }
    }
  }
  std::map<CellId, CellId> map = psi;
  for (int p = 0; p <= 3; ++p)
  {
    for (CellId id : part.cellsOfDimension(p))
    {
      if (map.count(id))
      {
        continue;
      }
      Cell copy = part.cell(id);
      for (CellId& operand : copy.operands)
      {
        operand = map.at(operand);
      }
      map[id] = complex.addCell(std::move(copy));
    }
  }
  for (const auto& [name, defaults] : part.attributes())
  {
    if (!complex.attributes().count(name))
    {
      complex.declareAttribute(name, defaults);
    }
  }
  for (int p = 0; p <= 3; ++p)
  {
    for (int s = 0; s < p; ++s)
    {
      for (const auto& [a, b] : part.boundary(p, s).pairs())
      {
        if (!complex.hasContainment(map.at(a), map.at(b)))
        {
          complex.addBoundary(map.at(a), map.at(b));
        }
      }
    }
    for (int s = 0; s <= p; ++s)
    {
      for (const auto& [a, b] : part.containment(p, s).pairs())
      {
        if (!complex.hasBoundary(map.at(a), map.at(b)))
        {
          complex.addContainment(map.at(a), map.at(b));
        }
      }
    }
  }
  return map;
}

} // namespace ictk::complex
