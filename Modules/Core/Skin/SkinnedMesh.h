// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Skinned meshes as data (issue 17; thesis 5.4 "input", L3217): a triangle mesh with a rigging
// skeleton, per-vertex skinning weights and key-framed joint transforms, and the linear blend
// skinning that poses it at an instant. The characters of the thesis (Andy, the zebra of 5.5) are
// such meshes; SkinFile.h reads them from the files animators write (.x, .gltf, .fbx, ... through
// Assimp). Nothing here knows files, cells or time spans: the engine and the tests build on it.
//
// Conventions (those of the files it reads):
// - The node hierarchy is a tree; every node has a local transform relative to its parent, and its
//   global transform is the product of the local ones from the root. `nodes` lists parents before
//   children.
// - A joint is a node that deforms vertices, with its offset matrix (the inverse of the joint's
//   global transform in the bind pose, in the world frame of `restPoints`). At an instant, joint j
//   moves a vertex by its skinning matrix M_j = G_j(t) * offset_j.
// - Linear blend skinning: p'_i = sum_j w_ij M_j p_i; the weights of a vertex are non-negative
//   and sum to 1 (the reader normalises them). Normals: n'_i = normalize(A^-T n_i) with A the
//   linear part of sum_j w_ij M_j: the inverse transpose, not the M_j^-1 printed in the thesis'
//   5.5 formula (L3418, an erratum: M^-1 turns normals backwards, and only the inverse transpose
//   keeps them normal to the surface under a non-uniform scale).
// - An animation is a set of channels, each animating one node's local transform by position,
//   rotation (unit quaternion) and scale keys on a time axis of ticks; a node without a channel
//   keeps its bind-pose local transform. Between keys, positions and scales are interpolated
//   linearly and rotations spherically (slerp on the shorter arc); before the first key and after
//   the last one the end key holds. Seconds become ticks by `ticksPerSecond`.

#include "Geometry/PlacedShape.h"

#include <array>
#include <cstddef>
#include <string>
#include <vector>

namespace ictk::skin
{

using geometry::Affine;
using geometry::Vec3;

/// A rotation as a unit quaternion w + x i + y j + z k.
struct Quaternion
{
  double w = 1, x = 0, y = 0, z = 0;
};

/// The rotation matrix of q (normalised first; a zero quaternion is the identity).
Affine rotationOf(const Quaternion& q);
/// Spherical linear interpolation from a (s = 0) to b (s = 1) on the shorter arc; normalised.
Quaternion slerp(const Quaternion& a, const Quaternion& b, double s);

struct VectorKey
{
  double time = 0; ///< ticks
  Vec3 value{ 0, 0, 0 };
};

struct RotationKey
{
  double time = 0; ///< ticks
  Quaternion value;
};

/// The keys of one node's local transform: T(position) R(rotation) S(scale). A list with no key
/// leaves that component at the identity.
struct Channel
{
  int node = -1;
  std::vector<VectorKey> positions;
  std::vector<RotationKey> rotations;
  std::vector<VectorKey> scales;
};

struct Animation
{
  std::string name;
  double duration = 0;        ///< ticks
  double ticksPerSecond = 25; ///< the file's, or 25 when it gives none
  std::vector<Channel> channels;

  double durationSeconds() const { return duration / ticksPerSecond; }
};

struct Node
{
  std::string name;
  int parent = -1; ///< -1 for the root; always before this node in `nodes`
  Affine local;    ///< the bind pose's local transform
};

struct Joint
{
  int node = -1;
  Affine offset; ///< world (rest mesh) frame -> the joint's frame in the bind pose
};

/// One influence of a joint on a vertex.
struct Influence
{
  int joint = -1;
  double weight = 0;
};

struct SkinnedMesh
{
  std::string file; ///< where it was read from, for messages ("" when built in memory)
  std::vector<Node> nodes;
  std::vector<Joint> joints;
  std::vector<Vec3> restPoints;  ///< the rest mesh, in the world frame of the bind pose
  std::vector<Vec3> restNormals; ///< unit; empty when the file has none
  std::vector<std::array<int, 3>> triangles;
  /// The influences of vertex i are influences[influenceStart[i] .. influenceStart[i + 1]).
  std::vector<std::size_t> influenceStart{ 0 };
  std::vector<Influence> influences;
  std::vector<Animation> animations;

  std::size_t vertexCount() const { return restPoints.size(); }
  /// The animation called `name`; throws std::invalid_argument naming the file and the
  /// animations there are when none is.
  const Animation& animation(const std::string& name) const;
  /// The joint of the largest weight on each vertex and that weight (the first on a tie).
  std::vector<Influence> dominantInfluences() const;
  /// Throws std::invalid_argument (naming the file) when an index is out of range, a parent is
  /// not before its child, a weight is negative or not finite, or a vertex has no influence.
  void validate() const;
};

/// Makes the surface a manifold where only corners are shared: a vertex that joins separate fans
/// of triangles (patches of a character touching at one corner, left by its texture seams, as in
/// BCN_Epileptic.X) gets a copy per extra fan (discretize::splitNonManifoldVertices) carrying its
/// normal and influences, so the surface and its skinning do not change; the copies are appended
/// after the file's vertices. Returns how many vertices were added. A B-cell needs this
/// (complex::checkCell); the counts of the file (`assimp info`) are those before it.
std::size_t splitNonManifoldVertices(SkinnedMesh& mesh);

/// A bone of the rigging skeleton: a joint and its parent joint (the joint of its node's nearest
/// ancestor that is one), as indices into SkinnedMesh::joints.
struct Bone
{
  int parentJoint = -1;
  int joint = -1;
};

/// Every bone, in the order of the joints (a root joint has none).
std::vector<Bone> bonesOf(const SkinnedMesh& mesh);
/// Joint j's marker: its origin in the rest mesh's frame (offset_j^-1 applied to the origin).
Vec3 jointMarker(const SkinnedMesh& mesh, int joint);

/// The global transforms of every node at `seconds` into `animation` (nullptr: the bind pose).
std::vector<Affine> poseNodes(const SkinnedMesh& mesh, const Animation* animation, double seconds);
/// The skinning matrices M_j = G_j * offset_j of every joint, given the nodes' global transforms.
std::vector<Affine> jointMatrices(const SkinnedMesh& mesh, const std::vector<Affine>& globals);

/// A posed mesh: the rest mesh's triangles over these points and normals.
struct Posed
{
  std::vector<Vec3> points;
  std::vector<Vec3> normals; ///< empty when the mesh has no normals
};

/// Linear blend skinning of the rest mesh by the given skinning matrices (one per joint).
Posed skin(const SkinnedMesh& mesh, const std::vector<Affine>& jointMatrices);
/// The same with other rest points (one per vertex) in place of the rest mesh's: thesis 5.5's
/// p'_i(t) = sum_j w_ij M_j(t) f_alpha(p_i, p_i + dp_i) for vertices moved in the bind pose.
Posed skin(const SkinnedMesh& mesh, const std::vector<Affine>& jointMatrices,
  const std::vector<Vec3>& restPoints);
/// The same with other rest normals too (thesis 5.5's n'_i(t), L3418, for normals turned in the
/// bind pose); `restNormals` empty: none.
Posed skin(const SkinnedMesh& mesh, const std::vector<Affine>& jointMatrices,
  const std::vector<Vec3>& restPoints, const std::vector<Vec3>& restNormals);
/// The mesh posed at `seconds` into `animation` (nullptr: the bind pose).
Posed pose(const SkinnedMesh& mesh, const Animation* animation, double seconds);

} // namespace ictk::skin
