// SPDX-License-Identifier: BSD-3-Clause
// The models shipped with ICTK: small reference shapes for tests and demos, and the benchmark
// models, three of which (sphere, csg3, random1000) are written to be exactly the negated fields of
// VTK implicit-function trees.
#include "FRep/BundledModels.h"

#include "FRep/Operations.h"
#include "FRep/Primitives.h"

#include <cmath>
#include <random>
#include <stdexcept>

namespace ictk::frep::bundled
{

namespace
{
using Kind = CsgNode::Kind;

/// Uniform numbers that are the same on every platform: std::mt19937's sequence is fixed by the
/// standard, but std::uniform_real_distribution's mapping is not, so the mapping is ours.
class PortableRandom
{
public:
  explicit PortableRandom(std::uint32_t seed)
    : engine_(seed)
  {
  }
  /// 53 random bits in [0, 1), from two draws (the classic genrand_res53).
  double uniform01()
  {
    const std::uint64_t a = engine_() >> 5;
    const std::uint64_t b = engine_() >> 6;
    return (static_cast<double>(a) * 67108864.0 + static_cast<double>(b)) *
      (1.0 / 9007199254740992.0);
  }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform01(); }

private:
  std::mt19937 engine_;
};

/// Rounds to a multiple of 1/1024, so that the parameters print exactly (e.g. for a HyperFun or
/// Python transcription of the model).
double quantise(double v)
{
  return std::round(v * 1024.0) / 1024.0;
}

/// Reflects v into [-limit, limit] (one bounce is enough for steps shorter than the interval).
double reflect(double v, double limit)
{
  if (v > limit)
  {
    return 2 * limit - v;
  }
  if (v < -limit)
  {
    return -2 * limit - v;
  }
  return v;
}

int addNode(CsgRecipe& r, const CsgNode& n)
{
  r.nodes.push_back(n);
  return static_cast<int>(r.nodes.size()) - 1;
}

CsgNode leaf(Kind kind, const std::array<double, 6>& p)
{
  CsgNode n;
  n.kind = kind;
  n.p = p;
  return n;
}

CsgNode operation(Kind kind, int a, int b)
{
  CsgNode n;
  n.kind = kind;
  n.a = a;
  n.b = b;
  return n;
}

// Minus vtkSphere::EvaluateFunction, term by term in VTK's order, so the negation is exact.
Expr sphereField(double cx, double cy, double cz, double r)
{
  const Expr x = Expr::x(), y = Expr::y(), z = Expr::z();
  return Expr(r * r) - ((square(x - cx) + square(y - cy)) + square(z - cz));
}

// Minus vtkCylinder::EvaluateFunction for the axis (0, 1, 0). VTK subtracts the projection on the
// axis from the full squared distance; along y that leaves a y residue of at most one rounding
// error, which is the only place where ICTK and VTK differ.
Expr cylinderYField(double cx, double cz, double r)
{
  return Expr(r * r) - (square(Expr::x() - cx) + square(Expr::z() - cz));
}

Expr field(const CsgRecipe& r, int index)
{
  const CsgNode& n = r.nodes.at(static_cast<std::size_t>(index));
  switch (n.kind)
  {
    case Kind::Sphere:
      return sphereField(n.p[0], n.p[1], n.p[2], n.p[3]);
    case Kind::Box:
      return vtkBoxField({ n.p[0], n.p[1], n.p[2] }, { n.p[3], n.p[4], n.p[5] });
    case Kind::CylinderY:
      return cylinderYField(n.p[0], n.p[2], n.p[3]);
    case Kind::Union:
      return max(field(r, n.a), field(r, n.b));
    case Kind::Intersection:
      return min(field(r, n.a), field(r, n.b));
    case Kind::Difference:
      return min(field(r, n.a), -field(r, n.b));
  }
  throw std::logic_error("csgField: bad node kind");
}

// --- random1000 ---------------------------------------------------------------------------------

// 48 primitives give a DAG of about 1000 nodes (checked by TestFRepModels).
constexpr int RandomPrimitiveCount = 48;
constexpr std::uint32_t RandomSeed = 20240611u;

// A balanced tree over leaves [lo, hi). The operation is drawn before the children (pre-order),
// which fixes the sequence of draws. Near the leaves, where neighbours overlap (the centres follow
// a random walk), intersections and differences carve; higher up, unions dominate so that the
// model does not collapse to nothing.
int combine(CsgRecipe& r, PortableRandom& rng, const std::vector<int>& leaves, int lo, int hi)
{
  if (hi - lo == 1)
  {
    return leaves[static_cast<std::size_t>(lo)];
  }
  const double u = rng.uniform01();
  Kind kind;
  if (hi - lo <= 4)
  {
    kind = u < 0.5 ? Kind::Union : (u < 0.7 ? Kind::Intersection : Kind::Difference);
  }
  else
  {
    kind = u < 0.85 ? Kind::Union : Kind::Difference;
  }
  const int mid = (lo + hi) / 2;
  const int a = combine(r, rng, leaves, lo, mid);
  const int b = combine(r, rng, leaves, mid, hi);
  return addNode(r, operation(kind, a, b));
}

// --- the other models
// ------------------------------------------------------------------------------

Expr ellipsoidField(const Vec3& c, double a, double b, double cc)
{
  const Expr x = Expr::x(), y = Expr::y(), z = Expr::z();
  return Expr(1.0) - ((square((x - c[0]) / a) + square((y - c[1]) / b)) + square((z - c[2]) / cc));
}

Shape xyz(const Expr& f, const char* label)
{
  return Shape(f, Domain::XYZ, label);
}

Hypervolume blend100()
{
  // A body with two blended lobes, rounded off by a blended intersection with an ellipsoid: every
  // operation is a blend, so interval pruning can cut little (the hard case for the batch kernels).
  Shape s = xyz(sphereField(0, 0, 0, 0.55), "body");
  struct Lobe
  {
    Vec3 c;
    double a, b, cc;
  };
  const Lobe lobes[] = {
    { { 0.6, 0.0, 0.0 }, 0.45, 0.22, 0.22 },
    { { -0.45, 0.35, 0.0 }, 0.3, 0.4, 0.25 },
  };
  for (const Lobe& l : lobes)
  {
    s = blendUnion(s, xyz(ellipsoidField(l.c, l.a, l.b, l.cc), "lobe"), 0.25, 0.6, 0.6);
  }
  s = blendIntersection(
    s, xyz(ellipsoidField({ 0.05, 0.0, 0.05 }, 1.0, 0.9, 0.9), "cap"), 0.1, 0.5, 0.5);
  return Hypervolume(s.withLabel("blend100"));
}

Hypervolume walnut()
{
  // Shell: an ellipsoid minus an inner one, its outside roughened by Gardner noise. hfNoiseG is a
  // product of three series, one of which vanishes on each coordinate axis, so the axes are smooth
  // (which makes the shell's values there easy to check by hand).
  const Expr outer = ellipsoidField({ 0, 0, 0 }, 1.0, 0.8, 0.8) + gardnerNoise(0.25, 12.0, 1.4);
  const Expr inner = ellipsoidField({ 0, 0, 0 }, 0.85, 0.68, 0.68);
  const Expr shell = min(outer, -inner);
  // Kernel: two halves side by side in the cavity.
  const Expr kernel = max(ellipsoidField({ 0, 0.12, 0 }, 0.6, 0.3, 0.42),
    ellipsoidField({ 0, -0.12, 0 }, 0.6, 0.3, 0.42));
  const Expr f = max(shell, kernel);
  Hypervolume hv(Shape(f, Domain::XYZ, "walnut"));

  // Material ids on the whole object; outside it is -1. theta1 (0, "no material") cannot occur
  // since the partition is the geometry itself, but documents the convention.
  Attribute material;
  material.name = "material";
  material.components = { select(shell, 1.0, 2.0) };
  material.partition = f;
  material.insideDefault = { 0.0 };
  material.outsideDefault = { -1.0 };
  hv.addAttribute(material);

  // Density graded with the radius in the shell (denser inside); the kernel, inside the geometry
  // but outside the shell partition, gets the uniform theta1.
  Attribute density;
  density.name = "density";
  const Expr radius = sqrt((square(Expr::x()) + square(Expr::y())) + square(Expr::z()));
  density.components = { Expr(1.2) - 0.4 * radius };
  density.partition = shell;
  density.insideDefault = { 1.05 };
  density.outsideDefault = { 0.0 };
  hv.addAttribute(density);

  Attribute colour;
  colour.name = "colour";
  colour.components = { select(shell, 0.55, 0.93), select(shell, 0.36, 0.84),
    select(shell, 0.2, 0.62) };
  colour.partition = f;
  colour.insideDefault = { 0.0, 0.0, 0.0 };
  colour.outsideDefault = { 0.0, 0.0, 0.0 };
  hv.addAttribute(colour);
  return hv;
}

Hypervolume disk2d()
{
  // The thesis' 2D example (L532-L539): a disk of radius 2.
  return Hypervolume(
    Shape(Expr(4.0) - square(Expr::x()) - square(Expr::y()), Domain::XY, "disk2d"));
}

Hypervolume morph()
{
  // Linear metamorphosis of two distance fields driven by time, (1 - s) ball + s box with
  // s = clamp(t, 0, 1). Both are Euclidean distances so the intermediate shapes stay well scaled.
  const Expr x = Expr::x(), y = Expr::y(), z = Expr::z();
  const Shape ball = xyz(Expr(1.0) - sqrt((square(x) + square(y)) + square(z)), "ball");
  const Shape box = xyz(vtkBoxField({ -0.8, -0.8, -0.8 }, { 0.8, 0.8, 0.8 }), "box");
  return Hypervolume(metamorphosis(ball, box, 0.0, 1.0).withLabel("morph"));
}

ModelInfo info(const char* name, const char* description, double lo, double hi,
  std::function<Hypervolume()> build)
{
  ModelInfo m;
  m.name = name;
  m.description = description;
  m.boundsLo = { lo, lo, lo };
  m.boundsHi = { hi, hi, hi };
  m.build = std::move(build);
  return m;
}
} // namespace

