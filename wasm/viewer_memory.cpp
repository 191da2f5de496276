#include "viewer_memory.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace tetstream::viewer {
namespace {

// Per-element costs in bytes (see the header for where they come from).
constexpr double kPerVertex =
    12 + 9 + 4 +
    1;  // position; star block (start, size, class); the de-duplication stamp (seen); link numbering (vertex_link.h)
constexpr double kPerFieldValue = 4;
constexpr double kPerTet = 16 + 23;       // vertex ids; 4 corners in the star pool at 1.4 slots each
constexpr double kPerSplit = 4 + 4 + 24;  // undo log (splitJ, splitTetsBefore); record offsets (one per column)
constexpr double kPerSplitKept = 4;       // undo log: j's isoField value before the split (FORMAT.md §4, flag bit 2)
constexpr double kSurfacePerTet = 56;     // isosurface + interval tree, measured 49 plus margin
constexpr double kHullPerTriangle = 110;
constexpr double kFixed = 1 << 20;  // zstd context, scratch, the JSON of the manifest

}  // namespace

LevelCounts chunkCounts(const Manifest& m, uint32_t index) {
  LevelCounts c;
  if (index >= m.chunks.size()) return c;
  const ChunkInfo& info = m.chunks[index];
  const ChunkInfo* before = index > 0 ? &m.chunks[index - 1] : nullptr;
  c.vertices = double(info.vertices) - (before ? double(before->vertices) : 0);
  c.tets = double(info.tets) - (before ? double(before->tets) : 0);
  c.largestRaw = double(info.rawBytes);
  if (index > 0) {
    c.splits = info.splits;
    c.payloadBytes = double(info.rawBytes);
  }
  return c;
}

void addCounts(LevelCounts& total, const LevelCounts& more) {
  total.vertices += more.vertices;
  total.tets += more.tets;
  total.splits += more.splits;
  total.payloadBytes += more.payloadBytes;
  total.largestRaw = std::max(total.largestRaw, more.largestRaw);
}

void subtractCounts(LevelCounts& total, const LevelCounts& less) {
  total.vertices = std::max(0.0, total.vertices - less.vertices);
  total.tets = std::max(0.0, total.tets - less.tets);
  total.splits = std::max(0.0, total.splits - less.splits);
  total.payloadBytes = std::max(0.0, total.payloadBytes - less.payloadBytes);
  // (largestRaw stays: the decoder's buffer does not shrink)
}

uint64_t estimateBytes(const Manifest& m, const LevelCounts& c) {
  const double v = c.vertices, t = c.tets;
  const double hullTriangles = 4 * std::cbrt(t * t);  // a cube of 6n³ tets has 12n² ≈ 3.6 t^(2/3)
  const double bytes = kFixed + v * (kPerVertex + kPerFieldValue * double(m.fields.size())) + t * kPerTet +
                       c.splits * (kPerSplit + kPerSplitKept) + c.payloadBytes + c.largestRaw + t * kSurfacePerTet +
                       hullTriangles * kHullPerTriangle;
  return uint64_t(bytes);
}

uint64_t estimateLevelBytes(const Manifest& m, uint32_t chunks) {
  chunks = std::min<uint32_t>(chunks, uint32_t(m.chunks.size()));
  if (chunks == 0) return 0;
  LevelCounts total;
  for (uint32_t c = 0; c < chunks; ++c) addCounts(total, chunkCounts(m, c));
  return estimateBytes(m, total);
}

uint32_t chunksThatFit(const Manifest& m, uint64_t budgetBytes) {
  // Levels only grow: the estimate is monotone in the chunk count.
  uint32_t lo = 0, hi = uint32_t(m.chunks.size());
  while (lo < hi) {
    const uint32_t mid = lo + (hi - lo + 1) / 2;
    if (estimateLevelBytes(m, mid) <= budgetBytes)
      lo = mid;
    else
      hi = mid - 1;
  }
  return lo;
}

uint64_t datasetMemoryBytes(const Dataset& ds) {
  auto bytes = [](const auto& v) { return uint64_t(v.capacity() * sizeof(v[0])); };
  const ProgressiveMesh& pm = ds.pm;
  uint64_t n = bytes(pm.mesh.positions) + bytes(pm.mesh.tets) + pm.stars.bytes() + bytes(pm.splitJ) +
               bytes(pm.splitTetsBefore) + bytes(pm.splitJValues) + bytes(pm.seen);
  for (const ScalarField& f : pm.mesh.fields) n += bytes(f.values);
  for (const auto& p : ds.payloads) n += bytes(p);
  n += bytes(ds.payloads) + bytes(ds.chunkFirstSplit) + bytes(ds.recordStart) + bytes(ds.decoder.raw);
  return n;
}

std::string formatBytes(uint64_t bytes) {
  char buf[32];
  const double mb = double(bytes) / (1 << 20);
  if (mb >= 1024)
    std::snprintf(buf, sizeof buf, "%.1f GB", mb / 1024);
  else if (mb < 1)
    std::snprintf(buf, sizeof buf, "%.0f KB", double(bytes) / 1024);
  else if (mb >= 10)
    std::snprintf(buf, sizeof buf, "%.0f MB", mb);
  else
    std::snprintf(buf, sizeof buf, "%.1f MB", mb);
  return buf;
}

}  // namespace tetstream::viewer
