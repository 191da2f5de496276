#include "harness.h"

#include <unistd.h>
#include <zstd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <string_view>

#include "chunk.h"
#include "dataset.h"
#include "hash.h"
#include "io/generators.h"
#include "io/mesh_io.h"
#include "io/readers.h"
#include "manifest.h"
#include "pack/chunk_encode.h"
#include "pack/packer.h"
#include "partial.h"
#include "validate.h"

namespace tetstream::fuzz {
namespace {

// A small real dataset, packed once per process: a base and several split chunks.
struct Context {
  std::string manifestJson;
  std::vector<std::vector<uint8_t>> files;  // chunk files in manifest order
};

std::vector<uint8_t> readAll(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// `mesh` packed with `o` into a scratch folder, read back whole.
Context packedContext(TetMesh mesh, PackOptions o, const char* tag) {
  o.zstdLevel = 1;
  o.chunkKb = 1;
  const auto dir = std::filesystem::temp_directory_path() / (std::string(tag) + "-" + std::to_string(getpid()));
  PackSummary summary;
  if (!packMesh(std::move(mesh), dir.string(), o, summary))
    fuzzCheckFailed("packing the fuzz dataset", __FILE__, __LINE__);
  Context c;
  std::vector<uint8_t> json = readAll(dir / "manifest.json");
  c.manifestJson.assign(json.begin(), json.end());
  for (const ChunkInfo& info : summary.manifest.chunks) c.files.push_back(readAll(dir / info.file));
  std::filesystem::remove_all(dir);
  return c;
}

const Context& context() {
  static const Context ctx = [] {
    TetMesh mesh = makeGridMesh(6);
    addHarmonicField(mesh);
    mesh.name = "fuzz";
    PackOptions o;
    o.baseVertices = 24;
    o.minBaseVertices = 8;
    Context c = packedContext(std::move(mesh), o, "tetstream-fuzz");
    if (c.files.size() < 3) fuzzCheckFailed("the fuzz dataset needs two split chunks", __FILE__, __LINE__);
    return c;
  }();
  return ctx;
}

// Copies every member but the (uncopyable, stateless between chunks) zstd context.
void copyState(Dataset& to, const Dataset& from) {
  to.manifest = from.manifest;
  to.quant = from.quant;
  to.pm = from.pm;
  to.chunksReceived = from.chunksReceived;
  to.bytesReceived = from.bytesReceived;
  to.received = from.received;
  to.payloads = from.payloads;
  to.chunkFirstSplit = from.chunkFirstSplit;
  to.tetsAfter = from.tetsAfter;
  to.nodeIds = from.nodeIds;
  to.nodeChunksReceived = from.nodeChunksReceived;
  to.inManifestOrder = from.inManifestOrder;
  to.recordStart = from.recordStart;
  to.stableJ = from.stableJ;
  to.splitsDecoded = from.splitsDecoded;
  to.reader = from.reader;
}

// ds with the real chunks before `index` received and applied. Prepared once per index and
// copied for each input: replaying the real chunks every time made the fuzzer ten times slower.
void openAt(Dataset& ds, uint32_t index) {
  static std::vector<std::unique_ptr<Dataset>> prepared;
  const Context& ctx = context();
  if (prepared.size() <= index) prepared.resize(index + 1);
  if (!prepared[index]) {
    auto p = std::make_unique<Dataset>();
    FUZZ_CHECK(openDataset(*p, ctx.manifestJson));
    std::vector<uint32_t> changed;
    for (uint32_t c = 0; c < index; ++c) {
      FUZZ_CHECK(receiveChunk(*p, c, ctx.files[c]));
      bool reached = false;
      FUZZ_CHECK(stepTowards(*p, p->splitsReceived(), ~0u, changed, &reached) && reached);
    }
    prepared[index] = std::move(p);
  }
  copyState(ds, *prepared[index]);
}

// The chunk file for a payload, with the manifest entry made to match it.
std::vector<uint8_t> chunkFromPayload(ChunkKind kind, uint32_t index, const uint8_t* data, size_t size,
                                      ChunkInfo& info) {
  static ZSTD_CCtx* cctx = ZSTD_createCCtx();  // one context for every input: much faster
  std::vector<uint8_t> raw;
  beginChunk(raw, kind, index);
  raw.insert(raw.end(), data, data + size);
  std::vector<uint8_t> file(ZSTD_compressBound(raw.size()));
  const size_t n = ZSTD_compressCCtx(cctx, file.data(), file.size(), raw.data(), raw.size(), 1);
  FUZZ_CHECK(!ZSTD_isError(n));
  file.resize(n);
  info.bytes = n;
  info.rawBytes = raw.size();
  info.hash = contentHash(file);
  return file;
}

// The manifest entry made to match a chunk file given as it is.
void matchFile(std::span<const uint8_t> file, ChunkInfo& info) {
  info.bytes = file.size();
  info.hash = contentHash(file);
  unsigned long long declared = ZSTD_getFrameContentSize(file.data(), file.size());
  if (declared != ZSTD_CONTENTSIZE_ERROR && declared != ZSTD_CONTENTSIZE_UNKNOWN) info.rawBytes = declared;
}

void checkStructure(const TetMesh& m) {
  const ValidationReport v = validateMesh(m);
  FUZZ_CHECK(!v.fatal());
  FUZZ_CHECK(m.positions.size() == 3 * size_t(m.vertexCount()));
  for (const ScalarField& f : m.fields) FUZZ_CHECK(f.values.size() == m.vertexCount());
}

// What a reader promises (mesh_io.h); flaws such as a tet with a repeated vertex are the
// packer's to report, so they may pass here.
void checkReaderPromise(const TetMesh& m) {
  FUZZ_CHECK(m.tetCount() > 0);
  for (uint32_t v : m.tets) FUZZ_CHECK(v < m.vertexCount());
  for (float x : m.positions) FUZZ_CHECK(std::isfinite(x));
  FUZZ_CHECK(m.positions.size() == 3 * size_t(m.vertexCount()));
  for (const ScalarField& f : m.fields) FUZZ_CHECK(f.values.size() == m.vertexCount());
}

std::span<const uint8_t> payloadOf(ChunkDecoder& dec, const ChunkInfo& info, uint32_t index,
                                   const std::vector<uint8_t>& file) {
  std::span<const uint8_t> payload;
  FUZZ_CHECK(openChunk(dec, info, index, file, payload));
  return payload;
}

}  // namespace

void fuzzCheckFailed(const char* what, const char* file, int line) {
  std::fprintf(stderr, "fuzz check failed: %s (%s:%d)\n", what, file, line);
  std::abort();
}

void manifest(const uint8_t* data, size_t size) {
  Manifest m;
  if (!parseManifest(std::string_view(reinterpret_cast<const char*>(data), size), m)) return;
  const std::string once = writeManifest(m);
  Manifest again;
  FUZZ_CHECK(parseManifest(once, again));
  FUZZ_CHECK(writeManifest(again) == once);
}

void splitChunk(const uint8_t* data, size_t size) {
  if (size < 1) return;
  const Context& ctx = context();
  const uint32_t splitChunks = uint32_t(ctx.files.size() - 1);
  const uint32_t index = 1 + (data[0] >> 1) % splitChunks;
  static Dataset ds;  // reused: its zstd context was a tenth of the time when made per input
  openAt(ds, index);
  const uint32_t splitsBefore = ds.splitsApplied(), tetsBefore = ds.pm.mesh.tetCount();
  const uint32_t verticesBefore = ds.pm.mesh.vertexCount();
  const std::vector<uint32_t> tetsCopy = ds.pm.mesh.tets;

  std::vector<uint8_t> file;
  ChunkInfo& info = ds.manifest.chunks[index];
  if (data[0] & 1) {
    file.assign(data + 1, data + size);
    matchFile(file, info);
  } else {
    file = chunkFromPayload(ChunkKind::Splits, index, data + 1, size - 1, info);
  }
  std::vector<uint32_t> changed;
  bool reached = false;
  if (!receiveChunk(ds, index, file)) {
    FUZZ_CHECK(ds.chunksReceived == index && ds.splitsApplied() == splitsBefore);
    return;
  }
  if (!stepTowards(ds, ds.splitsReceived(), ~0u, changed, &reached)) {
    // A bad record undoes its whole chunk: back to exactly the level before it.
    FUZZ_CHECK(ds.chunksReceived == index && ds.splitsApplied() == splitsBefore);
    FUZZ_CHECK(ds.pm.mesh.tetCount() == tetsBefore && ds.pm.mesh.vertexCount() == verticesBefore);
    FUZZ_CHECK(ds.pm.mesh.tets == tetsCopy);
    return;
  }
  FUZZ_CHECK(reached);
  checkStructure(ds.pm.mesh);
  // Whatever the chunk did, the level slider can take it back exactly.
  FUZZ_CHECK(stepTowards(ds, splitsBefore, ~0u, changed, &reached) && reached);
  FUZZ_CHECK(ds.pm.mesh.tetCount() == tetsBefore && ds.pm.mesh.vertexCount() == verticesBefore);
}

// A small dataset with a hierarchy of nodes, packed once per process.
const Context& nodeContext() {
  static const Context ctx = [] {
    TetMesh mesh = makeGridMesh(10);
    addHarmonicField(mesh);
    mesh.name = "fuzz-nodes";
    PackOptions o;
    o.leafVertices = 64;
    Context c = packedContext(std::move(mesh), o, "tetstream-fuzz-nodes");
    Manifest m;
    if (!parseManifest(c.manifestJson, m) || m.nodes.size() < 4)
      fuzzCheckFailed("the fuzz dataset needs a hierarchy", __FILE__, __LINE__);
    return c;
  }();
  return ctx;
}

// The nodes below a root, which nodeChunk replaces.
std::vector<uint32_t> innerNodes(const Manifest& m) {
  std::vector<uint32_t> out;
  for (uint32_t k = 0; k < m.nodes.size(); ++k)
    if (m.nodes[k].parent >= 0) out.push_back(k);
  return out;
}

void nodeChunk(const uint8_t* data, size_t size) {
  if (size < 1) return;
  const Context& ctx = nodeContext();
  static std::string json;
  static PartialDataset pd;
  static std::vector<uint32_t> inner;
  if (inner.empty()) {
    Manifest m;
    FUZZ_CHECK(parseManifest(ctx.manifestJson, m));
    inner = innerNodes(m);
    json = ctx.manifestJson;
  }
  const uint32_t k = inner[(data[0] >> 1) % inner.size()];
  std::vector<uint8_t> replaced;
  ChunkInfo* info = nullptr;
  ChunkSource read = [&](uint32_t index, std::vector<uint8_t>& file) {
    file = info && index == pd.manifest.nodes[k].firstChunk ? replaced : ctx.files[index];
    return Result::success();
  };
  FUZZ_CHECK(openPartial(pd, json, read));
  const std::vector<uint32_t> ancestors =
      withAncestors(pd.manifest, std::vector<uint32_t>{uint32_t(pd.manifest.nodes[k].parent)});
  for (uint32_t a : ancestors) FUZZ_CHECK(applyNode(pd, a, read));
  const uint32_t first = pd.manifest.nodes[k].firstChunk;
  info = &pd.manifest.chunks[first];
  if (data[0] & 1) {
    replaced.assign(data + 1, data + size);
    matchFile(replaced, *info);
  } else {
    replaced = chunkFromPayload(ChunkKind::Splits, first, data + 1, size - 1, *info);
  }
  const std::vector<uint32_t> tetsBefore = pd.pm.mesh.tets;
  const uint32_t verticesBefore = pd.pm.vertexCount();
  if (!applyNode(pd, k, read)) {
    FUZZ_CHECK(!pd.loaded(k) && pd.pm.vertexCount() == verticesBefore && pd.pm.mesh.tets == tetsBefore);
    return;
  }
  checkStructure(pd.pm.mesh);
  undoLastNode(pd);
  FUZZ_CHECK(pd.pm.vertexCount() == verticesBefore && pd.pm.mesh.tets == tetsBefore);
}

void baseChunk(const uint8_t* data, size_t size) {
  const Context& ctx = context();
  static Dataset ds;  // the manifest parsed once (half of the time when parsed per input)
  openAt(ds, 0);
  std::vector<uint8_t> file = chunkFromPayload(ChunkKind::Base, 0, data, size, ds.manifest.chunks[0]);
  if (!receiveChunk(ds, 0, file)) {
    FUZZ_CHECK(ds.chunksReceived == 0);
    return;
  }
  checkStructure(ds.pm.mesh);
  // The real first split chunk on top of whatever base this was: it may fail, never crash.
  if (!receiveChunk(ds, 1, ctx.files[1])) return;
  std::vector<uint32_t> changed;
  bool reached = false;
  if (stepTowards(ds, ds.splitsReceived(), ~0u, changed, &reached))
    checkStructure(ds.pm.mesh);
  else
    FUZZ_CHECK(ds.splitsApplied() == 0);
}

void meshFile(const char* extension, const uint8_t* data, size_t size) {
  TetMesh m;
  ReadReport report;
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  if (readMeshBytes(bytes, std::string("fuzz") + extension, m, report)) checkReaderPromise(m);
  // One process's share of two and of three as well: read by rows, only the points the cells
  // use (io/row_pick.h).
  if (std::string_view(extension) == ".xdmf") {
    ReadOptions share;
    share.shareIndex = 1;
    share.shareCount = 2;
    TetMesh half;
    ReadReport halfReport;
    if (readXdmf(bytes, "fuzz.xdmf", std::nullopt, share, half, halfReport)) checkReaderPromise(half);
  }
  // Of a structured grid, slabs along k, or j, or i (the fewer layers, the more axes tried).
  const std::string_view ext(extension);
  if (ext == ".vtu" || ext == ".vti" || ext == ".vts") {
    for (uint32_t count : {2u, 3u}) {
      TetMesh part;
      ReadReport partReport;
      if (readVtu(bytes, std::string("fuzz") + extension, part, partReport, 1, count)) checkReaderPromise(part);
    }
  }
}

void twoFiles(const char* format, const uint8_t* data, size_t size) {
  if (size < 4) return;
  const size_t first = std::min<size_t>(
      size - 4, size_t(data[0]) | size_t(data[1]) << 8 | size_t(data[2]) << 16 | size_t(data[3]) << 24);
  const std::string_view a(reinterpret_cast<const char*>(data + 4), first);
  const std::string_view b(reinterpret_cast<const char*>(data + 4 + first), size - 4 - first);
  TetMesh m;
  ReadReport report;
  const std::string f = format;
  Result r = f == "tetgen"  ? readTetgen(a, "fuzz.node", b, "fuzz.ele", m, report)
             : f == "medit" ? readMedit(a, "fuzz.mesh", b, "fuzz.sol", m, report)
                            : readPlot3d(a, "fuzz.xyz", b, "fuzz.q", m, report);
  if (r) checkReaderPromise(m);
}

void hpcHeaders(const uint8_t* data, size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  const vtkio::NetcdfHeaderResult whole = vtkio::checkNetcdfClassicHeader(bytes, size, "fuzz.exo");
  FUZZ_CHECK(!whole.needMore);  // the whole file was given
  FUZZ_CHECK(whole.result || whole.result.message.starts_with("fuzz.exo: "));
  // Given only the first half of the same file, the check asks for more or reaches the same verdict
  // (the header alone decides; the data's extents use the file's size).
  const vtkio::NetcdfHeaderResult half = vtkio::checkNetcdfClassicHeader(bytes.substr(0, size / 2), size, "fuzz.exo");
  if (!half.needMore) FUZZ_CHECK(half.result.status == whole.result.status);
  uint64_t end = 0;
  if (vtkio::adfDataEnd(bytes, end)) FUZZ_CHECK(end < (uint64_t(1) << 48));
  (void)vtkio::containerSignature(bytes);
}

void listing(const uint8_t* data, size_t size) {
  if (size < 1) return;
  static const char* const kExtension[] = {".pvtu", ".vtm", ".pvtk"};
  const std::string label = std::string("fuzz") + kExtension[data[0] % 3];
  std::string list;
  std::map<std::string, std::string> files;
  bool first = true;
  for (size_t p = 1; p + 2 <= size;) {
    const size_t nameLength = std::min<size_t>(size_t(data[p]) | size_t(data[p + 1]) << 8, size - p - 2);
    p += 2;
    std::string name(reinterpret_cast<const char*>(data + p), nameLength);
    p += nameLength;
    size_t length = 0;
    if (size - p >= 4) {
      length = size_t(data[p]) | size_t(data[p + 1]) << 8 | size_t(data[p + 2]) << 16 | size_t(data[p + 3]) << 24;
      p += 4;
    }
    length = std::min(length, size - p);
    std::string bytes(reinterpret_cast<const char*>(data + p), length);
    p += length;
    if (first)
      list = std::move(bytes);
    else
      files.emplace(std::move(name), std::move(bytes));
    first = false;
  }
  int loads = 0;
  const PieceLoader load = [&](const std::string& path, PieceBytes& piece) {
    ++loads;
    auto it = files.find(path);
    if (it == files.end()) return fail(Status::IoError, path + ": no such file");
    piece.bytes = it->second;
    return Result::success();
  };
  TetMesh m;
  ReadReport report;
  if (readListing(list, label, load, m, report)) checkReaderPromise(m);
  FUZZ_CHECK(size_t(loads) <= files.size() + 1);  // no file is read twice; the first missing one stops the read
}

bool runTarget(const std::string& name, const uint8_t* data, size_t size) {
  if (name == "manifest")
    manifest(data, size);
  else if (name == "split-chunk")
    splitChunk(data, size);
  else if (name == "node-chunk")
    nodeChunk(data, size);
  else if (name == "base-chunk")
    baseChunk(data, size);
  else if (name.starts_with("mesh-") && name.size() > 5)
    meshFile(std::string(".").append(name, 5).c_str(), data, size);
  else if (name == "pair-tetgen" || name == "pair-medit" || name == "pair-plot3d")
    twoFiles(name.c_str() + 5, data, size);
  else if (name == "hpc-headers")
    hpcHeaders(data, size);
  else if (name == "listing")
    listing(data, size);
  else
    return false;
  return true;
}

std::vector<std::pair<std::string, std::vector<uint8_t>>> seeds(const std::string& target) {
  const Context& ctx = context();
  std::vector<std::pair<std::string, std::vector<uint8_t>>> out;
  Manifest m;
  FUZZ_CHECK(parseManifest(ctx.manifestJson, m));
  ChunkDecoder dec;
  if (target == "manifest") {
    out.push_back({"packed", std::vector<uint8_t>(ctx.manifestJson.begin(), ctx.manifestJson.end())});
    // The same chunks as a chain of two nodes (the first split chunk, then the rest), so fuzzing
    // starts inside the node rules whatever hierarchy the packer wrote.
    Manifest chain = m;
    chain.nodes.clear();
    for (uint32_t first : {1u, 2u}) {
      NodeInfo n;
      n.parent = int32_t(first) - 2;
      n.firstChunk = first;
      n.chunkCount = first == 1 ? 1 : uint32_t(m.chunks.size()) - 2;
      n.vertexBegin = m.chunks[first - 1].vertices;
      n.vertexEnd = m.chunks[first + n.chunkCount - 1].vertices;
      n.tetBegin = m.chunks[first - 1].tets;
      n.tetEnd = m.chunks[first + n.chunkCount - 1].tets;
      n.bounds = m.bounds;
      for (const FieldInfo& f : m.fields) n.ranges.push_back(f.range);
      n.fieldError = m.chunks[first - 1].fieldError;
      chain.nodes.push_back(n);
    }
    const std::string text = writeManifest(chain);
    FUZZ_CHECK(parseManifest(text, chain));
    out.push_back({"nodes", std::vector<uint8_t>(text.begin(), text.end())});
  } else if (target == "node-chunk") {
    const Context& nodes = nodeContext();
    Manifest nm;
    FUZZ_CHECK(parseManifest(nodes.manifestJson, nm));
    const std::vector<uint32_t> inner = innerNodes(nm);
    for (uint32_t pick = 0; pick < inner.size() && pick < 8; ++pick) {
      const uint32_t c = nm.nodes[inner[pick]].firstChunk;
      std::span<const uint8_t> p = payloadOf(dec, nm.chunks[c], c, nodes.files[c]);
      std::vector<uint8_t> payload{uint8_t(pick << 1)};
      payload.insert(payload.end(), p.begin(), p.end());
      out.push_back({"node-" + std::to_string(pick), payload});
      std::vector<uint8_t> file{uint8_t(pick << 1 | 1)};
      file.insert(file.end(), nodes.files[c].begin(), nodes.files[c].end());
      out.push_back({"node-file-" + std::to_string(pick), file});
    }
  } else if (target == "base-chunk") {
    std::span<const uint8_t> p = payloadOf(dec, m.chunks[0], 0, ctx.files[0]);
    out.push_back({"base", std::vector<uint8_t>(p.begin(), p.end())});
  } else if (target == "split-chunk") {
    for (uint32_t c = 1; c < ctx.files.size(); ++c) {
      std::span<const uint8_t> p = payloadOf(dec, m.chunks[c], c, ctx.files[c]);
      std::vector<uint8_t> payload{uint8_t((c - 1) << 1)};
      payload.insert(payload.end(), p.begin(), p.end());
      out.push_back({"payload-" + std::to_string(c), payload});
      std::vector<uint8_t> file{uint8_t((c - 1) << 1 | 1)};
      file.insert(file.end(), ctx.files[c].begin(), ctx.files[c].end());
      out.push_back({"file-" + std::to_string(c), file});
    }
  }
  return out;
}

}  // namespace tetstream::fuzz
