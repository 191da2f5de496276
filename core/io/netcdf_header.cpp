// A check of a netCDF classic header (CDF-1, CDF-2 and CDF-5) before the netCDF library opens
// the file (readers.h). The library believes the header's counts: a damaged count makes it
// allocate (and fill) gigabytes before it finds anything wrong, and a truncated file reads as
// zeros past its end. Here every count is checked against the bytes the file has left, and
// every variable's data against the file's size, so the library only sees headers that
// describe the bytes that are there.
//
// Layout (the netCDF classic format specification, all big-endian):
//   header   = "CDF" version  numrecs  dim_list  gatt_list  var_list
//   list     = ABSENT (tag 0, count 0) | tag count item...   tags: 10 dims, 12 atts, 11 vars
//   dim      = name  length (0: the record dimension)
//   att      = name  nc_type  count  values (padded to 4 bytes)
//   var      = name  ndims  dimid...  att_list  nc_type  vsize  begin
//   name     = count  chars (padded to 4 bytes)
// Counts, lengths, ndims, dimids and vsize are 4 bytes in CDF-1/2 and 8 in CDF-5; begin is 4 bytes
// in CDF-1 and 8 in CDF-2/5; tags and nc_type are 4 bytes.
#include <bit>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "io/readers.h"

namespace tetstream::vtkio {

namespace {

// The most names may hold (NC_MAX_NAME) and the most dimensions a variable may have
// (NC_MAX_VAR_DIMS) in the netCDF library.
constexpr uint64_t kMaxName = 256;
constexpr uint64_t kMaxVarDims = 1024;

uint64_t typeSize(uint32_t type) {
  switch (type) {
    case 1:             // byte
    case 2:             // char
    case 7: return 1;   // ubyte
    case 3:             // short
    case 8: return 2;   // ushort
    case 4:             // int
    case 5:             // float
    case 9: return 4;   // uint
    case 6:             // double
    case 10:            // int64
    case 11: return 8;  // uint64
    default: return 0;
  }
}

uint64_t padded4(uint64_t n) { return (n + 3) & ~uint64_t(3); }

struct Cursor {
  std::string_view s;
  size_t pos = 0;
  bool out = false;  // ran past the bytes given

  bool take(size_t n, const uint8_t*& p) {
    if (s.size() - pos < n) {
      out = true;
      return false;
    }
    p = reinterpret_cast<const uint8_t*>(s.data() + pos);
    pos += n;
    return true;
  }
  bool u32(uint32_t& v) {
    const uint8_t* p;
    if (!take(4, p)) return false;
    v = uint32_t(p[0]) << 24 | uint32_t(p[1]) << 16 | uint32_t(p[2]) << 8 | p[3];
    return true;
  }
  bool u64(uint64_t& v) {
    uint32_t hi, lo;
    if (!u32(hi) || !u32(lo)) return false;
    v = uint64_t(hi) << 32 | lo;
    return true;
  }
  bool sized(bool wide, uint64_t& v) {
    if (wide) return u64(v);
    uint32_t w;
    if (!u32(w)) return false;
    v = w;
    return true;
  }
  bool skip(uint64_t n) {
    const uint8_t* p;
    if (n > s.size() - pos) {
      out = true;
      return false;
    }
    return take(size_t(n), p);
  }
};

struct Var {
  std::string name;
  std::vector<uint64_t> dims;
  uint64_t typeBytes = 0, begin = 0;
};

class HeaderCheck {
 public:
  HeaderCheck(std::string_view head, uint64_t fileSize, const std::string& label)
      : c_{head}, fileSize_(fileSize), label_(label) {}

  NetcdfHeaderResult run() {
    header() && dims() && attributes("global attributes") && vars() && extents();
    return result_;
  }

 private:
  bool header() {
    const uint8_t* magic;
    if (!c_.take(4, magic)) return ranOut("its signature");
    if (std::memcmp(magic, "CDF", 3) != 0 || (magic[3] != 1 && magic[3] != 2 && magic[3] != 5))
      return bad(Status::BadMagic, "not a netCDF classic file (no CDF\\1, CDF\\2 or CDF\\5 signature)");
    cdf5_ = magic[3] == 5;
    cdf2_ = magic[3] == 2;
    uint64_t numrecs;
    if (!c_.sized(cdf5_, numrecs)) return ranOut("the record count");
    streaming_ = numrecs == (cdf5_ ? ~uint64_t(0) : 0xFFFFFFFFull);
    numrecs_ = numrecs;
    return true;
  }

