// The surface, slice and hull cross from the refinement worker to the page as deltas: what the
// model's trackers (IncrementalIsosurface, HullTracker) wrote since their last clearChanges(),
// in runs of slots with their data, or everything after a full extraction. The page keeps a
// mirror of each (the same arrays, the same change lists), which the renderer uploads exactly
// as it would the trackers themselves. Both sides are the same wasm program, so numbers are
// written in its byte order and read back with the same layout.
//
// Delta layout (one message): u8 parts (bit 0 surface, 1 slice, 2 hull), then each part present:
//   surface/slice: u32 vertex slots, u32 triangles, u32 live vertices, f64 area, u8 full;
//     full: positions (3 f32 per slot), normals (3 f32), colours (1 f32), indices (3 u32 per
//     triangle); else u32 vertex runs {u32 begin, u32 count, positions, normals, colours of
//     those slots}, u32 triangle runs {u32 begin, u32 count, indices}.
//   hull: u32 triangles, u32 lines, u8 full; full: corner positions (9 f32 per triangle),
//     corner normals (9 f32), line vertices (6 f32 per line); else u32 triangle runs {begin,
//     count, positions, normals}, u32 line runs {begin, count, line vertices}.
// A run also carries the stale slots between two changed ones when the gap is short (fewer
// bytes than a new run's header, and one upload instead of two); stale slots are never drawn.
// GL-free, so the round trip is unit-tested natively.
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "hull.h"
#include "isosurface_incremental.h"

namespace tetstream::viewer {

enum DeltaPart : uint8_t { kDeltaSurface = 1, kDeltaSlice = 2, kDeltaHull = 4 };

// Appends what changed in each given tracker (null: not part of this delta) to `out`; clears
// nothing (the caller calls clearChanges() once the delta is written).
void writeDelta(const IncrementalIsosurface* surface, const IncrementalIsosurface* slice, const HullTracker* hull,
                std::vector<uint8_t>& out);

// The page's copy of an IncrementalIsosurface, with the accessors the renderer uses.
class SurfaceMirror {
 public:
  std::span<const float> positions() const { return positions_; }
  std::span<const float> normals() const { return normals_; }
  std::span<const float> colours() const { return colours_; }
  std::span<const uint32_t> indices() const { return indices_; }
  uint32_t vertexSlotCount() const { return uint32_t(colours_.size()); }
  uint32_t triangleCount() const { return uint32_t(indices_.size() / 3); }
  uint32_t vertexCount() const { return liveVertices_; }
  double area() const { return area_; }

  bool fullUploadNeeded() const { return fullUpload_; }
  std::span<const uint32_t> changedVertices() const { return changedVertices_; }
  std::span<const uint32_t> changedTriangles() const { return changedTriangles_; }
  void clearChanges();

  // Forgets everything (a new dataset): the next upload is full.
  void clear();
  size_t memoryBytes() const;

 private:
  friend class DeltaReader;
  std::vector<float> positions_, normals_, colours_;
  std::vector<uint32_t> indices_;
  uint32_t liveVertices_ = 0;
  double area_ = 0;
  bool fullUpload_ = true;
  std::vector<uint32_t> changedVertices_, changedTriangles_;
};

// The page's copy of a HullTracker, with the accessors the renderer uses.
class HullMirror {
 public:
  uint32_t triangleCount() const { return uint32_t(positions_.size() / 9); }
  uint32_t lineCount() const { return uint32_t(lines_.size() / 6); }
  std::span<const float> trianglePositions() const { return positions_; }
  std::span<const float> triangleNormals() const { return normals_; }
  std::span<const float> lineVertices() const { return lines_; }

  bool fullUploadNeeded() const { return fullUpload_; }
  std::span<const uint32_t> changedTriangles() const { return changedTriangles_; }
  std::span<const uint32_t> changedLines() const { return changedLines_; }
  void clearChanges();

  void clear();
  size_t memoryBytes() const;

 private:
  friend class DeltaReader;
  std::vector<float> positions_, normals_, lines_;
  bool fullUpload_ = true;
  std::vector<uint32_t> changedTriangles_, changedLines_;
};

// What applyDelta changed.
struct DeltaApplied {
  bool surface = false, slice = false, hull = false;
};

// Applies one delta (writeDelta's output) to the mirrors. A malformed delta (truncated, counts
// past the data, runs past the arrays) changes nothing and returns false with the reason.
bool applyDelta(std::span<const uint8_t> bytes, SurfaceMirror& surface, SurfaceMirror& slice, HullMirror& hull,
                DeltaApplied& applied, std::string& error);

}  // namespace tetstream::viewer
