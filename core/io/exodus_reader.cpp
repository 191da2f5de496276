// Exodus II reader (readers.h), through SEACAS's Exodus II library over netCDF. The library
// parses the container; this file checks what it reports before sizing anything by it and turns
// every failure into a Result naming the file and the item (block id, variable name).
//
// What is read, in the file's internal numbering (connectivity and variables both use it, so the
// node and element number maps are not needed to match them; they only name nodes and elements
// in messages, as users know them by those ids):
//   - coordinates (num_dim 3);
//   - element blocks, in file order: TETRA/TET, HEX, WEDGE, PYRAMID of any node count (corners
//     first in Exodus as in VTK; higher-order nodes dropped); HEXSHELL, NFACED, lower-dimensional
//     and unknown types skipped with a count by type name;
//   - the time steps' times (ex_get_all_times -> chooseTimeStep), then the chosen step's nodal
//     variables (fields) and element variables (cell data, NaN where the truth table leaves a
//     block out). Vectors are stored as components (vel_x, vel_y, vel_z): each stays a field
//     under its own name, and NAME_magnitude is added (the readers' name for a vector's norm).
// Not read: global, node set and side set variables, sets, attributes.
//
// A share for one of several processes (ReadOptions::shareIndex of shareCount, core/dist): the
// elements from index·N/count to (index + 1)·N/count in file order (all blocks), and the nodes
// their corners use (the run from the smallest to the largest, or of it only those, a window at
// a time: io/row_pick.h), with those rows of every variable, all through the library's partial
// reads; nodes on the cuts are read by both sides and joined later by their coordinates.
#include <exodusII.h>
#include <netcdf.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>

#include "io/readers.h"
#include "io/row_pick.h"

namespace tetstream {
namespace {

using namespace vtkio;

// The library's return codes (exodusII_int.h, not a public header): 0 success, 1 a warning
// (something not found: no data was read), negative an error.
constexpr int kExodusOk = 0;

std::string lastExodusError() {
  const char* msg = nullptr;
  const char* func = nullptr;
  int code = 0;
  ex_get_err(&msg, &func, &code);
  std::string s = msg && *msg ? msg : "no details from the library";
  if (s.size() > 240) s = s.substr(0, 240) + "...";
  return s;
}

// Closes the file however the read ends.
struct ExodusFile {
  int id = -1;
  ~ExodusFile() {
    if (id >= 0) ex_close(id);
  }
};

std::string upper(std::string_view s) {
  std::string out(s);
  for (char& c : out)
    if (c >= 'a' && c <= 'z') c = char(c - 'a' + 'A');
  return out;
}

// An Exodus element type name (topology) as tetstream reads it.
struct ExodusType {
  bool volume = false;
  CellShape shape = CellShape::Tet;
  int vtkType = 0;       // of a skipped type, for ReadReport::skippedCells (0: none)
  bool special = false;  // NFACED/NSIDED: connectivity is not nodes-per-element
};

ExodusType exodusType(std::string_view topology, int64_t nodes) {
  const std::string t = upper(topology);
  auto starts = [&](const char* p) { return t.rfind(p, 0) == 0; };
  ExodusType e;
  if (starts("NFACED") || starts("NSIDED")) {
    e.special = true;
    return e;
  }
  if (starts("HEXSHELL")) return e;  // a shell element, 12 nodes; not a volume cell
  if (starts("TET")) return {true, CellShape::Tet, 10};
  if (starts("HEX")) return {true, CellShape::Hex, 12};
  if (starts("WEDGE")) return {true, CellShape::Wedge, 13};
  if (starts("PYRA")) return {true, CellShape::Pyramid, 14};
  // Lower-dimensional cells, by node count: VTK's linear or quadratic cell of the same kind.
  if (starts("TRI")) e.vtkType = nodes == 3 ? 5 : nodes == 6 ? 22 : 0;
  if (starts("QUAD") || starts("SHELL")) e.vtkType = nodes == 4 ? 9 : nodes == 8 ? 23 : nodes == 9 ? 28 : 0;
  if (starts("BAR") || starts("BEAM") || starts("TRUSS") || starts("ROD") || starts("EDGE"))
    e.vtkType = nodes == 2 ? 3 : nodes == 3 ? 21 : 0;
  if (starts("SPHERE") || starts("CIRCLE") || starts("POINT")) e.vtkType = 1;
  return e;
}

struct Block {
  int64_t id = 0;
  std::string type;  // as the file spells it
  int64_t count = 0, nodesPer = 0;
  ExodusType kind;
  uint64_t firstElement = 0;  // index of its first element among all blocks'
  // The elements read (all, or those of this process's share): from readFrom (0-based in the
  // block), readCount of them; their cell data goes from localFirst among the cells read.
  int64_t readFrom = 0, readCount = 0;
  uint64_t localFirst = 0;
};

class ExodusReader {
 public:
  ExodusReader(const std::string& path, const ReadOptions& options, ReadReport& report)
      : path_(path), options_(options), report_(report) {}

