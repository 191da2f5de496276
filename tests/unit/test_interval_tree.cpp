// Interval tree (core/interval_tree.h): queries equal brute force on static and changing data,
// the stabbing rule equals the marching-tets classification, and a benchmark (prints only)
// against a plain scan and a static Cignoni interval tree on Harmonic n = 64.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <random>
#include <string>

#include "interval_tree.h"
#include "io/generators.h"
#include "tet_tables.h"

using namespace tetstream;

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
const float kNaN = std::numeric_limits<float>::quiet_NaN();

std::vector<uint32_t> sorted(std::vector<uint32_t> v) {
  std::sort(v.begin(), v.end());
  return v;
}

std::vector<uint32_t> query(const IntervalTree& tree, float iso) {
  std::vector<uint32_t> out;
  tree.query(iso, out);
  return sorted(out);
}

// Brute force over a mirror where absent ids are nullopt.
std::vector<uint32_t> bruteForce(const std::vector<std::optional<Interval>>& ivs, float iso) {
  std::vector<uint32_t> out;
  for (uint32_t i = 0; i < ivs.size(); ++i)
    if (ivs[i] && ivs[i]->min <= iso && iso < ivs[i]->max) out.push_back(i);
  return out;
}

// Values from a small set, so endpoints repeat a lot; -inf (from NaN field values) included.
float randomValue(std::mt19937& rng, int levels) {
  int k = int(rng() % uint32_t(levels + 1));
  if (k == levels) return -kInf;
  return float(k) * 0.25f - 1.0f;
}

Interval randomInterval(std::mt19937& rng, int levels) {
  float a = randomValue(rng, levels), b = randomValue(rng, levels);
  if (rng() % 8 == 0) b = a;  // empty: no λ stabs it
  return {std::min(a, b), std::max(a, b)};
}

// Isovalues worth asking: every endpoint level, values between them, the extremes and NaN.
std::vector<float> probeValues(int levels) {
  std::vector<float> out = {-kInf, kInf, kNaN, -0.0f, 0.0f};
  for (int k = -1; k <= levels; ++k) {
    out.push_back(float(k) * 0.25f - 1.0f);
    out.push_back(float(k) * 0.25f - 1.0f + 0.125f);
  }
  return out;
}

void expectMatches(const IntervalTree& tree, const std::vector<std::optional<Interval>>& mirror, int levels,
                   const std::string& where) {
  ASSERT_TRUE(tree.validate()) << where;
  for (float iso : probeValues(levels)) ASSERT_EQ(query(tree, iso), bruteForce(mirror, iso)) << where << " λ=" << iso;
}

}  // namespace

TEST(IntervalTree, StabbingRuleEqualsMarchingCase) {
  // Every 4-tuple over values with ties, ±inf and NaN, at every isovalue of the same set.
  const float values[] = {-kInf, -1.0f, -0.0f, 0.0f, 0.5f, 1.0f, kInf, kNaN};
  TetMesh m;
  m.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  m.tets = {0, 1, 2, 3};
  std::vector<float> field(4);
  long checked = 0;
  for (int code = 0; code < 8 * 8 * 8 * 8; ++code) {
    for (int i = 0, c = code; i < 4; ++i, c /= 8) field[i] = values[c % 8];
    Interval iv = tetInterval(m, field, 0);
    for (float iso : values) {
      unsigned mask = 0;
      for (int i = 0; i < 4; ++i) mask |= unsigned(field[i] > iso) << i;
      bool hasTriangles = kMarchingTets[mask].triangleCount > 0;
      ASSERT_EQ(stabs(iv, iso), hasTriangles) << "code " << code << " λ=" << iso;
      ++checked;
    }
  }
  EXPECT_EQ(checked, 4096 * 8);
}

TEST(IntervalTree, EmptyTree) {
  IntervalTree fresh;
  EXPECT_TRUE(query(fresh, 0.0f).empty());
  EXPECT_EQ(fresh.idCount(), 0u);
  fresh.remove(3);  // absent: no-op
  fresh.truncate(0);
  EXPECT_TRUE(fresh.validate());

  IntervalTree built;
  built.build(std::span<const Interval>());
  EXPECT_TRUE(query(built, 0.0f).empty());
  EXPECT_TRUE(built.validate());
  EXPECT_EQ(built.bucketCount(), 1u);

  // Only empty intervals: ids known, nothing stored.
  std::vector<Interval> flat = {{1, 1}, {-kInf, -kInf}, {0, 0}};
  built.build(flat);
  EXPECT_EQ(built.idCount(), 3u);
  EXPECT_EQ(built.storedCount(), 0u);
  for (float iso : probeValues(8)) EXPECT_TRUE(query(built, iso).empty());

  // Insert into a default-constructed tree.
  fresh.insert(5, {0, 1});
  EXPECT_EQ(fresh.idCount(), 6u);
  EXPECT_TRUE(fresh.contains(5));
  EXPECT_FALSE(fresh.contains(4));
  EXPECT_EQ(query(fresh, 0.0f), std::vector<uint32_t>{5});
  EXPECT_TRUE(query(fresh, 1.0f).empty());  // half-open: λ == max is not inside
  EXPECT_TRUE(fresh.validate());
}

