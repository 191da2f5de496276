#include "dataset.h"

#include <algorithm>
#include <cstdio>
#include <vector>

namespace tetstream {
namespace {

Result readFile(const std::string& path, uint64_t limit, std::vector<uint8_t>& out) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return fail(Status::IoError, path + ": cannot open");
  out.clear();
  uint8_t buf[1 << 16];
  size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) {
    if (out.size() + n > limit) {
      std::fclose(f);
      return fail(Status::TooLarge, path + ": larger than " + std::to_string(limit) + " bytes");
    }
    out.insert(out.end(), buf, buf + n);
  }
  bool err = std::ferror(f);
  std::fclose(f);
  if (err) return fail(Status::IoError, path + ": read error");
  return Result::success();
}

}  // namespace

Result openDataset(Dataset& ds, std::string_view manifestJson) {
  Manifest m;
  if (Result r = parseManifest(manifestJson, m); !r) return r;
  ds.manifest = std::move(m);
  ds.quant = makeQuantizer(ds.manifest);
  ds.pm = ProgressiveMesh{};
  ds.chunksApplied = 0;
  ds.bytesApplied = 0;
  ds.chunkOpen = false;
  return Result::success();
}

Result beginChunk(Dataset& ds, uint32_t index, std::span<const uint8_t> file) {
  if (ds.chunkOpen || index != ds.chunksApplied || index >= ds.manifest.chunks.size())
    return fail(Status::BadArgument, "chunk " + std::to_string(index) + " applied out of order (next is " +
                                         std::to_string(ds.chunksApplied) + ")");
  const ChunkInfo& info = ds.manifest.chunks[index];
  std::span<const uint8_t> payload;
  if (Result r = openChunk(ds.decoder, info, index, file, payload); !r) return r;
  if (info.kind == ChunkKind::Base) {
    TetMesh mesh;
    if (Result r = decodeBaseMesh(payload, ds.manifest, mesh); !r) return r;
    initProgressive(ds.pm, std::move(mesh));
    ds.chunksApplied = 1;
    ds.bytesApplied = info.bytes;
    return Result::success();
  }
  if (Result r = beginSplits(ds.splits, payload, info, ds.manifest); !r) return r;
  ds.chunkOpen = true;
  ds.openSplitsApplied = 0;
  return Result::success();
}

Result stepChunk(Dataset& ds, uint32_t maxSplits, std::vector<uint32_t>& changed, bool* done) {
  *done = !ds.chunkOpen;
  if (!ds.chunkOpen) return Result::success();
  const ChunkInfo& info = ds.manifest.chunks[ds.chunksApplied];
  for (uint32_t n = 0; n < maxSplits && ds.splits.remaining > 0; ++n) {
    Result r = applyNextSplit(ds.splits, ds.pm, ds.quant, changed);
    if (!r) {
      // Back to the last complete chunk: a half-applied chunk is no level of the format.
      for (; ds.openSplitsApplied > 0; --ds.openSplitsApplied) undoSplit(ds.pm, changed);
      ds.chunkOpen = false;
      r.message = "chunk " + std::to_string(ds.chunksApplied) + ": " + r.message;
      return r;
    }
    ++ds.openSplitsApplied;
  }
  if (ds.splits.remaining == 0) {
    ds.chunkOpen = false;
    if (ds.pm.vertexCount() != info.vertices || ds.pm.tetCount() != info.tets) {
      for (; ds.openSplitsApplied > 0; --ds.openSplitsApplied) undoSplit(ds.pm, changed);
      return fail(Status::Corrupt, "chunk " + std::to_string(ds.chunksApplied) + ": counts after the chunk differ from the manifest");
    }
    ++ds.chunksApplied;
    ds.bytesApplied += info.bytes;
    *done = true;
  }
  return Result::success();
}

Result applyChunk(Dataset& ds, uint32_t index, std::span<const uint8_t> file) {
  if (Result r = beginChunk(ds, index, file); !r) return r;
  std::vector<uint32_t> changed;
  bool done = false;
  while (!done) {
    changed.clear();
    if (Result r = stepChunk(ds, 1u << 16, changed, &done); !r) return r;
  }
  return Result::success();
}

bool isPackedDir(const std::string& path) {
  std::FILE* f = std::fopen((path + "/manifest.json").c_str(), "rb");
  if (!f) return false;
  std::fclose(f);
  return true;
}

Result loadPackedDir(const std::string& dir, Dataset& ds, int maxChunks, uint32_t maxVertices) {
  std::vector<uint8_t> bytes;
  if (Result r = readFile(dir + "/manifest.json", 16u << 20, bytes); !r) return r;
  if (Result r = openDataset(ds, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size())); !r)
    return r;
  size_t n = ds.manifest.chunks.size();
  if (maxChunks >= 0 && size_t(maxChunks) < n) n = size_t(maxChunks);
  std::vector<uint32_t> changed;
  for (uint32_t i = 0; i < n; ++i) {
    if (i > 0 && ds.pm.vertexCount() >= maxVertices) break;
    const ChunkInfo& c = ds.manifest.chunks[i];
    if (Result r = readFile(dir + "/" + c.file, c.bytes, bytes); !r) {
      if (r.status == Status::TooLarge) r.status = Status::SizeMismatch;
      return r;
    }
    if (Result r = beginChunk(ds, i, bytes); !r) return r;
    for (bool done = false; !done;) {
      uint32_t room = ds.pm.vertexCount() < maxVertices ? maxVertices - ds.pm.vertexCount() : 0;
      if (room == 0 && ds.chunkOpen) return Result::success();  // stop inside this chunk
      changed.clear();
      if (Result r = stepChunk(ds, std::min<uint32_t>(room, 1u << 16), changed, &done); !r) return r;
    }
  }
  return Result::success();
}

}  // namespace tetstream
