// SPDX-License-Identifier: BSD-3-Clause
#include "Skin/SkinFile.h"

#include <filesystem>
#include <stdexcept>

#ifdef ICTK_HAVE_ASSIMP
#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <cmath>
#include <fstream>
#include <map>
#endif

namespace ictk::skin
{

#ifndef ICTK_HAVE_ASSIMP

bool canReadSkinnedMeshFiles()
{
  return false;
}

SkinnedMesh readSkinnedMesh(const std::string& path)
{
  throw std::runtime_error(path +
    ": cannot read skinned meshes: this ICTK was built without Assimp (configure with "
    "-DICTK_ENABLE_ASSIMP=ON and Debian's libassimp-dev)");
}

#else

namespace
{

[[noreturn]] void fail(const std::string& path, const std::string& what)
{
  throw std::runtime_error(path + ": " + what);
}

Affine affineOf(const aiMatrix4x4& m)
{
  Affine a;
  a.a = { m.a1, m.a2, m.a3, m.b1, m.b2, m.b3, m.c1, m.c2, m.c3 };
  a.b = { m.a4, m.b4, m.c4 };
  return a;
}

Vec3 vec(const aiVector3D& v)
{
  return { v.x, v.y, v.z };
}

bool nearlyEqual(const Affine& p, const Affine& q)
{
  // The files store single precision: offsets that agree to it are one joint.
  for (int i = 0; i < 9; ++i)
    if (std::abs(p.a[i] - q.a[i]) > 1e-5 * (1 + std::abs(p.a[i])))
      return false;
  for (int i = 0; i < 3; ++i)
    if (std::abs(p.b[i] - q.b[i]) > 1e-5 * (1 + std::abs(p.b[i])))
      return false;
  return true;
}

class SceneReader
{
public:
  SceneReader(const std::string& path, const aiScene& scene)
    : path_(path)
    , scene_(scene)
  {
    out_.file = path;
  }

  SkinnedMesh read()
  {
    addNode(*scene_.mRootNode, -1);
    std::vector<Affine> globals = poseNodes(out_, nullptr, 0);
    for (std::size_t n = 0; n < nodesAi_.size(); ++n)
      for (unsigned k = 0; k < nodesAi_[n]->mNumMeshes; ++k)
        addMesh(static_cast<int>(n), *scene_.mMeshes[nodesAi_[n]->mMeshes[k]], globals[n]);
    if (out_.triangles.empty())
      fail(path_, "has no triangle mesh");
    for (unsigned a = 0; a < scene_.mNumAnimations; ++a)
      addAnimation(*scene_.mAnimations[a]);
    out_.validate();
    return std::move(out_);
  }

private:
  void addNode(const aiNode& node, int parent)
  {
    int index = static_cast<int>(out_.nodes.size());
    out_.nodes.push_back({ node.mName.C_Str(), parent, affineOf(node.mTransformation) });
    nodesAi_.push_back(&node);
    byName_.emplace(node.mName.C_Str(), index); // the first of a name, as Assimp's FindNode
    for (unsigned c = 0; c < node.mNumChildren; ++c)
      addNode(*node.mChildren[c], index);
  }

  int nodeNamed(const std::string& name, const std::string& what) const
  {
    auto it = byName_.find(name);
    if (it == byName_.end())
      fail(path_, what + " '" + name + "' names no node of the scene");
    return it->second;
  }

  int jointFor(int node, const Affine& offset)
  {
    for (std::size_t j = 0; j < out_.joints.size(); ++j)
      if (out_.joints[j].node == node && nearlyEqual(out_.joints[j].offset, offset))
        return static_cast<int>(j);
    out_.joints.push_back({ node, offset });
    return static_cast<int>(out_.joints.size()) - 1;
  }

