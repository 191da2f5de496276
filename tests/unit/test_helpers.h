// Helpers shared by the unit tests (compiled once in test_helpers.cpp).
// Each section belongs to the tests named in its heading; add new sections below.
#pragma once
#include <array>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "io/mesh_io.h"
#include "manifest.h"
#include "mesh.h"
#include "pack/packer.h"
#include "pack/simplify.h"
#include "quantize.h"

namespace tetstream::test {

// ------------------------------------------------------------------ files and fixtures

// Absolute path of a file in tests/fixtures (TETSTREAM_FIXTURES).
std::string fixturePath(const std::string& name);
// Every .vtu/.vtk file in tests/fixtures, sorted by name.
std::vector<std::string> fixtureFiles();
// Whole file as bytes; empty when it cannot be read.
std::string loadFile(const std::string& path);
// Writes bytes; false on failure.
bool saveFile(const std::string& path, const std::string& bytes);
// A fixture folder's expectations (JSON written with the fixtures), parsed once per path; a
// discarded value when the file is missing or not JSON.
const nlohmann::json& fixtureJson(const std::string& name);
// The vertex at exactly these coordinates (compared as float), or -1.
int64_t findVertex(const TetMesh& m, double x, double y, double z);
// A fresh folder under the system temp dir, unique to this process and `name`; removed again
// when the object goes out of scope (also when an ASSERT returns early).
struct ScratchDir {
  std::string path;
  explicit ScratchDir(const std::string& name);
  ~ScratchDir();
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
};
// "\n  note" for every note of a read, for failure messages; whether a note contains needle.
inline std::string allNotes(const ReadReport& r) {
  std::string s;
  for (const std::string& n : r.notes) s += "\n  " + n;
  return s;
}
inline bool hasNote(const ReadReport& r, const std::string& needle) {
  for (const std::string& n : r.notes)
    if (n.find(needle) != std::string::npos) return true;
  return false;
}
// A failed Result with this status whose message contains needle.
#define EXPECT_FAILS(expr, wantStatus, needle)                                          \
  do {                                                                                  \
    ::tetstream::Result r_ = (expr);                                                    \
    EXPECT_EQ(r_.status, wantStatus) << statusName(r_.status) << ": " << r_.message;    \
    EXPECT_NE(r_.message.find(needle), std::string::npos) << "message: " << r_.message; \
  } while (0)
// True when /usr/bin/python3 can import meshio (checked once).
bool haveMeshioPython();
// Runs a shell command, returns its exit status and stdout.
int runCommand(const std::string& command, std::string& output);

// ------------------------------------------------------------------ tiny meshes (core tests)

// One positively oriented tet at the unit corner, field f = 0, 1, 2, 3.
inline TetMesh oneTet() {
  TetMesh m;
  m.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  m.tets = {0, 1, 2, 3};
  m.fields.push_back({"f", {0, 1, 2, 3}});
  return m;
}

// Two positively oriented tets sharing the face (1, 2, 3).
inline TetMesh twoTets() {
  TetMesh m;
  m.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1};
  m.tets = {0, 1, 2, 3, 4, 1, 3, 2};
  m.fields.push_back({"f", {0, 1, 2, 3, 4}});
  return m;
}

// Harmonic n³ with both generated fields ("harmonic", then "distance").
TetMesh harmonicMesh(uint32_t n);

// A fresh, empty folder `name` inside a scratch folder shared by one test suite; everything is
// removed when the test program exits.
std::string suiteDir(const std::string& suite, const std::string& name);

// A hostile but consistently hashed split chunk: `file` with its last record cut short,
// recompressed; `info` (the manifest entry) is updated to match, so only applying finds it.
std::vector<uint8_t> forgeTruncatedChunk(const std::vector<uint8_t>& file, ChunkInfo& info);

// A file's bytes as a byte vector (for the chunk decoder's span).
inline std::vector<uint8_t> loadBytes(const std::string& path) {
  std::string s = loadFile(path);
  return std::vector<uint8_t>(s.begin(), s.end());
}

// ------------------------------------------------------------------ cells (test_formats.cpp, test_cells.cpp)

// Sum of the tets' unsigned volumes.
double totalVolume(const TetMesh& m);
// Area of the boundary surface (a split that does not conform leaves inner faces on it).
// The boundary faces as outward-wound vertex triples (adjacency.h's extractBoundary).
std::vector<uint32_t> boundaryTriangles(const TetMesh& m);
double boundaryArea(const TetMesh& m);
// A conforming, valid mesh: every inner face shared by exactly two tets, a closed manifold
// boundary, one orientation, no flat or duplicate tets, no unused vertices.
void expectValid(const TetMesh& m, const std::string& what);

