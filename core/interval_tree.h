// Index of tetrahedra by scalar interval, for finding the tets an isosurface cuts (paper §4.2)
// without testing every tet, and kept up to date while vertex splits add and change tets (§4.3).
//
// Which tets are returned. A tet's interval is [min, max) of the field at its 4 vertices, and a
// query at λ returns the tets with  min <= λ < max  ("λ stabs the interval"). Under the
// classification rule of tet_tables.h (bit set when s > λ, a value equal to λ counts as below)
// that is exactly the set of tets whose marching case is neither 0 (all at or below) nor 15 (all
// above), so the query misses no tet that yields triangles. It may return a tet whose triangles
// all degenerate to a repeated surface vertex (two or more corners exactly on λ); the extractor
// still creates those surface vertices, so it must visit such tets anyway. A NaN field value is
// never above λ, so tetInterval() maps it to -inf: the rule stays exact for NaN and ±inf values,
// and a NaN isovalue stabs nothing (marching tets finds nothing either). Intervals with
// min == max are stabbed by no λ and are kept out of the buckets (only their interval is stored).
//
// Design: a bucketed span space (a one-level, flattened interval tree). Intervals are ordered by
// the key (min, id); the key range is cut into buckets of at most kBucketMax intervals, and each
// bucket holds its intervals in one slab of a shared arena, sorted by max descending. A query
// walks the bucket headers in min order: a bucket whose keys are all <= λ contributes the prefix
// of its slab with max > λ (every entry read is output, plus one); the single bucket that
// straddles λ tests min per entry; the walk stops at the first bucket with min > λ. The header
// caches the bucket's largest max, so buckets with nothing to give are skipped without touching
// the arena. Compared with Cignoni et al.'s interval tree (whose node lists are unbounded: the
// root alone holds every interval containing the median) the bounded buckets make insert and
// remove a binary search plus a memmove of at most kBucketMax entries, with no lazily merged
// pending lists; tests/unit/test_interval_tree.cpp measures both.
//
// Complexity (N stored intervals, k returned, B buckets: B = N/(kBucketMax/2) after a build,
// at least N/kBucketMax at any time, more only when removals empty buckets):
//   build         O(N log N)
//   query         O(B + k + kBucketMax): B sequential 16-byte header reads; no allocation once
//                 the caller's vector has capacity.
//   insert/update/remove  O(log B + kBucketMax): binary search on the bucket keys, memmove in
//                 the slab. A full bucket splits at its median key (O(kBucketMax + B), once per
//                 >= kBucketMax/2 inserts into it); a full slab moves to the arena's end; the arena
//                 is compacted in place when a quarter of it is dead, or an eighth before it
//                 would grow (amortised O(1) per operation). When removals leave the buckets on
//                 average 1/8 full the buckets are rebuilt (amortised over those removals).
// Memory: 8 bytes per id (its interval) + 8 bytes per stored interval in a slab with slack
// (built 80% full) + dead arena up to a quarter + 28 bytes per bucket. memoryBytes() reports
// the actual figure. A query costs in proportion to the cut tets it returns, an order of
// magnitude below a scan of every tet's interval; an update of one tet's interval is about a
// microsecond. Figures: docs/design-notes.md.
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include "mesh.h"

namespace tetstream {

struct Interval {
  float min = 0, max = 0;
};

// Whether the isovalue stabs the interval: min <= λ < max (see above).
inline bool stabs(Interval iv, float isovalue) { return iv.min <= isovalue && isovalue < iv.max; }

// Interval of tet t over `field` (one value per mesh vertex), with NaN values taken as -inf.
// stabs(tetInterval(...), λ) is true exactly when marching tets classifies the tet into a case
// with triangles.
Interval tetInterval(const TetMesh& mesh, std::span<const float> field, uint32_t t);

class IntervalTree {
 public:
  // Largest number of intervals per bucket; see the complexity note above.
  static constexpr uint32_t kBucketMax = 256;

  // Ids 0 .. intervals.size()-1 get intervals[i]; every old id is forgotten.
  // Preconditions (asserted): no NaN, min <= max.
  void build(std::span<const Interval> intervals);
  // Ids are tet ids: interval of every tet of `mesh` over `field` (tetInterval).
  void build(const TetMesh& mesh, std::span<const float> field);
  // Forgets everything, keeps the memory.
  void clear();
  // Room for ids 0 .. ids-1 without growing the per-id array.
  void reserve(uint32_t ids) { intervals_.reserve(ids); }

  // A new id (T_new). id may be >= idCount() (the id space grows; ids skipped over are absent)
  // or an id that was removed. Precondition (asserted): id is absent, iv as for build().
  void insert(uint32_t id, Interval iv);
  // A present id's interval changed (T_moved). No work when it did not change.
  void update(uint32_t id, Interval iv);
  // Forgets id (undoing a split); no-op when it is absent.
  void remove(uint32_t id);
  // Removes every id >= idCount and shrinks the id space to idCount (undo shrinks the mesh).
  void truncate(uint32_t idCount);

  // Appends to `out` every present id whose interval λ stabs, in no particular order.
  void query(float isovalue, std::vector<uint32_t>& out) const;

  // One more than the largest id the tree knows of (present or absent).
  uint32_t idCount() const { return uint32_t(intervals_.size()); }
  bool contains(uint32_t id) const { return id < idCount() && !isAbsent(intervals_[id]); }
  // Interval of a present id.
  Interval interval(uint32_t id) const { return intervals_[id]; }
  // Number of stored (stabbable, min < max) intervals.
  uint32_t storedCount() const { return stored_; }
  uint32_t bucketCount() const { return uint32_t(buckets_.size()); }
  // Heap bytes in use (vector capacities).
  size_t memoryBytes() const;
  // Checks every internal invariant (tests); false when one is broken.
  bool validate() const;

 private:
  struct Entry {
    float max;
    uint32_t id;
  };
  // Header read by queries; loKey_/cap_ are only needed by updates, kept apart.
  struct Bucket {
    float loMin;   // min of the smallest key the bucket may hold (-inf for bucket 0)
    float topMax;  // largest max in the bucket, -inf when empty
    uint32_t start, count;
  };

  static bool isAbsent(Interval iv) { return iv.min > iv.max; }
  void set(uint32_t id, Interval iv);
  uint32_t findBucket(uint64_t key) const;
  void bucketInsert(Interval iv, uint32_t id);
  void bucketRemove(Interval iv, uint32_t id);
  void splitBucket(uint32_t b);
  uint32_t allocSlab(uint32_t cap);
  void compactArena();
  void resetBuckets();
  void rebucket();
  void maybeRebucket();

  std::vector<Interval> intervals_;  // per id; absent ids hold {+inf, -inf}
  std::vector<Bucket> buckets_;      // in key order; never empty once used
  std::vector<uint64_t> loKey_;      // per bucket: smallest (orderedMin << 32 | id) it may hold
  std::vector<uint32_t> cap_;        // per bucket: slab capacity
  std::vector<Entry> arena_;         // the slabs, with dead gaps
  size_t deadEntries_ = 0;           // arena entries in no slab
  uint32_t stored_ = 0;
  std::vector<uint64_t> scratchKeys_;   // build, split
  std::vector<Entry> scratchEntries_;   // split
  std::vector<uint32_t> scratchOrder_;  // compaction
};

}  // namespace tetstream
