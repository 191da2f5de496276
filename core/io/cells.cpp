// From the cells a reader found to the tetrahedral mesh tetstream packs (readers.h, CellSoup):
// one implementation for every input format.
//
// 1. Coincident vertices (bit-equal float coordinates, -0 = +0) are merged into the first copy;
//    point fields are averaged over each group.
// 2. Cells become tetrahedra. A tetrahedron stays as it is. Every other cell is coned from its
//    lowest corner, m, over each face that does not contain m; a quad face is cut along the
//    diagonal through its own lowest corner. "Lowest" is first in the order of the corners'
//    coordinates (x, then y, then z; the merged vertex id only between copies left apart at one
//    position), not of their ids: the processes of a distributed pack number the pieces they read
//    each their own way, and a face two of them hold must still be cut the same way. Two cells
//    sharing a quad face therefore cut it the same way (the rule looks at the face's corners only),
//    and the faces at m are cut through m, which the cone needs. Because the lowest corner of the
//    whole cell always has its three (hexahedron), two (wedge) or one (pyramid) quad faces cut
//    through it, every hexahedron gets 6 tetrahedra, a wedge 3, a pyramid 2: the diagonal
//    configurations that need a Steiner point (cyclic diagonals, as in Schoenhardt's prism) cannot
//    arise under this rule. On an axis-aligned grid the lowest corner of a cell is its
//    (xmin, ymin, zmin) corner and every face is cut from its lowest to its highest corner: the
//    Kuhn split along the cell's main diagonal. (On a curvilinear grid the split does not follow
//    the grid: Blunt Fin's one warped cell gives an inverted tet, where the order of ids happened
//    not to; the reader says so.) A split cell's tetrahedra are oriented together by the sign of
//    their total volume, so a mirrored corner order in the input does not invert them.
// 3. Tetrahedra with a repeated vertex (collapsed cells, or duplicates that were merged) have no
//    volume and no interior: they are dropped, which keeps the mesh conforming.
// 4. Cell arrays become point fields: the value at a vertex is the average over the cells around
//    it, weighted by cell volume (unweighted where those cells are all flat).
// 5. Vertices no tetrahedron uses (mid-edge nodes, nodes of skipped cells, merged duplicates,
//    points no cell lists) are dropped and the rest renumbered in order.
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <compare>
#include <cstdio>
#include <limits>
#include <numeric>

#include "adjacency.h"
#include "io/readers.h"

