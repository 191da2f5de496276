// Measurements behind docs/benchmarks.md for the progressive engine (never run as a test):
//   tetstream_bench error ORIGINAL.vtu APPROX.vtu --field F
//       field error of APPROX sampled at ORIGINAL's vertices (RMS, max, relative to the range),
//       and boundary preservation (volume ratio, bounding box)
//   tetstream_bench raw MESH.vtu OUT.bin
//       the mesh as raw arrays, for the `zstd -19` baseline
//   tetstream_bench vtu MESH OUT.vtu
//       any mesh our readers take, written as .vtu in the order read (structured grids and
//       hexahedra split into tets), so that VTK gets the very tets we pack, numbered as in the file
//   tetstream_bench regions PACKDIR OUT.vtu --bytes N
//       the level the viewer holds when it loads everything of a dataset of regions, once N bytes
//       of chunks are in: regions in its order (most field error first, each after its parent;
//       wasm/fetch_plan.cpp, every region in view), as .vtu
//   tetstream_bench closure PACKDIR --values A,B,C
//       what each isovalue needs (fraction of the stream's bytes): whole nodes as the viewer
//       fetches them ("tree"), and with each split's exact dependencies on earlier splits, split
//       by split ("splitClosure") or node by node ("nodeClosure")
//   tetstream_bench isodist ORIGINAL.vtu APPROX.vtu --field F --value V
//       distance between the isosurfaces of the two meshes (area-weighted mean and max over
//       triangle centroids and vertices, both directions, relative to ORIGINAL's diagonal)
// (Streaming rates are measured by tests/node/core_check.cpp --stream, natively and in wasm.)
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <queue>
#include <string>
#include <vector>

#include "chunk.h"
#include "dataset.h"
#include "io/mesh_io.h"
#include "isosurface.h"
#include "partial.h"
#include "split_stream.h"
#include "tet_quality.h"

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
    double l[4];
    const double lo = barycentric(q, p, l);
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
  if (Result r = readMesh(argv[2], orig, rep); !r) {
    std::fprintf(stderr, "%s\n", r.message.c_str());
    return 1;
  }
  if (Result r = readMesh(argv[3], approx, rep); !r) {
    std::fprintf(stderr, "%s\n", r.message.c_str());
    return 1;
  }
  const std::string field = arg(argc, argv, "--field", orig.fields[0].name.c_str());
  int fo = orig.findField(field), fa = approx.findField(arg(argc, argv, "--approx-field", field.c_str()));
  if (fa < 0 && approx.fields.size() == 1) fa = 0;  // VTK's decimation renames it "scalars"
  if (fo < 0 || fa < 0) {
    std::fprintf(stderr, "field %s missing\n", field.c_str());
    return 1;
  }
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
  // Tet shape of the approximation: 3/κ (1 for an equilateral tet, 0 for a flat one).
  double qSum = 0, qMin = 1;
  for (uint32_t t = 0; t < approx.tetCount(); ++t) {
    double c[4][3];
    for (int k = 0; k < 4; ++k)
      for (int d = 0; d < 3; ++d) c[k][d] = approx.positions[3 * size_t(approx.tets[4 * size_t(t) + k]) + d];
    double q = 3.0 / tetShape(c[0], c[1], c[2], c[3]).kappa();
    qSum += q;
    qMin = std::min(qMin, q);
  }
  double rms = std::sqrt(sum2 / orig.vertexCount()), span = double(range.max) - range.min;
  std::printf(
      "{\"tets\": %u, \"vertices\": %u, \"rms\": %.6g, \"max\": %.6g, \"rmsRelative\": %.6g, \"maxRelative\": %.6g, "
      "\"volumeRatio\": %.6f, \"meanQuality\": %.4f, \"minQuality\": %.3g}\n",
      approx.tetCount(), approx.vertexCount(), rms, maxErr, rms / span, maxErr / span, volA / volO,
      qSum / std::max(1u, approx.tetCount()), qMin);
  return 0;
}

// Nearest-triangle queries over an isosurface: triangles bucketed in a uniform grid, searched
// ring by ring until the ring is farther than the best distance found.
struct TriangleGrid {
  const IsoSurface& s;
  Bounds b;
  int n = 1;
  float cell = 1;
  std::vector<uint32_t> start, items;

