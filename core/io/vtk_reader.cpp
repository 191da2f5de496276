// Legacy VTK reader (DATASET UNSTRUCTURED_GRID, STRUCTURED_POINTS, STRUCTURED_GRID,
// RECTILINEAR_GRID). Reference: "VTK File Formats", legacy section
// (https://docs.vtk.org/en/latest/design_documents/VTKFileFormats.html) and vtkDataReader.
//
// The file is keyword lines ("POINTS 27 float") each followed by its values: whitespace-separated
// text in ASCII files, packed big-endian values starting right after the keyword line's '\n' in
// BINARY files. Cells come in two layouts: classic "CELLS n size" (per cell: count, ids) and the
// 5.1 "CELLS nOffsets nConnectivity" followed by OFFSETS and CONNECTIVITY arrays (VTK 9, meshio 5).
// VTK 9 follows arrays with "METADATA" blocks that end at an empty line; they are skipped.
// Structured datasets have no cells in the file: DIMENSIONS nx ny nz gives (nx-1)(ny-1)(nz-1)
// hexahedra over points numbered x fastest, from ORIGIN/SPACING (STRUCTURED_POINTS), POINTS
// (STRUCTURED_GRID) or X/Y/Z_COORDINATES (RECTILINEAR_GRID). Cell data becomes point data.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <set>

#include "io/readers.h"

namespace tetstream {
namespace {

using namespace vtkio;

// VTK writes names with %XX escapes for spaces and other special characters.
std::string decodeName(std::string_view s) {
  auto hex = [](char c) -> int {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
  };
  std::string out;
  for (size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '%' && i + 2 < s.size() && hex(s[i + 1]) >= 0 && hex(s[i + 2]) >= 0) {
      out += char(hex(s[i + 1]) * 16 + hex(s[i + 2]));
      i += 2;
    } else {
      out += s[i];
    }
  }
  return out;
}

std::vector<std::string_view> split(std::string_view line) {
  std::vector<std::string_view> out;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && isSpace(line[i])) ++i;
    size_t b = i;
    while (i < line.size() && !isSpace(line[i])) ++i;
    if (i > b) out.push_back(line.substr(b, i - b));
  }
  return out;
}

// A legacy data type name: the numeric types, "bit" (packed, MSB first) and the string types we
// can neither read nor skip safely.
struct LegacyType {
  ScalarType scalar = ScalarType::Float32;
  bool bit = false;
  bool string = false;
};

bool parseLegacyType(std::string_view n, LegacyType& t) {
  struct Entry {
    const char* name;
    ScalarType type;
  };
  // "long" is 8 bytes as VTK writes it on LP64 systems; "vtkIdType" is written as 32-bit int.
  static constexpr Entry kTypes[] = {
      {"unsigned_char", ScalarType::UInt8},    {"char", ScalarType::Int8},
      {"signed_char", ScalarType::Int8},       {"short", ScalarType::Int16},
      {"unsigned_short", ScalarType::UInt16},  {"int", ScalarType::Int32},
      {"unsigned_int", ScalarType::UInt32},    {"long", ScalarType::Int64},
      {"unsigned_long", ScalarType::UInt64},   {"vtkIdType", ScalarType::Int32},
      {"float", ScalarType::Float32},          {"double", ScalarType::Float64},
      {"vtktypeint8", ScalarType::Int8},       {"vtktypeuint8", ScalarType::UInt8},
      {"vtktypeint16", ScalarType::Int16},     {"vtktypeuint16", ScalarType::UInt16},
      {"vtktypeint32", ScalarType::Int32},     {"vtktypeuint32", ScalarType::UInt32},
      {"vtktypeint64", ScalarType::Int64},     {"vtktypeuint64", ScalarType::UInt64},
      {"vtktypefloat32", ScalarType::Float32}, {"vtktypefloat64", ScalarType::Float64},
  };
  t = {};
  if (iequals(n, "bit")) {
    t.bit = true;
    return true;
  }
  if (iequals(n, "string") || iequals(n, "utf8_string") || iequals(n, "variant")) {
    t.string = true;
    return true;
  }
  for (const Entry& e : kTypes)
    if (iequals(n, e.name)) {
      t.scalar = e.type;
      return true;
    }
  return false;
}

enum class Section { Dataset, PointData, CellData };
enum class Kind { Unstructured, StructuredPoints, StructuredGrid, Rectilinear };

struct Legacy {
  std::string label;
  std::string_view s;
  size_t pos = 0;
  bool binary = false;
  ReadReport& report;

