#include "pack/split_encode.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <deque>
#include <future>
#include <string>

#include "chunk.h"
#include "pack/chunk_encode.h"
#include "pack/level_error.h"
#include "pack/region_stats.h"
#include "pack/split_order.h"
#include "progressive.h"
#include "quantize.h"
#include "split_stream.h"
#include "varint.h"

namespace tetstream {
namespace {

constexpr uint32_t kNone = ~uint32_t(0);

void putU32(std::vector<uint8_t>& b, uint32_t x) {
  for (int i = 0; i < 4; ++i) b.push_back(uint8_t(x >> (8 * i)));
}

class Encoder {
 public:
  Encoder(const TetMesh& mesh, SimplifyResult& s, const Manifest& m, const StreamOptions& o, EncodedStream& out)
      : mesh_(mesh), s_(s), m_(m), opt_(o), out_(out), q_(makeQuantizer(m)) {}

  Result run() {
    buildBase();
    const CollapseLog& log = s_.log;
    const uint32_t C = log.size();
    // Estimated field error with a splits applied: the largest of the collapses still in place.
    prefixMax_.resize(C);
    // The estimate sums terms that can overshoot; no error exceeds the field's range.
    const int iso = m_.findField(m_.isoField);
    const float range = iso >= 0 ? m_.fields[size_t(iso)].range.max - m_.fields[size_t(iso)].range.min : 0.0f;
    range_ = range;
    for (uint32_t c = 0; c < C; ++c)
      prefixMax_[c] = std::min(range, std::max(c ? prefixMax_[c - 1] : 0.0f, log.fieldError[c]));
    out_.baseFieldError = C ? prefixMax_[C - 1] : 0;
    startMeter(iso);
    planNodes();
    // The base chunk compresses on another thread while the splits are encoded.
    std::future<Result> base = std::async(std::launch::async, [this] {
      out_.baseInfo.fieldError = out_.baseFieldError;
      return encodeBaseChunk(out_.base, 0, opt_.zstdLevel, out_.baseFile, out_.baseInfo);
    });
    Result r = encodeSplits(C);
    Result b = base.get();
    if (metered_) {
      const LevelError e = baseError();
      out_.baseInfo.fieldRms = e.rms;
      out_.baseInfo.fieldMax = e.max;
    }
    if (r && metered_ && !out_.chunks.empty()) measure(out_.chunks.back());  // the full level
    return r ? b : r;
  }

  // encodeUnit: the splits of a part's log from its handoff (split_encode.h). Nothing is
  // compressed; the chunks are kept raw in `unit`. The field error is measured by node at
  // uo.measureAt only.
  Result runUnit(const UnitEncodeOptions& uo, UnitEncoded& unit) {
    unit_ = &unit;
    unitRoot_ = !uo.topIsRegion;
    if (Result r = buildHandoff(uo); !r) return r;
    if (uo.measureAt) {
      if (uo.measureAt->size() != mesh_.vertexCount())
        return fail(Status::BadArgument, "encodeUnit: " + std::to_string(uo.measureAt->size()) +
                                             " vertices to measure at for a part of " +
                                             std::to_string(mesh_.vertexCount()));
      measureAt_ = uo.measureAt;
      startMeter(m_.findField(m_.isoField));
    }
    planNodes();
    Result r = encodeSplits(s_.log.size());
    if (metered_) baseError();  // (the meter reads out_.base on another thread until then)
    if (!r) return r;
    // Every vertex and tet alive at the part's start is in pm_ now: its stable id, for the units
    // whose handoffs are made of them.
    unit.startVertex.assign(out_.streamVertexOf.size(), kNoStable);
    for (size_t v = 0; v < out_.streamVertexOf.size(); ++v)
      if (out_.streamVertexOf[v] != kNone) unit.startVertex[v] = stableVertex(out_.streamVertexOf[v]);
    unit.startTet.assign(out_.streamTetOf.size(), kNoStable);
    for (size_t t = 0; t < out_.streamTetOf.size(); ++t)
      if (out_.streamTetOf[t] != kNone) unit.startTet[t] = stableTet(out_.streamTetOf[t]);
    unit.startValue.clear();
    if (s_.valuesField >= 0) {
      const std::vector<float>& now = pm_.mesh.fields[size_t(s_.valuesField)].values;
      unit.startValue.assign(out_.streamVertexOf.size(), std::numeric_limits<float>::quiet_NaN());
      for (size_t v = 0; v < out_.streamVertexOf.size(); ++v)
        if (out_.streamVertexOf[v] != kNone) unit.startValue[v] = now[out_.streamVertexOf[v]];
    }
    unit.handoff = std::move(out_.base);
    return Result::success();
  }

 private:
  static constexpr uint64_t kNoStable = ~uint64_t(0);
  // Counts and ids of the format stay below 2^31 (FORMAT.md §5); zz(j − j_prev) relies on it.
  static constexpr uint64_t kMaxStable = (uint64_t(1) << 31) - 1;

