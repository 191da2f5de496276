// Open-addressing hash map from a 64-bit key to a uint32 value: the surface vertex of a cut
// edge in both isosurface extractors, the crease line of a boundary edge in the viewer's hull.
// Flat arrays, linear probing, capacity a power of two and at most half full; erase shifts later
// members of the probe run back (no tombstones). clear() keeps the capacity, so a long-lived
// extractor does not reallocate.
#pragma once
#include <algorithm>
#include <cassert>
#include <cstdint>
#include <span>
#include <vector>

#include "hash.h"

namespace tetstream {

class FlatMap {
 public:
  static constexpr uint64_t kEmpty = ~uint64_t(0);  // never a key
  static constexpr uint32_t kNone = ~uint32_t(0);   // find(): absent

  void clear() {
    if (size_ != 0) std::fill(keys_.begin(), keys_.end(), kEmpty);
    size_ = 0;
  }
  void reserve(size_t n) {
    size_t cap = 16;
    while (cap < 2 * n) cap *= 2;
    if (cap > keys_.size()) rehash(cap);
  }
  size_t size() const { return size_; }
  size_t memoryBytes() const { return keys_.capacity() * 8 + values_.capacity() * 4; }

  // The value stored for key, or kNone when absent.
  uint32_t find(uint64_t key) const {
    if (keys_.empty()) return kNone;
    const size_t mask = keys_.size() - 1;
    for (size_t i = hash64(key) & mask;; i = (i + 1) & mask) {
      if (keys_[i] == key) return values_[i];
      if (keys_[i] == kEmpty) return kNone;
    }
  }

  // The value stored for key; when absent, stores `value` first. *inserted tells which.
  uint32_t findOrInsert(uint64_t key, uint32_t value, bool* inserted) {
    assert(key != kEmpty);
    if (2 * (size_ + 1) > keys_.size()) rehash(keys_.empty() ? 1024 : 2 * keys_.size());
    const size_t mask = keys_.size() - 1;
    for (size_t i = hash64(key) & mask;; i = (i + 1) & mask) {
      if (keys_[i] == key) {
        *inserted = false;
        return values_[i];
      }
      if (keys_[i] == kEmpty) {
        keys_[i] = key;
        values_[i] = value;
        ++size_;
        *inserted = true;
        return value;
      }
    }
  }

  // Precondition (asserted): key present.
  void erase(uint64_t key) {
    assert(!keys_.empty());
    const size_t mask = keys_.size() - 1;
    size_t i = hash64(key) & mask;
    while (keys_[i] != key) {
      assert(keys_[i] != kEmpty);
      i = (i + 1) & mask;
    }
    // Backward shift: move later members of the probe run into the hole unless their home slot
    // lies cyclically in (hole, j], where they must stay reachable.
    for (size_t j = i;;) {
      j = (j + 1) & mask;
      if (keys_[j] == kEmpty) break;
      const size_t h = hash64(keys_[j]) & mask;
      const bool stays = i <= j ? (i < h && h <= j) : (i < h || h <= j);
      if (stays) continue;
      keys_[i] = keys_[j];
      values_[i] = values_[j];
      i = j;
    }
    keys_[i] = kEmpty;
    --size_;
  }

  // Rewrites every value v as remap[v] (compaction).
  void remapValues(std::span<const uint32_t> remap) {
    for (size_t i = 0; i < keys_.size(); ++i)
      if (keys_[i] != kEmpty) values_[i] = remap[values_[i]];
  }

 private:
  void rehash(size_t cap) {
    std::vector<uint64_t> oldKeys(cap, kEmpty);
    std::vector<uint32_t> oldValues(cap);
    oldKeys.swap(keys_);
    oldValues.swap(values_);
    size_ = 0;
    bool inserted;
    for (size_t i = 0; i < oldKeys.size(); ++i)
      if (oldKeys[i] != kEmpty) findOrInsert(oldKeys[i], oldValues[i], &inserted);
  }

  std::vector<uint64_t> keys_;
  std::vector<uint32_t> values_;
  size_t size_ = 0;
};

}  // namespace tetstream
