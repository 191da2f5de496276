// Content hash of chunk files (FORMAT.md §1): XXH3 64-bit, seed 0, printed as
// "xxh3-64:" followed by 16 lowercase hex digits. And hash64, the mixer of in-memory hash tables.
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

namespace tetstream {

uint64_t contentHash(std::span<const uint8_t> bytes);
std::string formatHash(uint64_t h);
// Parses the "xxh3-64:<16 hex>" form; false on anything else.
bool parseHash(std::string_view text, uint64_t* out);

// splitmix64's finaliser: every bit of x reaches every bit of the result, so keys built from
// nearby vertex ids spread over a hash table's slots (FlatMap; parities of edge sets).
inline uint64_t hash64(uint64_t x) {
  x ^= x >> 30;
  x *= 0xbf58476d1ce4e5b9ull;
  x ^= x >> 27;
  x *= 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

}  // namespace tetstream
