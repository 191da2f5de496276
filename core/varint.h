// LEB128 varints and zigzag signed mapping for the vertex-split stream (FORMAT.md §4).
// Writers append to a byte vector; the reader is bounds-checked for hostile input.
#pragma once
#include <cstdint>
#include <cstring>
#include <span>
#include <vector>

namespace tetstream {

inline uint32_t zigzag(int32_t v) { return (uint32_t(v) << 1) ^ uint32_t(v >> 31); }
inline int32_t unzigzag(uint32_t u) { return int32_t(u >> 1) ^ -int32_t(u & 1); }

inline void putVarint(std::vector<uint8_t>& out, uint32_t v) {
  while (v >= 0x80) {
    out.push_back(uint8_t(v | 0x80));
    v >>= 7;
  }
  out.push_back(uint8_t(v));
}

inline void putF32(std::vector<uint8_t>& out, float f) {
  uint8_t b[4];
  std::memcpy(b, &f, 4);  // little-endian hosts only (chunk.h)
  out.insert(out.end(), b, b + 4);
}

// Cursor over untrusted bytes: every read reports failure instead of running past the end.
struct ByteReader {
  std::span<const uint8_t> data;
  size_t pos = 0;

  bool atEnd() const { return pos == data.size(); }
  bool varint(uint32_t& v) {
    v = 0;
    for (int shift = 0; shift < 35; shift += 7) {
      if (pos >= data.size()) return false;
      uint8_t b = data[pos++];
      if (shift == 28 && (b & 0xf0)) return false;  // more than 32 bits
      v |= uint32_t(b & 0x7f) << shift;
      if (!(b & 0x80)) return true;
    }
    return false;
  }
  bool f32(float& f) {
    if (data.size() - pos < 4) return false;
    std::memcpy(&f, data.data() + pos, 4);
    pos += 4;
    return true;
  }
  bool u32(uint32_t& v) {
    if (data.size() - pos < 4) return false;
    v = uint32_t(data[pos]) | uint32_t(data[pos + 1]) << 8 | uint32_t(data[pos + 2]) << 16 |
        uint32_t(data[pos + 3]) << 24;
    pos += 4;
    return true;
  }
  bool bytes(size_t n, const uint8_t*& p) {
    if (data.size() - pos < n) return false;
    p = data.data() + pos;
    pos += n;
    return true;
  }
};

}  // namespace tetstream
