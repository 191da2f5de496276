// Writes a file so that it appears whole or not at all: data goes to PATH.tmp, which is renamed
// to PATH on commit(); a failed or abandoned write removes the temporary file. Pack side only.
#pragma once
#include <cstdio>
#include <string>

#include "status.h"

namespace tetstream {

class FileWriter {
 public:
  explicit FileWriter(std::string path);
  ~FileWriter();  // removes the temporary file unless committed
  FileWriter(const FileWriter&) = delete;
  FileWriter& operator=(const FileWriter&) = delete;

  // Appends bytes; failures are remembered and reported by commit().
  void write(const void* data, size_t bytes);
  // Closes and renames into place; IoError naming the path and the reason on any failure.
  Result commit();

 private:
  std::string path_, tmp_;
  std::FILE* f_ = nullptr;
  bool ok_ = true, committed_ = false;
  std::string openError_;
};

}  // namespace tetstream
