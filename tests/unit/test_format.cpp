// Packed format: round trip through files, determinism, and hostile manifests and chunks.
#include <gtest/gtest.h>
#include <zstd.h>

#include <filesystem>
#include <limits>

#include "chunk.h"
#include "dataset.h"
#include "hash.h"
#include "io/generators.h"
#include "pack/chunk_encode.h"
#include "pack/packer.h"
#include "test_helpers.h"

using namespace tetstream;

namespace {

std::string tempDir(const std::string& name) { return test::suiteDir("format", name); }
TetMesh harmonic(uint32_t n) { return test::harmonicMesh(n); }

// The whole mesh as one exact base chunk (no simplification, no quantization): the tests here
// are about the container; test_pack_roundtrip.cpp and test_split_stream.cpp cover the split stream.
PackOptions wholeMesh() {
  PackOptions o;
  o.baseFraction = 1.0;
  o.lossless = true;
  o.zstdLevel = 3;
  return o;
}

std::string packed(const std::string& name, const TetMesh& m, PackSummary* summary = nullptr) {
  std::string dir = tempDir(name);
  PackSummary s;
  Result r = packMesh(m, dir, wholeMesh(), s);
  EXPECT_TRUE(r) << r.message;
  if (summary) *summary = s;
  return dir;
}

}  // namespace

TEST(Format, PackThenLoadIsExact) {
  TetMesh m = harmonic(9);
  std::string dir = packed("roundtrip", m);
  Dataset ds;
  Result r = loadPackedDir(dir, ds);
  ASSERT_TRUE(r) << r.message;
  EXPECT_EQ(ds.pm.mesh.positions, m.positions);
  EXPECT_EQ(ds.pm.mesh.tets, m.tets);
  ASSERT_EQ(ds.pm.mesh.fields.size(), 2u);
  EXPECT_EQ(ds.pm.mesh.fields[0].name, "harmonic");
  EXPECT_EQ(ds.pm.mesh.fields[0].values, m.fields[0].values);
  EXPECT_EQ(ds.pm.mesh.fields[1].values, m.fields[1].values);
  EXPECT_EQ(ds.manifest.isoField, "harmonic");
  EXPECT_EQ(ds.chunksApplied(), 1u);
}

TEST(Format, PackOrientsTetsPositively) {
  TetMesh m = harmonic(5);
  for (uint32_t t = 0; t < m.tetCount(); t += 2) std::swap(m.tets[4 * t + 1], m.tets[4 * t + 2]);
  PackSummary s;
  std::string dir = packed("orient", m, &s);
  EXPECT_EQ(s.flippedTets, (m.tetCount() + 1) / 2);
  Dataset ds;
  ASSERT_TRUE(loadPackedDir(dir, ds));
  for (uint32_t t = 0; t < ds.pm.mesh.tetCount(); ++t) EXPECT_GT(tetVolume(ds.pm.mesh, t), 0);
}

