// SPDX-License-Identifier: BSD-3-Clause
// Manifold dual contouring (Ju et al. 2002; Schaefer, Ju & Warren 2007) over an interval-pruned
// octree. Outline:
//  1. The octree is descended sequentially to tasks of TaskCells^3 cells; each task (in
//     parallel) descends further with narrowed evaluators to blocks of BlockCells^3 cells, samples
//     each block's corner grid in one values() call, finds the Hermite data of its sign-changing
//     edges in a few batched false-position steps, and places one vertex per patch component of
//     each cell.
//  2. The blocks are sorted by position (the output order does not depend on the threads), rare
//     non-manifold configurations are repaired by splitting a vertex, vertices are numbered, and
//     each sign-changing edge becomes a quad of the four cells around it.
//
// Grid indexing, per axis a: point p lies at lo + (p - 1) h; points 1..pin[a] are inside the box;
// points 0 and pin[a] + 1 are outside (a padding layer, so that a solid cut by the box is closed);
// cell c spans points c and c + 1, for c in [0, pin[a]].
#include "Discretize/Surface.h"

#include "FRep/Sampling.h"

#include <Eigen/Dense>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <vector>

namespace ictk::discretize
{
namespace
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
// False-position steps per edge crossing.
constexpr int RootSteps = 3;
// Eigenvalues of the QEF matrix below this fraction of the largest are dropped.
constexpr double EigenCutoff = 0.01;
// A feature-line vertex may fall this many cell edges outside its cell before the rank drops to
// 1 (measured on the sphere-gyroid: 0 gives chamfered curved edges, 0.5 folds at coarse sizes).
constexpr double FeatureLineSlack = 0.1;
// Vertices keep this fraction of the cell edge away from the cell faces, so that vertices of
// different cells never coincide.
constexpr double CellMargin = 1e-4;
constexpr std::uint16_t NoVertex = 0xFFFF;

// --- cube tables ------------------------------------------------------------------------------
// Corner c = x + 2y + 4z. Edge 4a + u + 2v runs along axis a, at coordinate u on the first and v
// on the second of the other two axes (ascending). Face 2a + s holds the corners with coordinate
// s on axis a.
constexpr int OtherAxes[3][2] = { { 1, 2 }, { 0, 2 }, { 0, 1 } };

int cornerAt(const int c[3])
{
  return c[0] | (c[1] << 1) | (c[2] << 2);
}

int edgeAt(int axis, const int c[3])
{
  return 4 * axis + c[OtherAxes[axis][0]] + 2 * c[OtherAxes[axis][1]];
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
  CubeGeometry()
  {
    for (int e = 0; e < 12; ++e)
    {
      const int a = e / 4, u = e & 1, v = (e >> 1) & 1;
      int c[3];
      c[a] = 0;
      c[OtherAxes[a][0]] = u;
      c[OtherAxes[a][1]] = v;
      edgeCorner[e][0] = cornerAt(c);
      c[a] = 1;
      edgeCorner[e][1] = cornerAt(c);
      edgeFace[e][0] = 2 * OtherAxes[a][0] + u;
      edgeFace[e][1] = 2 * OtherAxes[a][1] + v;
    }
    for (int f = 0; f < 6; ++f)
    {
      const int a = f / 2, s = f & 1, b = OtherAxes[a][0], cc = OtherAxes[a][1];
      for (int v = 0; v < 2; ++v)
      {
        for (int u = 0; u < 2; ++u)
        {
          int c[3];
          c[a] = s;
          c[b] = u;
          c[cc] = v;
          faceCorner[f][u + 2 * v] = cornerAt(c);
        }
      }
      for (int v = 0; v < 2; ++v)
      {
        int c[3] = { 0, 0, 0 };
        c[a] = s;
        c[cc] = v;
        faceEdgeB[f][v] = edgeAt(b, c);
      }
      for (int u = 0; u < 2; ++u)
      {
        int c[3] = { 0, 0, 0 };
        c[a] = s;
        c[b] = u;
        faceEdgeC[f][u] = edgeAt(cc, c);
      }
    }
  }
};

const CubeGeometry& cube()
{
  static const CubeGeometry g;
  return g;
}

bool inside(int mask, int corner)
{
  return (mask >> corner) & 1;
}

/// Faces whose four corners alternate in sign (two diagonal inside corners).
int ambiguousFaces(int mask)
{
  const CubeGeometry& g = cube();
  int faces = 0;
  for (int f = 0; f < 6; ++f)
  {
    const bool q00 = inside(mask, g.faceCorner[f][0]), q10 = inside(mask, g.faceCorner[f][1]),
               q01 = inside(mask, g.faceCorner[f][2]), q11 = inside(mask, g.faceCorner[f][3]);
    if (q00 == q11 && q10 == q01 && q00 != q10)
    {
      faces |= 1 << f;
    }
  }
  return faces;
}

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
std::vector<std::vector<CycleStep>> patchCycles(int mask, int connected)
{
  const CubeGeometry& g = cube();
  int partner[12][2];
  for (auto& p : partner)
  {
    p[0] = p[1] = -1;
  }
  auto link = [&](int f, int e1, int e2)
  {
    partner[e1][g.edgeFace[e1][0] == f ? 0 : 1] = e2;
    partner[e2][g.edgeFace[e2][0] == f ? 0 : 1] = e1;
  };
  auto crosses = [&](int e)
  {
    return inside(mask, g.edgeCorner[e][0]) != inside(mask, g.edgeCorner[e][1]);
  };
  for (int f = 0; f < 6; ++f)
  {
    const int eb0 = g.faceEdgeB[f][0], eb1 = g.faceEdgeB[f][1], ec0 = g.faceEdgeC[f][0],
              ec1 = g.faceEdgeC[f][1];
    const int edges[4] = { eb0, eb1, ec0, ec1 };
    int active[4], n = 0;
    for (int e : edges)
    {
      if (crosses(e))
      {
        active[n++] = e;
      }
    }
    if (n == 2)
    {
      link(f, active[0], active[1]);
    }
    else if (n == 4)
    {
      // Cut off the two corners of the sign that is not joined across the face; corner q(u,v)
      // touches eb[v] and ec[u].
      const bool q00Inside = inside(mask, g.faceCorner[f][0]);
      const bool joinedInside = (connected >> f) & 1;
      // The separated corners are q00 and q11 when they are inside and not joined, or outside
      // while the inside (q10, q01) is joined.
      if (q00Inside != joinedInside)
      {
        link(f, eb0, ec0); // q00
        link(f, eb1, ec1); // q11
      }
      else
      {
        link(f, eb0, ec1); // q10
        link(f, eb1, ec0); // q01
      }
    }
  }
  std::vector<std::vector<CycleStep>> cycles;
  bool seen[12] = {};
  for (int start = 0; start < 12; ++start)
  {
    if (seen[start] || !crosses(start))
    {
      continue;
    }
    std::vector<CycleStep> cycle;
    int e = start, slot = 0;
    do
    {
      seen[e] = true;
      const int face = g.edgeFace[e][slot];
      const int next = partner[e][slot];
      cycle.push_back({ e, face });
      slot = g.edgeFace[next][0] == face ? 1 : 0;
      e = next;
    } while (e != start);
    cycles.push_back(std::move(cycle));
  }
  return cycles;
}

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
  CaseTable()
    : entries(256 * 64)
  {
    for (int mask = 0; mask < 256; ++mask)
    {
      ambiguous[mask] = static_cast<std::uint8_t>(ambiguousFaces(mask));
      for (int bits = 0; bits < 64; ++bits)
      {
        if ((bits & ~ambiguous[mask]) != 0)
        {
          continue;
        }
        CaseEntry& entry = entries[mask * 64 + bits];
        std::fill(std::begin(entry.component), std::end(entry.component), 0xFF);
        const auto cycles = patchCycles(mask, bits);
        entry.components = static_cast<std::uint8_t>(cycles.size());
        for (std::size_t k = 0; k < cycles.size(); ++k)
        {
          int facesSeen = 0;
          for (const CycleStep& s : cycles[k])
          {
            entry.component[s.edge] = static_cast<std::uint8_t>(k);
            if ((facesSeen >> s.face) & 1)
            {
              entry.doubled |= static_cast<std::uint8_t>(1 << s.face);
            }
            facesSeen |= 1 << s.face;
          }
        }
      }
    }
  }
};

