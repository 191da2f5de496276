#include "partial.h"

#include <algorithm>
#include <cstdio>

#include "dataset.h"

namespace tetstream {

std::vector<uint32_t> nodesForIsovalue(const Manifest& m, int field, float isovalue) {
  std::vector<uint32_t> out;
  if (field < 0 || size_t(field) >= m.fields.size()) return out;
  for (uint32_t k = 0; k < m.nodes.size(); ++k) {
    const Range& r = m.nodes[k].ranges[size_t(field)];
    if (r.min <= isovalue && isovalue <= r.max) out.push_back(k);
  }
  return out;
}

FrontierError frontierFieldError(const Manifest& m, std::span<const uint8_t> applied) {
  FrontierError e;
  bool measured = true;
  for (size_t k = 0; k < m.nodes.size() && k < applied.size(); ++k) {
    const NodeInfo& n = m.nodes[k];
    if (applied[k] || (n.parent >= 0 && !applied[size_t(n.parent)])) continue;
    e.estimate = std::max(e.estimate, n.fieldError);
    measured = measured && n.fieldMax >= 0;
    e.measured = std::max(e.measured, n.fieldMax);
  }
  if (!measured) e.measured = -1;
  return e;
}

std::vector<uint32_t> withAncestors(const Manifest& m, std::span<const uint32_t> nodes) {
  std::vector<uint8_t> in(m.nodes.size(), 0);
  for (uint32_t k : nodes)
    for (int32_t n = int32_t(k); n >= 0 && !in[size_t(n)]; n = m.nodes[size_t(n)].parent) in[size_t(n)] = 1;
  std::vector<uint32_t> out;
  for (uint32_t k = 0; k < in.size(); ++k)
    if (in[k]) out.push_back(k);
  return out;
}

std::vector<uint32_t> PartialDataset::stableVertexIds() const {
  std::vector<uint32_t> ids(pm.vertexCount());
  const uint32_t base = manifest.chunks[0].vertices;
  for (uint32_t v = 0; v < base && v < ids.size(); ++v) ids[v] = v;
  for (uint32_t k : applied) {
    const NodeInfo& n = manifest.nodes[k];
    for (uint32_t s = n.vertexBegin; s < n.vertexEnd; ++s) ids[vertexStart[k] + (s - n.vertexBegin)] = s;
  }
  return ids;
}

Result openPartial(PartialDataset& pd, std::string_view manifestJson, const ChunkSource& read) {
  pd.pm = ProgressiveMesh{};
  pd.applied.clear();
  pd.bytesLoaded = 0;
  if (Result r = parseManifest(manifestJson, pd.manifest); !r) return r;
  pd.quant = makeQuantizer(pd.manifest);
  pd.vertexStart.assign(pd.manifest.nodes.size(), PartialDataset::kNotLoaded);
  std::vector<uint8_t> file;
  if (Result r = read(0, file); !r) return r;
  const ChunkInfo& info = pd.manifest.chunks[0];
  std::span<const uint8_t> payload;
  if (Result r = openChunk(pd.decoder, info, 0, file, payload); !r) return r;
  TetMesh mesh;
  if (Result r = decodeBaseMesh(payload, pd.manifest, mesh); !r) return r;
  initProgressive(pd.pm, std::move(mesh));
  pd.bytesLoaded = info.bytes;
  return Result::success();
}

namespace {

// "node 12 (region [x0, y0, z0] .. [x1, y1, z1])": where a failure is, for the user.
std::string nodeName(const Manifest& m, uint32_t k) {
  const Bounds& b = m.nodes[k].bounds;
  char buf[160];
  std::snprintf(buf, sizeof buf, "node %u (region [%g, %g, %g] .. [%g, %g, %g])", k, b.min[0], b.min[1], b.min[2],
                b.max[0], b.max[1], b.max[2]);
  return buf;
}

// The runs of stable ids that node k's records may name: the base's, its ancestors', its own.
VertexIdMap idMapFor(const PartialDataset& pd, uint32_t k) {
  VertexIdMap map;
  const Manifest& m = pd.manifest;
  for (int32_t n = int32_t(k); n >= 0; n = m.nodes[size_t(n)].parent) {
    const NodeInfo& node = m.nodes[size_t(n)];
    const uint32_t start = uint32_t(n) == k ? pd.pm.vertexCount() : pd.vertexStart[size_t(n)];
    map.runs.push_back({node.vertexBegin, node.vertexEnd, start});
  }
  map.runs.push_back({0, m.chunks[0].vertices, 0});
  std::reverse(map.runs.begin(), map.runs.end());
  return map;
}

}  // namespace

Result applyNode(PartialDataset& pd, uint32_t k, const ChunkSource& read, std::vector<uint32_t>* changedOut) {
  const Manifest& m = pd.manifest;
  if (k >= m.nodes.size()) return fail(Status::BadArgument, "no node " + std::to_string(k));
  const NodeInfo& node = m.nodes[k];
  if (pd.loaded(k)) return fail(Status::BadArgument, nodeName(m, k) + " is applied already");
  if (node.parent >= 0 && !pd.loaded(uint32_t(node.parent)))
    return fail(Status::BadArgument, nodeName(m, k) + " needs its parent, node " + std::to_string(node.parent));
  const VertexIdMap ids = idMapFor(pd, k);
  const uint32_t splitsBefore = pd.pm.splitsApplied(), vertexStart = pd.pm.vertexCount();
  std::vector<uint8_t> file;
  std::vector<uint32_t> own;
  std::vector<uint32_t>& changed = changedOut ? *changedOut : own;
  auto undo = [&](Result r) {
    while (pd.pm.splitsApplied() > splitsBefore) undoSplit(pd.pm, changed);
    r.message = nodeName(m, k) + ": " + r.message;
    return r;
  };
  uint64_t bytes = 0;
  for (uint32_t c = node.firstChunk; c < node.firstChunk + node.chunkCount; ++c) {
    const ChunkInfo& info = m.chunks[c];
    std::span<const uint8_t> payload;
    if (Result r = read(c, file); !r) return undo(r);
    if (Result r = openChunk(pd.decoder, info, c, file, payload); !r) return undo(r);
    if (Result r = beginSplits(pd.reader, payload, info, m); !r) return undo(r);
    pd.reader.ids = &ids;
    for (uint32_t s = 0; s < info.splits; ++s) {
      if (!changedOut) changed.clear();
      if (Result r = applyNextSplit(pd.reader, pd.pm, pd.quant, changed); !r) return undo(r);
    }
    if (Result r = endSplits(pd.reader); !r) return undo(r);
    bytes += info.bytes;
  }
  pd.reader.ids = nullptr;
  pd.vertexStart[k] = vertexStart;
  pd.applied.push_back(k);
  pd.bytesLoaded += bytes;
  return Result::success();
}

void undoLastNode(PartialDataset& pd, std::vector<uint32_t>* changedOut) {
  if (pd.applied.empty()) return;
  const uint32_t k = pd.applied.back();
  const NodeInfo& node = pd.manifest.nodes[k];
  std::vector<uint32_t> own;
  std::vector<uint32_t>& changed = changedOut ? *changedOut : own;
  for (uint32_t s = node.vertexBegin; s < node.vertexEnd; ++s) {
    if (!changedOut) changed.clear();
    undoSplit(pd.pm, changed);
  }
  pd.vertexStart[k] = PartialDataset::kNotLoaded;
  pd.applied.pop_back();
  for (uint32_t c = node.firstChunk; c < node.firstChunk + node.chunkCount; ++c)
    pd.bytesLoaded -= pd.manifest.chunks[c].bytes;
}

Result readManifestFile(const std::string& dir, std::string& json) {
  std::vector<uint8_t> bytes;
  if (Result r = readFileBytes(dir + "/manifest.json", kManifestLimitBytes, bytes); !r) return r;
  json.assign(bytes.begin(), bytes.end());
  return Result::success();
}

Result loadPartialDir(const std::string& dir, std::span<const uint32_t> nodes, PartialDataset& pd) {
  std::string json;
  if (Result r = readManifestFile(dir, json); !r) return r;
  ChunkSource read = [&](uint32_t index, std::vector<uint8_t>& file) {
    const ChunkInfo& c = pd.manifest.chunks[index];
    Result r = readFileBytes(dir + "/" + c.file, c.bytes, file);
    if (r.status == Status::TooLarge) r.status = Status::SizeMismatch;
    return r;
  };
  if (Result r = openPartial(pd, json, read); !r) return r;
  for (uint32_t k : nodes)
    if (k >= pd.manifest.nodes.size()) return fail(Status::BadArgument, "no node " + std::to_string(k));
  for (uint32_t k : withAncestors(pd.manifest, nodes))
    if (Result r = applyNode(pd, k, read); !r) return r;
  return Result::success();
}

}  // namespace tetstream
