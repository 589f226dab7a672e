// SPDX-License-Identifier: BSD-3-Clause
// The .scn scene language of seed 003 (Lang/Scene.h; papers.md 5.B items 32-35 and 38): every
// keyword, the default union, inverse as De Morgan's pair, object references and the
// self-contained file written back, transformations at hand-derived points, colours and object
// ids as attributes, perturbations through the language, diagnostics with file:line:col, and
// picking the frontmost object of a picture.
#include "Discretize/Mesh.h"
#include "FRep/Evaluators.h"
#include "FRep/Tape.h"
#include "Lang/ModelFile.h"
#include "Lang/Scene.h"
#include "Render/RayCast.h"
#include "TempDir.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <random>
#include <string>

using namespace ictk;
using lang::ParseError;

namespace
{

lang::BuiltScene build(const std::string& text)
{
  return lang::buildScene(lang::parseScene(text, "test.scn", nullptr));
}

double at(const frep::Hypervolume& model, double x, double y, double z)
{
  return frep::evaluateReference(model.geometry().function(), { x, y, z, 0 });
}

/// The attribute values (all components, in order) at a point.
std::vector<double> attributes(const frep::Hypervolume& model, double x, double y, double z)
{
  frep::HypervolumeEvaluator evaluator(model);
  std::vector<double> values(model.attributeComponentCount());
  double f = 0;
  evaluator.eval({ x, y, z, 0 }, f, values.data());
  return values;
}

/// The first diagnostic of a scene that must not read, as "line:col: message".
std::string firstError(const std::string& text)
{
  try
  {
    lang::buildScene(lang::parseScene(text, "bad.scn", nullptr));
  }
  catch (const ParseError& e)
  {
    const lang::Diagnostic& d = e.diagnostics().front();
    EXPECT_EQ(d.where.file, "bad.scn");
    return std::to_string(d.where.line) + ":" + std::to_string(d.where.column) + ": " + d.message;
  }
  ADD_FAILURE() << "no error for: " << text;
  return {};
}

void write(const std::string& path, const std::string& text)
{
  std::ofstream(path) << text;
}

std::array<double, 3> randomPoint(std::mt19937_64& rng, double h)
{
  std::uniform_real_distribution<double> u(-h, h);
  return { u(rng), u(rng), u(rng) };
}

} // namespace

TEST(Scene, EveryKeyword)
{
  // Item 32: every keyword of seed 003 (lines 141, 153-155, 169, 181) is accepted; `object` is in
  // ObjectReferenceAndSelfContainedSave.
  const std::string text = "ell seat ellpar unihyp duahyp cone cylinder layer plane clin parabola\n"
                           "hyperbola torus cube\n"
                           "union { ell inverse move 1 2 3 rotate 10 20 30 scale 2 scale 1 2 3\n"
                           "  skewx 0.1 0.2 skewy 0.3 0.4 skewz 0.5 0.6\n"
                           "  matrix 1 0 0 0  0 1 0 0  0 0 1 0  color 0.1 0.2 0.3 }\n"
                           "intersection { ell cone } inter { ell cone }\n";
  const lang::Scene scene = lang::parseScene(text, "all.scn", nullptr);
  ASSERT_EQ(scene.objects.size(), 17u);
  const lang::SceneNode& u = scene.objects[14];
  EXPECT_EQ(u.kind, lang::SceneNode::Kind::Union);
  EXPECT_TRUE(u.inverse);
  EXPECT_EQ(u.transforms.size(), 8u);
  ASSERT_TRUE(u.colour);
  EXPECT_EQ((*u.colour)[2], 0.3);
  EXPECT_EQ(scene.objects[15].kind, lang::SceneNode::Kind::Intersection);
  EXPECT_EQ(scene.objects[16].kind, lang::SceneNode::Kind::Intersection);
  EXPECT_EQ(lang::buildScene(scene).objects.size(), 19u);
  // `color` takes exactly three numbers.
  EXPECT_EQ(firstError("ell { color 1 0 }"), "1:7: 'color' takes 3 numbers, found 2");
  EXPECT_EQ(firstError("ell { color 1 0 0 1 }"),
    "1:19: 'color' takes 3 numbers (red, green, blue), found more");
  EXPECT_EQ(firstError("ell {\n  color 1 0 2\n}"), "2:3: a colour's components lie in [0, 1]");
}