const CaseTable& caseTable()
{
  static const CaseTable table;
  return table;
}

/// The ambiguous faces whose inside corners are joined: by the asymptotic decider, the bilinear
/// saddle of the face is inside iff the product of the inside values is at least that of the
/// outside values. Both cells of a face compute it from the same four values.
int joinedFaces(int mask, const double v[8])
{
  const CubeGeometry& g = cube();
  const int faces = caseTable().ambiguous[mask];
  int bits = 0;
  for (int f = 0; f < 6; ++f)
  {
    if ((faces >> f) & 1)
    {
      const int* q = g.faceCorner[f];
      const double diagonal00 = v[q[0]] * v[q[3]], diagonal10 = v[q[1]] * v[q[2]];
      const bool q00Inside = inside(mask, q[0]);
      const double in = q00Inside ? diagonal00 : diagonal10;
      const double out = q00Inside ? diagonal10 : diagonal00;
      if (in >= out)
      {
        bits |= 1 << f;
      }
    }
  }
  return bits;
}

// --- grid layout --------------------------------------------------------------------------------

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

enum class NodeKind
{
  Skip,
  Inside, // inside everywhere in the box, but it touches the outside padding
  Mixed
};

NodeKind classify(FieldEvaluator& ev, const Layout& layout, const std::array<int, 3>& o, int size)
{
  if (!layout.intersectsCells(o))
  {
    return NodeKind::Skip;
  }
  const Interval iv = ev.bound(layout.clippedBox(o, size));
  // NaN counts as outside, like a negative value.
  if (iv.empty())
  {
    return iv.maybeNaN ? NodeKind::Skip : NodeKind::Mixed;
  }
  if (iv.hi < 0)
  {
    return NodeKind::Skip;
  }
  if (iv.lo > 0 && !iv.maybeNaN)
  {
    return layout.touchesOutside(o, size) ? NodeKind::Inside : NodeKind::Skip;
  }
  return NodeKind::Mixed;
}

// --- per-block results --------------------------------------------------------------------------

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

// --- QEF ----------------------------------------------------------------------------------------

struct Hermite
{
  Point3 p;
  Point3 n;
  bool hasNormal;
};

/// The vertex of one patch component: the minimiser of sum (n_i . (x - p_i))^2 nearest the mass
/// point (eigenvalues below EigenCutoff of the largest dropped), clamped to `clamp`.
Point3 placeVertex(const Hermite* data, int count, bool sharp, const Box3& clamp, double h)
{
  // Local coordinates (relative to the clamp box corner, in cell units) for conditioning.
  const Point3& o = clamp.lo;
  Eigen::Vector3d mass = Eigen::Vector3d::Zero();
  for (int i = 0; i < count; ++i)
  {
    mass += Eigen::Vector3d(
      (data[i].p[0] - o[0]) / h, (data[i].p[1] - o[1]) / h, (data[i].p[2] - o[2]) / h);
  }
  mass /= static_cast<double>(count);
  Eigen::Vector3d x = mass;
  if (sharp)
  {
    Eigen::Matrix3d ata = Eigen::Matrix3d::Zero();
    Eigen::Vector3d atb = Eigen::Vector3d::Zero();
    int normals = 0;
    for (int i = 0; i < count; ++i)
    {
      if (!data[i].hasNormal)
      {
        continue;
      }
      const Eigen::Vector3d n(data[i].n[0], data[i].n[1], data[i].n[2]);
      const Eigen::Vector3d p(
        (data[i].p[0] - o[0]) / h, (data[i].p[1] - o[1]) / h, (data[i].p[2] - o[2]) / h);
      ata += n * n.transpose();
      atb += n * n.dot(p - mass);
      ++normals;
    }
    if (normals > 0)
    {
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es;
      es.computeDirect(ata);
      const Eigen::Vector3d lambda = es.eigenvalues(); // ascending
      const Eigen::Matrix3d& v = es.eigenvectors();
      const Eigen::Vector3d vtb = v.transpose() * atb;
      const double largest = lambda[2];
      // The cell, in local units. A corner outside it is a feature of a neighbouring cell or a
      // false corner made by curvature (a cause of folds): the rank is lowered to 2 (the point
      // of the feature line nearest the mass point), and to 1 (the mass point moved onto the
      // mean tangent plane) when that point lies more than FeatureLineSlack cells outside too.
      Eigen::Vector3d extent;
      for (int a = 0; a < 3; ++a)
      {
        extent[a] = (clamp.hi[a] - clamp.lo[a]) / h;
      }
      for (int rank = 3; rank >= 1; --rank)
      {
        Eigen::Vector3d inv = Eigen::Vector3d::Zero();
        for (int k = 3 - rank; k < 3; ++k)
        {
          if (largest > 0 && lambda[k] > EigenCutoff * largest)
          {
            inv[k] = 1.0 / lambda[k];
          }
        }
        const Eigen::Vector3d candidate = mass + v * inv.cwiseProduct(vtb);
        if (!candidate.allFinite())
        {
          continue;
        }
        x = candidate;
        const double slack = rank == 3 ? 1e-9 : FeatureLineSlack;
        if ((candidate.array() >= -slack).all() &&
          (candidate.array() <= extent.array() + slack).all())
        {
          break;
        }
      }
    }
  }
  Point3 r;
  for (int a = 0; a < 3; ++a)
  {
    const double width = clamp.hi[a] - clamp.lo[a];
    const double margin = std::min(CellMargin * h, 0.25 * width);
    const double w = o[a] + x[a] * h;
    r[a] = std::clamp(std::isfinite(w) ? w : 0.5 * (clamp.lo[a] + clamp.hi[a]),
      clamp.lo[a] + margin, clamp.hi[a] - margin);
  }
  return r;
}

