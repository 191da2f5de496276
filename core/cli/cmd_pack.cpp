// tetstream pack INPUT -o OUTDIR [--field NAME] [--weights G,F,S] [--base-fraction F |
//   --base-vertices N | --max-error E] [--lossless] [--compact] [--chunk-kb K] [--json]
#include <sys/resource.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <memory>

#include "cli_common.h"
#include "commands.h"
#include "dist/distributed_pack.h"
#include "pack/packer.h"

namespace tetstream::cli {
namespace {

// 0.0263 -> "2.6%", 0.000412 -> "0.041%": two significant digits.
std::string formatPercent(double fraction) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2g%%", 100 * fraction);
  return buf;
}

// One-line progress on a terminal: phase, bar, percent, rate, time left. Silent otherwise.
class ProgressLine {
 public:
  explicit ProgressLine(bool enabled) : enabled_(enabled) {}
  void update(const char* phase, uint64_t done, uint64_t planned) {
    if (!enabled_) return;
    auto now = std::chrono::steady_clock::now();
    if (phase != phase_) {
      finishLine();
      phase_ = phase;
      phaseStart_ = now;
    } else if (done < planned && now - lastDraw_ < std::chrono::milliseconds(100)) {
      return;
    }
    lastDraw_ = now;
    const double secs = std::chrono::duration<double>(now - phaseStart_).count();
    const double fraction = planned ? double(done) / double(planned) : 0.0;
    char rate[48] = "", eta[32] = "";
    // A rate only where the phase counts items (reading counts itself as 0 then 1 of 1).
    const char* unit = phase_ == "simplify" ? "collapses" : phase_ == "encode" ? "splits" : nullptr;
    if (planned && secs > 0.2) {
      if (unit) std::snprintf(rate, sizeof rate, ", %.0fk %s/s", done / secs / 1000, unit);
      if (fraction > 0.02 && fraction < 1)
        std::snprintf(eta, sizeof eta, ", %.0f s left", secs * (1 - fraction) / fraction);
    }
    const int filled = int(fraction * 30 + 0.5);
    std::fprintf(stderr, "\r  %-9s [%.*s%*s] %5.1f%%  %.1f s%s%s   ", phase, filled, "##############################",
                 30 - filled, "", 100 * fraction, secs, rate, eta);
    drawn_ = true;
  }
  void finishLine() {
    if (drawn_) std::fprintf(stderr, "\n");
    drawn_ = false;
  }

 private:
  bool enabled_, drawn_ = false;
  std::string phase_;
  std::chrono::steady_clock::time_point phaseStart_, lastDraw_;
};

double peakMemoryMB() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss / 1024.0;  // Linux reports KiB
}

struct Opts {
  std::string input, out, field, name;
  std::vector<double> weights;
  double baseFraction = 0.01, maxError = -1, maxMemoryGb = 0;
  uint32_t baseVertices = 0, baseTets = 0, chunkKb = 256, leafVertices = PackOptions{}.leafVertices;
  int level = 18, threads = 2;
  bool lossless = false, json = false, samples = false, compact = false;
  ReadOptions read;
};

// The command line as PackOptions (maxErrorSet and the others: whether those options were given).
PackOptions packOptionsOf(const Opts& o, bool maxErrorSet, bool baseVerticesSet, bool baseTetsSet) {
  PackOptions opt;
  opt.field = o.field;
  opt.name = o.name;
  opt.zstdLevel = o.level;
  opt.threads = o.threads;
  opt.fitValues = !o.samples;
  if (!o.weights.empty())
    for (int k = 0; k < 3; ++k) opt.weights[k] = o.weights[size_t(k)];
  opt.baseFraction = o.baseFraction;
  if (baseVerticesSet) opt.baseVertices = std::max<uint32_t>(o.baseVertices, 4);
  if (baseTetsSet) opt.baseTets = o.baseTets;
  if (maxErrorSet) {
    opt.maxError = o.maxError;
    opt.baseFraction = 0;  // as far as the error bound allows
  }
  opt.lossless = o.lossless;
  opt.orderSplits = o.compact;
  opt.chunkKb = o.chunkKb;
  opt.leafVertices = o.leafVertices;
  opt.maxMemoryBytes = o.maxMemoryGb * 1e9;
  return opt;
}

