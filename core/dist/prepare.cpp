#include "dist/prepare.h"

#include <algorithm>
#include <cmath>

#include "adjacency.h"
#include "dist/units.h"
#include "quantize.h"

namespace tetstream::dist {

// The fields every rank read, compared (ranks without tets take them).
Result agreeOnFields(Comm& comm, TetMesh& mesh) {
  Bytes mine;
  Writer w(mine);
  w.put<uint8_t>(mesh.tetCount() > 0);
  w.put<uint64_t>(mesh.fields.size());
  for (const ScalarField& f : mesh.fields) w.putString(f.name);
  const std::vector<Bytes> all = comm.allGather(mine);
  std::vector<std::string> names;
  int from = -1;
  for (int r = 0; r < comm.size(); ++r) {
    Reader in(all[size_t(r)]);
    if (!in.get<uint8_t>()) continue;
    std::vector<std::string> theirs(in.get<uint64_t>());
    for (std::string& n : theirs) n = in.getString();
    if (from < 0) {
      names = theirs;
      from = r;
    } else if (theirs != names) {
      auto list = [](const std::vector<std::string>& v) {
        std::string s;
        for (const std::string& n : v) s += (s.empty() ? "" : ", ") + n;
        return "(" + s + ")";
      };
      return fail(Status::Corrupt, "the pieces of rank " + std::to_string(r) + " have the fields " + list(theirs) +
                                       ", those of rank " + std::to_string(from) + " " + list(names) +
                                       ": every piece must have the same point arrays");
    }
  }
  if (from < 0) return fail(Status::NoTets, "the input has no tetrahedra");
  if (mesh.tetCount() == 0) {
    mesh.fields.clear();
    for (const std::string& n : names) mesh.fields.push_back({n, {}});
  }
  return Result::success();
}

// What every rank's reader said: the format as the first rank that read anything saw it (said
// to be its share when ranks read shares), and every note once, with the ranks that made it
// unless every rank that read anything did.
void gatherReadReports(Comm& comm, const ReadReport& report, std::string& format, std::vector<std::string>& notes) {
  Bytes mine;
  Writer w(mine);
  w.putString(report.format);
  w.put<uint8_t>(report.shared);
  w.put<uint64_t>(report.notes.size());
  for (const std::string& n : report.notes) w.putString(n);
  const std::vector<Bytes> all = comm.allGather(mine);
  std::vector<std::pair<std::string, std::vector<int>>> said;
  int readers = 0;
  for (int r = 0; r < comm.size(); ++r) {
    Reader in(all[size_t(r)]);
    const std::string f = in.getString();
    const bool shared = in.get<uint8_t>();
    readers += !f.empty();
    if (format.empty() && !f.empty()) format = shared ? "rank " + std::to_string(r) + "'s share: " + f : f;
    for (uint64_t k = in.get<uint64_t>(); k-- > 0 && in.ok();) {
      std::string n = in.getString();
      auto it = std::find_if(said.begin(), said.end(), [&](const auto& x) { return x.first == n; });
      if (it == said.end()) it = said.insert(said.end(), {std::move(n), {}});
      it->second.push_back(r);
    }
  }
  for (const auto& [text, ranks] : said) {
    if (int(ranks.size()) >= readers || comm.size() == 1) {
      notes.push_back(text);
      continue;
    }
    std::string who;
    for (int r : ranks) who += (who.empty() ? "" : ", ") + std::to_string(r);
    notes.push_back((ranks.size() == 1 ? "rank " : "ranks ") + who + ": " + text);
  }
}

// Reads this rank's share: its files of a listing, or its slice of the tets of a single file.
Result readShare(Comm& comm, const std::string& input, ReadOptions read, TetMesh& mesh, ReadReport& report) {
  read.shareIndex = uint32_t(comm.rank());
  read.shareCount = uint32_t(comm.size());
  if (Result r = readMesh(input, mesh, report, read); !r) return r;
  if (!report.shared && comm.size() > 1) {
    const uint64_t T = mesh.tetCount(), from = T * uint64_t(comm.rank()) / uint64_t(comm.size()),
                   to = T * uint64_t(comm.rank() + 1) / uint64_t(comm.size());
    mesh.tets = std::vector<uint32_t>(mesh.tets.begin() + ptrdiff_t(4 * from), mesh.tets.begin() + ptrdiff_t(4 * to));
  }
  for (float x : mesh.positions)
    if (!std::isfinite(x)) return fail(Status::NonFinite, input + ": a point has a coordinate that is not finite");
  return Result::success();
}

// The manifest's header fields, agreed: bounds and field ranges over the owned points, counts
// (each tet counted by the owner of its first vertex).
void describeWhole(Comm& comm, const PartMesh& p, const std::string& name, Manifest& m) {
  const size_t F = p.mesh.fields.size();
  std::vector<double> lo, hi;
  ownedExtent(p, lo, hi);
  std::vector<uint64_t> counts(2, 0);
  counts[0] = ownedCount(p);
  for (uint32_t t = 0; t < p.mesh.tetCount(); ++t) counts[1] += p.owned[p.mesh.tets[4 * size_t(t)]];
  comm.minInPlace(lo);
  comm.maxInPlace(hi);
  comm.sumInPlace(counts);
  m.name = name;
  for (int k = 0; k < 3; ++k) m.bounds.min[k] = float(lo[size_t(k)]), m.bounds.max[k] = float(hi[size_t(k)]);
  m.vertices = uint32_t(counts[0]);
  m.tets = uint32_t(counts[1]);
  m.fields.clear();
  for (size_t f = 0; f < F; ++f) {
    Range r{float(lo[3 + f]), float(hi[3 + f])};
    if (!(r.min <= r.max)) r = {0, 0};
    m.fields.push_back({p.mesh.fields[f].name, r});
  }
}

// Re-orients negatively oriented tets (an odd permutation), as packMesh does; returns how many
// of those this rank counts (those whose first vertex it owns).
uint64_t orient(PartMesh& p) {
  uint64_t flipped = 0;
  for (uint32_t t = 0; t < p.mesh.tetCount(); ++t)
    if (tetVolume(p.mesh, t) < 0) {
      uint32_t* v = &p.mesh.tets[4 * size_t(t)];
      std::swap(v[2], v[3]);
      flipped += p.owned[v[0]];
    }
  return flipped;
}

// The quantization grid: 16 bits unless snapping to it would flatten or turn over a tet somewhere.
void chooseGrid(Comm& comm, PartMesh& p, Manifest& m, bool nonFinite, const PackOptions& opt,
                std::vector<std::string>& notes) {
  m.lossless = opt.lossless || nonFinite;
  if (nonFinite && !opt.lossless) notes.push_back("fields contain NaN or infinite values: stored lossless (float32)");
  if (m.lossless) return;
  std::vector<float> snapped(p.mesh.positions.size());
  for (int bits : {16, 20, 24}) {
    m.positionBits = bits;
    const Quantizer q = makeQuantizer(m);
    for (size_t k = 0; k < snapped.size(); ++k) snapped[k] = q.position[k % 3].snap(p.mesh.positions[k]);
    std::vector<uint64_t> broken(1, 0);
    for (uint32_t t = 0; t < p.mesh.tetCount(); ++t) {
      const uint32_t* v = &p.mesh.tets[4 * size_t(t)];
      if (!p.owned[v[0]]) continue;
      auto volume = [v](const std::vector<float>& x) {
        return tetVolume(&x[3 * size_t(v[0])], &x[3 * size_t(v[1])], &x[3 * size_t(v[2])], &x[3 * size_t(v[3])]);
      };
      broken[0] += volume(p.mesh.positions) > 0 && !(volume(snapped) > 0);
    }
    comm.sumInPlace(broken);
    if (broken[0] == 0) break;
    notes.push_back(std::to_string(broken[0]) + " tetrahedra are too small for a " + std::to_string(bits) +
                    "-bit position grid" + (bits < 24 ? ": trying more bits" : ": storing lossless"));
    if (bits == 24) m.lossless = true;
  }
  if (m.lossless) {
    m.positionBits = 16;
    return;
  }
  p.mesh.positions = std::move(snapped);
  const Quantizer q = makeQuantizer(m);
  for (size_t f = 0; f < p.mesh.fields.size(); ++f)
    for (float& x : p.mesh.fields[f].values) x = q.field[f].snap(x);
}

// The mean volume of an interior vertex over the whole mesh (SimplifyPart::meanVertexVolume), as
// the simplifier's set-up computes it: a quarter of each non-flat tet's volume to each vertex.
double meanVertexVolume(Comm& comm, const PartMesh& p) {
  FaceAdjacency adj;
  buildFaceAdjacency(p.mesh.tets, p.mesh.vertexCount(), adj);
  std::vector<uint8_t> boundary(p.mesh.vertexCount(), 0);
  for (size_t h = 0; h < adj.opposite.size(); ++h)
    if (adj.opposite[h] == kNoNeighbor)
      for (int k = 0; k < 4; ++k)
        if (k != int(h & 3)) boundary[p.mesh.tets[(h & ~size_t(3)) + size_t(k)]] = 1;
  std::vector<double> volume(p.mesh.vertexCount(), 0);
  for (uint32_t t = 0; t < p.mesh.tetCount(); ++t) {
    const double q = std::abs(tetVolume(p.mesh, t)) / 4;
    for (int k = 0; k < 4; ++k) volume[p.mesh.tets[4 * size_t(t) + size_t(k)]] += q;
  }
  std::vector<double> sums(4, 0);  // interior volume, interior count, all volume, all count
  for (uint32_t v = 0; v < p.mesh.vertexCount(); ++v)
    if (p.owned[v]) {
      sums[0] += boundary[v] ? 0 : volume[v];
      sums[1] += boundary[v] ? 0 : 1;
      sums[2] += volume[v];
      sums[3] += 1;
    }
  comm.sumInPlace(sums);
  const double inside = sums[1] ? sums[0] / sums[1] : 0, all = sums[3] ? sums[2] / sums[3] : 0;
  return inside > 0 ? inside : all > 0 ? all : INFINITY;
}

}  // namespace tetstream::dist
