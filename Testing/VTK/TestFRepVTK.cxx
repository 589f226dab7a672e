// SPDX-License-Identifier: BSD-3-Clause
// ictkFRepSampler and ictkFRepImplicitFunction against closed-form fields.

#include "FRep/Domain.h"
#include "FRep/Expr.h"
#include "FRep/Hypervolume.h"
#include "FRep/ModelRegistry.h"
#include "FRep/Primitives.h"

#include "ictkFRepImplicitFunction.h"
#include "ictkFRepSampler.h"
#include "ictkQuadricToVtk.h"

#include <vtkCallbackCommand.h>
#include <vtkClipPolyData.h>
#include <vtkCommand.h>
#include <vtkDataArray.h>
#include <vtkExecutive.h>
#include <vtkImageData.h>
#include <vtkMassProperties.h>
#include <vtkNew.h>
#include <vtkPlaneSource.h>
#include <vtkPointData.h>
#include <vtkQuadric.h>
#include <vtkSMPTools.h>
#include <vtkTriangleFilter.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <random>
#include <string>
#include <thread>
#include <vector>

using namespace ictk::frep;

namespace
{
// f = 1 - x^2 - y^2 - z^2; density = 2 + x everywhere; colour = (x, y, z) where x >= 0, else the
// defaults (0.5, 0.5, 0.5) inside and (-1, -1, -1) outside.
Hypervolume TestSphere()
{
  const Expr x = Expr::x(), y = Expr::y(), z = Expr::z();
  Hypervolume hv(Shape(Expr(1.0) - square(x) - square(y) - square(z), Domain::XYZ, "sphere"));
  Attribute density;
  density.name = "density";
  density.components = { Expr(2.0) + x };
  hv.addAttribute(density);
  Attribute colour;
  colour.name = "colour";
  colour.components = { x, y, z };
  colour.partition = x;
  colour.insideDefault = { 0.5, 0.5, 0.5 };
  colour.outsideDefault = { -1, -1, -1 };
  hv.addAttribute(colour);
  return hv;
}

double SphereF(const double p[3])
{
  return 1.0 - p[0] * p[0] - p[1] * p[1] - p[2] * p[2];
}

/// Records the messages of ErrorEvents (which then are not printed).
struct ErrorRecorder
{
  std::vector<std::string> messages;
  vtkNew<vtkCallbackCommand> command;

  ErrorRecorder()
  {
    command->SetClientData(this);
    command->SetCallback(
      [](vtkObject*, unsigned long, void* self, void* text) {
        static_cast<ErrorRecorder*>(self)->messages.emplace_back(static_cast<const char*>(text));
      });
  }
  void Watch(vtkObject* o) { o->AddObserver(vtkCommand::ErrorEvent, command); }
  bool Contains(const std::string& s) const
  {
    for (const std::string& m : messages)
    {
      if (m.find(s) != std::string::npos)
      {
        return true;
      }
    }
    return false;
  }
};

void CheckSphereGrid(vtkImageData* image, double tolerance)
{
  vtkDataArray* f = image->GetPointData()->GetArray("f");
  vtkDataArray* density = image->GetPointData()->GetArray("density");
  vtkDataArray* colour = image->GetPointData()->GetArray("colour");
  ASSERT_NE(f, nullptr);
  ASSERT_NE(density, nullptr);
  ASSERT_NE(colour, nullptr);
  EXPECT_EQ(image->GetPointData()->GetScalars(), f);
  EXPECT_EQ(f->GetNumberOfComponents(), 1);
  EXPECT_EQ(density->GetNumberOfComponents(), 1);
  EXPECT_EQ(colour->GetNumberOfComponents(), 3);
  for (vtkIdType i = 0; i < image->GetNumberOfPoints(); ++i)
  {
    double p[3];
    image->GetPoint(i, p);
    const double value = SphereF(p);
    ASSERT_NEAR(f->GetComponent(i, 0), value, tolerance) << "point " << i;
    ASSERT_NEAR(density->GetComponent(i, 0), 2.0 + p[0], tolerance);
    for (int c = 0; c < 3; ++c)
    {
      const double expected = p[0] >= 0 ? p[c] : (value >= 0 ? 0.5 : -1.0);
      ASSERT_NEAR(colour->GetComponent(i, c), expected, tolerance) << "point " << i << " c " << c;
    }
  }
}
} // namespace

