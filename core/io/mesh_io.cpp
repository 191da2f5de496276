#include "io/mesh_io.h"

#include <algorithm>
#include <bit>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <new>

#include "io/hdf5_file.h"
#include "io/mapped_file.h"
#include "io/readers.h"

namespace tetstream {
namespace {

std::string lowerExtension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

constexpr const char* kSupported =
    "supported: .vtu/.vts/.vti (VTK XML), .vtk (legacy VTK), partitioned VTK output (.pvtu, .vtm, .pvtk, with "
    "their pieces), .msh (Gmsh 2.2/4.1), .node/.ele (TetGen), .mesh (Medit), PLOT3D grids (.xyz, .x, .g, .grd, "
    ".p3d, .bin; Q file with --q), Exodus II (.exo, .e, .ex2, .exii, .g), CGNS (.cgns), .xdmf/.xmf (XDMF 2/3, "
    "HDF5 or XML data), .vtkhdf/.hdf (VTKHDF; .h5/.hdf5 with a /VTKHDF group)";

enum class Format { Unknown, VtkXml, LegacyVtk, Gmsh, Medit, Tetgen, Plot3d, Listing, Exodus, Cgns, Xdmf, VtkHdf };

// The extensions that name a format outright; anything else is sniffed from the content.
Format byExtension(const std::string& ext) {
  if (ext == ".vtu" || ext == ".vts" || ext == ".vti") return Format::VtkXml;
  if (ext == ".vtk") return Format::LegacyVtk;
  if (ext == ".pvtu" || ext == ".vtm" || ext == ".pvtk") return Format::Listing;
  if (ext == ".msh") return Format::Gmsh;
  if (ext == ".mesh") return Format::Medit;
  if (ext == ".node" || ext == ".ele") return Format::Tetgen;
  if (ext == ".xyz") return Format::Plot3d;
  if (ext == ".xdmf" || ext == ".xmf") return Format::Xdmf;
  if (ext == ".vtkhdf" || ext == ".hdf") return Format::VtkHdf;
  // ".g" (a Genesis mesh, or a PLOT3D grid) is told by content.
  if (ext == ".exo" || ext == ".e" || ext == ".ex2" || ext == ".exii") return Format::Exodus;
  if (ext == ".cgns") return Format::Cgns;
  return Format::Unknown;
}

bool isPlot3dExtension(const std::string& ext) {
  for (const char* e : {".xyz", ".x", ".g", ".grd", ".p3d", ".bin", ".dat", ".q", ".fmt"})
    if (ext == e) return true;
  return false;
}

// Recognizes a format by its first bytes. Text formats have a magic word; binary data of a file
// with a PLOT3D-like extension is taken as PLOT3D (the reader then checks the sizes).
Format sniff(std::string_view head, const std::string& ext) {
  size_t p = 0;
  if (head.substr(0, 3) == "\xEF\xBB\xBF") p = 3;
  // Skip blank lines and '#' comment lines (Medit, TetGen) but not "# vtk DataFile".
  while (p < head.size()) {
    if (head[p] == ' ' || head[p] == '\t' || head[p] == '\r' || head[p] == '\n') {
      ++p;
      continue;
    }
    if (head[p] == '#' && head.substr(p, 14) != "# vtk DataFile") {
      size_t e = head.find('\n', p);
      if (e == std::string_view::npos) break;
      p = e + 1;
      continue;
    }
    break;
  }
  std::string_view t = head.substr(std::min(p, head.size()));
  // An HDF5 file (.h5, .hdf5, ...) that is not Exodus II or CGNS (hpcFormatByContent, before this)
  // is taken as VTKHDF; its reader says so when /VTKHDF is missing.
  if (hdf5::hasSignature(head)) return Format::VtkHdf;
  if (t.starts_with("<")) return head.find("<Xdmf") != std::string_view::npos ? Format::Xdmf : Format::VtkXml;
  if (t.starts_with("# vtk DataFile")) return Format::LegacyVtk;
  if (t.starts_with("$MeshFormat")) return Format::Gmsh;
  if (t.starts_with("MeshVersionFormatted")) return Format::Medit;
  if (isPlot3dExtension(ext)) return Format::Plot3d;
  return Format::Unknown;
}

// The formats that can hold several time steps (and so take --step and --time).
bool hasTimeSteps(Format f) {
  switch (f) {
    case Format::Exodus:
    case Format::Cgns:
    case Format::Xdmf:
    case Format::VtkHdf: return true;
    default: return false;
  }
}

const char* formatName(Format f) {
  switch (f) {
    case Format::VtkXml: return "VTK XML";
    case Format::LegacyVtk: return "legacy VTK";
    case Format::Gmsh: return "Gmsh";
    case Format::Medit: return "Medit";
    case Format::Tetgen: return "TetGen";
    case Format::Plot3d: return "PLOT3D";
    case Format::Xdmf: return "XDMF";
    case Format::VtkHdf: return "VTKHDF";
    case Format::Exodus: return "Exodus II";
    case Format::Cgns: return "CGNS";
    case Format::Listing: return "a listing of VTK pieces";
    default: return "unknown";
  }
}

Result readWholeFile(const std::string& path, std::string& bytes) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return fail(Status::IoError, path + ": cannot open (" + std::strerror(errno) + ")");
  bytes.clear();
  // One read into a buffer of the file's size (growing a string 64 KB at a time copied a large
  // mesh file several times over); then whatever follows if the file grew meanwhile.
  std::error_code ec;
  const uintmax_t size = std::filesystem::file_size(path, ec);
  if (!ec && size > 0) {
    bytes.resize(size_t(size));
    bytes.resize(std::fread(bytes.data(), 1, bytes.size(), f));
  }
  char buf[1 << 16];
  size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) bytes.append(buf, n);
  bool bad = std::ferror(f) != 0;
  std::fclose(f);
  if (bad) return fail(Status::IoError, path + ": read error");
  return Result::success();
}

