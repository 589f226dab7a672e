// SPDX-License-Identifier: BSD-3-Clause
// The CGAL Mesh_3 backend. This is the only translation unit that includes Mesh_3 (it takes about
// a minute and 3-4 GB to compile); linking it makes the binary GPL-3.0-or-later.
// It is one file of more than 1,000 lines on purpose: every piece split off would either include
// Mesh_3 again (another minute and 3-4 GB per translation unit) or need its types in a header,
// which would spread that cost to every file that includes it.
#include "Mesh/CGAL/MeshCgal.h"

#include "Complex/Discretization.h"
#include "Discretize/Curves.h"
#include "FRep/Sampling.h"
#include "FRep/Threads.h"
#include "FRep/Vector.h"

// Slivers_exuder's Parallel_tag code uses the work-sharing structures without including them.
#include <CGAL/Mesh_3/Worksharing_data_structures.h>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Labeled_mesh_domain_3.h>
#include <CGAL/Mesh_complex_3_in_triangulation_3.h>
#include <CGAL/Mesh_criteria_3.h>
#include <CGAL/Mesh_domain_with_polyline_features_3.h>
#include <CGAL/Mesh_triangulation_3.h>
#include <CGAL/Random.h>
#include <CGAL/exude_mesh_3.h>
#include <CGAL/make_mesh_3.h>
#include <CGAL/perturb_mesh_3.h>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace ictk::mesh
{
namespace
{

using complex::Cell;
using complex::CellId;
using complex::Complex;
using frep::Box3;
using frep::FieldPtr;
using Polyline = std::vector<Point3>;

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using BaseDomain = CGAL::Labeled_mesh_domain_3<K>;
using Domain = CGAL::Mesh_domain_with_polyline_features_3<BaseDomain>;
/// The triangulation types of one concurrency mode: CGAL::Sequential_tag (the deterministic mode,
/// and one thread) or CGAL::Parallel_tag (refinement, perturbation and exudation on TBB threads).
template <class Concurrency>
struct Mesh3
{
  using Tr = typename CGAL::Mesh_triangulation_3<Domain, CGAL::Default, Concurrency>::type;
  using C3t3 =
    CGAL::Mesh_complex_3_in_triangulation_3<Tr, Domain::Corner_index, Domain::Curve_index>;
  using Criteria = CGAL::Mesh_criteria_3<Tr>;
};

/// Facet and cell circumradius bounds per unit of TetraOptions::size (see tetrahedralizeCgal).
constexpr double kFacetRadius = 0.75;
constexpr double kCellRadius = 0.8;

// --- small vector helpers ---------------------------------------------------------------------
using frep::distance;
using frep::dot;
using frep::sub;

/// The point of segment [a, b] nearest to p.
Point3 nearestOnSegment(const Point3& p, const Point3& a, const Point3& b)
{
  const Point3 ab = sub(b, a);
  const double len2 = dot(ab, ab);
  const double t = len2 > 0 ? std::clamp(dot(sub(p, a), ab) / len2, 0.0, 1.0) : 0.0;
  return { a[0] + t * ab[0], a[1] + t * ab[1], a[2] + t * ab[2] };
}
std::string pointText(const Point3& p)
{
  std::ostringstream s;
  s.precision(9);
  s << "(" << p[0] << ", " << p[1] << ", " << p[2] << ")";
  return s.str();
}
bool inBox(const Point3& p, const Box3& b)
{
  return p[0] >= b.lo[0] && p[0] <= b.hi[0] && p[1] >= b.lo[1] && p[1] <= b.hi[1] &&
    p[2] >= b.lo[2] && p[2] <= b.hi[2];
}
Box3 padded(const Box3& b, double pad)
{
  return { { b.lo[0] - pad, b.lo[1] - pad, b.lo[2] - pad },
    { b.hi[0] + pad, b.hi[1] + pad, b.hi[2] + pad } };
}
double diagonal(const Box3& b)
{
  return distance(b.lo, b.hi);
}

// --- the 3D cells as one labelled domain ------------------------------------------------------

/// A 3D implicit cell: {p in box : every inside field >= 0}.
struct Solid
{
  CellId id = 0;
  std::string name;
  double priority = 0;
  Box3 box;
  std::vector<FieldPtr> inside;
};

std::vector<Solid> collectSolids(const Complex& complex)
{
  std::vector<Solid> solids;
  for (CellId id : complex.cellsOfDimension(3))
  {
    const Cell& c = complex.cell(id);
    const auto* g = std::get_if<complex::ImplicitGeometry>(&c.geometry);
    if (!g || !g->carriers.empty() || g->inside.empty())
    {
      throw std::invalid_argument("cell '" + c.name +
        "': the CGAL backend meshes implicit 3D cells (inside fields) only, not " +
        complex::kindCode(c.kind) + " cells of this form");
    }
    Solid s;
    s.id = id;
    s.name = c.name;
    s.priority = c.priority;
    s.box = g->bounds;
    s.inside = g->inside;
    for (int a = 0; a < 3; ++a)
    {
      if (!std::isfinite(s.box.lo[a]) || !std::isfinite(s.box.hi[a]) || !s.box.valid())
      {
        throw std::invalid_argument(
          "cell '" + c.name + "': the CGAL backend needs finite, valid bounds");
      }
    }
    solids.push_back(std::move(s));
  }
  if (solids.empty())
  {
    throw std::invalid_argument("the complex has no 3D cell to mesh");
  }
  return solids;
}

/// The label function of the domain. Each thread gets its own field evaluators (FieldEvaluator is
/// not thread safe); CGAL copies the function object, so copies share this oracle.
///
/// Mesh_3 calls it millions of times (circumcentres of new cells, both ends of every dual segment,
/// every bisection step; perturbation and exudation redo much of that), so it avoids work a plain
/// C++ lambda would not do: a grid of blocks over the domain records, per solid, whether interval
/// arithmetic proves the block inside or outside it (most circumcentres lie in such blocks and
/// need no field evaluation), solids are tried by decreasing priority (a point inside the highest
/// one needs no lower one), and the thread's evaluators are found through a thread_local cache
/// instead of a lookup in the thread-specific table. The labels are those of plain evaluation.
class Labeller
{
public:
  Labeller(const std::vector<Solid>& solids, const Box3& domain, double overlapTolerance,
    ProgressScope& progress)
    : solids_(solids)
    , tolerance_(overlapTolerance)
    , progress_(progress)
    , serial_(nextSerial())
  {
    order_.resize(solids_.size());
    for (std::size_t i = 0; i < order_.size(); ++i)
    {
      order_[i] = i;
    }
    std::stable_sort(order_.begin(), order_.end(),
      [&](std::size_t a, std::size_t b) { return solids_[a].priority > solids_[b].priority; });
    certify(domain);
  }

  /// 0 outside every solid, else the 1-based index of the solid holding p.
  int label(const Point3& p)
  {
    Local& l = local();
    if ((++l.calls & 0xFFF) == 0)
    {
      // Within a meshing step the phase stays: the report is the chance to stop.
      progress_.report(phase_);
    }
    const std::uint8_t* known = blockStates(p);
    int best = -1;
    double bestDepth = -1;
    for (const std::size_t i : order_)
    {
      const Solid& s = solids_[i];
      if (best >= 0 && s.priority < solids_[best].priority)
      {
        break; // only lower priorities left
      }
      const std::uint8_t state = known ? known[i] : kUnknown;
      if (state == kOutside || (state == kUnknown && (!inBox(p, s.box) || !inside(l, i, p))))
      {
        continue;
      }
      if (best < 0)
      {
        best = static_cast<int>(i);
        bestDepth = -1;
        continue;
      }
      // Equal priority: fine on a shared boundary (both depths about 0), an error inside both.
      if (bestDepth < 0)
      {
        bestDepth = depth(l, static_cast<std::size_t>(best), p);
      }
      const double d = depth(l, i, p);
      if (d > tolerance_ && bestDepth > tolerance_)
      {
        const std::size_t first = std::min(static_cast<std::size_t>(best), i);
        const std::size_t second = std::max(static_cast<std::size_t>(best), i);
        throw std::invalid_argument("cells '" + solids_[first].name + "' and '" +
          solids_[second].name + "' overlap at " + pointText(p) + " and have the same priority (" +
          std::to_string(s.priority) + "); give one of them a higher priority");
      }
      if (d > bestDepth)
      {
        best = static_cast<int>(i);
        bestDepth = d;
      }
    }
    return best + 1;
  }

  void setPhase(double fraction) { phase_ = fraction; }

private:
  static constexpr std::uint8_t kUnknown = 0;
  static constexpr std::uint8_t kInside = 1;
  static constexpr std::uint8_t kOutside = 2;

  struct Local
  {
    std::vector<std::vector<std::unique_ptr<frep::FieldEvaluator>>> evaluators;
    std::uint64_t calls = 0;
  };

  static std::uint64_t nextSerial()
  {
    static std::atomic<std::uint64_t> serial{ 0 };
    return ++serial;
  }

  Local& local()
  {
    // The serial, not the address, names the oracle: a later Labeller may reuse this one's
    // address, never its serial.
    struct Cache
    {
      std::uint64_t owner = 0;
      Local* local = nullptr;
    };
    thread_local Cache cache;
    if (cache.owner == serial_)
    {
      return *cache.local;
    }
    Local& l = local_.local();
    if (l.evaluators.empty())
    {
      for (const Solid& s : solids_)
      {
        std::vector<std::unique_ptr<frep::FieldEvaluator>> e;
        for (const FieldPtr& f : s.inside)
        {
          e.push_back(f->evaluator());
        }
        l.evaluators.push_back(std::move(e));
      }
    }
    cache = { serial_, &l };
    return l;
  }

  /// Per block and solid: inside or outside for every point of the block (its box padded by a
  /// hair, so rounding in the block index cannot matter), or unknown.
  void certify(const Box3& domain)
  {
    // About 32 blocks along the longest side, fewer when there are many solids.
    double longest = 0;
    for (int a = 0; a < 3; ++a)
    {
      longest = std::max(longest, domain.hi[a] - domain.lo[a]);
    }
    const double perSide =
      std::clamp(std::cbrt(4e6 / static_cast<double>(solids_.size())), 1.0, 32.0);
    if (!(longest > 0) || !std::isfinite(longest))
    {
      return;
    }
    const double step = longest / perSide;
    for (int a = 0; a < 3; ++a)
    {
      gridLo_[a] = domain.lo[a];
      blocks_[a] = std::max(1, static_cast<int>(std::ceil((domain.hi[a] - domain.lo[a]) / step)));
    }
    gridStep_ = step;
    const std::size_t count =
      static_cast<std::size_t>(blocks_[0]) * std::size_t(blocks_[1]) * std::size_t(blocks_[2]);
    states_.assign(count * solids_.size(), kUnknown);
    const double hair = 1e-9 * step;
    for (std::size_t i = 0; i < solids_.size(); ++i)
    {
      const Solid& s = solids_[i];
      std::vector<std::unique_ptr<frep::FieldEvaluator>> fields;
      for (const FieldPtr& f : s.inside)
      {
        fields.push_back(f->evaluator());
      }
      for (int z = 0; z < blocks_[2]; ++z)
      {
        for (int y = 0; y < blocks_[1]; ++y)
        {
          for (int x = 0; x < blocks_[0]; ++x)
          {
            const int at[3] = { x, y, z };
            Box3 b;
            bool meetsBox = true, inBounds = true;
            for (int a = 0; a < 3; ++a)
            {
              b.lo[a] = gridLo_[a] + at[a] * step - hair;
              b.hi[a] = gridLo_[a] + (at[a] + 1) * step + hair;
              meetsBox = meetsBox && b.hi[a] >= s.box.lo[a] && b.lo[a] <= s.box.hi[a];
              inBounds = inBounds && b.lo[a] >= s.box.lo[a] && b.hi[a] <= s.box.hi[a];
            }
            std::uint8_t state = kUnknown;
            if (!meetsBox)
            {
              state = kOutside;
            }
            else
            {
              bool allInside = inBounds;
              for (auto& f : fields)
              {
                const frep::Interval v = f->bound(b);
                if (v.negative() || (v.empty() && v.maybeNaN))
                {
                  state = kOutside; // negative or NaN everywhere: not >= 0 anywhere
                  break;
                }
                allInside = allInside && !v.maybeNaN && !v.empty() && v.lo >= 0;
              }
              if (state == kUnknown && allInside)
              {
                state = kInside;
              }
            }
            const std::size_t block = (std::size_t(z) * std::size_t(blocks_[1]) + std::size_t(y)) *
                std::size_t(blocks_[0]) +
              std::size_t(x);
            states_[block * solids_.size() + i] = state;
          }
        }
      }
    }
  }

  /// The states of p's block (one per solid), or nullptr outside the grid.
  const std::uint8_t* blockStates(const Point3& p) const
  {
    if (states_.empty())
    {
      return nullptr;
    }
    std::size_t block = 0;
    for (int a = 2; a >= 0; --a)
    {
      const double u = (p[a] - gridLo_[a]) / gridStep_;
      if (!(u >= 0) || !(u < blocks_[a]))
      {
        return nullptr;
      }
      block = block * std::size_t(blocks_[a]) + static_cast<std::size_t>(u);
    }
    return &states_[block * solids_.size()];
  }

  static bool inside(Local& l, std::size_t i, const Point3& p)
  {
    for (auto& e : l.evaluators[i])
    {
      const double v = e->value(p);
      if (!(v >= 0))
      {
        return false;
      }
    }
    return true;
  }

  /// Distance estimate from p (inside the solid) to its boundary: min of f / |grad f|.
  static double depth(Local& l, std::size_t i, const Point3& p)
  {
    double d = std::numeric_limits<double>::infinity();
    for (auto& e : l.evaluators[i])
    {
      Point3 g;
      const double v = e->gradient(p, g);
      const double n = std::sqrt(dot(g, g));
      d = std::min(d, n > 1e-12 ? v / n : v);
    }
    return d;
  }

  const std::vector<Solid>& solids_;
  std::vector<std::size_t> order_;
  double tolerance_;
  ProgressScope& progress_;
  double phase_ = 0;
  std::uint64_t serial_;
  Point3 gridLo_{ 0, 0, 0 };
  double gridStep_ = 1;
  int blocks_[3] = { 0, 0, 0 };
  std::vector<std::uint8_t> states_;
  tbb::enumerable_thread_specific<Local> local_;
};

/// Where two solids of equal priority have overlapping boxes, samples the overlap so that an
/// overlap is reported before meshing, deterministically.
void checkOverlaps(const std::vector<Solid>& solids, Labeller& labeller, double size)
{
  for (std::size_t i = 0; i < solids.size(); ++i)
  {
    for (std::size_t j = i + 1; j < solids.size(); ++j)
    {
      if (solids[i].priority != solids[j].priority)
      {
        continue;
      }
      Box3 o;
      for (int a = 0; a < 3; ++a)
      {
        o.lo[a] = std::max(solids[i].box.lo[a], solids[j].box.lo[a]);
        o.hi[a] = std::min(solids[i].box.hi[a], solids[j].box.hi[a]);
      }
      if (!o.valid())
      {
        continue;
      }
      // About size / 2 apart, at most ~2e5 samples per pair.
      std::array<int, 3> n{};
      double h = size / 2;
      for (;;)
      {
        double count = 1;
        for (int a = 0; a < 3; ++a)
        {
          n[a] = 1 + static_cast<int>(std::ceil((o.hi[a] - o.lo[a]) / h));
          count *= n[a];
        }
        if (count <= 2e5)
        {
          break;
        }
        h *= 1.5;
      }
      for (int x = 0; x <= n[0]; ++x)
      {
        for (int y = 0; y <= n[1]; ++y)
        {
          for (int z = 0; z <= n[2]; ++z)
          {
            const Point3 p{ o.lo[0] + (o.hi[0] - o.lo[0]) * x / n[0],
              o.lo[1] + (o.hi[1] - o.lo[1]) * y / n[1], o.lo[2] + (o.hi[2] - o.lo[2]) * z / n[2] };
            labeller.label(p); // throws for an overlap
          }
        }
      }
    }
  }
}

// --- 2D cells inside solids ------------------------------------------------------------------
//
// A labelled domain only has surfaces where the label changes, so a patch {G = 0, H >= 0} inside
// a solid is made one: the points of the solid with G < 0 and every H >= 0 (within the patch's
// box) get a sub-label, and Mesh_3 meshes the interface {G = 0, H >= 0} between the solid's label
// and the sub-label. The price is the rest of that interface, the walls {H = 0, G < 0} from the
// patch's rim to the solid's boundary: faces inside the solid no one asked for (harmless: both
// sides keep the solid's cell and material). The rim and the walls' edges are protected so the
// patch ends cleanly at its rim.

/// A 2D implicit cell that passes through the interior of some solid.
struct Patch
{
  std::string name;
  FieldPtr carrier;
  std::vector<FieldPtr> trims;
  /// The patch's bounds, padded, and unbounded along axes the patch is flat in (its own bounds
  /// there only say where its plane is, they must not cut the sub-label's region short).
  Box3 region;
  /// The solids (indices) it passes through.
  std::vector<std::size_t> solids;
};

/// At most this many patches: the label of a point holds one bit per patch.
constexpr std::size_t kMaxPatches = 16;

/// The sub-label bits of a point: bit k when p is on the negative side of patch k's carrier
/// within its trims and region. Thread-local evaluators, as in Labeller.
class PatchSides
{
public:
  explicit PatchSides(const std::vector<Patch>& patches)
    : patches_(patches)
  {
  }

  int mask(const Point3& p)
  {
    Local& l = local_.local();
    if (l.carriers.empty())
    {
      for (const Patch& pa : patches_)
      {
        l.carriers.push_back(pa.carrier->evaluator());
        std::vector<std::unique_ptr<frep::FieldEvaluator>> t;
        for (const FieldPtr& f : pa.trims)
        {
          t.push_back(f->evaluator());
        }
        l.trims.push_back(std::move(t));
      }
    }
    int m = 0;
    for (std::size_t k = 0; k < patches_.size(); ++k)
    {
      if (!inBox(p, patches_[k].region) || !(l.carriers[k]->value(p) < 0))
      {
        continue;
      }
      bool in = true;
      for (auto& t : l.trims[k])
      {
        in = in && t->value(p) >= 0;
      }
      m |= in ? 1 << k : 0;
    }
    return m;
  }

private:
  struct Local
  {
    std::vector<std::unique_ptr<frep::FieldEvaluator>> carriers;
    std::vector<std::vector<std::unique_ptr<frep::FieldEvaluator>>> trims;
  };
  const std::vector<Patch>& patches_;
  tbb::enumerable_thread_specific<Local> local_;
};

/// The implicit 2D cells some of whose points lie at least `margin` inside a solid (the label is
/// the same there and at `margin` in 14 directions): cells on a boundary or an interface are
/// already surfaces of the domain. Mapped and explicit 2D cells are not inserted (no carrier to
/// split by).
std::vector<Patch> collectPatches(const Complex& complex, const std::vector<Solid>& solids,
  Labeller& labeller, const TetraOptions& options)
{
  static const int directions[14][3] = { { 1, 0, 0 }, { -1, 0, 0 }, { 0, 1, 0 }, { 0, -1, 0 },
    { 0, 0, 1 }, { 0, 0, -1 }, { 1, 1, 1 }, { 1, 1, -1 }, { 1, -1, 1 }, { 1, -1, -1 }, { -1, 1, 1 },
    { -1, 1, -1 }, { -1, -1, 1 }, { -1, -1, -1 } };
  const double margin = 0.5 * options.size;
  std::vector<Patch> patches;
  for (CellId id : complex.cellsOfDimension(2))
  {
    const Cell& c = complex.cell(id);
    const auto* g = std::get_if<complex::ImplicitGeometry>(&c.geometry);
    if (!g || g->carriers.size() != 1)
    {
      continue;
    }
    complex::DiscretizationOptions d;
    d.featureSize = options.size / 2;
    d.threads = options.threads;
    const discretize::SurfaceMesh mesh = complex::discretizeCell(complex, id, d).surface;
    std::vector<bool> through(solids.size(), false);
    Box3 extent{ { std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
                   std::numeric_limits<double>::infinity() },
      { -std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
        -std::numeric_limits<double>::infinity() } };
    for (const Point3& p : mesh.points)
    {
      for (int a = 0; a < 3; ++a)
      {
        extent.lo[a] = std::min(extent.lo[a], p[a]);
        extent.hi[a] = std::max(extent.hi[a], p[a]);
      }
      const int label = labeller.label(p);
      bool inside = label > 0;
      for (int k = 0; k < 14 && inside; ++k)
      {
        const double scale = k < 6 ? margin : margin / std::sqrt(3.0);
        inside = labeller.label({ p[0] + scale * directions[k][0], p[1] + scale * directions[k][1],
                   p[2] + scale * directions[k][2] }) == label;
      }
      if (inside)
      {
        through[static_cast<std::size_t>(label - 1)] = true;
      }
    }
    Patch patch;
    for (std::size_t i = 0; i < solids.size(); ++i)
    {
      if (through[i])
      {
        patch.solids.push_back(i);
      }
    }
    if (patch.solids.empty())
    {
      continue;
    }
    patch.name = c.name;
    patch.carrier = g->carriers[0];
    patch.trims = g->inside;
    patch.region = padded(g->bounds, options.size);
    for (int a = 0; a < 3; ++a)
    {
      if (extent.hi[a] - extent.lo[a] < 0.5 * (g->bounds.hi[a] - g->bounds.lo[a]))
      {
        patch.region.lo[a] = -std::numeric_limits<double>::infinity();
        patch.region.hi[a] = std::numeric_limits<double>::infinity();
      }
    }
    patches.push_back(std::move(patch));
  }
  if (patches.size() > kMaxPatches)
  {
    throw std::invalid_argument("the CGAL backend inserts at most " + std::to_string(kMaxPatches) +
      " 2D cells inside solids; this complex has " + std::to_string(patches.size()) + " (first '" +
      patches.front().name + "'): use the TetGen backend");
  }
  return patches;
}

// --- feature curves ---------------------------------------------------------------------------

/// A solid's boundary as smooth faces: the leaves of the min/max tree of its inside fields (their
/// common min is the root). A leaf's zero set is on the boundary where every sibling along its
/// path to the root allows it: a min's other operands >= 0, a max's <= 0. Two faces meet in a sharp
/// edge; tracing the curve where both vanish, under their paths' conditions, finds it exactly,
/// which no sampling of the solid's field does (issue 21: the CGAL boxes lost 0.7 % of their
/// volume at rounded edges).
struct SolidFaces
{
  struct Node
  {
    bool minimum = true;
    std::vector<FieldPtr> branches;
  };
  struct Face
  {
    FieldPtr field;
    /// (node, branch) from the root down.
    std::vector<std::pair<std::size_t, std::size_t>> path;
  };
  std::vector<Node> nodes;
  std::vector<Face> faces;

  /// The conditions of a face's path: where they hold, the face is on the solid's boundary.
  std::vector<FieldPtr> faceTrims(std::size_t face) const { return trims(faces[face].path, 0, {}); }

  /// The conditions under which faces k and m meet on the boundary: both paths' conditions, but
  /// not, at the node where the paths part, each branch's condition on the other (it vanishes
  /// along the whole crease).
  std::vector<FieldPtr> creaseTrims(std::size_t k, std::size_t m) const
  {
    const auto& a = faces[k].path;
    const auto& b = faces[m].path;
    std::size_t d = 0;
    while (d < a.size() && d < b.size() && a[d] == b[d])
    {
      ++d;
    }
    // Above the parting node the paths agree: their conditions once.
    std::vector<FieldPtr> out = trims(std::vector(a.begin(), a.begin() + std::ptrdiff_t(d)), 0, {});
    if (d < a.size() && d < b.size())
    {
      const auto t = trims({ a[d] }, 0, b[d].second);
      out.insert(out.end(), t.begin(), t.end());
    }
    for (const auto* path : { &a, &b })
    {
      const auto t = trims(*path, d + 1, {});
      out.insert(out.end(), t.begin(), t.end());
    }
    return out;
  }

private:
  std::vector<FieldPtr> trims(const std::vector<std::pair<std::size_t, std::size_t>>& path,
    std::size_t from, std::optional<std::size_t> alsoSkip) const
  {
    std::vector<FieldPtr> out;
    for (std::size_t e = from; e < path.size(); ++e)
    {
      const Node& n = nodes[path[e].first];
      for (std::size_t j = 0; j < n.branches.size(); ++j)
      {
        if (j != path[e].second && (e != from || j != alsoSkip))
        {
          out.push_back(n.minimum ? n.branches[j] : frep::negatedField(n.branches[j]));
        }
      }
    }
    return out;
  }
};

/// At most this many faces per solid: every pair is traced.
constexpr std::size_t kMaxFaces = 16;

SolidFaces solidFaces(const Solid& s)
{
  SolidFaces out;
  out.nodes.push_back({ true, s.inside });
  // Breadth first, so that a deep tree is cut evenly at kMaxFaces.
  std::vector<SolidFaces::Face> pending;
  for (std::size_t i = 0; i < s.inside.size(); ++i)
  {
    pending.push_back({ s.inside[i], { { 0, i } } });
  }
  for (std::size_t next = 0; next < pending.size(); ++next)
  {
    SolidFaces::Face f = pending[next];
    const std::size_t open = pending.size() - next - 1;
    const auto split = out.faces.size() + open + 2 <= kMaxFaces ? f.field->split() : std::nullopt;
    if (!split)
    {
      out.faces.push_back(std::move(f));
      continue;
    }
    const std::size_t node = out.nodes.size();
    out.nodes.push_back({ split->minimum, { split->a, split->b } });
    for (std::size_t j = 0; j < 2; ++j)
    {
      auto path = f.path;
      path.emplace_back(node, j);
      pending.push_back({ j == 0 ? split->a : split->b, std::move(path) });
    }
  }
  return out;
}

void appendCurves(const discretize::CurveSet& curves, std::vector<Polyline>& out)
{
  for (const auto& line : curves.lines)
  {
    Polyline p;
    for (auto i : line)
    {
      p.push_back(curves.points[i]);
    }
    out.push_back(std::move(p));
  }
}

/// {f = 0, g = 0, trims >= 0} in the box; nothing when the two surfaces coincide or touch (no
/// curve to protect there) or the tracer gives up.
void traceFeature(const frep::FieldPtr& f, const frep::FieldPtr& g,
  const std::vector<FieldPtr>& trims, const Box3& box, double step, int threads,
  std::vector<Polyline>& out)
{
  discretize::CurveOptions o;
  o.step = step;
  o.threads = threads;
  o.maxSeedBoxes = 1e6;
  o.maxPoints = 1e6;
  try
  {
    appendCurves(discretize::traceCurve(*f, *g, trims, box, o), out);
  }
  catch (const frep::Cancelled&)
  {
    throw;
  }
  catch (const std::exception&)
  {
    // Coincident boundaries (two cells sharing a face), tangent contacts: not curves.
  }
}

/// Drops repeated points and too short polylines.
void cleanPolylines(std::vector<Polyline>& lines, double tolerance)
{
  std::vector<Polyline> out;
  for (auto& line : lines)
  {
    Polyline p;
    for (const auto& q : line)
    {
      if (p.empty() || distance(p.back(), q) > tolerance * 1e-3)
      {
        p.push_back(q);
      }
    }
    const bool closed = line.size() > 2 && line.front() == line.back();
    if (closed && p.size() > 1 && p.back() != p.front())
    {
      if (distance(p.back(), p.front()) <= tolerance * 1e-3)
      {
        p.back() = p.front();
      }
      else
      {
        p.push_back(p.front());
      }
    }
    double length = 0;
    for (std::size_t i = 1; i < p.size(); ++i)
    {
      length += distance(p[i - 1], p[i]);
    }
    if (p.size() >= 2 && length > tolerance && !(p.size() <= 3 && p.front() == p.back()))
    {
      out.push_back(std::move(p));
    }
  }
  lines = std::move(out);
}

double distanceToPolyline(const Point3& p, const Polyline& line)
{
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 1; i < line.size(); ++i)
  {
    best = std::min(best, distance(p, nearestOnSegment(p, line[i - 1], line[i])));
  }
  return best;
}

bool isClosed(const Polyline& p)
{
  return p.size() > 2 && p.front() == p.back();
}

/// Merges the candidate curves into a set CGAL accepts: a curve lying along an accepted one (every
/// point within `duplicate`) is dropped, end points closer than `snap` become one corner, and a
/// curve with a corner on its interior is split there.
std::vector<Polyline> mergeFeatures(
  const std::vector<Polyline>& candidates, double duplicate, double snap)
{
  std::vector<Polyline> accepted;
  for (const auto& c : candidates)
  {
    bool covered = !accepted.empty();
    for (const auto& q : c)
    {
      double d = std::numeric_limits<double>::infinity();
      for (const auto& a : accepted)
      {
        d = std::min(d, distanceToPolyline(q, a));
        if (d <= duplicate)
        {
          break;
        }
      }
      if (d > duplicate)
      {
        covered = false;
        break;
      }
    }
    if (!covered)
    {
      accepted.push_back(c);
    }
  }
  // The tracer stops a little short of a trim's zero, so a curve that ends on another one (a
  // scan's iso-surface meeting a box face, ending at the box's edge: issue 15) can end up to
  // `duplicate` away from it, at distances from which CGAL makes micro-tetrahedra. Such an end
  // is extended onto the other curve, where it becomes a corner that splits it.
  for (std::size_t k = 0; k < accepted.size(); ++k)
  {
    if (isClosed(accepted[k]))
    {
      continue;
    }
    for (const bool back : { false, true })
    {
      Polyline& a = accepted[k];
      const Point3 end = back ? a.back() : a.front();
      double best = std::numeric_limits<double>::infinity();
      Point3 onto{};
      for (std::size_t m = 0; m < accepted.size(); ++m)
      {
        const Polyline& b = accepted[m];
        for (std::size_t i = 1; m != k && i < b.size(); ++i)
        {
          const Point3 q = nearestOnSegment(end, b[i - 1], b[i]);
          if (distance(end, q) < best)
          {
            best = distance(end, q);
            onto = q;
          }
        }
      }
      if (best > snap && best <= duplicate)
      {
        a.insert(back ? a.end() : a.begin(), onto);
      }
    }
  }
  // Corners: end points of open curves, clustered.
  std::vector<Point3> corners;
  auto corner = [&](Point3& p)
  {
    for (const auto& c : corners)
    {
      if (distance(c, p) <= snap)
      {
        p = c;
        return;
      }
    }
    corners.push_back(p);
  };
  for (auto& a : accepted)
  {
    if (!isClosed(a))
    {
      corner(a.front());
      corner(a.back());
    }
  }
  // Split curves at corners on their interior (a closed curve through a corner becomes two open
  // curves, from the corner to its opposite point and back).
  bool changed = true;
  while (changed)
  {
    changed = false;
    for (std::size_t k = 0; k < accepted.size() && !changed; ++k)
    {
      Polyline& a = accepted[k];
      for (const auto& c : corners)
      {
        if (!isClosed(a) && (a.front() == c || a.back() == c))
        {
          continue;
        }
        // Nearest segment.
        std::size_t seg = 0;
        double best = std::numeric_limits<double>::infinity();
        for (std::size_t i = 1; i < a.size(); ++i)
        {
          const double d = distance(c, nearestOnSegment(c, a[i - 1], a[i]));
          if (d < best)
          {
            best = d;
            seg = i;
          }
        }
        if (!(best <= snap))
        {
          continue;
        }
        // Insert c as a vertex: replace a near vertex, else add it inside segment `seg`.
        std::size_t at = 0;
        if (distance(c, a[seg - 1]) <= snap && (seg - 1 > 0 || isClosed(a)))
        {
          at = seg - 1;
          a[at] = c;
        }
        else if (distance(c, a[seg]) <= snap && (seg < a.size() - 1 || isClosed(a)))
        {
          at = seg;
          a[at] = c;
        }
        else
        {
          a.insert(a.begin() + static_cast<std::ptrdiff_t>(seg), c);
          at = seg;
        }
        if (isClosed(a) || at == 0 || at == a.size() - 1)
        {
          if (at == 0 || at == a.size() - 1)
          {
            // A closed curve through its own start point: make the corner its start.
            a.front() = c;
            a.back() = c;
          }
          // Rotate so the closed curve starts at c, then split at the opposite vertex.
          Polyline loop(a.begin(), a.end() - 1); // drop the repeated end
          std::rotate(
            loop.begin(), loop.begin() + static_cast<std::ptrdiff_t>(at % loop.size()), loop.end());
          loop.push_back(loop.front());
          const std::size_t half = loop.size() / 2;
          Polyline first(loop.begin(), loop.begin() + static_cast<std::ptrdiff_t>(half) + 1);
          Polyline second(loop.begin() + static_cast<std::ptrdiff_t>(half), loop.end());
          corners.push_back(loop[half]);
          a = std::move(first);
          accepted.push_back(std::move(second));
        }
        else
        {
          Polyline second(a.begin() + static_cast<std::ptrdiff_t>(at), a.end());
          a.resize(at + 1);
          accepted.push_back(std::move(second));
        }
        changed = true;
        break;
      }
    }
  }
  return accepted;
}

std::vector<Polyline> featureCurves(const Complex& complex, const std::vector<Solid>& solids,
  const std::vector<Patch>& patches, const Box3& domainBox, const TetraOptions& options)
{
  const double size = options.size;
  const double step = size / 4;
  const double pad = 1e-7 * diagonal(domainBox);
  std::vector<Polyline> candidates;
  // 1D cells first: they are the user's curves.
  for (CellId id : complex.cellsOfDimension(1))
  {
    complex::DiscretizationOptions d;
    d.featureSize = step;
    d.threads = options.threads;
    const complex::CellMesh m = complex::discretizeCell(complex, id, d);
    std::vector<Polyline> lines;
    appendCurves(m.curves, lines);
    for (auto& l : lines)
    {
      const bool near = std::any_of(
        l.begin(), l.end(), [&](const Point3& p) { return inBox(p, padded(domainBox, size)); });
      if (near)
      {
        candidates.push_back(std::move(l));
      }
    }
  }
  // Creases of each solid: where two of its faces meet.
  std::vector<SolidFaces> faces;
  for (const Solid& s : solids)
  {
    faces.push_back(solidFaces(s));
    const SolidFaces& f = faces.back();
    for (std::size_t k = 0; k < f.faces.size(); ++k)
    {
      for (std::size_t m = k + 1; m < f.faces.size(); ++m)
      {
        traceFeature(f.faces[k].field, f.faces[m].field, f.creaseTrims(k, m), padded(s.box, pad),
          step, options.threads, candidates);
      }
    }
  }
  // Curves where the boundaries of two solids meet.
  for (std::size_t i = 0; i < solids.size(); ++i)
  {
    for (std::size_t j = i + 1; j < solids.size(); ++j)
    {
      const Solid& a = solids[i];
      const Solid& b = solids[j];
      Box3 o;
      for (int ax = 0; ax < 3; ++ax)
      {
        o.lo[ax] = std::max(a.box.lo[ax], b.box.lo[ax]);
        o.hi[ax] = std::min(a.box.hi[ax], b.box.hi[ax]);
      }
      if (!o.valid())
      {
        continue;
      }
      for (std::size_t k = 0; k < faces[i].faces.size(); ++k)
      {
        for (std::size_t m = 0; m < faces[j].faces.size(); ++m)
        {
          std::vector<FieldPtr> trims = faces[i].faceTrims(k);
          const std::vector<FieldPtr> other = faces[j].faceTrims(m);
          trims.insert(trims.end(), other.begin(), other.end());
          traceFeature(faces[i].faces[k].field, faces[j].faces[m].field, trims, padded(o, pad),
            step, options.threads, candidates);
        }
      }
    }
  }
  // The rims of the 2D cells inside solids, and the edges of their sub-labels' walls (where two
  // walls meet, where a wall meets the solid's boundary).
  for (const Patch& pa : patches)
  {
    const FieldPtr below = frep::negatedField(pa.carrier);
    for (const std::size_t si : pa.solids)
    {
      const Solid& s = solids[si];
      Box3 o;
      for (int ax = 0; ax < 3; ++ax)
      {
        o.lo[ax] = std::max(s.box.lo[ax], pa.region.lo[ax]);
        o.hi[ax] = std::min(s.box.hi[ax], pa.region.hi[ax]);
      }
      if (!o.valid())
      {
        continue;
      }
      o = padded(o, pad);
      auto others = [&](const std::vector<FieldPtr>& fields, std::size_t skip)
      {
        std::vector<FieldPtr> out;
        for (std::size_t r = 0; r < fields.size(); ++r)
        {
          if (r != skip)
          {
            out.push_back(fields[r]);
          }
        }
        return out;
      };
      for (std::size_t j = 0; j < pa.trims.size(); ++j)
      {
        std::vector<FieldPtr> trims = others(pa.trims, j);
        trims.insert(trims.end(), s.inside.begin(), s.inside.end());
        traceFeature(pa.carrier, pa.trims[j], trims, o, step, options.threads, candidates);
        for (std::size_t k = j + 1; k < pa.trims.size(); ++k)
        {
          std::vector<FieldPtr> t2;
          for (std::size_t r = 0; r < pa.trims.size(); ++r)
          {
            if (r != j && r != k)
            {
              t2.push_back(pa.trims[r]);
            }
          }
          t2.push_back(below);
          t2.insert(t2.end(), s.inside.begin(), s.inside.end());
          traceFeature(pa.trims[j], pa.trims[k], t2, o, step, options.threads, candidates);
        }
        for (std::size_t m = 0; m < s.inside.size(); ++m)
        {
          std::vector<FieldPtr> t3 = others(pa.trims, j);
          t3.push_back(below);
          const auto rest = others(s.inside, m);
          t3.insert(t3.end(), rest.begin(), rest.end());
          traceFeature(pa.trims[j], s.inside[m], t3, o, step, options.threads, candidates);
        }
      }
    }
  }
  cleanPolylines(candidates, 1e-3 * size);
  auto merged = mergeFeatures(candidates, 0.02 * size, 1e-3 * size);
  cleanPolylines(merged, 1e-3 * size);
  return merged;
}

Box3 domainBox(const std::vector<Solid>& solids)
{
  Box3 b = solids.front().box;
  for (const Solid& s : solids)
  {
    for (int a = 0; a < 3; ++a)
    {
      b.lo[a] = std::min(b.lo[a], s.box.lo[a]);
      b.hi[a] = std::max(b.hi[a], s.box.hi[a]);
    }
  }
  return b;
}

void checkOptions(const TetraOptions& options)
{
  if (!(options.size > 0) || !std::isfinite(options.size))
  {
    throw std::invalid_argument("the mesh size must be a positive number");
  }
}

/// Initial surface points for every solid, found deterministically: a point holding the solid's
/// label (a grid search in its box), then CGAL's own segment intersection along 14 directions
/// from it. Points near a protected curve are skipped (a point inside a protecting ball is hidden
/// by it anyway; one just outside would crowd it).
template <class C3t3>
void seedSurfaces(C3t3& c3t3, const Domain& domain, const std::vector<Solid>& solids,
  Labeller& labeller, const std::vector<Polyline>& features, const Box3& outer, double size)
{
  const double reach = 2 * diagonal(outer);
  auto cwp = c3t3.triangulation().geom_traits().construct_weighted_point_3_object();
  const auto intersects = domain.do_intersect_surface_object();
  const auto intersection = domain.construct_intersection_object();
  std::vector<Point3> seeds;
  for (std::size_t i = 0; i < solids.size(); ++i)
  {
    const Box3& b = solids[i].box;
    std::optional<Point3> seed;
    for (int n = 4; n <= 64 && !seed; n *= 2)
    {
      for (int x = 0; x < n && !seed; ++x)
      {
        for (int y = 0; y < n && !seed; ++y)
        {
          for (int z = 0; z < n && !seed; ++z)
          {
            const Point3 q{ b.lo[0] + (b.hi[0] - b.lo[0]) * (x + 0.5) / n,
              b.lo[1] + (b.hi[1] - b.lo[1]) * (y + 0.5) / n,
              b.lo[2] + (b.hi[2] - b.lo[2]) * (z + 0.5) / n };
            if (labeller.label(q) == static_cast<int>(i) + 1)
            {
              seed = q;
            }
          }
        }
      }
    }
    if (!seed)
    {
      continue;
    }
    for (int dx = -1; dx <= 1; ++dx)
    {
      for (int dy = -1; dy <= 1; ++dy)
      {
        for (int dz = -1; dz <= 1; ++dz)
        {
          const int nonzero = (dx != 0) + (dy != 0) + (dz != 0);
          if (nonzero != 1 && nonzero != 3)
          {
            continue;
          }
          const double s = reach / std::sqrt(static_cast<double>(nonzero));
          const K::Point_3 from((*seed)[0], (*seed)[1], (*seed)[2]);
          const K::Point_3 to(from.x() + s * dx, from.y() + s * dy, from.z() + s * dz);
          const K::Segment_3 segment(from, to);
          const auto surface = intersects(segment);
          if (!surface)
          {
            continue;
          }
          const auto hit = intersection(segment);
          const K::Point_3& q = std::get<0>(hit);
          const Point3 point{ q.x(), q.y(), q.z() };
          const bool nearCurve = std::any_of(features.begin(), features.end(),
            [&](const Polyline& f) { return distanceToPolyline(point, f) < 0.5 * size; });
          // Two solids sharing a face find the same interface point from either side, up to
          // the bisection's error: both inserted, they left clusters of vertices 1e-8 apart that
          // refinement never removes (issue 21's micro-tetrahedra).
          const bool nearSeed = std::any_of(seeds.begin(), seeds.end(),
            [&](const Point3& s) { return distance(point, s) < 0.5 * size; });
          if (nearCurve || nearSeed)
          {
            continue;
          }
          const auto v = c3t3.triangulation().insert(cwp(q));
          if (v != typename C3t3::Triangulation::Vertex_handle())
          {
            c3t3.set_dimension(v, 2);
            c3t3.set_index(v, domain.index_from_surface_patch_index(*surface));
            seeds.push_back(point);
          }
        }
      }
    }
  }
}

/// make_mesh_3's steps on the domain, with initial surface points on every solid, and the
/// tetrahedra of the complex as a TetMesh (materials 1..n; labels above n are patch sub-labels).
template <class Concurrency>
TetMesh refine(const Domain& domain, const std::vector<Solid>& solids, Labeller& labeller,
  const std::vector<Polyline>& features, const Box3& outer, const TetraOptions& options,
  ProgressScope& progress, int n)
{
  using C3t3 = typename Mesh3<Concurrency>::C3t3;
  // CGAL's sizes are circumradius bounds. Delaunay refinement leaves most elements well below
  // them: with the regular-element radii (h / sqrt 3, h sqrt(6) / 4) the sphere-in-box benchmark
  // came out with 2.3 times estimateTetrahedra's count (mean element about 0.76 h). These bounds
  // make the mean tetrahedron about the volume of a regular one of edge h, as the estimate says.
  const double h = options.size;
  namespace p = CGAL::parameters;
  typename Mesh3<Concurrency>::Criteria criteria(p::edge_size = h, p::facet_angle = 25,
    p::facet_size = kFacetRadius * h, p::facet_distance = 0.1 * h, p::cell_radius_edge_ratio = 3,
    p::cell_size = kCellRadius * h);

  labeller.setPhase(0.1);
  // make_mesh_3's steps, with initial surface points on every solid. make_mesh_3's own seeding
  // (random rays from the centre of the box, and only when the protected curves give no surface
  // facet) is not used: it misses solids away from the curves (the flower's stamen), and a centre
  // on an interface (the two-material bar's) put dozens of points within 1e-8 of each other there.
  typename Mesh3<Concurrency>::C3t3 c3t3;
  if (!features.empty())
  {
    CGAL::Mesh_3::internal::init_c3t3_with_features(c3t3, domain, criteria);
  }
  seedSurfaces(c3t3, domain, solids, labeller, features, outer, h);
  CGAL::refine_mesh_3(c3t3, domain, criteria, p::no_perturb(), p::no_exude(), p::no_reset_c3t3());
  progress.report(0.6);
  if (!options.deterministic)
  {
    labeller.setPhase(0.6);
    CGAL::perturb_mesh_3(
      c3t3, domain, p::time_limit = 0, p::sliver_bound = std::max(0.0, options.minDihedralDegrees));
    progress.report(0.8);
  }
  labeller.setPhase(0.8);
  CGAL::exude_mesh_3(
    c3t3, p::time_limit = 0, p::sliver_bound = std::max(0.0, options.minDihedralDegrees));
  progress.report(0.95);

  // Output: the tetrahedra of the complex, vertices numbered in order of first use.
  TetMesh mesh;
  for (const Solid& s : solids)
  {
    mesh.materialNames.push_back(s.name);
  }
  const typename C3t3::Triangulation& tr = c3t3.triangulation();
  // Vertices are found by their time stamps (unique, below the number of vertices ever inserted):
  // an array lookup instead of a hash map that missed the cache four times per tetrahedron.
  std::size_t stamps = 0;
  for (auto v = tr.finite_vertices_begin(); v != tr.finite_vertices_end(); ++v)
  {
    stamps = std::max(stamps, v->time_stamp() + 1);
  }
  constexpr std::uint32_t unused = std::numeric_limits<std::uint32_t>::max();
  std::vector<std::uint32_t> index(stamps, unused);
  mesh.tetrahedra.reserve(c3t3.number_of_cells_in_complex());
  mesh.cells.reserve(c3t3.number_of_cells_in_complex());
  mesh.materials.reserve(c3t3.number_of_cells_in_complex());
  for (auto c = c3t3.cells_in_complex_begin(); c != c3t3.cells_in_complex_end(); ++c)
  {
    const int subLabel = static_cast<int>(c3t3.subdomain_index(c));
    if (subLabel < 1)
    {
      continue;
    }
    const int label = (subLabel - 1) % n + 1;
    std::array<std::uint32_t, 4> tet{};
    for (int k = 0; k < 4; ++k)
    {
      std::uint32_t& i = index[c->vertex(k)->time_stamp()];
      if (i == unused)
      {
        i = static_cast<std::uint32_t>(mesh.points.size());
        const auto& wp = tr.point(c, k);
        mesh.points.push_back(
          { CGAL::to_double(wp.x()), CGAL::to_double(wp.y()), CGAL::to_double(wp.z()) });
      }
      tet[k] = i;
    }
    if (orientation(
          mesh.points[tet[0]], mesh.points[tet[1]], mesh.points[tet[2]], mesh.points[tet[3]]) < 0)
    {
      std::swap(tet[2], tet[3]);
    }
    mesh.tetrahedra.push_back(tet);
    mesh.cells.push_back(solids[static_cast<std::size_t>(label - 1)].id);
    mesh.materials.push_back(label);
  }
  return mesh;
}

} // namespace