  // Both set the result and return false, for `return bad(...)` in the steps below.
  bool bad(Status s, const std::string& what) {
    result_.result = fail(s, label_ + ": " + what);
    return false;
  }
  // The header goes on past the bytes given: more are needed, or the file ends inside it.
  bool ranOut(const std::string& where) {
    if (c_.s.size() < fileSize_) {
      result_.needMore = true;
      return false;
    }
    return bad(Status::Truncated, "the netCDF header ends in " + where + ", past the file's end (" +
                                      std::to_string(fileSize_) + " bytes; truncated?)");
  }
  uint64_t left() const { return fileSize_ - c_.pos; }

  bool name(const std::string& what, std::string& out) {
    uint64_t n;
    if (!c_.sized(cdf5_, n)) return ranOut("the name of " + what);
    if (n == 0 || n > kMaxName)
      return bad(Status::Corrupt, "the netCDF header gives " + what + " a name of " + std::to_string(n) + " bytes");
    const uint8_t* p;
    if (!c_.take(size_t(n), p)) return ranOut("the name of " + what);
    out = printable(std::string_view(reinterpret_cast<const char*>(p), size_t(n)));
    if (!c_.skip(padded4(n) - n)) return ranOut("the name of " + what);
    return true;
  }

  // A list's tag and count; false (with the result set) when it is neither absent nor `tag`, or
  // its count cannot fit in what is left, at `minBytes` each.
  bool listHead(uint32_t tag, const char* what, uint64_t minBytes, uint64_t& count) {
    uint32_t t;
    if (!c_.u32(t)) return ranOut(std::string("the list of ") + what);
    if (!c_.sized(cdf5_, count)) return ranOut(std::string("the list of ") + what);
    if (t == 0 && count == 0) return true;
    if (t != tag)
      return bad(Status::Corrupt, std::string("the netCDF header's list of ") + what + " has tag " + std::to_string(t) +
                                      ", expected " + std::to_string(tag));
    if (count > left() / minBytes)
      return bad(Status::Truncated, std::string("the netCDF header lists ") + std::to_string(count) + " " + what +
                                        ", more than the rest of the file (" + std::to_string(left()) +
                                        " bytes) can hold (truncated or damaged?)");
    return true;
  }

  bool dims() {
    uint64_t n;
    if (!listHead(10, "dimensions", 8, n)) return false;
    for (uint64_t d = 0; d < n; ++d) {
      std::string nm;
      uint64_t length;
      if (!name("dimension " + std::to_string(d), nm)) return false;
      if (!c_.sized(cdf5_, length)) return ranOut("dimension '" + nm + "'");
      dimLength_.push_back(length);
    }
    return true;
  }

  bool attributes(const std::string& owner) {
    uint64_t n;
    if (!listHead(12, ("attributes of " + owner).c_str(), 12, n)) return false;
    for (uint64_t a = 0; a < n; ++a) {
      std::string nm;
      uint32_t type;
      uint64_t count;
      if (!name("an attribute of " + owner, nm)) return false;
      if (!c_.u32(type) || !c_.sized(cdf5_, count)) return ranOut("attribute '" + nm + "' of " + owner);
      const uint64_t size = typeSize(type);
      if (!size || (!cdf5_ && type > 6))
        return bad(Status::Corrupt, "attribute '" + nm + "' of " + owner + " has netCDF type " + std::to_string(type));
      if (count > left() / size)
        return bad(Status::Truncated, "attribute '" + nm + "' of " + owner + " declares " + std::to_string(count) +
                                          " values, more than the rest of the file (" + std::to_string(left()) +
                                          " bytes) can hold (truncated or damaged?)");
      if (!c_.skip(padded4(count * size))) return ranOut("attribute '" + nm + "' of " + owner);
    }
    return true;
  }

  bool vars() {
    uint64_t n;
    if (!listHead(11, "variables", 16, n)) return false;
    for (uint64_t k = 0; k < n; ++k) {
      Var v;
      if (!name("variable " + std::to_string(k), v.name)) return false;
      const std::string what = "variable '" + v.name + "'";
      uint64_t ndims;
      if (!c_.sized(cdf5_, ndims)) return ranOut(what);
      if (ndims > kMaxVarDims || ndims > left() / 4)
        return bad(Status::Corrupt, what + " has " + std::to_string(ndims) + " dimensions");
      for (uint64_t d = 0; d < ndims; ++d) {
        uint64_t id;
        if (!c_.sized(cdf5_, id)) return ranOut(what);
        if (id >= dimLength_.size())
          return bad(Status::Corrupt,
                     what + " uses dimension " + std::to_string(id) + " of " + std::to_string(dimLength_.size()));
        if (dimLength_[id] == 0 && d != 0)
          return bad(Status::Corrupt, what + " uses the record dimension other than first");
        v.dims.push_back(dimLength_[id]);
      }
      if (!attributes(what)) return false;
      uint32_t type;
      uint64_t vsize, begin;
      if (!c_.u32(type) || !c_.sized(cdf5_, vsize) || !c_.sized(cdf5_ || cdf2_, begin)) return ranOut(what);
      v.typeBytes = typeSize(type);
      if (!v.typeBytes || (!cdf5_ && type > 6))
        return bad(Status::Corrupt, what + " has netCDF type " + std::to_string(type));
      v.begin = begin;
      vars_.push_back(std::move(v));
    }
    return true;
  }

