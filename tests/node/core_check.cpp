// Loads a packed dataset, extracts one isosurface and prints a JSON line with its counts, area,
// time and a hash of the exact output arrays. Built natively and as wasm (run under node with
// NODERAWFS); tests/node/core.test.mjs checks that both print the same surface.
//   tetstream_core_check PACKDIR ISOVALUE [FIELD] [REPEATS]
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "dataset.h"
#include "hash.h"
#include "isosurface.h"

using namespace tetstream;

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s PACKDIR ISOVALUE [FIELD] [REPEATS]\n", argv[0]);
    return 2;
  }
  Dataset ds;
  auto t0 = std::chrono::steady_clock::now();
  if (Result r = loadPackedDir(argv[1], ds); !r) {
    std::fprintf(stderr, "error: %s\n", r.message.c_str());
    return 1;
  }
  double loadMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  const std::string field = argc > 3 ? argv[3] : ds.manifest.isoField;
  int f = ds.pm.mesh.findField(field);
  if (f < 0) {
    std::fprintf(stderr, "error: no field '%s'\n", field.c_str());
    return 1;
  }
  const int repeats = argc > 4 ? std::max(1, std::atoi(argv[4])) : 1;
  IsoExtractor x;
  IsoSurface s;
  double best = 1e300;
  for (int i = 0; i < repeats; ++i) {
    auto t = std::chrono::steady_clock::now();
    extractIsosurface(ds.pm.mesh, ds.pm.mesh.fields[size_t(f)].values, std::strtof(argv[2], nullptr), x, s);
    best = std::min(best, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count());
  }
  auto bytes = [](const auto& v) {
    return std::span<const uint8_t>(reinterpret_cast<const uint8_t*>(v.data()), v.size() * sizeof(v[0]));
  };
  std::printf(
      "{\"tets\": %u, \"triangles\": %u, \"vertices\": %u, \"area\": %.17g, \"positionsHash\": \"%s\", "
      "\"indicesHash\": \"%s\", \"normalsHash\": \"%s\", \"loadMs\": %.3f, \"ms\": %.3f}\n",
      ds.pm.mesh.tetCount(), s.triangleCount(), s.vertexCount(), surfaceArea(s), formatHash(contentHash(bytes(s.positions))).c_str(),
      formatHash(contentHash(bytes(s.indices))).c_str(), formatHash(contentHash(bytes(s.normals))).c_str(), loadMs, best);
  return 0;
}
