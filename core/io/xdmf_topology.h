// XDMF cell types (XdmfTopologyType): their names, the codes Mixed topologies give them, and
// what the readers make of them.
#pragma once
#include <cstdint>
#include <string_view>
#include <utility>

#include "io/readers.h"

namespace tetstream::xdmf {

struct TopologyKind {
  const char* name;  // as XDMF spells it
  int code;          // in Mixed topologies
  int64_t vtk;       // the VTK cell type, 0 for none
  int nodes;         // per cell; 0: given per grid (NodesPerElement) or per cell (Mixed)
  bool read;         // a volume cell tetstream reads
};

inline constexpr TopologyKind kKinds[] = {
    {"Polyvertex", 0x1, 2, 0, false},
    {"Polyline", 0x2, 4, 0, false},
    {"Polygon", 0x3, 7, 0, false},
    {"Triangle", 0x4, 5, 3, false},
    {"Quadrilateral", 0x5, 9, 4, false},
    {"Tetrahedron", 0x6, 10, 4, true},
    {"Pyramid", 0x7, 14, 5, true},
    {"Wedge", 0x8, 13, 6, true},
    {"Hexahedron", 0x9, 12, 8, true},
    {"Polyhedron", 0x10, 42, 0, false},
    {"Edge_3", 0x22, 21, 3, false},
    {"Quadrilateral_9", 0x23, 28, 9, false},
    {"Triangle_6", 0x24, 22, 6, false},
    {"Quadrilateral_8", 0x25, 23, 8, false},
    {"Tetrahedron_10", 0x26, 24, 10, true},
    {"Pyramid_13", 0x27, 27, 13, true},
    {"Wedge_15", 0x28, 26, 15, true},
    {"Wedge_18", 0x29, 32, 18, true},
    {"Hexahedron_20", 0x30, 25, 20, true},
    {"Hexahedron_24", 0x31, 33, 24, true},
    {"Hexahedron_27", 0x32, 29, 27, true},
    // Higher orders: node orders tetstream does not know, counted and skipped.
    {"Hexahedron_64", 0x33, 0, 64, false},
    {"Hexahedron_125", 0x34, 0, 125, false},
    {"Hexahedron_216", 0x35, 0, 216, false},
    {"Hexahedron_343", 0x36, 0, 343, false},
    {"Hexahedron_512", 0x37, 0, 512, false},
    {"Hexahedron_729", 0x38, 0, 729, false},
    {"Hexahedron_1000", 0x39, 0, 1000, false},
    {"Hexahedron_1331", 0x40, 0, 1331, false},
    {"Hexahedron_Spectral_64", 0x41, 0, 64, false},
    {"Hexahedron_Spectral_125", 0x42, 0, 125, false},
    {"Hexahedron_Spectral_216", 0x43, 0, 216, false},
    {"Hexahedron_Spectral_343", 0x44, 0, 343, false},
    {"Hexahedron_Spectral_512", 0x45, 0, 512, false},
    {"Hexahedron_Spectral_729", 0x46, 0, 729, false},
    {"Hexahedron_Spectral_1000", 0x47, 0, 1000, false},
    {"Hexahedron_Spectral_1331", 0x48, 0, 1331, false},
};

// Short spellings some writers use (meshio reads them too).
inline constexpr std::pair<const char*, const char*> kAliases[] = {
    {"Tet_10", "Tetrahedron_10"}, {"Hex_20", "Hexahedron_20"},   {"Hex_24", "Hexahedron_24"},
    {"Hex_27", "Hexahedron_27"},  {"Quad_8", "Quadrilateral_8"}, {"Quad_9", "Quadrilateral_9"},
    {"Tri_6", "Triangle_6"},      {"Quad", "Quadrilateral"},     {"Tri", "Triangle"},
    {"Tet", "Tetrahedron"},       {"Hex", "Hexahedron"},
};

inline const TopologyKind* kindByName(std::string_view name) {
  for (const auto& [alias, full] : kAliases)
    if (vtkio::iequals(name, alias)) name = full;
  for (const TopologyKind& k : kKinds)
    if (vtkio::iequals(name, k.name)) return &k;
  return nullptr;
}

inline const TopologyKind* kindByCode(int64_t code) {
  for (const TopologyKind& k : kKinds)
    if (k.code == code) return &k;
  return nullptr;
}

}  // namespace tetstream::xdmf
