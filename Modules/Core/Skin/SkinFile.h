// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Reading skinned meshes from the files animators write (issue 17): DirectX .x, glTF 2, FBX,
// Collada and the other formats Assimp imports. Assimp is an optional, private dependency of
// this library (CMake option ICTK_ENABLE_ASSIMP, Debian's libassimp-dev): its headers are
// included by SkinFile.cxx only, and a build without it still has the library, whose reader
// then refuses every file with a message that says so.
//
// What is read: every mesh of the scene as Assimp's real-time preset gives it (triangulated,
// identical vertices joined: the counts `assimp info` prints; points and lines are skipped) with
// its normals, merged into one rest mesh; the node hierarchy; the bones as joints with their offset
// matrices (a bone used by several meshes with the same offset is one joint); the bones' weights,
// normalised to sum 1 per vertex; every animation's node channels and timing. A skinned mesh (one
// with bones) is posed by its bones alone, its node's transform not applied (Assimp's convention,
// and glTF's rule), so its rest mesh is its own coordinates; a mesh without bones is placed by its
// node (its rest mesh is the node's bind transform applied), and so is a vertex no bone weighs: its
// mesh's node is a joint too, weighing it 1. Texture coordinates, materials, cameras, lights and
// morph targets are not read.

#include "Skin/SkinnedMesh.h"

#include <string>

namespace ictk::skin
{

/// Whether this build reads files (it was built with Assimp).
bool canReadSkinnedMeshFiles();

/// Reads the skinned mesh in `path`. Throws std::runtime_error whose message starts with the
/// path: a missing or unreadable file, a file Assimp cannot import (its reason), a scene with no
/// triangle mesh, a bone or channel that names no node, a build without Assimp.
SkinnedMesh readSkinnedMesh(const std::string& path);

} // namespace ictk::skin
