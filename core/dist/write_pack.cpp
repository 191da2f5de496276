#include "dist/write_pack.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <future>

#include "pack/chunk_encode.h"
#include "pack/pack_output.h"

namespace tetstream::dist {
namespace fs = std::filesystem;
namespace {

// A node's region figures: per node of the unit's own tree (RegionTree numbering), over the
// input points of the part that its leaves hold. A combined part is one node, its group's region.
struct NodeFigures {
  std::vector<Bounds> bounds;
  std::vector<std::vector<Range>> ranges;
};

NodeFigures nodeFigures(const Unit& u, const RankTree& tree, const RegionFigures& regions, size_t F) {
  NodeFigures out;
  const RankTree::Group& g = tree.groups[size_t(u.group)];
  const RegionTree& t = u.s.tree;
  const uint32_t nodes = std::max<uint32_t>(t.nodes(), 2);
  out.bounds.assign(nodes, Bounds{{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}});
  out.ranges.assign(nodes, std::vector<Range>(F, Range{INFINITY, -INFINITY}));
  if (g.low < 0 && t.depth > 0) {
    const PartMesh& p = u.part;
    // A leaf's own points, and those of its tets in later leaves (RegionTree::rim).
    auto include = [&](uint32_t leaf, uint32_t v) {
      const uint32_t n = (1u << t.depth) + leaf;
      for (int k = 0; k < 3; ++k) {
        out.bounds[n].min[k] = std::min(out.bounds[n].min[k], p.mesh.positions[3 * size_t(v) + size_t(k)]);
        out.bounds[n].max[k] = std::max(out.bounds[n].max[k], p.mesh.positions[3 * size_t(v) + size_t(k)]);
      }
      for (size_t f = 0; f < F; ++f) {
        const float x = p.mesh.fields[f].values[v];
        if (!std::isfinite(x)) continue;
        out.ranges[n][f].min = std::min(out.ranges[n][f].min, x);
        out.ranges[n][f].max = std::max(out.ranges[n][f].max, x);
      }
    };
    for (uint32_t v = 0; v < p.mesh.vertexCount(); ++v)
      if (p.owned[v] && v < t.leafOf.size() && t.leafOf[v] != ~0u) include(t.leafOf[v], v);
    for (const auto& [leaf, v] : t.rim) include(leaf, v);
    for (uint32_t n = nodes; n-- > 2;)
      for (int k = 0; k < 3; ++k) {
        out.bounds[n / 2].min[k] = std::min(out.bounds[n / 2].min[k], out.bounds[n].min[k]);
        out.bounds[n / 2].max[k] = std::max(out.bounds[n / 2].max[k], out.bounds[n].max[k]);
        if (k == 0)
          for (size_t f = 0; f < F; ++f) {
            out.ranges[n / 2][f].min = std::min(out.ranges[n / 2][f].min, out.ranges[n][f].min);
            out.ranges[n / 2][f].max = std::max(out.ranges[n / 2][f].max, out.ranges[n][f].max);
          }
      }
  }
  // Within the group's region (which also stands in for nodes without points).
  const Bounds gb = regions.groupBounds(g);
  for (uint32_t n = 1; n < nodes; ++n) {
    for (int k = 0; k < 3; ++k) {
      Bounds& b = out.bounds[n];
      if (!(b.min[k] <= b.max[k])) b.min[k] = gb.min[k], b.max[k] = gb.max[k];
      b.min[k] = std::clamp(b.min[k], gb.min[k], gb.max[k]);
      b.max[k] = std::clamp(b.max[k], b.min[k], gb.max[k]);
    }
    for (size_t f = 0; f < F; ++f) {
      const Range gr = regions.groupRange(g, f);
      Range& x = out.ranges[n][f];
      if (!(x.min <= x.max)) x = gr;
      x.min = std::clamp(x.min, gr.min, gr.max);
      x.max = std::clamp(x.max, x.min, gr.max);
    }
  }
  return out;
}

void putBounds(Writer& w, const Bounds& b) {
  for (int k = 0; k < 3; ++k) w.put(b.min[k]), w.put(b.max[k]);
}
Bounds getBounds(Reader& in) {
  Bounds b;
  for (int k = 0; k < 3; ++k) b.min[k] = in.get<float>(), b.max[k] = in.get<float>();
  return b;
}

// What rank 0 learns of one unit.
struct UnitReport {
  int group = -1;
  std::vector<ChunkInfo> chunks;
  std::vector<float> chunkError;  // largest collapse error per chunk
  std::vector<UnitNode> nodes;
  std::vector<Bounds> nodeBounds;
  std::vector<std::vector<Range>> nodeRanges;
};

}  // namespace

Result writeDistributed(Comm& comm, const RankTree& tree, const UnitLayout& layout, std::vector<Unit>& units,
                        const RegionFigures& regions, Manifest& m, const std::string& outDir, const PackOptions& opt,
                        const RankFigures& mine, const MeasuredError& measured, DistributedSummary& out) {
  const int me = comm.rank();
  const size_t G = tree.groups.size(), F = m.fields.size();
  // Every unit's first chunk index, in preorder after the base.
  std::vector<uint64_t> chunkCount(G, 0);
  for (const Unit& u : units) chunkCount[size_t(u.group)] = u.encoded.chunks.size();
  comm.sumInPlace(chunkCount);
  std::vector<uint64_t> firstChunk(G, 0);
  uint64_t next = 1;
  for (int g : tree.preorder()) {
    firstChunk[size_t(g)] = next;
    next += chunkCount[size_t(g)];
  }
  if (next > UINT32_MAX) return comm.agree(fail(Status::TooLarge, "more chunks than the format numbers"));

  Result status = injectedFault(me, "write");
  if (status && me == 0) {
    std::error_code ec;
    fs::create_directories(fs::path(outDir) / "chunks", ec);
    if (ec) status = fail(Status::IoError, outDir + ": cannot create folder: " + ec.message());
  }
  if (Result r = comm.agree(status); !r) return r;

  // Compress and write this rank's chunks, on its threads.
  ChunkInfo base;
  std::vector<UnitReport> reports;
  for (Unit& u : units) {
    UnitReport& rep = reports.emplace_back();
    rep.group = u.group;
    const size_t n = u.encoded.chunks.size();
    rep.chunks.resize(n);
    rep.chunkError.resize(n);
    std::vector<Result> results(n);
    auto work = [&](size_t k) {
      std::vector<uint8_t> file;
      const uint32_t index = uint32_t(firstChunk[size_t(u.group)] + k);
      results[k] = finishUnitChunk(u.encoded.chunks[k], index, opt.zstdLevel, file, rep.chunks[k]);
      if (!results[k]) return;
      rep.chunks[k].file = chunkFileName(index, rep.chunks[k].hash);
      results[k] = writeWholeFile((fs::path(outDir) / rep.chunks[k].file).string(), file.data(), file.size());
      u.encoded.chunks[k].raw = {};
    };
    for (size_t k = 0; k < n; k += 2) {
      std::future<void> second;
      if (k + 1 < n && opt.threads > 1) second = std::async(std::launch::async, work, k + 1);
      work(k);
      if (second.valid())
        second.get();
      else if (k + 1 < n)
        work(k + 1);
    }
    for (const Result& r : results)
      if (status && !r) status = r;
    for (size_t k = 0; k < n; ++k) rep.chunkError[k] = u.encoded.chunks[k].maxCollapseError;  // (capped at assembly)
    rep.nodes = u.encoded.nodes;
    const NodeFigures figures = nodeFigures(u, tree, regions, F);
    for (const UnitNode& node : rep.nodes) {
      rep.nodeBounds.push_back(figures.bounds[std::min<size_t>(node.node, figures.bounds.size() - 1)]);
      rep.nodeRanges.push_back(figures.ranges[std::min<size_t>(node.node, figures.ranges.size() - 1)]);
    }
    if (u.group == 0 && status) {
      std::vector<uint8_t> file;
      status = encodeBaseChunk(u.encoded.handoff, 0, opt.zstdLevel, file, base);
      base.file = chunkFileName(0, base.hash);
      if (status) status = writeWholeFile((fs::path(outDir) / base.file).string(), file.data(), file.size());
    }
  }
  if (Result r = comm.agree(status); !r) return r;

  // Everything rank 0 needs, gathered.
  Bytes sent;
  Writer w(sent);
  w.put(mine);
  w.put<uint64_t>(reports.size());
  for (const UnitReport& rep : reports) {
    w.put(rep.group);
    w.put<uint64_t>(rep.chunks.size());
    for (size_t k = 0; k < rep.chunks.size(); ++k) {
      const ChunkInfo& c = rep.chunks[k];
      w.putString(c.file);
      w.put(c.bytes), w.put(c.rawBytes), w.put(c.hash), w.put(c.vertices), w.put(c.tets), w.put(c.splits);
      w.put(rep.chunkError[k]);
    }
    w.put<uint64_t>(rep.nodes.size());
    for (size_t k = 0; k < rep.nodes.size(); ++k) {
      w.put(rep.nodes[k]);
      putBounds(w, rep.nodeBounds[k]);
      for (const Range& x : rep.nodeRanges[k]) w.put(x);
    }
  }
  const std::vector<Bytes> all = comm.allGather(sent);
  if (me != 0) return comm.agree(Result::success());

  std::vector<UnitReport> byGroup(G);
  for (const Bytes& b : all) {
    Reader in(b);
    out.ranks.push_back(in.get<RankFigures>());
    for (uint64_t n = in.get<uint64_t>(); n-- > 0 && in.ok();) {
      UnitReport rep;
      rep.group = in.get<int>();
      for (uint64_t k = in.get<uint64_t>(); k-- > 0 && in.ok();) {
        ChunkInfo c;
        c.kind = ChunkKind::Splits;
        c.file = in.getString();
        c.bytes = in.get<uint64_t>(), c.rawBytes = in.get<uint64_t>(), c.hash = in.get<uint64_t>();
        c.vertices = in.get<uint32_t>(), c.tets = in.get<uint32_t>(), c.splits = in.get<uint32_t>();
        rep.chunks.push_back(c);
        rep.chunkError.push_back(in.get<float>());
      }
      for (uint64_t k = in.get<uint64_t>(); k-- > 0 && in.ok();) {
        rep.nodes.push_back(in.get<UnitNode>());
        rep.nodeBounds.push_back(getBounds(in));
        std::vector<Range> ranges(F);
        for (Range& x : ranges) x = in.get<Range>();
        rep.nodeRanges.push_back(std::move(ranges));
      }
      if (rep.group >= 0 && size_t(rep.group) < G) byGroup[size_t(rep.group)] = std::move(rep);
    }
  }

  // The manifest: the base, then every unit's chunks and nodes in preorder.
  const int iso = m.findField(m.isoField);
  const float range = iso >= 0 ? m.fields[size_t(iso)].range.max - m.fields[size_t(iso)].range.min : 0.0f;
  m.chunks.assign(1, base);
  std::vector<float> chunkError(1, 0);
  m.nodes.clear();
  std::vector<float> nodeError;
  std::vector<int32_t> topNode(G, -1);  // per group: the manifest index of its unit's node 1
  for (int g : tree.preorder()) {
    UnitReport& rep = byGroup[size_t(g)];
    const uint32_t chunk0 = uint32_t(m.chunks.size());
    for (size_t k = 0; k < rep.chunks.size(); ++k) {
      m.chunks.push_back(rep.chunks[k]);
      chunkError.push_back(rep.chunkError[k]);
    }
    int32_t attach = -1;  // the nearest group above with a node
    for (int up = tree.groups[size_t(g)].parent; up >= 0 && attach < 0; up = tree.groups[size_t(up)].parent)
      attach = topNode[size_t(up)];
    std::vector<std::pair<uint32_t, int32_t>> local;  // (node of the unit, manifest index)
    for (size_t k = 0; k < rep.nodes.size(); ++k) {
      const UnitNode& un = rep.nodes[k];
      NodeInfo info;
      info.parent = attach;
      for (uint32_t up = un.node >> 1; up >= 1; up >>= 1) {
        auto it = std::find_if(local.begin(), local.end(), [&](const auto& x) { return x.first == up; });
        if (it != local.end()) {
          info.parent = it->second;
          break;
        }
      }
      info.firstChunk = chunk0 + un.firstChunk;
      info.chunkCount = un.chunkCount;
      info.vertexBegin = uint32_t(un.vertexBegin), info.vertexEnd = uint32_t(un.vertexEnd);
      info.tetBegin = uint32_t(un.tetBegin), info.tetEnd = uint32_t(un.tetEnd);
      info.bounds = rep.nodeBounds[k];
      info.ranges = rep.nodeRanges[k];
      info.fieldRms = un.fieldRms;
      info.fieldMax = un.fieldMax;
      float own = 0;
      for (uint32_t c = un.firstChunk; c < un.firstChunk + un.chunkCount && c < rep.chunkError.size(); ++c)
        own = std::max(own, rep.chunkError[c]);
      local.push_back({un.node, int32_t(m.nodes.size())});
      if (un.node == 1) topNode[size_t(g)] = int32_t(m.nodes.size());
      m.nodes.push_back(std::move(info));
      nodeError.push_back(own);
    }
  }
  // A node's error: the largest of its collapses and those below it (in place while its splits
  // are not applied); a chunk's: the largest of the collapses in the chunks after it.
  for (size_t n = m.nodes.size(); n-- > 0;)
    if (m.nodes[n].parent >= 0)
      nodeError[size_t(m.nodes[n].parent)] = std::max(nodeError[size_t(m.nodes[n].parent)], nodeError[n]);
  for (size_t n = 0; n < m.nodes.size(); ++n) m.nodes[n].fieldError = std::min(range, nodeError[n]);
  float after = 0;
  for (size_t c = m.chunks.size(); c-- > 0;) {
    m.chunks[c].fieldError = std::min(range, after);
    after = std::max(after, chunkError[c]);
  }
  if (m.nodes.size() <= 1) m.nodes.clear();  // (one region: one sequence, as packMesh writes it)
  m.chunks[0].fieldRms = measured.baseRms;
  m.chunks[0].fieldMax = measured.baseMax;
  if (!m.nodes.empty()) {  // the root's region is the whole mesh, before its splits the base
    m.nodes[0].fieldRms = measured.baseRms;
    m.nodes[0].fieldMax = measured.baseMax;
  }
  if (m.chunks.size() > 1) m.chunks.back().fieldRms = m.chunks.back().fieldMax = 0;  // (the input on the grid)
  m.vertices = m.chunks.back().vertices;
  m.tets = m.chunks.back().tets;
  Result r = writeManifestFiles(outDir, m);
  PackSummary& s = out.pack;
  s.manifest = m;
  s.baseVertices = base.vertices;
  s.baseTets = base.tets;
  s.splits = m.vertices - base.vertices;
  s.stopReason = "target reached";
  (void)layout;
  return comm.agree(r);
}

}  // namespace tetstream::dist
