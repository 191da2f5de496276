// Incremental isosurface (core/isosurface_incremental.h), the property of paper §4.3: after any
// sequence of local mesh edits (simulated vertex splits and their undo) the maintained surface
// equals a from-scratch extractIsosurface on the current mesh. Plus the change lists, compact(),
// and a benchmark on Harmonic n = 64 (prints only).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>

#include "dataset.h"
#include "io/generators.h"
#include "isosurface.h"
#include "isosurface_incremental.h"
#include "pack/packer.h"
#include "test_helpers.h"

using namespace tetstream;

namespace {

using Tri = std::array<float, 9>;

// Triangles as position triples, each rotated so its smallest corner comes first (winding kept).
std::vector<Tri> triangleSet(const IsoSurface& s) {
  std::vector<Tri> out;
  for (size_t i = 0; i < s.indices.size(); i += 3) {
    std::array<std::array<float, 3>, 3> c;
    for (int k = 0; k < 3; ++k)
      for (int d = 0; d < 3; ++d) c[k][d] = s.positions[3 * size_t(s.indices[i + k]) + d];
    int first = int(std::min_element(c.begin(), c.end()) - c.begin());
    Tri t;
    for (int k = 0; k < 3; ++k)
      for (int d = 0; d < 3; ++d) t[3 * k + d] = c[(first + k) % 3][d];
    out.push_back(t);
  }
  std::sort(out.begin(), out.end());
  return out;
}

struct Vert {
  std::array<float, 3> p, n;
  bool operator<(const Vert& o) const { return p != o.p ? p < o.p : n < o.n; }
};

std::vector<Vert> vertexSet(const IsoSurface& s) {
  std::vector<Vert> out(s.vertexCount());
  for (uint32_t v = 0; v < s.vertexCount(); ++v)
    for (int d = 0; d < 3; ++d) {
      out[v].p[d] = s.positions[3 * size_t(v) + d];
      out[v].n[d] = s.normals[3 * size_t(v) + d];
    }
  std::sort(out.begin(), out.end());
  return out;
}

void expectSameSurface(const IncrementalIsosurface& inc, const TetMesh& m, const std::string& where) {
  ASSERT_TRUE(inc.validate()) << where;
  IsoExtractor x;
  IsoSurface ref, got;
  extractIsosurface(m, m.fields[0].values, inc.isovalue(), x, ref);
  inc.toIsoSurface(got);
  ASSERT_EQ(inc.vertexCount(), ref.vertexCount()) << where;
  ASSERT_EQ(got.vertexCount(), ref.vertexCount()) << where;
  ASSERT_EQ(inc.triangleCount(), ref.triangleCount()) << where;
  ASSERT_TRUE(triangleSet(got) == triangleSet(ref)) << where << ": triangle sets differ";
  std::vector<Vert> a = vertexSet(got), b = vertexSet(ref);
  for (size_t i = 0; i < a.size(); ++i) {
    ASSERT_TRUE(a[i].p == b[i].p) << where << ": vertex positions differ";
    for (int d = 0; d < 3; ++d) ASSERT_NEAR(a[i].n[d], b[i].n[d], 1e-5) << where << ": normal of vertex " << i;
  }
  const double area = surfaceArea(ref);
  ASSERT_NEAR(inc.area(), area, 1e-9 * std::max(1.0, area)) << where;
}

// Simulated vertex splits: vertex j gives some of its tets (T_moved) to a new vertex i, and new
// tets (i, j, a, b) appear (T_new); undo restores exactly. Not geometrically a real split (tets
// may overlap or be inverted), but every index stays valid, which is all updateTets relies on.
struct SplitRecord {
  uint32_t j, i, oldTetCount;
  std::vector<uint32_t> moved;
};

struct Editor {
  TetMesh& m;
  std::mt19937 rng;
  float quantum = 0;  // > 0: new values are multiples of it (many exact hits of λ)
  std::vector<SplitRecord> stack;
  std::vector<uint32_t> changed;

  std::vector<float>& field() { return m.fields[0].values; }
  float uniform(float lo, float hi) { return lo + (hi - lo) * float(rng() % 100001) / 100000.0f; }