TEST(FRepSampler, GridMatchesFormulaWithBoundsSpacingExtentAndAttributes)
{
  vtkNew<ictkFRepSampler> sampler;
  sampler->SetHypervolume(TestSphere());
  sampler->SetModelBounds(-1, 1, -2, 2, -1.5, 1.5);
  sampler->SetSampleDimensions(5, 9, 7);
  sampler->Update();
  vtkImageData* image = sampler->GetOutput();

  int extent[6];
  image->GetExtent(extent);
  EXPECT_EQ(std::vector<int>(extent, extent + 6), (std::vector<int>{ 0, 4, 0, 8, 0, 6 }));
  double spacing[3], origin[3], bounds[6];
  image->GetSpacing(spacing);
  image->GetOrigin(origin);
  image->GetBounds(bounds);
  for (int a = 0; a < 3; ++a)
  {
    EXPECT_DOUBLE_EQ(spacing[a], 0.5);
  }
  EXPECT_DOUBLE_EQ(origin[0], -1);
  EXPECT_DOUBLE_EQ(origin[1], -2);
  EXPECT_DOUBLE_EQ(origin[2], -1.5);
  EXPECT_DOUBLE_EQ(bounds[1], 1);
  EXPECT_DOUBLE_EQ(bounds[3], 2);
  EXPECT_DOUBLE_EQ(bounds[5], 1.5);
  EXPECT_EQ(image->GetPointData()->GetArray("f")->GetDataType(), VTK_FLOAT);
  CheckSphereGrid(image, 1e-6);

  // A known grid point: (i, j, k) = (2, 4, 3) is the origin, where f = 1.
  EXPECT_FLOAT_EQ(static_cast<float>(image->GetPointData()->GetArray("f")->GetComponent(
                    image->ComputePointId(std::array<int, 3>{ 2, 4, 3 }.data()), 0)),
    1.0f);
}

TEST(FRepSampler, DoubleOutputIsExact)
{
  vtkNew<ictkFRepSampler> sampler;
  sampler->SetHypervolume(TestSphere());
  sampler->SetModelBounds(-1.1, 0.9, -1, 1, -1, 1);
  sampler->SetSampleDimensions(11, 6, 4);
  sampler->SetOutputScalarTypeToDouble();
  sampler->Update();
  EXPECT_EQ(sampler->GetOutput()->GetPointData()->GetArray("f")->GetDataType(), VTK_DOUBLE);
  CheckSphereGrid(sampler->GetOutput(), 1e-12);
}

TEST(FRepSampler, SameValuesForAnyThreadCount)
{
  std::vector<std::vector<float>> results;
  for (int threads : { 1, 2 })
  {
    vtkNew<ictkFRepSampler> sampler;
    sampler->SetHypervolume(TestSphere());
    sampler->SetModelBounds(-1, 1, -1, 1, -1, 1);
    sampler->SetSampleDimensions(70, 33, 20);
    sampler->SetNumberOfThreads(threads);
    sampler->Update();
    vtkDataArray* f = sampler->GetOutput()->GetPointData()->GetArray("f");
    std::vector<float> values(static_cast<std::size_t>(f->GetNumberOfTuples()));
    for (vtkIdType i = 0; i < f->GetNumberOfTuples(); ++i)
    {
      values[static_cast<std::size_t>(i)] = static_cast<float>(f->GetComponent(i, 0));
    }
    results.push_back(values);
  }
  EXPECT_EQ(results[0], results[1]);
}

