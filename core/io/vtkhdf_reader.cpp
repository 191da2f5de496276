// VTKHDF reader (VTK's HDF5 format), UnstructuredGrid. Layout reference: "VTKHDF format
// specification" (docs.vtk.org, vtk_file_formats/vtkhdf_file_format).
//
// /VTKHDF (attributes Version = [major, minor], Type = "UnstructuredGrid") holds one row per
// partition in NumberOfPoints, NumberOfCells and NumberOfConnectivityIds, and the partitions'
// rows one after another in Points (n x 3), Types, Connectivity (ids local to the partition) and
// Offsets (NumberOfCells + 1 per partition, from 0), and in PointData/<name> and CellData/<name>.
// A Steps group (VTKHDF 2) makes time steps: per step Values (the time), PartOffsets and
// NumberOfParts (which partition rows), PointOffsets, CellOffsets and ConnectivityIdOffsets (where
// its rows start; its Offsets rows start at CellOffsets + PartOffsets, one extra per partition
// before it), and PointDataOffsets/<name>, CellDataOffsets/<name>. Only the chosen step's rows are
// read.
#include <cmath>
#include <cstdio>
#include <span>
#include <tuple>
#include <type_traits>

#include "io/hdf5_file.h"
#include "io/readers.h"

namespace tetstream {
namespace {

using namespace vtkio;

const std::string kRoot = "/VTKHDF";
constexpr int64_t kMaxPartitions = int64_t(1) << 24;  // far beyond any run's rank count

// Rows [first, first + count) of a rank-1 or rank-2 dataset, with its column count.
template <class T>
Result readRows(const hdf5::File& f, const std::string& dataset, uint64_t first, uint64_t count, std::vector<T>& out,
                uint64_t& columns) {
  hdf5::Shape shape;
  if (Result r = f.shape(dataset, shape); !r) return r;
  if (shape.dims.empty() || shape.dims.size() > 2)
    return fail(Status::Corrupt,
                f.where(dataset) + " has " + std::to_string(shape.dims.size()) + " dimensions, expected 1 or 2");
  columns = shape.dims.size() == 2 ? shape.dims[1] : 1;
  if (columns == 0 || columns > kMaxComponents)
    return fail(Status::Corrupt, f.where(dataset) + " has " + std::to_string(columns) + " columns");
  uint64_t end = 0;
  if (__builtin_add_overflow(first, count, &end) || end > shape.dims[0])
    return fail(shape.dims[0] < end ? Status::Truncated : Status::Corrupt,
                f.where(dataset) + " has " + std::to_string(shape.dims[0]) + " rows; rows " + std::to_string(first) +
                    ".." + std::to_string(first + count) + " are needed");
  if constexpr (std::is_same_v<T, double>)
    return f.readDoubles(dataset, f.rows(shape, first, count), count * columns, out);
  else
    return f.readInts(dataset, f.rows(shape, first, count), count * columns, out);
}

// One value of a per-step dataset (the first column of a 2D one).
Result stepValue(const hdf5::File& f, const std::string& dataset, uint64_t step, int64_t& out) {
  std::vector<int64_t> v;
  uint64_t columns;
  if (Result r = readRows(f, dataset, step, 1, v, columns); !r) return r;
  out = v[0];
  if (out < 0)
    return fail(Status::Corrupt, f.where(dataset) + ": step " + std::to_string(step) + " has " + std::to_string(out));
  return Result::success();
}

Result sumCounts(const hdf5::File& f, const std::string& dataset, const std::vector<int64_t>& v, uint64_t& total) {
  total = 0;
  for (size_t p = 0; p < v.size(); ++p) {
    if (v[p] < 0 || __builtin_add_overflow(total, uint64_t(v[p]), &total))
      return fail(Status::Corrupt,
                  f.where(dataset) + ": partition " + std::to_string(p) + " has " + std::to_string(v[p]));
  }
  return Result::success();
}

}  // namespace

Result readVtkHdf(const std::string& path, const ReadOptions& options, TetMesh& out, ReadReport& report) {
  out = TetMesh{};
  hdf5::File f;
  if (Result r = f.open(path); !r) return r;
  if (!f.isGroup(kRoot))
    return fail(Status::BadMagic, path +
                                      ": an HDF5 file without a /VTKHDF group, so not VTKHDF (if it holds the "
                                      "data of an XDMF file, read the .xdmf)");
  std::string type;
  if (Result r = f.stringAttribute(kRoot, "Type", type); !r) return r;
  if (type != "UnstructuredGrid")
    return fail(Status::Unsupported, path + ": VTKHDF Type '" + printable(type) +
                                         "' is not read; tetstream reads VTKHDF UnstructuredGrid (for images, "
                                         "save .vti)");
  std::string versionText;
  if (f.hasAttribute(kRoot, "Version")) {
    std::vector<int64_t> version;
    if (Result r = f.intAttribute(kRoot, "Version", version, 2); !r) return r;
    if (version[0] > 2)
      return fail(Status::UnsupportedVersion,
                  path + ": VTKHDF version " + std::to_string(version[0]) + " (tetstream reads versions 1 and 2)");
    versionText = ' ' + std::to_string(version[0]) + '.' + std::to_string(version.size() > 1 ? version[1] : 0);
  }

  // The step and where its rows start.
  const bool temporal = f.isGroup(kRoot + "/Steps");
  std::vector<double> times;
  if (temporal) {
    uint64_t columns;
    hdf5::Shape shape;
    if (Result r = f.shape(kRoot + "/Steps/Values", shape); !r) return r;
    if (shape.dims.size() != 1)
      return fail(Status::Corrupt, f.where(kRoot + "/Steps/Values") + " is not a list of times");
    if (Result r = readRows(f, kRoot + "/Steps/Values", 0, shape.dims[0], times, columns); !r) return r;
    for (size_t i = 0; i < times.size(); ++i)
      if (!std::isfinite(times[i]))
        return fail(Status::NonFinite,
                    f.where(kRoot + "/Steps/Values") + ": step " + std::to_string(i) + " has a non-finite time");
  }
  size_t step = 0;
  if (Result r = chooseTimeStep(times, options, path, report, step); !r) return r;
  int64_t partOffset = 0, parts = 0, pointOffset = 0, cellOffset = 0, connOffset = 0;
  if (temporal) {
    for (auto [name, value] : {std::pair{"PartOffsets", &partOffset},
                               {"NumberOfParts", &parts},
                               {"PointOffsets", &pointOffset},
                               {"CellOffsets", &cellOffset},
                               {"ConnectivityIdOffsets", &connOffset}})
      if (Result r = stepValue(f, kRoot + "/Steps/" + name, step, *value); !r) return r;
  } else {
    hdf5::Shape shape;
    if (Result r = f.shape(kRoot + "/NumberOfPoints", shape); !r) return r;
    parts = int64_t(shape.count());
  }
  if (parts <= 0) return fail(Status::NoTets, path + ": no partitions" + (temporal ? " in this step" : std::string()));
  if (parts > kMaxPartitions)
    return fail(Status::TooLarge, path + ": " + std::to_string(parts) + " partitions (at most " +
                                      std::to_string(kMaxPartitions) + " are read)");

  // Partition sizes, then every array's rows for them.
  std::vector<int64_t> np, nc, nconn;
  uint64_t columns = 0, totalPoints = 0, totalCells = 0, totalConn = 0;
  for (auto [name, v, total] : {std::tuple{"NumberOfPoints", &np, &totalPoints},
                                {"NumberOfCells", &nc, &totalCells},
                                {"NumberOfConnectivityIds", &nconn, &totalConn}}) {
    if (Result r = readRows(f, kRoot + "/" + name, uint64_t(partOffset), uint64_t(parts), *v, columns); !r) return r;
    if (Result r = sumCounts(f, kRoot + "/" + name, *v, *total); !r) return r;
  }
  // A share of the partitions (ReadOptions): their rows start after those of the partitions
  // before them, and each partition before adds one row to Offsets.
  int64_t pointSkip = 0, cellSkip = 0;
  const uint64_t partitionsInFile = uint64_t(parts);
  if (options.shareCount > 1 && partitionsInFile >= options.shareCount) {
    const size_t from = size_t(partitionsInFile * options.shareIndex / options.shareCount),
                 to = size_t(partitionsInFile * (options.shareIndex + 1ull) / options.shareCount);
    for (size_t p = 0; p < from; ++p) {
      pointSkip += np[p], cellSkip += nc[p], connOffset += nconn[p];
      ++partOffset;
    }
    pointOffset += pointSkip;
    cellOffset += cellSkip;
    for (std::vector<int64_t>* v : {&np, &nc, &nconn})
      *v = std::vector<int64_t>(v->begin() + ptrdiff_t(from), v->begin() + ptrdiff_t(to));
    parts = int64_t(to - from);
    totalPoints = totalCells = totalConn = 0;
    for (size_t p = 0; p < np.size(); ++p)
      totalPoints += uint64_t(np[p]), totalCells += uint64_t(nc[p]), totalConn += uint64_t(nconn[p]);
    report.shared = true;
  }
  if (totalPoints > kMaxVertices)
    return fail(Status::TooLarge,
                path + ": " + std::to_string(totalPoints) + " points; tetstream indexes vertices with 32 bits");
  TetMesh mesh;
  CellSoup soup;
  {
    std::vector<double> points;
    if (Result r = readRows(f, kRoot + "/Points", uint64_t(pointOffset), totalPoints, points, columns); !r) return r;
    if (columns != 3)
      return fail(Status::Corrupt,
                  f.where(kRoot + "/Points") + " has " + std::to_string(columns) + " columns, expected 3 (x, y, z)");
    mesh.positions.assign(points.begin(), points.end());
  }
  std::vector<int64_t> types, conn, offsets;
  if (Result r = readRows(f, kRoot + "/Types", uint64_t(cellOffset), totalCells, types, columns); !r) return r;
  if (Result r = readRows(f, kRoot + "/Connectivity", uint64_t(connOffset), totalConn, conn, columns); !r) return r;
  if (Result r = readRows(f, kRoot + "/Offsets", uint64_t(cellOffset + partOffset), totalCells + uint64_t(parts),
                          offsets, columns);
      !r)
    return r;
  uint64_t vertexBase = 0, cellAt = 0, connAt = 0;
  for (int64_t p = 0; p < parts; ++p) {
    const std::string where = parts == 1 ? path : path + " partition " + std::to_string(p);
    const uint64_t n = uint64_t(nc[size_t(p)]), m = uint64_t(nconn[size_t(p)]);
    std::span<const int64_t> partConn(conn.data() + connAt, m), partTypes(types.data() + cellAt, n),
        partOffsets(offsets.data() + cellAt + uint64_t(p), n + 1);
    if (Result r = appendVtkCells(where, partConn, partOffsets, partTypes, vertexBase, uint64_t(np[size_t(p)]), soup);
        !r)
      return r;
    vertexBase += uint64_t(np[size_t(p)]);
    cellAt += n;
    connAt += m;
  }

  // Point and cell data: the same rows, from their own offsets in a time series.
  std::vector<CellArray> cellArrays;
  for (const char* section : {"PointData", "CellData"}) {
    const bool cells = section[0] == 'C';
    const std::string group = kRoot + "/" + section;
    if (!f.isGroup(group)) continue;
    std::vector<std::string> names;
    if (Result r = f.members(group, names); !r) return r;
    for (const std::string& name : names) {
      const std::string dataset = group + "/" + name;
      hdf5::Shape shape;
      if (Result r = f.shape(dataset, shape); !r) return r;
      if (!shape.isFloat && !shape.isInteger) {
        report.notes.push_back(std::string("skipped ") + (cells ? "cell" : "point") + " array '" + printable(name) +
                               "' (not numbers)");
        continue;
      }
      int64_t first = 0;
      if (temporal) {
        const std::string offsetsSet = kRoot + "/Steps/" + (cells ? "CellDataOffsets/" : "PointDataOffsets/") + name;
        if (!f.exists(offsetsSet)) {
          report.notes.push_back(std::string("skipped ") + (cells ? "cell" : "point") + " array '" + printable(name) +
                                 "': the time series gives no " + offsetsSet);
          continue;
        }
        if (Result r = stepValue(f, offsetsSet, step, first); !r) return r;
      }
      first += cells ? cellSkip : pointSkip;
      std::vector<double> values;
      if (Result r = readRows(f, dataset, uint64_t(first), cells ? totalCells : totalPoints, values, columns); !r)
        return r;
      const std::string fname = fieldNameFor(name, uint32_t(columns), report, cells ? "cell" : "point");
      std::vector<float> scalars = tuplesToScalars(values, uint32_t(columns));
      if (cells)
        cellArrays.push_back({fname, std::vector<double>(scalars.begin(), scalars.end())});
      else
        addField(mesh, {fname, std::move(scalars)}, report);
    }
  }
  if (parts > 1) report.notes.push_back("concatenated " + std::to_string(parts) + " partitions");
  report.format = "VTKHDF" + versionText + " UnstructuredGrid, " + std::to_string(partitionsInFile) +
                  (partitionsInFile == 1 ? " partition" : " partitions") + stepText(report);
  if (Result r = finishMesh(path, mesh, soup, std::move(cellArrays), report); !r) return r;
  out = std::move(mesh);
  return Result::success();
}

}  // namespace tetstream
