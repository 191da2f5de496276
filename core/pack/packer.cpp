#include "packer.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <utility>

#include "chunk_encode.h"
#include "io/file_writer.h"
#include "pack/pack_output.h"
#include "pack/renumber.h"
#include "pack/simplify.h"
#include "pack/split_encode.h"
#include "quantize.h"
#include "validate.h"

namespace tetstream {
namespace fs = std::filesystem;
namespace {

double msSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// The positions snapped to the quantization grid of `m` (FORMAT.md §4), into `snapped`. Returns
// the number of tets that the snapping flattens or turns over (0 means this grid is safe).
// (Into a copy of the positions only: copying the whole mesh and keeping every tet's volume
// costs more than the snapping.)
uint64_t snapPositions(const TetMesh& mesh, const Manifest& m, std::vector<float>& snapped) {
  const Quantizer q = makeQuantizer(m);
  snapped.resize(mesh.positions.size());
  for (size_t k = 0; k < snapped.size(); ++k) snapped[k] = q.position[k % 3].snap(mesh.positions[k]);
  uint64_t broken = 0;
  for (uint32_t t = 0; t < mesh.tetCount(); ++t) {
    const uint32_t* v = &mesh.tets[4 * size_t(t)];
    auto volume = [v](const std::vector<float>& p) {
      return tetVolume(&p[3 * size_t(v[0])], &p[3 * size_t(v[1])], &p[3 * size_t(v[2])], &p[3 * size_t(v[3])]);
    };
    broken += volume(mesh.positions) > 0 && !(volume(snapped) > 0);
  }
  return broken;
}

// Snaps the fields to the grid of `m`.
void snapFields(TetMesh& mesh, const Manifest& m) {
  const Quantizer q = makeQuantizer(m);
  for (size_t f = 0; f < mesh.fields.size(); ++f)
    for (float& x : mesh.fields[f].values) x = q.field[f].snap(x);
}

}  // namespace

// Packing needs about kPackBytesPerTet per input tet at its peak (the measured peaks of the
// benchmark meshes, huge pages included, with a margin). A mesh that would need more than the
// limit is refused up front with the figure, rather than failing an allocation halfway through
// a long run.
constexpr double kPackBytesPerTet = 200;

Result checkMemoryFor(const TetMesh& mesh, const PackOptions& opt) {
  double limit = opt.maxMemoryBytes;
  const bool physical = !(limit > 0);
  if (physical) {
    const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
    limit = pages > 0 && page > 0 ? 0.9 * double(pages) * double(page) : 0;
  }
  const double need = kPackBytesPerTet * double(mesh.tetCount()) + 64.0 * mesh.vertexCount();
  if (limit > 0 && need > limit) {
    auto size = [](double bytes) {
      char t[32];
      std::snprintf(t, sizeof t, bytes >= 1e9 ? "%.1f GB" : "%.0f MB", bytes >= 1e9 ? bytes / 1e9 : bytes / 1e6);
      return std::string(t);
    };
    return fail(Status::TooLarge, "packing " + std::to_string(mesh.tetCount()) + " tetrahedra needs about " +
                                      size(need) + " of memory, more than the " + size(limit) + " allowed (" +
                                      (physical ? "90% of the physical memory; " : "") + "--max-memory)");
  }
  return Result::success();
}

uint32_t leafVerticesFor(uint64_t largestPart, uint32_t parts, const PackOptions& opt,
                         std::vector<std::string>& notes) {
  if (opt.leafVertices == 0 || opt.maxLeaves == 0) return opt.leafVertices;
  // Each part's tree halves its regions until each holds at most the leaf size
  // (simplify_tree.cpp): with ceil(largestPart / P), P a power of two, no part has more than P
  // leaves, and P · parts ≤ maxLeaves.
  uint64_t perPart = 1;
  while (2 * perPart * std::max(parts, 1u) <= opt.maxLeaves) perPart *= 2;
  const uint64_t least = (largestPart + perPart - 1) / perPart;
  if (least <= opt.leafVertices) return opt.leafVertices;
  const uint32_t leaf = uint32_t(std::min<uint64_t>(least, UINT32_MAX));
  notes.push_back("regions of up to " + std::to_string(leaf) + " vertices instead of " +
                  std::to_string(opt.leafVertices) + ": at most " + std::to_string(opt.maxLeaves) +
                  " leaf regions keep the manifest small enough to open at once");
  return leaf;
}

Result packMesh(TetMesh mesh, const std::string& outDir, const PackOptions& opt, PackSummary& summary) {
  summary = PackSummary{};
  const auto start = std::chrono::steady_clock::now();
  auto progress = [&](const char* phase, uint64_t done, uint64_t planned) {
    if (opt.progress) opt.progress(phase, done, planned);
  };
  if (Result r = checkMemoryFor(mesh, opt); !r) return r;
  progress("validate", 0, 0);
  // A numbering that scatters neighbours costs cache misses at every step from here on, the
  // validation's included (renumber.h): such meshes are renumbered first (the stream has its
  // own numbering), when their indices and positions are usable at all (the validation says
  // what is wrong with the others). (The spread is a sample, whatever the indices: the full
  // pass of renumberable() only follows for a scattered mesh.)
  const double spread = mesh.tetCount() >= opt.renumberMinTets ? numberingSpread(mesh) : 0.0;
  const bool renumber = spread > kScatteredNumbering && renumberable(mesh);
  if (renumber) renumberForLocality(mesh);
  FaceAdjacency adjacency;  // built by the validation, used again by the simplifier
  ValidationReport report = validateMesh(mesh, &adjacency);
  if (report.fatal()) {
    std::string why;
    for (const std::string& f : report.findings) why += (why.empty() ? "" : "; ") + f;
    Status s = report.noTets               ? Status::NoTets
               : report.outOfRangeIndices  ? Status::OutOfRange
               : report.nonFinitePositions ? Status::NonFinite
                                           : Status::Corrupt;
    return fail(s, "cannot pack this mesh: " + why);
  }
  if (mesh.fields.empty()) return fail(Status::MissingField, "the mesh has no point scalar field to show");
  int iso = opt.field.empty() ? 0 : mesh.findField(opt.field);
  if (iso < 0) {
    std::string names;
    for (const ScalarField& f : mesh.fields) names += (names.empty() ? "" : ", ") + f.name;
    return fail(Status::MissingField, "no field named '" + opt.field + "' (fields: " + names + ")");
  }
  for (const std::string& f : report.findings) summary.notes.push_back("input: " + f);

  // FORMAT.md §3 wants positively oriented tets: flip the others (an odd permutation).
  // (Swapping slots 2 and 3 swaps the faces opposite them: the adjacency follows.)
  // (Only when the validation saw any: every tet's volume again is a pass over the whole mesh.)
  std::vector<uint32_t>& opp = adjacency.opposite;
  const bool turnAdjacency = opp.size() == mesh.tets.size();
  const bool anyToTurn = report.negativeTets > 0 || report.zeroVolumeTets > 0 || report.repeatedVertexTets > 0;
  for (uint32_t t = 0; anyToTurn && t < mesh.tetCount(); ++t)
    if (tetVolume(mesh, t) < 0) {
      std::swap(mesh.tets[4 * size_t(t) + 2], mesh.tets[4 * size_t(t) + 3]);
      ++summary.flippedTets;
      if (!turnAdjacency) continue;
      std::swap(opp[4 * size_t(t) + 2], opp[4 * size_t(t) + 3]);
      for (uint32_t h = 4 * t + 2; h <= 4 * t + 3; ++h)
        if (opp[h] != kNoNeighbor) opp[opp[h]] = h;
    }
  if (summary.flippedTets)
    summary.notes.push_back("re-oriented " + std::to_string(summary.flippedTets) + " negatively oriented tetrahedra");
  if (renumber) {
    char note[160];
    std::snprintf(note, sizeof note,
                  "renumbered vertices and tetrahedra for speed: the file's numbering scatters "
                  "neighbours (a tetrahedron's vertex ids span %.0f%% of them, median)",
                  100 * spread);
    summary.notes.push_back(note);
  }

  Manifest& m = summary.manifest;
  m.generator = std::string("tetstream ") + kLibraryVersion;
  m.name = opt.name.empty() ? mesh.name : opt.name;
  if (m.name.empty()) m.name = "dataset";
  m.bounds = computeBounds(mesh.positions);
  m.vertices = mesh.vertexCount();
  m.tets = mesh.tetCount();
  for (const ScalarField& f : mesh.fields) m.fields.push_back({f.name, computeRange(f.values)});
  m.isoField = mesh.fields[size_t(iso)].name;

  // Quantization grid: 16 bits unless the mesh has elements too small for it.
  m.lossless = opt.lossless || report.nonFiniteFieldValues > 0;
  if (report.nonFiniteFieldValues && !opt.lossless)
    summary.notes.push_back("fields contain NaN or infinite values: stored lossless (float32)");
  if (!m.lossless) {
    std::vector<float> snapped;
    for (int bits : {16, 20, 24}) {
      m.positionBits = bits;
      uint64_t broken = snapPositions(mesh, m, snapped);
      if (broken == 0) break;
      summary.notes.push_back(std::to_string(broken) + " tetrahedra are too small for a " + std::to_string(bits) +
                              "-bit position grid" + (bits < 24 ? ": trying more bits" : ": storing lossless"));
      if (bits == 24) m.lossless = true;
    }
    if (!m.lossless) {
      mesh.positions = std::move(snapped);
      snapFields(mesh, m);
    }
    m.positionBits = m.lossless ? 16 : m.positionBits;
  }

  // Simplify. Non-manifold or duplicated tets break the collapse's assumptions: keep them whole.
  SimplifyResult simplified;
  summary.prepareMs = msSince(start);
  auto t0 = std::chrono::steady_clock::now();
  SimplifyOptions so;
  so.weightGeometry = opt.weights[0];
  so.weightField = opt.weights[1];
  so.weightShape = opt.weights[2];
  so.threads = opt.threads;
  so.leafVertices = leafVerticesFor(mesh.vertexCount(), 1, opt, summary.notes);
  so.fitValues = opt.fitValues;
  so.field = iso;
  so.recordReadSets = opt.orderSplits;
  so.maxError = opt.maxError;
  so.targetTets = opt.baseTets;
  so.targetVertices = opt.baseVertices
                          ? opt.baseVertices
                          : uint32_t(std::llround(std::clamp(opt.baseFraction, 0.0, 1.0) * mesh.vertexCount()));
  // A fraction of a small mesh would leave a base too coarse to show anything: keep a floor.
  // And a cap: the base is what a viewer waits for before the first picture, so on a huge mesh
  // it stays a couple of MB (65,536 vertices: about 2 MB, under 2 s at 10 Mbit/s) rather than
  // growing with the mesh (1% of Harmonic 256³ is 6.4 MB); the detail comes with the nodes.
  if (!opt.baseVertices && opt.baseFraction > 0)
    so.targetVertices =
        std::max(std::min(so.targetVertices, opt.maxBaseVertices), std::min(opt.minBaseVertices, mesh.vertexCount()));
  if (report.nonManifoldFaces || report.duplicateTets) {
    summary.notes.push_back("non-manifold or duplicated tetrahedra: packed without simplification");
    so.targetVertices = mesh.vertexCount();
  }
  so.progress = [&](uint32_t done, uint32_t planned) { progress("simplify", done, planned); };
  progress("simplify", 0, 0);  // (its set-up, a sizeable share of its time, reports no collapses yet)
  if (Result r = simplifyMesh(mesh, so, simplified, &adjacency, &mesh.tets); !r) return r;  // (mesh.tets taken over)
  summary.simplifyMs = msSince(t0);
  summary.stopReason = simplified.stopReason;
  summary.flatTetsRemoved = simplified.flatTetsRemoved;
  summary.flatTetsLeft = simplified.flatTetsLeft;
  summary.queuePops = simplified.queuePops;
  summary.regionCollapses = simplified.regionCollapses;
  summary.requeued = simplified.requeued;
  summary.costEvaluations = simplified.costEvaluations;

  t0 = std::chrono::steady_clock::now();
  progress("encode", 0, simplified.log.size());
  StreamOptions stream;
  stream.chunkBytes = std::max<uint32_t>(opt.chunkKb, 1) << 10;
  stream.firstChunkBytes = std::min<uint32_t>(stream.chunkBytes, 16u << 10);
  stream.zstdLevel = opt.zstdLevel;
  stream.ringWalk = opt.ringWalk;
  stream.orderSplits = opt.orderSplits;
  stream.threads = opt.threads;
  stream.progress = [&](uint32_t done, uint32_t planned) { progress("encode", done, planned); };
  EncodedStream enc;
  if (Result r = encodeStream(mesh, simplified, m, stream, enc); !r) return r;
  const std::vector<uint8_t>& baseFile = enc.baseFile;
  ChunkInfo base = enc.baseInfo;
  summary.encodeMs = msSince(t0);
  // Vertices no tet uses are not part of any level: the stream drops them.
  m.vertices = enc.chunks.empty() ? enc.base.vertexCount() : enc.chunks.back().vertices;
  m.tets = enc.chunks.empty() ? enc.base.tetCount() : enc.chunks.back().tets;
  if (report.unusedVertices)
    summary.notes.push_back("dropped " + std::to_string(report.unusedVertices) + " vertices that no tetrahedron uses");
  summary.baseVertices = enc.base.vertexCount();
  summary.movedMasks = enc.movedMasks;
  summary.baseTets = enc.base.tetCount();
  summary.splits = simplified.log.size();
  // --max-error stops on the simplifier's per-collapse estimate; say so when the measured error
  // of the base came out above it.
  const Range range = m.fields[size_t(iso)].range;
  if (std::isfinite(opt.maxError) && base.fieldMax >= 0 && range.max > range.min &&
      base.fieldMax > opt.maxError * (range.max - range.min)) {
    char buf[256];
    std::snprintf(buf, sizeof buf,
                  "the base's largest field error measured at the input's vertices, %.3g of the range, "
                  "is above --max-error %.3g (the simplifier's estimate per collapse stayed within it)",
                  base.fieldMax / (range.max - range.min), opt.maxError);
    summary.notes.push_back(buf);
  }

  t0 = std::chrono::steady_clock::now();
  progress("write", 0, 0);
  std::error_code ec;
  fs::create_directories(fs::path(outDir) / "chunks", ec);
  if (ec) return fail(Status::IoError, outDir + ": cannot create folder: " + ec.message());
  base.file = chunkFileName(0, base.hash);
  if (Result r = writeWholeFile((fs::path(outDir) / base.file).string(), baseFile.data(), baseFile.size()); !r)
    return r;
  m.chunks.push_back(base);
  for (size_t c = 0; c < enc.files.size(); ++c) {
    ChunkInfo info = enc.chunks[c];
    info.file = chunkFileName(uint32_t(c + 1), info.hash);
    if (Result r = writeWholeFile((fs::path(outDir) / info.file).string(), enc.files[c].data(), enc.files[c].size());
        !r)
      return r;
    m.chunks.push_back(info);
  }
  // One region alone (a small mesh, --leaf-vertices 0) is no hierarchy: one sequence of chunks.
  if (enc.nodes.size() > 1) m.nodes = std::move(enc.nodes);

  Result r = writeManifestFiles(outDir, m);
  summary.writeMs = msSince(t0);
  return r;
}

}  // namespace tetstream