  explicit TriangleGrid(const IsoSurface& surface) : s(surface), b(computeBounds(surface.positions)) {
    const uint32_t t = s.triangleCount();
    float ext = std::max({b.max[0] - b.min[0], b.max[1] - b.min[1], b.max[2] - b.min[2], 1e-12f});
    n = std::clamp(int(std::cbrt(double(t) / 2)), 1, 256);
    cell = ext / float(n);
    std::vector<uint32_t> count(size_t(n) * n * n + 1, 0);
    forEach([&](uint32_t, size_t c) { ++count[c + 1]; });
    for (size_t c = 1; c < count.size(); ++c) count[c] += count[c - 1];
    start = count;
    items.resize(count.back());
    forEach([&](uint32_t tri, size_t c) { items[count[c]++] = tri; });
  }
  int cellOf(float x, int k) const { return std::clamp(int((x - b.min[k]) / cell), 0, n - 1); }
  template <typename F>
  void forEach(F f) const {
    for (uint32_t t = 0; t < s.triangleCount(); ++t) {
      int lo[3] = {n, n, n}, hi[3] = {0, 0, 0};
      for (int v = 0; v < 3; ++v)
        for (int k = 0; k < 3; ++k) {
          int c = cellOf(s.positions[3 * size_t(s.indices[3 * size_t(t) + v]) + k], k);
          lo[k] = std::min(lo[k], c);
          hi[k] = std::max(hi[k], c);
        }
      for (int z = lo[2]; z <= hi[2]; ++z)
        for (int y = lo[1]; y <= hi[1]; ++y)
          for (int x = lo[0]; x <= hi[0]; ++x) f(t, size_t(x) + size_t(n) * (y + size_t(n) * z));
    }
  }
  // Squared distance from p to triangle t (closest point on a triangle, Ericson §5.1.5).
  double dist2(const double* p, uint32_t t) const {
    double a[3], bb[3], c[3];
    for (int k = 0; k < 3; ++k) {
      a[k] = s.positions[3 * size_t(s.indices[3 * size_t(t)]) + k];
      bb[k] = s.positions[3 * size_t(s.indices[3 * size_t(t) + 1]) + k];
      c[k] = s.positions[3 * size_t(s.indices[3 * size_t(t) + 2]) + k];
    }
    auto dot = [](const double* u, const double* v) { return u[0] * v[0] + u[1] * v[1] + u[2] * v[2]; };
    double ab[3], ac[3], ap[3], q[3];
    for (int k = 0; k < 3; ++k) {
      ab[k] = bb[k] - a[k];
      ac[k] = c[k] - a[k];
      ap[k] = p[k] - a[k];
    }
    double d1 = dot(ab, ap), d2 = dot(ac, ap);
    auto at = [&](double u, double v) {  // a + u ab + v ac
      for (int k = 0; k < 3; ++k) q[k] = a[k] + u * ab[k] + v * ac[k];
      double e = 0;
      for (int k = 0; k < 3; ++k) e += (p[k] - q[k]) * (p[k] - q[k]);
      return e;
    };
    if (d1 <= 0 && d2 <= 0) return at(0, 0);
    double bp[3];
    for (int k = 0; k < 3; ++k) bp[k] = p[k] - bb[k];
    double d3 = dot(ab, bp), d4 = dot(ac, bp);
    if (d3 >= 0 && d4 <= d3) return at(1, 0);
    double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) return at(d1 / (d1 - d3), 0);
    double cp[3];
    for (int k = 0; k < 3; ++k) cp[k] = p[k] - c[k];
    double d5 = dot(ab, cp), d6 = dot(ac, cp);
    if (d6 >= 0 && d5 <= d6) return at(0, 1);
    double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) return at(0, d2 / (d2 - d6));
    double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
      double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
      return at(1 - w, w);
    }
    double den = 1 / (va + vb + vc);
    return at(vb * den, vc * den);
  }
  double distance(const double* p) const {
    int c[3] = {cellOf(float(p[0]), 0), cellOf(float(p[1]), 1), cellOf(float(p[2]), 2)};
    double best = 1e300;
    for (int ring = 0; ring < n; ++ring) {
      for (int z = c[2] - ring; z <= c[2] + ring; ++z)
        for (int y = c[1] - ring; y <= c[1] + ring; ++y)
          for (int x = c[0] - ring; x <= c[0] + ring; ++x) {
            if (x < 0 || y < 0 || z < 0 || x >= n || y >= n || z >= n) continue;
            if (std::max({std::abs(x - c[0]), std::abs(y - c[1]), std::abs(z - c[2])}) != ring) continue;
            size_t cc = size_t(x) + size_t(n) * (y + size_t(n) * z);
            for (uint32_t k = start[cc]; k < start[cc + 1]; ++k) best = std::min(best, dist2(p, items[k]));
          }
      // Cells of ring r+1 are at least r·cell away from p's cell.
      if (best < 1e300 && std::sqrt(best) <= ring * double(cell)) break;
    }
    return std::sqrt(best);
  }
};