  bool split(float iso) {
    const uint32_t j = rng() % m.vertexCount();
    std::vector<uint32_t> around;
    for (uint32_t t = 0; t < m.tetCount(); ++t)
      for (int k = 0; k < 4; ++k)
        if (m.tets[4 * t + k] == j) around.push_back(t);
    if (around.empty()) return false;
    SplitRecord rec{j, m.vertexCount(), m.tetCount(), {}};
    for (uint32_t t : around)
      if (rng() % 2 == 0) rec.moved.push_back(t);
    if (rec.moved.empty()) rec.moved.push_back(around[rng() % around.size()]);

    for (int d = 0; d < 3; ++d) m.positions.push_back(m.positions[3 * j + d] + uniform(-0.05f, 0.05f));
    float value;
    uint32_t pick = rng() % 10;
    if (pick < 2)
      value = iso;  // exactly on λ
    else if (pick < 4)
      value = field()[m.tets[4 * rec.moved[0] + rng() % 4]];  // a neighbour's value
    else
      value = field()[j] + uniform(-0.1f, 0.1f);
    if (quantum > 0) value = std::round(value / quantum) * quantum;
    field().push_back(value);

    changed.clear();
    for (uint32_t t : rec.moved) {
      for (int k = 0; k < 4; ++k)
        if (m.tets[4 * t + k] == j) m.tets[4 * t + k] = rec.i;
      changed.push_back(t);
    }
    const int added = 1 + int(rng() % 3);
    for (int n = 0; n < added; ++n) {
      uint32_t t = rec.moved[rng() % rec.moved.size()];
      uint32_t others[3], c = 0;
      for (int k = 0; k < 4; ++k)
        if (m.tets[4 * t + k] != rec.i) others[c++] = m.tets[4 * t + k];
      uint32_t a = others[rng() % 3], b;
      do b = others[rng() % 3];
      while (b == a);
      uint32_t tet[4] = {rec.i, j, a, b};
      if (rng() % 2) std::swap(tet[0], tet[1]);  // either orientation
      changed.push_back(m.tetCount());
      m.tets.insert(m.tets.end(), tet, tet + 4);
    }
    if (rng() % 3 == 0) changed.erase(changed.begin() + rec.moved.size(), changed.end());  // new ids implied
    stack.push_back(std::move(rec));
    return true;
  }

  void undo() {
    SplitRecord rec = std::move(stack.back());
    stack.pop_back();
    changed.clear();
    for (uint32_t t : rec.moved) {
      for (int k = 0; k < 4; ++k)
        if (m.tets[4 * t + k] == rec.i) m.tets[4 * t + k] = rec.j;
      changed.push_back(t);
    }
    if (rng() % 2)  // the removed ids may be listed too
      for (uint32_t t = rec.oldTetCount; t < m.tetCount(); ++t) changed.push_back(t);
    m.tets.resize(4 * size_t(rec.oldTetCount));
    m.positions.resize(3 * size_t(rec.i));
    field().resize(rec.i);
  }
};

TetMesh harmonicGrid(uint32_t n, float quantum = 0) {
  TetMesh m = makeGridMesh(n);
  addHarmonicField(m);
  if (quantum > 0)
    for (float& v : m.fields[0].values) v = std::round(v / quantum) * quantum;
  return m;
}

// Random splits and undos with the from-scratch comparison after every step; the isovalue is
// changed now and then (rebuild), to a random value or to a value some vertex has exactly.
// deferredTree: the interval tree covers only a prefix of the tets, grown now and then by a
// random amount (setTreeDeferred, extendTree), as the viewer does while a level streams in.
void runEdits(TetMesh& m, float quantum, uint32_t seed, int steps, bool deferredTree = false) {
  Editor ed{m, std::mt19937(seed), quantum};
  IncrementalIsosurface inc;
  inc.setTreeDeferred(deferredTree);
  float iso = quantum > 0 ? 2 * quantum : 0.05f;
  inc.rebuild(m, m.fields[0].values, iso);
  expectSameSurface(inc, m, "initial");
  for (int step = 0; step < steps; ++step) {
    if (!ed.stack.empty() && ed.rng() % 100 < 40) {
      ed.undo();
    } else if (!ed.split(iso)) {
      continue;
    }
    inc.updateTets(m, m.fields[0].values, ed.changed);
    expectSameSurface(inc, m, "step " + std::to_string(step));
    if (::testing::Test::HasFatalFailure()) return;
    if (deferredTree && ed.rng() % 8 == 0) {
      const bool whole = inc.extendTree(m, m.fields[0].values, ed.rng() % 4 == 0 ? ~0u : ed.rng() % 300);
      ASSERT_EQ(whole, inc.treeCoverage() == m.tetCount());
      ASSERT_TRUE(inc.validate()) << "extended at step " << step;
    }
    if (step % 60 == 59) {
      iso = ed.rng() % 2 ? m.fields[0].values[ed.rng() % m.vertexCount()] : ed.uniform(-0.1f, 0.4f);
      if (quantum > 0) iso = std::round(iso / quantum) * quantum;
      inc.rebuild(m, m.fields[0].values, iso);
      expectSameSurface(inc, m, "rebuild at step " + std::to_string(step));
      if (::testing::Test::HasFatalFailure()) return;
    }
  }
  while (!ed.stack.empty()) {
    ed.undo();
    inc.updateTets(m, m.fields[0].values, ed.changed);
  }
  expectSameSurface(inc, m, "all undone");
}

}  // namespace

