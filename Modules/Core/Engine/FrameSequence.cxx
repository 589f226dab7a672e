// SPDX-License-Identifier: BSD-3-Clause
#include "Engine/FrameSequence.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <utility>

namespace ictk::engine
{

double frameCount(double t0, double t1, double dt)
{
  return std::floor((t1 - t0) / dt + 1e-3) + 1;
}

std::vector<double> frameTimes(double t0, double t1, double dt)
{
  std::vector<double> times;
  if (!(t1 > t0) || !(dt > 0))
  {
    times.push_back(t0);
    return times;
  }
  const double count = frameCount(t0, t1, dt) - 1;
  const auto n = static_cast<long long>(std::min(count, MaxFrames));
  times.reserve(static_cast<std::size_t>(n + 2));
  for (long long k = 0; k <= n; ++k)
  {
    times.push_back(t0 + static_cast<double>(k) * dt);
  }
  if (std::abs(t1 - times.back()) < 1e-3 * dt)
  {
    times.back() = t1;
  }
  else if (count < MaxFrames)
  {
    times.push_back(t1);
  }
  return times;
}

struct FrameSequence::Impl
{
  Loader load;
  FrameSequenceOptions options;
  std::optional<DynamicModel> model;
  std::optional<CoherentDiscretizer> mesher;
  std::vector<double> times;
  double maxStep = 0;
  double start = 0;
  /// The records evaluated since the last frame was handed out.
  std::vector<FrameRecord> pending;
  /// A frame failed or was cancelled: the next one starts again, so that what is computed does
  /// not depend on where that happened.
  bool restart = false;
  /// The engine stands at a time between the requested ones: going on from there would give
  /// later frames one more stop than a run from the start, so the next later frame restarts.
  bool offGrid = false;
  /// During at(): where the engine's and the discretiser's reports go, the share of the frame's
  /// progress that their current call fills; empty between frames.
  Progress stage;

  /// A callback for the engine's or the discretiser's options that forwards to `stage`; empty
  /// without a progress callback of the sequence, so that they report nothing.
  Progress toStage()
  {
    if (!options.progress)
    {
      return {};
    }
    return [this](double fraction)
    {
      return !stage || stage(fraction);
    };
  }

