#include "interval_tree.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstring>
#include <limits>

namespace tetstream {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr Interval kAbsent = {kInf, -kInf};
// Slabs are built this full, so that a few splits around a bucket do not move its slab at once.
constexpr uint32_t kBuildFill = IntervalTree::kBucketMax / 2;
constexpr uint32_t kMinSlab = 8;

// Maps floats (no NaN) to uint32 so that unsigned order is float order; -0 is canonicalised
// to +0 before, so equal floats give equal keys.
uint32_t orderedBits(float f) {
  uint32_t b;
  std::memcpy(&b, &f, 4);  // not std::bit_cast: Emscripten's libc++ (clang 14) lacks it
  return (b & 0x80000000u) ? ~b : b | 0x80000000u;
}
// Total order on stored intervals: by min, ties broken by id, so every key is unique and a
// bucket split always halves the bucket, even on a plateau of equal minima.
uint64_t makeKey(float min, uint32_t id) { return uint64_t(orderedBits(min)) << 32 | id; }

Interval canonical(Interval iv) { return {iv.min + 0.0f, iv.max + 0.0f}; }  // -0 -> +0
bool isStored(Interval iv) { return iv.min < iv.max; }
uint32_t slabFor(uint32_t count) { return std::max(kMinSlab, count + count / 4); }

}  // namespace

Interval tetInterval(const TetMesh& mesh, std::span<const float> field, uint32_t t) {
  assert(t < mesh.tetCount());
  const uint32_t* v = &mesh.tets[4 * size_t(t)];
  Interval iv = {kInf, -kInf};
  for (int i = 0; i < 4; ++i) {
    assert(v[i] < field.size());
    float s = field[v[i]];
    if (std::isnan(s)) s = -kInf;  // never above λ (tet_tables.h): behaves like -inf
    iv.min = std::min(iv.min, s);
    iv.max = std::max(iv.max, s);
  }
  return iv;
}

// ------------------------------------------------------------------ build

void IntervalTree::clear() {
  intervals_.clear();
  stored_ = 0;
  resetBuckets();
}

void IntervalTree::resetBuckets() {
  buckets_.assign(1, Bucket{-kInf, -kInf, 0, 0});
  loKey_.assign(1, 0);
  cap_.assign(1, 0);
  arena_.clear();
  deadEntries_ = 0;
}

void IntervalTree::build(std::span<const Interval> intervals) {
  intervals_.resize(intervals.size());
  for (size_t i = 0; i < intervals.size(); ++i) {
    Interval iv = canonical(intervals[i]);
    assert(!std::isnan(iv.min) && !std::isnan(iv.max) && iv.min <= iv.max);
    intervals_[i] = iv;
  }
  rebucket();
}

void IntervalTree::build(const TetMesh& mesh, std::span<const float> field) {
  assert(field.size() == mesh.vertexCount());
  const uint32_t n = mesh.tetCount();
  intervals_.resize(n);
  for (uint32_t t = 0; t < n; ++t) intervals_[t] = canonical(tetInterval(mesh, field, t));
  rebucket();
}

// Rebuilds the buckets from intervals_: sort by key, cut into buckets of kBuildFill.
void IntervalTree::rebucket() {
  scratchKeys_.clear();
  for (uint32_t i = 0; i < intervals_.size(); ++i)
    if (isStored(intervals_[i])) scratchKeys_.push_back(makeKey(intervals_[i].min, i));
  std::sort(scratchKeys_.begin(), scratchKeys_.end());
  const size_t n = scratchKeys_.size();
  stored_ = uint32_t(n);
  const size_t nb = std::max<size_t>(1, (n + kBuildFill - 1) / kBuildFill);
  buckets_.resize(nb);
  loKey_.resize(nb);
  cap_.resize(nb);
  // Bucket b holds sorted keys [first(b), first(b + 1)); 64-bit products (size_t is 32 bits in wasm).
  auto first = [&](size_t b) { return size_t(uint64_t(b) * n / nb); };
  size_t total = 0;
  for (size_t b = 0; b < nb; ++b) {
    size_t lo = first(b), hi = first(b + 1);
    cap_[b] = slabFor(uint32_t(hi - lo));
    buckets_[b].start = uint32_t(total);
    buckets_[b].count = uint32_t(hi - lo);
    total += cap_[b];
  }
  arena_.resize(total);
  deadEntries_ = 0;
  for (size_t b = 0; b < nb; ++b) {
    Bucket& k = buckets_[b];
    size_t lo = first(b);
    loKey_[b] = b == 0 ? 0 : scratchKeys_[lo];
    k.loMin = b == 0 ? -kInf : intervals_[uint32_t(scratchKeys_[lo])].min;
    Entry* e = arena_.data() + k.start;
    for (uint32_t i = 0; i < k.count; ++i) {
      uint32_t id = uint32_t(scratchKeys_[lo + i]);
      e[i] = {intervals_[id].max, id};
    }
    std::sort(e, e + k.count, [](const Entry& a, const Entry& c) { return a.max > c.max; });
    k.topMax = k.count ? e[0].max : -kInf;
  }
  // 8 bytes a tet that only a build needs; a split needs kBucketMax of them.
  scratchKeys_.clear();
  scratchKeys_.shrink_to_fit();
}

