// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Opening and saving model files by extension: .hf (HyperFun) and .xml (FRep XML); .scn and
// .scene (seed 003's scenes, Lang/Scene.h) are read, and written only from a scene
// (saveSceneFile); .vm (Fidget's SSA benchmark format, negated on import) and .blob (a BlobTree,
// mapped to f >= 0 inside by frep::blob::shape) are read only.

#include "FRep/BlobTree.h"
#include "FRep/Hypervolume.h"
#include "Lang/BlobReader.h"
#include "Lang/Diagnostics.h"

#include <array>
#include <optional>
#include <string>
#include <vector>

namespace ictk::lang
{

struct ModelFile
{
  std::string name;
  int parameterCount = 0;
  frep::Hypervolume model;
  /// A box that holds the model, when the file says (FRep XML may carry one); otherwise unset.
  std::optional<std::array<double, 6>> bounds;
};

/// A .blob file read once (docs/blobtree.md). An animated tree (key-frames, waves, an animated
/// threshold) changes with time outside its domain: it is a model only at a time t, its instance
/// (BlobTree::instantiate). A static tree is the same model at every t.
struct BlobModelFile
{
  std::string name;
  frep::blob::BlobTree tree; ///< the generic tree, as read
  BlobOrigins origins;       ///< where its animated values were written
  bool animated() const { return tree.animated(); }
  /// The instance at time t (lang::instantiateBlob): throws ParseError at the node whose value
  /// is out of its range at t.
  frep::blob::BlobTree instance(double t) const { return instantiateBlob(tree, origins, t); }
  /// The model at time t: the instance's shape (potential - T; with its materials as the
  /// attributes "colour" and "optics" when the tree has material nodes) and its support box at t
  /// with a 2 % margin as the bounds.
  ModelFile at(double t) const;
};
/// Reads a .blob file; throws ParseError (diagnostics name the file).
BlobModelFile loadBlobModelFile(const std::string& path, const Limits& limits = {});

/// True for paths ending in .blob (case-insensitive).
bool isBlobFile(const std::string& path);
/// True for paths ending in .hf, .xml, .scn, .scene, .vm or .blob (case-insensitive).
bool isModelFile(const std::string& path);
/// True for paths ending in .scn or .scene (case-insensitive): seed 003's scenes (Lang/Scene.h).
bool isSceneFile(const std::string& path);
/// Opens a .hf, .xml, .scn, .vm or .blob file; throws ParseError (diagnostics name the file) or
/// std::invalid_argument for an unknown extension. `parameterValues` specialises a HyperFun model
/// (see readHyperFun); an XML model keeps its parameter slots. A scene is its built hypervolume
/// (lang::buildScene: the attributes "object", "colour", "perturbation"). A static .blob is its
/// tree's model (BlobModelFile::at); an animated one has no model without a time and is refused
/// (std::invalid_argument naming the file): read it with loadBlobModelFile and instantiate it.
ModelFile loadModelFile(const std::string& path, const Limits& limits = {},
  const std::vector<double>& parameterValues = {});
/// A box {xmin, xmax, ymin, ymax, zmin, zmax} that holds the model: the file's own bounds when it
/// carries them, else found by interval arithmetic (frep::boundingBox) inside [-10, 10]^3
/// (HyperFun's default modelling box) with a 2 % margin, the axes the model's domain does not use
/// flat at 0. A model whose parameters are needed to bound it gets the whole search box.
std::array<double, 6> modelFileBounds(
  const ModelFile& file, const std::vector<double>& parameters = {});
/// Saves as .hf or .xml by extension, through a temporary file renamed on success.
void saveModelFile(const ModelFile& model, const std::string& path);
/// Writes the scene file `input` as one self-contained scene file `path` (its `object`
/// references inlined, seed 003 line 157), atomically as saveModelFile.
void saveSceneFile(const std::string& input, const std::string& path, const Limits& limits = {});
/// Writes a BlobTree as the .blob file `path` (lang::writeBlob), atomically as saveModelFile: the
/// tree as read, its animations kept, or with `time` its static instance at that time (generalised
/// cylinders and surfaces of revolution expanded into their elements, every animated value at
/// its value at t). Throws std::invalid_argument for a path that is not a .blob or a time that is
/// not finite, std::runtime_error when the file cannot be written.
void saveBlobFile(
  const BlobModelFile& blob, const std::string& path, std::optional<double> time = std::nullopt);

} // namespace ictk::lang
