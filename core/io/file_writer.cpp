#include "io/file_writer.h"

#include <cerrno>
#include <cstring>

namespace tetstream {

FileWriter::FileWriter(std::string path) : path_(std::move(path)), tmp_(path_ + ".tmp") {
  f_ = std::fopen(tmp_.c_str(), "wb");
  if (!f_) openError_ = std::strerror(errno);
}

FileWriter::~FileWriter() {
  if (f_) std::fclose(f_);
  if (!committed_) std::remove(tmp_.c_str());
}

void FileWriter::write(const void* data, size_t bytes) {
  if (f_ && ok_ && bytes) ok_ = std::fwrite(data, 1, bytes, f_) == bytes;
}

Result FileWriter::commit() {
  if (!f_) return fail(Status::IoError, path_ + ": cannot create " + tmp_ + " (" + openError_ + ")");
  bool ok = std::fclose(f_) == 0 && ok_;
  f_ = nullptr;
  if (!ok) return fail(Status::IoError, path_ + ": write failed (disk full?)");
  if (std::rename(tmp_.c_str(), path_.c_str()) != 0)
    return fail(Status::IoError, path_ + ": cannot rename " + tmp_ + " (" + std::strerror(errno) + ")");
  committed_ = true;
  return Result::success();
}

}  // namespace tetstream
