// SPDX-License-Identifier: BSD-3-Clause
#include "ictkFRepEvaluator.h"

#include "ictkFRepModel.h"

#include "FRep/Evaluators.h"
#include "FRep/Hypervolume.h"
#include "FRep/Tape.h"
#include "FRep/Threads.h"

#include "vtkDataArray.h"
#include "vtkObjectFactory.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <optional>

namespace frep = ictk::frep;

vtkStandardNewMacro(ictkFRepEvaluator);

struct ictkFRepEvaluator::Internals
{
  ictkFRepModel Model;
  /// The tapes of the model last resolved (compiled once per model).
  const frep::Hypervolume* Compiled = nullptr;
  frep::TapePtr Geometry;
};

namespace
{
/// Points are read a block at a time into coordinate rows, whatever the array's type.
constexpr vtkIdType Block = 4096;

/// Runs body(begin, end) over [0, n) in blocks, on `threads` threads (0: TBB's default).
template <typename Body>
void ForBlocks(vtkIdType n, int threads, const Body& body)
{
  auto run = [&]
  {
    tbb::parallel_for(tbb::blocked_range<vtkIdType>(0, (n + Block - 1) / Block, 1),
      [&](const tbb::blocked_range<vtkIdType>& r)
      {
        for (vtkIdType b = r.begin(); b != r.end(); ++b)
        {
          body(b * Block, std::min(n, (b + 1) * Block));
        }
      });
  };
  ictk::runOnThreads(threads, run);
}

/// The coordinates of points [begin, end) as four rows (t = `time` for 3-component points).
void ReadPoints(vtkDataArray* points, vtkIdType begin, vtkIdType end, double time,
  std::array<std::vector<double>, 4>& rows)
{
  const int components = points->GetNumberOfComponents();
  for (auto& row : rows)
  {
    row.resize(static_cast<std::size_t>(end - begin));
  }
  for (vtkIdType i = begin; i < end; ++i)
  {
    const auto k = static_cast<std::size_t>(i - begin);
    for (int a = 0; a < 3; ++a)
    {
      rows[a][k] = points->GetComponent(i, a);
    }
    rows[3][k] = components == 4 ? points->GetComponent(i, 3) : time;
  }
}

/// Runs body(evaluator, begin, end, rows) over blocks of the points, with one evaluator per thread
/// (made by make(slot)) and the block's coordinates as four rows.
template <typename Evaluator, typename Make, typename Body>
void ForPointBlocks(
  vtkDataArray* points, int threads, double time, const Make& make, const Body& body)
{
  tbb::enumerable_thread_specific<std::optional<Evaluator>> evaluators;
  ForBlocks(points->GetNumberOfTuples(), threads,
    [&](vtkIdType begin, vtkIdType end)
    {
      auto& slot = evaluators.local();
      if (!slot)
      {
        make(slot);
      }
      std::array<std::vector<double>, 4> rows;
      ReadPoints(points, begin, end, time, rows);
      body(*slot, begin, end, rows);
    });
}
} // namespace

ictkFRepEvaluator::ictkFRepEvaluator()
  : Internal(new Internals)
{
}

ictkFRepEvaluator::~ictkFRepEvaluator()
{
  delete[] this->ModelName;
  delete[] this->FileName;
}

void ictkFRepEvaluator::SetModelName(const char* name)
{
  if (this->Internal->Model.SelectModelName(this->ModelName, this->FileName, name))
  {
    this->Modified();
  }
}

void ictkFRepEvaluator::SetFileName(const char* name)
{
  if (this->Internal->Model.SelectFileName(this->ModelName, this->FileName, name))
  {
    this->Modified();
  }
}

void ictkFRepEvaluator::SetHypervolume(const frep::Hypervolume& hv)
{
  this->Internal->Model.Explicit = std::make_unique<frep::Hypervolume>(hv);
  this->Modified();
}

void ictkFRepEvaluator::SetParameters(const double* values, int count)
{
  std::vector<double> p(values, values + std::max(0, count));
  if (p != this->Internal->Model.Parameters)
  {
    this->Internal->Model.Parameters = std::move(p);
    this->Internal->Model.ReadPath.clear();
    this->Modified();
  }
}

