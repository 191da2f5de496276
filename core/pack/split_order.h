// The order of the splits inside one chunk with pack --compact (FORMAT.md §4). In cost order
// the kept vertices of consecutive splits lie anywhere in the mesh, and naming p_j takes ~16 bits
// a split, a large share of the stream. Inside a chunk the splits can go in another order
// that keeps each one's effect: a split comes after every earlier one (in cost order) that writes
// a tet it reads or writes, and after every earlier one that reads a tet it writes. Splits are
// put in waves, each one wave past everything it must follow; the splits of a wave touch nothing
// another of the wave writes, so within a wave they go by p_j's stream id, ascending, and the
// kept-vertex deltas are small. The mesh at the chunk's end is the same as in cost order (up to
// the numbering of the vertices and tets created inside the chunk), and every split meets
// exactly the neighbourhood it met in cost order, so every prefix is still a valid mesh.
//
// A split reads the tets around p_j before it (CollapseLog::star, recorded with
// SimplifyOptions::recordReadSets) and writes T_moved and the tets it creates
// (CollapseLog::moved, removed), all named by their original ids.
#pragma once
#include <algorithm>
#include <cstdint>
#include <vector>

#include "pack/simplify.h"

namespace tetstream {

class SplitOrder {
 public:
  explicit SplitOrder(uint32_t tets) : state_(tets) {}

  // Waves for splits first .. first + count − 1 of the stream (split s undoes collapse
  // log.size() − 1 − s).
  void plan(const CollapseLog& log, uint32_t first, uint32_t count);

  // Calls emit(s) for every planned split, wave by wave; within a wave by key(s), the stream id of
  // its p_j, asked once the waves before are emitted (p_j exists by then: the split that creates
  // it writes the tets around it, so it is in an earlier wave).
  template <class Key, class Emit>
  void run(Key key, Emit emit) {
    for (uint32_t w = 0; w + 1 < waveStart_.size(); ++w) {
      wave_.clear();
      for (uint32_t n = waveStart_[w]; n < waveStart_[w + 1]; ++n)
        wave_.push_back(uint64_t(key(first_ + byWave_[n])) << 32 | byWave_[n]);
      std::sort(wave_.begin(), wave_.end());
      for (uint64_t x : wave_) emit(first_ + uint32_t(x));
    }
  }

  uint32_t waves() const { return uint32_t(waveStart_.size()) - 1; }

 private:
  struct TetState {
    uint32_t stamp = 0;    // plan() call that last touched this tet (0: never)
    uint32_t written = 0;  // the wave of its last writer in that chunk (0: none)
    uint32_t read = 0;     // the latest wave that read it
  };
  std::vector<TetState> state_;
  CollapseTets tets_;                                         // of the collapse being planned
  std::vector<uint32_t> waveOf_, waveStart_, byWave_, next_;  // per split; splits grouped by wave
  std::vector<uint64_t> wave_;
  uint32_t first_ = 0, stamp_ = 0;
};

}  // namespace tetstream
