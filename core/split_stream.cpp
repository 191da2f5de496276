#include "split_stream.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace tetstream {
namespace {

Result corrupt(const std::string& what) { return fail(Status::Corrupt, "split chunk: " + what); }

bool toLocal(const SplitReader& r, uint32_t stable, uint32_t& local) {
  if (!r.ids) {
    local = stable;
    return true;
  }
  return r.ids->toLocal(stable, local);
}

}  // namespace

void SplitReader::tell(uint32_t* offsets) const {
  for (uint32_t k = 0; k < kSplitColumns; ++k) offsets[k] = uint32_t(in[k].pos);
}

void SplitReader::seek(const uint32_t* offsets) {
  for (uint32_t k = 0; k < kSplitColumns; ++k) in[k].pos = offsets[k];
}

bool SplitReader::atEnd() const {
  for (const ByteReader& c : in)
    if (!c.atEnd()) return false;
  return true;
}

Result beginSplits(SplitReader& r, std::span<const uint8_t> payload, const ChunkInfo& info, const Manifest& m) {
  ByteReader header{payload, 0};
  uint32_t count = 0, flags = 0;
  if (!header.u32(count) || !header.u32(flags))
    return fail(Status::Truncated, "split chunk: payload shorter than its header");
  if (count != info.splits)
    return corrupt(std::to_string(count) + " splits where the manifest says " + std::to_string(info.splits));
  if (flags & ~(kSplitFlagLossless | kSplitFlagKeptValues | kSplitFlagKeptIsoValue | kSplitFlagColumns |
                kSplitFlagImpliedMoved | kSplitFlagRingWalk))
    return fail(Status::Unsupported, "split chunk: unknown flags");
  r.ringWalk = flags & kSplitFlagRingWalk;
  r.columns = flags & kSplitFlagColumns;
  r.impliedMoved = flags & kSplitFlagImpliedMoved;
  for (ByteReader& c : r.in) c = ByteReader{};
  if (r.columns) {
    // The columns' byte lengths, then the columns, which must fill the payload exactly.
    uint32_t length[kSplitColumns];
    for (uint32_t& n : length)
      if (!header.u32(n)) return fail(Status::Truncated, "split chunk: payload shorter than its header");
    size_t at = header.pos;
    for (uint32_t k = 0; k < kSplitColumns; ++k) {
      if (length[k] > payload.size() - at)
        return fail(Status::Truncated, "split chunk: a column runs past the payload end");
      r.in[k] = ByteReader{payload.subspan(at, length[k]), 0};
      at += length[k];
    }
    if (at != payload.size()) return corrupt("bytes after the last column");
  } else {
    r.in[0] = ByteReader{payload.subspan(header.pos), 0};
  }
  if ((flags & kSplitFlagKeptValues) && (flags & kSplitFlagKeptIsoValue))
    return corrupt("both kinds of kept values flagged");
  r.lossless = flags & kSplitFlagLossless;
  r.keptFirst = r.keptCount = 0;
  if (flags & kSplitFlagKeptValues) r.keptCount = uint32_t(m.fields.size());
  if (flags & kSplitFlagKeptIsoValue) {
    const int f = m.findField(m.isoField);
    if (f < 0) return corrupt("kept values of a field the manifest does not have");
    r.keptFirst = uint32_t(f);
    r.keptCount = 1;
  }
  r.jFields.resize(r.keptCount);
  if (r.lossless != m.lossless) return corrupt("lossless flag differs from the manifest");
  r.remaining = count;
  r.prevJ = 0;
  return Result::success();
}