  Result read(TetMesh& out) {
    std::error_code ec;
    const uint64_t fileBytes = fileBytes_ = std::filesystem::file_size(path_, ec);
    if (ec) return fail(Status::IoError, path_ + ": cannot open (" + ec.message() + ")");
    std::lock_guard<std::mutex> lock(hpcLibraryMutex());
    if (Result r = checkExodusFile(path_, container_); !r) return r;
    limit_ = maxDecodedBytes(fileBytes, container_);
    ex_opts(0);  // no messages on stderr, never abort: failures come back as return codes
    int cpuWordSize = 8, ioWordSize = 0;
    float version = 0;
    file_.id = ex_open(path_.c_str(), EX_READ | EX_ALL_INT64_API, &cpuWordSize, &ioWordSize, &version);
    if (file_.id < 0) return fail(Status::Corrupt, path_ + ": not a readable Exodus II file: " + lastExodusError());
    ioWordSize_ = ioWordSize == 4 ? 4 : 8;

    ex_init_params init{};
    if (ex_get_init_ext(file_.id, &init) != kExodusOk)
      return fail(Status::Corrupt, path_ + ": cannot read the Exodus II header: " + lastExodusError());
    if (Result r = checkInit(init); !r) return r;
    // Names longer than the default 32 characters (the file says how long its longest is).
    const int64_t nameLength = ex_inquire_int(file_.id, EX_INQ_DB_MAX_USED_NAME_LENGTH);
    nameLength_ = int(std::clamp<int64_t>(nameLength, 32, 255));
    ex_set_max_name_length(file_.id, nameLength_);

    TetMesh mesh;
    CellSoup soup;
    numNodes_ = init.num_nodes;
    share_ = options_.shareCount > 1;
    // The cells first: a share's nodes are those its cells span.
    std::vector<std::vector<int64_t>> conns;
    if (Result r = readBlocks(init, conns); !r) return r;
    if (Result r = chooseNodes(conns); !r) return r;
    for (size_t b = 0; b < blocks_.size(); ++b)
      if (Result r = addBlockCells(blocks_[b], conns[b], soup); !r) return r;
    conns.clear();
    if (Result r = readCoordinates(mesh); !r) return r;
    size_t step = 0;
    if (Result r = readTimes(step); !r) return r;
    std::vector<CellArray> cellArrays;
    if (Result r = readNodalVariables(step, mesh); !r) return r;
    if (Result r = readElementVariables(step, cellArrays); !r) return r;
    noteUnreadVariables();
    report_.format = formatText();
    if (Result r = finishMesh(path_, mesh, soup, std::move(cellArrays), report_); !r) return r;
    out = std::move(mesh);
    return Result::success();
  }

 private:
  // A count the file declares, of `bytesEach` stored bytes each, must fit in what the file holds.
  Result checkCount(const std::string& what, int64_t count, uint64_t bytesEach) const {
    if (count < 0) return fail(Status::Corrupt, path_ + ": " + what + " is negative (" + std::to_string(count) + ")");
    if (uint64_t(count) > limit_ / std::max<uint64_t>(bytesEach, 1))
      return fail(Status::Truncated, path_ + ": " + what + " is " + std::to_string(count) + ", more than a file of " +
                                         std::to_string(fileBytes_) + " bytes can hold");
    return Result::success();
  }

