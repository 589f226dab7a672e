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

#include <map>
#include <optional>
#include <string>

namespace ictk::lang
{

/// Where the animated values of a tree read from text were written: the keyword of each node
/// with an animated value (by its index in the tree) and the threshold keyword, as diagnostics
/// without a message. Only these can be refused after reading, at a time t.
struct BlobOrigins
{
  std::map<std::uint32_t, Diagnostic> nodes;
  std::optional<Diagnostic> threshold;
};

/// Parses .blob text; `fileName` names the source in diagnostics. Throws ParseError with the
/// errors found (file:line:col), each at the offending token or node keyword. `origins`, when
/// given, receives where the animated values were written (for instantiateBlob).
frep::blob::BlobTree readBlob(const std::string& text, const std::string& fileName = {},
  const Limits& limits = {}, BlobOrigins* origins = nullptr);
/// Reads and parses a file. Throws ParseError (also for an unreadable or too large file).
frep::blob::BlobTree readBlobFile(
  const std::string& path, const Limits& limits = {}, BlobOrigins* origins = nullptr);

/// The instance of a tree read from text at time t (BlobTree::instantiate). A value out of its
/// range at t (frep::blob::InstanceError, e.g. a radius a wave drives below 0) is thrown as a
/// ParseError at the node's keyword, naming the value and t; a node without an origin rethrows
/// the InstanceError.
frep::blob::BlobTree instantiateBlob(
  const frep::blob::BlobTree& tree, const BlobOrigins& origins, double t);

/// The .blob text of a generic tree: the threshold, then the nodes reachable from the root, one
/// a line, indented by depth, with their animations as wave(...) and keys(...) and their angles
/// in degrees. readBlob reads it back to the same tree: the same nodes, values and animations
/// (bit for bit, but for angles, which go through degrees and back to within an ulp). Numbers
/// are written in their shortest form that reads back exactly. Throws std::invalid_argument for
/// an empty tree.
std::string writeBlob(const frep::blob::BlobTree& tree);

} // namespace ictk::lang
