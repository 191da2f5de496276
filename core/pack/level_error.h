// The field error of every level of the stream, measured at the input's vertices: how far the
// level's piecewise-linear field, interpolated at each input vertex, lies from the input's value
// there (the figure the benchmarks compare with VTK). The encoder drives it while it replays the
// splits, so the manifest can give each chunk's level a measured RMS and maximum over every input
// vertex; the simplifier's per-collapse estimate (fieldError) is no bound: a level's measured
// largest error can exceed it.
//
// Every input vertex stays located in a tet of the level mesh. A split changes only the tets
// T_moved (j becomes i) and adds T_new around the new edge (i, j); together they cover exactly
// what T_moved covered before (paper §4.3's locality). So a split only marks its moved tets
// dirty (and the tets around j when j's value changed); a measurement runs through the input
// vertices in order, on two threads, and tests those in dirty tets there; those no longer inside
// walk from it to the tet that holds them now. Each vertex is tested at most once a measurement
// however many splits its tet went through. (A sample of vertices followed split by split takes
// about the same time and misses the largest errors, which lie at few vertices.)
// An input vertex outside the level mesh (where a coarse level cuts across a curved or
// non-convex boundary) takes the tet it is least outside of among those near where a walk
// towards it ends, with its coordinates clamped to that tet; as splits move the boundary, those
// are walked again from there at each measurement.
#pragma once
#include <cmath>
#include <cstdint>
#include <span>
#include <thread>
#include <vector>

#include "progressive.h"

namespace tetstream {

struct LevelError {
  double rms = 0, max = 0;  // in units of the field, over the input vertices with a finite value
};

class LevelErrorMeter {
 public:
  // `positions` and `values`: the input's (3 and 1 per input vertex); `level`: the base level,
  // whose field `field` is measured. levelOf[v]: input vertex v's id in the base, or ~0u when v
  // was collapsed; then baseOf[v] is the input vertex of the base it was collapsed into (directly
  // or not), around which it lies, and intoOf[v] the one it was collapsed into directly. Locates
  // every input vertex; total() is then the base's error. May run on another thread while
  // afterSplit() is called (which touches nothing begin() does), as long as current() comes after
  // both. The meter keeps `intoOf`.
  void begin(std::span<const float> positions, std::span<const float> values, const TetMesh& level, size_t field,
             std::vector<uint32_t> levelOf, std::span<const uint32_t> baseOf, std::span<const uint32_t> intoOf);
  LevelError total() const;
  // The error of the last measurement (begin() or current()) by group: out[g] over the input
  // vertices v with groupOf(v) = g (out sized by the caller; groups past its end are skipped).
  template <typename GroupOf>
  void totalByGroup(GroupOf groupOf, std::vector<LevelError>& out) const {
    std::vector<double> sum(out.size(), 0.0);
    std::vector<uint32_t> count(out.size(), 0);
    for (uint32_t v = 0; v < samples_.size(); ++v) {
      const Sample& s = samples_[v];
      const uint32_t g = groupOf(v);
      if (g >= out.size() || s.tet == kNone || !std::isfinite(s.err)) continue;
      sum[g] += double(s.err) * s.err;
      out[g].max = std::max(out[g].max, double(s.err));
      ++count[g];
    }
    for (size_t g = 0; g < out.size(); ++g) out[g].rms = count[g] ? std::sqrt(sum[g] / count[g]) : 0.0;
  }

  // After applySplit() restored input vertex `input` next to level vertex j, moving the listed
  // tets from j to the new vertex (`stars`: the level's). When the split gave p_j a value back,
  // every tet around j interpolates anew. Only notes what changed.
  void afterSplit(uint32_t input, uint32_t j, std::span<const uint32_t> moved, const StarPool& stars,
                  bool jValueChanged);

  // The error of the level now: `level` is the mesh the splits were applied to (begin()'s, or a
  // copy of it that went on), `stars` its vertices' tets. On two threads when `threads` > 1 and
  // the input is large; the figures are the same on one.
  LevelError current(const TetMesh& level, const StarPool& stars, int threads = 2);

