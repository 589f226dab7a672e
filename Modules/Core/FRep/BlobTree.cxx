// SPDX-License-Identifier: BSD-3-Clause
// The BlobTree (papers.md section 3). The distance functions, the kernel and the operators are
// written once, as templates over the scalar type: double for evaluate() (the tree traversal of
// the paper, which skips elements whose box misses the point) and Expr for potential() (the
// lowering to the DAG, where the box test becomes a Select that interval evaluation resolves).
// It runs to about 1,100 lines because the distances, the operators and the one traversal that
// uses them (with the TextureTree's materials) belong together; time and instantiation are in
// BlobTreeInstance.cxx.
#include "FRep/BlobTree.h"
#include "FRep/Operations.h"
#include "FRep/SolidTexture.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <type_traits>

namespace ictk::frep::blob
{

namespace
{

// --- scalar operations for double; Expr's are found by argument-dependent lookup --------------
inline double select(double c, double a, double b)
{
  return c >= 0 ? a : b;
}
inline double square(double a)
{
  return a * a;
}
inline double min(double a, double b)
{
  return b < a ? b : a;
}
inline double max(double a, double b)
{
  return a < b ? b : a;
}
inline double sqrt(double a)
{
  return std::sqrt(a);
}
inline double abs(double a)
{
  return std::fabs(a);
}
inline double pow(double a, double b)
{
  return std::pow(a, b);
}
inline double sin(double a)
{
  return std::sin(a);
}
inline double cos(double a)
{
  return std::cos(a);
}

template <class S>
struct P
{
  S x, y, z;
};

template <class S>
P<S> minus(const P<S>& p, const double* c)
{
  return { p.x - c[0], p.y - c[1], p.z - c[2] };
}
template <class S>
S dot(const P<S>& p, const Vec3& v)
{
  return p.x * v[0] + p.y * v[1] + p.z * v[2];
}
template <class S>
S norm2(const P<S>& p)
{
  return square(p.x) + square(p.y) + square(p.z);
}

Vec3 vec(const double* v)
{
  return { v[0], v[1], v[2] };
}
Vec3 vsub(const double* a, const double* b)
{
  return { a[0] - b[0], a[1] - b[1], a[2] - b[2] };
}
Vec3 vcross(const Vec3& a, const Vec3& b)
{
  return { a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0] };
}
double vdot(const Vec3& a, const Vec3& b)
{
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
Vec3 vscale(const Vec3& a, double s)
{
  return { a[0] * s, a[1] * s, a[2] * s };
}

// --- squared distances to the skeletons (papers.md 3.2) -----------------------------------------
template <class S>
S segmentDistance2(const P<S>& p, const double* a, const double* b)
{
  const Vec3 ab = vsub(b, a);
  const double l2 = vdot(ab, ab);
  const P<S> pa = minus(p, a);
  if (l2 == 0)
  {
    return norm2(pa);
  }
  const S t = min(max(dot(pa, ab) * (1.0 / l2), S(0.0)), S(1.0));
  return square(pa.x - t * ab[0]) + square(pa.y - t * ab[1]) + square(pa.z - t * ab[2]);
}

// The hull of the spheres (a, r0) and (b, r1), in the plane of the axis: x along it, y >= 0 away
// from it. The tangent line touches both circles where the outward normal n = (sin, cos),
// sin = (r0 - r1) / L; along the line t = (cos, -sin) the tangent points sit at s = 0 and
// s = L cos, so s < 0 is sphere a's cap, s > L cos sphere b's, and between them the distance is
// the line's, n.q - r0. One sphere inside the other (|r0 - r1| >= L) leaves the larger.
template <class S>
S coneSphereDistance(const P<S>& p, const double* a, const double* b, double r0, double r1)
{
  const Vec3 ab = vsub(b, a);
  const double l = std::sqrt(vdot(ab, ab));
  const P<S> pa = minus(p, a);
  if (!(std::fabs(r0 - r1) < l))
  {
    return r0 >= r1 ? sqrt(norm2(pa)) - r0 : sqrt(norm2(minus(p, b))) - r1;
  }
  const Vec3 u = vscale(ab, 1.0 / l);
  const S x = dot(pa, u);
  const S q2 = norm2(pa);
  const S y = sqrt(max(q2 - square(x), S(0.0)));
  const double sn = (r0 - r1) / l;
  const double cs = std::sqrt(1.0 - sn * sn);
  const S s = x * cs - y * sn;
  const S capA = sqrt(q2) - r0;
  const S capB = sqrt(square(x - l) + square(y)) - r1;
  const S side = x * sn + y * cs - r0;
  return select(-s, capA, select(s - l * cs, capB, side));
}

// Circle and disc: h along the normal, rho in the plane.
template <class S>
S roundDistance2(const P<S>& p, const double* c, const double* n, double r, bool disc)
{
  const Vec3 nn = vscale(vec(n), 1.0 / std::sqrt(vdot(vec(n), vec(n))));
  const P<S> pc = minus(p, c);
  const S h = dot(pc, nn);
  const S rho = sqrt(max(norm2(pc) - square(h), S(0.0)));
  return square(h) + square(disc ? max(rho - r, S(0.0)) : rho - r);
}

// Over the triangle (all three edge tests >= 0) the distance is the height; elsewhere the nearest
// edge's.
template <class S>
S triangleDistance2(const P<S>& p, const double* a, const double* b, const double* c)
{
  const double* v[3] = { a, b, c };
  const Vec3 n = vcross(vsub(b, a), vsub(c, a));
  const Vec3 nn = vscale(n, 1.0 / std::sqrt(vdot(n, n)));
  S inside = dot(minus(p, a), vcross(n, vsub(b, a)));
  S edges = segmentDistance2(p, a, b);
  for (int i = 1; i < 3; ++i)
  {
    const double* from = v[i];
    const double* to = v[(i + 1) % 3];
    inside = min(inside, dot(minus(p, from), vcross(n, vsub(to, from))));
    edges = min(edges, segmentDistance2(p, from, to));
  }
  return select(inside, square(dot(minus(p, a), nn)), edges);
}

// The thick triangle: over the triangle |h| - t(q) with t interpolated by the barycentric
// coordinates of the foot q; beyond an edge (P, Q) the distance to its nearest point minus the
// thickness there, the least over the three edges. Both agree on the planes through the edges
// perpendicular to the triangle, where the regions meet.
template <class S>
S thickTriangleDistance(const P<S>& p, const double* v)
{
  const double* corner[3] = { v, v + 3, v + 6 };
  const double t[3] = { v[9], v[10], v[11] };
  const Vec3 n = vcross(vsub(v + 3, v), vsub(v + 6, v));
  const double n2 = vdot(n, n);
  // Edge functions: w_k is the barycentric coordinate of the vertex opposite edge k.
  S inside(0.0), edges(0.0), thickness(0.0);
  for (int k = 0; k < 3; ++k)
  {
    const double* from = corner[k];
    const double* to = corner[(k + 1) % 3];
    const S w = dot(minus(p, from), vcross(n, vsub(to, from))) * (1.0 / n2);
    thickness = k == 0 ? w * t[2] : thickness + w * t[(k + 2) % 3];
    inside = k == 0 ? w : min(inside, w);
    const Vec3 e = vsub(to, from);
    const S u = min(max(dot(minus(p, from), e) * (1.0 / vdot(e, e)), S(0.0)), S(1.0));
    const S de = sqrt(square(p.x - from[0] - u * e[0]) + square(p.y - from[1] - u * e[1]) +
                   square(p.z - from[2] - u * e[2])) -
      (t[k] + u * (t[(k + 1) % 3] - t[k]));
    edges = k == 0 ? de : min(edges, de);
  }
  const S h = abs(dot(minus(p, v), vscale(n, 1.0 / std::sqrt(n2))));
  return select(inside, h - thickness, edges);
}

// The box's orthonormal frame: e1 normalised, e2 made orthogonal to it, e3 = e1 x e2.
std::array<Vec3, 3> boxFrame(const double* e1, const double* e2)
{
  const Vec3 u = vscale(vec(e1), 1.0 / std::sqrt(vdot(vec(e1), vec(e1))));
  const Vec3 w = vsub(e2, vscale(u, vdot(vec(e2), u)).data());
  const Vec3 v = vscale(w, 1.0 / std::sqrt(vdot(w, w)));
  return { u, v, vcross(u, v) };
}

// The rounded box (c e1 e2 a b c r): outside the box its distance from the point's excess over
// the half-sides in the box's frame, minus the rounding r; 0 inside.
template <class S>
S boxDistance2(const P<S>& p, const double* v)
{
  const std::array<Vec3, 3> e = boxFrame(v + 3, v + 6);
  const P<S> pc = minus(p, v);
  S d2(0.0);
  for (int k = 0; k < 3; ++k)
  {
    const S q = max(abs(dot(pc, e[k])) - v[9 + k], S(0.0));
    d2 = k == 0 ? square(q) : d2 + square(q);
  }
  return v[12] == 0 ? d2 : square(max(sqrt(d2) - v[12], S(0.0)));
}

// Squared distance of an element's skeleton (the values after R and i).
template <class S>
S skeletonDistance2(Kind kind, const double* v, std::uint32_t count, const P<S>& p)
{
  switch (kind)
  {
    case Kind::Point:
      return norm2(minus(p, v));
    case Kind::Segment:
      return segmentDistance2(p, v, v + 3);
    case Kind::Circle:
      return roundDistance2(p, v, v + 3, v[6], false);
    case Kind::Disc:
      return roundDistance2(p, v, v + 3, v[6], true);
    case Kind::Triangle:
      return triangleDistance2(p, v, v + 3, v + 6);
    case Kind::Curve:
    {
      S d2 = segmentDistance2(p, v, v + 3);
      for (std::uint32_t k = 6; k + 3 <= count; k += 3)
      {
        d2 = min(d2, segmentDistance2(p, v + k - 3, v + k));
      }
      return d2;
    }
    case Kind::Cylinder:
      return v[6] == 0 ? segmentDistance2(p, v, v + 3)
                       : square(max(sqrt(segmentDistance2(p, v, v + 3)) - v[6], S(0.0)));
    case Kind::ConeSphere:
      return square(max(coneSphereDistance(p, v, v + 3, v[6], v[7]), S(0.0)));
    case Kind::ThickTriangle:
      return square(max(thickTriangleDistance(p, v), S(0.0)));
    case Kind::Box:
      return boxDistance2(p, v);
    case Kind::HollowCone:
    {
      // The 2D cone-sphere in the meridian half-plane (rho, h) of the point.
      const Vec3 n = vscale(vec(v + 3), 1.0 / std::sqrt(vdot(vec(v + 3), vec(v + 3))));
      const P<S> pc = minus(p, v);
      const S h = dot(pc, n);
      const S rho = sqrt(max(norm2(pc) - square(h), S(0.0)));
      const double a[3] = { v[6], v[7], 0 }, b[3] = { v[9], v[10], 0 };
      return square(max(coneSphereDistance(P<S>{ rho, h, S(0.0) }, a, b, v[8], v[11]), S(0.0)));
    }
    default:
      return S(0.0);
  }
}

// Wyvill on m = max(0, 1 - d^2/R^2): (1 - q)^2 (9 - 4q) / 9 = m^2 (5 + 4m) / 9, zero beyond R.
template <class S>
S wyvill(const S& d2, double R, double intensity)
{
  const S m = max(1.0 - d2 * (1.0 / (R * R)), S(0.0));
  return (intensity / 9.0) * (square(m) * (5.0 + 4.0 * m));
}

// --- boxes ---------------------------------------------------------------------------------------
using Box = std::array<Vec3, 2>;

Box emptyBox()
{
  const double inf = std::numeric_limits<double>::infinity();
  return { Vec3{ inf, inf, inf }, Vec3{ -inf, -inf, -inf } };
}
void grow(Box& b, const Vec3& p, double r)
{
  for (int k = 0; k < 3; ++k)
  {
    b[0][k] = std::min(b[0][k], p[k] - r);
    b[1][k] = std::max(b[1][k], p[k] + r);
  }
}
void merge(Box& b, const Box& o)
{
  for (int k = 0; k < 3; ++k)
  {
    b[0][k] = std::min(b[0][k], o[0][k]);
    b[1][k] = std::max(b[1][k], o[1][k]);
  }
}
bool isEmpty(const Box& b)
{
  return !(b[0][0] <= b[1][0] && b[0][1] <= b[1][1] && b[0][2] <= b[1][2]);
}

// bbox(skeleton) + R (papers.md 3.2, line 62), in the element's own frame.
Box elementBox(Kind kind, const double* values, std::uint32_t count)
{
  const double R = values[0];
  const double* v = values + 2;
  Box b = emptyBox();
  switch (kind)
  {
    case Kind::Circle:
    case Kind::Disc:
      grow(b, vec(v), v[6] + R); // the sphere around the round skeleton
      break;
    case Kind::Cylinder:
      grow(b, vec(v), v[6] + R);
      grow(b, vec(v + 3), v[6] + R);
      break;
    case Kind::ConeSphere:
      grow(b, vec(v), v[6] + R);
      grow(b, vec(v + 3), v[7] + R);
      break;
    case Kind::ThickTriangle:
      for (int k = 0; k < 3; ++k)
      {
        grow(b, vec(v + 3 * k), std::max({ v[9], v[10], v[11] }) + R);
      }
      break;
    case Kind::Box:
    {
      // The rounded box's half-extent along axis k: sum_j h_j |e_j[k]| + r.
      const std::array<Vec3, 3> e = boxFrame(v + 3, v + 6);
      for (int k = 0; k < 3; ++k)
      {
        const double half = v[9] * std::fabs(e[0][k]) + v[10] * std::fabs(e[1][k]) +
          v[11] * std::fabs(e[2][k]) + v[12] + R;
        b[0][k] = v[k] - half;
        b[1][k] = v[k] + half;
      }
      break;
    }
    case Kind::HollowCone:
    {
      // The cylinder about the axis that holds the revolved profile: its ends' discs of radius r
      // span r sqrt(1 - n_k^2) along axis k.
      const Vec3 n = vscale(vec(v + 3), 1.0 / std::sqrt(vdot(vec(v + 3), vec(v + 3))));
      const double reach = std::max(v[8], v[11]) + R;
      const double r = std::max(v[6], v[9]) + reach;
      for (const double h : { std::min(v[7], v[10]) - reach, std::max(v[7], v[10]) + reach })
      {
        for (int k = 0; k < 3; ++k)
        {
          const double centre = v[k] + h * n[k];
          const double half = r * std::sqrt(std::max(1.0 - n[k] * n[k], 0.0));
          b[0][k] = std::min(b[0][k], centre - half);
          b[1][k] = std::max(b[1][k], centre + half);
        }
      }
      break;
    }
    default:
      for (std::uint32_t k = 0; k + 3 <= count - 2; k += 3)
      {
        grow(b, vec(v + k), R);
      }
  }
  return b;
}

// --- operators (papers.md 3.3; the R_0 pair is the kernel's, computed without cancellation)
// ---------------------------------------------------------------------
template <class S>
S unionRT(const S& a, const S& b, double T)
{
  const S u = a - T;
  const S v = b - T;
  return T + (1.0 / (2.0 - std::sqrt(2.0))) * rUnion(u, v);
}
template <class S>
S intersectionRT(const S& a, const S& b, double T)
{
  const S u = a - T;
  const S v = b - T;
  return T + (1.0 / (2.0 + std::sqrt(2.0))) * rIntersection(u, v);
}
// Negative fields (a difference's 2T - f_B) are clamped so that f^n stays defined.
template <class S>
S hyperPower(const S& a, double n)
{
  return pow(max(a, S(0.0)), S(n));
}
template <class S>
S localBlendOf(const S& a, const S& b, const S& r)
{
  const S w = min(max(r, S(0.0)), S(1.0));
  return w * (a + b) + (1.0 - w) * max(a, b);
}

// --- the traversal, for double (evaluate) and Expr (potential)
// --------------------------------------
template <class S>
struct Walker
{
  const BlobTree& tree;
  double T;
  std::size_t* kernels;

  S leaf(const Node& node, const double* v, const P<S>& p) const
  {
    const Box box = elementBox(node.kind, v, node.valueCount);
    if constexpr (std::is_same_v<S, double>)
    {
      for (int k = 0; k < 3; ++k)
      {
        const double c = k == 0 ? p.x : (k == 1 ? p.y : p.z);
        if (!(c >= box[0][k] && c <= box[1][k]))
        {
          return 0.0; // the short-circuit: no distance, no kernel
        }
      }
      if (kernels)
      {
        ++*kernels;
      }
      return wyvill(skeletonDistance2(node.kind, v + 2, node.valueCount - 2, p), v[0], v[1]);
    }
    else
    {
      const S inside =
        min(min(min(p.x - box[0][0], box[1][0] - p.x), min(p.y - box[0][1], box[1][1] - p.y)),
          min(p.z - box[0][2], box[1][2] - p.z));
      return select(inside,
        wyvill(skeletonDistance2(node.kind, v + 2, node.valueCount - 2, p), v[0], v[1]), S(0.0));
    }
  }

  // A node's field and, when textured, its material (papers.md 3.5): f and Phi in one pass.
  struct Value
  {
    S f;
    std::array<S, MaterialSize> phi;
  };
  bool textured = false;
  TextureHyperBlend hyperMode = TextureHyperBlend::Corrected;

  // Phi = a if c >= 0, else b, component-wise.
  static std::array<S, MaterialSize> pick(
    const S& c, const std::array<S, MaterialSize>& a, const std::array<S, MaterialSize>& b)
  {
    std::array<S, MaterialSize> out;
    for (int k = 0; k < MaterialSize; ++k)
    {
      out[k] = select(c, a[k], b[k]);
    }
    return out;
  }

  Value value(std::uint32_t index, const P<S>& p, bool underBlend,
    const std::array<S, MaterialSize>& material) const
  {
    const Node& node = tree.node(index);
    const double* v = tree.values(index);
    const std::uint32_t* c = tree.children(index);
    if (isSkeletal(node.kind))
    {
      return { leaf(node, v, p), material };
    }
    const bool blendBelow = underBlend || isBlend(node.kind);
    const auto child = [&](std::uint32_t k, const P<S>& q, bool below)
    {
      return value(c[k], q, below, material);
    };
    switch (node.kind)
    {
      case Kind::Blend:
      case Kind::HyperBlend:
      {
        // f = sum f_i (or (sum f_i^n)^(1/n)); Phi weighted by f_i (line 191), by f_i^n in the
        // corrected hyper-blend, or (sum f_i^n Phi_i^n)^(1/n) / (sum f_i^n)^(1/n) as printed
        // (line 195, E11). Where every weight is 0, the mean of the children's Phi.
        const bool hyper = node.kind == Kind::HyperBlend;
        const double n = hyper ? v[0] : 1.0;
        S sum(0.0), weights(0.0);
        std::array<S, MaterialSize> weighted, mean;
        weighted.fill(S(0.0));
        mean.fill(S(0.0));
        for (std::uint32_t k = 0; k < node.childCount; ++k)
        {
          const Value a = child(k, p, true);
          const S w = hyper ? hyperPower(a.f, n) : a.f;
          sum = k == 0 ? w : sum + w;
          if (!textured)
          {
            continue;
          }
          weights = weights + w;
          for (int m = 0; m < MaterialSize; ++m)
          {
            const S phi = hyper && hyperMode == TextureHyperBlend::Verbatim
              ? hyperPower(a.phi[m], n)
              : a.phi[m];
            weighted[m] = weighted[m] + w * phi;
            mean[m] = mean[m] + a.phi[m] * (1.0 / node.childCount);
          }
        }
        Value out{ hyper ? pow(sum, S(1.0 / n)) : sum, material };
        if (textured)
        {
          for (int m = 0; m < MaterialSize; ++m)
          {
            const S phi = hyper && hyperMode == TextureHyperBlend::Verbatim
              ? pow(max(weighted[m] / weights, S(0.0)), S(1.0 / n))
              : weighted[m] / weights;
            out.phi[m] = select(-weights, mean[m], phi);
          }
        }
        return out;
      }
      case Kind::LocalBlend:
      {
        const Value a = child(0, p, true), b = child(1, p, true), r = child(2, p, true);
        Value out{ localBlendOf(a.f, b.f, r.f), material };
        if (textured) // line 199: w Phi_{A+B} + (1 - w) Phi_{A u B}
        {
          const S w = min(max(r.f, S(0.0)), S(1.0));
          const S total = a.f + b.f;
          const auto sharp = pick(b.f - a.f, b.phi, a.phi);
          for (int m = 0; m < MaterialSize; ++m)
          {
            const S smooth = select(
              -total, 0.5 * (a.phi[m] + b.phi[m]), (a.f * a.phi[m] + b.f * b.phi[m]) / total);
            out.phi[m] = w * smooth + (1.0 - w) * sharp[m];
          }
        }
        return out;
      }
      case Kind::Union:
      case Kind::Intersection:
      case Kind::Max:
      {
        // Line 203: the union keeps Phi_A iff f_A > f_B, the intersection iff f_A < f_B; ties B.
        const bool isUnion = node.kind != Kind::Intersection;
        const bool rFunction = blendBelow && node.kind != Kind::Max;
        Value f = child(0, p, blendBelow);
        for (std::uint32_t k = 1; k < node.childCount; ++k)
        {
          const Value g = child(k, p, blendBelow);
          if (textured)
          {
            f.phi = isUnion ? pick(g.f - f.f, g.phi, f.phi) : pick(f.f - g.f, g.phi, f.phi);
          }
          f.f = rFunction ? (isUnion ? unionRT(f.f, g.f, T) : intersectionRT(f.f, g.f, T))
                          : (isUnion ? max(f.f, g.f) : min(f.f, g.f));
        }
        return f;
      }
      case Kind::Difference:
      {
        const Value a = child(0, p, blendBelow);
        const Value bv = child(1, p, blendBelow);
        const S b = 2.0 * T - bv.f;
        Value out{ blendBelow ? intersectionRT(a.f, b, T) : min(a.f, b), material };
        if (textured) // Phi_A iff f_A < 2T - f_B
        {
          out.phi = pick(a.f - b, bv.phi, a.phi);
        }
        return out;
      }
      case Kind::Material:
      {
        std::array<S, MaterialSize> own;
        for (int m = 0; m < MaterialSize; ++m)
        {
          own[m] = S(v[m]);
        }
        return value(c[0], p, blendBelow, own);
      }
      case Kind::Marble:
      case Kind::Wood:
      case Kind::Granite:
      {
        // A solid texture: Phi varies with the point, in this node's frame (FRep/SolidTexture.h).
        if (!textured)
        {
          return child(0, p, blendBelow);
        }
        const texture::Pattern pattern = node.kind == Kind::Marble
          ? texture::Pattern::Marble
          : (node.kind == Kind::Wood ? texture::Pattern::Wood : texture::Pattern::Granite);
        const S s = texture::pattern(pattern, p.x, p.y, p.z, v[9], v[10], static_cast<int>(v[11]));
        std::array<S, MaterialSize> own;
        for (int m = 0; m < 3; ++m)
        {
          own[m] = v[m] + s * (v[m + 3] - v[m]);
        }
        for (int m = 3; m < MaterialSize; ++m)
        {
          own[m] = S(v[m + 3]);
        }
        return value(c[0], p, blendBelow, own);
      }
      case Kind::Translate:
        return child(0, minus(p, v), blendBelow);
      case Kind::Rotate:
      {
        // w^-1 is the rotation by -angle (Rodrigues).
        const Vec3 k = vscale(vec(v), 1.0 / std::sqrt(vdot(vec(v), vec(v))));
        const double cs = std::cos(v[3]);
        const double sn = -std::sin(v[3]);
        const S kp = dot(p, k);
        const P<S> kxp{ p.z * k[1] - p.y * k[2], p.x * k[2] - p.z * k[0], p.y * k[0] - p.x * k[1] };
        const S w = kp * (1.0 - cs);
        return child(0,
          P<S>{ p.x * cs + kxp.x * sn + w * k[0], p.y * cs + kxp.y * sn + w * k[1],
            p.z * cs + kxp.z * sn + w * k[2] },
          blendBelow);
      }
      case Kind::Scale:
        return child(
          0, P<S>{ p.x * (1.0 / v[0]), p.y * (1.0 / v[1]), p.z * (1.0 / v[2]) }, blendBelow);
      case Kind::Twist:
      {
        const S a = p.z * v[0];
        const S cs = cos(a);
        const S sn = sin(a);
        return child(0, P<S>{ p.x * cs + p.y * sn, p.y * cs - p.x * sn, p.z }, blendBelow);
      }
      default:
        throw std::invalid_argument(
          std::string("blobtree: ") + kindName(node.kind) + " must be expanded before evaluation");
    }
  }
};

// --- node rules ----------------------------------------------------------------------------------
struct Rule
{
  const char* name;
  std::uint32_t values; // fixed values (or the head of a variable list)
  std::uint32_t item;   // 0: fixed; else values per repeated item
  std::uint32_t minItems;
  std::uint32_t minChildren;
  std::uint32_t maxChildren; // 0: unlimited
};

const Rule& rule(Kind kind)
{
  static const Rule rules[] = {
    { "point", 5, 0, 0, 0, 0 },
    { "segment", 8, 0, 0, 0, 0 },
    { "circle", 9, 0, 0, 0, 0 },
    { "disc", 9, 0, 0, 0, 0 },
    { "triangle", 11, 0, 0, 0, 0 },
    { "curve", 2, 3, 2, 0, 0 },
    { "cylinder", 9, 0, 0, 0, 0 },
    { "conesphere", 10, 0, 0, 0, 0 },
    { "hollowcone", 14, 0, 0, 0, 0 },
    { "thicktriangle", 14, 0, 0, 0, 0 },
    { "box", 15, 0, 0, 0, 0 },
    { "gcylinder", 3, 4, 2, 0, 0 },
    { "revolution", 9, 3, 2, 0, 0 },
    { "thicksurface", 2, 12, 1, 0, 0 },
    { "blend", 0, 0, 0, 1, 0 },
    { "hyperblend", 1, 0, 0, 1, 0 },
    { "localblend", 0, 0, 0, 3, 3 },
    { "union", 0, 0, 0, 1, 0 },
    { "intersection", 0, 0, 0, 1, 0 },
    { "difference", 0, 0, 0, 2, 2 },
    { "max", 0, 0, 0, 1, 0 },
    { "material", 6, 0, 0, 1, 1 },
    { "marble", 12, 0, 0, 1, 1 },
    { "wood", 12, 0, 0, 1, 1 },
    { "granite", 12, 0, 0, 1, 1 },
    { "translate", 3, 0, 0, 1, 1 },
    { "rotate", 4, 0, 0, 1, 1 },
    { "scale", 3, 0, 0, 1, 1 },
    { "twist", 1, 0, 0, 1, 1 },
  };
  return rules[static_cast<int>(kind)];
}

std::string show(double v)
{
  std::ostringstream out;
  out.precision(12);
  out << v;
  return out.str();
}

[[noreturn]] void fail(Kind kind, const std::string& what)
{
  throw std::invalid_argument(std::string("blobtree: ") + kindName(kind) + ": " + what);
}

void requirePositive(Kind kind, const char* name, double v)
{
  if (!(v > 0))
  {
    fail(kind, std::string(name) + " must be positive (got " + show(v) + ")");
  }
}
void requireNonNegative(Kind kind, const char* name, double v)
{
  if (!(v >= 0))
  {
    fail(kind, std::string(name) + " must not be negative (got " + show(v) + ")");
  }
}

// The checks of a node's values beyond their count: finite, then the geometric rules. add()
// applies them to the values as given, instantiate() to the animated nodes' values at t.
void checkValues(Kind kind, const double* v, std::uint32_t count)
{
  for (std::uint32_t k = 0; k < count; ++k)
  {
    if (!std::isfinite(v[k]))
    {
      fail(kind, "every value must be finite (got " + show(v[k]) + ")");
    }
  }
  if (isSkeletal(kind) || isComplexPrimitive(kind))
  {
    requirePositive(kind, "the radius of influence R", v[0]);
  }
  const double* s = count >= 2 ? v + 2 : v; // an operator may have no values (v null)
  switch (kind)
  {
    case Kind::Circle:
    case Kind::Disc:
      if (vdot(vec(s + 3), vec(s + 3)) == 0)
      {
        fail(kind, "the normal n must not be the zero vector");
      }
      requirePositive(kind, "the radius r", s[6]);
      break;
    case Kind::Triangle:
    {
      const Vec3 n = vcross(vsub(s + 3, s), vsub(s + 6, s));
      if (!(vdot(n, n) > 0))
      {
        fail(kind, "the three vertices must not be collinear");
      }
      break;
    }
    case Kind::Cylinder:
      requireNonNegative(kind, "the radius r", s[6]);
      break;
    case Kind::ConeSphere:
      requireNonNegative(kind, "the radius r0", s[6]);
      requireNonNegative(kind, "the radius r1", s[7]);
      break;
    case Kind::GeneralisedCylinder:
    {
      if (!(v[2] >= 1 && v[2] <= 100000 && v[2] == std::floor(v[2])))
      {
        fail(kind,
          "the number of segments n must be an integer in [1, 100000] (got " + show(v[2]) + ")");
      }
      for (std::uint32_t k = 6; k < count; k += 4)
      {
        requireNonNegative(kind, "every radius", v[k]);
      }
      break;
    }
    case Kind::ThickTriangle:
    {
      const Vec3 n = vcross(vsub(s + 3, s), vsub(s + 6, s));
      if (!(vdot(n, n) > 0))
      {
        fail(kind, "the three vertices must not be collinear");
      }
      for (int k = 9; k < 12; ++k)
      {
        requireNonNegative(kind, "every thickness", s[k]);
      }
      break;
    }
    case Kind::ThickSurface:
      for (std::uint32_t k = 2; k + 12 <= count; k += 12)
      {
        const double* tri = v + k;
        const Vec3 n = vcross(vsub(tri + 4, tri), vsub(tri + 8, tri));
        if (!(vdot(n, n) > 0))
        {
          fail(kind, "triangle " + std::to_string((k - 2) / 12) + " is degenerate (collinear)");
        }
        for (int q = 3; q < 12; q += 4)
        {
          requireNonNegative(kind, "every thickness", tri[q]);
        }
      }
      break;
    case Kind::Box:
      if (!(vdot(vcross(vec(s + 3), vec(s + 6)), vcross(vec(s + 3), vec(s + 6))) > 0))
      {
        fail(kind, "the axes e1 and e2 must be non-zero and not parallel");
      }
      for (int k = 9; k < 12; ++k)
      {
        requireNonNegative(kind, "every half-side", s[k]);
      }
      requireNonNegative(kind, "the rounding r", s[12]);
      break;
    case Kind::HollowCone:
      if (vdot(vec(s + 3), vec(s + 3)) == 0)
      {
        fail(kind, "the axis must not be the zero vector");
      }
      requireNonNegative(kind, "the distance to the axis rho0", s[6]);
      requireNonNegative(kind, "the distance to the axis rho1", s[9]);
      requireNonNegative(kind, "the thickness t0", s[8]);
      requireNonNegative(kind, "the thickness t1", s[11]);
      break;
    case Kind::SurfaceOfRevolution:
    {
      if (!(v[2] >= 1 && v[2] <= 100000 && v[2] == std::floor(v[2])))
      {
        fail(kind,
          "the number of segments n must be an integer in [1, 100000] (got " + show(v[2]) + ")");
      }
      if (vdot(vec(v + 6), vec(v + 6)) == 0)
      {
        fail(kind, "the axis must not be the zero vector");
      }
      for (std::uint32_t k = 9; k + 3 <= count; k += 3)
      {
        requireNonNegative(kind, "every distance to the axis rho", v[k]);
        requireNonNegative(kind, "every thickness t", v[k + 2]);
      }
      break;
    }
    case Kind::HyperBlend:
      requirePositive(kind, "the exponent n", v[0]);
      break;
    case Kind::Material:
      for (int k = 0; k < MaterialSize; ++k)
      {
        requireNonNegative(kind, "every material value", v[k]);
      }
      break;
    case Kind::Marble:
    case Kind::Wood:
    case Kind::Granite:
      for (int k = 0; k < 9; ++k)
      {
        requireNonNegative(kind, "every colour and optics value", v[k]);
      }
      requirePositive(kind, "the period or scale lambda", v[9]);
      if (!(v[11] >= 1 && v[11] <= texture::MaxOctaves && v[11] == std::floor(v[11])))
      {
        fail(kind,
          "the number of octaves n must be an integer in [1, " +
            std::to_string(texture::MaxOctaves) + "] (got " + show(v[11]) + ")");
      }
      break;
    case Kind::Rotate:
      if (vdot(vec(v), vec(v)) == 0)
      {
        fail(kind, "the axis must not be the zero vector");
      }
      break;
    case Kind::Scale:
      for (int k = 0; k < 3; ++k)
      {
        if (v[k] == 0)
        {
          fail(kind, "the scale factors must not be zero");
        }
      }
      break;
    default:
      break;
  }
}

} // namespace

// --- public ------------------------------------------------------------------------------------

const char* kindName(Kind kind)
{
  return rule(kind).name;
}
bool isSkeletal(Kind kind)
{
  return kind <= Kind::Box;
}
bool isComplexPrimitive(Kind kind)
{
  return kind == Kind::GeneralisedCylinder || kind == Kind::SurfaceOfRevolution ||
    kind == Kind::ThickSurface;
}
bool isWarp(Kind kind)
{
  return kind >= Kind::Translate;
}
bool isTexture(Kind kind)
{
  return kind >= Kind::Material && kind <= Kind::Granite;
}
bool isBlend(Kind kind)
{
  return kind == Kind::Blend || kind == Kind::HyperBlend || kind == Kind::LocalBlend;
}

BlobTree::BlobTree(double threshold)
  : threshold_(DefaultThreshold)
{
  setThreshold(threshold);
}

void BlobTree::setThreshold(double threshold)
{
  if (!(threshold > 0) || !std::isfinite(threshold))
  {
    throw std::invalid_argument(
      "blobtree: the threshold T must be positive and finite (got " + show(threshold) + ")");
  }
  threshold_ = threshold;
}

std::uint32_t BlobTree::add(
  Kind kind, const std::vector<double>& values, const std::vector<std::uint32_t>& children)
{
  const Rule& r = rule(kind);
  const auto count = static_cast<std::uint32_t>(values.size());
  if (r.item == 0 && count != r.values)
  {
    fail(
      kind, "expects " + std::to_string(r.values) + " values (got " + std::to_string(count) + ")");
  }
  if (r.item != 0 && (count < r.values + r.item * r.minItems || (count - r.values) % r.item != 0))
  {
    fail(kind,
      "expects " + std::to_string(r.values) + " values then at least " +
        std::to_string(r.minItems) + " groups of " + std::to_string(r.item) + " (got " +
        std::to_string(count) + " values)");
  }
  checkValues(kind, values.data(), count);
  const auto k = static_cast<std::uint32_t>(children.size());
  if (k < r.minChildren || (r.maxChildren != 0 && k > r.maxChildren) ||
    (r.minChildren == 0 && k != 0))
  {
    fail(kind,
      r.minChildren == 0
        ? "takes no children"
        : (r.maxChildren == r.minChildren ? "takes exactly " + std::to_string(r.minChildren) +
                " children (got " + std::to_string(k) + ")"
                                          : "takes at least one child"));
  }
  for (std::uint32_t c : children)
  {
    if (c >= nodes_.size())
    {
      fail(kind, "child " + std::to_string(c) + " is not a node of the tree");
    }
  }
  if (nodes_.size() >= std::numeric_limits<std::uint32_t>::max() - 1)
  {
    fail(kind, "the tree is full");
  }
  // A tree, not a DAG: every node has at most one parent, so evaluation is linear in its size.
  parented_.resize(nodes_.size(), false);
  for (std::uint32_t c : children)
  {
    if (parented_[c])
    {
      fail(kind, "node " + std::to_string(c) + " already has a parent (a BlobTree is a tree)");
    }
    parented_[c] = true;
  }
  Node node{ kind, static_cast<std::uint32_t>(values_.size()), count,
    static_cast<std::uint32_t>(links_.size()), k };
  values_.insert(values_.end(), values.begin(), values.end());
  links_.insert(links_.end(), children.begin(), children.end());
  nodes_.push_back(node);
  parented_.push_back(false);
  touch();
  root_ = static_cast<std::uint32_t>(nodes_.size() - 1);
  return root_;
}

void BlobTree::setRoot(std::uint32_t node)
{
  if (node >= nodes_.size())
  {
    throw std::invalid_argument(
      "blobtree: root " + std::to_string(node) + " is not a node of the tree");
  }
  root_ = node;
  touch();
}

void BlobTree::animate(std::uint32_t node, std::uint32_t index, Animation animation)
{
  if (node >= nodes_.size() || index >= nodes_[node].valueCount)
  {
    throw std::invalid_argument("blobtree: cannot animate value " + std::to_string(index) +
      " of node " + std::to_string(node) + ": no such value");
  }
  if (animation.type == Animation::Type::Wave &&
    (!(animation.period > 0) || !std::isfinite(animation.period) ||
      !std::isfinite(animation.base) || !std::isfinite(animation.amplitude) ||
      !std::isfinite(animation.phase)))
  {
    throw std::invalid_argument(
      "blobtree: a wave needs finite values and a positive period (got period " +
      show(animation.period) + ")");
  }
  if (animation.type == Animation::Type::Keys)
  {
    if (animation.order < 1 || animation.order > 4 || animation.keys.empty())
    {
      throw std::invalid_argument(
        "blobtree: key-frames need at least one key and an order n in [1, 4]");
    }
    for (std::size_t k = 0; k < animation.keys.size(); ++k)
    {
      const auto& key = animation.keys[k];
      if (key.size() != static_cast<std::size_t>(animation.order) + 1)
      {
        throw std::invalid_argument("blobtree: key " + std::to_string(k) + " needs " +
          std::to_string(animation.order + 1) + " values (time, then n derivatives)");
      }
      for (double v : key)
      {
        if (!std::isfinite(v))
        {
          throw std::invalid_argument("blobtree: key-frame values must be finite");
        }
      }
      if (k > 0 && !(key[0] > animation.keys[k - 1][0]))
      {
        throw std::invalid_argument("blobtree: key times must increase (key " + std::to_string(k) +
          " at " + show(key[0]) + ")");
      }
    }
  }
  animations_.push_back({ nodes_[node].firstValue + index, std::move(animation) });
  if (std::find(animatedNodes_.begin(), animatedNodes_.end(), node) == animatedNodes_.end())
  {
    animatedNodes_.push_back(node);
  }
}

InstanceError::InstanceError(std::uint32_t node, double time, const std::string& reason)
  : std::invalid_argument(reason + " at t = " + show(time) +
      (node == Threshold ? std::string() : " (node " + std::to_string(node) + ")"))
  , node_(node)
  , time_(time)
  , reason_(reason)
{
}

void BlobTree::checkAt(double t, const double* values, double threshold) const
{
  // Only animated values change with t; the others passed add()'s checks.
  if (!(threshold > 0) || !std::isfinite(threshold))
  {
    throw InstanceError(InstanceError::Threshold, t,
      "blobtree: the threshold T must be positive and finite (got " + show(threshold) + ")");
  }
  for (const std::uint32_t i : animatedNodes_)
  {
    const Node& n = nodes_[i];
    try
    {
      checkValues(n.kind, values + n.firstValue, n.valueCount);
    }
    catch (const std::invalid_argument& e)
    {
      throw InstanceError(i, t, e.what());
    }
  }
}

const Animation* BlobTree::animation(std::uint32_t node, std::uint32_t index) const
{
  if (node >= nodes_.size() || index >= nodes_[node].valueCount)
  {
    return nullptr;
  }
  const std::uint32_t value = nodes_[node].firstValue + index;
  for (auto a = animations_.rbegin(); a != animations_.rend(); ++a)
  {
    if (a->value == value)
    {
      return &a->animation;
    }
  }
  return nullptr;
}

void BlobTree::animateThreshold(Animation animation)
{
  BlobTree probe;
  probe.add(Kind::Translate, { 0, 0, 0 }, { probe.add(Kind::Point, { 1, 1, 0, 0, 0 }) });
  probe.animate(1, 0, animation); // the same checks
  thresholdAnimation_.assign(1, std::move(animation));
}

void BlobTree::clear()
{
  nodes_.clear();
  values_.clear();
  links_.clear();
  parented_.clear();
  animations_.clear();
  thresholdAnimation_.clear();
  animatedNodes_.clear();
  pieces_.clear();
  root_ = 0;
  touch();
}

namespace
{
template <class F>
void visitReachable(const BlobTree& tree, F&& f)
{
  if (tree.empty())
  {
    return;
  }
  std::vector<std::uint32_t> stack{ tree.root() };
  while (!stack.empty())
  {
    const std::uint32_t i = stack.back();
    stack.pop_back();
    f(tree.node(i));
    const std::uint32_t* c = tree.children(i);
    stack.insert(stack.end(), c, c + tree.node(i).childCount);
  }
}
} // namespace

std::size_t BlobTree::leafCount() const
{
  std::size_t n = 0;
  visitReachable(*this, [&](const Node& node) { n += isSkeletal(node.kind); });
  return n;
}
std::size_t BlobTree::operatorCount() const
{
  std::size_t n = 0;
  visitReachable(*this,
    [&](const Node& node)
    {
      n += !isSkeletal(node.kind) && !isWarp(node.kind) && !isComplexPrimitive(node.kind) &&
        !isTexture(node.kind);
    });
  return n;
}
std::size_t BlobTree::warpCount() const
{
  std::size_t n = 0;
  visitReachable(*this, [&](const Node& node) { n += isWarp(node.kind); });
  return n;
}
std::size_t BlobTree::count(Kind kind) const
{
  std::size_t n = 0;
  visitReachable(*this, [&](const Node& node) { n += node.kind == kind; });
  return n;
}

// --- evaluation ----------------------------------------------------------------------------------

namespace
{
const BlobTree& expanded(const BlobTree& tree, BlobTree& storage)
{
  for (const Node& n : tree.nodes())
  {
    if (isComplexPrimitive(n.kind))
    {
      tree.instantiate(0.0, storage);
      return storage;
    }
  }
  return tree;
}
} // namespace

namespace
{
template <class S>
std::array<S, MaterialSize> defaultMaterial()
{
  return { S(DefaultMaterial[0]), S(DefaultMaterial[1]), S(DefaultMaterial[2]),
    S(DefaultMaterial[3]), S(DefaultMaterial[4]), S(DefaultMaterial[5]) };
}

// The one entry to the traversal: (f, Phi) at p, complex primitives expanded first.
template <class S>
typename Walker<S>::Value walkTree(const BlobTree& tree, const P<S>& p, bool textured,
  TextureHyperBlend mode, std::size_t* kernels = nullptr)
{
  if (tree.empty())
  {
    throw std::invalid_argument("blobtree: the tree is empty");
  }
  BlobTree storage;
  const BlobTree& t = expanded(tree, storage);
  Walker<S> walk{ t, t.threshold(), kernels };
  walk.textured = textured;
  walk.hyperMode = mode;
  return walk.value(t.root(), p, false, defaultMaterial<S>());
}
} // namespace

Expr potential(const BlobTree& tree)
{
  return walkTree(
    tree, P<Expr>{ Expr::x(), Expr::y(), Expr::z() }, false, TextureHyperBlend::Corrected)
    .f;
}

Shape shape(const BlobTree& tree)
{
  return Shape(potential(tree) - tree.threshold(), Domain::XYZ, "blobtree");
}

double evaluate(const BlobTree& tree, const Vec3& p, std::size_t* kernelEvaluations)
{
  return walkTree(
    tree, P<double>{ p[0], p[1], p[2] }, false, TextureHyperBlend::Corrected, kernelEvaluations)
    .f;
}

std::array<Expr, MaterialSize> material(const BlobTree& tree, TextureHyperBlend mode)
{
  return walkTree(tree, P<Expr>{ Expr::x(), Expr::y(), Expr::z() }, true, mode).phi;
}

double evaluateTextured(const BlobTree& tree, const Vec3& p, std::array<double, MaterialSize>& phi,
  TextureHyperBlend mode)
{
  const auto v = walkTree(tree, P<double>{ p[0], p[1], p[2] }, true, mode);
  phi = v.phi;
  return v.f;
}

Hypervolume texturedHypervolume(const BlobTree& tree, TextureHyperBlend mode)
{
  const std::array<Expr, MaterialSize> phi = material(tree, mode);
  Hypervolume hv(shape(tree));
  // Components [first, first + 3) of Phi as one attribute, the default material everywhere else.
  for (const auto& [name, first] : { std::pair<const char*, int>{ "colour", 0 }, { "optics", 3 } })
  {
    Attribute a;
    a.name = name;
    a.components = { phi[first], phi[first + 1], phi[first + 2] };
    a.insideDefault = { DefaultMaterial[first], DefaultMaterial[first + 1],
      DefaultMaterial[first + 2] };
    a.outsideDefault = a.insideDefault;
    hv.addAttribute(a);
  }
  return hv;
}

std::array<Vec3, 2> supportBox(const BlobTree& tree)
{
  if (tree.empty())
  {
    throw std::invalid_argument("blobtree: the tree is empty");
  }
  BlobTree storage;
  const BlobTree& t = expanded(tree, storage);
  // Children come before their parents, so one pass in index order has every child's box ready.
  std::vector<Box> boxes(t.nodes().size(), emptyBox());
  for (std::uint32_t i = 0; i < t.nodes().size(); ++i)
  {
    const Node& n = t.node(i);
    const double* v = t.values(i);
    const std::uint32_t* c = t.children(i);
    if (isSkeletal(n.kind))
    {
      boxes[i] = elementBox(n.kind, v, n.valueCount);
      continue;
    }
    if (!isWarp(n.kind))
    {
      for (std::uint32_t k = 0; k < n.childCount; ++k)
      {
        merge(boxes[i], boxes[c[k]]);
      }
      continue;
    }
    const Box& b = boxes[c[0]];
    if (isEmpty(b))
    {
      continue;
    }
    if (n.kind == Kind::Translate)
    {
      boxes[i] = { Vec3{ b[0][0] + v[0], b[0][1] + v[1], b[0][2] + v[2] },
        Vec3{ b[1][0] + v[0], b[1][1] + v[1], b[1][2] + v[2] } };
    }
    else if (n.kind == Kind::Scale)
    {
      for (int k = 0; k < 3; ++k)
      {
        const double a = b[0][k] * v[k];
        const double e = b[1][k] * v[k];
        boxes[i][0][k] = std::min(a, e);
        boxes[i][1][k] = std::max(a, e);
      }
    }
    else if (n.kind == Kind::Rotate)
    {
      const Vec3 k = vscale(vec(v), 1.0 / std::sqrt(vdot(vec(v), vec(v))));
      const double cs = std::cos(v[3]);
      const double sn = std::sin(v[3]);
      for (int corner = 0; corner < 8; ++corner)
      {
        const Vec3 q{ b[corner & 1][0], b[(corner >> 1) & 1][1], b[(corner >> 2) & 1][2] };
        const Vec3 kq = vcross(k, q);
        const double w = vdot(k, q) * (1 - cs);
        grow(boxes[i],
          { q[0] * cs + kq[0] * sn + w * k[0], q[1] * cs + kq[1] * sn + w * k[1],
            q[2] * cs + kq[2] * sn + w * k[2] },
          0.0);
      }
    }
    else // Twist: every slice turns about z, so the box's corners sweep a disc
    {
      double rho = 0;
      for (int corner = 0; corner < 4; ++corner)
      {
        rho = std::max(rho, std::hypot(b[corner & 1][0], b[(corner >> 1) & 1][1]));
      }
      boxes[i] = { Vec3{ -rho, -rho, b[0][2] }, Vec3{ rho, rho, b[1][2] } };
    }
  }
  const Box& b = boxes[t.root()];
  if (isEmpty(b))
  {
    return { Vec3{ 0, 0, 0 }, Vec3{ 0, 0, 0 } };
  }
  return b;
}

double kernel(double d2, double R, double intensity)
{
  return wyvill(d2, R, intensity);
}
double hyperBlend(double a, double b, double n)
{
  return std::pow(hyperPower(a, n) + hyperPower(b, n), 1.0 / n);
}
double localBlend(double a, double b, double r)
{
  return localBlendOf(a, b, r);
}
double differenceMinMax(double a, double b, double T)
{
  return min(a, 2.0 * T - b);
}
double unionR(double a, double b, double T)
{
  return unionRT(a, b, T);
}
double intersectionR(double a, double b, double T)
{
  return intersectionRT(a, b, T);
}

} // namespace ictk::frep::blob
