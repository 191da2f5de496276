#include "io/cgns_mixed.h"

#include <cgns_io.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <limits>

#include "io/row_pick.h"

namespace tetstream::cgns {

namespace {

std::string cgioError() {
  char message[CGIO_MAX_ERROR_LENGTH + 1] = {};
  cgio_error_message(message);
  return *message ? message : "no details from the library";
}

// A 1-D integer array of the file, read a range at a time.
struct IntArray {
  int cgio = -1;
  double id = 0;
  bool wide = false;  // I8, else I4
  cgsize_t size = 0;

  // Opens node `path`; false (no message) when the file has no such node.
  Result open(int fn, const std::string& path, const std::string& where, bool& found) {
    found = false;
    double root = 0;
    if (cg_get_cgio(fn, &cgio) != CG_OK || cg_root_id(fn, &root) != CG_OK)
      return fail(Status::Corrupt, where + ": " + cg_get_error());
    if (cgio_get_node_id(cgio, root, path.c_str(), &id) != CGIO_ERR_NONE) return Result::success();
    found = true;
    char type[CGIO_MAX_DATATYPE_LENGTH + 1] = {};
    int ndims = 0;
    cgsize_t dims[CGIO_MAX_DIMENSIONS] = {};
    if (cgio_get_data_type(cgio, id, type) != CGIO_ERR_NONE ||
        cgio_get_dimensions(cgio, id, &ndims, dims) != CGIO_ERR_NONE)
      return fail(Status::Corrupt, where + ": " + cgioError());
    if ((std::strcmp(type, "I4") && std::strcmp(type, "I8")) || ndims != 1 || dims[0] < 0)
      return fail(Status::Corrupt, where + ": " + path + " is " + type + " of " + std::to_string(ndims) +
                                       " dimensions (expected integers in one)");
    wide = !std::strcmp(type, "I8");
    size = dims[0];
    return Result::success();
  }