// ------------------------------------------------------------------ updates

void IntervalTree::insert(uint32_t id, Interval iv) {
  assert(!contains(id));
  assert(!std::isnan(iv.min) && !std::isnan(iv.max) && iv.min <= iv.max);
  set(id, iv);
}

void IntervalTree::update(uint32_t id, Interval iv) {
  assert(contains(id));
  assert(!std::isnan(iv.min) && !std::isnan(iv.max) && iv.min <= iv.max);
  set(id, iv);
}

void IntervalTree::remove(uint32_t id) {
  if (!contains(id)) return;
  set(id, kAbsent);
  maybeRebucket();
}

void IntervalTree::truncate(uint32_t idCount) {
  if (idCount >= intervals_.size()) return;
  for (uint32_t id = idCount; id < intervals_.size(); ++id)
    if (isStored(intervals_[id])) bucketRemove(intervals_[id], id);
  intervals_.resize(idCount);
  maybeRebucket();
}

void IntervalTree::set(uint32_t id, Interval iv) {
  if (buckets_.empty()) resetBuckets();
  iv = canonical(iv);
  if (id >= intervals_.size()) intervals_.resize(size_t(id) + 1, kAbsent);
  Interval old = intervals_[id];
  if (old.min == iv.min && old.max == iv.max) return;
  if (isStored(old)) bucketRemove(old, id);
  intervals_[id] = iv;
  if (isStored(iv)) bucketInsert(iv, id);
}

// Removals never merge buckets; when most buckets have gone empty (a long undo) the query's
// header walk would dominate, so start over from the intervals.
void IntervalTree::maybeRebucket() {
  if (buckets_.size() > 64 && size_t(stored_) * 8 < buckets_.size() * kBuildFill) rebucket();
}

uint32_t IntervalTree::findBucket(uint64_t key) const {
  // Last bucket whose lower key is <= key; loKey_[0] == 0 so there always is one.
  return uint32_t(std::upper_bound(loKey_.begin(), loKey_.end(), key) - loKey_.begin() - 1);
}

// A new slab at the arena's end. Bucket starts may change (compaction): callers re-read them.
uint32_t IntervalTree::allocSlab(uint32_t cap) {
  if (arena_.size() + cap > arena_.capacity()) {
    // Reuse dead space before growing; grow by 1/4, not 2x: memory counts more in wasm than
    // the amortised copy.
    if (8 * deadEntries_ > arena_.size()) compactArena();
    if (arena_.size() + cap > arena_.capacity())
      arena_.reserve(std::max(arena_.size() + cap, arena_.capacity() + arena_.capacity() / 4));
  }
  size_t start = arena_.size();
  assert(start + cap <= std::numeric_limits<uint32_t>::max());
  arena_.resize(start + cap);
  return uint32_t(start);
}

