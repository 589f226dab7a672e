// SPDX-License-Identifier: BSD-3-Clause
// The CGAL Mesh_3 backend (Mesh/CGAL/MeshCgal.h) against plain CGAL Mesh_3 on the same implicit
// model: a sphere of radius 0.5 (priority 1) inside the box [-1, 1]^3 (priority 0), two materials,
// at sizes 0.1, 0.05 and 0.025, deterministic (no perturb / exude) and default (perturb + exude);
// the backend's default mode also on 2 threads (CGAL's Parallel_tag, issue 20) against plain
// sequential CGAL.
//
// "Plain CGAL" is what a CGAL user would write: a labelled domain whose label function is a C++
// lambda, the box's 12 edges given as 2-point polylines, and the same criteria, error bound and
// steps as the backend. The difference is ICTK's cost: compiled tape evaluation instead of inline
// C++, the priority/overlap logic, feature detection by curve tracing, output conversion.
// Each case reports tetrahedra, tets/s, the minimum dihedral angle (degrees), the mean edge
// length (per tetrahedron edge) and the time.
//
// Issue 15's specimen (ctImplant / plainCgalCt, when Debian's invesalius-examples is installed):
// Data/Studies/ct-implant/ct-implant.json through the backend at 1 mm, against plain CGAL on the
// same labelled domain: a label function reading the CT by trilinear interpolation (bone where
// HU >= 226 in the box, the pin and its shell by their radii), the box's 12 edges and the pin's
// and shell's circles on the box's top and bottom faces as polylines. Plain CGAL is not told the
// curves where the bone meets the box's faces (a user would have to trace them), so its bone
// surface there is not protected. plainCgalCt/no_exude stops after refinement; plainCgalCt/exuded
// also exudes slivers (make_mesh_3's default), as the backend's deterministic mode does.
//
//   ictkBenchMeshCgal                                   all cases (a few minutes)
//   ictkBenchMeshCgal --benchmark_filter=0.1/           (any Google Benchmark flag)
#include "Lang/ComplexFile.h"
#include "Mesh/CGAL/MeshCgal.h"
#include "MeshTestModels.h"
#include "Voxel/VolumeFile.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Labeled_mesh_domain_3.h>
#include <CGAL/Mesh_complex_3_in_triangulation_3.h>
#include <CGAL/Mesh_criteria_3.h>
#include <CGAL/Mesh_domain_with_polyline_features_3.h>
#include <CGAL/Mesh_triangulation_3.h>
#include <CGAL/Random.h>
#include <CGAL/make_mesh_3.h>

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <unordered_map>

using namespace ictk;

namespace
{

using frep::Point3;

double minDihedralDegrees(
  const std::vector<Point3>& points, const std::vector<std::array<std::uint32_t, 4>>& tets)
{
  static const int edges[6][4] = { { 0, 1, 2, 3 }, { 0, 2, 1, 3 }, { 0, 3, 1, 2 }, { 1, 2, 0, 3 },
    { 1, 3, 0, 2 }, { 2, 3, 0, 1 } };
  double best = 180;
  for (const auto& t : tets)
  {
    for (const auto& e : edges)
    {
      const Point3& a = points[t[e[0]]];
      const Point3& b = points[t[e[1]]];
      Point3 axis{ b[0] - a[0], b[1] - a[1], b[2] - a[2] };
      const double n = std::sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
      for (auto& c : axis)
      {
        c /= n;
      }
      Point3 u[2];
      for (int k = 0; k < 2; ++k)
      {
        const Point3& q = points[t[e[2 + k]]];
        Point3 v{ q[0] - a[0], q[1] - a[1], q[2] - a[2] };
        const double d = v[0] * axis[0] + v[1] * axis[1] + v[2] * axis[2];
        for (int c = 0; c < 3; ++c)
        {
          v[c] -= d * axis[c];
        }
        u[k] = v;
      }
      const double dot = u[0][0] * u[1][0] + u[0][1] * u[1][1] + u[0][2] * u[1][2];
      const double nu = std::sqrt(u[0][0] * u[0][0] + u[0][1] * u[0][1] + u[0][2] * u[0][2]) *
        std::sqrt(u[1][0] * u[1][0] + u[1][1] * u[1][1] + u[1][2] * u[1][2]);
      best = std::min(best, std::acos(std::clamp(dot / nu, -1.0, 1.0)) * 180 / M_PI);
    }
  }
  return best;
}

void report(benchmark::State& state, const std::vector<Point3>& points,
  const std::vector<std::array<std::uint32_t, 4>>& tets)
{
  state.counters["tets"] = static_cast<double>(tets.size());
  state.counters["points"] = static_cast<double>(points.size());
  state.counters["tets/s"] = benchmark::Counter(
    static_cast<double>(tets.size()), benchmark::Counter::kIsIterationInvariantRate);
  state.counters["minDihedral"] = minDihedralDegrees(points, tets);
  double sum = 0;
  for (const auto& t : tets)
  {
    for (int a = 0; a < 4; ++a)
    {
      for (int b = a + 1; b < 4; ++b)
      {
        const Point3& p = points[t[a]];
        const Point3& q = points[t[b]];
        sum += std::sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) +
          (p[2] - q[2]) * (p[2] - q[2]));
      }
    }
  }
  state.counters["meanEdge"] = tets.empty() ? 0 : sum / (6.0 * static_cast<double>(tets.size()));
}