TEST(IncrementalIso, TinyMeshes) {
  for (TetMesh m : {test::oneTet(), test::twoTets()}) {
    for (float iso : {-1.0f, 0.0f, 0.5f, 1.0f, 2.0f, 2.5f, 3.0f, 4.0f}) {
      IncrementalIsosurface inc;
      inc.rebuild(m, m.fields[0].values, iso);
      expectSameSurface(inc, m, "λ=" + std::to_string(iso));
      inc.updateTets(m, m.fields[0].values, {});
      std::vector<uint32_t> all = {0, 1};
      inc.updateTets(m, m.fields[0].values, std::span(all).first(m.tetCount()));
      expectSameSurface(inc, m, "updated, λ=" + std::to_string(iso));
    }
  }
}

TEST(IncrementalIso, DegenerateTrianglesKeepTheirVertices) {
  // v2, v3 on λ, v0, v1 above: both triangles collapse, the two surface vertices stay
  // (extractIsosurface creates them before dropping the triangles).
  TetMesh m = test::oneTet();
  m.fields[0].values = {2, 3, 1, 1};
  IncrementalIsosurface inc;
  inc.rebuild(m, m.fields[0].values, 1.0f);
  EXPECT_EQ(inc.triangleCount(), 0u);
  EXPECT_EQ(inc.vertexCount(), 2u);
  expectSameSurface(inc, m, "degenerate");
  m.fields[0].values = {2, 3, 0, 1};  // a value changes: allowed when all its tets are listed
  std::vector<uint32_t> t0 = {0};
  inc.updateTets(m, m.fields[0].values, t0);
  expectSameSurface(inc, m, "value changed");
  EXPECT_EQ(inc.triangleCount(), 1u);  // one of the two triangles still collapses at v3
  EXPECT_EQ(inc.vertexCount(), 3u);
}

TEST(IncrementalIso, SplitsAndUndosEqualFromScratch) {
  TetMesh m = harmonicGrid(8);
  runEdits(m, 0, 1, 500);
}

TEST(IncrementalIso, DeferredTreeSplitsAndUndosEqualFromScratch) {
  TetMesh m = harmonicGrid(8);
  runEdits(m, 0, 2, 500, true);
  TetMesh q = harmonicGrid(6, 1.0f / 16);
  runEdits(q, 1.0f / 16, 3, 300, true);
}

TEST(IncrementalIso, DeferredTreeIsBuiltInSteps) {
  TetMesh m = harmonicGrid(10);
  const auto& f = m.fields[0].values;
  IncrementalIsosurface inc;
  inc.setTreeDeferred(true);
  inc.reserveTets(m.tetCount());
  inc.rebuild(m, f, 0.1f);
  EXPECT_EQ(inc.treeCoverage(), 0u) << "deferred: rebuild tests the tets itself";
  expectSameSurface(inc, m, "no tree");
  uint32_t calls = 0;
  while (!inc.extendTree(m, f, 1000)) ++calls;
  EXPECT_EQ(calls, (m.tetCount() - 1) / 1000);
  EXPECT_EQ(inc.treeCoverage(), m.tetCount());
  EXPECT_EQ(inc.intervalTree().storedCount() > 0, true);
  for (float iso : {-0.05f, 0.02f, 0.3f}) {
    inc.rebuild(m, f, iso);
    expectSameSurface(inc, m, "tree built in steps, λ=" + std::to_string(iso));
  }
  // Not deferred any more: rebuild keeps the covering tree (no second build).
  inc.setTreeDeferred(false);
  inc.rebuild(m, f, 0.1f);
  expectSameSurface(inc, m, "after switching back");
}

TEST(IncrementalIso, IsovalueOnVertexValues) {
  // Field and every new value on multiples of 1/16, λ too: many vertices exactly on λ,
  // shared surface vertices at mesh vertices, degenerate triangles.
  TetMesh m = harmonicGrid(8, 1.0f / 16);
  runEdits(m, 1.0f / 16, 2, 500);
}

