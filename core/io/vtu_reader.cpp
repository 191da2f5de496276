// VTK XML UnstructuredGrid reader. Layout reference: "VTK File Formats", XML section
// (https://docs.vtk.org/en/latest/design_documents/VTKFileFormats.html) and vtkXMLWriter's
// WriteBinaryDataInternal for the compressed-block header.
//
// A DataArray's payload (a size or compression header and the data) is read by vtu_payload.h.
// Raw appended data is binary after `<AppendedData encoding="raw">` and `_`, so it is never handed
// to pugixml: we parse only the XML before <AppendedData (closing </VTKFile> ourselves) and read
// the payloads straight from the file bytes at each DataArray's offset.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <pugixml.hpp>
#include <set>

#include "io/readers.h"
#include "io/row_pick.h"
#include "io/vtu_payload.h"

namespace tetstream {
namespace {

using namespace vtkio;

bool mulOverflows(uint64_t a, uint64_t b, uint64_t& out) { return __builtin_mul_overflow(a, b, &out); }

// ------------------------------------------------------------------ file-level settings
struct Vtu : PayloadFormat {
  std::string label;
  std::string_view file;  // the file's bytes: the inline arrays' text stays there (skeletonXml)
  bool hasAppended = false;
  bool appendedBase64 = false;
  std::string_view appended;  // after '_' up to </AppendedData>
  size_t fileBytes = 0;
  std::set<std::string> encodings;  // seen, for ReadReport::format
  // Base64 text found plain so far, by where it starts (the file's or the XML's text, which stay
  // where they are while the file is read): a share reads an array a window at a time.
  std::map<const char*, ByteSource::PlainSpan> plainText;
};

// Message prefix for one DataArray: "a.vtu: DataArray 'offsets'" (+ " in Piece 2").
struct ArrayRef {
  std::string where;  // "a.vtu" or "a.vtu Piece 2"
  std::string name;
  std::string str() const { return where + ": DataArray '" + name + "'"; }
};

// The attribute that stands, in the XML handed to pugixml, for a DataArray's text left in the
// file: "offset length" (skeletonXml). No VTK writer uses the name.
constexpr const char* kTextAttribute = "tetstream-text";

// The XML part of a VTK XML file for pugixml, without the text of large inline DataArrays: each
// such array's numbers or base64 (a run with no '<' and no '&' up to </DataArray>) stays in the
// file, and its start tag gains kTextAttribute saying where. A file of inline data was copied
// whole into the document and parsed whole; now the copy is the markup alone. `left`: whether
// any text was left in the file.
std::string skeletonXml(std::string_view xml, bool& left) {
  constexpr size_t kLeaveInFile = 256;  // (shorter texts are copied: nothing to gain)
  std::string out;
  size_t copied = 0;
  for (size_t at = xml.find("<DataArray"); at != std::string_view::npos; at = xml.find("<DataArray", at + 1)) {
    // The start tag's end: the first '>' outside quotes.
    size_t gt = at;
    char quote = 0;
    for (; gt < xml.size(); ++gt) {
      const char c = xml[gt];
      if (quote) {
        if (c == quote) quote = 0;
      } else if (c == '"' || c == '\'') {
        quote = c;
      } else if (c == '>') {
        break;
      }
    }
    if (gt >= xml.size() || xml[gt - 1] == '/') continue;  // (cut short, or an empty element)
    const size_t lt = xml.find('<', gt + 1);
    if (lt == std::string_view::npos || xml.substr(lt, 12) != "</DataArray>" || lt - gt - 1 < kLeaveInFile ||
        xml.substr(gt + 1, lt - gt - 1).find('&') != std::string_view::npos)
      continue;
    if (out.empty()) out.reserve(xml.size() / 64 + 4096);
    out.append(xml.substr(copied, gt - copied));
    out += " ";
    out += kTextAttribute;
    out += "=\"" + std::to_string(gt + 1) + " " + std::to_string(lt - gt - 1) + "\">";
    copied = lt;
    at = lt;
  }
  left = copied > 0;
  if (!left) return std::string(xml);
  out.append(xml.substr(copied));
  return out;
}

// The text of a DataArray: its character data, skipping child elements (VTK 9 puts
// <InformationKey> elements inside arrays, before or after the numbers), or the run of the file
// that skeletonXml left there.
std::string_view arrayText(const Vtu& vtu, pugi::xml_node da, std::string& storage) {
  if (pugi::xml_attribute left = da.attribute(kTextAttribute)) {
    uint64_t offset = 0, length = 0;
    std::string_view spec = left.value();
    size_t pos = 0;
    if (parseU64(nextToken(spec, pos), offset) && parseU64(nextToken(spec, pos), length) && offset <= vtu.file.size() &&
        length <= vtu.file.size() - offset)
      return vtu.file.substr(offset, length);
    return {};  // (not reached: skeletonXml wrote it from the file)
  }
  std::string_view single;
  int parts = 0;
  for (pugi::xml_node c = da.first_child(); c; c = c.next_sibling()) {
    if (c.type() != pugi::node_pcdata && c.type() != pugi::node_cdata) continue;
    std::string_view v = c.value();
    if (parts == 0) single = v;
    if (parts == 1) storage.assign(single);
    if (parts >= 1) storage.append(" ").append(v);
    ++parts;
  }
  return parts <= 1 ? single : std::string_view(storage);
}

// Values [first, first + count) of an array, for a process that reads a share of a piece.
struct ValueRange {
  uint64_t first = 0;
  uint64_t count = UINT64_MAX;  // (all from first)
};

// Reads a DataArray holding expectedValues numbers into out (int64_t or double): all of them, or
// those of `range` (the others are passed over; of compressed data only the blocks that hold the
// range are inflated).
template <class T>
Result readDataArray(Vtu& vtu, pugi::xml_node da, const ArrayRef& ref, uint64_t expectedValues, std::vector<T>& out,
                     ValueRange range = {}) {
  constexpr bool wantInts = std::is_same_v<T, int64_t>;
  range.first = std::min(range.first, expectedValues);
  range.count = std::min(range.count, expectedValues - range.first);
  const bool whole = range.first == 0 && range.count == expectedValues;
  ScalarType type;
  const char* typeName = da.attribute("type").value();
  if (!parseXmlScalarType(typeName, type))
    return fail(Status::Unsupported, ref.str() + ": type '" + typeName + "' is not a numeric type tetstream reads");
  if (wantInts && !isIntegerType(type))
    return fail(Status::Corrupt, ref.str() + ": must hold integers, found type " + typeName);
  uint64_t expectedBytes;
  if (mulOverflows(expectedValues, scalarSize(type), expectedBytes))
    return fail(Status::TooLarge, ref.str() + ": " + std::to_string(expectedValues) + " values overflow a 64-bit size");

  std::string_view format = da.attribute("format").value();
  std::string storage;
  if (format == "ascii") {
    vtu.encodings.insert("ascii");
    std::string_view text = arrayText(vtu, da, storage);
    // Each value takes at least one character and a separator, so this bound is real data.
    out.clear();
    out.reserve(size_t(std::min<uint64_t>(range.count, text.size() / 2 + 1)));
    size_t pos = 0;
    for (uint64_t i = 0; i < range.first + range.count; ++i) {
      T v;
      int r;
      if constexpr (wantInts)
        r = parseNextInt(text, pos, v);
      else
        r = parseNextDouble(text, pos, v);
      if (r == 0)
        return fail(Status::Corrupt,
                    ref.str() + ": has " + std::to_string(i) + " of " + std::to_string(expectedValues) + " values");
      if (r < 0) {
        std::string_view tok = text.substr(pos, text.substr(pos).find_first_of(" \t\r\n"));
        return fail(Status::Corrupt, ref.str() + ": value " + std::to_string(i) + " '" + printable(tok) + "' is not " +
                                         (wantInts ? "an integer" : "a number"));
      }
      if (i >= range.first) out.push_back(v);
    }
    double extra;
    if (whole && parseNextDouble(text, pos, extra) != 0)
      return fail(Status::Corrupt,
                  ref.str() + ": has more than the expected " + std::to_string(expectedValues) + " values");
    return Result::success();
  }

  ByteSource src = ByteSource::raw({});
  if (format == "binary") {
    vtu.encodings.insert("inline base64");
    const std::string_view text = arrayText(vtu, da, storage);
    src = ByteSource::base64(text, text.data() == storage.data() ? nullptr : &vtu.plainText[text.data()]);
  } else if (format == "appended") {
    if (!vtu.hasAppended)
      return fail(Status::Corrupt, ref.str() + ": format=\"appended\" but the file has no <AppendedData> section");
    uint64_t offset;
    if (!parseU64(da.attribute("offset").value(), offset))
      return fail(Status::Corrupt,
                  ref.str() + ": offset '" + da.attribute("offset").value() + "' is not a non-negative integer");
    if (offset >= vtu.appended.size())
      return fail(Status::Truncated, ref.str() + ": offset " + std::to_string(offset) + " is beyond the " +
                                         std::to_string(vtu.appended.size()) + " bytes of appended data");
    vtu.encodings.insert(vtu.appendedBase64 ? "appended base64" : "appended raw");
    const std::string_view text = vtu.appended.substr(offset);
    src = vtu.appendedBase64 ? ByteSource::base64(text, &vtu.plainText[text.data()]) : ByteSource::raw(text);
  } else {
    return fail(Status::Unsupported,
                ref.str() + ": format '" + std::string(format) + "' (expected ascii, binary or appended)");
  }

  std::vector<uint8_t> bytes;
  const uint8_t* data = nullptr;
  const uint64_t size = scalarSize(type);
  if (Result r = readPayload(vtu, src, ref.str(), expectedBytes, range.first * size, (range.first + range.count) * size,
                             bytes, data);
      !r)
    return r;
  out.resize(range.count);
  if constexpr (wantInts) {
    size_t ok = decodeInts(data, range.count, type, vtu.bigEndian, out.data());
    if (ok != range.count)
      return fail(Status::OutOfRange,
                  ref.str() + ": value " + std::to_string(range.first + ok) + " exceeds the Int64 range");
  } else {
    decodeDoubles(data, range.count, type, vtu.bigEndian, out.data());
  }
  return Result::success();
}

pugi::xml_node findArray(pugi::xml_node parent, const char* name) {
  for (pugi::xml_node da : parent.children("DataArray"))
    if (std::strcmp(da.attribute("Name").value(), name) == 0) return da;
  return {};
}

Result readCount(pugi::xml_node node, const char* attr, const std::string& where, uint64_t& out) {
  if (!parseU64(node.attribute(attr).value(), out))
    return fail(Status::Corrupt,
                where + ": " + attr + "='" + node.attribute(attr).value() + "' is not a non-negative integer");
  return Result::success();
}

Result readComponents(pugi::xml_node da, const ArrayRef& ref, uint64_t& comps) {
  comps = 1;
  if (!da.attribute("NumberOfComponents")) return Result::success();
  if (!parseU64(da.attribute("NumberOfComponents").value(), comps) || comps == 0 || comps > kMaxComponents)
    return fail(Status::Corrupt, ref.str() + ": NumberOfComponents='" + da.attribute("NumberOfComponents").value() +
                                     "' (expected 1.." + std::to_string(kMaxComponents) + ")");
  return Result::success();
}

enum class GridKind { Unstructured, Structured, Image };

// The geometry of a structured piece: its Extent and, for ImageData, how indices become points.
struct Grid {
  int64_t extent[6] = {0, 0, 0, 0, 0, 0};
  double origin[3] = {0, 0, 0}, spacing[3] = {1, 1, 1};
  double direction[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  uint64_t n(int axis) const { return uint64_t(extent[2 * axis + 1] - extent[2 * axis] + 1); }
};

// Parses "a b c ..." of exactly `count` numbers from an attribute.
template <class T>
bool parseNumbers(const char* text, int count, T* out) {
  std::string_view s(text);
  size_t pos = 0;
  for (int k = 0; k < count; ++k) {
    if constexpr (std::is_same_v<T, int64_t>) {
      if (parseNextInt(s, pos, out[k]) != 1) return false;
    } else {
      if (parseNextDouble(s, pos, out[k]) != 1 || !std::isfinite(out[k])) return false;
    }
  }
  T extra;
  if constexpr (std::is_same_v<T, int64_t>)
    return parseNextInt(s, pos, extra) == 0;
  else
    return parseNextDouble(s, pos, extra) == 0;
}

Result readExtent(pugi::xml_node node, const char* attr, const std::string& where, Grid& g) {
  const char* text = node.attribute(attr).value();
  if (!parseNumbers(text, 6, g.extent))
    return fail(Status::Corrupt, where + ": " + attr + "='" + printable(text) + "' is not six integers");
  for (int a = 0; a < 3; ++a)
    if (g.extent[2 * a + 1] < g.extent[2 * a] || g.extent[2 * a + 1] - g.extent[2 * a] >= int64_t(kMaxVertices))
      return fail(Status::Corrupt, where + ": " + attr + "='" + printable(text) + "' has an empty or huge range");
  return Result::success();
}

// The rows of a piece one process reads: a run of its cells and the run of points they span,
// or of that run only the points they use (`pointPick`, ascending ids; empty: the whole run).
struct PieceRows {
  uint64_t pointFirst = 0, points = UINT64_MAX;
  uint64_t cellFirst = 0, cells = UINT64_MAX;
  std::vector<uint64_t> pointPick, cellPick;  // when not empty: only these rows (ascending)
};

// Whether a DataArray's rows can be read a window at a time for the cost of the window: binary
// data, raw or base64, inline or appended, compressed or not, is reached by offset (base64 text
// by four characters for three bytes where it is plain: ByteSource::skip). Text that would be
// read again from the array's start for every window is read once instead: ASCII, and inline
// base64 with white space inside (wrapped into lines).
bool readsByWindow(const Vtu& vtu, pugi::xml_node da) {
  const std::string_view format = da.attribute("format").value();
  if (format != "binary") return format == "appended";
  std::string storage;
  std::string_view text = arrayText(vtu, da, storage);
  const size_t first = text.find_first_not_of(" \t\r\n"), last = text.find_last_not_of(" \t\r\n");
  if (first == std::string_view::npos) return true;
  text = text.substr(first, last + 1 - first);
  for (char c : {' ', '\n', '\r', '\t'})
    if (std::memchr(text.data(), c, text.size())) return false;
  return true;
}

// The values of rows `rows` of an array of `rowCount` rows of `comps` components each
// (readDataArray), or of those only the rows in `pick` (ascending ids inside `rows`) when it is
// not empty.
template <class T>
Result readRows(Vtu& vtu, pugi::xml_node da, const ArrayRef& ref, uint64_t rowCount, uint64_t comps, uint64_t first,
                uint64_t count, std::span<const uint64_t> pick, std::vector<T>& out) {
  auto values = [&](uint64_t from, uint64_t n) {
    return ValueRange{from * comps, n == UINT64_MAX ? UINT64_MAX : n * comps};
  };
  if (pick.empty()) return readDataArray(vtu, da, ref, rowCount * comps, out, values(first, count));
  return io::readPickedRows(
      pick, rowCount, readsByWindow(vtu, da), ref.str(),
      [&](uint64_t from, uint64_t n, std::vector<T>& window) {
        return readDataArray(vtu, da, ref, rowCount * comps, window, values(from, n));
      },
      out);
}

// Reads the PointData and CellData arrays of one piece (np points, nc cells) into it: fields,
// cell arrays, and the arrays that describe the partition (vtkGhostType, global ids). Of `rows`
// only (all of them by default).
Result readPieceData(Vtu& vtu, pugi::xml_node piece, const std::string& where, uint64_t np, uint64_t nc,
                     ReadReport& report, bool notePieceConversions, MeshPiece& out, const PieceRows& rows = {}) {
  for (const char* section : {"PointData", "CellData"}) {
    const bool cells = section[0] == 'C';
    const char* kind = cells ? "cell" : "point";
    const std::string_view idsAttribute = piece.child(section).attribute("GlobalIds").value();
    int index = 0;
    for (pugi::xml_node da : piece.child(section).children("DataArray")) {
      std::string name = da.attribute("Name").value();
      if (name.empty()) name = "array" + std::to_string(index);
      ++index;
      ArrayRef ref{where, name};
      ScalarType type;
      if (!parseXmlScalarType(da.attribute("type").value(), type)) {
        if (notePieceConversions)
          report.notes.push_back(std::string("skipped ") + kind + " array '" + name + "' of non-numeric type '" +
                                 da.attribute("type").value() + "'");
        continue;
      }
      uint64_t comps;
      if (Result r = readComponents(da, ref, comps); !r) return r;
      std::vector<double> values;
      if (Result r = cells ? readRows(vtu, da, ref, nc, comps, rows.cellFirst, rows.cells, rows.cellPick, values)
                           : readRows(vtu, da, ref, np, comps, rows.pointFirst, rows.points, rows.pointPick, values);
          !r)
        return r;
      if (const PartitionArray p = partitionArrayKind(name, cells, idsAttribute); p != PartitionArray::None) {
        if (Result r = takePartitionArray(p, name, ref.str(), values, comps, cells, out); !r) return r;
        continue;
      }
      ReadReport scratch;
      std::string fname = fieldNameFor(name, uint32_t(comps), notePieceConversions ? report : scratch, kind);
      std::vector<float> scalars = tuplesToScalars(values, uint32_t(comps));
      if (cells)
        out.cellArrays.push_back({fname, std::vector<double>(scalars.begin(), scalars.end())});
      else
        out.mesh.fields.push_back({fname, std::move(scalars)});
    }
  }
  return Result::success();
}

// Reads one Piece: its points, its cells (numbered within the piece) and its arrays.
// The <Cells> arrays of a piece of nc cells, each required.
Result findCellArrays(pugi::xml_node piece, const std::string& where, uint64_t nc, pugi::xml_node& offsets,
                      pugi::xml_node& types, pugi::xml_node& connectivity) {
  pugi::xml_node cells = piece.child("Cells");
  offsets = findArray(cells, "offsets");
  types = findArray(cells, "types");
  connectivity = findArray(cells, "connectivity");
  for (auto [node, name] : {std::pair{offsets, "offsets"}, {types, "types"}, {connectivity, "connectivity"}})
    if (!node)
      return fail(Status::Corrupt,
                  where + ": NumberOfCells=" + std::to_string(nc) + " but <Cells> has no DataArray '" + name + "'");
  return Result::success();
}

// Reads the points [first, first + count) of a piece of np points into mesh.positions, or of
// those the ones in `pick` (readRows).
Result readPointRows(Vtu& vtu, pugi::xml_node piece, const std::string& where, uint64_t np, ValueRange rows,
                     TetMesh& mesh, std::span<const uint64_t> pick = {}) {
  pugi::xml_node da = piece.child("Points").child("DataArray");
  ArrayRef ref{where, da ? da.attribute("Name").as_string("Points") : "Points"};
  if (!da) return fail(Status::Corrupt, where + ": " + std::to_string(np) + " points but no <Points> DataArray");
  uint64_t comps;
  if (Result r = readComponents(da, ref, comps); !r) return r;
  if (comps != 3)
    return fail(Status::Corrupt, ref.str() + ": points have " + std::to_string(comps) + " components, expected 3");
  std::vector<double> p;
  if (Result r = readRows(vtu, da, ref, np, 3, rows.first, rows.count, pick, p); !r) return r;
  mesh.positions.reserve(mesh.positions.size() + p.size());
  for (double x : p) mesh.positions.push_back(float(x));
  return Result::success();
}

// Of a structured piece, `slab` (when given) names the share of its layers of cells along one
// axis to read: layers index·L/count to (index + 1)·L/count and their points.
struct Slab {
  uint32_t index = 0, count = 1;
};

// The most points a file of `fileBytes` could carry values for: 16 a byte, at least 2^20. Until
// its arrays are read, a huge Extent may be a lie; this bounds what is set up for it before.
uint64_t mostPointsIn(uint64_t fileBytes) { return std::max<uint64_t>(uint64_t(1) << 20, 16 * fileBytes); }

// The axis a piece is cut into `count` slabs along: k when it has that many layers of cells (k
// is the slowest index, so a slab's points and cells are runs of the arrays), else j (a run in
// each k plane), else i (a run in each row). -1 when no axis has that many, or when the piece
// has no cells or j or i would list more rows than a file of `fileBytes` could carry values
// for (mostPointsIn): a hostile Extent must not make that list huge. Such a piece is read whole,
// which checks its arrays before it allocates.
int slabAxis(const Grid& g, uint32_t count, uint64_t fileBytes) {
  if (g.n(2) - 1 >= count) return 2;
  uint64_t points = 1;
  for (int axis = 0; axis < 3; ++axis)
    if (g.n(axis) < 2 || __builtin_mul_overflow(points, g.n(axis), &points)) return -1;
  if (points > mostPointsIn(fileBytes)) return -1;
  for (int axis = 1; axis >= 0; --axis)
    if (g.n(axis) - 1 >= count) return axis;
  return -1;
}

// The rows of slab [from, to] along `axis` (0 or 1) of an ni x nj x nk block of rows (points, or
// cells with one fewer along each axis), ascending.
std::vector<uint64_t> slabRows(uint64_t ni, uint64_t nj, uint64_t nk, int axis, uint64_t from, uint64_t to) {
  std::vector<uint64_t> out;
  const uint64_t iFrom = axis == 0 ? from : 0, iTo = axis == 0 ? to : ni - 1;
  const uint64_t jFrom = axis == 1 ? from : 0, jTo = axis == 1 ? to : nj - 1;
  out.reserve((iTo - iFrom + 1) * (jTo - jFrom + 1) * nk);
  for (uint64_t k = 0; k < nk; ++k)
    for (uint64_t j = jFrom; j <= jTo; ++j)
      for (uint64_t i = iFrom; i <= iTo; ++i) out.push_back(i + ni * (j + nj * k));
  return out;
}

Result readPiece(Vtu& vtu, GridKind kind, const Grid& whole, pugi::xml_node piece, const std::string& where,
                 MeshPiece& out, ReadReport& report, bool notePieceConversions, const Slab* slab = nullptr) {
  TetMesh& mesh = out.mesh;
  CellSoup& soup = out.soup;
  uint64_t np = 0, nc = 0;
  Grid g = whole;
  PieceRows rows;
  if (kind == GridKind::Unstructured) {
    if (Result r = readCount(piece, "NumberOfPoints", where, np); !r) return r;
    if (Result r = readCount(piece, "NumberOfCells", where, nc); !r) return r;
  } else {
    if (Result r = readExtent(piece, "Extent", where, g); !r) return r;
    uint64_t n = 1, c = 1;
    for (int a = 0; a < 3; ++a) {
      if (__builtin_mul_overflow(n, g.n(a), &n) || n > kMaxVertices)
        return fail(Status::TooLarge, where + ": Extent gives more than 2^32-1 points");
      c *= g.n(a) - 1;
    }
    np = n;
    nc = c;
    // ImageData stores no coordinates: until its arrays arrive, a huge extent is a lie.
    if (kind == GridKind::Image && np > mostPointsIn(vtu.fileBytes))
      return fail(Status::Truncated, where + ": Extent declares " + std::to_string(np) + " points, far more than a " +
                                         std::to_string(vtu.fileBytes) + "-byte file can carry data for");
    if (slab) {
      const int axis = slabAxis(g, slab->count, vtu.fileBytes);
      if (axis < 0) return fail(Status::Corrupt, where + ": too thin to cut into " + std::to_string(slab->count));
      const uint64_t layers = g.n(axis) - 1, from = layers * slab->index / slab->count,
                     to = layers * (slab->index + 1) / slab->count, plane = g.n(0) * g.n(1);
      if (axis == 2) {
        rows = {from * plane, (to - from + 1) * plane, from * (g.n(0) - 1) * (g.n(1) - 1),
                (to - from) * (g.n(0) - 1) * (g.n(1) - 1)};
      } else {
        rows.pointPick = slabRows(g.n(0), g.n(1), g.n(2), axis, from, to);
        rows.cellPick = slabRows(g.n(0) - 1, g.n(1) - 1, g.n(2) - 1, axis, from, to - 1);
        rows.pointFirst = rows.cellFirst = 0;
        rows.points = rows.pointPick.size();
        rows.cells = rows.cellPick.size();
      }
      g.extent[2 * axis] += int64_t(from);
      g.extent[2 * axis + 1] = g.extent[2 * axis] + int64_t(to - from);
    }
  }
  // What is read of the piece: all of it, or a slab's rows.
  const uint64_t npRead = slab ? rows.points : np, ncRead = slab ? rows.cells : nc;
  const uint64_t vertexBase = mesh.positions.size() / 3;
  if (np > kMaxVertices || vertexBase + np > kMaxVertices)
    return fail(Status::TooLarge,
                where + ": " + std::to_string(vertexBase + np) + " points; tetstream indexes vertices with 32 bits");

  // ImageData's geometry costs nothing to declare: read its arrays first, so a file that does not
  // carry the values for its extent stops before a grid is built for it.
  if (kind == GridKind::Image) {
    if (Result r = readPieceData(vtu, piece, where, np, nc, report, notePieceConversions, out, rows); !r) return r;
    if (mesh.fields.empty() && out.cellArrays.empty())
      return fail(Status::MissingField, where + ": the image has no numeric PointData or CellData arrays to show");
  }

  // Points
  if (kind == GridKind::Image) {
    mesh.positions.reserve(mesh.positions.size() + 3 * npRead);
    for (int64_t k = g.extent[4]; k <= g.extent[5]; ++k)
      for (int64_t j = g.extent[2]; j <= g.extent[3]; ++j)
        for (int64_t i = g.extent[0]; i <= g.extent[1]; ++i) {
          const double d[3] = {double(i) * g.spacing[0], double(j) * g.spacing[1], double(k) * g.spacing[2]};
          for (int c = 0; c < 3; ++c)
            mesh.positions.push_back(float(g.origin[c] + g.direction[3 * c] * d[0] + g.direction[3 * c + 1] * d[1] +
                                           g.direction[3 * c + 2] * d[2]));
        }
  } else if (np > 0) {
    if (Result r = readPointRows(vtu, piece, where, np, {rows.pointFirst, rows.points}, mesh, rows.pointPick); !r)
      return r;
  }

  // Cells
  if (kind != GridKind::Unstructured) {
    appendStructuredCells(g.n(0), g.n(1), g.n(2), vertexBase, soup.inputCells, soup);
    soup.inputCells += ncRead;
  } else if (nc > 0) {
    // Offsets first, since the last offset is the connectivity length.
    pugi::xml_node daOff, daTypes, daConn;
    if (Result r = findCellArrays(piece, where, nc, daOff, daTypes, daConn); !r) return r;
    std::vector<int64_t> ends, offsets, types, conn;
    if (Result r = readDataArray(vtu, daOff, {where, "offsets"}, nc, ends); !r) return r;
    int64_t connSize = ends.back();
    if (connSize < 0)
      return fail(Status::Corrupt,
                  where + ": DataArray 'offsets': last offset " + std::to_string(connSize) + " is negative");
    if (Result r = readDataArray(vtu, daTypes, {where, "types"}, nc, types); !r) return r;
    if (Result r = readDataArray(vtu, daConn, {where, "connectivity"}, uint64_t(connSize), conn); !r) return r;
    // VTU offsets are cell ends; appendVtkCells wants starts plus the final end.
    offsets.reserve(ends.size() + 1);
    offsets.push_back(0);
    offsets.insert(offsets.end(), ends.begin(), ends.end());
    ends = {};
    if (Result r = appendVtkCells(where, conn, offsets, types, vertexBase, np, soup); !r) return r;
  }
  if (kind == GridKind::Image) return Result::success();
  return readPieceData(vtu, piece, where, np, nc, report, notePieceConversions, out, rows);
}

// The points a share reads (io/row_pick.h): of binary data only those its cells use
// (rows.pointPick, read by readRows: a window at a time, or the run once where windows would
// cost more), else the run their ids span. `conn` is renumbered to the points read.
void pickUsedPoints(pugi::xml_node piece, std::vector<int64_t>& conn, PieceRows& rows) {
  rows.pointPick.clear();
  if (rows.points > 0 &&
      std::string_view(piece.child("Points").child("DataArray").attribute("format").value()) != "ascii") {
    rows.pointPick = io::pickUsedRows(conn, rows.pointFirst, rows.points);
  } else {
    for (int64_t& id : conn) id -= int64_t(rows.pointFirst);
  }
}

// Reads share `index` of `count` of an unstructured piece: its cells from index·nc/count up to
// (index + 1)·nc/count and their points (pickUsedPoints), with those rows of every array. The
// other rows are passed over (raw appended data is not even read from the mapped file,
// compressed blocks not inflated); the points on the cuts are read by both sides and joined by
// the distributed pack like the points pieces share.
Result readPieceShare(Vtu& vtu, pugi::xml_node piece, const std::string& label, uint32_t index, uint32_t count,
                      MeshPiece& out, ReadReport& report, bool notePieceConversions, uint64_t& cellsTotal) {
  uint64_t np = 0, nc = 0;
  if (Result r = readCount(piece, "NumberOfPoints", label, np); !r) return r;
  if (Result r = readCount(piece, "NumberOfCells", label, nc); !r) return r;
  cellsTotal = nc;
  PieceRows rows;
  rows.cellFirst = nc * index / count;
  rows.cells = nc * (index + 1ull) / count - rows.cellFirst;
  out.where = label + " (cells " + std::to_string(rows.cellFirst) + " to " +
              std::to_string(rows.cellFirst + rows.cells) + " of " + std::to_string(nc) + ")";
  const std::string& where = out.where;
  if (np > kMaxVertices)
    return fail(Status::TooLarge,
                where + ": " + std::to_string(np) + " points; tetstream indexes vertices with 32 bits");

  std::vector<int64_t> ends, types, conn;
  if (rows.cells > 0) {
    pugi::xml_node daOff, daTypes, daConn;
    if (Result r = findCellArrays(piece, where, nc, daOff, daTypes, daConn); !r) return r;
    // The cell before the first ends where the first starts; the last cell's end is the
    // connectivity's length.
    const uint64_t before = rows.cellFirst > 0 ? 1 : 0;
    if (Result r =
            readDataArray(vtu, daOff, {where, "offsets"}, nc, ends, {rows.cellFirst - before, rows.cells + before});
        !r)
      return r;
    std::vector<int64_t> last{ends.back()};
    if (rows.cellFirst + rows.cells < nc)
      if (Result r = readDataArray(vtu, daOff, {where, "offsets"}, nc, last, {nc - 1, 1}); !r) return r;
    const int64_t start = before ? ends.front() : 0, stop = ends.back(), connSize = last.back();
    if (start < 0 || stop < start || stop > connSize)
      return fail(Status::Corrupt, where + ": DataArray 'offsets': the cells span connectivity " +
                                       std::to_string(start) + ".." + std::to_string(stop) + ", outside 0.." +
                                       std::to_string(connSize) + " or going backwards");
    if (Result r = readDataArray(vtu, daTypes, {where, "types"}, nc, types, {rows.cellFirst, rows.cells}); !r) return r;
    if (Result r = readDataArray(vtu, daConn, {where, "connectivity"}, uint64_t(connSize), conn,
                                 {uint64_t(start), uint64_t(stop - start)});
        !r)
      return r;
    // Offsets relative to the run read, with the first cell's start in front.
    if (before) ends.erase(ends.begin());
    for (int64_t& e : ends) {
      if (e < start || e > stop)
        return fail(Status::Corrupt, where + ": DataArray 'offsets': a cell ends at " + std::to_string(e) +
                                         ", outside the connectivity " + std::to_string(start) + ".." +
                                         std::to_string(stop) + " of the cells read");
      e -= start;
    }
    ends.insert(ends.begin(), 0);
  } else {
    ends = {0};
  }

  int64_t lo = INT64_MAX, hi = -1;
  for (int64_t id : conn) {
    if (id < 0 || uint64_t(id) >= np)
      return fail(Status::Corrupt, where + ": a cell names point " + std::to_string(id) + " of a piece of " +
                                       std::to_string(np) + " points");
    lo = std::min(lo, id);
    hi = std::max(hi, id);
  }
  rows.pointFirst = hi < 0 ? 0 : uint64_t(lo);
  rows.points = hi < 0 ? 0 : uint64_t(hi + 1 - lo);
  pickUsedPoints(piece, conn, rows);
  const uint64_t pointsRead = rows.pointPick.empty() ? rows.points : rows.pointPick.size();

  TetMesh& mesh = out.mesh;
  const uint64_t vertexBase = mesh.positions.size() / 3;
  if (rows.points > 0)
    if (Result r = readPointRows(vtu, piece, where, np, {rows.pointFirst, rows.points}, mesh, rows.pointPick); !r)
      return r;
  if (Result r = appendVtkCells(where, conn, ends, types, vertexBase, pointsRead, out.soup); !r) return r;
  return readPieceData(vtu, piece, where, np, nc, report, notePieceConversions, out, rows);
}

// Locates <AppendedData ...> and its '_' marker in the raw bytes. xmlEnd is where the parsable XML
// stops; dataBegin/dataEnd bound the payload area.
Result locateAppended(std::string_view bytes, const std::string& label, size_t& xmlEnd, bool& found, bool& base64,
                      std::string_view& data) {
  found = false;
  size_t tag = bytes.find("<AppendedData");
  if (tag == std::string_view::npos) {
    xmlEnd = bytes.size();
    return Result::success();
  }
  found = true;
  xmlEnd = tag;
  size_t gt = bytes.find('>', tag);
  if (gt == std::string_view::npos || gt - tag > 4096)
    return fail(Status::Truncated, label + ": the <AppendedData> tag is not closed");
  // Parse the start tag alone, as an empty element, to read its attributes.
  std::string tagXml(bytes.substr(tag, gt - tag));
  if (!tagXml.empty() && tagXml.back() == '/') tagXml.pop_back();
  tagXml += "/>";
  pugi::xml_document tdoc;
  if (!tdoc.load_buffer(tagXml.data(), tagXml.size()))
    return fail(Status::Corrupt, label + ": malformed <AppendedData> tag");
  std::string_view encoding = tdoc.first_child().attribute("encoding").value();
  if (encoding == "raw")
    base64 = false;
  else if (encoding == "base64")
    base64 = true;
  else
    return fail(Status::Unsupported,
                label + ": AppendedData encoding '" + std::string(encoding) + "' (expected raw or base64)");

  size_t p = gt + 1;
  while (p < bytes.size() && (bytes[p] == ' ' || bytes[p] == '\n' || bytes[p] == '\r' || bytes[p] == '\t')) ++p;
  if (p >= bytes.size()) return fail(Status::Truncated, label + ": file ends after <AppendedData>");
  if (bytes[p] != '_') return fail(Status::Corrupt, label + ": expected '_' to start the appended data");
  ++p;
  // The data ends at the last </AppendedData>, which must be followed by </VTKFile>. Requiring both
  // catches a file cut inside or right after its binary payload.
  size_t close = bytes.rfind("</AppendedData>");
  if (close == std::string_view::npos || close < p)
    return fail(Status::Truncated, label + ": file ends inside <AppendedData> (no </AppendedData>)");
  size_t after = bytes.find_first_not_of(" \t\r\n", close + 15);
  if (after == std::string_view::npos || bytes.substr(after, 10) != "</VTKFile>")
    return fail(Status::Truncated, label + ": file ends before </VTKFile>");
  data = bytes.substr(p, close - p);
  return Result::success();
}

// Reads the pieces, or of at least shareCount pieces share shareIndex of them: the others are
// never decoded (their points are welded to these by the distributed pack, as the pieces of a
// listing are).
Result readPieces(Vtu& vtu, GridKind kind, const Grid& whole, const std::vector<pugi::xml_node>& nodes,
                  const std::string& label, uint32_t shareIndex, uint32_t shareCount, std::vector<MeshPiece>& pieces,
                  ReadReport& report) {
  size_t from = 0, to = nodes.size();
  if (shareCount > 1 && nodes.size() >= shareCount) {
    from = nodes.size() * shareIndex / shareCount;
    to = nodes.size() * (shareIndex + 1ull) / shareCount;
    report.shared = true;
    report.notes.push_back("read pieces " + std::to_string(from + 1) + " to " + std::to_string(to) + " of " +
                           std::to_string(nodes.size()) + ", this process's share of the file");
  }
  pieces.reserve(to - from);  // bounded: each is an element of the file
  for (size_t k = from; k < to; ++k) {
    MeshPiece& piece = pieces.emplace_back();
    piece.where = nodes.size() == 1 ? label : label + " Piece " + std::to_string(k);
    piece.name = "Piece " + std::to_string(k);
    if (Result r = readPiece(vtu, kind, whole, nodes[k], piece.where, piece, report, k == from); !r) return r;
  }
  return Result::success();
}

// Of fewer structured pieces than processes, each at least shareCount cells deep along some
// axis: the slab `slab` of every piece (readPiece, slabAxis).
Result readSlabShares(Vtu& vtu, GridKind kind, const Grid& whole, const std::vector<pugi::xml_node>& nodes,
                      const std::string& label, const Slab& slab, std::vector<MeshPiece>& pieces, ReadReport& report) {
  uint64_t cells = 0, cellsRead = 0;
  std::string axes;              // the axes the pieces are cut along, each once
  pieces.reserve(nodes.size());  // bounded: each is an element of the file
  for (size_t k = 0; k < nodes.size(); ++k) {
    MeshPiece& piece = pieces.emplace_back();
    piece.where = nodes.size() == 1 ? label : label + " Piece " + std::to_string(k);
    piece.name = "Piece " + std::to_string(k);
    if (Result r = readPiece(vtu, kind, whole, nodes[k], piece.where, piece, report, k == 0, &slab); !r) return r;
    Grid g;
    readExtent(nodes[k], "Extent", label, g);  // (read above)
    cells += (g.n(0) - 1) * (g.n(1) - 1) * (g.n(2) - 1);
    cellsRead += piece.soup.inputCells;
    const char axis = "ijk"[slabAxis(g, slab.count, vtu.fileBytes)];
    if (axes.find(axis) == std::string::npos) axes += axes.empty() ? std::string(1, axis) : std::string(" and ") + axis;
  }
  report.shared = true;
  report.notes.push_back(
      "read slab " + std::to_string(slab.index + 1) + " of " + std::to_string(slab.count) + " of " +
      (nodes.size() == 1 ? std::string("the grid") : "each of the " + std::to_string(nodes.size()) + " pieces") +
      " along " + axes + " (" + std::to_string(cellsRead) + " of " + std::to_string(cells) +
      " cells), this process's share of the file");
  return Result::success();
}

// Of fewer unstructured pieces than processes, share shareIndex of the cells of every piece.
Result readCellShares(Vtu& vtu, const std::vector<pugi::xml_node>& nodes, const std::string& label, uint32_t shareIndex,
                      uint32_t shareCount, std::vector<MeshPiece>& pieces, ReadReport& report) {
  uint64_t cells = 0, cellsRead = 0, points = 0;
  pieces.reserve(nodes.size());  // bounded: each is an element of the file
  for (size_t k = 0; k < nodes.size(); ++k) {
    MeshPiece& piece = pieces.emplace_back();
    piece.name = "Piece " + std::to_string(k);
    uint64_t total = 0;
    if (Result r = readPieceShare(vtu, nodes[k], nodes.size() == 1 ? label : label + " Piece " + std::to_string(k),
                                  shareIndex, shareCount, piece, report, k == 0, total);
        !r)
      return r;
    cells += total;
    cellsRead += piece.soup.inputCells;
    points += piece.mesh.positions.size() / 3;
  }
  report.shared = true;
  const std::string which = nodes.size() == 1
                                ? "share " + std::to_string(shareIndex + 1) + " of " + std::to_string(shareCount)
                                : "a share of each of the " + std::to_string(nodes.size()) + " pieces";
  report.notes.push_back("read " + std::to_string(cellsRead) + " of the " + std::to_string(cells) + " cells (" + which +
                         ") and the " + std::to_string(points) +
                         " points read for them, this process's share of the file");
  return Result::success();
}

}  // namespace

Result vtkio::readVtuPieces(std::string_view bytes, const std::string& label, std::vector<MeshPiece>& pieces,
                            ReadReport& report, uint32_t shareIndex, uint32_t shareCount) {
  pieces.clear();
  // Sniff before XML parsing so a legacy file or junk gets a clear message.
  size_t start = 0;
  if (bytes.substr(0, 3) == "\xEF\xBB\xBF") start = 3;
  start = std::min(bytes.size(), bytes.find_first_not_of(" \t\r\n", start));
  if (start >= bytes.size() || bytes[start] != '<') {
    std::string hint = bytes.substr(start, 14) == "# vtk DataFile" ? " (it is a legacy VTK file; name it .vtk)" : "";
    return fail(bytes.empty() ? Status::Truncated : Status::BadMagic,
                label + ": not a VTK XML file: " + (bytes.empty() ? "empty" : "does not start with '<'") + hint);
  }

  Vtu vtu;
  vtu.label = label;
  size_t xmlEnd;
  if (Result r = locateAppended(bytes, label, xmlEnd, vtu.hasAppended, vtu.appendedBase64, vtu.appended); !r) return r;
  vtu.file = bytes;
  bool left = false;
  std::string xml = skeletonXml(bytes.substr(0, xmlEnd), left);
  if (vtu.hasAppended) xml += "</VTKFile>";

  pugi::xml_document doc;
  pugi::xml_parse_result pr = doc.load_buffer_inplace(xml.data(), xml.size(), pugi::parse_default, pugi::encoding_utf8);
  if (!pr && left) {
    // Said of the file as written: where in it the markup breaks.
    xml.assign(bytes.substr(0, xmlEnd));
    if (vtu.hasAppended) xml += "</VTKFile>";
    pr = doc.load_buffer_inplace(xml.data(), xml.size(), pugi::parse_default, pugi::encoding_utf8);
  }
  if (!pr) {
    // pugixml reports where the broken element starts, not where the text stops; a file that does
    // not end with </VTKFile> was cut short.
    std::string_view tail = bytes.substr(0, bytes.find_last_not_of(" \t\r\n") + 1);
    bool cut = !vtu.hasAppended && !tail.ends_with("</VTKFile>");
    return fail(cut ? Status::Truncated : Status::Corrupt, label + ": " + (cut ? "file ends before </VTKFile>; " : "") +
                                                               "malformed XML at byte " + std::to_string(pr.offset) +
                                                               ": " + pr.description());
  }
  pugi::xml_node root = doc.document_element();
  if (std::strcmp(root.name(), "VTKFile") != 0)
    return fail(Status::BadMagic, label + ": root element is <" + root.name() + ">, expected <VTKFile>");
  std::string type = root.attribute("type").value();
  GridKind kind;
  if (type == "UnstructuredGrid")
    kind = GridKind::Unstructured;
  else if (type == "StructuredGrid")
    kind = GridKind::Structured;
  else if (type == "ImageData")
    kind = GridKind::Image;
  else if (type == "PUnstructuredGrid" || type == "vtkMultiBlockDataSet")
    return fail(Status::Unsupported, label + ": VTKFile type '" + type +
                                         "' lists piece files; read it by its path (as .pvtu or .vtm), which finds "
                                         "the pieces beside it");
  else
    return fail(Status::Unsupported, label + ": VTKFile type '" + printable(type) +
                                         "' is not supported; tetstream reads UnstructuredGrid (.vtu), StructuredGrid "
                                         "(.vts) and ImageData (.vti)");
  vtu.fileBytes = bytes.size();

  std::string_view order = root.attribute("byte_order").value();
  if (order == "BigEndian")
    vtu.bigEndian = true;
  else if (!order.empty() && order != "LittleEndian")
    return fail(Status::Corrupt,
                label + ": byte_order '" + std::string(order) + "' (expected LittleEndian or BigEndian)");
  std::string_view header = root.attribute("header_type").value();
  if (header == "UInt64")
    vtu.header64 = true;
  else if (!header.empty() && header != "UInt32")
    return fail(Status::Unsupported, label + ": header_type '" + std::string(header) + "' (expected UInt32 or UInt64)");
  std::string_view compressor = root.attribute("compressor").value();
  if (compressor == "vtkZLibDataCompressor")
    vtu.zlib = true;
  else if (!compressor.empty())
    return fail(Status::Unsupported, label + ": compressor '" + std::string(compressor) +
                                         "' is not supported; re-save with zlib or without compression");

  pugi::xml_node grid = root.child(type.c_str());
  if (!grid) return fail(Status::Corrupt, label + ": <VTKFile> has no <" + type + ">");
  Grid whole;
  if (kind != GridKind::Unstructured) {
    if (Result r = readExtent(grid, "WholeExtent", label + " <" + type + ">", whole); !r) return r;
    if (kind == GridKind::Image) {
      if (grid.attribute("Origin") && !parseNumbers(grid.attribute("Origin").value(), 3, whole.origin))
        return fail(Status::Corrupt, label + ": ImageData Origin='" + printable(grid.attribute("Origin").value()) +
                                         "' is not three finite numbers");
      if (grid.attribute("Spacing") && !parseNumbers(grid.attribute("Spacing").value(), 3, whole.spacing))
        return fail(Status::Corrupt, label + ": ImageData Spacing='" + printable(grid.attribute("Spacing").value()) +
                                         "' is not three finite numbers");
      if (grid.attribute("Direction") && !parseNumbers(grid.attribute("Direction").value(), 9, whole.direction))
        return fail(Status::Corrupt, label + ": ImageData Direction='" +
                                         printable(grid.attribute("Direction").value()) +
                                         "' is not nine finite numbers");
    }
  }
  if (kind != GridKind::Unstructured && (whole.n(0) < 2 || whole.n(1) < 2 || whole.n(2) < 2))
    return fail(Status::NoTets, label + ": WholeExtent " + std::to_string(whole.n(0)) + "x" +
                                    std::to_string(whole.n(1)) + "x" + std::to_string(whole.n(2)) +
                                    " is not a 3D grid (no volume cells)");
  std::vector<pugi::xml_node> nodes;
  for (pugi::xml_node p : grid.children("Piece")) nodes.push_back(p);
  if (nodes.empty()) return fail(Status::Corrupt, label + ": <" + type + "> has no <Piece>");

  pieces.clear();
  const bool fewer = shareCount > 1 && nodes.size() < shareCount;
  bool slabs = fewer && kind != GridKind::Unstructured;
  for (pugi::xml_node p : nodes) {
    Grid g;
    slabs = slabs && readExtent(p, "Extent", label, g) && slabAxis(g, shareCount, vtu.fileBytes) >= 0;
  }
  Result r = fewer && kind == GridKind::Unstructured
                 ? readCellShares(vtu, nodes, label, shareIndex, shareCount, pieces, report)
             : slabs ? readSlabShares(vtu, kind, whole, nodes, label, {shareIndex, shareCount}, pieces, report)
                     : readPieces(vtu, kind, whole, nodes, label, shareIndex, shareCount, pieces, report);
  if (!r) return r;

  std::string enc;
  for (const std::string& e : vtu.encodings) enc += (enc.empty() ? "" : ", ") + e;
  std::string dims = kind == GridKind::Unstructured ? std::string()
                                                    : ", " + std::to_string(whole.n(0)) + "x" +
                                                          std::to_string(whole.n(1)) + "x" + std::to_string(whole.n(2));
  report.format = "VTK XML " + type + " (" + (enc.empty() ? std::string("no arrays") : enc) +
                  (vtu.zlib ? ", zlib" : "") + (vtu.header64 ? ", UInt64 header" : ", UInt32 header") +
                  (vtu.bigEndian ? ", BigEndian" : "") + dims + ")";
  return Result::success();
}

Result readVtu(std::string_view bytes, const std::string& label, TetMesh& out, ReadReport& report, uint32_t shareIndex,
               uint32_t shareCount) {
  out = TetMesh{};
  std::vector<MeshPiece> pieces;
  if (Result r = readVtuPieces(bytes, label, pieces, report, shareIndex, shareCount); !r) return r;
  PieceMergeSummary summary;
  if (Result r = mergePieces(label, pieces, PieceMergeRules{}, out, report, summary); !r) return r;
  if (summary.pieces > 1 || summary.ghostCells + summary.hiddenCells) report.format += describeMerge(summary);
  return Result::success();
}

std::string vtkio::vtkXmlFileType(std::string_view head) {
  size_t tag = head.find("<VTKFile");
  if (tag == std::string_view::npos) return {};
  size_t gt = head.find('>', tag);
  if (gt == std::string_view::npos) return {};
  std::string tagXml(head.substr(tag, gt - tag));
  if (!tagXml.empty() && tagXml.back() == '/') tagXml.pop_back();
  tagXml += "/>";
  pugi::xml_document doc;
  if (!doc.load_buffer(tagXml.data(), tagXml.size())) return {};
  return doc.first_child().attribute("type").value();
}

}  // namespace tetstream
