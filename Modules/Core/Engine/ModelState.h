// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The state of a running model (DynamicModel's private part), shared by the engine's own sources
// and by nothing else: no public header includes it. What the model was built into (cells,
// instances, relations, attributes, events, animation curves as specs), the parameter table and
// the stepper, the structural state that rides in the stepper's snapshots, and the scope through
// which the interpreter's code sees it all. Its members are defined by concern: building from the
// syntax tree in ModelBuild.cxx (cells' shapes in ModelShapes.cxx), values, placements and the
// scope in ModelValues.cxx, running (reactions, instances, frames) in ModelRun.cxx, the library
// calls of code in ModelLibrary.cxx.

#include "Dynamics/Animation.h"
#include "Dynamics/Stepper.h"
#include "Engine/DynamicModel.h"
#include "FRep/Tape.h"
#include "Skin/Projection.h"
#include "Skin/SkinnedMesh.h"
#include "Skin/StandIn.h"

#include <limits>
#include <map>
#include <optional>
#include <set>

namespace ictk::engine
{

using geometry::Affine;
using geometry::PlacedShape;
using geometry::PlacedShapePtr;
using geometry::QueryOptions;
using geometry::ShapePart;
using geometry::Vec3;
using lang::icm::CellDef;
using lang::icm::Expr;
using lang::icm::ExprPtr;
using lang::icm::Instance;
using lang::icm::ParamDecl;
using lang::icm::Pos;
using lang::icm::Procedure;
using lang::icm::Property;
using lang::icm::Relation;

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
inline constexpr std::size_t kNone = static_cast<std::size_t>(-1);
// The instance entity comes first in its plan: its update is the one that drives the cells.
inline constexpr double kInstancePriority = 1e300;

/// A parameter of a cell, an instance or the model.
struct ParamSpec
{
  Pos pos;
  std::string name;
  Value initial;
};

/// `alias name` in STATE_PARAMETERS: a name for a path (a parameter of a cell or the instance).
struct AliasSpec
{
  std::string name;
  ExprPtr path;
};

/// The numbers of a blend-like shape at one step (CellSpec::Operands).
struct OperandNumbers
{
  /// blend / blendCells: the blending union's a0 (`amount`, the added material) and the
  /// operands' scales a1, a2 (thesis 2.2.3, L643-L647); 1 when not given.
  double amount = 0.0;
  double a1 = 1.0, a2 = 1.0;
  frep::SpaceTimeBlendParameters spaceTime;
  /// spaceTimeBlendCells' ninth number: how far the automatic space-time alignment moves each
  /// operand toward the other's bounding domain (thesis 5.3.2 L3108; 0 = plain blending).
  double align = 0.0;
  /// spaceTimeBlendCells' warp (thesis 5.3.3, Geometry/SpaceTimeWarp.h): the control pairs
  /// given as vec3 source, destination arguments after align, or, when warpCount > 0, that many
  /// automatic control points of each operand at least warpSeparation apart, paired.
  std::vector<geometry::ControlPair> pairs;
  int warpCount = 0;
  double warpSeparation = 0.0;
};

/// setProjection(cell, alpha [, "weights" [, spread]]): how far a skinned mesh's vertices have
/// moved to its stand-in (Skin/Projection.h), and the weight map that delays them per vertex.
struct ProjectionSetting
{
  double alpha = 0;
  std::string weights; ///< a model function of the bind-pose position ("": none)
  double spread = 0.5;
  bool operator==(const ProjectionSetting& o) const
  {
    return alpha == o.alpha && weights == o.weights && spread == o.spread;
  }
};

struct CellSpec
{
  std::string name;
  Pos pos;
  complex::CellKind kind = complex::CellKind::FRep;
  int dimension = 3;
  frep::Box3 domain;
  bool hasDomain = false;
  bool hasLifespan = false;
  dyn::TimeSpan life = dyn::TimeSpan::infinite();
  bool hasClock = false;
  dyn::TimeSpan clock = dyn::TimeSpan::infinite();
  double priority = 0.0;
  std::vector<ShapePart> parts; ///< from `shape =` (empty: a T-cell set by reactions)
  /// A `shape =` of constructors whose arguments read the cell's or the model's parameters
  /// (`segment(vec3(0, 0, 0), vec3(0, -curLength, 0))`): built once the parameters exist and
  /// again at every updatePost.
  const Property* shapeExpression = nullptr;
  /// A HyperFun/XML field, kept as a tape so setShapeParameter can rebind its parameters.
  frep::TapePtr tape;
  int parameterCount = 0;
  std::size_t fieldPart = kNone;
  /// The field's domain has time (XYZT, or XYT for a 2D exemplar): the cell is a space-time
  /// object (thesis 5.3, `dim = 4D` or `3D`) whose shape at global time t is its cross-section
  /// there (makeCrossSection(shape, globalT)): the field with T bound to t.
  bool spaceTime = false;
  /// blend(A, B, amount) / union(A, B) / spaceTimeBlendCells(A, B, t0, t1, ...): operands are
  /// cells, placed when the shape is needed.
  struct Operands
  {
    ShapePart::Kind kind = ShapePart::Kind::Union;
    std::string a, b;
    /// The constructor's numbers (blend: amount [, a1, a2]; space-time blend: t0, t1, a0, a1,
    /// a2, a3 ...), expressions over the cell's and the model's parameters evaluated at every
    /// step.
    std::vector<const Expr*> numbers;
    /// Their values at the model's start (ModelState::evaluateOperands).
    OperandNumbers atStart;
    /// The automatic control pairs found for the operands as they were (a hash of their
    /// versions and placements): the distance transforms are redone only when they change.
    mutable std::uint64_t pairedFor = 0;
    mutable std::vector<geometry::ControlPair> autoPairs;
    Pos pos; ///< the constructor's call
  };
  std::optional<Operands> operands;
  /// loadMesh("file", "animation"): a skinned mesh whose part `meshPart` is posed by the
  /// animation at the cell's time (animationTime), or by the matrices of setDeformation, cached
  /// for the last pose. loadSegmentsHierarchy("file", "animation"): its skeleton, one segment
  /// part per bone of `bones`, posed the same way.
  std::shared_ptr<const skin::SkinnedMesh> skinned;
  const skin::Animation* skinAnimation = nullptr;
  std::size_t meshPart = kNone;
  std::vector<skin::Bone> bones;
  mutable double posedAt = kNaN;
  mutable const void* posedBy = nullptr;     ///< the deformation posed by (nullptr: the animation)
  mutable ProjectionSetting posedProjection; ///< the projection posed with
  /// The weight maps setProjection named (model functions), at the rest points, by name: a
  /// function of the bind pose, evaluated once.
  mutable std::map<std::string, std::vector<double>> weightMaps;
  mutable std::shared_ptr<const std::vector<ShapePart>> posed;
  /// standIn(cell): the fitted stand-in of the skinned cell `standInOf` (in its bind pose), its
  /// field part cached for that cell's version.
  std::string standInOf;
  Pos standInPos;
  std::shared_ptr<const skin::StandIn> standIn;
  /// Its field's tape, compiled once: each pose binds the segments' ends (StandInField).
  std::shared_ptr<const skin::StandInField> standInField;
  /// The mesh cell's vertices projected onto the stand-in (bind pose; setProjection).
  std::shared_ptr<const skin::Projection> projection;
  mutable std::uint64_t standInVersion = 0;
  mutable std::shared_ptr<const std::vector<ShapePart>> standInParts;
  std::vector<ParamSpec> params;
  std::map<std::string, const Procedure*> reactions; ///< "update", "react:EVENT", ...
};

struct RelationSpec
{
  Pos pos;
  std::string name;
  std::string master, masterMember; ///< cell (or instance/model parameter) and member path
  std::string dependent, dependentMember;
  double priority = 1.0;
  bool hierarchical = false;
};

/// An attribute (thesis L864): a HyperFun function of the cell's local coordinates, or an
/// external mapping known only by name (no function: it is not evaluated).
struct AttributeSpec
{
  std::string name;
  frep::TapePtr tape;
  int dimension = 3;
  std::string text;
};

struct InstanceSpec
{
  std::string name;
  Pos pos;
  bool isTemplate = false;
  std::vector<std::string> cells;
  std::vector<RelationSpec> boundary, containment, dependency;
  std::vector<ParamSpec> params;       ///< instance parameters and typed state parameters
  std::vector<std::string> stateNames; ///< typed state parameters and aliases, in order
  std::vector<AliasSpec> aliases;
  std::map<std::string, const Procedure*> reactions;
  std::map<std::string, std::map<std::string, const Procedure*>> cellReactions;
  const Procedure* predicate = nullptr;
  std::set<std::string> reactsTo;
  std::vector<std::pair<std::string, std::string>> attributeLinks; ///< (cell, attribute)
};

/// The structural state: what the parameter table cannot hold. Copied with every snapshot.
struct Structure
{
  std::size_t active = kNone;
  std::size_t previous = kNone;
  bool justActivated = false;
  double activatedAt = 0.0;
  std::map<std::string, double> presentSince;
  std::map<std::string, std::shared_ptr<const std::vector<ShapePart>>> shapes; ///< set by code
  std::map<std::string, std::vector<double>> shapeParameters;
  std::map<std::string, std::uint64_t> versions;
  std::map<std::string, OperandNumbers> operandNumbers; ///< evaluated at each step
  std::map<std::string, Value> texts;                   ///< non-numeric parameters (strings)
  /// setDeformation(cell, transforms): the skinning matrices that pose a skinned cell.
  std::map<std::string, std::shared_ptr<const std::vector<Affine>>> deformations;
  /// setProjection(cell, alpha [, weights [, spread]]): how far a skinned mesh's vertices have
  /// moved to its stand-in.
  std::map<std::string, ProjectionSetting> projections;
  /// Cells whose hierarchical parent changed at an instance switch: the offset that keeps their
  /// placement in the world at the switch (ModelState::keepPlacementsAcross).
  std::map<std::string, Affine> keptPlacements;
};

struct ModelState
{
  lang::IcmModel model;
  RunOptions options;
  std::string file;
  Interpreter interpreter;
  std::vector<CellSpec> cells;
  std::map<std::string, std::size_t> cellIndex;
  std::vector<InstanceSpec> instances;
  std::map<std::string, std::size_t> instanceIndex;
  std::map<std::string, dyn::AnimationCurve> curves[4]; ///< per component x, y, z, and scalar
  std::set<std::string> curveNames;
  std::map<std::string, std::size_t> curveWidth;
  std::map<std::string, AttributeSpec> attributes;
  std::vector<ParamSpec> modelParams;
  std::vector<std::string> modelStateNames;
  std::set<std::string> eventNames;
  std::map<std::string, double> eventPriority;
  std::map<std::string, std::vector<std::string>> eventParams;
  std::map<std::string, dyn::TimeSpan> eventSpans;
  std::map<std::string, dyn::TimeSpan> timespans;
  dyn::ParameterTable table;
  std::map<std::string, Value::Type> types; ///< qualified parameter -> type
  /// An `array of TRANSFORM` of a skinned cell: its number of transforms (the joints), each
  /// 12 numbers of the table (`name.0` .. : the row-major linear part, then the translation).
  std::map<std::string, std::size_t> transformCounts;
  std::unique_ptr<dyn::Stepper> stepper;
  Structure s;
  std::size_t graphInstance = kNone;
  bool started = false;
  std::size_t processedSeen = 0;
  std::size_t acceptedSeen = 0; ///< stepper->acceptedTimes() already reported in a FrameRecord
  int rejectionsSeen = 0;
  std::uint64_t nextVersion = 1;
  dyn::StepContext* context = nullptr; ///< the frame being evaluated (events, TIME_REJECTED)

