// Gmsh .msh reader, versions 2.2 and 4.1, ASCII and binary. Reference: the Gmsh manual, "MSH
// file format" (version 4.1) and "Legacy formats" (version 2.2).
//
// A file is a sequence of sections "$Name ... $EndName". Read: $MeshFormat, $Nodes, $Elements,
// $NodeData (fields), $ElementData (cell data -> point data). Skipped with a note: $ElementNodeData.
// Skipped silently: $PhysicalNames, $Entities, $Periodic and anything else (physical and entity
// tags are not used). In binary files the counts and section headers of 2.2 are text lines and
// the records binary; in 4.1 everything inside a section is binary (int = 4 bytes, size_t = the
// data-size of $MeshFormat, double = 8 bytes). The byte order is found from the int 1 that
// follows the binary $MeshFormat line. Node and element tags are arbitrary positive numbers, so
// they are mapped to indices (dense when they are compact, sorted pairs otherwise).
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>

#include "io/readers.h"

namespace tetstream {
namespace {

using namespace vtkio;

// Gmsh element types: node count, and for volume elements the linear shape (corners first).
struct GmshType {
  int type;
  int nodes;
  int dim;
  const char* name;
};
// clang-format off
constexpr GmshType kGmshTypes[] = {
  {1, 2, 1, "2-node line"}, {2, 3, 2, "3-node triangle"}, {3, 4, 2, "4-node quadrangle"},
  {4, 4, 3, "4-node tetrahedron"}, {5, 8, 3, "8-node hexahedron"}, {6, 6, 3, "6-node prism"},
  {7, 5, 3, "5-node pyramid"}, {8, 3, 1, "3-node line"}, {9, 6, 2, "6-node triangle"},
  {10, 9, 2, "9-node quadrangle"}, {11, 10, 3, "10-node tetrahedron"}, {12, 27, 3, "27-node hexahedron"},
  {13, 18, 3, "18-node prism"}, {14, 14, 3, "14-node pyramid"}, {15, 1, 0, "1-node point"},
  {16, 8, 2, "8-node quadrangle"}, {17, 20, 3, "20-node hexahedron"}, {18, 15, 3, "15-node prism"},
  {19, 13, 3, "13-node pyramid"}, {20, 9, 2, "9-node triangle"}, {21, 10, 2, "10-node triangle"},
  {22, 12, 2, "12-node triangle"}, {23, 15, 2, "15-node triangle"}, {24, 15, 2, "15-node triangle"},
  {25, 21, 2, "21-node triangle"}, {26, 4, 1, "4-node line"}, {27, 5, 1, "5-node line"},
  {28, 6, 1, "6-node line"}, {29, 20, 3, "20-node tetrahedron"}, {30, 35, 3, "35-node tetrahedron"},
  {31, 56, 3, "56-node tetrahedron"}, {36, 16, 2, "16-node quadrangle"}, {37, 25, 2, "25-node quadrangle"},
  {38, 36, 2, "36-node quadrangle"}, {39, 12, 2, "12-node quadrangle"}, {40, 16, 2, "16-node quadrangle"},
  {41, 20, 2, "20-node quadrangle"}, {42, 28, 2, "28-node triangle"}, {43, 36, 2, "36-node triangle"},
  {44, 45, 2, "45-node triangle"}, {45, 55, 2, "55-node triangle"}, {46, 66, 2, "66-node triangle"},
  {47, 49, 2, "49-node quadrangle"}, {48, 64, 2, "64-node quadrangle"}, {49, 81, 2, "81-node quadrangle"},
  {50, 100, 2, "100-node quadrangle"}, {51, 121, 2, "121-node quadrangle"}, {62, 7, 1, "7-node line"},
  {63, 8, 1, "8-node line"}, {64, 9, 1, "9-node line"}, {65, 10, 1, "10-node line"},
  {66, 11, 1, "11-node line"}, {71, 84, 3, "84-node tetrahedron"}, {72, 120, 3, "120-node tetrahedron"},
  {73, 165, 3, "165-node tetrahedron"}, {74, 220, 3, "220-node tetrahedron"},
  {75, 286, 3, "286-node tetrahedron"}, {90, 40, 3, "40-node prism"}, {91, 75, 3, "75-node prism"},
  {92, 64, 3, "64-node hexahedron"}, {93, 125, 3, "125-node hexahedron"}, {118, 30, 3, "30-node pyramid"},
  {119, 55, 3, "55-node pyramid"},
};
// clang-format on

const GmshType* gmshType(int64_t type) {
  for (const GmshType& t : kGmshTypes)
    if (t.type == type) return &t;
  return nullptr;
}

// The linear shape of a 3D element from its name ("...tetrahedron", "...hexahedron", ...).
bool volumeShape(const GmshType& t, CellShape& shape) {
  if (t.dim != 3) return false;
  std::string_view n = t.name;
  shape = n.ends_with("tetrahedron")  ? CellShape::Tet
          : n.ends_with("hexahedron") ? CellShape::Hex
          : n.ends_with("prism")      ? CellShape::Wedge
                                      : CellShape::Pyramid;
  return true;
}

// VTK type of the same linear cell, for ReadReport::skippedCells (0 when there is none).
int vtkTypeOf(const GmshType& t) {
  switch (t.type) {
    case 1: return 3;
    case 2: return 5;
    case 3: return 9;
    case 8: return 21;
    case 9: return 22;
    case 10: return 28;
    case 15: return 1;
    case 16: return 23;
    default: return 0;
  }
}

// Tag -> index for node or element tags (positive integers, maybe sparse).
class TagMap {
 public:
  void add(uint64_t tag, uint32_t index) {
    pairs_.push_back({tag, index});
    maxTag_ = std::max(maxTag_, tag);
  }
  // Builds the lookup; false (with the tag) when a tag appears twice.
  bool finish(uint64_t& duplicate) {
    if (maxTag_ <= 4 * pairs_.size() + 1024) {
      dense_.assign(maxTag_ + 1, kNone);
      for (auto [tag, index] : pairs_) {
        if (dense_[tag] != kNone) {
          duplicate = tag;
          return false;
        }
        dense_[tag] = index;
      }
      pairs_ = {};
      return true;
    }
    std::sort(pairs_.begin(), pairs_.end());
    for (size_t i = 1; i < pairs_.size(); ++i)
      if (pairs_[i].first == pairs_[i - 1].first) {
        duplicate = pairs_[i].first;
        return false;
      }
    return true;
  }
  int64_t find(uint64_t tag) const {
    if (!dense_.empty() || pairs_.empty())
      return tag < dense_.size() && dense_[tag] != kNone ? int64_t(dense_[tag]) : int64_t(-1);
    auto it = std::lower_bound(pairs_.begin(), pairs_.end(), std::pair<uint64_t, uint32_t>{tag, 0});
    return it != pairs_.end() && it->first == tag ? int64_t(it->second) : int64_t(-1);
  }