  // The stable id (FORMAT.md §1.1) of pm_'s vertex or tet. pm_ holds the handoff in ascending
  // stable order, then the unit's new ones, whose stable ids follow vertexBegin_/tetBegin_ in
  // creation order; all handoff ids lie below those, so the map is strictly increasing and every
  // order the format takes by id is the same in pm_'s ids. Only ids written into records need
  // it: the kept vertex and explicit new-tet vertices. In encodeStream the map is the identity
  // (no handoff ids, begins 0).
  uint32_t stableVertex(uint32_t v) const {
    const size_t H = handoffVertexStable_.size();
    return v < H ? handoffVertexStable_[v] : uint32_t(vertexBegin_ + (v - H));
  }
  uint32_t stableTet(uint32_t t) const {
    const size_t H = handoffTetStable_.size();
    return t < H ? handoffTetStable_[t] : uint32_t(tetBegin_ + (t - H));
  }

  // The handoff (the part's mesh at the end of its simplification) as pm_'s start: vertices and
  // tets in ascending stable id order, values as the reader sees them (as buildBase).
  Result buildHandoff(const UnitEncodeOptions& uo) {
    const uint32_t V = mesh_.vertexCount(), T = uint32_t(s_.tetAlive.size());
    if (uo.stableVertex.size() != V || uo.stableTet.size() != T || s_.vertexAlive.size() != V ||
        s_.tets.size() != 4 * size_t(T))
      return fail(Status::BadArgument, "encodeUnit: " + std::to_string(uo.stableVertex.size()) +
                                           " stable vertex ids and " + std::to_string(uo.stableTet.size()) +
                                           " stable tet ids for a part of " + std::to_string(V) + " vertices and " +
                                           std::to_string(T) + " tets");
    // Ascending by stable id; each below the unit's own, and distinct.
    auto order = [](const std::vector<uint8_t>& alive, const std::vector<uint64_t>& stable, uint64_t begin,
                    const char* what, const char* whats, std::vector<uint32_t>& ids,
                    std::vector<uint32_t>& stableOf) -> Result {
      ids.clear();
      for (uint32_t x = 0; x < alive.size(); ++x)
        if (alive[x]) ids.push_back(x);
      std::sort(ids.begin(), ids.end(), [&](uint32_t a, uint32_t b) { return stable[a] < stable[b]; });
      stableOf.resize(ids.size());
      for (size_t k = 0; k < ids.size(); ++k) {
        const uint64_t id = stable[ids[k]];
        if (id >= begin)
          return fail(Status::BadArgument, std::string("encodeUnit: ") + what + " " + std::to_string(ids[k]) +
                                               " of the handoff has stable id " +
                                               (id == kNoStable ? std::string("none") : std::to_string(id)) +
                                               ", not below the unit's first, " + std::to_string(begin));
        if (k && id == stableOf[k - 1])
          return fail(Status::BadArgument,
                      std::string("encodeUnit: two ") + whats + " of the handoff have stable id " + std::to_string(id));
        stableOf[k] = uint32_t(id);
      }
      return Result::success();
    };
    std::vector<uint32_t> vertices, tets;
    if (Result r = order(s_.vertexAlive, uo.stableVertex, uo.vertexBegin, "vertex", "vertices", vertices,
                         handoffVertexStable_);
        !r)
      return r;
    if (Result r = order(s_.tetAlive, uo.stableTet, uo.tetBegin, "tet", "tets", tets, handoffTetStable_); !r) return r;
    // The splits create a vertex each and at most every tet not in the handoff.
    if (uo.vertexBegin + s_.log.size() > kMaxStable || uo.tetBegin + (T - tets.size()) > kMaxStable)
      return fail(Status::TooLarge, "encodeUnit: stable ids from vertex " + std::to_string(uo.vertexBegin) +
                                        " and tet " + std::to_string(uo.tetBegin) +
                                        " would pass the format's limit of 2^31 - 1 (FORMAT.md §5)");
    vertexBegin_ = uo.vertexBegin;
    tetBegin_ = uo.tetBegin;

    TetMesh& b = emptyBase(V, T);
    for (uint32_t v : vertices) {
      out_.streamVertexOf[v] = b.vertexCount();
      b.positions.insert(b.positions.end(), &mesh_.positions[3 * size_t(v)], &mesh_.positions[3 * size_t(v)] + 3);
      for (size_t f = 0; f < mesh_.fields.size(); ++f) b.fields[f].values.push_back(valueAt(f, v));
    }
    for (uint32_t t : tets) {
      out_.streamTetOf[t] = b.tetCount();
      for (int k = 0; k < 4; ++k) {
        const uint32_t v = out_.streamVertexOf[s_.tets[4 * size_t(t) + k]];
        if (v == kNone)
          return fail(Status::Corrupt, "encodeUnit: tet " + std::to_string(t) + " of the handoff has a dead vertex");
        b.tets.push_back(v);
      }
    }
    std::vector<uint32_t>().swap(s_.tets);  // (as buildBase)
    initProgressive(pm_, b);
    if (s_.valuesField >= 0) {
      pm_.keptFirst = uint32_t(s_.valuesField);
      pm_.keptCount = 1;
      pm_.keptFixed = true;
    }
    reserveProgressive(pm_, V, T);
    return Result::success();
  }

