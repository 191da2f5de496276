// Medit .mesh reader (ASCII) with an optional .sol. Reference: P. Frey, "MEDIT: an interactive
// mesh visualization software" (INRIA RT-0253), and libMeshb's keyword table.
//
// A file is keywords, each followed by a count and that many entries of a fixed number of
// numbers: "Vertices n" then n lines "x y z ref", "Tetrahedra n" then "a b c d ref" (1-based
// vertex numbers), and so on, until "End". Keywords not listed here are skipped up to the next
// word (their entries are numbers). Read: Vertices, Tetrahedra, TetrahedraP2, Prisms, Pyramids,
// Hexahedra (Hexaedra), HexahedraQ2; counted and skipped: Edges, Triangles, Quadrilaterals and
// their P2/Q2 forms. References (the last number of an entry) are ignored.
// The .sol file: "SolAtVertices n", then "k t1 .. tk" (type 1 scalar, 2 vector, 3 symmetric
// tensor, 4 full tensor), then n lines of all solutions' values. Fields sol0, sol1, ... (vectors
// and tensors as their magnitude).
#include <cctype>
#include <cmath>

#include "io/readers.h"

namespace tetstream {
namespace {

using namespace vtkio;

struct Keyword {
  const char* name;
  int numbers;  // per entry, reference included; -1: the dimension (+ nothing); -2: dimension + 1
  int cell;     // -1: not a volume cell; else a CellShape
  int nodes;    // nodes per cell (volume cells)
};
// clang-format off
constexpr Keyword kKeywords[] = {
  {"Vertices", -2, -1, 0},
  {"Edges", 3, -1, 0}, {"Triangles", 4, -1, 0}, {"Quadrilaterals", 5, -1, 0},
  {"EdgesP2", 4, -1, 0}, {"TrianglesP2", 7, -1, 0}, {"QuadrilateralsQ2", 10, -1, 0},
  {"Tetrahedra", 5, int(CellShape::Tet), 4}, {"TetrahedraP2", 11, int(CellShape::Tet), 10},
  {"Prisms", 7, int(CellShape::Wedge), 6}, {"Pyramids", 6, int(CellShape::Pyramid), 5},
  {"Hexahedra", 9, int(CellShape::Hex), 8}, {"Hexaedra", 9, int(CellShape::Hex), 8},
  {"HexahedraQ2", 28, int(CellShape::Hex), 27},
  {"Corners", 1, -1, 0}, {"RequiredVertices", 1, -1, 0}, {"Ridges", 1, -1, 0}, {"RequiredEdges", 1, -1, 0},
  {"RequiredTriangles", 1, -1, 0}, {"RequiredQuadrilaterals", 1, -1, 0}, {"Normals", -1, -1, 0},
  {"NormalAtVertices", 2, -1, 0}, {"NormalAtTriangleVertices", 3, -1, 0}, {"Tangents", -1, -1, 0},
  {"TangentAtVertices", 2, -1, 0}, {"TangentAtEdgeVertices", 3, -1, 0},
};
// clang-format on

const Keyword* keyword(std::string_view w) {
  for (const Keyword& k : kKeywords)
    if (iequals(w, k.name)) return &k;
  return nullptr;
}

bool startsWord(std::string_view tok) {
  return !tok.empty() && std::isalpha(static_cast<unsigned char>(tok[0])) && !iequals(tok, "nan") &&
         !iequals(tok, "inf");
}

Result count(TextReader& t, const std::string& kw, uint64_t perEntry, uint64_t& n) {
  int64_t v;
  if (Result r = t.integer(kw + " count", v); !r) return r;
  if (v < 0) return fail(Status::Corrupt, t.at(t.pos) + ": " + kw + " count " + std::to_string(v) + " is negative");
  // Every number takes at least two bytes: a bound on the count before anything is sized by it.
  if (uint64_t(v) > (t.s.size() - t.pos) / (2 * std::max<uint64_t>(perEntry, 1)) + 1)
    return fail(Status::Truncated, t.at(t.pos) + ": " + kw + " declares " + std::to_string(v) +
                                       " entries, more than the rest of the file can hold");
  n = uint64_t(v);
  return Result::success();
}

// Skips numbers up to the next word (an unknown keyword's data).
void skipNumbers(TextReader& t) {
  while (true) {
    std::string_view tok = t.peekToken();
    if (tok.empty() || startsWord(tok)) return;
    t.pos += tok.size();
  }
}

Result readSol(std::string_view sol, const std::string& label, uint32_t vertices, TetMesh& mesh, ReadReport& report) {
  TextReader t{label, sol};
  int64_t dim = 3;
  bool any = false;
  while (true) {
    std::string_view w = t.peekToken();
    if (w.empty() || iequals(w, "End")) break;
    const size_t p = t.pos;
    t.pos += w.size();
    if (!startsWord(w)) return fail(Status::Corrupt, t.at(p) + ": expected a keyword, found '" + printable(w) + "'");
    if (iequals(w, "MeshVersionFormatted")) {
      int64_t v;
      if (Result r = t.integer("the version", v); !r) return r;
      continue;
    }
    if (iequals(w, "Dimension")) {
      if (Result r = t.integer("the dimension", dim); !r) return r;
      if (dim != 3)
        return fail(Status::Unsupported, t.at(p) + ": dimension " + std::to_string(dim) + "; tetstream reads 3D");
      continue;
    }
    if (!iequals(w, "SolAtVertices")) {
      report.notes.push_back("skipped " + std::string(printable(w)) + " in " + label + " (only SolAtVertices is read)");
      skipNumbers(t);
      continue;
    }
    uint64_t n;
    if (Result r = count(t, "SolAtVertices", 1, n); !r) return r;
    if (n != vertices)
      return fail(Status::Corrupt, t.at(p) + ": SolAtVertices has " + std::to_string(n) + " entries, the mesh has " +
                                       std::to_string(vertices) + " vertices");
    int64_t k;
    if (Result r = t.integer("the number of solutions", k); !r) return r;
    if (k < 1 || k > 64)
      return fail(Status::Corrupt, t.at(p) + ": " + std::to_string(k) + " solutions per vertex (expected 1..64)");
    std::vector<int> comps;
    uint64_t total = 0;
    for (int64_t i = 0; i < k; ++i) {
      int64_t type;
      if (Result r = t.integer("solution type", type); !r) return r;
      int c = type == 1   ? 1
              : type == 2 ? int(dim)
              : type == 3 ? int(dim * (dim + 1) / 2)
              : type == 4 ? int(dim * dim)
                          : 0;
      if (!c)
        return fail(Status::Corrupt, t.at(t.pos) + ": solution type " + std::to_string(type) + " (expected 1..4)");
      comps.push_back(c);
      total += uint64_t(c);
    }
    if (n * total > (sol.size() - t.pos) / 2 + 1)
      return fail(Status::Truncated, t.at(p) + ": SolAtVertices needs " + std::to_string(n * total) +
                                         " values, more than the rest of the file can hold");
    std::vector<ScalarField> fs;
    for (int64_t i = 0; i < k; ++i) {
      std::string name = fieldNameFor("sol" + std::to_string(i), uint32_t(comps[size_t(i)]), report);
      fs.push_back({name, std::vector<float>(n)});
    }
    std::vector<double> tuple(64);
    for (uint64_t v = 0; v < n; ++v)
      for (int64_t i = 0; i < k; ++i) {
        double sq = 0, x = 0;
        for (int c = 0; c < comps[size_t(i)]; ++c) {
          if (Result r = t.number("vertex " + std::to_string(v + 1) + " solution value", x); !r) return r;
          sq += x * x;
        }
        fs[size_t(i)].values[v] = comps[size_t(i)] == 1 ? float(x) : float(std::sqrt(sq));
      }
    for (ScalarField& f : fs) addField(mesh, std::move(f), report);
    any = true;
  }
  if (!any)
    report.notes.push_back(label + " has no SolAtVertices: no fields from it");
  else
    report.notes.push_back("read the fields of " + label + " (SolAtVertices)");
  return Result::success();
}

}  // namespace

Result readMedit(std::string_view bytes, const std::string& label, std::string_view sol, const std::string& solLabel,
                 TetMesh& out, ReadReport& report) {
  out = TetMesh{};
  TextReader t{label, bytes};
  if (bytes.empty()) return fail(Status::Truncated, label + ": empty file");
  std::string_view first = t.peekToken();
  if (!iequals(first, "MeshVersionFormatted")) {
    if (first.empty() || std::string_view("MeshVersionFormatted").starts_with(first))
      return fail(Status::Truncated, label + ": file ends before 'MeshVersionFormatted'");
    return fail(Status::BadMagic, label + ": not a Medit mesh: starts with '" + printable(first) +
                                      "', expected 'MeshVersionFormatted' (binary .meshb is not read)");
  }
  TetMesh mesh;
  CellSoup soup;
  int64_t dim = 3;
  bool haveVertices = false, ended = false;
  uint64_t nv = 0;
  std::vector<std::pair<std::string, uint64_t>> skipped;
  while (true) {
    std::string_view w = t.peekToken();
    if (w.empty()) break;
    const size_t p = t.pos;
    t.pos += w.size();
    if (!startsWord(w)) return fail(Status::Corrupt, t.at(p) + ": expected a keyword, found '" + printable(w) + "'");
    if (iequals(w, "End")) {
      ended = true;
      break;
    }
    if (iequals(w, "MeshVersionFormatted")) {
      int64_t v;
      if (Result r = t.integer("the version", v); !r) return r;
      continue;
    }
    if (iequals(w, "Dimension")) {
      if (Result r = t.integer("the dimension", dim); !r) return r;
      if (dim != 3)
        return fail(Status::Unsupported,
                    t.at(p) + ": dimension " + std::to_string(dim) + "; tetstream reads 3D meshes");
      continue;
    }
    const Keyword* k = keyword(w);
    if (!k) {
      skipped.push_back({std::string(printable(w)), 0});
      skipNumbers(t);
      continue;
    }
    const std::string kw = k->name;
    const uint64_t per = k->numbers == -1 ? uint64_t(dim) : k->numbers == -2 ? uint64_t(dim + 1) : uint64_t(k->numbers);
    uint64_t n;
    if (Result r = count(t, kw, per, n); !r) return r;
    if (kw == "Vertices") {
      if (haveVertices) return fail(Status::Corrupt, t.at(p) + ": a second Vertices section");
      if (n > kMaxVertices)
        return fail(Status::TooLarge,
                    t.at(p) + ": " + std::to_string(n) + " vertices; tetstream indexes vertices with 32 bits");
      haveVertices = true;
      nv = n;
      mesh.positions.resize(3 * n);
      for (uint64_t v = 0; v < n; ++v) {
        double x;
        for (int c = 0; c < 3; ++c) {
          if (Result r = t.number("vertex " + std::to_string(v + 1) + " coordinate", x); !r) return r;
          mesh.positions[3 * v + uint64_t(c)] = float(x);
        }
        if (Result r = t.number("vertex " + std::to_string(v + 1) + " reference", x); !r) return r;
      }
      continue;
    }
    if (k->cell < 0) {
      for (uint64_t i = 0; i < n * per; ++i) {
        double x;
        if (Result r = t.number(kw + " value", x); !r) return r;
      }
      const bool isCell = kw.starts_with("Edges") || kw.starts_with("Triangles") || kw.starts_with("Quadrilaterals");
      if (isCell && n) {
        soup.skipped[{0, "Medit " + kw}] += n;
        soup.inputCells += n;
      }
      continue;
    }
    if (!haveVertices) return fail(Status::Corrupt, t.at(p) + ": " + kw + " before Vertices");
    const CellShape shape = CellShape(k->cell);
    const int corners = kShapeCorners[k->cell];
    for (uint64_t c = 0; c < n; ++c) {
      uint32_t ids[8];
      for (int q = 0; q < k->nodes; ++q) {
        int64_t v;
        if (Result r = t.integer(kw + " " + std::to_string(c + 1) + " vertex", v); !r) return r;
        if (v < 1 || uint64_t(v) > nv)
          return fail(Status::OutOfRange, t.at(t.pos) + ": " + kw + " " + std::to_string(c + 1) + " uses vertex " +
                                              std::to_string(v) + ", but there are " + std::to_string(nv) +
                                              " vertices (numbered from 1)");
        if (q < corners) ids[q] = uint32_t(v - 1);
        soup.markReferenced(uint64_t(v - 1));
      }
      double ref;
      if (Result r = t.number(kw + " " + std::to_string(c + 1) + " reference", ref); !r) return r;
      soup.add(shape, ids, soup.inputCells++);
    }
    if (k->nodes > corners && n) soup.reduced["Medit " + kw] = {corners, n};
  }
  if (!haveVertices) return fail(Status::Truncated, label + ": file ends before Vertices");
  if (!ended) report.notes.push_back(label + " has no End keyword (read to the end of the file)");
  for (const auto& [w, n] : skipped) report.notes.push_back("skipped unknown keyword '" + w + "' and its numbers");
  report.format = "Medit .mesh (ASCII)";
  if (!sol.empty()) {
    if (Result r = readSol(sol, solLabel, uint32_t(nv), mesh, report); !r) return r;
    report.format += " + .sol";
  }
  if (Result r = finishMesh(label, mesh, soup, {}, report); !r) return r;
  out = std::move(mesh);
  return Result::success();
}

}  // namespace tetstream
