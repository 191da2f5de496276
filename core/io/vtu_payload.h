// The binary payload of a VTK XML DataArray, in every encoding the format has (inline base64,
// appended raw or base64): a size header and the data, or a compression header and zlib blocks
//   uncompressed: [nbytes]                                                     data
//   zlib:         [nblocks][blockSize][lastBlockSize][csize_0 .. csize_n-1]    zlib blocks
// each header word a UInt32 or UInt64 (header_type), in the file's byte order. lastBlockSize 0
// means "a full block" (VTK); meshio writes the full size instead. Both are accepted. Layout
// reference: vtkXMLWriter's WriteBinaryDataInternal.
#pragma once
#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "status.h"

namespace tetstream::vtkio {

// The bytes of one binary payload, from raw appended data or from base64 text. Base64 is decoded
// one 4-character group at a time, and a group ending in '=' does not end the stream: VTK encodes
// the compressed-block header and the blocks as separate base64 strings and concatenates them
// (meshio does the same for compressed data, but encodes header+data as one string otherwise).
class ByteSource {
 public:
  // Of base64 text, the characters from `from` to `to` (offsets in it) hold no white space and no
  // padding: skip() jumps over groups there. Kept by the caller for text read more than once.
  struct PlainSpan {
    size_t from = 0, to = 0;
  };

  static ByteSource raw(std::string_view bytes) { return ByteSource(bytes, false); }
  // `plain`: where this text was found plain before (it grows as skip() checks more); may be null.
  static ByteSource base64(std::string_view text, PlainSpan* plain = nullptr) {
    ByteSource s(text, true);
    s.plain_ = plain;
    return s;
  }

  // An upper bound on the bytes still available (exact for raw data).
  uint64_t available() const {
    uint64_t left = data_.size() - pos_;
    return b64_ ? left / 4 * 3 + 3 + (pendingCount_ - pendingPos_) : left;
  }

  // Copies the next n bytes to dst. On failure returns false with error() set.
  bool read(uint8_t* dst, size_t n) {
    if (n == 0) return true;  // dst may be null for an empty array (memcpy must not see it)
    if (!b64_) {
      if (data_.size() - pos_ < n) {
        error_ = "data ends " + std::to_string(n - (data_.size() - pos_)) + " bytes early";
        return false;
      }
      std::memcpy(dst, data_.data() + pos_, n);
      pos_ += n;
      return true;
    }
    while (n > 0) {
      if (pendingPos_ == pendingCount_) {
        const size_t fast = plainGroups(dst, n);
        dst += fast;
        n -= fast;
        if (n == 0) break;
        if (!decodeGroup()) return false;
      }
      size_t take = std::min<size_t>(n, size_t(pendingCount_ - pendingPos_));
      std::memcpy(dst, pending_ + pendingPos_, take);
      pendingPos_ += int(take);
      dst += take;
      n -= take;
    }
    return true;
  }

  // Passes over the next n bytes. Of base64 text, whole groups are jumped over, four characters
  // for three bytes, where the text ahead holds no white space or padding (every writer's text
  // inside one encoded string): a process reading a window of a large array decodes the window,
  // not what comes before it. Elsewhere (white space or padding may sit anywhere, so a character
  // offset cannot be computed) the text is decoded on the way, into a small buffer.
  bool skip(uint64_t n) {
    if (!b64_) {
      if (data_.size() - pos_ < n) {
        error_ = "data ends " + std::to_string(n - (data_.size() - pos_)) + " bytes early";
        return false;
      }
      pos_ += size_t(n);
      return true;
    }
    const size_t pending = size_t(std::min<uint64_t>(n, uint64_t(pendingCount_ - pendingPos_)));
    pendingPos_ += int(pending);
    n -= pending;
    if (const uint64_t groups = n / 3; groups > 0 && groups <= (data_.size() - pos_) / 4 && plainAhead(4 * groups)) {
      pos_ += size_t(4 * groups);
      n -= 3 * groups;
    }
    uint8_t scratch[3 * 4096];
    for (; n > 0;) {
      const size_t take = size_t(std::min<uint64_t>(n, sizeof scratch));
      if (!read(scratch, take)) return false;
      n -= take;
    }
    return true;
  }

  // The text from here holds the payload's last `bytes` bytes. When what is left of it, less
  // white space at its end, is exactly as many characters as those bytes take as one base64
  // string, there is no room in it for white space or padding before its end: it is plain, and
  // skip() jumps over it without looking (the inline arrays of VTK and meshio; text of another
  // length, wrapped into lines for one, is looked at before a jump).
  void claimPlain(uint64_t bytes) {
    if (!b64_) return;
    const uint64_t decoded = uint64_t(pendingCount_ - pendingPos_);
    if (bytes < decoded) return;
    size_t end = data_.size();
    while (end > pos_ && meaning()[uint8_t(data_[end - 1])] == kSpace) --end;
    if (end - pos_ != (bytes - decoded + 2) / 3 * 4) return;
    if (!plain_) plain_ = &ownPlain_;
    *plain_ = {pos_, end};
  }

  // The next n bytes where they are, for a raw source that holds them (no copy); else null,
  // and read() copies them.
  const uint8_t* inPlace(size_t n) {
    if (b64_ || data_.size() - pos_ < n) return nullptr;
    const uint8_t* at = reinterpret_cast<const uint8_t*>(data_.data()) + pos_;
    pos_ += n;
    return at;
  }

