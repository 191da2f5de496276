// Mesh files in and out (pack side). Readers: VTK XML (.vtu UnstructuredGrid, .vts StructuredGrid,
// .vti ImageData), legacy VTK (.vtk: UNSTRUCTURED_GRID, STRUCTURED_POINTS, STRUCTURED_GRID,
// RECTILINEAR_GRID), partitioned VTK output (.pvtu with its .vtu pieces, .vtm multiblock of
// unstructured blocks, legacy .pvtk with its .vtk pieces, and a .vtu of several <Piece>s),
// Gmsh .msh 2.2/4.1 (ASCII and binary), TetGen .node/.ele, Medit .mesh (+ .sol), PLOT3D grid + Q,
// Exodus II (.exo, .e, .ex2, .exii, .g; through SEACAS's library, over netCDF or HDF5), CGNS
// (.cgns, ADF or HDF5; through the CGNS library), XDMF 2/3 (.xdmf/.xmf; heavy data in HDF5, XML or
// raw binary) and VTKHDF UnstructuredGrid (.vtkhdf/.hdf, or HDF5 with a /VTKHDF group;
// partitions), the last four with time steps. HDF5 is read through the HDF5 library
// (hdf5_file.h). Writer: .vtu.
//
// The readers take bytes from strangers: every failure is a Result whose message names the file,
// the array, section, line or cell, and what was expected vs. found. They never throw, never
// allocate more than the input can justify (a count is checked against the bytes left before
// anything is sized by it), and report everything they change or drop in ReadReport::notes, one
// line per step.
//
// What a read produces (TetMesh, core/mesh.h), the same for every format (cells.cpp):
//   - Tetrahedra stay; hexahedra, wedges and pyramids (and structured grid cells) are split into
//     6, 3 and 2 tetrahedra, each quad face cut through its corner lowest in (x, y, z) so
//     neighbouring cells agree (conforming), however the reader numbered them; higher-order
//     cells keep their corners.
//   - Coincident vertices (equal coordinates) are merged; tetrahedra that then repeat a vertex are
//     dropped; vertices no tetrahedron uses (mid-edge nodes, unreferenced points) are dropped.
//   - 1-component point arrays become scalar fields under their own name; n-component arrays
//     become "NAME_magnitude" (Euclidean norm of the tuple). Exodus II and CGNS store vectors as
//     one variable per component (vel_x, MomentumX, ...): those stay fields, and a NAME_magnitude
//     is added. Cell data becomes point data: the
//     volume-weighted average over the cells around each vertex ("NAME_cell" when a point array has
//     the name). Lower-dimensional cells are counted by name and listed in notes and skippedCells.
//   - Pieces of a partitioned mesh (piece_merge.cpp) become one mesh: ghost cells (vtkGhostType
//     DUPLICATECELL, and HIDDENCELL) are dropped; the points pieces share are welded by global ids
//     (GlobalIds, GlobalNodeIds) when every piece has them, else by exact coordinates, and take
//     the owning piece's values (disagreements between pieces are counted in a note, never
//     averaged). vtkGhostType and global id arrays are not fields. A listing's pieces are read
//     only from its folder and subfolders (no absolute paths, none leaving it).
//   - Orientation and flat tetrahedra are left to the packer (it re-orients and removes them).
// Errors: IoError (file), BadMagic (not this format), Unsupported (valid file, feature not read,
// e.g. DATASET POLYDATA or an LZ4 compressor), Truncated, Corrupt, OutOfRange (a cell's vertex id;
// the message names the cell), NonFinite (a NaN/Inf coordinate; names the vertex), TooLarge (more
// than 2^32-1 vertices or tets), DecompressFailed (a zlib block), NoTets (no volume cells at all).
// On failure `out` is left empty; notes gathered so far stay in the report.
#pragma once
#include <cstdint>
#include <optional>
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

// One state of a file that holds several (the time steps of a transient result).
struct TimeStep {
  uint64_t index = 0;  // 0-based, in the file's order
  double time = 0;     // the simulation time the file gives it
};

struct ReadReport {
  std::string format;              // what was read, e.g. "VTK XML UnstructuredGrid (appended raw, zlib, UInt64 header)"
  std::vector<std::string> notes;  // human-readable, one line each, in the order they happened
  std::vector<SkippedCells> skippedCells;  // by VTK type, ascending
  std::vector<TimeStep> steps;             // every time step of the file; empty for a single state
  uint64_t stepRead = 0;                   // the index of the step that was read (when steps is not empty)
  uint64_t filesListed = 0;                // of a listing of pieces: the files it lists (0: not a listing)
  bool shared = false;                     // only share ReadOptions::shareIndex of the pieces or partitions was read
  // Cell data made point data: per such field, the volume of the cells its average at each
  // vertex was taken over (the distributed pack joins the averages ranks took over their own
  // cells at the points they share, weighted by these). Empty when no cell data was read.
  struct CellAverage {
    std::string field;
    std::vector<double> weight;  // per vertex of the mesh read
  };
  std::vector<CellAverage> cellAverages;
};