TEST(Scene, DefaultUnionIsTheMax)
{
  // Item 33: two top-level objects are their union, max(F1, F2), at every sample.
  const lang::BuiltScene two = build("ell\ncube { move 1.5 0 0 }");
  const lang::BuiltScene a = build("ell");
  const lang::BuiltScene b = build("cube { move 1.5 0 0 }");
  std::mt19937_64 rng(33);
  for (int i = 0; i < 500; ++i)
  {
    const auto p = randomPoint(rng, 3);
    EXPECT_EQ(at(two.model, p[0], p[1], p[2]),
      std::max(at(a.model, p[0], p[1], p[2]), at(b.model, p[0], p[1], p[2])));
  }
  // An explicit union is the same field.
  EXPECT_EQ(at(build("union { ell cube { move 1.5 0 0 } }").model, 0.9, 0.2, 0.1),
    at(two.model, 0.9, 0.2, 0.1));
}

TEST(Scene, InverseOfAUnionIsTheIntersectionOfInverses)
{
  // Item 34: inverse(union(A, B)) and intersection(inverse A, inverse B) have one solid (with
  // max/min and -f they are one field).
  const lang::BuiltScene left = build("union { inverse ell cone { move 0.5 0 0 } }");
  const lang::BuiltScene right = build("inter { ell { inverse } cone { move 0.5 0 0 inverse } }");
  std::mt19937_64 rng(34);
  int inside = 0;
  for (int i = 0; i < 1000; ++i)
  {
    const auto p = randomPoint(rng, 2);
    const double l = at(left.model, p[0], p[1], p[2]);
    const double r = at(right.model, p[0], p[1], p[2]);
    EXPECT_EQ(l >= 0, r >= 0);
    EXPECT_EQ(l, r);
    inside += l >= 0 ? 1 : 0;
  }
  EXPECT_GT(inside, 100);
  EXPECT_LT(inside, 900);
}

TEST(Scene, Transformations)
{
  // move: the ball's centre at (1, 2, 3).
  EXPECT_EQ(at(build("ell { move 1 2 3 }").model, 1, 2, 3), 1);
  // scale 2 1 1: an ellipsoid with half-axis 2 along x; (2, 0, 0) is on it, (1, 0, 0) has
  // 1 - 1/4.
  const lang::BuiltScene e = build("ell { scale 2 1 1 }");
  EXPECT_EQ(at(e.model, 2, 0, 0), 0);
  EXPECT_EQ(at(e.model, 1, 0, 0), 0.75);
  // rotate 90 0 0 turns the z axis onto -y: the cylinder about z becomes one about y.
  const lang::BuiltScene c = build("cylinder { rotate 90 0 0 }");
  EXPECT_NEAR(at(c.model, 0, 5, 0), 1, 1e-12);
  EXPECT_NEAR(at(c.model, 0, 0, 5), -24, 1e-12);
  // Transformations compose in the order written: scale then move puts the centre at the move;
  // move then scale scales the move too.
  EXPECT_EQ(at(build("ell { scale 2 move 1 0 0 }").model, 1, 0, 0), 1);
  EXPECT_EQ(at(build("ell { move 1 0 0 scale 2 }").model, 2, 0, 0), 1);
  // skewx 1 0: x += y; the cube's local (0.5, 0.5, 0) is at (1, 0.5, 0), where the box field
  // min((1 - x^2), (1 - y^2), (1 - z^2)) is 0.75.
  EXPECT_EQ(at(build("cube { skewx 1 0 }").model, 1, 0.5, 0), 0.75);
  EXPECT_EQ(at(build("cube { skewy 0 1 }").model, 0, 0.5, 0.5), 0.75); // y += z
  EXPECT_EQ(at(build("cube { skewz 1 0 }").model, 0.5, 0, 0.5), 0.75); // z += x
  // matrix: rows [A | b]; a pure translation by (2, 0, 0).
  EXPECT_EQ(at(build("ell { matrix 1 0 0 2  0 1 0 0  0 0 1 0 }").model, 2, 0, 0), 1);
  // The torus: radius of revolution 1 and tube 0.25 by default, `radii` to change them.
  EXPECT_NEAR(at(build("torus").model, 1, 0, 0), 0.0625, 1e-12);
  EXPECT_NEAR(at(build("torus { radii 2 0.5 }").model, 2, 0, 0.5), 0, 1e-12);
}

