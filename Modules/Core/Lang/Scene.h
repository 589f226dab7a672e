// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The scene language of seed 003 (Vyatkin's VxSceneBuilder, papers.md 2.3; docs/scene.md), as the
// .scn front end: objects of the twelve base quadric types (FRep/Quadrics.h), the library's
// `torus` and `cube`, `union` and `intersection` (`inter`) blocks, files referenced with `object`,
// united by default; in an object's block, in any order: `inverse`, the transformations `move`,
// `rotate`, `scale`, `skewx`, `skewy`, `skewz`, `matrix`, `color` with three values and (ours,
// papers.md E9) `perturb K <quadric>`, seed 003's perturbation functions with their factor:
//
//   // a ball with a bump, and a red cone cut by a slab
//   ell { scale 1 1 0.8  perturb 10 { ell { scale 0.5  move 1 0 0 } } }
//   inter { cone layer { scale 1 1 0.5 }  color 1 0 0  move 3 0 0 }
//
// The paper gives keywords and three samples, no grammar and no semantics of the numbers: what
// the numbers mean (degrees, the order the transformations compose in, the union being max) is
// ours and documented in docs/scene.md. A scene is read into a syntax tree (Scene), which is built
// into a hypervolume (buildScene) and written back as one self-contained file (writeScene:
// `object` references are inlined, seed 003 line 157).

#include "FRep/Hypervolume.h"
#include "FRep/Quadrics.h"
#include "Lang/Diagnostics.h"

#include <array>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace ictk::lang
{

/// One transformation of an object's block, in the order written.
struct SceneTransform
{
  enum class Kind
  {
    Move,   ///< dx dy dz
    Rotate, ///< ax ay az: degrees about x, then y, then z
    Scale,  ///< s, or sx sy sz (non-zero)
    SkewX,  ///< a b: x += a y + b z
    SkewY,  ///< a b: y += a x + b z
    SkewZ,  ///< a b: z += a x + b y
    Matrix  ///< 12 numbers, rows [A | b] of p' = A p + b (A invertible)
  };
  Kind kind = Kind::Move;
  std::vector<double> values;
  SourceLocation where;
};

struct ScenePerturbation;

struct SceneNode
{
  enum class Kind
  {
    Quadric,
    Torus,
    Cube,
    Union,
    Intersection,
    Object ///< a referenced file: its top-level objects are the children
  };
  Kind kind = Kind::Quadric;
  frep::QuadricType quadric = frep::QuadricType::Ell; ///< Kind::Quadric
  SourceLocation where;
  std::vector<SceneTransform> transforms;
  std::optional<std::array<double, 3>> colour;
  bool inverse = false;
  /// Torus: radius of revolution and tube radius (`radii R r`, ours; default 1 and 0.25).
  std::array<double, 2> radii{ 1.0, 0.25 };
  bool hasRadii = false;
  std::vector<SceneNode> children;
  std::vector<ScenePerturbation> perturbations; ///< Quadric, Torus, Cube
  /// Kind::Object: the name as written and the file it was read from.
  std::string reference;
  std::string referencedFile;
};

/// `perturb K <quadric>`: R = K max(0, Q)^3 added to the object's field in its own frame (before
/// the object's transformations), Q placed by its own block.
struct ScenePerturbation
{
  double factor = 1;
  SceneNode quadric;
};

struct Scene
{
  std::string file;
  std::vector<SceneNode> objects; ///< united (seed 003 line 151)
};

/// What `object NAME` reads: the path of the file and its text, for a name written in `from`
/// (a file path); nullopt when there is no such file.
using SceneLoader = std::function<std::optional<std::pair<std::string, std::string>>(
  const std::string& name, const std::string& from)>;

/// Parses scene text; `file` names it in diagnostics. `loader` reads `object` references (none:
/// every reference is an error). Throws ParseError with every error found (file:line:col).
Scene parseScene(const std::string& text, const std::string& file, const SceneLoader& loader,
  const Limits& limits = {});
/// Reads a scene file; `object NAME` is NAME, NAME.scn or NAME.scene beside the file that names
/// it. A reference cycle is an error.
Scene readSceneFile(const std::string& path, const Limits& limits = {});

/// One primitive object (quadric, torus or cube) of a built scene, numbered from 1 in the order
/// of the file (a referenced file's objects where it is referenced).
struct SceneObject
{
  int id = 0;
  std::string keyword;
  SourceLocation where;
};

struct BuiltScene
{
  /// The solid (the union of the top-level objects, max; intersection is min; inverse is -f),
  /// with the attribute "object" (the id of the primitive whose field decides f at the point)
  /// and, when some object has a `color`, the attribute "colour" (that primitive's colour, an
  /// object without one taking its nearest enclosing block's, else 0.8 grey).
  /// When some object is perturbed, also the attribute "perturbation": the id of the
  /// perturbation (numbered from 1 in the file's order, like the objects) whose support (Q >= 0)
  /// holds the point, on the primitive that decides f (the last written where supports overlap),
  /// 0 where none does: picking it is seed 003's Ctrl-click, which selects perturbations only.
  frep::Hypervolume model;
  std::vector<SceneObject> objects;
  std::vector<SceneObject> perturbations;
};
/// Throws ParseError (at the node) for what reads but does not build: a singular matrix, an
/// empty union or intersection, a scale of 0.
BuiltScene buildScene(const Scene& scene);

/// The scene as one self-contained file: `object` references become `union` blocks holding the
/// referenced objects (seed 003 line 157); numbers are written so that they read back exactly.
std::string writeScene(const Scene& scene);

} // namespace ictk::lang
