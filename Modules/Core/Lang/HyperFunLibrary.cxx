// SPDX-License-Identifier: BSD-3-Clause
// The HyperFun built-ins: the math functions and the hf* library (primitives, convolution
// surfaces, blends, space maps, attributes), each compiled to FRep kernel shapes with HyperFun's
// argument orders. The sources are HyperFun's library (pmur002/hyperfun, src/hflibrary_lib) and
// interpreter (src/interpreter_lib/int_calc.c, int_global.c):
//  - Library space maps change their array argument in place (hfShift3D.c, ...).
//  - The third parameter array s carries attributes; hfA_SetColor(f, s, r, g, b) writes
//    s[1..3] = (r, g, b) where f >= 0 (hfA_SetColor.c); s[1..3] at return become the "colour"
//    attribute.
// Where ICTK differs it says so: sign() is the true sign (HyperFun's FUNC_sign always returns 1,
// a bug).
#include "Lang/HyperFunCompilerDetail.h"

#include "FRep/Implants.h"
#include "FRep/Operations.h"
#include "FRep/Primitives.h"

#include <cmath>

namespace ictk::lang::hf::detail
{
namespace
{

/// Rounding towards zero, as modf's integral part (constant arguments fold).
Expr truncate(const Expr& v)
{
  return frep::select(v, frep::floor(v), -frep::floor(-v));
}

} // namespace

std::optional<Val> Compiler::mathFunction(Frame& f, const ExprNode& n)
{
  using Unary = Expr (*)(const Expr&);
  static const std::unordered_map<std::string, Unary> unary = {
    { "sqrt",
      [](const Expr& a)
      {
        return frep::sqrt(a);
      } },
    { "exp",
      [](const Expr& a)
      {
        return frep::exp(a);
      } },
    { "log",
      [](const Expr& a)
      {
        return frep::log(a);
      } },
    { "logd",
      [](const Expr& a)
      {
        return frep::log(a) / std::log(10.0);
      } },
    { "sin",
      [](const Expr& a)
      {
        return frep::sin(a);
      } },
    { "cos",
      [](const Expr& a)
      {
        return frep::cos(a);
      } },
    { "tan",
      [](const Expr& a)
      {
        return frep::tan(a);
      } },
    { "asin",
      [](const Expr& a)
      {
        return frep::asin(a);
      } },
    { "acos",
      [](const Expr& a)
      {
        return frep::acos(a);
      } },
    { "atan",
      [](const Expr& a)
      {
        return frep::atan(a);
      } },
    { "abs",
      [](const Expr& a)
      {
        return frep::abs(a);
      } },
    { "sign",
      [](const Expr& a)
      {
        return frep::sign(a);
      } },
    { "sinh",
      [](const Expr& a)
      {
        return (frep::exp(a) - frep::exp(-a)) / 2.0;
      } },
    { "cosh",
      [](const Expr& a)
      {
        return (frep::exp(a) + frep::exp(-a)) / 2.0;
      } },
    // 1 - 2 / (e^2a + 1) stays finite for large |a| (no inf / inf).
    { "tanh",
      [](const Expr& a)
      {
        return 1.0 - 2.0 / (frep::exp(2.0 * a) + 1.0);
      } },
  };
  auto u = unary.find(n.name);
  if (u != unary.end())
  {
    arity(n, 1);
    const Val a = eval(f, n.kids[0]);
    count(4, n);
    if (a.e.isConstant())
    {
      // HyperFun stops with a run-time error on these; a constant one is certainly wrong.
      const double v = a.e.constantValue();
      if (n.name == "sqrt" && v < 0)
      {
        fail(n.line, n.column, "square root of a negative number (" + fmt(v) + ")");
      }
      if ((n.name == "log" || n.name == "logd") && !(v > 0))
      {
        fail(n.line, n.column, "logarithm of a non-positive number (" + fmt(v) + ")");
      }
      if ((n.name == "asin" || n.name == "acos") && std::fabs(v) > 1)
      {
        fail(n.line, n.column, n.spelling + " argument must lie in [-1, 1] (got " + fmt(v) + ")");
      }
    }
    return plain(u->second(a.e));
  }
  if (n.name == "max" || n.name == "min" || n.name == "atan2" || n.name == "mod")
  {
    arity(n, 2);
    const Val a = eval(f, n.kids[0]);
    const Val b = eval(f, n.kids[1]);
    count(1, n);
    if (n.name == "max")
    {
      return plain(frep::max(a.e, b.e));
    }
    if (n.name == "min")
    {
      return plain(frep::min(a.e, b.e));
    }
    if (n.name == "atan2")
    {
      return plain(frep::atan2(a.e, b.e));
    }
    if (a.e.isConstant() && b.e.isConstant())
    {
      const double x = a.e.constantValue(), y = b.e.constantValue();
      if (!std::isfinite(x) || !std::isfinite(y) || std::fabs(x) > 2e9 || std::fabs(y) > 2e9 ||
        hfRound(y) == 0)
      {
        fail(n.line, n.column, "invalid arguments of mod");
      }
      // FUNC_mod: fmod of the rounded arguments.
      return plain(Expr(std::fmod(static_cast<double>(hfRound(x)), hfRound(y))));
    }
    // The same on expressions: HF_round(d) = floor(d + 0.5) and fmod(p, q) = p - q trunc(p / q),
    // exact for the integers HyperFun allows (|p|, |q| < 2^26 keep p / q away from an integer
    // by more than its rounding error). A divisor that rounds to 0 gives NaN where HyperFun
    // stops.
    const Expr p = frep::floor(a.e + 0.5), q = frep::floor(b.e + 0.5);
    return plain(p - q * truncate(p / q));
  }
  if (n.name == "ceil" || n.name == "floor" || n.name == "int" || n.name == "frac")
  {
    arity(n, 1);
    const Expr v = eval(f, n.kids[0]).e;
    count(3, n);
    if (n.name == "floor")
    {
      return plain(frep::floor(v));
    }
    if (n.name == "ceil")
    {
      return plain(-frep::floor(-v));
    }
    // modf: the integral part truncates towards zero; the fraction keeps the sign of v.
    return plain(n.name == "int" ? truncate(v) : v - truncate(v));
  }
  return std::nullopt;
}

std::vector<double> Compiler::constants(Frame& f, const ExprNode& n, std::size_t k)
{
  const std::vector<Expr>& items = arrayArgument(f, n.kids[k], n.spelling, static_cast<int>(k + 1));
  std::vector<double> out;
  out.reserve(items.size());
  for (std::size_t i = 0; i < items.size(); ++i)
  {
    if (!items[i].isConstant())
    {
      const ExprNode& an = node(n.kids[k]);
      fail(an.line, an.column,
        "argument " + std::to_string(k + 1) + " of " + n.spelling + " (item " +
          std::to_string(i + 1) + ") must be known at compile time, but it depends on " +
          dependsOn(items[i]));
    }
    out.push_back(items[i].constantValue());
  }
  return out;
}

double Compiler::number(Frame& f, const ExprNode& n, std::size_t k)
{
  const Val v = eval(f, n.kids[k]);
  return constant(v, node(n.kids[k]), "argument " + std::to_string(k + 1) + " of " + n.spelling);
}

frep::Vec3 Compiler::vec3(Frame& f, const ExprNode& n, std::size_t k)
{
  const auto v = constants(f, n, k);
  if (v.size() < 3)
  {
    const ExprNode& an = node(n.kids[k]);
    fail(an.line, an.column,
      "argument " + std::to_string(k + 1) + " of " + n.spelling + " must have 3 items");
  }
  return { v[0], v[1], v[2] };
}

std::array<Expr, frep::AxisCount> Compiler::coordinates(Frame& f, const ExprNode& n, std::size_t k)
{
  const std::vector<Expr>& xt = arrayArgument(f, n.kids[k], n.spelling, static_cast<int>(k + 1));
  if (xt.size() < 3)
  {
    const ExprNode& an = node(n.kids[k]);
    fail(an.line, an.column,
      n.spelling + " needs a coordinate array of 3 items (x, y, z), '" + an.spelling + "' has " +
        std::to_string(xt.size()));
  }
  return { xt[0], xt[1], xt[2], xt.size() > 3 ? xt[3] : Expr::t() };
}

Val Compiler::place(const Expr& e, const std::array<Expr, frep::AxisCount>& map, const ExprNode& n)
{
  count(e.nodeCount(), n);
  return plain(e.substitute(map));
}

template <typename Build>
Expr Compiler::kernel(const ExprNode& n, Build build)
{
  try
  {
    return build();
  }
  catch (const std::exception& e)
  {
    fail(n.line, n.column, n.spelling + ": " + e.what());
  }
}

std::vector<frep::Vec3> Compiler::points(
  Frame& f, const ExprNode& n, std::size_t k, std::size_t count3)
{
  const auto v = constants(f, n, k);
  if (v.size() < 3 * count3)
  {
    const ExprNode& an = node(n.kids[k]);
    fail(an.line, an.column,
      "argument " + std::to_string(k + 1) + " of " + n.spelling + " must have " +
        std::to_string(3 * count3) + " items (3 per point)");
  }
  std::vector<frep::Vec3> out(count3);
  for (std::size_t i = 0; i < count3; ++i)
  {
    out[i] = { v[3 * i], v[3 * i + 1], v[3 * i + 2] };
  }
  return out;
}

std::vector<double> Compiler::firstN(Frame& f, const ExprNode& n, std::size_t k, std::size_t count)
{
  auto v = constants(f, n, k);
  if (v.size() < count)
  {
    const ExprNode& an = node(n.kids[k]);
    fail(an.line, an.column,
      "argument " + std::to_string(k + 1) + " of " + n.spelling + " must have at least " +
        std::to_string(count) + " items");
  }
  v.resize(count);
  return v;
}

Val Compiler::spaceMap(Frame& f, const ExprNode& n, const std::function<Shape(const Shape&)>& op)
{
  const auto map = coordinates(f, n, 0);
  std::array<Expr, 3> next;
  for (int i = 0; i < 3; ++i)
  {
    const Shape probe(Expr::variable(static_cast<Axis>(i)), frep::Domain::XYZ);
    const Expr component = kernel(n, [&] { return op(probe).function(); });
    count(component.nodeCount(), n);
    next[static_cast<std::size_t>(i)] = component.substitute(map);
  }
  Var& target = lookup(f, node(n.kids[0]));
  for (std::size_t i = 0; i < 3; ++i)
  {
    target.items[i] = next[i];
  }
  return plain(Expr(1.0)); // the HyperFun space maps return 1
}

const std::unordered_map<std::string, Compiler::Handler>& Compiler::library()
{
  if (!library_.empty())
  {
    return library_;
  }
  auto& L = library_;
  using frep::Vec3;
  auto args = [this](const ExprNode& n, std::size_t k)
  {
    arity(n, k);
  };
  // Primitives called as hfName(x, centre, scalars...): `build(centre, scalars)` makes the shape.
  using Scalars = std::array<double, 5>;
  auto centred = [=](
                   std::size_t scalarCount, std::function<Shape(const Vec3&, const Scalars&)> build)
  {
    return [=](Frame& f, const ExprNode& n)
    {
      args(n, 2 + scalarCount);
      const auto m = coordinates(f, n, 0);
      const Vec3 c = vec3(f, n, 1);
      Scalars v{};
      for (std::size_t i = 0; i < scalarCount; ++i)
      {
        v[i] = number(f, n, 2 + i);
      }
      return place(kernel(n, [&] { return build(c, v).function(); }), m, n);
    };
  };
  L["hfsphere"] = centred(1, [](const Vec3& c, const Scalars& v) { return frep::sphere(c, v[0]); });
  L["hfellipsoid"] = centred(
    3, [](const Vec3& c, const Scalars& v) { return frep::ellipsoid(c, v[0], v[1], v[2]); });
  // hfBlock.c uses the global ALPHA, 0 by default: the R-function block, not the min form.
  L["hfblock"] = centred(3,
    [](const Vec3& vertex, const Scalars& v)
    { return frep::blockRFunction(vertex, v[0], v[1], v[2], 0.0); });
  L["hfsuperell"] = centred(5,
    [](const Vec3& c, const Scalars& v)
    { return frep::superellipsoid(c, v[0], v[1], v[2], v[3], v[4]); });
  const std::pair<const char*, Axis> axes[] = { { "x", Axis::X }, { "y", Axis::Y },
    { "z", Axis::Z } };
  for (const auto& [suffix, axis] : axes)
  {
    const Axis ax = axis;
    L[std::string("hfcylinder") + suffix] =
      centred(1, [=](const Vec3& c, const Scalars& v) { return frep::cylinder(ax, c, v[0]); });
    L[std::string("hfellcyl") + suffix] = centred(2,
      [=](const Vec3& c, const Scalars& v) { return frep::ellipticCylinder(ax, c, v[0], v[1]); });
    L[std::string("hfcone") + suffix] =
      centred(1, [=](const Vec3& c, const Scalars& v) { return frep::cone(ax, c, v[0]); });
    L[std::string("hfellcone") + suffix] = centred(
      2, [=](const Vec3& c, const Scalars& v) { return frep::ellipticCone(ax, c, v[0], v[1]); });
    L[std::string("hftorus") + suffix] =
      centred(2, [=](const Vec3& c, const Scalars& v) { return frep::torus(ax, c, v[0], v[1]); });
    L[std::string("hfrotate3d") + suffix] = [=](Frame& f, const ExprNode& n)
    {
      args(n, 2);
      const double theta = number(f, n, 1);
      return spaceMap(f, n, [&](const Shape& s) { return frep::rotate(s, ax, theta); });
    };
    L[std::string("hftwist") + suffix] = [=](Frame& f, const ExprNode& n)
    {
      args(n, 5);
      const double z1 = number(f, n, 1), z2 = number(f, n, 2), t1 = number(f, n, 3),
                   t2 = number(f, n, 4);
      return spaceMap(f, n, [&](const Shape& s) { return frep::twist(s, ax, z1, z2, t1, t2); });
    };
    L[std::string("hftaper") + suffix] = [=](Frame& f, const ExprNode& n)
    {
      args(n, 5);
      const double z1 = number(f, n, 1), z2 = number(f, n, 2), s1 = number(f, n, 3),
                   s2 = number(f, n, 4);
      return spaceMap(f, n, [&](const Shape& s) { return frep::taper(s, ax, z1, z2, s1, s2); });
    };
  }
  // hfBlobby(x, x0, y0, z0, a, b, T), hfMetaBall(x, x0, y0, z0, b, d, T), hfSoft(x, x0, y0, z0,
  // d, T): centres given as three coordinate arrays.
  auto centres = [this](Frame& f, const ExprNode& n, std::size_t& count)
  {
    const auto xs = constants(f, n, 1);
    const auto ys = constants(f, n, 2);
    const auto zs = constants(f, n, 3);
    count = std::min(xs.size(), std::min(ys.size(), zs.size()));
    std::vector<Vec3> c(count);
    for (std::size_t i = 0; i < count; ++i)
    {
      c[i] = { xs[i], ys[i], zs[i] };
    }
    return c;
  };
  L["hfblobby"] = [=](Frame& f, const ExprNode& n)
  {
    args(n, 7);
    const auto m = coordinates(f, n, 0);
    std::size_t k = 0;
    const auto c = centres(f, n, k);
    const auto a = firstN(f, n, 4, k), b = firstN(f, n, 5, k);
    const double T = number(f, n, 6);
    return place(kernel(n, [&] { return frep::blobby(c, a, b, T).function(); }), m, n);
  };
  L["hfmetaball"] = [=](Frame& f, const ExprNode& n)
  {
    args(n, 7);
    const auto m = coordinates(f, n, 0);
    std::size_t k = 0;
    const auto c = centres(f, n, k);
    const auto b = firstN(f, n, 4, k), d = firstN(f, n, 5, k);
    const double T = number(f, n, 6);
    return place(kernel(n, [&] { return frep::metaball(c, b, d, T).function(); }), m, n);
  };
  L["hfsoft"] = [=](Frame& f, const ExprNode& n)
  {
    args(n, 6);
    const auto m = coordinates(f, n, 0);
    std::size_t k = 0;
    const auto c = centres(f, n, k);
    const auto d = firstN(f, n, 4, k);
    const double T = number(f, n, 5);
    return place(kernel(n, [&] { return frep::softObject(c, d, T).function(); }), m, n);
  };
  L["hfconvpoint"] = [=](Frame& f, const ExprNode& n)
  {
    args(n, 4);
    const auto m = coordinates(f, n, 0);
    const auto s = constants(f, n, 2);
    const auto pts = points(f, n, 1, s.size());
    const double T = number(f, n, 3);
    return place(kernel(n, [&] { return frep::convolutionPoints(pts, s, T).function(); }), m, n);
  };
  L["hfconvline"] = [=](Frame& f, const ExprNode& n)
  {
    args(n, 5);
    const auto m = coordinates(f, n, 0);
    const auto s = constants(f, n, 3);
    const auto b = points(f, n, 1, s.size());
    const auto e = points(f, n, 2, s.size());
    const double T = number(f, n, 4);
    std::vector<std::array<Vec3, 2>> segs(s.size());
    for (std::size_t i = 0; i < s.size(); ++i)
    {
      segs[i] = { b[i], e[i] };
    }
    return place(kernel(n, [&] { return frep::convolutionSegments(segs, s, T).function(); }), m, n);
  };
  L["hfconvliner"] = [=](Frame& f, const ExprNode& n)
  {
    // hfConvLineR(x, begin, end, R): the end array sets the number of segments.
    args(n, 4);
    const auto m = coordinates(f, n, 0);
    const std::size_t k = constants(f, n, 2).size() / 3;
    const auto b = points(f, n, 1, k);
    const auto e = points(f, n, 2, k);
    const double R = number(f, n, 3);
    std::vector<std::array<Vec3, 2>> segs(k);
    for (std::size_t i = 0; i < k; ++i)
    {
      segs[i] = { b[i], e[i] };
    }
    return place(
      kernel(n, [&] { return frep::convolutionSegmentsRadius(segs, R).function(); }), m, n);
  };
  L["hfconvarc"] = [=](Frame& f, const ExprNode& n)
  {
    // hfConvArc(x, center, radius, theta, axis, angle, S, T); its field is integrated over the
    // angle, i.e. ICTK's arc-length field divided by the radius (Primitives.h).
    args(n, 8);
    const auto m = coordinates(f, n, 0);
    const auto s = constants(f, n, 6);
    const std::size_t k = s.size();
    const auto c = points(f, n, 1, k);
    const auto r = firstN(f, n, 2, k), th = firstN(f, n, 3, k);
    const auto ax = points(f, n, 4, k);
    const auto an = firstN(f, n, 5, k);
    const double T = number(f, n, 7);
    const Expr sum = kernel(n,
      [&]
      {
        Expr acc;
        for (std::size_t i = 0; i < k; ++i)
        {
          const Expr term = frep::cauchyArcField(c[i], r[i], th[i], ax[i], an[i], s[i]) / r[i];
          acc = i == 0 ? term : acc + term;
        }
        return acc - T;
      });
    return place(sum, m, n);
  };
  L["hfconvtriangle"] = [=](Frame& f, const ExprNode& n)
  {
    // hfConvTriangle returns s^3 times the area integral (Primitives.h).
    args(n, 4);
    const auto m = coordinates(f, n, 0);
    const auto s = constants(f, n, 2);
    const auto v = points(f, n, 1, 3 * s.size());
    const double T = number(f, n, 3);
    const Expr sum = kernel(n,
      [&]
      {
        Expr acc;
        for (std::size_t i = 0; i < s.size(); ++i)
        {
          const Expr term = (s[i] * s[i] * s[i]) *
            frep::cauchyTriangleField({ v[3 * i], v[3 * i + 1], v[3 * i + 2] }, s[i]);
          acc = i == 0 ? term : acc + term;
        }
        return acc - T;
      });
    return place(sum, m, n);
  };
  L["hfconvcurve"] = [=](Frame& f, const ExprNode& n)
  {
    args(n, 4);
    const auto m = coordinates(f, n, 0);
    const auto all = constants(f, n, 1);
    const auto pts = points(f, n, 1, all.size() / 3);
    const double s = firstN(f, n, 2, 1)[0];
    const double T = number(f, n, 3);
    return place(kernel(n, [&] { return frep::convolutionCurve(pts, s, T).function(); }), m, n);
  };
  L["hfconvmesh"] = [=](Frame& f, const ExprNode& n)
  {
    args(n, 5);
    const auto m = coordinates(f, n, 0);
    const auto all = constants(f, n, 1);
    const auto verts = points(f, n, 1, all.size() / 3);
    const auto idx = constants(f, n, 2);
    std::vector<std::array<int, 3>> tris(idx.size() / 3);
    for (std::size_t i = 0; i < tris.size(); ++i)
    {
      for (std::size_t j = 0; j < 3; ++j)
      {
        const double d = idx[3 * i + j];
        // hfConvMesh's indices are 1-based.
        tris[i][j] = std::isfinite(d) && std::fabs(d) < 1e9 ? hfRound(d) - 1 : -1;
      }
    }
    const double s = firstN(f, n, 3, 1)[0];
    const double T = number(f, n, 4);
    return place(
      kernel(n, [&] { return frep::convolutionMesh(verts, tris, s, T).function(); }), m, n);
  };
  L["hfnoiseg"] = [=](Frame& f, const ExprNode& n)
  {
    args(n, 4);
    const auto m = coordinates(f, n, 0);
    const double a = number(f, n, 1), w = number(f, n, 2), ph = number(f, n, 3);
    return place(kernel(n, [&] { return frep::gardnerNoise(a, w, ph); }), m, n);
  };
  auto blend = [=](bool unionBlend)
  {
    return [=](Frame& f, const ExprNode& n)
    {
      // hfBlendUni/Int(f1, f2, a0, a1, a2): Operations.h blendUnion / blendIntersection.
      args(n, 5);
      const Expr f1 = eval(f, n.kids[0]).e;
      const Expr f2 = eval(f, n.kids[1]).e;
      const Expr a0 = eval(f, n.kids[2]).e;
      const Expr a1 = eval(f, n.kids[3]).e;
      const Expr a2 = eval(f, n.kids[4]).e;
      for (const Expr* a : { &a1, &a2 })
      {
        if (a->isConstant() && a->constantValue() == 0)
        {
          fail(n.line, n.column, n.spelling + ": a1 and a2 must be non-zero");
        }
      }
      count(16, n);
      const Expr base = unionBlend ? rUnion(f1, f2) : rIntersection(f1, f2);
      return plain(base + a0 / (1.0 + frep::square(f1 / a1) + frep::square(f2 / a2)));
    };
  };
  L["hfblenduni"] = blend(true);
  L["hfblendint"] = blend(false);
  // hfSpaceTimeBlend(f1, f2, t, t0, t1, a0, a1, a2, a3) (ICTK's, thesis 5.3.1): t is the time
  // coordinate, normally x[4]; Operations.h spaceTimeBlendExpr.
  L["hfspacetimeblend"] = [=](Frame& f, const ExprNode& n)
  {
    if (n.kids.size() > 9)
    {
      // spaceTimeBlendCells' align and warp (thesis 5.3.2-5.3.3) evaluate an operand at moved
      // points; this call has the operands' values at x only, so it cannot take them.
      const ExprNode& extra = node(n.kids[9]);
      fail(extra.line, extra.column,
        n.spelling +
          " takes 9 arguments: it blends the operands' values at x, so it has no align or warp "
          "(they move the points an operand is evaluated at); those are options of "
          "spaceTimeBlendCells in .icm models (docs/icm.md), or move the operands' coordinates "
          "in HyperFun before evaluating them");
    }
    args(n, 9);
    const Expr f1 = eval(f, n.kids[0]).e;
    const Expr f2 = eval(f, n.kids[1]).e;
    const Expr t = eval(f, n.kids[2]).e;
    frep::SpaceTimeBlendParameters p;
    double* slots[] = { &p.t0, &p.t1, &p.a0, &p.a1, &p.a2, &p.a3 };
    for (std::size_t i = 0; i < 6; ++i)
      *slots[i] = number(f, n, 3 + i);
    count(40, n);
    return plain(kernel(n, [&] { return frep::spaceTimeBlendExpr(f1, f2, t, p); }));
  };
  // ICTK's implants (FRep/Implants.h, docs/medical.md), placed by an origin and an axis (3
  // items each) in x's frame: hfPin(x, origin, axis, radius, length), hfScrew(x, origin, axis,
  // core, major, pitch, length), hfPlate(x, origin, axis, reference, length, width, thickness,
  // holeRadius, holes) with holes 2 items (x, y in the plate) per hole, and hfGyroid(x, cell,
  // wall), whose wall may be any expression (a graded scaffold).
  auto placement = [=](Frame& f, const ExprNode& n, bool withReference)
  {
    frep::Placement p;
    p.origin = vec3(f, n, 1);
    p.axis = vec3(f, n, 2);
    if (withReference)
    {
      p.reference = vec3(f, n, 3);
    }
    return p;
  };
  L["hfpin"] = [=](Frame& f, const ExprNode& n)
  {
    args(n, 5);
    const auto m = coordinates(f, n, 0);
    const frep::Placement p = placement(f, n, false);
    const double r = number(f, n, 3), length = number(f, n, 4);
    return place(kernel(n, [&] { return frep::pin(r, length, p).function(); }), m, n);
  };
  L["hfscrew"] = [=](Frame& f, const ExprNode& n)
  {
    args(n, 7);
    const auto m = coordinates(f, n, 0);
    const frep::Placement p = placement(f, n, false);
    const frep::ScrewThread t{ number(f, n, 3), number(f, n, 4), number(f, n, 5), number(f, n, 6) };
    return place(kernel(n, [&] { return frep::screw(t, p).function(); }), m, n);
  };
  L["hfplate"] = [=](Frame& f, const ExprNode& n)
  {
    args(n, 9);
    const auto m = coordinates(f, n, 0);
    const frep::Placement p = placement(f, n, true);
    frep::PlateShape s{ number(f, n, 4), number(f, n, 5), number(f, n, 6), number(f, n, 7), {} };
    const auto holes = constants(f, n, 8);
    if (holes.size() % 2 != 0)
    {
      const ExprNode& an = node(n.kids[8]);
      fail(an.line, an.column,
        "argument 9 of " + n.spelling + " must have 2 items (x, y) per hole, it has " +
          std::to_string(holes.size()));
    }
    for (std::size_t i = 0; i + 1 < holes.size(); i += 2)
    {
      s.holes.push_back({ holes[i], holes[i + 1] });
    }
    return place(kernel(n, [&] { return frep::plate(s, p).function(); }), m, n);
  };
  L["hfgyroid"] = [=](Frame& f, const ExprNode& n)
  {
    args(n, 3);
    const auto m = coordinates(f, n, 0);
    const double cell = number(f, n, 1);
    const Expr wall = eval(f, n.kids[2]).e;
    const Val distance = place(kernel(n, [&] { return frep::gyroidDistance(cell); }), m, n);
    return plain(0.5 * wall - distance.e);
  };
  L["hfshift3d"] = [=](Frame& f, const ExprNode& n)
  {
    args(n, 4);
    const Vec3 v = { number(f, n, 1), number(f, n, 2), number(f, n, 3) };
    return spaceMap(f, n, [&](const Shape& s) { return frep::shift(s, v); });
  };
  L["hfscale3d"] = [=](Frame& f, const ExprNode& n)
  {
    args(n, 4);
    const Vec3 v = { number(f, n, 1), number(f, n, 2), number(f, n, 3) };
    return spaceMap(f, n, [&](const Shape& s) { return frep::scale(s, v); });
  };
  L["hfstretch3d"] = [=](Frame& f, const ExprNode& n)
  {
    args(n, 5);
    const Vec3 c = vec3(f, n, 1);
    const Vec3 v = { number(f, n, 2), number(f, n, 3), number(f, n, 4) };
    return spaceMap(f, n, [&](const Shape& s) { return frep::stretch(s, c, v); });
  };
  // hfSpaceMapCubic/Exp(xt, source, target, b) (int_global.c): the number of control points is
  // set by the source array (3 items each); target and b are read for as many.
  auto controlPoints = [=](bool cubic)
  {
    return [=](Frame& f, const ExprNode& n)
    {
      args(n, 4);
      const auto all = constants(f, n, 1);
      if (all.size() % 3 != 0)
      {
        const ExprNode& an = node(n.kids[1]);
        fail(an.line, an.column,
          "argument 2 of " + n.spelling + " must have 3 items per control point, it has " +
            std::to_string(all.size()));
      }
      const std::size_t k = all.size() / 3;
      const auto src = points(f, n, 1, k);
      const auto dst = points(f, n, 2, k);
      const auto b = points(f, n, 3, k);
      return spaceMap(f, n,
        [&](const Shape& s) {
          return cubic ? frep::spaceMapCubic(s, src, dst, b) : frep::spaceMapExp(s, src, dst, b);
        });
    };
  };
  L["hfspacemapcubic"] = controlPoints(true);
  L["hfspacemapexp"] = controlPoints(false);
  // Attributes: hfA_SetColor(f, s, r, g, b) and hfA_SetAttributes(f, s, s1) write into s where
  // f >= 0 (hfA_SetColor.c, hfA_SetAttributes.c).
  L["hfa_setcolor"] = [=](Frame& f, const ExprNode& n)
  {
    args(n, 5);
    const Expr field = eval(f, n.kids[0]).e;
    arrayArgument(f, n.kids[1], n.spelling, 2);
    Var& s = lookup(f, node(n.kids[1]));
    if (s.items.size() < 3)
    {
      fail(n.line, n.column, n.spelling + ": the attribute array must have 3 items");
    }
    const Expr rgb[3] = { eval(f, n.kids[2]).e, eval(f, n.kids[3]).e, eval(f, n.kids[4]).e };
    count(3, n);
    for (std::size_t i = 0; i < 3; ++i)
    {
      s.items[i] = frep::select(field, rgb[i], s.items[i]);
    }
    return plain(Expr(1.0));
  };
  L["hfa_setattributes"] = [=](Frame& f, const ExprNode& n)
  {
    args(n, 3);
    const Expr field = eval(f, n.kids[0]).e;
    arrayArgument(f, n.kids[1], n.spelling, 2);
    const std::vector<Expr> src = arrayArgument(f, n.kids[2], n.spelling, 3);
    Var& s = lookup(f, node(n.kids[1]));
    count(src.size(), n);
    for (std::size_t i = 0; i < s.items.size() && i < src.size(); ++i)
    {
      s.items[i] = frep::select(field, src[i], s.items[i]);
    }
    return plain(Expr(1.0));
  };
  return library_;
}

} // namespace ictk::lang::hf::detail
