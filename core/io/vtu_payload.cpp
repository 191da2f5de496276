#include "io/vtu_payload.h"

#include <zlib.h>

namespace tetstream::vtkio {
namespace {

// Guard against ratios zlib cannot produce (deflate tops out near 1032:1), so a forged block header
// cannot make us allocate far more than the file holds.
constexpr uint64_t kMaxZlibRatio = 1032;

bool readHeaderWord(const PayloadFormat& vtu, ByteSource& src, uint64_t& out) {
  uint8_t b[8];
  const int n = vtu.header64 ? 8 : 4;
  if (!src.read(b, size_t(n))) return false;
  out = 0;
  for (int i = 0; i < n; ++i) out = out << 8 | b[vtu.bigEndian ? i : n - 1 - i];
  return true;
}

}  // namespace

Result readPayload(const PayloadFormat& vtu, ByteSource& src, const std::string& what, uint64_t expectedBytes,
                   uint64_t begin, uint64_t end, std::vector<uint8_t>& bytes, const uint8_t*& data) {
  auto srcError = [&](const char* stage) {
    Status s = src.error().find("invalid") != std::string::npos || src.error().find("padding") != std::string::npos
                   ? Status::Corrupt
                   : Status::Truncated;
    return fail(s, what + ": " + stage + ": " + src.error());
  };
  const uint64_t word = vtu.header64 ? 8 : 4;

  if (!vtu.zlib) {
    uint64_t n;
    if (!readHeaderWord(vtu, src, n)) return srcError("reading the size header");
    if (n != expectedBytes)
      return fail(n > src.available() ? Status::Truncated : Status::Corrupt,
                  what + ": header says " + std::to_string(n) + " bytes, expected " + std::to_string(expectedBytes) +
                      (n > src.available() ? " (and the file holds fewer)" : ""));
    if (n > src.available())
      return fail(Status::Truncated, what + ": needs " + std::to_string(n) + " bytes, at most " +
                                         std::to_string(src.available()) + " remain");
    src.claimPlain(n);
    if (!src.skip(begin)) return srcError("reading the data");
    if ((data = src.inPlace(end - begin))) return Result::success();
    bytes.resize(end - begin);
    if (!src.read(bytes.data(), end - begin)) return srcError("reading the data");
    data = bytes.data();
    return Result::success();
  }

  uint64_t nblocks, blockSize, lastSize;
  if (!readHeaderWord(vtu, src, nblocks)) return srcError("reading the compression header");
  // The rest of the header (2 + nblocks words) must fit in what is left, or nblocks is a lie.
  if (nblocks > src.available() / word)
    return fail(Status::Truncated, what + ": compression header declares " + std::to_string(nblocks) +
                                       " blocks, more than the file holds");
  if (!readHeaderWord(vtu, src, blockSize) || !readHeaderWord(vtu, src, lastSize))
    return srcError("reading the compression header");
  std::vector<uint64_t> csize(nblocks);  // bounded: nblocks words fit in the remaining bytes
  uint64_t compressedTotal = 0;
  for (uint64_t b = 0; b < nblocks; ++b) {
    if (!readHeaderWord(vtu, src, csize[b])) return srcError("reading the compressed block sizes");
    if (csize[b] > src.available() || compressedTotal + csize[b] < compressedTotal)
      return fail(Status::Truncated, what + ": compressed block " + std::to_string(b) + " of " +
                                         std::to_string(nblocks) + " needs " + std::to_string(csize[b]) +
                                         " bytes, more than the file holds");
    compressedTotal += csize[b];
  }
  uint64_t total = 0;
  if (nblocks > 0) {
    uint64_t last = lastSize == 0 ? blockSize : lastSize;
    if (last > blockSize)
      return fail(Status::Corrupt, what + ": last block size " + std::to_string(last) + " exceeds the block size " +
                                       std::to_string(blockSize));
    if (__builtin_mul_overflow(nblocks - 1, blockSize, &total) || total + last < total)
      return fail(Status::Corrupt, what + ": compression header sizes overflow");
    total += last;
  }
  if (total != expectedBytes)
    return fail(Status::Corrupt, what + ": compressed data holds " + std::to_string(total) + " bytes, expected " +
                                     std::to_string(expectedBytes));
  if (compressedTotal > src.available())
    return fail(Status::Truncated, what + ": compressed blocks need " + std::to_string(compressedTotal) +
                                       " bytes, at most " + std::to_string(src.available()) + " remain");
  for (uint64_t b = 0; b < nblocks; ++b) {
    uint64_t usize = (b + 1 == nblocks) ? total - (nblocks - 1) * blockSize : blockSize;
    if (usize > csize[b] * kMaxZlibRatio + 64)
      return fail(Status::Corrupt, what + ": block " + std::to_string(b) + " claims " + std::to_string(usize) +
                                       " bytes from " + std::to_string(csize[b]) +
                                       " compressed, beyond what zlib can produce");
  }

  // The blocks that hold [begin, end): those before are passed over, those after never read.
  const uint64_t firstBlock = end > begin ? begin / blockSize : 0,
                 endBlock = end > begin ? (end - 1) / blockSize + 1 : 0;
  src.claimPlain(compressedTotal);
  uint64_t before = 0;
  for (uint64_t b = 0; b < firstBlock; ++b) before += csize[b];  // (no overflow: checked above)
  if (!src.skip(before)) return srcError("reading a compressed block");
  bytes.resize(size_t((endBlock == nblocks ? total : endBlock * blockSize) - firstBlock * blockSize));
  std::vector<uint8_t> packed;
  uint64_t at = 0;
  for (uint64_t b = firstBlock; b < endBlock; ++b) {
    uint64_t usize = (b + 1 == nblocks) ? total - b * blockSize : blockSize;
    packed.resize(csize[b]);
    if (!src.read(packed.data(), csize[b])) return srcError("reading a compressed block");
    uLongf got = uLongf(usize);
    int z = uncompress(bytes.data() + at, &got, packed.data(), uLong(csize[b]));
    if (z != Z_OK || got != usize) {
      const char* why = z == Z_DATA_ERROR  ? "corrupt zlib data (Z_DATA_ERROR)"
                        : z == Z_BUF_ERROR ? "inflates to more than the header says (Z_BUF_ERROR)"
                        : z == Z_MEM_ERROR ? "out of memory (Z_MEM_ERROR)"
                        : z == Z_OK        ? "inflates to fewer bytes than the header says"
                                           : "zlib error";
      return fail(Status::DecompressFailed,
                  what + ": zlib block " + std::to_string(b) + " of " + std::to_string(nblocks) + ": " + why);
    }
    at += usize;
  }
  data = end > begin ? bytes.data() + (begin - firstBlock * blockSize) : bytes.data();
  return Result::success();
}

}  // namespace tetstream::vtkio
