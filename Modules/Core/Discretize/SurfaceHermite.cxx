// SPDX-License-Identifier: BSD-3-Clause
// The Hermite data of manifold dual contouring (SurfaceDetail.h), one block at a time: the block's
// corner grid is sampled in one values() call, the crossing on every sign-changing edge is found
// by false position (Illinois) with all open edges of the block evaluated together in each step,
// the normal there by the gradient, and each cell gets one vertex per component of its patch
// (placed by SurfaceQef.cxx). Batching per block is what makes the evaluators fast: per-point
// calls would cost several times more.
#include "Discretize/SurfaceDetail.h"

#include <algorithm>
#include <cmath>
#include <iterator>

namespace ictk::discretize::detail::surface
{
namespace
{

// False-position steps per edge crossing.
constexpr int RootSteps = 3;

} // namespace

BlockContourer::BlockContourer(const Layout& layout, bool sharp)
  : layout_(layout)
  , sharp_(sharp)
{
  values_.resize(BlockPointCount);
  for (auto& s : edgeSlot_)
  {
    s.assign(BlockPointCount, -1);
  }
}

bool BlockContourer::run(
  FieldEvaluator& ev, const std::array<int, 3>& o, bool knownInside, Block& block)
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

void BlockContourer::sample(FieldEvaluator& ev, const std::array<int, 3>& o, bool knownInside)
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

void BlockContourer::findCells(const std::array<int, 3>& o)
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

void BlockContourer::findCrossings(
  FieldEvaluator& ev, const std::array<int, 3>& o, bool knownInside)
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

int BlockContourer::pointOffset(int corner)
{
  return (corner & 1) + BlockPoints * ((corner >> 1) & 1) +
    BlockPoints * BlockPoints * ((corner >> 2) & 1);
}

BlockContourer::Edge BlockContourer::makeEdge(
  const std::array<int, 3>& o, int axis, int point, bool knownInside) const
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

double BlockContourer::falsePosition(const Edge& e)
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

void BlockContourer::placeVertices(const std::array<int, 3>& o, Block& block)
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

Box3 BlockContourer::cellClamp(const std::array<int, 3>& o, int localCell) const
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

} // namespace ictk::discretize::detail::surface
