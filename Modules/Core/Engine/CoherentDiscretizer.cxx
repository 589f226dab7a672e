// SPDX-License-Identifier: BSD-3-Clause
#include "Engine/CoherentDiscretizer.h"

#include "Complex/Attributes.h"
#include "FRep/Sampling.h"
#include "Geometry/ShapeCells.h"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <utility>
#include <variant>

namespace ictk::engine
{
using geometry::Affine;
using geometry::PlacedShape;
using geometry::ShapePart;
using geometry::Vec3;

namespace
{

bool sameAffine(const Affine& a, const Affine& b)
{
  return a.a == b.a && a.b == b.b;
}

bool hasWorldParts(const PlacedShape& s)
{
  return std::any_of(s.parts.begin(), s.parts.end(), geometry::combinesCells);
}

std::vector<frep::Point3>& pointsOf(complex::CellMesh& m)
{
  return m.dimension == 0 ? m.points.points : m.dimension == 1 ? m.curves.points : m.surface.points;
}

double determinant(const std::array<double, 9>& a)
{
  return a[0] * (a[4] * a[8] - a[5] * a[7]) - a[1] * (a[3] * a[8] - a[5] * a[6]) +
    a[2] * (a[3] * a[7] - a[4] * a[6]);
}

bool isNormalArray(const discretize::PointArray& array)
{
  std::string name = array.name;
  std::transform(name.begin(), name.end(), name.begin(),
    [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return array.components == 3 && (name == "normals" || name == "normal");
}

/// The local mesh mapped into the world by `place`.
complex::CellMesh placed(const complex::CellMesh& local, const Affine& place)
{
  complex::CellMesh out = local;
  if (place.isIdentity())
  {
    return out;
  }
  for (frep::Point3& p : pointsOf(out))
  {
    p = place.apply(p);
  }
  // Normals are covectors: they map by the inverse transpose of the linear part.
  Affine normalMap;
  bool haveNormalMap = false;
  for (discretize::PointArray& array : out.pointData())
  {
    if (!isNormalArray(array))
    {
      continue;
    }
    if (!haveNormalMap)
    {
      const Affine inverse = place.inverse();
      for (int r = 0; r < 3; ++r)
      {
        for (int c = 0; c < 3; ++c)
        {
          normalMap.a[3 * r + c] = inverse.a[3 * c + r];
        }
      }
      haveNormalMap = true;
    }
    for (std::size_t i = 0; i + 2 < array.values.size(); i += 3)
    {
      Vec3 n = normalMap.applyLinear({ array.values[i], array.values[i + 1], array.values[i + 2] });
      const double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      for (int k = 0; k < 3; ++k)
      {
        array.values[i + k] = length > 0 ? n[k] / length : n[k];
      }
    }
  }
  // A mirroring placement turns triangles inside out; keep the outward orientation.
  if (out.dimension >= 2 && determinant(place.a) < 0)
  {
    for (auto& t : out.surface.triangles)
    {
      std::swap(t[1], t[2]);
    }
  }
  return out;
}

} // namespace

CoherenceStats& CoherenceStats::operator+=(const CoherenceStats& o)
{
  frames += o.frames;
  computed += o.computed;
  moved += o.moved;
  reused += o.reused;
  blocksContoured += o.blocksContoured;
  blocksReused += o.blocksReused;
  seconds += o.seconds;
  return *this;
}

CoherentDiscretizer::CoherentDiscretizer(CoherenceOptions options)
  : options_(std::move(options))
  , featureSize_(options_.featureSize > 0 ? options_.featureSize : 0.0)
{
}

void CoherentDiscretizer::reset()
{
  kept_.clear();
  last_ = {};
  total_ = {};
  lastCells_.clear();
}

complex::ComplexMesh CoherentDiscretizer::discretize(const DynamicModel& model)
{
  return discretize(model.cells(), model.complex());
}

complex::ComplexMesh CoherentDiscretizer::discretize(const std::vector<CellState>& cells,
  const complex::Complex& complex, const std::vector<complex::CellId>& only)
{
  const auto start = std::chrono::steady_clock::now();
  std::vector<complex::CellId> ids = complex.cellIds();
  if (ids.size() != cells.size())
  {
    throw std::invalid_argument("the complex has " + std::to_string(ids.size()) +
      " cells but the model reports " + std::to_string(cells.size()));
  }
  if (!(featureSize_ > 0))
  {
    featureSize_ = complex::defaultFeatureSize(complex);
  }
  std::vector<complex::CellId> targets = only;
  std::sort(targets.begin(), targets.end());
  targets.erase(std::unique(targets.begin(), targets.end()), targets.end());
  if (!targets.empty())
  {
    ids = targets;
    for (complex::CellId id : complex::attributeSupport(complex, targets, 0.25 * featureSize_))
    {
      ids.push_back(id);
    }
    std::sort(ids.begin(), ids.end());
  }
  complex::DiscretizationOptions o;
  o.featureSize = featureSize_;
  o.tolerance = options_.tolerance;
  o.threads = options_.threads;

  ProgressScope progress(options_.progress);
  CoherenceStats frame;
  frame.frames = 1;
  std::vector<std::pair<std::string, CellWork>> work;
  work.reserve(ids.size());
  complex::ComplexMesh mesh;
  mesh.featureSize = featureSize_;
  mesh.cells.reserve(ids.size());
  for (std::size_t i = 0; i < ids.size(); ++i)
  {
    const complex::CellId id = ids[i];
    if (id >= cells.size() || complex.cell(id).name != cells[id].name)
    {
      throw std::invalid_argument("cell " + std::to_string(id) + " of the complex ('" +
        complex.cell(id).name + "') is not the model's cell of that index");
    }
    const CellState& state = cells[id];
    if (!state.shape)
    {
      throw std::invalid_argument("cell '" + state.name + "' has no shape");
    }
    const PlacedShape& shape = *state.shape;
    const bool worldParts = hasWorldParts(shape);
    // World-space parts ignore the placement of a local frame: such a shape is meshed where it
    // is, and its mesh holds for that placement only.
    const Affine place = worldParts ? Affine{} : shape.place;

    auto found = kept_.find(state.name);
    const bool valid = options_.coherent && found != kept_.end() &&
      found->second.version == state.shapeVersion && found->second.worldParts == worldParts &&
      (!worldParts || sameAffine(found->second.madeUnder, shape.place));
    if (valid)
    {
      Kept& kept = found->second;
      if (sameAffine(kept.lastPlace, shape.place))
      {
        ++frame.reused;
        work.emplace_back(state.name, CellWork::Reused);
      }
      else
      {
        ++frame.moved;
        work.emplace_back(state.name, CellWork::Moved);
      }
      kept.lastPlace = shape.place;
      mesh.cells.push_back(placed(kept.local, place));
    }
    else
    {
      PlacedShape local = shape;
      if (!worldParts)
      {
        local.place = Affine{};
      }
      complex::Complex one;
      one.name = state.name;
      complex::Cell cell = toComplexCell(local, state.kind, options_.geometry);
      cell.attributes.clear();
      cell.operands.clear();
      const complex::CellId localId = one.addCell(std::move(cell));
      complex::DiscretizationOptions cellOptions = o;
      cellOptions.progress = nullptr;
      Kept kept;
      kept.version = state.shapeVersion;
      const complex::Cell& made = one.cell(localId);
      if (options_.coherent && found != kept_.end() && made.dimension == 3 &&
        std::holds_alternative<complex::ImplicitGeometry>(made.geometry))
      {
        const Kept& before = found->second;
        kept.surface =
          before.surface ? before.surface : std::make_shared<discretize::SurfaceMemory>();
        kept.misses = before.misses;
        kept.skip = before.skip;
        if (kept.skip > 0)
        {
          --kept.skip;
        }
        else
        {
          kept.surface->setLastCall({});
          cellOptions.surfaceMemory = kept.surface.get();
        }
      }
      kept.local = complex::discretizeCell(one, localId, cellOptions);
      if (cellOptions.surfaceMemory)
      {
        const discretize::SurfaceReuse& r = kept.surface->lastCall();
        frame.blocksContoured += r.blocksContoured;
        frame.blocksReused += r.blocksReused;
        // A memory's first call has nothing to reuse: only later calls count as misses.
        const bool tried = found->second.surface != nullptr;
        if (tried && r.blocksReused == 0 && r.blocksContoured > 0)
        {
          kept.misses = std::min<std::uint32_t>(kept.misses + 1, 6);
          kept.skip = (1u << kept.misses) - 1;
        }
        else if (r.blocksReused > 0)
        {
          kept.misses = 0;
        }
      }
      // Attributes are evaluated where the points are, every frame; the point arrays that come
      // with an explicit geometry (a skinned mesh's dominant joint) go with the points.
      const auto* given = std::get_if<complex::ExplicitGeometry>(&one.cell(localId).geometry);
      auto& arrays = kept.local.pointData();
      arrays.erase(std::remove_if(arrays.begin(), arrays.end(),
                     [&](const discretize::PointArray& a)
                     {
                       return !given ||
                         std::none_of(given->pointData.begin(), given->pointData.end(),
                           [&](const discretize::PointArray& g) { return g.name == a.name; });
                     }),
        arrays.end());
      kept.worldParts = worldParts;
      kept.madeUnder = shape.place;
      kept.lastPlace = shape.place;
      mesh.cells.push_back(placed(kept.local, place));
      ++frame.computed;
      work.emplace_back(state.name, CellWork::Computed);
      if (options_.coherent)
      {
        kept_[state.name] = std::move(kept);
      }
    }
    mesh.cells.back().cell = id;
    progress.report(0.9 * double(i + 1) / double(ids.size()));
  }

  // Attributes are functions of world position: evaluated where the points are now, never kept.
  for (complex::CellMesh& m : mesh.cells)
  {
    if (!targets.empty() && !std::binary_search(targets.begin(), targets.end(), m.cell))
    {
      continue; // a cell meshed only to locate points: its own attributes are not needed
    }
    for (const auto& binding : complex.cell(m.cell).attributes)
    {
      complex::appendAttribute(binding, m.vertices(), m.pointData());
    }
  }
  complex::appendUnboundAttributes(complex, mesh, 0.25 * featureSize_, targets);
  if (!targets.empty())
  {
    mesh.cells.erase(std::remove_if(mesh.cells.begin(), mesh.cells.end(),
                       [&](const complex::CellMesh& m)
                       { return !std::binary_search(targets.begin(), targets.end(), m.cell); }),
      mesh.cells.end());
  }
  progress.report(1.0);
  frame.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  last_ = frame;
  total_ += frame;
  lastCells_ = std::move(work);
  return mesh;
}

} // namespace ictk::engine