TEST(Scene, PerturbationsThroughTheLanguage)
{
  // Item 30's fixture written as a scene: the ball perturbed by Q = 0.25 - |X - (1, 0, 0)|^2 with
  // k = 10: F'(1, 0, 0) = 10 / 64; the surface crosses +x at 1.0709777. `ell { scale 0.5 move 1 0
  // 0 }` is 1 - 4 |X - (1, 0, 0)|^2 = 4 Q (a placed type keeps the value 1 at its centre), so the
  // fixture's k = 10 is 10 / 4^3 = 0.15625 here.
  const lang::BuiltScene s = build("ell { perturb 0.15625 ell { scale 0.5 move 1 0 0 } }");
  EXPECT_NEAR(at(s.model, 1, 0, 0), 0.15625, 1e-15);
  double lo = 1.0, hi = 1.4;
  for (int i = 0; i < 200 && hi - lo > 1e-15; ++i)
  {
    const double m = 0.5 * (lo + hi);
    (at(s.model, m, 0, 0) >= 0 ? lo : hi) = m;
  }
  EXPECT_NEAR(lo, 1.0709777, 5e-8);
  // The perturbation moves with its object.
  const lang::BuiltScene moved =
    build("ell { perturb 0.15625 ell { scale 0.5 move 1 0 0 } move 0 0 5 }");
  EXPECT_NEAR(at(moved.model, 1, 0, 5), 0.15625, 1e-15);
  EXPECT_EQ(firstError("union { ell perturb 1 ell }"),
    "1:13: 'perturb' applies to a quadric, torus or cube, not to a group");
  EXPECT_EQ(firstError("ell { perturb 1 torus }"),
    "1:17: 'perturb' takes a factor and a perturbing quadric (ell, seat, ...)");
}

TEST(Scene, ColoursAndObjectIds)
{
  // Objects are numbered from 1 in the file's order; the attribute "object" is the id of the
  // primitive that decides f, "colour" its colour (an object without one inherits its block's,
  // else 0.8 grey).
  const lang::BuiltScene s = build("ell { color 1 0 0 }\n"
                                   "union { color 0 0 1 ell { move 3 0 0 } cube { move 6 0 0 } }\n"
                                   "ell { move -3 0 0 }");
  ASSERT_EQ(s.objects.size(), 4u);
  EXPECT_EQ(s.objects[1].keyword, "ell");
  EXPECT_EQ(s.objects[2].keyword, "cube");
  EXPECT_EQ(s.objects[2].where.line, 2);
  EXPECT_EQ(s.objects[2].where.column, 40);
  const struct
  {
    double x;
    double id;
    std::array<double, 3> rgb;
  } expected[] = { { 0, 1, { 1, 0, 0 } }, { 3, 2, { 0, 0, 1 } }, { 6, 3, { 0, 0, 1 } },
    { -3, 4, { 0.8, 0.8, 0.8 } } };
  for (const auto& e : expected)
  {
    const std::vector<double> v = attributes(s.model, e.x, 0.1, 0.2);
    ASSERT_EQ(v.size(), 4u); // object, then colour
    EXPECT_EQ(v[0], e.id) << "at x = " << e.x;
    EXPECT_EQ(v[1], e.rgb[0]);
    EXPECT_EQ(v[2], e.rgb[1]);
    EXPECT_EQ(v[3], e.rgb[2]);
  }
  // A scene without colours has only the ids.
  EXPECT_EQ(build("ell cone").model.attributes().size(), 1u);
}