 private:
  static constexpr uint32_t kNone = 0xFFFFFFFFu;
  std::vector<std::pair<uint64_t, uint32_t>> pairs_;
  std::vector<uint32_t> dense_;
  uint64_t maxTag_ = 0;
};

struct Gmsh {
  std::string label;
  std::string_view s;
  ReadReport& report;
  size_t pos = 0;
  int major = 0;
  std::string version;
  bool binary = false, swap = false;
  int sizeT = 8;

  std::vector<float> positions;
  TagMap nodeTags, elementTags;
  bool haveNodes = false, haveElements = false, sawTags = false;
  uint64_t elementCount = 0;  // every element read (the next input index)
  CellSoup soup;
  std::vector<ScalarField> fields;
  std::vector<CellArray> cellArrays;
  std::map<std::string, int> dataSteps;  // view name -> $NodeData/$ElementData sections seen
  uint64_t physicalNames = 0;

  Gmsh(std::string l, std::string_view bytes, ReadReport& r) : label(std::move(l)), s(bytes), report(r) {}

  std::string at(size_t p) const {
    if (binary) return "byte " + std::to_string(p);
    return "line " + std::to_string(1 + std::count(s.begin(), s.begin() + std::ptrdiff_t(std::min(p, s.size())), '\n'));
  }
  Result error(Status st, size_t p, const std::string& section, const std::string& msg) const {
    return fail(st, label + " " + at(p) + (section.empty() ? "" : " ($" + section + ")") + ": " + msg);
  }

  // ------------------------------------------------------------ text
  void skipSpace() { vtkio::skipSpace(s, pos); }
  std::string_view token() { return nextToken(s, pos); }
  std::string_view line() { return nextLine(s, pos); }
  Result textInt(const std::string& sec, const std::string& what, int64_t& v) {
    return textNumber(sec, what, v, parseNextInt, "an integer");
  }
  Result textDouble(const std::string& sec, const std::string& what, double& v) {
    return textNumber(sec, what, v, parseNextDouble, "a number");
  }
  template <typename T>
  Result textNumber(const std::string& sec, const std::string& what, T& v, int (*parse)(std::string_view, size_t&, T&),
                    const char* kind) {
    const size_t p = pos;
    int r = parse(s, pos, v);
    if (r == 0) return error(Status::Truncated, p, sec, "file ends before " + what);
    if (r < 0) return error(Status::Corrupt, pos, sec, what + ": '" + printable(token()) + "' is not " + kind);
    return Result::success();
  }
  Result textCount(const std::string& sec, const std::string& what, uint64_t& v) {
    int64_t x;
    if (Result r = textInt(sec, what, x); !r) return r;
    if (x < 0) return error(Status::Corrupt, pos, sec, what + " is negative (" + std::to_string(x) + ")");
    v = uint64_t(x);
    return Result::success();
  }

