#include "manifest.h"

#include <cassert>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <nlohmann/json.hpp>

#include "hash.h"

namespace tetstream {
namespace {

using json = nlohmann::json;

constexpr size_t kMaxManifestBytes = kManifestLimitBytes;
constexpr int kMaxDepth = 32;
constexpr size_t kMaxChunks = kManifestMaxChunks;
constexpr size_t kMaxFields = 64;
constexpr uint64_t kMaxChunkBytes = 256ull << 20;
constexpr uint64_t kMaxRawBytes = kMaxChunkRawBytes;
constexpr uint64_t kMaxCount = (1ull << 31) - 1;

// Where a character of JSON text stands: inside a string (its quotes included) or not. Both
// scans of raw text below (nesting, layout) must skip what strings hold.
struct StringTracker {
  bool inString = false, escaped = false;
  // True when c belongs to a string (an opening quote starts one).
  bool inside(char c) {
    if (!inString) return inString = c == '"';
    if (escaped)
      escaped = false;
    else if (c == '\\')
      escaped = true;
    else if (c == '"')
      inString = false;
    return true;
  }
};

// nlohmann's DOM destructor and our walk would recurse on absurd nesting; refuse it up front.
bool nestingWithin(std::string_view s, int limit) {
  int depth = 0;
  StringTracker text;
  for (char c : s) {
    if (text.inside(c)) continue;
    if (c == '{' || c == '[') {
      if (++depth > limit) return false;
    } else if (c == '}' || c == ']')
      --depth;
  }
  return true;
}

// Typed getters: the manifest is untrusted, so every access checks type and range and the
// first problem is reported with the key's path.
struct Reader {
  std::string error;

