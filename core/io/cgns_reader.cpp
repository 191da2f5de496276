// CGNS reader (readers.h), through the CGNS mid-level library (ADF and HDF5 files alike). The
// library parses the container; this file checks what it reports before sizing anything by it
// and turns every failure into a Result naming the file and the item (base, zone, section,
// solution, field), with the library's own message (cg_get_error).
//
// What is read:
//   - the first base whose cells are 3D (cell and physical dimension 3); other bases are noted;
//   - every zone of it. Structured zones: the grid's cells, split as every structured grid is
//     (appendStructuredCells). Unstructured zones: element sections of TETRA, PYRA, PENTA and
//     HEXA of any order (corners first in CGNS as in VTK; higher-order nodes dropped) and MIXED
//     sections of them; NODE, BAR, TRI, QUAD and NGON_n (faces) sections are skipped with a count
//     by type; NFACE_n (polyhedra) is refused. Zones are joined where their points coincide:
//     finishMesh merges equal coordinates, which is what abutting zones share; the
//     ZoneGridConnectivity (1-to-1 or general) is not read;
//   - FlowSolution nodes at Vertex (fields) and CellCenter (cell data; cell values are matched
//     to elements by element number, 1..cells of the zone). Other locations and solutions over
//     a point subset are skipped with a note. Vectors stored as components (MomentumX, ...) stay
//     fields and gain NAME_magnitude;
//   - time steps: a BaseIterativeData's TimeValues (else IterationValues) -> chooseTimeStep, and
//     per zone the solution its ZoneIterativeData's FlowSolutionPointers names for that step.
//     Without BaseIterativeData every FlowSolution of a zone is read (one state).
// A share for one of several processes (ReadOptions::shareIndex of shareCount, core/dist): of a
// base with at least as many zones as processes, the zones from index·Z/count to
// (index + 1)·Z/count, each whole (zones meet where their points coincide, which core/dist joins
// as one process does). A base of one unstructured zone: the elements
// numbered from index·N/count + 1 to (index + 1)·N/count and the vertices their corners use (the
// run from the smallest to the largest, or only those: io/row_pick.h), with those rows of the
// solutions (the library's partial reads; a MIXED section's elements through io/cgns_mixed.h); of
// several (fewer than processes), the same of each. A base
// of fewer structured zones than processes, each at least `count` cells deep along its longest
// index direction: of every zone the cells of layers index·L/count to (index + 1)·L/count along it
// and their points (the layer where two processes' slabs meet is read by both, and joined by
// core/dist). Of fewer zones than processes, structured and unstructured together, the slabs of
// the one and the windows of the other. A base of fewer zones than processes with a structured
// zone thinner than that is read whole by every process.
#include <cgnslib.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <optional>

#include "io/cgns_mixed.h"
#include "io/readers.h"
#include "io/row_pick.h"

namespace tetstream {
namespace {

using namespace vtkio;

constexpr uint32_t kNoCellValue = 0xFFFFFFFFu;  // source of a cell without CellCenter values

std::string lastCgnsError() {
  const char* e = cg_get_error();
  std::string s = e && *e ? e : "no details from the library";
  return s.size() > 240 ? s.substr(0, 240) + "..." : s;
}

// The library prints warnings to stdout unless given a handler (which would corrupt --json
// output); they are kept for the notes instead. Errors are read back with cg_get_error().
std::vector<std::string>* gWarnings = nullptr;  // guarded by hpcLibraryMutex()
void onCgnsMessage(int kind, char* message) {
  if (kind == 0 && gWarnings && gWarnings->size() < 4 && message) gWarnings->push_back(message);
}

// Closes the file however the read ends, and whatever the library left of it in HDF5.
struct CgnsFile {
  int fn = -1;
  std::string path;
  bool hdf5 = false;
  ~CgnsFile() {
    if (fn >= 0) cg_close(fn);
    if (hdf5) closeHdf5Leftovers(path);
  }
};

// What a CGNS element type is to the readers, by its name ("TETRA_10", "HEXA_27", "MIXED", ...).
struct CgnsType {
  bool volume = false;
  CellShape shape = CellShape::Tet;
  int vtkType = 0;  // of a skipped type, for ReadReport::skippedCells
};
CgnsType cgnsType(const std::string& name) {
  auto starts = [&](const char* p) { return name.rfind(p, 0) == 0; };
  if (starts("TETRA_")) return {true, CellShape::Tet, 10};
  if (starts("PYRA_")) return {true, CellShape::Pyramid, 14};
  if (starts("PENTA_")) return {true, CellShape::Wedge, 13};
  if (starts("HEXA_")) return {true, CellShape::Hex, 12};
  if (name == "NODE") return {false, CellShape::Tet, 1};
  if (name == "BAR_2") return {false, CellShape::Tet, 3};
  if (name == "BAR_3") return {false, CellShape::Tet, 21};
  if (name == "TRI_3") return {false, CellShape::Tet, 5};
  if (name == "TRI_6") return {false, CellShape::Tet, 22};
  if (name == "QUAD_4") return {false, CellShape::Tet, 9};
  if (name == "QUAD_8") return {false, CellShape::Tet, 23};
  if (name == "QUAD_9") return {false, CellShape::Tet, 28};
  return {};
}

// A valid ElementType_t code's name; empty for a number the library does not define (a MIXED
// section's codes come from the file and are checked before the library sees them).
std::string elementTypeName(int code) {
  if (code < 0 || code >= NofValidElementTypes) return {};
  const char* n = cg_ElementTypeName(CGNS_ENUMT(ElementType_t)(code));
  return n ? n : "";
}

// What the element type of a valid code is to the readers, looked up once per code (MIXED
// sections name a type per element).
const CgnsType& typeOfCode(cgsize_t code) {
  static const std::vector<CgnsType> byCode = [] {
    std::vector<CgnsType> t(size_t(NofValidElementTypes));
    for (int c = 0; c < NofValidElementTypes; ++c) t[size_t(c)] = cgnsType(elementTypeName(c));
    return t;
  }();
  static const CgnsType none;
  return code >= 0 && code < NofValidElementTypes ? byCode[size_t(code)] : none;
}

// "1 structured zone", "12 unstructured zones".
std::string zonesText(size_t n, const char* kind) {
  return std::to_string(n) + " " + kind + (n == 1 ? " zone" : " zones");
}

struct Zone {
  int index = 0;
  std::string name;
  bool structured = false;
  uint64_t dims[3] = {0, 0, 0};  // structured: vertices along i, j, k (of the slab read, below)
  // Structured, a share's slab: the index direction it is cut along and its first layer of points
  // (0-based); the whole zone is the slab from 0 along k.
  int slabAxis = 2;
  uint64_t slabFirst = 0;
  uint64_t vertices = 0, cells = 0;
  uint64_t vertexBase = 0, slotBase = 0;  // where its points and its cells' values start
  // What is read of it (an unstructured zone read in a share: a window; else everything):
  // vertices from vertexFirst (0-based), elements numbered from cellFirst + 1.
  uint64_t vertexFirst = 0, vertexCount = 0, cellFirst = 0, cellCount = 0;
  bool window = false;  // a share's window: only its elements are read (else every section whole)
  // Of the window's run of vertices, the ones its elements' corners use (io/row_pick.h); when
  // not all are, only those are read (`pick`, ascending, 0-based).
  std::optional<io::UsedRows> used;
  std::vector<uint64_t> pick;
  uint64_t verticesRead() const { return used ? used->used() : vertexCount; }
  // Where vertex v (1-based) is among those read; -1 when it is not read.
  int64_t vertexRead(int64_t v) const {
    if (used) return used->placeOf(uint64_t(v - 1));
    return uint64_t(v) > vertexFirst && uint64_t(v) <= vertexFirst + vertexCount ? v - 1 - int64_t(vertexFirst) : -1;
  }
  std::map<int, std::vector<cgsize_t>> windowConnectivity;  // per section: its window's elements, read once
  bool stepSolution = false;                                // the time step names one solution (below), or none
  std::string solution;
};

// An element section of a zone, as the file declares it.
struct Section {
  std::string where, type;
  std::string path;  // "/base/zone/section", for the library's node I/O
  CGNS_ENUMT(ElementType_t) etype;
  cgsize_t start = 0, end = 0;
};

class CgnsReader {
 public:
  CgnsReader(const std::string& path, const ReadOptions& options, ReadReport& report)
      : path_(path), options_(options), report_(report) {}