  // ------------------------------------------------------------ binary
  size_t left() const { return s.size() - pos; }
  // `count` records of `per` bytes, checked without overflow.
  Result need(uint64_t count, uint64_t per, const std::string& sec, const std::string& what) const {
    if (per && count > left() / per)
      return error(Status::Truncated, pos, sec,
                   what + " needs " + std::to_string(count) + " x " + std::to_string(per) + " bytes, only " +
                       std::to_string(left()) + " remain");
    return Result::success();
  }
  Result need(uint64_t bytes, const std::string& sec, const std::string& what) const {
    if (bytes > left())
      return error(Status::Truncated, pos, sec,
                   what + " needs " + std::to_string(bytes) + " bytes, only " + std::to_string(left()) + " remain");
    return Result::success();
  }
  uint64_t rawU(int bytes) {
    uint64_t v = 0;
    if (bytes == 4) {
      uint32_t x;
      std::memcpy(&x, s.data() + pos, 4);
      v = swap ? __builtin_bswap32(x) : x;
    } else {
      uint64_t x;
      std::memcpy(&x, s.data() + pos, 8);
      v = swap ? __builtin_bswap64(x) : x;
    }
    pos += size_t(bytes);
    return v;
  }
  int32_t binInt() { return int32_t(uint32_t(rawU(4))); }
  uint64_t binSize() { return rawU(sizeT); }
  double binDouble() { return std::bit_cast<double>(rawU(8)); }

  // A count in a 4.1 section header: size_t in binary, text otherwise.
  Result count41(const std::string& sec, const std::string& what, uint64_t& v) {
    if (!binary) return textCount(sec, what, v);
    if (Result r = need(uint64_t(sizeT), sec, what); !r) return r;
    v = binSize();
    return Result::success();
  }
  Result int41(const std::string& sec, const std::string& what, int64_t& v) {
    if (!binary) return textInt(sec, what, v);
    if (Result r = need(4, sec, what); !r) return r;
    v = binInt();
    return Result::success();
  }

  // ------------------------------------------------------------ sections
  // After a section's content: optional whitespace, then $End<name>.
  Result expectEnd(const std::string& sec) {
    skipSpace();
    const std::string want = "$End" + sec;
    if (s.substr(pos, want.size()) != want) {
      if (pos >= s.size()) return error(Status::Truncated, pos, sec, "file ends before " + want);
      return error(Status::Corrupt, pos, sec,
                   "expected " + want + ", found '" + printable(s.substr(pos, std::min<size_t>(24, left()))) + "'");
    }
    pos += want.size();
    return Result::success();
  }
  Result skipSection(const std::string& sec) {
    const std::string want = "\n$End" + sec;
    size_t e = s.find(want, pos > 0 ? pos - 1 : 0);
    if (e == std::string_view::npos)
      return error(Status::Truncated, pos, sec, "file ends inside the section (no $End" + sec + ")");
    pos = e + want.size();
    return Result::success();
  }

  Result meshFormat() {
    const std::string sec = "MeshFormat";
    size_t p = pos;
    std::vector<std::string_view> a;
    std::string_view l = line();
    for (size_t i = 0; i < l.size();) {
      while (i < l.size() && isSpace(l[i])) ++i;
      size_t b = i;
      while (i < l.size() && !isSpace(l[i])) ++i;
      if (i > b) a.push_back(l.substr(b, i - b));
    }
    if (a.size() < 3)
      return error(pos >= s.size() ? Status::Truncated : Status::Corrupt, p, sec,
                   "expected 'version file-type data-size', found '" + printable(l) + "'");
    version = std::string(a[0]);
    if (version == "2" || version == "2.0" || version == "2.1" || version == "2.2")
      major = 2;
    else if (version == "4.1")
      major = 4;
    else if (version.starts_with("4") || version.starts_with("3"))
      return error(Status::UnsupportedVersion, p, sec,
                   "MSH " + printable(version) +
                       " is not supported; tetstream reads 2.2 and 4.1 (re-save with "
                       "Gmsh: -format msh41 or msh22)");
    else
      return error(Status::UnsupportedVersion, p, sec, "unknown MSH version '" + printable(version) + "'");
    if (a[1] == "1")
      binary = true;
    else if (a[1] != "0")
      return error(Status::Corrupt, p, sec, "file-type '" + printable(a[1]) + "', expected 0 (ASCII) or 1 (binary)");
    uint64_t ds;
    if (!parseU64(a[2], ds) || (major == 2 ? ds != 8 : (ds != 4 && ds != 8)))
      return error(Status::Unsupported, p, sec,
                   "data-size '" + printable(a[2]) + "', expected " + (major == 2 ? "8" : "4 or 8"));
    sizeT = int(ds);
    if (binary) {
      if (left() < 4) return error(Status::Truncated, pos, sec, "file ends before the binary endianness check (int 1)");
      uint32_t one;
      std::memcpy(&one, s.data() + pos, 4);
      if (one == 1)
        swap = false;
      else if (one == 0x01000000u)
        swap = true;
      else
        return error(
            Status::Corrupt, pos, sec, "the endianness check should be the int 1 in either byte order, found 0x" + [&] {
              char b[16];
              std::snprintf(b, sizeof b, "%08x", one);
              return std::string(b);
            }());
      pos += 4;
    }
    return expectEnd(sec);
  }