Expr vtkBoxField(const std::array<double, 3>& lo, const std::array<double, 3>& hi)
{
  // vtkBox returns max_i d_i inside (all d_i <= 0) and sqrt(sum_i max(d_i, 0)^2) outside, with
  // d_i = max(lo_i - p_i, p_i - hi_i). With e_i = -d_i = min(p_i - lo_i, hi_i - p_i) the negation
  // is max(min_i e_i, 0) - sqrt(sum_i min(e_i, 0)^2): one of the two terms is always 0, so each
  // case is the same arithmetic as VTK's, negated, without a branch.
  const Expr p[3] = { Expr::x(), Expr::y(), Expr::z() };
  Expr e[3];
  for (int i = 0; i < 3; ++i)
  {
    if (!(hi[i] > lo[i]))
    {
      throw std::invalid_argument("vtkBoxField: every side of the box must be longer than 0");
    }
    e[i] = min(p[i] - lo[i], Expr(hi[i]) - p[i]);
  }
  const Expr inside = max(min(min(e[0], e[1]), e[2]), 0.0);
  const Expr outside =
    sqrt((square(min(e[0], 0.0)) + square(min(e[1], 0.0))) + square(min(e[2], 0.0)));
  return inside - outside;
}

Expr csgField(const CsgRecipe& recipe)
{
  if (recipe.root < 0 || static_cast<std::size_t>(recipe.root) >= recipe.nodes.size())
  {
    throw std::invalid_argument("csgField: the recipe has no root");
  }
  return field(recipe, recipe.root);
}