TEST(IntervalTree, StaticQueriesEqualBruteForce) {
  std::mt19937 rng(7);
  for (uint32_t n : {1u, 2u, 100u, 1000u, 20000u}) {
    for (int levels : {3, 12, 200}) {
      std::vector<Interval> ivs(n);
      std::vector<std::optional<Interval>> mirror(n);
      for (uint32_t i = 0; i < n; ++i) mirror[i] = ivs[i] = randomInterval(rng, levels);
      IntervalTree tree;
      tree.build(ivs);
      expectMatches(tree, mirror, levels, "n=" + std::to_string(n) + " levels=" + std::to_string(levels));
    }
  }
}

TEST(IntervalTree, DynamicQueriesEqualBruteForce) {
  std::mt19937 rng(11);
  for (int levels : {4, 40}) {
    const uint32_t n0 = 3000;
    std::vector<Interval> ivs(n0);
    std::vector<std::optional<Interval>> mirror(n0);
    for (uint32_t i = 0; i < n0; ++i) mirror[i] = ivs[i] = randomInterval(rng, levels);
    IntervalTree tree;
    tree.build(ivs);
    for (int step = 0; step < 30000; ++step) {
      const uint32_t op = rng() % 100;
      const uint32_t count = uint32_t(mirror.size());
      if (op < 35) {  // insert new ids, sometimes skipping some
        uint32_t id = count + (rng() % 10 == 0 ? rng() % 5 : 0);
        Interval iv = randomInterval(rng, levels);
        if (rng() % 4 == 0) iv = {0.0f, 0.5f};  // a plateau of equal keys: forces splits on ties
        tree.insert(id, iv);
        mirror.resize(id + 1);
        mirror[id] = iv;
      } else if (op < 85 && count > 0) {  // update (T_moved), or reinsert a removed id
        uint32_t id = rng() % count;
        Interval iv = randomInterval(rng, levels);
        if (mirror[id])
          tree.update(id, iv);
        else
          tree.insert(id, iv);
        mirror[id] = iv;
      } else if (op < 97 && count > 0) {
        uint32_t id = rng() % count;
        tree.remove(id);
        mirror[id].reset();
      } else if (count > 0) {  // undo several splits at once
        uint32_t keep = count - std::min<uint32_t>(count, rng() % 40);
        tree.truncate(keep);
        mirror.resize(keep);
      }
      ASSERT_EQ(tree.idCount(), mirror.size());
      if (step % 1000 == 999) {
        expectMatches(tree, mirror, levels, "step " + std::to_string(step));
      } else {
        float iso = randomValue(rng, levels);
        ASSERT_EQ(query(tree, iso), bruteForce(mirror, iso)) << "step " << step << " λ=" << iso;
      }
    }
    expectMatches(tree, mirror, levels, "end");
    EXPECT_GT(tree.bucketCount(), 1u);
  }
}

TEST(IntervalTree, GrowsFromSmallBaseAndShrinksBack) {
  // The streaming pattern: a small base, then many more ids than the base had, then undo all.
  std::mt19937 rng(3);
  std::vector<std::optional<Interval>> mirror(50);
  std::vector<Interval> base(50);
  for (uint32_t i = 0; i < 50; ++i) mirror[i] = base[i] = randomInterval(rng, 64);
  IntervalTree tree;
  tree.build(base);
  for (uint32_t id = 50; id < 60000; ++id) {
    Interval iv = randomInterval(rng, 64);
    tree.insert(id, iv);
    mirror.push_back(iv);
    if (id % 7 == 0) {  // a moved tet
      uint32_t m = rng() % id;
      Interval jv = randomInterval(rng, 64);
      if (mirror[m]) tree.update(m, jv);
      mirror[m] = jv;
    }
  }
  expectMatches(tree, mirror, 64, "grown");
  const size_t bytesGrown = tree.memoryBytes();
  EXPECT_LT(bytesGrown / 60000, 40u) << "bytes per id after growth";
  std::printf("[ info     ] %.1f bytes per id after growing from 50 to 60000 ids\n", double(bytesGrown) / 60000);
  while (mirror.size() > 50) {
    uint32_t keep = uint32_t(mirror.size()) - std::min<uint32_t>(uint32_t(mirror.size()) - 50, 1 + rng() % 8);
    tree.truncate(keep);
    mirror.resize(keep);
  }
  expectMatches(tree, mirror, 64, "shrunk");
  EXPECT_LT(tree.bucketCount(), 64u) << "emptied buckets are dropped by a rebucket";
}

