// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The FRep primitive library (f >= 0 inside). Formulas follow the HyperFun library (hf* names in
// brackets) so that HyperFun models read later give the same fields; every function lowers to the
// expression DAG, so all evaluators support every primitive.

#include "FRep/Domain.h"

#include <array>
#include <vector>

namespace ictk::frep
{
using Vec2 = std::array<double, 2>;
using Vec3 = std::array<double, 3>;

// --- 1D and 2D ------------------------------------------------------------------------------
/// Segment [a, b] on axis X (domain X): (x - a)(b - x).
Shape interval(double a, double b);
/// Time interval [t0, t1] (domain T): (t - t0)(t1 - t).
Shape timeInterval(double t0, double t1);
/// Disk (domain XY): r^2 - |p - c|^2.
Shape circle(const Vec2& center, double r);
/// Elliptic disk (domain XY): 1 - ((x-cx)/a)^2 - ((y-cy)/b)^2.
Shape ellipse(const Vec2& center, double a, double b);
/// Axis-aligned rectangle (domain XY) with corner `vertex` and sides dx, dy.
Shape rectangle(const Vec2& vertex, double dx, double dy);

// --- 3D (domain XYZ) ---------------------------------------------------------------------------
Shape sphere(const Vec3& center, double r);                               // hfSphere
Shape ellipsoid(const Vec3& center, double a, double b, double c);        // hfEllipsoid
Shape block(const Vec3& vertex, double dx, double dy, double dz);         // hfBlock
Shape cylinder(Axis axis, const Vec3& center, double r);                  // hfCylinderX/Y/Z
Shape ellipticCylinder(Axis axis, const Vec3& center, double a, double b); // hfEllCylX/Y/Z
Shape cone(Axis axis, const Vec3& apex, double r);                        // hfConeX/Y/Z
Shape ellipticCone(Axis axis, const Vec3& apex, double a, double b);      // hfEllConeX/Y/Z
Shape torus(Axis axis, const Vec3& center, double R, double r);           // hfTorusX/Y/Z
Shape superellipsoid(const Vec3& center, double a, double b, double c, double s1, double s2); // hfSuperell
/// General quadric with 10 coefficients (seed 003 eq. 1):
/// A11x^2 + A22y^2 + A33z^2 + A12xy + A13xz + A23yz + A14x + A24y + A34z + A44.
Shape quadric(const std::array<double, 10>& coefficients);
/// Half-space n.(p - p0) <= 0 is outside: f = n.(p0 - p)... see Primitives.cxx.
Shape halfSpace(const Vec3& point, const Vec3& inwardNormal);

// --- skeletal and convolution primitives --------------------------------------------------------
/// Blobby model [hfBlobby]: sum_i b_i exp(-a_i r_i^2) - T.
Shape blobby(const std::vector<Vec3>& centers, const std::vector<double>& a,
  const std::vector<double>& b, double threshold);
/// Metaballs [hfMetaBall] (Nishimura piecewise quadratic).
Shape metaball(const std::vector<Vec3>& centers, const std::vector<double>& b,
  const std::vector<double>& d, double threshold);
/// Soft objects [hfSoft] (Wyvill, McPheeters & Wyvill 1986).
Shape softObject(const std::vector<Vec3>& centers, const std::vector<double>& d, double threshold);

/// Convolution surfaces with the Cauchy kernel h(r) = 1 / (1 + s^2 r^2)^2
/// (thesis_ch2_3.md section 1.7; McCormack & Sherstyuk 1998), f = sum of skeleton fields - T.
Shape convolutionPoints(const std::vector<Vec3>& points, const std::vector<double>& s, double threshold);
Shape convolutionSegments(const std::vector<std::array<Vec3, 2>>& segments, const std::vector<double>& s,
  double threshold);
Shape convolutionArcs(/* center, radius, axis, angle per arc */ const std::vector<Vec3>& centers,
  const std::vector<double>& radii, const std::vector<Vec3>& axes, const std::vector<double>& angles,
  const std::vector<double>& s, double threshold);
Shape convolutionTriangles(const std::vector<std::array<Vec3, 3>>& triangles, const std::vector<double>& s,
  double threshold);
/// A polyline skeleton (consecutive points joined by segments).
Shape convolutionCurve(const std::vector<Vec3>& polyline, double s, double threshold);
/// A triangle-mesh skeleton.
Shape convolutionMesh(const std::vector<Vec3>& vertices, const std::vector<std::array<int, 3>>& triangles,
  double s, double threshold);

// --- noise and perturbation ---------------------------------------------------------------------
/// Gardner-style solid noise [hfNoiseG], added to a field to roughen it.
Expr gardnerNoise(double amplitude, double frequency, double phase);
/// Vyatkin perturbation (seed 003 eq. 2-3, with the signed factor of papers.md E9):
/// F' = F + sum_i k_i R_i, R_i = Q_i^3 where Q_i >= 0, else 0.
Shape perturb(const Shape& base, const std::vector<Shape>& perturbingQuadrics,
  const std::vector<double>& factors);

} // namespace ictk::frep
