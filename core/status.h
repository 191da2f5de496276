// Error reporting for everything that comes from a file or the network.
// Caller mistakes are asserted; untrusted bytes get a Status plus a human-readable message.
#pragma once
#include <cstdint>
#include <string>

namespace tetstream {

enum class Status : uint8_t {
  Ok = 0,
  IoError,             // file missing or unreadable
  Truncated,           // data ends before what its header promises
  BadMagic,            // not a file of the expected kind
  UnsupportedVersion,  // a newer or unknown format version
  Unsupported,         // a valid file using a feature tetstream does not read
  Corrupt,             // inconsistent or malformed content
  OutOfRange,          // an index or count outside what the data allows
  NonFinite,           // NaN or Inf where a finite number is required
  TooLarge,            // a size beyond the documented limits
  HashMismatch,        // content differs from the manifest's hash
  SizeMismatch,        // content size differs from the manifest
  NoTets,              // a mesh with no tetrahedra
  MissingField,        // a named scalar field is not present
  BadManifest,         // manifest JSON is invalid or misses required keys
  DecompressFailed,    // zstd refused the data
  BadArgument,         // a user-supplied option is invalid
};

const char* statusName(Status s);

// A status with context, e.g. {Truncated, "mesh.vtu: DataArray 'connectivity' has 40 of 64 values"}.
struct Result {
  Status status = Status::Ok;
  std::string message;

  bool ok() const { return status == Status::Ok; }
  explicit operator bool() const { return ok(); }
  static Result success() { return {}; }
};

inline Result fail(Status s, std::string msg) { return Result{s, std::move(msg)}; }

}  // namespace tetstream