  Result addNode(const std::string& sec, uint64_t tag, const double xyz[3]) {
    if (positions.size() / 3 >= kMaxVertices)
      return error(Status::TooLarge, pos, sec, "more than 2^32-1 nodes; tetstream indexes vertices with 32 bits");
    nodeTags.add(tag, uint32_t(positions.size() / 3));
    for (int k = 0; k < 3; ++k) positions.push_back(float(xyz[k]));
    return Result::success();
  }

  Result nodes() {
    const std::string sec = "Nodes";
    if (haveNodes) return error(Status::Corrupt, pos, sec, "a second $Nodes section");
    haveNodes = true;
    if (major == 2) {
      uint64_t n;
      if (Result r = textCount(sec, "the node count", n); !r) return r;
      if (binary) {
        line();
        if (Result r = need(n, 28, sec, std::to_string(n) + " nodes"); !r) return r;
        positions.reserve(3 * n);
        for (uint64_t i = 0; i < n; ++i) {
          int32_t tag = binInt();
          double xyz[3] = {binDouble(), binDouble(), binDouble()};
          if (tag < 1)
            return error(Status::Corrupt, pos - 28, sec, "node tag " + std::to_string(tag) + " is not positive");
          if (Result r = addNode(sec, uint64_t(tag), xyz); !r) return r;
        }
      } else {
        if (n > left() / 8)
          return error(Status::Truncated, pos, sec,
                       std::to_string(n) + " nodes cannot fit in the " + std::to_string(left()) + " bytes left");
        positions.reserve(3 * n);
        for (uint64_t i = 0; i < n; ++i) {
          uint64_t tag;
          double xyz[3];
          if (Result r = textCount(sec, "node " + std::to_string(i) + " tag", tag); !r) return r;
          for (double& c : xyz)
            if (Result r = textDouble(sec, "node tag " + std::to_string(tag) + " coordinate", c); !r) return r;
          if (Result r = addNode(sec, tag, xyz); !r) return r;
        }
      }
      return finishTags(nodeTags, sec, "node");
    }
    uint64_t blocks, n, minTag, maxTag;
    for (auto [v, what] :
         {std::pair{&blocks, "numEntityBlocks"}, {&n, "numNodes"}, {&minTag, "minNodeTag"}, {&maxTag, "maxNodeTag"}})
      if (Result r = count41(sec, what, *v); !r) return r;
    // Each node takes at least 3 doubles (binary) or 6 characters (text): a bound on n.
    if (n > left() / (binary ? 24 : 6) || blocks > left() / (binary ? 12 + uint64_t(sizeT) : 8) + 1)
      return error(Status::Truncated, pos, sec,
                   std::to_string(n) + " nodes in " + std::to_string(blocks) + " blocks cannot fit in the " +
                       std::to_string(left()) + " bytes left");
    positions.reserve(3 * n);
    uint64_t seen = 0;
    std::vector<uint64_t> tags;
    for (uint64_t b = 0; b < blocks; ++b) {
      int64_t dim, entity, parametric;
      uint64_t inBlock;
      if (Result r = int41(sec, "entityDim", dim); !r) return r;
      if (Result r = int41(sec, "entityTag", entity); !r) return r;
      if (Result r = int41(sec, "parametric", parametric); !r) return r;
      if (Result r = count41(sec, "numNodesInBlock", inBlock); !r) return r;
      if (dim < 0 || dim > 3 || (parametric != 0 && parametric != 1))
        return error(Status::Corrupt, pos, sec,
                     "node block " + std::to_string(b) + ": entityDim " + std::to_string(dim) + ", parametric " +
                         std::to_string(parametric) + " (expected 0..3 and 0 or 1)");
      if (inBlock > n - seen)
        return error(Status::Corrupt, pos, sec,
                     "node block " + std::to_string(b) + " has " + std::to_string(inBlock) + " nodes, more than the " +
                         std::to_string(n - seen) + " left of numNodes " + std::to_string(n));
      seen += inBlock;
      const int coords = 3 + (parametric ? int(dim) : 0);
      tags.resize(inBlock);
      if (binary) {
        if (Result r = need(inBlock, uint64_t(sizeT) + 8 * uint64_t(coords), sec, "node block " + std::to_string(b));
            !r)
          return r;
        for (uint64_t& t : tags) t = binSize();
        for (uint64_t i = 0; i < inBlock; ++i) {
          double c[6];
          for (int k = 0; k < coords; ++k) c[k] = binDouble();
          if (Result r = addNode(sec, tags[i], c); !r) return r;
        }
      } else {
        for (uint64_t& t : tags)
          if (Result r = textCount(sec, "node tag", t); !r) return r;
        for (uint64_t i = 0; i < inBlock; ++i) {
          double c[6];
          for (int k = 0; k < coords; ++k)
            if (Result r = textDouble(sec, "node tag " + std::to_string(tags[i]) + " coordinate", c[k]); !r) return r;
          if (Result r = addNode(sec, tags[i], c); !r) return r;
        }
      }
    }
    if (seen != n)
      return error(Status::Corrupt, pos, sec,
                   "the blocks hold " + std::to_string(seen) + " nodes, numNodes says " + std::to_string(n));
    return finishTags(nodeTags, sec, "node");
  }

