// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The semantic checker of the IC model language, shared by its parts (internal to Lang: no public
// header includes it). One Checker walks a model; its checks are split by what they check:
//   IcmCheck.cxx           the walk (run) and the declarations: time spans, events, animations,
//                          parameters, constants
//   IcmCheckStructure.cxx  model structure: cells, their properties and shapes, attributes
//   IcmCheckInstances.cxx  templates and instances: USE, derivation, relations
//   IcmCheckCode.cxx       imperative code: reactions, predicates, functions (scopes, types,
//                          built-in calls, whose signatures come from Lang/IcmBuiltins.h)

#include "Lang/HyperFun.h"
#include "Lang/Icm.h"
#include "Lang/IcmBuiltins.h"
#include "Lang/IcmLexer.h"

#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

namespace ictk::skin
{
struct SkinnedMesh;
}

namespace ictk::lang::icmcheck
{

using namespace icm;

enum class Ty
{
  Unknown,
  Real,
  Int,
  Bool,
  Vec3,
  String,
  Shape,
  Void,
  Cell,
  Event
};

const char* tyName(Ty t);
/// The value types of code (as written in the thesis or in lower case).
bool valueType(const std::string& s, Ty& t);
Ty resultType(const std::string& r);
bool numeric(Ty t);
/// Properties every cell has (the built-in transform, geometry and bookkeeping).
const std::set<std::string>& cellProperties();
/// Where an expression starts (its leftmost token).
Pos start(const Expr& e);
std::string lineOf(Pos p);
// A constant number: 1.5, -2, or a braced list of them.
bool constantNumber(const ExprPtr& e, double& v);

using CellMap = std::map<std::string, const CellDef*>;

struct Code
{
  const Instance* instance = nullptr;
  const CellDef* cell = nullptr;
  const CellMap* cells = nullptr;
  std::set<std::string> vars;     ///< parameters and state parameters in scope
  std::map<std::string, Ty> args; ///< formals (read-only)
  std::map<std::string, const Event*> eventArgs;
  std::vector<std::map<std::string, Ty>> locals;
  std::set<std::string> loopVars;
  bool predicate = false;
  bool function = false;
  std::size_t functionIndex = 0; ///< of the function being checked (calls go to earlier ones)
};

class Checker
{
public:
  Checker(const Model& m, hf::DiagnosticSink& sink, const Limits& limits)
    : m_(m)
    , sink_(sink)
    , limits_(limits)
  {
  }

  void run();

private:
  const Model& m_;
  hf::DiagnosticSink& sink_;
  const Limits& limits_;
  std::map<std::string, const Timespan*> timespans_;
  std::map<std::string, const CellDef*> animations_;
  std::map<std::string, const Event*> events_;
  CellMap globalCells_;
  std::map<std::string, const Instance*> instances_;
  std::map<std::string, const Procedure*> functions_;
  std::set<std::string> globalVars_;
  std::set<std::string> globalAttributes_;
  std::map<std::string, const CellDef*> allCells_; ///< global and instance cells, first wins
  // Memoised closures over USE, bases and '<-' (with guards against cycles).
  mutable std::map<const CellDef*, std::set<std::string>> paramsCache_;
  /// Skinned meshes read by path (nullptr with its message when the file cannot be read).
  std::map<std::string, std::pair<std::shared_ptr<const skin::SkinnedMesh>, std::string>> skinned_;
  mutable std::set<const CellDef*> paramsBusy_;
  mutable std::map<const Instance*, CellMap> cellsCache_;
  mutable std::set<const Instance*> cellsBusy_;
  mutable std::map<const Instance*, std::set<std::string>> attributesCache_;
  mutable std::set<const Instance*> attributesBusy_;
  using RelationKey = std::pair<const Instance*, std::string>;
  mutable std::map<RelationKey, std::set<std::string>> relationsCache_;
  mutable std::set<RelationKey> relationsBusy_;
  void err(Pos p, const std::string& message) { sink_.error(p.line, p.column, message); }

  template <class T>
  bool declare(
    std::map<std::string, const T*>& table, const Name& n, const T* what, const std::string& kind)
  {
    const auto it = table.find(n.text);
    if (it != table.end())
    {
      err(n.pos,
        "duplicate " + kind + " '" + n.text + "' (first defined at " + lineOf(it->second->pos) +
          ")");
      return false;
    }
    table.emplace(n.text, what);
    return true;
  }

  // ---- declarations -----------------------------------------------------------------------------
  void timespan(const Timespan& t);
  // keys = {t, v} or {t, x, y, z}, ...; interpolation = step | linear | catmullrom | hermite;
  // before / after = constant | linear | loop | mirror.
  void animation(const CellDef& a);
  void event(const Event& e);
  void priority(const Property& p);
  void timespanRef(const Property& p);
  void params(const std::vector<ParamDecl>& ps, std::map<std::string, const ParamDecl*>& seen,
    const CellMap* cells, const std::string& kind,
    const std::set<std::string>* aliasRoots = nullptr);
  void paramType(const ParamDecl& p);
  // A constant in a declaration: numbers, + - * /, pi and vec3(...).
  void constant(const ExprPtr& e);

