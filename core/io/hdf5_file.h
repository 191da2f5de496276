// An HDF5 file opened read-only through the HDF5 library, for the readers of formats that keep
// their data in HDF5 (XDMF heavy data, VTKHDF). Every failure is a Result naming the file and the
// object; the library's own error stack is never printed (its innermost message goes into ours).
//
// Sizes are checked before anything is allocated: a read names how many values it expects, and
// a dataset whose shape says more than its storage can hold (a damaged or forged file) is refused
// rather than read as fill values.
#pragma once
#include <hdf5.h>

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "status.h"

namespace tetstream::hdf5 {

// One HDF5 identifier, closed with its own close function when the object goes.
class Handle {
 public:
  Handle() = default;
  Handle(hid_t id, herr_t (*close)(hid_t)) : id_(id), close_(close) {}
  Handle(Handle&& o) noexcept : id_(o.id_), close_(o.close_) { o.id_ = H5I_INVALID_HID; }
  Handle& operator=(Handle&& o) noexcept {
    if (this != &o) {
      reset();
      id_ = o.id_;
      close_ = o.close_;
      o.id_ = H5I_INVALID_HID;
    }
    return *this;
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  ~Handle() { reset(); }
  hid_t get() const { return id_; }
  bool valid() const { return id_ >= 0; }
  void reset() {
    if (id_ >= 0 && close_) close_(id_);
    id_ = H5I_INVALID_HID;
  }

 private:
  hid_t id_ = H5I_INVALID_HID;
  herr_t (*close_)(hid_t) = nullptr;
};

// The shape of a dataset: its dimensions, slowest first, and the kind of its elements.
struct Shape {
  std::vector<uint64_t> dims;
  bool isFloat = false;    // H5T_FLOAT
  bool isInteger = false;  // H5T_INTEGER
  uint64_t count() const;  // product of dims (1 for a scalar dataspace)
};

// A selection of a dataset: per dimension the first index, the step and how many. Empty: all.
struct Slab {
  std::vector<uint64_t> start, stride, count;
  bool all() const { return start.empty(); }
};

// True when the bytes start with HDF5's signature (at offset 0, where every writer puts it
// unless a user block comes first).
bool hasSignature(std::string_view head);

class File {
 public:
  // Opens `path` read-only. IoError when it cannot be opened, BadMagic when it is not HDF5,
  // Truncated/Corrupt when the library refuses it (its message is included).
  Result open(const std::string& path);
  const std::string& path() const { return path_; }

  // Whether `object` (a path such as "/VTKHDF/PointData") names a group or a dataset of this
  // file (links into other files count as absent).
  bool exists(const std::string& object) const;
  bool isGroup(const std::string& object) const;
  // The names of a group's members, in name order.
  Result members(const std::string& group, std::vector<std::string>& names) const;

  Result shape(const std::string& dataset, Shape& out) const;
  // Reads `slab` of a numeric dataset (all of it when empty), converted by the library to
  // double / int64. `expect` is the number of values the caller needs; the read fails unless the
  // selection holds exactly that many.
  Result readDoubles(const std::string& dataset, const Slab& slab, uint64_t expect, std::vector<double>& out) const;
  Result readInts(const std::string& dataset, const Slab& slab, uint64_t expect, std::vector<int64_t>& out) const;
  // Rows [first, first + rows) of a dataset of rank 1 or 2 (all columns of a 2D one).
  Slab rows(const Shape& shape, uint64_t first, uint64_t count) const;

  // Attributes of a group or dataset: a string (fixed or variable length, trailing NULs and
  // spaces dropped) and up to `max` integers.
  Result stringAttribute(const std::string& object, const char* name, std::string& out) const;
  Result intAttribute(const std::string& object, const char* name, std::vector<int64_t>& out, size_t max = 16) const;
  bool hasAttribute(const std::string& object, const char* name) const;

  // "file.h5: dataset '/a/b'" for messages.
  std::string where(const std::string& object, const char* kind = "dataset") const;

 private:
  // Whether `object` is in this file, missing, or behind a link into another file.
  enum class Found { Here, Missing, OtherFile };
  Found find(const std::string& object) const;
  // Opens the dataset and selects `slab` in it, checked against its shape and storage.
  Result select(const std::string& dataset, const Slab& slab, uint64_t expect, Handle& ds, Handle& fileSpace,
                Handle& memSpace) const;
  // Opens attribute `name` of `object` with its type and space; `what` names it in messages.
  Result openAttribute(const std::string& object, const char* name, const std::string& what, Handle& attr, Handle& type,
                       Handle& space) const;
  template <typename T>
  Result readSelection(const std::string& dataset, const Slab& slab, uint64_t expect, hid_t memType,
                       std::vector<T>& out) const;

  std::string path_;
  Handle file_;
};

// The innermost message of HDF5's current error stack ("" when there is none), then clears it.
std::string lastError();

}  // namespace tetstream::hdf5