TEST(IntervalTree, BuildFromMeshEqualsMarchingClassification) {
  TetMesh m = makeGridMesh(9);
  addHarmonicField(m);
  const std::vector<float>& f = m.fields[0].values;
  IntervalTree tree;
  tree.build(m, f);
  ASSERT_TRUE(tree.validate());
  std::vector<float> isos = {-0.1f, 0.0f, 0.05f, 0.3f, f[100], f[200], f[364]};
  for (float iso : isos) {
    std::vector<uint32_t> expected;
    for (uint32_t t = 0; t < m.tetCount(); ++t) {
      unsigned mask = 0;
      for (int i = 0; i < 4; ++i) mask |= unsigned(f[m.tets[4 * t + i]] > iso) << i;
      if (kMarchingTets[mask].triangleCount) expected.push_back(t);
    }
    EXPECT_EQ(query(tree, iso), expected) << "λ=" << iso;
  }
}

// ------------------------------------------------------------------ benchmark (prints only)

namespace {

// The structure of the paper (§4.2, Cignoni et al.), static, as a yardstick: a balanced tree of
// the sorted distinct endpoints; each interval lives at the first node whose split value it
// contains (min <= s < max), in a list by min ascending and one by max descending.
struct CignoniTree {
  std::vector<float> split;
  std::vector<uint32_t> nodeStart;  // M + 1
  std::vector<std::pair<float, uint32_t>> byMin, byMax;

  uint32_t nodeOf(Interval iv) const {
    uint32_t lo = 0, hi = uint32_t(split.size());
    while (lo < hi) {
      uint32_t mid = (lo + hi) / 2;
      float s = split[mid];
      if (iv.max <= s)
        hi = mid;
      else if (iv.min > s)
        lo = mid + 1;
      else
        return mid;
    }
    return ~0u;
  }

  void build(std::span<const Interval> ivs) {
    split.clear();
    for (const Interval& iv : ivs)
      if (iv.min < iv.max) split.push_back(iv.min), split.push_back(iv.max);
    std::sort(split.begin(), split.end());
    split.erase(std::unique(split.begin(), split.end()), split.end());
    const size_t m = split.size();
    std::vector<uint32_t> node(ivs.size(), ~0u);
    nodeStart.assign(m + 1, 0);
    for (uint32_t i = 0; i < ivs.size(); ++i)
      if (ivs[i].min < ivs[i].max) ++nodeStart[(node[i] = nodeOf(ivs[i])) + 1];
    for (size_t k = 0; k < m; ++k) nodeStart[k + 1] += nodeStart[k];
    byMin.resize(nodeStart[m]);
    byMax.resize(nodeStart[m]);
    std::vector<uint32_t> fill(nodeStart.begin(), nodeStart.end() - 1);
    for (uint32_t i = 0; i < ivs.size(); ++i) {
      if (node[i] == ~0u) continue;
      uint32_t at = fill[node[i]]++;
      byMin[at] = {ivs[i].min, i};
      byMax[at] = {ivs[i].max, i};
    }
    for (size_t k = 0; k < m; ++k) {
      std::sort(byMin.begin() + nodeStart[k], byMin.begin() + nodeStart[k + 1],
                [](auto& a, auto& b) { return a.first < b.first; });
      std::sort(byMax.begin() + nodeStart[k], byMax.begin() + nodeStart[k + 1],
                [](auto& a, auto& b) { return a.first > b.first; });
    }
  }