  Result read(TetMesh& out) {
    std::error_code ec;
    const uint64_t fileBytes = std::filesystem::file_size(path_, ec);
    if (ec) return fail(Status::IoError, path_ + ": cannot open (" + ec.message() + ")");
    if (Result r = checkSignature(fileBytes); !r) return r;
    limit_ = maxDecodedBytes(fileBytes, container_);

    std::lock_guard<std::mutex> lock(hpcLibraryMutex());
    std::vector<std::string> warnings;
    gWarnings = &warnings;
    struct Reset {
      ~Reset() { gWarnings = nullptr; }
    } reset;
    cg_configure(CG_CONFIG_ERROR, reinterpret_cast<void*>(&onCgnsMessage));
    cg_configure(CG_CONFIG_RIND_INDEX, CG_CONFIG_RIND_CORE);  // index 1 is the first core point
    Result r = readOpen(out);
    for (const std::string& w : warnings) report_.notes.push_back("CGNS library: " + printable(w));
    return r;
  }

 private:
  Result readOpen(TetMesh& out) {
    file_.path = path_;
    file_.hdf5 = container_ == Container::Hdf5;
    // The library reads the whole node tree as it opens the file, through HDF5 or ADF, which can
    // crash on a damaged file: the open is tried first in a child process.
    if (runInChildProcess([&] {
          int fn = -1;
          if (cg_open(path_.c_str(), CG_MODE_READ, &fn) == CG_OK) cg_close(fn);
          return 0;
        }) != 0)
      return fail(Status::Corrupt, path_ + ": damaged: the CGNS library crashed opening it (in a separate process)");
    if (cg_open(path_.c_str(), CG_MODE_READ, &file_.fn) != CG_OK) {
      file_.fn = -1;
      return fail(Status::Corrupt, path_ + ": not a readable CGNS file: " + lastCgnsError());
    }
    if (Result r = chooseBase(); !r) return r;
    if (Result r = readZones(); !r) return r;
    for (Zone& z : zones_) z.vertexCount = z.vertices, z.cellCount = z.cells;
    if (Result r = keepShareOfZones(); !r) return r;
    size_t step = 0;
    if (Result r = readTimes(step); !r) return r;

    TetMesh mesh;
    CellSoup soup;
    mesh.positions.resize(3 * size_t(totalVertices_));
    for (Zone& z : zones_) {
      if (Result r = readCoordinates(z, mesh); !r) return r;
      if (Result r = z.structured ? readStructuredCells(z, soup) : readSections(z, soup); !r) return r;
    }
    std::vector<CellArray> cellArrays;
    if (Result r = readSolutions(mesh, cellArrays); !r) return r;
    report_.format = formatText();
    if (Result r = finishMesh(path_, mesh, soup, std::move(cellArrays), report_); !r) return r;
    out = std::move(mesh);
    return Result::success();
  }

  Result checkSignature(uint64_t fileBytes) {
    std::string head(4096, '\0');
    std::FILE* f = std::fopen(path_.c_str(), "rb");
    if (!f) return fail(Status::IoError, path_ + ": cannot open");
    head.resize(std::fread(head.data(), 1, head.size(), f));
    std::fclose(f);
    container_ = containerSignature(head);
    if (container_ != Container::Adf && container_ != Container::Hdf5)
      return fail(Status::BadMagic, path_ + ": not a CGNS file: it starts with neither the ADF nor the HDF5 signature" +
                                        (head.empty() ? " (the file is empty)" : ""));
    // ADF reads past a file's end unchecked: the header says where the data ends.
    uint64_t end = 0;
    if (container_ == Container::Adf && !adfDataEnd(head, end))
      return fail(Status::Corrupt, path_ + ": the ADF file header is damaged (no end-of-file pointer)");
    if (container_ == Container::Adf && fileBytes < end)
      return fail(Status::Truncated, path_ + ": " + std::to_string(fileBytes) +
                                         " bytes, but its ADF header says the data runs to byte " +
                                         std::to_string(end) + " (truncated?)");
    return Result::success();
  }

  Result checkCount(const std::string& what, uint64_t count, uint64_t bytesEach) const {
    if (count > limit_ / std::max<uint64_t>(bytesEach, 1))
      return fail(Status::Truncated,
                  path_ + ": " + what + " is " + std::to_string(count) + ", more than the file can hold");
    return Result::success();
  }

  std::string zoneLabel(const Zone& z) const { return path_ + " zone '" + z.name + "'"; }

  Result chooseBase() {
    int nbases = 0;
    if (cg_nbases(file_.fn, &nbases) != CG_OK)
      return fail(Status::Corrupt, path_ + ": cannot read its bases: " + lastCgnsError());
    std::string others;
    for (int b = 1; b <= nbases; ++b) {
      char name[64] = {};
      int cellDim = 0, physDim = 0;
      if (cg_base_read(file_.fn, b, name, &cellDim, &physDim) != CG_OK)
        return fail(Status::Corrupt, path_ + ": base " + std::to_string(b) + ": " + lastCgnsError());
      if (base_ == 0 && cellDim == 3 && physDim == 3) {
        base_ = b;
        baseName_ = printable(name);
      } else {
        others += (others.empty() ? "" : ", ") + std::string("'") + printable(name) + "' (" + std::to_string(cellDim) +
                  "D cells)";
      }
    }
    if (base_ == 0)
      return fail(Status::NoTets, path_ + ": no base with 3D cells" +
                                      (others.empty() ? std::string(" (the file has no base)") : " among " + others));
    if (!others.empty()) report_.notes.push_back("read base '" + baseName_ + "'; not read: " + others);
    return Result::success();
  }

