#include "pack/split_order.h"

#include <algorithm>

namespace tetstream {

void SplitOrder::plan(const CollapseLog& log, uint32_t first, uint32_t count) {
  first_ = first;
  ++stamp_;
  const uint32_t C = log.size();
  waveOf_.resize(count);
  uint32_t waves = 0;
  auto at = [&](uint32_t t) -> TetState& {
    TetState& s = state_[t];
    if (s.stamp != stamp_) s = {stamp_, 0, 0};
    return s;
  };
  for (uint32_t k = 0; k < count; ++k) {
    const uint32_t c = C - 1 - (first + k);
    log.readTets(c, tets_);
    const uint32_t s0 = log.starBegin[c], s1 = log.starBegin[c + 1];
    // After the last writer of every tet it reads, after every writer and reader of a tet it writes.
    uint32_t after = 0;
    for (uint32_t e = s0; e < s1; ++e) after = std::max(after, at(log.star[e]).written);
    auto writes = [&](uint32_t t) {
      const TetState& s = at(t);
      after = std::max({after, s.written, s.read});
    };
    for (uint32_t t : tets_.moved) writes(t);
    for (uint32_t t : tets_.removed) writes(t);
    const uint32_t wave = after + 1;
    for (uint32_t e = s0; e < s1; ++e) state_[log.star[e]].read = std::max(state_[log.star[e]].read, wave);
    for (uint32_t t : tets_.moved) state_[t].written = wave;
    for (uint32_t t : tets_.removed) state_[t].written = wave;
    waveOf_[k] = wave;
    waves = std::max(waves, wave);
  }
  // The splits grouped by wave, in cost order within each (a counting sort).
  waveStart_.assign(waves + 1, 0);
  for (uint32_t k = 0; k < count; ++k) ++waveStart_[waveOf_[k]];  // (waves count from 1)
  for (uint32_t w = 1; w <= waves; ++w) waveStart_[w] += waveStart_[w - 1];
  byWave_.resize(count);
  next_.assign(waveStart_.begin(), waveStart_.end() - 1);
  for (uint32_t k = 0; k < count; ++k) byWave_[next_[waveOf_[k] - 1]++] = k;
}

}  // namespace tetstream
