// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Internal to the Discretize library: the pieces of contourSurface (Surface.h), shared by the
// files that implement it. Not installed (PRIVATE_HEADERS in CMakeLists.txt): its declarations
// may change freely.
//
// Manifold dual contouring (Ju et al. 2002; Schaefer, Ju & Warren 2007) over an interval-pruned
// octree, one concern per file (as Fidget splits its mesher into octree, QEF and dual contouring):
//  - SurfaceOctree.cxx: the grid over the box and the octree that prunes it by interval bounds:
//    descended sequentially to tasks of TaskCells^3 cells, then by each task (in parallel), with
//    narrowed evaluators, to blocks of BlockCells^3 cells;
//  - SurfaceHermite.cxx: one block: samples its corner grid in one values() call, finds the
//    Hermite data of its sign-changing edges in a few batched false-position steps, and places
//    one vertex per patch component of each cell;
//  - SurfaceCube.cxx: the cube tables: the marching-cubes patch of a cell, its boundary cycles and
//    their components, and the asymptotic decider of ambiguous faces;
//  - SurfaceQef.cxx: where a vertex goes: the quadric error function of its crossings (the only
//    user of Eigen);
//  - SurfaceRepair.cxx: the rare non-manifold configurations, repaired by splitting a vertex;
//  - Surface.cxx: contourSurface itself: threads and progress, the blocks sorted by position (the
//    output order does not depend on the threads), vertex numbering, and the quad of the four
//    cells around each sign-changing edge.
//
// Grid indexing, per axis a: point p lies at lo + (p - 1) h; points 1..pin[a] are inside the box;
// points 0 and pin[a] + 1 are outside (a padding layer, so that a solid cut by the box is closed);
// cell c spans points c and c + 1, for c in [0, pin[a]].

#include "Discretize/Surface.h"
#include "FRep/Sampling.h"

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

namespace ictk::discretize::detail::surface
{

using frep::FieldEvaluator;
using frep::Interval;

constexpr int BlockCells = 8;
constexpr int BlockPoints = BlockCells + 1;
constexpr int BlockPointCount = BlockPoints * BlockPoints * BlockPoints;
constexpr int BlockCellCount = BlockCells * BlockCells * BlockCells;
// Tasks handed to the threads: cubes of this many cells per axis (a power-of-2 multiple of
// BlockCells).
constexpr int TaskCells = 4 * BlockCells;
constexpr std::uint16_t NoVertex = 0xFFFF;

// --- cube tables (SurfaceCube.cxx) -----------------------------------------------------------
// Corner c = x + 2y + 4z. Edge 4a + u + 2v runs along axis a, at coordinate u on the first and v
// on the second of the other two axes (ascending). Face 2a + s holds the corners with coordinate
// s on axis a.
constexpr int OtherAxes[3][2] = { { 1, 2 }, { 0, 2 }, { 0, 1 } };

inline int cornerAt(const int c[3])
{
  return c[0] | (c[1] << 1) | (c[2] << 2);
}

inline int edgeAt(int axis, const int c[3])
{
  return 4 * axis + c[OtherAxes[axis][0]] + 2 * c[OtherAxes[axis][1]];
}

inline bool inside(int mask, int corner)
{
  return (mask >> corner) & 1;
}

struct CubeGeometry
{
  int edgeCorner[12][2]; // [0] has coordinate 0 on the edge's axis
  int edgeFace[12][2];   // the two faces that hold the edge
  // Face f: corners q[u + 2v] and edges: eb[v] along the first other axis (from q(0,v) to
  // q(1,v)), ec[u] along the second (from q(u,0) to q(u,1)).
  int faceCorner[6][4];
  int faceEdgeB[6][2];
  int faceEdgeC[6][2];
  CubeGeometry();
};

const CubeGeometry& cube();

/// One step of a patch boundary cycle: the edge and the face that leads to the next edge
/// (-1 for the closing step of a piece cut by splitVertices).
struct CycleStep
{
  int edge;
  int face;
};

/// The boundary cycles of the marching-cubes patch of a cell: on each face the sign-changing
/// edges are paired (on an ambiguous face, by `connected`: bit f set = the inside corners of face
/// f are joined), so the pairs form disjoint cycles on the cube, each bounding one disc.
std::vector<std::vector<CycleStep>> patchCycles(int mask, int connected);

struct CaseEntry
{
  std::uint8_t components = 0;
  std::uint8_t component[12]; // 0xFF: the edge does not cross
  /// Bit f: face f is ambiguous and both of its segments lie on one cycle.
  std::uint8_t doubled = 0;
};

struct CaseTable
{
  std::uint8_t ambiguous[256];
  std::vector<CaseEntry> entries; // [mask * 64 + connected bits of the ambiguous faces]
  CaseTable();
};

const CaseTable& caseTable();

/// The ambiguous faces whose inside corners are joined: by the asymptotic decider, the bilinear
/// saddle of the face is inside iff the product of the inside values is at least that of the
/// outside values. Both cells of a face compute it from the same four values.
int joinedFaces(int mask, const double v[8]);

// --- grid layout (SurfaceOctree.cxx) ---------------------------------------------------------

struct Layout
{
  Point3 lo{};
  Point3 hi{}; // max(box.hi, the last inside point): interval boxes enclose every point used
  double h = 0;
  std::array<int, 3> pin{};   // inside points are 1..pin[a]
  std::array<int, 3> cells{}; // cells 0..pin[a]
  int rootCells = 0;          // octree root edge (a power-of-2 multiple of BlockCells)
  std::int64_t blocksPerAxis = 0;

