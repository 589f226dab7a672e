// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The declarative form of an implicit complex (.json, documented in docs/complex-json.md): cells
// with HyperFun fields, attribute functions, and the boundary and containment relations. The IC
// model language (.icm) produces the same objects.

#include "Complex/Complex.h"
#include "Lang/Diagnostics.h"

#include <functional>
#include <memory>
#include <string>

namespace ictk::voxel
{
struct VoxelGrid;
}

namespace ictk::lang
{

/// Readers for cell data in files the core does not read itself (VTK formats); the VTK layer
/// (ictkComplexSource::ReadComplexFile) installs them. Each throws std::exception with a message
/// naming the file when it cannot read it.
struct ComplexFileReaders
{
  /// An explicit cell's geometry (B cells: "file").
  std::function<complex::ExplicitGeometry(const std::string& path)> mesh;
  /// A voxel cell's grid (V cells: "file", "array"); .vdb files are read by the core when unset.
  std::function<std::shared_ptr<voxel::VoxelGrid>(
    const std::string& path, const std::string& array)>
    volume;
  /// Told each voxel cell's name and grid as the cell's field reads it (after its "stamp"), so
  /// that a study takes its materials' Hounsfield units from the very values it meshed.
  std::function<void(const std::string& cell, std::shared_ptr<const voxel::VoxelGrid> grid)>
    scanRead;
};

/// True for paths ending in .json (case-insensitive).
bool isComplexFile(const std::string& path);

/// Reads a complex from JSON text; `fileName` names the file in diagnostics and is the base of
/// relative paths inside it. Throws ParseError with every problem found (file:line:col where the
/// position is known: JSON syntax, the cell an error belongs to, HyperFun errors inside fields).
complex::Complex readComplexJson(const std::string& text, const std::string& fileName,
  const Limits& limits = {}, const ComplexFileReaders& readers = {});
/// Reads a .json complex file; an unreadable or too large file is a ParseError too.
complex::Complex readComplexFile(
  const std::string& path, const Limits& limits = {}, const ComplexFileReaders& readers = {});

} // namespace ictk::lang
