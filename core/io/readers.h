// The format back ends behind mesh_io.h, plus the pieces the two VTK readers share.
// Callers normally use readMesh/readMeshBytes/writeMesh; tests call these directly on bytes.
#pragma once
#include <algorithm>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "io/mapped_file.h"
#include "io/mesh_io.h"
#include "mesh.h"
#include "status.h"

namespace tetstream {

// VTK XML UnstructuredGrid (.vtu), StructuredGrid (.vts) and ImageData (.vti), by the VTKFile
// type: format="ascii", inline "binary" (base64) and appended data (encoding="raw" or "base64"),
// optionally vtkZLibDataCompressor, header_type UInt32 or UInt64, LittleEndian or BigEndian.
// Several Pieces are the pieces of one mesh (PETSc writes one per rank): mergePieces() drops ghost
// cells and welds the points they share. Point and cell data are read; vtkGhostType and global id
// arrays describe the partition and are not fields. `label` names the source in messages.
// shareIndex, shareCount: as readVtuPieces (a distributed pack's process reads its pieces).
Result readVtu(std::string_view bytes, const std::string& label, TetMesh& out, ReadReport& report,
               uint32_t shareIndex = 0, uint32_t shareCount = 1);

// Legacy VTK (.vtk) DATASET UNSTRUCTURED_GRID, STRUCTURED_POINTS, STRUCTURED_GRID or
// RECTILINEAR_GRID, ASCII or BINARY (big-endian), versions up to 5.1: classic CELLS n size and
// the 5.1 OFFSETS/CONNECTIVITY layout; POINT_DATA SCALARS, VECTORS, NORMALS, TENSORS(6) and FIELD
// arrays become fields, CELL_DATA ones become point data (vtkGhostType and GLOBAL_IDS do not: ghost
// cells are dropped as in readVtu).
Result readLegacyVtk(std::string_view bytes, const std::string& label, TetMesh& out, ReadReport& report);

// Gmsh .msh 2.2 and 4.1, ASCII and binary (either byte order). Tetrahedra, hexahedra, prisms and
// pyramids of any order (higher-order nodes dropped); other elements skipped with a count;
// $NodeData becomes fields, $ElementData becomes point data (volume-weighted). Physical and
// entity tags are ignored.
Result readGmsh(std::string_view bytes, const std::string& label, TetMesh& out, ReadReport& report);

// TetGen .node + .ele (either file's bytes may come first; `nodeLabel`/`eleLabel` name them).
// Point attributes become fields attr0, attr1, ...; 0- or 1-based numbering; 4- or 10-node tets.
Result readTetgen(std::string_view node, const std::string& nodeLabel, std::string_view ele,
                  const std::string& eleLabel, TetMesh& out, ReadReport& report);

// Medit .mesh (ASCII): Vertices, Tetrahedra, Hexahedra, Prisms, Pyramids, TetrahedraP2,
// HexahedraQ2; `sol` (may be empty) is a sibling .sol file whose SolAtVertices become fields.
Result readMedit(std::string_view mesh, const std::string& label, std::string_view sol, const std::string& solLabel,
                 TetMesh& out, ReadReport& report);

// PLOT3D grid (.xyz/.x/.g/.bin) with an optional Q solution file (empty: geometry only). The
// layout (byte order, 4- or 8-byte reals, C binary or Fortran records, single- or multi-grid
// header, IBLANK) is found by trying every combination against the file size.
Result readPlot3d(std::string_view grid, const std::string& gridLabel, std::string_view q, const std::string& qLabel,
                  TetMesh& out, ReadReport& report);

// XDMF 2 and 3 (.xdmf, .xmf; xdmf_reader.cpp): unstructured grids (Tetrahedron, Pyramid, Wedge,
// Hexahedron, their quadratic forms, Mixed), Geometry XYZ or X_Y_Z, Node and Cell attributes,
// legacy DOLFIN finite element functions, spatial collections (merged) and temporal collections
// (one step read: options.step / options.time, default the last). DataItems in XML, HDF5
// ("FILE:/dataset") or raw binary, HyperSlab and JOIN functions; References and <xi:include>
// within the document. Heavy-data files are looked up in `dataFolder` (the XDMF file's folder)
// or below it; without a folder (nullopt: bytes in memory) HDF and Binary items are refused with
// Unsupported. `xml` is the XDMF file's text; `label` names it in messages.
Result readXdmf(std::string_view xml, const std::string& label, const std::optional<std::string>& dataFolder,
                const ReadOptions& options, TetMesh& out, ReadReport& report);

// VTKHDF (vtkhdf_reader.cpp): /VTKHDF of Type UnstructuredGrid, any number of partitions
// (concatenated; their shared points merged by finishMesh), PointData and CellData, cell types as
// in .vtu; a Steps group makes time steps (options.step / options.time, default the last) and
// only the chosen step's rows are read. Read by path through the HDF5 library.
Result readVtkHdf(const std::string& path, const ReadOptions& options, TetMesh& out, ReadReport& report);

// Exodus II (SEACAS) through its own library, over netCDF classic, 64-bit offset, 64-bit data
// or netCDF-4 (HDF5). Element blocks of tetrahedra, hexahedra, wedges and pyramids of any order
// (higher-order nodes dropped) are merged; other blocks (TRI, QUAD, SHELL, BAR, ...) are skipped
// with a count by type. Nodal variables become fields, element variables cell data, both of the
// time step chosen by options (chooseTimeStep; only that step is read). By path only: the library
// reads the file itself.
Result readExodus(const std::string& path, const ReadOptions& options, TetMesh& out, ReadReport& report);

// CGNS (ADF or HDF5) through the CGNS library: the first base with 3D cells; unstructured zones
// (TETRA, PYRA, PENTA, HEXA of any order and MIXED sections; NFACE_n refused) and structured
// zones (split as structured grids are), zones joined where their points coincide;
// FlowSolution at Vertex (fields) and CellCenter (cell data), of the time step chosen by
// options when the base has BaseIterativeData. By path only.
Result readCgns(const std::string& path, const ReadOptions& options, TetMesh& out, ReadReport& report);

// The listing files of partitioned VTK output (partitioned_reader.cpp): parallel VTK XML (.pvtu,
// PUnstructuredGrid), VTK multiblock (.vtm, vtkMultiBlockDataSet) and legacy parallel VTK (.pvtk,
// vtkPDataSetWriter's <File version="pvtk-1.0">). `load` gives the bytes of a piece by the path the
// listing names, relative to the listing's folder; the listing is checked first (no absolute path,
// none leaving the folder, none naming the listing itself, none named twice, at most kMaxPieces).
// Every piece is read by the serial reader of its format and the pieces are merged by
// mergePieces(). `label` names the listing in messages (its path).
enum class ListingKind { None, Pvtu, Vtm, Pvtk };
// What a file's first bytes say it is: a listing, or None for anything else (a .vtu, junk).
ListingKind listingKind(std::string_view head);
// A piece file's bytes: mapped (`file`: a process that reads a share of the file then touches
// only that share's pages), or held by the loader; `bytes` views them.
struct PieceBytes {
  MappedFile file;
  std::string_view bytes;
};
using PieceLoader = std::function<Result(const std::string& relativePath, PieceBytes& piece)>;
// Reads the files of share `shareIndex` of `shareCount` only (ReadOptions).
Result readListing(std::string_view listing, const std::string& label, const PieceLoader& load, TetMesh& out,
                   ReadReport& report, uint32_t shareIndex = 0, uint32_t shareCount = 1);

// VTK XML, appended raw binary: Float32 points, Int64 connectivity/offsets, UInt8 types, Float32
// point data. One fwrite per array; writes PATH.tmp, then renames.
Result writeVtu(const std::string& path, const TetMesh& mesh);

// The mesh as the partitioned output of a parallel run: PATH.pvtu listing `pieces` .vtu files
// in the folder PATH (without .pvtu) beside it, piece k holding the k-th of `pieces` equal runs
// of tets and the points they use (interface points repeated), no ghost cells.
Result writePvtu(const std::string& path, const TetMesh& mesh, uint32_t pieces);

// ------------------------------------------------------------------ shared by the readers
namespace vtkio {

// The numeric element types of VTK arrays (XML spelling: "Int8" ... "Float64").
enum class ScalarType : uint8_t { Int8, UInt8, Int16, UInt16, Int32, UInt32, Int64, UInt64, Float32, Float64 };
size_t scalarSize(ScalarType t);
const char* scalarTypeName(ScalarType t);
bool isIntegerType(ScalarType t);
// Parses the XML spelling; false for anything else ("String", "Bit", ...).
bool parseXmlScalarType(std::string_view name, ScalarType& t);

// Converts `count` packed values at `src` (little- or big-endian) to int64. Returns the index of
// the first value that is not representable (a UInt64 above INT64_MAX), or `count` when all are.
size_t decodeInts(const uint8_t* src, size_t count, ScalarType t, bool bigEndian, int64_t* dst);
void decodeDoubles(const uint8_t* src, size_t count, ScalarType t, bool bigEndian, double* dst);

// One whitespace-separated ASCII number from text at pos (a leading '+' is allowed; "nan" and
// "inf" parse). Returns 1 and advances pos on success, 0 at the end of the text, -1 when the next
// token is not a number (pos is then at that token). Integers also accept integral "4.0" / "4e0".
int parseNextDouble(std::string_view text, size_t& pos, double& out);
int parseNextInt(std::string_view text, size_t& pos, int64_t& out);
bool parseU64(std::string_view s, uint64_t& out);  // whole string, decimal digits only

// ASCII case-insensitive equality (keywords of the text formats).
inline bool iequals(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i) {
    char x = a[i], y = b[i];
    if (x >= 'A' && x <= 'Z') x = char(x - 'A' + 'a');
    if (y >= 'A' && y <= 'Z') y = char(y - 'A' + 'a');
    if (x != y) return false;
  }
  return true;
}

// Text scanning shared by the ASCII readers: whitespace as in C's isspace; a token is the next
// run of non-space bytes (empty at the end); a line is the rest of the current line, its '\n'
// consumed and a trailing '\r' dropped (binary data starts right after it).
inline bool isSpace(char c) { return c == ' ' || c == '\n' || c == '\r' || c == '\t' || c == '\f' || c == '\v'; }
inline void skipSpace(std::string_view s, size_t& pos) {
  while (pos < s.size() && isSpace(s[pos])) ++pos;
}
inline std::string_view nextToken(std::string_view s, size_t& pos) {
  skipSpace(s, pos);
  const size_t b = pos;
  while (pos < s.size() && !isSpace(s[pos])) ++pos;
  return s.substr(b, pos - b);
}
inline std::string_view nextLine(std::string_view s, size_t& pos) {
  size_t e = s.find('\n', pos);
  if (e == std::string_view::npos) e = s.size();
  std::string_view line = s.substr(pos, e - pos);
  pos = std::min(s.size(), e + 1);
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  return line;
}

// Untrusted text for a message: at most 40 characters, non-printable bytes as '?'.
std::string printable(std::string_view s);

// "VTK_HEXAHEDRON" for 12; "VTK cell type 99" for a number VTK does not define.
std::string vtkCellTypeName(int64_t type);

// ------------------------------------------------------------------ cells (cells.cpp)
// Every reader collects its volume cells in a CellSoup (corners only, in VTK order) and hands it
// to finishMesh, which turns it into tetrahedra the same way for every format. That one place
// merges coincident vertices, splits hexahedra, wedges and pyramids conformingly, turns cell data
// into point data and drops unused vertices, each step said in one note line.
enum class CellShape : uint8_t { Tet = 0, Pyramid = 1, Wedge = 2, Hex = 3 };
inline constexpr int kShapeCorners[4] = {4, 5, 6, 8};

struct CellSoup {
  std::vector<uint8_t> shapes;    // per cell
  std::vector<uint32_t> corners;  // concatenated, kShapeCorners[shape] per cell, VTK corner order
  std::vector<uint32_t> source;   // per cell: index of the input cell it came from (for cell data)
  uint64_t inputCells = 0;        // every input cell seen, kept or not (the next source index)
  // Higher-order cells reduced to their corners: type label ("VTK_QUADRATIC_TETRA (24)") ->
  // (corners kept, count).
  std::map<std::string, std::pair<int, uint64_t>> reduced;
  // Cells that are not read: (VTK type or 0, label) -> count. The label names the format's type.
  std::map<std::pair<int64_t, std::string>, uint64_t> skipped;
  // Vertices some input cell lists (any node, also mid-edge nodes and nodes of skipped cells).
  // Readers that cannot leave a vertex out (structured grids) may leave it empty.
  std::vector<uint8_t> referenced;