  // What has been read.
  bool haveDataset = false, havePoints = false, haveCells = false, haveTypes = false, newCellLayout = false;
  Kind kind = Kind::Unstructured;
  bool haveDims = false, haveOrigin = false, haveSpacing = false;
  uint64_t dims[3] = {0, 0, 0};
  double origin[3] = {0, 0, 0}, spacing[3] = {1, 1, 1};
  std::vector<double> axis[3];  // RECTILINEAR_GRID coordinates
  uint64_t pointCount = 0, cellCount = 0;
  std::vector<float> positions;
  std::vector<int64_t> connectivity, offsets, types;
  std::vector<ScalarField> fields;
  std::vector<CellArray> cellArrays;
  std::vector<std::string> skippedArrays;
  MeshPiece partition;  // the arrays that describe the partition (vtkGhostType, GLOBAL_IDS)
  Section section = Section::Dataset;
  uint64_t sectionCount = 0;

  Legacy(std::string l, std::string_view bytes, ReadReport& r) : label(std::move(l)), s(bytes), report(r) {}

  // "line 12" in ASCII files; a byte offset in BINARY files, where newlines in the data make line
  // numbers meaningless.
  std::string at(size_t p) const {
    if (binary) return "byte " + std::to_string(p);
    return "line " + std::to_string(1 + std::count(s.begin(), s.begin() + std::ptrdiff_t(std::min(p, s.size())), '\n'));
  }

  // Writers end every line, the last one included, with '\n'. Malformed text on an unterminated
  // last line means the file was cut there, and the status says so.
  Result error(Status st, size_t p, const std::string& msg) const {
    if (st == Status::Corrupt && !s.empty() && s.back() != '\n' &&
        s.find('\n', std::min(pos, s.size())) == std::string_view::npos)
      return fail(Status::Truncated, label + " " + at(p) + ": " + msg + " (the file ends in this line)");
    return fail(st, label + " " + at(p) + ": " + msg);
  }

  void skipSpace() { vtkio::skipSpace(s, pos); }
  std::string_view token() { return nextToken(s, pos); }      // empty at the end of the file
  std::string_view restOfLine() { return nextLine(s, pos); }  // binary data starts after it

  bool peekKeyword(const char* kw) {
    size_t save = pos;
    bool yes = iequals(token(), kw);
    pos = save;
    return yes;
  }

  // Reads `count` values of type t at pos into *out (nullptr: skip them).
  template <class T>
  Result readValues(const LegacyType& t, uint64_t count, const std::string& what, std::vector<T>* out) {
    constexpr bool wantInts = std::is_same_v<T, int64_t>;
    const size_t start = pos;
    if (t.string) return error(Status::Unsupported, start, what + " is a string array, which tetstream cannot read");
    if (wantInts && !t.bit && !isIntegerType(t.scalar))
      return error(Status::Corrupt, start, what + " must hold integers, found " + scalarTypeName(t.scalar));
    const uint64_t left = s.size() - pos;
    if (binary) {
      uint64_t bytes;
      if (t.bit)
        bytes = count / 8 + (count % 8 != 0);
      else if (__builtin_mul_overflow(count, uint64_t(scalarSize(t.scalar)), &bytes))
        bytes = UINT64_MAX;
      if (bytes > left)
        return error(Status::Truncated, start,
                     what + ": needs " + std::to_string(bytes) + " bytes for " + std::to_string(count) +
                         " values, only " + std::to_string(left) + " remain");
      const uint8_t* src = reinterpret_cast<const uint8_t*>(s.data() + pos);
      if (out) {
        out->resize(count);
        if (t.bit) {
          for (uint64_t i = 0; i < count; ++i) (*out)[i] = T((src[i / 8] >> (7 - i % 8)) & 1);
        } else if constexpr (wantInts) {
          size_t ok = decodeInts(src, count, t.scalar, true, out->data());
          if (ok != count)
            return error(Status::OutOfRange, start,
                         what + ": value " + std::to_string(ok) + " exceeds the Int64 range");
        } else {
          decodeDoubles(src, count, t.scalar, true, out->data());
        }
      }
      pos += bytes;
      return Result::success();
    }
    // ASCII: every value needs at least one character, so a count beyond the bytes left is a lie.
    if (count > left)
      return error(
          Status::Truncated, start,
          what + ": declares " + std::to_string(count) + " values but only " + std::to_string(left) + " bytes remain");
    if (out) {
      out->clear();
      out->reserve(count);
    }
    for (uint64_t i = 0; i < count; ++i) {
      int r;
      T v;
      if constexpr (wantInts)
        r = parseNextInt(s, pos, v);
      else {
        r = parseNextDouble(s, pos, v);
      }
      if (r == 0)
        return error(Status::Truncated, start,
                     what + ": file ends after " + std::to_string(i) + " of " + std::to_string(count) + " values");
      if (r < 0) {
        std::string_view tok = s.substr(pos);
        tok = tok.substr(
            0, std::min<size_t>(tok.size(), size_t(std::find_if(tok.begin(), tok.end(), isSpace) - tok.begin())));
        return error(Status::Corrupt, pos,
                     what + ": value " + std::to_string(i) + " '" + printable(tok) + "' is not " +
                         (wantInts ? "an integer" : "a number"));
      }
      if (out) out->push_back(v);
    }
    return Result::success();
  }

