// The format back ends behind mesh_io.h, plus the pieces the two VTK readers share.
// Callers normally use readMesh/readMeshBytes/writeMesh; tests call these directly on bytes.
#pragma once
#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "mesh.h"
#include "pack/mesh_io.h"
#include "status.h"

namespace tetstream {

// VTK XML UnstructuredGrid (.vtu): format="ascii", inline "binary" (base64) and appended data
// (encoding="raw" or "base64"), optionally vtkZLibDataCompressor, header_type UInt32 or UInt64,
// LittleEndian or BigEndian. Several Pieces are concatenated. `label` names the source in messages.
Result readVtu(std::string_view bytes, const std::string& label, TetMesh& out, ReadReport& report);

// Legacy VTK (.vtk) DATASET UNSTRUCTURED_GRID, ASCII or BINARY (big-endian), versions up to 5.1:
// classic CELLS n size and the 5.1 OFFSETS/CONNECTIVITY layout; POINT_DATA SCALARS, VECTORS,
// NORMALS, TENSORS(6) and FIELD arrays become fields; CELL_DATA is skipped with a note.
Result readLegacyVtk(std::string_view bytes, const std::string& label, TetMesh& out, ReadReport& report);

// VTK XML, appended raw binary: Float32 points, Int64 connectivity/offsets, UInt8 types, Float32
// point data. One fwrite per array; writes PATH.tmp, then renames.
Result writeVtu(const std::string& path, const TetMesh& mesh);

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

// Untrusted text for a message: at most 40 characters, non-printable bytes as '?'.
std::string printable(std::string_view s);

// "VTK_HEXAHEDRON" for 12; "VTK cell type 99" for a number VTK does not define.
std::string vtkCellTypeName(int64_t type);

// Counts of what appendTets kept and dropped, over all pieces of a file.
struct CellTally {
  uint64_t cells = 0;
  uint64_t quadraticTets = 0;
  std::map<int64_t, uint64_t> skipped;  // VTK type -> count
};

// Cell c of a piece uses connectivity[offsets[c] .. offsets[c+1]); offsets has types.size()+1
// entries. Tets (and the corners of quadratic tets) are appended to mesh.tets with ids shifted by
// vertexBase; ids must be < pieceVertexCount. `where` starts every message ("a.vtu" or
// "a.vtu Piece 2"). Corrupt for bad offsets or a tet of the wrong size, OutOfRange for an id.
Result appendTets(const std::string& where, std::span<const int64_t> connectivity, std::span<const int64_t> offsets,
                  std::span<const int64_t> types, uint64_t vertexBase, uint64_t pieceVertexCount, TetMesh& mesh,
                  CellTally& tally);

// `tuples` holds vertexCount tuples of `components` values. Returns the scalar per tuple: the
// value itself for 1 component, else the tuple's Euclidean norm.
std::vector<float> tuplesToScalars(std::span<const double> tuples, uint32_t components);
// "NAME" for 1 component, "NAME_magnitude" otherwise; a note says what was converted.
std::string fieldNameFor(const std::string& arrayName, uint32_t components, ReadReport& report);
// Adds the field unless a field of that name exists (then a note says it was dropped).
void addField(TetMesh& mesh, ScalarField field, ReadReport& report);

// Checks shared by every reader once all cells are in: vertex/tet counts within uint32, finite
// coordinates (NonFinite names the vertex), at least one tet (NoTets lists what was found), and
// notes for quadratic tets, skipped cells and non-finite field values. Fills report.skippedCells.
Result finishMesh(const std::string& label, TetMesh& mesh, const CellTally& tally, ReadReport& report);

// Caps on what a file may declare before we believe it.
inline constexpr uint64_t kMaxComponents = 1024;  // per array tuple
inline constexpr uint64_t kMaxVertices = 0xFFFFFFFFull;

}  // namespace vtkio
}  // namespace tetstream
