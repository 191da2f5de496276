// The listing files of partitioned VTK output (readers.h, readListing): what they list and which
// files may be read for them. Joining the pieces is piece_merge.cpp's.
//
//   .pvtu  <VTKFile type="PUnstructuredGrid"><PUnstructuredGrid GhostLevel=".."> with
//          <PPointData>/<PCellData> declaring the arrays and one <Piece Source="a_0.vtu"/> per
//          piece (vtkXMLPUnstructuredGridWriter; deal.II, MFEM, FEniCS, OpenGeoSys write the same).
//          Every piece must be an UnstructuredGrid and carry every declared array.
//   .vtm   <VTKFile type="vtkMultiBlockDataSet"> with <Block> and <Piece> (a multipiece) elements
//          nesting <DataSet file="m/m_0.vtu"/> leaves (vtkXMLMultiBlockDataWriter). Leaves that the
//          serial VTK XML reader takes (.vtu, .vts, .vti) are read; other types (PolyData, listings)
//          are skipped with a note naming the block.
//   .pvtk  <File version="pvtk-1.0" dataType="vtkUnstructuredGrid" numberOfPieces="2"> with
//          <Piece fileName="a.0.vtk"/> (vtkPDataSetWriter): legacy VTK pieces.
//
// Which files a listing may name: relative paths that stay inside the listing's folder
// (subfolders are fine; "." and ".." are resolved by name first). Absolute paths and paths that
// climb out are refused: a listing from elsewhere must not make the tool read, and then publish
// in a pack, files the listing's author chose. A piece that names the listing, or a file named
// twice, is refused too: no file is read more than once, so the work is bounded by the bytes on
// disk, and pieces are never read as listings, so listings cannot recurse.
#include <cctype>
#include <cstring>
#include <filesystem>
#include <pugixml.hpp>
#include <set>

#include "io/readers.h"