// ------------------------------------------------------------------ packs and levels
// (test_pack_roundtrip.cpp, test_simplify*.cpp, test_split_stream.cpp, test_level_error.cpp,
// test_renumber.cpp, test_dataset_level.cpp)

// A fresh folder `name` in the scratch folder of the packing tests.
std::string tempDir(const std::string& name);
inline TetMesh harmonic(uint32_t n) { return harmonicMesh(n); }
inline uint32_t gridVertex(uint32_t n, uint32_t i, uint32_t j, uint32_t k) { return i + n * (j + n * k); }

// Chunk `info` of the pack in `dir`, decompressed (empty when that fails).
std::vector<uint8_t> rawChunk(const std::string& dir, const ChunkInfo& info);

// Harmonic n³ without the tets whose centroid `drop` selects, and without the vertices no
// tet uses any more.
TetMesh carved(uint32_t n, bool (*drop)(const float* centroid));
// The octant x, y, z > 0 removed: a non-convex domain with concave creases.
TetMesh lShape(uint32_t n);

// The simplifier's result as a mesh (all input vertices kept, the surviving tets).
TetMesh baseMeshOf(const TetMesh& m, const SimplifyResult& r);
// The coarsest level as the simplifier leaves it: alive vertices and tets, the steering field's
// values as fitted.
TetMesh coarseMesh(const TetMesh& in, const SimplifyResult& r);

// V − E + F of the boundary surface: 2 for a ball-shaped domain, 0 for one with a tunnel.
long boundaryEuler(const TetMesh& m);
double meshVolume(const TetMesh& m);

// Packs m into tempDir(name) at zstd level 3 (expects success); returns the folder.
std::string pack(const std::string& name, const TetMesh& m, PackOptions o, PackSummary* summary = nullptr);

// Asserts what FORMAT.md promises for every level.
void expectValidLevel(const TetMesh& m, const std::string& what);
// Compares the fully refined mesh with the input: same vertex set (positions to within half a
// grid step per coordinate, or bit-exact) and the same tets with the same orientation.
void expectSameMesh(const TetMesh& in, const TetMesh& out, const Quantizer& q, bool exact);
// Two packed folders hold the same bytes: manifest and every chunk file.
void expectSamePack(const std::string& a, const std::string& b);
// Packs m in small chunks, simplified all the way, and checks every prefix: valid, counts as
// the manifest says, field error not growing; the last level is the input.
void roundTrip(const std::string& name, const TetMesh& m, PackOptions o);

// By brute force, the coarse tet that holds p best (largest smallest barycentric coordinate,
// returned) and p's barycentric coordinates in it.
double bestTet(const TetMesh& coarse, const float* p, uint32_t& tet, double w[4]);
// RMS over the input's vertices of (coarse field interpolated there − input value).
double fieldRms(const TetMesh& in, const TetMesh& coarse, int field);

// A mesh's tets by their corners' coordinates (each sorted), sorted: equal for the same tets
// whatever the vertex numbering.
using Corner = std::array<float, 3>;
std::vector<std::array<Corner, 4>> tetsByCorners(const TetMesh& m);

// The options of process `index` of `count` (ReadOptions::shareIndex, shareCount).
ReadOptions shareOf(uint32_t index, uint32_t count);

// Reads the file at `path` in `count` shares: every share reads and says it is one
// (ReadReport::shared), and with `nonEmpty` holds a tet at least. Returns their tets in all.
uint64_t tetsOfShares(const std::string& path, uint32_t count, bool nonEmpty);

// Reads the file at `path` in `count` shares: each holds only points its tets use (read no
// others: io/row_pick.h), and its reader says how many it read ("the N " + noteTail).
void expectSharesReadOnlyUsedPoints(const std::string& path, uint32_t count, const std::string& noteTail);

// `m` with its points in a shuffled order (the same every time), as a solver that numbers points
// and cells each its own way writes them: a run of the tets uses points from all over.
TetMesh shuffledPoints(const TetMesh& m);

// Reads the file at `path` in `count` shares (ReadOptions::shareIndex, as the processes of a
// distributed pack do): each is a share (ReadReport::shared) with fewer points than the whole,
// each point's values are the whole's at that position, and together the shares hold every tet
// of the whole once. Cell data (`skipField`, and NAME_cell) is left out: it becomes point values
// by averaging over the cells read, on a cut over fewer cells (core/dist averages it over every
// rank's cells).
void expectSharesMakeTheWhole(const std::string& path, uint32_t count, const std::string& skipField = "");

}  // namespace tetstream::test