Result readHead(const std::string& path, std::string& head) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return fail(Status::IoError, path + ": cannot open (" + std::strerror(errno) + ")");
  head.resize(4096);
  head.resize(std::fread(head.data(), 1, head.size(), f));
  std::fclose(f);
  return Result::success();
}

bool fileExists(const std::string& path) {
  std::error_code ec;
  return std::filesystem::is_regular_file(path, ec);
}

// Runs a reader, turning exceptions (out of memory) into a Result and clearing `out` on failure.
template <class F>
Result guarded(const std::string& name, TetMesh& out, F&& read) {
  Result r;
  // The readers allocate only what the input justifies, but a huge valid file can still exhaust
  // memory; that must come back as a Result, not an exception through the library boundary.
  try {
    r = read();
  } catch (const std::bad_alloc&) {
    r = fail(Status::TooLarge, name + ": out of memory while reading");
  } catch (...) {
    r = fail(Status::Corrupt, name + ": internal error while reading");
  }
  if (!r) {
    out = TetMesh{};
    return r;
  }
  out.name = std::filesystem::path(name).stem().string();
  return r;
}

Result readOneFile(Format fmt, std::string_view bytes, const std::string& name, TetMesh& out, ReadReport& report) {
  switch (fmt) {
    case Format::VtkXml: return readVtu(bytes, name, out, report);
    case Format::LegacyVtk: return readLegacyVtk(bytes, name, out, report);
    case Format::Gmsh: return readGmsh(bytes, name, out, report);
    case Format::Medit: return readMedit(bytes, name, {}, "", out, report);
    case Format::Plot3d: return readPlot3d(bytes, name, {}, "", out, report);
    case Format::Tetgen:
      return fail(Status::Unsupported,
                  name + ": a TetGen mesh is two files (.node and .ele); read it by path, not from bytes");
    // From bytes an XDMF file has no folder: only XML data items can be read.
    case Format::Xdmf: return readXdmf(bytes, name, std::nullopt, {}, out, report);
    case Format::VtkHdf:
      return fail(Status::Unsupported, name +
                                           ": a VTKHDF file is HDF5, which is read through the HDF5 library from "
                                           "a file; read it by path, not from bytes");
    case Format::Exodus:
    case Format::Cgns:
      return fail(Status::Unsupported,
                  name + ": " + formatName(fmt) +
                      " files are read by their library from disk; read it by path, not from bytes");
    case Format::Listing:
      return fail(Status::Unsupported, name +
                                           ": a listing of piece files (.pvtu, .vtm, .pvtk); read it by path, "
                                           "which finds the pieces beside it");
    default: break;
  }
  return fail(Status::Unsupported, name + ": unsupported mesh format; " + kSupported);
}