  // In cost order: each split encoded and applied, a chunk flushed once it holds its share or
  // its node ends (a chunk holds the splits of one node: FORMAT.md §1.1).
  Result encodeSplits(uint32_t C) {
    startChunk();
    if (opt_.orderSplits && !s_.log.starBegin.empty()) return encodeOrderedSplits(C);
    for (uint32_t split = 0; split < C; ++split) {
      const uint32_t c = C - 1 - split;
      if (split == spans_[span_].first) beginNode();
      if (!splitFits(c)) {
        collect();
        return misfit();
      }
      encodeSplit(c);
      ++inChunk_;
      if (opt_.progress && (c & 4095) == 0) opt_.progress(split + 1, C);
      const uint32_t nodeEnd = spans_[span_].end;
      if (recordBytes() >= target_ * ratio_ || split + 1 == nodeEnd ||
          tapers(split + 1 - spans_[span_].first, nodeEnd - split - 1))
        if (Result r = flushChunk(split + 1); !r) {
          collect();
          return r;
        }
      if (split + 1 == nodeEnd) endNode();
    }
    return collect();
  }

  // The nodes in stream order (FORMAT.md §1.1): the log's sections from the last (the root's)
  // to the first, each a run of splits [first, end).
  struct Span {
    uint32_t node, first, end;
  };
  void planNodes() {
    const RegionTree& tree = s_.tree;
    const uint32_t C = s_.log.size();
    for (size_t sec = tree.sectionNode.size(); sec-- > 0;) {
      const uint32_t begin = sec ? tree.sectionEnd[sec - 1] : 0;
      spans_.push_back({tree.sectionNode[sec], C - tree.sectionEnd[sec], C - begin});
    }
    span_ = 0;
    if (C && (spans_.empty() || spans_.back().end != C))  // (a log in no section: one node, the root)
      spans_.assign(1, Span{1, 0, C});
    if (!unit_) stats_ = regionStats(mesh_, s_, m_);  // (a unit's driver has the whole tree's)
    indexOf_.assign(std::max<uint32_t>(tree.nodes(), 2), -1);
  }

  // A node's first split is next: its manifest entry starts, and when it begins a level of the
  // tree, the field error of the mesh now (the previous level's last chunk) is measured, by node.
  void beginNode() {
    const uint32_t n = spans_[span_].node;
    if (unit_) {
      unitNode_ = UnitNode{};
      unitNode_.node = n;
      unitNode_.firstChunk = uint32_t(unit_->chunks.size());
      unitNode_.vertexBegin = stableVertexCount();
      unitNode_.tetBegin = stableTetCount();
      if (metered_) {
        measureLevel(n);
        unitNode_.fieldRms = levelErrors_[n].rms;
        unitNode_.fieldMax = levelErrors_[n].max;
      }
      target_ = isRoot(n) ? opt_.firstChunkBytes : opt_.chunkBytes;
      return;
    }
    NodeInfo& info = node_;
    info = NodeInfo{};
    for (uint32_t up = n >> 1; up >= 1 && info.parent < 0; up >>= 1) info.parent = indexOf_[up];
    info.firstChunk = uint32_t(jobs_.size()) + 1;
    info.vertexBegin = pm_.vertexCount();
    info.tetBegin = pm_.tetCount();
    info.bounds = stats_.bounds[n];
    info.ranges = stats_.ranges[n];
    info.fieldError = std::min(range_, stats_.fieldError[n]);
    if (metered_) {
      measureLevel(n);
      info.fieldRms = levelErrors_[n].rms;
      info.fieldMax = levelErrors_[n].max;
    }
    // The root's first chunk is small, for the first refinements to come soon after the base;
    // other nodes are fetched whole, chosen by what they show.
    target_ = isRoot(n) ? opt_.firstChunkBytes : opt_.chunkBytes;
  }

  // When node n begins a level of the tree, the field error of the mesh now by node of that level
  // (levelErrors_), over the input vertices measured (a unit's measureAt_, else all): the whole
  // base's for the root, then a measurement at each level (the one before it, for a stream: the
  // last chunk's figures). A unit's first level is the handoff, which the meter located first.
  void measureLevel(uint32_t n) {
    const RegionTree& tree = s_.tree;
    const uint32_t level = tree.depth ? tree.levelOf(n) : 0;
    if (level == measuredLevel_) return;
    const bool first = measuredLevel_ == ~0u;
    measuredLevel_ = level;
    levelErrors_.assign(std::max<uint32_t>(tree.nodes(), 2), LevelError{});
    if (!unit_ && n == 1) {
      levelErrors_[1] = baseError();
      return;
    }
    baseError();  // (the meter has located the input's vertices)
    if (unit_ && !first)
      meter_.current(pm_.mesh, pm_.stars, opt_.threads);
    else if (!unit_ && !jobs_.empty())
      measure(jobs_.back().info);
    meter_.totalByGroup(
        [&](uint32_t v) {
          if (measureAt_ && !(*measureAt_)[v]) return ~0u;
          if (!tree.depth) return 1u;
          return tree.leafOf[v] != ~0u ? tree.nodeOf(v, level) : ~0u;
        },
        levelErrors_);
  }

  // Node n of the tree is the whole mesh's root (a unit's top node is when its part is the root).
  bool isRoot(uint32_t n) const { return n == 1 && (!unit_ || unitRoot_); }
  // The whole stream's counts with pm_'s splits applied (a unit's: the ids its next split creates).
  uint64_t stableVertexCount() const { return vertexBegin_ + (pm_.vertexCount() - handoffVertexStable_.size()); }
  uint64_t stableTetCount() const { return tetBegin_ + (pm_.tetCount() - handoffTetStable_.size()); }