// --- block contouring ---------------------------------------------------------------------------

class BlockContourer
{
public:
  BlockContourer(const Layout& layout, bool sharp)
    : layout_(layout)
    , sharp_(sharp)
  {
    values_.resize(BlockPointCount);
    for (auto& s : edgeSlot_)
    {
      s.assign(BlockPointCount, -1);
    }
  }

  /// Contours the block at `o` (cells o..o+BlockCells-1) into `block`; false if it has no
  /// active cell.
  bool run(FieldEvaluator& ev, const std::array<int, 3>& o, bool knownInside, Block& block)
  {
    sample(ev, o, knownInside);
    findCells(o);
    if (active_.empty())
    {
      return false;
    }
    findCrossings(ev, o, knownInside);
    block.key = layout_.blockKey(o);
    block.origin = o;
    block.slot.assign(BlockCellCount, NoVertex);
    placeVertices(o, block);
    for (const Edge& e : edges_)
    {
      edgeSlot_[e.axis][e.point] = -1;
    }
    return true;
  }

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

  static int local(int i, int j, int k) { return i + BlockPoints * (j + BlockPoints * k); }

  void sample(FieldEvaluator& ev, const std::array<int, 3>& o, bool knownInside)
  {
    xs_.clear();
    ys_.clear();
    zs_.clear();
    where_.clear();
    for (int k = 0; k < BlockPoints; ++k)
    {
      const int pz = o[2] + k;
      const bool inZ = layout_.inBox(2, pz);
      const double z = layout_.coord(2, pz);
      for (int j = 0; j < BlockPoints; ++j)
      {
        const int py = o[1] + j;
        const bool inYZ = inZ && layout_.inBox(1, py);
        const double y = layout_.coord(1, py);
        for (int i = 0; i < BlockPoints; ++i)
        {
          const int px = o[0] + i;
          const int idx = local(i, j, k);
          if (!(inYZ && layout_.inBox(0, px)))
          {
            values_[idx] = -1;
          }
          else if (knownInside)
          {
            values_[idx] = 1;
          }
          else
          {
            xs_.push_back(layout_.coord(0, px));
            ys_.push_back(y);
            zs_.push_back(z);
            where_.push_back(idx);
          }
        }
      }
    }
    if (!where_.empty())
    {
      out_.resize(where_.size());
      ev.values(xs_.data(), ys_.data(), zs_.data(), out_.data(), where_.size());
      for (std::size_t n = 0; n < where_.size(); ++n)
      {
        values_[where_[n]] = out_[n];
      }
    }
  }

  void findCells(const std::array<int, 3>& o)
  {
    active_.clear();
    const int ni = std::min(BlockCells, layout_.cells[0] - o[0]);
    const int nj = std::min(BlockCells, layout_.cells[1] - o[1]);
    const int nk = std::min(BlockCells, layout_.cells[2] - o[2]);
    // Inside bits of the points (NaN is outside).
    for (int n = 0; n < BlockPointCount; ++n)
    {
      in_[n] = values_[n] >= 0 ? 1 : 0;
    }
    static constexpr int cornerOffset[8] = { 0, 1, BlockPoints, BlockPoints + 1,
      BlockPoints * BlockPoints, BlockPoints * BlockPoints + 1,
      BlockPoints * BlockPoints + BlockPoints, BlockPoints * BlockPoints + BlockPoints + 1 };
    for (int k = 0; k < nk; ++k)
    {
      for (int j = 0; j < nj; ++j)
      {
        for (int i = 0; i < ni; ++i)
        {
          const int base = local(i, j, k);
          int mask = 0;
          for (int c = 0; c < 8; ++c)
          {
            mask |= in_[base + cornerOffset[c]] << c;
          }
          if (mask != 0 && mask != 255)
          {
            active_.push_back({ i + BlockCells * (j + BlockCells * k), base, mask });
          }
        }
      }
    }
  }

