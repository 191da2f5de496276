// The simplifier's record of its collapses, which the encoder replays backwards as vertex splits.
//
// What a collapse did to the tets (which it removed, which moved from i to j) is most of the
// record: about 20 tets a collapse. As plain uint32 lists that is a sixth of the packer's peak
// memory; coded as varints (tet ids as differences, sorted where the order does not matter,
// vertices relative to j) it takes about half. The encoder and split_order.h read it one collapse at a time (readTets).
#pragma once
#include <cstdint>
#include <vector>

namespace tetstream {

// What one collapse hec(i → j) did to the tets, in original vertex and tet ids.
struct CollapseTets {
  std::vector<uint32_t> moved;    // tets whose i slot became j (ascending once read back)
  std::vector<uint32_t> removed;  // tets removed, in the order the collapse removed them
  std::vector<uint32_t> others;   // 2 per removed tet: its vertices besides i and j, ordered so
                                  // that (i, j, a, b) has the tet's orientation
  void clear() {
    moved.clear();
    removed.clear();
    others.clear();
  }
};

// One collapse after another, as they happened.
struct CollapseLog {
  std::vector<uint32_t> i, j;         // removed vertex, kept vertex
  std::vector<float> fieldError;      // E_f of the collapse (field units), for the manifest
  std::vector<float> iValue, jValue;  // the steering field at i and j just before the collapse
  // Collapse c's CollapseTets, coded in tetBytes[tetsBegin[c] .. tetsBegin[c + 1]) (the closing
  // entry is added once the log is complete; until then the last record ends at tetBytes.size()).
  std::vector<uint64_t> tetsBegin;
  std::vector<uint8_t> tetBytes;
  std::vector<uint32_t> starBegin;  // likewise for star: the tets around j just after the collapse,
  std::vector<uint32_t> star;       // what its split reads (only with recordReadSets; split_order.h)

  uint32_t size() const { return uint32_t(i.size()); }

  // Appends the record of the collapse just logged (onto j); sorts t.moved.
  void appendTets(CollapseTets& t, uint32_t j);
  // Appends record c of `src` unchanged.
  void appendTetsOf(const CollapseLog& src, uint32_t c);
  // Collapse c's tets (moved ascending).
  void readTets(uint32_t c, CollapseTets& out) const;
  // Adds the closing entries of tetsBegin (and of starBegin, when read sets were recorded).
  void close(bool readSets);

  // Bytes a record takes at most, for reserving: a header and so many moved and removed tets.
  static constexpr double kHeaderBytes = 4, kMovedBytes = 3, kRemovedBytes = 9;  // (typical: 2, 2, 6)
};

}  // namespace tetstream
