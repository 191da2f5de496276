#include "geometry_sync.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <type_traits>

namespace tetstream::viewer {
namespace {

// Slots of stale data a run may carry between two changed slots rather than start a new one.
constexpr uint32_t kRunGap = 4;

struct Run {
  uint32_t begin, count;
};

// Sorted runs over the listed slots below `count` (the lists may name slots past it, and repeat).
std::vector<Run> runsOf(std::span<const uint32_t> changed, uint32_t count) {
  std::vector<uint32_t> slots;
  slots.reserve(changed.size());
  for (uint32_t s : changed)
    if (s < count) slots.push_back(s);
  std::sort(slots.begin(), slots.end());
  std::vector<Run> runs;
  for (uint32_t s : slots) {
    if (!runs.empty() && s < runs.back().begin + runs.back().count + kRunGap) {
      runs.back().count = std::max(runs.back().count, s + 1 - runs.back().begin);
      continue;
    }
    runs.push_back({s, 1});
  }
  return runs;
}

template <class T>
void put(std::vector<uint8_t>& out, const T& v) {
  const auto* p = reinterpret_cast<const uint8_t*>(&v);
  out.insert(out.end(), p, p + sizeof(T));
}

// `count` elements of `width` values each from element `begin`.
template <class T>
void putRange(std::vector<uint8_t>& out, std::span<const T> data, uint32_t width, uint32_t begin, uint32_t count) {
  const auto* p = reinterpret_cast<const uint8_t*>(data.data() + size_t(begin) * width);
  out.insert(out.end(), p, p + size_t(count) * width * sizeof(T));
}

void writeSurface(const IncrementalIsosurface& s, std::vector<uint8_t>& out) {
  const uint32_t slots = s.vertexSlotCount(), triangles = s.triangleCount();
  // An emptied surface (the slice turned off, a reset) goes whole: it costs nothing, and a
  // partial update never shrinks the vertex slots the mirror's triangles refer to.
  const bool full = s.fullUploadNeeded() || slots == 0;
  put(out, slots);
  put(out, triangles);
  put(out, s.vertexCount());
  put(out, s.area());
  put(out, uint8_t(full));
  if (full) {
    putRange(out, s.positions(), 3, 0, slots);
    putRange(out, s.normals(), 3, 0, slots);
    putRange(out, s.colours(), 1, 0, slots);
    putRange(out, s.indices(), 3, 0, triangles);
    return;
  }
  const std::vector<Run> vertexRuns = runsOf(s.changedVertices(), slots);
  put(out, uint32_t(vertexRuns.size()));
  for (const Run& r : vertexRuns) {
    put(out, r.begin);
    put(out, r.count);
    putRange(out, s.positions(), 3, r.begin, r.count);
    putRange(out, s.normals(), 3, r.begin, r.count);
    putRange(out, s.colours(), 1, r.begin, r.count);
  }
  const std::vector<Run> triangleRuns = runsOf(s.changedTriangles(), triangles);
  put(out, uint32_t(triangleRuns.size()));
  for (const Run& r : triangleRuns) {
    put(out, r.begin);
    put(out, r.count);
    putRange(out, s.indices(), 3, r.begin, r.count);
  }
}

void writeHull(const HullTracker& h, std::vector<uint8_t>& out) {
  const uint32_t triangles = h.triangleCount(), lines = h.lineCount();
  put(out, triangles);
  put(out, lines);
  put(out, uint8_t(h.fullUploadNeeded()));
  if (h.fullUploadNeeded()) {
    putRange(out, h.trianglePositions(), 9, 0, triangles);
    putRange(out, h.triangleNormals(), 9, 0, triangles);
    putRange(out, h.lineVertices(), 6, 0, lines);
    return;
  }
  const std::vector<Run> triangleRuns = runsOf(h.changedTriangles(), triangles);
  put(out, uint32_t(triangleRuns.size()));
  for (const Run& r : triangleRuns) {
    put(out, r.begin);
    put(out, r.count);
    putRange(out, h.trianglePositions(), 9, r.begin, r.count);
    putRange(out, h.triangleNormals(), 9, r.begin, r.count);
  }
  const std::vector<Run> lineRuns = runsOf(h.changedLines(), lines);
  put(out, uint32_t(lineRuns.size()));
  for (const Run& r : lineRuns) {
    put(out, r.begin);
    put(out, r.count);
    putRange(out, h.lineVertices(), 6, r.begin, r.count);
  }
}

}  // namespace

void writeDelta(const IncrementalIsosurface* surface, const IncrementalIsosurface* slice, const HullTracker* hull,
                std::vector<uint8_t>& out) {
  put(out, uint8_t((surface ? kDeltaSurface : 0) | (slice ? kDeltaSlice : 0) | (hull ? kDeltaHull : 0)));
  if (surface) writeSurface(*surface, out);
  if (slice) writeSurface(*slice, out);
  if (hull) writeHull(*hull, out);
}

void SurfaceMirror::clearChanges() {
  fullUpload_ = false;
  changedVertices_.clear();
  changedTriangles_.clear();
}

void SurfaceMirror::clear() { *this = SurfaceMirror{}; }

size_t SurfaceMirror::memoryBytes() const {
  return (positions_.capacity() + normals_.capacity() + colours_.capacity()) * sizeof(float) +
         (indices_.capacity() + changedVertices_.capacity() + changedTriangles_.capacity()) * sizeof(uint32_t);
}

void HullMirror::clearChanges() {
  fullUpload_ = false;
  changedTriangles_.clear();
  changedLines_.clear();
}

void HullMirror::clear() { *this = HullMirror{}; }

size_t HullMirror::memoryBytes() const {
  return (positions_.capacity() + normals_.capacity() + lines_.capacity()) * sizeof(float) +
         (changedTriangles_.capacity() + changedLines_.capacity()) * sizeof(uint32_t);
}

// Reads a delta twice: once to check every count against the bytes and the arrays (nothing
// changes), then to copy.
class DeltaReader {
 public:
  DeltaReader(std::span<const uint8_t> bytes, bool write) : bytes_(bytes), write_(write) {}