int ictkFRepEvaluator::GetNumberOfParameters()
{
  return static_cast<int>(this->Internal->Model.Parameters.size());
}

const frep::Hypervolume* ictkFRepEvaluator::GetHypervolume()
{
  this->LastError.clear();
  const frep::Hypervolume* hv =
    this->Internal->Model.Resolve(this->ModelName, this->FileName, this->LastError);
  if (hv && hv != this->Internal->Compiled)
  {
    this->Internal->Geometry = frep::Tape::compile(hv->geometry().function());
    this->Internal->Compiled = hv;
  }
  return hv;
}

int ictkFRepEvaluator::Load()
{
  if (!this->GetHypervolume())
  {
    vtkErrorMacro(<< this->LastError);
    return 0;
  }
  return 1;
}

const char* ictkFRepEvaluator::GetName()
{
  const frep::Hypervolume* hv = this->GetHypervolume();
  if (!hv)
  {
    return "";
  }
  if (this->FileName)
  {
    return this->FileName;
  }
  return this->ModelName ? this->ModelName : "";
}

bool ictkFRepEvaluator::IsTimeDependent()
{
  const frep::Hypervolume* hv = this->GetHypervolume();
  return hv &&
    (frep::domainAxes(hv->geometry().domain()) & (1u << static_cast<int>(frep::Axis::T))) != 0;
}

void ictkFRepEvaluator::GetBounds(double bounds[6])
{
  const frep::Hypervolume* hv = this->GetHypervolume();
  const ictkFRepModel& m = this->Internal->Model;
  if (!hv || m.Explicit)
  {
    const double empty[6] = { 1, -1, 1, -1, 1, -1 };
    std::copy(empty, empty + 6, bounds);
    return;
  }
  for (int a = 0; a < 3; ++a)
  {
    bounds[2 * a] = m.ResolvedLo[a];
    bounds[2 * a + 1] = m.ResolvedHi[a];
  }
}

int ictkFRepEvaluator::GetNumberOfAttributes()
{
  const frep::Hypervolume* hv = this->GetHypervolume();
  return hv ? static_cast<int>(hv->attributes().size()) : 0;
}

const char* ictkFRepEvaluator::GetAttributeName(int i)
{
  const frep::Hypervolume* hv = this->GetHypervolume();
  return hv && i >= 0 && i < static_cast<int>(hv->attributes().size())
    ? hv->attributes()[static_cast<std::size_t>(i)].name.c_str()
    : nullptr;
}

int ictkFRepEvaluator::GetAttributeNumberOfComponents(int i)
{
  const frep::Hypervolume* hv = this->GetHypervolume();
  return hv && i >= 0 && i < static_cast<int>(hv->attributes().size())
    ? static_cast<int>(hv->attributes()[static_cast<std::size_t>(i)].components.size())
    : 0;
}

int ictkFRepEvaluator::GetAttributeComponentCount()
{
  const frep::Hypervolume* hv = this->GetHypervolume();
  return hv ? static_cast<int>(hv->attributeComponentCount()) : 0;
}

namespace
{
/// The checks every Evaluate* makes; "" when the arrays fit.
std::string CheckArrays(vtkDataArray* points, vtkDataArray* out, int components, const char* what)
{
  if (!points)
  {
    return "no points given";
  }
  if (points->GetNumberOfComponents() != 3 && points->GetNumberOfComponents() != 4)
  {
    return "points must have 3 (x, y, z) or 4 (x, y, z, t) components, not " +
      std::to_string(points->GetNumberOfComponents());
  }
  if (!out)
  {
    return std::string("no array given for the ") + what;
  }
  if (out->GetNumberOfComponents() != components ||
    out->GetNumberOfTuples() != points->GetNumberOfTuples())
  {
    return std::string("the ") + what + " array must have " +
      std::to_string(points->GetNumberOfTuples()) + " tuples of " + std::to_string(components) +
      " components, not " + std::to_string(out->GetNumberOfTuples()) + " of " +
      std::to_string(out->GetNumberOfComponents());
  }
  return "";
}
} // namespace

