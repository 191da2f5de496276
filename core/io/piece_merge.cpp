// Joining the pieces of a partitioned mesh into one (readers.h, MeshPiece, mergePieces).
//
// A parallel run writes one piece per rank. Pieces repeat the points on their interfaces, and
// with ghost levels also the cells around them. The rules, in order:
//
// 1. Ghost cells go: a cell whose vtkGhostType has DUPLICATECELL (another piece owns it) or
//    HIDDENCELL (blanked, not part of the data) is dropped, and so is its cell data. Points flagged
//    HIDDENPOINT stay for the cells that use them; the flags themselves are never a field.
// 2. Interface points are welded. With global ids in every piece (GlobalIds, GlobalNodeIds, a
//    legacy GLOBAL_IDS section), points with one id are one point, wherever the pieces put them
//    (a float32 piece and a float64 piece round differently) as long as the copies lie within
//    kGlobalIdTolerance of the model's size: farther apart, the ids are not global and the read
//    fails with counts. Without ids, points with bit-equal coordinates are welded, by finishMesh's
//    merge of coincident vertices (the rule every reader already follows).
// 3. A welded point takes its owner's position and values: the first piece (in listing order)
//    whose copy is used by a kept cell and is not DUPLICATEPOINT or HIDDENPOINT. No value is
//    averaged across pieces. Where other pieces' copies give a field another value, a note counts
//    them per field with the largest difference. Differences within 1e-6 of the value (or of the
//    field's range) are float rounding, counted apart; larger ones are reported as disagreements.
//    Neither stops the read: the result is well defined (the owner's value), and output whose
//    pieces differ by design (discontinuous fields written at shared points) must still pack.
// 4. A cell that two pieces both hold (ghost cells written without vtkGhostType) is kept once.
// 5. Arrays: a listing that declares its arrays (.pvtu) must find each in every piece; otherwise
//    an array that some piece lacks is dropped with a note naming the piece.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <set>
#include <tuple>

#include "io/readers.h"