  bool read(SurfaceMirror& surface, SurfaceMirror& slice, HullMirror& hull, DeltaApplied& applied) {
    uint8_t parts = 0;
    if (!get(parts) || (parts & ~uint8_t(kDeltaSurface | kDeltaSlice | kDeltaHull))) return fail("unknown parts");
    if ((parts & kDeltaSurface) && !readSurface(surface)) return false;
    if ((parts & kDeltaSlice) && !readSurface(slice)) return false;
    if ((parts & kDeltaHull) && !readHull(hull)) return false;
    if (at_ != bytes_.size()) return fail("bytes past its end");
    applied = {(parts & kDeltaSurface) != 0, (parts & kDeltaSlice) != 0, (parts & kDeltaHull) != 0};
    return true;
  }
  const std::string& error() const { return error_; }

 private:
  bool fail(const char* what) {
    error_ = std::string("a malformed geometry update: ") + what;
    return false;
  }

  template <class T>
  bool get(T& v) {
    if (bytes_.size() - at_ < sizeof(T)) return fail("truncated");
    std::memcpy(&v, bytes_.data() + at_, sizeof(T));
    at_ += sizeof(T);
    return true;
  }

  // `count` elements of `width` values into `dst` from element `begin` (dst holds `size` elements).
  // below: when not 0, every value must be less (triangle corners: the vertex slots).
  template <class T>
  bool getRange(std::vector<T>& dst, uint32_t width, uint32_t begin, uint32_t count, uint32_t size,
                uint32_t below = 0) {
    if (uint64_t(begin) + count > size) return fail("a run past the arrays");
    const size_t n = size_t(count) * width * sizeof(T);
    if (bytes_.size() - at_ < n) return fail("truncated");
    if constexpr (std::is_same_v<T, uint32_t>) {
      for (size_t k = 0; below && k < size_t(count) * width; ++k) {
        uint32_t v = 0;
        std::memcpy(&v, bytes_.data() + at_ + 4 * k, 4);
        if (v >= below) return fail("a triangle past the vertices");
      }
    }
    if (write_ && n) std::memcpy(dst.data() + size_t(begin) * width, bytes_.data() + at_, n);
    at_ += n;
    return true;
  }

  // Runs of `widths` values per slot into `arrays`, slots listed in `changed`.
  template <class T, size_t N>
  bool getRuns(std::array<std::vector<T>*, N> arrays, std::array<uint32_t, N> widths, uint32_t size,
               std::vector<uint32_t>& changed, uint32_t below = 0) {
    uint32_t runs = 0;
    if (!get(runs)) return false;
    for (uint32_t k = 0; k < runs; ++k) {
      uint32_t begin = 0, count = 0;
      if (!get(begin) || !get(count)) return false;
      for (size_t a = 0; a < N; ++a)
        if (!getRange(*arrays[a], widths[a], begin, count, size, below)) return false;
      if (write_)
        for (uint32_t s = begin; s < begin + count; ++s) changed.push_back(s);
    }
    return true;
  }

