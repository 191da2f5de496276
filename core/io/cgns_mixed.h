// MIXED element sections of CGNS: each element is its ElementType_t code followed by its nodes.
// ElementStartOffset (CGNS 3.4 and later) says where each element begins, but files written by
// CGNS 3.4.0's own tools carry wrong offsets, so the codes decide: a process that reads a share
// of the elements reads the offsets of its elements only, then the connectivity they name, and
// keeps both when the codes agree with every offset; else it walks the codes from the section's
// first element to its own, a window at a time. Reads go through the library's node I/O (cgio),
// which reads a range of an array for the cost of the range, in ADF and HDF5 files alike.
#pragma once
#include <cgnslib.h>

#include <span>
#include <string>
#include <vector>

#include "status.h"

namespace tetstream::cgns {

// The entries (1 + its nodes) of an element of the type `code` in a MIXED section; 0 for a code
// that is no fixed-size element type.
int mixedEntries(cgsize_t code);

// Of a MIXED section (`path`: "/base/zone/section" in the file `fn`) whose elements are numbered
// start..end with `dataSize` connectivity entries, the elements numbered first..last as codes and
// nodes in `out`. `walked` says the offsets did not serve (missing, or disagreeing with the codes).
// `where` names the section in messages.
Result readMixedWindow(int fn, const std::string& path, const std::string& where, cgsize_t start, cgsize_t end,
                       cgsize_t dataSize, cgsize_t first, cgsize_t last, std::vector<cgsize_t>& out, bool& walked);

}  // namespace tetstream::cgns