  // Entries [from, from + count) (0-based).
  Result read(cgsize_t from, cgsize_t count, const std::string& where, std::vector<cgsize_t>& out) const {
    out.resize(size_t(count));
    if (count == 0) return Result::success();
    if (from < 0 || count > size || from > size - count)
      return fail(Status::Corrupt, where + ": entries " + std::to_string(from) + " to " + std::to_string(from + count) +
                                       " of an array of " + std::to_string(size));
    const cgsize_t first = from + 1, last = from + count, one = 1, dims = count;
    auto get = [&](void* data) {
      if (cgio_read_data(cgio, id, &first, &last, &one, 1, &dims, &one, &dims, &one, data) == CGIO_ERR_NONE)
        return Result::success();
      return fail(Status::Corrupt, where + ": " + cgioError());
    };
    if (wide == (sizeof(cgsize_t) == 8)) return get(out.data());
    std::vector<int64_t> w(wide ? size_t(count) : 0);
    std::vector<int32_t> n(wide ? 0 : size_t(count));
    if (Result r = get(wide ? static_cast<void*>(w.data()) : static_cast<void*>(n.data())); !r) return r;
    for (size_t k = 0; k < out.size(); ++k) {
      const int64_t v = wide ? w[k] : n[k];
      if (v < std::numeric_limits<cgsize_t>::min() || v > std::numeric_limits<cgsize_t>::max())
        return fail(Status::TooLarge, where + ": entry " + std::to_string(from + cgsize_t(k)) + " is " +
                                          std::to_string(v) + ", beyond the CGNS library's sizes");
      out[k] = cgsize_t(v);
    }
    return Result::success();
  }
};

Result badElement(const std::string& where, cgsize_t element, cgsize_t code) {
  return fail(Status::Corrupt, where + ": element " + std::to_string(element) + " has element type code " +
                                   std::to_string(code) + ", not one a MIXED section may hold");
}

// Whether the elements whose codes and nodes `conn` holds agree with `offsets` (theirs, and the
// next one's: conn's first entry is at offsets[0]).
bool agrees(std::span<const cgsize_t> conn, std::span<const cgsize_t> offsets) {
  size_t at = 0;
  for (size_t k = 0; k + 1 < offsets.size(); ++k) {
    if (at >= conn.size() || cgsize_t(at) != offsets[k] - offsets[0]) return false;
    const int n = mixedEntries(conn[at]);
    if (n == 0) return false;
    at += size_t(n);
  }
  return cgsize_t(at) == offsets.back() - offsets[0] && at == conn.size();
}

}  // namespace

int mixedEntries(cgsize_t code) {
  if (code < 0 || code >= NofValidElementTypes) return 0;
  const auto type = CGNS_ENUMT(ElementType_t)(code);
  if (type == CGNS_ENUMV(MIXED) || type == CGNS_ENUMV(NGON_n) || type == CGNS_ENUMV(NFACE_n)) return 0;
  int npe = 0;
  if (cg_npe(type, &npe) != CG_OK || npe < 1) return 0;
  return 1 + npe;
}

Result readMixedWindow(int fn, const std::string& path, const std::string& where, cgsize_t start, cgsize_t end,
                       cgsize_t dataSize, cgsize_t first, cgsize_t last, std::vector<cgsize_t>& out, bool& walked) {
  out.clear();
  walked = false;
  IntArray conn, offsets;
  bool found = false;
  if (Result r = conn.open(fn, path + "/ElementConnectivity", where, found); !r) return r;
  if (!found) return fail(Status::Corrupt, where + ": no ElementConnectivity");
  if (conn.size != dataSize)
    return fail(Status::Corrupt, where + ": ElementConnectivity holds " + std::to_string(conn.size) +
                                     " entries, the section says " + std::to_string(dataSize));
  if (first > last) return Result::success();
  if (Result r = offsets.open(fn, path + "/ElementStartOffset", where, found); !r) return r;
  if (found && offsets.size == end - start + 2) {
    std::vector<cgsize_t> mine;
    if (Result r = offsets.read(first - start, last - first + 2, where + " ElementStartOffset", mine); !r) return r;
    const bool ordered = std::is_sorted(mine.begin(), mine.end()) && mine.front() >= 0 && mine.back() <= dataSize &&
                         (first != start || mine.front() == 0);
    if (ordered) {
      if (Result r = conn.read(mine.front(), mine.back() - mine.front(), where + " ElementConnectivity", out); !r)
        return r;
      if (agrees(out, mine)) return Result::success();
    }
  }
  // The codes from the first element: a window of entries at a time, each from the first
  // element the last one did not hold whole.
  walked = true;
  out.clear();
  std::vector<cgsize_t> window;
  cgsize_t at = 0, element = start;
  while (element <= last) {
    if (at >= dataSize)
      return fail(Status::Corrupt, where + ": the connectivity (" + std::to_string(dataSize) +
                                       " entries) ends at element " + std::to_string(element) + " of " +
                                       std::to_string(start) + ".." + std::to_string(end));
    const cgsize_t n = std::min<cgsize_t>(cgsize_t(io::kPickWindow), dataSize - at);
    if (Result r = conn.read(at, n, where + " ElementConnectivity", window); !r) return r;
    size_t k = 0;
    while (element <= last && k < window.size()) {
      const int entries = mixedEntries(window[k]);
      if (entries == 0) return badElement(where, element, window[k]);
      if (size_t(entries) > window.size() - k) {
        if (at + n == dataSize)
          return fail(Status::Corrupt, where + ": element " + std::to_string(element) + " needs " +
                                           std::to_string(entries - 1) + " nodes; the connectivity ends after " +
                                           std::to_string(window.size() - k - 1));
        break;
      }
      if (element >= first)
        out.insert(out.end(), window.begin() + std::ptrdiff_t(k), window.begin() + std::ptrdiff_t(k) + entries);
      k += size_t(entries);
      ++element;
    }
    at += cgsize_t(k);
  }
  return Result::success();
}

}  // namespace tetstream::cgns
