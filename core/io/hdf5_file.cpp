#include "io/hdf5_file.h"

#include <cerrno>
#include <cstdio>
#include <cstring>

namespace tetstream::hdf5 {
namespace {

// HDF5 prints its error stack to stderr unless told not to; the readers turn every failure into
// a Result instead. Set once per process, before the first call that can fail.
void silenceLibrary() {
  static const bool done = [] {
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
    return true;
  }();
  (void)done;
}

// Bounds on what a file may declare before it is believed.
constexpr int kMaxRank = 32;
constexpr size_t kMaxPath = 4096;  // characters of an object's path
constexpr hsize_t kMaxMembers = 1u << 20;
// Filters (deflate, szip, ...) shrink data; deflate tops out near 1032:1. A selection that needs
// more than this many times the bytes stored for its dataset is refused before it is allocated.
constexpr uint64_t kMaxFilterRatio = 2048;

std::string withLibraryMessage(const std::string& text) {
  const std::string lib = lastError();
  return lib.empty() ? text : text + " (HDF5: " + lib + ")";
}

std::string dimsText(const std::vector<uint64_t>& dims) {
  if (dims.empty()) return "a scalar";
  std::string s;
  for (uint64_t d : dims) s += (s.empty() ? "" : " x ") + std::to_string(d);
  return s;
}

}  // namespace

uint64_t Shape::count() const {
  uint64_t n = 1;
  for (uint64_t d : dims)
    if (__builtin_mul_overflow(n, d, &n)) return UINT64_MAX;
  return n;
}

bool hasSignature(std::string_view head) { return head.substr(0, 8) == std::string_view("\x89HDF\r\n\x1a\n", 8); }

std::string lastError() {
  std::string innermost;
  auto walk = [](unsigned, const H5E_error2_t* e, void* data) -> herr_t {
    auto* s = static_cast<std::string*>(data);
    if (s->empty() && e && e->desc && *e->desc) *s = e->desc;
    return 0;
  };
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, walk, &innermost);
  H5Eclear2(H5E_DEFAULT);
  return innermost;
}

Result File::open(const std::string& path) {
  silenceLibrary();
  path_ = path;
  file_.reset();
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return fail(Status::IoError, path + ": cannot open (" + std::strerror(errno) + ")");
  char head[8] = {};
  const size_t got = std::fread(head, 1, sizeof head, f);
  std::fclose(f);
  // HDF5 also finds a signature after a user block (at 512, 1024, ...); the library checks that.
  if (got < 8 || !hasSignature(std::string_view(head, got))) {
    if (H5Fis_hdf5(path.c_str()) <= 0) {
      lastError();
      // .hdf is also HDF4's extension, a different format.
      const bool hdf4 = got >= 4 && std::string_view(head, 4) == std::string_view("\x0e\x03\x13\x01", 4);
      return fail(got == 0 ? Status::Truncated : Status::BadMagic,
                  path + ": not an HDF5 file (" +
                      (got == 0 ? "empty"
                       : hdf4   ? "it is HDF4, which tetstream does not read"
                                : "no HDF5 signature") +
                      ")");
    }
  }
  const hid_t id = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (id < 0) {
    const std::string lib = lastError();
    const bool cut = lib.find("truncated") != std::string::npos || lib.find("eof") != std::string::npos;
    return fail(cut ? Status::Truncated : Status::Corrupt,
                path + ": the HDF5 library cannot open it (" + (lib.empty() ? "damaged file" : lib) + ")" +
                    (cut ? "; the file is shorter than it says (cut off while copying or writing?)" : ""));
  }
  file_ = Handle(id, H5Fclose);
  return Result::success();
}

std::string File::where(const std::string& object, const char* kind) const {
  return path_ + ": " + kind + " '" + object + "'";
}

bool File::exists(const std::string& object) const { return find(object) == Found::Here; }

File::Found File::find(const std::string& object) const {
  if (!file_.valid() || object.size() > kMaxPath) return Found::Missing;
  if (object.empty() || object == "/") return Found::Here;
  // H5Lexists fails (rather than says no) when an intermediate group is missing: walk the path.
  std::string prefix;
  size_t pos = object[0] == '/' ? 1 : 0;
  if (object[0] == '/') prefix = "";
  while (pos <= object.size()) {
    size_t e = object.find('/', pos);
    if (e == std::string::npos) e = object.size();
    if (e > pos) {
      prefix += '/';
      prefix.append(object, pos, e - pos);
      const htri_t r = H5Lexists(file_.get(), prefix.c_str(), H5P_DEFAULT);
      if (r <= 0) {
        lastError();
        return Found::Missing;
      }
      // Links to other files are not followed: the data must be in this file.
      H5L_info_t link;
      if (H5Lget_info(file_.get(), prefix.c_str(), &link, H5P_DEFAULT) < 0) {
        lastError();
        return Found::Missing;
      }
      if (link.type == H5L_TYPE_EXTERNAL) return Found::OtherFile;
      // A link can dangle (soft or external links): the object must open too.
      const hid_t o = H5Oopen(file_.get(), prefix.c_str(), H5P_DEFAULT);
      if (o < 0) {
        lastError();
        return Found::Missing;
      }
      H5Oclose(o);
    }
    pos = e + 1;
  }
  return Found::Here;
}

