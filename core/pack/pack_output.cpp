#include "pack/pack_output.h"

#include <zlib.h>

#include <cstdio>
#include <filesystem>

#include "io/file_writer.h"

namespace tetstream {
namespace fs = std::filesystem;
namespace {

// `text` as a gzip file (deflate at level 9 in a gzip wrapper).
Result writeGzipped(const std::string& path, const std::string& text) {
  z_stream z{};
  if (deflateInit2(&z, 9, Z_DEFLATED, 15 + 16, 9, Z_DEFAULT_STRATEGY) != Z_OK)
    return fail(Status::IoError, path + ": cannot start gzip");
  std::vector<uint8_t> out(deflateBound(&z, uLong(text.size())) + 32);
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(text.data()));
  z.avail_in = uInt(text.size());
  z.next_out = out.data();
  z.avail_out = uInt(out.size());
  const int done = deflate(&z, Z_FINISH);
  out.resize(z.total_out);
  deflateEnd(&z);
  if (done != Z_STREAM_END) return fail(Status::IoError, path + ": gzip failed");
  return writeWholeFile(path, out.data(), out.size());
}

}  // namespace

std::string chunkFileName(uint32_t index, uint64_t hash) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "chunks/%05u-%016llx.tsc", index, static_cast<unsigned long long>(hash));
  return buf;
}

Result writeWholeFile(const std::string& path, const void* data, size_t size) {
  FileWriter out(path);
  out.write(data, size);
  return out.commit();
}

Result writeManifestFiles(const std::string& outDir, const Manifest& m) {
  // Checked before anything in the folder changes: an earlier pack there stays readable.
  if (m.chunks.size() > kManifestMaxChunks)
    return fail(Status::TooLarge, "the pack has " + std::to_string(m.chunks.size()) + " chunks, more than the " +
                                      std::to_string(kManifestMaxChunks) +
                                      " a reader takes: use larger --chunk-kb or --leaf-vertices");
  const std::string json = writeManifest(m);
  if (json.size() > kManifestLimitBytes)
    return fail(Status::TooLarge, "the pack's manifest would be " + std::to_string(json.size() >> 20) +
                                      " MiB, more than the 64 MiB a reader takes: use larger --leaf-vertices");
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(fs::path(outDir) / "chunks", ec)) {
    std::string rel = "chunks/" + entry.path().filename().string();
    bool ours = entry.path().extension() == ".tsc";
    bool referenced = false;
    for (const ChunkInfo& c : m.chunks) referenced |= c.file == rel;
    if (ours && !referenced) fs::remove(entry.path(), ec);
  }
  Result r = writeWholeFile((fs::path(outDir) / "manifest.json").string(), json.data(), json.size());
  // The manifest gzipped beside it, written after it (so it is never the older of the two, which
  // servers take as stale): a large hierarchy's manifest is megabytes of JSON, fetched before
  // anything else, and compresses about six times (server/README.md: precompressed siblings).
  if (r) r = writeGzipped((fs::path(outDir) / "manifest.json.gz").string(), json);
  fs::remove(fs::path(outDir) / "manifest.json.br", ec);  // (one from an earlier pack would be stale)
  return r;
}

}  // namespace tetstream