  Result parseType(std::string_view name, size_t p, LegacyType& t) const {
    if (!parseLegacyType(name, t)) return error(Status::Corrupt, p, "unknown data type '" + printable(name) + "'");
    return Result::success();
  }

  Result parseCount(std::string_view tok, size_t p, const char* what, uint64_t& n) const {
    if (!parseU64(tok, n))
      return error(Status::Corrupt, p, std::string(what) + " '" + printable(tok) + "' is not a non-negative integer");
    return Result::success();
  }

  // VTK 9 follows arrays with "METADATA" and lines up to an empty one; call after the METADATA line.
  void skipMetadata() {
    while (pos < s.size()) {
      std::string_view line = restOfLine();
      if (split(line).empty()) break;
    }
  }

  void skipMetadataIfPresent() {
    if (!peekKeyword("METADATA")) return;
    token();
    restOfLine();
    skipMetadata();
  }

  Result readPoints(const std::vector<std::string_view>& a, size_t p) {
    if (!haveDataset) return error(Status::Corrupt, p, "POINTS before DATASET");
    if (havePoints) return error(Status::Corrupt, p, "a second POINTS section");
    if (a.size() < 2) return error(Status::Corrupt, p, "POINTS needs a count and a type");
    LegacyType t;
    if (Result r = parseCount(a[0], p, "POINTS count", pointCount); !r) return r;
    if (pointCount > kMaxVertices)
      return error(Status::TooLarge, p,
                   std::to_string(pointCount) + " points; tetstream indexes vertices with 32 bits");
    if (Result r = parseType(a[1], p, t); !r) return r;
    std::vector<double> v;
    if (Result r = readValues<double>(t, pointCount * 3, "POINTS", &v); !r) return r;
    positions.assign(v.begin(), v.end());
    havePoints = true;
    return Result::success();
  }

  uint64_t structuredCellCount() const {
    if (!haveDims) return 0;
    uint64_t n = 1;
    for (uint64_t d : dims) n *= d > 1 ? d - 1 : 0;
    return n;
  }

  // The structured dataset's mesh is complete once its points are known.
  bool meshComplete() const {
    switch (kind) {
      case Kind::Unstructured: return havePoints && haveCells && haveTypes;
      case Kind::StructuredPoints: return haveDims;
      case Kind::StructuredGrid: return haveDims && havePoints;
      case Kind::Rectilinear: return haveDims && !axis[0].empty() && !axis[1].empty() && !axis[2].empty();
    }
    return false;
  }

  Result readDimensions(const std::vector<std::string_view>& a, size_t p) {
    if (haveDims) return error(Status::Corrupt, p, "a second DIMENSIONS");
    if (a.size() < 3) return error(Status::Corrupt, p, "DIMENSIONS needs three counts");
    uint64_t n = 1;
    for (int k = 0; k < 3; ++k) {
      if (Result r = parseCount(a[size_t(k)], p, "DIMENSIONS", dims[k]); !r) return r;
      if (dims[k] == 0) return error(Status::Corrupt, p, "DIMENSIONS has a zero count");
      if (__builtin_mul_overflow(n, dims[k], &n) || n > kMaxVertices)
        return error(Status::TooLarge, p,
                     "DIMENSIONS " + std::string(a[0]) + " " + std::string(a[1]) + " " + std::string(a[2]) +
                         ": more than 2^32-1 points; tetstream indexes vertices with 32 bits");
    }
    // STRUCTURED_POINTS stores no coordinates: a huge grid in a tiny file is a lie until its point
    // data arrives, so cap what the file size can justify (16 points per byte, at least 2^20).
    if (kind == Kind::StructuredPoints && n > std::max<uint64_t>(uint64_t(1) << 20, 16 * uint64_t(s.size())))
      return error(Status::Truncated, p,
                   "DIMENSIONS declares " + std::to_string(n) + " points, far more than a file of " +
                       std::to_string(s.size()) + " bytes can carry data for");
    if (havePoints && n != pointCount)
      return error(Status::Corrupt, p,
                   "DIMENSIONS gives " + std::to_string(n) + " points, POINTS has " + std::to_string(pointCount));
    pointCount = n;
    haveDims = true;
    return Result::success();
  }

  Result readTriple(std::string_view kw, const std::vector<std::string_view>& a, size_t p) {
    if (a.size() < 3) return error(Status::Corrupt, p, std::string(kw) + " needs three numbers");
    double v[3];
    for (int k = 0; k < 3; ++k) {
      size_t q = 0;
      if (parseNextDouble(a[size_t(k)], q, v[k]) != 1 || !std::isfinite(v[k]))
        return error(Status::Corrupt, p,
                     std::string(kw) + ": '" + printable(a[size_t(k)]) + "' is not a finite number");
    }
    double* dst = iequals(kw, "ORIGIN") ? origin : spacing;
    std::copy(v, v + 3, dst);
    (iequals(kw, "ORIGIN") ? haveOrigin : haveSpacing) = true;
    return Result::success();
  }