  Result finishTags(TagMap& map, const std::string& sec, const char* what) {
    uint64_t dup = 0;
    if (!map.finish(dup))
      return error(Status::Corrupt, pos, sec, std::string(what) + " tag " + std::to_string(dup) + " appears twice");
    return Result::success();
  }

  // One element: its Gmsh type, tag and node tags.
  Result addElement(const std::string& sec, size_t p, int64_t type, uint64_t tag, const uint64_t* nodes, int count) {
    const GmshType* t = gmshType(type);
    const uint64_t index = elementCount++;
    if (index >= 0xFFFFFFFFull) return error(Status::TooLarge, p, sec, "more than 2^32-1 elements");
    elementTags.add(tag, uint32_t(index));
    CellShape shape;
    if (!t || !volumeShape(*t, shape)) {
      const std::string name = t ? std::string("Gmsh ") + t->name + " (type " + std::to_string(type) + ")"
                                 : "Gmsh element type " + std::to_string(type);
      ++soup.skipped[{t ? vtkTypeOf(*t) : 0, name}];
      for (int k = 0; k < count; ++k) {
        int64_t v = nodeTags.find(nodes[k]);
        if (v >= 0) soup.markReferenced(uint64_t(v));
      }
      return Result::success();
    }
    uint32_t ids[8];
    const int corners = kShapeCorners[int(shape)];
    for (int k = 0; k < count; ++k) {
      int64_t v = nodeTags.find(nodes[k]);
      if (v < 0)
        return error(Status::OutOfRange, p, sec,
                     "element " + std::to_string(tag) + " (" + t->name + ") uses node " + std::to_string(nodes[k]) +
                         ", which $Nodes does not define");
      if (k < corners) ids[k] = uint32_t(v);
      soup.markReferenced(uint64_t(v));
    }
    soup.add(shape, ids, index);
    if (count > corners) {
      auto& r = soup.reduced[std::string("Gmsh ") + t->name + " (type " + std::to_string(type) + ")"];
      r.first = corners;
      ++r.second;
    }
    return Result::success();
  }