  Result checkInit(const ex_init_params& init) {
    if (init.num_dim != 3) {
      if (init.num_dim == 1 || init.num_dim == 2)
        return fail(Status::NoTets, path_ + ": a " + std::to_string(init.num_dim) + "D Exodus II mesh (num_dim " +
                                        std::to_string(init.num_dim) + "): no volume cells");
      return fail(Status::Corrupt, path_ + ": num_dim is " + std::to_string(init.num_dim) + ", expected 3");
    }
    if (Result r = checkCount("the number of nodes", init.num_nodes, 3 * ioWordSize_); !r) return r;
    if (uint64_t(init.num_nodes) > kMaxVertices)
      return fail(Status::TooLarge,
                  path_ + ": " + std::to_string(init.num_nodes) + " nodes; tetstream indexes vertices with 32 bits");
    if (Result r = checkCount("the number of elements", init.num_elem, 4); !r) return r;
    if (Result r = checkCount("the number of element blocks", init.num_elem_blk, 4); !r) return r;
    return Result::success();
  }

  // "node 12 (id 1012)" when the node number map gives other ids, else "node 12" (1-based, as
  // Exodus numbers them).
  std::string nodeName(int64_t index1) {
    if (!nodeMapRead_) {
      nodeMapRead_ = true;
      nodeMap_.assign(size_t(numNodes_), 0);
      if (ex_get_id_map(file_.id, EX_NODE_MAP, nodeMap_.data()) < 0) nodeMap_.clear();
    }
    std::string s = "node " + std::to_string(index1);
    if (index1 >= 1 && uint64_t(index1) <= nodeMap_.size() && nodeMap_[size_t(index1 - 1)] != index1)
      s += " (id " + std::to_string(nodeMap_[size_t(index1 - 1)]) + ")";
    return s;
  }
  std::string elementName(const Block& b, int64_t k) {
    if (!elemMapRead_) {
      elemMapRead_ = true;
      elemMap_.assign(size_t(numElements_), 0);
      if (ex_get_id_map(file_.id, EX_ELEM_MAP, elemMap_.data()) < 0) elemMap_.clear();
    }
    const uint64_t global = b.firstElement + uint64_t(k);
    std::string s = "element " + std::to_string(k + 1);
    if (global < elemMap_.size() && elemMap_[global] != int64_t(global + 1))
      s += " (id " + std::to_string(elemMap_[global]) + ")";
    return s;
  }

  // The nodes read: all of them, or those a share's cells use (io/row_pick.h): the run from the
  // smallest to the largest, or of that run only the used ones (nodePick_) when it has others.
  Result chooseNodes(const std::vector<std::vector<int64_t>>& conns) {
    nodeFirst_ = 0;
    nodeCount_ = numNodes_;
    nodePick_.clear();
    used_.reset();
    if (!share_) return Result::success();
    int64_t lo = INT64_MAX, hi = 0;
    uint64_t cells = 0;
    auto eachCorner = [&](auto&& f) {
      for (size_t b = 0; b < blocks_.size(); ++b) {
        if (!blocks_[b].kind.volume) continue;
        const int corners = kShapeCorners[int(blocks_[b].kind.shape)];
        for (int64_t k = 0; k < blocks_[b].readCount; ++k)
          for (int q = 0; q < corners; ++q) {
            const int64_t v = conns[b][size_t(k * blocks_[b].nodesPer + q)];
            if (v >= 1 && v <= numNodes_) f(v);  // (others are refused with their element's name when added)
          }
      }
    };
    for (const Block& b : blocks_)
      if (b.kind.volume) cells += uint64_t(b.readCount);
    eachCorner([&](int64_t v) {
      lo = std::min(lo, v - 1);
      hi = std::max(hi, v);
    });
    if (hi == 0) lo = 0;
    nodeFirst_ = lo;
    nodeCount_ = hi - lo;
    used_ = std::make_unique<io::UsedRows>(uint64_t(lo), uint64_t(nodeCount_));
    eachCorner([&](int64_t v) { used_->mark(uint64_t(v - 1)); });
    used_->finish();
    if (!used_->all()) nodePick_ = used_->rows();
    report_.shared = true;
    report_.notes.push_back("read elements " + std::to_string(shareFrom_) + " to " + std::to_string(shareTo_) + " of " +
                            std::to_string(numElements_) + " (" + std::to_string(cells) + " of volume) and the " +
                            std::to_string(nodesRead()) + " nodes they use, this process's share of the file");
    return Result::success();
  }