  Result readAxis(std::string_view kw, const std::vector<std::string_view>& a, size_t p) {
    const int k = kw[0] == 'X' || kw[0] == 'x' ? 0 : kw[0] == 'Y' || kw[0] == 'y' ? 1 : 2;
    if (!axis[k].empty()) return error(Status::Corrupt, p, "a second " + std::string(kw));
    if (a.size() < 2) return error(Status::Corrupt, p, std::string(kw) + " needs a count and a type");
    uint64_t n;
    LegacyType t;
    if (Result r = parseCount(a[0], p, std::string(kw).c_str(), n); !r) return r;
    if (Result r = parseType(a[1], p, t); !r) return r;
    if (haveDims && n != dims[k])
      return error(
          Status::Corrupt, p,
          std::string(kw) + " has " + std::to_string(n) + " values, DIMENSIONS says " + std::to_string(dims[k]));
    if (n == 0) return error(Status::Corrupt, p, std::string(kw) + " is empty");
    return readValues<double>(t, n, std::string(kw), &axis[k]);
  }

  Result readCells(const std::vector<std::string_view>& a, size_t p) {
    if (!haveDataset) return error(Status::Corrupt, p, "CELLS before DATASET");
    if (haveCells) return error(Status::Corrupt, p, "a second CELLS section");
    if (a.size() < 2) return error(Status::Corrupt, p, "CELLS needs two counts");
    uint64_t n0, n1;
    if (Result r = parseCount(a[0], p, "CELLS count", n0); !r) return r;
    if (Result r = parseCount(a[1], p, "CELLS size", n1); !r) return r;
    haveCells = true;
    if (peekKeyword("OFFSETS")) {
      // 5.1 layout: n0 offsets (cells + 1), n1 connectivity ids.
      newCellLayout = true;
      for (const char* kw : {"OFFSETS", "CONNECTIVITY"}) {
        skipSpace();
        size_t kp = pos;
        std::string_view k = token();
        if (k.empty()) return error(Status::Truncated, kp, std::string("file ends before ") + kw);
        if (!iequals(k, kw))
          return error(Status::Corrupt, kp, std::string("expected ") + kw + ", found '" + printable(k) + "'");
        std::vector<std::string_view> ta = split(restOfLine());
        LegacyType t;
        if (ta.empty()) return error(Status::Corrupt, kp, std::string(kw) + " needs a data type");
        if (Result r = parseType(ta[0], kp, t); !r) return r;
        bool isOff = kw[0] == 'O';
        if (Result r = readValues<int64_t>(t, isOff ? n0 : n1, kw, isOff ? &offsets : &connectivity); !r) return r;
        skipMetadataIfPresent();
      }
      cellCount = n0 == 0 ? 0 : n0 - 1;
      if (n0 == 0) offsets.assign(1, 0);
      return Result::success();
    }
    // Classic layout: n0 cells written as "count id id ...", n1 integers in all.
    std::vector<int64_t> list;
    LegacyType t;
    t.scalar = ScalarType::Int32;
    if (Result r = readValues<int64_t>(t, n1, "CELLS", &list); !r) return r;
    if (n0 > n1)
      return error(Status::Corrupt, p,
                   "CELLS declares " + std::to_string(n0) + " cells in only " + std::to_string(n1) + " integers");
    offsets.reserve(n0 + 1);
    connectivity.reserve(n1 - n0);
    size_t q = 0;
    for (uint64_t c = 0; c < n0; ++c) {
      offsets.push_back(int64_t(connectivity.size()));
      if (q >= list.size())
        return error(Status::Corrupt, p,
                     "CELLS: cell " + std::to_string(c) + " starts after the last of the " +
                         std::to_string(list.size()) + " integers");
      int64_t k = list[q];
      if (k < 0 || uint64_t(k) > list.size() - q - 1)
        return error(Status::Corrupt, p,
                     "CELLS: cell " + std::to_string(c) + " declares " + std::to_string(k) + " points but only " +
                         std::to_string(list.size() - q - 1) + " integers remain");
      connectivity.insert(connectivity.end(), list.begin() + std::ptrdiff_t(q + 1),
                          list.begin() + std::ptrdiff_t(q + 1 + size_t(k)));
      q += 1 + size_t(k);
    }
    offsets.push_back(int64_t(connectivity.size()));
    if (q != list.size())
      return error(Status::Corrupt, p,
                   "CELLS: " + std::to_string(n0) + " cells use " + std::to_string(q) + " of the " +
                       std::to_string(list.size()) + " declared integers");
    cellCount = n0;
    return Result::success();
  }