TEST(FRepSampler, TwoPipelinesOverOneModelInTwoThreads)
{
  // Issue 19's concurrency promise: VTK's contract (no state change during an update) is kept
  // by each pipeline, and the pipelines share one model, whose thread-local evaluators each
  // thread builds for itself. Two threads each run their own sampler (on 2 threads) and their own
  // implicit function over one walnut, again and again: every result is the single-threaded one,
  // bit for bit.
  const ictk::frep::ModelInfo& info = ictk::frep::findModel("walnut");
  const Hypervolume walnut = info.build();
  auto sample = [&](int threads)
  {
    vtkNew<ictkFRepSampler> sampler;
    sampler->SetHypervolume(walnut);
    sampler->SetModelBounds(info.boundsLo[0], info.boundsHi[0], info.boundsLo[1], info.boundsHi[1],
      info.boundsLo[2], info.boundsHi[2]);
    sampler->SetSampleDimensions(24, 24, 24);
    sampler->SetNumberOfThreads(threads);
    sampler->Update();
    vtkDataArray* f = sampler->GetOutput()->GetPointData()->GetArray("f");
    std::vector<double> values(static_cast<std::size_t>(f->GetNumberOfTuples()));
    for (vtkIdType i = 0; i < f->GetNumberOfTuples(); ++i)
    {
      values[static_cast<std::size_t>(i)] = f->GetComponent(i, 0);
    }
    return values;
  };
  auto evaluate = [&]
  {
    vtkNew<ictkFRepImplicitFunction> function;
    function->SetHypervolume(walnut);
    std::vector<double> values;
    for (int i = 0; i < 2000; ++i)
    {
      double p[3] = { -1 + 0.001 * i, 0.3 - 0.0002 * i, 0.0005 * i - 0.5 };
      values.push_back(function->EvaluateFunction(p));
    }
    return values;
  };
  const std::vector<double> sampled = sample(1);
  const std::vector<double> evaluated = evaluate();
  ASSERT_GT(*std::max_element(sampled.begin(), sampled.end()), 0.0); // inside and outside
  ASSERT_LT(*std::min_element(sampled.begin(), sampled.end()), 0.0);
  std::array<int, 2> same{ 0, 0 };
  std::vector<std::thread> threads;
  for (int t = 0; t < 2; ++t)
  {
    threads.emplace_back(
      [&, t]
      {
        for (int round = 0; round < 4; ++round)
        {
          same[static_cast<std::size_t>(t)] += sample(2) == sampled;
          same[static_cast<std::size_t>(t)] += evaluate() == evaluated;
        }
      });
  }
  for (std::thread& thread : threads)
  {
    thread.join();
  }
  EXPECT_EQ(same[0], 8);
  EXPECT_EQ(same[1], 8);
}

TEST(FRepSampler, RegisteredModelUsesItsBounds)
{
  vtkNew<ictkFRepSampler> sampler;
  sampler->SetModelName("sphere");
  sampler->SetSampleDimensions(13, 13, 13);
  sampler->Update();
  vtkImageData* image = sampler->GetOutput();
  double bounds[6];
  image->GetBounds(bounds);
  EXPECT_DOUBLE_EQ(bounds[0], -1.2);
  EXPECT_DOUBLE_EQ(bounds[1], 1.2);
  EXPECT_DOUBLE_EQ(bounds[5], 1.2);
  // The bundled sphere is 1 - |p|^2 too.
  vtkDataArray* f = image->GetPointData()->GetArray("f");
  for (vtkIdType i = 0; i < image->GetNumberOfPoints(); ++i)
  {
    double p[3];
    image->GetPoint(i, p);
    ASSERT_NEAR(f->GetComponent(i, 0), SphereF(p), 1e-6);
  }
}

TEST(FRepSampler, FlatAxisIsSampledOnce)
{
  const Expr x = Expr::x(), y = Expr::y();
  vtkNew<ictkFRepSampler> sampler;
  sampler->SetHypervolume(Hypervolume(Shape(Expr(4.0) - square(x) - square(y), Domain::XY)));
  sampler->SetModelBounds(-2, 2, -2, 2, 0, 0);
  sampler->SetSampleDimensions(9, 9, 9);
  sampler->Update();
  int dims[3];
  sampler->GetOutput()->GetDimensions(dims);
  EXPECT_EQ(dims[0], 9);
  EXPECT_EQ(dims[1], 9);
  EXPECT_EQ(dims[2], 1);
}

TEST(FRepSampler, AbortExecuteCancelsAndLeavesAnEmptyOutput)
{
  vtkNew<ictkFRepSampler> sampler;
  sampler->SetHypervolume(TestSphere());
  sampler->SetModelBounds(-1, 1, -1, 1, -1, 1);
  sampler->SetSampleDimensions(96, 96, 96);
  int events = 0;
  vtkNew<vtkCallbackCommand> abort;
  abort->SetClientData(&events);
  abort->SetCallback(
    [](vtkObject* caller, unsigned long, void* count, void*)
    {
      ++*static_cast<int*>(count);
      static_cast<vtkAlgorithm*>(caller)->SetAbortExecute(1);
    });
  const unsigned long tag = sampler->AddObserver(vtkCommand::ProgressEvent, abort);
  sampler->Update();
  EXPECT_GE(events, 1);
  EXPECT_EQ(sampler->GetOutput()->GetNumberOfPoints(), 0);

  // Without the abort request the same sampler runs to the end.
  sampler->RemoveObserver(tag);
  sampler->SetAbortExecute(0);
  sampler->Modified();
  sampler->Update();
  EXPECT_EQ(sampler->GetOutput()->GetNumberOfPoints(), 96 * 96 * 96);
}

