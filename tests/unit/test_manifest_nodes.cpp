// Manifest version 2: the node hierarchy (FORMAT.md §1.1) written and parsed back, version 1
// still read, and every hostile node list refused with the key named.
#include <gtest/gtest.h>

#include <functional>
#include <nlohmann/json.hpp>

#include "manifest.h"

using namespace tetstream;
using json = nlohmann::json;

namespace {

// A base and four split chunks (5 vertices and 12 tets each) in a forest of four nodes:
// node 0 (chunk 1) with children 1 (chunk 2) and 2 (chunk 3); node 3 (chunk 4), another root.
Manifest tree() {
  Manifest m;
  m.name = "tree";
  m.bounds = {{0, 0, 0}, {4, 2, 2}};
  m.fields = {{"f", {-1, 1}}, {"g", {0, 10}}};
  m.isoField = "f";
  uint32_t v = 10, t = 20;
  for (uint32_t c = 0; c < 5; ++c) {
    ChunkInfo ci;
    ci.file = "chunks/0000" + std::to_string(c) + "-0123456789abcdef.tsc";
    ci.kind = c == 0 ? ChunkKind::Base : ChunkKind::Splits;
    ci.bytes = 100;
    ci.rawBytes = 200;
    ci.hash = 0x0123456789abcdefull + c;
    ci.splits = c == 0 ? 0 : 5;
    ci.vertices = v += ci.splits;
    ci.tets = t += c == 0 ? 0 : 12;
    ci.fieldError = 0.1 * (4 - c);
    m.chunks.push_back(ci);
  }
  m.vertices = v;
  m.tets = t;
  auto node = [&](int32_t parent, uint32_t chunk, Bounds b, Range f, Range g, double error) {
    NodeInfo n;
    n.parent = parent;
    n.firstChunk = chunk;
    n.chunkCount = 1;
    n.vertexBegin = m.chunks[chunk - 1].vertices;
    n.vertexEnd = m.chunks[chunk].vertices;
    n.tetBegin = m.chunks[chunk - 1].tets;
    n.tetEnd = m.chunks[chunk].tets;
    n.bounds = b;
    n.ranges = {f, g};
    n.fieldError = error;
    m.nodes.push_back(n);
  };
  node(-1, 1, {{0, 0, 0}, {2, 2, 2}}, {-1, 0.5f}, {0, 6}, 0.25);
  node(0, 2, {{0, 0, 0}, {1, 2, 2}}, {-1, 0}, {1, 6}, 0.125);
  node(0, 3, {{1, 0, 0}, {2, 2, 2}}, {-0.5f, 0.5f}, {0, 3}, 0);
  node(-1, 4, {{2, 0, 0}, {4, 2, 2}}, {0, 1}, {2, 10}, 0.5);
  m.nodes[0].fieldRms = 0.05;
  m.nodes[0].fieldMax = 0.1;
  return m;
}

json treeJson() { return json::parse(writeManifest(tree())); }

Result parse(const json& doc) {
  Manifest m;
  return parseManifest(doc.dump(), m);
}

}  // namespace

TEST(ManifestNodes, TreeRoundTrips) {
  const std::string text = writeManifest(tree());
  Manifest m;
  Result r = parseManifest(text, m);
  ASSERT_TRUE(r) << r.message;
  EXPECT_EQ(writeManifest(m), text);
  EXPECT_EQ(m.formatVersion, 2u);
  ASSERT_EQ(m.nodes.size(), 4u);
  EXPECT_EQ(m.nodes[0].parent, -1);
  EXPECT_EQ(m.nodes[2].parent, 0);
  EXPECT_EQ(m.nodes[3].parent, -1);
  EXPECT_EQ(m.nodes[2].firstChunk, 3u);
  EXPECT_EQ(m.nodes[2].chunkCount, 1u);
  EXPECT_EQ(m.nodes[2].vertexBegin, 20u);
  EXPECT_EQ(m.nodes[2].vertexEnd, 25u);
  EXPECT_EQ(m.nodes[2].tetBegin, 44u);
  EXPECT_EQ(m.nodes[2].tetEnd, 56u);
  EXPECT_EQ(m.nodes[1].bounds.max[0], 1.0f);
  ASSERT_EQ(m.nodes[2].ranges.size(), 2u);
  EXPECT_EQ(m.nodes[2].ranges[0].min, -0.5f);
  EXPECT_EQ(m.nodes[2].ranges[1].max, 3.0f);
  EXPECT_EQ(m.nodes[1].fieldError, 0.125);
  EXPECT_EQ(m.nodes[0].fieldRms, 0.05);
  EXPECT_EQ(m.nodes[0].fieldMax, 0.1);
  // Measured errors are optional, as for chunks: absent is -1 and is not written.
  EXPECT_EQ(m.nodes[1].fieldRms, -1.0);
  EXPECT_FALSE(treeJson()["nodes"][1].contains("fieldRms"));
}

