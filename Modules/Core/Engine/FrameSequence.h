// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// A running model as a sequence of frames: the one frame loop of ICTK, used by the VTK source
// ictkDynamicComplexSource (and through it by `ictk run` and ictkTimeSeriesWriter) and by anyone
// who wants a dynamic complex's time series in plain C++.
//
// A frame is the model advanced to a requested time, its complex and that complex's time-coherent
// discretisation (CoherentDiscretizer), with the engine's records on the way (requested times and
// located transitions). The engine only runs forwards and a frame must not depend on which frames
// were asked for before it, so every requested time before a frame is a stop on the way to it, a
// frame earlier than the engine's time starts the model again from its start, and so does any
// frame after a cancelled or failed one (where the engine stopped is then an accident).
//
// The requested times of a T0:T1:DT range follow one rule, frameTimes() (the CLI's --frames and the
// source's TimeStepSize both use it).

#include "Complex/Complex.h"
#include "Complex/Discretization.h"
#include "Engine/CoherentDiscretizer.h"
#include "Engine/DynamicModel.h"
#include "FRep/Progress.h"

#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace ictk::engine
{

/// More frames than anyone can look at: a range asking for them is a typo (a missing digit in DT).
constexpr double MaxFrames = 1e6;
/// The most engine steps a command runs to reach its last time (`--max-step`, or the step a
/// command chooses): beyond it a run would not end in any reasonable time.
constexpr double MaxEngineSteps = 1e7;

/// The number of frames T0 + k DT in [T0, T1], with DT / 1000 of slack for rounding (T1 itself
/// comes on top when DT does not divide the range); for refusing an absurd range before making it.
double frameCount(double t0, double t1, double dt);

/// The frame times of T0:T1:DT: T0 + k DT (by multiplication, not accumulation: frame k is at
/// T0 + k DT to the last bit) while <= T1 with DT / 1000 of slack, a last frame within that slack
/// of T1 being T1 itself, and T1 as one more frame when DT does not divide the range. A degenerate
/// range (T1 <= T0 or DT <= 0) is the one frame T0; a range of more than MaxFrames frames is cut
/// after the first MaxFrames + 1, without T1.
std::vector<double> frameTimes(double t0, double t1, double dt);

struct FrameSequenceOptions
{
  /// The requested frames, increasing. Empty: the model's time range (DynamicModel::timeRange)
  /// from its start at every timeStep, by frameTimes().
  std::vector<double> times;
  /// The spacing of the default frames; 0 = 1/100 of the model's time range.
  double timeStep = 0;
  /// The engine's largest step; 0 = the smallest spacing of the frames (1/100 of the model's time
  /// range when there is one frame, 1 when that is empty too).
  double maxStep = 0;
  /// The engine's options; its progress callback is the sequence's own (see progress).
  RunOptions run;
  /// The discretisation's options (feature size, coherence, threads); its progress callback is
  /// the sequence's own. A feature size of 0 is fixed from the complex at the model's start,
  /// whatever frame is asked for first.
  CoherenceOptions discretization;
  /// The cells of a frame's complex to discretise (of the share's); empty: every cell. A renderer
  /// that ray casts the solids given by fields asks for the others only
  /// (Render/ComplexRender.h meshedCells): the surface of a 3D field cell it never draws from its
  /// mesh is the most expensive part of a frame's discretisation.
  std::function<std::vector<complex::CellId>(const complex::Complex&)> cells;
  /// Progress of one frame: the engine's run to it in [0, 0.5], its discretisation in [0.5, 1];
  /// false cancels (ictk::Cancelled; the next frame starts the model again).
  Progress progress;
};

/// An MPI rank's share of a frame's cells: cell i of the complex goes to piece i mod pieces (the
/// engine runs on every rank: it is cheap and deterministic).
struct CellShare
{
  int piece = 0;
  int pieces = 1;
};

struct Frame
{
  double time = 0;      ///< the requested time (the frames' range clamps it)
  std::string instance; ///< the active instance
  /// The engine's records since the previous frame of this sequence (from the model's start, its
  /// start record included, when the model was (re)started for this frame): one per evaluated
  /// time, requested or a located transition.
  std::vector<FrameRecord> records;
  /// The active instance's complex; its cell ids follow the instance's cells.
  std::shared_ptr<const complex::Complex> complex;
  /// The coherent discretisation of the share's cells (every cell for one piece) that
  /// FrameSequenceOptions::cells picks.
  complex::ComplexMesh mesh;
};

class FrameSequence
{
public:
  /// Builds a model at its start; called again whenever the sequence starts over.
  using Loader = std::function<DynamicModel(RunOptions)>;

  /// A .icm model file (DynamicModel::load: lang::ParseError, ModelError).
  FrameSequence(const std::string& icmFile, FrameSequenceOptions options = {});
  /// A model from anywhere. Both load the model, start it and fix the frames and the feature size
  /// (std::invalid_argument for frames that are not finite and increasing). A frame before the
  /// model's start is the model at its start (a front end that cares checks startTime()).
  FrameSequence(Loader load, FrameSequenceOptions options = {});
  ~FrameSequence();
  FrameSequence(FrameSequence&&) noexcept;
  FrameSequence& operator=(FrameSequence&&) noexcept;

  /// The requested frames and the engine's largest step, as fixed at construction.
  const std::vector<double>& times() const;
  double maxStep() const;
  /// The model's time at its start.
  double startTime() const;
  const DynamicModel& model() const;
  const CoherentDiscretizer& discretizer() const;

  /// Frame i, at times()[i].
  Frame frame(std::size_t i, const CellShare& share = {});
  /// The frame at t (clamped to the frames' range), reached through every requested time before
  /// it; a t between requested times is a frame too, after which a later one starts over.
  Frame at(double t, const CellShare& share = {});

  /// Opaque; public only so the implementation's helpers can name it.
  struct Impl;

private:
  std::unique_ptr<Impl> impl_;
};

} // namespace ictk::engine