  void findCrossings(FieldEvaluator& ev, const std::array<int, 3>& o, bool knownInside)
  {
    const CubeGeometry& g = cube();
    edges_.clear();
    for (const ActiveCell& cell : active_)
    {
      for (int e = 0; e < 12; ++e)
      {
        const int c0 = g.edgeCorner[e][0], c1 = g.edgeCorner[e][1];
        if (inside(cell.mask, c0) == inside(cell.mask, c1))
        {
          continue;
        }
        const int axis = e / 4;
        const int point = cell.base + pointOffset(c0);
        if (edgeSlot_[axis][point] >= 0)
        {
          continue;
        }
        edgeSlot_[axis][point] = static_cast<int>(edges_.size());
        edges_.push_back(makeEdge(o, axis, point, knownInside));
      }
    }
    // Batched false position (Illinois): every step evaluates all open edges in one call.
    for (int step = 0; step < RootSteps; ++step)
    {
      xs_.clear();
      ys_.clear();
      zs_.clear();
      where_.clear();
      for (std::size_t n = 0; n < edges_.size(); ++n)
      {
        Edge& e = edges_[n];
        if (e.done)
        {
          continue;
        }
        const double t = e.pendingFace ? e.tb : falsePosition(e);
        double p[3] = { e.base[0], e.base[1], e.base[2] };
        p[e.axis] = t;
        xs_.push_back(p[0]);
        ys_.push_back(p[1]);
        zs_.push_back(p[2]);
        where_.push_back(static_cast<int>(n));
        trial_.resize(where_.size());
        trial_.back() = t;
      }
      if (where_.empty())
      {
        break;
      }
      out_.resize(where_.size());
      ev.values(xs_.data(), ys_.data(), zs_.data(), out_.data(), where_.size());
      for (std::size_t n = 0; n < where_.size(); ++n)
      {
        Edge& e = edges_[where_[n]];
        const double t = trial_[n], v = out_[n];
        if (e.pendingFace)
        {
          e.pendingFace = false;
          if (v >= 0)
          {
            e.done = true;
            e.face = true;
          }
          else
          {
            e.vb = v;
          }
          continue;
        }
        if (v >= 0)
        {
          e.ta = t;
          e.va = v;
          if (e.side == 0 && std::isfinite(e.vb))
          {
            e.vb *= 0.5;
          }
          e.side = 0;
        }
        else
        {
          e.tb = t;
          e.vb = v;
          if (e.side == 1 && std::isfinite(e.va))
          {
            e.va *= 0.5;
          }
          e.side = 1;
        }
      }
    }
    for (Edge& e : edges_)
    {
      double p[3] = { e.base[0], e.base[1], e.base[2] };
      Hermite& hm = e.hermite;
      if (e.face)
      {
        p[e.axis] = e.tb;
        hm.p = { p[0], p[1], p[2] };
        hm.n = { 0, 0, 0 };
        hm.n[e.axis] = 1;
        hm.hasNormal = true;
        continue;
      }
      p[e.axis] = falsePosition(e);
      hm.p = { p[0], p[1], p[2] };
      hm.hasNormal = false;
      if (sharp_)
      {
        Point3 grad;
        ev.gradient(hm.p, grad);
        const double len = std::sqrt(grad[0] * grad[0] + grad[1] * grad[1] + grad[2] * grad[2]);
        if (std::isfinite(len) && len > 0)
        {
          hm.n = { grad[0] / len, grad[1] / len, grad[2] / len };
          hm.hasNormal = true;
        }
      }
    }
  }

  static int pointOffset(int corner)
  {
    return (corner & 1) + BlockPoints * ((corner >> 1) & 1) +
      BlockPoints * BlockPoints * ((corner >> 2) & 1);
  }

  Edge makeEdge(const std::array<int, 3>& o, int axis, int point, bool knownInside) const
  {
    Edge e{};
    const int li[3] = { point % BlockPoints, (point / BlockPoints) % BlockPoints,
      point / (BlockPoints * BlockPoints) };
    for (int a = 0; a < 3; ++a)
    {
      e.base[a] = layout_.coord(a, o[a] + li[a]);
    }
    e.axis = axis;
    e.point = point;
    e.side = -1;
    const int step = axis == 0 ? 1 : (axis == 1 ? BlockPoints : BlockPoints * BlockPoints);
    const std::int64_t g0 = o[axis] + li[axis], g1 = g0 + 1;
    const double v0 = values_[point], v1 = values_[point + step];
    const bool firstInside = v0 >= 0;
    const std::int64_t gin = firstInside ? g0 : g1, gout = firstInside ? g1 : g0;
    e.ta = layout_.coord(axis, gin);
    e.va = firstInside ? v0 : v1;
    if (layout_.inBox(axis, gout))
    {
      e.tb = layout_.coord(axis, gout);
      e.vb = firstInside ? v1 : v0;
      return e;
    }
    // The outside end lies beyond the box: the crossing is on the box face unless f changes
    // sign before it.
    e.tb = gout == 0 ? layout_.lo[axis] : layout_.hi[axis];
    e.vb = -1;
    if (e.tb == e.ta || knownInside)
    {
      e.done = true;
      e.face = true;
    }
    else
    {
      e.pendingFace = true;
    }
    return e;
  }

  static double falsePosition(const Edge& e)
  {
    const double d = e.va - e.vb;
    if (std::isfinite(e.va) && std::isfinite(e.vb) && d > 0)
    {
      const double t = e.ta + e.va / d * (e.tb - e.ta);
      if (std::isfinite(t))
      {
        return t;
      }
    }
    return 0.5 * (e.ta + e.tb);
  }