  void query(float iso, std::vector<uint32_t>& out) const {
    uint32_t lo = 0, hi = uint32_t(split.size());
    while (lo < hi) {
      uint32_t mid = (lo + hi) / 2;
      if (iso < split[mid]) {
        for (uint32_t i = nodeStart[mid]; i < nodeStart[mid + 1] && byMin[i].first <= iso; ++i)
          out.push_back(byMin[i].second);
        hi = mid;
      } else {
        for (uint32_t i = nodeStart[mid]; i < nodeStart[mid + 1] && byMax[i].first > iso; ++i)
          out.push_back(byMax[i].second);
        lo = mid + 1;
      }
    }
  }
};

template <class F>
double bestMs(int reps, F&& f) {
  double best = 1e30;
  for (int r = 0; r < reps; ++r) {
    auto t0 = std::chrono::steady_clock::now();
    f();
    best = std::min(best, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  return best;
}

}  // namespace

TEST(IntervalTree, BenchmarkHarmonic64) {
  TetMesh m = makeGridMesh(64);
  addHarmonicField(m);
  const std::vector<float>& f = m.fields[0].values;
  const uint32_t n = m.tetCount();

  IntervalTree tree;
  const double buildMs = bestMs(1, [&] { tree.build(m, f); });
  std::vector<Interval> ivs(n);
  for (uint32_t t = 0; t < n; ++t) ivs[t] = tetInterval(m, f, t);
  CignoniTree cignoni;
  const double cignoniBuildMs = bestMs(1, [&] { cignoni.build(ivs); });
  std::printf(
      "[ bench    ] Harmonic n=64: %u tets, %u stored; bucketed span space: build %.1f ms, "
      "%u buckets, %.1f bytes/tet; static Cignoni tree: build %.1f ms, %zu nodes\n",
      n, tree.storedCount(), buildMs, tree.bucketCount(), double(tree.memoryBytes()) / n, cignoniBuildMs,
      cignoni.split.size());
  RecordProperty("tree_build_ms", std::to_string(buildMs));
  RecordProperty("tree_bytes_per_tet", std::to_string(double(tree.memoryBytes()) / n));

  std::vector<uint32_t> out;
  out.reserve(n);
  const Range r = computeRange(f);
  std::printf("[ bench    ] field range [%g, %g]; best of 5, ms:\n", r.min, r.max);
  std::printf("[ bench    ] %10s %8s %10s %10s %10s %10s\n", "λ", "cut", "tree", "cignoni", "scan iv", "scan mesh");
  for (float iso : {-0.2f, 0.0f, 0.02f, 0.1f, 0.3f, 0.6f, 0.9f, f[m.vertexCount() / 2 + 7]}) {
    size_t cut = 0;
    double tTree = bestMs(5, [&] {
      out.clear();
      tree.query(iso, out);
    });
    cut = out.size();
    std::vector<uint32_t> a = sorted(out);
    double tCig = bestMs(5, [&] {
      out.clear();
      cignoni.query(iso, out);
    });
    EXPECT_EQ(sorted(out), a);
    // A plain scan over precomputed intervals (8 bytes a tet, streamed).
    double tScan = bestMs(5, [&] {
      out.clear();
      for (uint32_t t = 0; t < n; ++t)
        if (stabs(ivs[t], iso)) out.push_back(t);
    });
    EXPECT_EQ(out, a);
    // What a from-scratch extraction does: classify every tet from its 4 vertex values.
    double tMesh = bestMs(5, [&] {
      out.clear();
      const uint32_t* tv = m.tets.data();
      const float* fv = f.data();
      for (uint32_t t = 0; t < n; ++t, tv += 4) {
        unsigned mask = (fv[tv[0]] > iso) | (fv[tv[1]] > iso) << 1 | (fv[tv[2]] > iso) << 2 | (fv[tv[3]] > iso) << 3;
        if (mask != 0 && mask != 15) out.push_back(t);
      }
    });
    EXPECT_EQ(out, a);
    std::printf("[ bench    ] %10g %8zu %10.3f %10.3f %10.3f %10.3f\n", iso, cut, tTree, tCig, tScan, tMesh);
    RecordProperty("query_ms_" + std::to_string(iso), std::to_string(tTree));
    RecordProperty("scan_ms_" + std::to_string(iso), std::to_string(tScan));
  }

  // Update cost: moving one tet's interval (remove + insert), as a split's T_moved does.
  std::mt19937 rng(5);
  const int updates = 200000;
  std::vector<std::pair<uint32_t, Interval>> moves(updates);
  for (auto& [id, iv] : moves) {
    id = rng() % n;
    iv = ivs[id];
    float d = (float(rng() % 1000) / 1000.0f - 0.5f) * 0.02f;
    (rng() & 1 ? iv.min : iv.max) += d;
    if (iv.min > iv.max) std::swap(iv.min, iv.max);
  }
  double tUpd = bestMs(1, [&] {
    for (auto& [id, iv] : moves) tree.update(id, iv);
  });
  const uint32_t inserts = 100000;
  double tIns = bestMs(1, [&] {
    for (uint32_t k = 0; k < inserts; ++k) tree.insert(n + k, moves[k].second);
  });
  std::printf(
      "[ bench    ] updates: %.3f us each (%d); inserts of new ids: %.3f us each; %u buckets, %.1f bytes/tet after\n",
      1000.0 * tUpd / updates, updates, 1000.0 * tIns / inserts, tree.bucketCount(),
      double(tree.memoryBytes()) / (n + inserts));
  RecordProperty("update_us", std::to_string(1000.0 * tUpd / updates));
  EXPECT_TRUE(tree.validate());
}
