// Mesh files in and out (pack side): VTK XML UnstructuredGrid (.vtu) and legacy VTK (.vtk).
//
// The readers take bytes from strangers: every failure is a Result whose message names the file,
// the array or cell, and what was expected vs. found. They never throw, never allocate more than
// the input can justify (a count is checked against the bytes left before anything is sized by
// it), and report everything they change or drop in ReadReport::notes.
//
// What a read produces (TetMesh, core/mesh.h):
//   - VTK_TETRA (10) cells become tets; VTK_QUADRATIC_TETRA (24) keep their 4 corners (a note
//     says so); every other cell type is counted by name and listed in notes and skippedCells.
//   - 1-component point arrays become scalar fields under their own name; n-component arrays
//     become "NAME_magnitude" (Euclidean norm of the tuple). Cell data is ignored with a note.
//   - All points are kept, also those no tet uses after dropping cells (validation reports them).
// Errors: IoError (file), BadMagic (not this format), Unsupported (valid file, feature not read,
// e.g. DATASET POLYDATA or an LZ4 compressor), Truncated, Corrupt, OutOfRange (a cell's vertex id;
// the message names the cell), NonFinite (a NaN/Inf coordinate; names the vertex), TooLarge (more
// than 2^32-1 vertices or tets), DecompressFailed (a zlib block), NoTets (no tetrahedra at all).
// On failure `out` is left empty; notes gathered so far stay in the report.
#pragma once
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "mesh.h"
#include "status.h"

namespace tetstream {

struct SkippedCells {
  int vtkType = 0;
  std::string typeName;  // e.g. "VTK_HEXAHEDRON"
  uint64_t count = 0;
};

struct ReadReport {
  std::string format;              // what was read, e.g. "VTK XML UnstructuredGrid (appended raw, zlib, UInt64 header)"
  std::vector<std::string> notes;  // human-readable, one line each, in the order they happened
  std::vector<SkippedCells> skippedCells;  // by VTK type, ascending
};

// Reads a mesh file, choosing the reader by extension (.vtu, .vtk; case-insensitive).
// out.name is set to the file's stem.
Result readMesh(const std::string& path, TetMesh& out, ReadReport& report);

// The same from bytes already in memory; `name` supplies the extension and the label in messages.
Result readMeshBytes(std::string_view bytes, const std::string& name, TetMesh& out, ReadReport& report);

// Writes a .vtu (VTK XML, appended raw binary; see vtu_writer.cpp). Only .vtu is supported.
// BadArgument when the mesh's arrays disagree in size (e.g. a field with the wrong length),
// IoError when the file cannot be written. Writes to PATH.tmp and renames, so a failed write never
// leaves a half file under PATH.
Result writeMesh(const std::string& path, const TetMesh& mesh);

}  // namespace tetstream
