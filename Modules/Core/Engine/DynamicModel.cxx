// SPDX-License-Identifier: BSD-3-Clause
// DynamicModel's public face over its state (ModelState.h): loading, the time range, the cells and
// the complex of the active instance, the log and the evaluation order. Building is in
// ModelBuild.cxx and ModelShapes.cxx, values and placements in ModelValues.cxx, running in
// ModelRun.cxx, the library calls of code in ModelLibrary.cxx.
#include "Engine/DynamicModel.h"

#include "Engine/ModelState.h"
#include "Geometry/ShapeCells.h"

#include <cmath>
#include <map>

namespace ictk::engine
{

DynamicModel DynamicModel::load(const std::string& path, RunOptions options)
{
  return DynamicModel(lang::readIcmFile(path), std::move(options));
}

DynamicModel::DynamicModel(lang::IcmModel model, RunOptions options)
  : impl_(std::make_unique<ModelState>(std::move(model), std::move(options)))
{
  impl_->build();
}

DynamicModel::~DynamicModel() = default;
DynamicModel::DynamicModel(DynamicModel&&) noexcept = default;
DynamicModel& DynamicModel::operator=(DynamicModel&&) noexcept = default;

const std::string& DynamicModel::name() const
{
  return impl_->model.name.text;
}

std::pair<double, double> DynamicModel::timeRange() const
{
  double lo = dyn::kInfinity, hi = -dyn::kInfinity;
  for (const auto& [n, span] : impl_->timespans)
    for (const dyn::TimeInterval& i : span.intervals())
    {
      if (std::isfinite(i.start))
        lo = std::min(lo, i.start);
      if (std::isfinite(i.end))
        hi = std::max(hi, i.end);
    }
  if (!std::isfinite(lo) || !std::isfinite(hi))
    return { 0.0, 0.0 };
  return { lo, hi };
}

double DynamicModel::time() const
{
  return impl_->stepper->time();
}

const std::string& DynamicModel::activeInstance() const
{
  static const std::string none;
  return impl_->s.active == kNone ? none : impl_->instances[impl_->s.active].name;
}

std::vector<CellState> DynamicModel::cells() const
{
  const ModelState& m = *impl_;
  std::vector<CellState> out;
  if (m.s.active == kNone)
    return out;
  for (const std::string& n : m.instances[m.s.active].cells)
  {
    const CellSpec& c = m.cells[m.cellIndex.at(n)];
    if (!c.operands && m.partsOf(c)->empty())
      continue;
    CellState st;
    st.name = n;
    st.kind = c.kind;
    st.dimension = m.spaceDimension(c);
    st.spaceTime = c.spaceTime;
    st.shape = m.shapeOf(n);
    st.shapeVersion = m.versionOf(n);
    out.push_back(std::move(st));
  }
  return out;
}

complex::Complex DynamicModel::complex() const
{
  const ModelState& m = *impl_;
  complex::Complex cx;
  std::map<std::string, complex::CellId> ids;
  for (const CellState& c : cells())
  {
    complex::Cell cell;
    try
    {
      cell = toComplexCell(*c.shape, c.kind, m.options.geometry);
    }
    catch (const std::exception& e)
    {
      m.fail(m.cells[m.cellIndex.at(c.name)].pos, "the cell " + c.name + ": " + e.what());
    }
    cell.name = c.name;
    cell.priority = m.cells[m.cellIndex.at(c.name)].priority;
    ids[c.name] = cx.addCell(std::move(cell));
  }
  if (m.s.active == kNone)
    return cx;
  const InstanceSpec& in = m.instances[m.s.active];
  for (const RelationSpec& r : in.boundary)
    if (ids.count(r.master) && ids.count(r.dependent))
    {
      try
      {
        cx.addBoundary(ids[r.dependent], ids[r.master]);
      }
      catch (const std::exception& e)
      {
        m.fail(r.pos, std::string("boundary relation: ") + e.what());
      }
    }
  // Attributes with a function follow their cell: evaluated in its local coordinates.
  for (const auto& [cell, name] : in.attributeLinks)
  {
    auto a = m.attributes.find(name);
    if (a == m.attributes.end() || !a->second.tape || !ids.count(cell))
      continue;
    PlacedShape local;
    local.cell = cell;
    local.dimension = 3;
    local.place = m.place(cell);
    ShapePart part;
    part.kind = ShapePart::Kind::Field;
    // An attribute of space and time (x[4]) follows the model's time, as space-time cells do.
    part.field = frep::tapeField(a->second.tape, m.shapeTime());
    part.fieldDimension = a->second.dimension;
    // unbounded: the attribute is defined wherever its cell is
    part.bounds = frep::Box3{ { -1e30, -1e30, -1e30 }, { 1e30, 1e30, 1e30 } };
    local.parts.push_back(part);
    auto fn = std::make_shared<complex::AttributeFunction>();
    fn->name = name;
    fn->components.push_back(worldField(local));
    fn->text.push_back(a->second.text);
    if (!cx.attributes().count(name))
      cx.declareAttribute(name, complex::AttributeDefaults{ 1, { 0.0 }, { 0.0 } });
    cx.bindAttribute(ids[cell], complex::AttributeBinding{ name, fn, 0.0 });
  }
  for (const RelationSpec& r : in.containment)
    if (ids.count(r.master) && ids.count(r.dependent))
    {
      try
      {
        cx.addContainment(ids[r.master], ids[r.dependent]);
      }
      catch (const std::exception& e)
      {
        m.fail(r.pos, std::string("containment relation: ") + e.what());
      }
    }
  return cx;
}

const std::vector<std::string>& DynamicModel::log() const
{
  return impl_->stepper->log();
}

std::vector<std::vector<std::string>> DynamicModel::evaluationOrder() const
{
  const ModelState& m = *impl_;
  if (m.s.active == kNone)
    return {};
  dyn::DependencyGraph g = m.graph(m.s.active);
  return g.plan().listNames();
}

} // namespace ictk::engine