  const std::string& error() const { return error_; }

 private:
  ByteSource(std::string_view d, bool b64) : data_(d), b64_(b64) {}

  // Each character's meaning in base64 text: its 6 bits (0-63), kPad for '=', kSpace for the
  // white space allowed between characters, kBad for the rest. One table for both decoders.
  static constexpr uint8_t kPad = 64, kSpace = 0x80, kBad = 0xff;
  static const std::array<uint8_t, 256>& meaning() {
    static const std::array<uint8_t, 256> table = [] {
      std::array<uint8_t, 256> t;
      t.fill(kBad);
      const char* alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
      for (int k = 0; k < 64; ++k) t[uint8_t(alphabet[k])] = uint8_t(k);
      t[uint8_t('=')] = kPad;
      for (char c : {' ', '\n', '\r', '\t'}) t[uint8_t(c)] = kSpace;
      return t;
    }();
    return table;
  }

  // Whether the next `chars` characters hold no white space and no padding ('='). What was
  // found plain is remembered (plain_), so that text read a window at a time is checked once.
  bool plainAhead(size_t chars) {
    PlainSpan here{pos_, pos_};
    PlainSpan& known = plain_ && plain_->from <= pos_ && pos_ <= plain_->to ? *plain_ : here;
    const size_t end = pos_ + chars;
    for (size_t at = known.to; at < end;) {
      const size_t step = std::min<size_t>(end - at, size_t(1) << 20);
      for (char c : {' ', '\n', '\r', '\t', '='})
        if (std::memchr(data_.data() + at, c, step)) return false;
      at += step;
      known.to = at;
    }
    if (plain_ && &known == &here) *plain_ = here;
    return true;
  }

  // Decodes whole groups straight into dst while the text is plain base64, four characters a
  // group with no white space, padding or stray character (decodeGroup() takes those, one group
  // at a time). Returns the bytes written, a multiple of 3, at most n.
  size_t plainGroups(uint8_t* dst, size_t n) {
    const std::array<uint8_t, 256>& table = meaning();
    const auto* text = reinterpret_cast<const unsigned char*>(data_.data());
    size_t done = 0;
    for (; n - done >= 3 && data_.size() - pos_ >= 4; done += 3, pos_ += 4) {
      const uint32_t a = table[text[pos_]], b = table[text[pos_ + 1]], c = table[text[pos_ + 2]],
                     d = table[text[pos_ + 3]];
      if ((a | b | c | d) >= kPad) break;  // (each is below 64 or at least kPad)
      const uint32_t bits = a << 18 | b << 12 | c << 6 | d;
      dst[done] = uint8_t(bits >> 16);
      dst[done + 1] = uint8_t(bits >> 8);
      dst[done + 2] = uint8_t(bits);
    }
    return done;
  }

  bool decodeGroup() {
    int v[4];
    int got = 0;
    while (got < 4) {
      if (pos_ >= data_.size()) {
        error_ = got ? "base64 text ends inside a 4-character group" : "base64 text ends early";
        return false;
      }
      const char c = data_[pos_];
      const uint8_t x = meaning()[uint8_t(c)];
      if (x == kSpace) {
        ++pos_;
        continue;
      }
      if (x == kBad) {
        char buf[64];
        std::snprintf(buf, sizeof buf, "invalid base64 character 0x%02x", unsigned(static_cast<unsigned char>(c)));
        error_ = buf;
        return false;
      }
      v[got++] = x;
      ++pos_;
    }
    // '=' may only pad the last one or two places of a group.
    if (v[0] == 64 || v[1] == 64 || (v[2] == 64 && v[3] != 64)) {
      error_ = "misplaced base64 padding '='";
      return false;
    }
    uint32_t bits = uint32_t(v[0]) << 18 | uint32_t(v[1]) << 12 | uint32_t(v[2] & 63) << 6 | uint32_t(v[3] & 63);
    pending_[0] = uint8_t(bits >> 16);
    pending_[1] = uint8_t(bits >> 8);
    pending_[2] = uint8_t(bits);
    pendingCount_ = v[2] == 64 ? 1 : v[3] == 64 ? 2 : 3;
    pendingPos_ = 0;
    return true;
  }

  std::string_view data_;
  size_t pos_ = 0;
  bool b64_;
  PlainSpan* plain_ = nullptr;
  PlainSpan ownPlain_;  // (plain_ when the caller keeps none)
  uint8_t pending_[3] = {0, 0, 0};
  int pendingCount_ = 0, pendingPos_ = 0;
  std::string error_;
};

// How a file writes its payloads (the VTKFile element's attributes).
struct PayloadFormat {
  bool bigEndian = false;
  bool header64 = false;  // header_type="UInt64"
  bool zlib = false;      // compressor="vtkZLibDataCompressor"
};

// Reads one binary payload (header + data, compressed or not) of expectedBytes bytes, and puts
// its bytes [begin, end) at `data`, still in the file's byte order. Raw appended data stays where
// it is in the file's bytes (a large mesh's arrays were copied once more for nothing); the rest
// goes to `bytes`. Of compressed data only the blocks that hold [begin, end) are inflated.
// `what` names the array in messages.
Result readPayload(const PayloadFormat& format, ByteSource& src, const std::string& what, uint64_t expectedBytes,
                   uint64_t begin, uint64_t end, std::vector<uint8_t>& bytes, const uint8_t*& data);

}  // namespace tetstream::vtkio
