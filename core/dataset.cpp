#include "dataset.h"

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
  ds.mesh = TetMesh{};
  ds.chunksApplied = 0;
  ds.bytesApplied = 0;
  return Result::success();
}

Result applyChunk(Dataset& ds, uint32_t index, std::span<const uint8_t> file) {
  if (index != ds.chunksApplied || index >= ds.manifest.chunks.size())
    return fail(Status::BadArgument, "chunk " + std::to_string(index) + " applied out of order (next is " +
                                         std::to_string(ds.chunksApplied) + ")");
  const ChunkInfo& info = ds.manifest.chunks[index];
  std::span<const uint8_t> payload;
  if (Result r = openChunk(ds.decoder, info, index, file, payload); !r) return r;
  if (info.kind != ChunkKind::Base)
    return fail(Status::Unsupported, "chunk " + std::to_string(index) +
                                         ": vertex-split chunks are not supported by this version of tetstream");
  TetMesh mesh;
  if (Result r = decodeBaseMesh(payload, ds.manifest, mesh); !r) return r;
  ds.mesh = std::move(mesh);
  ds.chunksApplied = index + 1;
  ds.bytesApplied += info.bytes;
  return Result::success();
}

bool isPackedDir(const std::string& path) {
  std::FILE* f = std::fopen((path + "/manifest.json").c_str(), "rb");
  if (!f) return false;
  std::fclose(f);
  return true;
}

Result loadPackedDir(const std::string& dir, Dataset& ds, int maxChunks) {
  std::vector<uint8_t> bytes;
  if (Result r = readFile(dir + "/manifest.json", 16u << 20, bytes); !r) return r;
  if (Result r = openDataset(ds, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size())); !r)
    return r;
  size_t n = ds.manifest.chunks.size();
  if (maxChunks >= 0 && size_t(maxChunks) < n) n = size_t(maxChunks);
  for (uint32_t i = 0; i < n; ++i) {
    const ChunkInfo& c = ds.manifest.chunks[i];
    if (Result r = readFile(dir + "/" + c.file, c.bytes, bytes); !r) {
      if (r.status == Status::TooLarge) r.status = Status::SizeMismatch;
      return r;
    }
    if (Result r = applyChunk(ds, i, bytes); !r) return r;
  }
  return Result::success();
}

}  // namespace tetstream