void ictkBackend(benchmark::State& state, double size, bool deterministic, int threads = 1)
{
  const complex::Complex k =
    lang::readComplexJson(ictk::testing::sphereInBoxJson(), "sphere-in-box.json");
  mesh::TetraOptions o;
  o.size = size;
  o.deterministic = deterministic;
  o.threads = threads; // the default mode on 2 threads is CGAL's Parallel_tag
  mesh::TetMesh m;
  for (auto _ : state)
  {
    m = mesh::tetrahedralizeCgal(k, o);
    benchmark::DoNotOptimize(m.tetrahedra.data());
  }
  report(state, m.points, m.tetrahedra);
}

// --- plain CGAL --------------------------------------------------------------------------------
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Domain = CGAL::Mesh_domain_with_polyline_features_3<CGAL::Labeled_mesh_domain_3<K>>;
using Tr = CGAL::Mesh_triangulation_3<Domain, CGAL::Default, CGAL::Sequential_tag>::type;
using C3t3 = CGAL::Mesh_complex_3_in_triangulation_3<Tr, Domain::Corner_index, Domain::Curve_index>;
using Criteria = CGAL::Mesh_criteria_3<Tr>;

/// The backend's criteria at `size`.
Criteria criteriaFor(double size)
{
  namespace p = CGAL::parameters;
  return Criteria(p::edge_size = size, p::facet_angle = 25, p::facet_size = 0.75 * size,
    p::facet_distance = 0.1 * size, p::cell_radius_edge_ratio = 3, p::cell_size = 0.8 * size);
}

/// The tetrahedra of the complex and their points, numbered in the order met.
void extract(
  const C3t3& c3t3, std::vector<Point3>& points, std::vector<std::array<std::uint32_t, 4>>& tets)
{
  points.clear();
  tets.clear();
  std::unordered_map<const void*, std::uint32_t> index;
  for (auto c = c3t3.cells_in_complex_begin(); c != c3t3.cells_in_complex_end(); ++c)
  {
    std::array<std::uint32_t, 4> t{};
    for (int k = 0; k < 4; ++k)
    {
      const auto [it, added] =
        index.emplace(&*c->vertex(k), static_cast<std::uint32_t>(points.size()));
      if (added)
      {
        const auto& wp = c3t3.triangulation().point(c, k);
        points.push_back({ wp.x(), wp.y(), wp.z() });
      }
      t[k] = it->second;
    }
    tets.push_back(t);
  }
}

void plainCgal(benchmark::State& state, double size, bool deterministic)
{
  std::vector<Point3> points;
  std::vector<std::array<std::uint32_t, 4>> tets;
  for (auto _ : state)
  {
    if (deterministic)
    {
      CGAL::get_default_random() = CGAL::Random(0);
    }
    CGAL::Random rng(0);
    std::function<int(const K::Point_3&)> label = [](const K::Point_3& p)
    {
      const double x = p.x(), y = p.y(), z = p.z();
      if (x * x + y * y + z * z <= 0.25)
      {
        return 2;
      }
      return std::abs(x) <= 1 && std::abs(y) <= 1 && std::abs(z) <= 1 ? 1 : 0;
    };
    // The same box, error bound and criteria as the backend.
    const double pad = 0.02 * std::sqrt(3.0) * 2.1 + size;
    const double lo = -1.05 - pad, hi = 1.05 + pad;
    Domain domain(label, K::Iso_cuboid_3(K::Point_3(lo, lo, lo), K::Point_3(hi, hi, hi)),
      K::FT(1e-10), CGAL::Null_subdomain_index(), &rng);
    std::vector<std::vector<K::Point_3>> edges;
    for (int axis = 0; axis < 3; ++axis)
    {
      for (int s1 : { -1, 1 })
      {
        for (int s2 : { -1, 1 })
        {
          double a[3], b[3];
          a[axis] = -1;
          b[axis] = 1;
          a[(axis + 1) % 3] = b[(axis + 1) % 3] = s1;
          a[(axis + 2) % 3] = b[(axis + 2) % 3] = s2;
          edges.push_back({ K::Point_3(a[0], a[1], a[2]), K::Point_3(b[0], b[1], b[2]) });
        }
      }
    }
    domain.add_features(edges.begin(), edges.end());
    namespace p = CGAL::parameters;
    const Criteria criteria = criteriaFor(size);
    C3t3 c3t3 = deterministic
      ? CGAL::make_mesh_3<C3t3>(domain, criteria, p::no_perturb(), p::no_exude())
      : CGAL::make_mesh_3<C3t3>(
          domain, criteria, p::perturb(p::sliver_bound = 12), p::exude(p::sliver_bound = 12));
    extract(c3t3, points, tets);
    benchmark::DoNotOptimize(tets.data());
  }
  report(state, points, tets);
}