// Area-weighted mean and max distance from the triangles of `from` (centroid and vertices) to `to`.
void oneWay(const IsoSurface& from, const TriangleGrid& to, double& sum, double& weight, double& maxD) {
  for (uint32_t t = 0; t < from.triangleCount(); ++t) {
    const float* v[3];
    for (int k = 0; k < 3; ++k) v[k] = &from.positions[3 * size_t(from.indices[3 * size_t(t) + k])];
    double u[3], w[3];
    for (int k = 0; k < 3; ++k) {
      u[k] = v[1][k] - v[0][k];
      w[k] = v[2][k] - v[0][k];
    }
    double area = 0.5 * std::sqrt(std::pow(u[1] * w[2] - u[2] * w[1], 2) + std::pow(u[2] * w[0] - u[0] * w[2], 2) +
                                  std::pow(u[0] * w[1] - u[1] * w[0], 2));
    double centroid[3];
    for (int k = 0; k < 3; ++k) centroid[k] = (v[0][k] + v[1][k] + v[2][k]) / 3.0;
    double d = to.distance(centroid);
    sum += d * area;
    weight += area;
    maxD = std::max(maxD, d);
    for (int k = 0; k < 3; ++k) {
      double q[3] = {v[k][0], v[k][1], v[k][2]};
      maxD = std::max(maxD, to.distance(q));
    }
  }
}

int cmdIsoDistance(int argc, char** argv) {
  TetMesh orig, approx;
  ReadReport rep;
  if (Result r = readMesh(argv[2], orig, rep); !r) {
    std::fprintf(stderr, "%s\n", r.message.c_str());
    return 1;
  }
  if (Result r = readMesh(argv[3], approx, rep); !r) {
    std::fprintf(stderr, "%s\n", r.message.c_str());
    return 1;
  }
  const std::string field = arg(argc, argv, "--field", orig.fields[0].name.c_str());
  const float value = float(std::atof(arg(argc, argv, "--value", "0")));
  int fo = orig.findField(field), fa = approx.findField(field);
  if (fa < 0 && approx.fields.size() == 1) fa = 0;  // VTK's decimation renames it "scalars"
  if (fo < 0 || fa < 0) {
    std::fprintf(stderr, "field %s missing\n", field.c_str());
    return 1;
  }
  IsoExtractor scratch;
  IsoSurface a, b;
  extractIsosurface(orig, orig.fields[size_t(fo)].values, value, scratch, a);
  extractIsosurface(approx, approx.fields[size_t(fa)].values, value, scratch, b);
  const double diag = computeBounds(orig.positions).diagonal();
  double sum = 0, weight = 0, maxD = 0;
  if (a.triangleCount() && b.triangleCount()) {
    TriangleGrid ga(a), gb(b);
    oneWay(a, gb, sum, weight, maxD);
    oneWay(b, ga, sum, weight, maxD);
  }
  std::printf("{\"trianglesOriginal\": %u, \"trianglesApprox\": %u, \"meanRelative\": %.6g, \"maxRelative\": %.6g}\n",
              a.triangleCount(), b.triangleCount(), weight > 0 ? sum / weight / diag : 0.0, maxD / diag);
  return 0;
}