  Result elements() {
    const std::string sec = "Elements";
    if (haveElements) return error(Status::Corrupt, pos, sec, "a second $Elements section");
    if (!haveNodes) return error(Status::Corrupt, pos, sec, "$Elements before $Nodes");
    haveElements = true;
    uint64_t nodes[512];
    if (major == 2) {
      uint64_t n;
      if (Result r = textCount(sec, "the element count", n); !r) return r;
      if (n > left() / (binary ? 12 : 6))
        return error(Status::Truncated, pos, sec,
                     std::to_string(n) + " elements cannot fit in the " + std::to_string(left()) + " bytes left");
      soup.shapes.reserve(n);
      if (!binary) {
        for (uint64_t i = 0; i < n; ++i) {
          const size_t p = pos;
          int64_t tag, type, ntags;
          if (Result r = textInt(sec, "element tag", tag); !r) return r;
          if (Result r = textInt(sec, "element type", type); !r) return r;
          if (Result r = textInt(sec, "element tag count", ntags); !r) return r;
          if (tag < 1 || ntags < 0 || ntags > 64)
            return error(Status::Corrupt, p, sec,
                         "element " + std::to_string(i) + ": tag " + std::to_string(tag) + ", " +
                             std::to_string(ntags) + " tags (expected a positive tag and 0..64 tags)");
          sawTags |= ntags > 0;
          for (int64_t k = 0; k < ntags; ++k) {
            int64_t x;
            if (Result r = textInt(sec, "element tag", x); !r) return r;
          }
          const GmshType* t = gmshType(type);
          int count = 0;
          if (t) {
            count = t->nodes;
            for (int k = 0; k < count; ++k)
              if (Result r = textCount(sec, "element " + std::to_string(tag) + " node", nodes[k]); !r) return r;
          } else {
            line();  // unknown type: its nodes are the rest of the line
          }
          if (Result r = addElement(sec, p, type, uint64_t(tag), nodes, count); !r) return r;
        }
      } else {
        line();
        uint64_t done = 0;
        while (done < n) {
          if (Result r = need(12, sec, "an element block header"); !r) return r;
          const size_t p = pos;
          int32_t type = binInt(), count = binInt(), ntags = binInt();
          const GmshType* t = gmshType(type);
          if (!t)
            return error(Status::Unsupported, p, sec,
                         "element type " + std::to_string(type) +
                             " is not one tetstream knows (cannot skip it in a binary file)");
          if (count < 1 || uint64_t(count) > n - done || ntags < 0 || ntags > 64)
            return error(Status::Corrupt, p, sec,
                         "element block of " + std::to_string(count) + " elements with " + std::to_string(ntags) +
                             " tags (" + std::to_string(n - done) + " elements left)");
          sawTags |= ntags > 0;
          const uint64_t per = 4 * uint64_t(1 + ntags + t->nodes);
          if (Result r = need(uint64_t(count), per, sec, "element block"); !r) return r;
          for (int32_t e = 0; e < count; ++e) {
            const size_t ep = pos;
            int32_t tag = binInt();
            pos += 4 * size_t(ntags);
            for (int k = 0; k < t->nodes; ++k) nodes[k] = uint64_t(int64_t(binInt()));
            if (tag < 1)
              return error(Status::Corrupt, ep, sec, "element tag " + std::to_string(tag) + " is not positive");
            if (Result r = addElement(sec, ep, type, uint64_t(tag), nodes, t->nodes); !r) return r;
          }
          done += uint64_t(count);
        }
      }
      return finishTags(elementTags, sec, "element");
    }
    uint64_t blocks, n, minTag, maxTag;
    for (auto [v, what] : {std::pair{&blocks, "numEntityBlocks"},
                           {&n, "numElements"},
                           {&minTag, "minElementTag"},
                           {&maxTag, "maxElementTag"}})
      if (Result r = count41(sec, what, *v); !r) return r;
    if (n > left() / (binary ? 2 * uint64_t(sizeT) : 4))
      return error(Status::Truncated, pos, sec,
                   std::to_string(n) + " elements cannot fit in the " + std::to_string(left()) + " bytes left");
    soup.shapes.reserve(n);
    uint64_t seen = 0;
    for (uint64_t b = 0; b < blocks; ++b) {
      int64_t dim, entity, type;
      uint64_t inBlock;
      const size_t p = pos;
      if (Result r = int41(sec, "entityDim", dim); !r) return r;
      if (Result r = int41(sec, "entityTag", entity); !r) return r;
      if (Result r = int41(sec, "elementType", type); !r) return r;
      if (Result r = count41(sec, "numElementsInBlock", inBlock); !r) return r;
      if (inBlock > n - seen)
        return error(Status::Corrupt, p, sec,
                     "element block " + std::to_string(b) + " has " + std::to_string(inBlock) +
                         " elements, more than the " + std::to_string(n - seen) + " left of numElements " +
                         std::to_string(n));
      seen += inBlock;
      const GmshType* t = gmshType(type);
      if (!t && binary)
        return error(
            Status::Unsupported, p, sec,
            "element type " + std::to_string(type) + " is not one tetstream knows (cannot skip it in a binary file)");
      if (binary) {
        const uint64_t per = uint64_t(sizeT) * uint64_t(1 + t->nodes);
        if (Result r = need(inBlock, per, sec, "element block " + std::to_string(b)); !r) return r;
        for (uint64_t e = 0; e < inBlock; ++e) {
          const size_t ep = pos;
          uint64_t tag = binSize();
          for (int k = 0; k < t->nodes; ++k) nodes[k] = binSize();
          if (Result r = addElement(sec, ep, type, tag, nodes, t->nodes); !r) return r;
        }
      } else {
        skipSpace();
        for (uint64_t e = 0; e < inBlock; ++e) {
          const size_t ep = pos;
          uint64_t tag;
          if (Result r = textCount(sec, "element tag", tag); !r) return r;
          int count = 0;
          if (t) {
            count = t->nodes;
            for (int k = 0; k < count; ++k)
              if (Result r = textCount(sec, "element " + std::to_string(tag) + " node", nodes[k]); !r) return r;
          } else {
            line();
          }
          if (Result r = addElement(sec, ep, type, tag, nodes, count); !r) return r;
        }
      }
    }
    if (seen != n)
      return error(Status::Corrupt, pos, sec,
                   "the blocks hold " + std::to_string(seen) + " elements, numElements says " + std::to_string(n));
    return finishTags(elementTags, sec, "element");
  }