TEST(IncrementalIso, ChangeListsReproduceTheArrays) {
  // A mirror updated only from fullUploadNeeded() and the change lists, as a renderer's GPU
  // buffers would be, stays equal to the live arrays.
  TetMesh m = harmonicGrid(8);
  Editor ed{m, std::mt19937(3)};
  IncrementalIsosurface inc;
  std::vector<float> pos, nrm;
  std::vector<uint32_t> idx;
  float iso = 0.05f;
  inc.rebuild(m, m.fields[0].values, iso);
  size_t partialUploads = 0, uploadedVertices = 0;
  for (int step = 0; step < 300; ++step) {
    if (step % 100 == 50) {
      inc.rebuild(m, m.fields[0].values, iso += 0.01f);
    } else if (step % 100 == 75) {
      inc.compact();
    } else {
      if (!ed.stack.empty() && ed.rng() % 100 < 40)
        ed.undo();
      else if (!ed.split(iso))
        continue;
      inc.updateTets(m, m.fields[0].values, ed.changed);
    }
    if (inc.fullUploadNeeded()) {
      EXPECT_TRUE(inc.changedVertices().empty());
      pos.assign(inc.positions().begin(), inc.positions().end());
      nrm.assign(inc.normals().begin(), inc.normals().end());
      idx.assign(inc.indices().begin(), inc.indices().end());
    } else {
      ++partialUploads;
      pos.resize(inc.positions().size());
      nrm.resize(inc.normals().size());
      idx.resize(inc.indices().size());
      for (uint32_t v : inc.changedVertices()) {
        ASSERT_GE(v, inc.changedVertexBegin());
        ASSERT_LT(v, inc.changedVertexEnd());
        for (int d = 0; d < 3; ++d) {
          pos[3 * v + d] = inc.positions()[3 * v + d];
          nrm[3 * v + d] = inc.normals()[3 * v + d];
        }
      }
      uploadedVertices += inc.changedVertices().size();
      for (uint32_t t : inc.changedTriangles()) {
        ASSERT_GE(t, inc.changedTriangleBegin());
        ASSERT_LT(t, inc.changedTriangleEnd());
        if (t >= inc.triangleCount()) continue;
        for (int k = 0; k < 3; ++k) idx[3 * t + k] = inc.indices()[3 * t + k];
      }
    }
    inc.clearChanges();
    ASSERT_TRUE(std::equal(idx.begin(), idx.end(), inc.indices().begin())) << "step " << step;
    // Every vertex a triangle uses must be current (free slots may be stale).
    for (uint32_t v : inc.indices())
      for (int d = 0; d < 3; ++d) {
        ASSERT_EQ(pos[3 * v + d], inc.positions()[3 * v + d]) << "step " << step;
        ASSERT_EQ(nrm[3 * v + d], inc.normals()[3 * v + d]) << "step " << step;
      }
  }
  EXPECT_GT(partialUploads, 200u);
  EXPECT_LT(uploadedVertices / partialUploads, inc.vertexCount() / 4) << "sub-range uploads stay local";
  expectSameSurface(inc, m, "end");
}

TEST(IncrementalIso, CompactKeepsTheSurface) {
  TetMesh m = harmonicGrid(7);
  Editor ed{m, std::mt19937(4)};
  IncrementalIsosurface inc;
  inc.rebuild(m, m.fields[0].values, 0.05f);
  for (int round = 0; round < 3; ++round) {
    for (int step = 0; step < 80; ++step) {
      if (!ed.stack.empty() && ed.rng() % 100 < 50)
        ed.undo();
      else if (!ed.split(0.05f))
        continue;
      inc.updateTets(m, m.fields[0].values, ed.changed);
    }
    inc.compact();
    EXPECT_EQ(inc.vertexSlotCount(), inc.vertexCount());
    expectSameSurface(inc, m, "compacted, round " + std::to_string(round));
  }
}

// ------------------------------------------------------------------ benchmark (prints only)

