// Helpers shared by the unit tests (compiled once in test_helpers.cpp).
// Each section belongs to the tests named in its heading; add new sections below.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "manifest.h"
#include "mesh.h"
#include "io/mesh_io.h"

namespace tetstream::test {

// ------------------------------------------------------------------ readers (test_readers.cpp)

// Absolute path of a file in tests/fixtures (TETSTREAM_FIXTURES).
std::string fixturePath(const std::string& name);
// Every .vtu/.vtk file in tests/fixtures, sorted by name.
std::vector<std::string> fixtureFiles();
// Whole file as bytes; empty when it cannot be read.
std::string loadFile(const std::string& path);
// Writes bytes; false on failure.
bool saveFile(const std::string& path, const std::string& bytes);
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

}  // namespace tetstream::test
