// SPDX-License-Identifier: BSD-3-Clause
#include "Complex/Validation.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace ictk::complex
{
namespace
{

std::string point(const Point3& p)
{
  char buffer[96];
  std::snprintf(buffer, sizeof buffer, "(%.6g, %.6g, %.6g)", p[0], p[1], p[2]);
  return buffer;
}

std::string relationName(RelationKind kind, int p, int s)
{
  return std::string(kind == RelationKind::Boundary ? "Rb^{" : "Rc^{") + std::to_string(p) +
    std::to_string(s) + "}";
}

/// The solid {min inside >= 0} of an implicit 3D cell, or nullptr.
frep::FieldPtr solidField(const Cell& c)
{
  const auto* g = std::get_if<ImplicitGeometry>(&c.geometry);
  if (!g || c.dimension != 3 || g->inside.empty())
  {
    return nullptr;
  }
  return g->inside.size() == 1 ? g->inside[0] : frep::minField(g->inside);
}

/// Searches the box for a point of solid s farther than `tolerance` outside solid p, proving
/// by interval arithmetic that the boxes it skips hold none. Returns true with the witness when
/// one is found.
bool findEscape(frep::FieldEvaluator& s, frep::FieldEvaluator& p, CellLocator& pLocator,
  const Box3& box, double tolerance, int depth, Point3& witness, double& deviation)
{
  const frep::Interval is = s.bound(box);
  if (is.negative() && !is.maybeNaN)
  {
    return false; // no point of s here
  }
  const frep::Interval ip = p.bound(box);
  if (ip.lo >= 0 && !ip.maybeNaN)
  {
    return false; // all of the box is inside p
  }
  const Point3 c = box.centre();
  if (depth == 0)
  {
    if (s.value(c) >= 0)
    {
      const double d = pLocator.distance(c);
      if (d > tolerance)
      {
        witness = c;
        deviation = d;
        return true;
      }
    }
    return false;
  }
  for (int octant = 0; octant < 8; ++octant)
  {
    Box3 child;
    for (int a = 0; a < 3; ++a)
    {
      const bool upper = (octant >> a) & 1;
      child.lo[a] = upper ? c[a] : box.lo[a];
      child.hi[a] = upper ? box.hi[a] : c[a];
    }
    if (findEscape(s, p, pLocator, child, tolerance, depth - 1, witness, deviation))
    {
      return true;
    }
  }
  return false;
}

} // namespace

bool boundaryHolds(
  CellLocator& p, CellLocator& s, double tolerance, std::size_t samples, RelationFinding* finding)
{
  double worst = -1;
  Point3 at{ 0, 0, 0 };
  for (const Point3& x : s.samples(samples))
  {
    const double d = p.boundaryDistance(x);
    if (!(d <= worst))
    {
      worst = d;
      at = x;
    }
  }
  if (finding)
  {
    finding->deviation = worst;
    finding->witness = at;
  }
  return worst >= 0 && worst <= tolerance;
}

bool containmentHolds(CellLocator& p, CellLocator& s, double tolerance, std::size_t samples,
  RelationFinding* finding, int intervalDepth)
{
  double worst = -1;
  Point3 at{ 0, 0, 0 };
  bool offBoundary = false;
  for (const Point3& x : s.samples(samples))
  {
    const double d = p.distance(x);
    if (!(d <= worst))
    {
      worst = d;
      at = x;
    }
    offBoundary = offBoundary || p.boundaryDistance(x) > tolerance;
  }
  bool holds = worst >= 0 && worst <= tolerance;
  std::string reason;
  if (holds)
  {
    // For two FRep solids, prove by intervals that no part of s pokes out of p between samples.
    const frep::FieldPtr fs = solidField(s.cell());
    const frep::FieldPtr fp = solidField(p.cell());
    if (fs && fp)
    {
      auto es = fs->evaluator();
      auto ep = fp->evaluator();
      Point3 witness;
      double deviation = 0;
      if (findEscape(*es, *ep, p, s.cell().bounds(), tolerance, intervalDepth, witness, deviation))
      {
        holds = false;
        worst = deviation;
        at = witness;
        reason = "part of the contained cell lies outside the container";
      }
    }
  }
  if (holds && !offBoundary)
  {
    holds = false;
    reason = "the cell lies entirely on the container's boundary (a boundary pair, not "
             "containment)";
  }
  if (finding)
  {
    finding->deviation = worst;
    finding->witness = at;
    finding->reason = reason;
  }
  return holds;
}

ValidationReport validateComplex(
  const Complex& complex, const ComplexMesh& mesh, const ValidationOptions& options)
{
  ValidationReport report;
  report.tolerance = options.tolerance > 0 ? options.tolerance : 0.25 * mesh.featureSize;
  const double tol = report.tolerance;
  std::vector<CellId> ids = complex.cellIds();
  std::map<CellId, CellLocator> locators;
  for (CellId id : ids)
  {
    locators.emplace(id, CellLocator(complex.cell(id), mesh.of(id)));
  }
  auto check = [&](RelationKind kind, CellId a, CellId b, RelationFinding& f)
  {
    f.kind = kind;
    f.first = a;
    f.second = b;
    CellLocator& pa = locators.at(a);
    CellLocator& sb = locators.at(b);
    return kind == RelationKind::Boundary
      ? boundaryHolds(pa, sb, tol, options.samplesPerCell, &f)
      : containmentHolds(pa, sb, tol, options.samplesPerCell, &f, options.intervalDepth);
  };
  for (CellId a : ids)
  {
    const Cell& p = complex.cell(a);
    for (CellId b : ids)
    {
      if (a == b)
      {
        continue;
      }
      const Cell& s = complex.cell(b);
      for (RelationKind kind : { RelationKind::Boundary, RelationKind::Containment })
      {
        const bool possible = kind == RelationKind::Boundary
          ? s.dimension < p.dimension
          : s.dimension <= p.dimension && p.isImplicit();
        if (!possible)
        {
          continue;
        }
        const bool declared =
          kind == RelationKind::Boundary ? complex.hasBoundary(a, b) : complex.hasContainment(a, b);
        if (!declared && !options.findUndeclared)
        {
          continue;
        }
        // An undeclared containment is not reported for a pair declared as boundary, and the
        // other way round: the pair is already accounted for.
        if (!declared && (complex.hasBoundary(a, b) || complex.hasContainment(a, b)))
        {
          continue;
        }
        RelationFinding f;
        const bool holds = check(kind, a, b, f);
        if (declared)
        {
          (holds ? report.satisfied : report.violated).push_back(f);
        }
        else if (holds)
        {
          report.undeclared.push_back(f);
        }
      }
    }
  }
  return report;
}

std::string ValidationReport::text(const Complex& complex) const
{
  std::ostringstream out;
  auto line = [&](const char* what, const RelationFinding& f)
  {
    const Cell& p = complex.cell(f.first);
    const Cell& s = complex.cell(f.second);
    out << what << ' ' << relationName(f.kind, p.dimension, s.dimension) << " ('" << p.name
        << "', '" << s.name << "'): deviation " << f.deviation << " at " << point(f.witness);
    if (!f.reason.empty())
    {
      out << ": " << f.reason;
    }
    out << '\n';
  };
  out << "tolerance " << tolerance << '\n';
  for (const auto& f : violated)
  {
    line("violated", f);
  }
  for (const auto& f : undeclared)
  {
    line("holds but not declared", f);
  }
  out << satisfied.size() << " declared pair(s) hold, " << violated.size() << " violated, "
      << undeclared.size() << " undeclared pair(s) hold\n";
  return out.str();
}

} // namespace ictk::complex