  ModelState(lang::IcmModel m, RunOptions o)
    : model(std::move(m))
    , options(std::move(o))
    , file(model.fileName)
    , interpreter(model.fileName, &model.functions)
  {
  }

  [[noreturn]] void fail(Pos p, const std::string& message) const
  {
    throw ModelError(file, p, message);
  }

  // ---- building --------------------------------------------------------------------------
  void build();
  void buildTimespans();
  /// Every spaceTimeBlendCells cell is one dimension above its two operands.
  void checkSpaceTimeBlends() const;
  /// Fits the stand-in of every standIn(cell) cell to its skinned cell's mesh (bind pose).
  void fitStandIns();
  /// The numbers of cell c's blend-like shape evaluated in its scope within `instance` (kNone:
  /// the model's start); fails at the place of one that is not a number or out of range.
  OperandNumbers evaluateOperands(const CellSpec& c, std::size_t instance);
  /// Reads spaceTimeBlendCells' warp arguments (those after align) into `out`; refuses them at
  /// their place when malformed.
  void warpOf(const CellSpec& c, const std::vector<Value>& args, OperandNumbers& out) const;
  /// The control pairs of a space-time blend's warp for its operands a and b as placed now:
  /// the given pairs, or the automatic ones (thick features of each operand, paired).
  std::vector<geometry::ControlPair> controlPairs(const CellSpec& c, const OperandNumbers& n,
    const PlacedShapePtr& a, const PlacedShapePtr& b, int depth) const;
  /// The numbers of cell c's blend-like shape at the current step.
  OperandNumbers operandNumbersOf(const CellSpec& c) const
  {
    const auto it = s.operandNumbers.find(c.name);
    return it != s.operandNumbers.end() ? it->second : c.operands->atStart;
  }
  void buildAnimations();
  void buildEvents();
  void buildCell(const CellDef& def);
  void buildShape(CellSpec& c, const Property& p);
  /// The parts of a `shape =` of constructors, their arguments evaluated in the cell's scope.
  void buildShapeParts(CellSpec& c, const Property& p, std::size_t instance);
  /// A shape whose constructors read parameters (shapeExpression), rebuilt at the cell's
  /// updatePost; the new parts replace the old ones when they differ.
  void rebuildShape(const CellSpec& c);
  void buildInstance(const Instance& in);
  std::vector<std::string> cellsOf(const Instance& in, int depth) const;
  std::vector<RelationSpec> relationsOf(
    const Instance& in, const std::string& kind, int depth) const;
  RelationSpec relationSpec(const Relation& r) const;
  void buildAttributes(const lang::icm::AttributesSection& section);
  std::vector<std::pair<std::string, std::string>> attributeLinksOf(
    const Instance& in, int depth) const;
  void addParam(const std::string& owner, const ParamSpec& p);
  Value initialValue(const ParamDecl& p);
  void buildStepper();
  dyn::DependencyGraph graph(std::size_t instance) const;

