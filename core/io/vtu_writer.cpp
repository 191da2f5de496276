// .vtu writer: VTK XML UnstructuredGrid with raw appended data, the layout ParaView itself writes
// by default, so VTK, ParaView and meshio read it without base64 or compression overhead.
// Each appended array is [UInt64 byte count][little-endian values]; one fwrite per array keeps a
// 1.5M-tet mesh (~100 MB of ids) to a handful of large writes.
#include <algorithm>
#include <bit>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "io/file_writer.h"
#include "io/readers.h"

namespace tetstream {
namespace {

static_assert(std::endian::native == std::endian::little, "vtu_writer writes host-order arrays as LittleEndian");

// Attribute-safe text: XML escapes, and control characters (not allowed in XML 1.0) as '_'.
std::string xmlEscape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default: out += static_cast<unsigned char>(c) < 32 ? '_' : c;
    }
  }
  return out;
}

struct Block {
  const void* data;
  uint64_t bytes;
};

}  // namespace

Result writeVtu(const std::string& path, const TetMesh& mesh) {
  if (mesh.positions.size() % 3 != 0 || mesh.tets.size() % 4 != 0)
    return fail(Status::BadArgument, path + ": positions or tets array length is not a multiple of 3 / 4");
  const uint64_t nv = mesh.positions.size() / 3, nt = mesh.tets.size() / 4;
  for (const ScalarField& f : mesh.fields)
    if (f.values.size() != nv)
      return fail(Status::BadArgument, path + ": field '" + f.name + "' has " + std::to_string(f.values.size()) +
                                           " values for " + std::to_string(nv) + " vertices");
  for (uint64_t i = 0; i < mesh.tets.size(); ++i)
    if (mesh.tets[i] >= nv)
      return fail(Status::BadArgument, path + ": tet " + std::to_string(i / 4) + " references vertex " +
                                           std::to_string(mesh.tets[i]) + " of " + std::to_string(nv));

  // VTK wants 64-bit ids here (vtkIdType); the widening copy is the only extra memory we use.
  std::vector<int64_t> connectivity(mesh.tets.begin(), mesh.tets.end());
  std::vector<int64_t> offsets(nt);
  for (uint64_t t = 0; t < nt; ++t) offsets[t] = int64_t(4 * (t + 1));
  std::vector<uint8_t> types(nt, 10);  // VTK_TETRA

  std::vector<Block> blocks;
  std::string xml =
      "<?xml version=\"1.0\"?>\n"
      "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
      "  <UnstructuredGrid>\n"
      "    <Piece NumberOfPoints=\"" +
      std::to_string(nv) + "\" NumberOfCells=\"" + std::to_string(nt) + "\">\n";
  uint64_t offset = 0;
  auto array = [&](const std::string& attrs, const void* data, uint64_t bytes) {
    xml += "        <DataArray " + attrs + " format=\"appended\" offset=\"" + std::to_string(offset) + "\"/>\n";
    blocks.push_back({data, bytes});
    offset += 8 + bytes;
  };
  xml += mesh.fields.empty() ? "      <PointData>\n"
                             : "      <PointData Scalars=\"" + xmlEscape(mesh.fields[0].name) + "\">\n";
  for (const ScalarField& f : mesh.fields)
    array("type=\"Float32\" Name=\"" + xmlEscape(f.name) + "\"", f.values.data(), 4 * nv);
  xml += "      </PointData>\n      <CellData>\n      </CellData>\n      <Points>\n";
  array("type=\"Float32\" Name=\"Points\" NumberOfComponents=\"3\"", mesh.positions.data(), 12 * nv);
  xml += "      </Points>\n      <Cells>\n";
  array("type=\"Int64\" Name=\"connectivity\"", connectivity.data(), 8 * connectivity.size());
  array("type=\"Int64\" Name=\"offsets\"", offsets.data(), 8 * nt);
  array("type=\"UInt8\" Name=\"types\"", types.data(), nt);
  xml += "      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n  <AppendedData encoding=\"raw\">\n   _";

  FileWriter out(path);
  out.write(xml.data(), xml.size());
  for (const Block& b : blocks) {
    out.write(&b.bytes, 8);
    out.write(b.data, size_t(b.bytes));
  }
  const char tail[] = "\n  </AppendedData>\n</VTKFile>\n";
  out.write(tail, sizeof tail - 1);
  return out.commit();
}

Result writePvtu(const std::string& path, const TetMesh& mesh, uint32_t pieces) {
  namespace fs = std::filesystem;
  const fs::path listing(path);
  const std::string stem = listing.stem().string();
  std::error_code ec;
  fs::create_directories(listing.parent_path() / stem, ec);
  if (ec)
    return fail(Status::IoError, (listing.parent_path() / stem).string() + ": cannot create folder: " + ec.message());
  const uint64_t T = mesh.tetCount();
  pieces = uint32_t(std::clamp<uint64_t>(pieces, 1, std::max<uint64_t>(T, 1)));
  std::string text =
      "<?xml version=\"1.0\"?>\n<VTKFile type=\"PUnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\" "
      "header_type=\"UInt64\">\n  <PUnstructuredGrid GhostLevel=\"0\">\n    <PPointData>\n";
  for (const ScalarField& f : mesh.fields)
    text += "      <PDataArray type=\"Float32\" Name=\"" + xmlEscape(f.name) + "\"/>\n";
  text +=
      "    </PPointData>\n    <PPoints>\n      <PDataArray type=\"Float32\" NumberOfComponents=\"3\"/>\n    "
      "</PPoints>\n";
  std::vector<uint32_t> local(mesh.vertexCount(), ~0u);
  for (uint32_t k = 0; k < pieces; ++k) {
    // Piece k: the tets of its range and the points they use (a point on an interface is in
    // every piece that uses it, as parallel writers do).
    TetMesh piece;
    piece.name = mesh.name;
    for (const ScalarField& f : mesh.fields) piece.fields.push_back({f.name, {}});
    std::vector<uint32_t> used;
    for (uint64_t t = T * k / pieces; t < T * (k + 1) / pieces; ++t)
      for (int c = 0; c < 4; ++c) {
        const uint32_t v = mesh.tets[4 * t + size_t(c)];
        if (local[v] == ~0u) {
          local[v] = uint32_t(used.size());
          used.push_back(v);
          piece.positions.insert(piece.positions.end(), &mesh.positions[3 * size_t(v)],
                                 &mesh.positions[3 * size_t(v)] + 3);
          for (size_t f = 0; f < mesh.fields.size(); ++f) piece.fields[f].values.push_back(mesh.fields[f].values[v]);
        }
        piece.tets.push_back(local[v]);
      }
    for (uint32_t v : used) local[v] = ~0u;
    const std::string name = stem + "/" + stem + "_" + std::to_string(k) + ".vtu";
    if (Result r = writeVtu((listing.parent_path() / name).string(), piece); !r) return r;
    text += "    <Piece Source=\"" + xmlEscape(name) + "\"/>\n";
  }
  text += "  </PUnstructuredGrid>\n</VTKFile>\n";
  FileWriter out(path);
  out.write(text.data(), text.size());
  return out.commit();
}

}  // namespace tetstream