  void endNode() {
    if (unit_) {
      unitNode_.chunkCount = uint32_t(unit_->chunks.size()) - unitNode_.firstChunk;
      unitNode_.vertexEnd = stableVertexCount();
      unitNode_.tetEnd = stableTetCount();
      unit_->nodes.push_back(unitNode_);
      ++span_;
      return;
    }
    NodeInfo& info = node_;
    info.chunkCount = uint32_t(jobs_.size()) + 1 - info.firstChunk;
    info.vertexEnd = pm_.vertexCount();
    info.tetEnd = pm_.tetCount();
    indexOf_[spans_[span_].node] = int32_t(out_.nodes.size());
    out_.nodes.push_back(std::move(info));
    ++span_;
  }

  // Towards the end of the root's splits chunks halve again (a chunk ends once it holds about as
  // many bytes as the splits still to come would take, at the mean size so far), down to the
  // first chunk's size: a viewer that keeps pace with the link then has a small last chunk to
  // apply when the last byte arrives, instead of a whole large one. A rest smaller than that
  // stays in the chunk.
  bool tapers(uint32_t done, uint32_t left) const {
    if (!isRoot(spans_[span_].node)) return false;
    const double least = opt_.firstChunkBytes * ratio_;
    const double rest = double(left) * double(flushedRaw_ + recordBytes()) / double(done);
    return double(recordBytes()) >= std::max(least, rest) && rest >= least;
  }

  // StreamOptions::orderSplits: chunk by chunk, how many splits it takes (plannedSplits), their
  // order (split_order.h), then each split encoded and applied in that order. Split s undoes
  // collapse C − 1 − s.
  Result encodeOrderedSplits(uint32_t C) {
    SplitOrder order(uint32_t(s_.tetAlive.size()));
    const CollapseLog& log = s_.log;
    for (uint32_t done = 0; done < C;) {
      if (done == spans_[span_].first) beginNode();
      const uint32_t count = std::min(plannedSplits(done, C), spans_[span_].end - done);
      order.plan(log, done, count);
      bool misfits = false;
      order.run([&](uint32_t s) { return out_.streamVertexOf[log.j[C - 1 - s]]; },
                [&](uint32_t s) {
                  misfits = misfits || !splitFits(C - 1 - s);
                  if (misfits) return;
                  encodeSplit(C - 1 - s);
                  ++inChunk_;
                  if (opt_.progress && (inChunk_ & 4095) == 0) opt_.progress(done + inChunk_, C);
                });
      done += count;
      Result r = misfits ? misfit() : flushChunk(done);
      if (!r) {
        collect();
        return r;
      }
      if (done == spans_[span_].end) endNode();
    }
    return collect();
  }

  // The splits the next ordered chunk takes, planned before it is encoded: from the record bytes
  // per split so far (a guess for the first chunk), about target_ bytes once compressed at the
  // ratio seen, halving towards the end like tapers().
  uint32_t plannedSplits(uint32_t done, uint32_t C) const {
    const double perSplit = done ? double(flushedRaw_) / done : kFirstGuessBytesPerSplit;
    const uint32_t left = C - done;
    const double least = opt_.firstChunkBytes * ratio_ / perSplit;  // in splits
    double count = std::ceil(double(target_) * ratio_ / perSplit);
    if (2 * count >= left && left - std::ceil(left / 2.0) >= least) count = std::ceil(left / 2.0);
    return uint32_t(std::clamp(count, 1.0, double(left)));
  }
  static constexpr double kFirstGuessBytesPerSplit = 12;  // typical of the compressed stream

  // Each level's field error, measured at every input vertex (level_error.h) for the field that
  // steered the simplification. The meter locates them in the base on another thread (it reads
  // out_.base and a copy of its vertex ids, which stay as they are) while the splits are encoded
  // and applied to pm_, a copy of the base; it takes them up at the first measurement.
  void startMeter(int iso) {
    metered_ = iso >= 0;
    if (!metered_) return;
    const CollapseLog& log = s_.log;
    baseOf_.resize(mesh_.vertexCount());
    for (uint32_t v = 0; v < baseOf_.size(); ++v) baseOf_[v] = v;
    for (uint32_t c = log.size(); c-- > 0;) baseOf_[log.i[c]] = baseOf_[log.j[c]];
    intoOf_.resize(mesh_.vertexCount());
    for (uint32_t v = 0; v < intoOf_.size(); ++v) intoOf_[v] = v;
    for (uint32_t c = 0; c < log.size(); ++c) intoOf_[log.i[c]] = log.j[c];
    const std::span<const float> values = mesh_.fields[size_t(iso)].values;
    baseError_ = std::async(std::launch::async, [this, iso, values, levelOf = out_.streamVertexOf]() mutable {
      meter_.begin(mesh_.positions, values, out_.base, size_t(iso), std::move(levelOf), baseOf_, intoOf_);
      return meter_.total();
    });
  }

  // The base's error (once the meter has located the input's vertices there).
  const LevelError& baseError() {
    if (baseError_.valid()) baseErrorValue_ = baseError_.get();
    return baseErrorValue_;
  }

  void measure(ChunkInfo& info) {
    if (!metered_) return;
    baseError();
    const LevelError e = meter_.current(pm_.mesh, pm_.stars, opt_.threads);
    info.fieldRms = e.rms;
    info.fieldMax = e.max;
  }