  // $NodeData / $ElementData: tags, then `count` records of (tag, components values).
  Result data(const std::string& sec, bool perNode) {
    if (perNode ? !haveNodes : !haveElements)
      return error(Status::Corrupt, pos, sec, perNode ? "$NodeData before $Nodes" : "$ElementData before $Elements");
    std::string name = "view";
    uint64_t nstr, nreal, nint;
    if (Result r = textCount(sec, "the number of string tags", nstr); !r) return r;
    if (nstr > 64) return error(Status::Corrupt, pos, sec, std::to_string(nstr) + " string tags");
    line();
    for (uint64_t i = 0; i < nstr; ++i) {
      std::string_view l = line();
      if (pos >= s.size() && l.empty()) return error(Status::Truncated, pos, sec, "file ends in the string tags");
      size_t a = l.find('"'), b = l.rfind('"');
      std::string v = a != std::string_view::npos && b > a ? std::string(l.substr(a + 1, b - a - 1)) : std::string(l);
      if (i == 0) name = v;
    }
    if (Result r = textCount(sec, "the number of real tags", nreal); !r) return r;
    if (nreal > 64) return error(Status::Corrupt, pos, sec, std::to_string(nreal) + " real tags");
    for (uint64_t i = 0; i < nreal; ++i) {
      double x;
      if (Result r = textDouble(sec, "a real tag", x); !r) return r;
    }
    if (Result r = textCount(sec, "the number of integer tags", nint); !r) return r;
    if (nint < 3 || nint > 64)
      return error(Status::Corrupt, pos, sec,
                   std::to_string(nint) + " integer tags, expected at least 3 (time step, components, count)");
    int64_t it[4] = {0, 0, 0, 0};
    for (uint64_t i = 0; i < nint; ++i) {
      int64_t x;
      if (Result r = textInt(sec, "an integer tag", x); !r) return r;
      if (i < 4) it[i] = x;
    }
    const int64_t comps = it[1], count = it[2];
    if (comps < 1 || uint64_t(comps) > kMaxComponents || count < 0)
      return error(Status::Corrupt, pos, sec,
                   "'" + printable(name) + "': " + std::to_string(comps) + " components, " + std::to_string(count) +
                       " values (expected 1.." + std::to_string(kMaxComponents) + " components)");
    const int step = dataSteps[name]++;
    const bool keep = step == 0;
    const size_t target = perNode ? positions.size() / 3 : size_t(elementCount);
    std::vector<double> tuple(static_cast<size_t>(comps));
    std::vector<double> out;
    std::vector<float> outF;
    if (keep) {
      if (perNode)
        outF.assign(target, std::numeric_limits<float>::quiet_NaN());
      else
        out.assign(target, std::numeric_limits<double>::quiet_NaN());
    }
    const std::string quoted = "'" + printable(name) + "'";
    auto store = [&](int64_t tag, size_t p) -> Result {
      const int64_t index = tag < 1 ? -1 : (perNode ? nodeTags : elementTags).find(uint64_t(tag));
      if (index < 0) {
        std::string msg = quoted;
        msg.append(" gives a value for ").append(perNode ? "node " : "element ").append(std::to_string(tag));
        return error(Status::OutOfRange, p, sec, msg + ", which does not exist");
      }
      if (!keep) return Result::success();
      double m = tuple[0];
      if (comps > 1) {
        double sq = 0;
        for (double x : tuple) sq += x * x;
        m = std::sqrt(sq);
      }
      if (perNode)
        outF[size_t(index)] = float(m);
      else
        out[size_t(index)] = m;
      return Result::success();
    };
    if (binary) {
      line();
      // Records are (int tag, doubles); Gmsh 4.1 documents size_t tags in some places, so accept
      // either, whichever lands on $End<section>.
      const uint64_t rec4 = 4 + 8 * uint64_t(comps), rec8 = uint64_t(sizeT) + 8 * uint64_t(comps);
      uint64_t rec = rec4;
      if (Result r = need(uint64_t(count), rec4, sec, "'" + printable(name) + "'"); !r) return r;
      auto endsAt = [&](uint64_t bytes) {
        size_t e = pos + size_t(bytes);
        while (e < s.size() && isSpace(s[e])) ++e;
        return s.substr(e, 4 + sec.size()) == "$End" + sec;
      };
      if (!endsAt(rec4 * uint64_t(count)) && rec8 != rec4 && rec8 * uint64_t(count) <= left() &&
          endsAt(rec8 * uint64_t(count)))
        rec = rec8;
      for (int64_t i = 0; i < count; ++i) {
        const size_t p = pos;
        int64_t tag = rec == rec4 ? int64_t(binInt()) : int64_t(binSize());
        for (double& x : tuple) x = binDouble();
        if (Result r = store(tag, p); !r) return r;
      }
    } else {
      if (uint64_t(count) > left() / 4)
        return error(Status::Truncated, pos, sec,
                     "'" + printable(name) + "' declares " + std::to_string(count) + " values, more than the " +
                         std::to_string(left()) + " bytes left can hold");
      for (int64_t i = 0; i < count; ++i) {
        const size_t p = pos;
        int64_t tag;
        if (Result r = textInt(sec, "a " + std::string(perNode ? "node" : "element") + " tag", tag); !r) return r;
        for (double& x : tuple)
          if (Result r = textDouble(sec, "'" + printable(name) + "' value", x); !r) return r;
        if (Result r = store(tag, p); !r) return r;
      }
    }
    if (keep) {
      std::string fname = fieldNameFor(name, uint32_t(comps), report, perNode ? "point" : "cell");
      if (perNode)
        fields.push_back({fname, std::move(outF)});
      else
        cellArrays.push_back({fname, std::move(out)});
    }
    return expectEnd(sec);
  }