namespace tetstream {
namespace vtkio {
namespace {

struct Face {
  uint8_t n;
  uint8_t v[4];
};
struct ShapeFaces {
  int count;
  Face faces[6];
};
// Faces as corner cycles, all wound the same way (outward for VTK's corner order), so that the
// cone tets of a convex cell all have one orientation; the split fixes that orientation from
// the sign of their total volume, and a tet of the other sign then means a warped cell.
constexpr ShapeFaces kFaces[4] = {
    {4, {{3, {1, 2, 3}}, {3, {0, 3, 2}}, {3, {0, 1, 3}}, {3, {0, 2, 1}}}},
    {5, {{4, {0, 3, 2, 1}}, {3, {0, 1, 4}}, {3, {1, 2, 4}}, {3, {2, 3, 4}}, {3, {3, 0, 4}}}},
    {5, {{3, {0, 1, 2}}, {3, {3, 5, 4}}, {4, {0, 3, 4, 1}}, {4, {1, 4, 5, 2}}, {4, {2, 5, 3, 0}}}},
    {6,
     {{4, {0, 3, 2, 1}},
      {4, {4, 5, 6, 7}},
      {4, {0, 1, 5, 4}},
      {4, {1, 2, 6, 5}},
      {4, {2, 3, 7, 6}},
      {4, {3, 0, 4, 7}}}},
};
constexpr const char* kShapeNames[4][2] = {
    {"tetrahedron", "tetrahedra"}, {"pyramid", "pyramids"}, {"wedge", "wedges"}, {"hexahedron", "hexahedra"}};

// Whether vertex a comes before b in the split's order: by coordinates (x, y, z), then by id.
bool lower(const float* pos, uint32_t a, uint32_t b) {
  const float* p = pos + 3 * size_t(a);
  const float* q = pos + 3 * size_t(b);
  for (int k = 0; k < 3; ++k)
    if (p[k] != q[k]) return p[k] < q[k];
  return a < b;
}

// Splits one cell (corner ids after merging; pos: the vertices' coordinates) into tets appended
// to out (4 ids each).
void splitCell(CellShape shape, const uint32_t* ids, const float* pos, std::vector<uint32_t>& out) {
  const int nc = kShapeCorners[int(shape)];
  if (shape == CellShape::Tet) {
    out.insert(out.end(), ids, ids + 4);
    return;
  }
  int m = 0;
  for (int k = 1; k < nc; ++k)
    if (lower(pos, ids[k], ids[m])) m = k;
  const uint32_t apex = ids[m];
  const ShapeFaces& sf = kFaces[int(shape)];
  for (int f = 0; f < sf.count; ++f) {
    const Face& face = sf.faces[f];
    uint32_t g[4];
    bool touches = false;
    for (int k = 0; k < face.n; ++k) {
      g[k] = ids[face.v[k]];
      touches |= face.v[k] == m;
    }
    // A face at m is cut through m by its neighbours' cones. (In a degenerate cell another
    // corner may share m's id: its faces give tets with a repeated vertex, dropped later.)
    if (touches) continue;
    if (face.n == 3) {
      out.insert(out.end(), {apex, g[0], g[1], g[2]});
      continue;
    }
    int k = 0;
    for (int q = 1; q < 4; ++q)
      if (lower(pos, g[q], g[k])) k = q;
    if (k == 0 || k == 2)
      out.insert(out.end(), {apex, g[0], g[1], g[2], apex, g[0], g[2], g[3]});
    else
      out.insert(out.end(), {apex, g[1], g[2], g[3], apex, g[1], g[3], g[0]});
  }
}

double signedVolume6(const float* p, const uint32_t* t) {
  const float* a = p + 3 * size_t(t[0]);
  const float* b = p + 3 * size_t(t[1]);
  const float* c = p + 3 * size_t(t[2]);
  const float* d = p + 3 * size_t(t[3]);
  double u[3], v[3], w[3];
  for (int k = 0; k < 3; ++k) {
    u[k] = double(b[k]) - a[k];
    v[k] = double(c[k]) - a[k];
    w[k] = double(d[k]) - a[k];
  }
  return u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) + u[2] * (v[0] * w[1] - v[1] * w[0]);
}

double longestEdgeCubed(const float* p, const uint32_t* t) {
  double best = 0;
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j) {
      double d = 0;
      for (int k = 0; k < 3; ++k) {
        double x = double(p[3 * size_t(t[i]) + k]) - p[3 * size_t(t[j]) + k];
        d += x * x;
      }
      best = std::max(best, d);
    }
  return best * std::sqrt(best);
}

bool repeated(const uint32_t* t) {
  return t[0] == t[1] || t[0] == t[2] || t[0] == t[3] || t[1] == t[2] || t[1] == t[3] || t[2] == t[3];
}

std::string plural(uint64_t n, const char* one, const char* many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}

}  // namespace

// (readers.h)
uint64_t findCoincident(const TetMesh& mesh, std::vector<uint32_t>& remap) {
  const uint32_t nv = uint32_t(mesh.positions.size() / 3);
  // Sorting (position bits, vertex) records themselves keeps memory access sequential; sorting
  // vertex ids with the positions looked up in every comparison was 3x slower.
  struct Record {
    std::array<uint32_t, 3> key;  // -0 as +0
    uint32_t v;
    auto operator<=>(const Record&) const = default;
  };
  std::vector<Record> records(nv);
  for (uint32_t v = 0; v < nv; ++v) {
    for (int c = 0; c < 3; ++c) {
      const float x = mesh.positions[3 * size_t(v) + c];
      records[v].key[c] = std::bit_cast<uint32_t>(x == 0.0f ? 0.0f : x);
    }
    records[v].v = v;
  }
  std::sort(records.begin(), records.end());
  uint64_t found = 0;
  remap.clear();
  for (size_t i = 1; i < records.size(); ++i)
    if (records[i].key == records[i - 1].key) {
      if (remap.empty()) {
        remap.resize(nv);
        std::iota(remap.begin(), remap.end(), 0u);
      }
      remap[records[i].v] = remap[records[i - 1].v];
      ++found;
    }
  return found;
}