// "grid.xyz" -> "grid.q"-style companions of a PLOT3D grid that exist on disk, best first.
std::vector<std::string> plot3dSolutionCandidates(const std::string& path) {
  namespace fs = std::filesystem;
  fs::path p(path);
  std::string file = p.filename().string(), dir = p.parent_path().string();
  auto join = [&](const std::string& f) { return dir.empty() ? f : (fs::path(dir) / f).string(); };
  std::vector<std::string> out;
  std::string lower = file;
  for (char& c : lower) c = char(std::tolower(static_cast<unsigned char>(c)));
  // "bluntfinxyz.bin" -> "bluntfinq.bin"; "wing.x" / "wing.xyz" -> "wing.q".
  for (const char* tag : {"xyz", "grid", "grd"}) {
    size_t at = lower.rfind(tag);
    if (at != std::string::npos) out.push_back(join(file.substr(0, at) + "q" + file.substr(at + std::strlen(tag))));
  }
  out.push_back(join(p.stem().string() + ".q"));
  std::vector<std::string> existing;
  for (const std::string& c : out)
    if (c != path && fileExists(c) && std::find(existing.begin(), existing.end(), c) == existing.end())
      existing.push_back(c);
  return existing;
}

// Maps the pieces a listing at `listingPath` names from its folder (readListing has checked
// that each path stays inside it).
PieceLoader pieceFiles(const std::string& listingPath) {
  namespace fs = std::filesystem;
  return [listingPath](const std::string& relative, PieceBytes& piece) {
    const fs::path full = fs::path(listingPath).parent_path() / relative;
    std::error_code ec;
    if (fs::equivalent(full, listingPath, ec)) return fail(Status::Corrupt, full.string() + " is the listing itself");
    if (Result r = piece.file.open(full.string()); !r) return r;
    piece.bytes = piece.file.bytes();
    return Result::success();
  };
}

}  // namespace

Result readMeshBytes(std::string_view bytes, const std::string& name, TetMesh& out, ReadReport& report) {
  out = TetMesh{};
  std::string ext = lowerExtension(name);
  Format fmt = byExtension(ext);
  if (fmt == Format::Unknown) {
    // netCDF and ADF hold Exodus II and CGNS (HDF5 may hold other formats: left to sniff()).
    const vtkio::Container c = vtkio::containerSignature(bytes);
    if (c != vtkio::Container::None && c != vtkio::Container::Hdf5)
      return fail(Status::Unsupported,
                  name + ": " + vtkio::containerName(c) +
                      " container (an Exodus II or CGNS file?); these are read by path, not from bytes");
    fmt = sniff(bytes.substr(0, 4096), ext);
  }
  if (fmt == Format::Unknown)
    return fail(Status::Unsupported, name + ": unsupported mesh format '" + ext + "'; " + kSupported);
  if (fmt == Format::VtkXml && listingKind(bytes.substr(0, 4096)) != ListingKind::None) fmt = Format::Listing;
  return guarded(name, out, [&] { return readOneFile(fmt, bytes, name, out, report); });
}