// --- issue 15: the CT specimen with its pin ---------------------------------------------------
const char* kCranium = "/usr/share/doc/invesalius-examples/examples/Cranium.inv3";

bool haveCranium(benchmark::State& state)
{
  if (!std::ifstream(kCranium).good())
  {
    state.SkipWithError("Cranium.inv3 is missing (Debian: invesalius-examples)");
    return false;
  }
  return true;
}

void ctImplant(benchmark::State& state)
{
  if (!haveCranium(state))
  {
    return;
  }
  mesh::TetraOptions o;
  o.size = 1;
  o.deterministic = true;
  mesh::TetMesh m;
  for (auto _ : state)
  {
    const complex::Complex k =
      lang::readComplexFile(ICTK_DATA_DIR "/Studies/ct-implant/ct-implant.json");
    m = mesh::tetrahedralizeCgal(k, o);
    benchmark::DoNotOptimize(m.tetrahedra.data());
  }
  report(state, m.points, m.tetrahedra);
}

/// `exude`: make_mesh_3's default sliver exudation, as the backend does in its deterministic
/// mode (the backend's quality against CGAL's at the same steps).
void plainCgalCt(benchmark::State& state, bool exude)
{
  if (!haveCranium(state))
  {
    return;
  }
  const double size = 1, lo[3] = { 110.5, 110.5, 146.25 }, hi[3] = { 134.5, 134.5, 152.25 };
  const double cx = 122.5, cy = 122.5, pin = 2.5, shell = 3;
  std::vector<Point3> points;
  std::vector<std::array<std::uint32_t, 4>> tets;
  for (auto _ : state)
  {
    CGAL::get_default_random() = CGAL::Random(0);
    CGAL::Random rng(0);
    const auto grid = voxel::readInv3(kCranium);
    std::function<int(const K::Point_3&)> label = [&](const K::Point_3& p)
    {
      const double x = p.x(), y = p.y(), z = p.z();
      if (x < lo[0] || x > hi[0] || y < lo[1] || y > hi[1] || z < lo[2] || z > hi[2])
      {
        return 0;
      }
      const double r = std::hypot(x - cx, y - cy);
      if (r <= pin)
      {
        return 4;
      }
      if (r <= shell)
      {
        return 3;
      }
      // The trilinear interpolant of the HU, the scan's first point at the origin.
      double u[3];
      std::int64_t i[3];
      const double q[3] = { x, y, z };
      for (int a = 0; a < 3; ++a)
      {
        const double g = (q[a] - grid->origin[a]) / grid->spacing[a];
        i[a] = std::clamp<std::int64_t>(static_cast<std::int64_t>(g), 0, grid->dimensions[a] - 2);
        u[a] = g - static_cast<double>(i[a]);
      }
      double hu = 0;
      for (int c = 0; c < 8; ++c)
      {
        const int dx = c & 1, dy = (c >> 1) & 1, dz = c >> 2;
        hu += (dx ? u[0] : 1 - u[0]) * (dy ? u[1] : 1 - u[1]) * (dz ? u[2] : 1 - u[2]) *
          grid->at(i[0] + dx, i[1] + dy, i[2] + dz);
      }
      return hu >= 226 ? 2 : 1;
    };
    const K::Point_3 a(lo[0] - size, lo[1] - size, lo[2] - size);
    const K::Point_3 b(hi[0] + size, hi[1] + size, hi[2] + size);
    Domain domain(label, K::Iso_cuboid_3(a, b), K::FT(1e-10), CGAL::Null_subdomain_index(), &rng);
    std::vector<std::vector<K::Point_3>> edges;
    for (int axis = 0; axis < 3; ++axis)
    {
      for (int s1 : { 0, 1 })
      {
        for (int s2 : { 0, 1 })
        {
          double e0[3], e1[3];
          e0[axis] = lo[axis];
          e1[axis] = hi[axis];
          const int j = (axis + 1) % 3, k = (axis + 2) % 3;
          e0[j] = e1[j] = s1 ? hi[j] : lo[j];
          e0[k] = e1[k] = s2 ? hi[k] : lo[k];
          edges.push_back({ K::Point_3(e0[0], e0[1], e0[2]), K::Point_3(e1[0], e1[1], e1[2]) });
        }
      }
    }
    for (const double radius : { pin, shell })
    {
      for (const double z : { lo[2], hi[2] })
      {
        std::vector<K::Point_3> circle;
        const int n = 64;
        for (int t = 0; t <= n; ++t)
        {
          const double angle = 2 * M_PI * (t % n) / n;
          circle.emplace_back(cx + radius * std::cos(angle), cy + radius * std::sin(angle), z);
        }
        edges.push_back(circle);
      }
    }
    domain.add_features(edges.begin(), edges.end());
    namespace p = CGAL::parameters;
    const Criteria criteria = criteriaFor(size);
    C3t3 c3t3 = exude ? CGAL::make_mesh_3<C3t3>(domain, criteria, p::no_perturb())
                      : CGAL::make_mesh_3<C3t3>(domain, criteria, p::no_perturb(), p::no_exude());
    extract(c3t3, points, tets);
    benchmark::DoNotOptimize(tets.data());
  }
  report(state, points, tets);
}

} // namespace