  // The nodes read, and where node v (1-based) is among them (nodeRead: -1 when not read).
  size_t nodesRead() const { return used_ ? size_t(used_->used()) : size_t(nodeCount_); }
  int64_t nodeRead(int64_t v) const {
    if (used_) return used_->placeOf(uint64_t(v - 1));
    return v >= 1 && v <= nodeCount_ ? v - 1 : -1;
  }

  // Values of the nodes read, one a node, from read(first, count, values) of 0-based runs: the
  // whole run, or of it the picked nodes a window at a time.
  template <class Read>
  Result readNodeRows(const std::string& what, Read&& read, std::vector<double>& out) {
    if (nodePick_.empty()) {
      out.resize(size_t(nodeCount_));
      return nodeCount_ ? read(nodeFirst_, nodeCount_, out) : Result::success();
    }
    return io::readPickedRows(
        nodePick_, uint64_t(numNodes_), true, what,
        [&](uint64_t from, uint64_t n, std::vector<double>& window) {
          window.resize(size_t(n));
          return read(int64_t(from), int64_t(n), window);
        },
        out);
  }

  Result readCoordinates(TetMesh& mesh) {
    const size_t n = nodesRead();
    std::vector<double> axis[3];
    for (int a = 0; a < 3; ++a) {
      double* at[3] = {nullptr, nullptr, nullptr};
      if (Result r = readNodeRows(
              "the node coordinates",
              [&](int64_t first, int64_t count, std::vector<double>& values) {
                at[a] = values.data();
                if (ex_get_partial_coord(file_.id, first + 1, count, at[0], at[1], at[2]) != kExodusOk)
                  return fail(Status::Corrupt, path_ + ": cannot read the node coordinates: " + lastExodusError());
                return Result::success();
              },
              axis[a]);
          !r)
        return r;
    }
    const std::vector<double>&x = axis[0], &y = axis[1], &z = axis[2];
    mesh.positions.resize(3 * n);
    for (size_t v = 0; v < n; ++v) {
      if (!std::isfinite(x[v]) || !std::isfinite(y[v]) || !std::isfinite(z[v])) {
        char buf[128];
        std::snprintf(buf, sizeof buf, "(%g, %g, %g)", x[v], y[v], z[v]);
        const int64_t node = nodePick_.empty() ? nodeFirst_ + int64_t(v) : int64_t(nodePick_[v]);
        return fail(Status::NonFinite, path_ + ": " + nodeName(node + 1) + " has a non-finite coordinate " + buf);
      }
      mesh.positions[3 * v] = float(x[v]);
      mesh.positions[3 * v + 1] = float(y[v]);
      mesh.positions[3 * v + 2] = float(z[v]);
    }
    return Result::success();
  }