bool File::isGroup(const std::string& object) const {
  if (!exists(object)) return false;
  const hid_t o = H5Oopen(file_.get(), object.c_str(), H5P_DEFAULT);
  if (o < 0) {
    lastError();
    return false;
  }
  const bool group = H5Iget_type(o) == H5I_GROUP;
  H5Oclose(o);
  return group;
}

Result File::members(const std::string& group, std::vector<std::string>& names) const {
  names.clear();
  if (!isGroup(group)) return fail(Status::Corrupt, where(group, "group") + " does not exist");
  Handle g(H5Gopen2(file_.get(), group.c_str(), H5P_DEFAULT), H5Gclose);
  H5G_info_t info;
  if (!g.valid() || H5Gget_info(g.get(), &info) < 0)
    return fail(Status::Corrupt, withLibraryMessage(where(group, "group") + " cannot be listed"));
  if (info.nlinks > kMaxMembers)
    return fail(Status::TooLarge, where(group, "group") + " has " + std::to_string(info.nlinks) + " members");
  for (hsize_t i = 0; i < info.nlinks; ++i) {
    const ssize_t n = H5Lget_name_by_idx(g.get(), ".", H5_INDEX_NAME, H5_ITER_INC, i, nullptr, 0, H5P_DEFAULT);
    if (n < 0 || n > 4096)
      return fail(Status::Corrupt, withLibraryMessage(where(group, "group") + ": a bad member name"));
    std::string name(size_t(n) + 1, '\0');
    H5Lget_name_by_idx(g.get(), ".", H5_INDEX_NAME, H5_ITER_INC, i, name.data(), name.size(), H5P_DEFAULT);
    name.resize(size_t(n));
    names.push_back(std::move(name));
  }
  return Result::success();
}

Result File::shape(const std::string& dataset, Shape& out) const {
  out = Shape{};
  if (const Found f = find(dataset); f != Found::Here)
    return fail(
        f == Found::OtherFile ? Status::Unsupported : Status::Corrupt,
        where(dataset) + (f == Found::OtherFile ? " is a link into another file, which tetstream does not follow"
                                                : " does not exist"));
  Handle ds(H5Dopen2(file_.get(), dataset.c_str(), H5P_DEFAULT), H5Dclose);
  if (!ds.valid()) return fail(Status::Corrupt, withLibraryMessage(where(dataset) + " is not a dataset"));
  Handle space(H5Dget_space(ds.get()), H5Sclose);
  const int rank = space.valid() ? H5Sget_simple_extent_ndims(space.get()) : -1;
  if (rank < 0 || rank > kMaxRank)
    return fail(Status::Corrupt, withLibraryMessage(where(dataset) + " has an unreadable dataspace"));
  std::vector<hsize_t> dims(size_t(rank), 0);
  if (rank > 0) H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr);
  out.dims.assign(dims.begin(), dims.end());
  Handle type(H5Dget_type(ds.get()), H5Tclose);
  const H5T_class_t cls = type.valid() ? H5Tget_class(type.get()) : H5T_NO_CLASS;
  out.isFloat = cls == H5T_FLOAT;
  out.isInteger = cls == H5T_INTEGER;
  return Result::success();
}

Slab File::rows(const Shape& shape, uint64_t first, uint64_t count) const {
  Slab s;
  s.start.assign(shape.dims.size(), 0);
  s.stride.assign(shape.dims.size(), 1);
  s.count = shape.dims;
  if (!shape.dims.empty()) {
    s.start[0] = first;
    s.count[0] = count;
  }
  return s;
}

