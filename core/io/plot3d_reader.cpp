// PLOT3D reader: a structured (curvilinear) grid file and an optional Q solution file.
// Reference: the PLOT3D user's manual (NASA TM-101067) and vtkMultiBlockPLOT3DReader.
//
// Grid file, per block b of nblocks (3D, "whole" format):
//   [nblocks]                         multi-grid files only
//   ni_b nj_b nk_b   for every block  (ints)
//   x[n_b] y[n_b] z[n_b] [iblank[n_b]] for every block (reals, ints), n_b = ni nj nk, i fastest
// Q file:
//   [nblocks]  ni nj nk for every block
//   per block: fsmach alpha re time (reals), then q[5][n_b]: density, momentum x, y, z, energy
// Files come in C binary (no markers) or Fortran unformatted records (each record framed by its
// byte length as a 4-byte int before and after), little- or big-endian, with 4- or 8-byte reals.
// Nothing in the file says which: every combination is tried, and the one whose header describes
// exactly the bytes of the file (Fortran markers included) wins. A file may be padded with zero
// bytes at the end (the Blunt Fin Q file is, to a multiple of 512): accepted with a note.
#include <bit>
#include <cmath>
#include <cstring>

#include "io/readers.h"

namespace tetstream {
namespace {

using namespace vtkio;

struct Layout {
  bool bigEndian = false, multiGrid = false, fortran = false, doubles = false, iblank = false;
  std::string str(bool withIblank) const {
    std::string s = std::string(fortran ? "Fortran records" : "C binary") + ", " + (bigEndian ? "big" : "little") +
                    "-endian, " + (doubles ? "double" : "float") + ", " + (multiGrid ? "multi-grid" : "single-grid") +
                    " header";
    if (withIblank) s += iblank ? ", IBLANK" : ", no IBLANK";
    return s;
  }
};

struct Reader {
  std::string_view s;
  Layout L;
  size_t pos = 0;
  bool ok = true;

