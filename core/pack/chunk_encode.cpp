#include "chunk_encode.h"

#include <zstd.h>

#include <cstring>

#include "chunk.h"
#include "hash.h"

namespace tetstream {
namespace {

void putU16(std::vector<uint8_t>& b, uint16_t x) {
  b.push_back(uint8_t(x));
  b.push_back(uint8_t(x >> 8));
}
void putU32(std::vector<uint8_t>& b, uint32_t x) {
  for (int i = 0; i < 4; ++i) b.push_back(uint8_t(x >> (8 * i)));
}
template <typename T>
void putArray(std::vector<uint8_t>& b, const std::vector<T>& a) {  // little-endian host (chunk.h)
  size_t at = b.size();
  b.resize(at + a.size() * sizeof(T));
  if (!a.empty()) std::memcpy(b.data() + at, a.data(), a.size() * sizeof(T));
}

}  // namespace

void beginChunk(std::vector<uint8_t>& raw, ChunkKind kind, uint32_t index) {
  raw.insert(raw.end(), kChunkMagic, kChunkMagic + 4);
  putU16(raw, uint16_t(kChunkVersion));
  putU16(raw, uint16_t(kind));
  putU32(raw, index);
  putU32(raw, 0);
}

Result finishChunk(const std::vector<uint8_t>& raw, int level, std::vector<uint8_t>& file, ChunkInfo& info) {
  file.resize(ZSTD_compressBound(raw.size()));
  ZSTD_CCtx* cctx = ZSTD_createCCtx();
  if (!cctx) return fail(Status::TooLarge, "out of memory for the zstd context");
  ZSTD_CCtx_setParameter(cctx, ZSTD_c_compressionLevel, level);
  if (level == kTunedZstdLevel) {
    // Level 18's match finder (btultra, 21-bit tables) gains nothing on split records: btopt
    // with 17-bit hash and chain tables gives the same bytes within a fraction of a percent in
    // two thirds of the time, and small tables are quick to set up for each chunk.
    ZSTD_CCtx_setParameter(cctx, ZSTD_c_strategy, ZSTD_btopt);
    ZSTD_CCtx_setParameter(cctx, ZSTD_c_hashLog, 17);
    ZSTD_CCtx_setParameter(cctx, ZSTD_c_chainLog, 17);
  }
  ZSTD_CCtx_setParameter(cctx, ZSTD_c_contentSizeFlag, 1);
  ZSTD_CCtx_setParameter(cctx, ZSTD_c_checksumFlag, 0);  // the manifest's hash covers the file
  size_t n = ZSTD_compress2(cctx, file.data(), file.size(), raw.data(), raw.size());
  ZSTD_freeCCtx(cctx);
  if (ZSTD_isError(n)) return fail(Status::DecompressFailed, std::string("zstd: ") + ZSTD_getErrorName(n));
  file.resize(n);
  info.bytes = n;
  info.rawBytes = raw.size();
  info.hash = contentHash(file);
  return Result::success();
}

Result encodeBaseChunk(const TetMesh& mesh, uint32_t index, int level, std::vector<uint8_t>& file, ChunkInfo& info) {
  std::vector<uint8_t> raw;
  raw.reserve(kChunkHeaderBytes + kBaseHeaderBytes + 12 * size_t(mesh.vertexCount()) +
              4 * mesh.fields.size() * mesh.vertexCount() + 16 * size_t(mesh.tetCount()));
  beginChunk(raw, ChunkKind::Base, index);
  putU32(raw, mesh.vertexCount());
  putU32(raw, mesh.tetCount());
  putU32(raw, uint32_t(mesh.fields.size()));
  putU32(raw, 0);
  putArray(raw, mesh.positions);
  for (const ScalarField& f : mesh.fields) putArray(raw, f.values);
  putArray(raw, mesh.tets);
  if (Result r = finishChunk(raw, level, file, info); !r) return r;
  info.kind = ChunkKind::Base;
  info.vertices = mesh.vertexCount();
  info.tets = mesh.tetCount();
  info.splits = 0;
  return Result::success();
}

}  // namespace tetstream