void IntervalTree::bucketInsert(Interval iv, uint32_t id) {
  const uint64_t key = makeKey(iv.min, id);
  uint32_t b = findBucket(key);
  if (buckets_[b].count == kBucketMax) {
    splitBucket(b);
    b = findBucket(key);
  }
  if (buckets_[b].count == cap_[b]) {
    // Slab full: move it to the arena's end with twice the room; the old slab goes dead.
    uint32_t cap = std::min(kBucketMax, std::max(kMinSlab, 2 * cap_[b]));
    uint32_t start = allocSlab(cap);
    Bucket& k = buckets_[b];
    std::memcpy(arena_.data() + start, arena_.data() + k.start, k.count * sizeof(Entry));
    deadEntries_ += cap_[b];
    k.start = start;
    cap_[b] = cap;
    if (deadEntries_ > 4096 && 4 * deadEntries_ > arena_.size()) compactArena();
  }
  Bucket& k = buckets_[b];
  Entry* e = arena_.data() + k.start;
  // After the entries with an equal max, so equal runs stay in insertion order.
  uint32_t pos = uint32_t(std::partition_point(e, e + k.count, [&](const Entry& x) { return x.max >= iv.max; }) - e);
  std::memmove(e + pos + 1, e + pos, (k.count - pos) * sizeof(Entry));
  e[pos] = {iv.max, id};
  ++k.count;
  if (pos == 0) k.topMax = iv.max;
  ++stored_;
}

void IntervalTree::bucketRemove(Interval iv, uint32_t id) {
  const uint32_t b = findBucket(makeKey(iv.min, id));
  Bucket& k = buckets_[b];
  Entry* e = arena_.data() + k.start;
  uint32_t pos = uint32_t(std::partition_point(e, e + k.count, [&](const Entry& x) { return x.max > iv.max; }) - e);
  while (pos < k.count && e[pos].id != id) {
    assert(e[pos].max == iv.max);
    ++pos;
  }
  assert(pos < k.count && "interval not in its bucket");
  if (pos >= k.count) return;
  std::memmove(e + pos, e + pos + 1, (k.count - pos - 1) * sizeof(Entry));
  --k.count;
  if (pos == 0) k.topMax = k.count ? e[0].max : -kInf;
  --stored_;
}

// Splits a full bucket at its median key: the lower half stays in the slab (keeping its room),
// the upper half gets a new slab and a new header right after.
void IntervalTree::splitBucket(uint32_t b) {
  const Bucket k = buckets_[b];
  Entry* e = arena_.data() + k.start;
  scratchKeys_.resize(k.count);
  for (uint32_t i = 0; i < k.count; ++i) scratchKeys_[i] = makeKey(intervals_[e[i].id].min, e[i].id);
  auto mid = scratchKeys_.begin() + k.count / 2;
  std::nth_element(scratchKeys_.begin(), mid, scratchKeys_.end());
  const uint64_t median = *mid;
  // Stable partition keeps both halves sorted by max descending.
  scratchEntries_.clear();
  uint32_t left = 0;
  for (uint32_t i = 0; i < k.count; ++i) {
    if (makeKey(intervals_[e[i].id].min, e[i].id) < median)
      e[left++] = e[i];
    else
      scratchEntries_.push_back(e[i]);
  }
  const uint32_t right = uint32_t(scratchEntries_.size());
  buckets_[b].count = left;
  buckets_[b].topMax = left ? e[0].max : -kInf;
  const uint32_t cap = slabFor(right);
  const uint32_t start = allocSlab(cap);  // invalidates e
  std::memcpy(arena_.data() + start, scratchEntries_.data(), right * sizeof(Entry));
  buckets_.insert(buckets_.begin() + b + 1,
                  Bucket{intervals_[uint32_t(median)].min, right ? scratchEntries_[0].max : -kInf, start, right});
  loKey_.insert(loKey_.begin() + b + 1, median);
  cap_.insert(cap_.begin() + b + 1, cap);
}

// Slides every slab down over the dead gaps, in arena order (so a move never overwrites a slab
// not yet moved).
void IntervalTree::compactArena() {
  scratchOrder_.resize(buckets_.size());
  for (uint32_t b = 0; b < buckets_.size(); ++b) scratchOrder_[b] = b;
  std::sort(scratchOrder_.begin(), scratchOrder_.end(),
            [&](uint32_t a, uint32_t c) { return buckets_[a].start < buckets_[c].start; });
  uint32_t write = 0;
  for (uint32_t b : scratchOrder_) {
    Bucket& k = buckets_[b];
    if (k.start != write) std::memmove(arena_.data() + write, arena_.data() + k.start, k.count * sizeof(Entry));
    k.start = write;
    write += cap_[b];
  }
  arena_.resize(write);
  deadEntries_ = 0;
}