  double coord(int a, std::int64_t p) const { return lo[a] + static_cast<double>(p - 1) * h; }
  bool inBox(int a, std::int64_t p) const { return p >= 1 && p <= pin[a]; }

  /// The part of the box covered by the points o..o+size of a node.
  Box3 clippedBox(const std::array<int, 3>& o, int size) const
  {
    Box3 b;
    for (int a = 0; a < 3; ++a)
    {
      b.lo[a] = std::max(lo[a], coord(a, o[a]));
      b.hi[a] = std::min(hi[a], coord(a, o[a] + size));
    }
    return b;
  }
  bool touchesOutside(const std::array<int, 3>& o, int size) const
  {
    for (int a = 0; a < 3; ++a)
    {
      if (o[a] == 0 || o[a] + size > pin[a])
      {
        return true;
      }
    }
    return false;
  }
  bool intersectsCells(const std::array<int, 3>& o) const
  {
    return o[0] < cells[0] && o[1] < cells[1] && o[2] < cells[2];
  }
  std::uint64_t blockKey(const std::array<int, 3>& o) const
  {
    return (static_cast<std::uint64_t>(o[2] / BlockCells) * blocksPerAxis +
             static_cast<std::uint64_t>(o[1] / BlockCells)) *
      blocksPerAxis +
      static_cast<std::uint64_t>(o[0] / BlockCells);
  }
};

/// The grid of cells of edge options.featureSize over `box`, with the checks that contourSurface
/// documents (std::invalid_argument).
Layout makeLayout(const Box3& box, const SurfaceOptions& options);

// --- per-block results -----------------------------------------------------------------------

struct CellRecord
{
  std::uint16_t local; // x + B (y + B z) in the block
  std::uint8_t mask;
  std::uint8_t doubled;
  std::uint16_t edgeVertex[12]; // block vertex of each crossing edge
};

/// What splitVertices needs to re-solve a cell (kept only for the rare doubled cells).
struct HermiteCell
{
  std::uint32_t cell; // index in Block::cells
  std::uint8_t joined;
  std::array<Point3, 12> point;
  std::array<Point3, 12> normal;
  std::array<bool, 12> hasNormal;
  Box3 clamp;
};

struct Block
{
  std::uint64_t key = 0;
  std::array<int, 3> origin{};
  std::vector<CellRecord> cells;
  std::vector<std::uint16_t> slot; // local cell -> index in cells, NoVertex if inactive
  std::vector<Point3> vertices;
  std::vector<HermiteCell> doubled;
  std::uint32_t vertexOffset = 0;
  std::vector<std::array<std::uint32_t, 3>> triangles;
};

/// The blocks, sorted by key, found by key.
class BlockIndex
{
public:
  explicit BlockIndex(const std::vector<std::unique_ptr<Block>>& blocks)
  {
    keys_.reserve(blocks.size());
    for (const auto& b : blocks)
    {
      keys_.push_back(b->key);
    }
  }
  /// Index of the block with this key, or -1.
  std::int64_t find(std::uint64_t key) const
  {
    const auto it = std::lower_bound(keys_.begin(), keys_.end(), key);
    return it != keys_.end() && *it == key ? it - keys_.begin() : -1;
  }

private:
  std::vector<std::uint64_t> keys_;
};

// --- QEF (SurfaceQef.cxx) --------------------------------------------------------------------

/// A crossing of the surface with a grid edge and the unit normal there.
struct Hermite
{
  Point3 p;
  Point3 n;
  bool hasNormal;
};

/// The vertex of one patch component: the minimiser of sum (n_i . (x - p_i))^2 nearest the mass
/// point (small eigenvalues dropped), clamped to `clamp` (the cell); `sharp` false: the mass
/// point.
Point3 placeVertex(const Hermite* data, int count, bool sharp, const Box3& clamp, double h);

// --- block contouring (SurfaceHermite.cxx) ---------------------------------------------------

/// Contours one block at a time; one per thread (it keeps its buffers between blocks).
class BlockContourer
{
public:
  BlockContourer(const Layout& layout, bool sharp);