Result readMesh(const std::string& path, TetMesh& out, ReadReport& report, const ReadOptions& options) {
  out = TetMesh{};
  namespace fs = std::filesystem;
  std::string ext = lowerExtension(path);
  Format fmt = byExtension(ext);
  if (fmt == Format::Unknown || fmt == Format::Plot3d) {
    // Sniff the first bytes before reading a possibly large file we cannot read anyway.
    std::string head;
    if (Result r = readHead(path, head); !r) return r;
    const vtkio::HpcFormat hpc = vtkio::hpcFormatByContent(path, head);
    fmt = hpc == vtkio::HpcFormat::Exodus ? Format::Exodus
          : hpc == vtkio::HpcFormat::Cgns ? Format::Cgns
                                          : sniff(head, ext);
    if (fmt == Format::Unknown)
      return fail(Status::Unsupported,
                  path + ": unsupported mesh format '" + ext + "' (content not recognized); " + kSupported);
  }
  if ((options.step || options.time) && !hasTimeSteps(fmt))
    return fail(Status::BadArgument,
                path + " (" + formatName(fmt) + ") holds one state; --step and --time apply to files with time steps");
  if (!options.solution.empty() && fmt != Format::Plot3d && fmt != Format::Medit)
    return fail(Status::BadArgument, path + ": a solution file (--q " + options.solution +
                                         ") goes with a PLOT3D grid or a Medit mesh, and this is " + formatName(fmt));

  if (fmt == Format::VtkHdf) return guarded(path, out, [&] { return readVtkHdf(path, options, out, report); });
  // The Exodus II and CGNS libraries read the file themselves.
  if (fmt == Format::Exodus) return guarded(path, out, [&] { return readExodus(path, options, out, report); });
  if (fmt == Format::Cgns) return guarded(path, out, [&] { return readCgns(path, options, out, report); });

  // A VTK XML file is mapped, not read into memory (MappedFile): its arrays are decoded from
  // where they lie, and a process's share of it touches only its own parts.
  if (fmt == Format::VtkXml) {
    MappedFile file;
    if (Result r = file.open(path); !r) return r;
    const std::string_view mapped = file.bytes();
    if (listingKind(mapped.substr(0, 4096)) == ListingKind::None)
      return guarded(path, out,
                     [&] { return readVtu(mapped, path, out, report, options.shareIndex, options.shareCount); });
  }
  std::string bytes, second;
  std::string secondPath;
  try {
    if (fmt == Format::Tetgen) {
      // Either file may be given; the other has the same stem.
      const std::string stem = (fs::path(path).parent_path() / fs::path(path).stem()).string();
      const std::string nodePath = ext == ".node" ? path : stem + ".node";
      const std::string elePath = ext == ".ele" ? path : stem + ".ele";
      if (Result r = readWholeFile(nodePath, bytes); !r)
        return fail(r.status, r.message + " (the .node file of TetGen mesh " + path + ")");
      if (Result r = readWholeFile(elePath, second); !r)
        return fail(r.status, r.message + " (the .ele file of TetGen mesh " + path + ")");
      return guarded(path, out, [&] { return readTetgen(bytes, nodePath, second, elePath, out, report); });
    }
    if (Result r = readWholeFile(path, bytes); !r) return r;
    if (fmt == Format::Medit || fmt == Format::Plot3d) {
      if (!options.solution.empty()) {
        secondPath = options.solution;
      } else if (fmt == Format::Medit) {
        std::string sol = (fs::path(path).parent_path() / fs::path(path).stem()).string() + ".sol";
        if (fileExists(sol)) secondPath = sol;
      } else {
        std::vector<std::string> cands = plot3dSolutionCandidates(path);
        if (!cands.empty()) {
          secondPath = cands[0];
          report.notes.push_back("using the Q solution file " + secondPath +
                                 " found next to the grid (name another with --q FILE)");
        }
      }
      if (!secondPath.empty())
        if (Result r = readWholeFile(secondPath, second); !r) return r;
    }
  } catch (const std::bad_alloc&) {
    return fail(Status::TooLarge, path + ": out of memory while loading the file");
  }
  if (fmt == Format::Medit)
    return guarded(path, out, [&] { return readMedit(bytes, path, second, secondPath, out, report); });
  if (fmt == Format::Plot3d)
    return guarded(path, out, [&] { return readPlot3d(bytes, path, second, secondPath, out, report); });
  if (fmt == Format::Xdmf) {
    const std::string folder = fs::path(path).parent_path().string();
    return guarded(path, out, [&] { return readXdmf(bytes, path, folder, options, out, report); });
  }
  // A listing of pieces, by its extension or by its content (a .pvtu saved as .vtu, say); a
  // VTK XML mesh saved under a listing's extension is read as the mesh it is.
  const std::string_view head = std::string_view(bytes).substr(0, 4096);
  const bool listing = listingKind(head) != ListingKind::None;
  if (fmt == Format::Listing && !listing && !vtkio::vtkXmlFileType(head).empty()) fmt = Format::VtkXml;
  if (fmt == Format::Listing || (fmt == Format::VtkXml && listing))
    return guarded(path, out, [&] {
      return readListing(bytes, path, pieceFiles(path), out, report, options.shareIndex, options.shareCount);
    });
  if (fmt == Format::VtkXml)
    return guarded(path, out,
                   [&] { return readVtu(bytes, path, out, report, options.shareIndex, options.shareCount); });
  return guarded(path, out, [&] { return readOneFile(fmt, bytes, path, out, report); });
}