CsgRecipe sphereRecipe()
{
  CsgRecipe r;
  r.root = addNode(r, leaf(Kind::Sphere, { 0, 0, 0, 1, 0, 0 }));
  return r;
}

CsgRecipe csg3Recipe()
{
  CsgRecipe r;
  const int sphere = addNode(r, leaf(Kind::Sphere, { 0, 0, 0, 1, 0, 0 }));
  const int box = addNode(r, leaf(Kind::Box, { -0.8, -0.8, -0.8, 0.8, 0.8, 0.8 }));
  const int cylinder = addNode(r, leaf(Kind::CylinderY, { 0, 0, 0, 0.4, 0, 0 }));
  const int both = addNode(r, operation(Kind::Intersection, sphere, box));
  r.root = addNode(r, operation(Kind::Difference, both, cylinder));
  return r;
}

CsgRecipe random1000Recipe()
{
  return randomCsgRecipe(RandomPrimitiveCount, RandomSeed);
}

CsgRecipe randomCsgRecipe(int primitives, std::uint32_t seed)
{
  if (primitives < 1)
  {
    throw std::invalid_argument("randomCsgRecipe: at least one primitive is needed");
  }
  PortableRandom rng(seed);
  CsgRecipe r;
  std::array<double, 3> c{ 0, 0, 0 };
  std::vector<int> leaves;
  for (int i = 0; i < primitives; ++i)
  {
    // One draw per statement: the order of evaluation of function arguments is unspecified.
    for (double& v : c)
    {
      const double step = rng.uniform(-0.3, 0.3);
      v = reflect(v + step, 0.75);
    }
    const bool isSphere = rng.uniform01() < 0.5;
    CsgNode n;
    if (isSphere)
    {
      const double radius = rng.uniform(0.15, 0.35);
      n = leaf(
        Kind::Sphere, { quantise(c[0]), quantise(c[1]), quantise(c[2]), quantise(radius), 0, 0 });
    }
    else
    {
      n.kind = Kind::Box;
      for (int a = 0; a < 3; ++a)
      {
        const double half = rng.uniform(0.1, 0.3);
        n.p[a] = quantise(c[a] - half);
        n.p[a + 3] = quantise(c[a] + half);
      }
    }
    leaves.push_back(addNode(r, n));
  }
  r.root = combine(r, rng, leaves, 0, primitives);
  return r;
}

