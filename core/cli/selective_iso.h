// `tetstream iso PACKDIR --value V --selective`: the isosurface from only the nodes of the patch
// hierarchy that the isovalue needs (FORMAT.md §1.1), checked against the full mesh's, with what
// it needed: how users size their hosting, and a benchmark of the hierarchy.
#pragma once
#include <string>

namespace tetstream::cli {

struct SelectiveIsoOptions {
  std::string dir, field, out;
  double value = 0;
  bool json = false;
  bool check = true;  // compare with the full mesh's surface (loads the whole dataset)
};

int runSelectiveIso(const SelectiveIsoOptions& o);

}  // namespace tetstream::cli
