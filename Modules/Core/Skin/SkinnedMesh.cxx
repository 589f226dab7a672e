// SPDX-License-Identifier: BSD-3-Clause
#include "Skin/SkinnedMesh.h"

#include "Discretize/MeshRepair.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

namespace ictk::skin
{

namespace
{

std::string where(const SkinnedMesh& mesh)
{
  return mesh.file.empty() ? std::string("skinned mesh") : mesh.file;
}

[[noreturn]] void fail(const SkinnedMesh& mesh, const std::string& what)
{
  throw std::invalid_argument(where(mesh) + ": " + what);
}

Quaternion normalized(const Quaternion& q)
{
  double n = std::sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
  if (!(n > 0))
    return Quaternion{};
  return { q.w / n, q.x / n, q.y / n, q.z / n };
}

/// The index of the key before `time` and the fraction of the way to the next one; the end keys
/// hold outside the keys' range.
template <class Key>
std::pair<std::size_t, double> bracket(const std::vector<Key>& keys, double time)
{
  auto after = std::upper_bound(
    keys.begin(), keys.end(), time, [](double t, const Key& k) { return t < k.time; });
  if (after == keys.begin())
    return { 0, 0.0 };
  if (after == keys.end())
    return { keys.size() - 1, 0.0 };
  std::size_t i = static_cast<std::size_t>(after - keys.begin()) - 1;
  double span = keys[i + 1].time - keys[i].time;
  return { i, span > 0 ? (time - keys[i].time) / span : 0.0 };
}

Vec3 sample(const std::vector<VectorKey>& keys, double time, const Vec3& none)
{
  if (keys.empty())
    return none;
  auto [i, s] = bracket(keys, time);
  if (s == 0.0)
    return keys[i].value;
  return frep::lerp(keys[i].value, keys[i + 1].value, s);
}

Quaternion sample(const std::vector<RotationKey>& keys, double time)
{
  if (keys.empty())
    return Quaternion{};
  auto [i, s] = bracket(keys, time);
  if (s == 0.0)
    return normalized(keys[i].value);
  return slerp(keys[i].value, keys[i + 1].value, s);
}

/// T(p) R(q) S(s).
Affine localTransform(const Channel& c, double ticks)
{
  Vec3 p = sample(c.positions, ticks, { 0, 0, 0 });
  Vec3 s = sample(c.scales, ticks, { 1, 1, 1 });
  Affine m = rotationOf(sample(c.rotations, ticks));
  for (int row = 0; row < 3; ++row)
    for (int col = 0; col < 3; ++col)
      m.a[3 * row + col] *= s[col];
  m.b = p;
  return m;
}

/// The inverse transpose of a 3x3 row-major matrix; throws for a singular one.
std::array<double, 9> inverseTranspose(const std::array<double, 9>& a)
{
  // The cofactor matrix over the determinant is the inverse transpose.
  std::array<double, 9> c = {
    a[4] * a[8] - a[5] * a[7],
    a[5] * a[6] - a[3] * a[8],
    a[3] * a[7] - a[4] * a[6],
    a[2] * a[7] - a[1] * a[8],
    a[0] * a[8] - a[2] * a[6],
    a[1] * a[6] - a[0] * a[7],
    a[1] * a[5] - a[2] * a[4],
    a[2] * a[3] - a[0] * a[5],
    a[0] * a[4] - a[1] * a[3],
  };
  double det = a[0] * c[0] + a[1] * c[1] + a[2] * c[2];
  if (det == 0 || !std::isfinite(det))
    throw std::invalid_argument("skinning: a vertex's blended joint matrix is singular");
  for (double& v : c)
    v /= det;
  return c;
}

} // namespace

Affine rotationOf(const Quaternion& quaternion)
{
  Quaternion q = normalized(quaternion);
  double w = q.w, x = q.x, y = q.y, z = q.z;
  Affine m;
  m.a = {
    1 - 2 * (y * y + z * z),
    2 * (x * y - w * z),
    2 * (x * z + w * y),
    2 * (x * y + w * z),
    1 - 2 * (x * x + z * z),
    2 * (y * z - w * x),
    2 * (x * z - w * y),
    2 * (y * z + w * x),
    1 - 2 * (x * x + y * y),
  };
  return m;
}

Quaternion slerp(const Quaternion& from, const Quaternion& to, double s)
{
  Quaternion a = normalized(from), b = normalized(to);
  double cosine = a.w * b.w + a.x * b.x + a.y * b.y + a.z * b.z;
  if (cosine < 0) // q and -q are the same rotation: take the shorter arc
  {
    cosine = -cosine;
    b = { -b.w, -b.x, -b.y, -b.z };
  }
  double ka = 1 - s, kb = s;
  if (cosine < 1 - 1e-12)
  {
    double angle = std::acos(std::min(1.0, cosine));
    double sine = std::sin(angle);
    ka = std::sin((1 - s) * angle) / sine;
    kb = std::sin(s * angle) / sine;
  }
  return normalized(
    { ka * a.w + kb * b.w, ka * a.x + kb * b.x, ka * a.y + kb * b.y, ka * a.z + kb * b.z });
}

const Animation& SkinnedMesh::animation(const std::string& name) const
{
  std::string names;
  for (const Animation& a : animations)
  {
    if (a.name == name)
      return a;
    names += (names.empty() ? "'" : ", '") + a.name + "'";
  }
  fail(*this,
    "no animation named '" + name + "' (" +
      (animations.empty() ? std::string("the file has no animation") : "it has " + names) + ")");
}

std::size_t splitNonManifoldVertices(SkinnedMesh& mesh)
{
  discretize::SurfaceMesh surface;
  surface.points = mesh.restPoints;
  for (const auto& t : mesh.triangles)
    surface.triangles.push_back({ static_cast<std::uint32_t>(t[0]),
      static_cast<std::uint32_t>(t[1]), static_cast<std::uint32_t>(t[2]) });
  const std::vector<std::uint32_t> copied = discretize::splitNonManifoldVertices(surface);
  // A copy is the same vertex for skinning: its normal and influences too.
  for (const std::uint32_t v : copied)
  {
    mesh.restPoints.push_back(mesh.restPoints[v]);
    if (!mesh.restNormals.empty())
      mesh.restNormals.push_back(mesh.restNormals[v]);
    for (std::size_t k = mesh.influenceStart[v]; k < mesh.influenceStart[v + 1]; ++k)
      mesh.influences.push_back(mesh.influences[k]);
    mesh.influenceStart.push_back(mesh.influences.size());
  }
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k)
      mesh.triangles[t][static_cast<std::size_t>(k)] =
        static_cast<int>(surface.triangles[t][static_cast<std::size_t>(k)]);
  return copied.size();
}