  Result readCellTypes(const std::vector<std::string_view>& a, size_t p) {
    if (!haveDataset) return error(Status::Corrupt, p, "CELL_TYPES before DATASET");
    if (haveTypes) return error(Status::Corrupt, p, "a second CELL_TYPES section");
    uint64_t n;
    if (a.empty()) return error(Status::Corrupt, p, "CELL_TYPES needs a count");
    if (Result r = parseCount(a[0], p, "CELL_TYPES count", n); !r) return r;
    LegacyType t;
    t.scalar = ScalarType::Int32;
    if (Result r = readValues<int64_t>(t, n, "CELL_TYPES", &types); !r) return r;
    haveTypes = true;
    return Result::success();
  }

  // Keeps or skips one attribute array of `tuples` x `comps` values.
  // GLOBAL_IDS sections are global ids whatever their name; other arrays by their name.
  Result attributeArray(const std::string& name, const LegacyType& t, uint64_t tuples, uint64_t comps,
                        const std::string& what, bool convertible, bool globalIds = false) {
    const PartitionArray partitionKind =
        globalIds ? (section == Section::CellData ? PartitionArray::CellIds : PartitionArray::PointIds)
                  : partitionArrayKind(name, section == Section::CellData);
    if (comps == 0 || comps > kMaxComponents)
      return error(
          Status::Corrupt, pos,
          what + " has " + std::to_string(comps) + " components (expected 1.." + std::to_string(kMaxComponents) + ")");
    uint64_t count;
    if (__builtin_mul_overflow(tuples, comps, &count))
      return error(Status::TooLarge, pos, what + ": value count overflows");
    const bool cellSection = section == Section::CellData;
    if (partitionKind != PartitionArray::None && section != Section::Dataset &&
        tuples == (cellSection ? sectionCount : pointCount)) {
      const std::string where = label + " " + at(pos) + ": " + what;
      std::vector<double> v;
      if (Result r = readValues<double>(t, count, what, &v); !r) return r;
      return takePartitionArray(partitionKind, name, where, v, comps, cellSection, partition);
    }
    bool keep = convertible &&
                ((section == Section::PointData && tuples == pointCount) || (cellSection && tuples == sectionCount));
    if (!keep) {
      skippedArrays.push_back(what);
      return readValues<double>(t, count, what, nullptr);
    }
    std::vector<double> v;
    if (Result r = readValues<double>(t, count, what, &v); !r) return r;
    if (cellSection) {
      std::vector<float> scalars = tuplesToScalars(v, uint32_t(comps));
      cellArrays.push_back(
          {fieldNameFor(name, uint32_t(comps), report, "cell"), std::vector<double>(scalars.begin(), scalars.end())});
      return Result::success();
    }
    ScalarField f{fieldNameFor(name, uint32_t(comps), report), tuplesToScalars(v, uint32_t(comps))};
    fields.push_back(std::move(f));
    return Result::success();
  }

  Result readField(const std::vector<std::string_view>& a, size_t p) {
    if (a.size() < 2) return error(Status::Corrupt, p, "FIELD needs a name and an array count");
    uint64_t n;
    if (Result r = parseCount(a[1], p, "FIELD array count", n); !r) return r;
    for (uint64_t i = 0; i < n; ++i) {
      skipSpace();
      size_t ap = pos;
      std::string_view first = token();
      if (first.empty())
        return error(Status::Truncated, ap,
                     "file ends after " + std::to_string(i) + " of " + std::to_string(n) + " FIELD arrays");
      if (iequals(first, "NULL_ARRAY")) {
        restOfLine();
        continue;
      }
      std::vector<std::string_view> rest = split(restOfLine());
      if (rest.size() < 3) return error(Status::Corrupt, ap, "FIELD array needs: name components tuples type");
      uint64_t comps, tuples;
      LegacyType t;
      if (Result r = parseCount(rest[0], ap, "FIELD array components", comps); !r) return r;
      if (Result r = parseCount(rest[1], ap, "FIELD array tuples", tuples); !r) return r;
      if (Result r = parseType(rest[2], ap, t); !r) return r;
      std::string name = decodeName(first);
      bool dataset = section == Section::Dataset;
      if (Result r = attributeArray(name, t, tuples, comps, "FIELD array '" + name + "'", !dataset && !t.bit); !r)
        return r;
      skipMetadataIfPresent();
    }
    return Result::success();
  }