std::vector<std::vector<Point3>> cgalFeatureCurves(
  const complex::Complex& complex, const TetraOptions& options)
{
  checkOptions(options);
  const auto solids = collectSolids(complex);
  const Box3 box = domainBox(solids);
  ProgressScope unreported{ Progress{} };
  Labeller labeller(
    solids, padded(box, 0.02 * diagonal(box) + options.size), 1e-3 * options.size, unreported);
  const auto patches = collectPatches(complex, solids, labeller, options);
  return featureCurves(complex, solids, patches, box, options);
}

bool cgalMeshesInParallel(const TetraOptions& options)
{
#ifdef CGAL_LINKED_WITH_TBB
  const int threads =
    options.threads > 0 ? options.threads : tbb::this_task_arena::max_concurrency();
  return !options.deterministic && threads > 1;
#else
  (void)options;
  return false;
#endif
}

TetMesh tetrahedralizeCgal(const complex::Complex& complex, const TetraOptions& options)
{
  checkOptions(options);
  const std::vector<Solid> solids = collectSolids(complex);
  double volume = 0;
  for (const Solid& s : solids)
  {
    volume +=
      (s.box.hi[0] - s.box.lo[0]) * (s.box.hi[1] - s.box.lo[1]) * (s.box.hi[2] - s.box.lo[2]);
  }
  const double estimate = estimateTetrahedra(volume, options.size);
  if (estimate > options.maxTetrahedra)
  {
    std::ostringstream s;
    s << "size " << options.size << " would give about " << std::llround(estimate)
      << " tetrahedra (bounding volume " << volume << "), above the limit of "
      << options.maxTetrahedra << ": use a larger size or raise maxTetrahedra";
    throw std::invalid_argument(s.str());
  }
  ProgressScope progress(options.progress);
  progress.report(0);

  const Box3 box = domainBox(solids);
  const double diag = diagonal(box);
  // The domain's box: a little larger than the cells' (so that faces on the cells' bounds are
  // seen as surfaces).
  const Box3 outer = padded(box, 0.02 * diag + options.size);
  auto labeller = std::make_shared<Labeller>(solids, outer, 1e-3 * options.size, progress);
  checkOverlaps(solids, *labeller, options.size);
  const std::vector<Patch> patches = collectPatches(complex, solids, *labeller, options);
  const std::vector<Polyline> features = featureCurves(complex, solids, patches, box, options);
  progress.report(0.1);

  // The domain: the label function, the outer box, bisection to 1e-10 of the diagonal.
  CGAL::Random rng(0);
  if (options.deterministic)
  {
    CGAL::get_default_random() = CGAL::Random(0);
  }
  // Labels above the solids' count are sub-labels: solid (label - 1) % n + 1 on the negative
  // sides of the patches in bits (label - 1) / n.
  const int n = static_cast<int>(solids.size());
  auto sides = patches.empty() ? nullptr : std::make_shared<PatchSides>(patches);
  std::function<int(const K::Point_3&)> function = [labeller, sides, n](const K::Point_3& p)
  {
    const Point3 q{ p.x(), p.y(), p.z() };
    const int label = labeller->label(q);
    return label > 0 && sides ? label + n * sides->mask(q) : label;
  };
  Domain domain(function,
    K::Iso_cuboid_3(K::Point_3(outer.lo[0], outer.lo[1], outer.lo[2]),
      K::Point_3(outer.hi[0], outer.hi[1], outer.hi[2])),
    K::FT(1e-10), CGAL::Null_subdomain_index(), &rng);
  {
    std::vector<std::vector<K::Point_3>> lines;
    for (const auto& f : features)
    {
      std::vector<K::Point_3> l;
      for (const auto& p : f)
      {
        l.emplace_back(p[0], p[1], p[2]);
      }
      lines.push_back(std::move(l));
    }
    domain.add_features(lines.begin(), lines.end());
  }

  TetMesh mesh;
  if (cgalMeshesInParallel(options))
  {
    runOnThreads(options.threads,
      [&]
      {
        mesh = refine<CGAL::Parallel_tag>(
          domain, solids, *labeller, features, outer, options, progress, n);
      });
  }
  else
  {
    mesh = refine<CGAL::Sequential_tag>(
      domain, solids, *labeller, features, outer, options, progress, n);
  }
  // A solid with no tetrahedron would silently be missing from the mesh (and from a solver's
  // element sets): refuse it by name.
  std::vector<bool> meshed(solids.size(), false);
  for (const std::int32_t m : mesh.materials)
  {
    meshed[static_cast<std::size_t>(m - 1)] = true;
  }
  for (std::size_t i = 0; i < solids.size(); ++i)
  {
    if (!meshed[i])
    {
      std::ostringstream s;
      s << "cell '" << solids[i].name << "' has no volume: no tetrahedron of it at size "
        << options.size << " (is it empty"
        << (solids.size() > 1 ? ", or covered by cells of higher priority" : "") << "?)";
      throw std::invalid_argument(s.str());
    }
  }
  progress.report(1);
  return mesh;
}

} // namespace ictk::mesh