// Raw little-endian arrays (positions f32, fields f32, tets u32): what `zstd -19` is run on to
// compare against the packed size.
int cmdRaw(char** argv) {
  TetMesh m;
  ReadReport rep;
  if (Result r = readMesh(argv[2], m, rep); !r) {
    std::fprintf(stderr, "%s\n", r.message.c_str());
    return 1;
  }
  std::FILE* f = std::fopen(argv[3], "wb");
  if (!f) return 1;
  std::fwrite(m.positions.data(), 4, m.positions.size(), f);
  for (const ScalarField& fl : m.fields) std::fwrite(fl.values.data(), 4, fl.values.size(), f);
  std::fwrite(m.tets.data(), 4, m.tets.size(), f);
  std::fclose(f);
  return 0;
}

// The mesh as read (any format), as .vtu: vertices and tets in the reader's order, unlike a
// lossless pack unpacked (stream order, which scatters neighbours and slows both tools down).
int cmdVtu(char** argv) {
  TetMesh m;
  ReadReport rep;
  if (Result r = readMesh(argv[2], m, rep); !r) {
    std::fprintf(stderr, "%s\n", r.message.c_str());
    return 1;
  }
  if (Result r = writeMesh(argv[3], m); !r) {
    std::fprintf(stderr, "%s\n", r.message.c_str());
    return 1;
  }
  return 0;
}

// The chunk files of the pack in `dir`, as pd's manifest names them.
ChunkSource packFiles(const std::string& dir, const PartialDataset& pd) {
  return [&dir, &pd](uint32_t index, std::vector<uint8_t>& file) {
    return readFileBytes(dir + "/" + pd.manifest.chunks[index].file, pd.manifest.chunks[index].bytes, file);
  };
}

// Opens the pack in `dir`: its manifest and base.
Result openPack(const std::string& dir, PartialDataset& pd) {
  std::string json;
  Result r = readManifestFile(dir, json);
  if (r) r = openPartial(pd, json, packFiles(dir, pd));
  return r;
}

int cmdRegions(int argc, char** argv) {
  const std::string dir = argv[2];
  const double budget = std::atof(arg(argc, argv, "--bytes", "0"));
  PartialDataset pd;
  const ChunkSource source = packFiles(dir, pd);
  Result r = openPack(dir, pd);
  const Manifest& m = pd.manifest;
  // Ready regions (parent applied) by the viewer's priority: measured field error.
  std::priority_queue<std::pair<double, uint32_t>> ready;
  auto offer = [&](uint32_t k) {
    const NodeInfo& n = m.nodes[k];
    ready.push({n.fieldMax >= 0 ? n.fieldMax : n.fieldError, k});
  };
  for (uint32_t k = 0; k < m.nodes.size(); ++k)
    if (m.nodes[k].parent < 0) offer(k);
  while (r && !ready.empty()) {
    const uint32_t k = ready.top().second;
    uint64_t bytes = 0;
    for (uint32_t c = m.nodes[k].firstChunk; c < m.nodes[k].firstChunk + m.nodes[k].chunkCount; ++c)
      bytes += m.chunks[c].bytes;
    if (double(pd.bytesLoaded + bytes) > budget) break;
    ready.pop();
    r = applyNode(pd, k, source);
    for (uint32_t c = 0; c < m.nodes.size(); ++c)
      if (m.nodes[c].parent == int32_t(k)) offer(c);
  }
  if (r) r = writeMesh(argv[3], pd.pm.mesh);
  if (!r) {
    std::fprintf(stderr, "%s\n", r.message.c_str());
    return 1;
  }
  std::printf("{\"bytes\": %llu, \"regions\": %zu, \"vertices\": %u}\n", (unsigned long long)pd.bytesLoaded,
              pd.applied.size(), pd.pm.vertexCount());
  return 0;
}