  uint32_t u32() {
    if (s.size() - pos < 4) {
      ok = false;
      return 0;
    }
    uint32_t v;
    std::memcpy(&v, s.data() + pos, 4);
    pos += 4;
    return L.bigEndian != (std::endian::native == std::endian::big) ? __builtin_bswap32(v) : v;
  }
  int32_t i32() { return int32_t(u32()); }
  // Fortran: the record marker must announce exactly `bytes`.
  bool begin(uint64_t bytes) {
    if (!L.fortran) return true;
    return u32() == bytes && ok;
  }
  bool end(uint64_t bytes) { return begin(bytes); }
  bool skip(uint64_t bytes) {
    if (s.size() - pos < bytes) return ok = false;
    pos += size_t(bytes);
    return true;
  }
  double real(size_t at) const {
    if (L.doubles) {
      uint64_t v;
      std::memcpy(&v, s.data() + at, 8);
      if (L.bigEndian != (std::endian::native == std::endian::big)) v = __builtin_bswap64(v);
      return std::bit_cast<double>(v);
    }
    uint32_t v;
    std::memcpy(&v, s.data() + at, 4);
    if (L.bigEndian != (std::endian::native == std::endian::big)) v = __builtin_bswap32(v);
    return double(std::bit_cast<float>(v));
  }
  int32_t int32At(size_t at) const {
    uint32_t v;
    std::memcpy(&v, s.data() + at, 4);
    if (L.bigEndian != (std::endian::native == std::endian::big)) v = __builtin_bswap32(v);
    return int32_t(v);
  }
};

struct Block {
  uint64_t n[3] = {0, 0, 0};
  uint64_t points() const { return n[0] * n[1] * n[2]; }
  size_t dataAt = 0;  // where x (grid) or q (solution) starts
};

// Reads nblocks and dims under layout L. False when they make no sense for this file.
bool readHeader(Reader& r, std::vector<Block>& blocks) {
  uint64_t nblocks = 1;
  if (r.L.multiGrid) {
    if (!r.begin(4)) return false;
    int32_t nb = r.i32();
    if (!r.ok || !r.end(4) || nb < 1) return false;
    nblocks = uint64_t(nb);
    if (nblocks > (r.s.size() - r.pos) / 12) return false;  // 12 header bytes per block must fit
  }
  const uint64_t dimBytes = 12 * nblocks;
  if (!r.begin(dimBytes)) return false;
  blocks.assign(nblocks, Block{});
  uint64_t total = 0;
  for (Block& b : blocks) {
    for (uint64_t& d : b.n) {
      int32_t v = r.i32();
      if (!r.ok || v < 1) return false;
      d = uint64_t(v);
    }
    // Each dimension is below 2^31, so the products below do not overflow before the check.
    if (b.n[0] * b.n[1] > kMaxVertices || b.points() > kMaxVertices || (total += b.points()) > kMaxVertices)
      return false;
  }
  return r.end(dimBytes);
}

// True when the rest of the file from pos is all zero bytes (padding).
bool zeroTail(std::string_view s, size_t pos) {
  for (size_t i = pos; i < s.size(); ++i)
    if (s[i] != 0) return false;
  return true;
}

// Walks the grid file under L; on success `blocks` have their data offsets and `end` is where the
// data stops.
bool walkGrid(std::string_view s, const Layout& L, std::vector<Block>& blocks, size_t& end) {
  Reader r{s, L};
  if (!readHeader(r, blocks)) return false;
  const uint64_t real = L.doubles ? 8 : 4;
  for (Block& b : blocks) {
    const uint64_t bytes = b.points() * (3 * real + (L.iblank ? 4 : 0));
    if (!r.begin(bytes)) return false;
    b.dataAt = r.pos;
    if (!r.skip(bytes) || !r.end(bytes)) return false;
  }
  end = r.pos;
  return true;
}

bool walkQ(std::string_view s, const Layout& L, std::vector<Block>& blocks, size_t& end, double header[4]) {
  Reader r{s, L};
  if (!readHeader(r, blocks)) return false;
  const uint64_t real = L.doubles ? 8 : 4;
  bool first = true;
  for (Block& b : blocks) {
    if (!r.begin(4 * real)) return false;
    if (first && s.size() - r.pos >= 4 * real)
      for (int k = 0; k < 4; ++k) header[k] = r.real(r.pos + size_t(k * real));
    first = false;
    if (!r.skip(4 * real) || !r.end(4 * real)) return false;
    const uint64_t bytes = 5 * real * b.points();
    if (!r.begin(bytes)) return false;
    b.dataAt = r.pos;
    if (!r.skip(bytes) || !r.end(bytes)) return false;
  }
  end = r.pos;
  return true;
}

std::vector<Layout> allLayouts(bool withIblank) {
  std::vector<Layout> out;
  for (int be = 0; be < 2; ++be)
    for (int fortran = 0; fortran < 2; ++fortran)
      for (int multi = 0; multi < 2; ++multi)
        for (int dbl = 0; dbl < 2; ++dbl)
          for (int ib = 0; ib < (withIblank ? 2 : 1); ++ib)
            out.push_back({be == 1, multi == 1, fortran == 1, dbl == 1, ib == 1});
  return out;
}

std::string dimsText(const std::vector<Block>& blocks) {
  std::string t;
  for (size_t b = 0; b < blocks.size() && b < 4; ++b)
    t += (b ? ", " : "") + std::to_string(blocks[b].n[0]) + "x" + std::to_string(blocks[b].n[1]) + "x" +
         std::to_string(blocks[b].n[2]);
  if (blocks.size() > 4) t += ", ...";
  return t;
}

}  // namespace

Result readPlot3d(std::string_view grid, const std::string& gridLabel, std::string_view q, const std::string& qLabel,
                  TetMesh& out, ReadReport& report) {
  out = TetMesh{};
  if (grid.empty()) return fail(Status::Truncated, gridLabel + ": empty file");
  if (grid.size() < 12)
    return fail(Status::Truncated, gridLabel + ": " + std::to_string(grid.size()) +
                                       " bytes, too short for a PLOT3D grid header (at least 12)");

  // Find the grid layout: an exact fit first, else a fit followed only by zero padding.
  Layout L;
  std::vector<Block> blocks;
  size_t end = 0;
  int exact = 0, padded = 0;
  Layout exactL, paddedL;
  std::vector<Block> exactB, paddedB;
  size_t paddedEnd = 0;
  for (const Layout& cand : allLayouts(true)) {
    std::vector<Block> b;
    size_t e;
    if (!walkGrid(grid, cand, b, e)) continue;
    if (e == grid.size()) {
      if (!exact++) exactL = cand, exactB = std::move(b);
    } else if (zeroTail(grid, e)) {
      if (!padded++) paddedL = cand, paddedB = std::move(b), paddedEnd = e;
    }
  }
  if (exact) {
    L = exactL;
    blocks = std::move(exactB);
    end = grid.size();
  } else if (padded) {
    L = paddedL;
    blocks = std::move(paddedB);
    end = paddedEnd;
    report.notes.push_back("ignored " + std::to_string(grid.size() - end) + " zero bytes at the end of " + gridLabel);
  } else {
    for (const Layout& cand : allLayouts(false)) {
      std::vector<Block> b;
      size_t e;
      double h[4];
      if (walkQ(grid, cand, b, e, h) && (e == grid.size() || zeroTail(grid, e)))
        return fail(Status::Corrupt, gridLabel +
                                         ": not a 3D PLOT3D grid, but it reads as a PLOT3D Q (solution) file: "
                                         "give the grid file and name this one with --q");
    }
    return fail(Status::Corrupt,
                gridLabel +
                    ": not a 3D PLOT3D grid: no layout (C binary or Fortran records, either byte order, "
                    "float or double, single- or multi-grid, with or without IBLANK) has a header whose sizes "
                    "add up to the file's " +
                    std::to_string(grid.size()) + " bytes (truncated or another format?)");
  }
  if (exact > 1 || (!exact && padded > 1))
    report.notes.push_back("the grid file's size fits " + std::to_string(exact ? exact : padded) +
                           " PLOT3D layouts; using the first: " + L.str(true));

  uint64_t total = 0;
  for (const Block& b : blocks) total += b.points();
  TetMesh mesh;
  mesh.positions.resize(3 * total);  // bounded: walkGrid checked the data is in the file
  std::vector<uint8_t> keep;
  if (L.iblank) keep.resize(total);
  Reader rd{grid, L};
  const size_t real = L.doubles ? 8 : 4;
  uint64_t base = 0, blanked = 0;
  for (const Block& b : blocks) {
    const uint64_t n = b.points();
    for (uint64_t v = 0; v < n; ++v)
      for (int c = 0; c < 3; ++c)
        mesh.positions[3 * (base + v) + uint64_t(c)] = float(rd.real(b.dataAt + size_t((uint64_t(c) * n + v) * real)));
    if (L.iblank)
      for (uint64_t v = 0; v < n; ++v) {
        keep[base + v] = rd.int32At(b.dataAt + size_t(3 * n * real + 4 * v)) != 0;
        blanked += !keep[base + v];
      }
    base += n;
  }

  CellSoup soup;
  base = 0;
  uint64_t kept = 0, cells = 0;
  for (const Block& b : blocks) {
    kept += appendStructuredCells(b.n[0], b.n[1], b.n[2], base, soup.inputCells, soup, L.iblank ? &keep : nullptr);
    const uint64_t c = (b.n[0] > 1 && b.n[1] > 1 && b.n[2] > 1) ? (b.n[0] - 1) * (b.n[1] - 1) * (b.n[2] - 1) : 0;
    soup.inputCells += c;
    cells += c;
    base += b.n[0] * b.n[1] * b.n[2];
  }
  (void)kept;
  report.format = "PLOT3D grid (" + L.str(true) + ", " + std::to_string(blocks.size()) +
                  (blocks.size() == 1 ? " block " : " blocks ") + dimsText(blocks) + ")";
  if (blocks.size() > 1)
    report.notes.push_back("read " + std::to_string(blocks.size()) +
                           " grid blocks one after the other (points shared by touching blocks are merged below)");
  if (L.iblank && blanked)
    report.notes.push_back("IBLANK: " + std::to_string(blanked) + " points are blanked (0); " +
                           std::to_string(cells - soup.shapes.size()) + " cells touching them are left out");
  if (cells == 0)
    return fail(Status::NoTets, gridLabel + ": the grid (" + dimsText(blocks) + ") is not 3D: no volume cells");

  // Solution
  if (q.empty()) {
    report.notes.push_back("no Q solution file: the grid has no fields (name one with --q FILE)");
  } else {
    int found = 0;
    Layout QL;
    std::vector<Block> qb;
    size_t qend = 0;
    double header[4] = {0, 0, 0, 0};
    bool qExact = false;
    for (int pass = 0; pass < 2 && !found; ++pass)
      for (const Layout& cand : allLayouts(false)) {
        std::vector<Block> b;
        size_t e;
        double h[4] = {0, 0, 0, 0};
        if (!walkQ(q, cand, b, e, h)) continue;
        bool same = b.size() == blocks.size();
        for (size_t k = 0; same && k < b.size(); ++k)
          same = b[k].n[0] == blocks[k].n[0] && b[k].n[1] == blocks[k].n[1] && b[k].n[2] == blocks[k].n[2];
        if (!same) continue;
        if (pass == 0 ? e != q.size() : !zeroTail(q, e)) continue;
        if (!found++) {
          QL = cand, qb = std::move(b), qend = e, qExact = pass == 0;
          std::copy(h, h + 4, header);
        }
      }
    if (!found)
      return fail(Status::Corrupt,
                  qLabel + ": not a PLOT3D Q file for this grid: no layout has a header with the grid's dimensions (" +
                      dimsText(blocks) + ") whose sizes add up to the file's " + std::to_string(q.size()) + " bytes");
    if (!qExact)
      report.notes.push_back("ignored " + std::to_string(q.size() - qend) + " zero bytes at the end of " + qLabel);
    Reader qr{q, QL};
    const size_t qreal = QL.doubles ? 8 : 4;
    ScalarField density{"density", std::vector<float>(total)},
        momentum{"momentum_magnitude", std::vector<float>(total)}, energy{"energy", std::vector<float>(total)},
        pressure{"pressure", std::vector<float>(total)};
    constexpr double kGamma = 1.4;
    base = 0;
    for (const Block& b : qb) {
      const uint64_t n = b.points();
      auto at = [&](int var, uint64_t v) { return qr.real(b.dataAt + size_t((uint64_t(var) * n + v) * qreal)); };
      for (uint64_t v = 0; v < n; ++v) {
        const double rho = at(0, v), mx = at(1, v), my = at(2, v), mz = at(3, v), e = at(4, v);
        const double m2 = mx * mx + my * my + mz * mz;
        density.values[base + v] = float(rho);
        momentum.values[base + v] = float(std::sqrt(m2));
        energy.values[base + v] = float(e);
        pressure.values[base + v] = float((kGamma - 1) * (e - 0.5 * m2 / rho));
      }
      base += n;
    }
    for (ScalarField* f : {&density, &momentum, &energy, &pressure}) mesh.fields.push_back(std::move(*f));
    char buf[160];
    std::snprintf(buf, sizeof buf, " (free-stream Mach %g, alpha %g, Re %g, time %g)", header[0], header[1], header[2],
                  header[3]);
    report.format += " + Q solution (" + QL.str(false) + ")";
    report.notes.push_back(std::string("PLOT3D Q") + buf +
                           ": fields density, momentum_magnitude (|rho u|), energy, and pressure derived as "
                           "(gamma - 1)(energy - |momentum|^2 / (2 density)) with gamma = 1.4");
  }

  if (Result r = finishMesh(gridLabel, mesh, soup, {}, report); !r) return r;
  out = std::move(mesh);
  return Result::success();
}

}  // namespace tetstream