  // No vertex or tet in the stream yet; the base mesh empty, with the fields' names.
  TetMesh& emptyBase(uint32_t V, uint32_t T) {
    out_.streamVertexOf.assign(V, kNone);
    out_.streamTetOf.assign(T, kNone);
    TetMesh& b = out_.base;
    b = TetMesh{};
    b.name = mesh_.name;
    b.fields.resize(mesh_.fields.size());
    for (size_t f = 0; f < mesh_.fields.size(); ++f) b.fields[f].name = mesh_.fields[f].name;
    return b;
  }

  void buildBase() {
    const uint32_t V = mesh_.vertexCount(), T = uint32_t(s_.tetAlive.size());  // (mesh_.tets may be gone: simplify.h)
    TetMesh& b = emptyBase(V, T);
    for (uint32_t v = 0; v < V; ++v) {
      if (!s_.vertexAlive[v]) continue;
      out_.streamVertexOf[v] = b.vertexCount();
      b.positions.insert(b.positions.end(), &mesh_.positions[3 * size_t(v)], &mesh_.positions[3 * size_t(v)] + 3);
      for (size_t f = 0; f < mesh_.fields.size(); ++f) b.fields[f].values.push_back(valueAt(f, v));
    }
    for (uint32_t t = 0; t < T; ++t) {
      if (!s_.tetAlive[t]) continue;
      out_.streamTetOf[t] = b.tetCount();
      for (int k = 0; k < 4; ++k) b.tets.push_back(out_.streamVertexOf[s_.tets[4 * size_t(t) + k]]);
    }
    std::vector<uint32_t>().swap(s_.tets);  // read no more: its memory is the splits' (split_encode.h)
    initProgressive(pm_, b);
    if (s_.valuesField >= 0) {  // splits give j back its value of the fitted field only
      pm_.keptFirst = uint32_t(s_.valuesField);
      pm_.keptCount = 1;
      pm_.keptFixed = true;
    }
    reserveProgressive(pm_, V, T);
  }

  // The current chunk's records so far, in bytes (all columns).
  size_t recordBytes() const {
    size_t n = 0;
    for (const std::vector<uint8_t>& c : columns_) n += c.size();
    return n;
  }
  std::vector<uint8_t>& column(SplitColumn c) { return columns_[size_t(c)]; }

  void startChunk() {
    flushedRaw_ += recordBytes();
    for (std::vector<uint8_t>& c : columns_) c.clear();
    inChunk_ = 0;
    chunkError_ = 0;
    prevJ_ = 0;  // each chunk decodes on its own (FORMAT.md §4)
  }

  // A value as the decoder will see it: on the field's quantization grid unless lossless.
  float snapped(size_t f, float x) const { return q_.lossless ? x : q_.field[f].snap(x); }
  // Field f at original vertex v at the base level: the simplifier's fitted value for the
  // field it steered by, the sample for the others.
  float valueAt(size_t f, uint32_t v) const {
    return int(f) == s_.valuesField ? snapped(f, s_.values[v]) : mesh_.fields[f].values[v];
  }

  uint32_t candidateIndex(uint32_t v) const {
    auto it = std::lower_bound(candidates_.begin(), candidates_.end(), v);
    if (it != candidates_.end() && *it == v) return uint32_t(it - candidates_.begin());
    return uint32_t(candidates_.size()) + stableVertex(v);  // explicit id, stable (FORMAT.md §1.1, §4)
  }

  void putValue(std::vector<uint8_t>& out, float value, float predictor, const QuantAxis& axis) {
    if (q_.lossless)
      putF32(out, value);
    else
      putVarint(out, zigzag(int32_t(axis.quantize(value)) - int32_t(axis.quantize(predictor))));
  }

  // Whether the split that undoes collapse c meets the mesh its log describes: p_j there and p_i
  // not yet, T_moved's tets around p_j, T_new's other vertices there. Always so in cost order and
  // in split_order.h's order; checked anyway (a few lookups a split), as applySplit trusts it.
  bool splitFits(uint32_t c) {
    const CollapseLog& log = s_.log;
    const uint32_t js = out_.streamVertexOf[log.j[c]];
    if (js == kNone || out_.streamVertexOf[log.i[c]] != kNone) return false;
    const CollapseTets& tets = tetsOf(c);
    for (uint32_t m : tets.moved) {
      const uint32_t t = out_.streamTetOf[m];
      if (t >= pm_.tetCount()) return false;
      const uint32_t* v = &pm_.mesh.tets[4 * size_t(t)];
      if (v[0] != js && v[1] != js && v[2] != js && v[3] != js) return false;
    }
    for (uint32_t v : tets.others)
      if (out_.streamVertexOf[v] == kNone) return false;
    return true;
  }
  // Collapse c's tets, read from the log once for splitFits and encodeSplit.
  const CollapseTets& tetsOf(uint32_t c) {
    if (tetsRead_ != c) s_.log.readTets(c, tets_);
    tetsRead_ = c;
    return tets_;
  }
  static Result misfit() {
    return fail(Status::Corrupt, "encoder: a split does not fit the mesh it undoes (internal error)");
  }