namespace {

// Averages the fields of each merged group into its first copy. Returns how many merged vertices
// had values other than their first copy's.
uint64_t averageMerged(TetMesh& mesh, const std::vector<uint32_t>& remap) {
  const uint32_t nv = uint32_t(remap.size());
  std::vector<uint32_t> groupSize(nv, 0);
  for (uint32_t v = 0; v < nv; ++v) ++groupSize[remap[v]];
  uint64_t differing = 0;
  std::vector<uint8_t> differs(nv, 0);
  for (ScalarField& f : mesh.fields) {
    std::vector<double> sum(nv, 0.0);
    for (uint32_t v = 0; v < nv; ++v) {
      sum[remap[v]] += f.values[v];
      const float a = f.values[v], b = f.values[remap[v]];
      if (a != b && !(std::isnan(a) && std::isnan(b))) differs[v] = 1;
    }
    for (uint32_t v = 0; v < nv; ++v)
      if (groupSize[v] > 1) f.values[v] = float(sum[v] / groupSize[v]);
  }
  for (uint8_t d : differs) differing += d;
  return differing;
}

struct Split {
  std::vector<uint32_t> tets;
  std::vector<double> cellVolume;  // per soup cell, when asked for
  uint64_t madeFromSplit = 0, degenerateTets = 0, degenerateCells = 0, tangledCells = 0;
};

// Splits every cell of the soup (ids through remap when given) into out.tets.
void splitAll(const CellSoup& soup, const uint32_t* remap, const float* pos, bool wantVolumes, Split& out) {
  const size_t ncells = soup.shapes.size();
  uint64_t made = 0;
  for (uint8_t sh : soup.shapes) made += sh == 0 ? 1 : sh == 1 ? 2 : sh == 2 ? 3 : 6;
  out.tets.reserve(4 * made);
  if (wantVolumes) out.cellVolume.assign(ncells, 0.0);
  std::vector<uint32_t> local;
  const uint32_t* ids = soup.corners.data();
  uint32_t mapped[8];
  for (size_t c = 0; c < ncells; ++c) {
    const CellShape shape = CellShape(soup.shapes[c]);
    const int nc = kShapeCorners[int(shape)];
    for (int k = 0; k < nc; ++k) mapped[k] = remap ? remap[ids[k]] : ids[k];
    ids += nc;
    local.clear();
    splitCell(shape, mapped, pos, local);
    const size_t nt = local.size() / 4;
    if (shape != CellShape::Tet) {
      double total = 0;
      for (size_t t = 0; t < nt; ++t) total += signedVolume6(pos, &local[4 * t]);
      if (total < 0)
        for (size_t t = 0; t < nt; ++t) std::swap(local[4 * t + 2], local[4 * t + 3]);
    }
    bool dropped = false, inverted = false;
    for (size_t t = 0; t < nt; ++t) {
      const uint32_t* q = &local[4 * t];
      if (repeated(q)) {
        ++out.degenerateTets;
        dropped = true;
        continue;
      }
      if (shape != CellShape::Tet || wantVolumes) {
        const double v6 = signedVolume6(pos, q);
        if (shape != CellShape::Tet && v6 < -1e-9 * longestEdgeCubed(pos, q)) inverted = true;
        if (wantVolumes) out.cellVolume[c] += std::abs(v6) / 6.0;
      }
      out.tets.insert(out.tets.end(), q, q + 4);
      out.madeFromSplit += shape != CellShape::Tet;
    }
    out.degenerateCells += dropped;
    out.tangledCells += inverted;
  }
}

// Faces shared by more than two tets plus boundary edges not shared by exactly two boundary faces.
uint64_t nonManifoldCount(const std::vector<uint32_t>& tets, uint32_t nv) {
  FaceAdjacency adj;
  buildFaceAdjacency(tets, nv, adj);
  std::vector<uint32_t> boundary;
  extractBoundary(tets, adj, boundary);
  return adj.nonManifoldFaces + countNonManifoldBoundaryEdges(boundary);
}

// How many more faces and boundary edges are non-manifold (nonManifoldCount) with the coincident
// vertices merged than with them kept apart; negative when merging repairs more than it damages.
// Only the cells with a merged vertex split differently, and their corners (R) hold every face and
// edge that can differ. Every tet with a face or edge at a vertex of R has a vertex in R, so
// counting on the tets with a vertex in R, merged and apart, gives the same difference as counting
// on the whole mesh twice: what lies outside them is the same either way, and what the cut makes
// look like boundary there is too, at a fraction of the time when few vertices merge.
// `mergedTets`: the whole mesh merged, counted instead when most cells are near a merged vertex;
// the whole mesh apart is then left in `apart` (for the caller, when it does not merge).
int64_t mergeDamage(const CellSoup& soup, const std::vector<uint32_t>& remap, const float* pos, uint32_t nv,
                    const std::vector<uint32_t>& mergedTets, bool wantVolumes, Split& apart) {
  enum : uint8_t { kMerged = 1, kNear = 2 };
  std::vector<uint8_t> mark(nv, 0);
  for (uint32_t v = 0; v < nv; ++v)
    if (remap[v] != v) mark[v] |= kMerged | kNear, mark[remap[v]] |= kMerged | kNear;
  auto forCells = [&](auto&& each) {
    const uint32_t* ids = soup.corners.data();
    for (size_t c = 0; c < soup.shapes.size(); ++c) {
      const int nc = kShapeCorners[soup.shapes[c]];
      each(c, ids, nc);
      ids += nc;
    }
  };
  forCells([&](size_t, const uint32_t* ids, int nc) {
    if (std::any_of(ids, ids + nc, [&](uint32_t v) { return mark[v] & kMerged; }))
      for (int k = 0; k < nc; ++k) mark[ids[k]] |= kNear;
  });
  auto isNear = [&](const uint32_t* ids, int nc) {
    return std::any_of(ids, ids + nc, [&](uint32_t v) { return mark[v] & kNear; });
  };
  size_t nearCells = 0;
  forCells([&](size_t, const uint32_t* ids, int nc) { nearCells += isNear(ids, nc); });
  if (4 * nearCells > soup.shapes.size()) {
    // Most of the mesh is near a merged vertex (as in a file that writes every cell with its own
    // copies of its points): the whole mesh is counted, without copying most of it again.
    const int64_t merged = int64_t(nonManifoldCount(mergedTets, nv));
    if (merged == 0) return 0;  // merging cannot do worse
    splitAll(soup, nullptr, pos, wantVolumes, apart);
    return merged - int64_t(nonManifoldCount(apart.tets, nv));
  }
  CellSoup near;  // the cells with a corner in R: the only ones that can make a tet with one
  forCells([&](size_t c, const uint32_t* ids, int nc) {
    if (isNear(ids, nc)) near.add(CellShape(soup.shapes[c]), ids, c);
  });
  auto count = [&](const uint32_t* map) {
    Split split;
    splitAll(near, map, pos, false, split);
    std::vector<uint32_t> kept;
    for (size_t t = 0; t < split.tets.size(); t += 4)
      if (std::any_of(&split.tets[t], &split.tets[t] + 4, [&](uint32_t v) { return mark[v] & kNear; }))
        kept.insert(kept.end(), &split.tets[t], &split.tets[t] + 4);
    return int64_t(nonManifoldCount(kept, nv));
  };
  return count(remap.data()) - count(nullptr);
}

}  // namespace

