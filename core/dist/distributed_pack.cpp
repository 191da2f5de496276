#include "dist/distributed_pack.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <future>

#include "dist/base_error.h"
#include "dist/partition.h"
#include "dist/prepare.h"
#include "dist/refit.h"
#include "dist/units.h"
#include "dist/write_pack.h"
#include "pack/part.h"
#include "pack/simplify.h"
#include "pack/split_encode.h"

namespace tetstream::dist {
namespace {

double msSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

double peakMB() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss / 1024.0;
}

// Packing needs about this many bytes per tet of a rank's part at its peak (as packer.cpp's
// kPackBytesPerTet, with the halo and the parts it combines).
constexpr double kBytesPerPartTet = 220;

}  // namespace

// A failure on purpose, for the tests of what the other ranks do when one fails in a phase:
// TETSTREAM_FAULT="RANK:PHASE" (read, simplify, combine, encode, write) makes that rank fail
// there as a real failure would.
Result injectedFault(int rank, const char* phase) {
  const char* fault = std::getenv("TETSTREAM_FAULT");
  if (!fault || std::string(fault) != std::to_string(rank) + ":" + phase) return Result::success();
  return fail(Status::IoError, std::string("a fault injected in phase '") + phase + "' (TETSTREAM_FAULT)");
}