  void encodeSplit(uint32_t c) {
    const CollapseLog& log = s_.log;
    const uint32_t i = log.i[c], j = log.j[c];
    const uint32_t js = out_.streamVertexOf[j], is = pm_.vertexCount();
    assert(js != kNone && out_.streamVertexOf[i] == kNone);
    out_.streamVertexOf[i] = is;
    const uint32_t jStable = stableVertex(js);  // records name vertices by stable id (FORMAT.md §1.1)
    putVarint(column(SplitColumn::KeptVertex), zigzag(int32_t(jStable) - int32_t(prevJ_)));
    prevJ_ = jStable;
    chunkError_ = std::max(chunkError_, log.fieldError[c]);

    // T_moved in stream tet ids, ascending (written by putMoved() once T_new is known).
    const CollapseTets& tets = tetsOf(c);
    moved_.clear();
    for (uint32_t m : tets.moved) moved_.push_back(out_.streamTetOf[m]);
    std::sort(moved_.begin(), moved_.end());
    starOf(pm_, js, star_);

    // New tets (i, j, a, b), ordered as an even permutation of the original tet. Around an
    // edge of a consistently oriented mesh the pairs (a, b) chain into the edge's link: a cycle
    // (interior edge) or a path (boundary edge), written as its vertices; otherwise as pairs.
    neighboursOf(pm_, js, candidates_);
    link_.build(pm_.mesh, js, star_, candidates_);
    const uint32_t count = uint32_t(tets.removed.size());
    pairs_.clear();
    for (uint32_t n = 0; n < count; ++n) {
      const uint32_t* ab = &tets.others[2 * size_t(n)];  // (i, j, a, b) has the tet's orientation
      pairs_.push_back({out_.streamVertexOf[ab[0]], out_.streamVertexOf[ab[1]], tets.removed[n]});
    }
    const RingMode mode = chainPairs();
    putVarint(column(SplitColumn::NewTetCount), count << 2 | uint32_t(mode));
    std::vector<uint8_t>& list = column(SplitColumn::NewTets);
    if (mode == RingMode::Pairs) {
      for (const Pair& p : pairs_) {
        putVarint(list, candidateIndex(p.a));
        putVarint(list, candidateIndex(p.b));
      }
    } else {
      ring_.clear();
      for (const Pair& p : pairs_) ring_.push_back(p.a);
      if (mode == RingMode::Path) ring_.push_back(pairs_.back().b);
      putRing(list);
    }
    newTets_.clear();
    for (uint32_t n = 0; n < count; ++n) {
      newTets_.insert(newTets_.end(), {is, js, pairs_[n].a, pairs_[n].b});
      out_.streamTetOf[pairs_[n].tet] = pm_.tetCount() + n;
    }
    putMoved();

    const float* pi = &mesh_.positions[3 * size_t(i)];
    const float* pj = &pm_.mesh.positions[3 * size_t(js)];
    for (int k = 0; k < 3; ++k) putValue(column(SplitColumn::Position), pi[k], pj[k], q_.position[k]);
    // p_i's values as they were when it was removed, then (with fitted values) the values p_j
    // had before the collapse, which the split gives back.
    const size_t F = mesh_.fields.size();
    fields_.resize(F);
    for (size_t f = 0; f < F; ++f) {
      fields_[f] = int(f) == s_.valuesField ? snapped(f, log.iValue[c]) : mesh_.fields[f].values[i];
      putValue(column(SplitColumn::Values), fields_[f], pm_.mesh.fields[f].values[js], q_.field[f]);
    }
    float jValue = 0;
    bool jValueChanged = false;
    if (s_.valuesField >= 0) {
      const size_t f = size_t(s_.valuesField);
      jValue = snapped(f, log.jValue[c]);
      putValue(column(SplitColumn::Values), jValue, pm_.mesh.fields[f].values[js], q_.field[f]);
      jValueChanged = jValue != pm_.mesh.fields[f].values[js];
    }
    changed_.clear();
    applySplit(pm_, SplitOp{js, moved_, newTets_, pi, fields_.data(), s_.valuesField >= 0 ? &jValue : nullptr},
               changed_);
    if (metered_) meter_.afterSplit(i, js, moved_, pm_.stars, jValueChanged);
  }

  // A cycle's or path's vertices (ring_) as a walk in p_j's link (FORMAT.md §4, flag bit 5):
  // after the first, each by its rank among the link neighbours of the one before that are not
  // on the ring yet, or past those by its index among all of p_j's neighbours.
  void putRing(std::vector<uint8_t>& out) {
    uint64_t used = 0;
    uint32_t from = VertexLink::kNone;
    for (uint32_t v : ring_) {
      const uint32_t near = from != VertexLink::kNone ? link_.choices(from, used) : 0;
      const uint32_t rank = from != VertexLink::kNone ? link_.rankOf(from, used, v) : VertexLink::kNone;
      putVarint(out, rank != VertexLink::kNone ? rank : near + candidateIndex(v));
      from = opt_.ringWalk ? link_.localOf(v) : VertexLink::kNone;
      if (from != VertexLink::kNone) used |= uint64_t(1) << from;
    }
  }

  // T_moved: the marker 0 when the reader finds it from T_new (vertex_link.h), else 1 and a bit
  // per tet around p_j (star_), in ascending order.
  void putMoved() {
    std::vector<uint8_t>& out = column(SplitColumn::Moved);
    link_.moved(newTets_, implied_);
    if (implied_ == moved_) {
      out.push_back(0);
      return;
    }
    out.push_back(1);
    ++out_.movedMasks;
    const size_t maskAt = out.size();
    out.resize(maskAt + (star_.size() + 7) / 8, 0);
    for (size_t k = 0, x = 0; k < star_.size() && x < moved_.size(); ++k)
      if (star_[k] == moved_[x]) {
        out[maskAt + (k >> 3)] |= uint8_t(1u << (k & 7));
        ++x;
      }
  }

