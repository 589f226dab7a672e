// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Two-material bars for the mesh tests (issue 6): [0,1]x[0,0.2]^2 and [1,2]x[0,0.2]^2 as a
// complex read from JSON, meshed by the Kuhn split of a box grid and labelled by centroids; the
// area of the faces a mesh has on a plane (internal surfaces); a sphere in a box.

#include "Lang/ComplexFile.h"
#include "Mesh/Structured.h"
#include "Mesh/TetAttributes.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <string>

namespace ictk::testing
{

/// A sphere of radius 0.5 (priority 1) inside the box [-1, 1]^3: two materials, the CGAL
/// backend's benchmark (ictkBenchMeshCgal) and its parallel test.
inline const char* sphereInBoxJson()
{
  return R"({
  "cells": [
    { "name": "box", "kind": "F", "dimension": 3,
      "inside": ["x[1] + 1", "1 - x[1]", "x[2] + 1", "1 - x[2]", "x[3] + 1", "1 - x[3]"],
      "bounds": [[-1.05, -1.05, -1.05], [1.05, 1.05, 1.05]] },
    { "name": "sphere", "kind": "F", "dimension": 3, "priority": 1,
      "inside": ["0.25 - x[1]^2 - x[2]^2 - x[3]^2"],
      "bounds": [[-0.55, -0.55, -0.55], [0.55, 0.55, 0.55]] }
  ]
})";
}

/// The solver check's bar: E = 210000 | 70000, nu = 0 (springs in series are then exact) unless
/// `poisson` says otherwise.
inline std::string barJson(const std::string& left = "steel",
  const std::string& right = "aluminium", const std::string& leftModulus = "210000",
  bool spare = false, const std::string& poisson = "0")
{
  std::string s = R"({ "name": "bar",
  "attributes": {
    "youngs_modulus": { "components": 1, "inside": [1] },
    "poisson_ratio": { "components": 1, "inside": [0] },
    "density": { "components": 1, "inside": [1e-9] }
  },
  "attribute_functions": {
    "E1": [")" +
    leftModulus + R"("], "E2": ["70000"], "NU": [")" + poisson + R"("], "RHO": ["7.8e-9"]
  },
  "cells": [
    { "name": ")" +
    left + R"(", "kind": "F", "dimension": 3,
      "inside": ["x[1]", "1 - x[1]", "x[2]", "0.2 - x[2]", "x[3]", "0.2 - x[3]"],
      "bounds": [[0, 0, 0], [1, 0.2, 0.2]],
      "attributes": { "youngs_modulus": "E1", "poisson_ratio": "NU", "density": "RHO" } },
    { "name": ")" +
    right + R"(", "kind": "F", "dimension": 3,
      "inside": ["x[1] - 1", "2 - x[1]", "x[2]", "0.2 - x[2]", "x[3]", "0.2 - x[3]"],
      "bounds": [[1, 0, 0], [2, 0.2, 0.2]],
      "attributes": { "youngs_modulus": "E2", "poisson_ratio": "NU" } })";
  if (spare)
  {
    s += R"(,
    { "name": "spare", "kind": "F", "dimension": 3,
      "inside": ["1 - (x[1] - 5)^2 - x[2]^2 - x[3]^2"], "bounds": [[4, -1, -1], [6, 1, 1]],
      "attributes": { "youngs_modulus": "E2" } })";
  }
  return s + "\n  ]\n}\n";
}

/// The bar meshed with `nx` blocks along x and `ny` across, attributes assigned.
inline mesh::TetMesh barMesh(const complex::Complex& k, int nx = 20, int ny = 2)
{
  mesh::TetMesh m = mesh::kuhnTetMesh({ { 0, 0, 0 }, { 2, 0.2, 0.2 } }, { nx, ny, ny });
  mesh::labelByCentroid(m, k);
  mesh::assignAttributes(m, k);
  return m;
}

/// The area of the faces with every corner within `tolerance` of the plane z = z0 that two
/// tetrahedra share; `once` gets the area of those only one tetrahedron has.
inline double sharedAreaOnPlane(const mesh::TetMesh& m, double z0, double tolerance, double* once)
{
  std::map<std::array<std::uint32_t, 3>, int> faces;
  for (const auto& t : m.tetrahedra)
  {
    for (int skip = 0; skip < 4; ++skip)
    {
      std::array<std::uint32_t, 3> f{};
      int n = 0;
      bool onPlane = true;
      for (int c = 0; c < 4; ++c)
      {
        if (c != skip)
        {
          f[std::size_t(n++)] = t[std::size_t(c)];
          onPlane = onPlane && std::abs(m.points[t[std::size_t(c)]][2] - z0) <= tolerance;
        }
      }
      if (onPlane)
      {
        std::sort(f.begin(), f.end());
        ++faces[f];
      }
    }
  }
  double shared = 0;
  *once = 0;
  for (const auto& [f, count] : faces)
  {
    const frep::Point3& a = m.points[f[0]];
    const frep::Point3& b = m.points[f[1]];
    const frep::Point3& c = m.points[f[2]];
    const double ux = b[0] - a[0], uy = b[1] - a[1], vx = c[0] - a[0], vy = c[1] - a[1];
    const double area = 0.5 * std::abs(ux * vy - uy * vx);
    (count == 2 ? shared : *once) += area;
  }
  return shared;
}

} // namespace ictk::testing