TEST(FRepSampler, ProgressReachesOne)
{
  vtkNew<ictkFRepSampler> sampler;
  sampler->SetHypervolume(TestSphere());
  sampler->SetModelBounds(-1, 1, -1, 1, -1, 1);
  sampler->SetSampleDimensions(40, 40, 40);
  std::vector<double> seen;
  vtkNew<vtkCallbackCommand> record;
  record->SetClientData(&seen);
  record->SetCallback([](vtkObject*, unsigned long, void* list, void* progress)
    { static_cast<std::vector<double>*>(list)->push_back(*static_cast<double*>(progress)); });
  sampler->AddObserver(vtkCommand::ProgressEvent, record);
  sampler->Update();
  ASSERT_FALSE(seen.empty());
  EXPECT_DOUBLE_EQ(seen.back(), 1.0);
  for (std::size_t i = 1; i < seen.size(); ++i)
  {
    EXPECT_GE(seen[i], seen[i - 1]);
  }
}

TEST(FRepSampler, BadInputIsAnErrorNotACrash)
{
  struct Case
  {
    const char* what;
    std::function<void(ictkFRepSampler*)> setup;
    const char* message;
  };
  const std::vector<Case> cases{
    { "unknown model", [](ictkFRepSampler* s) { s->SetModelName("no-such-model"); },
      "unknown model 'no-such-model'" },
    { "no model", [](ictkFRepSampler*) {}, "no model" },
    { "zero dimensions",
      [](ictkFRepSampler* s)
      {
        s->SetModelName("sphere");
        s->SetSampleDimensions(0, 10, 10);
      },
      "at least 1" },
    { "too large",
      [](ictkFRepSampler* s)
      {
        s->SetModelName("sphere");
        s->SetSampleDimensions(100000, 100000, 100000);
      },
      "GB" },
    { "hypervolume without bounds", [](ictkFRepSampler* s) { s->SetHypervolume(TestSphere()); },
      "ModelBounds must be set" },
    { "missing parameters",
      [](ictkFRepSampler* s)
      {
        s->SetHypervolume(Hypervolume(Shape(Expr::parameter(0) - square(Expr::x()), Domain::XYZ)));
        s->SetModelBounds(-1, 1, -1, 1, -1, 1);
        s->SetSampleDimensions(4, 4, 4);
      },
      "parameter" },
  };
  for (const Case& c : cases)
  {
    vtkNew<ictkFRepSampler> sampler;
    ErrorRecorder errors;
    errors.Watch(sampler);
    errors.Watch(sampler->GetExecutive());
    c.setup(sampler);
    sampler->Update();
    EXPECT_TRUE(errors.Contains(c.message)) << c.what;
    EXPECT_EQ(sampler->GetOutput()->GetNumberOfPoints(), 0) << c.what;
  }
}

TEST(FRepSampler, ParametersReachTheModel)
{
  vtkNew<ictkFRepSampler> sampler;
  sampler->SetHypervolume(Hypervolume(Shape(Expr::parameter(0) - square(Expr::x()), Domain::XYZ)));
  sampler->SetParameters({ 3.0 });
  sampler->SetModelBounds(-1, 1, 0, 0, 0, 0);
  sampler->SetSampleDimensions(3, 1, 1);
  sampler->Update();
  vtkDataArray* f = sampler->GetOutput()->GetPointData()->GetArray("f");
  ASSERT_EQ(f->GetNumberOfTuples(), 3);
  EXPECT_FLOAT_EQ(static_cast<float>(f->GetComponent(0, 0)), 2.0f);
  EXPECT_FLOAT_EQ(static_cast<float>(f->GetComponent(1, 0)), 3.0f);
}

TEST(FRepImplicitFunction, NegatedValueAndGradient)
{
  vtkNew<ictkFRepImplicitFunction> function;
  function->SetHypervolume(TestSphere());
  ASSERT_TRUE(function->HasModel());
  for (const auto& q : std::vector<std::array<double, 3>>{
         { 0, 0, 0 }, { 0.3, -0.4, 0.5 }, { 1.5, 2, -1 }, { -0.25, 0.125, 0.9 } })
  {
    double p[3] = { q[0], q[1], q[2] };
    EXPECT_NEAR(function->FunctionValue(p), -SphereF(p), 1e-14);
    double g[3];
    function->FunctionGradient(p, g);
    for (int a = 0; a < 3; ++a)
    {
      EXPECT_NEAR(g[a], 2 * p[a], 1e-14);
    }
  }
}