  Result readZones() {
    int nzones = 0;
    if (cg_nzones(file_.fn, base_, &nzones) != CG_OK)
      return fail(Status::Corrupt, path_ + ": base '" + baseName_ + "': cannot read its zones: " + lastCgnsError());
    uint64_t slots = 0;
    for (int zi = 1; zi <= nzones; ++zi) {
      Zone z;
      z.index = zi;
      char name[64] = {};
      cgsize_t size[9] = {};
      CGNS_ENUMT(ZoneType_t) type;
      if (cg_zone_read(file_.fn, base_, zi, name, size) != CG_OK || cg_zone_type(file_.fn, base_, zi, &type) != CG_OK)
        return fail(Status::Corrupt, path_ + ": zone " + std::to_string(zi) + ": " + lastCgnsError());
      z.name = printable(name);
      if (type == CGNS_ENUMV(Structured)) {
        int indexDim = 0;
        if (cg_index_dim(file_.fn, base_, zi, &indexDim) != CG_OK || indexDim != 3)
          return fail(Status::Corrupt, zoneLabel(z) + ": a structured zone of a 3D base with index dimension " +
                                           std::to_string(indexDim));
        z.structured = true;
        for (int d = 0; d < 3; ++d) {
          if (size[d] < 1)
            return fail(Status::Corrupt, zoneLabel(z) + ": " + std::to_string(size[d]) + " vertices along index " +
                                             std::to_string(d + 1));
          z.dims[d] = uint64_t(size[d]);
        }
        // Each dimension is below 2^31: the products do not overflow.
        z.vertices = z.dims[0] * z.dims[1] * z.dims[2];
        z.cells = (z.dims[0] - 1) * (z.dims[1] - 1) * (z.dims[2] - 1);
      } else if (type == CGNS_ENUMV(Unstructured)) {
        if (size[0] < 0 || size[1] < 0)
          return fail(Status::Corrupt, zoneLabel(z) + ": " + std::to_string(size[0]) + " vertices, " +
                                           std::to_string(size[1]) + " cells");
        z.vertices = uint64_t(size[0]);
        z.cells = uint64_t(size[1]);
      } else {
        return fail(Status::Unsupported, zoneLabel(z) + ": zone type " + std::to_string(int(type)) +
                                             " (neither Structured nor Unstructured)");
      }
      if (Result r = checkCount(zoneLabel(z) + ": its number of vertices", z.vertices, 3 * 4); !r) return r;
      if (Result r = checkCount(zoneLabel(z) + ": its number of cells", z.cells, 4); !r) return r;
      z.vertexBase = totalVertices_;
      z.slotBase = slots;
      totalVertices_ += z.vertices;
      slots += z.cells;
      if (totalVertices_ > kMaxVertices)
        return fail(Status::TooLarge, path_ + ": more than 2^32-1 vertices in all zones");
      if (slots >= kNoCellValue) return fail(Status::TooLarge, path_ + ": more than 2^32-2 cells in all zones");
      structured_ += z.structured;
      zones_.push_back(std::move(z));
    }
    totalSlots_ = slots;
    if (zones_.empty()) return fail(Status::NoTets, path_ + ": base '" + baseName_ + "' has no zones");
    return Result::success();
  }

  // For one process of several, its zones only, or of fewer zones than processes its share of
  // each (the header comment), numbered from its first.
  Result keepShareOfZones() {
    const uint64_t n = options_.shareCount, z = zones_.size();
    if (n >= 2 && z < n) return keepSharesOfZones();
    if (n < 2) return Result::success();
    const uint64_t from = z * options_.shareIndex / n, to = z * (options_.shareIndex + 1) / n;
    zones_ = std::vector<Zone>(zones_.begin() + std::ptrdiff_t(from), zones_.begin() + std::ptrdiff_t(to));
    numberZones();
    report_.shared = true;
    report_.notes.push_back("read zones " + std::to_string(from + 1) + " to " + std::to_string(to) + " of " +
                            std::to_string(z) + ", this process's share of the file");
    return Result::success();
  }

  // Where each zone's points and cells' values start once the zones read are chosen, and the
  // totals.
  void numberZones() {
    totalVertices_ = totalSlots_ = 0;
    structured_ = 0;
    for (Zone& zone : zones_) {
      zone.vertexBase = totalVertices_;
      zone.slotBase = totalSlots_;
      totalVertices_ += zone.verticesRead();  // (what is read of it: all, a slab or a window)
      totalSlots_ += zone.cellCount;
      structured_ += zone.structured;
    }
  }

  static int longestAxis(const Zone& z) { return int(std::max_element(z.dims, z.dims + 3) - z.dims); }

  // Of fewer zones than processes, each process's share of every zone: a slab of a structured
  // zone, a window of an unstructured one (the header comment); every zone whole when a
  // structured one is too thin to give each process a layer of cells.
  Result keepSharesOfZones() {
    const uint64_t n = options_.shareCount;
    for (const Zone& z : zones_)
      if (z.structured && z.dims[longestAxis(z)] - 1 < n) return Result::success();
    uint64_t layers = 0, cellLayers = 0, elements = 0;
    for (Zone& z : zones_) {
      if (z.structured) {
        slabOfZone(z, layers, cellLayers);
      } else {
        elements += z.cells;
        if (Result r = windowOfZone(z); !r) return r;
      }
    }
    numberZones();
    report_.shared = true;
    const size_t unstructured = zones_.size() - structured_;
    const std::string slabs = "slab " + std::to_string(options_.shareIndex + 1) + " of " + std::to_string(n) + " of " +
                              (structured_ == 1 ? "the " : "each of the ") + zonesText(structured_, "structured") +
                              " (" + std::to_string(cellLayers) + " of " + std::to_string(layers) + " layers of cells)";
    uint64_t windowCells = 0, windowVertices = 0;
    const Zone* one = nullptr;  // the unstructured zone, when there is one
    for (const Zone& z : zones_)
      if (!z.structured) windowCells += z.cellCount, windowVertices += z.verticesRead(), one = &z;
    const std::string windows =
        unstructured == 1 ? "elements " + std::to_string(one->cellFirst + 1) + " to " +
                                std::to_string(one->cellFirst + one->cellCount) + " of " + std::to_string(one->cells) +
                                (structured_ ? " of the unstructured zone" : "") + " and the " +
                                std::to_string(one->verticesRead()) + " vertices they use"
                          : std::to_string(windowCells) + " of the " + std::to_string(elements) +
                                " elements (a share of each of the " + zonesText(unstructured, "unstructured") +
                                ") and the " + std::to_string(windowVertices) + " vertices they use";
    report_.notes.push_back("read " +
                            (unstructured == 0  ? slabs
                             : structured_ == 0 ? windows
                                                : slabs + " and " + windows) +
                            ", this process's share of the file");
    return Result::success();
  }