// ------------------------------------------------------------------ query

void IntervalTree::query(float isovalue, std::vector<uint32_t>& out) const {
  const float iso = isovalue;
  const size_t nb = buckets_.size();
  const Bucket* bk = buckets_.data();
  const Entry* arena = arena_.data();
  for (size_t b = 0; b < nb; ++b) {
    const Bucket& k = bk[b];
    if (k.loMin > iso) break;         // this and all later buckets: every min > λ
    if (!(k.topMax > iso)) continue;  // every max <= λ (also: empty bucket, NaN λ)
    const Entry* e = arena + k.start;
    const uint32_t n = k.count;
    if (b + 1 < nb && bk[b + 1].loMin <= iso) {
      // Every key is below the next bucket's lower key, so every min <= λ.
      for (uint32_t i = 0; i < n && e[i].max > iso; ++i) out.push_back(e[i].id);
    } else {
      // The bucket straddling λ: min decides per entry.
      for (uint32_t i = 0; i < n && e[i].max > iso; ++i)
        if (intervals_[e[i].id].min <= iso) out.push_back(e[i].id);
    }
  }
}

// ------------------------------------------------------------------ introspection

size_t IntervalTree::memoryBytes() const {
  return intervals_.capacity() * sizeof(Interval) + buckets_.capacity() * sizeof(Bucket) +
         loKey_.capacity() * sizeof(uint64_t) + cap_.capacity() * sizeof(uint32_t) + arena_.capacity() * sizeof(Entry) +
         scratchKeys_.capacity() * sizeof(uint64_t) + scratchEntries_.capacity() * sizeof(Entry) +
         scratchOrder_.capacity() * sizeof(uint32_t);
}

bool IntervalTree::validate() const {
  if (buckets_.empty()) return intervals_.empty() || stored_ == 0;
  if (loKey_.size() != buckets_.size() || cap_.size() != buckets_.size() || loKey_[0] != 0) return false;
  size_t total = 0, capSum = 0;
  std::vector<std::pair<uint32_t, uint32_t>> slabs;
  for (size_t b = 0; b < buckets_.size(); ++b) {
    const Bucket& k = buckets_[b];
    if (b > 0 && !(loKey_[b - 1] < loKey_[b])) return false;
    // The boundary key may belong to an id that has moved since; its min is in the key.
    if (b > 0 && orderedBits(k.loMin) != uint32_t(loKey_[b] >> 32)) return false;
    if (k.count > cap_[b] || k.count > kBucketMax || size_t(k.start) + cap_[b] > arena_.size()) return false;
    const Entry* e = arena_.data() + k.start;  // no &arena_[k.start]: start may be the end (UB)
    if (k.topMax != (k.count ? e[0].max : -kInf)) return false;
    for (uint32_t i = 0; i < k.count; ++i) {
      if (i > 0 && e[i - 1].max < e[i].max) return false;
      if (e[i].id >= intervals_.size()) return false;
      Interval iv = intervals_[e[i].id];
      if (!isStored(iv) || iv.max != e[i].max) return false;
      uint64_t key = makeKey(iv.min, e[i].id);
      if (key < loKey_[b] || (b + 1 < buckets_.size() && key >= loKey_[b + 1])) return false;
    }
    total += k.count;
    capSum += cap_[b];
    if (cap_[b]) slabs.push_back({k.start, cap_[b]});
  }
  std::sort(slabs.begin(), slabs.end());
  for (size_t i = 1; i < slabs.size(); ++i)
    if (slabs[i - 1].first + slabs[i - 1].second > slabs[i].first) return false;
  size_t storedNow = 0;
  for (const Interval& iv : intervals_) storedNow += isStored(iv);
  return total == stored_ && storedNow == stored_ && capSum + deadEntries_ == arena_.size();
}

}  // namespace tetstream