 private:
  static constexpr uint32_t kNone = ~uint32_t(0);
  static constexpr uint32_t kVertex =
      kNone - 1;  // Sample::tet of an input vertex that is a level vertex (kNone: unplaced)
  // A point counts as inside a tet when its smallest coordinate is at least this: points on a
  // face (every input vertex on the boundary of a box) are not outside by round-off.
  static constexpr double kInside = -1e-9;

  // A tet's barycentric coordinates as affine functions of the point: set up once per tet, a
  // point then costs three dot products, and most tets are rejected after the first.
  struct TetFrame {
    double p0[3], r[3][3];
    bool make(const LevelErrorMeter& m, uint32_t t);  // false for a flat tet
    // The coordinates of x; returns the smallest. Returns early, with the rest of l unset, as
    // soon as one is below `stopBelow`.
    double coordinates(const float* x, double l[4], double stopBelow = -HUGE_VAL) const;
  };

  // What a thread has worked out in one measurement (the geometry changes between): the frames
  // of the tets it met and the tets across their faces. Input vertices next to each other walk
  // the same way, so these are asked for again and again.
  struct Scratch {
    struct FrameSlot {
      TetFrame frame;
      uint32_t tet = ~0u, epoch = 0;
      bool solid = false;
    };
    struct AcrossSlot {
      uint32_t face = ~0u, epoch = 0, tet = 0;
    };
    std::vector<FrameSlot> frames;
    std::vector<AcrossSlot> across;
    uint32_t epoch = 0;
    void next() {
      if (frames.empty()) frames.resize(4096), across.resize(8192);
      ++epoch;
    }
  };
  Scratch scratch_[2];  // one per thread of a measurement
  const TetFrame* frameOf(Scratch& s, uint32_t t) const;
  uint32_t acrossByStars(Scratch& s, uint32_t t, int k) const;
  uint32_t acrossByStarsUncached(uint32_t t, int k) const;

  // Where a search put an input vertex: its tet (kNone: none found), its error there, and
  // whether it lies outside the level mesh (then its coordinates were clamped to the tet).
  struct Found {
    uint32_t tet;
    float err;
    bool outside;
    double lo;  // the smallest coordinate of v in the tet
  };
  Found walk(Scratch& s, uint32_t v) const;
  template <typename Tets>
  bool lookAmong(Scratch& s, uint32_t v, const Tets& tets, Found& found) const;
  Found locateAgain(Scratch& s, uint32_t v) const;
  Found nearby(Scratch& s, uint32_t v, Found walked) const;  // (locateAgain's second step)
  void place(uint32_t v, const Found& f);
  float errorAt(uint32_t v, uint32_t t, const double l[4]) const;
  void becomeVertex(uint32_t v, uint32_t level);
  void follow(Scratch& s, uint32_t begin, uint32_t end);
  void markDirty(uint32_t t);

  // Per input vertex, in one place.
  struct Sample {
    float x[3], value;  // the input's position and value
    float err;          // |interpolated − value|
    uint32_t tet;       // its tet in the level mesh, kVertex, or kNone (not measured)
  };
  std::vector<Sample> samples_;
  std::vector<uint8_t> outside_;     // per input vertex: outside the level mesh (clamped)
  const TetMesh* mesh_ = nullptr;    // the level mesh
  const StarPool* stars_ = nullptr;  // its vertices' tets
  size_t field_ = 0;
  const std::vector<float>& levelValues() const { return mesh_->fields[field_].values; }
  std::vector<uint32_t> inputOf_;     // per level vertex: the input vertex it is
  std::vector<uint32_t> levelOf_;     // per input vertex: the level vertex it is, or kNone
  std::span<const uint32_t> intoOf_;  // per input vertex: the one it was collapsed into (begin())
  // What the splits since the last measurement changed (afterSplit(), which may run while begin()
  // does): the input vertices they restored, in level vertex order; the level vertices given a
  // new value; per level tet, whether its input vertices are to be tested again.
  std::vector<uint32_t> restored_, revalued_;
  std::vector<uint64_t> dirty_;

  // f(0) and f(1), on two threads when `two`, else one after the other. Two from this many input
  // vertices on: below, starting a thread costs more than it saves.
  static constexpr uint32_t kTwoThreads = 16384;
  template <typename F>
  static void onTwo(bool two, F f) {
    if (!two) return f(0), f(1);
    std::thread second(f, 1);
    f(0);
    second.join();
  }
};

}  // namespace tetstream
