// SPDX-License-Identifier: BSD-3-Clause
// The BlobTree through time (papers.md 3.6): the evolution functions of animated values, and the
// instantiation of a generic tree at t, which evaluates them and expands the complex primitives
// (generalised cylinders, papers.md 3.4) into skeletal elements. Kept apart from BlobTree.cxx (the
// tree, its evaluation and its lowering) because instantiation is the part that must be fast
// (item 66) and reuses an instance's layout.
#include "FRep/BlobTree.h"

#include <algorithm>
#include <atomic>
#include <cmath>

namespace ictk::frep::blob
{

namespace
{
constexpr double pi = 3.14159265358979323846;

// Catmull-Rom through the control points (x, y, z, r), uniform parameter u in [0, count - 1]:
// the tangent at a control point is half the difference of its neighbours, one-sided at the ends.
// Written as p0 + h01 (p1 - p0) + h10 m0 + h11 m1 so that a constant radius stays bit-exact (the
// leaf rules of papers.md 3.4 compare radii exactly). `tangents` receives 4 count values.
void curveTangents(const double* ctrl, std::uint32_t count, double* tangents)
{
  for (std::uint32_t i = 0; i < count; ++i)
  {
    const double* before = ctrl + 4 * (i == 0 ? 0 : i - 1);
    const double* after = ctrl + 4 * (i + 1 == count ? i : i + 1);
    const double f = (i == 0 || i + 1 == count) ? 1.0 : 0.5;
    for (int k = 0; k < 4; ++k)
    {
      tangents[4 * i + k] = f * (after[k] - before[k]);
    }
  }
}

std::array<double, 4> curvePoint(
  const double* ctrl, const double* tangents, std::uint32_t count, double u)
{
  const std::uint32_t i = std::min(static_cast<std::uint32_t>(u), count - 2);
  const double s = u - static_cast<double>(i);
  const double h01 = s * s * (3 - 2 * s);
  const double h10 = s * (1 - s) * (1 - s);
  const double h11 = s * s * (s - 1);
  const double* p0 = ctrl + 4 * i;
  const double* m0 = tangents + 4 * i;
  std::array<double, 4> out{};
  for (int k = 0; k < 4; ++k)
  {
    out[k] = p0[k] + h01 * (p0[4 + k] - p0[k]) + h10 * m0[k] + h11 * m0[4 + k];
  }
  out[3] = std::max(out[3], 0.0);
  return out;
}

} // namespace

double Animation::eval(double t) const
{
  return derivative(t, 0);
}

double Animation::derivative(double t, int j) const
{
  if (type == Type::Wave)
  {
    // d^j/dt^j of A sin(w t + phase) is A w^j sin(w t + phase + j pi / 2).
    const double angle = 2 * pi * t / period + phase;
    if (j == 0)
    {
      return base + amplitude * std::sin(angle);
    }
    return amplitude * std::pow(2 * pi / period, j) * std::sin(angle + j * pi / 2);
  }
  // Clamped outside the keys: constant there. At the last key its own derivatives (from the
  // left); beyond it 0.
  if (keys.size() == 1 || t < keys.front()[0])
  {
    return j == 0 ? keys.front()[1] : 0.0;
  }
  if (t >= keys.back()[0])
  {
    return j == 0 ? keys.back()[1] : (t == keys.back()[0] && j < order ? keys.back()[1 + j] : 0.0);
  }
  std::size_t k = 0;
  while (keys[k + 1][0] <= t)
  {
    ++k;
  }
  if (t == keys[k][0] && j < order)
  {
    return keys[k][1 + j]; // at a key its own value and derivatives, exactly
  }
  // P(s) = sum c_m s^m on s = (t - t_k) / h, derivatives scaled by h^j: the first n coefficients
  // come from the left key, the last n from the right key's conditions (an n x n solve).
  const int n = order;
  const double h = keys[k + 1][0] - keys[k][0];
  std::vector<double> c(2 * n, 0.0);
  double hj = 1, fact = 1;
  for (int q = 0; q < n; ++q)
  {
    c[q] = keys[k][1 + q] * hj / fact;
    hj *= h;
    fact *= (q + 1);
  }
  auto falling = [](int m, int q)
  {
    double f = 1;
    for (int r = 0; r < q; ++r)
    {
      f *= (m - r);
    }
    return f;
  };
  // Row q: sum_{m >= n} c_m m!/(m-q)! = v1_q h^q - sum_{m < n} c_m m!/(m-q)!.
  std::vector<double> A(n * n), rhs(n);
  hj = 1;
  for (int q = 0; q < n; ++q)
  {
    double r = keys[k + 1][1 + q] * hj;
    for (int m = 0; m < n; ++m)
    {
      r -= c[m] * (m >= q ? falling(m, q) : 0.0);
    }
    for (int m = n; m < 2 * n; ++m)
    {
      A[q * n + (m - n)] = falling(m, q);
    }
    rhs[q] = r;
    hj *= h;
  }
  for (int col = 0; col < n; ++col) // Gaussian elimination with partial pivoting
  {
    int piv = col;
    for (int r = col + 1; r < n; ++r)
    {
      if (std::fabs(A[r * n + col]) > std::fabs(A[piv * n + col]))
      {
        piv = r;
      }
    }
    for (int q = 0; q < n; ++q)
    {
      std::swap(A[col * n + q], A[piv * n + q]);
    }
    std::swap(rhs[col], rhs[piv]);
    for (int r = col + 1; r < n; ++r)
    {
      const double f = A[r * n + col] / A[col * n + col];
      for (int q = col; q < n; ++q)
      {
        A[r * n + q] -= f * A[col * n + q];
      }
      rhs[r] -= f * rhs[col];
    }
  }
  for (int r = n - 1; r >= 0; --r)
  {
    double v = rhs[r];
    for (int q = r + 1; q < n; ++q)
    {
      v -= A[r * n + q] * c[n + q];
    }
    c[n + r] = v / A[r * n + r];
  }
  // The j-th derivative: sum_{m >= j} c_m m!/(m-j)! s^(m-j), divided by h^j.
  const double s = (t - keys[k][0]) / h;
  double value = 0;
  for (int m = 2 * n - 1; m >= j; --m)
  {
    value = value * s + c[m] * falling(m, j);
  }
  return j == 0 ? value : value / std::pow(h, j);
}

namespace
{
// Every change to a tree's structure takes a new number, so that an instance knows whether it
// was laid out from the structure it is asked to hold again.
std::atomic<std::uint64_t> structures{ 0 };

// A generalised cylinder's element between two samples (x, y, z, r): its kind by the rule of
// papers.md 3.4 and its values, written into a slot of 10.
Kind cylinderPiece(const double* nv, const std::array<double, 4>& a, const std::array<double, 4>& b,
  double* out, std::uint32_t& count)
{
  out[0] = nv[0];
  out[1] = nv[1];
  out[2] = a[0];
  out[3] = a[1];
  out[4] = a[2];
  out[5] = b[0];
  out[6] = b[1];
  out[7] = b[2];
  if (a[3] != b[3])
  {
    out[8] = a[3];
    out[9] = b[3];
    count = 10;
    return Kind::ConeSphere;
  }
  out[8] = b[3];
  count = b[3] == 0 ? 8 : 9;
  return b[3] == 0 ? Kind::Segment : Kind::Cylinder;
}

// A surface of revolution's element between two profile samples (rho, h, 0, t): a HollowCone
// about the primitive's axis (values R i n c axis ...), rho kept >= 0 where the spline overshoots.
Kind revolutionPiece(const double* nv, const std::array<double, 4>& a,
  const std::array<double, 4>& b, double* out, std::uint32_t& count)
{
  const double values[14] = { nv[0], nv[1], nv[3], nv[4], nv[5], nv[6], nv[7], nv[8],
    std::max(a[0], 0.0), a[1], a[3], std::max(b[0], 0.0), b[1], b[3] };
  std::copy(values, values + 14, out);
  count = 14;
  return Kind::HollowCone;
}
// Two triangles of a surface with variable thickness (a ta b tb c tc each) that are the halves
// of a rectangle, with one thickness t at their six vertices: their union, the rectangle swept by
// a sphere of radius t (ThickTriangle's rounded sides), is the rounded box of half-sides
// (a, b, 0) and rounding t, written into `box` (c e1 e2 a b c r). They share a diagonal (two
// vertices, bit for bit) and their other vertices p, q make a parallelogram with it (p + q =
// s0 + s1) with equal diagonals: a rectangle, to 1e-12 of the diagonal's length.
bool rectangleBox(const double* one, const double* two, double* box)
{
  const double t = one[3];
  for (int k = 0; k < 3; ++k)
  {
    if (one[4 * k + 3] != t || two[4 * k + 3] != t)
    {
      return false;
    }
  }
  const auto same = [](const double* a, const double* b)
  {
    return a[0] == b[0] && a[1] == b[1] && a[2] == b[2];
  };
  const double* shared[2] = { nullptr, nullptr };
  const double* p = nullptr;
  int found = 0;
  for (int a = 0; a < 3; ++a)
  {
    bool inTwo = false;
    for (int b = 0; b < 3; ++b)
    {
      inTwo = inTwo || same(one + 4 * a, two + 4 * b);
    }
    if (inTwo && found < 2)
    {
      shared[found++] = one + 4 * a;
    }
    else if (!inTwo)
    {
      p = one + 4 * a;
    }
  }
  if (found != 2 || !p)
  {
    return false;
  }
  const double* q = nullptr;
  for (int b = 0; b < 3; ++b)
  {
    if (!same(two + 4 * b, shared[0]) && !same(two + 4 * b, shared[1]))
    {
      q = two + 4 * b;
    }
  }
  if (!q)
  {
    return false;
  }
  double diagonal = 0, other = 0, gap = 0;
  for (int k = 0; k < 3; ++k)
  {
    diagonal += (shared[1][k] - shared[0][k]) * (shared[1][k] - shared[0][k]);
    other += (q[k] - p[k]) * (q[k] - p[k]);
    const double g = p[k] + q[k] - shared[0][k] - shared[1][k];
    gap += g * g;
  }
  if (!(gap <= 1e-24 * diagonal) || !(std::fabs(other - diagonal) <= 1e-12 * diagonal))
  {
    return false;
  }
  // The sides from p: u = s0 - p, w = s1 - p; the centre the diagonal's midpoint.
  double u2 = 0, w2 = 0;
  for (int k = 0; k < 3; ++k)
  {
    box[k] = 0.5 * (shared[0][k] + shared[1][k]);
    box[3 + k] = shared[0][k] - p[k];
    box[6 + k] = shared[1][k] - p[k];
    u2 += box[3 + k] * box[3 + k];
    w2 += box[6 + k] * box[6 + k];
  }
  box[9] = 0.5 * std::sqrt(u2);
  box[10] = 0.5 * std::sqrt(w2);
  box[11] = 0;
  box[12] = t;
  return true;
}
} // namespace

void BlobTree::touch()
{
  structure_ = ++structures;
  instanceOf_ = 0;
}

namespace
{
// A balanced tree of binary max nodes over the pieces (line 114: the union, no bulging; line
// 125: a hierarchy that follows the pieces' order, so spatial neighbours share subtrees).
template <class Push>
std::uint32_t joinUnderMax(
  std::vector<std::uint32_t>& level, std::vector<std::uint32_t>& next, Push& push)
{
  while (level.size() > 1)
  {
    next.clear();
    for (std::size_t k = 0; k + 1 < level.size(); k += 2)
    {
      next.push_back(push(Kind::Max, nullptr, 0, 0, &level[k], 2));
    }
    if (level.size() % 2)
    {
      next.push_back(level.back());
    }
    level.swap(next);
  }
  return level[0];
}
} // namespace

void BlobTree::instantiate(double t, BlobTree& out) const
{
  // The values at t (parameters P_A(t)), checked as add() checks values (a wave or key-frames
  // may leave a value's range at some t), before `out` changes: a refused instance leaves it as
  // it was. Then the nodes in order, complex ones expanded.
  const double threshold =
    thresholdAnimation_.empty() ? threshold_ : thresholdAnimation_[0].eval(t);
  std::vector<double>& v = out.scratch_;
  v.assign(values_.begin(), values_.end());
  for (const Animated& a : animations_)
  {
    v[a.value] = a.animation.eval(t);
  }
  checkAt(t, v.data(), threshold);
  // The instance keeps its layout when it was made from this structure: only values change.
  const bool relayout = out.instanceOf_ == 0 || out.instanceOf_ != structure_;
  if (relayout)
  {
    out.clear();
  }
  out.threshold_ = threshold;
  if (nodes_.empty())
  {
    return;
  }
  std::vector<std::uint32_t>& map = out.map_;
  if (relayout)
  {
    map.assign(nodes_.size(), 0);
    out.pieces_.clear();
  }
  auto push = [&out](Kind kind, const double* values, std::uint32_t count, std::uint32_t slot,
                const std::uint32_t* children, std::uint32_t childCount)
  {
    out.nodes_.push_back({ kind, static_cast<std::uint32_t>(out.values_.size()), count,
      static_cast<std::uint32_t>(out.links_.size()), childCount });
    out.values_.insert(out.values_.end(), values, values + slot);
    out.links_.insert(out.links_.end(), children, children + childCount);
    return static_cast<std::uint32_t>(out.nodes_.size() - 1);
  };
  std::vector<std::uint32_t> level, next;
  std::size_t piece = 0;
  for (std::uint32_t i = 0; i < nodes_.size(); ++i)
  {
    const Node& n = nodes_[i];
    const double* nv = v.data() + n.firstValue;
    if (!isComplexPrimitive(n.kind))
    {
      if (!relayout)
      {
        std::copy(nv, nv + n.valueCount, out.values_.data() + out.nodes_[map[i]].firstValue);
        continue;
      }
      map[i] = push(n.kind, nv, n.valueCount, n.valueCount, nullptr, 0);
      for (std::uint32_t k = 0; k < n.childCount; ++k)
      {
        out.links_.push_back(map[links_[n.firstChild + k]]);
      }
      out.nodes_.back().childCount = n.childCount;
      continue;
    }
    // Generalised cylinder (papers.md 3.4, lines 118-125): n segments of the sampled curve, a
    // cone-sphere where the end radii differ, a line-swept sphere where they are equal, a
    // segment where both are null, under a balanced tree of binary unions (max: Kind::Max). Each
    // element has a slot of 10 values, so that a kind changing with t keeps the layout.
    //
    // Surface of revolution (lines 150-159): the profile (rho, h, t) sampled the same way, each
    // segment a HollowCone (its ends are the junction tori), under the same union tree.
    if (n.kind == Kind::ThickSurface)
    {
      // Surface with variable thickness (lines 127-140): a thick triangle per triangle, a plain
      // triangle where its three thicknesses are null (line 139), in slots of 15 values. Two
      // successive triangles that make a rectangle of one thickness are one box (line 140); the
      // pairs are found only in a static surface, so that every instance has the layout of the
      // first.
      const bool merge =
        std::find(animatedNodes_.begin(), animatedNodes_.end(), i) == animatedNodes_.end();
      level.clear();
      for (std::uint32_t k = 2; k + 12 <= n.valueCount; k += 12)
      {
        const double* tri = nv + k;
        double pieceValues[15] = { nv[0], nv[1], tri[0], tri[1], tri[2], tri[4], tri[5], tri[6],
          tri[8], tri[9], tri[10], tri[3], tri[7], tri[11], 0 };
        const bool thin = tri[3] == 0 && tri[7] == 0 && tri[11] == 0;
        Kind kind = thin ? Kind::Triangle : Kind::ThickTriangle;
        std::uint32_t count = thin ? 11 : 14;
        if (merge && k + 24 <= n.valueCount && rectangleBox(tri, tri + 12, pieceValues + 2))
        {
          kind = Kind::Box;
          count = 15;
          k += 12;
        }
        if (relayout)
        {
          level.push_back(push(kind, pieceValues, count, 15, nullptr, 0));
          out.pieces_.push_back(level.back());
        }
        else
        {
          Node& leaf = out.nodes_[out.pieces_[piece++]];
          leaf.kind = kind;
          leaf.valueCount = count;
          std::copy(pieceValues, pieceValues + 15, out.values_.data() + leaf.firstValue);
        }
      }
      if (relayout)
      {
        map[i] = joinUnderMax(level, next, push);
      }
      continue;
    }
    const bool revolution = n.kind == Kind::SurfaceOfRevolution;
    const auto segments = static_cast<std::uint32_t>(nv[2]);
    const double* ctrl = nv + 3;
    std::uint32_t controls = (n.valueCount - 3) / 4;
    if (revolution)
    {
      // The profile as (rho, h, 0, t), the layout of the curve code.
      controls = (n.valueCount - 9) / 3;
      std::vector<double>& profile = out.profile_;
      profile.resize(4 * controls);
      for (std::uint32_t k = 0; k < controls; ++k)
      {
        profile[4 * k] = nv[9 + 3 * k];
        profile[4 * k + 1] = nv[10 + 3 * k];
        profile[4 * k + 2] = 0;
        profile[4 * k + 3] = nv[11 + 3 * k];
      }
      ctrl = profile.data();
    }
    const std::uint32_t slot = revolution ? 14 : 10;
    std::vector<double>& tangents = out.tangents_;
    tangents.resize(4 * controls);
    curveTangents(ctrl, controls, tangents.data());
    std::array<double, 4> prev = curvePoint(ctrl, tangents.data(), controls, 0.0);
    level.clear();
    for (std::uint32_t s = 1; s <= segments; ++s)
    {
      const std::array<double, 4> cur = curvePoint(ctrl, tangents.data(), controls,
        static_cast<double>(controls - 1) * s / static_cast<double>(segments));
      double pieceValues[14];
      std::uint32_t count = 0;
      const Kind kind = revolution ? revolutionPiece(nv, prev, cur, pieceValues, count)
                                   : cylinderPiece(nv, prev, cur, pieceValues, count);
      if (relayout)
      {
        level.push_back(push(kind, pieceValues, count, slot, nullptr, 0));
        out.pieces_.push_back(level.back());
      }
      else
      {
        Node& leaf = out.nodes_[out.pieces_[piece++]];
        leaf.kind = kind;
        leaf.valueCount = count;
        std::copy(pieceValues, pieceValues + slot, out.values_.data() + leaf.firstValue);
      }
      prev = cur;
    }
    if (!relayout)
    {
      continue;
    }
    map[i] = joinUnderMax(level, next, push);
  }
  out.root_ = map[root_];
  out.instanceOf_ = structure_;
}

BlobTree BlobTree::instantiate(double t) const
{
  BlobTree out;
  instantiate(t, out);
  return out;
}

} // namespace ictk::frep::blob