  // A structured zone's slab for this process: the layers of cells from index·L/count to
  // (index + 1)·L/count along its longest index direction, and their points.
  void slabOfZone(Zone& z, uint64_t& layers, uint64_t& cellLayers) {
    const uint64_t n = options_.shareCount, k = options_.shareIndex;
    const int a = longestAxis(z);
    const uint64_t K = z.dims[a] - 1, from = K * k / n, to = K * (k + 1) / n;
    z.slabAxis = a;
    z.slabFirst = from;
    z.dims[a] = to - from + 1;
    z.vertices = z.vertexCount = z.dims[0] * z.dims[1] * z.dims[2];
    z.cells = z.cellCount = (z.dims[0] - 1) * (z.dims[1] - 1) * (z.dims[2] - 1);
    layers += K;
    cellLayers += to - from;
  }

  // The window of one unstructured zone: the share's elements and the vertices their corners use
  // (the run they span, or only those: Zone::pick). The share's connectivity is read here to find
  // them and kept for readSections; of a MIXED section through io/cgns_mixed.h.
  Result windowOfZone(Zone& z) {
    const uint64_t from = z.cells * options_.shareIndex / options_.shareCount,
                   to = z.cells * (options_.shareIndex + 1ull) / options_.shareCount;
    int nsections = 0;
    if (cg_nsections(file_.fn, base_, z.index, &nsections) != CG_OK)
      return fail(Status::Corrupt, zoneLabel(z) + ": cannot read its element sections: " + lastCgnsError());
    std::vector<std::pair<int, Section>> read;  // the sections with elements in the window
    for (int s = 1; s <= nsections; ++s) {
      Section sec;
      if (Result r = readSection(z, s, sec); !r) return r;
      const cgsize_t first = std::max<cgsize_t>(sec.start, cgsize_t(from + 1)),
                     last = std::min<cgsize_t>(sec.end, cgsize_t(to));
      if (first > last) continue;
      std::vector<cgsize_t>& conn = z.windowConnectivity[s];
      if (sec.type == "MIXED") {
        cgsize_t dataSize = 0;
        bool walked = false;
        if (cg_ElementDataSize(file_.fn, base_, z.index, s, &dataSize) != CG_OK)
          return fail(Status::Corrupt, sec.where + ": " + lastCgnsError());
        if (Result r = cgns::readMixedWindow(file_.fn, sec.path, sec.where, sec.start, sec.end, dataSize, first, last,
                                             conn, walked);
            !r)
          return r;
        if (walked)
          report_.notes.push_back(sec.where + ": its ElementStartOffset does not say where this process's elements " +
                                  "begin; found by their types, from the first element");
      } else {
        int npe = 0;
        if (!cgnsType(sec.type).volume || cg_npe(sec.etype, &npe) != CG_OK || npe < 1) {
          z.windowConnectivity.erase(s);
          continue;
        }
        conn.resize(size_t(last - first + 1) * size_t(npe));
        if (cg_elements_partial_read(file_.fn, base_, z.index, s, first, last, conn.data(), nullptr) != CG_OK)
          return fail(Status::Corrupt, sec.where + ": " + lastCgnsError());
      }
      read.emplace_back(s, sec);
    }
    // The vertices the volume elements' corners use (higher-order nodes and the nodes of elements
    // that are not read are not read).
    uint64_t lo = UINT64_MAX, hi = 0;
    auto eachCorner = [&](auto&& visit) {
      for (const auto& [s, sec] : read)
        forEachElement(sec, z.windowConnectivity[s], [&](const CgnsType& kind, const cgsize_t* nodes, int count) {
          if (!kind.volume) return;
          for (int q = 0; q < std::min(count, kShapeCorners[int(kind.shape)]); ++q)
            if (nodes[q] >= 1 && uint64_t(nodes[q]) <= z.vertices) visit(uint64_t(nodes[q] - 1));
        });
    };
    eachCorner([&](uint64_t v) { lo = std::min(lo, v), hi = std::max(hi, v + 1); });
    if (hi == 0) lo = 0;
    z.vertexFirst = lo;
    z.vertexCount = hi - lo;
    z.used.emplace(lo, hi - lo);
    eachCorner([&](uint64_t v) { z.used->mark(v); });
    z.used->finish();
    if (!z.used->all()) z.pick = z.used->rows();
    z.cellFirst = from;
    z.cellCount = to - from;
    z.window = true;
    return Result::success();
  }

  // Calls visit(its type, nodes, node count) for each element of a section's connectivity: of a
  // MIXED section each element's code says its type (checked when it was read), else every
  // element is the section's type.
  template <class Visit>
  static void forEachElement(const Section& sec, std::span<const cgsize_t> conn, Visit&& visit) {
    if (sec.type == "MIXED") {
      for (size_t at = 0; at < conn.size();) {
        const int entries = cgns::mixedEntries(conn[at]);
        if (entries == 0 || size_t(entries) > conn.size() - at) return;
        visit(typeOfCode(conn[at]), &conn[at + 1], entries - 1);
        at += size_t(entries);
      }
      return;
    }
    int npe = 0;
    if (cg_npe(sec.etype, &npe) != CG_OK || npe < 1) return;
    const CgnsType kind = cgnsType(sec.type);
    for (size_t at = 0; at + size_t(npe) <= conn.size(); at += size_t(npe)) visit(kind, &conn[at], npe);
  }

  // Section s of zone z.
  Result readSection(const Zone& z, int s, Section& out) {
    char name[64] = {};
    int nbndry = 0, parentFlag = 0;
    if (cg_section_read(file_.fn, base_, z.index, s, name, &out.etype, &out.start, &out.end, &nbndry, &parentFlag) !=
        CG_OK)
      return fail(Status::Corrupt, zoneLabel(z) + ": section " + std::to_string(s) + ": " + lastCgnsError());
    out.where = zoneLabel(z) + " section '" + printable(name) + "'";
    out.path = "/" + baseName_ + "/" + z.name + "/" + name;
    out.type = elementTypeName(int(out.etype));
    return Result::success();
  }