  void add(CellShape shape, const uint32_t* ids, uint64_t sourceIndex) {
    shapes.push_back(uint8_t(shape));
    corners.insert(corners.end(), ids, ids + kShapeCorners[int(shape)]);
    source.push_back(uint32_t(sourceIndex));
  }
  void markReferenced(uint64_t v) {
    if (referenced.size() <= v) referenced.resize(v + 1, 0);
    referenced[v] = 1;
  }
};

// A scalar per input cell (NaN: this cell has no value), to become point data.
struct CellArray {
  std::string name;
  std::vector<double> values;
};

// What a VTK cell type is to the readers: its linear shape, the node count it must have (0: at
// least the corners, for Lagrange/Bezier cells of any order), the corners it keeps.
struct VtkCellInfo {
  bool volume = false;  // a 3D cell tetstream reads
  CellShape shape = CellShape::Tet;
  int nodes = 0;       // exact node count, or 0 for "at least kShapeCorners"
  bool voxel = false;  // VTK_VOXEL: corners in (i, j, k) order, not around the faces
};
VtkCellInfo vtkCellInfo(int64_t type);

// Cell c of a piece uses connectivity[offsets[c] .. offsets[c+1]); offsets has types.size()+1
// entries. Volume cells go to the soup with ids shifted by vertexBase; ids must be <
// pieceVertexCount. `where` starts every message ("a.vtu" or "a.vtu Piece 2"). Corrupt for bad
// offsets or a cell of the wrong size, OutOfRange for an id.
Result appendVtkCells(const std::string& where, std::span<const int64_t> connectivity, std::span<const int64_t> offsets,
                      std::span<const int64_t> types, uint64_t vertexBase, uint64_t pieceVertexCount, CellSoup& soup);

// Adds `count` hexahedra of an ni x nj x nk structured grid (points numbered i fastest, starting
// at vertexBase) to the soup; cell (i, j, k) has source index sourceBase + i + (ni-1)(j + (nj-1)k).
// keepPoint, when given, has one flag per point (indexed like the mesh, vertexBase included): a cell with a point whose
// flag is 0 is left out (PLOT3D IBLANK = 0). Returns the number of cells added.
uint64_t appendStructuredCells(uint64_t ni, uint64_t nj, uint64_t nk, uint64_t vertexBase, uint64_t sourceBase,
                               CellSoup& soup, const std::vector<uint8_t>* keepPoint = nullptr);

// `tuples` holds vertexCount tuples of `components` values. Returns the scalar per tuple: the
// value itself for 1 component, else the tuple's Euclidean norm.
std::vector<float> tuplesToScalars(std::span<const double> tuples, uint32_t components);
// "NAME" for 1 component, "NAME_magnitude" otherwise; a note says what was converted.
// `kind` is "point" or "cell" (for the note).
std::string fieldNameFor(const std::string& arrayName, uint32_t components, ReadReport& report,
                         const char* kind = "point");
// Adds the field unless a field of that name exists (then a note says it was dropped).
void addField(TetMesh& mesh, ScalarField field, ReadReport& report);

// Checks and conversions shared by every reader once all cells are in: finite coordinates
// (NonFinite names the input vertex), then (cells.cpp) coincident vertices merged, cells split into
// tetrahedra, cell arrays turned into point fields (volume-weighted), unused vertices dropped;
// vertex/tet counts within uint32, at least one tet (NoTets lists what was found); notes for each
// step, skipped cells and non-finite field values. Fills report.skippedCells.
// mesh.positions and mesh.fields hold the input points; mesh.tets is filled here.
Result finishMesh(const std::string& label, TetMesh& mesh, CellSoup& soup, std::vector<CellArray> cellArrays,
                  ReadReport& report);

// ------------------------------------------------------------------ time steps (time_steps.cpp)
// Picks the step to read from a file's step times (in file order) by options.step, options.time
// (the nearest step, with a note when not exact) or, by default, the last (with a note naming
// how many there are). Fills report.steps and report.stepRead. Empty `times` (one state) is
// index 0, and then --step or --time is a BadArgument, as is an index past the end.
Result chooseTimeStep(std::span<const double> times, const ReadOptions& options, const std::string& label,
                      ReadReport& report, size_t& index);
// ", step 3 of 5 (t = 0.75)" for ReadReport::format (steps counted from 0, as --step takes them);
// "" for a file of one state.
std::string stepText(const ReadReport& report);

// ------------------------------------------------------------------ HPC containers (hpc_container.cpp)
// The storage under Exodus II and CGNS files, by its first bytes.
enum class Container : uint8_t { None, NetcdfClassic, Netcdf64BitOffset, Netcdf64BitData, Hdf5, Adf };
Container containerSignature(std::string_view head);
const char* containerName(Container c);  // "netCDF classic", "HDF5", "ADF", ...

// Exodus II or CGNS, told by content for a file whose extension says nothing: ADF is CGNS; an
// HDF5 file is CGNS with a CGNSLibraryVersion node, Exodus II with the netCDF attributes and
// variables Exodus writes; a netCDF file is Exodus II with them. Anything else (VTKHDF, other
// netCDF or HDF5 data) is None.
enum class HpcFormat : uint8_t { None, Exodus, Cgns };
HpcFormat hpcFormatByContent(const std::string& path, std::string_view head);

// HDF5 1.10 (also under netCDF-4 and CGNS) can free wild pointers while it opens a damaged file:
// such opens are tried first in a forked child process with its output discarded, so that a crash
// there takes down the child only. Returns the child's exit code (probe's value, 0..255; a probe
// returns 0 for "went through", and anything else means it did not), -1 when it died by a signal.
// Where no child can be made the probe runs in this process. Call it where no other thread is
// running library code (the readers hold hpcLibraryMutex()).
int runInChildProcess(const std::function<int()>& probe);

// The HDF5, netCDF, Exodus II and CGNS libraries keep global state and are not built thread-safe:
// every call into them holds this lock.
std::mutex& hpcLibraryMutex();

// Checks a netCDF classic header (CDF-1/2/5; `head` is the file's first bytes) before the netCDF
// library reads it: every count must fit in the file's bytes, every variable's data in the file
// (else Truncated, or Corrupt), as the library believes the counts and allocates by them.
// needMore: the header goes on past `head` (give more of the file and check again).
struct NetcdfHeaderResult {
  Result result;
  bool needMore = false;
};
NetcdfHeaderResult checkNetcdfClassicHeader(std::string_view head, uint64_t fileSize, const std::string& label);
// The same for the file at `path`, reading as much of it as the header needs.
Result checkNetcdfClassicFile(const std::string& path);

// Where an ADF file's data ends (its header's end-of-file pointer, a byte offset); false when
// `head` (the first bytes) has no ADF header. The ADF library reads past a file's end unchecked.
bool adfDataEnd(std::string_view head, uint64_t& end);

// Closes what HDF5 still holds of the file at `path` (the CGNS library leaves groups of a file it
// failed to open behind; HDF5 would report them on stderr at exit).
void closeHdf5Leftovers(const std::string& path);

// An Exodus II file as the Exodus library may be given it (exodus_checks.cpp): a netCDF classic
// header that checks out, a file netCDF opens, and variables and attributes that hold what the
// library's buffers expect. `container` is set from the signature.
Result checkExodusFile(const std::string& path, Container& container);

// The most bytes a container of fileBytes can decode to: what it stores, or for HDF5 (which may
// compress) the deflate limit. Counts a file declares are checked against this before allocating.
uint64_t maxDecodedBytes(uint64_t fileBytes, Container c);

// Exodus II and CGNS store vectors as one scalar per component ("vel_x", "vel_y", "vel_z";
// "MomentumX", "MomentumY", "MomentumZ"). Three consecutive names that differ only in a last
// x/y/z (either case, the same for all three, after an optional '_') form a vector: names[first]
// .. names[first + 2], called `stem` ("vel", "Momentum").
struct ComponentTriple {
  std::string stem;
  size_t first = 0;
};
std::vector<ComponentTriple> componentTriples(const std::vector<std::string>& names);
// For every triple among mesh.fields[firstField ..] (or arrays[first ..]), adds the vector's
// magnitude as STEM_magnitude (the readers' name for a vector's norm; the components stay), with
// a note. A cell's magnitude is NaN where a component is.
void addComponentMagnitudes(TetMesh& mesh, size_t firstField, ReadReport& report);
void addComponentMagnitudes(std::vector<CellArray>& arrays, size_t first, ReadReport& report);
// ------------------------------------------------------------------ pieces (piece_merge.cpp)
// A mesh written in pieces (a parallel run's ranks, a multiblock's blocks, the <Piece>s of one
// VTK XML file) is read piece by piece into MeshPieces and joined by mergePieces(), which then
// hands the whole to finishMesh() like any other reader.

// VTK's ghost flags (vtkDataSetAttributes::CellGhostTypes and PointGhostTypes).
inline constexpr uint8_t kDuplicateCell = 1;   // a copy of a cell another piece owns
inline constexpr uint8_t kHiddenCell = 32;     // blanked: not part of the dataset
inline constexpr uint8_t kDuplicatePoint = 1;  // a copy of a point another piece owns
inline constexpr uint8_t kHiddenPoint = 2;     // there for the cells that use it, not shown itself

// Arrays that describe how a mesh was partitioned: they never become fields.
enum class PartitionArray { None, GhostType, GhostLevels, PointIds, CellIds };
// `idsAttribute` is the array a VTK XML <PointData GlobalIds="..."> (or <CellData>) names.
// vtkGhostType; vtkGhostLevels (VTK before 8.1: a level above 0 is a ghost); GlobalIds,
// GlobalNodeIds (Exodus) for points; GlobalIds, GlobalCellIds, GlobalElementIds for cells.
PartitionArray partitionArrayKind(std::string_view name, bool cellData, std::string_view idsAttribute = {});

struct MeshPiece {
  std::string where;                  // starts every message: "a.pvtu piece 2 (a_2.vtu)"
  std::string name;                   // in notes: "Piece 1", "piece 2 (a_2.vtu)"
  TetMesh mesh;                       // the piece's points and point fields (tets unused)
  CellSoup soup;                      // corners index this piece's points
  std::vector<CellArray> cellArrays;  // one value per input cell of the piece
  std::vector<uint8_t> pointGhost;    // vtkGhostType per point; empty when absent
  std::vector<uint8_t> cellGhost;     // vtkGhostType per input cell; empty when absent
  std::vector<int64_t> globalIds;     // per point; empty when absent
  std::string globalIdsName;          // the array they came from ("GlobalIds")
};

// Checks and keeps a partition array read as numbers: `values` holds `tuples` x `components`.
// Ghost flags must be integers 0..255 (GhostLevels: 0..255, any level above 0 is a duplicate),
// global ids integers in 0..2^53. Corrupt otherwise, naming `what` ("a.vtu: DataArray 'GlobalIds'").
// Cell global ids are only dropped. A second array of a kind that is already there is ignored.
Result takePartitionArray(PartitionArray kind, const std::string& name, const std::string& what,
                          std::span<const double> values, uint64_t components, bool cellData, MeshPiece& piece);

struct PieceMergeRules {
  // The field names a listing declares (.pvtu PPointData/PCellData, after the magnitude rule):
  // a piece without one is an error, arrays it does not declare are dropped with a note. When
  // `declared` is false, an array some piece lacks is dropped with a note naming that piece.
  bool declared = false;
  // (field name, how the listing declares it: "'v' (3 components)")
  std::vector<std::pair<std::string, std::string>> pointFields, cellFields;
  const char* joined = "concatenated";  // the note's verb for several pieces
};

// What mergePieces did, for ReadReport::format.
struct PieceMergeSummary {
  uint64_t pieces = 0;
  uint64_t ghostCells = 0;      // dropped: vtkGhostType DUPLICATECELL
  uint64_t hiddenCells = 0;     // dropped: vtkGhostType HIDDENCELL
  uint64_t duplicateCells = 0;  // dropped: a cell another piece also holds, unflagged
  uint64_t weldedPoints = 0;    // interface points: distinct points that kept cells of 2+ pieces use
  bool byGlobalIds = false;     // welded by GlobalIds (else by coordinates)
  std::string globalIdsName;
};
// ", 4 pieces, 1,234 ghost cells dropped, 5,678 interface points welded by GlobalIds".
std::string describeMerge(const PieceMergeSummary& s, const char* pieceWord = "pieces");
// "1,234".
std::string withThousands(uint64_t n);

// Joins the pieces into one mesh and finishes it (finishMesh). Per piece: ghost and hidden cells
// are dropped. Between pieces: points are welded by global id when every piece has global ids
// (points with one id must lie within kGlobalIdTolerance of each other: Corrupt otherwise, with
// counts), else by exact coordinates (finishMesh's merge of coincident vertices); a welded point
// takes the values of its owning piece (the first piece whose copy is neither DUPLICATEPOINT
// nor HIDDENPOINT), and every field's disagreements are counted in a note. Cells that two pieces
// both hold (ghost cells left unflagged) are kept once. `pieces` is consumed.
Result mergePieces(const std::string& label, std::vector<MeshPiece>& pieces, const PieceMergeRules& rules, TetMesh& out,
                   ReadReport& report, PieceMergeSummary& summary);

// The pieces of a VTK XML file, one MeshPiece per <Piece> (vtu_reader.cpp); report.format says
// what was read. readVtu() is this followed by mergePieces(). Of a file of at least shareCount
// pieces only share shareIndex is read: pieces shareIndex·n/shareCount up to
// (shareIndex + 1)·n/shareCount; of fewer unstructured pieces, the same share of every piece's
// cells and the points they span, or only those they use when they leave some of that run unused
// and the points are appended raw data (ReadReport::shared says; structured pieces are read
// whole).
Result readVtuPieces(std::string_view bytes, const std::string& label, std::vector<MeshPiece>& pieces,
                     ReadReport& report, uint32_t shareIndex = 0, uint32_t shareCount = 1);
// A legacy VTK file as one MeshPiece (vtk_reader.cpp); readLegacyVtk() merges it alone.
Result readLegacyVtkPiece(std::string_view bytes, const std::string& label, MeshPiece& piece, ReadReport& report);
// The VTKFile type attribute of a VTK XML file ("UnstructuredGrid"), from its first bytes; empty
// when there is no <VTKFile> start tag there.
std::string vtkXmlFileType(std::string_view head);

// Finds bit-equal positions (-0 = +0). Returns how many vertices have an earlier copy; remap[v]
// is the first copy of v's position (empty when there are none). (cells.cpp)
uint64_t findCoincident(const TetMesh& mesh, std::vector<uint32_t>& remap);

// Whitespace-separated text with '#' comments (TetGen, Medit), with line numbers for messages.
struct TextReader {
  std::string label;
  std::string_view s;
  size_t pos = 0;

