// Measurements behind the README's figures for the progressive engine (never run as a test):
//   tetstream_bench error ORIGINAL.vtu APPROX.vtu --field F
//       field error of APPROX sampled at ORIGINAL's vertices (RMS, max, relative to the range),
//       and boundary preservation (volume ratio, bounding box)
//   tetstream_bench raw MESH.vtu OUT.bin
//       the mesh as raw arrays, for the `zstd -19` baseline
// (Streaming rates are measured by tests/node/core_check.cpp --stream, natively and in wasm.)
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "pack/mesh_io.h"

using namespace tetstream;

namespace {

const char* arg(int argc, char** argv, const char* name, const char* fallback) {
  for (int i = 1; i + 1 < argc; ++i)
    if (!std::strcmp(argv[i], name)) return argv[i + 1];
  return fallback;
}

// Uniform grid of tet bounding boxes for point location.
struct Locator {
  const TetMesh& m;
  Bounds b;
  int n;
  std::vector<uint32_t> start, items;

  explicit Locator(const TetMesh& mesh) : m(mesh), b(computeBounds(mesh.positions)) {
    n = std::clamp(int(std::cbrt(mesh.tetCount() / 2.0)), 1, 128);
    std::vector<uint32_t> count(size_t(n) * n * n + 1, 0);
    forEachCell([&](uint32_t, size_t c) { ++count[c + 1]; });
    for (size_t c = 1; c < count.size(); ++c) count[c] += count[c - 1];
    start = count;
    items.resize(count.back());
    forEachCell([&](uint32_t t, size_t c) { items[count[c]++] = t; });
  }
  int cellOf(float x, int k) const {
    float ext = b.max[k] - b.min[k];
    int c = ext > 0 ? int((x - b.min[k]) / ext * n) : 0;
    return std::clamp(c, 0, n - 1);
  }
  template <typename F>
  void forEachCell(F f) const {
    for (uint32_t t = 0; t < m.tetCount(); ++t) {
      int lo[3], hi[3];
      for (int k = 0; k < 3; ++k) {
        float mn = 1e30f, mx = -1e30f;
        for (int v = 0; v < 4; ++v) {
          float x = m.positions[3 * size_t(m.tets[4 * size_t(t) + v]) + k];
          mn = std::min(mn, x);
          mx = std::max(mx, x);
        }
        lo[k] = cellOf(mn, k);
        hi[k] = cellOf(mx, k);
      }
      for (int z = lo[2]; z <= hi[2]; ++z)
        for (int y = lo[1]; y <= hi[1]; ++y)
          for (int x = lo[0]; x <= hi[0]; ++x) f(t, size_t(x) + size_t(n) * (y + size_t(n) * z));
    }
  }
  // Field value at p: inside the containing tet, else from the nearest tet (clamped weights).
  double sample(const float* p, const std::vector<float>& field) const {
    int c[3] = {cellOf(p[0], 0), cellOf(p[1], 1), cellOf(p[2], 2)};
    double best = -1e30, value = 0;
    for (int ring = 0; ring <= 2 && best < -1e-6; ++ring)
      for (int z = c[2] - ring; z <= c[2] + ring; ++z)
        for (int y = c[1] - ring; y <= c[1] + ring; ++y)
          for (int x = c[0] - ring; x <= c[0] + ring; ++x) {
            if (x < 0 || y < 0 || z < 0 || x >= n || y >= n || z >= n) continue;
            size_t cell = size_t(x) + size_t(n) * (y + size_t(n) * z);
            for (uint32_t k = start[cell]; k < start[cell + 1]; ++k) tryTet(items[k], p, field, best, value);
          }
    return value;
  }
  void tryTet(uint32_t t, const float* p, const std::vector<float>& field, double& best, double& value) const {
    const uint32_t* v = &m.tets[4 * size_t(t)];
    const float* q[4] = {&m.positions[3 * size_t(v[0])], &m.positions[3 * size_t(v[1])], &m.positions[3 * size_t(v[2])],
                         &m.positions[3 * size_t(v[3])]};
    double det = tetVolume(q[0], q[1], q[2], q[3]);
    if (det == 0) return;
    double l[4], lo = 1e30;
    for (int k = 0; k < 4; ++k) {
      const float* r[4] = {q[0], q[1], q[2], q[3]};
      r[k] = p;
      l[k] = tetVolume(r[0], r[1], r[2], r[3]) / det;
      lo = std::min(lo, l[k]);
    }
    if (lo <= best) return;
    best = lo;
    double sum = 0, val = 0;
    for (int k = 0; k < 4; ++k) sum += std::max(0.0, l[k]);
    for (int k = 0; k < 4; ++k) val += std::max(0.0, l[k]) / sum * field[v[k]];
    value = val;
  }
};

int cmdError(int argc, char** argv) {
  TetMesh orig, approx;
  ReadReport rep;
  if (Result r = readMesh(argv[2], orig, rep); !r) { std::fprintf(stderr, "%s\n", r.message.c_str()); return 1; }
  if (Result r = readMesh(argv[3], approx, rep); !r) { std::fprintf(stderr, "%s\n", r.message.c_str()); return 1; }
  const std::string field = arg(argc, argv, "--field", orig.fields[0].name.c_str());
  int fo = orig.findField(field), fa = approx.findField(arg(argc, argv, "--approx-field", field.c_str()));
  if (fa < 0 && approx.fields.size() == 1) fa = 0;  // VTK's decimation renames it "scalars"
  if (fo < 0 || fa < 0) { std::fprintf(stderr, "field %s missing\n", field.c_str()); return 1; }
  Locator loc(approx);
  Range range = computeRange(orig.fields[size_t(fo)].values);
  double sum2 = 0, maxErr = 0;
  for (uint32_t v = 0; v < orig.vertexCount(); ++v) {
    double e = std::abs(loc.sample(&orig.positions[3 * size_t(v)], approx.fields[size_t(fa)].values) -
                        orig.fields[size_t(fo)].values[v]);
    sum2 += e * e;
    maxErr = std::max(maxErr, e);
  }
  double volO = 0, volA = 0;
  for (uint32_t t = 0; t < orig.tetCount(); ++t) volO += std::abs(tetVolume(orig, t));
  for (uint32_t t = 0; t < approx.tetCount(); ++t) volA += std::abs(tetVolume(approx, t));
  double rms = std::sqrt(sum2 / orig.vertexCount()), span = double(range.max) - range.min;
  std::printf("{\"tets\": %u, \"vertices\": %u, \"rms\": %.6g, \"max\": %.6g, \"rmsRelative\": %.6g, \"maxRelative\": %.6g, "
              "\"volumeRatio\": %.6f}\n",
              approx.tetCount(), approx.vertexCount(), rms, maxErr, rms / span, maxErr / span, volA / volO);
  return 0;
}

// Raw little-endian arrays (positions f32, fields f32, tets u32): what `zstd -19` is run on to
// compare against the packed size.
int cmdRaw(char** argv) {
  TetMesh m;
  ReadReport rep;
  if (Result r = readMesh(argv[2], m, rep); !r) { std::fprintf(stderr, "%s\n", r.message.c_str()); return 1; }
  std::FILE* f = std::fopen(argv[3], "wb");
  if (!f) return 1;
  std::fwrite(m.positions.data(), 4, m.positions.size(), f);
  for (const ScalarField& fl : m.fields) std::fwrite(fl.values.data(), 4, fl.values.size(), f);
  std::fwrite(m.tets.data(), 4, m.tets.size(), f);
  std::fclose(f);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc >= 4 && !std::strcmp(argv[1], "error")) return cmdError(argc, argv);
  if (argc >= 4 && !std::strcmp(argv[1], "raw")) return cmdRaw(argv);
  std::fprintf(stderr, "usage: tetstream_bench error ORIG.vtu APPROX.vtu [--field F] | raw MESH.vtu OUT.bin\n");
  return 2;
}
