// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The .blob file form of a BlobTree (FRep/BlobTree.h; docs/blobtree.md): one node per keyword,
// its values as numbers (brackets group them for the reader's eye only), its children in braces.
//
//   # a blended pair under a frame node
//   threshold 0.5
//   rotate [0 0 1] 30 {
//     blend {
//       point 1.0 1 [0 0 0]
//       segment 0.8 1 [0 0 0] [1 0 0]
//     }
//   }
//
// Angles (rotate, twist) are in degrees in the file. A value may be animated: wave(base amplitude
// period phase) or keys(n, t v v' ..., t v v' ...) (Hermite-Ferguson of degree 2n - 1); so may
// the threshold.

#include "FRep/BlobTree.h"
#include "Lang/Diagnostics.h"

#include <string>

namespace ictk::lang
{

/// Parses .blob text; `fileName` names the source in diagnostics. Throws ParseError with the
/// errors found (file:line:col), each at the offending token or node keyword.
frep::blob::BlobTree readBlob(
  const std::string& text, const std::string& fileName = {}, const Limits& limits = {});
/// Reads and parses a file. Throws ParseError (also for an unreadable or too large file).
frep::blob::BlobTree readBlobFile(const std::string& path, const Limits& limits = {});

/// The .blob text of a generic tree: the threshold, then the nodes reachable from the root, one
/// a line, indented by depth, with their animations as wave(...) and keys(...) and their angles
/// in degrees. readBlob reads it back to the same tree: the same nodes, values and animations
/// (bit for bit, but for angles, which go through degrees and back to within an ulp). Numbers
/// are written in their shortest form that reads back exactly. Throws std::invalid_argument for
/// an empty tree.
std::string writeBlob(const frep::blob::BlobTree& tree);

} // namespace ictk::lang
