// The core's view side on a packed dataset, built natively and as wasm (run under node with
// NODERAWFS) so both can be compared and timed:
//   tetstream_core_check PACKDIR ISOVALUE [FIELD] [REPEATS]
//       one isosurface of the full mesh, its boundary hull and a slice through its middle:
//       counts, area, time and hashes of the exact output arrays (tests/node/core.test.mjs
//       checks native == wasm)
//   tetstream_core_check --stream PACKDIR ISOVALUE
//       decode + apply + local isosurface update over every split, the undo rate, and isovalue
//       re-extraction with the interval tree against a plain scan at several levels (benchmarks)
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "dataset.h"
#include "hash.h"
#include "hull.h"
#include "isosurface.h"
#include "isosurface_incremental.h"
#include "slice.h"

using namespace tetstream;
using Clock = std::chrono::steady_clock;

namespace {

double msSince(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

// A chunk or manifest file: at most 1 GiB, the format's limit for a chunk.
constexpr uint64_t kFileLimit = uint64_t(1) << 30;

int surfaceCheck(int argc, char** argv) {
  Dataset ds;
  auto t0 = Clock::now();
  if (Result r = loadPackedDir(argv[1], ds); !r) {
    std::fprintf(stderr, "error: %s\n", r.message.c_str());
    return 1;
  }
  double loadMs = msSince(t0);
  const std::string field = argc > 3 ? argv[3] : ds.manifest.isoField;
  const TetMesh& mesh = ds.pm.mesh;
  int f = mesh.findField(field);
  if (f < 0) {
    std::fprintf(stderr, "error: no field '%s'\n", field.c_str());
    return 1;
  }
  const int repeats = argc > 4 ? std::max(1, std::atoi(argv[4])) : 1;
  IsoExtractor x;
  IsoSurface s;
  double best = 1e300;
  for (int i = 0; i < repeats; ++i) {
    auto t = Clock::now();
    extractIsosurface(mesh, mesh.fields[size_t(f)].values, std::strtof(argv[2], nullptr), x, s);
    best = std::min(best, msSince(t));
  }
  auto bytes = [](const auto& v) {
    return std::span<const uint8_t>(reinterpret_cast<const uint8_t*>(v.data()), v.size() * sizeof(v[0]));
  };
  auto hash = [&](const auto& v) { return formatHash(contentHash(bytes(v))); };
  // The viewer's hull and a slice through the middle of the bounds (core/hull.h, core/slice.h).
  HullTracker hull;
  hull.rebuild(ds.pm);
  SliceTracker slice;
  const Bounds& b = ds.manifest.bounds;
  slice.setPlane({0, 0, 1}, 0.5f * (b.min[2] + b.max[2]));
  slice.rebuild(mesh, {});
  const IncrementalIsosurface& cut = slice.surface();
  std::printf(
      "{\"tets\": %u, \"triangles\": %u, \"vertices\": %u, \"area\": %.17g, \"positionsHash\": \"%s\", "
      "\"indicesHash\": \"%s\", \"normalsHash\": \"%s\", \"hullTriangles\": %u, \"hullLines\": %u, "
      "\"hullHash\": \"%s\", \"linesHash\": \"%s\", \"sliceTriangles\": %u, \"sliceArea\": %.17g, "
      "\"slicePositionsHash\": \"%s\", \"sliceIndicesHash\": \"%s\", \"loadMs\": %.3f, \"ms\": %.3f}\n",
      mesh.tetCount(), s.triangleCount(), s.vertexCount(), surfaceArea(s), hash(s.positions).c_str(),
      hash(s.indices).c_str(), hash(s.normals).c_str(), hull.triangleCount(), hull.lineCount(),
      hash(hull.trianglePositions()).c_str(), hash(hull.lineVertices()).c_str(), cut.triangleCount(), cut.area(),
      hash(cut.positions()).c_str(), hash(cut.indices()).c_str(), loadMs, best);
  return 0;
}

int streamBench(const std::string& dir, float iso) {
  Dataset ds;
  if (Result r = loadPackedDir(dir, ds, 1); !r) {
    std::fprintf(stderr, "error: %s\n", r.message.c_str());
    return 1;
  }
  std::vector<std::vector<uint8_t>> files(ds.manifest.chunks.size());
  for (uint32_t c = 1; c < files.size(); ++c)
    if (!readFileBytes(dir + "/" + ds.manifest.chunks[c].file, kFileLimit, files[c]).ok()) return 1;
  const int field = ds.manifest.findField(ds.manifest.isoField);
  // As the viewer does: receive each chunk, then splits in batches with a local update each.
  // `surface` is already built on the base; returns false on a bad chunk or record.
  std::vector<uint32_t> changed;
  bool reached;
  auto streamAll = [&](Dataset& d, IncrementalIsosurface& surface) {
    for (uint32_t c = 1; c < files.size(); ++c) {
      if (Result r = receiveChunk(d, c, files[c]); !r) {
        std::fprintf(stderr, "error: %s\n", r.message.c_str());
        return false;
      }
      while (d.splitsApplied() < d.splitsReceived()) {
        changed.clear();
        if (!stepTowards(d, ~0u, 64, changed, &reached)) return false;
        surface.updateTets(d.pm.mesh, d.pm.mesh.fields[size_t(field)].values, changed);
        surface.clearChanges();
      }
    }
    return true;
  };
  IncrementalIsosurface inc;
  inc.rebuild(ds.pm.mesh, ds.pm.mesh.fields[size_t(field)].values, iso);
  auto t0 = Clock::now();
  if (!streamAll(ds, inc)) return 1;
  const double streamMs = msSince(t0);
  const uint32_t splits = ds.splitsApplied(), finalTriangles = inc.triangleCount();
  // The same stream as the viewer runs it: the interval tree deferred until the level settles
  // (IncrementalIsosurface::setTreeDeferred), so only the surface follows each split.
  Dataset fresh;
  if (!loadPackedDir(dir, fresh, 1)) return 1;
  IncrementalIsosurface surface;
  surface.setTreeDeferred(true);
  surface.rebuild(fresh.pm.mesh, fresh.pm.mesh.fields[size_t(field)].values, iso);
  t0 = Clock::now();
  if (!streamAll(fresh, surface) || surface.triangleCount() != finalTriangles) return 1;
  const double viewerMs = msSince(t0);
  t0 = Clock::now();
  while (ds.splitsApplied() > 0) {  // the level slider all the way down
    changed.clear();
    stepTowards(ds, 0, 64, changed, &reached);
    inc.updateTets(ds.pm.mesh, ds.pm.mesh.fields[size_t(field)].values, changed);
    inc.clearChanges();
  }
  const double undoMs = msSince(t0);
  std::printf(
      "{\"splits\": %u, \"finalTriangles\": %u, \"streamMs\": %.1f, \"splitsPerSecond\": %.0f, "
      "\"viewerSplitsPerSecond\": %.0f, \"undoMs\": %.1f, \"undoSplitsPerSecond\": %.0f, \"levels\": [",
      splits, finalTriangles, streamMs, splits / streamMs * 1000, splits / viewerMs * 1000, undoMs,
      splits / undoMs * 1000);
  // Isovalue changes at several levels: interval tree (rebuild) against a scan of every tet.
  bool first = true;
  for (double fraction : {0.05, 0.10, 0.15, 0.30, 1.0}) {
    const uint32_t target = uint32_t(fraction * splits);
    changed.clear();
    stepTowards(ds, target, ~0u, changed, &reached);
    const TetMesh& m = ds.pm.mesh;
    const std::vector<float>& values = m.fields[size_t(field)].values;
    const Range range = ds.manifest.fields[size_t(field)].range;
    std::printf("%s{\"fraction\": %.2f, \"vertices\": %u, \"tets\": %u, \"isovalues\": [", first ? "" : ", ", fraction,
                m.vertexCount(), m.tetCount());
    first = false;
    // The same surface (vertex sharing, normals, the records that local updates need) found
    // through the tree, and through a test of every tet's interval (the tree deferred and never
    // built: what an isovalue change costs while a level streams in); and, for reference, the
    // plain extractor, which makes a bare triangle soup from every tet.
    IncrementalIsosurface tree, scan;
    scan.setTreeDeferred(true);
    for (int k = 0; k < 4; ++k) {
      const float value = range.min + (range.max - range.min) * (0.2f + 0.2f * k);
      double treeMs = 1e30, scanMs = 1e30, plainMs = 1e30;
      IsoExtractor x;
      IsoSurface s;
      for (int rep = 0; rep < 3; ++rep) {
        auto a = Clock::now();
        tree.rebuild(m, values, value);
        if (rep > 0 || k > 0) treeMs = std::min(treeMs, msSince(a));  // the first call builds the tree
        a = Clock::now();
        scan.rebuild(m, values, value);
        scanMs = std::min(scanMs, msSince(a));
        a = Clock::now();
        extractIsosurface(m, values, value, x, s);
        plainMs = std::min(plainMs, msSince(a));
      }
      if (scan.triangleCount() != tree.triangleCount()) return 1;
      std::printf("%s{\"isovalue\": %.4g, \"triangles\": %u, \"treeMs\": %.2f, \"scanMs\": %.2f, \"plainMs\": %.2f}",
                  k ? ", " : "", value, tree.triangleCount(), treeMs, scanMs, plainMs);
    }
    std::printf("]}");
  }
  std::printf("]}\n");
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc >= 4 && !std::strcmp(argv[1], "--stream")) return streamBench(argv[2], std::strtof(argv[3], nullptr));
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s PACKDIR ISOVALUE [FIELD] [REPEATS] | --stream PACKDIR ISOVALUE\n", argv[0]);
    return 2;
  }
  return surfaceCheck(argc, argv);
}
