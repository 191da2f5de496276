// The rows of points a share of a file's cells reads. Its cells name points by id; reading the
// run from the smallest id to the largest is one partial read, but when the file numbers its
// points far from its cells' order (a run of cells using points from all over the file, as
// solvers that number points and cells each their own way write them), that run is nearly every
// point, on every process. Then only the points the cells use are read, a window of rows at a
// time where the format can read a window for the cost of the window (appended raw VTK data,
// HDF5 hyperslabs), so that what a process holds is its share, not the file.
#pragma once
#include <algorithm>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "status.h"

namespace tetstream::io {

// Picked rows are read in windows of this many rows, each from the first picked row not read yet.
inline constexpr uint64_t kPickWindow = uint64_t(1) << 20;

// The rows of a run [first, first + count) that a share's cells use: a bit a row, and per 64 rows
// the count of used rows before them, so that a row's place among the used costs a popcount
// (1.5 bits a row of the run).
class UsedRows {
 public:
  UsedRows(uint64_t first, uint64_t count);
  // Row `id` (inside the run) is used.
  void mark(uint64_t id) { bits_[(id - first_) / 64] |= uint64_t(1) << ((id - first_) % 64); }
  // Once every row is marked: counts them.
  void finish();
  uint64_t used() const { return used_; }
  bool all() const { return used_ == count_; }
  bool isUsed(uint64_t id) const { return bits_[(id - first_) / 64] >> ((id - first_) % 64) & 1; }
  // The place of used row `id` among the used rows (after finish()).
  uint64_t place(uint64_t id) const;
  // Where row `id` is among the used rows; -1 when it lies outside the run or is not used.
  int64_t placeOf(uint64_t id) const {
    return id >= first_ && id - first_ < count_ && isUsed(id) ? int64_t(place(id)) : -1;
  }
  // The used rows, ascending.
  std::vector<uint64_t> rows() const;

 private:
  uint64_t first_, count_, used_ = 0;
  std::vector<uint64_t> bits_;
  std::vector<uint64_t> before_;
};

// `ids`: the point ids a run of cells names, all in the run [first, first + count). Returns the
// ids it uses, ascending, and renumbers `ids` to their places among them; or, when they use every
// point of the run, returns nothing and makes `ids` relative to `first`.
std::vector<uint64_t> pickUsedRows(std::vector<int64_t>& ids, uint64_t first, uint64_t count);

// Of an array of `rowCount` rows, the rows in `pick` (ascending), one after another in `out`.
// read(from, n, window) reads rows [from, from + n) into `window` (a whole number of values per
// row); with `byWindow` it is called for windows of kPickWindow rows from each first picked row
// not read yet, else once, from the first picked row to the last.
template <class T, class Read>
Result readPickedRows(std::span<const uint64_t> pick, uint64_t rowCount, bool byWindow, const std::string& what,
                      Read&& read, std::vector<T>& out) {
  out.clear();
  std::vector<T> window;
  for (size_t k = 0; k < pick.size();) {
    const uint64_t from = pick[k], n = byWindow ? std::min(kPickWindow, rowCount - from) : pick.back() + 1 - from;
    if (Result r = read(from, n, window); !r) return r;
    if (n == 0 || window.size() % n != 0)
      return fail(Status::Corrupt, what + ": " + std::to_string(window.size()) + " values for " + std::to_string(n) +
                                       " rows (expected a whole number per row)");
    const uint64_t per = window.size() / n;
    if (out.empty()) out.reserve(pick.size() * per);
    for (; k < pick.size() && pick[k] < from + n; ++k) {
      const auto row = window.begin() + std::ptrdiff_t((pick[k] - from) * per);
      out.insert(out.end(), row, row + std::ptrdiff_t(per));
    }
  }
  return Result::success();
}

}  // namespace tetstream::io
