// XDMF 2 and 3 reader: the grids of an XDMF file (xdmf_document.h reads its XML and data) as one
// tetrahedral mesh. Layout reference: "XDMF Model and Format" (xdmf.org); the cell type codes of
// Mixed topologies are XdmfTopologyType's.
//
// What is read:
//   - The Domain's grids. A temporal collection (GridType="Collection" CollectionType="Temporal")
//     makes time steps, one per child grid, its time from <Time Value=...> (or the collection's
//     <Time TimeType="List"> / "HyperSlab"); one step is read (options.step / options.time, the
//     last by default) and only its data. Other top-level temporal collections with the same
//     times on the same mesh (DOLFINx writes one per function) add their attributes to it; the
//     top-level grids outside the collections (DOLFINx's mesh grid) are what the steps refer to.
//   - Without a temporal collection, every top-level grid is read; spatial collections and trees
//     are flattened into pieces whose points are concatenated (coincident ones merged later). A
//     grid whose Geometry is one already read (by reference or include) adds its cells to those
//     points, less the cells it repeats (DOLFINx writes cell tags as such a grid).
//   - Topology: Tetrahedron, Pyramid, Wedge, Hexahedron, their quadratic forms (corners kept) and
//     Mixed; grids of surface, line or point cells (DOLFINx's facet tags) and cells of higher
//     order than quadratic are counted and skipped without reading their data.
//   - Geometry XYZ and X_Y_Z. Attributes with Center="Node" become fields, Center="Cell" cell
//     data (volume-weighted to the points), legacy DOLFIN finite element functions (Center=
//     "Other") are read through their dofs (xdmf_function.h); vectors and tensors become their
//     magnitude. An attribute survives only if every piece has it.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <set>
#include <span>

#include "io/readers.h"
#include "io/row_pick.h"
#include "io/xdmf_document.h"
#include "io/xdmf_function.h"
#include "io/xdmf_mixed.h"
#include "io/xdmf_topology.h"

namespace tetstream {
namespace {

using namespace vtkio;
using xdmf::Document;
using xdmf::kindByName;
using xdmf::TopologyKind;
using xdmf::Values;

constexpr int kMaxGridDepth = 16;
constexpr size_t kMaxPieces = size_t(1) << 20;

// Skipped cells are named by their XDMF type, whatever the VTK type behind them.
void countSkipped(CellSoup& soup, const TopologyKind& k, uint64_t n) {
  if (n) soup.skipped[{k.vtk, "XDMF " + std::string(k.name)}] += n;
}

std::string gridName(pugi::xml_node g) {
  const char* n = g.attribute("Name").value();
  return *n ? printable(n) : std::string();
}

bool isCollection(pugi::xml_node g) { return iequals(g.attribute("GridType").value(), "Collection"); }
bool isTemporal(pugi::xml_node g) {
  return isCollection(g) && iequals(g.attribute("CollectionType").value(), "Temporal");
}

// Whether a topology of `nodes` ids a cell, declared `dims`, can be read in rows of cells.
bool cellRowsDeclared(const std::vector<uint64_t>& dims, uint64_t nodes) {
  return nodes > 0 && ((dims.size() == 2 && dims[1] == nodes) || (dims.size() == 1 && dims[0] % nodes == 0));
}

// An attribute of a function space (Center="Other"): its dofs are not per point or cell.
bool anyOfFunctionSpace(const std::vector<pugi::xml_node>& attributes) {
  return std::any_of(attributes.begin(), attributes.end(),
                     [](pugi::xml_node a) { return iequals(a.attribute("Center").value(), "Other"); });
}

// One process's share of a grid (ReadOptions::shareIndex of shareCount): rows of its cells and
// of its points, out of how many; of the points' run only those in pointPick when it is not
// empty (io/row_pick.h).
struct Rows {
  uint64_t cellsTotal = 0, cellFirst = 0;
  uint64_t pointsTotal = 0, pointFirst = 0, pointsSpan = 0;
  std::vector<uint64_t> pointPick;
};

// A piece's arrays, merged across pieces like the VTK XML reader does.
struct PieceArrays {
  std::vector<ScalarField> fields;
  std::vector<CellArray> cellArrays;
};

class XdmfReader {
 public:
  XdmfReader(Document& doc, const ReadOptions& options, ReadReport& report)
      : doc_(doc), options_(options), report_(report) {}
  Result read(TetMesh& out);

 private:
  Result flatten(pugi::xml_node grid, const std::string& what, int depth, std::vector<pugi::xml_node>& pieces);
  Result stepTimes(pugi::xml_node collection, const std::vector<pugi::xml_node>& steps, const std::string& what,
                   std::vector<double>& times);
  Result sameMesh(pugi::xml_node a, pugi::xml_node b, const std::string& what, bool& same);
  Result readPiece(pugi::xml_node grid, const std::vector<pugi::xml_node>& companions, const std::string& where,
                   bool first, PieceArrays& arrays, bool& skipped, bool& sharedPoints);
  Result shareGrids(const std::vector<pugi::xml_node>& pieces, const std::vector<pugi::xml_node>& companions,
                    std::vector<bool>& readHere);
  Result gridShape(pugi::xml_node grid, const std::vector<pugi::xml_node>& companions, const std::string& where,
                   bool& volume, bool& byRows, const void*& geometry);
  Result readShareOfGrid(pugi::xml_node topo, pugi::xml_node geo, const TopologyKind* kind,
                         const std::vector<pugi::xml_node>& attributes, const std::string& where, PieceArrays& arrays,
                         bool& done);
  Result pointRows(pugi::xml_node geo, const std::string& where, uint64_t first, uint64_t count,
                   std::span<const uint64_t> pick, uint64_t& total);
  // Rows [first, first + count) of a DataItem of `total` rows, or of them those in `pick`.
  Result pickedRows(pugi::xml_node item, const std::string& what, uint64_t total, uint64_t first, uint64_t count,
                    std::span<const uint64_t> pick, xdmf::Values<double>& out);
  void dropRepeatedCells(size_t firstNew, uint64_t vertexBase, uint64_t points, const std::string& where);
  Result readCells(pugi::xml_node topo, const TopologyKind* kind, const std::string& where, uint64_t points,
                   uint64_t vertexBase, std::vector<int64_t>& conn, int& nodes, uint64_t& cells);
  // A share's rows [from, to) of a Mixed topology of `total` values, walked a window at a time
  // where its data reads windows for their cost (HDF5), else read whole and walked.
  Result mixedRows(pugi::xml_node item, const std::string& where, int64_t base, uint64_t total, uint64_t from,
                   uint64_t to, uint64_t declared, xdmf::MixedCells& out);
  Result appendMixed(const std::string& where, const xdmf::MixedCells& cells, uint64_t vertexBase, uint64_t points);
  // Walks a Mixed topology of `total` values from its first, a window at a time where its data
  // reads windows for their cost (HDF5), else read whole, until the walker is done or the values
  // end (`at`: the values walked).
  Result walkMixed(pugi::xml_node item, const std::string& what, uint64_t total, xdmf::MixedWalker& walker,
                   xdmf::MixedCells& out, uint64_t& at);
  // The cells of a Mixed topology that does not declare their count: all walked, none kept.
  Result countMixed(pugi::xml_node item, const std::string& where, uint64_t total, uint64_t& cells);
  Result readPoints(pugi::xml_node geo, const std::string& where, uint64_t& points);
  // rows: given, only those rows of each attribute are read (a share of the grid).
  Result readAttributes(const std::vector<pugi::xml_node>& attributes, const std::string& where,
                        const xdmf::GridCells& grid, bool first, bool sharedPoints, PieceArrays& arrays,
                        const Rows* rows = nullptr);
  Result baseOffset(pugi::xml_node topo, const std::string& what, int64_t& base);
  Result declaredCells(pugi::xml_node topo, const std::string& what, bool& hasCount, uint64_t& declared);