Expr sphereGyroidField()
{
  const Expr x = Expr::x(), y = Expr::y(), z = Expr::z();
  const double s = 0.5;
  const Expr g = sin(x / s) * cos(y / s) + sin(y / s) * cos(z / s) + sin(z / s) * cos(x / s);
  const Expr gyroid = max(g, g - 0.5);
  const Expr sphere = sqrt(x * x + y * y + z * z) - 3.0;
  const Expr sg = max(sphere, gyroid);
  return -min(sg, min(sg, 2.0 * sqrt(abs(sg)) - 0.5));
}

std::vector<ModelInfo> modelInfos()
{
  std::vector<ModelInfo> models;
  models.push_back(info("sphere", "unit sphere at the origin, f = 1 - x^2 - y^2 - z^2", -1.2, 1.2,
    [] { return Hypervolume(Shape(csgField(sphereRecipe()), Domain::XYZ, "sphere")); }));
  models.push_back(info("csg3",
    "(sphere r=1 intersect box [-0.8,0.8]^3) \\ cylinder along y r=0.4 (min/max); exactly minus "
    "the "
    "vtkImplicitBoolean of vtkSphere, vtkBox, vtkCylinder",
    -1.2, 1.2, [] { return Hypervolume(Shape(csgField(csg3Recipe()), Domain::XYZ, "csg3")); }));
  models.push_back(info("blend100",
    "a sphere with two ellipsoidal lobes, all blended (blendUnion, blendIntersection), about 100 "
    "DAG nodes",
    -1.2, 1.2, blend100));
  models.push_back(info("random1000",
    "random CSG (min/max) of 48 spheres and boxes, about 1000 DAG nodes, fixed seed; expressible "
    "in VTK",
    -1.2, 1.2,
    [] { return Hypervolume(Shape(csgField(random1000Recipe()), Domain::XYZ, "random1000")); }));
  models.push_back(info("walnut",
    "heterogeneous demo: noisy shell and two-lobed kernel; attributes material (1 shell, 2 "
    "kernel, -1 outside), density (graded in the shell), colour (RGB)",
    -1.3, 1.3, walnut));
  ModelInfo disk =
    info("disk2d", "2D disk f = 4 - x^2 - y^2 (domain XY, thesis L532-L539)", -2.4, 2.4, disk2d);
  disk.boundsLo[2] = 0;
  disk.boundsHi[2] = 0;
  models.push_back(std::move(disk));
  models.push_back(info("morph",
    "space-time (XYZT) metamorphosis from a unit ball (t <= 0) to the box [-0.8,0.8]^3 (t >= 1)",
    -1.2, 1.2, morph));
  models.push_back(info("sphere_gyroid",
    "libfive's mesh benchmark sphereGyroid: a gyroid shell clipped by a sphere of radius 3, "
    "negated to f >= 0 inside",
    -5, 5, [] { return Hypervolume(Shape(sphereGyroidField(), Domain::XYZ, "sphere_gyroid")); }));
  return models;
}

} // namespace ictk::frep::bundled
