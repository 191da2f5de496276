#include "dataset.h"

#include <algorithm>
#include <cstdio>
#include <vector>

namespace tetstream {

Result readFileBytes(const std::string& path, uint64_t limit, std::vector<uint8_t>& out) {
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
  const bool err = std::ferror(f);
  std::fclose(f);
  return err ? fail(Status::IoError, path + ": read error") : Result::success();
}

uint32_t Dataset::placeOfSplit(uint32_t g) const {
  // A binary search: a hierarchy's view holds thousands of chunks, and every split asks.
  const auto after = std::upper_bound(chunkFirstSplit.begin() + 2, chunkFirstSplit.end(), g);
  return uint32_t(after - chunkFirstSplit.begin()) - 1;
}

uint32_t Dataset::chunksApplied() const {
  if (chunksReceived == 0) return 0;
  return std::min(placeOfSplit(pm.splitsApplied()), chunksReceived);
}

uint32_t Dataset::splitsThroughChunk(uint32_t index) const {
  if (index + 1 < chunkFirstSplit.size()) return chunkFirstSplit[index + 1];
  uint32_t n = 0;  // not received yet: from the manifest
  for (uint32_t c = 1; c <= index && c < manifest.chunks.size(); ++c) n += manifest.chunks[c].splits;
  return n;
}

int32_t Dataset::nodeOfChunk(uint32_t index) const {
  const std::vector<NodeInfo>& nodes = manifest.nodes;
  if (nodes.empty() || index == 0) return -1;
  auto after = std::upper_bound(nodes.begin(), nodes.end(), index,
                                [](uint32_t i, const NodeInfo& n) { return i < n.firstChunk; });
  return int32_t(after - nodes.begin()) - 1;
}

bool Dataset::canReceive(uint32_t index) const {
  if (index >= manifest.chunks.size()) return false;
  if (chunksReceived == 0) return index == 0;
  if (manifest.nodes.empty()) return index == chunksReceived;
  const int32_t k = nodeOfChunk(index);
  if (k < 0) return false;
  const NodeInfo& n = manifest.nodes[size_t(k)];
  return index == n.firstChunk + nodeChunksReceived[size_t(k)] && (n.parent < 0 || nodeComplete(uint32_t(n.parent)));
}

Result openDataset(Dataset& ds, std::string_view manifestJson) {
  Manifest m;
  if (Result r = parseManifest(manifestJson, m); !r) return r;
  ds.manifest = std::move(m);
  ds.quant = makeQuantizer(ds.manifest);
  ds.pm = ProgressiveMesh{};
  ds.chunksReceived = 0;
  ds.bytesReceived = 0;
  ds.received.clear();
  ds.payloads.clear();
  ds.chunkFirstSplit.clear();
  ds.tetsAfter.clear();
  ds.nodeIds.assign(ds.manifest.nodes.size(), {});
  ds.nodeChunksReceived.assign(ds.manifest.nodes.size(), 0);
  ds.inManifestOrder = true;
  ds.recordStart.assign(kSplitColumns, 0);
  ds.stableJ.clear();
  ds.splitsDecoded = 0;
  return Result::success();
}

namespace {

// The stable ids node k's records may name (FORMAT.md §1.1) besides its own: its ancestors' and
// the base's. A map's first runs are its node's own, one per chunk received (receiveChunk):
// chunks of several nodes may arrive interleaved, so a node's vertices need not be contiguous.
VertexIdMap ancestorIdMap(const Dataset& ds, uint32_t k) {
  VertexIdMap map;
  const Manifest& m = ds.manifest;
  for (int32_t a = m.nodes[k].parent; a >= 0; a = m.nodes[size_t(a)].parent) {
    const std::vector<VertexIdMap::Run>& up = ds.nodeIds[size_t(a)].runs;
    map.runs.insert(map.runs.end(), up.begin(), up.begin() + ds.nodeChunksReceived[size_t(a)]);
  }
  map.runs.push_back({0, m.chunks[0].vertices, 0});
  return map;
}

}  // namespace

Result receiveChunk(Dataset& ds, uint32_t index, std::span<const uint8_t> file, bool hashChecked) {
  if (!ds.canReceive(index))
    return fail(Status::BadArgument,
                "chunk " + std::to_string(index) + " received out of order" +
                    (ds.manifest.nodes.empty() ? " (next is " + std::to_string(ds.chunksReceived) + ")"
                                               : " (its node's parent is not complete)"));
  const ChunkInfo& info = ds.manifest.chunks[index];
  std::span<const uint8_t> payload;
  if (Result r = openChunk(ds.decoder, info, index, file, payload, hashChecked); !r) return r;
  if (info.kind == ChunkKind::Base) {
    TetMesh mesh;
    if (Result r = decodeBaseMesh(payload, ds.manifest, mesh); !r) return r;
    initProgressive(ds.pm, std::move(mesh));
    ds.payloads.assign(1, {});
    ds.chunkFirstSplit.assign({0, 0});
    ds.tetsAfter.assign(1, ds.pm.baseTets);
  } else {
    if (Result r = beginSplits(ds.reader, payload, info, ds.manifest); !r) return r;
    if (const int32_t k = ds.nodeOfChunk(index); k >= 0) {
      // The chunk's vertices: stable ids from where the manifest's order puts them, local ids next in the mesh.
      const VertexIdMap::Run own{ds.manifest.chunks[index - 1].vertices, info.vertices,
                                 ds.pm.baseVertices + ds.splitsReceived()};
      uint32_t& count = ds.nodeChunksReceived[size_t(k)];
      VertexIdMap& map = ds.nodeIds[size_t(k)];
      if (count == 0) map = ancestorIdMap(ds, uint32_t(k));
      map.runs.insert(map.runs.begin() + count, own);
      ++count;
    }
    ds.inManifestOrder = ds.inManifestOrder && index == ds.chunksReceived;
    ds.payloads.emplace_back(payload.begin(), payload.end());
    ds.chunkFirstSplit.push_back(ds.chunkFirstSplit.back() + info.splits);
    ds.tetsAfter.push_back(ds.tetsAfter.back() + (info.tets - ds.manifest.chunks[index - 1].tets));
  }
  ds.received.push_back(index);
  ds.chunksReceived = uint32_t(ds.received.size());
  ds.bytesReceived += info.bytes;
  return Result::success();
}

namespace {

// Drops received chunks from place `place` on (after a decode failure inside it).
void dropChunksFrom(Dataset& ds, uint32_t place) {
  for (uint32_t c = uint32_t(ds.received.size()); c-- > place;)  // (latest first: each is its node's last own run)
    if (const int32_t k = ds.nodeOfChunk(ds.received[c]); k >= 0) {
      uint32_t& count = ds.nodeChunksReceived[size_t(k)];
      --count;
      ds.nodeIds[size_t(k)].runs.erase(ds.nodeIds[size_t(k)].runs.begin() + count);
    }
  ds.received.resize(place);
  ds.payloads.resize(place);
  ds.chunkFirstSplit.resize(place + 1);
  ds.tetsAfter.resize(place);
  ds.chunksReceived = place;
  ds.bytesReceived = 0;
  for (uint32_t index : ds.received) ds.bytesReceived += ds.manifest.chunks[index].bytes;
  ds.splitsDecoded = std::min(ds.splitsDecoded, ds.chunkFirstSplit.back());
  ds.recordStart.resize(kSplitColumns * (size_t(ds.splitsDecoded) + 1));
  ds.stableJ.resize(ds.splitsDecoded);
}

// Applies split g = ds.splitsApplied() from its chunk's payload.
Result redoNext(Dataset& ds, std::vector<uint32_t>& changed) {
  const uint32_t g = ds.splitsApplied();
  const uint32_t c = ds.placeOfSplit(g);
  const uint32_t first = ds.chunkFirstSplit[c], end = ds.chunkFirstSplit[c + 1];
  const uint32_t index = ds.received[c];
  const int32_t node = ds.nodeOfChunk(index);
  SplitReader& r = ds.reader;
  // The chunk's header was checked when it was received: this only sets the cursors.
  Result res = beginSplits(r, ds.payloads[c], ds.manifest.chunks[index], ds.manifest);
  r.ids = ds.inManifestOrder || node < 0 ? nullptr : &ds.nodeIds[size_t(node)];
  if (res && g != first) {
    r.seek(&ds.recordStart[kSplitColumns * size_t(g)]);
    r.remaining = end - g;
    r.prevJ = ds.stableJ[g - 1];
  }
  if (res) res = applyNextSplit(r, ds.pm, ds.quant, changed);
  r.ids = nullptr;
  if (res && g + 1 == end) {
    if (ds.pm.vertexCount() != ds.pm.baseVertices + end || ds.pm.tetCount() != ds.tetsAfter[c])
      res = fail(Status::Corrupt, "split chunk: counts after the chunk differ from the manifest");
    else if (!r.atEnd())
      res = fail(Status::Corrupt, "split chunk: bytes after the last split");
    if (!res) undoSplit(ds.pm, changed);
  }
  if (!res) {
    while (ds.splitsApplied() > first) undoSplit(ds.pm, changed);
    dropChunksFrom(ds, c);
    res.message = "chunk " + std::to_string(index) + ": " + res.message;
    return res;
  }
  if (g == ds.splitsDecoded) {
    ds.recordStart.resize(kSplitColumns * (size_t(g) + 2));
    r.tell(&ds.recordStart[kSplitColumns * (size_t(g) + 1)]);
    ds.stableJ.push_back(r.prevJ);
    ++ds.splitsDecoded;
  }
  return res;
}

}  // namespace

Result stepTowards(Dataset& ds, uint32_t targetSplits, uint32_t maxSteps, std::vector<uint32_t>& changed,
                   bool* reached) {
  const uint32_t target = std::min(targetSplits, ds.splitsReceived());
  for (uint32_t n = 0; n < maxSteps && ds.splitsApplied() != target; ++n) {
    if (ds.splitsApplied() > target) {
      undoSplit(ds.pm, changed);
    } else if (Result r = redoNext(ds, changed); !r) {
      *reached = false;
      return r;
    }
  }
  *reached = ds.splitsApplied() == target;
  return Result::success();
}

uint32_t nodeFirstSplit(const Dataset& ds, uint32_t node) {
  for (uint32_t place = 1; place < ds.received.size(); ++place)
    if (ds.nodeOfChunk(ds.received[place]) == int32_t(node)) return ds.chunkFirstSplit[place];
  return ds.splitsReceived();
}

Result forgetNode(Dataset& ds, uint32_t node) {
  const std::vector<NodeInfo>& nodes = ds.manifest.nodes;
  if (node >= nodes.size() || ds.nodeChunksReceived[node] == 0)
    return fail(Status::BadArgument, "node " + std::to_string(node) + " has no chunk received");
  for (uint32_t k = 0; k < nodes.size(); ++k)
    if (nodes[k].parent == int32_t(node) && ds.nodeChunksReceived[k] > 0)
      return fail(Status::BadArgument, "node " + std::to_string(node) + " has a received child");
  if (ds.splitsApplied() > nodeFirstSplit(ds, node))
    return fail(Status::BadArgument, "splits of node " + std::to_string(node) + " are applied");
  // The places that stay, in order; the splits of the others leave the order, and so do their
  // vertices' places in the mesh (local ids), which the id maps' later runs move down past.
  const uint32_t base = ds.pm.baseVertices, decoded = ds.splitsDecoded;
  std::vector<uint32_t> received{ds.received[0]}, firstSplit{0, 0}, tetsAfter{ds.tetsAfter[0]};
  std::vector<std::vector<uint8_t>> payloads(1);
  std::vector<uint32_t> recordStart, stableJ;
  std::vector<std::pair<uint32_t, uint32_t>> gone;  // local vertex ranges [begin, end) given back
  for (uint32_t place = 1; place < ds.received.size(); ++place) {
    const uint32_t index = ds.received[place], g0 = ds.chunkFirstSplit[place], g1 = ds.chunkFirstSplit[place + 1];
    if (ds.nodeOfChunk(index) == int32_t(node)) {
      gone.push_back({base + g0, base + g1});
      continue;
    }
    received.push_back(index);
    payloads.push_back(std::move(ds.payloads[place]));
    firstSplit.push_back(firstSplit.back() + (g1 - g0));
    tetsAfter.push_back(tetsAfter.back() + (ds.manifest.chunks[index].tets - ds.manifest.chunks[index - 1].tets));
    for (uint32_t g = g0; g < std::min(g1, decoded); ++g) {  // (decoded splits stay a prefix of the order)
      recordStart.insert(recordStart.end(), &ds.recordStart[kSplitColumns * size_t(g)],
                         &ds.recordStart[kSplitColumns * size_t(g + 1)]);
      stableJ.push_back(ds.stableJ[g]);
    }
  }
  // Where the next record to decode starts: only read inside a chunk, where it stayed.
  recordStart.insert(recordStart.end(), &ds.recordStart[kSplitColumns * size_t(decoded)],
                     &ds.recordStart[kSplitColumns * size_t(decoded + 1)]);
  for (uint32_t k = 0; k < nodes.size(); ++k)
    for (VertexIdMap::Run& run : ds.nodeIds[k].runs) {
      uint32_t below = 0;
      for (const auto& [begin, end] : gone)
        if (begin < run.localBegin) below += end - begin;
      run.localBegin -= below;
    }
  ds.nodeIds[node] = {};
  ds.nodeChunksReceived[node] = 0;
  ds.received = std::move(received);
  ds.payloads = std::move(payloads);
  ds.chunkFirstSplit = std::move(firstSplit);
  ds.tetsAfter = std::move(tetsAfter);
  ds.splitsDecoded = uint32_t(stableJ.size());
  ds.recordStart = std::move(recordStart);
  ds.stableJ = std::move(stableJ);
  ds.chunksReceived = uint32_t(ds.received.size());
  ds.bytesReceived = 0;
  ds.inManifestOrder = true;
  for (uint32_t place = 0; place < ds.received.size(); ++place) {
    ds.bytesReceived += ds.manifest.chunks[ds.received[place]].bytes;
    ds.inManifestOrder = ds.inManifestOrder && ds.received[place] == place;
  }
  return Result::success();
}

Result applyChunk(Dataset& ds, uint32_t index, std::span<const uint8_t> file) {
  if (ds.splitsApplied() != ds.splitsReceived())
    return fail(Status::BadArgument, "applyChunk needs every received split applied first");
  if (Result r = receiveChunk(ds, index, file); !r) return r;
  std::vector<uint32_t> changed;
  for (bool reached = false; !reached;) {
    changed.clear();
    if (Result r = stepTowards(ds, ds.splitsReceived(), 1u << 16, changed, &reached); !r) return r;
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
  if (Result r = readFileBytes(dir + "/manifest.json", kManifestLimitBytes, bytes); !r) return r;
  if (Result r = openDataset(ds, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size())); !r)
    return r;
  size_t n = ds.manifest.chunks.size();
  if (maxChunks >= 0 && size_t(maxChunks) < n) n = size_t(maxChunks);
  std::vector<uint32_t> changed;
  for (uint32_t i = 0; i < n; ++i) {
    if (i > 0 && ds.pm.vertexCount() >= maxVertices) break;
    const ChunkInfo& c = ds.manifest.chunks[i];
    if (Result r = readFileBytes(dir + "/" + c.file, c.bytes, bytes); !r) {
      if (r.status == Status::TooLarge) r.status = Status::SizeMismatch;
      return r;
    }
    if (Result r = receiveChunk(ds, i, bytes); !r) return r;
    // Each split adds one vertex: stop inside the chunk at the vertex budget.
    uint32_t target = ds.splitsReceived();
    if (maxVertices != ~0u && ds.pm.baseVertices + uint64_t(target) > maxVertices)
      target = maxVertices > ds.pm.baseVertices ? maxVertices - ds.pm.baseVertices : 0;
    for (bool reached = false; !reached;) {
      changed.clear();
      if (Result r = stepTowards(ds, target, 1u << 16, changed, &reached); !r) return r;
    }
  }
  return Result::success();
}

}  // namespace tetstream