Result File::select(const std::string& dataset, const Slab& slab, uint64_t expect, Handle& ds, Handle& fileSpace,
                    Handle& memSpace) const {
  Shape sh;
  if (Result r = shape(dataset, sh); !r) return r;
  if (!sh.isFloat && !sh.isInteger)
    return fail(Status::Unsupported, where(dataset) + " does not hold numbers (not an integer or float type)");
  ds = Handle(H5Dopen2(file_.get(), dataset.c_str(), H5P_DEFAULT), H5Dclose);
  fileSpace = Handle(H5Dget_space(ds.get()), H5Sclose);
  if (!ds.valid() || !fileSpace.valid())
    return fail(Status::Corrupt, withLibraryMessage(where(dataset) + " cannot be opened"));
  uint64_t count = sh.count();
  if (!slab.all()) {
    const size_t rank = sh.dims.size();
    if (slab.start.size() != rank || slab.stride.size() != rank || slab.count.size() != rank)
      return fail(Status::Corrupt, where(dataset) + " has " + std::to_string(rank) +
                                       " dimensions; the selection names " + std::to_string(slab.start.size()));
    count = 1;
    for (size_t d = 0; d < rank; ++d) {
      uint64_t last = 0;
      if (slab.stride[d] == 0 ||
          (slab.count[d] > 0 && (__builtin_mul_overflow(slab.count[d] - 1, slab.stride[d], &last) ||
                                 __builtin_add_overflow(last, slab.start[d], &last) || last >= sh.dims[d])))
        return fail(Status::OutOfRange,
                    where(dataset) + " (" + dimsText(sh.dims) + "): the selection start " +
                        std::to_string(slab.start[d]) + ", stride " + std::to_string(slab.stride[d]) + ", count " +
                        std::to_string(slab.count[d]) + " in dimension " + std::to_string(d) + " goes past its end");
      if (__builtin_mul_overflow(count, slab.count[d], &count)) count = UINT64_MAX;
    }
  }
  if (count != expect)
    return fail(Status::Corrupt, where(dataset) + " (" + dimsText(sh.dims) + ") gives " + std::to_string(count) +
                                     " values where " + std::to_string(expect) + " are needed");
  if (count == 0) return Result::success();

  // The data must be in this file: datasets stored in external raw files or mapped from other
  // files (virtual datasets) could name any file on the machine.
  Handle type(H5Dget_type(ds.get()), H5Tclose);
  Handle dcpl(H5Dget_create_plist(ds.get()), H5Pclose);
  if (dcpl.valid() && (H5Pget_external_count(dcpl.get()) > 0 || H5Pget_layout(dcpl.get()) == H5D_VIRTUAL))
    return fail(Status::Unsupported, where(dataset) +
                                         " keeps its data in other files (external storage or a "
                                         "virtual dataset), which tetstream does not follow");
  // Storage against shape: a selection cannot need more bytes than the file keeps for the
  // dataset (a few thousand times more when it is compressed).
  const uint64_t elementBytes = type.valid() ? H5Tget_size(type.get()) : 0;
  const uint64_t stored = H5Dget_storage_size(ds.get());
  const int filters = dcpl.valid() ? H5Pget_nfilters(dcpl.get()) : 0;
  uint64_t needed = 0, limit = 0;
  if (__builtin_mul_overflow(count, elementBytes, &needed)) needed = UINT64_MAX;
  if (__builtin_mul_overflow(stored, filters > 0 ? kMaxFilterRatio : 1, &limit)) limit = UINT64_MAX;
  if (needed > limit)
    return fail(stored == 0 ? Status::Truncated : Status::Corrupt,
                where(dataset) + " (" + dimsText(sh.dims) + "): the selection needs " + std::to_string(needed) +
                    " bytes, but the file stores " + std::to_string(stored) + (filters > 0 ? " (compressed)" : "") +
                    " for the dataset" + (stored == 0 ? " (it was never written)" : " (damaged file?)"));

  if (!slab.all()) {
    std::vector<hsize_t> start(slab.start.begin(), slab.start.end()), stride(slab.stride.begin(), slab.stride.end()),
        cnt(slab.count.begin(), slab.count.end());
    if (H5Sselect_hyperslab(fileSpace.get(), H5S_SELECT_SET, start.data(), stride.data(), cnt.data(), nullptr) < 0)
      return fail(Status::Corrupt, withLibraryMessage(where(dataset) + ": the selection is refused"));
  }
  // Memory laid out like the selection (same rank and counts): with a flat one, HDF5 maps a
  // chunked dataset element by element (a 1M-tet topology in gzip chunks of one column: 2.9 s
  // against 0.3 s).
  std::vector<hsize_t> memDims = slab.all() ? std::vector<hsize_t>(sh.dims.begin(), sh.dims.end())
                                            : std::vector<hsize_t>(slab.count.begin(), slab.count.end());
  memSpace = memDims.empty() ? Handle(H5Screate(H5S_SCALAR), H5Sclose)
                             : Handle(H5Screate_simple(int(memDims.size()), memDims.data(), nullptr), H5Sclose);
  if (!memSpace.valid()) return fail(Status::TooLarge, withLibraryMessage(where(dataset) + ": no memory space"));
  return Result::success();
}