  // The step's times from BaseIterativeData, and each zone's solution for it.
  Result readTimes(size_t& step) {
    char name[64] = {};
    int nsteps = 0;
    std::vector<double> times;
    const int found = cg_biter_read(file_.fn, base_, name, &nsteps);
    if (found == CG_OK && nsteps > 0) {
      if (Result r = checkCount("the number of time steps", uint64_t(nsteps), 4); !r) return r;
      if (Result r = readStepValues(nsteps, times); !r) return r;
    } else if (found == CG_ERROR) {
      return fail(Status::Corrupt, path_ + ": base '" + baseName_ + "': BaseIterativeData: " + lastCgnsError());
    }
    if (Result r = chooseTimeStep(times, options_, path_, report_, step); !r) return r;
    if (times.empty()) return Result::success();
    for (Zone& z : zones_) {
      char zname[64] = {};
      const int has = cg_ziter_read(file_.fn, base_, z.index, zname);
      if (has == CG_NODE_NOT_FOUND) {
        report_.notes.push_back(zoneLabel(z) + " has no ZoneIterativeData: its solutions are the same at every step");
        continue;
      }
      if (has != CG_OK) return fail(Status::Corrupt, zoneLabel(z) + ": ZoneIterativeData: " + lastCgnsError());
      std::vector<std::string> pointers;
      if (Result r = readSolutionPointers(z, size_t(nsteps), pointers); !r) return r;
      if (pointers.empty()) {
        report_.notes.push_back(zoneLabel(z) +
                                " has no FlowSolutionPointers: its solutions are the same at every step");
        continue;
      }
      z.stepSolution = true;
      z.solution = pointers[step];
    }
    return Result::success();
  }

  Result readStepValues(int nsteps, std::vector<double>& times) {
    if (cg_goto(file_.fn, base_, "BaseIterativeData_t", 1, "end") != CG_OK)
      return fail(Status::Corrupt, path_ + ": BaseIterativeData: " + lastCgnsError());
    int narrays = 0;
    if (cg_narrays(&narrays) != CG_OK) return fail(Status::Corrupt, path_ + ": BaseIterativeData: " + lastCgnsError());
    int timeArray = 0, iterationArray = 0;
    for (int a = 1; a <= narrays; ++a) {
      char aname[64] = {};
      CGNS_ENUMT(DataType_t) type;
      int ndim = 0;
      cgsize_t dims[12] = {};
      if (cg_array_info(a, aname, &type, &ndim, dims) != CG_OK)
        return fail(Status::Corrupt, path_ + ": BaseIterativeData array " + std::to_string(a) + ": " + lastCgnsError());
      const bool right = ndim == 1 && dims[0] == nsteps && type != CGNS_ENUMV(Character);
      if (std::string(aname) == "TimeValues" && right) timeArray = a;
      if (std::string(aname) == "IterationValues" && right) iterationArray = a;
    }
    const int use = timeArray ? timeArray : iterationArray;
    if (!use) {
      report_.notes.push_back(path_ + ": BaseIterativeData lists " + std::to_string(nsteps) +
                              " steps but no TimeValues or IterationValues of that length; read as one state");
      return Result::success();
    }
    times.resize(size_t(nsteps));
    if (cg_array_read_as(use, CGNS_ENUMV(RealDouble), times.data()) != CG_OK)
      return fail(Status::Corrupt, path_ + ": BaseIterativeData " + (timeArray ? "TimeValues" : "IterationValues") +
                                       ": " + lastCgnsError());
    if (!timeArray) report_.notes.push_back("the steps have no TimeValues: their IterationValues serve as times");
    return Result::success();
  }

  Result readSolutionPointers(const Zone& z, size_t nsteps, std::vector<std::string>& pointers) {
    if (cg_goto(file_.fn, base_, "Zone_t", z.index, "ZoneIterativeData_t", 1, "end") != CG_OK)
      return fail(Status::Corrupt, zoneLabel(z) + ": ZoneIterativeData: " + lastCgnsError());
    int narrays = 0;
    if (cg_narrays(&narrays) != CG_OK)
      return fail(Status::Corrupt, zoneLabel(z) + ": ZoneIterativeData: " + lastCgnsError());
    for (int a = 1; a <= narrays; ++a) {
      char aname[64] = {};
      CGNS_ENUMT(DataType_t) type;
      int ndim = 0;
      cgsize_t dims[12] = {};
      if (cg_array_info(a, aname, &type, &ndim, dims) != CG_OK)
        return fail(Status::Corrupt,
                    zoneLabel(z) + ": ZoneIterativeData array " + std::to_string(a) + ": " + lastCgnsError());
      if (std::string(aname) != "FlowSolutionPointers") continue;
      if (type != CGNS_ENUMV(Character) || ndim != 2 || dims[0] < 1 || dims[0] > 256 || uint64_t(dims[1]) != nsteps)
        return fail(Status::Corrupt, zoneLabel(z) + ": FlowSolutionPointers is not " + std::to_string(nsteps) +
                                         " names (one per step of BaseIterativeData)");
      std::vector<char> text(size_t(dims[0]) * nsteps);
      if (cg_array_read(a, text.data()) != CG_OK)
        return fail(Status::Corrupt, zoneLabel(z) + ": FlowSolutionPointers: " + lastCgnsError());
      for (size_t s = 0; s < nsteps; ++s) {
        std::string n(text.data() + s * size_t(dims[0]), size_t(dims[0]));
        n = n.substr(0, n.find('\0'));
        while (!n.empty() && n.back() == ' ') n.pop_back();
        pointers.push_back(n);
      }
      return Result::success();
    }
    return Result::success();
  }

  Result readCoordinate(const Zone& z, const char* name, std::vector<double>& values) {
    cgsize_t lo[3] = {1, 1, 1}, hi[3] = {1, 1, 1};
    if (z.structured) {
      for (int d = 0; d < 3; ++d) hi[d] = cgsize_t(z.dims[d]);
      lo[z.slabAxis] = cgsize_t(z.slabFirst + 1);
      hi[z.slabAxis] += cgsize_t(z.slabFirst);
    } else {
      lo[0] = cgsize_t(z.vertexFirst + 1);
      hi[0] = cgsize_t(z.vertexFirst + z.vertexCount);
    }
    auto read = [&](std::vector<double>& out) {
      out.resize(size_t(hi[0] - lo[0] + 1) * size_t(hi[1] - lo[1] + 1) * size_t(hi[2] - lo[2] + 1));
      if (cg_coord_read(file_.fn, base_, z.index, name, CGNS_ENUMV(RealDouble), lo, hi, out.data()) != CG_OK)
        return fail(Status::Corrupt, zoneLabel(z) + ": " + name + ": " + lastCgnsError());
      return Result::success();
    };
    if (z.pick.empty()) return read(values);
    return io::readPickedRows(
        z.pick, z.vertices, true, zoneLabel(z) + ": " + name,
        [&](uint64_t from, uint64_t n, std::vector<double>& window) {
          lo[0] = cgsize_t(from + 1);
          hi[0] = cgsize_t(from + n);
          return read(window);
        },
        values);
  }