Result packDistributed(Comm& comm, const std::string& input, const ReadOptions& read, const std::string& outDir,
                       const PackOptions& opt, DistributedSummary& out) {
  out = DistributedSummary{};
  const int N = comm.size(), me = comm.rank();
  auto t0 = std::chrono::steady_clock::now();
  auto progress = [&](const char* phase) {
    if (opt.progress && me == 0) opt.progress(phase, 0, 0);
  };
  progress("read");

  // ---- read
  TetMesh mesh;
  ReadReport report;
  Result r = readShare(comm, input, read, mesh, report);
  if (r) r = injectedFault(me, "read");
  if (r = comm.agree(r); !r) return r;
  if (r = agreeOnFields(comm, mesh); !r) return r;  // (the same on every rank)
  gatherReadReports(comm, report, out.inputFormat, out.pack.notes);
  std::vector<std::string>& notes = out.pack.notes;
  const int iso = opt.field.empty() ? 0 : mesh.findField(opt.field);
  if (iso < 0) {
    std::string names;
    for (const ScalarField& f : mesh.fields) names += (names.empty() ? "" : ", ") + f.name;
    return fail(Status::MissingField, "no field named '" + opt.field + "' (fields: " + names + ")");
  }
  if (mesh.fields.empty()) return fail(Status::MissingField, "the mesh has no point scalar field to show");
  out.readMs = msSince(t0);

  // ---- partition
  t0 = std::chrono::steady_clock::now();
  progress("partition");
  std::vector<uint64_t> tetCounts(static_cast<size_t>(N), 0);
  tetCounts[size_t(me)] = mesh.tetCount();
  comm.sumInPlace(tetCounts);
  uint64_t firstTet = 0;
  for (int k = 0; k < me; ++k) firstTet += tetCounts[size_t(k)];
  for (uint64_t c : tetCounts) out.inputTets += c;
  const std::string name = opt.name.empty() ? mesh.name : opt.name;
  const RankTree tree = cutRegions(comm, mesh);
  PartMesh part;
  DistributionReport joined;
  std::vector<std::vector<double>> cellWeight(mesh.fields.size());
  for (ReadReport::CellAverage& a : report.cellAverages)
    if (const int f = mesh.findField(a.field); f >= 0) cellWeight[size_t(f)] = std::move(a.weight);
  report.cellAverages.clear();
  r = distribute(comm, std::move(mesh), firstTet, tree, cellWeight, part, joined);
  cellWeight.clear();
  if (r = comm.agree(r); !r) return r;
  {
    std::vector<uint64_t> agreed = joined.disagreements;
    agreed.push_back(joined.joinedPoints);
    comm.sumInPlace(agreed);
    if (me == 0 && N > 1) {
      notes.push_back("joined " + std::to_string(agreed.back()) +
                      " points that the pieces of several ranks hold (by exact coordinates)");
      for (size_t f = 0; f < part.mesh.fields.size(); ++f)
        if (agreed[f])
          notes.push_back("field '" + part.mesh.fields[f].name + "': " + std::to_string(agreed[f]) +
                          " joined points have different values in different pieces (the lowest rank's copy kept)");
    }
  }
  {
    double limit = opt.maxMemoryBytes;
    if (!(limit > 0)) {
      const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
      limit = pages > 0 && page > 0 ? 0.9 * double(pages) * double(page) / N : 0;  // (ranks share a node here)
    }
    const double need = kBytesPerPartTet * part.mesh.tetCount();
    r = limit > 0 && need > limit
            ? fail(Status::TooLarge, "its part (" + std::to_string(part.mesh.tetCount()) + " tetrahedra) needs about " +
                                         std::to_string(int64_t(need / 1e6)) + " MB, more than the " +
                                         std::to_string(int64_t(limit / 1e6)) +
                                         " MB allowed per rank (--max-memory): use more ranks")
            : Result::success();
    if (r = comm.agree(r); !r) return r;
  }
  out.partitionMs = msSince(t0);

  // ---- prepare
  Manifest m;
  m.generator = std::string("tetstream ") + kLibraryVersion;
  describeWhole(comm, part, name.empty() ? "dataset" : name, m);
  m.isoField = part.mesh.fields[size_t(iso)].name;
  std::vector<uint64_t> prepared(2, 0);
  prepared[0] = orient(part);
  for (const ScalarField& f : part.mesh.fields)
    for (float x : f.values) prepared[1] += !std::isfinite(x);
  comm.sumInPlace(prepared);
  if (prepared[0] && me == 0)
    notes.push_back("re-oriented " + std::to_string(prepared[0]) + " negatively oriented tetrahedra");
  chooseGrid(comm, part, m, prepared[1] > 0, opt, notes);
  RegionFigures regions = regionFigures(comm, part, m);

  // ---- simplify, then combine up the tree of ranks
  t0 = std::chrono::steady_clock::now();
  progress("simplify");
  SimplifyPart shared;
  shared.fieldMin = m.fields[size_t(iso)].range.min;
  shared.fieldMax = m.fields[size_t(iso)].range.max;
  shared.diagonal = m.bounds.diagonal() > 0 ? m.bounds.diagonal() : 1.0;
  shared.meanVertexVolume = meanVertexVolume(comm, part);
  shared.inputVertices = m.vertices;
  uint64_t target =
      opt.baseVertices ? opt.baseVertices : uint64_t(std::llround(std::clamp(opt.baseFraction, 0.0, 1.0) * m.vertices));
  if (!opt.baseVertices && opt.baseFraction > 0)
    target = std::max<uint64_t>(std::min<uint64_t>(target, opt.maxBaseVertices),
                                std::min<uint64_t>(opt.minBaseVertices, m.vertices));
  std::vector<uint64_t> ownedPerRank(static_cast<size_t>(N), 0);
  ownedPerRank[size_t(me)] = ownedCount(part);
  comm.sumInPlace(ownedPerRank);
  const uint32_t leafVertices =
      leafVerticesFor(*std::max_element(ownedPerRank.begin(), ownedPerRank.end()), uint32_t(N), opt, notes);
  auto simplifyUnit = [&](Unit& u, const CarriedVertexState* carried) {
    const RankTree::Group& g = tree.groups[size_t(u.group)];
    SimplifyPart sp = shared;
    sp.owned = &u.part.owned;
    sp.carried = carried;
    sp.topMin = regions.groupRange(g, size_t(iso)).min;
    sp.topMax = regions.groupRange(g, size_t(iso)).max;
    sp.topIsRegion = u.group != 0;
    SimplifyOptions so;
    so.weightGeometry = opt.weights[0];
    so.weightField = opt.weights[1];
    so.weightShape = opt.weights[2];
    so.threads = opt.threads;
    so.leafVertices = g.low < 0 ? leafVertices : 0;  // (a combined part is one region: the cut)
    so.fitValues = opt.fitValues;
    so.field = iso;
    so.maxError = opt.maxError;
    // The part's share of the base: the input vertices its group's region holds.
    uint64_t held = 0;
    for (int k = g.first; k < g.first + g.count; ++k) held += ownedPerRank[size_t(k)];
    const double share = m.vertices ? double(held) / m.vertices : 1.0;
    so.targetVertices = uint32_t(std::max<double>(4, std::llround(double(target) * share)));
    so.targetTets = opt.baseTets ? uint32_t(std::llround(opt.baseTets * share)) : 0;
    so.part = &sp;
    // (The part's tets are taken over, not copied: 16 bytes a tet of the peak, as packMesh does.)
    Result res = simplifyMesh(u.part.mesh, so, u.s, nullptr, &u.part.mesh.tets);
    if (res) u.handoff = partAfter(u.part, u.s);
    if (g.low < 0) std::vector<uint64_t>().swap(u.part.tetId);  // (only a combined part hands ids down)
    return res;
  };
  std::vector<Unit> units;  // bottom-up: this rank's leaf, then the groups it combines
  std::vector<int> chain{tree.leafOf(me)};
  while (tree.groups[size_t(chain.back())].parent >= 0 &&
         tree.groups[size_t(tree.groups[size_t(chain.back())].parent)].first == me)
    chain.push_back(tree.groups[size_t(chain.back())].parent);
  RankFigures mine;
  mine.ownedVertices = ownedCount(part);
  mine.tets = part.mesh.tetCount();
  units.reserve(chain.size());
  Result status;
  bool secondary = false;
  for (size_t c = 0; c < chain.size(); ++c) {
    Unit& u = units.emplace_back();
    u.group = chain[c];
    const RankTree::Group& g = tree.groups[size_t(u.group)];
    if (c == 0) {
      u.part = std::move(part);
      if (status) status = injectedFault(me, "simplify");
      if (status) status = simplifyUnit(u, nullptr);
      mine.partMs = msSince(t0);
      continue;
    }
    // Combine: the low child's handoff is this rank's previous unit's; the high one comes from
    // its first rank.
    Bytes got;
    const bool theirsOk = comm.receive(tree.groups[size_t(g.high)].first, g.high, got);
    PartMesh high;
    if (status && !theirsOk) {
      status = fail(Status::Corrupt, "a rank below failed");
      secondary = true;
    }
    if (status && !readPart(got, high)) status = fail(Status::Corrupt, "a part from a rank below is damaged");
    if (!status) continue;
    Unit& low = units[c - 1];
    u.childVertexIds[0] = low.handoff.vertexId;
    u.childTetIds[0] = low.handoff.tetId;
    u.childVertexIds[1] = high.vertexId;
    u.childTetIds[1] = high.tetId;
    u.part = mergeParts(low.handoff, high);
    high = PartMesh{};
    CarriedVertexState carried = std::move(u.part.carried);
    const auto c0 = std::chrono::steady_clock::now();
    status = injectedFault(me, "combine");
    if (status) status = simplifyUnit(u, &carried);
    mine.combineMs += msSince(c0);
  }
  if (const int up = tree.groups[size_t(chain.back())].parent; up >= 0) {
    Bytes sent;
    if (status) writePart(units.back().handoff, sent);
    comm.send(tree.groups[size_t(up)].first, chain.back(), sent, !status);
  }
  mine.simplifyMs = msSince(t0);
  if (r = comm.agree(status, secondary); !r) return r;
  out.simplifyMs = msSince(t0);

  // ---- the base's values fitted again against the whole input
  Unit* root = nullptr;
  for (Unit& u : units) root = u.group == 0 ? &u : root;
  refitBase(comm, root, units.front().part, iso);

  // ---- encode, top-down
  t0 = std::chrono::steady_clock::now();
  progress("encode");
  const UnitLayout layout = planUnits(comm, tree, units);
  status = Result::success();
  secondary = false;
  for (size_t c = units.size(); c-- > 0;) {
    Unit& u = units[c];
    const RankTree::Group& g = tree.groups[size_t(u.group)];
    UnitEncodeOptions uo;
    uo.stream.firstChunkBytes = std::min<uint32_t>(opt.chunkKb << 10, 16u << 10);
    uo.stream.chunkBytes = opt.chunkKb << 10;
    uo.stream.zstdLevel = opt.zstdLevel;
    uo.stream.ringWalk = opt.ringWalk;
    uo.stream.threads = opt.threads;
    uo.topIsRegion = u.group != 0;
    // A rank's own part holds its input vertices at full resolution: its nodes' field error is
    // measured there (a combined part holds coarse parts: its node keeps the estimate).
    uo.measureAt = g.low < 0 ? &u.part.owned : nullptr;
    uo.vertexBegin = layout.vertexBegin[size_t(u.group)];
    uo.tetBegin = layout.tetBegin[size_t(u.group)];
    StableIds hand;  // stable ids of the handoff (and the values it starts from), in its order
    if (u.group == 0) {
      for (uint64_t k = 0; k < u.handoff.vertexId.size(); ++k) hand.vertices.push_back(k);
      for (uint64_t k = 0; k < u.handoff.tetId.size(); ++k) hand.tets.push_back(k);
    } else if (c + 1 < units.size()) {
      hand = std::move(units[c + 1].childStable[0]);
    } else {
      Bytes got;
      const bool ok = comm.receive(tree.groups[size_t(g.parent)].first, u.group, got);
      if (status && !ok) {
        status = fail(Status::Corrupt, "a rank above failed");
        secondary = true;
      }
      Reader in(got);
      hand.vertices = in.getVector<uint64_t>();
      hand.tets = in.getVector<uint64_t>();
      hand.values = in.getVector<float>();
      if (status && (!in.atEnd() || hand.vertices.size() != u.handoff.vertexId.size() ||
                     hand.tets.size() != u.handoff.tetId.size()))
        status = fail(Status::Corrupt, "stable ids from the rank above are damaged");
    }
    if (status) status = injectedFault(me, "encode");
    if (status) status = encodeOne(u, hand, m, uo);
    for (int side = 0; side < 2 && g.low >= 0; ++side) {
      const int child = side ? g.high : g.low;
      StableIds ids;
      if (status) ids = stableIdsOf(u, side);
      if (side == 0) {
        u.childStable[0] = std::move(ids);
        continue;
      }
      Bytes sent;
      Writer w(sent);
      w.putVector(ids.vertices);
      w.putVector(ids.tets);
      w.putVector(ids.values);
      comm.send(tree.groups[size_t(child)].first, child, sent, !status);
    }
  }
  mine.encodeMs = msSince(t0);
  if (r = comm.agree(status, secondary); !r) return r;

  // ---- write
  progress("write");
  mine.peakMB = peakMB();
  {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    mine.cpuSeconds =
        double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
  }
  // The base's error at the input's vertices (none at the full level: the input on the grid).
  MeasuredError measured;
  measureBaseError(comm, root ? &root->encoded.handoff : nullptr, units.front().part, iso, measured.baseRms,
                   measured.baseMax);
  return writeDistributed(comm, tree, layout, units, regions, m, outDir, opt, mine, measured, out);  // (agreed)
}

}  // namespace tetstream::dist