BENCHMARK_CAPTURE(ictkBackend, 0.1_deterministic, 0.1, true)
  ->Unit(benchmark::kMillisecond)
  ->UseRealTime()
  ->Iterations(1);
BENCHMARK_CAPTURE(plainCgal, 0.1_deterministic, 0.1, true)
  ->Unit(benchmark::kMillisecond)
  ->UseRealTime()
  ->Iterations(1);
BENCHMARK_CAPTURE(ictkBackend, 0.1_default, 0.1, false)
  ->Unit(benchmark::kMillisecond)
  ->UseRealTime()
  ->Iterations(1);
BENCHMARK_CAPTURE(plainCgal, 0.1_default, 0.1, false)
  ->Unit(benchmark::kMillisecond)
  ->UseRealTime()
  ->Iterations(1);
BENCHMARK_CAPTURE(ictkBackend, 0.1_default_2threads, 0.1, false, 2)
  ->Unit(benchmark::kMillisecond)
  ->UseRealTime()
  ->Iterations(1);
BENCHMARK_CAPTURE(ictkBackend, 0.05_deterministic, 0.05, true)
  ->Unit(benchmark::kMillisecond)
  ->UseRealTime()
  ->Iterations(1);
BENCHMARK_CAPTURE(plainCgal, 0.05_deterministic, 0.05, true)
  ->Unit(benchmark::kMillisecond)
  ->UseRealTime()
  ->Iterations(1);
BENCHMARK_CAPTURE(ictkBackend, 0.05_default, 0.05, false)
  ->Unit(benchmark::kMillisecond)
  ->UseRealTime()
  ->Iterations(1);
BENCHMARK_CAPTURE(plainCgal, 0.05_default, 0.05, false)
  ->Unit(benchmark::kMillisecond)
  ->UseRealTime()
  ->Iterations(1);
BENCHMARK_CAPTURE(ictkBackend, 0.05_default_2threads, 0.05, false, 2)
  ->Unit(benchmark::kMillisecond)
  ->UseRealTime()
  ->Iterations(1);
BENCHMARK_CAPTURE(ictkBackend, 0.025_deterministic, 0.025, true)
  ->Unit(benchmark::kMillisecond)
  ->UseRealTime()
  ->Iterations(1);
BENCHMARK_CAPTURE(plainCgal, 0.025_deterministic, 0.025, true)
  ->Unit(benchmark::kMillisecond)
  ->UseRealTime()
  ->Iterations(1);
BENCHMARK_CAPTURE(ictkBackend, 0.025_default, 0.025, false)
  ->Unit(benchmark::kMillisecond)
  ->UseRealTime()
  ->Iterations(1);
BENCHMARK_CAPTURE(plainCgal, 0.025_default, 0.025, false)
  ->Unit(benchmark::kMillisecond)
  ->UseRealTime()
  ->Iterations(1);
BENCHMARK(ctImplant)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);
BENCHMARK_CAPTURE(plainCgalCt, no_exude, false)
  ->Unit(benchmark::kMillisecond)
  ->UseRealTime()
  ->Iterations(1);
BENCHMARK_CAPTURE(plainCgalCt, exuded, true)
  ->Unit(benchmark::kMillisecond)
  ->UseRealTime()
  ->Iterations(1);
BENCHMARK_CAPTURE(ictkBackend, 0.025_default_2threads, 0.025, false, 2)
  ->Unit(benchmark::kMillisecond)
  ->UseRealTime()
  ->Iterations(1);
BENCHMARK_MAIN();