  Result readCoordinates(const Zone& z, TetMesh& mesh) {
    if (z.verticesRead() == 0) return Result::success();
    int ncoords = 0;
    if (cg_ncoords(file_.fn, base_, z.index, &ncoords) != CG_OK)
      return fail(Status::Corrupt, zoneLabel(z) + ": GridCoordinates: " + lastCgnsError());
    std::string names;
    bool cartesian[3] = {false, false, false}, cylindrical[3] = {false, false, false};
    for (int c = 1; c <= ncoords; ++c) {
      char name[64] = {};
      CGNS_ENUMT(DataType_t) type;
      if (cg_coord_info(file_.fn, base_, z.index, c, &type, name) != CG_OK)
        return fail(Status::Corrupt, zoneLabel(z) + ": coordinate " + std::to_string(c) + ": " + lastCgnsError());
      const std::string n = name;
      names += (names.empty() ? "" : ", ") + printable(n);
      cartesian[0] |= n == "CoordinateX", cartesian[1] |= n == "CoordinateY", cartesian[2] |= n == "CoordinateZ";
      cylindrical[0] |= n == "CoordinateR", cylindrical[1] |= n == "CoordinateTheta";
      cylindrical[2] |= n == "CoordinateZ";
    }
    std::vector<double> a, b, c;
    const bool cyl = !(cartesian[0] && cartesian[1] && cartesian[2]);
    if (cyl && !(cylindrical[0] && cylindrical[1] && cylindrical[2]))
      return fail(Status::Unsupported, zoneLabel(z) + ": coordinates " + (names.empty() ? "(none)" : names) +
                                           "; expected CoordinateX, CoordinateY, CoordinateZ (or CoordinateR, "
                                           "CoordinateTheta, CoordinateZ)");
    if (Result r = readCoordinate(z, cyl ? "CoordinateR" : "CoordinateX", a); !r) return r;
    if (Result r = readCoordinate(z, cyl ? "CoordinateTheta" : "CoordinateY", b); !r) return r;
    if (Result r = readCoordinate(z, "CoordinateZ", c); !r) return r;
    if (cyl && !cylindricalNoted_) {
      cylindricalNoted_ = true;
      report_.notes.push_back("converted cylindrical coordinates (R, Theta, Z) to Cartesian");
    }
    for (uint64_t v = 0; v < z.verticesRead(); ++v) {
      double x = a[v], y = b[v];
      if (cyl) x = a[v] * std::cos(b[v]), y = a[v] * std::sin(b[v]);
      if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(c[v]))
        return fail(Status::NonFinite, zoneLabel(z) + ": vertex " +
                                           std::to_string((z.pick.empty() ? z.vertexFirst + v : z.pick[v]) + 1) +
                                           " has a non-finite coordinate");
      float* p = &mesh.positions[3 * (z.vertexBase + v)];
      p[0] = float(x), p[1] = float(y), p[2] = float(c[v]);
    }
    return Result::success();
  }

  Result readStructuredCells(const Zone& z, CellSoup& soup) {
    appendStructuredCells(z.dims[0], z.dims[1], z.dims[2], z.vertexBase, z.slotBase, soup);
    soup.inputCells += z.cells;
    return Result::success();
  }

  // One element of an unstructured zone: e is its element number (1-based within the zone).
  Result addElement(const Zone& z, const std::string& where, const std::string& type, const CgnsType& kind,
                    const cgsize_t* nodes, int count, int64_t e, CellSoup& soup) {
    if (!kind.volume) {
      ++soup.skipped[{kind.vtkType, "CGNS " + type}];
      for (int q = 0; q < count; ++q)
        if (const int64_t at = z.vertexRead(nodes[q]); at >= 0) soup.referenced[z.vertexBase + uint64_t(at)] = 1;
      return Result::success();
    }
    const int corners = kShapeCorners[int(kind.shape)];
    if (count < corners)
      return fail(Status::Corrupt,
                  where + ": element " + std::to_string(e) + " (" + type + ") has " + std::to_string(count) + " nodes");
    uint32_t ids[8];
    for (int q = 0; q < count; ++q) {
      const cgsize_t v = nodes[q];
      if (v < 1 || uint64_t(v) > z.vertices)
        return fail(Status::OutOfRange, where + ": element " + std::to_string(e) + " (" + type + ") uses vertex " +
                                            std::to_string(v) + ", but the zone's vertices are numbered 1.." +
                                            std::to_string(z.vertices));
      const int64_t at = z.vertexRead(v);
      if (at < 0 && (q < corners || !z.used))  // (a share reads its elements' corners: not reached)
        return fail(Status::OutOfRange, where + ": element " + std::to_string(e) + " uses vertex " + std::to_string(v) +
                                            " outside the vertices read");
      if (at < 0) continue;  // (a higher-order node a share does not read)
      soup.referenced[z.vertexBase + uint64_t(at)] = 1;
      if (q < corners) ids[q] = uint32_t(z.vertexBase + uint64_t(at));
    }
    const uint64_t source = uint64_t(e) > z.cellFirst && uint64_t(e) <= z.cellFirst + z.cellCount
                                ? z.slotBase + uint64_t(e - 1) - z.cellFirst
                                : kNoCellValue;
    soup.add(kind.shape, ids, source);
    if (count > corners) {
      auto& r = soup.reduced["CGNS " + type];
      r.first = corners;
      ++r.second;
    }
    return Result::success();
  }