  /// Contours the block at `o` (cells o..o+BlockCells-1) into `block`; false if it has no
  /// active cell.
  bool run(FieldEvaluator& ev, const std::array<int, 3>& o, bool knownInside, Block& block);

private:
  struct Edge
  {
    int axis;
    int point;      // local index of the lower end
    double base[3]; // world coordinates of the lower end
    double ta, va;  // inside end: coordinate along the axis and value
    double tb, vb;  // outside end
    int side;       // Illinois: the end replaced last (0 = a, 1 = b, -1 none)
    bool pendingFace;
    bool done;
    bool face; // the crossing is on the box face (normal = the axis)
    Hermite hermite;
  };

  struct ActiveCell
  {
    int local; // cell index in the block
    int base;  // point index of corner 0
    int mask;
  };

  static int local(int i, int j, int k) { return i + BlockPoints * (j + BlockPoints * k); }
  static int pointOffset(int corner);
  static double falsePosition(const Edge& e);

  void sample(FieldEvaluator& ev, const std::array<int, 3>& o, bool knownInside);
  void findCells(const std::array<int, 3>& o);
  void findCrossings(FieldEvaluator& ev, const std::array<int, 3>& o, bool knownInside);
  Edge makeEdge(const std::array<int, 3>& o, int axis, int point, bool knownInside) const;
  void placeVertices(const std::array<int, 3>& o, Block& block);
  /// The box a vertex of the cell may occupy: the cell, within the (padded) box.
  Box3 cellClamp(const std::array<int, 3>& o, int localCell) const;

