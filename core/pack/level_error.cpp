#include "pack/level_error.h"

#include <algorithm>
#include <cmath>
#include <thread>
#include <utility>

namespace tetstream {
namespace {

// The tets of a star, from its corners (4t + k).
struct Tets {
  std::span<const uint32_t> corners;
  struct It {
    const uint32_t* c;
    uint32_t operator*() const { return *c >> 2; }
    It& operator++() { return ++c, *this; }
    bool operator!=(const It& o) const { return c != o.c; }
  };
  It begin() const { return {corners.data()}; }
  It end() const { return {corners.data() + corners.size()}; }
};

uint32_t mixTet(uint32_t x) {
  x *= 0x9e3779b1u;
  return x ^ x >> 15;
}

// The level's field at coordinates l of tet t, clamped to the tet (outside it, a point of the
// tet stands in).
double interpolate(const std::vector<uint32_t>& tets, const std::vector<float>& values, uint32_t t, const double l[4]) {
  const uint32_t* v = &tets[4 * size_t(t)];
  double sum = 0, weight = 0;
  for (int k = 0; k < 4; ++k) {
    const double w = std::max(0.0, l[k]);
    sum += w * values[v[k]];
    weight += w;
  }
  return sum / weight;
}

}  // namespace

// l_k = r_k · (x − p0) for k = 1..3, with r the rows of the inverse of the edge matrix
// (r_m = e_{m+1} × e_{m+2} / det), and l_0 = 1 − l_1 − l_2 − l_3.
bool LevelErrorMeter::TetFrame::make(const LevelErrorMeter& m, uint32_t t) {
  const uint32_t* v = &m.mesh_->tets[4 * size_t(t)];
  const float* p = m.mesh_->positions.data();
  double e[3][3];
  for (int a = 0; a < 3; ++a) p0[a] = p[3 * size_t(v[0]) + a];
  for (int m = 0; m < 3; ++m)
    for (int a = 0; a < 3; ++a) e[m][a] = p[3 * size_t(v[m + 1]) + a] - p0[a];
  for (int m = 0; m < 3; ++m) {
    const double* u = e[(m + 1) % 3];
    const double* w = e[(m + 2) % 3];
    r[m][0] = u[1] * w[2] - u[2] * w[1];
    r[m][1] = u[2] * w[0] - u[0] * w[2];
    r[m][2] = u[0] * w[1] - u[1] * w[0];
  }
  const double det = e[0][0] * r[0][0] + e[0][1] * r[0][1] + e[0][2] * r[0][2];
  if (!(std::abs(det) > 0) || !std::isfinite(det)) return false;
  for (auto& row : r)
    for (double& x : row) x /= det;
  return true;
}

double LevelErrorMeter::TetFrame::coordinates(const float* x, double l[4], double stopBelow) const {
  const double y[3] = {x[0] - p0[0], x[1] - p0[1], x[2] - p0[2]};
  double lo = HUGE_VAL, rest = 1;
  for (int m = 0; m < 3; ++m) {
    l[m + 1] = r[m][0] * y[0] + r[m][1] * y[1] + r[m][2] * y[2];
    if (l[m + 1] < stopBelow) return l[m + 1];
    lo = std::min(lo, l[m + 1]);
    rest -= l[m + 1];
  }
  l[0] = rest;
  return std::min(lo, rest);
}

const LevelErrorMeter::TetFrame* LevelErrorMeter::frameOf(Scratch& s, uint32_t t) const {
  Scratch::FrameSlot& slot = s.frames[mixTet(t) & (s.frames.size() - 1)];
  if (slot.tet != t || slot.epoch != s.epoch) {
    slot.tet = t;
    slot.epoch = s.epoch;
    slot.solid = slot.frame.make(*this, t);
  }
  return slot.solid ? &slot.frame : nullptr;
}

float LevelErrorMeter::errorAt(uint32_t v, uint32_t t, const double l[4]) const {
  return float(std::abs(samples_[v].value - interpolate(mesh_->tets, levelValues(), t, l)));
}

void LevelErrorMeter::becomeVertex(uint32_t v, uint32_t level) {
  samples_[v].tet = kVertex;
  samples_[v].err = float(std::abs(samples_[v].value - double(levelValues()[level])));
  outside_[v] = 0;
}

// From input vertex v's tet towards it, across the face of the most negative coordinate. Where
// that face is on the boundary, across the next negative one that is not (and not back): around
// a concave part of the boundary, where the straight way would leave a non-convex mesh. The
// best tet seen wins when no way is left or the walk takes too long.
LevelErrorMeter::Found LevelErrorMeter::walk(Scratch& s, uint32_t v) const {
  const float* x = samples_[v].x;
  uint32_t t = samples_[v].tet;
  uint32_t bestTet = kNone, previous = kNone;
  double best = -HUGE_VAL, bestL[4];
  for (int step = 0; step < 256; ++step) {
    const TetFrame* frame = frameOf(s, t);
    if (!frame) break;  // flat: no way on
    double l[4];
    const double lo = frame->coordinates(x, l);
    if (lo > best) {
      best = lo;
      bestTet = t;
      std::copy(l, l + 4, bestL);
    }
    if (lo >= kInside) break;
    int order[4] = {0, 1, 2, 3};
    std::sort(order, order + 4, [&](int a, int b) { return l[a] < l[b]; });
    uint32_t next = kNone;
    for (int n = 0; n < 4 && l[order[n]] < 0 && next == kNone; ++n) {
      const uint32_t u = acrossByStars(s, t, order[n]);
      if (u != previous || n == 0) next = u;
    }
    if (next == kNone) break;
    previous = t;
    t = next;
  }
  if (bestTet == kNone) return {kNone, 0.0f, true, -HUGE_VAL};
  return {bestTet, errorAt(v, bestTet, bestL), best < kInside, best};
}

// Whether one of `tets` holds input vertex v (then `found` says where). If not, `found` becomes
// the one of them that v is least outside of, if it is less outside of it than of found's.
template <typename Tets>
bool LevelErrorMeter::lookAmong(Scratch& s, uint32_t v, const Tets& tets, Found& found) const {
  for (uint32_t t : tets) {
    const TetFrame* f = frameOf(s, t);
    double l[4];
    if (!f) continue;
    const double lo = f->coordinates(samples_[v].x, l);
    if (lo <= found.lo) continue;
    found = {t, errorAt(v, t, l), lo < kInside, lo};
    if (!found.outside) return true;
  }
  return false;
}

// The tet beyond the face of t opposite corner k, from the stars of the face's vertices.
uint32_t LevelErrorMeter::acrossByStars(Scratch& s, uint32_t t, int k) const {
  const uint32_t face = 4 * t + uint32_t(k);
  Scratch::AcrossSlot& slot = s.across[mixTet(face) & (s.across.size() - 1)];
  if (slot.face != face || slot.epoch != s.epoch) {
    slot.face = face;
    slot.epoch = s.epoch;
    slot.tet = acrossByStarsUncached(t, k);
  }
  return slot.tet;
}

uint32_t LevelErrorMeter::acrossByStarsUncached(uint32_t t, int k) const {
  const uint32_t* v = &mesh_->tets[4 * size_t(t)];
  uint32_t a = v[(k + 1) & 3], b = v[(k + 2) & 3], c = v[(k + 3) & 3];
  // Around the face's corner with the fewest tets.
  if (stars_->corners(b).size() < stars_->corners(a).size()) std::swap(a, b);
  if (stars_->corners(c).size() < stars_->corners(a).size()) std::swap(a, c);
  for (uint32_t corner : stars_->corners(a)) {
    const uint32_t u = corner >> 2;
    const uint32_t* w = &mesh_->tets[4 * size_t(u)];
    if (u != t && (w[0] == b || w[1] == b || w[2] == b || w[3] == b) &&
        (w[0] == c || w[1] == c || w[2] == c || w[3] == c))
      return u;
  }
  return kNone;
}

// Input vertex v left its tet, or was outside the mesh: a walk from there. If that ends outside,
// a look among the tets of the level vertex that v was collapsed into (directly or not), where
// v lies unless a collapse along the boundary moved the boundary past it. (A walk can leave a
// non-convex mesh on the way to a point inside it, e.g. input vertices near a fin.) If
// v is outside the mesh after all, it takes the tet it is least outside of among those, the
// walk's, and the tets around the corners of the best of these: often much nearer than the
// walk's own where a coarse level cuts across a curved boundary (around holes).
LevelErrorMeter::Found LevelErrorMeter::locateAgain(Scratch& s, uint32_t v) const { return nearby(s, v, walk(s, v)); }

LevelErrorMeter::Found LevelErrorMeter::nearby(Scratch& s, uint32_t v, Found found) const {
  if (!found.outside || found.tet == kNone) return found;
  uint32_t x = v;
  while (levelOf_[x] == kNone && intoOf_[x] != x) x = intoOf_[x];
  if (levelOf_[x] != kNone && lookAmong(s, v, Tets{stars_->corners(levelOf_[x])}, found)) return found;
  uint32_t ended[4];
  std::copy_n(&mesh_->tets[4 * size_t(found.tet)], 4, ended);
  for (uint32_t corner : ended)
    if (lookAmong(s, v, Tets{stars_->corners(corner)}, found)) break;
  return found;
}

void LevelErrorMeter::place(uint32_t v, const Found& f) {
  if (f.tet == kNone) return;
  samples_[v].tet = f.tet;
  samples_[v].err = f.err;
  outside_[v] = f.outside;
}

void LevelErrorMeter::begin(std::span<const float> positions, std::span<const float> values, const TetMesh& level,
                            size_t field, std::vector<uint32_t> levelOf, std::span<const uint32_t> baseOf,
                            std::span<const uint32_t> intoOf) {
  intoOf_ = intoOf;
  levelOf_ = std::move(levelOf);
  mesh_ = &level;
  stars_ = nullptr;
  field_ = field;
  Scratch& s = scratch_[0];
  s.next();
  const std::vector<uint32_t>& tets = level.tets;
  const size_t V = values.size();
  samples_.resize(V);
  outside_.assign(V, 0);
  for (uint32_t v = 0; v < V; ++v)
    samples_[v] = {{positions[3 * v], positions[3 * v + 1], positions[3 * v + 2]}, values[v], 0.0f, kNone};
  inputOf_.assign(level.vertexCount(), kNone);
  // The base's stars (it is small), for the same search as at every later level; the meter
  // keeps none of it (current() is given the encoder's).
  StarPool stars;
  stars.reserve(level.vertexCount(), tets.size());
  for (uint32_t x = 0; x < level.vertexCount(); ++x) stars.addVertex(8);
  for (size_t c = 0; c < tets.size(); ++c) stars.add(tets[c], uint32_t(c));
  stars_ = &stars;
  // Vertices next to each other in the numbering mostly lie in the same tet: the last one found
  // is tried first.
  uint32_t last = kNone;
  for (uint32_t v = 0; v < V; ++v) {
    if (levelOf_[v] != kNone) inputOf_[levelOf_[v]] = v;
    const uint32_t at = levelOf_[baseOf[v]];
    if (!std::isfinite(values[v]) || at == kNone || stars.corners(at).empty()) continue;  // in no tet
    if (levelOf_[v] != kNone) {
      becomeVertex(v, levelOf_[v]);
      continue;
    }
    if (last != kNone) {
      const TetFrame* frame = frameOf(s, last);
      double l[4] = {};
      if (frame && frame->coordinates(samples_[v].x, l, kInside) >= kInside) {  // (l is whole then)
        place(v, {last, errorAt(v, last, l), false, 0.0});
        continue;
      }
    }
    samples_[v].tet = stars.corners(at)[0] >> 2;  // (where the walk starts)
    const Found f = locateAgain(s, v);
    place(v, f);
    last = f.outside ? kNone : f.tet;
  }
  stars_ = nullptr;
}

LevelError LevelErrorMeter::total() const {
  double sum = 0, max = 0;
  size_t n = 0;
  for (const Sample& s : samples_) {
    if (s.tet == kNone || !std::isfinite(s.err)) continue;
    sum += double(s.err) * s.err;
    max = std::max(max, double(s.err));
    ++n;
  }
  return {n ? std::sqrt(sum / double(n)) : 0.0, max};
}

void LevelErrorMeter::markDirty(uint32_t t) {
  if (t >= dirty_.size() * 64) dirty_.resize(std::max<size_t>(t / 64 + 1, 2 * dirty_.size()), 0);
  dirty_[t >> 6] |= uint64_t(1) << (t & 63);
}

void LevelErrorMeter::afterSplit(uint32_t input, uint32_t j, std::span<const uint32_t> moved, const StarPool& stars,
                                 bool jValueChanged) {
  restored_.push_back(input);
  for (uint32_t t : moved) markDirty(t);
  if (!jValueChanged) return;
  revalued_.push_back(j);
  for (uint32_t c : stars.corners(j)) markDirty(c >> 2);
}

// Input vertices [begin, end): those in a dirty tet are tested there (most are still inside),
// those that left it and those outside the mesh are located again. Writes only these vertices'
// samples and flags, and s.
void LevelErrorMeter::follow(Scratch& s, uint32_t begin, uint32_t end) {
  const size_t words = dirty_.size();
  for (uint32_t v = begin; v < end; ++v) {
    const uint32_t t = samples_[v].tet;
    if (t >= kVertex) continue;
    const bool dirty = (t >> 6) < words && (dirty_[t >> 6] >> (t & 63) & 1);
    if (!dirty && !outside_[v]) continue;
    if (!dirty) {  // outside the mesh: walked again, as splits elsewhere move the boundary
      const Found f = walk(s, v);
      if (f.tet != t || !f.outside) place(v, nearby(s, v, f));  // (else as it was)
      continue;
    }
    if (!outside_[v]) {
      const TetFrame* f = frameOf(s, t);
      double l[4] = {};
      if (f && f->coordinates(samples_[v].x, l, kInside) >= kInside) {  // (l is whole then)
        samples_[v].err = errorAt(v, t, l);
        continue;
      }
    }
    place(v, locateAgain(s, v));
  }
}

LevelError LevelErrorMeter::current(const TetMesh& level, const StarPool& stars, int threads) {
  mesh_ = &level;
  stars_ = &stars;
  for (uint32_t input : restored_) {
    levelOf_[input] = uint32_t(inputOf_.size());
    inputOf_.push_back(input);
    if (std::isfinite(samples_[input].value))
      becomeVertex(input, uint32_t(inputOf_.size() - 1));
    else
      samples_[input].tet = kNone;
  }
  restored_.clear();
  for (uint32_t j : revalued_)
    if (inputOf_[j] != kNone && samples_[inputOf_[j]].tet == kVertex) becomeVertex(inputOf_[j], j);
  revalued_.clear();
  // Every input vertex in a dirty tet or outside the mesh: half of them on each of two threads
  // when there are many (the tets are only read); each vertex's result is the same either way.
  const uint32_t V = uint32_t(samples_.size()), half = V / 2;
  for (Scratch& s : scratch_) s.next();
  onTwo(threads > 1 && V >= kTwoThreads, [&](int k) { follow(scratch_[k], k ? half : 0, k ? V : half); });
  std::fill(dirty_.begin(), dirty_.end(), 0);
  return total();
}

}  // namespace tetstream
