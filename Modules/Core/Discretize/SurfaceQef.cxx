// SPDX-License-Identifier: BSD-3-Clause
// Vertex placement of manifold dual contouring (SurfaceDetail.h): each patch component of a cell
// gets the point that best fits the tangent planes of its crossings (the quadric error function),
// which keeps sharp edges and corners, solved by eigen-decomposition with small eigenvalues
// dropped so that flat and cylindrical patches stay near their mass point. The only user of Eigen,
// so that Eigen stays out of every header.
#include "Discretize/SurfaceDetail.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>

namespace ictk::discretize::detail::surface
{
namespace
{

// Eigenvalues of the QEF matrix below this fraction of the largest are dropped.
constexpr double EigenCutoff = 0.01;
// A feature-line vertex may fall this many cell edges outside its cell before the rank drops to
// 1 (measured on the sphere-gyroid: 0 gives chamfered curved edges, 0.5 folds at coarse sizes).
constexpr double FeatureLineSlack = 0.1;
// Vertices keep this fraction of the cell edge away from the cell faces, so that vertices of
// different cells never coincide.
constexpr double CellMargin = 1e-4;

} // namespace

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

} // namespace ictk::discretize::detail::surface