Result applyNextSplit(SplitReader& r, ProgressiveMesh& pm, const Quantizer& q, std::vector<uint32_t>& changed) {
  if (r.remaining == 0) return corrupt("no split left in the chunk");
  const uint32_t V = pm.vertexCount(), i = V;
  uint32_t u;
  if (!r.column(SplitColumn::KeptVertex).varint(u)) return fail(Status::Truncated, "split chunk: record ends early");
  const int64_t j64 = int64_t(r.prevJ) + unzigzag(u);
  uint32_t j = uint32_t(j64);
  if (j64 < 0 || j64 > int64_t(UINT32_MAX) || !toLocal(r, uint32_t(j64), j) || j >= V)
    return fail(Status::OutOfRange, "split chunk: kept vertex " + std::to_string(j64) + " does not exist");

  // T_moved: a bit per tet around j, in ascending tet order, or (a marker byte says which)
  // found from T_new below.
  starOf(pm, j, r.star);
  ByteReader& movedIn = r.column(SplitColumn::Moved);
  uint8_t marker = 1;
  if (r.impliedMoved) {
    const uint8_t* m;
    if (!movedIn.bytes(1, m)) return fail(Status::Truncated, "split chunk: record ends early");
    marker = *m;
    if (marker > 1) return corrupt("a moved-tets marker other than 0 or 1");
  }
  r.moved.clear();
  if (marker == 1) {
    const uint8_t* mask;
    if (!movedIn.bytes((r.star.size() + 7) / 8, mask)) return fail(Status::Truncated, "split chunk: record ends early");
    for (size_t k = 0; k < r.star.size(); ++k)
      if (mask[k >> 3] >> (k & 7) & 1) r.moved.push_back(r.star[k]);
    if (r.star.size() % 8 && mask[r.star.size() / 8] >> (r.star.size() % 8))
      return corrupt("mask bits beyond the star");
  }

  // T_new: (i, j, a, b), vertices named by index into j's sorted neighbours, or past the end
  // for an explicit vertex id; listed as pairs or as the chain of the edge's link.
  neighboursOf(pm, j, r.candidates);
  if (r.impliedMoved || r.ringWalk) r.link.build(pm.mesh, j, r.star, r.candidates);
  uint32_t header;
  if (!r.column(SplitColumn::NewTetCount).varint(header))
    return fail(Status::Truncated, "split chunk: record ends early");
  const uint32_t m = header >> 2, mode = header & 3;
  if (m > kMaxNewTetsPerSplit) return corrupt(std::to_string(m) + " new tets in one split");
  if (mode > uint32_t(RingMode::Path)) return corrupt("unknown new-tet list mode");
  r.newTets.clear();
  const uint32_t nc = uint32_t(r.candidates.size());
  ByteReader& tetsIn = r.column(SplitColumn::NewTets);
  // A vertex by its place among j's neighbours, or past them its id.
  // (an id that the map does not hold becomes V: invalid below)
  auto named = [&](uint32_t x) {
    uint32_t v = V;
    return x < nc ? r.candidates[x] : toLocal(r, x - nc, v) ? v : V;
  };
  auto read = [&](uint32_t& v) {
    uint32_t x;
    if (!tetsIn.varint(x)) return false;
    v = named(x);
    return true;
  };
  auto valid = [&](uint32_t v) { return v < V && v != j; };
  if (RingMode(mode) == RingMode::Pairs) {
    for (uint32_t n = 0; n < m; ++n) {
      uint32_t a, b;
      if (!read(a) || !read(b)) return fail(Status::Truncated, "split chunk: record ends early");
      if (!valid(a) || !valid(b) || a == b)
        return fail(Status::OutOfRange, "split chunk: a new tet has an invalid vertex");
      r.newTets.insert(r.newTets.end(), {i, j, a, b});
    }
  } else {
    const bool cycle = RingMode(mode) == RingMode::Cycle;
    if (cycle && m < 3) return corrupt("a link cycle of fewer than three vertices");
    const uint32_t count = cycle ? m : m + 1;
    r.ring.resize(count);
    // With flag bit 5, each vertex after the first is named among the link neighbours of the one
    // before that are not on the ring yet (vertex_link.h), or past them as above.
    uint64_t used = 0;
    uint32_t from = VertexLink::kNone;
    for (uint32_t& v : r.ring) {
      uint32_t x;
      if (!tetsIn.varint(x)) return fail(Status::Truncated, "split chunk: record ends early");
      const uint32_t near = from != VertexLink::kNone ? r.link.choices(from, used) : 0;
      v = x < near ? r.link.choice(from, used, x) : named(x - near);
      if (!valid(v)) return fail(Status::OutOfRange, "split chunk: a new tet has an invalid vertex");
      from = r.ringWalk ? r.link.localOf(v) : VertexLink::kNone;
      if (from != VertexLink::kNone) used |= uint64_t(1) << from;
    }
    for (uint32_t n = 0; n < m; ++n) {
      const uint32_t a = r.ring[n], b = r.ring[(n + 1) % count];
      if (a == b) return fail(Status::OutOfRange, "split chunk: a new tet has an invalid vertex");
      r.newTets.insert(r.newTets.end(), {i, j, a, b});
    }
  }

  if (marker == 0) r.link.moved(r.newTets, r.moved);

  // Position and field values of p_i: raw floats, or grid steps relative to p_j.
  float position[3];
  const size_t F = pm.mesh.fields.size();
  r.fields.resize(F);
  // Every split chunk of a dataset carries the same kind of kept values (the undo log holds
  // that many values a split).
  if (r.keptFirst + r.keptCount > F) return corrupt("kept values of a field the mesh does not have");
  if (pm.keptFixed && (pm.keptFirst != r.keptFirst || pm.keptCount != r.keptCount))
    return corrupt("kept values of other fields than the dataset's earlier splits");
  ByteReader& positionIn = r.column(SplitColumn::Position);
  ByteReader& valuesIn = r.column(SplitColumn::Values);
  if (r.lossless) {
    for (float& x : position)
      if (!positionIn.f32(x)) return fail(Status::Truncated, "split chunk: record ends early");
    for (float& x : r.fields)
      if (!valuesIn.f32(x)) return fail(Status::Truncated, "split chunk: record ends early");
    for (float& x : r.jFields)
      if (!valuesIn.f32(x)) return fail(Status::Truncated, "split chunk: record ends early");
    for (float x : position)
      if (!std::isfinite(x)) return fail(Status::NonFinite, "split chunk: a vertex position is not finite");
  } else {
    auto predicted = [&](ByteReader& in, const QuantAxis& axis, float base, float& out) {
      uint32_t d;
      if (!in.varint(d)) return false;
      int64_t qv = int64_t(axis.quantize(base)) + unzigzag(d);
      if (qv < 0 || qv > int64_t(axis.maxQ)) return false;
      out = axis.dequantize(uint32_t(qv));
      return true;
    };
    const float* pj = &pm.mesh.positions[3 * size_t(j)];
    for (int k = 0; k < 3; ++k)
      if (!predicted(positionIn, q.position[k], pj[k], position[k]))
        return corrupt("a position leaves the grid or the record ends early");
    for (size_t f = 0; f < F; ++f)
      if (!predicted(valuesIn, q.field[f], pm.mesh.fields[f].values[j], r.fields[f]))
        return corrupt("a field value leaves its range or the record ends early");
    for (uint32_t k = 0; k < r.keptCount; ++k) {
      const size_t f = r.keptFirst + k;
      if (!predicted(valuesIn, q.field[f], pm.mesh.fields[f].values[j], r.jFields[k]))
        return corrupt("a field value leaves its range or the record ends early");
    }
  }
  if (r.remaining == 1 && !r.atEnd()) return corrupt("bytes after the last split");

  pm.keptFirst = r.keptFirst;
  pm.keptCount = r.keptCount;
  pm.keptFixed = true;
  SplitOp op{j, r.moved, r.newTets, position, r.fields.data(), r.keptCount ? r.jFields.data() : nullptr};
  applySplit(pm, op, changed);
  r.prevJ = uint32_t(j64);  // (stable: the next record's delta is from it)
  --r.remaining;
  return Result::success();
}

Result endSplits(const SplitReader& r) {
  if (r.remaining != 0) return corrupt(std::to_string(r.remaining) + " splits not applied");
  if (!r.atEnd()) return corrupt("bytes after the last split");
  return Result::success();
}

}  // namespace tetstream