  // Bytes of one record of v (or all of a fixed variable), 0 on overflow with *over set.
  static uint64_t product(const Var& v, bool& over) {
    uint64_t bytes = v.typeBytes;
    const size_t first = !v.dims.empty() && v.dims[0] == 0 ? 1 : 0;
    for (size_t d = first; d < v.dims.size(); ++d)
      if (__builtin_mul_overflow(bytes, v.dims[d], &bytes)) {
        over = true;
        return 0;
      }
    return bytes;
  }

  // Every variable's data lies after the header and inside the file.
  bool extents() {
    const uint64_t headerEnd = c_.pos;
    uint64_t recsize = 0, recordVars = 0, lastRecord = 0;
    for (const Var& v : vars_) {
      bool over = false;
      const uint64_t bytes = product(v, over);
      const bool record = !v.dims.empty() && v.dims[0] == 0;
      if (over) return bad(Status::Corrupt, "variable '" + v.name + "' has dimensions whose product overflows 64 bits");
      if (v.begin < headerEnd)
        return bad(Status::Corrupt, "variable '" + v.name + "' starts at byte " + std::to_string(v.begin) +
                                        ", inside the header (which ends at " + std::to_string(headerEnd) + ")");
      if (record) {  // checked below, with the number of records
        recsize += padded4(bytes);
        lastRecord = bytes;
        ++recordVars;
        continue;
      }
      if (v.begin > fileSize_ || bytes > fileSize_ - v.begin)
        return bad(Status::Truncated, "variable '" + v.name + "' needs the bytes " + std::to_string(v.begin) + ".." +
                                          std::to_string(v.begin) + "+" + std::to_string(bytes) +
                                          ", but the file has " + std::to_string(fileSize_) + " (truncated?)");
    }
    // One record variable is stored unpadded (the netCDF library's rule).
    if (recordVars == 1) recsize = lastRecord;
    if (streaming_ || numrecs_ == 0) return true;
    for (const Var& v : vars_) {
      if (v.dims.empty() || v.dims[0] != 0) continue;
      bool over = false;
      const uint64_t bytes = product(v, over);
      uint64_t end = 0;
      if (__builtin_mul_overflow(numrecs_ - 1, recsize, &end) || __builtin_add_overflow(end, v.begin, &end) ||
          __builtin_add_overflow(end, bytes, &end) || end > fileSize_)
        return bad(Status::Truncated, "record variable '" + v.name + "' needs " + std::to_string(numrecs_) +
                                          " records, past the end of the file (" + std::to_string(fileSize_) +
                                          " bytes; truncated?)");
    }
    return true;
  }

  Cursor c_;
  uint64_t fileSize_;
  const std::string& label_;
  bool cdf5_ = false, cdf2_ = false, streaming_ = false;
  uint64_t numrecs_ = 0;
  std::vector<uint64_t> dimLength_;
  std::vector<Var> vars_;
  NetcdfHeaderResult result_;
};

}  // namespace

NetcdfHeaderResult checkNetcdfClassicHeader(std::string_view head, uint64_t fileSize, const std::string& label) {
  if (head.size() > fileSize) head = head.substr(0, size_t(fileSize));
  return HeaderCheck(head, fileSize, label).run();
}

Result checkNetcdfClassicFile(const std::string& path) {
  std::error_code ec;
  const uint64_t fileBytes = std::filesystem::file_size(path, ec);
  if (ec) return fail(Status::IoError, path + ": cannot open (" + ec.message() + ")");
  // The header is read in growing pieces: most are a few KB, a file of thousands of variables has
  // megabytes of it.
  for (size_t want = size_t(1) << 16;; want *= 4) {
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) return fail(Status::IoError, path + ": cannot open");
    std::string head(size_t(std::min<uint64_t>(want, fileBytes)), '\0');
    head.resize(std::fread(head.data(), 1, head.size(), f));
    std::fclose(f);
    const NetcdfHeaderResult h = checkNetcdfClassicHeader(head, fileBytes, path);
    if (!h.needMore || head.size() >= fileBytes) return h.result;
  }
}

}  // namespace tetstream::vtkio
