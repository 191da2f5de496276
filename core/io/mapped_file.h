// A file mapped read-only into memory: its pages are read from disk when first touched, so a
// reader that needs a few parts of a large file (one process's pieces of a .vtu with appended
// data) holds those parts only, where reading the file into a buffer would hold all of it.
#pragma once
#include <string>
#include <string_view>

#include "status.h"

namespace tetstream {

class MappedFile {
 public:
  MappedFile() = default;
  ~MappedFile();
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;

  // Maps the regular file at `path` (an empty file maps to no bytes). IoError naming the path
  // and the reason when it cannot be opened or mapped.
  Result open(const std::string& path);
  std::string_view bytes() const { return {static_cast<const char*>(data_), size_}; }

 private:
  void* data_ = nullptr;
  size_t size_ = 0;
};

}  // namespace tetstream
