// SPDX-License-Identifier: BSD-3-Clause
#include "Mesh/ScanMaterials.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace ictk::mesh
{
namespace
{

Point3 mix(const Point3& a, const Point3& b, const Point3& c, const Point3& d, double wa, double wb,
  double wc, double wd)
{
  return { wa * a[0] + wb * b[0] + wc * c[0] + wd * d[0],
    wa * a[1] + wb * b[1] + wc * c[1] + wd * d[1], wa * a[2] + wb * b[2] + wc * c[2] + wd * d[2] };
}

Point3 mid(const Point3& a, const Point3& b)
{
  return { 0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1]), 0.5 * (a[2] + b[2]) };
}

/// The 32 equal-weight points of the integrated sampling (the header's rule).
void integrationPoints(const std::array<Point3, 4>& v, std::vector<Point3>& out)
{
  const Point3 &a = v[0], &b = v[1], &c = v[2], &d = v[3];
  const Point3 ab = mid(a, b), ac = mid(a, c), ad = mid(a, d), bc = mid(b, c), bd = mid(b, d),
               cd = mid(c, d);
  const std::array<std::array<Point3, 4>, 8> parts{ { { a, ab, ac, ad }, { b, ab, bc, bd },
    { c, ac, bc, cd }, { d, ad, bd, cd }, { ac, bd, ab, ad }, { ac, bd, ad, cd },
    { ac, bd, cd, bc }, { ac, bd, bc, ab } } };
  constexpr double alpha = 0.5854101966249685; // (5 + 3 sqrt 5) / 20
  constexpr double beta = 0.1381966011250105;  // (5 - sqrt 5) / 20
  for (const auto& t : parts)
  {
    out.push_back(mix(t[0], t[1], t[2], t[3], alpha, beta, beta, beta));
    out.push_back(mix(t[0], t[1], t[2], t[3], beta, alpha, beta, beta));
    out.push_back(mix(t[0], t[1], t[2], t[3], beta, beta, alpha, beta));
    out.push_back(mix(t[0], t[1], t[2], t[3], beta, beta, beta, alpha));
  }
}

void setArray(TetMesh& mesh, const std::string& name, std::vector<double> values)
{
  for (auto& a : mesh.cellData)
  {
    if (a.name == name)
    {
      a.components = 1;
      a.values = std::move(values);
      return;
    }
  }
  mesh.cellData.push_back({ name, 1, std::move(values) });
}

/// The lowest density written (air's law density is below 0).
constexpr double kMinimumDensity = 1e-3;

} // namespace

double ModulusLaw::operator()(double rho) const
{
  return a + b * std::pow(std::max(rho, 0.0), c);
}

double ModulusLaw::density(double modulus) const
{
  return modulus > a && b > 0 ? std::pow((modulus - a) / b, 1 / c) : NAN;
}

double scanModulus(double hu, const ScanMaterialOptions& options)
{
  return std::max(options.minimumModulus, options.modulus(options.density(hu)));
}

void checkScanMaterials(
  const ScanMaterialOptions& options, const std::vector<std::string>& materialNames)
{
  if (!(options.minimumModulus > 0) || !(options.poissonRatio > -1 && options.poissonRatio < 0.5))
  {
    throw std::invalid_argument("scan materials: the minimum modulus must be > 0 and the Poisson "
                                "ratio in (-1, 0.5)");
  }
  for (const auto& name : options.scanCells)
  {
    if (std::find(materialNames.begin(), materialNames.end(), name) == materialNames.end())
    {
      throw std::invalid_argument("scan materials: '" + name + "' is no cell of the mesh");
    }
  }
  for (const auto& [name, m] : options.fixed)
  {
    if (std::find(materialNames.begin(), materialNames.end(), name) == materialNames.end())
    {
      throw std::invalid_argument("scan materials: '" + name + "' is no cell of the mesh");
    }
    if (!(m.youngsModulus > 0) || !(m.density > 0) ||
      !(m.poissonRatio > -1 && m.poissonRatio < 0.5))
    {
      throw std::invalid_argument("scan materials: the material of '" + name +
        "' needs a positive modulus and density and a Poisson ratio in (-1, 0.5)");
    }
  }
  for (const auto& name : materialNames)
  {
    if (!options.scanCells.count(name) && !options.fixed.count(name))
    {
      throw std::invalid_argument(
        "scan materials: cell '" + name + "' is neither a scan cell nor given a fixed material");
    }
  }
}

