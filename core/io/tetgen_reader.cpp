// TetGen .node + .ele reader. Reference: the TetGen user's manual, "File formats".
//
//   .node: <#points> <dimension = 3> <#attributes> <#boundary markers: 0 or 1>
//          <point#> <x> <y> <z> [attributes] [boundary marker]        one line per point
//   .ele:  <#tetrahedra> <nodes per tet: 4 or 10> <#region attributes: 0 or 1>
//          <tet#> <n1> <n2> <n3> <n4> [n5 .. n10] [region attribute]  one line per tet
// '#' starts a comment anywhere. Numbering starts at 0 or 1: the first point's number decides,
// and the .ele file uses the same numbers. Point attributes become fields attr0, attr1, ...;
// boundary markers and region attributes are not read (a note says so). 10-node tets list their
// corners first.
#include "io/readers.h"

namespace tetstream {

using namespace vtkio;

Result readTetgen(std::string_view node, const std::string& nodeLabel, std::string_view ele,
                  const std::string& eleLabel, TetMesh& out, ReadReport& report) {
  out = TetMesh{};
  TextReader n{nodeLabel, node};
  int64_t count, dim, nattr, nmark;
  if (node.empty()) return fail(Status::Truncated, nodeLabel + ": empty file");
  if (Result r = n.integer("the number of points", count); !r) return r;
  const int header = n.tokensLeftOnLine();
  if (Result r = n.integer("the dimension", dim); !r) return r;
  nattr = 0;
  nmark = 0;
  if (header >= 2)
    if (Result r = n.integer("the number of attributes", nattr); !r) return r;
  if (header >= 3) {
    if (Result r = n.integer("the number of boundary markers", nmark); !r) return r;
  }
  if (dim != 3)
    return fail(dim == 2 ? Status::Unsupported : Status::Corrupt,
                n.at(0) + ": dimension " + std::to_string(dim) + "; tetstream reads 3D TetGen meshes");
  if (count < 0 || nattr < 0 || nattr > int64_t(kMaxComponents) || nmark < 0 || nmark > 1)
    return fail(Status::Corrupt, n.at(0) + ": header '" + std::to_string(count) + " " + std::to_string(dim) + " " +
                                     std::to_string(nattr) + " " + std::to_string(nmark) +
                                     "' (expected #points 3 #attributes 0|1)");
  // Each point line has at least 4 numbers of 1 character and a separator: a bound on count.
  if (uint64_t(count) > node.size() / 8 + 1)
    return fail(Status::Truncated, n.at(0) + ": declares " + std::to_string(count) + " points, more than a file of " +
                                       std::to_string(node.size()) + " bytes can hold");
  if (uint64_t(count) > kMaxVertices)
    return fail(Status::TooLarge,
                n.at(0) + ": " + std::to_string(count) + " points; tetstream indexes vertices with 32 bits");
  TetMesh mesh;
  mesh.positions.resize(3 * size_t(count));
  std::vector<ScalarField> attrs(static_cast<size_t>(nattr));
  for (int64_t a = 0; a < nattr; ++a)
    attrs[size_t(a)] = {"attr" + std::to_string(a), std::vector<float>(size_t(count))};
  int64_t base = 0;
  for (int64_t i = 0; i < count; ++i) {
    n.skip();
    const size_t p = n.pos;
    int64_t id;
    if (Result r = n.integer("point " + std::to_string(i) + "'s number", id); !r) return r;
    if (i == 0) {
      if (id != 0 && id != 1)
        return fail(Status::Corrupt,
                    n.at(p) + ": the first point is numbered " + std::to_string(id) + ", expected 0 or 1");
      base = id;
    }
    if (id != base + i)
      return fail(Status::Corrupt, n.at(p) + ": point numbered " + std::to_string(id) + ", expected " +
                                       std::to_string(base + i) + " (points must be numbered consecutively)");
    for (int k = 0; k < 3; ++k) {
      double x;
      if (Result r = n.number("point " + std::to_string(id) + " coordinate", x); !r) return r;
      mesh.positions[3 * size_t(i) + size_t(k)] = float(x);
    }
    for (int64_t a = 0; a < nattr; ++a) {
      double x;
      if (Result r = n.number("point " + std::to_string(id) + " attribute " + std::to_string(a), x); !r) return r;
      attrs[size_t(a)].values[size_t(i)] = float(x);
    }
    if (nmark) {
      int64_t m;
      if (Result r = n.integer("point " + std::to_string(id) + " boundary marker", m); !r) return r;
    }
  }
  for (ScalarField& f : attrs) mesh.fields.push_back(std::move(f));
  if (nattr)
    report.notes.push_back("TetGen point attributes became fields attr0" +
                           (nattr > 1 ? std::string("..attr") + std::to_string(nattr - 1) : std::string()));
  if (nmark) report.notes.push_back("ignored the points' boundary markers");

  TextReader e{eleLabel, ele};
  if (ele.empty()) return fail(Status::Truncated, eleLabel + ": empty file");
  int64_t ntets, per, nregion = 0;
  if (Result r = e.integer("the number of tetrahedra", ntets); !r) return r;
  const int eh = e.tokensLeftOnLine();
  if (Result r = e.integer("the nodes per tetrahedron", per); !r) return r;
  if (eh >= 2)
    if (Result r = e.integer("the number of region attributes", nregion); !r) return r;
  if (ntets < 0 || (per != 4 && per != 10) || nregion < 0 || nregion > 64)
    return fail(Status::Corrupt, e.at(0) + ": header '" + std::to_string(ntets) + " " + std::to_string(per) + " " +
                                     std::to_string(nregion) + "' (expected #tetrahedra 4|10 #attributes)");
  if (uint64_t(ntets) > ele.size() / 10 + 1)
    return fail(Status::Truncated, e.at(0) + ": declares " + std::to_string(ntets) +
                                       " tetrahedra, more than a file of " + std::to_string(ele.size()) +
                                       " bytes can hold");
  CellSoup soup;
  soup.shapes.reserve(size_t(ntets));
  soup.corners.reserve(4 * size_t(ntets));
  soup.source.reserve(size_t(ntets));
  for (int64_t t = 0; t < ntets; ++t) {
    e.skip();
    const size_t p = e.pos;
    int64_t id;
    if (Result r = e.integer("tetrahedron " + std::to_string(t) + "'s number", id); !r) return r;
    uint32_t ids[4];
    for (int64_t k = 0; k < per; ++k) {
      int64_t v;
      if (Result r = e.integer("tetrahedron " + std::to_string(id) + " node", v); !r) return r;
      if (v < base || v - base >= count)
        return fail(Status::OutOfRange, e.at(p) + ": tetrahedron " + std::to_string(id) + " uses point " +
                                            std::to_string(v) + ", but the points are numbered " +
                                            std::to_string(base) + ".." + std::to_string(base + count - 1));
      if (k < 4) ids[k] = uint32_t(v - base);
      soup.markReferenced(uint64_t(v - base));
    }
    for (int64_t a = 0; a < nregion; ++a) {
      double x;
      if (Result r = e.number("tetrahedron " + std::to_string(id) + " region attribute", x); !r) return r;
    }
    soup.add(CellShape::Tet, ids, uint64_t(t));
  }
  soup.inputCells = uint64_t(ntets);
  if (per == 10) soup.reduced["TetGen 10-node tetrahedron"] = {4, uint64_t(ntets)};
  if (nregion) report.notes.push_back("ignored the tetrahedra's region attributes");
  report.format =
      std::string("TetGen .node/.ele (") + (base ? "1" : "0") + "-based, " + std::to_string(per) + "-node tetrahedra)";
  if (Result r = finishMesh(nodeLabel, mesh, soup, {}, report); !r) return r;
  out = std::move(mesh);
  return Result::success();
}

}  // namespace tetstream