namespace tetstream {
namespace {

using namespace vtkio;

constexpr int kMaxBlockDepth = 64;  // .vtm blocks inside blocks

struct Listed {
  std::string path;  // as the listing names it
  std::string name;  // "piece 2", "block solid/1/0"
};

// 'text' for a message (untrusted: printable() cuts and cleans it).
std::string inQuotes(std::string_view text) {
  std::string q(1, '\'');
  q += printable(text);
  q += '\'';
  return q;
}

// The listing's file name, which no piece may name.
std::string ownName(const std::string& label) { return std::filesystem::path(label).filename().string(); }

// The relative path a piece names, resolved by name ("a/./b/../c" -> "a/c"), or why it is refused.
Result piecePath(const std::string& where, std::string_view raw, std::string& out) {
  const std::string shown = inQuotes(raw);
  if (raw.empty()) return fail(Status::Corrupt, where + ": names no file");
  const bool drive = raw.size() >= 2 && std::isalpha(static_cast<unsigned char>(raw[0])) && raw[1] == ':';
  if (raw[0] == '/' || raw[0] == '\\' || drive)
    return fail(Status::Unsupported, where + ": " + shown +
                                         " is an absolute path; pieces are read only from the listing's folder and "
                                         "its subfolders, named relative to the listing");
  std::vector<std::string_view> parts;
  size_t b = 0;
  for (size_t i = 0; i <= raw.size(); ++i) {
    if (i < raw.size() && raw[i] != '/' && raw[i] != '\\') continue;
    const std::string_view part = raw.substr(b, i - b);
    b = i + 1;
    if (part.empty() || part == ".") continue;
    if (part == "..") {
      if (parts.empty())
        return fail(Status::Unsupported, where + ": " + shown +
                                             " leaves the listing's folder; pieces are read only from the listing's "
                                             "folder and its subfolders");
      parts.pop_back();
      continue;
    }
    parts.push_back(part);
  }
  if (parts.empty()) return fail(Status::Corrupt, where + ": " + shown + " names no file");
  out.clear();
  for (std::string_view p : parts) out.append(out.empty() ? "" : "/").append(p);
  return Result::success();
}

// The arrays a .pvtu declares, as field names (the rule of fieldNameFor) with how it says them.
void declaredArrays(pugi::xml_node section, bool cells, std::vector<std::pair<std::string, std::string>>& out) {
  int index = 0;
  for (pugi::xml_node da : section.children("PDataArray")) {
    std::string name = da.attribute("Name").value();
    if (name.empty()) name = "array" + std::to_string(index);
    ++index;
    ScalarType type;
    if (!parseXmlScalarType(da.attribute("type").value(), type)) continue;  // pieces skip these too
    if (partitionArrayKind(name, cells, section.attribute("GlobalIds").value()) != PartitionArray::None) continue;
    uint64_t comps = 1;
    if (da.attribute("NumberOfComponents") &&
        (!parseU64(da.attribute("NumberOfComponents").value(), comps) || comps == 0 || comps > kMaxComponents))
      comps = 1;  // a piece that disagrees says so itself
    ReadReport scratch;
    out.push_back({fieldNameFor(name, uint32_t(comps), scratch),
                   inQuotes(name) + (comps > 1 ? " (" + std::to_string(comps) + " components)" : "")});
  }
}

// The <DataSet file=...> leaves of a .vtm, depth first, with their block path for notes.
Result vtmLeaves(const std::string& label, pugi::xml_node node, const std::string& path, int depth,
                 std::vector<Listed>& out, uint64_t& empty) {
  if (depth > kMaxBlockDepth)
    return fail(Status::Corrupt, label + ": blocks nested deeper than " + std::to_string(kMaxBlockDepth));
  int position = 0;
  for (pugi::xml_node c = node.first_child(); c; c = c.next_sibling(), ++position) {
    if (c.type() != pugi::node_element) continue;
    std::string part = c.attribute("name") ? c.attribute("name").value() : "";
    if (part.empty()) part = c.attribute("index") ? c.attribute("index").value() : std::to_string(position);
    const std::string here = path.empty() ? printable(part) : path + "/" + printable(part);
    const std::string_view kind = c.name();
    if (kind == "Block" || kind == "Piece") {
      if (Result r = vtmLeaves(label, c, here, depth + 1, out, empty); !r) return r;
    } else if (kind == "DataSet") {
      if (!c.attribute("file") || !*c.attribute("file").value()) {
        ++empty;  // an empty block
        continue;
      }
      if (out.size() >= kMaxPieces)
        return fail(Status::TooLarge, label + ": lists more than " + std::to_string(kMaxPieces) + " datasets");
      out.push_back({c.attribute("file").value(), "block " + here});
    }
  }
  return Result::success();
}

}  // namespace

ListingKind listingKind(std::string_view head) {
  // The first element, after an XML declaration, comments and white space.
  size_t p = head.substr(0, 3) == "\xEF\xBB\xBF" ? 3 : 0;
  for (;;) {
    p = head.find_first_not_of(" \t\r\n", p);
    if (p == std::string_view::npos || head[p] != '<') return ListingKind::None;
    std::string_view end;
    if (head.substr(p, 2) == "<?")
      end = "?>";
    else if (head.substr(p, 4) == "<!--")
      end = "-->";
    else
      break;
    p = head.find(end, p);
    if (p == std::string_view::npos) return ListingKind::None;
    p += end.size();
  }
  const std::string_view tag = head.substr(p, head.find('>', p) - p);
  if (tag.starts_with("<File") && tag.size() > 5 && std::strchr(" \t\r\n", tag[5]) &&
      tag.find("pvtk") != std::string_view::npos)
    return ListingKind::Pvtk;
  if (!tag.starts_with("<VTKFile")) return ListingKind::None;
  const std::string type = vtkXmlFileType(head.substr(p));
  if (type == "PUnstructuredGrid") return ListingKind::Pvtu;
  if (type == "vtkMultiBlockDataSet") return ListingKind::Vtm;
  return ListingKind::None;
}

Result readListing(std::string_view listing, const std::string& label, const PieceLoader& load, TetMesh& out,
                   ReadReport& report, uint32_t shareIndex, uint32_t shareCount) {
  out = TetMesh{};
  pugi::xml_document doc;
  const pugi::xml_parse_result parsed = doc.load_buffer(listing.data(), listing.size());
  if (!parsed)
    return fail(listing.empty() ? Status::Truncated : Status::Corrupt,
                label + ": malformed XML at byte " + std::to_string(parsed.offset) + ": " + parsed.description());
  const pugi::xml_node root = doc.document_element();
  const std::string_view rootName = root.name();
  const std::string type = root.attribute("type").value();

  ListingKind kind = ListingKind::None;
  std::string what;
  std::vector<Listed> listed;
  PieceMergeRules rules;
  rules.joined = "joined";
  if (rootName == "File" && std::string_view(root.attribute("version").value()).starts_with("pvtk")) {
    kind = ListingKind::Pvtk;
    what = "parallel legacy VTK (.pvtk)";
    const std::string_view dataType = root.attribute("dataType").value();
    if (dataType == "vtkPolyData")
      return fail(Status::Unsupported, label + ": dataType vtkPolyData: surfaces have no volume cells");
    for (pugi::xml_node p : root.children("Piece")) {
      if (listed.size() >= kMaxPieces)
        return fail(Status::TooLarge, label + ": lists more than " + std::to_string(kMaxPieces) + " pieces");
      listed.push_back({p.attribute("fileName").value(), "piece " + std::to_string(listed.size())});
    }
    uint64_t declared;
    if (root.attribute("numberOfPieces") &&
        (!parseU64(root.attribute("numberOfPieces").value(), declared) || declared != listed.size()))
      return fail(Status::Corrupt, label + ": numberOfPieces='" + printable(root.attribute("numberOfPieces").value()) +
                                       "' but " + std::to_string(listed.size()) + " <Piece> elements");
  } else if (rootName == "VTKFile" && type == "PUnstructuredGrid") {
    kind = ListingKind::Pvtu;
    what = "parallel VTK (.pvtu)";
    const pugi::xml_node grid = root.child("PUnstructuredGrid");
    if (!grid) return fail(Status::Corrupt, label + ": <VTKFile> has no <PUnstructuredGrid>");
    for (pugi::xml_node p : grid.children("Piece")) {
      if (listed.size() >= kMaxPieces)
        return fail(Status::TooLarge, label + ": lists more than " + std::to_string(kMaxPieces) + " pieces");
      listed.push_back({p.attribute("Source").value(), "piece " + std::to_string(listed.size())});
    }
    // VTK reads the arrays the listing declares and no others; a listing with no PPointData or
    // PCellData at all (written by hand) declares nothing, and then the arrays that every piece
    // has are kept.
    rules.declared = grid.child("PPointData") || grid.child("PCellData");
    declaredArrays(grid.child("PPointData"), false, rules.pointFields);
    declaredArrays(grid.child("PCellData"), true, rules.cellFields);
  } else if (rootName == "VTKFile" && type == "vtkMultiBlockDataSet") {
    kind = ListingKind::Vtm;
    what = "VTK multiblock (.vtm)";
    uint64_t empty = 0;
    if (Result r = vtmLeaves(label, root.child("vtkMultiBlockDataSet"), "", 0, listed, empty); !r) return r;
    if (empty) report.notes.push_back("skipped " + std::to_string(empty) + " empty blocks");
  } else {
    return fail(Status::BadMagic, label + ": not a listing of pieces (root <" + printable(rootName) + ">" +
                                      (type.empty() ? "" : " type '" + printable(type) + "'") +
                                      "); expected a PUnstructuredGrid (.pvtu), vtkMultiBlockDataSet (.vtm) or "
                                      "pvtk-1.0 (.pvtk) listing");
  }
  if (listed.empty()) return fail(Status::NoTets, label + ": lists no pieces");

  // Every path checked before anything is read.
  std::set<std::string> seen;
  const std::string self = ownName(label);
  for (Listed& l : listed) {
    const std::string where = label + " " + l.name;
    std::string path;
    if (Result r = piecePath(where, l.path, path); !r) return r;
    if (path == self) return fail(Status::Corrupt, where + ": names " + self + " itself");
    if (!seen.insert(path).second)
      return fail(Status::Corrupt, where + ": " + path + " is listed twice (each piece is one file)");
    l.name += " (" + path + ")";
    l.path = std::move(path);
  }

  report.filesListed = listed.size();
  // Of more processes than files, the processes that share a file each read a share of its
  // cells (a .vtu file's; of another file the first of them reads it all).
  uint32_t fileShare = 0, fileShares = 1;
  if (shareCount > 1) {
    const uint64_t n = listed.size(), from = shareIndex * n / shareCount;
    uint64_t to = (shareIndex + 1ull) * n / shareCount;
    if (n < shareCount && n > 0) {  // file `from` is read by the processes p with p·n/shareCount = from
      auto firstProcess = [&](uint64_t file) { return uint32_t((file * shareCount + n - 1) / n); };
      fileShare = shareIndex - firstProcess(from);
      fileShares = firstProcess(from + 1) - firstProcess(from);
      to = from + 1;
    }
    listed = std::vector<Listed>(listed.begin() + ptrdiff_t(from), listed.begin() + ptrdiff_t(to));
    report.shared = true;
    if (listed.empty()) return Result::success();
  }

  std::vector<MeshPiece> pieces;
  std::set<std::string> notes(report.notes.begin(), report.notes.end()), formats;
  std::vector<std::string> skipped;
  for (const Listed& l : listed) {
    const std::string where = label + " " + l.name;
    PieceBytes piece;
    if (Result r = load(l.path, piece); !r) return fail(r.status, where + ": " + r.message);
    const std::string_view bytes = piece.bytes;
    ReadReport pieceReport;
    const size_t before = pieces.size();
    if (kind == ListingKind::Pvtk) {
      if (fileShare > 0) continue;
      if (Result r = readLegacyVtkPiece(bytes, where, pieces.emplace_back(), pieceReport); !r) return r;
    } else {
      const std::string pieceType = vtkXmlFileType(std::string_view(bytes).substr(0, 4096));
      const bool volume = pieceType == "UnstructuredGrid" ||
                          (kind == ListingKind::Vtm && (pieceType == "StructuredGrid" || pieceType == "ImageData"));
      if (!volume && kind == ListingKind::Vtm && !pieceType.empty()) {
        skipped.push_back(l.name + ": " + printable(pieceType));
        continue;
      }
      if (!volume && !pieceType.empty())
        return fail(Status::Corrupt, where + ": is a VTK XML " + printable(pieceType) +
                                         " file; the pieces of a PUnstructuredGrid are UnstructuredGrid (.vtu)");
      std::vector<MeshPiece> sub;
      if (Result r = readVtuPieces(bytes, where, sub, pieceReport, fileShare, fileShares); !r) return r;
      if (fileShares > 1 && !pieceReport.shared && fileShare > 0) sub.clear();  // (read whole by the first)
      for (MeshPiece& p : sub) pieces.push_back(std::move(p));
    }
    for (size_t k = before; k < pieces.size(); ++k) {
      const bool several = pieces.size() - before > 1;
      pieces[k].name = l.name + (several ? " Piece " + std::to_string(k - before) : "");
      pieces[k].where = where + (several ? " Piece " + std::to_string(k - before) : "");
    }
    formats.insert(pieceReport.format);
    for (std::string& n : pieceReport.notes)
      if (notes.insert(n).second) report.notes.push_back(std::move(n));
  }
  if (!skipped.empty()) {
    std::string list;
    for (const std::string& s : skipped) list += (list.empty() ? "" : "; ") + s;
    report.notes.push_back("skipped " +
                           (skipped.size() == 1
                                ? std::string("1 block that is not a volume mesh")
                                : std::to_string(skipped.size()) + " blocks that are not volume meshes") +
                           " (tetstream reads UnstructuredGrid, StructuredGrid and ImageData blocks; a listing "
                           "inside a listing is not read): " +
                           list);
  }
  if (pieces.empty() && fileShare > 0) return Result::success();  // (the file's first process reads it)
  if (pieces.empty())
    return fail(Status::NoTets,
                label + ": no block is a volume mesh (" + std::to_string(skipped.size()) + " skipped: see the notes)");

  PieceMergeSummary summary;
  if (Result r = mergePieces(label, pieces, rules, out, report, summary); !r) return r;
  std::string pieceFormats;
  for (const std::string& f : formats) pieceFormats += (pieceFormats.empty() ? "" : "; ") + f;
  report.format =
      what + describeMerge(summary, kind == ListingKind::Vtm ? "datasets" : "pieces") + "; pieces: " + pieceFormats;
  return Result::success();
}

}  // namespace tetstream