struct ReadOptions {
  // The solution file of a PLOT3D grid (Q file) or a Medit mesh (.sol). Empty: a PLOT3D grid looks
  // for a sibling ("bluntfinxyz.bin" -> "bluntfinq.bin", "wing.x" -> "wing.q"), a Medit mesh for
  // NAME.sol.
  std::string solution;
  // Which time step of a file with several: by index, or the one nearest a simulation time. Neither:
  // the last (the end state of a run, what a user usually looks at first). A file of one state
  // refuses either with BadArgument.
  std::optional<uint64_t> step;
  std::optional<double> time;
  // Of a listing of pieces (.pvtu, .vtm, .pvtk), read only share `shareIndex` of `shareCount`:
  // the listed files from shareIndex·n/shareCount up to (shareIndex + 1)·n/shareCount, n the
  // files listed (each process of a distributed pack reads its own; every path is still
  // checked); of fewer files than processes, the processes of one file each read a share of its
  // cells, as below (of a legacy piece the first of them reads it, the others nothing). A VTKHDF
  // file of at least shareCount partitions, or a VTK XML file of at least shareCount <Piece>s:
  // the partitions or pieces likewise. A .vtu of fewer pieces: the cells in those rows of each
  // piece and their points; a .vti or .vts of fewer pieces, each at least shareCount cells deep
  // along some axis: those layers of cells of each piece (along k where it is deep enough, else
  // j, else i). An XDMF file of at least shareCount volume grids
  // (a spatial collection): those grids, each whole. Of fewer grids, each of one cell type: the
  // cells in those rows of its topology and their points. An Exodus II file: the elements in those
  // rows of its blocks (in file order) and their nodes. A CGNS base of at least shareCount zones:
  // those zones, each whole; of fewer unstructured zones of fixed-type sections: their elements
  // in those rows and their vertices; of fewer structured zones, each deep enough: a slab of
  // layers of cells of each zone and their points. Points read by rows are the run from the
  // smallest id the cells use to the largest, or only those they use when the run has others and
  // the format reads a window of rows alone (io/row_pick.h). Other files ignore it
  // (ReadReport::shared says).
  uint32_t shareIndex = 0, shareCount = 1;
};

// Reads a mesh file, choosing the reader by extension (case-insensitive): .vtu/.vts/.vti, .vtk,
// .pvtu/.vtm/.pvtk (and the pieces they list), .msh, .mesh, .node/.ele (reads both), .xyz,
// .exo/.e/.ex2/.exii, .cgns, .xdmf/.xmf (heavy data from the file's folder or below it),
// .vtkhdf/.hdf; other extensions are recognized by their content (a listing under any name;
// Exodus II for netCDF, or HDF5 with Exodus's variables; CGNS for ADF, or HDF5 with a
// CGNSLibraryVersion node; any other HDF5: VTKHDF; XML with <Xdmf: XDMF; PLOT3D for binary data
// under .x, .g, .grd, .p3d, .bin, .dat). out.name is the file's stem.
Result readMesh(const std::string& path, TetMesh& out, ReadReport& report, const ReadOptions& options = {});

// The same from bytes already in memory; `name` supplies the extension and the label in messages.
// Formats of two files read only the first here (a PLOT3D grid without Q, a Medit mesh without
// .sol); TetGen needs readTetgen (readers.h), a listing of pieces readListing (readers.h). XDMF
// reads only XML data items (HDF and Binary ones are in other files: Unsupported); Exodus II, CGNS
// and VTKHDF are Unsupported (their libraries read files, not memory: read them by path).
Result readMeshBytes(std::string_view bytes, const std::string& name, TetMesh& out, ReadReport& report);

// Writes a .vtu (VTK XML, appended raw binary; see vtu_writer.cpp). Only .vtu is supported.
// BadArgument when the mesh's arrays disagree in size (e.g. a field with the wrong length),
// IoError when the file cannot be written. Writes to PATH.tmp and renames, so a failed write never
// leaves a half file under PATH.
Result writeMesh(const std::string& path, const TetMesh& mesh, uint32_t pieces = 1);

}  // namespace tetstream
