#include "pack/collapse_log.h"

#include <algorithm>
#include <cassert>

#include "varint.h"

namespace tetstream {

namespace {

// The log is the packer's own data, never read from a file: decoding needs no bounds checks.
inline uint32_t takeVarint(const uint8_t*& p) {
  uint32_t v = 0;
  for (int shift = 0;; shift += 7) {
    const uint8_t b = *p++;
    v |= uint32_t(b & 0x7f) << shift;
    if (!(b & 0x80)) return v;
  }
}

}  // namespace

// Record: count of moved tets, count of removed tets; the moved tets ascending, the first as
// it is and the rest as differences; each removed tet as a signed difference from the tet
// before it (the last moved one, or 0); its two other vertices as signed differences from j.
void CollapseLog::appendTets(CollapseTets& t, uint32_t jv) {
  assert(t.others.size() == 2 * t.removed.size());
  tetsBegin.push_back(tetBytes.size());
  std::sort(t.moved.begin(), t.moved.end());
  putVarint(tetBytes, uint32_t(t.moved.size()));
  putVarint(tetBytes, uint32_t(t.removed.size()));
  uint32_t prev = 0;
  for (uint32_t m : t.moved) {
    putVarint(tetBytes, m - prev);
    prev = m;
  }
  for (size_t k = 0; k < t.removed.size(); ++k) {
    putVarint(tetBytes, zigzag(int32_t(t.removed[k] - prev)));
    prev = t.removed[k];
    putVarint(tetBytes, zigzag(int32_t(t.others[2 * k] - jv)));
    putVarint(tetBytes, zigzag(int32_t(t.others[2 * k + 1] - jv)));
  }
}

void CollapseLog::appendTetsOf(const CollapseLog& src, uint32_t c) {
  const uint64_t b0 = src.tetsBegin[c], b1 = c + 1 < src.tetsBegin.size() ? src.tetsBegin[c + 1] : src.tetBytes.size();
  tetsBegin.push_back(tetBytes.size());
  tetBytes.insert(tetBytes.end(), src.tetBytes.begin() + ptrdiff_t(b0), src.tetBytes.begin() + ptrdiff_t(b1));
}

void CollapseLog::readTets(uint32_t c, CollapseTets& out) const {
  const uint8_t* p = tetBytes.data() + tetsBegin[c];
  const uint32_t jv = j[c];
  const uint32_t moved = takeVarint(p), removed = takeVarint(p);
  out.moved.resize(moved);
  out.removed.resize(removed);
  out.others.resize(2 * size_t(removed));
  uint32_t prev = 0;
  for (uint32_t k = 0; k < moved; ++k) out.moved[k] = prev += takeVarint(p);
  for (uint32_t k = 0; k < removed; ++k) {
    out.removed[k] = prev += uint32_t(unzigzag(takeVarint(p)));
    out.others[2 * k] = jv + uint32_t(unzigzag(takeVarint(p)));
    out.others[2 * k + 1] = jv + uint32_t(unzigzag(takeVarint(p)));
  }
}

void CollapseLog::close(bool readSets) {
  tetsBegin.push_back(tetBytes.size());
  if (readSets) starBegin.push_back(uint32_t(star.size()));
}

}  // namespace tetstream