  // Every block's parameters, and the connectivity of the elements read (per block: readCount
  // rows of nodesPer 1-based node numbers; none for blocks whose cells are not read).
  Result readBlocks(const ex_init_params& init, std::vector<std::vector<int64_t>>& conns) {
    numElements_ = init.num_elem;
    shareFrom_ = 0;
    shareTo_ = uint64_t(numElements_);
    if (share_) {
      shareFrom_ = uint64_t(numElements_) * options_.shareIndex / options_.shareCount;
      shareTo_ = uint64_t(numElements_) * (options_.shareIndex + 1ull) / options_.shareCount;
    }
    std::vector<int64_t> ids(size_t(init.num_elem_blk));
    if (!ids.empty() && ex_get_ids(file_.id, EX_ELEM_BLOCK, ids.data()) != kExodusOk)
      return fail(Status::Corrupt, path_ + ": cannot read the element block ids: " + lastExodusError());
    uint64_t first = 0;
    for (int64_t id : ids) {
      ex_block param{};
      param.id = id;
      param.type = EX_ELEM_BLOCK;
      if (ex_get_block_param(file_.id, &param) < 0)
        return fail(Status::Corrupt, path_ + ": element block " + std::to_string(id) + ": " + lastExodusError());
      Block b;
      b.id = id;
      param.topology[MAX_STR_LENGTH] = '\0';
      b.type = printable(param.topology);
      b.count = param.num_entry;
      b.nodesPer = param.num_nodes_per_entry;
      b.firstElement = first;
      b.kind = exodusType(b.type, b.nodesPer);
      const std::string where = "element block " + std::to_string(id) + " (" + b.type + ")";
      if (Result r = checkCount(where + ": its number of elements", b.count, 1); !r) return r;
      if (b.count > 0 && !b.kind.special) {
        if (b.nodesPer < 1 || b.nodesPer > 1000)
          return fail(Status::Corrupt,
                      path_ + ": " + where + " has " + std::to_string(b.nodesPer) + " nodes per element");
        if (Result r = checkCount(where + ": its connectivity size", b.count * b.nodesPer, 4); !r) return r;
      }
      first += uint64_t(b.count);
      if (first > uint64_t(init.num_elem))
        return fail(Status::Corrupt, path_ + ": the element blocks hold more elements than the " +
                                         std::to_string(init.num_elem) + " the header declares");
      const uint64_t from = std::clamp(shareFrom_, b.firstElement, first),
                     to = std::clamp(shareTo_, b.firstElement, first);
      b.readFrom = int64_t(from - b.firstElement);
      b.readCount = int64_t(to - from);
      b.localFirst = from - shareFrom_;
      conns.emplace_back();
      if (Result r = readConnectivity(b, where, conns.back()); !r) return r;
      blocks_.push_back(std::move(b));
    }
    return Result::success();
  }

  Result readConnectivity(const Block& b, const std::string& where, std::vector<int64_t>& conn) {
    if (b.readCount == 0 || b.kind.special || (share_ && !b.kind.volume)) return Result::success();
    const int corners = kShapeCorners[int(b.kind.shape)];
    if (b.kind.volume && b.nodesPer < corners)
      return fail(Status::Corrupt, path_ + ": " + where + " has " + std::to_string(b.nodesPer) +
                                       " nodes per element; the shape needs at least " + std::to_string(corners));
    conn.resize(size_t(b.readCount * b.nodesPer));
    if (ex_get_partial_conn(file_.id, EX_ELEM_BLOCK, b.id, b.readFrom + 1, b.readCount, conn.data(), nullptr,
                            nullptr) != kExodusOk)
      return fail(Status::Corrupt, path_ + ": " + where + ": cannot read its connectivity: " + lastExodusError());
    return Result::success();
  }