TEST(IncrementalIso, BenchmarkHarmonic64) {
  using Clock = std::chrono::steady_clock;
  auto ms = [](Clock::time_point a, Clock::time_point b) {
    return std::chrono::duration<double, std::milli>(b - a).count();
  };
  TetMesh m = harmonicGrid(64);
  const uint32_t baseVertices = m.vertexCount(), baseTets = m.tetCount();
  IsoExtractor x;
  IsoSurface ref;
  IncrementalIsosurface inc;

  auto t0 = Clock::now();
  inc.rebuild(m, m.fields[0].values, 0.1f);
  auto t1 = Clock::now();
  std::printf("[ bench    ] Harmonic n=64 (%u tets): first rebuild with tree build %.1f ms\n", baseTets, ms(t0, t1));
  std::printf("[ bench    ] %8s %10s %10s %14s %12s\n", "λ", "triangles", "vertices", "extract (ms)", "rebuild (ms)");
  for (float iso : {0.02f, 0.1f, 0.3f, 0.7f}) {
    t0 = Clock::now();
    extractIsosurface(m, m.fields[0].values, iso, x, ref);
    t1 = Clock::now();
    inc.rebuild(m, m.fields[0].values, iso);
    auto t2 = Clock::now();
    t0 = Clock::now();
    extractIsosurface(m, m.fields[0].values, iso, x, ref);  // warm
    t1 = Clock::now();
    inc.rebuild(m, m.fields[0].values, iso);
    t2 = Clock::now();
    EXPECT_EQ(inc.triangleCount(), ref.triangleCount());
    std::printf("[ bench    ] %8g %10u %10u %14.2f %12.2f\n", iso, ref.triangleCount(), ref.vertexCount(), ms(t0, t1),
                ms(t1, t2));
    RecordProperty("rebuild_ms_" + std::to_string(iso), std::to_string(ms(t1, t2)));
    RecordProperty("extract_ms_" + std::to_string(iso), std::to_string(ms(t0, t1)));
  }

  // Splits around random base vertices near the surface; tets found through a vertex -> tet
  // table of the base mesh (tets that no longer hold j are skipped).
  const float iso = 0.1f;
  inc.rebuild(m, m.fields[0].values, iso);
  std::vector<uint32_t> start(baseVertices + 1, 0), incident(4 * size_t(baseTets));
  for (uint32_t v : m.tets) ++start[v + 1];
  for (uint32_t v = 0; v < baseVertices; ++v) start[v + 1] += start[v];
  {
    std::vector<uint32_t> fill(start.begin(), start.end() - 1);
    for (uint32_t t = 0; t < baseTets; ++t)
      for (int k = 0; k < 4; ++k) incident[fill[m.tets[4 * t + k]]++] = t;
  }
  std::vector<float>& f = m.fields[0].values;
  std::mt19937 rng(9);
  std::vector<SplitRecord> stack;
  std::vector<uint32_t> changed;
  const int splits = 20000;
  double splitMs = 0;
  size_t changedTotal = 0;
  inc.clearChanges();
  while (int(stack.size()) < splits) {
    uint32_t j = rng() % baseVertices;
    if (std::abs(f[j] - iso) > 0.05f) continue;  // splits that touch the surface
    SplitRecord rec{j, m.vertexCount(), m.tetCount(), {}};
    for (uint32_t k = start[j]; k < start[j + 1]; ++k) {
      uint32_t t = incident[k];
      uint32_t* tv = &m.tets[4 * size_t(t)];
      if (rng() % 2 || (tv[0] != j && tv[1] != j && tv[2] != j && tv[3] != j)) continue;
      for (int c = 0; c < 4; ++c)
        if (tv[c] == j) tv[c] = rec.i;
      rec.moved.push_back(t);
    }
    if (rec.moved.empty()) continue;
    for (int d = 0; d < 3; ++d) m.positions.push_back(m.positions[3 * j + d] + 0.001f * float(d + 1));
    f.push_back(f[j] + (float(rng() % 1000) / 1000.0f - 0.5f) * 0.02f);
    changed.assign(rec.moved.begin(), rec.moved.end());
    for (int n = 0; n < 2; ++n) {
      const uint32_t* tv = &m.tets[4 * size_t(rec.moved[n % rec.moved.size()])];
      uint32_t others[3], c = 0;
      for (int k = 0; k < 4; ++k)
        if (tv[k] != rec.i) others[c++] = tv[k];
      uint32_t tet[4] = {rec.i, j, others[n], others[(n + 1) % 3]};
      changed.push_back(m.tetCount());
      m.tets.insert(m.tets.end(), tet, tet + 4);
    }
    changedTotal += changed.size();
    auto a = Clock::now();
    inc.updateTets(m, f, changed);
    splitMs += ms(a, Clock::now());
    stack.push_back(std::move(rec));
  }
  const size_t uploads = inc.changedVertices().size();
  inc.clearChanges();
  t0 = Clock::now();
  inc.rebuild(m, f, 0.2f);
  t1 = Clock::now();
  extractIsosurface(m, f, 0.2f, x, ref);
  auto t2 = Clock::now();
  EXPECT_EQ(inc.triangleCount(), ref.triangleCount());
  const double bytesPerTet = double(inc.memoryBytes()) / m.tetCount();
  const double treeBytesPerTet = double(inc.intervalTree().memoryBytes()) / m.tetCount();
  inc.rebuild(m, f, iso);
  double undoMs = 0;
  while (!stack.empty()) {
    SplitRecord rec = std::move(stack.back());
    stack.pop_back();
    for (uint32_t t : rec.moved)
      for (int k = 0; k < 4; ++k)
        if (m.tets[4 * size_t(t) + k] == rec.i) m.tets[4 * size_t(t) + k] = rec.j;
    m.tets.resize(4 * size_t(rec.oldTetCount));
    m.positions.resize(3 * size_t(rec.i));
    f.resize(rec.i);
    auto a = Clock::now();
    inc.updateTets(m, f, rec.moved);
    undoMs += ms(a, Clock::now());
  }
  std::printf(
      "[ bench    ] %d splits near λ=%g (%.1f changed tets each): updateTets %.2f us per split, "
      "undo %.2f us per split; %zu vertex slots to upload after all splits\n",
      splits, iso, double(changedTotal) / splits, 1000 * splitMs / splits, 1000 * undoMs / splits, uploads);
  std::printf(
      "[ bench    ] after the splits: rebuild at λ=0.2 %.2f ms (extractIsosurface %.2f ms); "
      "%.1f bytes per tet in the incremental state (tree %.1f)\n",
      ms(t0, t1), ms(t1, t2), bytesPerTet, treeBytesPerTet);
  RecordProperty("split_update_us", std::to_string(1000 * splitMs / splits));
  RecordProperty("undo_update_us", std::to_string(1000 * undoMs / splits));
  expectSameSurface(inc, m, "after undoing every split");
}