  const Layout& layout_;
  bool sharp_;
  std::vector<double> values_;
  std::uint8_t in_[BlockPointCount];
  std::vector<int> edgeSlot_[3];
  std::vector<ActiveCell> active_;
  std::vector<Edge> edges_;
  std::vector<double> xs_, ys_, zs_, out_, trial_;
  std::vector<int> where_;
};

// --- time coherence (SurfaceMemory, Surface.h) ----------------------------------------------

/// A block as the octree yielded it, before the assembly's repairs and numbering, with what it
/// was computed from: the fingerprint of the block's evaluator (none when it is known to be
/// inside: such a block never evaluates the field, its values are +1 inside the box and -1
/// beyond).
struct KeptBlock
{
  std::uint64_t key = 0;
  bool knownInside = false;
  bool fingerprinted = false;
  std::vector<std::uint64_t> fingerprint;
  std::shared_ptr<const Block> block; ///< null: the block has no active cell
};

/// A task (an octree node handed to a thread) and its blocks, in descent order.
struct KeptTask
{
  std::array<int, 3> origin{};
  int size = 0;
  bool knownInside = false;
  bool fingerprinted = false;
  std::vector<std::uint64_t> fingerprint;
  std::vector<KeptBlock> blocks;
};

/// What one task of a call with a SurfaceMemory reuses (the previous call's task at the same
/// place) and keeps (this call's).
struct TaskMemory
{
  const KeptTask* previous = nullptr;
  std::vector<std::pair<std::uint64_t, std::size_t>> byKey; // previous->blocks, sorted by key
  KeptTask* next = nullptr;
  std::size_t contoured = 0;
  std::size_t reused = 0;
  const KeptBlock* find(std::uint64_t key) const
  {
    const auto it =
      std::lower_bound(byKey.begin(), byKey.end(), std::make_pair(key, std::size_t(0)));
    return it != byKey.end() && it->first == key ? &previous->blocks[it->second] : nullptr;
  }
};

/// Whether kept work done with (knownInside, fingerprint) holds for a node now: known inside
/// both times (the field is not evaluated), or evaluators with equal fingerprints.
inline bool sameWork(bool knownInside, bool fingerprinted, const std::vector<std::uint64_t>& fp,
  bool keptInside, bool keptFingerprinted, const std::vector<std::uint64_t>& keptFp)
{
  if (knownInside != keptInside)
  {
    return false;
  }
  return knownInside || (fingerprinted && keptFingerprinted && fp == keptFp);
}

// --- octree (SurfaceOctree.cxx) --------------------------------------------------------------

/// A node of the octree handed to a thread.
struct Task
{
  std::array<int, 3> origin;
  int size;
  bool knownInside;
};

/// The nodes of the octree down to TaskCells that may hold the surface (or are inside and touch
/// the outside padding), in octree order.
void collectTasks(FieldEvaluator& ev, const Layout& layout, const std::array<int, 3>& o, int size,
  std::vector<Task>& tasks);

/// Descends the node at `o` to its blocks that may hold the surface and contours them into
/// `blocks`, in octree order. With `memory`: a block whose evaluator has the fingerprint it had
/// in the previous call is copied from it instead, and every block visited is kept.
void descend(FieldEvaluator& ev, const Layout& layout, const std::array<int, 3>& o, int size,
  bool knownInside, BlockContourer& contourer, std::vector<std::unique_ptr<Block>>& blocks,
  TaskMemory* memory = nullptr);

// --- non-manifold repair (SurfaceRepair.cxx) -------------------------------------------------

/// Splits the vertex of each cell pair whose shared ambiguous face makes a dual edge bound four
/// quads (a tunnel through two cells), so that the surface stays a 2-manifold. `blocks` sorted by
/// key, `index` over them.
void splitVertices(std::vector<std::unique_ptr<Block>>& blocks, const BlockIndex& index,
  const Layout& layout, bool sharp);

} // namespace ictk::discretize::detail::surface

namespace ictk::discretize
{

struct SurfaceMemory::State
{
  /// The grid the kept work belongs to: another grid forgets it.
  bool valid = false;
  Point3 lo{};
  double h = 0;
  std::array<int, 3> pin{};
  bool sharp = true;
  /// In the order of collectTasks.
  std::vector<detail::surface::KeptTask> tasks;
};

} // namespace ictk::discretize
