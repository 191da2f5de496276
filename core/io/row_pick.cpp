#include "io/row_pick.h"

#include <bit>

namespace tetstream::io {

UsedRows::UsedRows(uint64_t first, uint64_t count)
    : first_(first), count_(count), bits_(size_t((count + 63) / 64), 0) {}

void UsedRows::finish() {
  before_.resize(bits_.size());
  used_ = 0;
  for (size_t w = 0; w < bits_.size(); ++w) {
    before_[w] = used_;
    used_ += uint64_t(std::popcount(bits_[w]));
  }
}

uint64_t UsedRows::place(uint64_t id) const {
  const uint64_t k = id - first_;
  if (all()) return k;
  return before_[k / 64] + uint64_t(std::popcount(bits_[k / 64] & ((uint64_t(1) << (k % 64)) - 1)));
}

std::vector<uint64_t> UsedRows::rows() const {
  std::vector<uint64_t> out;
  out.reserve(size_t(used_));
  for (size_t w = 0; w < bits_.size(); ++w)
    for (uint64_t b = bits_[w]; b; b &= b - 1) out.push_back(first_ + 64 * w + uint64_t(std::countr_zero(b)));
  return out;
}

std::vector<uint64_t> pickUsedRows(std::vector<int64_t>& ids, uint64_t first, uint64_t count) {
  UsedRows used(first, count);
  for (int64_t id : ids) used.mark(uint64_t(id));
  used.finish();
  if (used.all()) {
    for (int64_t& id : ids) id -= int64_t(first);
    return {};
  }
  for (int64_t& id : ids) id = int64_t(used.place(uint64_t(id)));
  return used.rows();
}

}  // namespace tetstream::io