TEST(Scene, ObjectReferenceAndSelfContainedSave)
{
  // Item 35 (seed 003 lines 157-167): `object x` in y.scn loads x.scene; saving y writes one file
  // with no reference, which reads alone (no loader) into the same field.
  test_support::TempDir dir;
  write(dir.file("x.scene"), "//x.scene\ncube\ntorus\n");
  write(dir.file("y.scn"), "//y.scn\nobject x { move 0 0 2 color 0 1 0 }\nell { scale 0.3 }\n");
  const lang::Scene y = lang::readSceneFile(dir.file("y.scn"));
  ASSERT_EQ(y.objects.size(), 2u);
  EXPECT_EQ(y.objects[0].kind, lang::SceneNode::Kind::Object);
  EXPECT_EQ(y.objects[0].children.size(), 2u);
  const lang::BuiltScene built = lang::buildScene(y);
  EXPECT_EQ(built.objects.size(), 3u);
  EXPECT_EQ(built.objects[0].where.file, y.objects[0].referencedFile);
  lang::saveSceneFile(dir.file("y.scn"), dir.file("flat.scn"));
  std::ifstream in(dir.file("flat.scn"));
  const std::string flat((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const lang::BuiltScene again = lang::buildScene(lang::parseScene(flat, "flat.scn", nullptr));
  std::mt19937_64 rng(35);
  for (int i = 0; i < 300; ++i)
  {
    const auto p = randomPoint(rng, 3);
    EXPECT_EQ(at(again.model, p[0], p[1], p[2]), at(built.model, p[0], p[1], p[2]));
    EXPECT_EQ(attributes(again.model, p[0], p[1], p[2]), attributes(built.model, p[0], p[1], p[2]));
  }
  // Every model command reads it through the model files.
  const lang::ModelFile model = lang::loadModelFile(dir.file("y.scn"));
  EXPECT_EQ(model.name, "y");
  EXPECT_EQ(at(model.model, 0, 0, 2), at(built.model, 0, 0, 2));
  EXPECT_THROW(lang::saveModelFile(model, dir.file("z.scn")), std::invalid_argument);
  // A cycle and a missing file are errors at the reference.
  write(dir.file("a.scn"), "object b\n");
  write(dir.file("b.scn"), "ell\nobject a\n");
  try
  {
    lang::readSceneFile(dir.file("a.scn"));
    ADD_FAILURE() << "no error for a cycle";
  }
  catch (const ParseError& e)
  {
    EXPECT_NE(std::string(e.what()).find("the references form a cycle"), std::string::npos)
      << e.what();
  }
  write(dir.file("c.scn"), "ell\n  object nowhere\n");
  try
  {
    lang::readSceneFile(dir.file("c.scn"));
    ADD_FAILURE() << "no error for a missing file";
  }
  catch (const ParseError& e)
  {
    EXPECT_EQ(e.diagnostics().front().where.line, 2);
    EXPECT_EQ(e.diagnostics().front().where.column, 10);
    EXPECT_NE(
      e.diagnostics().front().message.find("no file nowhere, nowhere.scn"), std::string::npos);
  }
}

TEST(Scene, Diagnostics)
{
  const std::pair<const char*, const char*> cases[] = {
    { "ell\nsphere",
      "2:1: unknown object 'sphere' (expected a quadric type, torus, cube, union, intersection, "
      "inter or object)" },
    { "ell {\n  scale 1 0 1\n}", "2:3: a scale factor must not be 0" },
    { "ell { move 1 2 }", "1:7: 'move' takes 3 numbers, found 2" },
    { "ell {", "1:5: '{' is not closed" },
    { "ell }", "1:5: '}' without a matching '{'" },
    { "ell { cone }",
      "1:7: 'cone' is not an item of a primitive's block (objects go in a union or intersection "
      "block)" },
    { "union { }", "1:1: 'union' holds no object" },
    { "// nothing\n", "2:1: the scene has no object" },
    { "ell { move 1e999 0 0 }", "1:12: '1e999' is not a finite number" },
    { "ell { radii 1 2 }", "1:7: 'radii' applies to a torus" },
    { "ell { matrix 1 0 0 0 0 0 0 0 0 0 1 0 }",
      "1:7: the transformations are singular (they flatten the object): no inverse to place it "
      "by" },
    { "object x", "1:8: 'object x': references to files are not read here" },
    { "ell /* open", "1:5: unterminated comment" },
  };
  for (const auto& [text, expected] : cases)
  {
    EXPECT_EQ(firstError(text), expected);
  }
  // Several errors in one run, each with its place and its source line.
  try
  {
    lang::parseScene("sphere\nell { move 1 }\ncube { color 2 0 0 }\n", "many.scn", nullptr);
    ADD_FAILURE();
  }
  catch (const ParseError& e)
  {
    ASSERT_EQ(e.diagnostics().size(), 3u);
    EXPECT_EQ(e.diagnostics()[1].where.line, 2);
    EXPECT_EQ(e.diagnostics()[1].sourceLine, "ell { move 1 }");
    EXPECT_NE(
      std::string(e.what()).find("many.scn:3:8: error: a colour's components"), std::string::npos)
      << e.what();
  }
}

TEST(Scene, PickTheFrontmostObject)
{
  // Item 38: two balls placed by hand on the z axis, seen from above by an orthographic camera
  // (10 model units up, 8 units high in 80 pixels: pixel centres 0.1 apart, the centre pixel
  // (40, 40) at (0.05, 0.05)). The small ball (id 2, radius 0.5 at z = 2) hides the big one
  // (id 1, radius 1 at the origin) in the middle; beside it (0.75 from the axis) only the big one
  // is seen; a corner sees nothing.
  const lang::BuiltScene s = build("ell\nell { scale 0.5 move 0 0 2 }");
  const frep::Box3 box{ { -1.5, -1.5, -1.5 }, { 1.5, 1.5, 3 } };
  const render::Camera camera = render::Camera::lookAt(
    { 0, 0, 10 }, { 0, 0, 0 }, { 0, 1, 0 }, render::Projection::Orthographic, 30, 4, 80, 80);
  const render::Pick middle = render::pick(s.model, box, camera, 40, 40);
  ASSERT_TRUE(middle.hit);
  ASSERT_EQ(middle.values.size(), 1u);
  EXPECT_EQ(middle.values[0], 2);
  // The top of the small ball under (0.05, 0.05): z = 2 + sqrt(0.25 - 0.005), depth 10 - z.
  EXPECT_NEAR(middle.depth, 8 - std::sqrt(0.245), 1e-5);
  EXPECT_NEAR(middle.point[2], 2 + std::sqrt(0.245), 1e-5);
  const render::Pick side = render::pick(s.model, box, camera, 47, 40); // x = +-0.75
  ASSERT_TRUE(side.hit);
  EXPECT_EQ(side.values[0], 1);
  EXPECT_NEAR(side.point[2], std::sqrt(1 - 0.75 * 0.75 - 0.05 * 0.05), 1e-5);
  EXPECT_FALSE(render::pick(s.model, box, camera, 0, 0).hit);
  // The pick is the picture's own pixel: the same depth as the full ray cast there.
  const render::RayCastResult picture = render::rayCast(s.model, box, camera);
  EXPECT_NEAR(picture.depth[40 * 80 + 40], middle.depth, 1e-6);
  EXPECT_NEAR(picture.depth[40 * 80 + 47], side.depth, 1e-6);
  EXPECT_THROW(render::pick(s.model, box, camera, 80, 0), std::invalid_argument);
  EXPECT_THROW(render::pick(s.model, box, camera, 1, 1, "density"), std::invalid_argument);
}

TEST(Scene, PickAPerturbation)
{
  // Item 38 with seed 003's Ctrl flag: the attribute "perturbation" is the id of the perturbation
  // whose support holds the point, 0 where none does. Two perturbations of one ball (ids 1 and 2)
  // and a second ball without any.
  const lang::BuiltScene s = build("ell { perturb 0.15625 ell { scale 0.5 move 1 0 0 }\n"
                                   "      perturb 1 ell { scale 0.3 move 0 1 0 } }\n"
                                   "ell { move 3 0 0 }");
  ASSERT_EQ(s.perturbations.size(), 2u);
  EXPECT_EQ(s.perturbations[1].where.line, 2);
  const frep::Attribute* a = s.model.findAttribute("perturbation");
  ASSERT_NE(a, nullptr);
  auto perturbationAt = [&](double x, double y, double z)
  {
    return attributes(s.model, x, y, z).back();
  };
  EXPECT_EQ(perturbationAt(1.05, 0, 0), 1);
  EXPECT_EQ(perturbationAt(0, 1.0, 0), 2);
  EXPECT_EQ(perturbationAt(-1, 0, 0), 0);
  EXPECT_EQ(perturbationAt(3, 0, 0), 0);
  // Picked from -x the ball's unperturbed side shows (0); from above, on the ray x = 1, y = 0,
  // the bump of perturbation 1.
  const frep::Box3 box{ { -1.5, -1.5, -1.5 }, { 4.5, 1.5, 1.5 } };
  const render::Camera camera = render::Camera::lookAt(
    { -10, 0, 0 }, { 0, 0, 0 }, { 0, 0, 1 }, render::Projection::Orthographic, 30, 2, 21, 21);
  const render::Pick front = render::pick(s.model, box, camera, 10, 10, "perturbation");
  ASSERT_TRUE(front.hit);
  EXPECT_EQ(front.values[0], 0);
  const render::Camera east = render::Camera::lookAt(
    { 1, 0, 10 }, { 1, 0, 0 }, { 0, 1, 0 }, render::Projection::Orthographic, 30, 2, 21, 21);
  EXPECT_EQ(render::pick(s.model, box, east, 10, 10, "perturbation").values[0], 1);
  EXPECT_EQ(render::pick(s.model, box, east, 10, 10, "object").values[0], 1);
}

TEST(Scene, ReRenderingAfterAnEditMakesNoMesh)
{
  // Item 36: changing a perturbation factor in the scene and rendering again gives a new depth
  // buffer straight from the field (the ray caster evaluates the tape; there is no mesh to
  // rebuild), seen by the discretiser's instrumentation counter: no mesh is made by the loop, and
  // the counter does count the mesh the polygon view of the same scene makes. The bump of k = 10
  // is nearer the camera on +x than that of k = 1 (item 30's fixture: k / 64 in the language, see
  // PerturbationsThroughTheLanguage).
  const frep::Box3 box{ { -1.5, -1.5, -1.5 }, { 1.5, 1.5, 1.5 } };
  const render::Camera camera = render::Camera::lookAt(
    { 10, 0, 0 }, { 0, 0, 0 }, { 0, 0, 1 }, render::Projection::Orthographic, 30, 2, 21, 21);
  lang::Scene scene =
    lang::parseScene("ell { perturb 0.015625 ell { scale 0.5 move 1 0 0 } }", "edit.scn", nullptr);
  const std::size_t centre = 10 * 21 + 10;
  const std::int64_t meshesBefore = discretize::meshesMade();
  const render::RayCastResult k1 = render::rayCast(lang::buildScene(scene).model, box, camera);
  scene.objects[0].perturbations[0].factor = 0.15625; // the edit
  const render::RayCastResult k10 = render::rayCast(lang::buildScene(scene).model, box, camera);
  EXPECT_EQ(discretize::meshesMade(), meshesBefore);
  EXPECT_NEAR(k1.depth[centre], 10 - 1.0077766, 1e-5);
  EXPECT_NEAR(k10.depth[centre], 10 - 1.0709777, 1e-5);
  EXPECT_GT(k10.pointEvaluations, 0);
  EXPECT_GT(k10.intervalEvaluations, 0);
  // The counter is live: the polygon view (`ictk render --mode mesh`) tessellates.
  const render::ScenePrimitives polygons =
    render::modelScene(lang::buildScene(scene).model, box, 0.1);
  EXPECT_GT(discretize::meshesMade(), meshesBefore);
}

TEST(Scene, ObjectsAreReleasedWithTheirLastReference)
{
  // Item 39 (AddRef/Release, std::shared_ptr semantics): a built scene's expression nodes are
  // shared by reference counting. They live while the model (or a copy) holds them, and go when
  // the count reaches 0: with the last copy, or when the holder is assigned another scene, whose
  // nodes then are all that remain. A tape compiled from the model holds no node. The edit loop of
  // item 36 therefore keeps one scene's nodes alive, however long it runs.
  const std::string ball = "ell { perturb 0.015625 ell { scale 0.5 move 1 0 0 } }\n";
  const std::string cone = "inter { cone layer { scale 1 1 0.5 } color 1 0 0 move 3 0 0 }\n";
  const std::size_t before = frep::Expr::liveNodeCount();
  std::size_t ballNodes = 0;
  {
    lang::BuiltScene s = build(ball);
    ballNodes = frep::Expr::liveNodeCount() - before;
    EXPECT_GT(ballNodes, 20u);
    const lang::BuiltScene copy = s; // a second reference to the same nodes, not new ones
    EXPECT_EQ(frep::Expr::liveNodeCount(), before + ballNodes);
    s = build(cone); // the ball's nodes stay: `copy` holds them
    const std::size_t both = frep::Expr::liveNodeCount();
    EXPECT_GT(both, before + ballNodes);
    s = build(ball); // hash-consing: the same nodes as `copy`'s
    EXPECT_EQ(frep::Expr::liveNodeCount(), before + ballNodes);
  }
  EXPECT_EQ(frep::Expr::liveNodeCount(), before);
  {
    const frep::TapePtr tape = build(cone).model.compile();
    EXPECT_EQ(frep::Expr::liveNodeCount(), before); // the scene went; its tape holds no node
    EXPECT_GT(tape->instructions().size(), 10u);
  }
  // The edit loop: every factor is a new constant and new nodes above it; the previous ones go.
  lang::Scene scene = lang::parseScene(ball, "edit.scn", nullptr);
  lang::BuiltScene built = lang::buildScene(scene);
  for (int k = 1; k <= 100; ++k)
  {
    scene.objects[0].perturbations[0].factor = k / 64.0;
    built = lang::buildScene(scene);
    EXPECT_LE(frep::Expr::liveNodeCount(), before + ballNodes + 2) << k;
  }
}

TEST(Scene, DocsTypeTable)
{
  // docs/scene.md's table of the twelve types is frep::quadricTypes(): keyword, formula and
  // description, row by row, in order.
  std::ifstream in(std::string(ICTK_SOURCE_DIR) + "/docs/scene.md");
  ASSERT_TRUE(in) << "docs/scene.md";
  std::string line;
  while (std::getline(in, line) && line.find("<!-- quadric-types") == std::string::npos)
  {
  }
  std::getline(in, line); // header
  std::getline(in, line); // rule
  for (const frep::QuadricTypeInfo& t : frep::quadricTypes())
  {
    ASSERT_TRUE(std::getline(in, line));
    std::string description = t.description;
    // Markdown escapes the bar of |z|.
    for (std::size_t p = description.find('|'); p != std::string::npos;
         p = description.find('|', p + 2))
    {
      description.insert(p, "\\");
    }
    EXPECT_EQ(
      line, "| `" + std::string(t.keyword) + "` | `" + t.formula + "` | " + description + " |");
  }
  ASSERT_TRUE(std::getline(in, line));
  EXPECT_TRUE(line.empty()) << "a row the code does not have: " << line;
}