  bool readSurface(SurfaceMirror& m) {
    uint32_t slots = 0, triangles = 0, live = 0;
    double area = 0;
    uint8_t full = 0;
    if (!get(slots) || !get(triangles) || !get(live) || !get(area) || !get(full)) return false;
    // Every slot and triangle costs bytes in a full delta; a partial one grows the arrays by at
    // most what the model grew (slots beyond the data are refused by the runs' checks).
    if (full && (uint64_t(slots) * 28 + uint64_t(triangles) * 12 > bytes_.size() - at_)) return fail("truncated");
    if (!full && (uint64_t(slots) > (uint64_t(1) << 28) || uint64_t(triangles) > (uint64_t(1) << 28)))
      return fail("absurd counts");
    // Vertex slots only grow between full updates (the triangles kept refer to them).
    if (!full && slots < m.vertexSlotCount()) return fail("vertex slots shrank");
    if (write_) {
      m.positions_.resize(size_t(slots) * 3);
      m.normals_.resize(size_t(slots) * 3);
      m.colours_.resize(slots);
      m.indices_.resize(size_t(triangles) * 3);
      m.liveVertices_ = live;
      m.area_ = area;
    }
    if (full) {
      if (!getRange(m.positions_, 3, 0, slots, slots) || !getRange(m.normals_, 3, 0, slots, slots) ||
          !getRange(m.colours_, 1, 0, slots, slots) || !getRange(m.indices_, 3, 0, triangles, triangles, slots))
        return false;
      if (write_) {
        m.fullUpload_ = true;
        m.changedVertices_.clear();
        m.changedTriangles_.clear();
      }
    } else {
      if (!getRuns<float, 3>({&m.positions_, &m.normals_, &m.colours_}, {3, 3, 1}, slots, m.changedVertices_) ||
          !getRuns<uint32_t, 1>({&m.indices_}, {3}, triangles, m.changedTriangles_, slots))
        return false;
    }
    return true;
  }

  bool readHull(HullMirror& m) {
    uint32_t triangles = 0, lines = 0;
    uint8_t full = 0;
    if (!get(triangles) || !get(lines) || !get(full)) return false;
    if (full && (uint64_t(triangles) * 72 + uint64_t(lines) * 24 > bytes_.size() - at_)) return fail("truncated");
    if (!full && (uint64_t(triangles) > (uint64_t(1) << 28) || uint64_t(lines) > (uint64_t(1) << 28)))
      return fail("absurd counts");
    if (write_) {
      m.positions_.resize(size_t(triangles) * 9);
      m.normals_.resize(size_t(triangles) * 9);
      m.lines_.resize(size_t(lines) * 6);
    }
    if (full) {
      if (!getRange(m.positions_, 9, 0, triangles, triangles) || !getRange(m.normals_, 9, 0, triangles, triangles) ||
          !getRange(m.lines_, 6, 0, lines, lines))
        return false;
      if (write_) {
        m.fullUpload_ = true;
        m.changedTriangles_.clear();
        m.changedLines_.clear();
      }
      return true;
    }
    return getRuns<float, 2>({&m.positions_, &m.normals_}, {9, 9}, triangles, m.changedTriangles_) &&
           getRuns<float, 1>({&m.lines_}, {6}, lines, m.changedLines_);
  }

  std::span<const uint8_t> bytes_;
  bool write_;
  size_t at_ = 0;
  std::string error_;
};

bool applyDelta(std::span<const uint8_t> bytes, SurfaceMirror& surface, SurfaceMirror& slice, HullMirror& hull,
                DeltaApplied& applied, std::string& error) {
  DeltaReader check(bytes, false);  // reads the mirrors' sizes, writes nothing
  if (!check.read(surface, slice, hull, applied)) {
    error = check.error();
    return false;
  }
  DeltaReader copy(bytes, true);
  if (!copy.read(surface, slice, hull, applied)) {
    error = copy.error();
    return false;
  }
  return true;
}

}  // namespace tetstream::viewer