Result writeMesh(const std::string& path, const TetMesh& mesh, uint32_t pieces) {
  std::string ext = lowerExtension(path);
  if (ext != ".vtu" && ext != ".pvtu")
    return fail(Status::Unsupported, path + ": can only write .vtu or .pvtu, not '" + ext + "'");
  try {
    return ext == ".pvtu" ? writePvtu(path, mesh, pieces) : writeVtu(path, mesh);
  } catch (const std::bad_alloc&) {
    return fail(Status::TooLarge, path + ": out of memory while writing");
  }
}

// ------------------------------------------------------------------ shared by the readers
namespace vtkio {

size_t scalarSize(ScalarType t) {
  switch (t) {
    case ScalarType::Int8:
    case ScalarType::UInt8: return 1;
    case ScalarType::Int16:
    case ScalarType::UInt16: return 2;
    case ScalarType::Int32:
    case ScalarType::UInt32:
    case ScalarType::Float32: return 4;
    case ScalarType::Int64:
    case ScalarType::UInt64:
    case ScalarType::Float64: return 8;
  }
  return 1;
}

static constexpr const char* kScalarNames[] = {"Int8",   "UInt8", "Int16",  "UInt16",  "Int32",
                                               "UInt32", "Int64", "UInt64", "Float32", "Float64"};

const char* scalarTypeName(ScalarType t) { return kScalarNames[int(t)]; }

bool isIntegerType(ScalarType t) { return t != ScalarType::Float32 && t != ScalarType::Float64; }

bool parseXmlScalarType(std::string_view name, ScalarType& t) {
  for (int i = 0; i < 10; ++i)
    if (name == kScalarNames[i]) {
      t = ScalarType(i);
      return true;
    }
  return false;
}

namespace {

// std::byteswap is C++23.
inline uint16_t bswap(uint16_t v) { return __builtin_bswap16(v); }
inline uint32_t bswap(uint32_t v) { return __builtin_bswap32(v); }
inline uint64_t bswap(uint64_t v) { return __builtin_bswap64(v); }

template <class U>
U loadRaw(const uint8_t* p, bool bigEndian) {
  U v;
  std::memcpy(&v, p, sizeof v);
  if (bigEndian != (std::endian::native == std::endian::big)) v = bswap(v);
  return v;
}

// Reads element i of type t as the C++ type T via its unsigned bit pattern.
template <class T>
T loadAs(const uint8_t* src, size_t i, ScalarType t, bool be) {
  const uint8_t* p = src + i * scalarSize(t);
  switch (t) {
    case ScalarType::Int8: return T(int8_t(*p));
    case ScalarType::UInt8: return T(*p);
    case ScalarType::Int16: return T(int16_t(loadRaw<uint16_t>(p, be)));
    case ScalarType::UInt16: return T(loadRaw<uint16_t>(p, be));
    case ScalarType::Int32: return T(int32_t(loadRaw<uint32_t>(p, be)));
    case ScalarType::UInt32: return T(loadRaw<uint32_t>(p, be));
    case ScalarType::Int64: return T(int64_t(loadRaw<uint64_t>(p, be)));
    case ScalarType::UInt64: return T(loadRaw<uint64_t>(p, be));
    case ScalarType::Float32: return T(std::bit_cast<float>(loadRaw<uint32_t>(p, be)));
    case ScalarType::Float64: return T(std::bit_cast<double>(loadRaw<uint64_t>(p, be)));
  }
  return T(0);
}

}  // namespace

size_t decodeInts(const uint8_t* src, size_t count, ScalarType t, bool bigEndian, int64_t* dst) {
  if (t == ScalarType::UInt64) {
    for (size_t i = 0; i < count; ++i) {
      uint64_t v = loadRaw<uint64_t>(src + 8 * i, bigEndian);
      if (v > uint64_t(std::numeric_limits<int64_t>::max())) return i;
      dst[i] = int64_t(v);
    }
    return count;
  }
  for (size_t i = 0; i < count; ++i) dst[i] = loadAs<int64_t>(src, i, t, bigEndian);
  return count;
}

void decodeDoubles(const uint8_t* src, size_t count, ScalarType t, bool bigEndian, double* dst) {
  for (size_t i = 0; i < count; ++i) dst[i] = loadAs<double>(src, i, t, bigEndian);
}

// Finds the next token without consuming it; returns false at the end of the text.
static bool peekToken(std::string_view text, size_t& pos, std::string_view& tok) {
  while (pos < text.size() && isSpace(text[pos])) ++pos;
  if (pos >= text.size()) return false;
  size_t b = pos;
  while (pos < text.size() && !isSpace(text[pos])) ++pos;
  tok = text.substr(b, pos - b);
  pos = b;
  return true;
}

static bool parseDoubleToken(std::string_view tok, double& out) {
  if (!tok.empty() && tok[0] == '+') tok.remove_prefix(1);
  if (tok.empty()) return false;
  auto [p, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), out);
  // Out-of-range magnitudes become ±inf / 0 like strtod does; the finiteness check reports them.
  if (ec == std::errc::result_out_of_range) {
    bool neg = tok[0] == '-';
    size_t e = tok.find_first_of("eE");
    bool tiny = e != std::string_view::npos && e + 1 < tok.size() && tok[e + 1] == '-';
    out = tiny ? (neg ? -0.0 : 0.0) : (neg ? -HUGE_VAL : HUGE_VAL);
    return p == tok.data() + tok.size();
  }
  return ec == std::errc() && p == tok.data() + tok.size();
}