  const json* member(const json& obj, const char* key, const std::string& path) {
    if (!error.empty()) return nullptr;
    auto it = obj.find(key);
    if (it == obj.end()) {
      error = "missing key '" + path + key + "'";
      return nullptr;
    }
    return &*it;
  }
  bool string(const json& obj, const char* key, const std::string& path, std::string& out) {
    const json* v = member(obj, key, path);
    if (!v) return false;
    if (!v->is_string()) {
      error = "'" + path + key + "' must be a string";
      return false;
    }
    out = v->get_ref<const std::string&>();
    return true;
  }
  bool integer(const json& obj, const char* key, const std::string& path, uint64_t lo, uint64_t hi, uint64_t& out) {
    const json* v = member(obj, key, path);
    if (!v) return false;
    if (!v->is_number_unsigned()) {
      error = "'" + path + key + "' must be a non-negative integer";
      return false;
    }
    out = v->get<uint64_t>();
    if (out < lo || out > hi) {
      error = "'" + path + key + "' = " + std::to_string(out) + " is outside [" + std::to_string(lo) + ", " +
              std::to_string(hi) + "]";
      return false;
    }
    return true;
  }
  bool number(const json& obj, const char* key, const std::string& path, double& out) {
    const json* v = member(obj, key, path);
    if (!v) return false;
    if (!v->is_number()) {
      error = "'" + path + key + "' must be a number";
      return false;
    }
    out = v->get<double>();
    if (!std::isfinite(out)) {
      error = "'" + path + key + "' must be finite";
      return false;
    }
    return true;
  }
  // Positions and ranges are stored as floats: a finite double beyond float range (1e39) would
  // become infinite, so it is refused like any other non-finite number.
  static bool finiteFloat(const json& x, float& out) {
    if (!x.is_number()) return false;
    out = float(x.get<double>());
    return std::isfinite(x.get<double>()) && std::isfinite(out);
  }
  bool vec3(const json& obj, const char* key, const std::string& path, float out[3]) {
    const json* v = member(obj, key, path);
    if (!v) return false;
    if (!v->is_array() || v->size() != 3) {
      error = "'" + path + key + "' must be an array of 3 numbers";
      return false;
    }
    for (int k = 0; k < 3; ++k) {
      if (!finiteFloat((*v)[size_t(k)], out[k])) {
        error = "'" + path + key + "' must hold finite numbers";
        return false;
      }
    }
    return true;
  }
  // [a, b]: two non-negative integers, each at most hi.
  bool integerPair(const json& obj, const char* key, const std::string& path, uint64_t hi, uint64_t out[2]) {
    const json* v = member(obj, key, path);
    if (!v) return false;
    if (!v->is_array() || v->size() != 2 || !(*v)[0].is_number_unsigned() || !(*v)[1].is_number_unsigned()) {
      error = "'" + path + key + "' must be an array of 2 non-negative integers";
      return false;
    }
    for (size_t k = 0; k < 2; ++k) {
      out[k] = (*v)[k].get<uint64_t>();
      if (out[k] > hi) {
        error = "'" + path + key + "' holds " + std::to_string(out[k]) + ", above " + std::to_string(hi);
        return false;
      }
    }
    return true;
  }
  // Optional measured error (files written before it lack the key): -1 when absent, else >= 0.
  void optionalError(const json& obj, const char* key, const std::string& path, double& out) {
    if (obj.contains(key) && number(obj, key, path, out) && out < 0)
      error = "'" + path + key + "' must not be negative";
  }
};

bool validChunkFileName(const std::string& f) {
  const std::string prefix = "chunks/";
  if (f.size() <= prefix.size() || f.size() > 128 || f.compare(0, prefix.size(), prefix) != 0) return false;
  for (size_t i = prefix.size(); i < f.size(); ++i) {
    char c = f[i];
    bool ok = (c >= '0' && c <= '9') || (c >= 'a' && c <= 'z') || c == '-' || c == '.';
    if (!ok) return false;
  }
  return f.find("..") == std::string::npos;
}

Result bad(const std::string& msg) { return fail(Status::BadManifest, "manifest: " + msg); }

bool within(const Range& inner, const Range& outer) { return inner.min >= outer.min && inner.max <= outer.max; }
bool within(const Bounds& inner, const Bounds& outer) {
  for (int k = 0; k < 3; ++k)
    if (inner.min[k] < outer.min[k] || inner.max[k] > outer.max[k]) return false;
  return true;
}

// A node's per-field [min, max] list: one finite pair per field, min <= max, inside the field's
// range and inside the parent's (selection by isovalue relies on the ranges nesting).
Result parseRanges(const json& n, const std::string& path, const Manifest& m, const NodeInfo* parent, NodeInfo& node) {
  auto it = n.find("ranges");
  if (it == n.end()) return bad("missing key '" + path + "ranges'");
  if (!it->is_array() || it->size() != m.fields.size())
    return bad("'" + path + "ranges' must be an array of " + std::to_string(m.fields.size()) +
               " [min, max] pairs, one per field");
  for (size_t f = 0; f < m.fields.size(); ++f) {
    const json& p = (*it)[f];
    const std::string at = "'" + path + "ranges[" + std::to_string(f) + "]'";
    Range r;
    if (!p.is_array() || p.size() != 2 || !Reader::finiteFloat(p[0], r.min) || !Reader::finiteFloat(p[1], r.max))
      return bad(at + " must be [min, max], two finite numbers");
    if (r.min > r.max) return bad(at + " has min > max");
    if (!within(r, m.fields[f].range)) return bad(at + " is outside the range of field '" + m.fields[f].name + "'");
    if (parent && !within(r, parent->ranges[f])) return bad(at + " is outside the parent's range");
    node.ranges.push_back(r);
  }
  return Result::success();
}

// FORMAT.md §1.1. Run after the chunks: the nodes' vertex and tet ids must agree with their counts.
Result parseNodes(Reader& r, const json& list, Manifest& m) {
  const size_t splitChunks = m.chunks.size() - 1;
  if (!list.is_array() || list.size() > splitChunks)
    return bad("'nodes' must be an array of at most one node per split chunk (" + std::to_string(splitChunks) + ")");
  uint64_t nextChunk = 1;  // the first chunk in no node yet (chunk 0 is the base)
  for (size_t k = 0; k < list.size(); ++k) {
    const json& n = list[k];
    const std::string name = "nodes[" + std::to_string(k) + "]", path = name + ".";
    if (!n.is_object()) return bad("'" + name + "' must be an object");
    NodeInfo node;
    // Parents come first, so the list is a forest in application order and has no cycle.
    const json* p = r.member(n, "parent", path);
    if (!p) return bad(r.error);
    const bool isBase = p->is_number_integer() && !p->is_number_unsigned() && p->get<int64_t>() == -1;
    if (!isBase && !(p->is_number_unsigned() && p->get<uint64_t>() < k))
      return bad("'" + path + "parent' must be -1 (the base) or the index of an earlier node");
    node.parent = isBase ? -1 : int32_t(p->get<uint64_t>());
    const NodeInfo* parent = isBase ? nullptr : &m.nodes[size_t(node.parent)];

    uint64_t chunks[2], vertices[2], tets[2];
    r.integerPair(n, "chunks", path, kMaxChunks, chunks);
    r.integerPair(n, "vertices", path, kMaxCount, vertices);
    r.integerPair(n, "tets", path, kMaxCount, tets);
    if (!r.error.empty()) return bad(r.error);
    // The nodes' chunks follow each other: together every split chunk once, in order.
    if (chunks[1] < 1) return bad("'" + path + "chunks' must hold at least one chunk");
    if (chunks[0] != nextChunk)
      return bad("'" + path + "chunks' must start at chunk " + std::to_string(nextChunk) +
                 (k == 0 ? " (the first split chunk)" : ", where the previous node ends"));
    if (chunks[0] + chunks[1] > m.chunks.size()) return bad("'" + path + "chunks' runs past the last chunk");
    nextChunk = chunks[0] + chunks[1];
    node.firstChunk = uint32_t(chunks[0]);
    node.chunkCount = uint32_t(chunks[1]);
    // Stable ids: what the node's splits create in the whole stream's numbering.
    const ChunkInfo &before = m.chunks[node.firstChunk - 1], &last = m.chunks[nextChunk - 1];
    if (vertices[0] != before.vertices || vertices[1] != last.vertices)
      return bad("'" + path + "vertices' must be [" + std::to_string(before.vertices) + ", " +
                 std::to_string(last.vertices) + "], the counts before and after its chunks");
    if (tets[0] != before.tets || tets[1] != last.tets)
      return bad("'" + path + "tets' must be [" + std::to_string(before.tets) + ", " + std::to_string(last.tets) +
                 "], the counts before and after its chunks");
    node.vertexBegin = uint32_t(vertices[0]);
    node.vertexEnd = uint32_t(vertices[1]);
    node.tetBegin = uint32_t(tets[0]);
    node.tetEnd = uint32_t(tets[1]);

    const json* b = r.member(n, "bounds", path);
    if (!b) return bad(r.error);
    if (!b->is_object()) return bad("'" + path + "bounds' must be an object");
    r.vec3(*b, "min", path + "bounds.", node.bounds.min);
    r.vec3(*b, "max", path + "bounds.", node.bounds.max);
    if (!r.error.empty()) return bad(r.error);
    for (int a = 0; a < 3; ++a)
      if (node.bounds.min[a] > node.bounds.max[a]) return bad("'" + path + "bounds.min' exceeds 'bounds.max'");
    if (!within(node.bounds, m.bounds)) return bad("'" + path + "bounds' is outside the top-level 'bounds'");
    if (parent && !within(node.bounds, parent->bounds)) return bad("'" + path + "bounds' is outside the parent's");

    if (Result rr = parseRanges(n, path, m, parent, node); !rr) return rr;
    if (r.number(n, "fieldError", path, node.fieldError) && node.fieldError < 0)
      r.error = "'" + path + "fieldError' must not be negative";
    r.optionalError(n, "fieldRms", path, node.fieldRms);
    r.optionalError(n, "fieldMax", path, node.fieldMax);
    if (!r.error.empty()) return bad(r.error);
    m.nodes.push_back(std::move(node));
  }
  if (!m.nodes.empty() && nextChunk != m.chunks.size())
    return bad("'nodes[" + std::to_string(m.nodes.size() - 1) + "].chunks' stops before chunk " +
               std::to_string(nextChunk) + ": every split chunk (1 to " + std::to_string(m.chunks.size() - 1) +
               ") belongs to a node");
  return Result::success();
}

}  // namespace

uint64_t Manifest::totalBytes() const {
  uint64_t s = 0;
  for (const ChunkInfo& c : chunks) s += c.bytes;
  return s;
}

int Manifest::findField(std::string_view fieldName) const {
  for (size_t i = 0; i < fields.size(); ++i)
    if (fields[i].name == fieldName) return int(i);
  return -1;
}

Result parseManifest(std::string_view text, Manifest& m) {
  if (text.size() > kMaxManifestBytes) return fail(Status::TooLarge, "manifest: larger than 64 MiB");
  if (!nestingWithin(text, kMaxDepth)) return bad("nested deeper than 32 levels");
  json doc = json::parse(text.begin(), text.end(), nullptr, /*allow_exceptions=*/false);
  if (doc.is_discarded()) return bad("not valid JSON");
  if (!doc.is_object()) return bad("top level must be an object");

  Reader r;
  std::string format;
  if (r.string(doc, "format", "", format) && format != "tetstream")
    return bad("'format' is \"" + format + "\", expected \"tetstream\"");
  uint64_t version = 0;
  if (!r.error.empty()) return bad(r.error);
  {
    const json* v = r.member(doc, "formatVersion", "");
    if (!v) return bad(r.error);
    if (!v->is_number_unsigned() || v->get<uint64_t>() < 1 || v->get<uint64_t>() > kFormatVersion) {
      return fail(Status::UnsupportedVersion,
                  "manifest: formatVersion " + v->dump() + " is not supported (this reader reads versions 1 and 2)");
    }
    version = v->get<uint64_t>();
  }
  m = Manifest{};
  m.formatVersion = uint32_t(version);
  if (auto it = doc.find("generator"); it != doc.end() && it->is_string()) m.generator = it->get<std::string>();
  r.string(doc, "name", "", m.name);
  if (const json* b = r.member(doc, "bounds", "")) {
    if (!b->is_object()) return bad("'bounds' must be an object");
    r.vec3(*b, "min", "bounds.", m.bounds.min);
    r.vec3(*b, "max", "bounds.", m.bounds.max);
    if (r.error.empty())
      for (int k = 0; k < 3; ++k)
        if (m.bounds.min[k] > m.bounds.max[k]) return bad("'bounds.min' exceeds 'bounds.max'");
  }
  uint64_t nv = 0, nt = 0;
  r.integer(doc, "vertices", "", 4, kMaxCount, nv);
  r.integer(doc, "tets", "", 1, kMaxCount, nt);
  if (!r.error.empty()) return bad(r.error);
  m.vertices = uint32_t(nv);
  m.tets = uint32_t(nt);

  const json* fields = r.member(doc, "fields", "");
  if (!fields) return bad(r.error);
  if (!fields->is_array() || fields->size() > kMaxFields) return bad("'fields' must be an array of at most 64 fields");
  for (size_t i = 0; i < fields->size(); ++i) {
    const json& f = (*fields)[i];
    std::string path = "fields[" + std::to_string(i) + "].";
    if (!f.is_object()) return bad("'" + path.substr(0, path.size() - 1) + "' must be an object");
    FieldInfo fi;
    double lo = 0, hi = 0;
    r.string(f, "name", path, fi.name);
    r.number(f, "min", path, lo);
    r.number(f, "max", path, hi);
    if (!r.error.empty()) return bad(r.error);
    if (fi.name.empty() || fi.name.size() > 256) return bad("'" + path + "name' must have 1 to 256 characters");
    if (!std::isfinite(float(lo)) || !std::isfinite(float(hi)))
      return bad("'" + path + "min' and 'max' must be finite as 32-bit floats");
    if (lo > hi) return bad("'" + path + "min' exceeds max");
    if (m.findField(fi.name) >= 0) return bad("field name '" + fi.name + "' appears twice");
    fi.range = {float(lo), float(hi)};
    m.fields.push_back(std::move(fi));
  }
  if (r.string(doc, "isoField", "", m.isoField) && !m.fields.empty() && m.findField(m.isoField) < 0)
    return bad("'isoField' names a field that is not in 'fields'");
  if (!r.error.empty()) return bad(r.error);

  if (const json* q = r.member(doc, "quantization", "")) {
    if (!q->is_object()) return bad("'quantization' must be an object");
    if (auto it = q->find("lossless"); it != q->end() && it->is_boolean() && it->get<bool>()) {
      m.lossless = true;
    } else {
      uint64_t pb = 0, fb = 0;
      r.integer(*q, "positionBits", "quantization.", 8, 24, pb);
      r.integer(*q, "fieldBits", "quantization.", 8, 16, fb);
      m.positionBits = int(pb);
      m.fieldBits = int(fb);
    }
  }
  if (!r.error.empty()) return bad(r.error);

  const json* chunks = r.member(doc, "chunks", "");
  if (!chunks) return bad(r.error);
  if (!chunks->is_array() || chunks->empty() || chunks->size() > kMaxChunks)
    return bad("'chunks' must be an array of 1 to " + std::to_string(kMaxChunks) + " chunks");
  for (size_t i = 0; i < chunks->size(); ++i) {
    const json& c = (*chunks)[i];
    std::string path = "chunks[" + std::to_string(i) + "].";
    if (!c.is_object()) return bad("'" + path.substr(0, path.size() - 1) + "' must be an object");
    ChunkInfo ci;
    std::string kind, hash;
    uint64_t v = 0, t = 0, s = 0;
    r.string(c, "file", path, ci.file);
    r.string(c, "kind", path, kind);
    r.integer(c, "bytes", path, 1, kMaxChunkBytes, ci.bytes);
    r.integer(c, "rawBytes", path, 16, kMaxRawBytes, ci.rawBytes);
    r.string(c, "hash", path, hash);
    r.integer(c, "vertices", path, 4, kMaxCount, v);
    r.integer(c, "tets", path, 1, kMaxCount, t);
    r.integer(c, "splits", path, 0, kMaxCount, s);
    r.number(c, "fieldError", path, ci.fieldError);
    // Measured errors (format 1 files written before them lack the keys: -1, not shown).
    r.optionalError(c, "fieldRms", path, ci.fieldRms);
    r.optionalError(c, "fieldMax", path, ci.fieldMax);
    if (!r.error.empty()) return bad(r.error);
    if (!validChunkFileName(ci.file)) return bad("'" + path + "file' is not a plain name under chunks/");
    if (kind != (i == 0 ? "base" : "splits"))
      return bad("'" + path + "kind' must be \"" + (i == 0 ? "base" : "splits") + "\"");
    ci.kind = i == 0 ? ChunkKind::Base : ChunkKind::Splits;
    if (!parseHash(hash, &ci.hash)) return bad("'" + path + "hash' must be \"xxh3-64:\" and 16 hex digits");
    ci.vertices = uint32_t(v);
    ci.tets = uint32_t(t);
    ci.splits = uint32_t(s);
    if (i == 0 && s != 0) return bad("'chunks[0].splits' must be 0");
    // A chunk may not claim to inflate far beyond what zstd does on real mesh data (2-5x), so
    // a hostile 100-byte file cannot make the reader set aside a gigabyte before decoding.
    if (ci.rawBytes > maxRawBytesFor(ci.bytes))
      return bad("'" + path + "rawBytes' claims more than 64 times 'bytes' (+1 MiB)");
    if (i > 0) {
      const ChunkInfo& prev = m.chunks.back();
      if (uint64_t(prev.vertices) + s != v)
        return bad("'" + path + "vertices' must equal the previous count plus 'splits'");
      if (t < prev.tets) return bad("'" + path + "tets' decreases");
    }
    m.chunks.push_back(std::move(ci));
  }
  if (m.chunks.back().vertices != m.vertices || m.chunks.back().tets != m.tets)
    return bad("the last chunk's counts differ from 'vertices'/'tets'");
  // Version 1 has no nodes (a key of that name is unknown there, so ignored); version 2 must
  // say, even when empty (one sequence of split chunks).
  if (version < 2) return Result::success();
  const json* nodes = r.member(doc, "nodes", "");
  if (!nodes) return bad(r.error);
  return parseNodes(r, *nodes, m);
}

namespace {

// The double nearest to the shortest decimal that gives back float x: the manifest's 32-bit
// values (bounds, ranges, errors) written in 9 digits at most instead of a double's 17 (the
// manifest of a large hierarchy holds hundreds of thousands of them; it is fetched first).
double shortest(double x) {
  const float f = float(x);
  char buf[32];
  for (int digits = 6;; ++digits) {  // (9 always gives a float back; std::to_chars is not in every libc++)
    std::snprintf(buf, sizeof buf, "%.*g", digits, double(f));
    const double d = std::strtod(buf, nullptr);
    if (float(d) == f || digits >= 9) return d;
  }
}

// Compact JSON laid out for people: a member of the object, or an element of an array in it (a
// chunk, a node, a field), a line each; ": " and ", " elsewhere.
std::string layOut(const std::string& compact) {
  std::string out;
  out.reserve(compact.size() + compact.size() / 8);
  int depth = 0;
  StringTracker text;
  auto newline = [&] { out += '\n' + std::string(size_t(depth), ' '); };
  for (size_t k = 0; k < compact.size(); ++k) {
    const char c = compact[k];
    if (text.inside(c)) {
      out += c;
      continue;
    }
    switch (c) {
      case ':': out += ": "; break;
      case ',':
        out += ',';
        if (depth <= 2)
          newline();
        else
          out += ' ';
        break;
      case '{':
      case '[':
        out += c;
        if (k + 1 < compact.size() && (compact[k + 1] == '}' || compact[k + 1] == ']')) {  // empty
          out += compact[++k];
          break;
        }
        ++depth;
        if (depth <= 2) newline();
        break;
      case '}':
      case ']':
        --depth;
        if (depth <= 1) newline();
        out += c;
        break;
      default: out += c;
    }
  }
  return out + '\n';
}

}  // namespace

std::string writeManifest(const Manifest& m) {
  json doc;
  doc["format"] = "tetstream";
  doc["formatVersion"] = m.formatVersion;
  doc["generator"] = m.generator.empty() ? std::string("tetstream ") + kLibraryVersion : m.generator;
  doc["name"] = m.name;
  auto point = [](const float* p) { return json::array({shortest(p[0]), shortest(p[1]), shortest(p[2])}); };
  doc["bounds"] = {{"min", point(m.bounds.min)}, {"max", point(m.bounds.max)}};
  doc["vertices"] = m.vertices;
  doc["tets"] = m.tets;
  json fields = json::array();
  for (const FieldInfo& f : m.fields)
    fields.push_back({{"name", f.name}, {"min", shortest(f.range.min)}, {"max", shortest(f.range.max)}});
  doc["fields"] = fields;
  doc["isoField"] = m.isoField;
  if (m.lossless)
    doc["quantization"] = {{"lossless", true}};
  else
    doc["quantization"] = {{"positionBits", m.positionBits}, {"fieldBits", m.fieldBits}};
  json chunks = json::array();
  for (const ChunkInfo& c : m.chunks) {
    chunks.push_back({{"file", c.file},
                      {"kind", c.kind == ChunkKind::Base ? "base" : "splits"},
                      {"bytes", c.bytes},
                      {"rawBytes", c.rawBytes},
                      {"hash", formatHash(c.hash)},
                      {"vertices", c.vertices},
                      {"tets", c.tets},
                      {"splits", c.splits},
                      {"fieldError", shortest(c.fieldError)}});
    if (c.fieldRms >= 0) chunks.back()["fieldRms"] = shortest(c.fieldRms);
    if (c.fieldMax >= 0) chunks.back()["fieldMax"] = shortest(c.fieldMax);
  }
  doc["chunks"] = chunks;
  assert(m.formatVersion >= 2 || m.nodes.empty());  // version 1 cannot hold nodes
  if (m.formatVersion >= 2) {
    json nodes = json::array();
    for (const NodeInfo& n : m.nodes) {
      json ranges = json::array();
      for (const Range& r : n.ranges) ranges.push_back({shortest(r.min), shortest(r.max)});
      nodes.push_back({{"parent", n.parent},
                       {"chunks", {n.firstChunk, n.chunkCount}},
                       {"vertices", {n.vertexBegin, n.vertexEnd}},
                       {"tets", {n.tetBegin, n.tetEnd}},
                       {"bounds", {{"min", point(n.bounds.min)}, {"max", point(n.bounds.max)}}},
                       {"ranges", ranges},
                       {"fieldError", shortest(n.fieldError)}});
      if (n.fieldRms >= 0) nodes.back()["fieldRms"] = shortest(n.fieldRms);
      if (n.fieldMax >= 0) nodes.back()["fieldMax"] = shortest(n.fieldMax);
    }
    doc["nodes"] = nodes;
  }
  return layOut(doc.dump());
}

}  // namespace tetstream