TEST(Format, PackRaisesThePositionGridForTetsTooSmallForIt) {
  // A unit tet and one 4e-6 across: the 16-bit grid (steps of 1.5e-5) would flatten the small
  // one, the 20-bit grid (9.5e-7) keeps it.
  TetMesh m;
  const float corner[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (float scale : {1.0f, 4e-6f})
    for (const auto& c : corner)
      for (int k = 0; k < 3; ++k) m.positions.push_back((scale < 1 ? 0.5f : 0.0f) + scale * c[k]);
  m.tets = {0, 1, 2, 3, 4, 5, 6, 7};
  m.fields.push_back({"f", {0, 1, 2, 3, 4, 5, 6, 7}});
  PackOptions o = wholeMesh();
  o.lossless = false;
  PackSummary s;
  const std::string dir = tempDir("grid");
  ASSERT_TRUE(packMesh(m, dir, o, s));
  EXPECT_EQ(s.manifest.positionBits, 20);
  EXPECT_FALSE(s.manifest.lossless);
  bool noted = false;
  for (const std::string& n : s.notes) noted |= n.find("too small for a 16-bit position grid") != std::string::npos;
  EXPECT_TRUE(noted);
  Dataset ds;
  ASSERT_TRUE(loadPackedDir(dir, ds));
  ASSERT_EQ(ds.pm.mesh.tetCount(), 2u);
  for (uint32_t t = 0; t < 2; ++t) EXPECT_GT(tetVolume(ds.pm.mesh, t), 0);
  for (size_t k = 0; k < m.positions.size(); ++k) EXPECT_NEAR(ds.pm.mesh.positions[k], m.positions[k], 1e-6);
}

TEST(Format, PackIsDeterministic) {
  TetMesh m = harmonic(7);
  std::string a = packed("det-a", m), b = packed("det-b", m);
  EXPECT_EQ(test::loadFile(a + "/manifest.json"), test::loadFile(b + "/manifest.json"));
  Dataset ds;
  ASSERT_TRUE(loadPackedDir(a, ds));
  const std::string f = ds.manifest.chunks[0].file;
  EXPECT_EQ(test::loadBytes(a + "/" + f), test::loadBytes(b + "/" + f));
}

TEST(Format, RepackReplacesStaleChunks) {
  std::string dir = tempDir("repack");
  PackSummary s;
  ASSERT_TRUE(packMesh(harmonic(5), dir, wholeMesh(), s));
  ASSERT_TRUE(packMesh(harmonic(6), dir, wholeMesh(), s));
  int files = 0;
  for (auto& e : std::filesystem::directory_iterator(dir + "/chunks")) files += e.path().extension() == ".tsc";
  EXPECT_EQ(files, 1);
}

TEST(Format, PackRefusesUnusableMeshes) {
  PackSummary s;
  TetMesh noField = makeGridMesh(3);
  EXPECT_EQ(packMesh(noField, tempDir("nofield"), {}, s).status, Status::MissingField);
  TetMesh m = harmonic(3);
  PackOptions o;
  o.field = "nope";
  Result r = packMesh(m, tempDir("badfield"), o, s);
  EXPECT_EQ(r.status, Status::MissingField);
  EXPECT_NE(r.message.find("harmonic"), std::string::npos) << "the message lists the fields";
  TetMesh bad = harmonic(3);
  bad.tets[5] = 1000;
  EXPECT_EQ(packMesh(bad, tempDir("badidx"), {}, s).status, Status::OutOfRange);
  // Too big for the memory allowed: refused before any work, with the figures.
  PackOptions small;
  small.maxMemoryBytes = 1000;
  r = packMesh(harmonic(3), tempDir("toobig"), small, s);
  EXPECT_EQ(r.status, Status::TooLarge);
  EXPECT_NE(r.message.find("--max-memory"), std::string::npos) << r.message;
}

TEST(Format, ManifestRoundTrip) {
  PackSummary s;
  std::string dir = packed("manifest", harmonic(4), &s);
  Manifest m;
  ASSERT_TRUE(parseManifest(writeManifest(s.manifest), m));
  EXPECT_EQ(writeManifest(m), writeManifest(s.manifest));
  EXPECT_GE(m.chunks[0].fieldRms, 0.0);
  // Manifests written before the measured errors still load: -1 (not given).
  Manifest older = s.manifest, back;
  for (ChunkInfo& c : older.chunks) c.fieldRms = c.fieldMax = -1;
  const std::string text = writeManifest(older);
  EXPECT_EQ(text.find("fieldRms"), std::string::npos);
  ASSERT_TRUE(parseManifest(text, back));
  EXPECT_EQ(back.chunks[0].fieldRms, -1.0);
  EXPECT_EQ(back.chunks[0].fieldMax, -1.0);
}

TEST(Format, HashFormat) {
  uint64_t h = 0;
  EXPECT_TRUE(parseHash(formatHash(0x0123456789abcdefull), &h));
  EXPECT_EQ(h, 0x0123456789abcdefull);
  EXPECT_FALSE(parseHash("xxh3-64:0123", &h));
  EXPECT_FALSE(parseHash("md5:0123456789abcdef", &h));
  EXPECT_FALSE(parseHash("xxh3-64:0123456789abcdeg", &h));
}

// Each hostile manifest is refused with a message, never a crash.
TEST(Format, HostileManifestsAreRefused) {
  PackSummary s;
  packed("hostile", harmonic(4), &s);
  const std::string good = writeManifest(s.manifest);
  auto with = [&](const std::string& from, const std::string& to) {
    std::string t = good;
    size_t at = t.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return t.replace(at, from.size(), to);
  };
  std::vector<std::string> cases = {
      "",
      "not json",
      "[]",
      "{}",
      std::string(100000, '['),
      with("\"formatVersion\": 2", "\"formatVersion\": 3"),
      with("\"formatVersion\": 2", "\"formatVersion\": \"2\""),
      with("\"format\": \"tetstream\"", "\"format\": \"other\""),
      with("\"vertices\": 64", "\"vertices\": -1"),
      with("\"vertices\": 64", "\"vertices\": 99999999999"),
      with("\"tets\": 162", "\"tets\": 1.5"),
      with("\"file\": \"chunks/", "\"file\": \"../../etc/"),
      with("\"file\": \"chunks/", "\"file\": \"chunks/../"),
      with("\"file\": \"chunks/", "\"file\": \"/chunks/"),
      with("\"hash\": \"xxh3-64:", "\"hash\": \"xxh3-64:zz"),
      with("\"kind\": \"base\"", "\"kind\": \"splits\""),
      with("\"name\": \"harmonic\"", "\"name\": 7"),
      with("\"chunks\": [", "\"chunks\": 5, \"x\": ["),
      with("\"min\": [", "\"min\": [1e39, "),
      with("\"fieldRms\": ", "\"fieldRms\": -1, \"z\": "),
      with("\"fieldMax\": ", "\"fieldMax\": \"x\", \"y\": "),
  };
  for (const std::string& c : cases) {
    Manifest m;
    Result r = parseManifest(c, m);
    EXPECT_FALSE(r.ok()) << "accepted: " << c.substr(0, 200);
    EXPECT_FALSE(r.message.empty());
  }
  // A small chunk that claims to inflate to a gigabyte: refused before any buffer is sized.
  Manifest inflated = s.manifest;
  inflated.chunks[0].rawBytes = 1000000000;
  Manifest m;
  Result r = parseManifest(writeManifest(inflated), m);
  EXPECT_FALSE(r.ok());
  EXPECT_NE(r.message.find("rawBytes"), std::string::npos) << r.message;
}

TEST(Format, CorruptTruncatedAndWrongChunksAreNeverApplied) {
  std::string dir = packed("corrupt", harmonic(6));
  Dataset ds;
  ASSERT_TRUE(loadPackedDir(dir, ds, 0));
  const ChunkInfo info = ds.manifest.chunks[0];
  std::vector<uint8_t> good = test::loadBytes(dir + "/" + info.file);

  std::vector<uint8_t> flipped = good;
  flipped[flipped.size() / 2] ^= 0x10;
  EXPECT_EQ(applyChunk(ds, 0, flipped).status, Status::HashMismatch);
  for (size_t len : {size_t(0), size_t(1), good.size() / 2, good.size() - 1})
    EXPECT_EQ(applyChunk(ds, 0, std::span(good.data(), len)).status, Status::SizeMismatch);
  EXPECT_EQ(applyChunk(ds, 1, good).status, Status::BadArgument) << "out of order";
  EXPECT_EQ(ds.chunksApplied(), 0u);
  EXPECT_EQ(ds.pm.mesh.tetCount(), 0u) << "nothing applied";
  Result ok = applyChunk(ds, 0, good);
  EXPECT_TRUE(ok) << ok.message;
}

// A chunk whose hash matches (the attacker controls the manifest too) but whose content lies.
TEST(Format, ConsistentlyHashedButInvalidPayloadsAreRefused) {
  TetMesh m = harmonic(4);
  std::string dir = packed("lying", m);
  Dataset ds;
  ASSERT_TRUE(loadPackedDir(dir, ds, 0));
  auto tryMesh = [&](const TetMesh& bad, Status expect) {
    std::vector<uint8_t> file;
    ChunkInfo info;
    ASSERT_TRUE(encodeBaseChunk(bad, 0, 3, file, info));
    Dataset d;
    ASSERT_TRUE(openDataset(d, test::loadFile(dir + "/manifest.json")));
    d.manifest.chunks[0].bytes = info.bytes;
    d.manifest.chunks[0].rawBytes = info.rawBytes;
    d.manifest.chunks[0].hash = info.hash;
    Result r = applyChunk(d, 0, file);
    EXPECT_EQ(r.status, expect) << r.message;
    EXPECT_EQ(d.pm.mesh.tetCount(), 0u);
  };
  TetMesh outOfRange = m;
  outOfRange.tets[7] = 5000;
  tryMesh(outOfRange, Status::OutOfRange);
  TetMesh repeated = m;
  repeated.tets[1] = repeated.tets[0];
  tryMesh(repeated, Status::Corrupt);
  TetMesh nan = m;
  nan.positions[5] = std::numeric_limits<float>::quiet_NaN();
  tryMesh(nan, Status::NonFinite);
  TetMesh fewer = m;
  fewer.tets.resize(fewer.tets.size() - 4);
  tryMesh(fewer, Status::Corrupt);
  TetMesh moreFields = m;
  moreFields.fields.push_back({"extra", std::vector<float>(m.vertexCount())});
  tryMesh(moreFields, Status::Corrupt);
}

TEST(Format, SplitChunksAreRefusedByThisVersion) {
  // Until vertex splits exist, a manifest that lists them must fail at that chunk, keeping the
  // base mesh usable.
  PackSummary s;
  std::string dir = packed("splits", harmonic(4), &s);
  Manifest m = s.manifest;
  ChunkInfo extra = m.chunks[0];
  extra.kind = ChunkKind::Splits;
  extra.file = "chunks/00001-0000000000000000.tsc";
  m.chunks.push_back(extra);
  Dataset ds;
  ASSERT_TRUE(openDataset(ds, writeManifest(m)));
  std::vector<uint8_t> base = test::loadBytes(dir + "/" + m.chunks[0].file);
  ASSERT_TRUE(applyChunk(ds, 0, base));
  EXPECT_FALSE(applyChunk(ds, 1, base).ok());
  EXPECT_EQ(ds.chunksApplied(), 1u);
  EXPECT_GT(ds.pm.mesh.tetCount(), 0u);
}
