// SPDX-License-Identifier: BSD-3-Clause
// A parsed scene (Lang/Scene.h) built into a hypervolume. Each object gives its field f, the id
// of the primitive that decides f at a point and that primitive's colour; a union is the max of
// its parts and an intersection the min (exact De Morgan pair under `inverse`, -f: seed 003
// line 181), and the id and colour follow the operand that wins, through select. An object's
// transformations compose in the order written into one affine map (frep::affine, a single
// substitution of x, y, z), which moves its field, id and colour alike.
#include "Lang/Scene.h"

#include "FRep/Operations.h"
#include "FRep/Primitives.h"

#include <cmath>
#include <stdexcept>

namespace ictk::lang
{

namespace
{

using Matrix = std::array<double, 12>; // rows [A | b] of p' = A p + b

constexpr Matrix Identity{ 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0 };
constexpr double DefaultGrey = 0.8;
constexpr double Pi = 3.14159265358979323846;

/// a after b: p -> a(b(p)).
Matrix compose(const Matrix& a, const Matrix& b)
{
  Matrix m{};
  for (int r = 0; r < 3; ++r)
  {
    for (int c = 0; c < 4; ++c)
    {
      double s = c == 3 ? a[static_cast<std::size_t>(4 * r + 3)] : 0.0;
      for (int k = 0; k < 3; ++k)
      {
        s += a[static_cast<std::size_t>(4 * r + k)] * b[static_cast<std::size_t>(4 * k + c)];
      }
      m[static_cast<std::size_t>(4 * r + c)] = s;
    }
  }
  return m;
}

Matrix rotation(int axis, double degrees)
{
  const double c = std::cos(degrees * Pi / 180);
  const double s = std::sin(degrees * Pi / 180);
  const int u = (axis + 1) % 3;
  const int v = (axis + 2) % 3;
  Matrix m = Identity;
  m[static_cast<std::size_t>(4 * u + u)] = c;
  m[static_cast<std::size_t>(4 * u + v)] = -s;
  m[static_cast<std::size_t>(4 * v + u)] = s;
  m[static_cast<std::size_t>(4 * v + v)] = c;
  return m;
}

Matrix matrixOf(const SceneTransform& t)
{
  const std::vector<double>& v = t.values;
  Matrix m = Identity;
  switch (t.kind)
  {
    case SceneTransform::Kind::Move:
      m[3] = v[0];
      m[7] = v[1];
      m[11] = v[2];
      return m;
    case SceneTransform::Kind::Rotate:
      return compose(rotation(2, v[2]), compose(rotation(1, v[1]), rotation(0, v[0])));
    case SceneTransform::Kind::Scale:
      m[0] = v[0];
      m[5] = v.size() == 3 ? v[1] : v[0];
      m[10] = v.size() == 3 ? v[2] : v[0];
      return m;
    case SceneTransform::Kind::SkewX:
      m[1] = v[0];
      m[2] = v[1];
      return m;
    case SceneTransform::Kind::SkewY:
      m[4] = v[0];
      m[6] = v[1];
      return m;
    case SceneTransform::Kind::SkewZ:
      m[8] = v[0];
      m[9] = v[1];
      return m;
    case SceneTransform::Kind::Matrix:
      for (std::size_t i = 0; i < 12; ++i)
      {
        m[i] = v[i];
      }
      return m;
  }
  return m;
}

/// An object's field, the id of the primitive that decides it, and that primitive's colour.
struct Part
{
  frep::Expr f;
  frep::Expr id;
  std::array<frep::Expr, 3> rgb;
  /// The id of the perturbation whose support holds the point (the last written where supports
  /// overlap), 0 where none does.
  frep::Expr perturbation;
};

class Builder
{
public:
  explicit Builder(bool coloured)
    : coloured_(coloured)
  {
  }

  Part node(const SceneNode& n, const std::array<double, 3>& inherited)
  {
    const std::array<double, 3> colour = n.colour ? *n.colour : inherited;
    Part part;
    switch (n.kind)
    {
      case SceneNode::Kind::Quadric:
      case SceneNode::Kind::Torus:
      case SceneNode::Kind::Cube:
        part = primitive(n, colour);
        break;
      case SceneNode::Kind::Union:
      case SceneNode::Kind::Object:
        part = combine(n.children, 0, n.children.size(), false, colour, n);
        break;
      case SceneNode::Kind::Intersection:
        part = combine(n.children, 0, n.children.size(), true, colour, n);
        break;
    }
    part = placed(part, n);
    if (n.inverse)
    {
      part.f = -part.f;
    }
    return part;
  }

  std::vector<SceneObject> objects;
  std::vector<SceneObject> perturbations;

private:
  [[noreturn]] static void fail(const SourceLocation& where, const std::string& message)
  {
    Diagnostic d;
    d.where = where;
    d.message = message;
    throw ParseError({ d });
  }