// Reads a selection into `out`, converted by the library to `memType` (its C type is T's).
template <typename T>
Result File::readSelection(const std::string& dataset, const Slab& slab, uint64_t expect, hid_t memType,
                           std::vector<T>& out) const {
  out.clear();
  Handle ds, fileSpace, memSpace;
  if (Result r = select(dataset, slab, expect, ds, fileSpace, memSpace); !r) return r;
  if (expect == 0) return Result::success();
  out.resize(expect);
  if (H5Dread(ds.get(), memType, memSpace.get(), fileSpace.get(), H5P_DEFAULT, out.data()) < 0) {
    out.clear();
    return fail(Status::Corrupt, withLibraryMessage(where(dataset) + " cannot be read"));
  }
  return Result::success();
}

Result File::readDoubles(const std::string& dataset, const Slab& slab, uint64_t expect,
                         std::vector<double>& out) const {
  return readSelection(dataset, slab, expect, H5T_NATIVE_DOUBLE, out);
}

Result File::readInts(const std::string& dataset, const Slab& slab, uint64_t expect, std::vector<int64_t>& out) const {
  return readSelection(dataset, slab, expect, H5T_NATIVE_INT64, out);
}

bool File::hasAttribute(const std::string& object, const char* name) const {
  if (!exists(object)) return false;
  const htri_t r = H5Aexists_by_name(file_.get(), object.c_str(), name, H5P_DEFAULT);
  if (r < 0) lastError();
  return r > 0;
}

Result File::openAttribute(const std::string& object, const char* name, const std::string& what, Handle& attr,
                           Handle& type, Handle& space) const {
  if (!hasAttribute(object, name)) return fail(Status::Corrupt, what + " does not exist");
  attr = Handle(H5Aopen_by_name(file_.get(), object.c_str(), name, H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  type = Handle(attr.valid() ? H5Aget_type(attr.get()) : H5I_INVALID_HID, H5Tclose);
  space = Handle(attr.valid() ? H5Aget_space(attr.get()) : H5I_INVALID_HID, H5Sclose);
  if (!type.valid() || !space.valid()) return fail(Status::Corrupt, withLibraryMessage(what + " cannot be opened"));
  return Result::success();
}

Result File::stringAttribute(const std::string& object, const char* name, std::string& out) const {
  out.clear();
  const std::string what = where(object, "object") + " attribute '" + name + "'";
  Handle attr, type, space;
  if (Result r = openAttribute(object, name, what, attr, type, space); !r) return r;
  if (H5Tget_class(type.get()) != H5T_STRING) return fail(Status::Corrupt, what + " is not a string");
  const hssize_t n = H5Sget_simple_extent_npoints(space.get());
  if (n != 1) return fail(Status::Corrupt, what + " holds " + std::to_string(n) + " strings, expected one");
  if (H5Tis_variable_str(type.get()) > 0) {
    Handle mem(H5Tcopy(H5T_C_S1), H5Tclose);
    H5Tset_size(mem.get(), H5T_VARIABLE);
    H5Tset_cset(mem.get(), H5Tget_cset(type.get()));
    char* text = nullptr;
    if (H5Aread(attr.get(), mem.get(), &text) < 0)
      return fail(Status::Corrupt, withLibraryMessage(what + " cannot be read"));
    if (text) out = std::string(text, strnlen(text, 4096));
    H5Dvlen_reclaim(mem.get(), space.get(), H5P_DEFAULT, &text);
  } else {
    const size_t size = H5Tget_size(type.get());
    if (size == 0 || size > 4096) return fail(Status::Corrupt, what + " has a string size of " + std::to_string(size));
    out.assign(size, '\0');
    if (H5Aread(attr.get(), type.get(), out.data()) < 0) {
      out.clear();
      return fail(Status::Corrupt, withLibraryMessage(what + " cannot be read"));
    }
  }
  while (!out.empty() && (out.back() == '\0' || out.back() == ' ')) out.pop_back();
  if (const size_t nul = out.find('\0'); nul != std::string::npos) out.resize(nul);
  return Result::success();
}

Result File::intAttribute(const std::string& object, const char* name, std::vector<int64_t>& out, size_t max) const {
  out.clear();
  const std::string what = where(object, "object") + " attribute '" + name + "'";
  Handle attr, type, space;
  if (Result r = openAttribute(object, name, what, attr, type, space); !r) return r;
  const H5T_class_t cls = H5Tget_class(type.get());
  if (cls != H5T_INTEGER && cls != H5T_FLOAT) return fail(Status::Corrupt, what + " is not a number");
  const hssize_t n = H5Sget_simple_extent_npoints(space.get());
  if (n < 1 || size_t(n) > max)
    return fail(Status::Corrupt, what + " holds " + std::to_string(n) + " values, expected 1.." + std::to_string(max));
  out.resize(size_t(n));
  if (H5Aread(attr.get(), H5T_NATIVE_INT64, out.data()) < 0) {
    out.clear();
    return fail(Status::Corrupt, withLibraryMessage(what + " cannot be read"));
  }
  return Result::success();
}

}  // namespace tetstream::hdf5
