// PLY reference: http://paulbourke.net/dataformats/ply/. Vertex records are interleaved in one
// buffer and faces in another, so the whole file is three fwrites.
#include "io/ply_writer.h"

#include <bit>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <vector>

#include "io/file_writer.h"

namespace tetstream {

static_assert(std::endian::native == std::endian::little, "ply_writer copies host floats as binary_little_endian");

Result writePly(const std::string& path, std::span<const float> positions, std::span<const float> normals,
                std::span<const uint32_t> triangles) {
  if (positions.size() % 3 != 0 || triangles.size() % 3 != 0)
    return fail(Status::BadArgument, path + ": positions or triangles length is not a multiple of 3");
  if (!normals.empty() && normals.size() != positions.size())
    return fail(Status::BadArgument, path + ": " + std::to_string(normals.size() / 3) + " normals for " +
                                         std::to_string(positions.size() / 3) + " vertices");
  const size_t nv = positions.size() / 3, nf = triangles.size() / 3;
  for (size_t i = 0; i < triangles.size(); ++i)
    if (triangles[i] >= nv)
      return fail(Status::BadArgument, path + ": triangle " + std::to_string(i / 3) + " references vertex " +
                                           std::to_string(triangles[i]) + " of " + std::to_string(nv));
  const bool withNormals = !normals.empty();

  std::string header = "ply\nformat binary_little_endian 1.0\ncomment written by tetstream\nelement vertex " +
                       std::to_string(nv) + "\nproperty float x\nproperty float y\nproperty float z\n";
  if (withNormals) header += "property float nx\nproperty float ny\nproperty float nz\n";
  header += "element face " + std::to_string(nf) + "\nproperty list uchar uint vertex_indices\nend_header\n";

  const size_t stride = withNormals ? 6 : 3;
  std::vector<float> verts(nv * stride);
  for (size_t v = 0; v < nv; ++v) {
    std::memcpy(&verts[v * stride], &positions[3 * v], 12);
    if (withNormals) std::memcpy(&verts[v * stride + 3], &normals[3 * v], 12);
  }
  std::vector<uint8_t> faces(nf * 13);  // 1 count byte + 3 uint32 ids, unaligned
  for (size_t t = 0; t < nf; ++t) {
    faces[13 * t] = 3;
    std::memcpy(&faces[13 * t + 1], &triangles[3 * t], 12);
  }

  FileWriter out(path);
  out.write(header.data(), header.size());
  out.write(verts.data(), verts.size() * sizeof(float));
  out.write(faces.data(), faces.size());
  return out.commit();
}

}  // namespace tetstream