  // SCALARS, VECTORS, ... in a POINT_DATA or CELL_DATA section.
  Result readAttribute(std::string_view kw, const std::vector<std::string_view>& a, size_t p) {
    if (section == Section::Dataset)
      return error(Status::Corrupt, p, std::string(kw) + " outside POINT_DATA / CELL_DATA");
    const uint64_t n = sectionCount;
    auto need = [&](size_t k) {
      return a.size() < k ? error(Status::Corrupt, p, std::string(kw) + " needs " + std::to_string(k) + " arguments")
                          : Result::success();
    };
    LegacyType t;
    if (iequals(kw, "SCALARS")) {
      if (Result r = need(2); !r) return r;
      if (Result r = parseType(a[1], p, t); !r) return r;
      uint64_t comps = 1;
      if (a.size() >= 3 && !parseU64(a[2], comps))
        return error(Status::Corrupt, p, "SCALARS component count '" + printable(a[2]) + "'");
      if (peekKeyword("LOOKUP_TABLE")) {
        token();
        restOfLine();
      }
      std::string name = decodeName(a[0]);
      return attributeArray(name, t, n, comps, "SCALARS '" + name + "'", !t.bit);
    }
    if (iequals(kw, "VECTORS") || iequals(kw, "NORMALS") || iequals(kw, "TENSORS") || iequals(kw, "TENSORS6")) {
      if (Result r = need(2); !r) return r;
      if (Result r = parseType(a[1], p, t); !r) return r;
      uint64_t comps = iequals(kw, "TENSORS") ? 9 : iequals(kw, "TENSORS6") ? 6 : 3;
      std::string name = decodeName(a[0]);
      return attributeArray(name, t, n, comps, std::string(kw) + " '" + name + "'", true);
    }
    if (iequals(kw, "GLOBAL_IDS") || iequals(kw, "PEDIGREE_IDS") || iequals(kw, "EDGE_FLAGS")) {
      if (Result r = need(2); !r) return r;
      if (Result r = parseType(a[1], p, t); !r) return r;
      return attributeArray(decodeName(a[0]), t, n, 1, std::string(kw) + " '" + decodeName(a[0]) + "'", false,
                            iequals(kw, "GLOBAL_IDS"));
    }
    if (iequals(kw, "TEXTURE_COORDINATES")) {
      if (Result r = need(3); !r) return r;
      uint64_t dim;
      if (Result r = parseCount(a[1], p, "TEXTURE_COORDINATES dimension", dim); !r) return r;
      if (Result r = parseType(a[2], p, t); !r) return r;
      return attributeArray(decodeName(a[0]), t, n, dim, "TEXTURE_COORDINATES '" + decodeName(a[0]) + "'", false);
    }
    // COLOR_SCALARS name nValues / LOOKUP_TABLE name size: floats in ASCII, unsigned chars in BINARY.
    bool color = iequals(kw, "COLOR_SCALARS");
    if (Result r = need(2); !r) return r;
    uint64_t k;
    if (Result r = parseCount(a[1], p, color ? "COLOR_SCALARS component count" : "LOOKUP_TABLE size", k); !r) return r;
    t.scalar = binary ? ScalarType::UInt8 : ScalarType::Float32;
    return attributeArray(decodeName(a[0]), t, color ? n : k, color ? k : 4,
                          std::string(kw) + " '" + decodeName(a[0]) + "'", false);
  }

  // One keyword line (already split into kw and args a) and the values that follow it.
  Result keyword(std::string_view kw, const std::vector<std::string_view>& a, size_t kp) {
    if (iequals(kw, "DATASET")) {
      if (a.empty()) return error(Status::Corrupt, kp, "DATASET needs a type");
      if (haveDataset) return error(Status::Corrupt, kp, "a second DATASET");
      if (iequals(a[0], "UNSTRUCTURED_GRID"))
        kind = Kind::Unstructured;
      else if (iequals(a[0], "STRUCTURED_POINTS"))
        kind = Kind::StructuredPoints;
      else if (iequals(a[0], "STRUCTURED_GRID"))
        kind = Kind::StructuredGrid;
      else if (iequals(a[0], "RECTILINEAR_GRID"))
        kind = Kind::Rectilinear;
      else
        return error(Status::Unsupported, kp,
                     "DATASET " + printable(a[0]) +
                         " is not supported; tetstream reads UNSTRUCTURED_GRID, STRUCTURED_POINTS, STRUCTURED_GRID "
                         "and RECTILINEAR_GRID");
      haveDataset = true;
      return Result::success();
    }
    if (!haveDataset) return error(Status::Corrupt, kp, "expected DATASET, found '" + printable(kw) + "'");
    const bool structured = kind != Kind::Unstructured;
    if (iequals(kw, "DIMENSIONS") && structured) return readDimensions(a, kp);
    if ((iequals(kw, "ORIGIN") || iequals(kw, "SPACING") || iequals(kw, "ASPECT_RATIO")) &&
        kind == Kind::StructuredPoints)
      return readTriple(kw, a, kp);
    if ((iequals(kw, "X_COORDINATES") || iequals(kw, "Y_COORDINATES") || iequals(kw, "Z_COORDINATES")) &&
        kind == Kind::Rectilinear)
      return readAxis(kw, a, kp);
    if (iequals(kw, "POINTS") && (kind == Kind::Unstructured || kind == Kind::StructuredGrid)) return readPoints(a, kp);
    if ((iequals(kw, "CELLS") || iequals(kw, "CELL_TYPES")) && structured)
      return error(Status::Corrupt, kp, std::string(kw) + " in a structured dataset");
    if (iequals(kw, "CELLS")) return readCells(a, kp);
    if (iequals(kw, "CELL_TYPES")) return readCellTypes(a, kp);
    if (iequals(kw, "POINT_DATA") || iequals(kw, "CELL_DATA")) {
      bool pd = iequals(kw, "POINT_DATA");
      if (a.empty() || !parseU64(a[0], sectionCount))
        return error(Status::Corrupt, kp, std::string(kw) + " needs a count");
      if (pd && (havePoints || haveDims) && sectionCount != pointCount)
        return error(
            Status::Corrupt, kp,
            "POINT_DATA " + std::to_string(sectionCount) + " but there are " + std::to_string(pointCount) + " points");
      const uint64_t cells = structured ? structuredCellCount() : cellCount;
      if (!pd && (haveCells || haveDims) && sectionCount != cells)
        return error(
            Status::Corrupt, kp,
            "CELL_DATA " + std::to_string(sectionCount) + " but there are " + std::to_string(cells) + " cells");
      section = pd ? Section::PointData : Section::CellData;
      return Result::success();
    }
    if (iequals(kw, "FIELD")) return readField(a, kp);
    if (iequals(kw, "METADATA")) {
      skipMetadata();
      return Result::success();
    }
    for (const char* attr : {"SCALARS", "VECTORS", "NORMALS", "TENSORS", "TENSORS6", "GLOBAL_IDS", "PEDIGREE_IDS",
                             "EDGE_FLAGS", "TEXTURE_COORDINATES", "COLOR_SCALARS", "LOOKUP_TABLE"})
      if (iequals(kw, attr)) return readAttribute(kw, a, kp);
    return error(Status::Corrupt, kp, "unknown keyword '" + printable(kw) + "'");
  }

