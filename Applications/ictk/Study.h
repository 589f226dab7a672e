// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// A study's mesh (docs/medical.md): the complex file read with its "study" object, checked (the
// implants inside the specimen, every cell with a material, the protected curves far enough
// apart for the CGAL backend), meshed into labelled tetrahedra and given the scan's materials.
// `ictk study` writes and solves it; `ictk bench`'s ct-implant workload times it
// (StudyCommand.cxx).

#include "Mesh/TetMesh.h"

#include <cstddef>
#include <string>

namespace ictk::cli
{

struct StudyRequest
{
  std::string model;
  /// The element size; 0: the study's "size".
  double size = 0;
  int threads = 0;
  bool deterministic = false;
  bool progress = false;
};

struct StudyMesh
{
  mesh::TetMesh mesh;
  double size = 0;
  /// The modulus bins of the deck (ln E) and the study's compression (0: none).
  double binWidth = 0.01;
  double compression = 0;
  double minModulus = 0, maxModulus = 0;
  /// Reading the complex and the scan; meshing (with the curve check); the materials.
  double readSeconds = 0, meshSeconds = 0, materialSeconds = 0;
};

/// Throws UserError (naming the file and the place) for a bad study.
StudyMesh MakeStudyMesh(const StudyRequest& request);

} // namespace ictk::cli
