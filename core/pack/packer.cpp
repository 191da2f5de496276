#include "packer.h"

#include <cstdio>
#include <filesystem>
#include <utility>

#include "chunk_encode.h"
#include "validate.h"

namespace tetstream {
namespace fs = std::filesystem;
namespace {

Result writeFile(const fs::path& path, const void* data, size_t size) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) return fail(Status::IoError, path.string() + ": cannot create");
  bool ok = std::fwrite(data, 1, size, f) == size;
  ok = std::fclose(f) == 0 && ok;
  if (!ok) return fail(Status::IoError, path.string() + ": write failed (disk full?)");
  return Result::success();
}

std::string chunkFileName(uint32_t index, uint64_t hash) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "chunks/%05u-%016llx.tsc", index, static_cast<unsigned long long>(hash));
  return buf;
}

}  // namespace

Result packMesh(TetMesh mesh, const std::string& outDir, const PackOptions& opt, PackSummary& summary) {
  summary = PackSummary{};
  ValidationReport report = validateMesh(mesh);
  if (report.fatal()) {
    std::string why;
    for (const std::string& f : report.findings) why += (why.empty() ? "" : "; ") + f;
    Status s = report.noTets ? Status::NoTets : report.outOfRangeIndices ? Status::OutOfRange
             : report.nonFinitePositions ? Status::NonFinite : Status::Corrupt;
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
  for (uint32_t t = 0; t < mesh.tetCount(); ++t)
    if (tetVolume(mesh, t) < 0) {
      std::swap(mesh.tets[4 * size_t(t) + 2], mesh.tets[4 * size_t(t) + 3]);
      ++summary.flippedTets;
    }
  if (summary.flippedTets)
    summary.notes.push_back("re-oriented " + std::to_string(summary.flippedTets) + " negatively oriented tetrahedra");

  Manifest& m = summary.manifest;
  m.generator = std::string("tetstream ") + kLibraryVersion;
  m.name = opt.name.empty() ? mesh.name : opt.name;
  if (m.name.empty()) m.name = "dataset";
  m.bounds = computeBounds(mesh.positions);
  m.vertices = mesh.vertexCount();
  m.tets = mesh.tetCount();
  for (const ScalarField& f : mesh.fields) m.fields.push_back({f.name, computeRange(f.values)});
  m.isoField = mesh.fields[size_t(iso)].name;

  std::error_code ec;
  fs::create_directories(fs::path(outDir) / "chunks", ec);
  if (ec) return fail(Status::IoError, outDir + ": cannot create folder: " + ec.message());

  std::vector<uint8_t> file;
  ChunkInfo base;
  if (Result r = encodeBaseChunk(mesh, 0, opt.zstdLevel, file, base); !r) return r;
  base.file = chunkFileName(0, base.hash);
  if (Result r = writeFile(fs::path(outDir) / base.file, file.data(), file.size()); !r) return r;
  m.chunks.push_back(base);

  // Remove chunk files an earlier pack left behind (only our own *.tsc names).
  for (const auto& entry : fs::directory_iterator(fs::path(outDir) / "chunks", ec)) {
    std::string rel = "chunks/" + entry.path().filename().string();
    bool ours = entry.path().extension() == ".tsc";
    bool referenced = false;
    for (const ChunkInfo& c : m.chunks) referenced |= c.file == rel;
    if (ours && !referenced) fs::remove(entry.path(), ec);
  }

  std::string json = writeManifest(m);
  fs::path tmp = fs::path(outDir) / "manifest.json.tmp";
  if (Result r = writeFile(tmp, json.data(), json.size()); !r) return r;
  fs::rename(tmp, fs::path(outDir) / "manifest.json", ec);
  if (ec) return fail(Status::IoError, outDir + "/manifest.json: " + ec.message());
  return Result::success();
}

}  // namespace tetstream