  // The block's elements read, into the soup, their nodes numbered from the first node read.
  Result addBlockCells(const Block& b, const std::vector<int64_t>& conn, CellSoup& soup) {
    const std::string where = "element block " + std::to_string(b.id) + " (" + b.type + ")";
    const uint64_t sourceBase = soup.inputCells;
    soup.inputCells += uint64_t(b.readCount);
    if (b.readCount == 0) return Result::success();
    const std::string label = "Exodus " + upper(b.type);
    if (b.kind.special ||
        conn.empty()) {  // polyhedra / polygons (connectivity not per element), or a share's lower-dimensional cells
      soup.skipped[{b.kind.special ? 0 : b.kind.vtkType, label}] += uint64_t(b.readCount);
      return Result::success();
    }
    if (soup.referenced.size() < nodesRead()) soup.referenced.resize(nodesRead(), 0);
    auto mark = [&](int64_t v) {  // (a share's nodes outside those it reads are not read)
      if (const int64_t at = nodeRead(v); at >= 0) soup.referenced[size_t(at)] = 1;
    };
    if (!b.kind.volume) {
      soup.skipped[{b.kind.vtkType, label}] += uint64_t(b.readCount);
      for (int64_t v : conn) mark(v);
      return Result::success();
    }
    const int corners = kShapeCorners[int(b.kind.shape)];
    soup.shapes.reserve(soup.shapes.size() + size_t(b.readCount));
    soup.source.reserve(soup.source.size() + size_t(b.readCount));
    soup.corners.reserve(soup.corners.size() + size_t(b.readCount) * size_t(corners));
    for (int64_t k = 0; k < b.readCount; ++k) {
      const int64_t* nodes = &conn[size_t(k * b.nodesPer)];
      uint32_t ids[8];
      for (int64_t q = 0; q < b.nodesPer; ++q) {
        const int64_t v = nodes[q];
        if (v < 1 || v > numNodes_)
          return fail(Status::OutOfRange, path_ + ": " + where + " " + elementName(b, b.readFrom + k) + " uses node " +
                                              std::to_string(v) + ", but the nodes are numbered 1.." +
                                              std::to_string(numNodes_));
        mark(v);
        if (q < corners) ids[q] = uint32_t(nodeRead(v));
      }
      soup.add(b.kind.shape, ids, sourceBase + uint64_t(k));
    }
    if (b.nodesPer > corners) {
      auto& r = soup.reduced[label + " (" + std::to_string(b.nodesPer) + " nodes)"];
      r.first = corners;
      r.second += uint64_t(b.readCount);
    }
    return Result::success();
  }

  Result readTimes(size_t& step) {
    const int64_t n = ex_inquire_int(file_.id, EX_INQ_TIME);
    if (n < 0) return fail(Status::Corrupt, path_ + ": cannot read the number of time steps: " + lastExodusError());
    if (Result r = checkCount("the number of time steps", n, ioWordSize_); !r) return r;
    times_.assign(size_t(n), 0.0);
    if (n > 0 && ex_get_all_times(file_.id, times_.data()) != kExodusOk)
      return fail(Status::Corrupt, path_ + ": cannot read the time steps' times: " + lastExodusError());
    if (n > std::numeric_limits<int>::max())
      return fail(Status::TooLarge, path_ + ": " + std::to_string(n) + " time steps");
    return chooseTimeStep(times_, options_, path_, report_, step);
  }

  Result variableNames(ex_entity_type type, const char* kind, std::vector<std::string>& names) {
    int n = 0;
    if (ex_get_variable_param(file_.id, type, &n) < 0)
      return fail(Status::Corrupt, path_ + ": cannot read the number of " + kind + " variables: " + lastExodusError());
    if (n < 0 || n > 100000) return fail(Status::Corrupt, path_ + ": " + std::to_string(n) + " " + kind + " variables");
    names.clear();
    if (n == 0) return Result::success();
    std::vector<std::vector<char>> buffers(size_t(n), std::vector<char>(size_t(nameLength_) + 1, '\0'));
    std::vector<char*> pointers;
    for (auto& b : buffers) pointers.push_back(b.data());
    if (ex_get_variable_names(file_.id, type, n, pointers.data()) != kExodusOk)
      return fail(Status::Corrupt, path_ + ": cannot read the " + kind + " variable names: " + lastExodusError());
    for (auto& b : buffers) {
      b.back() = '\0';
      std::string name = printable(b.data());
      // Exodus pads names with spaces in some writers.
      while (!name.empty() && name.back() == ' ') name.pop_back();
      names.push_back(name.empty() ? std::string(kind) + "_" + std::to_string(names.size() + 1) : name);
    }
    return Result::success();
  }

  // Without a time step a file has no variable values (a mesh only, or a run that wrote none).
  bool noValues(size_t count, const char* kind) {
    if (!times_.empty() || count == 0) return false;
    report_.notes.push_back(path_ + " declares " + std::to_string(count) + " " + kind +
                            " variables but holds no time step, so none has values; none read");
    return true;
  }