int parseNextDouble(std::string_view text, size_t& pos, double& out) {
  std::string_view tok;
  if (!peekToken(text, pos, tok)) return 0;
  if (!parseDoubleToken(tok, out)) return -1;
  pos += tok.size();
  return 1;
}

int parseNextInt(std::string_view text, size_t& pos, int64_t& out) {
  // The common case straight away: a sign, at most 18 digits, then white space or the end (the
  // token-then-from_chars path below took a quarter of reading an ASCII .vtu of 1.5M tets).
  // Anything else (more digits, "4.0", junk) takes that path.
  while (pos < text.size() && isSpace(text[pos])) ++pos;
  size_t at = pos + (pos < text.size() && (text[pos] == '-' || text[pos] == '+'));
  const size_t digits = at;
  uint64_t value = 0;
  for (; at < text.size() && at - digits < 18 && uint8_t(text[at] - '0') < 10; ++at)
    value = 10 * value + uint8_t(text[at] - '0');
  if (at > digits && (at == text.size() || isSpace(text[at]))) {
    out = text[pos] == '-' ? -int64_t(value) : int64_t(value);
    pos = at;
    return 1;
  }
  std::string_view tok;
  if (!peekToken(text, pos, tok)) return 0;
  std::string_view t = tok;
  if (!t.empty() && t[0] == '+') t.remove_prefix(1);
  auto [p, ec] = std::from_chars(t.data(), t.data() + t.size(), out);
  if (ec != std::errc() || p != t.data() + t.size()) {
    // Some writers print integer arrays as "4.0"; accept exactly integral values.
    double d;
    if (!parseDoubleToken(tok, d) || !(d >= -9.2e18 && d <= 9.2e18) || d != std::floor(d)) return -1;
    out = int64_t(d);
  }
  pos += tok.size();
  return 1;
}

bool parseU64(std::string_view s, uint64_t& out) {
  if (s.empty()) return false;
  auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
  return ec == std::errc() && p == s.data() + s.size();
}

std::string printable(std::string_view s) {
  std::string out(s.substr(0, 40));
  for (char& c : out)
    if (static_cast<unsigned char>(c) < 32 || static_cast<unsigned char>(c) > 126) c = '?';
  return s.size() > 40 ? out + "..." : out;
}

