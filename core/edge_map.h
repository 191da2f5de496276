// Open-addressing hash map from a 64-bit key to a uint32 value, for sharing isosurface vertices
// between the tetrahedra around a cut mesh edge. Flat arrays, linear probing, grows by doubling;
// clear() keeps the capacity so a long-lived extractor does not reallocate.
#pragma once
#include <cstdint>
#include <vector>

namespace tetstream {

class EdgeMap {
 public:
  static constexpr uint64_t kEmpty = ~uint64_t(0);

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

  // Returns a pointer to the value for key, inserting `value` if the key is new.
  // *inserted tells which happened.
  uint32_t findOrInsert(uint64_t key, uint32_t value, bool* inserted) {
    if (2 * (size_ + 1) > keys_.size()) rehash(keys_.empty() ? 1024 : 2 * keys_.size());
    size_t mask = keys_.size() - 1;
    for (size_t i = hash(key) & mask;; i = (i + 1) & mask) {
      if (keys_[i] == key) { *inserted = false; return values_[i]; }
      if (keys_[i] == kEmpty) {
        keys_[i] = key;
        values_[i] = value;
        ++size_;
        *inserted = true;
        return value;
      }
    }
  }

 private:
  static uint64_t hash(uint64_t x) {  // splitmix64 finaliser
    x ^= x >> 30; x *= 0xbf58476d1ce4e5b9ull;
    x ^= x >> 27; x *= 0x94d049bb133111ebull;
    return x ^ (x >> 31);
  }
  void rehash(size_t cap) {
    std::vector<uint64_t> oldKeys(cap, kEmpty);
    std::vector<uint32_t> oldValues(cap);
    oldKeys.swap(keys_);
    oldValues.swap(values_);
    size_ = 0;
    for (size_t i = 0; i < oldKeys.size(); ++i) {
      if (oldKeys[i] == kEmpty) continue;
      bool ins;
      findOrInsert(oldKeys[i], oldValues[i], &ins);
    }
  }

  std::vector<uint64_t> keys_;
  std::vector<uint32_t> values_;
  size_t size_ = 0;
};

}  // namespace tetstream