namespace tetstream {
namespace vtkio {
namespace {

std::string number(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", x);
  return buf;
}

std::string plural(uint64_t n, const char* one, const char* many) {
  return withThousands(n) + " " + (n == 1 ? one : many);
}

// Drops the piece's ghost and hidden cells (rule 1). Corners of dropped cells that no kept cell
// uses are no longer "referenced", so finishMesh counts them as points in no cell.
void dropGhostCells(MeshPiece& p, PieceMergeSummary& s) {
  if (p.cellGhost.empty()) return;
  CellSoup& soup = p.soup;
  std::vector<uint32_t> dropped;  // corners of dropped cells
  size_t w = 0, wc = 0;
  const uint32_t* ids = soup.corners.data();
  for (size_t c = 0, n = soup.shapes.size(); c < n; ++c) {
    const int nc = kShapeCorners[soup.shapes[c]];
    const uint32_t src = soup.source[c];
    const uint8_t flags = src < p.cellGhost.size() ? p.cellGhost[src] : 0;
    if (flags & (kDuplicateCell | kHiddenCell)) {
      flags& kDuplicateCell ? ++s.ghostCells : ++s.hiddenCells;
      dropped.insert(dropped.end(), ids, ids + nc);
      ids += nc;
      continue;
    }
    soup.shapes[w] = soup.shapes[c];
    soup.source[w] = src;
    std::copy_n(ids, nc, &soup.corners[wc]);  // (wc never passes the read position)
    ++w;
    wc += size_t(nc);
    ids += nc;
  }
  soup.shapes.resize(w);
  soup.source.resize(w);
  soup.corners.resize(wc);
  if (dropped.empty() || soup.referenced.empty()) return;
  for (uint32_t v : dropped)
    if (v < soup.referenced.size()) soup.referenced[v] = 0;
  for (uint32_t v : soup.corners)
    if (v < soup.referenced.size()) soup.referenced[v] = 1;
}

// The array names the merged mesh keeps (rule 5), in the first piece's order.
Result chooseArrays(const std::string& label, const std::vector<MeshPiece>& pieces, const PieceMergeRules& rules,
                    bool cells, std::vector<std::string>& names, ReadReport& report) {
  const char* kind = cells ? "cell" : "point";
  auto has = [&](const MeshPiece& p, const std::string& name) {
    if (cells)
      return std::any_of(p.cellArrays.begin(), p.cellArrays.end(), [&](const CellArray& a) { return a.name == name; });
    return p.mesh.findField(name) >= 0;
  };
  auto namesOf = [&](const MeshPiece& p) {
    std::vector<std::string> out;
    if (cells)
      for (const CellArray& a : p.cellArrays) out.push_back(a.name);
    else
      for (const ScalarField& f : p.mesh.fields) out.push_back(f.name);
    return out;
  };
  names.clear();
  std::set<std::string> noted;
  if (rules.declared) {
    for (const auto& [field, how] : cells ? rules.cellFields : rules.pointFields) {
      if (std::find(names.begin(), names.end(), field) != names.end()) continue;
      for (const MeshPiece& p : pieces)
        if (!has(p, field))
          return fail(Status::Corrupt, p.where + ": has no " + kind + " array " + how + ", which " + label +
                                           " declares for every piece");
      names.push_back(field);
    }
    for (const MeshPiece& p : pieces)
      for (const std::string& n : namesOf(p))
        if (std::find(names.begin(), names.end(), n) == names.end() && noted.insert(n).second)
          report.notes.push_back("dropped " + std::string(kind) + " array '" + n + "' of " + p.name + ": " + label +
                                 " does not declare it");
    return Result::success();
  }
  for (const std::string& n : namesOf(pieces[0]))
    if (std::find(names.begin(), names.end(), n) == names.end()) names.push_back(n);
  for (size_t k = 1; k < pieces.size(); ++k) {
    for (size_t i = 0; i < names.size();) {
      if (has(pieces[k], names[i])) {
        ++i;
        continue;
      }
      if (noted.insert(names[i]).second)
        report.notes.push_back("dropped " + std::string(kind) + " array '" + names[i] + "': " + pieces[k].name +
                               " lacks it");
      names.erase(names.begin() + std::ptrdiff_t(i));
    }
    for (const std::string& n : namesOf(pieces[k]))
      if (!has(pieces[0], n) && noted.insert(n).second)
        report.notes.push_back("dropped " + std::string(kind) + " array '" + n + "': " + pieces[0].name + " lacks it");
  }
  return Result::success();
}

}  // namespace

std::string withThousands(uint64_t n) {
  std::string digits = std::to_string(n), out;
  for (size_t i = 0; i < digits.size(); ++i) {
    if (i && (digits.size() - i) % 3 == 0) out += ',';
    out += digits[i];
  }
  return out;
}

std::string describeMerge(const PieceMergeSummary& s, const char* pieceWord) {
  std::string d = ", " + withThousands(s.pieces) + " " + (s.pieces == 1 ? "piece" : pieceWord);
  if (s.ghostCells) d += ", " + plural(s.ghostCells, "ghost cell", "ghost cells") + " dropped";
  if (s.hiddenCells) d += ", " + plural(s.hiddenCells, "hidden cell", "hidden cells") + " dropped";
  if (s.duplicateCells) d += ", " + plural(s.duplicateCells, "cell", "cells") + " held twice dropped";
  if (s.pieces > 1)
    d += ", " + plural(s.weldedPoints, "interface point", "interface points") + " welded by " +
         (s.byGlobalIds ? s.globalIdsName : std::string("coordinates"));
  return d;
}

PartitionArray partitionArrayKind(std::string_view name, bool cellData, std::string_view idsAttribute) {
  if (name == "vtkGhostType") return PartitionArray::GhostType;
  if (name == "vtkGhostLevels") return PartitionArray::GhostLevels;
  const PartitionArray ids = cellData ? PartitionArray::CellIds : PartitionArray::PointIds;
  if (!idsAttribute.empty() && name == idsAttribute) return ids;
  if (name == "GlobalIds") return ids;
  if (cellData) return name == "GlobalCellIds" || name == "GlobalElementIds" ? ids : PartitionArray::None;
  return name == "GlobalNodeIds" ? ids : PartitionArray::None;
}

Result takePartitionArray(PartitionArray kind, const std::string& name, const std::string& what,
                          std::span<const double> values, uint64_t components, bool cellData, MeshPiece& piece) {
  const bool ghost = kind == PartitionArray::GhostType || kind == PartitionArray::GhostLevels;
  if (components != 1)
    return fail(Status::Corrupt, what + ": has " + std::to_string(components) + " components; " +
                                     (ghost ? "ghost flags have" : "global ids have") + " one");
  if (kind == PartitionArray::CellIds || kind == PartitionArray::None) return Result::success();
  if (ghost) {
    std::vector<uint8_t>& out = cellData ? piece.cellGhost : piece.pointGhost;
    if (!out.empty()) return Result::success();
    out.resize(values.size());
    for (size_t i = 0; i < values.size(); ++i) {
      const double x = values[i];
      if (!(x >= 0 && x <= 255) || x != std::floor(x))
        return fail(Status::Corrupt, what + ": value " + std::to_string(i) + " is " + number(x) +
                                         ", not a ghost flag (an integer 0..255)");
      out[i] = kind == PartitionArray::GhostType ? uint8_t(x)
               : x > 0                           ? (cellData ? kDuplicateCell : kDuplicatePoint)
                                                 : 0;
    }
    return Result::success();
  }
  if (!piece.globalIds.empty()) return Result::success();
  piece.globalIds.resize(values.size());
  for (size_t i = 0; i < values.size(); ++i) {
    const double x = values[i];
    if (!(x >= 0 && x <= 9007199254740992.0) || x != std::floor(x))
      return fail(Status::Corrupt, what + ": value " + std::to_string(i) + " is " + number(x) +
                                       ", not a global id (an integer 0..2^53)");
    piece.globalIds[i] = int64_t(x);
  }
  piece.globalIdsName = name;
  return Result::success();
}

namespace {

// How the copies of one field differ from their owners' values (rule 3).
struct Agreement {
  uint64_t disagree = 0, rounding = 0;
  double largest = 0, largestRounding = 0;
};

// The welded points: groups of vertices of the concatenated mesh that are one point.
struct Groups {
  std::vector<uint32_t> start;    // group g is members[start[g] .. start[g+1])
  std::vector<uint32_t> members;  // ascending within a group (so in piece order)
  std::vector<uint32_t> owner;    // per group
  std::vector<uint8_t> spans;     // per group: used by kept cells of two or more pieces
};

// Groups from a map of each vertex to its group's first member (remap[v] <= v).
Groups groupsFrom(const std::vector<uint32_t>& first) {
  Groups g;
  const uint32_t nv = uint32_t(first.size());
  std::vector<uint32_t> size(nv, 0), slot(nv, ~0u);
  for (uint32_t v = 0; v < nv; ++v)
    if (first[v] != v) ++size[first[v]];
  uint32_t groups = 0, total = 0;
  for (uint32_t v = 0; v < nv; ++v)
    if (size[v]) {
      slot[v] = groups++;
      g.start.push_back(total);
      total += size[v] + 1;
    }
  g.start.push_back(total);
  g.members.resize(total);
  std::vector<uint32_t> fill(g.start.begin(), g.start.end() - 1);
  for (uint32_t v = 0; v < nv; ++v) {
    const uint32_t f = first[v];
    if (f == v && !size[v]) continue;
    g.members[fill[slot[f]]++] = v;
  }
  return g;
}

// The pieces concatenated: each piece's points and cells after the previous pieces' (corners
// and cell sources shifted), and what the steps below need to know about them.
struct Joined {
  size_t pieces = 0;
  TetMesh mesh;  // points and kept point fields
  CellSoup soup;
  std::vector<CellArray> cellArrays;
  std::vector<uint64_t> pointBase, cellBase;  // piece k's first point and input cell; then the totals
  std::vector<std::string> pieceNames;
  bool allIds = false, someIds = false, anyGhostPoints = false;
  std::string idsName;
  std::vector<int64_t> ids;         // per point, when every piece has global ids
  std::vector<uint8_t> pointGhost;  // per point, when a piece has point ghost flags
  std::vector<uint8_t> used;        // per point: a kept cell uses it