std::vector<Influence> SkinnedMesh::dominantInfluences() const
{
  std::vector<Influence> out(vertexCount());
  for (std::size_t i = 0; i < vertexCount(); ++i)
    for (std::size_t k = influenceStart[i]; k < influenceStart[i + 1]; ++k)
      if (out[i].joint < 0 || influences[k].weight > out[i].weight)
        out[i] = influences[k];
  return out;
}

void SkinnedMesh::validate() const
{
  for (std::size_t n = 0; n < nodes.size(); ++n)
    if (nodes[n].parent >= static_cast<int>(n) || nodes[n].parent < -1)
      fail(*this, "node '" + nodes[n].name + "' comes before its parent");
  for (const Joint& j : joints)
    if (j.node < 0 || j.node >= static_cast<int>(nodes.size()))
      fail(*this, "a joint names no node");
  if (!restNormals.empty() && restNormals.size() != restPoints.size())
    fail(*this, "the normals are not one per vertex");
  if (influenceStart.size() != restPoints.size() + 1 || influenceStart.back() != influences.size())
    fail(*this, "the skinning weights are not one list per vertex");
  for (const auto& t : triangles)
    for (int v : t)
      if (v < 0 || v >= static_cast<int>(restPoints.size()))
        fail(*this, "a triangle's corner is not a vertex");
  for (std::size_t i = 0; i < restPoints.size(); ++i)
  {
    if (influenceStart[i + 1] <= influenceStart[i])
      fail(*this, "vertex " + std::to_string(i) + " has no joint");
    for (std::size_t k = influenceStart[i]; k < influenceStart[i + 1]; ++k)
    {
      const Influence& f = influences[k];
      if (f.joint < 0 || f.joint >= static_cast<int>(joints.size()))
        fail(*this, "vertex " + std::to_string(i) + " names no joint");
      if (!(f.weight >= 0) || !std::isfinite(f.weight))
        fail(*this, "vertex " + std::to_string(i) + " has a negative or non-finite weight");
    }
  }
  for (const Animation& a : animations)
    for (const Channel& c : a.channels)
      if (c.node < 0 || c.node >= static_cast<int>(nodes.size()))
        fail(*this, "animation '" + a.name + "' animates no node");
}

