// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// A running dynamic implicit complex (thesis §4.3.3-4.4): an .icm model whose cells move and
// change under their reactions, ordered by the dependency relations of the active IC instance,
// with events, TIME_REJECTED, and transitions between instances located in time.
//
// The model's numeric state (cell parameters and transforms, state and instance parameters) lives
// in a dyn::ParameterTable and is advanced by dyn::Stepper (Modules/Core/Dynamics), which gives
// the frame order, the dependency pulls, events and time rejection; the structural state (the
// active instance, shapes set by reactions, the times cells and instances became present) rides
// along in the stepper's snapshots, so stepping back restores it too. docs/icm.md ("Running a
// model") describes the semantics.

#include "Complex/Complex.h"
#include "Dynamics/Dependencies.h"
#include "Engine/Interpreter.h"
#include "FRep/Progress.h"
#include "Geometry/PlacedShape.h"
#include "Lang/Icm.h"

#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace ictk::engine
{

struct ModelState;

struct RunOptions
{
  /// Transitions between instances are located to this time (bisection on the identity of the
  /// valid instance, so an instance valid only around an instant, such as a tangency, is found).
  double timeTolerance = 1e-9;
  /// Geometric tolerance of the reaction library (geometry::QueryOptions; 0 = relative default).
  geometry::QueryOptions geometry;
  /// Dependency cycles: every relation on a cycle reads the previous frame (Dependencies.h).
  dyn::CyclePolicy cycles = dyn::CyclePolicy::PreviousState;
  /// Progress and cancellation for long runs: called after every evaluated time with the fraction
  /// done of the current advanceTo(); return false to stop (advanceTo then throws
  /// ictk::Cancelled, the model stays at the last evaluated time).
  Progress progress;
};

/// One evaluated time: a requested frame or a located transition.
struct FrameRecord
{
  double time = 0.0;
  std::string instance;            ///< the active instance after this time was evaluated
  bool transition = false;         ///< a located change of instance (not a requested time)
  std::vector<std::string> events; ///< events dispatched while reaching this time, in order
  /// The times the engine accepted while reaching this one, in order (the last is `time`): more
  /// than one where a reaction rejected the time (TIME_REJECTED) and the step was refined.
  std::vector<double> steps;
  int rejectedSteps = 0; ///< the steps rejected on the way (TIME_REJECTED)
  /// The model's state parameters and the active instance's ones, in definition order.
  std::vector<std::pair<std::string, Value>> state;
};

/// One cell of the active instance now.
struct CellState
{
  std::string name;
  complex::CellKind kind = complex::CellKind::FRep;
  int dimension = 3;
  geometry::PlacedShapePtr shape; ///< placed in the world
  /// A space-time cell (XYZT, XYT, spaceTimeBlendCells): `shape` is its cross-section at the
  /// model's time, of dimension `dimension` (3 for XYZT, 2 for XYT).
  bool spaceTime = false;
  /// Changes whenever the shape's parts change (a reaction set the shape, a shape parameter
  /// changed, an operand of a blend or union moved); a change of placement alone keeps it, so a
  /// discretisation of the local shape stays valid and only needs moving (time coherence, thesis
  /// 4.6.8).
  std::uint64_t shapeVersion = 0;
};

class DynamicModel
{
public:
  /// Reads and checks a model file (lang::readIcmFile: ParseError with file:line:col) and builds
  /// it (ModelError with file:line:col for what only the engine can see: a dependency between
  /// parameters of different types, an unknown animation, a shape file that does not read...).
  static DynamicModel load(const std::string& path, RunOptions options = {});
  DynamicModel(lang::IcmModel model, RunOptions options = {});
  ~DynamicModel();
  DynamicModel(DynamicModel&&) noexcept;
  DynamicModel& operator=(DynamicModel&&) noexcept;

  const std::string& name() const;
  /// The union of the model's time spans ([0, 0] when it declares none).
  std::pair<double, double> timeRange() const;
  double time() const;
  const std::string& activeInstance() const;

  /// Evaluates the model at time(), choosing the initial instance, and returns that record.
  /// Called by the first advanceTo() when not called before.
  FrameRecord start();
  /// Advances to `t` (>= time()) in steps of at most `maxStep`, locating every change of instance
  /// on the way; returns one record per evaluated time (requested frames and transitions).
  std::vector<FrameRecord> advanceTo(double t, double maxStep);

  /// The cells of the active instance that have a shape now (a T-cell whose shape no reaction has
  /// set yet is left out), in the instance's order.
  std::vector<CellState> cells() const;
  /// The implicit complex of the active instance now: its cells (Geometry/ShapeCells.h
  /// toComplexCell) and its boundary and containment relations. Cell ids follow cells(): id i is
  /// cells()[i].
  complex::Complex complex() const;

  /// A value by path: a state or instance parameter ("isIntersection"), a cell parameter or
  /// property ("LHKF.translation", "LHKF.translation.x", "Barrel.alpha").
  Value value(const std::string& path) const;
  /// "Cell.update", "K2.updatePost", "CONTACT.react:COLLISION", ... of the accepted frames.
  const std::vector<std::string>& log() const;
  /// The evaluation lists of the active instance's dependency plan (names), for traces and tests.
  std::vector<std::vector<std::string>> evaluationOrder() const;

private:
  std::unique_ptr<ModelState> impl_; ///< Engine/ModelState.h, internal to the engine
};

} // namespace ictk::engine
