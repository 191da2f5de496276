#include <zstd.h>

#include <bit>
#include <cmath>
#include <cstring>

#include "chunk.h"
#include "hash.h"

namespace tetstream {
namespace {

uint32_t readU32(const uint8_t* p) {
  return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}
uint16_t readU16(const uint8_t* p) { return uint16_t(p[0] | p[1] << 8); }

// Copies n little-endian 32-bit words; memcpy is correct on the little-endian targets we build
// for (x86-64, wasm32), asserted at compile time.
static_assert(std::endian::native == std::endian::little, "chunk decoding assumes a little-endian host");
template <typename T>
void copyWords(const uint8_t* src, size_t n, std::vector<T>& dst) {
  dst.resize(n);
  if (n) std::memcpy(dst.data(), src, n * sizeof(T));
}

std::string chunkName(uint32_t index) { return "chunk " + std::to_string(index); }

}  // namespace

ChunkDecoder::~ChunkDecoder() { ZSTD_freeDCtx(dctx); }

Result openChunk(ChunkDecoder& dec, const ChunkInfo& info, uint32_t index, std::span<const uint8_t> file,
                 std::span<const uint8_t>& payload, bool hashChecked) {
  const std::string name = chunkName(index);
  if (file.size() != info.bytes)
    return fail(Status::SizeMismatch, name + ": " + std::to_string(file.size()) + " bytes, manifest says " +
                                          std::to_string(info.bytes) + " (truncated or wrong file)");
  if (!hashChecked && contentHash(file) != info.hash)
    return fail(Status::HashMismatch, name + ": content hash differs from the manifest (corrupt or wrong file)");
  unsigned long long declared = ZSTD_getFrameContentSize(file.data(), file.size());
  if (declared == ZSTD_CONTENTSIZE_ERROR) return fail(Status::DecompressFailed, name + ": not a zstd frame");
  if (declared != info.rawBytes)
    return fail(Status::SizeMismatch,
                name + ": zstd frame declares " +
                    (declared == ZSTD_CONTENTSIZE_UNKNOWN ? std::string("no size") : std::to_string(declared)) +
                    ", manifest says " + std::to_string(info.rawBytes) + " bytes");
  // The manifest parser enforces this too; checked again here because it guards an allocation.
  if (info.rawBytes > maxRawBytesFor(info.bytes))
    return fail(Status::TooLarge, name + ": declares " + std::to_string(info.rawBytes) +
                                      " bytes after decompression, more than " +
                                      std::to_string(maxRawBytesFor(info.bytes)) + " allowed for its size");
  if (!dec.dctx) dec.dctx = ZSTD_createDCtx();
  if (!dec.dctx) return fail(Status::TooLarge, name + ": out of memory for the zstd context");
  dec.raw.resize(info.rawBytes);
  size_t got = ZSTD_decompressDCtx(dec.dctx, dec.raw.data(), dec.raw.size(), file.data(), file.size());
  if (ZSTD_isError(got) || got != info.rawBytes) {
    std::vector<uint8_t>().swap(dec.raw);  // a refused chunk must not keep its memory
    if (ZSTD_isError(got)) return fail(Status::DecompressFailed, name + ": " + ZSTD_getErrorName(got));
    return fail(Status::SizeMismatch, name + ": decompressed to a different size than declared");
  }
  if (got < kChunkHeaderBytes) return fail(Status::Truncated, name + ": shorter than its header");
  const uint8_t* h = dec.raw.data();
  if (std::memcmp(h, kChunkMagic, 4) != 0) return fail(Status::BadMagic, name + ": not a tetstream chunk (magic)");
  if (readU16(h + 4) != kChunkVersion)
    return fail(Status::UnsupportedVersion, name + ": chunk format version " + std::to_string(readU16(h + 4)));
  uint16_t kind = readU16(h + 6);
  if (kind != uint16_t(info.kind))
    return fail(Status::Corrupt, name + ": chunk kind " + std::to_string(kind) + " where the manifest expects " +
                                     std::to_string(int(info.kind)));
  if (readU32(h + 8) != index)
    return fail(Status::Corrupt, name + ": header says it is chunk " + std::to_string(readU32(h + 8)));
  payload = std::span<const uint8_t>(dec.raw).subspan(kChunkHeaderBytes);
  return Result::success();
}

Result decodeBaseMesh(std::span<const uint8_t> payload, const Manifest& m, TetMesh& out) {
  out = TetMesh{};
  if (payload.size() < kBaseHeaderBytes) return fail(Status::Truncated, "base chunk: payload shorter than its header");
  const uint8_t* p = payload.data();
  const uint64_t V = readU32(p), T = readU32(p + 4), F = readU32(p + 8), flags = readU32(p + 12);
  const ChunkInfo& c = m.chunks.at(0);
  if (V != c.vertices || T != c.tets)
    return fail(Status::Corrupt, "base chunk: " + std::to_string(V) + " vertices / " + std::to_string(T) +
                                     " tets, manifest says " + std::to_string(c.vertices) + " / " +
                                     std::to_string(c.tets));
  if (F != m.fields.size()) return fail(Status::Corrupt, "base chunk: field count differs from the manifest");
  if (flags != 0) return fail(Status::Unsupported, "base chunk: unknown flags " + std::to_string(flags));
  const uint64_t expected = kBaseHeaderBytes + 12 * V + 4 * F * V + 16 * T;
  if (payload.size() != expected)
    return fail(Status::Corrupt, "base chunk: payload is " + std::to_string(payload.size()) + " bytes, expected " +
                                     std::to_string(expected));
  p += kBaseHeaderBytes;
  TetMesh mesh;
  mesh.name = m.name;
  copyWords(p, 3 * V, mesh.positions);
  p += 12 * V;
  for (float x : mesh.positions)
    if (!std::isfinite(x)) return fail(Status::NonFinite, "base chunk: a vertex position is NaN or infinite");
  mesh.fields.resize(F);
  for (uint64_t f = 0; f < F; ++f) {
    mesh.fields[f].name = m.fields[f].name;
    copyWords(p, V, mesh.fields[f].values);
    p += 4 * V;
  }
  copyWords(p, 4 * T, mesh.tets);
  for (uint64_t t = 0; t < T; ++t) {
    const uint32_t* v = &mesh.tets[4 * t];
    for (int k = 0; k < 4; ++k)
      if (v[k] >= V)
        return fail(Status::OutOfRange, "base chunk: tet " + std::to_string(t) + " uses vertex " +
                                            std::to_string(v[k]) + " of " + std::to_string(V));
    if (v[0] == v[1] || v[0] == v[2] || v[0] == v[3] || v[1] == v[2] || v[1] == v[3] || v[2] == v[3])
      return fail(Status::Corrupt, "base chunk: tet " + std::to_string(t) + " repeats a vertex");
  }
  out = std::move(mesh);
  return Result::success();
}

}  // namespace tetstream