TEST(FRepImplicitFunction, ConcurrentEvaluationMatchesSerial)
{
  vtkNew<ictkFRepImplicitFunction> function;
  function->SetModelName("walnut");
  ASSERT_TRUE(function->HasModel());
  constexpr vtkIdType N = 20000;
  auto point = [](vtkIdType i, double p[3])
  {
    p[0] = -1.3 + 2.6 * static_cast<double>(i % 37) / 36.0;
    p[1] = -1.3 + 2.6 * static_cast<double>((i / 37) % 23) / 22.0;
    p[2] = -1.3 + 2.6 * static_cast<double>(i % 101) / 100.0;
  };
  std::vector<double> serial(N), parallel(N);
  for (vtkIdType i = 0; i < N; ++i)
  {
    double p[3];
    point(i, p);
    serial[static_cast<std::size_t>(i)] = function->EvaluateFunction(p);
  }
  vtkSMPTools::For(0, N, 64,
    [&](vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType i = begin; i < end; ++i)
      {
        double p[3];
        point(i, p);
        parallel[static_cast<std::size_t>(i)] = function->EvaluateFunction(p);
        double g[3];
        function->EvaluateGradient(p, g);
      }
    });
  EXPECT_EQ(serial, parallel);
}

TEST(FRepImplicitFunction, UnknownModelIsAnErrorAndEmpty)
{
  vtkNew<ictkFRepImplicitFunction> function;
  ErrorRecorder errors;
  errors.Watch(function);
  function->SetModelName("no-such-model");
  EXPECT_TRUE(errors.Contains("unknown model"));
  EXPECT_FALSE(function->HasModel());
  double p[3] = { 0, 0, 0 };
  EXPECT_GT(function->FunctionValue(p), 0.0);
}

TEST(FRepImplicitFunction, TimeDependentModel)
{
  // f = t - x: inside where x <= t.
  vtkNew<ictkFRepImplicitFunction> function;
  function->SetHypervolume(Hypervolume(Shape(Expr::t() - Expr::x(), Domain::XYZT)));
  double p[3] = { 0.25, 0, 0 };
  function->SetTime(1.0);
  EXPECT_DOUBLE_EQ(function->FunctionValue(p), -0.75);
  function->SetTime(0.0);
  EXPECT_DOUBLE_EQ(function->FunctionValue(p), 0.25);
}

TEST(FRepImplicitFunction, ClipsAPlaneToTheUnitDisk)
{
  vtkNew<ictkFRepImplicitFunction> function;
  function->SetModelName("sphere");
  vtkNew<vtkPlaneSource> plane;
  plane->SetOrigin(-2, -2, 0);
  plane->SetPoint1(2, -2, 0);
  plane->SetPoint2(-2, 2, 0);
  plane->SetResolution(200, 200);
  vtkNew<vtkClipPolyData> clip;
  clip->SetInputConnection(plane->GetOutputPort());
  clip->SetClipFunction(function);
  clip->InsideOutOn(); // keep the negative side: the inside in VTK's convention
  vtkNew<vtkTriangleFilter> triangles;
  triangles->SetInputConnection(clip->GetOutputPort());
  vtkNew<vtkMassProperties> mass;
  mass->SetInputConnection(triangles->GetOutputPort());
  mass->Update();
  EXPECT_NEAR(mass->GetSurfaceArea(), M_PI, 0.01 * M_PI);
}

TEST(QuadricToVtk, ValuesAreMinusFAtRandomPoints)
{
  // papers.md 5.B item 25: a0..a9 = (A11, A22, A33, A12, A23, A13, A14, A24, A34, A44) negated;
  // vtkQuadric's value is -F at 100 random points.
  const std::array<double, 10> k{ 1.5, -2, 0.5, 0.3, -0.7, 1.1, 3, -4, 0.25, 0.2 };
  const ictk::frep::Expr f = ictk::frep::quadric(k).function();
  const vtkSmartPointer<vtkQuadric> vtk = ictkQuadricToVtk(k);
  std::mt19937_64 rng(25);
  std::uniform_real_distribution<double> u(-3, 3);
  for (int i = 0; i < 100; ++i)
  {
    double p[3] = { u(rng), u(rng), u(rng) };
    const double value = ictk::frep::evaluateReference(f, { p[0], p[1], p[2], 0 });
    EXPECT_NEAR(vtk->EvaluateFunction(p), -value, 1e-12 * (1 + std::abs(value)));
  }
}