  Result readNodalVariables(size_t step, TetMesh& mesh) {
    std::vector<std::string> names;
    if (Result r = variableNames(EX_NODAL, "nodal", names); !r) return r;
    if (names.empty() || noValues(names.size(), "nodal")) return Result::success();
    std::vector<double> values;
    const size_t firstField = mesh.fields.size();
    for (size_t k = 0; k < names.size(); ++k) {
      if (Result r = readNodeRows(
              "nodal variable '" + names[k] + "'",
              [&](int64_t first, int64_t count, std::vector<double>& out) {
                if (ex_get_partial_var(file_.id, int(step + 1), EX_NODAL, int(k + 1), 1, first + 1, count,
                                       out.data()) == kExodusOk ||
                    readNodalVariableDirectly(step, k, first, count, out))
                  return Result::success();
                return fail(Status::Corrupt, path_ + ": nodal variable '" + names[k] + "' at step " +
                                                 std::to_string(step) + ": " + lastExodusError());
              },
              values);
          !r)
        return r;
      ScalarField f;
      f.name = names[k];
      f.values.assign(values.begin(), values.end());
      addField(mesh, std::move(f), report_);
    }
    addComponentMagnitudes(mesh, firstField, report_);
    return Result::success();
  }

  // The library looks for nodal variables where the file's model size says: one variable each
  // (vals_nod_varK) in a "large model", all in vals_nod_var otherwise. meshio writes them one
  // each without saying the model is large, so the library finds none; they are read from
  // vals_nod_varK through netCDF (the Exodus file id is the netCDF id) when it has the layout
  // (time_step, num_nodes).
  bool readNodalVariableDirectly(size_t step, size_t k, int64_t first, int64_t count, std::vector<double>& values) {
    const std::string name = "vals_nod_var" + std::to_string(k + 1);
    int var = -1, ndims = 0;
    int dims[NC_MAX_VAR_DIMS];
    size_t length[2] = {0, 0};
    if (nc_inq_varid(file_.id, name.c_str(), &var) != NC_NOERR || nc_inq_varndims(file_.id, var, &ndims) != NC_NOERR ||
        ndims != 2 || nc_inq_vardimid(file_.id, var, dims) != NC_NOERR ||
        nc_inq_dimlen(file_.id, dims[0], &length[0]) != NC_NOERR ||
        nc_inq_dimlen(file_.id, dims[1], &length[1]) != NC_NOERR || length[0] <= step ||
        length[1] != uint64_t(numNodes_))
      return false;
    const size_t start[2] = {step, size_t(first)}, counts[2] = {1, size_t(count)};
    if (nc_get_vara_double(file_.id, var, start, counts, values.data()) != NC_NOERR) return false;
    if (!directNoted_) {
      directNoted_ = true;
      report_.notes.push_back(
          "read the nodal variables from vals_nod_var1.. through netCDF: the file stores them "
          "one per variable without marking itself a large model, where the Exodus library "
          "finds none");
    }
    return true;
  }