// What an isovalue would need if the ancestors of the regions it selects could be fetched split
// by split instead of whole: every node applied in stream order, each split's reads (the tets
// around its kept vertex) and writes (the stars of every vertex of the tets it moves or makes)
// give its exact dependencies on earlier splits; the splits needed are the selected leaves'
// and, of the other nodes, those whose tets straddle the isovalue at full resolution, closed
// under those dependencies. A bound on what patches of the upper levels could give.
int cmdClosure(int argc, char** argv) {
  const std::string dir = argv[2];
  std::vector<double> values;
  for (const char* p = arg(argc, argv, "--values", ""); *p;) {
    char* end;
    const double v = std::strtod(p, &end);
    if (end == p) break;  // (not a number: the list ends)
    values.push_back(v);
    p = *end == ',' ? end + 1 : end;
  }
  PartialDataset pd;
  const ChunkSource source = packFiles(dir, pd);
  Result r = openPack(dir, pd);
  if (!r) {
    std::fprintf(stderr, "%s\n", r.message.c_str());
    return 1;
  }
  const Manifest& m = pd.manifest;
  ProgressiveMesh& pm = pd.pm;
  std::vector<uint32_t> splitNode;
  std::vector<double> splitBytes;
  std::vector<uint32_t> depStart{0}, deps, touched;  // per split: its dependencies; tets it touched
  std::vector<uint32_t> touchedStart{0};
  // Per vertex (its star): the splits that wrote it since it was last read, and those that read
  // it since it was last written.
  std::vector<std::vector<uint32_t>> writers(pm.vertexCount()), readers(pm.vertexCount());
  std::vector<uint32_t> changed, star, mine, writes;
  std::vector<uint8_t> file;
  for (uint32_t k = 0; k < m.nodes.size() && r; ++k) {
    const NodeInfo& node = m.nodes[k];
    for (uint32_t c = node.firstChunk; c < node.firstChunk + node.chunkCount && r; ++c) {
      const ChunkInfo& info = m.chunks[c];
      std::span<const uint8_t> payload;
      if (!(r = source(c, file)) || !(r = openChunk(pd.decoder, info, c, file, payload)) ||
          !(r = beginSplits(pd.reader, payload, info, m)))
        break;
      for (uint32_t s = 0; s < info.splits; ++s) {
        const uint32_t g = uint32_t(splitNode.size());
        const uint32_t tetsBefore = pm.tetCount();
        changed.clear();
        if (!(r = applyNextSplit(pd.reader, pm, pd.quant, changed))) break;
        const uint32_t j = pm.splitJ.back(), i = pm.vertexCount() - 1;
        writers.emplace_back();
        readers.emplace_back();
        mine.clear();
        writes.clear();
        auto has = [&](uint32_t t, uint32_t v) {
          const uint32_t* q = &pm.mesh.tets[4 * size_t(t)];
          return q[0] == v || q[1] == v || q[2] == v || q[3] == v;
        };
        for (uint32_t t : changed)
          if (t >= tetsBefore || has(t, i)) {
            touched.push_back(t);
            for (int a = 0; a < 4; ++a) writes.push_back(pm.mesh.tets[4 * size_t(t) + size_t(a)]);
          }
        touchedStart.push_back(uint32_t(touched.size()));
        std::sort(writes.begin(), writes.end());
        writes.erase(std::unique(writes.begin(), writes.end()), writes.end());
        // Reads star(j): after the writers of it since its last read.
        for (uint32_t w : writers[j]) mine.push_back(w);
        readers[j].push_back(g);
        for (uint32_t v : writes) {
          for (uint32_t q : readers[v])
            if (q != g) mine.push_back(q);
          if (!readers[v].empty() && !(readers[v].size() == 1 && readers[v][0] == g)) {
            writers[v].clear();
            readers[v].clear();
          }
          writers[v].push_back(g);
        }
        std::sort(mine.begin(), mine.end());
        mine.erase(std::unique(mine.begin(), mine.end()), mine.end());
        for (uint32_t d : mine)
          if (d != g) deps.push_back(d);
        depStart.push_back(uint32_t(deps.size()));
        splitNode.push_back(k);
        splitBytes.push_back(double(info.bytes) / info.splits);
      }
      if (r) r = endSplits(pd.reader);
    }
  }
  if (!r) {
    std::fprintf(stderr, "%s\n", r.message.c_str());
    return 1;
  }
  const int f = std::max(0, m.findField(m.isoField));
  const std::vector<float>& value = pm.mesh.fields[size_t(f)].values;
  std::vector<bool> isLeaf(m.nodes.size(), true);
  for (const NodeInfo& n : m.nodes)
    if (n.parent >= 0) isLeaf[size_t(n.parent)] = false;
  double total = m.chunks[0].bytes;
  for (double b : splitBytes) total += b;
  std::printf("{\"splits\": %zu, \"dependencies\": %zu, \"bytesTotal\": %.0f, \"values\": [", splitNode.size(),
              deps.size(), total);
  for (size_t vi = 0; vi < values.size(); ++vi) {
    const double v = values[vi];
    std::vector<uint8_t> need(splitNode.size(), 0);
    std::vector<uint32_t> stack;
    std::vector<bool> nodeSelected(m.nodes.size());
    for (uint32_t k = 0; k < m.nodes.size(); ++k)
      nodeSelected[k] = m.nodes[k].ranges[size_t(f)].min <= v && v <= m.nodes[k].ranges[size_t(f)].max;
    for (uint32_t g = 0; g < splitNode.size(); ++g) {
      bool seed = false;
      if (!nodeSelected[splitNode[g]]) continue;
      if (isLeaf[splitNode[g]]) {
        seed = true;
      } else {  // the full-resolution tets it touched straddle v
        float lo = INFINITY, hi = -INFINITY;
        for (uint32_t e = touchedStart[g]; e < touchedStart[g + 1]; ++e)
          for (int a = 0; a < 4; ++a) {
            const float x = value[pm.mesh.tets[4 * size_t(touched[e]) + size_t(a)]];
            lo = std::min(lo, x), hi = std::max(hi, x);
          }
        seed = lo <= v && v <= hi;
      }
      if (seed && !need[g]) need[g] = 1, stack.push_back(g);
    }
    auto close = [&] {
      while (!stack.empty()) {
        const uint32_t g = stack.back();
        stack.pop_back();
        for (uint32_t e = depStart[g]; e < depStart[g + 1]; ++e)
          if (!need[deps[e]]) need[deps[e]] = 1, stack.push_back(deps[e]);
      }
    };
    close();
    double bytes = m.chunks[0].bytes, treeBytes = m.chunks[0].bytes;
    for (uint32_t g = 0; g < splitNode.size(); ++g) {
      if (need[g]) bytes += splitBytes[g];
      if (nodeSelected[splitNode[g]]) treeBytes += splitBytes[g];
    }
    // Whole nodes: a node with a needed split is needed whole, until nothing changes.
    std::vector<uint8_t> nodeNeeded(m.nodes.size(), 0);
    for (bool grew = true; grew;) {
      grew = false;
      for (uint32_t g = 0; g < splitNode.size(); ++g)
        if (need[g]) nodeNeeded[splitNode[g]] = 1;
      for (uint32_t g = 0; g < splitNode.size(); ++g)
        if (!need[g] && nodeNeeded[splitNode[g]]) need[g] = 1, stack.push_back(g), grew = true;
      close();
    }
    double nodeBytes = m.chunks[0].bytes;
    size_t nodesNeeded = 0;
    for (uint32_t g = 0; g < splitNode.size(); ++g)
      if (need[g]) nodeBytes += splitBytes[g];
    for (uint8_t x : nodeNeeded) nodesNeeded += x;
    std::printf("%s{\"value\": %g, \"tree\": %.4f, \"splitClosure\": %.4f, \"nodeClosure\": %.4f, \"nodes\": %zu}",
                vi ? ", " : "", v, treeBytes / total, bytes / total, nodeBytes / total, nodesNeeded);
  }
  std::printf("]}\n");
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc >= 4 && !std::strcmp(argv[1], "error")) return cmdError(argc, argv);
  if (argc >= 4 && !std::strcmp(argv[1], "isodist")) return cmdIsoDistance(argc, argv);
  if (argc >= 4 && !std::strcmp(argv[1], "raw")) return cmdRaw(argv);
  if (argc >= 4 && !std::strcmp(argv[1], "vtu")) return cmdVtu(argv);
  if (argc >= 4 && !std::strcmp(argv[1], "regions")) return cmdRegions(argc, argv);
  if (argc >= 3 && !std::strcmp(argv[1], "closure")) return cmdClosure(argc, argv);
  std::fprintf(
      stderr,
      "usage: tetstream_bench error ORIG.vtu APPROX.vtu [--field F] | raw MESH.vtu OUT.bin | vtu MESH OUT.vtu | "
      "isodist ORIG.vtu APPROX.vtu [--field F] [--value V] | regions PACKDIR OUT.vtu --bytes N | "
      "closure PACKDIR --values A,B,C\n");
  return 2;
}
