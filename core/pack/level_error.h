// The field error of every level of the stream, measured at the input's vertices: how far the
// level's piecewise-linear field, interpolated at each input vertex, lies from the input's value
// there (the figure the benchmarks compare with VTK). The encoder drives it while it replays the
// splits, so the manifest can give each chunk's level a measured RMS and maximum; the
// simplifier's per-collapse estimate (fieldError) is no bound: carotid's base measures a largest
// error of 252 against an estimate of 239.
//
// Every input vertex stays located in a tet of the level mesh. A split changes only the tets
// T_moved (j becomes i) and adds T_new around the new edge (i, j); together they cover exactly
// what T_moved covered before. So only the input vertices inside T_moved are located again, among
// T_new and T_moved; the rest keep their tet (paper §4.3's locality, applied to the samples).
// An input vertex outside the level mesh (where a coarse level cuts across a curved or
// non-convex boundary) takes the tet at which a walk towards it leaves the mesh, with its
// coordinates clamped to that tet; as splits move the boundary, those are walked again from
// there before each measurement.
#pragma once
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "progressive.h"

namespace tetstream {

struct LevelError {
  double rms = 0, max = 0;  // in units of the field, over the input vertices with a finite value
};

class LevelErrorMeter {
 public:
  // `positions` and `values`: the input's (3 and 1 per input vertex); `level`: the base level,
  // whose field `field` is measured, and `stars` its vertices' tets: the encoder's ProgressiveMesh,
  // read again at every split (afterSplit). levelOf[v]: input vertex v's id in the base, or ~0u
  // when v was collapsed; then baseOf[v] is the input vertex of the base it was collapsed into
  // (directly or not), where the search for its tet starts. Only an even sample of maxSamples
  // input vertices is followed (all of them in smaller meshes): on the encoder's thread,
  // following all 262,144 vertices of Harmonic 64³ cost half as much time as encoding did;
  // 16,384 add 0.15 s to its 1 s and give the RMS within 2% at every level.
  void begin(std::span<const float> positions, std::span<const float> values, const TetMesh& level, const StarPool* stars,
             size_t field, std::span<const uint32_t> levelOf, std::span<const uint32_t> baseOf, uint32_t maxSamples);
  static constexpr uint32_t kMaxSamples = 16384;

  // The error of a base level at every input vertex (no stars needed), e.g. on another thread.
  static LevelError measure(std::span<const float> positions, std::span<const float> values, const TetMesh& level,
                            size_t field, std::span<const uint32_t> levelOf, std::span<const uint32_t> baseOf);

  // After applySplit() restored input vertex `input` next to level vertex j, moving the listed
  // tets from j to the new vertex and appending tets from `firstNew` on. When the split gave p_j
  // a value back, every tet around j interpolates anew.
  void afterSplit(uint32_t input, uint32_t j, std::span<const uint32_t> moved, uint32_t firstNew, bool jValueChanged);

  // The error of the level now (after relocating the input vertices outside it).
  LevelError current();

 private:
  static constexpr uint32_t kNone = ~uint32_t(0);
  static constexpr uint32_t kVertex = kNone - 2;  // Sample::tet of an input vertex that is a level vertex
  static constexpr uint32_t kSkip = kNone - 1;    // ... of one left out of the sample (and kNone: unplaced)

  // A tet's barycentric coordinates as affine functions of the point: set up once per tet, a
  // point then costs three dot products, and most tets are rejected after the first.
  struct TetFrame {
    double p0[3], r[3][3];
    bool make(const LevelErrorMeter& m, uint32_t t);  // false for a flat tet
    // The coordinates of x; returns the smallest. Returns early, with the rest of l unset, as
    // soon as one is below `stopBelow`.
    double coordinates(const float* x, double l[4], double stopBelow = -HUGE_VAL) const;
  };

  void link(uint32_t v, uint32_t t);
  void unlink(uint32_t v);
  void becomeVertex(uint32_t v, uint32_t level);
  void setError(uint32_t v, uint32_t t, const double l[4]);
  template <typename Across>
  double walk(uint32_t v, uint32_t t, Across across);
  uint32_t acrossByStars(uint32_t t, int k) const;
  void markOutside(uint32_t v, bool outside);
  void relocateOutside();
  void updateAroundJ(uint32_t j, bool jValueChanged);

  // Per input vertex, in one place (they are visited in no useful order).
  struct Sample {
    float x[3], value;    // the input's position and value
    float err;            // |interpolated − value|
    uint32_t tet;         // its tet in the level mesh, kVertex, or kNone (not measured)
    uint32_t next, prev;  // the others in its tet (a list per tet)
  };
  std::vector<Sample> samples_;
  const TetMesh* mesh_ = nullptr;    // the level mesh
  const StarPool* stars_ = nullptr;  // its vertices' tets
  size_t field_ = 0;
  const std::vector<float>& levelValues() const { return mesh_->fields[field_].values; }
  // A flat bit set: one that is tested for every tet a split moves fits in the cache.
  struct Bits {
    std::vector<uint64_t> words;
    void resize(size_t n) { words.resize((n + 63) / 64, 0); }
    bool test(size_t i) const { return words[i >> 6] >> (i & 63) & 1; }
    void set(size_t i) { words[i >> 6] |= uint64_t(1) << (i & 63); }
    void clear(size_t i) { words[i >> 6] &= ~(uint64_t(1) << (i & 63)); }
  };
  std::vector<uint32_t> head_;         // per level tet: its first input vertex, or kNone
  Bits occupied_;                      // per level tet: head_ is not kNone
  Bits sampled_;                       // per input vertex: in the sample
  Bits outside_, listed_;              // per input vertex: outside the level mesh; in outsideList_
  std::vector<uint32_t> outsideList_;
  std::vector<uint32_t> inputOf_;      // per level vertex: the input vertex it is
  std::vector<uint32_t> pending_, pendingFrom_, candidates_;  // (pendingFrom_: the old tet's place in candidates_)
  std::vector<TetFrame> frames_;
  std::vector<uint8_t> frameState_;
};

}  // namespace tetstream
