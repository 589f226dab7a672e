// SPDX-License-Identifier: BSD-3-Clause
// The non-manifold repair of manifold dual contouring (SurfaceDetail.h). One vertex per patch
// component is a 2-manifold except where a tunnel narrower than a cell passes through two cells;
// there the vertices are split (the cell's patch cycles cut, each piece re-placed by the QEF) and
// the tunnel is closed off. Rare, so it runs once, sequentially, over the sorted blocks, after
// every block has its vertices and before they are numbered.
#include "Discretize/SurfaceDetail.h"

#include <map>
#include <utility>

namespace ictk::discretize::detail::surface
{
namespace
{

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

} // namespace

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

} // namespace ictk::discretize::detail::surface