  void addMesh(int node, const aiMesh& mesh, const Affine& nodeGlobal)
  {
    int first = static_cast<int>(out_.restPoints.size());
    unsigned count = mesh.mNumVertices;
    // A skinned mesh is posed by its bones alone, whose offsets map its own coordinates: its
    // node's transform does not apply (Assimp's convention and glTF's rule). A mesh without
    // bones is placed by its node.
    Affine global = mesh.mNumBones > 0 ? Affine{} : nodeGlobal;
    std::vector<std::vector<Influence>> weights(count);
    for (unsigned b = 0; b < mesh.mNumBones; ++b)
    {
      const aiBone& bone = *mesh.mBones[b];
      int joint = jointFor(nodeNamed(bone.mName.C_Str(), "bone"), affineOf(bone.mOffsetMatrix));
      for (unsigned w = 0; w < bone.mNumWeights; ++w)
      {
        const aiVertexWeight& vw = bone.mWeights[w];
        if (vw.mVertexId >= count)
          fail(path_,
            "bone '" + std::string(bone.mName.C_Str()) + "' weighs a vertex not in its mesh");
        if (vw.mWeight != 0)
          weights[vw.mVertexId].push_back({ joint, vw.mWeight });
      }
    }
    // A vertex no bone weighs follows the mesh's node: G(t) G_bind^-1 maps its rest position.
    Affine toNode = nodeGlobal.inverse();
    bool hasNormals = mesh.HasNormals() && (first == 0 || !out_.restNormals.empty());
    if (!hasNormals)
      out_.restNormals.clear();
    Affine normalMap;
    if (hasNormals)
    {
      // Normals go by the inverse transpose of the linear part.
      Affine inverse = global.inverse();
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
          normalMap.a[3 * r + c] = inverse.a[3 * c + r];
    }
    for (unsigned v = 0; v < count; ++v)
    {
      out_.restPoints.push_back(global.apply(vec(mesh.mVertices[v])));
      if (hasNormals)
      {
        Vec3 n = normalMap.applyLinear(vec(mesh.mNormals[v]));
        double length = frep::norm(n);
        out_.restNormals.push_back(length > 0 ? frep::scale(n, 1 / length) : n);
      }
      double sum = 0;
      for (const Influence& f : weights[v])
        sum += f.weight;
      if (!(sum > 0))
        weights[v] = { { jointFor(node, toNode), 1.0 } };
      else
        for (Influence& f : weights[v])
          f.weight /= sum;
      out_.influences.insert(out_.influences.end(), weights[v].begin(), weights[v].end());
      out_.influenceStart.push_back(out_.influences.size());
    }
    for (unsigned f = 0; f < mesh.mNumFaces; ++f)
    {
      const aiFace& face = mesh.mFaces[f];
      if (face.mNumIndices == 3)
        out_.triangles.push_back({ first + static_cast<int>(face.mIndices[0]),
          first + static_cast<int>(face.mIndices[1]), first + static_cast<int>(face.mIndices[2]) });
    }
  }

  void addAnimation(const aiAnimation& animation)
  {
    Animation a;
    a.name = animation.mName.C_Str();
    a.duration = animation.mDuration;
    if (animation.mTicksPerSecond > 0)
      a.ticksPerSecond = animation.mTicksPerSecond;
    for (unsigned c = 0; c < animation.mNumChannels; ++c)
    {
      const aiNodeAnim& in = *animation.mChannels[c];
      Channel channel;
      channel.node = nodeNamed(in.mNodeName.C_Str(), "animation '" + a.name + "': channel");
      for (unsigned k = 0; k < in.mNumPositionKeys; ++k)
        channel.positions.push_back({ in.mPositionKeys[k].mTime, vec(in.mPositionKeys[k].mValue) });
      for (unsigned k = 0; k < in.mNumScalingKeys; ++k)
        channel.scales.push_back({ in.mScalingKeys[k].mTime, vec(in.mScalingKeys[k].mValue) });
      for (unsigned k = 0; k < in.mNumRotationKeys; ++k)
      {
        const aiQuaternion& q = in.mRotationKeys[k].mValue;
        channel.rotations.push_back({ in.mRotationKeys[k].mTime, { q.w, q.x, q.y, q.z } });
      }
      a.channels.push_back(std::move(channel));
    }
    out_.animations.push_back(std::move(a));
  }

  const std::string& path_;
  const aiScene& scene_;
  SkinnedMesh out_;
  std::vector<const aiNode*> nodesAi_;
  std::map<std::string, int> byName_;
};

} // namespace

bool canReadSkinnedMeshFiles()
{
  return true;
}

SkinnedMesh readSkinnedMesh(const std::string& path)
{
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    fail(path, "no such file");
  if (!std::ifstream(path))
    fail(path, "cannot be opened");
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(path, aiProcessPreset_TargetRealtime_Fast);
  if (!scene || !scene->mRootNode)
    fail(path, std::string("Assimp cannot read it: ") + importer.GetErrorString());
  if ((scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE) || scene->mNumMeshes == 0)
    fail(path, "has no mesh");
  return SceneReader(path, *scene).read();
}

#endif

} // namespace ictk::skin
