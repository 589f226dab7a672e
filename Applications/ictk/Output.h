// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// How `ictk` writes its outputs: into a temporary file or folder beside the destination, moved
// into place once complete, so that an error or Ctrl-C never leaves a half-written file and never
// touches what was there before.

#include <string>

class vtkDataObject;
class vtkUnstructuredGrid;
class vtkXMLWriter;
class vtkXMLWriterBase;

namespace ictk::mesh
{
struct TetMesh;
}

namespace ictk::cli
{

/// A temporary file next to the destination, renamed onto it by Commit() and removed otherwise.
/// The constructor checks the destination (not a folder, its folder exists) and creates the
/// temporary file, so a command can fail before spending time on the work.
class AtomicOutput
{
public:
  explicit AtomicOutput(const std::string& destination);
  AtomicOutput(const AtomicOutput&) = delete;
  AtomicOutput& operator=(const AtomicOutput&) = delete;
  ~AtomicOutput();

  /// The temporary file to write (it keeps the destination's extension).
  const std::string& Path() const { return this->Temporary; }
  /// Writes `bytes` as the temporary file's content, checking every step (a full disk, the file
  /// size limit) so that a failure is a UserError naming the destination.
  void Write(const std::string& bytes);
  /// Moves the temporary file onto the destination, once it is known to be complete: flushed to
  /// the disk, and not cut short by a full disk or the file size limit (`ulimit -f`), which
  /// writers that ignore their stream's errors (vtkOBJWriter) would not report.
  void Commit();
  /// Commit's checks without the move: throws the UserError of Fail() unless the temporary file
  /// is complete. A command writing several files checks them all before moving any.
  void Verify() const;
  /// Throws the UserError "cannot write '<destination>': <why>; nothing written".
  [[noreturn]] void Fail(const std::string& why) const;

private:
  std::string Destination;
  std::string Temporary;
};

/// Runs a VTK XML writer into memory and writes its bytes with AtomicOutput::Write: VTK's XML
/// writers can crash when their stream fails mid-file (a full disk), so they never write a file
/// themselves.
void WriteXml(vtkXMLWriter* writer, vtkDataObject* data, AtomicOutput& file);

/// Writes a composite dataset file and its folder of pieces (named after the file's stem) into a
/// temporary folder beside `output`, then moves both into place. An earlier pieces folder is
/// replaced only when it holds nothing but pieces of this file.
void WriteComposite(vtkXMLWriterBase* writer, vtkDataObject* data, const std::string& output);

/// Writes `grid` as a .vtu (appended data) into `file` (through WriteXml) and commits it; throws
/// UserError naming the file's destination when writing fails.
void WriteUnstructuredGrid(vtkUnstructuredGrid* grid, AtomicOutput& file);

/// A tetrahedral mesh as a .vtu (ictkTetrahedralize's form: MaterialId, CellId and the
/// per-tetrahedron arrays), through a temporary file renamed on success.
void WriteTetMeshVtu(const mesh::TetMesh& mesh, const std::string& path);

} // namespace ictk::cli