  // ---- values ----------------------------------------------------------------------------
  std::string qualified(const std::string& owner, const std::string& name) const
  {
    return owner.empty() ? name : owner + "." + name;
  }
  bool hasParam(const std::string& q) const { return types.count(q) > 0; }
  Value get(const std::string& q) const;
  void set(const std::string& q, const Value& v);

  // ---- shapes ----------------------------------------------------------------------------
  /// The time shapes are evaluated at: the frame being evaluated, else the model's time.
  double shapeTime() const { return context ? context->globalT : stepper ? stepper->time() : 0.0; }
  /// The dimension of a cell's shape in space: a space-time cell's cross-section has one less.
  int spaceDimension(const CellSpec& c) const
  {
    return c.spaceTime ? c.dimension - 1 : c.dimension;
  }
  bool present(const std::string& cell) const
  {
    if (s.active == kNone)
      return false;
    const auto& cs = instances[s.active].cells;
    return std::find(cs.begin(), cs.end(), cell) != cs.end();
  }
  std::shared_ptr<const std::vector<ShapePart>> partsOf(const CellSpec& c) const;
  /// The time a skinned cell's animation is at: the cell's local time when it has a `timespan`
  /// (held before and after it), else the model's.
  double animationTime(const CellSpec& c) const
  {
    return c.hasClock ? c.clock.elapsed(shapeTime()) : shapeTime();
  }
  /// A skinned cell's skinning matrices now: those of setDeformation, else its animation's at
  /// its time.
  std::vector<Affine> skinningMatrices(const CellSpec& c) const;
  /// The standIn(cell) cell of a mesh cell (the first one), or nullptr.
  const CellSpec* standInOf(const std::string& mesh) const
  {
    for (const CellSpec& c : cells)
      if (c.standIn && c.standInOf == mesh)
        return &c;
    return nullptr;
  }
  Affine localPlace(const std::string& cell) const;
  Affine place(const std::string& cell, int depth = 0) const;
  /// The hierarchical parent of `cell` in `instance` (its first HIERARCHICAL master), or "".
  std::string hierarchicalParent(const std::string& cell, std::size_t instance) const;
  /// What carries the cell's own transform into the world: its parent's placement, times the
  /// offset kept when its parent changed (Structure::keptPlacements).
  Affine carrier(const std::string& cell, int depth = 0) const;
  /// At a switch from instance `from` to `to`: every cell in both whose hierarchical parent
  /// changes keeps its placement in the world (Structure::keptPlacements).
  void keepPlacementsAcross(std::size_t from, std::size_t to);
  PlacedShapePtr shapeOf(const std::string& cell, int depth = 0) const;
  /// spaceTimeBlendCells' automatic alignment (OperandNumbers::align) of the operands at time t.
  void alignInSpaceTime(
    PlacedShapePtr& a, PlacedShapePtr& b, const OperandNumbers& n, double t) const;
  std::uint64_t versionOf(const std::string& cell, int depth = 0) const;
  void bumpVersion(const std::string& cell) { s.versions[cell] = nextVersion++; }