  void placeVertices(const std::array<int, 3>& o, Block& block)
  {
    const CubeGeometry& g = cube();
    const CaseTable& table = caseTable();
    block.cells.reserve(active_.size());
    for (const ActiveCell& cell : active_)
    {
      double v[8];
      for (int c = 0; c < 8; ++c)
      {
        v[c] = values_[cell.base + pointOffset(c)];
      }
      const int joined = joinedFaces(cell.mask, v);
      const CaseEntry& entry = table.entries[cell.mask * 64 + joined];
      CellRecord record{};
      record.local = static_cast<std::uint16_t>(cell.local);
      record.mask = static_cast<std::uint8_t>(cell.mask);
      record.doubled = entry.doubled;
      std::fill(std::begin(record.edgeVertex), std::end(record.edgeVertex), NoVertex);
      const Box3 clamp = cellClamp(o, cell.local);
      Hermite data[12];
      int edgeOf[12];
      for (int e = 0; e < 12; ++e)
      {
        edgeOf[e] = -1;
        if (entry.component[e] != 0xFF)
        {
          edgeOf[e] = edgeSlot_[e / 4][cell.base + pointOffset(g.edgeCorner[e][0])];
        }
      }
      for (int k = 0; k < entry.components; ++k)
      {
        int count = 0;
        for (int e = 0; e < 12; ++e)
        {
          if (entry.component[e] == k)
          {
            data[count++] = edges_[edgeOf[e]].hermite;
          }
        }
        const auto id = static_cast<std::uint16_t>(block.vertices.size());
        block.vertices.push_back(placeVertex(data, count, sharp_, clamp, layout_.h));
        for (int e = 0; e < 12; ++e)
        {
          if (entry.component[e] == k)
          {
            record.edgeVertex[e] = id;
          }
        }
      }
      if (entry.doubled != 0)
      {
        HermiteCell hc{};
        hc.cell = static_cast<std::uint32_t>(block.cells.size());
        hc.joined = static_cast<std::uint8_t>(joined);
        hc.clamp = clamp;
        for (int e = 0; e < 12; ++e)
        {
          if (edgeOf[e] >= 0)
          {
            const Hermite& hm = edges_[edgeOf[e]].hermite;
            hc.point[e] = hm.p;
            hc.normal[e] = hm.n;
            hc.hasNormal[e] = hm.hasNormal;
          }
        }
        block.doubled.push_back(hc);
      }
      block.slot[cell.local] = static_cast<std::uint16_t>(block.cells.size());
      block.cells.push_back(record);
    }
  }

  /// The box a vertex of the cell may occupy: the cell, within the (padded) box.
  Box3 cellClamp(const std::array<int, 3>& o, int localCell) const
  {
    const int l[3] = { localCell % BlockCells, (localCell / BlockCells) % BlockCells,
      localCell / (BlockCells * BlockCells) };
    Box3 b;
    for (int a = 0; a < 3; ++a)
    {
      const int c = o[a] + l[a];
      b.lo[a] = std::max(layout_.lo[a], layout_.coord(a, c));
      b.hi[a] = std::min(layout_.hi[a], layout_.coord(a, c + 1));
    }
    return b;
  }