  // Closes the current chunk and compresses it on another thread while encoding goes on. The
  // size aimed at by chunk n uses the compression ratio of chunk n−2 (known by then), so chunk
  // boundaries never depend on thread timing.
  struct Pair {
    uint32_t a, b, tet;
  };

  // Orders pairs_ head to tail when they form one cycle or one path (FORMAT.md §4); leaves them
  // as they are otherwise. Deterministic: a cycle starts at its smallest vertex.
  RingMode chainPairs() {
    const size_t m = pairs_.size();
    if (m == 0) return RingMode::Pairs;
    chain_.clear();
    // Each a and each b must appear once for a chain.
    for (size_t x = 0; x < m; ++x)
      for (size_t y = x + 1; y < m; ++y)
        if (pairs_[x].a == pairs_[y].a || pairs_[x].b == pairs_[y].b) return RingMode::Pairs;
    auto next = [&](uint32_t b) -> int {
      for (size_t y = 0; y < m; ++y)
        if (pairs_[y].a == b) return int(y);
      return -1;
    };
    // A path starts at the pair whose a is nobody's b; a cycle at its smallest a.
    int start = -1;
    for (size_t x = 0; x < m; ++x) {
      bool hasPredecessor = false;
      for (size_t y = 0; y < m; ++y) hasPredecessor |= pairs_[y].b == pairs_[x].a;
      if (!hasPredecessor) {
        if (start >= 0) return RingMode::Pairs;  // two paths
        start = int(x);
      }
    }
    const bool cycle = start < 0;
    if (cycle) {
      start = 0;
      for (size_t x = 1; x < m; ++x)
        if (pairs_[x].a < pairs_[size_t(start)].a) start = int(x);
    }
    for (int x = start; x >= 0 && chain_.size() < m; x = next(pairs_[size_t(x)].b)) chain_.push_back(pairs_[size_t(x)]);
    if (chain_.size() != m) return RingMode::Pairs;
    if (cycle && chain_.back().b != chain_.front().a) return RingMode::Pairs;
    if (!cycle && next(chain_.back().b) >= 0) return RingMode::Pairs;
    if (cycle && m < 3) return RingMode::Pairs;  // a "cycle" of two tets is degenerate: keep pairs
    pairs_.swap(chain_);
    return cycle ? RingMode::Cycle : RingMode::Path;
  }

  // The chunk's header (with `index`) and payload.
  void writeChunk(std::vector<uint8_t>& raw, uint32_t index) const {
    beginChunk(raw, ChunkKind::Splits, index);
    putU32(raw, inChunk_);
    putU32(raw, kSplitFlagColumns | kSplitFlagImpliedMoved | (opt_.ringWalk ? kSplitFlagRingWalk : 0) |
                    (q_.lossless ? kSplitFlagLossless : 0) | (s_.valuesField >= 0 ? kSplitFlagKeptIsoValue : 0));
    for (const std::vector<uint8_t>& c : columns_) putU32(raw, uint32_t(c.size()));
    for (const std::vector<uint8_t>& c : columns_) raw.insert(raw.end(), c.begin(), c.end());
  }

  // A unit's chunk stays raw, its index 0 until the driver knows it (finishUnitChunk). Its size
  // aimed at uses the assumed ratio_, never updated: the real one is known after compression.
  void flushUnitChunk() {
    UnitChunk& chunk = unit_->chunks.emplace_back();
    writeChunk(chunk.raw, 0);
    chunk.splits = inChunk_;
    chunk.vertices = stableVertexCount();
    chunk.tets = stableTetCount();
    chunk.maxCollapseError = chunkError_;
    target_ = std::min<uint64_t>(2 * target_, opt_.chunkBytes);
    startChunk();
  }

  Result flushChunk(uint32_t splitsApplied) {
    if (unit_) {
      flushUnitChunk();
      return Result::success();
    }
    Job& job = jobs_.emplace_back();
    writeChunk(job.raw, uint32_t(jobs_.size()));
    job.info.kind = ChunkKind::Splits;
    job.info.vertices = pm_.vertexCount();
    job.info.tets = pm_.tetCount();
    job.info.splits = inChunk_;
    const uint32_t C = s_.log.size();
    job.info.fieldError = splitsApplied < C ? prefixMax_[C - splitsApplied - 1] : 0.0;
    job.done = std::async(std::launch::async,
                          [&job, level = opt_.zstdLevel] { return finishChunk(job.raw, level, job.file, job.info); });
    if (jobs_.size() >= 2) {
      Job& older = jobs_[jobs_.size() - 2];
      if (Result r = wait(older); !r) return r;
      if (older.info.bytes > 0) ratio_ = std::max(1.0, double(older.raw.size()) / double(older.info.bytes));
    }
    target_ = std::min<uint64_t>(2 * target_, opt_.chunkBytes);
    startChunk();
    return Result::success();
  }

  struct Job {
    std::vector<uint8_t> raw, file;
    ChunkInfo info;
    std::future<Result> done;
    bool waited = false;
    Result result;
  };

  static Result wait(Job& job) {
    if (!job.waited) {
      job.result = job.done.get();
      job.waited = true;
    }
    return job.result;
  }

  // Waits for every chunk and hands them over in order.
  Result collect() {
    for (Job& job : jobs_)
      if (Result r = wait(job); !r) return r;
    for (Job& job : jobs_) {
      out_.files.push_back(std::move(job.file));
      out_.chunks.push_back(job.info);
    }
    jobs_.clear();
    return Result::success();
  }