VtkCellInfo vtkCellInfo(int64_t type) {
  using S = CellShape;
  switch (type) {
    case 10: return {true, S::Tet, 4};
    case 11: return {true, S::Hex, 8, true};
    case 12: return {true, S::Hex, 8};
    case 13: return {true, S::Wedge, 6};
    case 14: return {true, S::Pyramid, 5};
    case 24: return {true, S::Tet, 10};
    case 25: return {true, S::Hex, 20};
    case 26: return {true, S::Wedge, 15};
    case 27: return {true, S::Pyramid, 13};
    case 29: return {true, S::Hex, 27};
    case 31: return {true, S::Wedge, 12};
    case 32: return {true, S::Wedge, 18};
    case 33: return {true, S::Hex, 24};
    case 37: return {true, S::Pyramid, 19};
    case 71:
    case 78: return {true, S::Tet, 0};
    case 72:
    case 79: return {true, S::Hex, 0};
    case 73:
    case 80: return {true, S::Wedge, 0};
    case 74:
    case 81: return {true, S::Pyramid, 0};
    default: return {};
  }
}

Result appendVtkCells(const std::string& where, std::span<const int64_t> connectivity, std::span<const int64_t> offsets,
                      std::span<const int64_t> types, uint64_t vertexBase, uint64_t pieceVertexCount, CellSoup& soup) {
  const size_t n = types.size();
  if (offsets.size() != n + 1)
    return fail(Status::Corrupt, where + ": " + std::to_string(n) + " cell types but " +
                                     std::to_string(offsets.size() - 1) + " cells in the offsets");
  const int64_t connSize = int64_t(connectivity.size());
  if (offsets[0] < 0 || offsets[0] > connSize)
    return fail(Status::Corrupt, where + ": first cell offset " + std::to_string(offsets[0]) +
                                     " is outside the connectivity (" + std::to_string(connSize) + " ids)");
  // Bounded by real data: types has n entries.
  soup.shapes.reserve(soup.shapes.size() + n);
  soup.source.reserve(soup.source.size() + n);
  soup.corners.reserve(soup.corners.size() + 4 * n);
  if (soup.referenced.size() < vertexBase + pieceVertexCount) soup.referenced.resize(vertexBase + pieceVertexCount, 0);

  for (size_t c = 0; c < n; ++c) {
    const int64_t b = offsets[c], e = offsets[c + 1];
    if (e < b || e > connSize)
      return fail(Status::Corrupt, where + ": cell " + std::to_string(c) + " has offsets " + std::to_string(b) + ".." +
                                       std::to_string(e) + ", outside 0.." + std::to_string(connSize) +
                                       " or going backwards");
    const int64_t type = types[c];
    const VtkCellInfo info = vtkCellInfo(type);
    if (!info.volume) {
      ++soup.skipped[{type, vtkCellTypeName(type) + " (" + std::to_string(type) + ")"}];
      for (int64_t k = b; k < e; ++k) {
        int64_t id = connectivity[size_t(k)];
        if (id >= 0 && uint64_t(id) < pieceVertexCount) soup.referenced[vertexBase + uint64_t(id)] = 1;
      }
      continue;
    }
    const int corners = kShapeCorners[int(info.shape)];
    const int64_t count = e - b;
    if (info.nodes ? count != info.nodes : count < corners)
      return fail(Status::Corrupt, where + ": cell " + std::to_string(c) + " is " + vtkCellTypeName(type) + " with " +
                                       std::to_string(count) + " points, expected " + (info.nodes ? "" : "at least ") +
                                       std::to_string(info.nodes ? info.nodes : corners));
    for (int64_t k = b; k < e; ++k) {
      int64_t id = connectivity[size_t(k)];
      if (id < 0 || uint64_t(id) >= pieceVertexCount)
        return fail(Status::OutOfRange, where + ": cell " + std::to_string(c) + " (" + vtkCellTypeName(type) +
                                            ") references vertex " + std::to_string(id) + ", but there are " +
                                            std::to_string(pieceVertexCount) + " points");
      soup.referenced[vertexBase + uint64_t(id)] = 1;
    }
    // Higher-order cells list their corners first, in the linear cell's order.
    static constexpr int kVoxelToHex[8] = {0, 1, 3, 2, 4, 5, 7, 6};
    uint32_t ids[8];
    for (int k = 0; k < corners; ++k)
      ids[k] = uint32_t(vertexBase + uint64_t(connectivity[size_t(b + (info.voxel ? kVoxelToHex[k] : k))]));
    soup.add(info.shape, ids, soup.inputCells + c);
    if (count > corners) {
      auto& r = soup.reduced[vtkCellTypeName(type) + " (" + std::to_string(type) + ")"];
      r.first = corners;
      ++r.second;
    }
  }
  soup.inputCells += n;
  return Result::success();
}

