// Content hash of chunk files (FORMAT.md §1): XXH3 64-bit, seed 0, printed as
// "xxh3-64:" followed by 16 lowercase hex digits.
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

}  // namespace tetstream