  /// The field of a primitive in its own frame, perturbed.
  Part primitive(const SceneNode& n, const std::array<double, 3>& colour)
  {
    frep::Shape shape = frep::namedQuadric(frep::QuadricType::Ell);
    std::string keyword;
    switch (n.kind)
    {
      case SceneNode::Kind::Torus:
        keyword = "torus";
        shape = frep::torus(frep::Axis::Z, { 0, 0, 0 }, n.radii[0], n.radii[1]);
        break;
      case SceneNode::Kind::Cube:
        // seed 003's library cube: the intersection of three layers, [-1, 1]^3.
        keyword = "cube";
        shape = frep::block({ -1, -1, -1 }, 2, 2, 2);
        break;
      default:
        keyword = frep::quadricTypeInfo(n.quadric).keyword;
        shape = frep::namedQuadric(n.quadric);
        break;
    }
    frep::Expr perturbation(0.0);
    if (!n.perturbations.empty())
    {
      std::vector<frep::Shape> quadrics;
      std::vector<double> factors;
      for (const ScenePerturbation& p : n.perturbations)
      {
        frep::Shape q = frep::namedQuadric(p.quadric.quadric);
        quadrics.push_back(frep::Shape(transformed(q.function(), p.quadric), frep::Domain::XYZ));
        factors.push_back(p.factor);
        const int pid = static_cast<int>(perturbations.size()) + 1;
        perturbations.push_back(
          { pid, frep::quadricTypeInfo(p.quadric.quadric).keyword, p.quadric.where });
        // Q >= 0: inside the support of R = k max(0, Q)^3.
        perturbation = frep::select(
          quadrics.back().function(), frep::Expr(static_cast<double>(pid)), perturbation);
      }
      shape = frep::perturb(shape, quadrics, factors);
    }
    const int id = static_cast<int>(objects.size()) + 1;
    objects.push_back({ id, keyword, n.where });
    Part part;
    part.f = shape.function();
    part.id = frep::Expr(static_cast<double>(id));
    part.perturbation = perturbation;
    for (std::size_t c = 0; c < 3; ++c)
    {
      part.rgb[c] = frep::Expr(coloured_ ? colour[c] : 0.0);
    }
    return part;
  }

  /// children[begin, end) united (max) or intersected (min), halved so that the tree is balanced.
  Part combine(const std::vector<SceneNode>& children, std::size_t begin, std::size_t end,
    bool minimum, const std::array<double, 3>& colour, const SceneNode& n)
  {
    if (begin == end)
    {
      fail(n.where, "an empty group");
    }
    if (end - begin == 1)
    {
      return node(children[begin], colour);
    }
    const std::size_t middle = begin + (end - begin) / 2;
    const Part a = combine(children, begin, middle, minimum, colour, n);
    const Part b = combine(children, middle, end, minimum, colour, n);
    // a wins where it is the max (union) or the min (intersection); ties go to a.
    const frep::Expr aWins = minimum ? b.f - a.f : a.f - b.f;
    Part part;
    part.f = minimum ? frep::min(a.f, b.f) : frep::max(a.f, b.f);
    part.id = frep::select(aWins, a.id, b.id);
    part.perturbation = frep::select(aWins, a.perturbation, b.perturbation);
    for (std::size_t c = 0; c < 3; ++c)
    {
      part.rgb[c] = frep::select(aWins, a.rgb[c], b.rgb[c]);
    }
    return part;
  }

  /// e moved by the node's transformations, composed in the order written.
  static frep::Expr transformed(const frep::Expr& e, const SceneNode& n)
  {
    if (n.transforms.empty() || e.axesUsed() == 0)
    {
      return e;
    }
    Matrix m = Identity;
    for (const SceneTransform& t : n.transforms)
    {
      m = compose(matrixOf(t), m);
    }
    for (double v : m)
    {
      if (!std::isfinite(v))
      {
        fail(n.transforms.back().where, "the transformations overflow");
      }
    }
    try
    {
      return frep::affine(frep::Shape(e, frep::Domain::XYZ), m).function();
    }
    catch (const std::invalid_argument&)
    {
      fail(n.transforms.back().where,
        "the transformations are singular (they flatten the object): no inverse to place it by");
    }
  }

  static Part placed(const Part& p, const SceneNode& n)
  {
    Part out;
    out.f = transformed(p.f, n);
    out.id = transformed(p.id, n);
    out.perturbation = transformed(p.perturbation, n);
    for (std::size_t c = 0; c < 3; ++c)
    {
      out.rgb[c] = transformed(p.rgb[c], n);
    }
    return out;
  }

  bool coloured_;
};

bool hasColour(const std::vector<SceneNode>& nodes)
{
  for (const SceneNode& n : nodes)
  {
    if (n.colour || hasColour(n.children))
    {
      return true;
    }
  }
  return false;
}

} // namespace

BuiltScene buildScene(const Scene& scene)
{
  if (scene.objects.empty())
  {
    Diagnostic d;
    d.where.file = scene.file;
    d.message = "the scene has no object";
    throw ParseError({ d });
  }
  const bool coloured = hasColour(scene.objects);
  Builder builder(coloured);
  SceneNode top;
  top.kind = SceneNode::Kind::Union;
  top.where = { scene.file, 1, 1 };
  top.children = scene.objects;
  const std::array<double, 3> grey{ DefaultGrey, DefaultGrey, DefaultGrey };
  const Part part = builder.node(top, grey);
  BuiltScene built{ frep::Hypervolume(frep::Shape(part.f, frep::Domain::XYZ, "scene")), {}, {} };
  frep::Attribute id;
  id.name = "object";
  id.components = { part.id };
  built.model.addAttribute(std::move(id));
  if (coloured)
  {
    frep::Attribute colour;
    colour.name = "colour";
    colour.components = { part.rgb[0], part.rgb[1], part.rgb[2] };
    built.model.addAttribute(std::move(colour));
  }
  if (!builder.perturbations.empty())
  {
    frep::Attribute perturbation;
    perturbation.name = "perturbation";
    perturbation.components = { part.perturbation };
    built.model.addAttribute(std::move(perturbation));
  }
  built.objects = std::move(builder.objects);
  built.perturbations = std::move(builder.perturbations);
  return built;
}

} // namespace ictk::lang
