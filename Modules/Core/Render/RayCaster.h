// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Internal to Render: the ray caster of RayCast.h over any solid, into a Canvas that may already
// hold surfaces (the common z-buffer of a complex, ComplexRender.h). A pixel's ray stops at the
// depth the canvas holds there, so a solid behind a rasterised tube is not searched and one in
// front of it is drawn over it. The solid is given by its per-thread evaluation (a Stage: interval
// bounds, pruning per piece of the view, values, gradients) and the paint of its surface, so that
// a model's tape (with its attributes) and a cell's fields (FRep or voxel) take the same search.

#include "FRep/Field.h"
#include "FRep/Interval.h"
#include "Render/Camera.h"
#include "Render/Canvas.h"
#include "Render/RayCast.h"

#include <cstdint>
#include <functional>
#include <memory>

namespace ictk::render::detail
{

/// The evaluation of a solid f >= 0 for one thread (not thread safe).
class Stage
{
public:
  virtual ~Stage() = default;
  /// An enclosure of f over the box.
  virtual frep::Interval bound(const frep::Box3& box) = 0;
  /// A stage with a shorter evaluation that gives the same values in the box of the last
  /// bound(); null when nothing would be cut. This stage owns it, and it stays valid until this
  /// stage's next narrowed() (the quadtree asks a stage again only for a sibling node, when the
  /// stage it got for the last one is no longer in use).
  virtual Stage* narrowed() = 0;
  /// May drop the stages narrowed() keeps for reuse (called when none of them is in use).
  virtual void forget() {}
  virtual double value(const frep::Point3& p) = 0;
  virtual frep::Point3 gradient(const frep::Point3& p) = 0;
};

/// The paint of a solid's surface, per thread.
class Painter
{
public:
  virtual ~Painter() = default;
  /// The paint at a point inside the solid.
  virtual Paint at(const frep::Point3& p) = 0;
};

struct Solid
{
  /// Makes a thread's full stage.
  std::function<std::unique_ptr<Stage>()> stage;
  /// Makes a thread's painter; empty: neutral grey.
  std::function<std::unique_ptr<Painter>()> painter;
  /// The box the solid is searched in (rays are clipped to it).
  frep::Box3 box;
  /// Canvas::owner of its pixels.
  std::int32_t owner = 0;
};

/// The stage of a field (a cell's; FieldEvaluator::narrowed prunes a tape field per piece).
std::unique_ptr<Stage> fieldStage(const frep::Field& field);

/// What a cast did; the pixels it drew are in the canvas.
struct CastCounts
{
  std::int64_t covered = 0;
  std::int64_t unresolved = 0;
  std::int64_t cut = 0;
  /// Of `cut`, the rays cut by the camera itself: it is inside the solid.
  std::int64_t eyeInside = 0;
  std::int64_t intervals = 0;
  std::int64_t points = 0;
};

/// Casts the rays of `camera` (the canvas's size) against the solid, each between its entry into
/// the solid's box and the depth the canvas holds; the hits nearer than that are drawn. Checks
/// the options and the box (std::invalid_argument); Cancelled from the progress callback.
CastCounts cast(
  Canvas& canvas, const Solid& solid, const Camera& camera, const RayCastOptions& options);

} // namespace ictk::render::detail
