// SPDX-License-Identifier: BSD-3-Clause
// Issue 16: Andyhausen's egg contents as two volumetric space partitions, the yolk and the white
// (thesis L3451-L3463), so a tetrahedral mesh of a frame of the running model labels the inside
// of the egg with two materials whose volumes are the partitions' analytic ones.
#include "Engine/DynamicModel.h"
#include "Mesh/Backends/Backends.h"
#include "Mesh/Quality.h"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <string>

namespace
{

using namespace ictk;

constexpr double pi = 3.14159265358979323846;

/// The egg's partitions in the model's frame at time t, meshed on their own.
mesh::TetMesh meshEggAt(double t, mesh::Backend backend)
{
  engine::DynamicModel m =
    engine::DynamicModel::load(std::string(ICTK_DATA_DIR) + "/Models/icm/andyhausen.icm");
  m.advanceTo(t, 0.25);
  const complex::Complex frame = m.complex();
  complex::Complex egg;
  for (const char* name : { "Egg_white", "Egg_yolk" })
  {
    const complex::Cell* c = frame.findCell(name);
    if (!c)
      throw std::runtime_error(std::string("no cell ") + name + " at t = " + std::to_string(t));
    egg.addCell(*c);
  }
  mesh::TetraOptions o;
  o.size = 0.04;
  o.deterministic = true;
  mesh::ValidityReport validity;
  mesh::TetMesh tets = mesh::tetrahedralize(egg, backend, o, &validity);
  EXPECT_TRUE(validity.valid()) << "t = " << t;
  return tets;
}

} // namespace

// The yolk is the ball of radius 0.2 at the contents' centre, the white the ellipsoid of
// semi-axes 0.4, 0.6, 0.4 without it: 4/3 pi 0.008 = 0.0335103 and 4/3 pi (0.096 - 0.008) =
// 0.3686136. The contents hang with the egg, centred at y = -1.3 - 0.4 t (t = 1: -1.7), and keep
// the place the shell left them at in ANDY_OUT (from t = 6.346875: y = -3.83875).
TEST(EngineEggMaterials, YolkAndWhiteAreTwoMaterialsOfAFrame)
{
  const auto backend = mesh::defaultBackend();
  if (!backend)
    GTEST_SKIP() << "no tetrahedral backend was built (ICTK_ENABLE_GPL_BACKENDS=OFF)";
  const double yolk = 4.0 / 3.0 * pi * 0.008, white = 4.0 / 3.0 * pi * (0.096 - 0.008);
  for (const auto& [t, centreY] : { std::pair{ 1.0, -1.7 }, std::pair{ 7.0, -3.83875 } })
  {
    SCOPED_TRACE("t = " + std::to_string(t));
    const mesh::TetMesh tets = meshEggAt(t, *backend);
    ASSERT_EQ(tets.materialNames, (std::vector<std::string>{ "Egg_white", "Egg_yolk" }));
    const mesh::QualityReport q = mesh::measureQuality(tets);
    ASSERT_EQ(q.materials.size(), 2u);
    std::size_t labelled = 0;
    for (const mesh::MaterialQuality& mq : q.materials)
    {
      EXPECT_GT(mq.tetrahedra, 0u) << mq.material;
      labelled += mq.tetrahedra;
    }
    EXPECT_EQ(labelled, tets.tetrahedra.size());
    // Inscribed surfaces of edge h = 0.04 lose O(h^2 / R) of the volume: for the ball of
    // radius 0.2 a chord's sagitta h^2 / (8 R) = 0.001 is 0.5 % of R, 1.5 % of the volume.
    std::cout << "t = " << t << ": white " << q.materials[0].volume << " (" << white << "), yolk "
              << q.materials[1].volume << " (" << yolk << "), " << tets.tetrahedra.size()
              << " tetrahedra\n";
    EXPECT_NEAR(q.materials[0].volume, white, 0.02 * white);
    EXPECT_NEAR(q.materials[1].volume, yolk, 0.02 * yolk);
    // The yolk is where the contents are: its tetrahedra's centroid is the contents' centre.
    double sum[3] = { 0, 0, 0 }, volume = 0;
    for (std::size_t k = 0; k < tets.tetrahedra.size(); ++k)
    {
      if (tets.materials[k] != 2)
        continue;
      const auto& tet = tets.tetrahedra[k];
      const double v = mesh::orientation(tets.points[tet[0]], tets.points[tet[1]],
                         tets.points[tet[2]], tets.points[tet[3]]) /
        6.0;
      for (int d = 0; d < 3; ++d)
        sum[d] += v *
          (tets.points[tet[0]][d] + tets.points[tet[1]][d] + tets.points[tet[2]][d] +
            tets.points[tet[3]][d]) /
          4.0;
      volume += v;
    }
    EXPECT_NEAR(sum[0] / volume, 0.0, 2e-3);
    EXPECT_NEAR(sum[1] / volume, centreY, 2e-3);
    EXPECT_NEAR(sum[2] / volume, 0.0, 2e-3);
  }
}