  Result parse() {
    if (s.empty()) return fail(Status::Truncated, label + ": empty file");
    size_t start = s.substr(0, 3) == "\xEF\xBB\xBF" ? 3 : 0;
    pos = start;
    skipSpace();
    if (s.substr(pos, 11) != "$MeshFormat") {
      if (std::string_view("$MeshFormat").starts_with(s.substr(pos)))
        return fail(Status::Truncated, label + ": file ends inside '$MeshFormat'");
      return fail(Status::BadMagic, label + ": not a Gmsh file: it starts with '" +
                                        printable(s.substr(pos, std::min<size_t>(20, s.size() - pos))) +
                                        "', expected '$MeshFormat' (ANSYS/Fluent .msh files are not read)");
    }
    bool haveFormat = false;
    while (true) {
      skipSpace();
      if (pos >= s.size()) break;
      const size_t p = pos;
      if (s[pos] != '$')
        return error(
            Status::Corrupt, p, "",
            "expected a section ('$Name'), found '" + printable(s.substr(pos, std::min<size_t>(20, left()))) + "'");
      std::string name(line().substr(1));
      while (!name.empty() && isSpace(name.back())) name.pop_back();
      if (name.starts_with("End"))
        return error(Status::Corrupt, p, "", "'$" + printable(name) + "' without its section");
      if (!haveFormat && name != "MeshFormat")
        return error(Status::Corrupt, p, "", "expected $MeshFormat first, found '$" + printable(name) + "'");
      Result r;
      if (name == "MeshFormat") {
        if (haveFormat) return error(Status::Corrupt, p, name, "a second $MeshFormat");
        haveFormat = true;
        r = meshFormat();
      } else if (name == "Nodes") {
        r = nodes();
        if (r) r = expectEnd(name);
      } else if (name == "Elements") {
        r = elements();
        if (r) r = expectEnd(name);
      } else if (name == "NodeData" || name == "ElementData") {
        r = data(name, name == "NodeData");
      } else {
        if (name == "ElementNodeData")
          report.notes.push_back("skipped a $ElementNodeData section (values per element node are not read)");
        if (name == "PhysicalNames") ++physicalNames;
        r = skipSection(name);
      }
      if (!r) return r;
    }
    if (!haveNodes) return fail(Status::Truncated, label + ": file ends before $Nodes");
    if (!haveElements) return fail(Status::Truncated, label + ": file ends before $Elements");
    report.format = "Gmsh MSH " + version + (binary ? std::string(" binary") : std::string(" ASCII")) +
                    (binary && swap ? " (other byte order)" : "");
    for (const auto& [name, steps] : dataSteps)
      if (steps > 1)
        report.notes.push_back("data '" + name + "' has " + std::to_string(steps) +
                               " sections (time steps): kept the first");
    if (physicalNames || sawTags)
      report.notes.push_back("ignored physical groups and entity tags (tetstream reads the mesh and its data only)");
    return Result::success();
  }
};

}  // namespace

Result readGmsh(std::string_view bytes, const std::string& label, TetMesh& out, ReadReport& report) {
  out = TetMesh{};
  Gmsh g(label, bytes, report);
  if (Result r = g.parse(); !r) return r;
  TetMesh mesh;
  mesh.positions = std::move(g.positions);
  for (ScalarField& f : g.fields) addField(mesh, std::move(f), report);
  g.soup.inputCells = g.elementCount;
  if (Result r = finishMesh(label, mesh, g.soup, std::move(g.cellArrays), report); !r) return r;
  out = std::move(mesh);
  return Result::success();
}

}  // namespace tetstream