uint64_t appendStructuredCells(uint64_t ni, uint64_t nj, uint64_t nk, uint64_t vertexBase, uint64_t sourceBase,
                               CellSoup& soup, const std::vector<uint8_t>* keepPoint) {
  if (ni < 2 || nj < 2 || nk < 2) return 0;
  const uint64_t cells = (ni - 1) * (nj - 1) * (nk - 1);
  soup.shapes.reserve(soup.shapes.size() + cells);
  soup.source.reserve(soup.source.size() + cells);
  soup.corners.reserve(soup.corners.size() + 8 * cells);
  uint64_t added = 0;
  for (uint64_t k = 0; k + 1 < nk; ++k)
    for (uint64_t j = 0; j + 1 < nj; ++j)
      for (uint64_t i = 0; i + 1 < ni; ++i) {
        const uint64_t p = i + ni * (j + nj * k);
        const uint64_t local[8] = {p,           p + 1,           p + 1 + ni,           p + ni,
                                   p + ni * nj, p + 1 + ni * nj, p + 1 + ni + ni * nj, p + ni + ni * nj};
        if (keepPoint) {
          bool keep = true;
          for (uint64_t q : local) keep &= (*keepPoint)[vertexBase + q] != 0;
          if (!keep) continue;
        }
        uint32_t ids[8];
        for (int q = 0; q < 8; ++q) ids[q] = uint32_t(vertexBase + local[q]);
        soup.add(CellShape::Hex, ids, sourceBase + i + (ni - 1) * (j + (nj - 1) * k));
        ++added;
      }
  return added;
}

