#include "hash.h"

#define XXH_INLINE_ALL
#include <xxhash.h>

namespace tetstream {

static constexpr std::string_view kPrefix = "xxh3-64:";

uint64_t contentHash(std::span<const uint8_t> bytes) { return XXH3_64bits(bytes.data(), bytes.size()); }

std::string formatHash(uint64_t h) {
  static const char* hex = "0123456789abcdef";
  std::string s(kPrefix);
  for (int i = 15; i >= 0; --i) s.push_back(hex[(h >> (4 * i)) & 15]);
  return s;
}

bool parseHash(std::string_view text, uint64_t* out) {
  if (text.size() != kPrefix.size() + 16 || text.substr(0, kPrefix.size()) != kPrefix) return false;
  uint64_t h = 0;
  for (char c : text.substr(kPrefix.size())) {
    int d = c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10 : -1;
    if (d < 0) return false;
    h = h << 4 | uint64_t(d);
  }
  *out = h;
  return true;
}

}  // namespace tetstream