TEST(ManifestNodes, OneNodeMayHoldSeveralChunks) {
  Manifest m = tree();
  m.nodes.resize(2);
  m.nodes[1].chunkCount = 3;
  m.nodes[1].vertexEnd = m.vertices;
  m.nodes[1].tetEnd = m.tets;
  m.nodes[1].bounds.max[0] = 2;
  Manifest back;
  Result r = parseManifest(writeManifest(m), back);
  ASSERT_TRUE(r) << r.message;
  EXPECT_EQ(back.nodes[1].chunkCount, 3u);
}

TEST(ManifestNodes, NoNodesIsOneSequence) {
  Manifest m = tree();
  m.nodes.clear();
  const std::string text = writeManifest(m);
  EXPECT_TRUE(json::parse(text)["nodes"].is_array()) << "version 2 always writes the key";
  Manifest back;
  ASSERT_TRUE(parseManifest(text, back));
  EXPECT_TRUE(back.nodes.empty());
  EXPECT_EQ(writeManifest(back), text);
}

TEST(ManifestNodes, VersionOneStillReads) {
  Manifest m = tree();
  m.formatVersion = 1;
  m.nodes.clear();
  const std::string text = writeManifest(m);
  EXPECT_EQ(text.find("nodes"), std::string::npos);
  Manifest back;
  ASSERT_TRUE(parseManifest(text, back));
  EXPECT_EQ(back.formatVersion, 1u);
  EXPECT_EQ(writeManifest(back), text);
  // In version 1 `nodes` is an unknown key, so ignored whatever it holds.
  json doc = json::parse(text);
  doc["nodes"] = "anything";
  ASSERT_TRUE(parseManifest(doc.dump(), back));
  EXPECT_TRUE(back.nodes.empty());
}

TEST(ManifestNodes, OtherVersionsAreRefused) {
  for (json v : {json(0), json(3), json(-1), json("2"), json(2.0), json(4294967298u)}) {
    json doc = treeJson();
    doc["formatVersion"] = v;
    Result r = parse(doc);
    EXPECT_EQ(r.status, Status::UnsupportedVersion) << v.dump();
    EXPECT_NE(r.message.find("reads versions 1 and 2"), std::string::npos) << r.message;
  }
}

