#include "status.h"

namespace tetstream {

const char* statusName(Status s) {
  switch (s) {
    case Status::Ok: return "ok";
    case Status::IoError: return "io-error";
    case Status::Truncated: return "truncated";
    case Status::BadMagic: return "bad-magic";
    case Status::UnsupportedVersion: return "unsupported-version";
    case Status::Unsupported: return "unsupported";
    case Status::Corrupt: return "corrupt";
    case Status::OutOfRange: return "out-of-range";
    case Status::NonFinite: return "non-finite";
    case Status::TooLarge: return "too-large";
    case Status::HashMismatch: return "hash-mismatch";
    case Status::SizeMismatch: return "size-mismatch";
    case Status::NoTets: return "no-tets";
    case Status::MissingField: return "missing-field";
    case Status::BadManifest: return "bad-manifest";
    case Status::DecompressFailed: return "decompress-failed";
    case Status::BadArgument: return "bad-argument";
  }
  return "unknown";
}

}  // namespace tetstream