  struct ActiveCell
  {
    int local; // cell index in the block
    int base;  // point index of corner 0
    int mask;
  };

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

// --- octree -------------------------------------------------------------------------------------

struct Task
{
  std::array<int, 3> origin;
  int size;
  bool knownInside;
};

void descend(FieldEvaluator& ev, const Layout& layout, const std::array<int, 3>& o, int size,
  bool knownInside, BlockContourer& contourer, std::vector<std::unique_ptr<Block>>& blocks)
{
  if (size == BlockCells)
  {
    if (knownInside && !layout.touchesOutside(o, size))
    {
      return;
    }
    auto block = std::make_unique<Block>();
    if (contourer.run(ev, o, knownInside, *block))
    {
      blocks.push_back(std::move(block));
    }
    return;
  }
  const int half = size / 2;
  for (int c = 0; c < 8; ++c)
  {
    const std::array<int, 3> child{ o[0] + (c & 1) * half, o[1] + ((c >> 1) & 1) * half,
      o[2] + ((c >> 2) & 1) * half };
    if (!layout.intersectsCells(child))
    {
      continue;
    }
    if (knownInside)
    {
      if (layout.touchesOutside(child, half))
      {
        descend(ev, layout, child, half, true, contourer, blocks);
      }
      continue;
    }
    const NodeKind kind = classify(ev, layout, child, half);
    if (kind == NodeKind::Skip)
    {
      continue;
    }
    if (kind == NodeKind::Inside)
    {
      descend(ev, layout, child, half, true, contourer, blocks);
      continue;
    }
    std::unique_ptr<FieldEvaluator> narrowed = ev.narrowed(layout.clippedBox(child, half));
    descend(narrowed ? *narrowed : ev, layout, child, half, false, contourer, blocks);
  }
}

void collectTasks(FieldEvaluator& ev, const Layout& layout, const std::array<int, 3>& o, int size,
  std::vector<Task>& tasks)
{
  const NodeKind kind = classify(ev, layout, o, size);
  if (kind == NodeKind::Skip)
  {
    return;
  }
  if (size <= TaskCells || kind == NodeKind::Inside)
  {
    tasks.push_back({ o, size, kind == NodeKind::Inside });
    return;
  }
  const int half = size / 2;
  for (int c = 0; c < 8; ++c)
  {
    collectTasks(ev, layout,
      { o[0] + (c & 1) * half, o[1] + ((c >> 1) & 1) * half, o[2] + ((c >> 2) & 1) * half }, half,
      tasks);
  }
}

// --- assembly -----------------------------------------------------------------------------------

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

struct CellRef
{
  Block* block = nullptr;
  CellRecord* cell = nullptr;
};

CellRef findCell(std::vector<std::unique_ptr<Block>>& blocks, const BlockIndex& index,
  const Layout& layout, const std::array<int, 3>& c)
{
  std::array<int, 3> origin;
  for (int a = 0; a < 3; ++a)
  {
    if (c[a] < 0 || c[a] >= layout.cells[a])
    {
      return {};
    }
    origin[a] = c[a] / BlockCells * BlockCells;
  }
  const std::int64_t b = index.find(layout.blockKey(origin));
  if (b < 0)
  {
    return {};
  }
  Block& block = *blocks[b];
  const int l =
    (c[0] - origin[0]) + BlockCells * ((c[1] - origin[1]) + BlockCells * (c[2] - origin[2]));
  if (block.slot[l] == NoVertex)
  {
    return {};
  }
  return { &block, &block.cells[block.slot[l]] };
}

/// Where one vertex per patch component is not manifold. An ambiguous face whose two segments lie
/// on one cycle of each of the two cells that share it (a tunnel through two cells) makes the dual
/// edge between the cells' vertices bound four quads. Cutting a cycle at the face's two segments
/// leaves two arcs, each joining an end of one segment to an end of the other. When the two
/// cells pair the ends differently, cutting the lower cell's cycle suffices: each of its two
/// vertices closes its fan through the upper cell's vertex, whose fan stays one disc. When they
/// pair them alike, both cycles are cut and the arcs are matched one to one. Either way the
/// surface becomes a manifold tube.
struct SplitState
{
  const HermiteCell* hermite = nullptr;
  std::vector<std::vector<CycleStep>> pieces;
  std::vector<int> origin; // the cycle (vertex) each piece comes from
};

/// The edge of the upper cell that is edge `e` (on face 2a + 1) of the lower one.
int edgeAcross(int e, int a)
{
  const CubeGeometry& g = cube();
  const int c0 = g.edgeCorner[e][0];
  int c[3] = { c0 & 1, (c0 >> 1) & 1, (c0 >> 2) & 1 };
  c[a] = 0;
  return edgeAt(e / 4, c);
}

/// The piece holding both segments of face f, and their positions in it.
bool findDoubled(const SplitState& s, int f, std::size_t& piece, std::size_t& i, std::size_t& j)
{
  for (piece = 0; piece < s.pieces.size(); ++piece)
  {
    std::size_t found = 0;
    for (std::size_t k = 0; k < s.pieces[piece].size(); ++k)
    {
      if (s.pieces[piece][k].face == f)
      {
        (found == 0 ? i : j) = k;
        ++found;
      }
    }
    if (found == 2)
    {
      return true;
    }
  }
  return false;
}

/// Cuts the piece at its steps i < j (both on one face) into two arcs closed by a virtual step.
void cutPiece(SplitState& s, std::size_t piece, std::size_t i, std::size_t j)
{
  const std::vector<CycleStep> steps = s.pieces[piece];
  const std::size_t m = steps.size();
  std::vector<CycleStep> first, second;
  for (std::size_t k = i + 1; k <= j; ++k)
  {
    first.push_back(steps[k % m]);
  }
  for (std::size_t k = j + 1; k <= i + m; ++k)
  {
    second.push_back(steps[k % m]);
  }
  first.back().face = -1;
  second.back().face = -1;
  s.pieces[piece] = std::move(first);
  s.pieces.push_back(std::move(second));
  s.origin.push_back(s.origin[piece]);
}

void splitVertices(std::vector<std::unique_ptr<Block>>& blocks, const BlockIndex& index,
  const Layout& layout, bool sharp)
{
  // Split states by (block, cell), created on first use; std::map keeps the order fixed.
  std::map<std::pair<std::size_t, std::uint32_t>, SplitState> states;
  std::map<std::pair<std::size_t, std::uint32_t>, const HermiteCell*> doubled;
  for (std::size_t b = 0; b < blocks.size(); ++b)
  {
    for (const HermiteCell& hc : blocks[b]->doubled)
    {
      doubled[{ b, hc.cell }] = &hc;
    }
  }
  auto stateOf = [&](std::size_t b, std::uint32_t cell) -> SplitState&
  {
    SplitState& s = states[{ b, cell }];
    if (!s.hermite)
    {
      s.hermite = doubled.at({ b, cell });
      const CellRecord& record = blocks[b]->cells[cell];
      s.pieces = patchCycles(record.mask, s.hermite->joined);
      for (std::size_t k = 0; k < s.pieces.size(); ++k)
      {
        s.origin.push_back(static_cast<int>(k));
      }
    }
    return s;
  };
  for (const auto& [where, hc] : doubled)
  {
    const Block& block = *blocks[where.first];
    const CellRecord& record = block.cells[hc->cell];
    const int l = record.local;
    const std::array<int, 3> c{ block.origin[0] + l % BlockCells,
      block.origin[1] + (l / BlockCells) % BlockCells,
      block.origin[2] + l / (BlockCells * BlockCells) };
    for (int a = 0; a < 3; ++a)
    {
      if (((record.doubled >> (2 * a + 1)) & 1) == 0)
      {
        continue;
      }
      std::array<int, 3> n = c;
      ++n[a];
      const CellRef other = findCell(blocks, index, layout, n);
      if (!other.cell || ((other.cell->doubled >> (2 * a)) & 1) == 0)
      {
        continue;
      }
      const std::size_t otherBlock = static_cast<std::size_t>(index.find(other.block->key));
      const auto otherCell = static_cast<std::uint32_t>(other.cell - other.block->cells.data());
      SplitState& lower = stateOf(where.first, hc->cell);
      SplitState& upper = stateOf(otherBlock, otherCell);
      std::size_t pl = 0, il = 0, jl = 0, pu = 0, iu = 0, ju = 0;
      if (!findDoubled(lower, 2 * a + 1, pl, il, jl) || !findDoubled(upper, 2 * a, pu, iu, ju))
      {
        continue; // already apart on one side: the dual edges differ
      }
      // The ends of the lower cell's first arc, seen from the upper cell.
      const auto& lp = lower.pieces[pl];
      const auto& up = upper.pieces[pu];
      const int lowerEnds[2] = { edgeAcross(lp[(il + 1) % lp.size()].edge, a),
        edgeAcross(lp[jl].edge, a) };
      const int upperEnds[2][2] = { { up[(iu + 1) % up.size()].edge, up[ju].edge },
        { up[(ju + 1) % up.size()].edge, up[iu].edge } };
      bool alike = false;
      for (const auto& ends : upperEnds)
      {
        alike = alike ||
          (std::min(ends[0], ends[1]) == std::min(lowerEnds[0], lowerEnds[1]) &&
            std::max(ends[0], ends[1]) == std::max(lowerEnds[0], lowerEnds[1]));
      }
      cutPiece(lower, pl, il, jl);
      if (alike)
      {
        cutPiece(upper, pu, iu, ju);
      }
    }
  }
  // Re-place the vertices of the cut cells: the first piece of each cycle keeps its vertex.
  for (auto& [where, s] : states)
  {
    if (s.pieces.size() == s.origin.size() &&
      s.origin.back() + 1 == static_cast<int>(s.pieces.size()))
    {
      continue; // nothing was cut
    }
    Block& block = *blocks[where.first];
    CellRecord& record = block.cells[where.second];
    const HermiteCell& hc = *s.hermite;
    std::vector<bool> reused(s.pieces.size(), false);
    for (std::size_t k = 0; k < s.pieces.size(); ++k)
    {
      Hermite data[12];
      int count = 0;
      for (const CycleStep& step : s.pieces[k])
      {
        data[count++] = { hc.point[step.edge], hc.normal[step.edge], hc.hasNormal[step.edge] };
      }
      const Point3 p = placeVertex(data, count, sharp, hc.clamp, layout.h);
      const std::uint16_t old = record.edgeVertex[s.pieces[k][0].edge];
      std::uint16_t id = old;
      if (reused[s.origin[k]])
      {
        id = static_cast<std::uint16_t>(block.vertices.size());
        block.vertices.push_back(p);
      }
      else
      {
        reused[s.origin[k]] = true;
        block.vertices[old] = p;
      }
      for (const CycleStep& step : s.pieces[k])
      {
        record.edgeVertex[step.edge] = id;
      }
    }
  }
}

double triangleScore(const Point3& a, const Point3& b, const Point3& c, int axis, double sign)
{
  const double u[3] = { b[0] - a[0], b[1] - a[1], b[2] - a[2] };
  const double v[3] = { c[0] - a[0], c[1] - a[1], c[2] - a[2] };
  const double n[3] = { u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
    u[0] * v[1] - u[1] * v[0] };
  const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  return len > 0 ? sign * n[axis] / len : -2.0;
}

/// The quads of the sign-changing edges owned by the block (the edges at corner 0 of its cells).
void emitQuads(Block& block, std::vector<std::unique_ptr<Block>>& blocks, const BlockIndex& index,
  const Layout& layout, const std::vector<Point3>& points)
{
  // Neighbour blocks on the negative sides, by (dx | dy << 1 | dz << 2).
  Block* neighbour[8];
  for (int d = 0; d < 8; ++d)
  {
    std::array<int, 3> o = block.origin;
    bool valid = true;
    for (int a = 0; a < 3; ++a)
    {
      if ((d >> a) & 1)
      {
        o[a] -= BlockCells;
        valid = valid && o[a] >= 0;
      }
    }
    const std::int64_t b = valid ? index.find(layout.blockKey(o)) : -1;
    neighbour[d] = b >= 0 ? blocks[b].get() : nullptr;
  }
  auto vertexOf = [&](const std::array<int, 3>& l, int edge) -> std::int64_t
  {
    int d = 0;
    int m[3];
    for (int a = 0; a < 3; ++a)
    {
      m[a] = l[a];
      if (l[a] < 0)
      {
        d |= 1 << a;
        m[a] += BlockCells;
      }
    }
    const Block* b = neighbour[d];
    if (!b)
    {
      return -1;
    }
    const std::uint16_t s = b->slot[m[0] + BlockCells * (m[1] + BlockCells * m[2])];
    if (s == NoVertex || b->cells[s].edgeVertex[edge] == NoVertex)
    {
      return -1;
    }
    return static_cast<std::int64_t>(b->vertexOffset) + b->cells[s].edgeVertex[edge];
  };
  for (const CellRecord& cell : block.cells)
  {
    const std::array<int, 3> l{ cell.local % BlockCells, (cell.local / BlockCells) % BlockCells,
      cell.local / (BlockCells * BlockCells) };
    for (int a = 0; a < 3; ++a)
    {
      const bool in0 = inside(cell.mask, 0);
      if (in0 == inside(cell.mask, 1 << a))
      {
        continue;
      }
      const int b = OtherAxes[a][0], c = OtherAxes[a][1];
      // The four cells around the edge, counter-clockwise in the (b, c) plane.
      static constexpr int ring[4][2] = { { 0, 0 }, { 1, 0 }, { 1, 1 }, { 0, 1 } };
      std::int64_t q[4];
      bool complete = true;
      for (int r = 0; r < 4; ++r)
      {
        std::array<int, 3> m = l;
        m[b] -= ring[r][0];
        m[c] -= ring[r][1];
        q[r] = vertexOf(m, 4 * a + ring[r][0] + 2 * ring[r][1]);
        complete = complete && q[r] >= 0;
      }
      if (!complete)
      {
        continue; // cannot happen for an exact field evaluator
      }
      // The ring's normal is +a for a = x, z and -a for a = y (b x c); the surface normal points
      // from the inside end of the edge to the outside one.
      const double ringSign = a == 1 ? -1.0 : 1.0;
      const double want = in0 ? 1.0 : -1.0;
      if (ringSign != want)
      {
        std::swap(q[1], q[3]);
      }
      const Point3 &p0 = points[q[0]], &p1 = points[q[1]], &p2 = points[q[2]], &p3 = points[q[3]];
      const double split02 =
        std::min(triangleScore(p0, p1, p2, a, want), triangleScore(p0, p2, p3, a, want));
      const double split13 =
        std::min(triangleScore(p1, p2, p3, a, want), triangleScore(p1, p3, p0, a, want));
      const auto v = [&](int r)
      {
        return static_cast<std::uint32_t>(q[r]);
      };
      if (split02 >= split13)
      {
        block.triangles.push_back({ v(0), v(1), v(2) });
        block.triangles.push_back({ v(0), v(2), v(3) });
      }
      else
      {
        block.triangles.push_back({ v(1), v(2), v(3) });
        block.triangles.push_back({ v(1), v(3), v(0) });
      }
    }
  }
}

Layout makeLayout(const Box3& box, const SurfaceOptions& options)
{
  const double h = options.featureSize;
  if (!std::isfinite(h) || !(h > 0))
  {
    std::ostringstream os;
    os << "contourSurface: featureSize must be positive and finite (got " << h << ")";
    throw std::invalid_argument(os.str());
  }
  Layout layout;
  layout.h = h;
  long double total = 1;
  for (int a = 0; a < 3; ++a)
  {
    if (!std::isfinite(box.lo[a]) || !std::isfinite(box.hi[a]) || !(box.lo[a] < box.hi[a]))
    {
      std::ostringstream os;
      os << "contourSurface: the box must be finite with lo < hi on every axis (axis " << a << ": ["
         << box.lo[a] << ", " << box.hi[a] << "])";
      throw std::invalid_argument(os.str());
    }
    const double n = (box.hi[a] - box.lo[a]) / h;
    // Points 1..pin at lo + (p - 1) h; the last one may fall on hi up to rounding.
    const double r = std::round(n);
    const double cellsAlong = std::abs(n - r) <= 1e-9 * std::max(1.0, n) ? r : std::floor(n);
    total *= static_cast<long double>(cellsAlong + 2);
    if (cellsAlong + 2 > static_cast<double>(1 << 24))
    {
      total = std::numeric_limits<long double>::infinity();
    }
    layout.pin[a] = static_cast<int>(std::min(cellsAlong, double(1 << 24))) + 1;
    layout.cells[a] = layout.pin[a] + 1;
  }
  if (total > static_cast<long double>(options.maxCells))
  {
    std::ostringstream os;
    os.precision(3);
    os << "contourSurface: featureSize " << h << " needs about " << static_cast<double>(total)
       << " cells over the box, more than maxCells = " << static_cast<double>(options.maxCells);
    throw std::invalid_argument(os.str());
  }
  layout.lo = box.lo;
  for (int a = 0; a < 3; ++a)
  {
    layout.hi[a] = std::max(box.hi[a], layout.coord(a, layout.pin[a]));
  }
  const int largest = std::max({ layout.cells[0], layout.cells[1], layout.cells[2] });
  layout.rootCells = BlockCells;
  while (layout.rootCells < largest)
  {
    layout.rootCells *= 2;
  }
  layout.blocksPerAxis = layout.rootCells / BlockCells;
  return layout;
}

} // namespace