  // "file line N" for byte position p.
  std::string at(size_t p) const {
    return label + " line " +
           std::to_string(1 + std::count(s.begin(), s.begin() + std::ptrdiff_t(std::min(p, s.size())), '\n'));
  }
  void skip() {
    while (pos < s.size()) {
      char c = s[pos];
      if (c == '#') {
        while (pos < s.size() && s[pos] != '\n') ++pos;
      } else if (isSpace(c)) {
        ++pos;
      } else {
        break;
      }
    }
  }
  std::string_view peekToken() {
    skip();
    size_t e = pos;
    while (e < s.size() && s[e] != ' ' && s[e] != '\t' && s[e] != '\r' && s[e] != '\n' && s[e] != '#') ++e;
    return s.substr(pos, e - pos);
  }
  // Number of tokens left on the current line (before a comment).
  int tokensLeftOnLine() const {
    int n = 0;
    size_t p = pos;
    while (p < s.size() && s[p] != '\n' && s[p] != '#') {
      while (p < s.size() && (s[p] == ' ' || s[p] == '\t' || s[p] == '\r')) ++p;
      if (p >= s.size() || s[p] == '\n' || s[p] == '#') break;
      ++n;
      while (p < s.size() && s[p] != ' ' && s[p] != '\t' && s[p] != '\r' && s[p] != '\n' && s[p] != '#') ++p;
    }
    return n;
  }
  // The next token as an integer / a number; Truncated at the end, Corrupt for anything else.
  Result integer(const std::string& what, int64_t& v) { return parsed(what, v, parseNextInt, "an integer"); }
  Result number(const std::string& what, double& v) { return parsed(what, v, parseNextDouble, "a number"); }

  template <typename T>
  Result parsed(const std::string& what, T& v, int (*parse)(std::string_view, size_t&, T&), const char* kind) {
    skip();
    const size_t p = pos;
    std::string_view tok = peekToken();
    if (tok.empty()) return fail(Status::Truncated, at(p) + ": file ends before " + what);
    size_t q = 0;
    if (parse(tok, q, v) != 1 || q != tok.size())
      return fail(Status::Corrupt, at(p) + ": " + what + ": '" + printable(tok) + "' is not " + kind);
    pos += tok.size();
    return Result::success();
  }
};

// Caps on what a file may declare before we believe it.
inline constexpr uint64_t kMaxComponents = 1024;  // per array tuple
inline constexpr uint64_t kMaxVertices = 0xFFFFFFFFull;
inline constexpr uint64_t kMaxPieces = uint64_t(1) << 20;  // pieces or blocks in one listing
// Points with one global id may lie this far apart, relative to the size of the model (its
// bounding-box diagonal plus its largest coordinate): float32 copies of float64 coordinates, or
// coordinates moved by a rounding, differ by far less; ids that are not global, by far more.
inline constexpr double kGlobalIdTolerance = 1e-5;

}  // namespace vtkio
}  // namespace tetstream
