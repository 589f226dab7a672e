// SPDX-License-Identifier: BSD-3-Clause
// Dual contouring checked by CGAL's polygon mesh processing: the sphere-gyroid of libfive's
// benchmark at coarse sizes is a valid, closed, outward-oriented mesh without self-intersections
// (exact predicates). Its own executable: CGAL adds -frounding-math to whatever links it.
#include "Discretize/Surface.h"
#include "FRep/BundledModels.h"
#include "FRep/Field.h"
#include "FRep/Primitives.h"
#include "FRep/Tape.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>

#include <gtest/gtest.h>

#include <utility>
#include <vector>

using namespace ictk;

namespace
{

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using CgalMesh = CGAL::Surface_mesh<Kernel::Point_3>;
namespace PMP = CGAL::Polygon_mesh_processing;

CgalMesh toCgal(const discretize::SurfaceMesh& mesh)
{
  CgalMesh out;
  std::vector<CgalMesh::Vertex_index> vertices;
  vertices.reserve(mesh.points.size());
  for (const auto& p : mesh.points)
  {
    vertices.push_back(out.add_vertex(Kernel::Point_3(p[0], p[1], p[2])));
  }
  for (const auto& t : mesh.triangles)
  {
    // add_face refuses (returns null) a face that would make the mesh non-manifold.
    EXPECT_NE(out.add_face(vertices[t[0]], vertices[t[1]], vertices[t[2]]), CgalMesh::null_face());
  }
  return out;
}

void expectClean(const discretize::SurfaceMesh& mesh)
{
  const CgalMesh m = toCgal(mesh);
  EXPECT_EQ(m.number_of_faces(), mesh.triangles.size());
  EXPECT_TRUE(m.is_valid(false));
  EXPECT_TRUE(CGAL::is_closed(m));
  EXPECT_TRUE(PMP::is_outward_oriented(m));
  std::vector<std::pair<CgalMesh::Face_index, CgalMesh::Face_index>> pairs;
  PMP::self_intersections(m, std::back_inserter(pairs));
  EXPECT_TRUE(pairs.empty()) << pairs.size() << " intersecting triangle pairs";
  EXPECT_FALSE(PMP::does_self_intersect(m));
}

} // namespace

TEST(DiscretizeSurfaceCgal, SphereGyroidHasNoSelfIntersections)
{
  const frep::FieldPtr field =
    frep::tapeField(frep::Tape::compile(frep::bundled::sphereGyroidField()));
  for (double h : { 0.1, 0.17, 0.2, 0.25, 0.31 })
  {
    SCOPED_TRACE(h);
    discretize::SurfaceOptions options;
    options.featureSize = h;
    const discretize::SurfaceMesh mesh =
      discretize::contourSurface(*field, { { -5, -5, -5 }, { 5, 5, 5 } }, options);
    ASSERT_GT(mesh.triangles.size(), 1000u);
    expectClean(mesh);
  }
}

TEST(DiscretizeSurfaceCgal, SharpSolidsHaveNoSelfIntersections)
{
  using frep::Expr;
  const Expr x = Expr::x(), y = Expr::y(), z = Expr::z();
  // A box with faces off the grid, and a cylinder cut by a slab (sharp circular edges).
  const Expr box =
    min(min(min(x + 0.53, 0.61 - x), min(y + 0.47, 0.38 - y)), min(z + 0.29, 0.44 - z));
  const Expr cylinder =
    min(frep::cylinder(frep::Axis::Z, { 0, 0, 0 }, 0.5).function(), min(0.3 - z, z + 0.3));
  for (const Expr& f : { box, cylinder })
  {
    discretize::SurfaceOptions options;
    options.featureSize = 0.05;
    expectClean(discretize::contourSurface(
      *frep::tapeField(frep::Tape::compile(f)), { { -1, -1, -1 }, { 1, 1, 1 } }, options));
  }
}
