// What the fuzz targets run, one function per parser of untrusted bytes. The same functions are
// called by libFuzzer (tests/fuzz/fuzz_*.cpp, clang -fsanitize=fuzzer) and by an ordinary unit
// test that replays the committed corpus (tests/unit/test_fuzz_corpus.cpp, plain g++), so every
// input the fuzzers found interesting, and every past finding, is checked on each `npm test`.
//
// Each function returns normally for any input; a broken invariant calls fuzzCheckFailed(),
// which aborts (the fuzzer records a crash, the replay test dies with the message).
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace tetstream::fuzz {

// manifest.json: parse; what parses must write and parse back to the same manifest.
void manifest(const uint8_t* data, size_t size);

// A split chunk against a real small dataset. data[0] picks the chunk that is replaced and
// how: bit 0 clear, the rest of the input is the chunk's decompressed payload (compressed and
// hashed here, so the fuzzer reaches the record decoder); set, it is the chunk file itself
// (zstd frame and header). Either way the manifest's size and hash are made to match, so only
// the decoder stands between the bytes and the mesh. A chunk that fails must leave the dataset
// exactly at the level before it; one that succeeds must leave a structurally valid mesh.
void splitChunk(const uint8_t* data, size_t size);

// The first chunk of a node of a patch hierarchy (FORMAT.md §1.1), applied to a partial dataset
// that holds its ancestors (partial.h): data[0] picks the node (not a root) and, as for
// splitChunk, whether the rest is the payload or the file. A chunk that fails must leave the
// mesh exactly as it was; one that applies must leave a structurally valid mesh that undoing
// the node takes back exactly.
void nodeChunk(const uint8_t* data, size_t size);

// The base-mesh chunk's payload (decompressed), with matching manifest counts where possible.
void baseChunk(const uint8_t* data, size_t size);

// A mesh file of the given extension (".vtu", ".vtk", ...) through readMeshBytes; what reads
// must be a mesh whose tets reference existing vertices and whose fields have one value each.
void meshFile(const char* extension, const uint8_t* data, size_t size);

// The checks made before the Exodus II and CGNS libraries see a file (readers.h): a netCDF
// classic header against the file's size (whole, and from its first half, which must ask for
// more or agree), and an ADF header's end-of-file pointer. Never a crash, nor a huge allocation.
void hpcHeaders(const uint8_t* data, size_t size);

// Runs the target of that name ("manifest", "split-chunk", "node-chunk", "base-chunk", "mesh-vtu" for
// meshFile(".vtu"), ..., "mesh-xdmf" for meshFile(".xdmf": the XML and its XML data items; heavy
// data in other files is refused from bytes), "pair-tetgen" for twoFiles("tetgen"), ...,
// "hpc-headers", "listing"). False for an unknown name.
bool runTarget(const std::string& name, const uint8_t* data, size_t size);

// The formats made of two files (TetGen .node + .ele, Medit .mesh + .sol, PLOT3D grid + Q):
// the first 4 bytes (little-endian) give the length of the first file, the rest is the second.
// `format` is "tetgen", "medit" or "plot3d".
void twoFiles(const char* format, const uint8_t* data, size_t size);

// A listing of pieces (.pvtu, .vtm, .pvtk) with the files it names, all in memory, through
// readListing: data[0] % 3 picks the listing's extension (.pvtu, .vtm, .pvtk); then records of
// [u16 name length][name][u32 length][bytes], little-endian, cut short where the input ends. The
// first record is the listing, the others the files a piece path may name. What reads must be a
// mesh as meshFile() checks it.
void listing(const uint8_t* data, size_t size);

// Real inputs to start fuzzing from (for tests/fuzz/run.sh): name -> bytes, per target.
std::vector<std::pair<std::string, std::vector<uint8_t>>> seeds(const std::string& target);

[[noreturn]] void fuzzCheckFailed(const char* what, const char* file, int line);

}  // namespace tetstream::fuzz

#define FUZZ_CHECK(x)                                                     \
  do {                                                                    \
    if (!(x)) ::tetstream::fuzz::fuzzCheckFailed(#x, __FILE__, __LINE__); \
  } while (0)