  Result readElementVariables(size_t step, std::vector<CellArray>& arrays) {
    std::vector<std::string> names;
    if (Result r = variableNames(EX_ELEM_BLOCK, "element", names); !r) return r;
    if (names.empty() || noValues(names.size(), "element")) return Result::success();
    const size_t nb = blocks_.size(), nv = names.size();
    if (nb * nv > (size_t(1) << 26))
      return fail(Status::TooLarge,
                  path_ + ": " + std::to_string(nv) + " element variables on " + std::to_string(nb) + " blocks");
    // Which variable each block has (1 everywhere when the file has no truth table).
    std::vector<int> truth(nb * nv, 1);
    if (const int status = nb ? ex_get_truth_table(file_.id, EX_ELEM_BLOCK, int(nb), int(nv), truth.data()) : 0;
        status < 0)
      return fail(Status::Corrupt, path_ + ": cannot read the element variable truth table: " + lastExodusError());
    else if (status > 0)
      std::fill(truth.begin(), truth.end(), 1);
    const uint64_t cells = blocks_.empty() ? 0 : blocks_.back().localFirst + uint64_t(blocks_.back().readCount);
    std::vector<double> values;
    for (size_t k = 0; k < nv; ++k) {
      CellArray a;
      a.name = names[k];
      a.values.assign(size_t(cells), std::numeric_limits<double>::quiet_NaN());
      for (size_t bi = 0; bi < nb; ++bi) {
        const Block& b = blocks_[bi];
        if (!b.kind.volume || b.readCount == 0 || !truth[bi * nv + k]) continue;
        values.resize(size_t(b.readCount));
        if (ex_get_partial_var(file_.id, int(step + 1), EX_ELEM_BLOCK, int(k + 1), b.id, b.readFrom + 1, b.readCount,
                               values.data()) != kExodusOk)
          return fail(Status::Corrupt, path_ + ": element variable '" + names[k] + "' on element block " +
                                           std::to_string(b.id) + " at step " + std::to_string(step) + ": " +
                                           lastExodusError());
        std::copy(values.begin(), values.end(), a.values.begin() + std::ptrdiff_t(b.localFirst));
      }
      arrays.push_back(std::move(a));
    }
    addComponentMagnitudes(arrays, 0, report_);
    return Result::success();
  }

  // Variables on other entities than nodes and element blocks are not read; a note says so.
  void noteUnreadVariables() {
    struct Kind {
      ex_entity_type type;
      const char* name;
    };
    std::string unread;
    for (const Kind& k :
         {Kind{EX_GLOBAL, "global"}, Kind{EX_NODE_SET, "node set"}, Kind{EX_SIDE_SET, "side set"},
          Kind{EX_ELEM_SET, "element set"}, Kind{EX_EDGE_BLOCK, "edge block"}, Kind{EX_FACE_BLOCK, "face block"}}) {
      int n = 0;
      if (ex_get_variable_param(file_.id, k.type, &n) == kExodusOk && n > 0)
        unread += (unread.empty() ? "" : ", ") + std::to_string(n) + " " + k.name;
    }
    if (!unread.empty())
      report_.notes.push_back("not read: the variables of other entities than nodes and element blocks (" + unread +
                              ")");
  }

  std::string formatText() const {
    size_t volume = 0;
    for (const Block& b : blocks_) volume += b.kind.volume;
    std::string s = std::string("Exodus II (") +
                    (container_ == Container::Hdf5 ? "netCDF-4" : containerName(container_)) + "), " +
                    std::to_string(blocks_.size()) + (blocks_.size() == 1 ? " element block" : " element blocks");
    if (volume != blocks_.size()) s += " (" + std::to_string(volume) + " of volume cells)";
    return s + stepText(report_);
  }

  const std::string& path_;
  const ReadOptions& options_;
  ReadReport& report_;
  ExodusFile file_;
  Container container_ = Container::None;
  uint64_t fileBytes_ = 0, limit_ = 0;
  uint64_t ioWordSize_ = 8;
  int nameLength_ = 32;
  int64_t numNodes_ = 0, numElements_ = 0;
  bool share_ = false;                     // reading one process's share (the header comment)
  uint64_t shareFrom_ = 0, shareTo_ = 0;   // the elements read, in file order over all blocks
  int64_t nodeFirst_ = 0, nodeCount_ = 0;  // the run of nodes a share's cells use (0-based first)
  std::unique_ptr<io::UsedRows> used_;     // (a share) of that run the nodes used
  std::vector<uint64_t> nodePick_;         // those nodes (0-based), ascending, when not all are: the nodes read
  std::vector<Block> blocks_;
  std::vector<double> times_;
  bool nodeMapRead_ = false, elemMapRead_ = false, directNoted_ = false;
  std::vector<int64_t> nodeMap_, elemMap_;
};

}  // namespace

Result readExodus(const std::string& path, const ReadOptions& options, TetMesh& out, ReadReport& report) {
  out = TetMesh{};
  return ExodusReader(path, options, report).read(out);
}

}  // namespace tetstream