  Result parse() {
    // Header: magic + version, title, ASCII|BINARY.
    if (s.empty()) return fail(Status::Truncated, label + ": empty file");
    std::string_view l1 = restOfLine();
    constexpr std::string_view kMagic = "# vtk DataFile Version";
    if (pos >= s.size() && l1.size() < kMagic.size() && kMagic.starts_with(l1))
      return fail(Status::Truncated, label + ": file ends inside the '# vtk DataFile Version' line");
    if (l1.size() < kMagic.size() || !iequals(l1.substr(0, kMagic.size()), kMagic)) {
      std::string hint = l1.substr(0, 1) == "<" ? " (it looks like VTK XML; name it .vtu)" : "";
      return fail(s.empty() ? Status::Truncated : Status::BadMagic,
                  label + ": not a legacy VTK file: first line '" + printable(l1) +
                      "', expected '# vtk DataFile Version x.x'" + hint);
    }
    std::vector<std::string_view> v = split(l1.substr(kMagic.size()));
    std::string version = v.empty() ? std::string("?") : std::string(v[0]);
    uint64_t major = 0;
    if (!v.empty() && parseU64(v[0].substr(0, v[0].find('.')), major) && major > 5)
      return fail(Status::UnsupportedVersion,
                  label + ": legacy VTK version " + printable(v[0]) + " (tetstream reads up to 5.1)");
    if (pos >= s.size()) return fail(Status::Truncated, label + ": file ends after the first line");
    restOfLine();  // title
    // vtkDataReader reads the file type as a word: blank lines before it are allowed.
    size_t mp = pos;
    std::vector<std::string_view> mode = split(restOfLine());
    while (mode.empty() && pos < s.size()) {
      mp = pos;
      mode = split(restOfLine());
    }
    if (mode.empty()) return error(Status::Truncated, mp, "file ends before ASCII/BINARY");
    if (iequals(mode[0], "BINARY"))
      binary = true;
    else if (!iequals(mode[0], "ASCII"))
      return error(Status::Corrupt, mp, "expected ASCII or BINARY, found '" + printable(mode[0]) + "'");

    while (true) {
      skipSpace();
      size_t kp = pos;
      std::string_view kw = token();
      if (kw.empty()) break;
      std::vector<std::string_view> a = split(restOfLine());
      Result r = keyword(kw, a, kp);
      if (r) continue;
      // A string array cannot be skipped (its length is not declared up front); once the mesh
      // itself is complete, keep what we have rather than refuse the file.
      if (r.status == Status::Unsupported && section != Section::Dataset && meshComplete()) {
        report.notes.push_back("stopped reading attributes: " + r.message.substr(label.size() + 1) +
                               "; later arrays are ignored");
        break;
      }
      return r;
    }
    if (!haveDataset) return fail(Status::Truncated, label + ": file ends before DATASET");
    if (kind != Kind::Unstructured) {
      if (!haveDims) return fail(Status::Truncated, label + ": file ends before DIMENSIONS");
      if (kind == Kind::StructuredGrid && !havePoints)
        return fail(Status::Truncated, label + ": file ends before POINTS");
      if (kind == Kind::Rectilinear)
        for (int k = 0; k < 3; ++k)
          if (axis[k].empty())
            return fail(Status::Truncated, label + ": file ends before " + "XYZ"[k] + std::string("_COORDINATES"));
      if (kind == Kind::StructuredGrid && pointCount != dims[0] * dims[1] * dims[2])
        return fail(Status::Corrupt, label + ": POINTS has " + std::to_string(pointCount) + " points, DIMENSIONS " +
                                         std::to_string(dims[0] * dims[1] * dims[2]));
      static constexpr const char* kKinds[] = {"", "STRUCTURED_POINTS", "STRUCTURED_GRID", "RECTILINEAR_GRID"};
      report.format = std::string("legacy VTK ") + version + " (" + (binary ? "BINARY" : "ASCII") + ", " +
                      kKinds[int(kind)] + " " + std::to_string(dims[0]) + "x" + std::to_string(dims[1]) + "x" +
                      std::to_string(dims[2]) + ")";
      return Result::success();
    }
    if (!havePoints) return fail(Status::Truncated, label + ": file ends before POINTS");
    if (haveCells && !haveTypes) return fail(Status::Truncated, label + ": file has CELLS but ends before CELL_TYPES");
    if (haveTypes && !haveCells) return fail(Status::Corrupt, label + ": CELL_TYPES without CELLS");
    if (haveTypes && types.size() != cellCount)
      return fail(Status::Corrupt, label + ": CELL_TYPES lists " + std::to_string(types.size()) + " cells, CELLS has " +
                                       std::to_string(cellCount));
    report.format = std::string("legacy VTK ") + version + " (" + (binary ? "BINARY" : "ASCII") +
                    (haveCells ? (newCellLayout ? ", OFFSETS/CONNECTIVITY cells" : ", classic CELLS") : "") + ")";
    return Result::success();
  }
};

}  // namespace