int ictkFRepEvaluator::EvaluateValues(vtkDataArray* points, vtkDataArray* values)
{
  const frep::Hypervolume* hv = this->GetHypervolume();
  if (hv)
  {
    this->LastError = CheckArrays(points, values, 1, "values");
  }
  if (!this->LastError.empty())
  {
    vtkErrorMacro(<< this->LastError);
    return 0;
  }
  const frep::TapePtr tape = this->Internal->Geometry;
  const std::vector<double>& parameters = this->Internal->Model.Parameters;
  ForPointBlocks<frep::BatchEvaluator<double>>(
    points, this->NumberOfThreads, this->Time, [&](auto& slot) { slot.emplace(tape, parameters); },
    [&](auto& evaluator, vtkIdType begin, vtkIdType end,
      const std::array<std::vector<double>, 4>& rows)
    {
      std::vector<double> out(static_cast<std::size_t>(end - begin));
      evaluator.eval(
        rows[0].data(), rows[1].data(), rows[2].data(), rows[3].data(), out.data(), out.size());
      for (vtkIdType i = begin; i < end; ++i)
      {
        values->SetComponent(i, 0, out[static_cast<std::size_t>(i - begin)]);
      }
    });
  return 1;
}

int ictkFRepEvaluator::EvaluateGradients(
  vtkDataArray* points, vtkDataArray* gradients, vtkDataArray* values)
{
  const frep::Hypervolume* hv = this->GetHypervolume();
  if (hv)
  {
    this->LastError = CheckArrays(points, gradients, 4, "gradients");
    if (this->LastError.empty() && values)
    {
      this->LastError = CheckArrays(points, values, 1, "values");
    }
  }
  if (!this->LastError.empty())
  {
    vtkErrorMacro(<< this->LastError);
    return 0;
  }
  const frep::TapePtr tape = this->Internal->Geometry;
  const std::vector<double>& parameters = this->Internal->Model.Parameters;
  ForPointBlocks<frep::GradientEvaluator>(
    points, this->NumberOfThreads, this->Time, [&](auto& slot) { slot.emplace(tape, parameters); },
    [&](auto& evaluator, vtkIdType begin, vtkIdType end,
      const std::array<std::vector<double>, 4>& rows)
    {
      for (vtkIdType i = begin; i < end; ++i)
      {
        const auto k = static_cast<std::size_t>(i - begin);
        const frep::ValueGradient g =
          evaluator.eval(rows[0][k], rows[1][k], rows[2][k], rows[3][k]);
        for (int a = 0; a < 4; ++a)
        {
          gradients->SetComponent(i, a, g.gradient[static_cast<std::size_t>(a)]);
        }
        if (values)
        {
          values->SetComponent(i, 0, g.value);
        }
      }
    });
  return 1;
}

int ictkFRepEvaluator::EvaluateAttributes(vtkDataArray* points, vtkDataArray* attributes)
{
  const frep::Hypervolume* hv = this->GetHypervolume();
  if (hv)
  {
    this->LastError = CheckArrays(
      points, attributes, static_cast<int>(hv->attributeComponentCount()), "attributes");
  }
  if (!this->LastError.empty())
  {
    vtkErrorMacro(<< this->LastError);
    return 0;
  }
  const std::vector<double>& parameters = this->Internal->Model.Parameters;
  const std::size_t width = hv->attributeComponentCount();
  ForPointBlocks<frep::HypervolumeEvaluator>(
    points, this->NumberOfThreads, this->Time, [&](auto& slot) { slot.emplace(*hv, parameters); },
    [&](auto& evaluator, vtkIdType begin, vtkIdType end,
      const std::array<std::vector<double>, 4>& rows)
    {
      std::vector<double> out(width);
      for (vtkIdType i = begin; i < end; ++i)
      {
        const auto k = static_cast<std::size_t>(i - begin);
        double value = 0;
        evaluator.eval({ rows[0][k], rows[1][k], rows[2][k], rows[3][k] }, value, out.data());
        for (std::size_t c = 0; c < width; ++c)
        {
          attributes->SetComponent(i, static_cast<int>(c), out[c]);
        }
      }
    });
  return 1;
}

void ictkFRepEvaluator::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "ModelName: " << (this->ModelName ? this->ModelName : "(none)") << "\n";
  os << indent << "FileName: " << (this->FileName ? this->FileName : "(none)") << "\n";
  os << indent << "Time: " << this->Time << "\n";
  os << indent << "NumberOfThreads: " << this->NumberOfThreads << "\n";
}
