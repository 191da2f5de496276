#include "test_helpers.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>
#include <zstd.h>

#include <algorithm>
#include <array>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>

#include "adjacency.h"
#include "chunk.h"
#include "dataset.h"
#include "io/generators.h"
#include "io/mesh_io.h"
#include "pack/chunk_encode.h"
#include "split_stream.h"
#include "validate.h"

namespace tetstream::test {

// ------------------------------------------------------------------ files and fixtures

std::string fixturePath(const std::string& name) { return std::string(TETSTREAM_FIXTURES) + "/" + name; }

const nlohmann::json& fixtureJson(const std::string& name) {
  static std::map<std::string, nlohmann::json> parsed;
  auto it = parsed.find(name);
  if (it == parsed.end())
    it = parsed.emplace(name, nlohmann::json::parse(loadFile(fixturePath(name)), nullptr, false)).first;
  return it->second;
}

int64_t findVertex(const TetMesh& m, double x, double y, double z) {
  for (uint32_t v = 0; v < m.vertexCount(); ++v)
    if (m.positions[3 * v] == float(x) && m.positions[3 * v + 1] == float(y) && m.positions[3 * v + 2] == float(z))
      return v;
  return -1;
}

std::vector<std::string> fixtureFiles() {
  std::vector<std::string> out;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(TETSTREAM_FIXTURES, ec)) {
    std::string ext = e.path().extension().string();
    if (ext == ".vtu" || ext == ".vtk") out.push_back(e.path().filename().string());
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::string loadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

bool saveFile(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(bytes.data(), std::streamsize(bytes.size()));
  return bool(out);
}

ScratchDir::ScratchDir(const std::string& name) {
  auto dir = std::filesystem::temp_directory_path() / ("tetstream-" + name + "-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  path = dir.string();
}

ScratchDir::~ScratchDir() {
  std::error_code ec;
  std::filesystem::remove_all(path, ec);
}

TetMesh harmonicMesh(uint32_t n) {
  TetMesh m = makeGridMesh(n);
  addHarmonicField(m);
  addDistanceField(m);
  m.name = "harmonic";
  return m;
}

std::string suiteDir(const std::string& suite, const std::string& name) {
  static std::map<std::string, std::unique_ptr<ScratchDir>> roots;  // destroyed at exit
  auto& root = roots[suite];
  if (!root) root = std::make_unique<ScratchDir>(suite);
  std::string dir = root->path + "/" + name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

std::vector<uint8_t> forgeTruncatedChunk(const std::vector<uint8_t>& file, ChunkInfo& info) {
  std::vector<uint8_t> raw(info.rawBytes);
  if (ZSTD_decompress(raw.data(), raw.size(), file.data(), file.size()) != raw.size()) return {};
  raw.pop_back();  // the last record ends early
  // In columns, the last column (Values) one byte shorter too, so the chunk passes its header.
  uint32_t flags, last;
  std::memcpy(&flags, &raw[kChunkHeaderBytes + 4], 4);
  if (flags & kSplitFlagColumns) {
    const size_t at = kChunkHeaderBytes + 8 + 4 * (kSplitColumns - 1);
    std::memcpy(&last, &raw[at], 4);
    if (last == 0) return {};
    --last;
    std::memcpy(&raw[at], &last, 4);
  }
  std::vector<uint8_t> bad;
  ChunkInfo forged = info;
  if (!finishChunk(raw, 3, bad, forged)) return {};
  info.bytes = forged.bytes;
  info.rawBytes = forged.rawBytes;
  info.hash = forged.hash;
  return bad;
}

int runCommand(const std::string& command, std::string& output) {
  output.clear();
  std::FILE* p = ::popen(command.c_str(), "r");
  if (!p) return -1;
  char buf[4096];
  size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) output.append(buf, n);
  int status = ::pclose(p);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

bool haveMeshioPython() {
  static const bool have = [] {
    std::string out;
    return runCommand("/usr/bin/python3 -c 'import meshio' 2>/dev/null", out) == 0;
  }();
  return have;
}

// ------------------------------------------------------------------ cells

double totalVolume(const TetMesh& m) {
  double v = 0;
  for (uint32_t t = 0; t < m.tetCount(); ++t) v += std::abs(tetVolume(m, t));
  return v;
}

std::vector<uint32_t> boundaryTriangles(const TetMesh& m) {
  FaceAdjacency adj;
  buildFaceAdjacency(m.tets, m.vertexCount(), adj);
  std::vector<uint32_t> tris;
  extractBoundary(m.tets, adj, tris);
  return tris;
}

double boundaryArea(const TetMesh& m) {
  const std::vector<uint32_t> tris = boundaryTriangles(m);
  double area = 0;
  for (size_t i = 0; i < tris.size(); i += 3) {
    const float* a = &m.positions[3 * size_t(tris[i])];
    const float* b = &m.positions[3 * size_t(tris[i + 1])];
    const float* c = &m.positions[3 * size_t(tris[i + 2])];
    double u[3], v[3];
    for (int k = 0; k < 3; ++k) {
      u[k] = double(b[k]) - a[k];
      v[k] = double(c[k]) - a[k];
    }
    double x = u[1] * v[2] - u[2] * v[1], y = u[2] * v[0] - u[0] * v[2], z = u[0] * v[1] - u[1] * v[0];
    area += 0.5 * std::sqrt(x * x + y * y + z * z);
  }
  return area;
}

// A conforming, valid mesh: every inner face shared by exactly two tets, a closed manifold
// boundary, one orientation, no flat or duplicate tets, no unused vertices.
void expectValid(const TetMesh& m, const std::string& what) {
  ValidationReport v = validateMesh(m);
  EXPECT_FALSE(v.fatal()) << what;
  EXPECT_EQ(v.invertedTets, 0u) << what;
  EXPECT_EQ(v.zeroVolumeTets, 0u) << what;
  EXPECT_EQ(v.duplicateTets, 0u) << what;
  EXPECT_EQ(v.unusedVertices, 0u) << what;
  EXPECT_EQ(v.nonManifoldFaces, 0u) << what;
  EXPECT_EQ(v.nonManifoldBoundaryEdges, 0u) << what;
}

// ------------------------------------------------------------------ packs and levels

std::string tempDir(const std::string& name) { return suiteDir("progressive", name); }

// Chunk `info` of the pack in `dir`, decompressed (empty when that fails).
std::vector<uint8_t> rawChunk(const std::string& dir, const ChunkInfo& info) {
  const std::vector<uint8_t> file = loadBytes(dir + "/" + info.file);
  std::vector<uint8_t> raw(info.rawBytes);
  if (ZSTD_decompress(raw.data(), raw.size(), file.data(), file.size()) != raw.size()) raw.clear();
  return raw;
}

// Harmonic n³ without the tets whose centroid `drop` selects, and without the vertices no
// tet uses any more.
TetMesh carved(uint32_t n, bool (*drop)(const float* centroid)) {
  TetMesh g = harmonic(n);
  TetMesh m;
  m.fields.resize(g.fields.size());
  for (size_t f = 0; f < g.fields.size(); ++f) m.fields[f].name = g.fields[f].name;
  std::vector<uint32_t> remap(g.vertexCount(), ~0u);
  for (uint32_t t = 0; t < g.tetCount(); ++t) {
    const uint32_t* v = &g.tets[4 * t];
    float c[3] = {0, 0, 0};
    for (int k = 0; k < 4; ++k)
      for (int a = 0; a < 3; ++a) c[a] += g.positions[3 * v[k] + a] / 4;
    if (drop(c)) continue;
    for (int k = 0; k < 4; ++k) {
      if (remap[v[k]] == ~0u) {
        remap[v[k]] = m.vertexCount();
        m.positions.insert(m.positions.end(), &g.positions[3 * v[k]], &g.positions[3 * v[k]] + 3);
        for (size_t f = 0; f < g.fields.size(); ++f) m.fields[f].values.push_back(g.fields[f].values[v[k]]);
      }
      m.tets.push_back(remap[v[k]]);
    }
  }
  m.name = "carved";
  return m;
}

// The octant x, y, z > 0 removed: a non-convex domain with concave creases.
TetMesh lShape(uint32_t n) {
  return carved(n, [](const float* c) { return c[0] > 0 && c[1] > 0 && c[2] > 0; });
}

// The simplifier's result as a mesh (all input vertices kept, the surviving tets).
TetMesh baseMeshOf(const TetMesh& m, const SimplifyResult& r) {
  TetMesh base;
  base.positions = m.positions;
  for (uint32_t t = 0; t < m.tetCount(); ++t)
    if (r.tetAlive[t]) base.tets.insert(base.tets.end(), &r.tets[4 * t], &r.tets[4 * t] + 4);
  return base;
}

// The coarsest level as the simplifier leaves it: alive vertices and tets, the steering field's
// values as fitted.
TetMesh coarseMesh(const TetMesh& in, const SimplifyResult& r) {
  TetMesh m;
  m.fields.resize(1);
  std::vector<uint32_t> index(in.vertexCount(), ~0u);
  for (uint32_t v = 0; v < in.vertexCount(); ++v) {
    if (!r.vertexAlive[v]) continue;
    index[v] = m.vertexCount();
    m.positions.insert(m.positions.end(), &in.positions[3 * v], &in.positions[3 * v] + 3);
    m.fields[0].values.push_back(r.values[v]);
  }
  for (uint32_t t = 0; t < in.tetCount(); ++t)
    if (r.tetAlive[t])
      for (int k = 0; k < 4; ++k) m.tets.push_back(index[r.tets[4 * t + k]]);
  return m;
}

// V − E + F of the boundary surface: 2 for a ball-shaped domain, 0 for one with a tunnel.
long boundaryEuler(const TetMesh& m) {
  const std::vector<uint32_t> b = boundaryTriangles(m);
  std::vector<uint32_t> verts(b);
  std::sort(verts.begin(), verts.end());
  verts.erase(std::unique(verts.begin(), verts.end()), verts.end());
  const long F = long(b.size() / 3);
  return long(verts.size()) - 3 * F / 2 + F;
}

double meshVolume(const TetMesh& m) {
  double v = 0;
  for (uint32_t t = 0; t < m.tetCount(); ++t) v += tetVolume(m, t);
  return v;
}

std::string pack(const std::string& name, const TetMesh& m, PackOptions o, PackSummary* summary) {
  std::string dir = tempDir(name);
  PackSummary s;
  o.zstdLevel = 3;
  Result r = packMesh(m, dir, o, s);
  EXPECT_TRUE(r) << r.message;
  if (summary) *summary = s;
  return dir;
}

// Asserts what FORMAT.md promises for every level.
void expectValidLevel(const TetMesh& m, const std::string& what) {
  ValidationReport r = validateMesh(m);
  EXPECT_EQ(r.negativeTets, 0u) << what;
  EXPECT_EQ(r.zeroVolumeTets, 0u) << what;
  EXPECT_EQ(r.repeatedVertexTets, 0u) << what;
  EXPECT_EQ(r.duplicateTets, 0u) << what;
  EXPECT_EQ(r.nonManifoldFaces, 0u) << what;
  EXPECT_EQ(r.nonManifoldBoundaryEdges, 0u) << what;
  EXPECT_EQ(r.unusedVertices, 0u) << what;
  EXPECT_EQ(boundaryEuler(m), 2) << what << ": the boundary of a ball-shaped domain stays a sphere";
}

// Compares the fully refined mesh with the input: same vertex set (positions to within `tol`
// per coordinate, fields to within `ftol`) and the same tets with the same orientation.
void expectSameMesh(const TetMesh& in, const TetMesh& out, const Quantizer& q, bool exact) {
  ASSERT_EQ(in.vertexCount(), out.vertexCount());
  ASSERT_EQ(in.tetCount(), out.tetCount());
  // Key vertices by grid cell: unique for these meshes, identical for both sides.
  auto key = [&](const float* p) {
    return std::array<uint32_t, 3>{q.position[0].quantize(p[0]), q.position[1].quantize(p[1]),
                                   q.position[2].quantize(p[2])};
  };
  std::map<std::array<uint32_t, 3>, uint32_t> original;
  for (uint32_t v = 0; v < in.vertexCount(); ++v) original[key(&in.positions[3 * v])] = v;
  ASSERT_EQ(original.size(), in.vertexCount());
  std::vector<uint32_t> toIn(out.vertexCount());
  for (uint32_t v = 0; v < out.vertexCount(); ++v) {
    auto it = original.find(key(&out.positions[3 * v]));
    ASSERT_NE(it, original.end());
    toIn[v] = it->second;
    for (int k = 0; k < 3; ++k) {
      float a = in.positions[3 * it->second + k], b = out.positions[3 * v + k];
      if (exact)
        EXPECT_EQ(std::memcmp(&a, &b, 4), 0);
      else
        EXPECT_LE(std::abs(a - b), 0.5f * q.position[k].step * 1.0001f);
    }
    for (size_t f = 0; f < in.fields.size(); ++f) {
      float a = in.fields[f].values[it->second], b = out.fields[f].values[v];
      if (exact)
        EXPECT_EQ(std::memcmp(&a, &b, 4), 0);
      else
        EXPECT_LE(std::abs(a - b), 0.5f * q.field[f].step * 1.0001f +
                                       FLT_EPSILON * (std::abs(q.field[f].min) + 2 * std::abs(b)));  // (+ float decode)
    }
  }
  // Tets: the same vertex sets, and each an even permutation of the input's (same orientation).
  std::map<std::array<uint32_t, 4>, std::array<uint32_t, 4>> inTets;
  for (uint32_t t = 0; t < in.tetCount(); ++t) {
    std::array<uint32_t, 4> v, s;
    std::copy_n(&in.tets[4 * t], 4, v.begin());
    s = v;
    std::sort(s.begin(), s.end());
    inTets[s] = v;
  }
  for (uint32_t t = 0; t < out.tetCount(); ++t) {
    std::array<uint32_t, 4> v, s;
    for (int k = 0; k < 4; ++k) v[k] = toIn[out.tets[4 * t + k]];
    s = v;
    std::sort(s.begin(), s.end());
    auto it = inTets.find(s);
    ASSERT_NE(it, inTets.end()) << "tet " << t << " is not in the input";
    int inversions = 0;  // parity of the permutation from the input's order to ours
    std::array<int, 4> pos;
    for (int k = 0; k < 4; ++k)
      pos[k] = int(std::find(it->second.begin(), it->second.end(), v[k]) - it->second.begin());
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b) inversions += pos[a] > pos[b];
    EXPECT_EQ(inversions % 2, 0) << "tet " << t << " changed orientation";
  }
}

// Two packed folders hold the same bytes: manifest and every chunk file.
void expectSamePack(const std::string& a, const std::string& b) {
  EXPECT_EQ(loadFile(a + "/manifest.json"), loadFile(b + "/manifest.json"));
  for (auto& e : std::filesystem::directory_iterator(a + "/chunks"))
    EXPECT_EQ(loadFile(e.path().string()), loadFile(b + "/chunks/" + e.path().filename().string()));
}

void roundTrip(const std::string& name, const TetMesh& m, PackOptions o) {
  o.chunkKb = 2;          // many small chunks: many prefixes to check
  o.minBaseVertices = 0;  // these meshes are small: simplify all the way to 1%
  PackSummary s;
  std::string dir = pack(name, m, o, &s);
  Dataset ds;
  Result r = loadPackedDir(dir, ds, 0);
  ASSERT_TRUE(r) << r.message;
  const size_t chunks = ds.manifest.chunks.size();
  ASSERT_GE(chunks, 3u) << "expected a base and several split chunks";
  EXPECT_LE(s.baseVertices, m.vertexCount() / 20) << s.stopReason;
  for (size_t k = 1; k <= chunks; ++k) {
    Dataset level;
    r = loadPackedDir(dir, level, int(k));
    ASSERT_TRUE(r) << r.message;
    EXPECT_EQ(level.pm.vertexCount(), level.manifest.chunks[k - 1].vertices);
    EXPECT_EQ(level.pm.tetCount(), level.manifest.chunks[k - 1].tets);
    expectValidLevel(level.pm.mesh, name + " after " + std::to_string(k) + " chunks");
    if (k > 1) {
      EXPECT_LE(level.manifest.chunks[k - 1].fieldError, level.manifest.chunks[k - 2].fieldError);
    }
  }
  Dataset full;
  ASSERT_TRUE(loadPackedDir(dir, full));
  EXPECT_EQ(full.manifest.chunks.back().fieldError, 0.0);
  expectSameMesh(m, full.pm.mesh, full.quant, o.lossless);
}

// By brute force, the coarse tet that holds p best (largest smallest barycentric coordinate,
// returned) and p's barycentric coordinates in it.
double bestTet(const TetMesh& coarse, const float* p, uint32_t& tet, double w[4]) {
  double best = -1e30;
  for (uint32_t t = 0; t < coarse.tetCount(); ++t) {
    const uint32_t* c = &coarse.tets[4 * t];
    const float* q[4] = {&coarse.positions[3 * c[0]], &coarse.positions[3 * c[1]], &coarse.positions[3 * c[2]],
                         &coarse.positions[3 * c[3]]};
    double l[4];
    const double lo = barycentric(q, p, l);
    if (lo <= best) continue;
    best = lo;
    tet = t;
    std::copy_n(l, 4, w);
  }
  return best;
}

// RMS over the input's vertices of (coarse field interpolated there − input value).
double fieldRms(const TetMesh& in, const TetMesh& coarse, int field) {
  double sum = 0;
  for (uint32_t v = 0; v < in.vertexCount(); ++v) {
    uint32_t tet = 0;
    double w[4] = {}, value = 0;
    bestTet(coarse, &in.positions[3 * v], tet, w);
    for (int k = 0; k < 4; ++k) value += w[k] * coarse.fields[size_t(field)].values[coarse.tets[4 * tet + k]];
    const double d = value - in.fields[size_t(field)].values[v];
    sum += d * d;
  }
  return std::sqrt(sum / in.vertexCount());
}

std::vector<std::array<Corner, 4>> tetsByCorners(const TetMesh& m) {
  std::vector<std::array<Corner, 4>> out;
  for (uint32_t t = 0; t < m.tetCount(); ++t) {
    std::array<Corner, 4> tet;
    for (int k = 0; k < 4; ++k) {
      const float* p = &m.positions[3 * size_t(m.tets[4 * size_t(t) + size_t(k)])];
      tet[size_t(k)] = {p[0], p[1], p[2]};
    }
    std::sort(tet.begin(), tet.end());
    out.push_back(tet);
  }
  std::sort(out.begin(), out.end());
  return out;
}

ReadOptions shareOf(uint32_t index, uint32_t count) {
  ReadOptions o;
  o.shareIndex = index;
  o.shareCount = count;
  return o;
}

uint64_t tetsOfShares(const std::string& path, uint32_t count, bool nonEmpty) {
  uint64_t tets = 0;
  for (uint32_t k = 0; k < count; ++k) {
    TetMesh part;
    ReadReport r;
    EXPECT_TRUE(readMesh(path, part, r, shareOf(k, count))) << path << " share " << k;
    EXPECT_TRUE(r.shared) << path << " share " << k;
    if (nonEmpty) {
      EXPECT_GT(part.tetCount(), 0u) << path << " share " << k;
    }
    tets += part.tetCount();
  }
  return tets;
}

void expectSharesReadOnlyUsedPoints(const std::string& path, uint32_t count, const std::string& noteTail) {
  for (uint32_t k = 0; k < count; ++k) {
    SCOPED_TRACE(path + ": share " + std::to_string(k) + " of " + std::to_string(count));
    TetMesh part;
    ReadReport r;
    ASSERT_TRUE(readMesh(path, part, r, shareOf(k, count)));
    std::vector<uint8_t> used(part.vertexCount(), 0);
    for (uint32_t v : part.tets) used[v] = 1;
    EXPECT_EQ(std::count(used.begin(), used.end(), 1), std::ptrdiff_t(part.vertexCount()));
    const std::string note = "the " + std::to_string(part.vertexCount()) + " " + noteTail;
    EXPECT_TRUE(std::any_of(r.notes.begin(), r.notes.end(),
                            [&](const std::string& n) { return n.find(note) != std::string::npos; }))
        << note << "; the last note: " << (r.notes.empty() ? "" : r.notes.back());
  }
}

TetMesh shuffledPoints(const TetMesh& m) {
  // Point p of the result is m's vertex order[p].
  std::vector<uint32_t> order(m.vertexCount()), placeOf(m.vertexCount());
  for (uint32_t v = 0; v < order.size(); ++v) order[v] = v;
  for (uint32_t v = uint32_t(order.size()); v-- > 1;) std::swap(order[v], order[(v * 2654435761u) % (v + 1)]);
  TetMesh out = m;
  for (uint32_t p = 0; p < order.size(); ++p) {
    placeOf[order[p]] = p;
    for (int k = 0; k < 3; ++k)
      out.positions[3 * size_t(p) + size_t(k)] = m.positions[3 * size_t(order[p]) + size_t(k)];
    for (size_t f = 0; f < m.fields.size(); ++f) out.fields[f].values[p] = m.fields[f].values[order[p]];
  }
  for (uint32_t& v : out.tets) v = placeOf[v];
  return out;
}

void expectSharesMakeTheWhole(const std::string& path, uint32_t count, const std::string& skipField) {
  auto skip = [&](const ScalarField& f) { return f.name == skipField || f.name.ends_with("_cell"); };
  SCOPED_TRACE(path + " in " + std::to_string(count) + " shares");
  TetMesh whole;
  ReadReport wr;
  ASSERT_TRUE(readMesh(path, whole, wr));
  EXPECT_FALSE(wr.shared);
  std::map<Corner, std::vector<float>> valueAt;
  for (uint32_t v = 0; v < whole.vertexCount(); ++v)
    for (const ScalarField& f : whole.fields)
      if (!skip(f))
        valueAt[{whole.positions[3 * v], whole.positions[3 * v + 1], whole.positions[3 * v + 2]}].push_back(
            f.values[v]);
  std::vector<std::array<Corner, 4>> all;
  for (uint32_t k = 0; k < count; ++k) {
    TetMesh part;
    ReadReport r;
    ASSERT_TRUE(readMesh(path, part, r, shareOf(k, count))) << "share " << k;
    EXPECT_TRUE(r.shared);
    EXPECT_LT(part.vertexCount(), whole.vertexCount()) << "share " << k;
    ASSERT_EQ(part.fields.size(), whole.fields.size());
    for (uint32_t v = 0; v < part.vertexCount(); ++v) {
      std::vector<float> mine;
      for (const ScalarField& f : part.fields)
        if (!skip(f)) mine.push_back(f.values[v]);
      const auto it = valueAt.find({part.positions[3 * v], part.positions[3 * v + 1], part.positions[3 * v + 2]});
      ASSERT_NE(it, valueAt.end()) << "a point the whole does not have";
      EXPECT_EQ(mine, it->second);
    }
    const auto tets = tetsByCorners(part);
    all.insert(all.end(), tets.begin(), tets.end());
  }
  std::sort(all.begin(), all.end());
  EXPECT_EQ(all, tetsByCorners(whole));
}

}  // namespace tetstream::test
