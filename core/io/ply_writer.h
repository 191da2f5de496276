// Binary PLY output for extracted isosurfaces (pack side: the CLI's `iso` command and tests).
#pragma once
#include <cstdint>
#include <span>
#include <string>

#include "status.h"

namespace tetstream {

// Writes binary little-endian PLY: vertices as float x y z [nx ny nz], faces as
// "list uchar uint vertex_indices" with 3 ids each.
//   positions: 3 floats per vertex; normals: 3 floats per vertex, or empty for no normals;
//   triangles: 3 vertex ids per triangle, each < vertex count.
// BadArgument when the arrays disagree in size or an id is out of range (the message names the
// triangle); IoError when the file cannot be written. Writes PATH.tmp, then renames.
Result writePly(const std::string& path, std::span<const float> positions, std::span<const float> normals,
                std::span<const uint32_t> triangles);

}  // namespace tetstream