  /// The model (again) at its start.
  void startModel()
  {
    RunOptions run = options.run;
    run.progress = toStage();
    model.reset();
    model.emplace(load(std::move(run)));
    pending.clear();
    pending.push_back(model->start());
    restart = false;
    offGrid = false;
  }
};

FrameSequence::FrameSequence(const std::string& icmFile, FrameSequenceOptions options)
  : FrameSequence([icmFile](RunOptions run) { return DynamicModel::load(icmFile, std::move(run)); },
      std::move(options))
{
}

FrameSequence::FrameSequence(Loader load, FrameSequenceOptions options)
  : impl_(std::make_unique<Impl>())
{
  Impl& in = *impl_;
  in.load = std::move(load);
  in.options = std::move(options);
  in.startModel();
  in.start = in.model->time();

  const auto [t0, t1] = in.model->timeRange();
  if (in.options.times.empty())
  {
    const double h = in.options.timeStep > 0 ? in.options.timeStep : (t1 - t0) / 100;
    in.times = frameTimes(t0, t1, h);
  }
  else
  {
    in.times = in.options.times;
    for (std::size_t i = 0; i < in.times.size(); ++i)
    {
      if (!std::isfinite(in.times[i]) || (i > 0 && !(in.times[i] > in.times[i - 1])))
      {
        throw std::invalid_argument("the frame times must be finite and increasing");
      }
    }
  }
  double spacing = 0;
  for (std::size_t i = 1; i < in.times.size(); ++i)
  {
    const double d = in.times[i] - in.times[i - 1];
    spacing = spacing > 0 ? std::min(spacing, d) : d;
  }
  in.maxStep = in.options.maxStep > 0 ? in.options.maxStep
    : spacing > 0                     ? spacing
    : t1 > t0                         ? (t1 - t0) / 100
                                      : 1.0;

  CoherenceOptions discretization = in.options.discretization;
  discretization.progress = in.toStage();
  in.mesher.emplace(std::move(discretization));
  if (!(in.options.discretization.featureSize > 0))
  {
    // Fixed from the model's start, whatever frame is asked for first.
    in.mesher->setFeatureSize(complex::defaultFeatureSize(in.model->complex()));
  }
}

FrameSequence::~FrameSequence() = default;
FrameSequence::FrameSequence(FrameSequence&&) noexcept = default;
FrameSequence& FrameSequence::operator=(FrameSequence&&) noexcept = default;

const std::vector<double>& FrameSequence::times() const
{
  return impl_->times;
}

double FrameSequence::maxStep() const
{
  return impl_->maxStep;
}

double FrameSequence::startTime() const
{
  return impl_->start;
}

const DynamicModel& FrameSequence::model() const
{
  return *impl_->model;
}

const CoherentDiscretizer& FrameSequence::discretizer() const
{
  return *impl_->mesher;
}

Frame FrameSequence::frame(std::size_t i, const CellShare& share)
{
  return at(impl_->times.at(i), share);
}

Frame FrameSequence::at(double t, const CellShare& share)
{
  Impl& in = *impl_;
  t = std::clamp(t, in.times.front(), in.times.back());
  // The engine's run to t fills [0, 0.5] of the frame's progress, its discretisation [0.5, 1].
  ProgressScope progress(in.options.progress);
  try
  {
    if (in.restart || t < in.model->time() || (in.offGrid && t != in.model->time()))
    {
      // The engine only runs forwards: start again from the model's start (the kept meshes go
      // too, since shape versions count within one run).
      in.startModel();
      in.mesher->reset();
    }
    // Every requested time on the way is a stop, so that a frame is computed by the same steps
    // whichever frames were asked for before it.
    std::vector<double> stops;
    for (double s : in.times)
    {
      if (s > in.model->time() && s < t)
      {
        stops.push_back(s);
      }
    }
    if (t > in.model->time())
    {
      stops.push_back(t);
    }
    for (std::size_t i = 0; i < stops.size(); ++i)
    {
      in.stage = progress.range(
        0.5 * double(i) / double(stops.size()), 0.5 * double(i + 1) / double(stops.size()));
      std::vector<FrameRecord> records = in.model->advanceTo(stops[i], in.maxStep);
      in.pending.insert(in.pending.end(), std::make_move_iterator(records.begin()),
        std::make_move_iterator(records.end()));
    }
    progress.report(0.5);
    in.stage = progress.range(0.5, 1);
    in.offGrid = !std::binary_search(in.times.begin(), in.times.end(), t);

    Frame f;
    f.time = t;
    f.instance = in.model->activeInstance();
    const std::vector<CellState> cells = in.model->cells();
    f.complex = std::make_shared<const complex::Complex>(in.model->complex());
    const int pieces = std::max(1, share.pieces);
    if (pieces == 1 && !in.options.cells)
    {
      f.mesh = in.mesher->discretize(cells, *f.complex);
    }
    else
    {
      const std::vector<complex::CellId> all = f.complex->cellIds();
      const std::vector<complex::CellId> picked =
        in.options.cells ? in.options.cells(*f.complex) : all;
      std::vector<complex::CellId> mine;
      for (std::size_t i = 0; i < all.size(); ++i)
      {
        if (static_cast<int>(i % static_cast<std::size_t>(pieces)) == share.piece &&
          std::find(picked.begin(), picked.end(), all[i]) != picked.end())
        {
          mine.push_back(all[i]);
        }
      }
      if (!mine.empty())
      {
        f.mesh = in.mesher->discretize(cells, *f.complex, mine);
      }
    }
    f.records = std::move(in.pending);
    in.pending.clear();
    progress.report(1.0);
    in.stage = nullptr;
    return f;
  }
  catch (...)
  {
    in.stage = nullptr;
    in.restart = true;
    throw;
  }
}

} // namespace ictk::engine
