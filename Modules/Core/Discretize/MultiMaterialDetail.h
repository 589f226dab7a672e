// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Internal to the Discretize library: the pieces of multiMaterialSurface (MultiMaterial.h),
// shared by the files that implement it, one phase each:
//  - MultiMaterial.cxx: the checks, the label of every grid point (sampled only in the blocks
//    whose interval bounds allow more than one label), the assembly and the regions;
//  - MultiMaterialTetra.cxx: the triangles of each tetrahedron of the Kuhn split, as keys of the
//    vertices they join (the topology, before any position);
//  - MultiMaterialVertices.cxx: where each vertex goes (bisection on edges, the triple line on
//    faces, the mean inside tetrahedra).
// Not installed (PRIVATE_HEADERS in CMakeLists.txt): its declarations may change freely.

#include "Discretize/MultiMaterial.h"
#include "FRep/Sampling.h"
#include "FRep/Vector.h"

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <limits>
#include <memory>
#include <vector>

namespace ictk::discretize::detail::material
{

using frep::FieldEvaluator;
using Label = std::int16_t;
constexpr std::uint64_t kNone = std::numeric_limits<std::uint64_t>::max();

using frep::cross;
using frep::dot;
using frep::lerp;
using frep::sub;

// Where the grid samples the inside of the box on each axis: at box.lo + (i - phase) h for
// i = 1..m, plus the box faces themselves. Planes at multiples of h from box.lo thus never pass
// through grid points, and the phases differ per axis so that grid diagonals do not cross such
// planes where two of them meet.
constexpr double kPhase[3] = { 0.5, 0.4, 0.6 };

/// A vertex: the sorted grid points of its grid point (1), edge (2), face (3) or tetrahedron
/// (4), kNone-padded.
struct VKey
{
  std::array<std::uint64_t, 4> v{ kNone, kNone, kNone, kNone };
  int size() const { return v[3] != kNone ? 4 : (v[2] != kNone ? 3 : (v[1] != kNone ? 2 : 1)); }
  bool operator<(const VKey& o) const { return v < o.v; }
  bool operator==(const VKey& o) const { return v == o.v; }
};

inline VKey makeKey(std::initializer_list<std::uint64_t> ids)
{
  VKey k;
  std::size_t i = 0;
  for (auto id : ids)
  {
    k.v[i++] = id;
  }
  std::sort(k.v.begin(), k.v.begin() + static_cast<std::ptrdiff_t>(i));
  return k;
}

struct Tri
{
  std::array<VKey, 3> key;
  std::array<std::int32_t, 2> labels;
};

struct BlockOut
{
  std::vector<Tri> triangles;
  std::vector<MaterialOverlap> overlaps;
};

struct Grid
{
  std::array<std::int64_t, 3> n{}; // points per axis (interior + the two box faces)
  Point3 lo{}, hi{}, h{};
  double coord(int a, std::int64_t i) const
  {
    return i == 0 ? lo[a]
                  : (i == n[a] - 1 ? hi[a] : lo[a] + (static_cast<double>(i) - kPhase[a]) * h[a]);
  }
  std::uint64_t index(std::int64_t i, std::int64_t j, std::int64_t k) const
  {
    return static_cast<std::uint64_t>((k * n[1] + j) * n[0] + i);
  }
  std::array<std::int64_t, 3> ijk(std::uint64_t p) const
  {
    const auto q = static_cast<std::int64_t>(p);
    return { q % n[0], (q / n[0]) % n[1], q / (n[0] * n[1]) };
  }
  Point3 point(std::uint64_t p) const
  {
    const auto c = ijk(p);
    return { coord(0, c[0]), coord(1, c[1]), coord(2, c[2]) };
  }
  bool onBox(std::int64_t i, std::int64_t j, std::int64_t k) const
  {
    return i == 0 || j == 0 || k == 0 || i == n[0] - 1 || j == n[1] - 1 || k == n[2] - 1;
  }
  bool onBox(std::uint64_t p) const
  {
    const auto c = ijk(p);
    return onBox(c[0], c[1], c[2]);
  }
};

/// Label ranks: rank(label) grows with priority, ties to the lower index, outside (0) lowest.
struct Ranking
{
  std::vector<int> order;       // solids, winner first
  std::vector<int> rankOfLabel; // by label (0 = outside)
  bool beats(int a, int b) const { return rankOfLabel[a] > rankOfLabel[b]; }
};

inline bool insideValue(double v)
{
  return v >= 0; // NaN is outside
}

struct Evaluators
{
  explicit Evaluators(const std::vector<frep::FieldPtr>& solids)
    : fields(&solids)
    , e(solids.size())
  {
  }
  FieldEvaluator& of(int solid)
  {
    auto& p = e[static_cast<std::size_t>(solid)];
    if (!p)
    {
      p = (*fields)[static_cast<std::size_t>(solid)]->evaluator();
    }
    return *p;
  }
  const std::vector<frep::FieldPtr>* fields;
  std::vector<std::unique_ptr<FieldEvaluator>> e;
};

/// The index of `key` in the sorted, unique `keys` (which hold it).
inline std::uint32_t keyIndex(const std::vector<VKey>& keys, const VKey& key)
{
  return static_cast<std::uint32_t>(std::lower_bound(keys.begin(), keys.end(), key) - keys.begin());
}

/// The triangles of the cells f0..f0+ext-1 (grid point indices) whose corners do not all have
/// one label, and the box caps of those on the box, appended to `triangles` as vertex keys, each
/// oriented from its lower label to its higher one.
void triangulateBlock(const Grid& g, const std::vector<Label>& labels,
  const std::array<std::int64_t, 3>& f0, const std::array<std::int64_t, 3>& ext,
  std::vector<Tri>& triangles);

/// The positions of the vertices `keys` (sorted, unique): grid points as they are, edge vertices
/// by bisection on the winning label's field, face vertices on the triple line, tetrahedron
/// vertices at the mean of their face vertices. Identical for any thread count.
std::vector<Point3> placeVertices(const std::vector<VKey>& keys, const Grid& g,
  const std::vector<Label>& labels, const Ranking& rank, const std::vector<frep::FieldPtr>& solids,
  int threads);

} // namespace ictk::discretize::detail::material