  Result readSections(Zone& z, CellSoup& soup) {
    int nsections = 0;
    if (cg_nsections(file_.fn, base_, z.index, &nsections) != CG_OK)
      return fail(Status::Corrupt, zoneLabel(z) + ": cannot read its element sections: " + lastCgnsError());
    if (soup.referenced.size() < totalVertices_) soup.referenced.resize(size_t(totalVertices_), 0);
    for (int s = 1; s <= nsections; ++s) {
      Section sec;
      if (Result r = readSection(z, s, sec); !r) return r;
      const std::string& where = sec.where;
      const std::string& type = sec.type;
      const CGNS_ENUMT(ElementType_t) etype = sec.etype;
      const cgsize_t start = sec.start, end = sec.end;
      if (end < start)
        return fail(Status::Corrupt, where + ": element range " + std::to_string(start) + ".." + std::to_string(end));
      const uint64_t count = uint64_t(end) - uint64_t(start) + 1;
      if (Result r = checkCount(where + ": its number of elements", count, 4); !r) return r;
      // The elements read: all, or those in a share's window (first > last: none).
      const cgsize_t first = z.window ? std::max<cgsize_t>(start, cgsize_t(z.cellFirst + 1)) : start,
                     last = z.window ? std::min<cgsize_t>(end, cgsize_t(z.cellFirst + z.cellCount)) : end;
      const uint64_t reading = last >= first ? uint64_t(last - first + 1) : 0;
      soup.inputCells += reading;
      if (type == "NFACE_n")
        return fail(Status::Unsupported, where + ": " + std::to_string(count) +
                                             " NFACE_n cells (polyhedra given by their faces) are not read; "
                                             "convert the zone to standard elements (TETRA_4, HEXA_8, ...)");
      if (type == "NGON_n") {  // faces of polyhedra or a polygonal surface: not volume cells
        soup.skipped[{7, "CGNS NGON_n"}] += reading;
        continue;
      }
      cgsize_t dataSize = 0;
      if (cg_ElementDataSize(file_.fn, base_, z.index, s, &dataSize) != CG_OK)
        return fail(Status::Corrupt, where + ": " + lastCgnsError());
      if (dataSize < 0) return fail(Status::Corrupt, where + ": " + std::to_string(dataSize) + " connectivity entries");
      if (Result r = checkCount(where + ": its connectivity size", uint64_t(dataSize), 4); !r) return r;
      std::vector<cgsize_t> conn(static_cast<size_t>(dataSize));
      if (type == "MIXED" && z.window) {  // the window's elements, read and checked when it was chosen
        auto kept = z.windowConnectivity.find(s);
        if (reading == 0 || kept == z.windowConnectivity.end()) continue;
        int64_t element = int64_t(first);
        for (size_t at = 0; at < kept->second.size(); ++element) {
          const cgsize_t* e = &kept->second[at];
          const int entries = cgns::mixedEntries(e[0]);  // (checked as the window was read)
          if (entries == 0 || size_t(entries) > kept->second.size() - at)
            return fail(Status::Corrupt, where + ": element " + std::to_string(element) + " is damaged");
          const std::string name = elementTypeName(int(e[0]));
          if (Result r = addElement(z, where, name, cgnsType(name), e + 1, entries - 1, element, soup); !r) return r;
          at += size_t(entries);
        }
        z.windowConnectivity.erase(kept);
        continue;
      }
      if (type == "MIXED") {
        if (Result r = readMixed(z, s, where, start, count, conn, soup); !r) return r;
        continue;
      }
      const CgnsType kind = cgnsType(type);
      int npe = 0;
      if (type.empty() || cg_npe(etype, &npe) != CG_OK || npe < 1)
        return fail(Status::Unsupported,
                    where + ": element type " + (type.empty() ? std::to_string(int(etype)) : type) + " is not read");
      if (uint64_t(dataSize) != count * uint64_t(npe))
        return fail(Status::Corrupt, where + ": " + std::to_string(count) + " " + type + " elements need " +
                                         std::to_string(count * uint64_t(npe)) + " node ids, the section has " +
                                         std::to_string(dataSize));
      if (reading == 0) continue;
      if (auto kept = z.windowConnectivity.find(s); kept != z.windowConnectivity.end()) {
        conn = std::move(kept->second);  // (read when the window was chosen)
        z.windowConnectivity.erase(kept);
      } else {
        conn.resize(size_t(reading) * size_t(npe));
        if (cg_elements_partial_read(file_.fn, base_, z.index, s, first, last, conn.data(), nullptr) != CG_OK)
          return fail(Status::Corrupt, where + ": " + lastCgnsError());
      }
      for (uint64_t k = 0; k < reading; ++k)
        if (Result r = addElement(z, where, type, kind, &conn[size_t(k) * size_t(npe)], npe,
                                  int64_t(first) + int64_t(k), soup);
            !r)
          return r;
    }
    return Result::success();
  }

  // MIXED: each element is its type code followed by its nodes. The codes alone say where each
  // element begins (a MIXED section holds fixed-size types only), and files written before
  // CGNS 3.4 have nothing else; ElementStartOffset, where present, is only compared (CGNS
  // 3.4.0's own tecplot_to_cgns writes it wrong, and the library's tools walk the codes too).
  Result readMixed(const Zone& z, int s, const std::string& where, cgsize_t start, uint64_t count,
                   std::vector<cgsize_t>& conn, CellSoup& soup) {
    std::vector<cgsize_t> offsets(size_t(count) + 1);
    if (cg_poly_elements_read(file_.fn, base_, z.index, s, conn.data(), offsets.data(), nullptr) != CG_OK)
      return fail(Status::Corrupt, where + ": " + lastCgnsError());
    const uint64_t size = conn.size();
    uint64_t at = 0, offsetsDiffer = 0;
    for (uint64_t k = 0; k < count; ++k) {
      const int64_t element = int64_t(start) + int64_t(k);
      if (at >= size)
        return fail(Status::Corrupt, where + ": the connectivity (" + std::to_string(size) +
                                         " entries) ends at element " + std::to_string(element) + " of " +
                                         std::to_string(start) + ".." +
                                         std::to_string(int64_t(start) + int64_t(count) - 1));
      offsetsDiffer += uint64_t(offsets[k]) != at;
      const cgsize_t code = conn[size_t(at)];
      const std::string type = elementTypeName(int(code));
      int npe = 0;
      if (type.empty() || type == "MIXED" || type == "NGON_n" || type == "NFACE_n" ||
          cg_npe(CGNS_ENUMT(ElementType_t)(code), &npe) != CG_OK || npe < 1)
        return fail(Status::Corrupt, where + ": element " + std::to_string(element) + " has element type code " +
                                         std::to_string(code) + ", not one a MIXED section may hold");
      if (uint64_t(npe) > size - at - 1)
        return fail(Status::Corrupt, where + ": element " + std::to_string(element) + " (" + type + ") needs " +
                                         std::to_string(npe) + " nodes; the connectivity ends after " +
                                         std::to_string(size - at - 1));
      if (Result r = addElement(z, where, type, cgnsType(type), &conn[size_t(at) + 1], npe, element, soup); !r)
        return r;
      at += 1 + uint64_t(npe);
    }
    if (at != size)
      return fail(Status::Corrupt, where + ": " + std::to_string(count) + " elements use " + std::to_string(at) +
                                       " connectivity entries of " + std::to_string(size));
    offsetsDiffer += uint64_t(offsets[count]) != at;
    if (offsetsDiffer)
      report_.notes.push_back(where + ": ElementStartOffset disagrees with the element types at " +
                              std::to_string(offsetsDiffer) + " of " + std::to_string(count + 1) +
                              " entries; read by the types");
    return Result::success();
  }

  // Fields by name, in the order first seen, over all zones' points or cells (NaN where a zone
  // has none).
  struct Collected {
    std::vector<std::string> names;
    std::map<std::string, size_t> index;
    std::vector<std::vector<double>> values;
    std::vector<double>& get(const std::string& name, size_t length) {
      auto [it, added] = index.emplace(name, names.size());
      if (added) {
        names.push_back(name);
        values.emplace_back(length, std::numeric_limits<double>::quiet_NaN());
      }
      return values[it->second];
    }
  };

