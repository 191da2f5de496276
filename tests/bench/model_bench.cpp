// The refinement worker's work without a browser: the viewer's model (wasm/viewer_state.h) fed
// a packed dataset's chunks in the order its fetch plan asks for them, refined in slices of
// `--slice-ms` with a geometry delta written after each slice, as wasm/worker_api.cpp does.
// Built natively and as wasm (run under node), so the split rate of the model itself can be
// told apart from what a browser adds (drawing on the same cores, messages).
//   tetstream_model_bench PACKDIR [--everything] [--slice-ms MS] [--isovalue V]
// Prints one JSON object: the time to open the manifest, splits applied, time in refinement slices and in deltas,
// splits/s, and what the model holds once complete (bytes by part, vector capacities), before and after the interval
// tree is grown.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "geometry_sync.h"
#include "viewer_state.h"

using namespace tetstream;
using namespace tetstream::viewer;
using BenchClock = std::chrono::steady_clock;

namespace {

double nowMs() { return std::chrono::duration<double, std::milli>(BenchClock::now().time_since_epoch()).count(); }

// A chunk or manifest file: at most 1 GiB, the format's limit for a chunk.
constexpr uint64_t kFileLimit = uint64_t(1) << 30;

// Offers every chunk the plan asks for that is not in hand yet; false when none was left.
bool offerPlanned(ViewerState& s, const std::string& dir) {
  bool any = false;
  std::vector<uint8_t> bytes;
  for (uint32_t c : chunksToFetch(s)) {
    if (s.dataset.hasChunk(c) || s.pendingChunks.count(c)) continue;
    if (!readFileBytes(dir + "/" + s.dataset.manifest.chunks[c].file, kFileLimit, bytes).ok()) {
      std::fprintf(stderr, "error: cannot read chunk %u\n", c);
      std::exit(1);
    }
    auto* copy = static_cast<uint8_t*>(std::malloc(bytes.size() ? bytes.size() : 1));
    std::memcpy(copy, bytes.data(), bytes.size());
    if (offerChunk(s, c, copy, bytes.size()) != ChunkCheck::Ok) {
      std::fprintf(stderr, "error: chunk %u refused: %s\n", c, s.error.c_str());
      std::exit(1);
    }
    any = true;
  }
  return any;
}

template <class V>
uint64_t bytesOf(const V& v) {
  return uint64_t(v.capacity() * sizeof(v[0]));
}

// The model's memory by part, as JSON.
std::string memoryJson(const ViewerState& s) {
  const Dataset& ds = s.dataset;
  const ProgressiveMesh& pm = ds.pm;
  uint64_t fields = 0, payloads = bytesOf(ds.payloads);
  for (const ScalarField& f : pm.mesh.fields) fields += bytesOf(f.values);
  for (const auto& p : ds.payloads) payloads += bytesOf(p);
  const std::pair<const char*, uint64_t> parts[] = {
      {"tets", bytesOf(pm.mesh.tets)},
      {"stars", pm.stars.bytes()},
      {"positions", bytesOf(pm.mesh.positions)},
      {"fields", fields},
      {"undo", bytesOf(pm.splitJ) + bytesOf(pm.splitTetsBefore) + bytesOf(pm.splitJValues)},
      {"seen", bytesOf(pm.seen)},
      {"payloads", payloads},
      {"recordStarts", bytesOf(ds.recordStart) + bytesOf(ds.stableJ)},
      {"surface", s.surface.memoryBytes()},
      {"hull", s.hull.memoryBytes()},
      {"total", memoryInUse(s)},
  };
  std::string out = "{";
  for (const auto& [name, bytes] : parts)
    out += std::string(out.size() > 1 ? ", " : "") + "\"" + name + "\": " + std::to_string(bytes);
  return out + "}";
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s PACKDIR [--everything] [--slice-ms MS] [--isovalue V]\n", argv[0]);
    return 2;
  }
  const std::string dir = argv[1];
  bool everything = false;
  double sliceMs = 12;
  const char* isovalue = nullptr;
  for (int i = 2; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--everything"))
      everything = true;
    else if (!std::strcmp(argv[i], "--slice-ms") && i + 1 < argc)
      sliceMs = std::atof(argv[++i]);
    else if (!std::strcmp(argv[i], "--isovalue") && i + 1 < argc)
      isovalue = argv[++i];
  }
  std::vector<uint8_t> manifest;
  if (!readFileBytes(dir + "/manifest.json", kFileLimit, manifest).ok()) {
    std::fprintf(stderr, "error: cannot read %s/manifest.json\n", dir.c_str());
    return 1;
  }
  ViewerState s;
  const double openStart = nowMs();
  if (Result r = openManifest(s, {reinterpret_cast<const char*>(manifest.data()), manifest.size()}); !r) {
    std::fprintf(stderr, "error: %s\n", r.message.c_str());
    return 1;
  }
  const double openMs = nowMs() - openStart;
  if (everything) setFetchMode(s, FetchMode::Everything);
  if (isovalue) setIsovalue(s, std::strtof(isovalue, nullptr));
  double refineMs = 0, deltaMs = 0, offerMs = 0;
  uint64_t deltaBytes = 0, slices = 0;
  std::vector<uint8_t> delta;
  for (;;) {
    double t = nowMs();
    const bool offered = offerPlanned(s, dir);
    offerMs += nowMs() - t;
    if (!refining(s) && !offered) break;
    while (refining(s)) {
      t = nowMs();
      advance(s, t + sliceMs, nowMs);
      const double t1 = nowMs();
      refineMs += t1 - t;
      delta.clear();
      writeDelta(s.dirty.surface ? &s.surface : nullptr, s.dirty.slice ? &s.slice.surface() : nullptr,
                 s.dirty.hull ? &s.hull : nullptr, delta);
      s.surface.clearChanges();
      s.slice.surface().clearChanges();
      s.hull.clearChanges();
      s.dirty = {};
      deltaMs += nowMs() - t1;
      deltaBytes += delta.size();
      ++slices;
    }
  }
  const uint32_t splits = s.dataset.splitsApplied();
  const std::string streamed = memoryJson(s);
  while (treePending(s)) growTree(s, nowMs() + 1000, nowMs);
  const std::string withTree = memoryJson(s);
  std::printf(
      "{\"state\": \"%s\", \"openMs\": %.1f, \"splits\": %u, \"tets\": %u, \"triangles\": %u, \"slices\": %llu, "
      "\"refineMs\": %.1f, "
      "\"deltaMs\": %.1f, \"offerMs\": %.1f, \"deltaBytes\": %llu, \"splitsPerSecond\": %.0f, "
      "\"withDeltaSplitsPerSecond\": %.0f, \"memory\": %s, \"memoryWithTree\": %s}\n",
      loadStateName(s.state), openMs, splits, s.dataset.pm.mesh.tetCount(), s.surface.triangleCount(),
      (unsigned long long)slices, refineMs, deltaMs, offerMs, (unsigned long long)deltaBytes, splits / refineMs * 1000,
      splits / (refineMs + deltaMs) * 1000, streamed.c_str(), withTree.c_str());
  return s.state == LoadState::Error ? 1 : 0;
}