// `pack` under an MPI launcher: every rank packs its share (dist/distributed_pack.h); rank 0
// reports, for the whole job and per rank.
int packOnRanks(const Opts& o, bool maxErrorSet, bool baseVerticesSet, bool baseTetsSet) {
  std::unique_ptr<dist::Comm> comm;
  if (Result r = dist::Comm::world(comm); !r) return reportError(r, o.json);
  const bool lead = comm->rank() == 0;
  if (o.compact) {
    Result r = fail(Status::BadArgument, "--compact is not available with several processes");
    return lead ? reportError(r, o.json) : 1;
  }
  Stopwatch total;
  PackOptions opt = packOptionsOf(o, maxErrorSet, baseVerticesSet, baseTetsSet);
  ProgressLine bar(lead && !o.json && isatty(2));
  opt.progress = [&bar](const char* phase, uint64_t done, uint64_t planned) { bar.update(phase, done, planned); };
  dist::DistributedSummary s;
  Result r = dist::packDistributed(*comm, o.input, o.read, o.out, opt, s);
  bar.finishLine();
  if (!lead) return r ? 0 : 1;
  if (!r) return reportError(r, o.json);
  const Manifest& m = s.pack.manifest;
  const uint64_t bytes = m.totalBytes();
  json ranks = json::array();
  double worstPeak = 0;
  for (size_t k = 0; k < s.ranks.size(); ++k) {
    const dist::RankFigures& f = s.ranks[k];
    worstPeak = std::max(worstPeak, f.peakMB);
    ranks.push_back({{"rank", k},
                     {"ownedVertices", f.ownedVertices},
                     {"tets", f.tets},
                     {"peakMemoryMB", f.peakMB},
                     {"simplifyMs", f.simplifyMs},
                     {"partMs", f.partMs},
                     {"combineMs", f.combineMs},
                     {"encodeMs", f.encodeMs},
                     {"cpuSeconds", f.cpuSeconds}});
  }
  if (o.json) {
    printJson({{"output", o.out},
               {"name", m.name},
               {"ranks", comm->size()},
               {"vertices", m.vertices},
               {"tets", m.tets},
               {"inputTets", s.inputTets},
               {"inputFormat", s.inputFormat},
               {"field", m.isoField},
               {"lossless", m.lossless},
               {"positionBits", m.positionBits},
               {"baseVertices", s.pack.baseVertices},
               {"baseTets", s.pack.baseTets},
               {"splits", s.pack.splits},
               {"chunks", m.chunks.size()},
               {"nodes", m.nodes.size()},
               {"bytes", bytes},
               {"baseBytes", m.chunks[0].bytes},
               {"baseFieldRms", m.chunks[0].fieldRms},
               {"baseFieldMax", m.chunks[0].fieldMax},
               {"readMs", s.readMs},
               {"partitionMs", s.partitionMs},
               {"simplifyMs", s.simplifyMs},
               {"ms", total.ms()},
               {"peakMemoryMB", worstPeak},
               {"perRank", ranks},
               {"notes", s.pack.notes}});
    return 0;
  }
  for (const std::string& n : s.pack.notes) std::printf("note: %s\n", n.c_str());
  std::printf("packed %s -> %s/ on %d ranks\n", o.input.c_str(), o.out.c_str(), comm->size());
  std::printf("  format    %s\n", s.inputFormat.c_str());
  std::printf("  input     %u vertices, %u tets, field '%s'\n", m.vertices, m.tets, m.isoField.c_str());
  std::printf("  base      %u vertices, %u tets, %.1f KB\n", s.pack.baseVertices, s.pack.baseTets,
              m.chunks[0].bytes / 1024.0);
  if (const ChunkInfo& b = m.chunks[0]; b.fieldRms >= 0)
    std::printf("  error     base field error at the input's vertices: RMS %.3g, largest %.3g\n", b.fieldRms,
                b.fieldMax);
  std::printf("  stream    %u splits in %zu chunks, %zu nodes, %.2f MB in all\n", s.pack.splits, m.chunks.size() - 1,
              m.nodes.size(), bytes / 1e6);
  std::printf("  time      read %.0f ms, partition %.0f ms, simplify %.0f ms, all %.0f ms\n", s.readMs, s.partitionMs,
              s.simplifyMs, total.ms());
  for (size_t k = 0; k < s.ranks.size(); ++k)
    std::printf(
        "  rank %-4zu %llu vertices, %llu tets; its part %.0f ms, combining %.0f ms, encode %.0f ms; %.1f s of "
        "processor; peak memory %.0f MB\n",
        k, static_cast<unsigned long long>(s.ranks[k].ownedVertices), static_cast<unsigned long long>(s.ranks[k].tets),
        s.ranks[k].partMs, s.ranks[k].combineMs, s.ranks[k].encodeMs, s.ranks[k].cpuSeconds, s.ranks[k].peakMB);
  return 0;
}

}  // namespace

