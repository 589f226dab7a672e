// SPDX-License-Identifier: BSD-3-Clause
// The projection of a skinned mesh onto its stand-in (issue 17; thesis 5.5, T-5.5 of
// ../shared/spec/thesis_ch5_6.md): g_alpha for normals and their inverse transpose under a
// non-uniformly scaled joint (item 6) by hand, the per-vertex delays of a weight map (item 5), the
// posed remainder that puts every vertex on the posed stand-in at alpha = 1 (item 1), and the
// solver's report (item 7).

#include "Skin/Projection.h"

#include "FRep/Tape.h"

#include "SkinnedTube.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace ictk::skin;

namespace
{

const double pi = std::acos(-1.0);

void expectNear(const Vec3& got, const Vec3& want, double tolerance, const std::string& what)
{
  for (int i = 0; i < 3; ++i)
    EXPECT_NEAR(got[i], want[i], tolerance) << what << " component " << i;
}

double length(const Vec3& v)
{
  return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

Affine rotationZ(double angle)
{
  return rotationOf({ std::cos(angle / 2), 0, 0, std::sin(angle / 2) });
}

/// The rotation by `angle` about the x axis through the point (0, 0, z).
Affine turnAboutX(double angle, double z)
{
  Affine r = rotationOf({ std::cos(angle / 2), std::sin(angle / 2), 0, 0 });
  r.b = { 0, 0, 0 };
  const Vec3 moved = r.apply({ 0, 0, z });
  r.b = { 0, -moved[1], z - moved[2] };
  return r;
}

/// One triangle on the plane x + y = 1 with the normals (1, 1, 0)/sqrt 2, on one joint.
SkinnedMesh oneJointTriangle()
{
  SkinnedMesh m;
  m.nodes = { { "root", -1, {} }, { "a", 0, {} } };
  m.joints = { { 1, {} } };
  m.restPoints = { { 1, 0, 0 }, { 0, 1, 0 }, { 1, 0, 1 } };
  const double s = 1 / std::sqrt(2.0);
  m.restNormals.assign(3, Vec3{ s, s, 0 });
  m.triangles = { { 0, 1, 2 } };
  for (int i = 0; i < 3; ++i)
  {
    m.influences.push_back({ 0, 1.0 });
    m.influenceStart.push_back(m.influences.size());
  }
  m.validate();
  return m;
}

SkinnedMesh tube()
{
  return fixtures::skinnedTube(24, 7);
}

/// The tube's stand-in, thinner than the tube (radius 0.2) so that every vertex has 0.1 to go.
StandIn thinStandIn(const SkinnedMesh& m)
{
  StandIn s = initialStandIn(m);
  s.segments.at(0).radius = 0.2;
  return s;
}

ictk::frep::FieldPtr fieldOf(const StandIn& s)
{
  return ictk::frep::tapeField(ictk::frep::Tape::compile(standInShape(s).function()), 0.0, {});
}

/// |F| / |grad F| at every point.
std::vector<double> distances(const ictk::frep::Field& f, const std::vector<Vec3>& points)
{
  const auto e = f.evaluator();
  std::vector<double> out;
  for (const Vec3& p : points)
  {
    Vec3 g{ 0, 0, 0 };
    const double v = e->gradient(p, g);
    out.push_back(std::abs(v) / length(g));
  }
  return out;
}

} // namespace

TEST(Projection, SlerpOfDirections)
{
  // Halfway from x to y is their bisector; a third of the way, 30 degrees from x.
  expectNear(slerpDirection({ 1, 0, 0 }, { 0, 1, 0 }, 0.5), { std::sqrt(0.5), std::sqrt(0.5), 0 },
    1e-15, "bisector");
  expectNear(slerpDirection({ 1, 0, 0 }, { 0, 1, 0 }, 1.0 / 3), { std::cos(pi / 6), 0.5, 0 }, 1e-15,
    "a third");
  // The ends are the vectors themselves, bit for bit.
  EXPECT_EQ(slerpDirection({ 1, 0, 0 }, { 0, 0.6, 0.8 }, 0), (Vec3{ 1, 0, 0 }));
  EXPECT_EQ(slerpDirection({ 1, 0, 0 }, { 0, 0.6, 0.8 }, 1), (Vec3{ 0, 0.6, 0.8 }));
  // Opposite vectors: halfway is a unit vector normal to both (the lerp would be 0).
  const Vec3 h = slerpDirection({ 0, 0, 1 }, { 0, 0, -1 }, 0.5);
  EXPECT_NEAR(length(h), 1, 1e-15);
  EXPECT_NEAR(h[2], 0, 1e-15);
}

TEST(Projection, GAlphaAndTheInverseTransposeUnderANonUniformScale)
{
  // One joint A = Rz(90) diag(2, 1, 1); every vertex projected by (0, 0, 1) with the stand-in's
  // normal (0, 0, 1) there; n = (1, 1, 0)/sqrt 2.
  SkinnedMesh m = oneJointTriangle();
  Projection p;
  p.offsets.assign(3, Vec3{ 0, 0, 1 });
  p.standInNormals.assign(3, Vec3{ 0, 0, 1 });
  Affine scale;
  scale.a = { 2, 0, 0, 0, 1, 0, 0, 0, 1 };
  const Affine joint = rotationZ(pi / 2) * scale;
  // alpha = 1/2: g = slerp(n, ñ, 1/2) = cos 45 n + sin 45 ñ = (1/2, 1/2, 1/sqrt 2) (n and ñ are
  // 90 degrees apart). A^-T = Rz(90) diag(1/2, 1, 1): (1/4, 1/2, 1/sqrt 2), turned to
  // (-1/2, 1/4, 1/sqrt 2), over its length sqrt(13/16) = 0.901388. (The thesis' M^-1 =
  // diag(1/2, 1, 1) Rz(-90) would give (1/4, -1/2, 1/sqrt 2)/|.|, M itself (-1/2, 1, 1/sqrt
  // 2)/|.|.)
  const Posed half = skinProjected(m, p, { joint }, { 0.5, 0.5, 0.5 });
  const double k = std::sqrt(13.0 / 16);
  for (int i = 0; i < 3; ++i)
  {
    expectNear(half.normals[i], { -0.5 / k, 0.25 / k, std::sqrt(0.5) / k }, 1e-15, "half");
    EXPECT_NEAR(length(half.normals[i]), 1, 1e-15);
  }
  // The points: (1, 0, 0) + (0, 0, 1/2), scaled to (2, 0, 1/2), turned to (0, 2, 1/2).
  expectNear(half.points[0], { 0, 2, 0.5 }, 1e-15, "point");
  // alpha = 1: the stand-in's normal carried by A^-T, (0, 0, 1); alpha = 0: the skinned normal
  // A^-T n = Rz(90) (1/2, 1, 0)/|.| = (-1, 1/2, 0)/|.|.
  const Posed whole = skinProjected(m, p, { joint }, { 1, 1, 1 });
  expectNear(whole.normals[0], { 0, 0, 1 }, 1e-15, "alpha 1");
  const Posed none = skinProjected(m, p, { joint }, { 0, 0, 0 });
  const double j = std::sqrt(1.25);
  expectNear(none.normals[0], { -1 / j, 0.5 / j, 0 }, 1e-15, "alpha 0");
  // The turned normal stays normal to the skinned triangle's edges at alpha = 0.
  for (int e : { 1, 2 })
    EXPECT_NEAR(
      ictk::frep::dot(ictk::frep::sub(none.points[e], none.points[0]), none.normals[0]), 0, 1e-15);
}

TEST(Projection, DelaysFromAWeightMap)
{
  // Weights 0, 1, 2 with spread 1/2: windows start at 1/2, 1/4 and 0 and last 1/2.
  const std::vector<double> d = projectionDelays({ 0, 1, 2 }, 0.5);
  ASSERT_EQ(d.size(), 3u);
  EXPECT_DOUBLE_EQ(d[0], 0.5);
  EXPECT_DOUBLE_EQ(d[1], 0.25);
  EXPECT_DOUBLE_EQ(d[2], 0.0);
  EXPECT_DOUBLE_EQ(delayedAlpha(0.5, d[0], 0.5), 0.0);
  EXPECT_DOUBLE_EQ(delayedAlpha(0.5, d[1], 0.5), 0.5);
  EXPECT_DOUBLE_EQ(delayedAlpha(0.5, d[2], 0.5), 1.0);
  // The ends are exact for every vertex; the order of the weights is the order of alpha_i.
  for (double delay : d)
  {
    EXPECT_EQ(delayedAlpha(0, delay, 0.5), 0.0);
    EXPECT_EQ(delayedAlpha(1, delay, 0.5), 1.0);
    double before = 0;
    for (double a = 0; a <= 1; a += 1.0 / 64)
    {
      const double now = delayedAlpha(a, delay, 0.5);
      EXPECT_GE(now, before);
      before = now;
    }
  }
  for (double a = 0; a <= 1; a += 1.0 / 64)
    EXPECT_GE(delayedAlpha(a, d[2], 0.5), delayedAlpha(a, d[1], 0.5));
  // Equal weights, or spread 0: no delay.
  EXPECT_EQ(projectionDelays({ 3, 3 }, 0.5), (std::vector<double>{ 0, 0 }));
  EXPECT_EQ(delayedAlpha(0.3, 0.0, 0.0), 0.3);
  EXPECT_THROW(projectionDelays({ 0, 1 }, 1.0), std::invalid_argument);
  EXPECT_THROW(projectionDelays({ 0, std::nan("") }, 0.5), std::invalid_argument);
}

TEST(Projection, AtAlphaOneEveryVertexIsOnThePosedStandIn)
{
  const SkinnedMesh m = tube();
  const StandIn rest = thinStandIn(m);
  const Projection p = projectOntoStandIn(m, rest);
  EXPECT_EQ(p.failures, 0);
  EXPECT_LT(p.maxResidual, 1e-9);
  EXPECT_LE(p.iterations, 10);
  // Every vertex on the hip joint, but the segment's knee end turned 4 degrees about x through
  // the hip: skinning the bind-pose projection leaves the vertices off the posed stand-in.
  const std::vector<Affine> matrices = { Affine{}, turnAboutX(4 * pi / 180, -1.5) };
  const auto posedField = fieldOf(poseStandIn(rest, matrices));
  const std::vector<double> ones(m.vertexCount(), 1.0), zeros(m.vertexCount(), 0.0);
  const ProjectionResidual thesisOnly =
    projectionResidual(skinProjected(m, p, matrices, ones), *posedField);
  EXPECT_GT(thesisOnly.distance, 0.02);
  // With the posed remainder: on it, and the normals along the stand-in's.
  const ProjectedPose on = poseOnStandIn(m, p, matrices, ones, *posedField);
  EXPECT_EQ(on.failures, 0);
  const ProjectionResidual r = projectionResidual(on.posed, *posedField);
  EXPECT_LT(r.distance, 1e-9);
  EXPECT_LT(r.degrees, 1e-6);
  for (const Vec3& n : on.posed.normals)
    EXPECT_NEAR(length(n), 1, 1e-14);
  // Placed by a uniform scale of 2, the distance doubles and the angle stays.
  Affine twice;
  twice.a = { 2, 0, 0, 0, 2, 0, 0, 0, 2 };
  const ProjectionResidual scaled = projectionResidual(on.posed, *posedField, twice);
  EXPECT_NEAR(scaled.distance, 2 * r.distance, 1e-12);
  EXPECT_NEAR(scaled.degrees, r.degrees, 1e-9);
  // Alpha = 0 is the plain skinned mesh, bit for bit, with its normals.
  const ProjectedPose off = poseOnStandIn(m, p, matrices, zeros, *posedField);
  const Posed plain = skin(m, matrices, m.restPoints, restNormalsOf(m));
  EXPECT_EQ(off.posed.points, plain.points);
  EXPECT_EQ(off.posed.normals, plain.normals);
  // The tube's normals (none in the file) are its triangles': radial.
  const Vec3 n0 = restNormalsOf(m)[3 * 24];
  expectNear(n0, { 1, 0, 0 }, 1e-12, "radial normal");
}

TEST(Projection, AWeightMapOrdersTheCompletionTimes)
{
  // Weights z: the top ring first. alpha sweeps 0..1 in steps of 1/256; a vertex is done when
  // |F| < 1e-9 |grad F| on the posed stand-in (T-5.5 item 5).
  const SkinnedMesh m = tube();
  const StandIn rest = thinStandIn(m);
  const Projection p = projectOntoStandIn(m, rest);
  const std::vector<Affine> matrices = { Affine{}, turnAboutX(2 * pi / 180, -1.5) };
  const auto posedField = fieldOf(poseStandIn(rest, matrices));
  std::vector<double> weights;
  for (const Vec3& q : m.restPoints)
    weights.push_back(q[2]);
  const double spread = 0.5;
  const std::vector<double> delays = projectionDelays(weights, spread);
  const int steps = 256;
  std::vector<int> done(m.vertexCount(), -1);
  for (int s = 0; s <= steps; ++s)
  {
    const double alpha = double(s) / steps;
    std::vector<double> alphas;
    for (double d : delays)
      alphas.push_back(delayedAlpha(alpha, d, spread));
    const ProjectedPose pose = poseOnStandIn(m, p, matrices, alphas, *posedField);
    const std::vector<double> far = distances(*posedField, pose.posed.points);
    for (std::size_t i = 0; i < far.size(); ++i)
    {
      if (done[i] < 0 && far[i] < 1e-9)
        done[i] = s;
      // Done stays done as alpha rises.
      if (done[i] >= 0)
      {
        EXPECT_LT(far[i], 1e-9) << "vertex " << i << " at " << alpha;
      }
    }
  }
  // Every vertex is done by alpha = 1; the higher ring first, each at 1 - spread u_i (u_i its
  // weight scaled to [0, 1]): the top ring at 1/2, the bottom one at 1.
  for (std::size_t i = 0; i < m.vertexCount(); ++i)
  {
    ASSERT_GE(done[i], 0) << "vertex " << i;
    const double u = (m.restPoints[i][2] + 0.6) / 1.2;
    EXPECT_NEAR(double(done[i]) / steps, 1 - spread * u, 1.0 / steps) << "vertex " << i;
    for (std::size_t j = 0; j < m.vertexCount(); ++j)
      if (m.restPoints[i][2] > m.restPoints[j][2] + 1e-12)
      {
        ASSERT_LT(done[i], done[j]) << i << " above " << j;
      }
  }
}

TEST(Projection, TheSolverReportsTheVerticesItCannotProject)
{
  // Two Newton steps are not enough from 0.1 away: the failures are counted and the first named;
  // the default converges within 10.
  const SkinnedMesh m = tube();
  const StandIn rest = thinStandIn(m);
  ProjectionOptions few;
  few.maxIterations = 1;
  const Projection p = projectOntoStandIn(m, rest, few);
  EXPECT_EQ(p.failures, static_cast<int>(m.vertexCount()));
  EXPECT_EQ(p.firstFailure, 0u);
  EXPECT_GT(p.maxResidual, 1e-9);
  const Projection q = projectOntoStandIn(m, rest);
  EXPECT_EQ(q.failures, 0);
  EXPECT_LE(q.iterations, 10);
}