std::vector<Affine> poseNodes(const SkinnedMesh& mesh, const Animation* animation, double seconds)
{
  std::vector<Affine> locals(mesh.nodes.size());
  for (std::size_t n = 0; n < mesh.nodes.size(); ++n)
    locals[n] = mesh.nodes[n].local;
  if (animation)
  {
    double ticks = seconds * animation->ticksPerSecond;
    for (const Channel& c : animation->channels)
      locals[static_cast<std::size_t>(c.node)] = localTransform(c, ticks);
  }
  std::vector<Affine> globals(mesh.nodes.size());
  for (std::size_t n = 0; n < mesh.nodes.size(); ++n)
  {
    int parent = mesh.nodes[n].parent;
    globals[n] = parent < 0 ? locals[n] : globals[static_cast<std::size_t>(parent)] * locals[n];
  }
  return globals;
}

std::vector<Bone> bonesOf(const SkinnedMesh& mesh)
{
  std::map<int, int> jointOfNode;
  for (std::size_t j = 0; j < mesh.joints.size(); ++j)
    jointOfNode.emplace(mesh.joints[j].node, static_cast<int>(j));
  std::vector<Bone> out;
  for (std::size_t j = 0; j < mesh.joints.size(); ++j)
  {
    int parent = mesh.nodes[static_cast<std::size_t>(mesh.joints[j].node)].parent;
    while (parent >= 0 && !jointOfNode.count(parent))
      parent = mesh.nodes[static_cast<std::size_t>(parent)].parent;
    if (parent >= 0)
      out.push_back({ jointOfNode.at(parent), static_cast<int>(j) });
  }
  return out;
}

Vec3 jointMarker(const SkinnedMesh& mesh, int joint)
{
  return mesh.joints[static_cast<std::size_t>(joint)].offset.inverse().b;
}

std::vector<Affine> jointMatrices(const SkinnedMesh& mesh, const std::vector<Affine>& globals)
{
  std::vector<Affine> out;
  out.reserve(mesh.joints.size());
  for (const Joint& j : mesh.joints)
    out.push_back(globals[static_cast<std::size_t>(j.node)] * j.offset);
  return out;
}

Posed skin(const SkinnedMesh& mesh, const std::vector<Affine>& matrices)
{
  return skin(mesh, matrices, mesh.restPoints);
}

Posed skin(
  const SkinnedMesh& mesh, const std::vector<Affine>& matrices, const std::vector<Vec3>& restPoints)
{
  return skin(mesh, matrices, restPoints, mesh.restNormals);
}

Posed skin(const SkinnedMesh& mesh, const std::vector<Affine>& matrices,
  const std::vector<Vec3>& restPoints, const std::vector<Vec3>& restNormals)
{
  if (restPoints.size() != mesh.vertexCount())
    throw std::invalid_argument("skin: " + std::to_string(restPoints.size()) +
      " rest points for a mesh of " + std::to_string(mesh.vertexCount()) + " vertices");
  if (!restNormals.empty() && restNormals.size() != mesh.vertexCount())
    throw std::invalid_argument("skin: " + std::to_string(restNormals.size()) +
      " rest normals for a mesh of " + std::to_string(mesh.vertexCount()) + " vertices");
  Posed out;
  std::size_t count = mesh.vertexCount();
  out.points.resize(count);
  if (!restNormals.empty())
    out.normals.resize(count);
  for (std::size_t i = 0; i < count; ++i)
  {
    Affine blended;
    blended.a.fill(0);
    for (std::size_t k = mesh.influenceStart[i]; k < mesh.influenceStart[i + 1]; ++k)
    {
      const Influence& f = mesh.influences[k];
      const Affine& m = matrices[static_cast<std::size_t>(f.joint)];
      for (int e = 0; e < 9; ++e)
        blended.a[e] += f.weight * m.a[e];
      for (int e = 0; e < 3; ++e)
        blended.b[e] += f.weight * m.b[e];
    }
    out.points[i] = blended.apply(restPoints[i]);
    if (!out.normals.empty())
    {
      Affine normalMap;
      normalMap.a = inverseTranspose(blended.a);
      Vec3 n = normalMap.applyLinear(restNormals[i]);
      double length = frep::norm(n);
      out.normals[i] = length > 0 ? frep::scale(n, 1 / length) : n;
    }
  }
  return out;
}

Posed pose(const SkinnedMesh& mesh, const Animation* animation, double seconds)
{
  return skin(mesh, jointMatrices(mesh, poseNodes(mesh, animation, seconds)));
}

} // namespace ictk::skin