ScanMaterialSummary assignScanMaterials(
  TetMesh& mesh, const frep::Field& hu, const ScanMaterialOptions& options)
{
  checkScanMaterials(options, mesh.materialNames);
  // Per material: from the scan (nullptr) or fixed.
  std::vector<const FixedMaterial*> fixed;
  for (const auto& name : mesh.materialNames)
  {
    const auto it = options.fixed.find(name);
    if (options.scanCells.count(name))
    {
      fixed.push_back(nullptr);
    }
    else
    {
      fixed.push_back(&it->second); // checkScanMaterials made sure it is there
    }
  }
  const std::size_t n = mesh.tetrahedra.size();
  std::vector<double> label(n), density(n), modulus(n), poisson(n);
  // The scan's points of every scan element, evaluated in one batch.
  const std::size_t per = options.sampling == ScanSampling::Integrated ? 32 : 1;
  std::vector<std::size_t> scanned;
  std::vector<Point3> points;
  for (std::size_t t = 0; t < n; ++t)
  {
    label[t] = mesh.materials[t];
    const FixedMaterial* f = fixed[static_cast<std::size_t>(mesh.materials[t] - 1)];
    if (f)
    {
      density[t] = f->density;
      modulus[t] = f->youngsModulus;
      poisson[t] = f->poissonRatio;
      continue;
    }
    std::array<Point3, 4> v;
    for (int k = 0; k < 4; ++k)
    {
      v[static_cast<std::size_t>(k)] = mesh.points[mesh.tetrahedra[t][static_cast<std::size_t>(k)]];
    }
    if (per == 1)
    {
      points.push_back(mix(v[0], v[1], v[2], v[3], 0.25, 0.25, 0.25, 0.25));
    }
    else
    {
      integrationPoints(v, points);
    }
    scanned.push_back(t);
  }
  std::vector<double> x(points.size()), y(points.size()), z(points.size()), h(points.size());
  for (std::size_t i = 0; i < points.size(); ++i)
  {
    x[i] = points[i][0];
    y[i] = points[i][1];
    z[i] = points[i][2];
  }
  if (!points.empty())
  {
    hu.evaluator()->values(x.data(), y.data(), z.data(), h.data(), points.size());
  }
  ScanMaterialSummary summary;
  summary.minModulus = scanned.empty() ? 0 : std::numeric_limits<double>::infinity();
  for (std::size_t s = 0; s < scanned.size(); ++s)
  {
    const std::size_t t = scanned[s];
    double e = 0;
    double rho = 0;
    for (std::size_t i = s * per; i < (s + 1) * per; ++i)
    {
      if (std::isnan(h[i]))
      {
        std::ostringstream m;
        m << "scan materials: the scan is NaN at (" << points[i][0] << ", " << points[i][1] << ", "
          << points[i][2] << ") in tetrahedron " << t;
        throw std::invalid_argument(m.str());
      }
      e += scanModulus(h[i], options);
      rho += options.density(h[i]);
    }
    modulus[t] = e / static_cast<double>(per);
    density[t] = std::max(kMinimumDensity, rho / static_cast<double>(per));
    poisson[t] = options.poissonRatio;
    summary.minModulus = std::min(summary.minModulus, modulus[t]);
    summary.maxModulus = std::max(summary.maxModulus, modulus[t]);
  }
  setArray(mesh, "label", std::move(label));
  setArray(mesh, "density", std::move(density));
  setArray(mesh, "youngs_modulus", std::move(modulus));
  setArray(mesh, "poisson_ratio", std::move(poisson));
  return summary;
}

} // namespace ictk::mesh