  const TetMesh& mesh_;
  SimplifyResult& s_;
  const Manifest& m_;
  const StreamOptions& opt_;
  EncodedStream& out_;
  Quantizer q_;
  ProgressiveMesh pm_;
  LevelErrorMeter meter_;
  bool metered_ = false;
  std::vector<uint32_t> baseOf_;  // per input vertex: the base vertex it went into
  std::vector<uint32_t> intoOf_;  // ... the vertex it went into directly (itself if none)
  // The base's error, measured on another thread: declared after all that task reads, so it is
  // destroyed, and waited for, first.
  std::future<LevelError> baseError_;
  LevelError baseErrorValue_;
  std::vector<float> prefixMax_, fields_;
  std::vector<uint8_t> columns_[kSplitColumns];  // the current chunk's records, column by column
  std::vector<Pair> pairs_, chain_;
  CollapseTets tets_;  // collapse tetsRead_'s (tetsOf)
  uint32_t tetsRead_ = kNone;
  std::deque<Job> jobs_;  // chunks being compressed, in order (stable addresses)
  std::vector<uint32_t> star_, moved_, candidates_, newTets_, changed_, implied_;
  VertexLink link_;  // of p_j, as the reader sees it
  std::vector<uint32_t> ring_;
  uint32_t prevJ_ = 0, inChunk_ = 0;
  uint64_t target_ = 0;
  std::vector<Span> spans_;
  size_t span_ = 0;                      // the node being encoded
  NodeInfo node_;                        // its manifest entry so far
  RegionStats stats_;                    // per node of the tree
  std::vector<int32_t> indexOf_;         // per node of the tree: its index in out_.nodes, -1 before
  uint32_t measuredLevel_ = ~0u;         // the level of the tree the last measurement was for
  std::vector<LevelError> levelErrors_;  // per node of that level
  float range_ = 0;                      // the isoField's range (no estimate exceeds it)
  uint64_t flushedRaw_ = 0;              // record bytes of the chunks before the current one
  double ratio_ = 2.5;
  // encodeUnit only: where the chunks go, and the stable ids of pm_'s handoff (by pm_ id) and of
  // the unit's first new vertex and tet (stableVertex).
  UnitEncoded* unit_ = nullptr;
  const std::vector<uint8_t>* measureAt_ = nullptr;  // the input vertices a unit measures at (null: all)
  bool unitRoot_ = false;                            // the unit's top node is the whole mesh's root
  UnitNode unitNode_;
  std::vector<uint32_t> handoffVertexStable_, handoffTetStable_;
  uint64_t vertexBegin_ = 0, tetBegin_ = 0;
  float chunkError_ = 0;  // the largest CollapseLog::fieldError of the current chunk's splits
};

}  // namespace

Result encodeStream(const TetMesh& mesh, SimplifyResult& s, const Manifest& m, const StreamOptions& opt,
                    EncodedStream& out) {
  out = EncodedStream{};
  // Kept values are written for the manifest's isoField only (split flag bit 2).
  if (s.valuesField >= 0 && m.findField(m.isoField) != s.valuesField)
    return fail(Status::Unsupported, "fitted values of a field other than the manifest's isoField");
  Encoder e(mesh, s, m, opt, out);
  return e.run();
}

Result encodeUnit(const TetMesh& mesh, SimplifyResult& s, const Manifest& m, const UnitEncodeOptions& opt,
                  UnitEncoded& out) {
  out = UnitEncoded{};
  if (s.valuesField >= 0 && m.findField(m.isoField) != s.valuesField)
    return fail(Status::Unsupported, "fitted values of a field other than the manifest's isoField");
  if (opt.stream.orderSplits) return fail(Status::Unsupported, "encodeUnit: splits in kept-vertex order");
  EncodedStream scratch;  // the encoder's maps and the handoff while it is built
  Encoder e(mesh, s, m, opt.stream, scratch);
  return e.runUnit(opt, out);
}

Result finishUnitChunk(UnitChunk& chunk, uint32_t index, int zstdLevel, std::vector<uint8_t>& file, ChunkInfo& info) {
  if (chunk.raw.size() < kChunkHeaderBytes)
    return fail(Status::BadArgument, "finishUnitChunk: a chunk of " + std::to_string(chunk.raw.size()) + " bytes");
  constexpr uint64_t kMaxCount = (uint64_t(1) << 31) - 1;  // FORMAT.md §5
  if (chunk.vertices > kMaxCount || chunk.tets > kMaxCount)
    return fail(Status::TooLarge, "chunk " + std::to_string(index) + ": " + std::to_string(chunk.vertices) +
                                      " vertices and " + std::to_string(chunk.tets) +
                                      " tets after it, past the format's limit of 2^31 - 1 (FORMAT.md §5)");
  for (int k = 0; k < 4; ++k) chunk.raw[8 + size_t(k)] = uint8_t(index >> (8 * k));  // header: chunk index
  if (Result r = finishChunk(chunk.raw, zstdLevel, file, info); !r) return r;
  info.kind = ChunkKind::Splits;
  info.splits = chunk.splits;
  info.vertices = uint32_t(chunk.vertices);
  info.tets = uint32_t(chunk.tets);
  return Result::success();
}

}  // namespace tetstream