Runner addPack(CLI::App& app) {
  auto o = std::make_shared<Opts>();
  CLI::App* sub = app.add_subcommand("pack", "Pack a mesh into a progressive dataset folder (manifest + chunks)");
  sub->add_option("input", o->input,
                  "mesh file: .vtu/.vts/.vti, .vtk, .pvtu/.vtm/.pvtk (with their pieces), .msh (Gmsh), .node/.ele "
                  "(TetGen), .mesh (Medit), PLOT3D grid, .exo (Exodus II), .cgns (CGNS), .xdmf (XDMF), .vtkhdf")
      ->required();
  addReadOptions(sub, o->read);
  sub->add_option("-o,--output", o->out, "output folder (created; an earlier pack there is replaced)")->required();
  sub->add_option("--field", o->field, "field that steers simplification and is shown first (default: the first)");
  sub->add_option("--name", o->name, "dataset name shown in the viewer (default: the file name)");
  sub->add_option("--weights", o->weights,
                  "cost weights G,F,S: boundary geometry, field, tet shape (default 100,1,0.005)")
      ->delimiter(',')
      ->expected(3);
  auto* bf = sub->add_option("--base-fraction", o->baseFraction,
                             "base mesh size as a fraction of the vertices (at most 65,536 of them)")
                 ->check(CLI::Range(0.0, 1.0))
                 ->capture_default_str();
  auto* bv = sub->add_option("--base-vertices", o->baseVertices, "base mesh size in vertices");
  auto* bt =
      sub->add_option("--base-tets", o->baseTets, "base mesh size in tets (with --base-fraction 0: the only target)");
  auto* me = sub->add_option("--max-error", o->maxError,
                             "stop simplifying when the next collapse would leave a field error above E (relative to "
                             "the field's range)")
                 ->check(CLI::PositiveNumber);
  bv->excludes(bf);
  me->excludes(bf);
  me->excludes(bv);
  sub->add_flag("--lossless", o->lossless, "keep exact float32 positions and fields (default: 16-bit grid)");
  sub->add_flag("--samples", o->samples,
                "coarse levels keep the input's values at their vertices (default: values fitted to the region "
                "each vertex stands for, which lowers the field error; the full level is the input either way)");
  sub->add_flag("--compact", o->compact,
                "a smaller stream (1-14% on the test datasets) for a longer pack (3-6%) and ~20% more memory: "
                "inside each chunk the splits go by kept vertex, not by cost");
  sub->add_option("--chunk-kb", o->chunkKb, "largest split chunk in KB; the first chunks are smaller")
      ->check(CLI::Range(1u, 65536u))
      ->capture_default_str();
  sub->add_option("--leaf-vertices", o->leafVertices,
                  "largest region of the patch hierarchy, in vertices (smaller: a viewer fetches less for one "
                  "isovalue, in more files; 0: one region; raised where it would make over 16,384 leaves)")
      ->capture_default_str();
  sub->add_option("--zstd-level", o->level, "zstd compression level")->check(CLI::Range(1, 22))->capture_default_str();
  sub->add_option("--max-memory", o->maxMemoryGb,
                  "refuse meshes that need more memory than this, in GB (default: 90% of RAM)")
      ->check(CLI::PositiveNumber);
  sub->add_option("--threads", o->threads,
                  "threads for simplification and for measuring each level's error (1 or 2; the output is the same)")
      ->check(CLI::Range(1, 2))
      ->capture_default_str();
  sub->add_flag("--json", o->json, "print the result as JSON on stdout");
  return [o, me, bv, bt] {
    if (dist::launchedByMpi()) return packOnRanks(*o, me->count() > 0, bv->count() > 0, bt->count() > 0);
    Stopwatch total;
    ProgressLine bar(!o->json && isatty(2));
    bar.update("read", 0, 1);
    Input in;
    if (Result r = loadInput(o->input, in, {}, o->read); !r) {
      bar.finishLine();
      return reportError(r, o->json);
    }
    if (in.packed)
      return reportError(fail(Status::BadArgument, o->input + " is already packed; give a mesh file"), o->json);
    bar.update("read", 1, 1);
    double readMs = total.ms();
    const uint32_t inputVertices = in.mesh.vertexCount();
    PackOptions opt = packOptionsOf(*o, me->count() > 0, bv->count() > 0, bt->count() > 0);
    opt.progress = [&bar](const char* phase, uint64_t done, uint64_t planned) { bar.update(phase, done, planned); };
    PackSummary s;
    Result r = packMesh(std::move(in.mesh), o->out, opt, s);
    bar.finishLine();
    if (!r) return reportError(r, o->json);

    const Manifest& m = s.manifest;
    uint64_t bytes = m.totalBytes(), baseBytes = m.chunks[0].bytes;
    double bitsPerTet = 8.0 * double(bytes) / m.tets;
    double bytesPerSplit = s.splits ? double(bytes - baseBytes) / s.splits : 0;
    json notes = in.notes;
    for (const std::string& n : s.notes) notes.push_back(n);
    if (o->json) {
      printJson({{"output", o->out},
                 {"name", m.name},
                 {"vertices", m.vertices},
                 {"tets", m.tets},
                 {"inputVertices", inputVertices},
                 {"inputFormat", in.format},
                 {"field", m.isoField},
                 {"lossless", m.lossless},
                 {"positionBits", m.positionBits},
                 {"baseVertices", s.baseVertices},
                 {"baseTets", s.baseTets},
                 {"splits", s.splits},
                 {"chunks", m.chunks.size()},
                 {"bytes", bytes},
                 {"baseBytes", baseBytes},
                 {"bitsPerTet", bitsPerTet},
                 {"bytesPerSplit", bytesPerSplit},
                 {"movedMasks", s.movedMasks},
                 {"baseFieldError", m.chunks[0].fieldError},
                 {"baseFieldRms", m.chunks[0].fieldRms},
                 {"baseFieldMax", m.chunks[0].fieldMax},
                 {"stopReason", s.stopReason},
                 {"flatTetsRemoved", s.flatTetsRemoved},
                 {"flatTetsLeft", s.flatTetsLeft},
                 {"queuePops", s.queuePops},
                 {"regionCollapses", s.regionCollapses},
                 {"requeued", s.requeued},
                 {"costEvaluations", s.costEvaluations},
                 {"readMs", readMs},
                 {"prepareMs", s.prepareMs},
                 {"simplifyMs", s.simplifyMs},
                 {"encodeMs", s.encodeMs},
                 {"writeMs", s.writeMs},
                 {"ms", total.ms()},
                 {"peakMemoryMB", peakMemoryMB()},
                 {"notes", notes}});
      return 0;
    }
    for (const auto& n : notes) std::printf("note: %s\n", n.get<std::string>().c_str());
    std::printf("packed %s -> %s/\n", o->input.c_str(), o->out.c_str());
    std::printf("  format    %s\n", in.format.c_str());
    std::printf("  input     %u vertices, %u tets, field '%s'\n", m.vertices, m.tets, m.isoField.c_str());
    std::printf("  base      %u vertices (%.2f%%), %u tets, %.1f KB\n", s.baseVertices,
                100.0 * s.baseVertices / std::max<uint32_t>(m.vertices, 1), s.baseTets, baseBytes / 1024.0);
    if (const ChunkInfo& b = m.chunks[0]; b.fieldRms >= 0) {
      const int iso = m.findField(m.isoField);
      const double range = iso >= 0 ? m.fields[size_t(iso)].range.max - m.fields[size_t(iso)].range.min : 0.0;
      auto share = [&](double e) {
        return range > 0 ? " (" + formatPercent(e / range) + " of the range)" : std::string();
      };
      std::printf("  error     base field error at the input's vertices: RMS %.3g%s, largest %.3g%s\n", b.fieldRms,
                  share(b.fieldRms).c_str(), b.fieldMax, share(b.fieldMax).c_str());
    }
    std::printf("  stream    %u splits in %zu chunk%s, %.2f MB in all, %.1f bits/tet, %.1f bytes/split\n", s.splits,
                m.chunks.size() - 1, m.chunks.size() == 2 ? "" : "s", bytes / 1e6, bitsPerTet, bytesPerSplit);
    std::printf("  values    %s\n", m.lossless ? "lossless float32"
                                               : ("quantized, " + std::to_string(m.positionBits) + "-bit positions, " +
                                                  std::to_string(m.fieldBits) + "-bit fields")
                                                     .c_str());
    std::printf("  stopped   %s", s.stopReason.c_str());
    if (s.flatTetsRemoved || s.flatTetsLeft)
      std::printf("; flat input tets: %u removed, %u left", s.flatTetsRemoved, s.flatTetsLeft);
    std::printf(
        "\n  time      read %.0f ms, prepare %.0f ms, simplify %.0f ms, encode %.0f ms, write %.0f ms; peak memory "
        "%.0f MB\n",
        readMs, s.prepareMs, s.simplifyMs, s.encodeMs, s.writeMs, peakMemoryMB());
    return 0;
  };
}

}  // namespace tetstream::cli