  Document& doc_;
  const ReadOptions& options_;
  ReadReport& report_;
  TetMesh mesh_;
  CellSoup soup_;
  std::vector<std::string> topologies_;  // read, in order, for ReadReport::format
  bool shareGrid_ = false;               // each process reads a share of the rows of every volume grid
  // Geometry elements read so far (after references): their first vertex and point count. A
  // grid on the points of an earlier one adds its cells to those points.
  std::map<const void*, std::pair<uint64_t, uint64_t>> geometries_;
};

Result XdmfReader::flatten(pugi::xml_node grid, const std::string& what, int depth,
                           std::vector<pugi::xml_node>& pieces) {
  if (depth > kMaxGridDepth)
    return fail(Status::Corrupt, what + ": grids nest more than " + std::to_string(kMaxGridDepth) +
                                     " deep (a collection that includes itself?)");
  std::string_view type = grid.attribute("GridType").value();
  if (type.empty() || iequals(type, "Uniform")) {
    pieces.push_back(grid);
    if (pieces.size() > kMaxPieces)
      return fail(Status::TooLarge, what + ": more than " + std::to_string(kMaxPieces) + " grids");
    return Result::success();
  }
  if (iequals(type, "Subset")) return fail(Status::Unsupported, what + ": GridType=\"Subset\" grids are not read");
  if (!iequals(type, "Collection") && !iequals(type, "Tree"))
    return fail(Status::Corrupt, what + ": GridType='" + printable(type) + "' (expected Uniform, Collection, Tree)");
  if (isTemporal(grid))
    return fail(Status::Unsupported, what +
                                         ": a temporal collection inside a time step or a spatial collection; "
                                         "tetstream reads time steps from the top-level temporal collections");
  std::vector<pugi::xml_node> kids;
  if (Result r = doc_.children(grid, "Grid", what, kids); !r) return r;
  for (pugi::xml_node k : kids) {
    const std::string name = gridName(k);
    if (Result r = flatten(k, what + " / Grid" + (name.empty() ? "" : " '" + name + "'"), depth + 1, pieces); !r)
      return r;
  }
  return Result::success();
}

Result XdmfReader::stepTimes(pugi::xml_node collection, const std::vector<pugi::xml_node>& steps,
                             const std::string& what, std::vector<double>& times) {
  times.clear();
  // A collection may give every step's time at once: a List of values, or a HyperSlab (start,
  // stride, count).
  if (pugi::xml_node t = collection.child("Time")) {
    std::string_view type = t.attribute("TimeType").value();
    if (iequals(type, "List") || iequals(type, "HyperSlab")) {
      pugi::xml_node item;
      if (Result r = doc_.dataItem(t, what + " <Time>", item); !r) return r;
      Values<double> v;
      if (Result r = doc_.numbers(item, what + " <Time>", v); !r) return r;
      if (iequals(type, "List")) {
        if (v.values.size() < steps.size())
          return fail(Status::Corrupt, what + ": <Time TimeType=\"List\"> gives " + std::to_string(v.values.size()) +
                                           " times for " + std::to_string(steps.size()) + " steps");
        times.assign(v.values.begin(), v.values.begin() + std::ptrdiff_t(steps.size()));
      } else {
        if (v.values.size() != 3)
          return fail(Status::Corrupt, what + ": <Time TimeType=\"HyperSlab\"> needs start, stride and count");
        for (size_t i = 0; i < steps.size(); ++i) times.push_back(v.values[0] + double(i) * v.values[1]);
      }
    }
  }
  if (times.empty()) {
    for (pugi::xml_node s : steps) {
      pugi::xml_node t = s.child("Time");
      double v;
      size_t pos = 0;
      if (!t || parseNextDouble(t.attribute("Value").value(), pos, v) != 1) {
        times.clear();
        break;
      }
      times.push_back(v);
    }
    if (times.empty() && !steps.empty()) {
      for (size_t i = 0; i < steps.size(); ++i) times.push_back(double(i));
      report_.notes.push_back(what + ": its steps have no <Time Value>; numbered 0, 1, ... as their times");
    }
  }
  for (size_t i = 0; i < times.size(); ++i)
    if (!std::isfinite(times[i]))
      return fail(Status::NonFinite, what + ": step " + std::to_string(i) + " has a non-finite time");
  return Result::success();
}

// Whether two grids stand on the same mesh: their Topology and Geometry are the same elements
// (after references) or name the same data.
Result XdmfReader::sameMesh(pugi::xml_node a, pugi::xml_node b, const std::string& what, bool& same) {
  same = true;
  for (const char* part : {"Topology", "Geometry"}) {
    std::vector<pugi::xml_node> x, y;
    if (Result r = doc_.children(a, part, what, x); !r) return r;
    if (Result r = doc_.children(b, part, what, y); !r) return r;
    if (x.size() != 1 || y.size() != 1) {
      same = false;
      return Result::success();
    }
    if (x[0] == y[0]) continue;
    pugi::xml_node dx, dy;
    if (!doc_.dataItem(x[0], what, dx) || !doc_.dataItem(y[0], what, dy)) {
      same = false;
      return Result::success();
    }
    auto key = [](pugi::xml_node d) {
      std::string s = d.child_value();
      s.erase(std::remove_if(s.begin(), s.end(), [](char c) { return isSpace(c); }), s.end());
      return std::string(d.attribute("Format").value()) + "|" + s;
    };
    if (dx != dy && key(dx) != key(dy)) same = false;
  }
  return Result::success();
}

Result XdmfReader::readPoints(pugi::xml_node geo, const std::string& where, uint64_t& points) {
  std::string_view type = geo.attribute("GeometryType").value();
  if (type.empty()) type = geo.attribute("Type").value();
  if (type.empty()) type = "XYZ";
  const std::string what = where + " Geometry";
  std::vector<double> xyz;
  if (iequals(type, "XYZ")) {
    pugi::xml_node item;
    if (Result r = doc_.dataItem(geo, what, item); !r) return r;
    Values<double> v;
    if (Result r = doc_.numbers(item, what, v); !r) return r;
    if (v.values.size() % 3 != 0)
      return fail(Status::Corrupt,
                  what + ": GeometryType XYZ with " + std::to_string(v.values.size()) + " values, not a multiple of 3");
    xyz = std::move(v.values);
  } else if (iequals(type, "X_Y_Z")) {
    std::vector<pugi::xml_node> items;
    if (Result r = doc_.children(geo, "DataItem", what, items); !r) return r;
    if (items.size() != 3)
      return fail(Status::Corrupt,
                  what + ": GeometryType X_Y_Z with " + std::to_string(items.size()) + " DataItems, expected 3");
    Values<double> axis[3];
    for (int a = 0; a < 3; ++a) {
      if (Result r = doc_.numbers(items[size_t(a)], what + " " + "XYZ"[a], axis[a]); !r) return r;
      if (axis[a].values.size() != axis[0].values.size())
        return fail(Status::Corrupt, what + ": X_Y_Z arrays of " + std::to_string(axis[0].values.size()) + " and " +
                                         std::to_string(axis[a].values.size()) + " values");
    }
    xyz.resize(3 * axis[0].values.size());
    for (size_t i = 0; i < axis[0].values.size(); ++i)
      for (int a = 0; a < 3; ++a) xyz[3 * i + size_t(a)] = axis[a].values[i];
  } else if (iequals(type, "XY")) {
    return fail(Status::Unsupported, what + ": GeometryType XY is a 2D mesh; tetstream reads volume meshes (XYZ)");
  } else if (iequals(type, "VXVYVZ") || iequals(type, "ORIGIN_DXDYDZ") || iequals(type, "ORIGIN_DXDY")) {
    return fail(Status::Unsupported, what + ": GeometryType " + printable(type) +
                                         " belongs to structured grids, which are not read from XDMF (convert to "
                                         ".vti/.vts)");
  } else {
    return fail(Status::Unsupported, what + ": GeometryType '" + printable(type) + "' (expected XYZ or X_Y_Z)");
  }
  points = xyz.size() / 3;
  const uint64_t base = mesh_.positions.size() / 3;
  if (base + points > kMaxVertices)
    return fail(Status::TooLarge,
                where + ": " + std::to_string(base + points) + " points; tetstream indexes vertices with 32 bits");
  mesh_.positions.reserve(mesh_.positions.size() + xyz.size());
  for (double x : xyz) mesh_.positions.push_back(float(x));
  return Result::success();
}

Result XdmfReader::appendMixed(const std::string& where, const xdmf::MixedCells& cells, uint64_t vertexBase,
                               uint64_t points) {
  if (Result r = appendVtkCells(where, cells.connectivity, cells.offsets, cells.types, vertexBase, points, soup_); !r)
    return r;
  // appendVtkCells counted the cells not read as VTK_EMPTY_CELL: they are named by XDMF type.
  uint64_t renamed = 0;
  for (const auto& [k, c] : cells.notRead) {
    countSkipped(soup_, *k, c);
    renamed += c;
  }
  if (renamed) {
    auto it = soup_.skipped.find({0, vtkCellTypeName(0) + " (0)"});
    if (it != soup_.skipped.end() && (it->second -= renamed) == 0) soup_.skipped.erase(it);
  }
  return Result::success();
}

Result XdmfReader::walkMixed(pugi::xml_node item, const std::string& what, uint64_t total, xdmf::MixedWalker& walker,
                             xdmf::MixedCells& out, uint64_t& at) {
  const bool byWindow = doc_.readsRowsAlone(item, total);
  uint64_t window = io::kPickWindow;
  Values<int64_t> v;
  at = 0;
  while (!walker.done() && at < total) {
    const uint64_t n = byWindow ? std::min(window, total - at) : total;
    if (Result r = byWindow ? doc_.integerRows(item, what, total, at, n, v) : doc_.integers(item, what, v); !r)
      return r;
    if (!byWindow && v.values.size() != total)
      return fail(Status::Corrupt,
                  what + ": " + std::to_string(v.values.size()) + " values, Dimensions says " + std::to_string(total));
    size_t used = 0;
    if (Result r = walker.walk(v.values, at + n == total, out, used); !r) return r;
    at += used;
    window = used ? io::kPickWindow : 2 * window;  // (a cell longer than the window: a larger one)
  }
  return Result::success();
}

Result XdmfReader::mixedRows(pugi::xml_node item, const std::string& where, int64_t base, uint64_t total, uint64_t from,
                             uint64_t to, uint64_t declared, xdmf::MixedCells& out) {
  const std::string what = where + " Topology";
  xdmf::MixedWalker walker(where, base, from, to, /*skippedNodes=*/false);
  uint64_t at = 0;
  if (Result r = walkMixed(item, what, total, walker, out, at); !r) return r;
  // Every cell up to the share's last was found; the last share also sees the values end there.
  if (walker.cells() < to || (to == declared && at != total))
    return fail(Status::Corrupt, what + ": NumberOfElements=" + std::to_string(declared) +
                                     " but the Mixed data holds " + (walker.cells() < to ? "only " : "more than ") +
                                     std::to_string(walker.cells()) + " cells");
  return Result::success();
}

Result XdmfReader::countMixed(pugi::xml_node item, const std::string& where, uint64_t total, uint64_t& cells) {
  xdmf::MixedWalker walker(where, 0, UINT64_MAX, UINT64_MAX);  // (keeps none)
  xdmf::MixedCells none;
  uint64_t at = 0;
  if (Result r = walkMixed(item, where + " Topology", total, walker, none, at); !r) return r;
  cells = walker.cells();
  return Result::success();
}

// XDMF 2: ids start at BaseOffset (1 for Fortran-style numbering); 0 without one.
Result XdmfReader::baseOffset(pugi::xml_node topo, const std::string& what, int64_t& base) {
  base = 0;
  if (!topo.attribute("BaseOffset")) return Result::success();
  size_t pos = 0;
  if (parseNextInt(topo.attribute("BaseOffset").value(), pos, base) != 1 || std::abs(base) > (int64_t(1) << 40))
    return fail(Status::Corrupt, what + ": BaseOffset='" + printable(topo.attribute("BaseOffset").value()) + "'");
  return Result::success();
}

Result XdmfReader::pickedRows(pugi::xml_node item, const std::string& what, uint64_t total, uint64_t first,
                              uint64_t count, std::span<const uint64_t> pick, xdmf::Values<double>& out) {
  if (pick.empty()) return doc_.numberRows(item, what, total, first, count, out);
  out = {};
  return io::readPickedRows(
      pick, total, doc_.readsRowsAlone(item, total), what,
      [&](uint64_t from, uint64_t n, std::vector<double>& window) {
        xdmf::Values<double> v;
        Result r = doc_.numberRows(item, what, total, from, n, v);
        window = std::move(v.values);
        return r;
      },
      out.values);
}

// Points [first, first + count) of a Geometry of `total` points (total: set from its declared
// size), or of them those in `pick`, appended to the mesh's.
Result XdmfReader::pointRows(pugi::xml_node geo, const std::string& where, uint64_t first, uint64_t count,
                             std::span<const uint64_t> pick, uint64_t& total) {
  std::string_view type = geo.attribute("GeometryType").value();
  if (type.empty()) type = geo.attribute("Type").value();
  if (type.empty()) type = "XYZ";
  const std::string what = where + " Geometry";
  const bool xyz = iequals(type, "XYZ");
  if (!xyz && !iequals(type, "X_Y_Z")) return readPoints(geo, where, total);  // (refused there, in words)
  std::vector<pugi::xml_node> items;
  if (xyz) {
    pugi::xml_node item;
    if (Result r = doc_.dataItem(geo, what, item); !r) return r;
    items.push_back(item);
  } else if (Result r = doc_.children(geo, "DataItem", what, items); !r) {
    return r;
  } else if (items.size() != 3) {
    return fail(Status::Corrupt,
                what + ": GeometryType X_Y_Z with " + std::to_string(items.size()) + " DataItems, expected 3");
  }
  const std::vector<uint64_t> dims = doc_.declaredDims(items[0]);
  uint64_t values = 1;
  for (uint64_t d : dims) values *= d;
  total = xyz ? values / 3 : values;
  if (dims.empty() || (xyz && values % 3) || first > total || count > total - first)
    return fail(Status::Corrupt,
                what + ": Dimensions that do not hold the " + std::to_string(first + count) + " points its cells use");
  Values<double> axis[3];
  for (size_t a = 0; a < items.size(); ++a) {
    // (XYZ as N x 3 rows or as 3N values; X_Y_Z as N values each)
    const bool rowsOfThree = xyz && dims.size() == 2 && dims[1] == 3;
    if (xyz && !rowsOfThree) {  // (a point is 3 rows: read by point when picked)
      std::vector<uint64_t> rows;
      for (uint64_t p : pick) rows.insert(rows.end(), {3 * p, 3 * p + 1, 3 * p + 2});
      if (Result r = pickedRows(items[a], what, 3 * total, 3 * first, 3 * count, rows, axis[a]); !r) return r;
    } else if (Result r = pickedRows(items[a], what, total, first, count, pick, axis[a]); !r) {
      return r;
    }
  }
  if (!pick.empty()) count = pick.size();
  mesh_.positions.reserve(mesh_.positions.size() + 3 * count);
  for (uint64_t i = 0; i < count; ++i)
    for (int k = 0; k < 3; ++k)
      mesh_.positions.push_back(float(xyz ? axis[0].values[3 * i + uint64_t(k)] : axis[k].values[i]));
  return Result::success();
}

// A share of one grid for one of several processes (core/dist): the cells from index·N/count to
// (index + 1)·N/count, and the points they use (the run from the smallest id to the largest, or
// only those: io/row_pick.h), with those rows of every attribute. Of one cell type the cells are
// rows of the topology; of Mixed cells the topology is walked from its first cell (a window at a
// time where its data allows) to find them, after a walk that counts them when the topology does
// not say how many. Each process reads about a count-th of the cells;
// the points on the cuts are read by both sides and joined later by their coordinates. done
// stays false (nothing read) for a grid this cannot cut: a topology of no declared size, or an
// attribute of a function space (its dofs are not per point or cell).
Result XdmfReader::readShareOfGrid(pugi::xml_node topo, pugi::xml_node geo, const TopologyKind* kind,
                                   const std::vector<pugi::xml_node>& attributes, const std::string& where,
                                   PieceArrays& arrays, bool& done) {
  done = false;
  if (anyOfFunctionSpace(attributes)) return Result::success();
  const std::string what = where + " Topology";
  pugi::xml_node item;
  if (Result r = doc_.dataItem(topo, what, item); !r) return r;
  const std::vector<uint64_t> dims = doc_.declaredDims(item);
  int64_t base = 0;
  if (Result r = baseOffset(topo, what, base); !r) return r;
  xdmf::MixedCells cells;  // the share's cells (ids less the base)
  uint64_t cellsTotal = 0, from = 0, to = 0;
  auto share = [&](uint64_t n) {
    cellsTotal = n;
    from = n * options_.shareIndex / options_.shareCount;
    to = n * (options_.shareIndex + 1ull) / options_.shareCount;
  };
  if (kind) {
    const uint64_t nodes = uint64_t(kind->nodes);
    if (!cellRowsDeclared(dims, nodes)) return Result::success();
    const bool cellRows = dims.size() == 2;
    share(cellRows ? dims[0] : dims[0] / nodes);
    Values<int64_t> ids;
    if (Result r = doc_.integerRows(item, what, dims[0], cellRows ? from : from * nodes,
                                    cellRows ? to - from : (to - from) * nodes, ids);
        !r)
      return r;
    cells.connectivity = std::move(ids.values);
    for (int64_t& id : cells.connectivity) id -= base;
    cells.types.assign(to - from, kind->vtk);
    cells.offsets.resize(to - from + 1);
    for (uint64_t c = 0; c < cells.offsets.size(); ++c) cells.offsets[c] = int64_t(c * nodes);
  } else {
    bool hasCount = false;
    uint64_t declared = 0;
    if (Result r = declaredCells(topo, what, hasCount, declared); !r) return r;
    if (dims.size() != 1) return Result::success();
    if (!hasCount)
      if (Result r = countMixed(item, where, dims[0], declared); !r) return r;
    share(declared);
    if (Result r = mixedRows(item, where, base, dims[0], from, to, declared, cells); !r) return r;
  }
  int64_t lo = INT64_MAX, hi = -1;
  for (int64_t id : cells.connectivity) {
    if (id < 0) return fail(Status::Corrupt, what + ": a cell names point " + std::to_string(id));
    lo = std::min(lo, id);
    hi = std::max(hi, id);
  }
  if (hi < 0) lo = 0;
  Rows rows;
  rows.cellsTotal = cellsTotal;
  rows.cellFirst = from;
  rows.pointFirst = uint64_t(lo);
  const uint64_t span = uint64_t(hi + 1 - lo);
  rows.pointsSpan = span;
  // The points the cells use (io/row_pick.h); the ids become their places among those read.
  rows.pointPick = io::pickUsedRows(cells.connectivity, rows.pointFirst, span);
  const uint64_t points = rows.pointPick.empty() ? span : rows.pointPick.size();
  const uint64_t vertexBase = mesh_.positions.size() / 3;
  if (Result r = pointRows(geo, where, rows.pointFirst, span, rows.pointPick, rows.pointsTotal); !r) return r;
  if (Result r = appendMixed(where, cells, vertexBase, points); !r) return r;
  xdmf::GridCells gc;
  gc.connectivity = kind ? &cells.connectivity : nullptr;
  gc.cells = to - from;
  gc.nodes = kind ? kind->nodes : 0;
  gc.corners = kind ? kShapeCorners[int(vtkCellInfo(kind->vtk).shape)] : 0;
  gc.points = points;
  if (Result r = readAttributes(attributes, where, gc, true, false, arrays, &rows); !r) return r;
  report_.shared = true;
  report_.notes.push_back("read cells " + std::to_string(from) + " to " + std::to_string(to) + " of " +
                          std::to_string(cellsTotal) + " and the " + std::to_string(points) +
                          " points they use, this process's share of the grid");
  done = true;
  return Result::success();
}

// What a grid is, for sharing it: a grid of volume cells tetstream reads, one whose cells can be
// shared out (readShareOfGrid: a declared size; no attribute of a function space), and its
// Geometry element (after references).
Result XdmfReader::gridShape(pugi::xml_node grid, const std::vector<pugi::xml_node>& companions,
                             const std::string& where, bool& volume, bool& byRows, const void*& geometry) {
  volume = byRows = false;
  geometry = nullptr;
  std::vector<pugi::xml_node> topos, geos, attributes;
  if (Result r = doc_.children(grid, "Topology", where, topos); !r) return r;
  if (topos.size() != 1) return Result::success();  // (readPiece says what is wrong)
  std::string_view typeName = topos[0].attribute("TopologyType").value();
  if (typeName.empty()) typeName = topos[0].attribute("Type").value();
  const bool mixed = iequals(typeName, "Mixed");
  const TopologyKind* kind = mixed ? nullptr : kindByName(typeName);
  volume = mixed || (kind && kind->read);
  if (!volume) return Result::success();
  if (Result r = doc_.children(grid, "Geometry", where, geos); !r) return r;
  if (geos.size() == 1) geometry = geos[0].internal_object();
  if (Result r = doc_.children(grid, "Attribute", where, attributes); !r) return r;
  for (pugi::xml_node c : companions) {
    std::vector<pugi::xml_node> more;
    if (Result r = doc_.children(c, "Attribute", where, more); !r) return r;
    attributes.insert(attributes.end(), more.begin(), more.end());
  }
  if (anyOfFunctionSpace(attributes)) return Result::success();
  pugi::xml_node item;
  if (Result r = doc_.dataItem(topos[0], where + " Topology", item); !r) return r;
  const std::vector<uint64_t> dims = doc_.declaredDims(item);
  // Mixed cells are found by walking the topology (counted first when it does not say how many).
  byRows = mixed ? dims.size() == 1 : cellRowsDeclared(dims, uint64_t(kind->nodes));
  return Result::success();
}

// Which grids this process reads (ReadOptions::shareIndex of shareCount). Of at least as many
// volume grids as processes (a spatial collection of one grid per rank), its share of them, each
// whole; of fewer, every one, each a share of its rows, when all can be read so. Otherwise, or
// when two volume grids stand on one Geometry (a grid of tags repeats the mesh's cells: on two
// processes the repeats would be kept twice), every grid is read whole and the caller keeps its
// share of the tets.
Result XdmfReader::shareGrids(const std::vector<pugi::xml_node>& pieces, const std::vector<pugi::xml_node>& companions,
                              std::vector<bool>& readHere) {
  std::vector<size_t> volumes;
  std::set<const void*> geometries;
  bool rows = true;
  for (size_t k = 0; k < pieces.size(); ++k) {
    bool volume, byRows;
    const void* geometry;
    if (Result r = gridShape(pieces[k], k == 0 ? companions : std::vector<pugi::xml_node>{},
                             doc_.label() + " Grid " + std::to_string(k), volume, byRows, geometry);
        !r)
      return r;
    if (!volume) continue;
    volumes.push_back(k);
    rows = rows && byRows;
    if (geometry && !geometries.insert(geometry).second) return Result::success();
  }
  const uint64_t n = volumes.size(), count = options_.shareCount, index = options_.shareIndex;
  if (n >= count) {
    const uint64_t from = n * index / count, to = n * (index + 1) / count;
    for (size_t v = 0; v < n; ++v) readHere[volumes[v]] = v >= from && v < to;
    report_.shared = true;
    const std::string which = to == from + 1 ? "grid " + std::to_string(to)
                                             : "grids " + std::to_string(from + 1) + " to " + std::to_string(to);
    report_.notes.push_back("read " + which + " of the " + std::to_string(n) +
                            " volume grids, this process's share of the file");
  } else if (n > 0 && rows) {
    shareGrid_ = true;
  }
  return Result::success();
}

// A topology's declared cell count (NumberOfElements, or XDMF 2's Dimensions), when it has one.
Result XdmfReader::declaredCells(pugi::xml_node topo, const std::string& what, bool& hasCount, uint64_t& declared) {
  declared = 0;
  hasCount = topo.attribute("NumberOfElements") || topo.attribute("Dimensions");
  if (!hasCount) return Result::success();
  const char* text = topo.attribute("NumberOfElements") ? topo.attribute("NumberOfElements").value()
                                                        : topo.attribute("Dimensions").value();
  size_t pos = 0;
  if (!parseU64(nextToken(text, pos), declared))
    return fail(Status::Corrupt, what + ": NumberOfElements='" + printable(text) + "' is not a count");
  return Result::success();
}

Result XdmfReader::readCells(pugi::xml_node topo, const TopologyKind* kind, const std::string& where, uint64_t points,
                             uint64_t vertexBase, std::vector<int64_t>& conn, int& nodes, uint64_t& cells) {
  const std::string what = where + " Topology";
  pugi::xml_node item;
  if (Result r = doc_.dataItem(topo, what, item); !r) return r;
  Values<int64_t> v;
  if (Result r = doc_.integers(item, what, v); !r) return r;
  int64_t base = 0;
  if (Result r = baseOffset(topo, what, base); !r) return r;
  bool hasCount = false;
  uint64_t declared = 0;
  if (Result r = declaredCells(topo, what, hasCount, declared); !r) return r;
  if (!kind) {  // Mixed: the node ids lose the base, the type codes do not
    xdmf::MixedCells mixed;
    xdmf::MixedWalker walker(where, base, 0, UINT64_MAX);
    size_t used = 0;
    if (Result r = walker.walk(v.values, true, mixed, used); !r) return r;
    if (Result r = appendMixed(where, mixed, vertexBase, points); !r) return r;
    cells = walker.cells();
    if (hasCount && declared != cells)
      return fail(Status::Corrupt, what + ": NumberOfElements=" + std::to_string(declared) +
                                       " but the Mixed data holds " + std::to_string(cells) + " cells");
    return Result::success();
  }
  for (int64_t& id : v.values) id -= base;
  nodes = kind->nodes;
  if (nodes == 0) nodes = 1;  // (only cells that are not read have no fixed count; never reached)
  if (v.values.size() % uint64_t(nodes) != 0)
    return fail(Status::Corrupt, what + ": " + std::to_string(v.values.size()) + " ids are not a whole number of " +
                                     kind->name + " cells of " + std::to_string(nodes) + " nodes");
  cells = v.values.size() / uint64_t(nodes);
  if (hasCount && declared != cells)
    return fail(Status::Corrupt, what + ": NumberOfElements=" + std::to_string(declared) + " but the DataItem holds " +
                                     std::to_string(cells) + " " + kind->name + " cells (" +
                                     std::to_string(v.values.size()) + " ids)");
  std::vector<int64_t> offsets(cells + 1), types(cells, kind->vtk);
  for (uint64_t c = 0; c <= cells; ++c) offsets[c] = int64_t(c * uint64_t(nodes));
  if (Result r = appendVtkCells(where, v.values, offsets, types, vertexBase, points, soup_); !r) return r;
  conn = std::move(v.values);
  return Result::success();
}

Result XdmfReader::readAttributes(const std::vector<pugi::xml_node>& attributes, const std::string& where,
                                  const xdmf::GridCells& grid, bool first, bool sharedPoints, PieceArrays& arrays,
                                  const Rows* rows) {
  ReadReport scratch;  // conversions are noted for the first piece only
  ReadReport& notes = first ? report_ : scratch;
  int index = 0;
  for (pugi::xml_node a : attributes) {
    std::string name = a.attribute("Name").value();
    if (name.empty()) name = "attribute" + std::to_string(index);
    ++index;
    const std::string what = where + " Attribute '" + printable(name) + "'";
    std::string_view center = a.attribute("Center").value();
    if (center.empty()) center = "Node";
    std::string_view type = a.attribute("AttributeType").value();
    if (type.empty()) type = a.attribute("Type").value();
    if (iequals(center, "Other") && iequals(a.attribute("ItemType").value(), "FiniteElementFunction")) {
      const uint32_t comps = iequals(type, "Vector") ? 3 : iequals(type, "Tensor") ? 9 : 1;
      if (Result r = xdmf::readFiniteElementFunction(doc_, a, name, comps, what, grid, notes, arrays.fields,
                                                     arrays.cellArrays);
          !r)
        return r;
      continue;
    }
    const bool node = iequals(center, "Node"), cell = iequals(center, "Cell");
    if (node && sharedPoints) {
      report_.notes.push_back(where + ": skipped point attribute '" + printable(name) +
                              "' (the grid stands on the points of an earlier grid, whose point data is read)");
      continue;
    }
    if (!node && !cell) {
      notes.notes.push_back("skipped attribute '" + printable(name) + "' with Center=\"" + printable(center) +
                            "\" (tetstream reads Node and Cell data)");
      continue;
    }
    pugi::xml_node item;
    if (Result r = doc_.dataItem(a, what, item); !r) return r;
    Values<double> v;
    const uint64_t n = node ? grid.points : grid.cells;
    if (rows) {  // a share of the grid: the rows of its points, or of its cells
      if (Result r =
              node ? pickedRows(item, what, rows->pointsTotal, rows->pointFirst, rows->pointsSpan, rows->pointPick, v)
                   : doc_.numberRows(item, what, rows->cellsTotal, rows->cellFirst, n, v);
          !r)
        return r;
    } else if (Result r = doc_.numbers(item, what, v); !r) {
      return r;
    }
    if (n == 0) continue;
    const uint64_t comps = v.values.size() / n;
    if (v.values.size() % n != 0 || comps == 0 || comps > kMaxComponents)
      return fail(Status::Corrupt, what + ": holds " + std::to_string(v.values.size()) + " values for " +
                                       std::to_string(n) + (node ? " points" : " cells") +
                                       " (expected a whole number of values per " + (node ? "point)" : "cell)"));
    const std::string fname = fieldNameFor(name, uint32_t(comps), notes, node ? "point" : "cell");
    std::vector<float> scalars = tuplesToScalars(v.values, uint32_t(comps));
    if (node)
      arrays.fields.push_back({fname, std::move(scalars)});
    else
      arrays.cellArrays.push_back({fname, std::vector<double>(scalars.begin(), scalars.end())});
  }
  return Result::success();
}

// Cells of a grid that repeat cells already read on the same points (the same corners in any
// order) are taken out again: DOLFINx writes its cell tags as a second grid of the mesh's cells.
void XdmfReader::dropRepeatedCells(size_t firstNew, uint64_t vertexBase, uint64_t points, const std::string& where) {
  using Key = std::array<uint32_t, 8>;
  auto keyOf = [](const uint32_t* ids, int n) {  // the corners in increasing order
    Key k;
    k.fill(UINT32_MAX);
    for (size_t i = 0; i < size_t(n) && i < k.size(); ++i) {
      size_t j = i;
      for (; j > 0 && k[j - 1] > ids[i]; --j) k[j] = k[j - 1];
      k[j] = ids[i];
    }
    return k;
  };
  std::set<Key> earlier;
  size_t at = 0;
  for (size_t c = 0; c < firstNew; ++c) {
    const int n = kShapeCorners[soup_.shapes[c]];
    if (soup_.corners[at] >= vertexBase && soup_.corners[at] < vertexBase + points)
      earlier.insert(keyOf(&soup_.corners[at], n));
    at += size_t(n);
  }
  size_t write = firstNew, writeAt = at;
  uint64_t dropped = 0;
  for (size_t c = firstNew; c < soup_.shapes.size(); ++c) {
    const int n = kShapeCorners[soup_.shapes[c]];
    if (earlier.count(keyOf(&soup_.corners[at], n))) {
      ++dropped;
    } else {
      soup_.shapes[write] = soup_.shapes[c];
      soup_.source[write] = soup_.source[c];
      std::copy_n(&soup_.corners[at], n, &soup_.corners[writeAt]);
      ++write;
      writeAt += size_t(n);
    }
    at += size_t(n);
  }
  soup_.shapes.resize(write);
  soup_.source.resize(write);
  soup_.corners.resize(writeAt);
  if (dropped)
    report_.notes.push_back(where + ": " + std::to_string(dropped) +
                            " cells repeat cells of an earlier grid on the same points (mesh tags?); not added again");
}

Result XdmfReader::readPiece(pugi::xml_node grid, const std::vector<pugi::xml_node>& companions,
                             const std::string& where, bool first, PieceArrays& arrays, bool& skipped,
                             bool& sharedPoints) {
  skipped = false;
  sharedPoints = false;
  std::vector<pugi::xml_node> topos, geos;
  if (Result r = doc_.children(grid, "Topology", where, topos); !r) return r;
  if (topos.size() != 1)
    return fail(Status::Corrupt, where + ": " + (topos.empty() ? "no <Topology>" : "more than one <Topology>"));
  pugi::xml_node topo = topos[0];
  std::string_view typeName = topo.attribute("TopologyType").value();
  if (typeName.empty()) typeName = topo.attribute("Type").value();
  const bool mixed = iequals(typeName, "Mixed");
  const TopologyKind* kind = mixed ? nullptr : kindByName(typeName);
  if (!mixed && !kind) {
    const bool structured = iequals(typeName.substr(0, 2), "2D") || iequals(typeName.substr(0, 2), "3D");
    return fail(Status::Unsupported,
                where + ": TopologyType '" + printable(typeName) + "' " +
                    (structured ? "is a structured grid, which is not read from XDMF (convert to .vti/.vts)"
                                : "is not an XDMF cell type tetstream knows"));
  }
  if (kind && !kind->read) {
    // A grid of cells that are not read (DOLFINx's facet tags, higher orders): counted, and
    // neither its points nor its attributes are read.
    uint64_t n = 0;
    const char* count = topo.attribute("NumberOfElements") ? topo.attribute("NumberOfElements").value()
                                                           : topo.attribute("Dimensions").value();
    size_t pos = 0;
    if (!parseU64(nextToken(count, pos), n)) {
      pugi::xml_node item;
      if (doc_.dataItem(topo, where, item)) {
        std::string_view d = item.attribute("Dimensions").value();
        size_t p = 0;
        parseU64(nextToken(d, p), n);
      }
    }
    countSkipped(soup_, *kind, n);
    soup_.inputCells += n;
    report_.notes.push_back(where + ": " + std::to_string(n) + " " + kind->name +
                            " cells, not volume cells tetstream reads; the grid was skipped");
    skipped = true;
    return Result::success();
  }
  if (Result r = doc_.children(grid, "Geometry", where, geos); !r) return r;
  if (geos.size() != 1)
    return fail(Status::Corrupt, where + ": " + (geos.empty() ? "no <Geometry>" : "more than one <Geometry>"));
  std::vector<pugi::xml_node> attributes;
  if (Result r = doc_.children(grid, "Attribute", where, attributes); !r) return r;
  for (pugi::xml_node c : companions) {
    std::vector<pugi::xml_node> more;
    if (Result r = doc_.children(c, "Attribute", where, more); !r) return r;
    attributes.insert(attributes.end(), more.begin(), more.end());
  }
  if (shareGrid_) {
    bool done = false;
    if (Result r = readShareOfGrid(topo, geos[0], kind, attributes, where, arrays, done); !r) return r;
    if (done) {
      const std::string name = mixed ? "Mixed" : kind->name;
      if (std::find(topologies_.begin(), topologies_.end(), name) == topologies_.end()) topologies_.push_back(name);
      return Result::success();
    }
  }

  uint64_t vertexBase = mesh_.positions.size() / 3, points = 0, cells = 0;
  if (auto seen = geometries_.find(geos[0].internal_object()); seen != geometries_.end()) {
    sharedPoints = true;
    vertexBase = seen->second.first;
    points = seen->second.second;
  } else {
    if (Result r = readPoints(geos[0], where, points); !r) return r;
    geometries_[geos[0].internal_object()] = {vertexBase, points};
  }
  std::vector<int64_t> conn;
  int nodes = 0;
  const size_t firstNew = soup_.shapes.size();
  if (Result r = readCells(topo, kind, where, points, vertexBase, conn, nodes, cells); !r) return r;
  if (sharedPoints) dropRepeatedCells(firstNew, vertexBase, points, where);
  const std::string name = mixed ? "Mixed" : kind->name;
  if (std::find(topologies_.begin(), topologies_.end(), name) == topologies_.end()) topologies_.push_back(name);

  xdmf::GridCells gc;
  gc.connectivity = mixed ? nullptr : &conn;
  gc.cells = cells;
  gc.nodes = nodes;
  gc.corners = kind ? kShapeCorners[int(vtkCellInfo(kind->vtk).shape)] : 0;
  gc.points = points;
  return readAttributes(attributes, where, gc, first, sharedPoints, arrays);
}

Result XdmfReader::read(TetMesh& out) {
  const std::string& label = doc_.label();
  pugi::xml_node root = doc_.root();
  std::string version = root.attribute("Version").value();
  const std::string major = version.substr(0, version.find('.'));
  if (!major.empty() && major != "1" && major != "2" && major != "3")
    return fail(Status::UnsupportedVersion,
                label + ": XDMF Version='" + printable(version) + "' (tetstream reads XDMF 2 and 3)");
  std::vector<pugi::xml_node> domains;
  if (Result r = doc_.children(root, "Domain", label, domains); !r) return r;
  if (domains.empty()) return fail(Status::Corrupt, label + ": <Xdmf> has no <Domain>");
  if (domains.size() > 1) report_.notes.push_back("read the first of " + std::to_string(domains.size()) + " Domains");
  std::vector<pugi::xml_node> top;
  if (Result r = doc_.children(domains[0], "Grid", label, top); !r) return r;
  if (top.empty()) return fail(Status::Corrupt, label + ": the Domain has no <Grid>");

  // Time steps: the first top-level temporal collection drives; the others join when they have
  // the same times.
  std::vector<pugi::xml_node> temporal;
  for (pugi::xml_node g : top)
    if (isTemporal(g)) temporal.push_back(g);
  std::vector<pugi::xml_node> pieces, companions;
  std::vector<double> times;
  std::string stepText;
  if (!temporal.empty()) {
    const std::string what = label + " Grid '" + gridName(temporal[0]) + "'";
    std::vector<pugi::xml_node> steps;
    if (Result r = doc_.children(temporal[0], "Grid", what, steps); !r) return r;
    if (steps.empty()) return fail(Status::Corrupt, what + ": a temporal collection without grids");
    if (Result r = stepTimes(temporal[0], steps, what, times); !r) return r;
    size_t index = 0;
    if (Result r = chooseTimeStep(times, options_, label, report_, index); !r) return r;
    stepText = vtkio::stepText(report_);
    const std::string stepWhat = what + " step " + std::to_string(index);
    if (Result r = flatten(steps[index], stepWhat, 0, pieces); !r) return r;
    for (size_t k = 1; k < temporal.size(); ++k) {
      const std::string otherWhat = label + " Grid '" + gridName(temporal[k]) + "'";
      std::vector<pugi::xml_node> other;
      std::vector<double> otherTimes;
      if (Result r = doc_.children(temporal[k], "Grid", otherWhat, other); !r) return r;
      if (Result r = stepTimes(temporal[k], other, otherWhat, otherTimes); !r) return r;
      bool same = otherTimes == times && pieces.size() == 1 && !isCollection(other[index]);
      if (same)
        if (Result r = sameMesh(pieces[0], other[index], otherWhat, same); !r) return r;
      if (same)
        companions.push_back(other[index]);
      else
        report_.notes.push_back("did not read the time series '" + gridName(temporal[k]) +
                                "': its steps or mesh differ from those of '" + gridName(temporal[0]) + "'");
    }
    const size_t others = top.size() - temporal.size();
    if (others)
      report_.notes.push_back("read the time series '" + gridName(temporal[0]) + "'" +
                              (companions.empty() ? "" : " with " + std::to_string(companions.size()) + " more") +
                              "; " + std::to_string(others) + " top-level grid" + (others == 1 ? "" : "s") +
                              " outside it (what its steps refer to) not read on " + (others == 1 ? "its" : "their") +
                              " own");
  } else {
    size_t index = 0;
    if (Result r = chooseTimeStep({}, options_, label, report_, index); !r) return r;
    for (pugi::xml_node g : top) {
      const std::string name = gridName(g);
      if (Result r = flatten(g, label + " Grid" + (name.empty() ? "" : " '" + name + "'"), 0, pieces); !r) return r;
    }
  }

  std::vector<bool> readHere(pieces.size(), true);
  if (options_.shareCount > 1)
    if (Result r = shareGrids(pieces, companions, readHere); !r) return r;

  // Pieces, their arrays merged: an array survives only if every piece that was read has it.
  PieceArrays merged;
  std::vector<bool> keepField, keepCell;
  size_t read = 0;
  for (size_t k = 0; k < pieces.size(); ++k) {
    if (!readHere[k]) continue;
    const std::string name = gridName(pieces[k]);
    std::string where = label + " Grid" + (name.empty() ? " " + std::to_string(k) : " '" + name + "'");
    PieceArrays pa;
    bool skipped = false, shared = false;
    if (Result r = readPiece(pieces[k], k == 0 ? companions : std::vector<pugi::xml_node>{}, where, read == 0, pa,
                             skipped, shared);
        !r)
      return r;
    if (skipped) continue;
    if (read++ == 0) {
      merged = std::move(pa);
      keepField.assign(merged.fields.size(), true);
      keepCell.assign(merged.cellArrays.size(), true);
      continue;
    }
    auto join = [&](auto& into, auto& from, std::vector<bool>& keep, const char* kind) {
      for (size_t i = 0; i < into.size(); ++i) {
        auto it = std::find_if(from.begin(), from.end(), [&](const auto& f) { return f.name == into[i].name; });
        if (it == from.end()) {
          if (keep[i])
            report_.notes.push_back(std::string("dropped ") + kind + " array '" + into[i].name + "': grid " + where +
                                    " lacks it");
          keep[i] = false;
        } else {
          into[i].values.insert(into[i].values.end(), it->values.begin(), it->values.end());
        }
      }
    };
    if (!shared) join(merged.fields, pa.fields, keepField, "point");  // (its points are an earlier grid's)
    join(merged.cellArrays, pa.cellArrays, keepCell, "cell");
  }
  for (size_t i = 0; i < merged.fields.size(); ++i)
    if (keepField[i]) addField(mesh_, std::move(merged.fields[i]), report_);
  std::vector<CellArray> cellArrays;
  for (size_t i = 0; i < merged.cellArrays.size(); ++i)
    if (keepCell[i]) cellArrays.push_back(std::move(merged.cellArrays[i]));
  if (read > 1) report_.notes.push_back("concatenated " + std::to_string(read) + " grids");

  std::string sources;
  for (const std::string& s : doc_.sources()) sources += (sources.empty() ? "" : ", ") + s;
  std::string kinds;
  for (const std::string& t : topologies_) kinds += (kinds.empty() ? "" : " + ") + t;
  report_.format = "XDMF" + (major.empty() ? std::string() : " " + major) +
                   (sources.empty() ? std::string() : " (" + sources + ")") + (kinds.empty() ? "" : ", " + kinds) +
                   (read > 1 ? ", " + std::to_string(read) + " grids" : "") + stepText;
  if (Result r = finishMesh(label, mesh_, soup_, std::move(cellArrays), report_); !r) return r;
  out = std::move(mesh_);
  return Result::success();
}

}  // namespace

Result readXdmf(std::string_view xml, const std::string& label, const std::optional<std::string>& dataFolder,
                const ReadOptions& options, TetMesh& out, ReadReport& report) {
  out = TetMesh{};
  Document doc(label, dataFolder);
  if (Result r = doc.parse(xml); !r) return r;
  XdmfReader reader(doc, options, report);
  return reader.read(out);
}

}  // namespace tetstream