  // ---- cells ------------------------------------------------------------------------------------
  // Memoised: a model may have many cells copied from one another.
  const std::set<std::string>& paramsOf(const CellDef* c, int depth = 0) const;
  std::set<std::string> paramsOfImpl(const CellDef* c, int depth) const;
  /// `Cell.member...`: the first member must be a parameter or a property of the cell.
  void cellMember(const Expr& path, const CellMap& cells);
  void cell(const CellDef& c, const CellMap& cells, const Instance* in);
  /// `owner` and `in`: the cell the property belongs to and its instance, when known (the
  /// numbers of blend-like shapes may then read the cell's parameters).
  void property(const Property& p, const CellMap& cells, const CellDef* owner = nullptr,
    const Instance* in = nullptr);
  // Compiles an inline HyperFun shape; its errors are placed in the model text.
  void hyperFun(const Property& p);
  void shape(const ExprPtr& v, const CellMap& cells, const CellDef* owner = nullptr,
    const Instance* in = nullptr);
  /// Whether the named cell's shape is a mesh file (file("*.obj" or "*.off")): an explicit surface
  /// that the geometric queries, blends and unions do not take.
  bool isMeshCell(const std::string& name, const CellMap* cells) const;
  /// The `loadMesh(...)` or `loadSegmentsHierarchy(...)` call of the named cell's shape (a
  /// skinned cell), or nullptr.
  const Expr* loadMeshOf(const std::string& name, const CellMap* cells) const;
  /// The named cell's `shape =` property (a copy's source's when it gives none), or nullptr.
  const Property* shapeOf(const std::string& name, const CellMap* cells, int depth = 0) const;
  /// loadMesh("path", "animation"): the file is read (Skin/SkinFile.h) and the animation looked
  /// up, so that what cannot work is refused here, at its place.
  void loadMesh(const Expr& call, bool surface = true);
  /// standIn(cell): the cell is a loadMesh cell.
  void standIn(const Expr& call, const CellMap& cells);
  /// The skinned mesh a loadMesh path argument names, read once; nullptr (and, when `report`, an
  /// error at the argument) when it cannot be read.
  const skin::SkinnedMesh* skinnedMesh(const Expr& path, bool report = true);
  /// jointPosition(cell, "joint"): the cell is a skinned cell and its skeleton has the joint;
  /// jointTransforms(cell, t) and setDeformation(cell, m): the cell is a skinned cell.
  void jointPosition(const Expr& call, const CellMap* cells);
  /// setProjection(cell, alpha [, "weights" [, spread]]), projectionResidual(cell),
  /// projectionAngle(cell): the cell is a loadMesh cell with a stand-in (some cell's shape is
  /// standIn(cell)); the weight map names a model function of three arguments; a constant spread
  /// is in [0, 1).
  void projectionCall(const Expr& call, const CellMap* cells);
  static std::string arity(const Signature& b);

  // ---- attributes -------------------------------------------------------------------------------
  void collectAttributes(const AttributesSection& s, std::set<std::string>& out) const;
  void attributesOf(const Instance& in, std::set<std::string>& out, int depth) const;
  void attributesOfImpl(const Instance& in, std::set<std::string>& out, int depth) const;
  void attributes(const AttributesSection& s, const CellMap& cells, const Instance* in);

  // ---- templates and instances ------------------------------------------------------------------
  const Instance* useTarget(const Use& u) const;
  // The cells of an instance: its base template's, USEd ones, listed ones and its own.
  void cellsOf(const Instance& in, CellMap& out, int depth) const;
  void cellsOfImpl(const Instance& in, CellMap& out, int depth) const;
  // Relation names of an instance's section ("dependency", "containment", "boundary").
  void relationNames(
    const Instance& in, const std::string& section, std::set<std::string>& out, int depth) const;
  void relationNamesImpl(
    const Instance& in, const std::string& section, std::set<std::string>& out, int depth) const;
  // The instances that `in` takes something from (its base and its USE targets).
  std::vector<const Instance*> sources(const Instance& in) const;
  // Whether `target` is reachable from `from` through bases and USE.
  bool reaches(const Instance* from, const Instance* target) const;
  // USE T.CELLS / T.ATTRIBUTES / T.RELATIONS.<section>.
  void use(const Use& u, const std::string& section, const Instance* in);
  void instance(const Instance& in);
  std::set<std::string> instanceVars_;
  void relation(
    const Relation& r, bool dependency, const CellMap& cells, const std::set<std::string>& attrs);
  static std::string pathText(const Expr& e);

  // ---- code -------------------------------------------------------------------------------------
  void reactionsOf(const std::vector<Procedure>& rs, const CellMap& cells, const Instance* in,
    const CellDef* owner);
  void procedure(const Procedure& p, Code& c);
  static bool returns(const std::vector<StmtPtr>& body);
  void statements(const std::vector<StmtPtr>& body, Code& c);
  bool isLocal(const Code& c, const std::string& n, Ty* t = nullptr) const;
  void statement(const Stmt& s, Code& c);
  void bound(const ExprPtr& e, Code& c);
  static bool assignable(Ty to, Ty from);
  void assign(const Stmt& s, Code& c);
  Ty name(const Expr& e, Code& c);
  Ty expr(const ExprPtr& ep, Code& c);
  Ty member(const Expr& e, Ty of);
  Ty binary(const Expr& e, Code& c);
  Ty call(const Expr& e, Code& c);
};

} // namespace ictk::lang::icmcheck