Result finishMesh(const std::string& label, TetMesh& mesh, CellSoup& soup, std::vector<CellArray> cellArrays,
                  ReadReport& report) {
  const uint64_t nv64 = mesh.positions.size() / 3;
  if (nv64 > kMaxVertices)
    return fail(Status::TooLarge,
                label + ": " + std::to_string(nv64) + " points; tetstream indexes vertices with 32 bits");
  const uint32_t nv = uint32_t(nv64);

  for (const auto& [name, r] : soup.reduced)
    report.notes.push_back("reduced " + std::to_string(r.second) + " " + name + " cells to their " +
                           std::to_string(r.first) + " corner vertices");
  std::string found;
  for (const auto& [key, count] : soup.skipped) {
    report.notes.push_back("skipped " + std::to_string(count) + " cells of unsupported type " + key.second);
    std::string name = key.second.substr(0, key.second.rfind(" ("));
    report.skippedCells.push_back({int(key.first), name, count});
    found += (found.empty() ? "" : ", ") + std::to_string(count) + " " + name;
  }
  if (soup.shapes.empty())
    return fail(Status::NoTets, label + ": no tetrahedra or other volume cells among " +
                                    std::to_string(soup.inputCells) + " cells" +
                                    (found.empty() ? "" : " (found " + found + ")"));

  for (uint32_t v = 0; v < nv; ++v) {
    const float* p = &mesh.positions[3 * size_t(v)];
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) {
      char buf[128];
      std::snprintf(buf, sizeof buf, "(%g, %g, %g)", double(p[0]), double(p[1]), double(p[2]));
      return fail(Status::NonFinite, label + ": point " + std::to_string(v) + " has a non-finite coordinate " + buf);
    }
  }

  // 1. Coincident vertices: where they are. Whether to merge them is decided below.
  std::vector<uint32_t> remap;
  const uint64_t coincident = findCoincident(mesh, remap);

  // 2./3. Split into tets, drop tets with a repeated vertex.
  const bool wantVolumes = !cellArrays.empty();
  uint64_t shapeCount[4] = {0, 0, 0, 0};
  for (uint8_t sh : soup.shapes) ++shapeCount[sh];
  Split split;
  if (!coincident && !wantVolumes && !(shapeCount[1] + shapeCount[2] + shapeCount[3])) {
    // The common case, all tets and nothing to merge: filter in place, no second copy.
    split.tets = std::move(soup.corners);
    size_t w = 0;
    for (size_t c = 0; c < split.tets.size() / 4; ++c) {
      const uint32_t* t = &split.tets[4 * c];
      if (repeated(t)) {
        ++split.degenerateTets;
        ++split.degenerateCells;
        continue;
      }
      if (w != c) std::copy_n(t, 4, &split.tets[4 * w]);
      ++w;
    }
    split.tets.resize(4 * w);
  } else {
    splitAll(soup, coincident ? remap.data() : nullptr, mesh.positions.data(), wantVolumes, split);
    if (coincident) {
      // Merging closes seams between pieces or blocks and collapses degenerate cells; but where a
      // mesh only touches itself (two boundary sheets meeting along a line), it would make the
      // boundary non-manifold. Merge unless it leaves more non-manifold faces and boundary edges
      // than keeping the copies apart; the split without merging is made only then.
      Split apart;  // (made by mergeDamage() when it counted the whole mesh)
      if (const int64_t damage = mergeDamage(soup, remap, mesh.positions.data(), nv, split.tets, wantVolumes, apart);
          damage > 0) {
        if (apart.tets.empty()) splitAll(soup, nullptr, mesh.positions.data(), wantVolumes, apart);
        report.notes.push_back("found " + plural(coincident, "vertex", "vertices") +
                               " at the same coordinates as another; not merged, since merging would make " +
                               plural(damage, "more face or boundary edge", "more faces or boundary edges") +
                               " non-manifold (the mesh touches itself there)");
        split = std::move(apart);
        remap.clear();
      } else {
        const uint64_t differing = averageMerged(mesh, remap);
        report.notes.push_back("merged " + plural(coincident, "duplicate vertex", "duplicate vertices") +
                               " (exactly the same coordinates) into the first copy" +
                               (differing
                                    ? "; " + std::to_string(differing) + " of them had other field values, averaged"
                                    : std::string()));
      }
    }
  }
  std::vector<uint32_t> tets = std::move(split.tets);
  if (tets.size() / 4 > 0xFFFFFFFFull) return fail(Status::TooLarge, label + ": more than 2^32-1 tetrahedra");

  if (shapeCount[1] + shapeCount[2] + shapeCount[3]) {
    std::string what;
    for (int sh : {3, 2, 1})
      if (shapeCount[sh])
        what += (what.empty() ? "" : ", ") + plural(shapeCount[sh], kShapeNames[sh][0], kShapeNames[sh][1]);
    const std::string how =
        " (each quad face cut through its corner lowest in x, then y, then z, so neighbouring "
        "cells agree whoever read them)";
    report.notes.push_back("split " + what + " into " + std::to_string(split.madeFromSplit) + " tetrahedra" + how);
  }
  if (split.degenerateTets)
    report.notes.push_back("dropped " + plural(split.degenerateTets, "tetrahedron", "tetrahedra") +
                           " with a repeated vertex (no volume) from " +
                           plural(split.degenerateCells, "degenerate cell", "degenerate cells"));
  if (split.tangledCells)
    report.notes.push_back(plural(split.tangledCells, "cell is", "cells are") +
                           " warped or tangled: splitting gave some inverted tetrahedra");
  if (tets.empty()) return fail(Status::NoTets, label + ": every cell is degenerate (no tetrahedron has a volume)");
  const std::vector<double>& cellVolume = split.cellVolume;
  const size_t ncells = soup.shapes.size();

  // 4. Cell arrays -> point fields, volume-weighted over the cells around each vertex.
  if (!cellArrays.empty()) {
    std::string names;
    std::vector<double> num(nv), den(nv), plain(nv);
    std::vector<uint32_t> cnt(nv);
    for (CellArray& a : cellArrays) {
      std::fill(num.begin(), num.end(), 0.0);
      std::fill(den.begin(), den.end(), 0.0);
      std::fill(plain.begin(), plain.end(), 0.0);
      std::fill(cnt.begin(), cnt.end(), 0u);
      const uint32_t* ids = soup.corners.data();
      for (size_t c = 0; c < ncells; ++c) {
        const int nc = kShapeCorners[soup.shapes[c]];
        uint32_t cid[8];
        for (int k = 0; k < nc; ++k) cid[k] = remap.empty() ? ids[k] : remap[ids[k]];
        ids += nc;
        const uint32_t src = soup.source[c];
        if (src >= a.values.size()) continue;
        const double val = a.values[src];
        if (!std::isfinite(val)) continue;
        for (int k = 0; k < nc; ++k) {
          bool seen = false;  // a degenerate cell lists a vertex twice: count it once
          for (int q = 0; q < k; ++q) seen |= cid[q] == cid[k];
          if (seen) continue;
          num[cid[k]] += cellVolume[c] * val;
          den[cid[k]] += cellVolume[c];
          plain[cid[k]] += val;
          ++cnt[cid[k]];
        }
      }
      ScalarField f;
      f.name = mesh.findField(a.name) >= 0 ? a.name + "_cell" : a.name;
      f.values.resize(nv);
      for (uint32_t v = 0; v < nv; ++v)
        f.values[v] = den[v] > 0   ? float(num[v] / den[v])
                      : cnt[v] > 0 ? float(plain[v] / cnt[v])
                                   : std::numeric_limits<float>::quiet_NaN();
      names += (names.empty() ? "'" : ", '") + f.name + "'";
      report.cellAverages.push_back({f.name, den});
      mesh.fields.push_back(std::move(f));
    }
    report.notes.push_back("converted cell data " + names +
                           " to point data (at each vertex, the volume-weighted average of the cells around it)");
  }
  const std::vector<uint8_t> referenced = std::move(soup.referenced);
  soup = CellSoup{};

  // 5. Drop vertices no tet uses.
  std::vector<uint32_t> newId(nv, 0xFFFFFFFFu);
  for (uint32_t id : tets) newId[id] = 0;
  uint32_t kept = 0;
  uint64_t higherOrder = 0, noCell = 0;
  for (uint32_t v = 0; v < nv; ++v) {
    if (newId[v] == 0) {
      newId[v] = kept++;
      continue;
    }
    if (!remap.empty() && remap[v] != v) continue;  // merged away: already said
    if (v < referenced.size() && referenced[v])
      ++higherOrder;
    else
      ++noCell;
  }
  if (kept < nv) {
    for (uint32_t& id : tets) id = newId[id];
    for (uint32_t v = 0; v < nv; ++v)
      if (newId[v] != 0xFFFFFFFFu && newId[v] != v) {
        std::copy_n(&mesh.positions[3 * size_t(v)], 3, &mesh.positions[3 * size_t(newId[v])]);
        for (ScalarField& f : mesh.fields) f.values[newId[v]] = f.values[v];
        for (ReadReport::CellAverage& a : report.cellAverages) a.weight[newId[v]] = a.weight[v];
      }
    mesh.positions.resize(3 * size_t(kept));
    mesh.positions.shrink_to_fit();
    for (ScalarField& f : mesh.fields) {
      f.values.resize(kept);
      f.values.shrink_to_fit();
    }
    for (ReadReport::CellAverage& a : report.cellAverages) a.weight.resize(kept);
    if (higherOrder + noCell) {
      std::string why;
      if (higherOrder) why = std::to_string(higherOrder) + " only higher-order nodes or nodes of skipped cells";
      if (noCell) why += (why.empty() ? "" : ", ") + std::to_string(noCell) + " in no cell";
      report.notes.push_back("dropped " + plural(higherOrder + noCell, "vertex", "vertices") +
                             " that no tetrahedron uses (" + why + ")");
    }
  }
  mesh.tets = std::move(tets);

  for (const ScalarField& f : mesh.fields) {
    size_t bad = 0;
    for (float x : f.values) bad += !std::isfinite(x);
    if (bad) report.notes.push_back("field '" + f.name + "' has " + std::to_string(bad) + " non-finite values");
  }
  return Result::success();
}

}  // namespace vtkio
}  // namespace tetstream
