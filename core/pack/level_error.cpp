#include "pack/level_error.h"

#include <algorithm>
#include <cmath>

#include "adjacency.h"

namespace tetstream {
namespace {

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

uint32_t mix(uint32_t x) {
  x *= 0x9e3779b1u;
  x ^= x >> 16;
  x *= 0x85ebca6bu;
  x ^= x >> 13;
  return x;
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

void LevelErrorMeter::link(uint32_t v, uint32_t t) {
  Sample& s = samples_[v];
  s.tet = t;
  s.prev = kNone;
  s.next = head_[t];
  if (head_[t] != kNone) samples_[head_[t]].prev = v;
  head_[t] = v;
  occupied_.set(t);
}

void LevelErrorMeter::unlink(uint32_t v) {
  Sample& s = samples_[v];
  if (s.tet >= kVertex) return;
  if (s.prev != kNone) samples_[s.prev].next = s.next;
  else if ((head_[s.tet] = s.next) == kNone) occupied_.clear(s.tet);
  if (s.next != kNone) samples_[s.next].prev = s.prev;
  s.tet = kNone;
}

void LevelErrorMeter::setError(uint32_t v, uint32_t t, const double l[4]) {
  samples_[v].err = float(std::abs(samples_[v].value - interpolate(mesh_->tets, levelValues(), t, l)));
}

void LevelErrorMeter::becomeVertex(uint32_t v, uint32_t level) {
  unlink(v);
  samples_[v].tet = kVertex;
  samples_[v].err = float(std::abs(samples_[v].value - double(levelValues()[level])));
}

// From tet t across the face of the most negative coordinate (across(t, k): the tet beyond the
// face opposite corner k, or kNone); the best tet seen wins when the walk leaves the mesh or
// takes too long. Returns the smallest coordinate there (negative: outside the mesh).
template <typename Across>
double LevelErrorMeter::walk(uint32_t v, uint32_t t, Across across) {
  const float* x = samples_[v].x;
  uint32_t bestTet = kNone;
  double best = -HUGE_VAL, bestL[4];
  for (int step = 0; step < 256; ++step) {
    TetFrame frame;
    if (!frame.make(*this, t)) break;  // flat: no way on
    double l[4];
    const double lo = frame.coordinates(x, l);
    if (lo > best) {
      best = lo;
      bestTet = t;
      std::copy(l, l + 4, bestL);
    }
    if (lo >= 0) break;
    const uint32_t next = across(t, int(std::min_element(l, l + 4) - l));
    if (next == kNone) break;
    t = next;
  }
  if (bestTet == kNone) return best;
  unlink(v);
  link(v, bestTet);
  setError(v, bestTet, bestL);
  markOutside(v, best < 0);
  return best;
}

void LevelErrorMeter::markOutside(uint32_t v, bool outside) {
  if (!outside) return outside_.clear(v);
  outside_.set(v);
  if (!listed_.test(v)) {
    listed_.set(v);
    outsideList_.push_back(v);
  }
}

// The tet beyond the face of t opposite corner k, from the stars of the face's vertices.
uint32_t LevelErrorMeter::acrossByStars(uint32_t t, int k) const {
  const uint32_t* v = &mesh_->tets[4 * size_t(t)];
  const uint32_t b = v[(k + 2) & 3], c = v[(k + 3) & 3];
  for (uint32_t corner : stars_->corners(v[(k + 1) & 3])) {
    const uint32_t u = corner >> 2;
    const uint32_t* w = &mesh_->tets[4 * size_t(u)];
    if (u != t && (w[0] == b || w[1] == b || w[2] == b || w[3] == b) && (w[0] == c || w[1] == c || w[2] == c || w[3] == c))
      return u;
  }
  return kNone;
}

// The input vertices outside the level mesh keep the tet they were least outside of, but splits
// elsewhere move the boundary: walk each from there again (the boundary layer of Blunt Fin's
// samples kept 5× the RMS of a fresh location without this).
void LevelErrorMeter::relocateOutside() {
  size_t keep = 0;
  for (uint32_t v : outsideList_) {
    if (outside_.test(v) && samples_[v].tet < kVertex &&
        walk(v, samples_[v].tet, [this](uint32_t t, int k) { return acrossByStars(t, k); }) < 0) {
      outsideList_[keep++] = v;
    } else {
      outside_.clear(v);
      listed_.clear(v);
    }
  }
  outsideList_.resize(keep);
}

void LevelErrorMeter::begin(std::span<const float> positions, std::span<const float> values, const TetMesh& level,
                            const StarPool* stars, size_t field, std::span<const uint32_t> levelOf,
                            std::span<const uint32_t> baseOf, uint32_t maxSamples) {
  mesh_ = &level;
  stars_ = stars;
  field_ = field;
  const std::vector<uint32_t>& tets = level.tets;
  const size_t V = values.size();
  // An even sample: by a hash of the id, as samples by id alone would follow the numbering's
  // pattern (every fourth column of a grid, say).
  const uint64_t stride = (V + maxSamples - 1) / std::max(maxSamples, 1u);
  samples_.resize(V);
  sampled_.resize(V);
  outside_.resize(V);
  listed_.resize(V);
  for (uint32_t v = 0; v < V; ++v) {
    const bool in = stride <= 1 || mix(v) % stride == 0;
    samples_[v] = {{positions[3 * v], positions[3 * v + 1], positions[3 * v + 2]}, values[v], 0.0f, in ? kNone : kSkip, kNone, kNone};
    if (in) sampled_.set(v);
  }
  head_.assign(level.tetCount(), kNone);
  occupied_.resize(level.tetCount());
  inputOf_.assign(level.vertexCount(), kNone);
  std::vector<uint32_t> someTet(level.vertexCount(), kNone);  // per base vertex: a tet around it
  for (size_t c = 0; c < tets.size(); ++c) someTet[tets[c]] = uint32_t(c / 4);
  // Across faces by the level's stars when it has them (the encoder's meter), else by a face
  // adjacency built here (measure(), on its own thread): the base's faces are not paired twice.
  FaceAdjacency adjacency;
  if (!stars_) buildFaceAdjacency(tets, level.vertexCount(), adjacency);
  auto across = [&](uint32_t t, int k) {
    if (stars_) return acrossByStars(t, k);
    const uint32_t h = adjacency.opposite[4 * size_t(t) + size_t(k)];
    return h == kNoNeighbor ? kNone : h >> 2;
  };
  for (uint32_t v = 0; v < V; ++v) {
    if (levelOf[v] != kNone) inputOf_[levelOf[v]] = v;
    if (!sampled_.test(v) || !std::isfinite(values[v])) continue;
    if (levelOf[v] != kNone) {
      if (someTet[levelOf[v]] != kNone) becomeVertex(v, levelOf[v]);
      continue;
    }
    const uint32_t at = levelOf[baseOf[v]];
    if (at == kNone || someTet[at] == kNone) continue;  // in no tet
    walk(v, someTet[at], across);
  }
}

LevelError LevelErrorMeter::measure(std::span<const float> positions, std::span<const float> values, const TetMesh& level,
                                    size_t field, std::span<const uint32_t> levelOf, std::span<const uint32_t> baseOf) {
  LevelErrorMeter m;
  m.begin(positions, values, level, nullptr, field, levelOf, baseOf, ~0u);
  return m.current();
}

void LevelErrorMeter::afterSplit(uint32_t input, uint32_t j, std::span<const uint32_t> moved, uint32_t firstNew,
                                 bool jValueChanged) {
  const uint32_t tetCount = mesh_->tetCount();
  head_.resize(tetCount, kNone);
  occupied_.resize(tetCount);
  inputOf_.push_back(input);
  if (sampled_.test(input)) {
    if (std::isfinite(samples_[input].value)) becomeVertex(input, mesh_->vertexCount() - 1);
    else unlink(input);
  }

  // The input vertices inside the moved tets are located again among the moved and the new
  // tets. Most stay in their old tet (a moved tet keeps part of its region); the others try the
  // rest. A tet's frame is set up when first needed.
  bool any = false;
  for (uint32_t t : moved) any |= occupied_.test(t);
  if (!any) return updateAroundJ(j, jValueChanged);
  const size_t n = moved.size() + (tetCount - firstNew);
  candidates_.assign(moved.begin(), moved.end());
  for (uint32_t t = firstNew; t < tetCount; ++t) candidates_.push_back(t);
  frames_.resize(n);
  frameState_.assign(n, 0);  // 0: not set up, 1: set up, 2: flat
  auto frame = [&](size_t c) -> const TetFrame* {
    if (frameState_[c] == 0) frameState_[c] = frames_[c].make(*this, candidates_[c]) ? 1 : 2;
    return frameState_[c] == 1 ? &frames_[c] : nullptr;
  };
  pending_.clear();
  pendingFrom_.clear();
  for (uint32_t k = 0; k < moved.size(); ++k) {
    if (!occupied_.test(moved[k])) continue;
    for (uint32_t v = head_[moved[k]], next; v != kNone; v = next) {
      next = samples_[v].next;
      double l[4];
      const TetFrame* f = frame(k);
      if (f && f->coordinates(samples_[v].x, l, 0.0) >= 0) {
        setError(v, moved[k], l);
        markOutside(v, false);
      } else {
        unlink(v);
        pending_.push_back(v);
        pendingFrom_.push_back(k);
      }
    }
  }
  for (size_t s = 0; s < pending_.size(); ++s) {
    const uint32_t v = pending_[s], old = pendingFrom_[s];
    const float* x = samples_[v].x;
    size_t found = n;
    double l[4];
    for (size_t c = 0; c < n && found == n; ++c) {
      const TetFrame* f = c != old ? frame(c) : nullptr;
      if (f && f->coordinates(x, l, 0.0) >= 0) found = c;
    }
    markOutside(v, found == n);
    if (found == n) {  // outside all of them: the one it is least outside of
      double best = -HUGE_VAL;
      for (size_t c = 0; c < n; ++c) {
        const TetFrame* f = frame(c);
        if (!f) continue;
        const double lo = f->coordinates(x, l);
        if (lo > best) best = lo, found = c;
      }
      if (found == n) continue;  // all flat
    }
    frames_[found].coordinates(x, l);
    link(v, candidates_[found]);
    setError(v, candidates_[found], l);
  }

  updateAroundJ(j, jValueChanged);
}

// A new value at j: every tet around it interpolates anew.
void LevelErrorMeter::updateAroundJ(uint32_t j, bool jValueChanged) {
  if (!jValueChanged) return;
  if (inputOf_[j] != kNone && samples_[inputOf_[j]].tet == kVertex) becomeVertex(inputOf_[j], j);  // (not kSkip)
  for (uint32_t c : stars_->corners(j)) {
    const uint32_t t = c >> 2;
    TetFrame f;
    if (!occupied_.test(t) || !f.make(*this, t)) continue;
    for (uint32_t v = head_[t]; v != kNone; v = samples_[v].next) {
      double l[4];
      f.coordinates(samples_[v].x, l);
      setError(v, t, l);
    }
  }
}

LevelError LevelErrorMeter::current() {
  if (stars_) relocateOutside();
  double sum = 0, max = 0;
  size_t n = 0;
  for (const Sample& s : samples_) {
    if (s.tet >= kSkip || !std::isfinite(s.err)) continue;
    sum += double(s.err) * s.err;
    max = std::max(max, double(s.err));
    ++n;
  }
  return {n ? std::sqrt(sum / double(n)) : 0.0, max};
}

}  // namespace tetstream