std::string vtkCellTypeName(int64_t type) {
  struct Name {
    int id;
    const char* name;
  };
  static constexpr Name kNames[] = {
      {0, "VTK_EMPTY_CELL"},
      {1, "VTK_VERTEX"},
      {2, "VTK_POLY_VERTEX"},
      {3, "VTK_LINE"},
      {4, "VTK_POLY_LINE"},
      {5, "VTK_TRIANGLE"},
      {6, "VTK_TRIANGLE_STRIP"},
      {7, "VTK_POLYGON"},
      {8, "VTK_PIXEL"},
      {9, "VTK_QUAD"},
      {10, "VTK_TETRA"},
      {11, "VTK_VOXEL"},
      {12, "VTK_HEXAHEDRON"},
      {13, "VTK_WEDGE"},
      {14, "VTK_PYRAMID"},
      {15, "VTK_PENTAGONAL_PRISM"},
      {16, "VTK_HEXAGONAL_PRISM"},
      {21, "VTK_QUADRATIC_EDGE"},
      {22, "VTK_QUADRATIC_TRIANGLE"},
      {23, "VTK_QUADRATIC_QUAD"},
      {24, "VTK_QUADRATIC_TETRA"},
      {25, "VTK_QUADRATIC_HEXAHEDRON"},
      {26, "VTK_QUADRATIC_WEDGE"},
      {27, "VTK_QUADRATIC_PYRAMID"},
      {28, "VTK_BIQUADRATIC_QUAD"},
      {29, "VTK_TRIQUADRATIC_HEXAHEDRON"},
      {30, "VTK_QUADRATIC_LINEAR_QUAD"},
      {31, "VTK_QUADRATIC_LINEAR_WEDGE"},
      {32, "VTK_BIQUADRATIC_QUADRATIC_WEDGE"},
      {33, "VTK_BIQUADRATIC_QUADRATIC_HEXAHEDRON"},
      {34, "VTK_BIQUADRATIC_TRIANGLE"},
      {35, "VTK_CUBIC_LINE"},
      {36, "VTK_QUADRATIC_POLYGON"},
      {37, "VTK_TRIQUADRATIC_PYRAMID"},
      {41, "VTK_CONVEX_POINT_SET"},
      {42, "VTK_POLYHEDRON"},
      {51, "VTK_PARAMETRIC_CURVE"},
      {52, "VTK_PARAMETRIC_SURFACE"},
      {53, "VTK_PARAMETRIC_TRI_SURFACE"},
      {54, "VTK_PARAMETRIC_QUAD_SURFACE"},
      {55, "VTK_PARAMETRIC_TETRA_REGION"},
      {56, "VTK_PARAMETRIC_HEX_REGION"},
      {60, "VTK_HIGHER_ORDER_EDGE"},
      {61, "VTK_HIGHER_ORDER_TRIANGLE"},
      {62, "VTK_HIGHER_ORDER_QUAD"},
      {63, "VTK_HIGHER_ORDER_POLYGON"},
      {64, "VTK_HIGHER_ORDER_TETRAHEDRON"},
      {65, "VTK_HIGHER_ORDER_WEDGE"},
      {66, "VTK_HIGHER_ORDER_PYRAMID"},
      {67, "VTK_HIGHER_ORDER_HEXAHEDRON"},
      {68, "VTK_LAGRANGE_CURVE"},
      {69, "VTK_LAGRANGE_TRIANGLE"},
      {70, "VTK_LAGRANGE_QUADRILATERAL"},
      {71, "VTK_LAGRANGE_TETRAHEDRON"},
      {72, "VTK_LAGRANGE_HEXAHEDRON"},
      {73, "VTK_LAGRANGE_WEDGE"},
      {74, "VTK_LAGRANGE_PYRAMID"},
      {75, "VTK_BEZIER_CURVE"},
      {76, "VTK_BEZIER_TRIANGLE"},
      {77, "VTK_BEZIER_QUADRILATERAL"},
      {78, "VTK_BEZIER_TETRAHEDRON"},
      {79, "VTK_BEZIER_HEXAHEDRON"},
      {80, "VTK_BEZIER_WEDGE"},
      {81, "VTK_BEZIER_PYRAMID"},
  };
  for (const Name& n : kNames)
    if (n.id == type) return n.name;
  return "VTK cell type " + std::to_string(type);
}

std::vector<float> tuplesToScalars(std::span<const double> tuples, uint32_t components) {
  std::vector<float> out(components ? tuples.size() / components : 0);
  if (components == 1) {
    for (size_t i = 0; i < out.size(); ++i) out[i] = float(tuples[i]);
    return out;
  }
  for (size_t i = 0; i < out.size(); ++i) {
    double s = 0;
    for (uint32_t k = 0; k < components; ++k) {
      double v = tuples[i * components + k];
      s += v * v;
    }
    out[i] = float(std::sqrt(s));
  }
  return out;
}

std::string fieldNameFor(const std::string& arrayName, uint32_t components, ReadReport& report, const char* kind) {
  if (components == 1) return arrayName;
  std::string name = arrayName + "_magnitude";
  report.notes.push_back("converted " + std::to_string(components) + "-component " + kind + " array '" + arrayName +
                         "' to its magnitude '" + name + "'");
  return name;
}

void addField(TetMesh& mesh, ScalarField field, ReadReport& report) {
  if (mesh.findField(field.name) >= 0) {
    report.notes.push_back("dropped a second point array named '" + field.name + "'");
    return;
  }
  mesh.fields.push_back(std::move(field));
}

}  // namespace vtkio
}  // namespace tetstream