// Each case breaks one rule of FORMAT.md §1.1; the message must name the key.
TEST(ManifestNodes, HostileNodesAreRefusedWithTheKeyNamed) {
  struct Case {
    const char* key;
    std::function<void(json&)> edit;
  };
  const Case cases[] = {
      {"'nodes'", [](json& d) { d.erase("nodes"); }},
      {"'nodes'",
       [](json& d) {
         d["nodes"] = {{"parent", -1}};
       }},
      {"'nodes'", [](json& d) { d["nodes"].push_back(d["nodes"][3]); }},  // more nodes than split chunks
      {"'nodes[1]'", [](json& d) { d["nodes"][1] = 5; }},
      // Parents: -1 or an earlier node, so no cycle and parents first.
      {"'nodes[1].parent'", [](json& d) { d["nodes"][1]["parent"] = 1; }},
      {"'nodes[1].parent'", [](json& d) { d["nodes"][1]["parent"] = 2; }},
      {"'nodes[0].parent'", [](json& d) { d["nodes"][0]["parent"] = 1; }},  // 0 -> 1 -> 0
      {"'nodes[1].parent'", [](json& d) { d["nodes"][1]["parent"] = -2; }},
      {"'nodes[1].parent'", [](json& d) { d["nodes"][1]["parent"] = 18446744073709551615u; }},
      {"'nodes[1].parent'", [](json& d) { d["nodes"][1]["parent"] = 0.5; }},
      {"'nodes[1].parent'", [](json& d) { d["nodes"][1]["parent"] = "0"; }},
      {"'nodes[1].parent'", [](json& d) { d["nodes"][1].erase("parent"); }},
      // Chunks: consecutive, non-empty, covering every split chunk once.
      {"'nodes[1].chunks'",
       [](json& d) {
         d["nodes"][1]["chunks"] = {2, 0};
       }},
      {"'nodes[1].chunks'",
       [](json& d) {
         d["nodes"][1]["chunks"] = {1, 1};
       }},                   // overlaps node 0
      {"'nodes[1].chunks'",  // node 0 takes chunk 2 too: node 1 overlaps it
       [](json& d) {
         json& n = d["nodes"][0];
         n["chunks"] = {1, 2};
         n["vertices"] = {10, 20};
         n["tets"] = {20, 44};
       }},
      {"'nodes[2].chunks'",
       [](json& d) {
         d["nodes"][2]["chunks"] = {4, 1};
       }},  // leaves chunk 3 out
      {"'nodes[0].chunks'",
       [](json& d) {
         d["nodes"][0]["chunks"] = {0, 1};
       }},                                                          // the base is no node's
      {"'nodes[2].chunks'", [](json& d) { d["nodes"].erase(3); }},  // chunk 4 in no node
      {"'nodes[3].chunks'",
       [](json& d) {
         d["nodes"][3]["chunks"] = {4, 2};
       }},
      {"'nodes[3].chunks'",
       [](json& d) {
         d["nodes"][3]["chunks"] = {4, 4294967295u};
       }},
      {"'nodes[3].chunks'",
       [](json& d) {
         d["nodes"][3]["chunks"] = {4294967295u, 1};
       }},
      {"'nodes[0].chunks'",
       [](json& d) {
         d["nodes"][0]["chunks"] = {-1, 1};
       }},
      {"'nodes[0].chunks'", [](json& d) { d["nodes"][0]["chunks"] = {1}; }},
      {"'nodes[0].chunks'",
       [](json& d) {
         d["nodes"][0]["chunks"] = {1.0, 1};
       }},
      {"'nodes[0].chunks'", [](json& d) { d["nodes"][0]["chunks"] = "1"; }},
      // Stable ids must agree with the chunks' counts.
      {"'nodes[1].vertices'",
       [](json& d) {
         d["nodes"][1]["vertices"] = {15, 21};
       }},
      {"'nodes[1].vertices'",
       [](json& d) {
         d["nodes"][1]["vertices"] = {14, 20};
       }},
      {"'nodes[1].vertices'",
       [](json& d) {
         d["nodes"][1]["vertices"] = {15, 99999999999};
       }},
      {"'nodes[1].vertices'",
       [](json& d) {
         d["nodes"][1]["vertices"] = {20, 15};
       }},
      {"'nodes[2].tets'",
       [](json& d) {
         d["nodes"][2]["tets"] = {44, 57};
       }},
      {"'nodes[2].tets'",
       [](json& d) {
         d["nodes"][2]["tets"] = {32, 56};
       }},
      {"'nodes[2].tets'", [](json& d) { d["nodes"][2].erase("tets"); }},
      // Ranges: one finite [min, max] per field, nested in the field's and the parent's.
      {"'nodes[1].ranges'", [](json& d) { d["nodes"][1]["ranges"].erase(1); }},
      {"'nodes[1].ranges'",
       [](json& d) {
         d["nodes"][1]["ranges"].push_back({0, 1});
       }},
      {"'nodes[1].ranges'",
       [](json& d) {
         d["nodes"][1]["ranges"] = {{"f", {0, 1}}};
       }},
      {"'nodes[2].ranges'", [](json& d) { d["nodes"][2].erase("ranges"); }},
      {"'nodes[1].ranges[0]'",
       [](json& d) {
         d["nodes"][1]["ranges"][0] = {-1, 0, 1};
       }},
      {"'nodes[1].ranges[1]'",
       [](json& d) {
         d["nodes"][1]["ranges"][1] = {5, 2};
       }},
      {"'nodes[1].ranges[0]'",
       [](json& d) {
         d["nodes"][1]["ranges"][0] = {-1, 0.75};
       }},  // parent's ends at 0.5
      {"'nodes[3].ranges[1]'",
       [](json& d) {
         d["nodes"][3]["ranges"][1] = {2, 11};
       }},  // field's ends at 10
      {"'nodes[3].ranges[0]'",
       [](json& d) {
         d["nodes"][3]["ranges"][0] = {0, 1e39};
       }},
      {"'nodes[3].ranges[0]'",
       [](json& d) {
         d["nodes"][3]["ranges"][0] = {nullptr, 1};
       }},  // NaN is written so
      {"'nodes[3].ranges[0]'",
       [](json& d) {
         d["nodes"][3]["ranges"][0] = {"0", 1};
       }},
      // Bounds: finite boxes nested in the top-level box and the parent's.
      {"'nodes[2].bounds'",
       [](json& d) {
         d["nodes"][2]["bounds"]["max"] = {2.5, 2, 2};
       }},
      {"'nodes[3].bounds'",
       [](json& d) {
         d["nodes"][3]["bounds"]["max"] = {5, 2, 2};
       }},
      {"'nodes[3].bounds.min'",
       [](json& d) {
         d["nodes"][3]["bounds"]["min"] = {3, 0, 3};
       }},
      {"'nodes[3].bounds.max'",
       [](json& d) {
         d["nodes"][3]["bounds"]["max"] = {1e39, 2, 2};
       }},
      {"'nodes[3].bounds.max'",
       [](json& d) {
         d["nodes"][3]["bounds"]["max"] = {4, 2};
       }},
      {"'nodes[0].bounds'", [](json& d) { d["nodes"][0].erase("bounds"); }},
      {"'nodes[0].bounds'", [](json& d) { d["nodes"][0]["bounds"] = "box"; }},
      // Errors: finite and not negative; the measured ones optional.
      {"'nodes[0].fieldError'", [](json& d) { d["nodes"][0]["fieldError"] = -0.5; }},
      {"'nodes[0].fieldError'", [](json& d) { d["nodes"][0]["fieldError"] = "x"; }},
      {"'nodes[0].fieldError'", [](json& d) { d["nodes"][0].erase("fieldError"); }},
      {"'nodes[0].fieldRms'", [](json& d) { d["nodes"][0]["fieldRms"] = -1; }},
      {"'nodes[0].fieldMax'", [](json& d) { d["nodes"][0]["fieldMax"] = nullptr; }},
  };
  ASSERT_TRUE(parse(treeJson()));
  for (const Case& c : cases) {
    json doc = treeJson();
    c.edit(doc);
    Result r = parse(doc);
    EXPECT_EQ(r.status, Status::BadManifest) << c.key << ": " << r.message;
    EXPECT_NE(r.message.find(c.key), std::string::npos) << "expected " << c.key << " in: " << r.message;
  }
}

// Values past float range would be stored as infinities; refused like any non-finite number.
TEST(ManifestNodes, NumbersBeyondFloatAreRefused) {
  json doc = treeJson();
  doc["fields"][0]["max"] = 1e39;
  Result r = parse(doc);
  EXPECT_NE(r.message.find("'fields[0].min'"), std::string::npos) << r.message;
  doc = treeJson();
  doc["bounds"]["max"] = {1e39, 2, 2};
  r = parse(doc);
  EXPECT_NE(r.message.find("'bounds.max'"), std::string::npos) << r.message;
}