  uint32_t vertexCount() const { return uint32_t(mesh.positions.size() / 3); }
  size_t pieceOf(uint32_t v) const {
    return size_t(std::upper_bound(pointBase.begin(), pointBase.end(), uint64_t(v)) - pointBase.begin() - 1);
  }
  size_t pieceOfCell(size_t c) const {
    return size_t(std::upper_bound(cellBase.begin(), cellBase.end(), uint64_t(soup.source[c])) - cellBase.begin() - 1);
  }
};

Result concatenate(const std::string& label, std::vector<MeshPiece>& pieces, const std::vector<std::string>& pointNames,
                   const std::vector<std::string>& cellNames, Joined& j) {
  const size_t n = pieces.size();
  j.pieces = n;
  j.pointBase.assign(n + 1, 0);
  j.cellBase.assign(n + 1, 0);
  for (size_t k = 0; k < n; ++k) {
    j.pointBase[k + 1] = j.pointBase[k] + pieces[k].mesh.positions.size() / 3;
    j.cellBase[k + 1] = j.cellBase[k] + pieces[k].soup.inputCells;
  }
  const uint64_t nv = j.pointBase[n];
  if (nv > kMaxVertices)
    return fail(Status::TooLarge, label + ": the pieces hold " + std::to_string(nv) +
                                      " points together; tetstream indexes vertices with 32 bits");
  if (j.cellBase[n] > 0xFFFFFFFFull)
    return fail(Status::TooLarge, label + ": the pieces hold " + std::to_string(j.cellBase[n]) + " cells together");
  j.allIds = true;
  bool anyIds = false, referenced = false;
  for (const MeshPiece& p : pieces) {
    anyIds |= !p.globalIds.empty();
    j.allIds &= !p.globalIds.empty();
    j.anyGhostPoints |= !p.pointGhost.empty();
    referenced |= !p.soup.referenced.empty();
    j.pieceNames.push_back(p.name);
  }
  if (j.allIds) j.idsName = pieces[0].globalIdsName;
  j.someIds = anyIds && !j.allIds;

  TetMesh& mesh = j.mesh;
  CellSoup& soup = j.soup;
  mesh.positions.reserve(3 * size_t(nv));
  for (const std::string& name : pointNames) mesh.fields.push_back({name, {}});
  for (const std::string& name : cellNames) j.cellArrays.push_back({name, {}});
  for (ScalarField& f : mesh.fields) f.values.reserve(nv);
  if (j.allIds) j.ids.reserve(nv);
  if (j.anyGhostPoints) j.pointGhost.reserve(nv);
  if (referenced) soup.referenced.reserve(nv);
  for (size_t k = 0; k < n; ++k) {
    MeshPiece& p = pieces[k];
    const uint64_t pointEnd = j.pointBase[k + 1], cellEnd = j.cellBase[k + 1];
    mesh.positions.insert(mesh.positions.end(), p.mesh.positions.begin(), p.mesh.positions.end());
    for (ScalarField& f : mesh.fields) {  // (chooseArrays made sure every piece has each)
      const std::vector<float>& from = p.mesh.fields[size_t(p.mesh.findField(f.name))].values;
      f.values.insert(f.values.end(), from.begin(), from.end());
      f.values.resize(pointEnd, std::numeric_limits<float>::quiet_NaN());
    }
    for (CellArray& a : j.cellArrays) {
      auto it =
          std::find_if(p.cellArrays.begin(), p.cellArrays.end(), [&](const CellArray& c) { return c.name == a.name; });
      a.values.insert(a.values.end(), it->values.begin(), it->values.end());
      a.values.resize(cellEnd, std::numeric_limits<double>::quiet_NaN());
    }
    if (j.allIds) {
      j.ids.insert(j.ids.end(), p.globalIds.begin(), p.globalIds.end());
      j.ids.resize(pointEnd, -1);
    }
    if (j.anyGhostPoints) {
      j.pointGhost.insert(j.pointGhost.end(), p.pointGhost.begin(), p.pointGhost.end());
      j.pointGhost.resize(pointEnd, 0);
    }
    if (referenced) {
      soup.referenced.insert(soup.referenced.end(), p.soup.referenced.begin(), p.soup.referenced.end());
      soup.referenced.resize(pointEnd, 0);
    }
    soup.shapes.insert(soup.shapes.end(), p.soup.shapes.begin(), p.soup.shapes.end());
    for (uint32_t v : p.soup.corners) soup.corners.push_back(uint32_t(j.pointBase[k] + v));
    for (uint32_t c : p.soup.source) soup.source.push_back(uint32_t(j.cellBase[k] + c));
    soup.inputCells += p.soup.inputCells;
    for (const auto& [type, r] : p.soup.reduced) {
      auto& into = soup.reduced[type];
      into.first = r.first;
      into.second += r.second;
    }
    for (const auto& [key, count] : p.soup.skipped) soup.skipped[key] += count;
    p = MeshPiece{};  // its arrays are in the whole now
  }
  j.used.assign(nv, 0);
  for (uint32_t v : soup.corners) j.used[v] = 1;
  return Result::success();
}

// Leaves out the points that no kept cell uses nor any other cell lists: the copies a piece
// holds for its ghost cells (VTK's piece extraction keeps the points of the ghost layer too), so
// that welding and finishMesh's merge see only the points of the mesh. Returns how many.
uint32_t dropUnusedPoints(Joined& j) {
  const uint32_t nv = j.vertexCount();
  std::vector<uint32_t> newId(nv, ~0u);
  uint32_t kept = 0;
  for (uint32_t v = 0; v < nv; ++v)
    if (j.used[v] || (!j.soup.referenced.empty() && j.soup.referenced[v])) newId[v] = kept++;
  if (kept == nv) return 0;
  for (uint32_t& v : j.soup.corners) v = newId[v];
  for (uint32_t v = 0; v < nv; ++v) {
    const uint32_t w = newId[v];
    if (w == ~0u || w == v) continue;
    std::copy_n(&j.mesh.positions[3 * size_t(v)], 3, &j.mesh.positions[3 * size_t(w)]);
    for (ScalarField& f : j.mesh.fields) f.values[w] = f.values[v];
    if (j.allIds) j.ids[w] = j.ids[v];
    if (j.anyGhostPoints) j.pointGhost[w] = j.pointGhost[v];
    if (!j.soup.referenced.empty()) j.soup.referenced[w] = j.soup.referenced[v];
    j.used[w] = j.used[v];
  }
  for (uint64_t& b : j.pointBase) {  // each piece's first point, renumbered (order is kept)
    uint64_t q = b;
    while (q < nv && newId[q] == ~0u) ++q;
    b = q < nv ? newId[q] : kept;
  }
  j.mesh.positions.resize(3 * size_t(kept));
  for (ScalarField& f : j.mesh.fields) f.values.resize(kept);
  if (j.allIds) j.ids.resize(kept);
  if (j.anyGhostPoints) j.pointGhost.resize(kept);
  if (!j.soup.referenced.empty()) j.soup.referenced.resize(kept);
  j.used.resize(kept);
  return nv - kept;
}

// The welded groups (rule 2) with their owners (rule 3). Counts the interface points and marks
// the pieces that share one.
Groups weldGroups(const Joined& j, PieceMergeSummary& summary, std::vector<uint8_t>& pieceTouches) {
  const uint32_t nv = j.vertexCount();
  std::vector<uint32_t> first;  // per vertex: its group's first member (itself when alone)
  if (j.allIds) {
    std::vector<std::pair<int64_t, uint32_t>> byId(nv);
    for (uint32_t v = 0; v < nv; ++v) byId[v] = {j.ids[v], v};
    std::sort(byId.begin(), byId.end());
    first.resize(nv);
    for (size_t i = 0; i < byId.size(); ++i)
      first[byId[i].second] = i > 0 && byId[i].first == byId[i - 1].first ? first[byId[i - 1].second] : byId[i].second;
  } else {
    findCoincident(j.mesh, first);
    if (first.empty()) {
      first.resize(nv);
      std::iota(first.begin(), first.end(), 0u);
    }
  }
  Groups groups = groupsFrom(first);
  const size_t count = groups.start.size() - 1;
  groups.owner.resize(count);
  groups.spans.resize(count);
  pieceTouches.assign(j.pieces, 0);
  for (size_t g = 0; g < count; ++g) {
    const uint32_t* m = &groups.members[groups.start[g]];
    const uint32_t size = groups.start[g + 1] - groups.start[g];
    uint32_t owner = ~0u, firstUsed = ~0u;
    size_t firstPiece = j.pieces;
    bool spans = false;
    for (uint32_t i = 0; i < size; ++i) {
      const uint32_t v = m[i];
      if (!j.used[v]) continue;
      const size_t pv = j.pieceOf(v);
      if (firstUsed == ~0u) firstUsed = v, firstPiece = pv;
      spans |= pv != firstPiece;
      if (owner == ~0u && !(j.anyGhostPoints && (j.pointGhost[v] & (kDuplicatePoint | kHiddenPoint)))) owner = v;
    }
    groups.owner[g] = owner != ~0u ? owner : firstUsed != ~0u ? firstUsed : m[0];
    groups.spans[g] = spans;
    if (!spans) continue;
    ++summary.weldedPoints;
    for (uint32_t i = 0; i < size; ++i)
      if (j.used[m[i]]) pieceTouches[j.pieceOf(m[i])] = 1;
  }
  return groups;
}

// With global ids, the copies of a point must lie together (rule 2): Corrupt with counts and an
// example when they do not, a note when they differ within the tolerance.
Result checkIdPositions(const std::string& label, const Joined& j, const Groups& groups,
                        const PieceMergeSummary& summary, ReadReport& report) {
  const Bounds b = computeBounds(j.mesh.positions);
  double extent = 0;
  for (int c = 0; c < 3; ++c) extent = std::max({extent, std::abs(double(b.min[c])), std::abs(double(b.max[c]))});
  const double tolerance = kGlobalIdTolerance * (double(b.diagonal()) + extent);
  uint64_t far = 0, near = 0;
  double farthest = 0, nearest = 0;
  std::string example;
  for (size_t g = 0; g + 1 < groups.start.size(); ++g) {
    const uint32_t o = groups.owner[g];
    const float* a = &j.mesh.positions[3 * size_t(o)];
    double worst = 0;
    for (uint32_t i = groups.start[g]; i < groups.start[g + 1]; ++i) {
      const uint32_t v = groups.members[i];
      const float* q = &j.mesh.positions[3 * size_t(v)];
      double d2 = 0;
      for (int c = 0; c < 3; ++c) d2 += (double(q[c]) - a[c]) * (double(q[c]) - a[c]);
      const double d = std::sqrt(d2);
      if (d > tolerance && example.empty()) {
        char at[80], other[80];
        std::snprintf(at, sizeof at, "(%g, %g, %g)", a[0], a[1], a[2]);
        std::snprintf(other, sizeof other, "(%g, %g, %g)", q[0], q[1], q[2]);
        example = "e.g. id " + std::to_string(j.ids[o]) + " is at " + at + " in " + j.pieceNames[j.pieceOf(o)] +
                  " and at " + other + " in " + j.pieceNames[j.pieceOf(v)];
      }
      worst = std::max(worst, d);
    }
    if (worst > tolerance)
      ++far, farthest = std::max(farthest, worst);
    else if (worst > 0 && groups.spans[g])
      ++near, nearest = std::max(nearest, worst);
  }
  if (far)
    return fail(Status::Corrupt, label + ": " + j.idsName + ": " + plural(far, "id names points", "ids name points") +
                                     " at different places in different pieces (largest distance " + number(farthest) +
                                     ", more than the tolerance " + number(tolerance) + "; " + example +
                                     "): the ids are not global, or the pieces are not of one mesh");
  if (near)
    report.notes.push_back(withThousands(near) + " of " + withThousands(summary.weldedPoints) +
                           " interface points lie up to " + number(nearest) +
                           " apart in different pieces (within the tolerance " + number(tolerance) +
                           "): each takes its owning piece's position");
  return Result::success();
}

// Every welded copy takes its owner's field values; what other pieces gave instead is counted
// per field (rule 3).
void takeOwnersValues(Joined& j, const Groups& groups, const PieceMergeSummary& summary, ReadReport& report) {
  for (ScalarField& f : j.mesh.fields) {
    const Range range = computeRange(f.values);
    const double span = double(range.max) - double(range.min);
    Agreement a;
    for (size_t g = 0; g + 1 < groups.start.size(); ++g) {
      const uint32_t o = groups.owner[g];
      const float ov = f.values[o];
      bool differs = false, rounds = false;
      double worst = 0;
      for (uint32_t i = groups.start[g]; i < groups.start[g + 1]; ++i) {
        const uint32_t v = groups.members[i];
        const float x = f.values[v];
        // Copies in the owner's piece keep their values (finishMesh treats them as in a file of
        // one piece); the other pieces' copies, and copies no kept cell uses, take the owner's.
        const bool ownPiece = j.pieceOf(v) == j.pieceOf(o);
        if (!j.used[v] || !ownPiece) f.values[v] = ov;
        if (!j.used[v] || ownPiece || x == ov || (std::isnan(x) && std::isnan(ov))) continue;
        const double d = std::abs(double(x) - double(ov));
        const double scale = std::max({std::abs(double(x)), std::abs(double(ov)), span});
        if (std::isfinite(d) && d <= 1e-6 * scale) {
          rounds = true;
          a.largestRounding = std::max(a.largestRounding, d);
        } else {
          differs = true;
          worst = std::max(worst, std::isfinite(d) ? d : std::numeric_limits<double>::infinity());
        }
      }
      if (differs)
        ++a.disagree, a.largest = std::max(a.largest, worst);
      else if (rounds)
        ++a.rounding;
    }
    const std::string of = " of " + withThousands(summary.weldedPoints) + " interface points";
    if (a.disagree)
      report.notes.push_back("field '" + f.name + "': " + withThousands(a.disagree) + of +
                             " disagree between pieces (largest difference " + number(a.largest) +
                             "); each takes its owning piece's value");
    if (a.rounding)
      report.notes.push_back("field '" + f.name + "': " + withThousands(a.rounding) + of +
                             " differ between pieces by float rounding only (at most " + number(a.largestRounding) +
                             "); each takes its owning piece's value");
  }
}

// Drops the cells that another piece also holds (rule 4): ghost cells written without their
// flags. Only a cell whose corners are all interface points can be one. Returns how many.
uint64_t dropCellsHeldTwice(Joined& j, const std::vector<uint32_t>& weldedTo, const std::vector<uint8_t>& welded) {
  CellSoup& soup = j.soup;
  struct Key {
    uint8_t shape;
    std::array<uint32_t, 8> ids;
    uint32_t cell;
    bool operator<(const Key& o) const { return std::tie(shape, ids, cell) < std::tie(o.shape, o.ids, o.cell); }
  };
  std::vector<Key> keys;
  std::vector<size_t> cornerAt(soup.shapes.size() + 1, 0);
  for (size_t c = 0; c < soup.shapes.size(); ++c) cornerAt[c + 1] = cornerAt[c] + size_t(kShapeCorners[soup.shapes[c]]);
  for (size_t c = 0; c < soup.shapes.size(); ++c) {
    const uint32_t* q = &soup.corners[cornerAt[c]];
    const int nc = kShapeCorners[soup.shapes[c]];
    if (!std::all_of(q, q + nc, [&](uint32_t v) { return welded[v] != 0; })) continue;
    Key k{soup.shapes[c], {}, uint32_t(c)};
    k.ids.fill(~0u);
    for (int i = 0; i < nc; ++i) k.ids[size_t(i)] = weldedTo[q[i]];
    std::sort(k.ids.begin(), k.ids.begin() + nc);
    keys.push_back(k);
  }
  std::sort(keys.begin(), keys.end());
  std::vector<uint8_t> drop(soup.shapes.size(), 0);
  uint64_t dropped = 0;
  // In each run of equal cells the first is kept; a later one from another piece is a copy.
  for (size_t i = 1, kept = 0; i < keys.size(); ++i) {
    if (keys[i].shape != keys[kept].shape || keys[i].ids != keys[kept].ids) {
      kept = i;
      continue;
    }
    if (j.pieceOfCell(keys[i].cell) == j.pieceOfCell(keys[kept].cell)) continue;  // the input's own duplicate
    drop[keys[i].cell] = 1;
    ++dropped;
  }
  if (!dropped) return 0;
  size_t w = 0, wc = 0;
  for (size_t c = 0; c < soup.shapes.size(); ++c) {
    const int nc = kShapeCorners[soup.shapes[c]];
    if (drop[c]) continue;
    std::copy_n(&soup.corners[cornerAt[c]], nc, &soup.corners[wc]);
    soup.shapes[w] = soup.shapes[c];
    soup.source[w] = soup.source[c];
    ++w;
    wc += size_t(nc);
  }
  soup.shapes.resize(w);
  soup.source.resize(w);
  soup.corners.resize(wc);
  return dropped;
}

// With global ids, every welded copy goes now, its cells given the owner (without ids,
// finishMesh merges the coincident copies).
void keepOwnersOnly(Joined& j, const std::vector<uint32_t>& weldedTo) {
  const uint32_t nv = j.vertexCount();
  std::vector<uint32_t> newId(nv, ~0u);
  uint32_t kept = 0;
  for (uint32_t v = 0; v < nv; ++v)
    if (weldedTo[v] == v) newId[v] = kept++;
  for (uint32_t& v : j.soup.corners) v = newId[weldedTo[v]];
  for (uint32_t v = 0; v < nv; ++v) {
    if (newId[v] == ~0u) continue;
    std::copy_n(&j.mesh.positions[3 * size_t(v)], 3, &j.mesh.positions[3 * size_t(newId[v])]);
    for (ScalarField& f : j.mesh.fields) f.values[newId[v]] = f.values[v];
  }
  if (!j.soup.referenced.empty()) {
    std::vector<uint8_t> referenced(kept, 0);
    for (uint32_t v = 0; v < nv; ++v) referenced[newId[weldedTo[v]]] |= j.soup.referenced[v];
    j.soup.referenced = std::move(referenced);
  }
  j.mesh.positions.resize(3 * size_t(kept));
  for (ScalarField& f : j.mesh.fields) f.values.resize(kept);
}

}  // namespace

Result mergePieces(const std::string& label, std::vector<MeshPiece>& pieces, const PieceMergeRules& rules, TetMesh& out,
                   ReadReport& report, PieceMergeSummary& summary) {
  out = TetMesh{};
  summary = PieceMergeSummary{};
  summary.pieces = pieces.size();
  if (pieces.empty()) return fail(Status::NoTets, label + ": no pieces");
  const size_t n = pieces.size();

  std::vector<std::string> pointNames, cellNames;
  if (n > 1 || rules.declared) {
    if (Result r = chooseArrays(label, pieces, rules, false, pointNames, report); !r) return r;
    if (Result r = chooseArrays(label, pieces, rules, true, cellNames, report); !r) return r;
  }
  uint64_t hiddenPoints = 0;
  for (MeshPiece& p : pieces) {
    dropGhostCells(p, summary);
    for (uint8_t f : p.pointGhost) hiddenPoints += (f & kHiddenPoint) != 0;
  }
  if (summary.ghostCells)
    report.notes.push_back("dropped " + plural(summary.ghostCells, "ghost cell", "ghost cells") +
                           " (vtkGhostType DUPLICATECELL: another piece owns them)");
  if (summary.hiddenCells)
    report.notes.push_back("dropped " + plural(summary.hiddenCells, "hidden cell", "hidden cells") +
                           " (vtkGhostType HIDDENCELL: blanked, not part of the data)");
  if (hiddenPoints)
    report.notes.push_back("kept " + plural(hiddenPoints, "hidden point", "hidden points") +
                           " (vtkGhostType HIDDENPOINT) for the cells that use them");

  if (n == 1 && !rules.declared) {
    // One piece: as it was read (the common case; nothing is copied).
    TetMesh mesh = std::move(pieces[0].mesh);
    CellSoup soup = std::move(pieces[0].soup);
    std::vector<CellArray> cellArrays = std::move(pieces[0].cellArrays);
    std::vector<ScalarField> fields = std::move(mesh.fields);
    mesh.fields.clear();
    for (ScalarField& f : fields) addField(mesh, std::move(f), report);
    pieces.clear();
    if (Result r = finishMesh(label, mesh, soup, std::move(cellArrays), report); !r) return r;
    out = std::move(mesh);
    return Result::success();
  }

  Joined j;
  if (Result r = concatenate(label, pieces, pointNames, cellNames, j); !r) return r;
  pieces.clear();
  if (j.someIds) report.notes.push_back("global ids are in some pieces only: interface points welded by coordinates");
  if (const uint32_t unused = dropUnusedPoints(j))
    report.notes.push_back("left out " + plural(unused, "point", "points") +
                           " that no kept cell uses (the copies pieces hold for their ghost cells, or points in no "
                           "cell)");
  std::vector<uint8_t> pieceTouches;
  const Groups groups = weldGroups(j, summary, pieceTouches);
  if (j.allIds)
    if (Result r = checkIdPositions(label, j, groups, summary, report); !r) return r;
  takeOwnersValues(j, groups, summary, report);

  const uint32_t nv = j.vertexCount();
  std::vector<uint32_t> weldedTo(nv);
  std::iota(weldedTo.begin(), weldedTo.end(), 0u);
  std::vector<uint8_t> welded(nv, 0);  // in a group that spans pieces
  for (size_t g = 0; g + 1 < groups.start.size(); ++g)
    for (uint32_t i = groups.start[g]; i < groups.start[g + 1]; ++i) {
      weldedTo[groups.members[i]] = groups.owner[g];
      welded[groups.members[i]] = groups.spans[g];
    }
  summary.duplicateCells = dropCellsHeldTwice(j, weldedTo, welded);
  if (summary.duplicateCells)
    report.notes.push_back("dropped " + plural(summary.duplicateCells, "cell", "cells") +
                           " that another piece also holds (ghost cells written without vtkGhostType)");
  if (j.allIds) keepOwnersOnly(j, weldedTo);
  summary.byGlobalIds = j.allIds;
  summary.globalIdsName = j.allIds ? j.idsName : std::string();

  const std::string how = j.allIds ? " by global ids ('" + j.idsName + "')" : " by exact coordinates";
  report.notes.push_back(std::string(rules.joined) + " " + plural(n, "piece", "pieces") + "; welded " +
                         plural(summary.weldedPoints, "interface point", "interface points") +
                         " (points that cells of two or more pieces use)" + how);
  const uint64_t alone = uint64_t(std::count(pieceTouches.begin(), pieceTouches.end(), 0));
  if (alone && n > 1)
    report.notes.push_back(plural(alone, "piece shares", "pieces share") + " no point with another piece");

  TetMesh mesh = std::move(j.mesh);
  std::vector<ScalarField> fields = std::move(mesh.fields);
  mesh.fields.clear();
  for (ScalarField& f : fields) addField(mesh, std::move(f), report);
  if (Result r = finishMesh(label, mesh, j.soup, std::move(j.cellArrays), report); !r) return r;
  out = std::move(mesh);
  return Result::success();
}

}  // namespace vtkio
}  // namespace tetstream