  // ---- running ---------------------------------------------------------------------------
  const Procedure* procedureFor(const std::string& cell, const std::string& key) const;
  void runCell(const std::string& cell, const std::string& key, dyn::StepContext& c,
    const dyn::Event* ev = nullptr);
  void runInstance(
    std::size_t i, const std::string& key, dyn::StepContext& c, const dyn::Event* ev = nullptr);
  void activate(dyn::StepContext& c);
  std::vector<std::size_t> validInstances(double t);
  void setActive(std::size_t i, double t);
  FrameRecord record(double t, bool transition);
  void step(double dt);
  void settle();
};

/// Flattens `a.b.c` (Name and Member nodes) into names; false for anything else.
bool pathOf(const Expr& e, std::vector<std::string>& out);

/// What code inside a cell's, an instance's or the model's procedures sees.
class EngineScope : public Scope
{
public:
  EngineScope(ModelState& m, std::string cell, std::size_t instance)
    : m_(m)
    , cell_(std::move(cell))
    , instance_(instance)
  {
  }

  bool lookup(const std::string& name, Value& out) override;
  bool member(const Value& base, const std::string& member, Value& out) override;
  bool assign(const std::string& name, const std::string& member, const Value& v) override;
  Value call(const lang::icm::Builtin& builtin, const std::vector<Value>& args) override;

  ModelState& model() const { return m_; }
  /// The placed shape of a cell argument (std::runtime_error for another value or a T-cell
  /// without a shape yet).
  PlacedShapePtr cellShape(const Value& v) const;

private:
  /// The qualified parameter a bare name stands for, or "".
  std::string resolve(const std::string& name) const;
  const AliasSpec* alias(const std::string& name) const;

  ModelState& m_;
  std::string cell_;
  std::size_t instance_;
};

} // namespace ictk::engine