  Result readSolutions(TetMesh& mesh, std::vector<CellArray>& cellArrays) {
    Collected points, cells;
    for (const Zone& z : zones_) {
      int nsols = 0;
      if (cg_nsols(file_.fn, base_, z.index, &nsols) != CG_OK)
        return fail(Status::Corrupt, zoneLabel(z) + ": cannot read its FlowSolution nodes: " + lastCgnsError());
      bool pointedFound = false;
      std::map<std::string, int> seen;  // "V:name" / "C:name" in this zone
      for (int s = 1; s <= nsols; ++s) {
        char name[64] = {};
        CGNS_ENUMT(GridLocation_t) location;
        if (cg_sol_info(file_.fn, base_, z.index, s, name, &location) != CG_OK)
          return fail(Status::Corrupt, zoneLabel(z) + ": FlowSolution " + std::to_string(s) + ": " + lastCgnsError());
        const std::string sol = printable(name);
        if (z.stepSolution && sol != z.solution) continue;
        pointedFound = true;
        const std::string where = zoneLabel(z) + " FlowSolution '" + sol + "'";
        CGNS_ENUMT(PointSetType_t) ptset;
        cgsize_t npnts = 0;
        if (cg_sol_ptset_info(file_.fn, base_, z.index, s, &ptset, &npnts) == CG_OK &&
            ptset != CGNS_ENUMV(PointSetTypeNull)) {
          report_.notes.push_back("skipped " + where + ": it covers a subset of the zone (PointList/PointRange)");
          continue;
        }
        const bool vertex = location == CGNS_ENUMV(Vertex), cell = location == CGNS_ENUMV(CellCenter);
        if (!vertex && !cell) {
          const char* ln = int(location) >= 0 && int(location) < NofValidGridLocation ? cg_GridLocationName(location)
                                                                                      : "an unknown location";
          report_.notes.push_back("skipped " + where + ": values at " + ln + " (Vertex and CellCenter are read)");
          continue;
        }
        if (Result r = readFields(z, s, where, vertex, vertex ? points : cells, seen); !r) return r;
      }
      if (z.stepSolution && !z.solution.empty() && z.solution != "Null" && !pointedFound)
        return fail(Status::Corrupt, zoneLabel(z) + ": FlowSolutionPointers names '" + z.solution + "' for step " +
                                         std::to_string(report_.stepRead) + ", but the zone has no such FlowSolution");
    }
    const size_t firstField = mesh.fields.size();
    for (size_t i = 0; i < points.names.size(); ++i) {
      ScalarField f;
      f.name = points.names[i];
      f.values.assign(points.values[i].begin(), points.values[i].end());
      addField(mesh, std::move(f), report_);
    }
    addComponentMagnitudes(mesh, firstField, report_);
    for (size_t i = 0; i < cells.names.size(); ++i) cellArrays.push_back({cells.names[i], std::move(cells.values[i])});
    addComponentMagnitudes(cellArrays, 0, report_);
    return Result::success();
  }

  Result readFields(const Zone& z, int s, const std::string& where, bool vertex, Collected& into,
                    std::map<std::string, int>& seen) {
    int nfields = 0;
    if (cg_nfields(file_.fn, base_, z.index, s, &nfields) != CG_OK)
      return fail(Status::Corrupt, where + ": " + lastCgnsError());
    const uint64_t n = vertex ? z.verticesRead() : z.cellCount;
    cgsize_t lo[3] = {1, 1, 1}, hi[3] = {1, 1, 1};
    if (z.structured) {
      for (int d = 0; d < 3; ++d) hi[d] = cgsize_t(vertex ? z.dims[d] : z.dims[d] - 1);
      lo[z.slabAxis] = cgsize_t(z.slabFirst + 1);
      hi[z.slabAxis] += cgsize_t(z.slabFirst);
    } else {
      lo[0] = cgsize_t((vertex ? z.vertexFirst : z.cellFirst) + 1);
      hi[0] = cgsize_t((vertex ? z.vertexFirst : z.cellFirst) + (vertex ? z.vertexCount : n));
    }
    auto read = [&](const char* fname, std::vector<double>& out) {
      out.resize(size_t(hi[0] - lo[0] + 1) * size_t(hi[1] - lo[1] + 1) * size_t(hi[2] - lo[2] + 1));
      return cg_field_read(file_.fn, base_, z.index, s, fname, CGNS_ENUMV(RealDouble), lo, hi, out.data()) == CG_OK;
    };
    std::vector<double> values(static_cast<size_t>(n));
    for (int f = 1; f <= nfields; ++f) {
      char fname[64] = {};
      CGNS_ENUMT(DataType_t) type;
      if (cg_field_info(file_.fn, base_, z.index, s, f, &type, fname) != CG_OK)
        return fail(Status::Corrupt, where + ": field " + std::to_string(f) + ": " + lastCgnsError());
      const std::string field = printable(fname);
      if (type == CGNS_ENUMV(Character)) continue;
      if (seen[std::string(vertex ? "V:" : "C:") + field]++) {
        report_.notes.push_back("skipped " + where + " field '" + field + "': an earlier solution of the zone has it");
        continue;
      }
      const std::string what = where + " field '" + field + "'";
      if (n && vertex && !z.pick.empty()) {
        const cgsize_t runLo = lo[0], runHi = hi[0];
        Result r = io::readPickedRows(
            z.pick, z.vertices, true, what,
            [&](uint64_t from, uint64_t count, std::vector<double>& window) {
              lo[0] = cgsize_t(from + 1);
              hi[0] = cgsize_t(from + count);
              return read(fname, window) ? Result::success() : fail(Status::Corrupt, what + ": " + lastCgnsError());
            },
            values);
        lo[0] = runLo, hi[0] = runHi;
        if (!r) return r;
      } else if (n && !read(fname, values)) {
        return fail(Status::Corrupt, what + ": " + lastCgnsError());
      }
      std::vector<double>& dst = into.get(field, size_t(vertex ? totalVertices_ : totalSlots_));
      std::copy(values.begin(), values.end(), dst.begin() + std::ptrdiff_t(vertex ? z.vertexBase : z.slotBase));
    }
    return Result::success();
  }

  std::string formatText() const {
    int type = 0;
    cg_get_file_type(file_.fn, &type);
    const char* container = type == CG_FILE_HDF5 ? "HDF5" : (type == CG_FILE_ADF || type == CG_FILE_ADF2) ? "ADF" : "?";
    const size_t unstructured = zones_.size() - structured_;
    std::string s = std::string("CGNS (") + container + "), base '" + baseName_ + "', ";
    if (unstructured && structured_)
      s += zonesText(unstructured, "unstructured") + " + " + zonesText(structured_, "structured");
    else
      s += zonesText(zones_.size(), structured_ ? "structured" : "unstructured");
    return s + stepText(report_);
  }

  const std::string& path_;
  const ReadOptions& options_;
  ReadReport& report_;
  CgnsFile file_;
  Container container_ = Container::None;
  uint64_t limit_ = 0;
  int base_ = 0;
  std::string baseName_;
  std::vector<Zone> zones_;
  size_t structured_ = 0;
  uint64_t totalVertices_ = 0, totalSlots_ = 0;
  bool cylindricalNoted_ = false;
};

}  // namespace

Result readCgns(const std::string& path, const ReadOptions& options, TetMesh& out, ReadReport& report) {
  out = TetMesh{};
  return CgnsReader(path, options, report).read(out);
}

}  // namespace tetstream
