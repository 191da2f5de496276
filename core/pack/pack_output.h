// The files of a packed dataset (FORMAT.md): chunk file names, whole-or-nothing writes, and the
// manifest written last. Shared by the one-process packer and the distributed one.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "manifest.h"
#include "status.h"

namespace tetstream {

// "chunks/00012-<hash>.tsc": the index keeps the folder in manifest order, the hash makes the
// name change with the content (cacheable forever).
std::string chunkFileName(uint32_t index, uint64_t hash);

// Writes `size` bytes to `path` as a whole (a temporary file renamed into place).
Result writeWholeFile(const std::string& path, const void* data, size_t size);

// Removes the chunk files an earlier pack left in `outDir` (ours only: *.tsc names that `m` does
// not reference), then writes manifest.json and its gzipped sibling.
Result writeManifestFiles(const std::string& outDir, const Manifest& m);

}  // namespace tetstream