SurfaceMesh contourSurface(
  const frep::Field& field, const frep::Box3& box, const SurfaceOptions& options)
{
  const Layout layout = makeLayout(box, options);
  caseTable(); // built once, before the threads need it

  std::vector<Task> tasks;
  {
    auto ev = field.evaluator();
    collectTasks(*ev, layout, { 0, 0, 0 }, layout.rootCells, tasks);
  }

  std::vector<std::vector<std::unique_ptr<Block>>> taskBlocks(tasks.size());
  struct ThreadState
  {
    std::unique_ptr<FieldEvaluator> evaluator;
    std::unique_ptr<BlockContourer> contourer;
  };
  tbb::enumerable_thread_specific<ThreadState> states;
  std::atomic<bool> cancelled{ false };
  std::atomic<std::size_t> done{ 0 };
  const std::thread::id caller = std::this_thread::get_id();
  std::size_t lastReported = 0;
  const std::size_t reportEvery = std::max<std::size_t>(1, tasks.size() / 100);
  // Contouring is ~90% of the time; assembly the rest.
  constexpr double contourShare = 0.9;

  auto runTask = [&](std::size_t t)
  {
    ThreadState& state = states.local();
    if (!state.evaluator)
    {
      state.evaluator = field.evaluator();
      state.contourer = std::make_unique<BlockContourer>(layout, options.sharpFeatures);
    }
    const Task& task = tasks[t];
    std::unique_ptr<FieldEvaluator> narrowed;
    if (!task.knownInside)
    {
      narrowed = state.evaluator->narrowed(layout.clippedBox(task.origin, task.size));
    }
    FieldEvaluator& ev = narrowed ? *narrowed : *state.evaluator;
    descend(ev, layout, task.origin, task.size, task.knownInside, *state.contourer, taskBlocks[t]);
  };
  auto body = [&](const tbb::blocked_range<std::size_t>& range)
  {
    for (std::size_t t = range.begin(); t != range.end(); ++t)
    {
      if (cancelled.load(std::memory_order_relaxed))
      {
        return;
      }
      runTask(t);
      const std::size_t n = done.fetch_add(1) + 1;
      if (options.progress && std::this_thread::get_id() == caller &&
        n - lastReported >= reportEvery)
      {
        lastReported = n;
        if (!options.progress(
              contourShare * static_cast<double>(n) / static_cast<double>(tasks.size())))
        {
          cancelled = true;
        }
      }
    }
  };

  std::vector<std::unique_ptr<Block>> blocks;
  std::vector<std::uint32_t> triangleOffset;
  SurfaceMesh mesh;
  auto run = [&]
  {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, tasks.size(), 1), body);
    if (cancelled)
    {
      return;
    }
    for (auto& list : taskBlocks)
    {
      for (auto& b : list)
      {
        blocks.push_back(std::move(b));
      }
    }
    std::sort(blocks.begin(), blocks.end(),
      [](const std::unique_ptr<Block>& x, const std::unique_ptr<Block>& y)
      { return x->key < y->key; });
    const BlockIndex index(blocks);
    splitVertices(blocks, index, layout, options.sharpFeatures);
    std::size_t vertexCount = 0;
    for (auto& b : blocks)
    {
      b->vertexOffset = static_cast<std::uint32_t>(vertexCount);
      vertexCount += b->vertices.size();
    }
    mesh.points.resize(vertexCount);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, blocks.size()),
      [&](const tbb::blocked_range<std::size_t>& range)
      {
        for (std::size_t b = range.begin(); b != range.end(); ++b)
        {
          std::copy(blocks[b]->vertices.begin(), blocks[b]->vertices.end(),
            mesh.points.begin() + blocks[b]->vertexOffset);
        }
      });
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, blocks.size()),
      [&](const tbb::blocked_range<std::size_t>& range)
      {
        for (std::size_t b = range.begin(); b != range.end(); ++b)
        {
          emitQuads(*blocks[b], blocks, index, layout, mesh.points);
        }
      });
    std::size_t triangleCount = 0;
    triangleOffset.resize(blocks.size());
    for (std::size_t b = 0; b < blocks.size(); ++b)
    {
      triangleOffset[b] = static_cast<std::uint32_t>(triangleCount);
      triangleCount += blocks[b]->triangles.size();
    }
    mesh.triangles.resize(triangleCount);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, blocks.size()),
      [&](const tbb::blocked_range<std::size_t>& range)
      {
        for (std::size_t b = range.begin(); b != range.end(); ++b)
        {
          std::copy(blocks[b]->triangles.begin(), blocks[b]->triangles.end(),
            mesh.triangles.begin() + triangleOffset[b]);
        }
      });
  };
  if (options.threads > 0)
  {
    tbb::task_arena arena(options.threads);
    arena.execute(run);
  }
  else
  {
    run();
  }
  if (cancelled)
  {
    throw frep::Cancelled();
  }
  if (options.progress)
  {
    options.progress(1.0);
  }
  return mesh;
}

} // namespace ictk::discretize