Result vtkio::readLegacyVtkPiece(std::string_view bytes, const std::string& label, MeshPiece& piece,
                                 ReadReport& report) {
  piece = MeshPiece{};
  Legacy lg(label, bytes, report);
  if (Result r = lg.parse(); !r) return r;

  TetMesh& mesh = piece.mesh;
  CellSoup& soup = piece.soup;
  if (lg.kind == Kind::Unstructured) {
    if (!lg.haveCells)
      return fail(Status::NoTets,
                  label + ": no CELLS section (" + std::to_string(lg.pointCount) + " points and no cells)");
    mesh.positions = std::move(lg.positions);
    if (lg.offsets.empty()) lg.offsets.push_back(0);
    if (Result r = appendVtkCells(label, lg.connectivity, lg.offsets, lg.types, 0, lg.pointCount, soup); !r) return r;
  } else {
    const uint64_t nx = lg.dims[0], ny = lg.dims[1], nz = lg.dims[2];
    if (nx < 2 || ny < 2 || nz < 2)
      return fail(Status::NoTets, label + ": DIMENSIONS " + std::to_string(nx) + " " + std::to_string(ny) + " " +
                                      std::to_string(nz) + " is not a 3D grid (no volume cells)");
    if (lg.kind == Kind::StructuredGrid) {
      mesh.positions = std::move(lg.positions);
    } else {
      mesh.positions.resize(3 * lg.pointCount);
      for (uint64_t k = 0, v = 0; k < nz; ++k)
        for (uint64_t j = 0; j < ny; ++j)
          for (uint64_t i = 0; i < nx; ++i, ++v) {
            const uint64_t ijk[3] = {i, j, k};
            for (int c = 0; c < 3; ++c)
              mesh.positions[3 * v + c] = float(
                  lg.kind == Kind::Rectilinear ? lg.axis[c][ijk[c]] : lg.origin[c] + lg.spacing[c] * double(ijk[c]));
          }
    }
    appendStructuredCells(nx, ny, nz, 0, 0, soup);
    soup.inputCells = lg.structuredCellCount();
  }
  mesh.fields = std::move(lg.fields);
  piece.cellArrays = std::move(lg.cellArrays);
  piece.pointGhost = std::move(lg.partition.pointGhost);
  piece.cellGhost = std::move(lg.partition.cellGhost);
  piece.globalIds = std::move(lg.partition.globalIds);
  piece.globalIdsName = std::move(lg.partition.globalIdsName);
  piece.where = label;
  for (const std::string& w : lg.skippedArrays) report.notes.push_back("skipped " + w);
  return Result::success();
}

Result readLegacyVtk(std::string_view bytes, const std::string& label, TetMesh& out, ReadReport& report) {
  out = TetMesh{};
  std::vector<MeshPiece> pieces(1);
  if (Result r = readLegacyVtkPiece(bytes, label, pieces[0], report); !r) return r;
  PieceMergeSummary summary;
  if (Result r = mergePieces(label, pieces, PieceMergeRules{}, out, report, summary); !r) return r;
  if (summary.ghostCells + summary.hiddenCells) report.format += describeMerge(summary);
  return Result::success();
}

}  // namespace tetstream
