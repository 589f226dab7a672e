// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Triangle meshes from .obj (Wavefront), .off (Object File Format), .ply (Stanford: ASCII and
// binary, either byte order) and .stl (ASCII and binary) files: the explicit surfaces that a .icm
// cell's `shape = file("handle.obj")` stands for (a B-cell, thesis loadMesh). Only what a surface
// needs is read: vertices and faces, each face of n >= 3 corners triangulated as a fan from its
// first corner; normals, texture coordinates, colours, groups and materials are skipped. An .stl
// file repeats each triangle's corners: equal corners are welded into one point. VTK-free, so the
// engine reads them without the VTK layer (which is why VTK's own .vtp is not among them).

#include "Complex/Cell.h"

#include <string>

namespace ictk::lang
{

/// True for paths ending in .obj, .off, .ply or .stl (case-insensitive): the mesh files
/// `file(...)` reads.
bool isMeshFile(const std::string& path);

/// The file's points and triangles (ExplicitGeometry's points and triangles; no polylines or
/// tetrahedra). Throws ParseError naming the file and line (binary files: the header's last line):
/// an unreadable file, a malformed number or count, a header or type it does not know, a face of
/// fewer than three corners, an index out of range (.obj's 1-based and negative indices are both
/// read), no faces at all.
complex::ExplicitGeometry readMeshFile(const std::string& path);

} // namespace ictk::lang