// The same property on the real stream: pack Harmonic, then walk the level up and down through
// every received split (applySplit / undoSplit via the dataset), updating locally after every
// few splits, and compare with a from-scratch extraction each time. With orderSplits the splits
// of each chunk come by kept vertex (pack --compact).
void expectRealSplitsEqualFromScratch(bool orderSplits) {
  test::ScratchDir dir(orderSplits ? "incremental-real-ordered" : "incremental-real");
  TetMesh m = makeGridMesh(10);
  addHarmonicField(m);
  PackOptions o;
  o.chunkKb = 1;
  o.zstdLevel = 3;
  o.orderSplits = orderSplits;
  PackSummary s;
  ASSERT_TRUE(packMesh(m, dir.path, o, s));
  Dataset ds;
  ASSERT_TRUE(loadPackedDir(dir.path, ds, 1));
  for (uint32_t c = 1; c < ds.manifest.chunks.size(); ++c)
    ASSERT_TRUE(receiveChunk(ds, c, test::loadBytes(dir.path + "/" + ds.manifest.chunks[c].file)));
  for (float iso : {0.2f, -0.1f}) {
    IncrementalIsosurface inc;
    std::vector<uint32_t> changed;
    bool reached = false;
    ASSERT_TRUE(stepTowards(ds, 0, ~0u, changed, &reached));
    inc.rebuild(ds.pm.mesh, ds.pm.mesh.fields[0].values, iso);
    expectSameSurface(inc, ds.pm.mesh, "base");
    const uint32_t total = ds.splitsReceived();
    // Up in steps of 7, down in steps of 13 to the middle, up again to the end.
    for (uint32_t target : {total, total / 2, total}) {
      const uint32_t stride = target < ds.splitsApplied() ? 13 : 7;
      while (ds.splitsApplied() != target) {
        changed.clear();
        ASSERT_TRUE(stepTowards(ds, target, stride, changed, &reached));
        inc.updateTets(ds.pm.mesh, ds.pm.mesh.fields[0].values, changed);
        expectSameSurface(inc, ds.pm.mesh, "at " + std::to_string(ds.splitsApplied()) + " splits");
      }
    }
    EXPECT_EQ(ds.pm.vertexCount(), m.vertexCount());
  }
}

TEST(IncrementalIso, RealVertexSplitsEqualFromScratch) { expectRealSplitsEqualFromScratch(false); }
TEST(IncrementalIso, RealVertexSplitsInKeptVertexOrderEqualFromScratch) { expectRealSplitsEqualFromScratch(true); }
