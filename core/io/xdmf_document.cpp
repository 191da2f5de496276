#include "io/xdmf_document.h"

#include <bit>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <type_traits>

#include "io/readers.h"
#include "io/xml_path.h"

namespace tetstream::xdmf {
namespace {

using vtkio::ScalarType;

constexpr int kMaxReferenceDepth = 8;
// DataItems inside DataItems (HyperSlab, Function) nest at most this deep, a JOIN takes at most
// kMaxJoin items, and one read reads at most kMaxItemReads items in all: nested JOINs that
// point back at JOINs would otherwise multiply (kMaxJoin^depth reads from a few lines of XML).
constexpr int kMaxItemDepth = 4;
constexpr size_t kMaxJoin = 16;
constexpr size_t kMaxItemReads = size_t(1) << 20;
constexpr size_t kMaxRank = 8;
constexpr uint64_t kMaxDimension = uint64_t(1) << 40;
// Elements handed out by children() in one read: far above any real file's count (a time series
// of 10^5 steps has a few 10^5), far below what a self-including document would expand to.
constexpr size_t kElementBudget = size_t(1) << 24;

bool iequals(std::string_view a, std::string_view b) { return vtkio::iequals(a, b); }

std::string_view trim(std::string_view s) {
  const size_t b = s.find_first_not_of(" \t\r\n");
  if (b == std::string_view::npos) return {};
  return s.substr(b, s.find_last_not_of(" \t\r\n") - b + 1);
}

bool isInclude(pugi::xml_node n) {
  std::string_view name = n.name();
  return name == "include" || name.ends_with(":include");
}

std::string dimsText(const std::vector<uint64_t>& dims) {
  std::string s;
  for (uint64_t d : dims) {
    if (!s.empty()) s += ' ';
    s += std::to_string(d);
  }
  return s;
}

uint64_t product(const std::vector<uint64_t>& dims) {
  uint64_t n = 1;
  for (uint64_t d : dims)
    if (__builtin_mul_overflow(n, d, &n)) return UINT64_MAX;
  return n;
}

Result parseDims(std::string_view text, const std::string& what, std::vector<uint64_t>& dims) {
  dims.clear();
  size_t pos = 0;
  while (true) {
    std::string_view tok = vtkio::nextToken(text, pos);
    if (tok.empty()) break;
    uint64_t d;
    if (!vtkio::parseU64(tok, d))
      return fail(Status::Corrupt, what + ": Dimensions='" + vtkio::printable(text) + "' is not a list of counts");
    if (d > kMaxDimension)
      return fail(Status::TooLarge, what + ": Dimensions='" + vtkio::printable(text) + "' declares " +
                                        std::to_string(d) + " along one axis");
    dims.push_back(d);
    if (dims.size() > kMaxRank)
      return fail(Status::Corrupt, what + ": Dimensions='" + vtkio::printable(text) + "' has more than 8 axes");
  }
  if (dims.empty()) return fail(Status::Corrupt, what + ": no Dimensions");
  if (product(dims) == UINT64_MAX)
    return fail(Status::TooLarge, what + ": Dimensions='" + vtkio::printable(text) + "' overflow");
  return Result::success();
}

// NumberType (XDMF 2) or DataType (XDMF 3), with Precision in bytes.
Result parseType(pugi::xml_node item, const std::string& what, ScalarType& t) {
  std::string_view name =
      item.attribute("DataType") ? item.attribute("DataType").value() : item.attribute("NumberType").value();
  if (name.empty()) name = "Float";
  const bool isChar = iequals(name, "Char") || iequals(name, "UChar");
  uint64_t precision = isChar ? 1 : 4;
  if (item.attribute("Precision") && !vtkio::parseU64(item.attribute("Precision").value(), precision))
    return fail(Status::Corrupt, what + ": Precision='" + vtkio::printable(item.attribute("Precision").value()) +
                                     "' is not a byte count");
  auto bad = [&] {
    return fail(Status::Unsupported, what + ": number type '" + vtkio::printable(name) + "' of " +
                                         std::to_string(precision) +
                                         " bytes (expected Float 4/8, Int or UInt 1/2/4/8, Char, UChar)");
  };
  if (iequals(name, "Float")) {
    if (precision != 4 && precision != 8) return bad();
    t = precision == 4 ? ScalarType::Float32 : ScalarType::Float64;
  } else if (iequals(name, "Int") || iequals(name, "UInt")) {
    const bool u = iequals(name, "UInt");
    switch (precision) {
      case 1: t = u ? ScalarType::UInt8 : ScalarType::Int8; break;
      case 2: t = u ? ScalarType::UInt16 : ScalarType::Int16; break;
      case 4: t = u ? ScalarType::UInt32 : ScalarType::Int32; break;
      case 8: t = u ? ScalarType::UInt64 : ScalarType::Int64; break;
      default: return bad();
    }
  } else if (iequals(name, "Char")) {
    t = ScalarType::Int8;
  } else if (iequals(name, "UChar")) {
    t = ScalarType::UInt8;
  } else {
    return bad();
  }
  return Result::success();
}

// Copies the values `slab` selects from `values` (laid out by `dims`, last index fastest).
template <class T>
Result applySlab(const std::vector<T>& values, const std::vector<uint64_t>& dims, const hdf5::Slab& slab,
                 const std::string& what, std::vector<T>& out) {
  const size_t rank = dims.size();
  if (slab.start.size() != rank)
    return fail(Status::Corrupt, what + ": the HyperSlab selects " + std::to_string(slab.start.size()) +
                                     " axes of data with " + std::to_string(rank));
  for (size_t d = 0; d < rank; ++d) {
    uint64_t last = 0;
    if (slab.stride[d] == 0 ||
        (slab.count[d] > 0 && (__builtin_mul_overflow(slab.count[d] - 1, slab.stride[d], &last) ||
                               __builtin_add_overflow(last, slab.start[d], &last) || last >= dims[d])))
      return fail(Status::OutOfRange, what + ": the HyperSlab (start " + std::to_string(slab.start[d]) + ", stride " +
                                          std::to_string(slab.stride[d]) + ", count " + std::to_string(slab.count[d]) +
                                          ") goes past axis " + std::to_string(d) + " of " + std::to_string(dims[d]));
  }
  out.clear();
  const uint64_t n = product(slab.count);
  if (n == 0) return Result::success();
  out.reserve(n);
  std::vector<uint64_t> index(rank, 0);
  std::vector<uint64_t> step(rank, 1);  // elements per unit of each axis
  for (size_t d = rank; d-- > 1;) step[d - 1] = step[d] * dims[d];
  for (uint64_t k = 0; k < n; ++k) {
    uint64_t at = 0;
    for (size_t d = 0; d < rank; ++d) at += (slab.start[d] + index[d] * slab.stride[d]) * step[d];
    out.push_back(values[at]);
    for (size_t d = rank; d-- > 0;) {
      if (++index[d] < slab.count[d]) break;
      index[d] = 0;
    }
  }
  return Result::success();
}

}  // namespace

Document::Document(std::string label, std::optional<std::string> folder)
    : label_(std::move(label)), folder_(std::move(folder)) {}

Result Document::parse(std::string_view xml) {
  size_t start = xml.substr(0, 3) == "\xEF\xBB\xBF" ? 3 : 0;
  start = std::min(xml.size(), xml.find_first_not_of(" \t\r\n", start));
  if (start >= xml.size()) return fail(Status::Truncated, label_ + ": empty file (no XDMF XML)");
  if (xml[start] != '<') return fail(Status::BadMagic, label_ + ": not an XDMF file: it does not start with '<' (XML)");
  xml_.assign(xml);
  const pugi::xml_parse_result pr =
      doc_.load_buffer_inplace(xml_.data(), xml_.size(), pugi::parse_default, pugi::encoding_utf8);
  if (!pr) {
    std::string_view tail = trim(xml);
    const bool cut = !tail.ends_with(">");
    return fail(cut ? Status::Truncated : Status::Corrupt,
                label_ + ": " + (cut ? "the file ends inside the XML; " : "") + "malformed XML at byte " +
                    std::to_string(pr.offset) + ": " + pr.description());
  }
  if (std::strcmp(root().name(), "Xdmf") != 0)
    return fail(Status::BadMagic, label_ + ": the root element is <" + vtkio::printable(root().name()) +
                                      ">, expected <Xdmf>; not an XDMF file");
  return Result::success();
}

Result Document::spend(size_t n, const std::string& what) {
  budget_ += n;
  if (budget_ > kElementBudget)
    return fail(Status::TooLarge, what + ": the references and includes expand to more than " +
                                      std::to_string(kElementBudget) + " elements (an include of itself?)");
  return Result::success();
}

Result Document::select(std::string_view path, const std::string& what, const std::vector<pugi::xml_node>*& out) {
  auto it = paths_.find(path);
  if (it == paths_.end()) {
    std::vector<pugi::xml_node> nodes;
    std::string error;
    if (!xmlpath::select(doc_, path, nodes, error)) return fail(Status::Unsupported, what + ": " + error);
    it = paths_.emplace(std::string(path), std::move(nodes)).first;
  }
  out = &it->second;
  return Result::success();
}

Result Document::follow(pugi::xml_node node, const std::string& what, pugi::xml_node& out) {
  out = node;
  for (int depth = 0; depth <= kMaxReferenceDepth; ++depth) {
    pugi::xml_attribute ref = out.attribute("Reference");
    if (!ref) return Result::success();
    std::string_view path = iequals(ref.value(), "XML") ? trim(out.child_value()) : trim(ref.value());
    if (!path.starts_with("/"))
      return fail(Status::Unsupported, what + ": <" + vtkio::printable(out.name()) + " Reference='" +
                                           vtkio::printable(ref.value()) +
                                           "'> does not point into this document (tetstream follows "
                                           "Reference=\"XML\" with a path as text, or Reference=\"/path\")");
    const std::vector<pugi::xml_node>* found;
    if (Result r = select(path, what, found); !r) return r;
    if (found->empty())
      return fail(Status::Corrupt,
                  what + ": the reference '" + vtkio::printable(path) + "' points at no element of the document");
    // XDMF takes the first element a reference finds; it must be of the kind that refers.
    if (std::strcmp((*found)[0].name(), out.name()) != 0)
      return fail(Status::Corrupt, what + ": the reference '" + vtkio::printable(path) + "' points at a <" +
                                       vtkio::printable((*found)[0].name()) + ">, expected a <" +
                                       vtkio::printable(out.name()) + ">");
    out = (*found)[0];
  }
  return fail(Status::Corrupt, what + ": references nest more than " + std::to_string(kMaxReferenceDepth) +
                                   " deep (a reference cycle?)");
}

Result Document::children(pugi::xml_node parent, const char* name, const std::string& what,
                          std::vector<pugi::xml_node>& out) {
  out.clear();
  return childrenAt(parent, name, what, 0, out);
}

Result Document::childrenAt(pugi::xml_node parent, const char* name, const std::string& what, int depth,
                            std::vector<pugi::xml_node>& out) {
  for (pugi::xml_node c = parent.first_child(); c; c = c.next_sibling()) {
    if (c.type() != pugi::node_element) continue;
    if (isInclude(c)) {
      if (Result r = expandInclude(c, name, what, depth, out); !r) return r;
      continue;
    }
    if (name && std::strcmp(c.name(), name) != 0) continue;
    pugi::xml_node f;
    if (Result r = follow(c, what, f); !r) return r;
    out.push_back(f);
    if (Result r = spend(1, what); !r) return r;
  }
  return Result::success();
}

Result Document::expandInclude(pugi::xml_node include, const char* name, const std::string& what, int depth,
                               std::vector<pugi::xml_node>& out) {
  if (depth > kMaxReferenceDepth)
    return fail(Status::Corrupt, what + ": <xi:include> elements nest more than " + std::to_string(kMaxReferenceDepth) +
                                     " deep (an include cycle?)");
  const std::string tag = std::string("<") + vtkio::printable(include.name());
  if (include.attribute("href") && *include.attribute("href").value())
    return fail(Status::Unsupported, what + ": " + tag + " href='" +
                                         vtkio::printable(include.attribute("href").value()) +
                                         "'> includes another file; tetstream reads includes within the same "
                                         "document only");
  std::string_view pointer = trim(include.attribute("xpointer").value());
  if (pointer.starts_with("xpointer(") && pointer.ends_with(")")) pointer = pointer.substr(9, pointer.size() - 10);
  if (!trim(pointer).starts_with("/"))
    return fail(Status::Unsupported, what + ": " + tag + " xpointer='" +
                                         vtkio::printable(include.attribute("xpointer").value()) +
                                         "'>: tetstream follows xpointer(/path) only");
  const std::vector<pugi::xml_node>* found;
  if (Result r = select(pointer, what, found); !r) return r;
  if (found->empty())
    return fail(Status::Corrupt, what + ": " + tag + " xpointer='" +
                                     vtkio::printable(include.attribute("xpointer").value()) +
                                     "'> points at no element of the document");
  if (Result r = spend(found->size(), what); !r) return r;
  for (pugi::xml_node n : *found) {
    if (isInclude(n)) {
      if (Result r = expandInclude(n, name, what, depth + 1, out); !r) return r;
      continue;
    }
    if (name && std::strcmp(n.name(), name) != 0) continue;
    pugi::xml_node f;
    if (Result r = follow(n, what, f); !r) return r;
    out.push_back(f);
  }
  return Result::success();
}

Result Document::dataItem(pugi::xml_node parent, const std::string& what, pugi::xml_node& out) {
  std::vector<pugi::xml_node> items;
  if (Result r = children(parent, "DataItem", what, items); !r) return r;
  if (items.empty()) return fail(Status::Corrupt, what + ": no <DataItem>");
  out = items[0];
  return Result::success();
}

Result Document::heavyPath(const std::string& name, const std::string& what, std::string& path) const {
  if (!folder_)
    return fail(Status::Unsupported, what + ": its data is in the file '" + vtkio::printable(name) +
                                         "', and this XDMF text was given without its folder; read the XDMF "
                                         "file by path");
  if (name.empty()) return fail(Status::Corrupt, what + ": names no data file");
  const bool absolute = name[0] == '/' || name[0] == '\\' ||
                        (name.size() > 1 && name[1] == ':' && std::isalpha(static_cast<unsigned char>(name[0])));
  bool up = false;
  size_t pos = 0;
  while (pos <= name.size()) {
    size_t e = name.find_first_of("/\\", pos);
    if (e == std::string::npos) e = name.size();
    up |= name.compare(pos, e - pos, "..") == 0 && e - pos == 2;
    pos = e + 1;
  }
  if (absolute || up)
    return fail(Status::Unsupported, what + ": the data file '" + vtkio::printable(name) + "' is " +
                                         (absolute ? "an absolute path" : "outside the XDMF file's folder ('..')") +
                                         "; tetstream reads heavy data only from the XDMF file's folder or below "
                                         "it (a relative name without '..')");
  path = folder_->empty() ? name : (std::filesystem::path(*folder_) / name).string();
  return Result::success();
}

Result Document::hdf5File(const std::string& path, const hdf5::File*& out) {
  auto it = files_.find(path);
  if (it == files_.end()) {
    auto f = std::make_unique<hdf5::File>();
    if (Result r = f->open(path); !r) return r;
    it = files_.emplace(path, std::move(f)).first;
  }
  out = it->second.get();
  return Result::success();
}

Result Document::numbers(pugi::xml_node item, const std::string& what, Values<double>& out) {
  return read(item, what, 0, out);
}

Result Document::integers(pugi::xml_node item, const std::string& what, Values<int64_t>& out) {
  return read(item, what, 0, out);
}

Result Document::numberRows(pugi::xml_node item, const std::string& what, uint64_t total, uint64_t first,
                            uint64_t count, Values<double>& out) {
  return readRows(item, what, total, first, count, out);
}

Result Document::integerRows(pugi::xml_node item, const std::string& what, uint64_t total, uint64_t first,
                             uint64_t count, Values<int64_t>& out) {
  return readRows(item, what, total, first, count, out);
}

std::vector<uint64_t> Document::declaredDims(pugi::xml_node item) {
  pugi::xml_node node;
  std::vector<uint64_t> dims;
  if (!follow(item, "", node) || std::strcmp(node.name(), "DataItem") != 0) return dims;
  std::string_view itemType = node.attribute("ItemType").value();
  if ((!itemType.empty() && !iequals(itemType, "Uniform")) ||
      !parseDims(node.attribute("Dimensions").value(), "", dims))
    dims.clear();
  return dims;
}

bool Document::readsRowsAlone(pugi::xml_node item, uint64_t total) {
  const std::vector<uint64_t> d = declaredDims(item);
  pugi::xml_node node;
  return !d.empty() && d[0] == total && total > 0 && follow(item, "", node).ok() &&
         iequals(node.attribute("Format").value(), "HDF");
}

template <class T>
Result Document::readRows(pugi::xml_node item, const std::string& what, uint64_t total, uint64_t first, uint64_t count,
                          Values<T>& out) {
  out = Values<T>{};
  if (first > total || count > total - first)
    return fail(Status::OutOfRange, what + ": rows " + std::to_string(first) + " to " + std::to_string(first + count) +
                                        " of " + std::to_string(total));
  if (const std::vector<uint64_t> d = declaredDims(item); !d.empty() && d[0] == total && total > 0) {
    pugi::xml_node node;
    if (Result r = follow(item, what, node); !r) return r;
    if (++itemReads_ > kMaxItemReads)
      return fail(Status::TooLarge, what + ": more than " + std::to_string(kMaxItemReads) + " DataItems to read");
    std::vector<uint64_t> dims;
    if (Result r = parseDims(node.attribute("Dimensions").value(), what, dims); !r) return r;
    hdf5::Slab slab;
    slab.start.assign(dims.size(), 0);
    slab.stride.assign(dims.size(), 1);
    slab.count = dims;
    slab.start[0] = first;
    slab.count[0] = count;
    if (count == 0) {  // (an empty selection: nothing to read)
      out.dims = slab.count;
      return Result::success();
    }
    Result r = readUniform(node, what, &slab, out);
    out.dims = slab.count;
    // (a dataset shaped otherwise than its Dimensions cannot take a hyperslab: read whole below)
    if (r || r.status != Status::Unsupported) return r;
  }
  Values<T> all;
  if (Result r = read(item, what, 0, all); !r) return r;
  if (total == 0 || all.values.size() % total != 0)
    return fail(Status::Corrupt, what + ": " + std::to_string(all.values.size()) +
                                     " values are not a whole number per " + "row of " + std::to_string(total));
  const uint64_t per = all.values.size() / total;
  out.values.assign(all.values.begin() + ptrdiff_t(first * per), all.values.begin() + ptrdiff_t((first + count) * per));
  out.dims = {count, per};
  return Result::success();
}

template <class T>
Result Document::read(pugi::xml_node item, const std::string& what, int depth, Values<T>& out) {
  out = Values<T>{};
  if (depth > kMaxItemDepth)
    return fail(Status::Corrupt, what + ": DataItems nest more than " + std::to_string(kMaxItemDepth) + " deep");
  if (++itemReads_ > kMaxItemReads)
    return fail(Status::TooLarge,
                what + ": more than " + std::to_string(kMaxItemReads) + " DataItems to read (Functions of Functions?)");
  pugi::xml_node node;
  if (Result r = follow(item, what, node); !r) return r;
  if (std::strcmp(node.name(), "DataItem") != 0)
    return fail(Status::Corrupt, what + ": expected a <DataItem>, found <" + vtkio::printable(node.name()) + ">");
  std::string_view itemType = node.attribute("ItemType").value();
  std::vector<pugi::xml_node> parts;
  if (iequals(itemType, "HyperSlab")) {
    // Two DataItems: the selection (start, stride and count per axis, 3 x rank) and the source.
    if (Result r = children(node, "DataItem", what, parts); !r) return r;
    if (parts.size() != 2)
      return fail(Status::Corrupt, what + ": a HyperSlab DataItem holds " + std::to_string(parts.size()) +
                                       " DataItems, expected 2 (the selection, then the data)");
    Values<int64_t> sel;
    if (Result r = read(parts[0], what + " (HyperSlab selection)", depth + 1, sel); !r) return r;
    if (sel.values.size() % 3 != 0 || sel.values.empty() || sel.values.size() / 3 > kMaxRank)
      return fail(Status::Corrupt, what + ": the HyperSlab selection holds " + std::to_string(sel.values.size()) +
                                       " values, expected 3 x the number of axes");
    hdf5::Slab slab;
    const size_t rank = sel.values.size() / 3;
    for (size_t k = 0; k < 3 * rank; ++k)
      if (sel.values[k] < 0) return fail(Status::Corrupt, what + ": the HyperSlab selection has a negative value");
    for (size_t d = 0; d < rank; ++d) {
      slab.start.push_back(uint64_t(sel.values[d]));
      slab.stride.push_back(uint64_t(sel.values[rank + d]));
      slab.count.push_back(uint64_t(sel.values[2 * rank + d]));
    }
    if (node.attribute("Dimensions")) {
      std::vector<uint64_t> dims;
      if (Result r = parseDims(node.attribute("Dimensions").value(), what, dims); !r) return r;
      if (product(dims) != product(slab.count))
        return fail(Status::Corrupt, what + ": the HyperSlab's Dimensions '" + dimsText(dims) + "' hold " +
                                         std::to_string(product(dims)) + " values, its selection " +
                                         std::to_string(product(slab.count)));
      out.dims = dims;
    } else {
      out.dims = slab.count;
    }
    pugi::xml_node source;
    if (Result r = follow(parts[1], what, source); !r) return r;
    if (*source.attribute("ItemType").value() && !iequals(source.attribute("ItemType").value(), "Uniform"))
      return fail(Status::Unsupported, what + ": a HyperSlab of an ItemType=\"" +
                                           vtkio::printable(source.attribute("ItemType").value()) + "\" DataItem");
    std::vector<uint64_t> dims = out.dims;
    if (Result r = readUniform(source, what, &slab, out); !r) return r;
    out.dims = dims;
    return Result::success();
  }
  if (iequals(itemType, "Function")) {
    // JOIN($0, $1, ...): the items side by side, one tuple per row (e.g. x, y, z columns).
    std::string_view f = trim(node.attribute("Function").value());
    std::vector<size_t> order;
    if (f.size() > 6 && iequals(f.substr(0, 5), "JOIN(") && f.back() == ')') {
      std::string_view args = f.substr(5, f.size() - 6);
      size_t pos = 0;
      while (pos < args.size()) {
        size_t e = args.find(',', pos);
        if (e == std::string_view::npos) e = args.size();
        std::string_view a = trim(args.substr(pos, e - pos));
        uint64_t k;
        if (a.size() < 2 || a[0] != '$' || !vtkio::parseU64(a.substr(1), k) || k >= kMaxJoin) {
          order.clear();
          break;
        }
        order.push_back(size_t(k));
        pos = e + 1;
      }
    }
    if (order.empty() || order.size() > kMaxJoin)
      return fail(Status::Unsupported, what + ": Function=\"" + vtkio::printable(f) +
                                           "\" (tetstream evaluates JOIN($0, $1, ...) of up to " +
                                           std::to_string(kMaxJoin) + " items only)");
    if (Result r = children(node, "DataItem", what, parts); !r) return r;
    std::vector<Values<T>> args(order.size());
    uint64_t n = 0;
    for (size_t k = 0; k < order.size(); ++k) {
      if (order[k] >= parts.size())
        return fail(Status::Corrupt, what + ": Function uses $" + std::to_string(order[k]) + " but holds " +
                                         std::to_string(parts.size()) + " DataItems");
      if (Result r = read(parts[order[k]], what + " ($" + std::to_string(order[k]) + ")", depth + 1, args[k]); !r)
        return r;
      if (k > 0 && args[k].values.size() != n)
        return fail(Status::Corrupt, what + ": Function JOIN of items of " + std::to_string(n) + " and " +
                                         std::to_string(args[k].values.size()) + " values");
      n = args[k].values.size();
    }
    out.values.resize(n * order.size());
    for (uint64_t i = 0; i < n; ++i)
      for (size_t k = 0; k < order.size(); ++k) out.values[i * order.size() + k] = args[k].values[i];
    out.dims = {n, order.size()};
    return Result::success();
  }
  if (!itemType.empty() && !iequals(itemType, "Uniform"))
    return fail(Status::Unsupported, what + ": DataItem ItemType=\"" + vtkio::printable(itemType) +
                                         "\" (tetstream reads Uniform, HyperSlab and JOIN Functions)");
  return readUniform(node, what, nullptr, out);
}

template <class T>
Result Document::readUniform(pugi::xml_node item, const std::string& whatIn, const hdf5::Slab* slab, Values<T>& out) {
  constexpr bool wantInts = std::is_same_v<T, int64_t>;
  std::string what = whatIn;
  if (item.attribute("Name") && *item.attribute("Name").value())
    what += " DataItem '" + vtkio::printable(item.attribute("Name").value()) + "'";
  std::vector<uint64_t> dims;
  if (Result r = parseDims(item.attribute("Dimensions").value(), what, dims); !r) return r;
  ScalarType type;
  if (Result r = parseType(item, what, type); !r) return r;
  const uint64_t declared = product(dims);
  std::string_view format = item.attribute("Format").value();
  if (format.empty()) format = "XML";
  std::string_view text = trim(item.child_value());
  out.dims = dims;
  std::vector<T> all;
  std::vector<T>& target = slab ? all : out.values;

  if (iequals(format, "XML")) {
    sources_.insert("XML data");
    // Every value takes a character and a separator: a count the text cannot hold is a lie.
    if (declared > (text.size() + 1) / 2)
      return fail(Status::Truncated, what + ": Dimensions '" + dimsText(dims) + "' declare " +
                                         std::to_string(declared) + " values, more than its " +
                                         std::to_string(text.size()) + " characters of text can hold");
    target.reserve(declared);
    size_t pos = 0;
    for (uint64_t i = 0; i < declared; ++i) {
      T v{};
      int got;
      if constexpr (wantInts)
        got = vtkio::parseNextInt(text, pos, v);
      else
        got = vtkio::parseNextDouble(text, pos, v);
      if (got == 0)
        return fail(Status::Truncated, what + ": holds " + std::to_string(i) + " of the " + std::to_string(declared) +
                                           " values its Dimensions '" + dimsText(dims) + "' declare");
      if (got < 0)
        return fail(Status::Corrupt, what + ": value " + std::to_string(i) + " '" +
                                         vtkio::printable(vtkio::nextToken(text, pos)) + "' is not " +
                                         (wantInts ? "an integer" : "a number"));
      target.push_back(v);
    }
    double extra;
    if (vtkio::parseNextDouble(text, pos, extra) != 0)
      return fail(Status::Corrupt, what + ": holds more than the " + std::to_string(declared) +
                                       " values its Dimensions '" + dimsText(dims) + "' declare");
  } else if (iequals(format, "HDF")) {
    sources_.insert("HDF5 heavy data");
    const size_t colon = text.find(':');
    if (colon == std::string_view::npos || colon == 0 || colon + 1 >= text.size())
      return fail(Status::Corrupt, what + ": HDF data '" + vtkio::printable(text) + "' is not FILE:/dataset");
    std::string file(trim(text.substr(0, colon))), dataset(trim(text.substr(colon + 1)));
    if (dataset.empty() || dataset[0] != '/') dataset = "/" + dataset;
    what += " (" + file + ":" + dataset + ")";
    std::string path;
    if (Result r = heavyPath(file, what, path); !r) return r;
    const hdf5::File* h5;
    if (Result r = hdf5File(path, h5); !r) return fail(r.status, what + ": " + r.message);
    hdf5::Shape shape;
    if (Result r = h5->shape(dataset, shape); !r) return fail(r.status, what + ": " + r.message);
    if (shape.count() != declared)
      return fail(Status::Corrupt, what + ": Dimensions '" + dimsText(dims) + "' declare " + std::to_string(declared) +
                                       " values, the dataset holds " + std::to_string(shape.count()) + " (" +
                                       dimsText(shape.dims) + ")");
    hdf5::Slab whole;
    if (slab && shape.dims != dims)
      return fail(Status::Unsupported, what + ": a HyperSlab of a dataset whose shape (" + dimsText(shape.dims) +
                                           ") is not its Dimensions '" + dimsText(dims) + "'");
    const uint64_t want = slab ? product(slab->count) : declared;
    Result r;
    if constexpr (wantInts)
      r = h5->readInts(dataset, slab ? *slab : whole, want, out.values);
    else
      r = h5->readDoubles(dataset, slab ? *slab : whole, want, out.values);
    if (!r) return fail(r.status, what + ": " + r.message);
    return Result::success();
  } else if (iequals(format, "Binary")) {
    sources_.insert("binary data");
    std::string file(text);
    what += " (" + file + ")";
    std::string_view compression = item.attribute("Compression").value();
    if (!compression.empty() && !iequals(compression, "Raw"))
      return fail(Status::Unsupported,
                  what + ": Compression=\"" + vtkio::printable(compression) + "\" (tetstream reads Raw binary data)");
    std::string_view endian = item.attribute("Endian").value();
    bool big = std::endian::native == std::endian::big;
    if (iequals(endian, "Big"))
      big = true;
    else if (iequals(endian, "Little"))
      big = false;
    else if (!endian.empty() && !iequals(endian, "Native"))
      return fail(Status::Corrupt, what + ": Endian='" + vtkio::printable(endian) + "' (expected Native, Big, Little)");
    uint64_t seek = 0;
    if (item.attribute("Seek") && !vtkio::parseU64(item.attribute("Seek").value(), seek))
      return fail(Status::Corrupt,
                  what + ": Seek='" + vtkio::printable(item.attribute("Seek").value()) + "' is not a byte offset");
    std::string path;
    if (Result r = heavyPath(file, what, path); !r) return r;
    std::error_code ec;
    const uint64_t size = std::filesystem::file_size(path, ec);
    if (ec) return fail(Status::IoError, what + ": cannot open " + path + " (" + ec.message() + ")");
    const uint64_t bytes = declared * vtkio::scalarSize(type);
    if (declared > UINT64_MAX / 8 || seek > size || size - seek < bytes)
      return fail(Status::Truncated, what + ": needs " + std::to_string(bytes) + " bytes from byte " +
                                         std::to_string(seek) + ", the file has " + std::to_string(size));
    std::vector<uint8_t> raw(bytes);
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) return fail(Status::IoError, what + ": cannot open " + path + " (" + std::strerror(errno) + ")");
    const bool ok = std::fseek(f, long(seek), SEEK_SET) == 0 && std::fread(raw.data(), 1, raw.size(), f) == raw.size();
    std::fclose(f);
    if (!ok) return fail(Status::IoError, what + ": read error in " + path);
    target.resize(declared);
    if constexpr (wantInts) {
      if (vtkio::decodeInts(raw.data(), declared, type, big, target.data()) != declared)
        return fail(Status::OutOfRange, what + ": a value exceeds the Int64 range");
    } else {
      vtkio::decodeDoubles(raw.data(), declared, type, big, target.data());
    }
  } else {
    return fail(Status::Unsupported,
                what + ": Format=\"" + vtkio::printable(format) + "\" (tetstream reads XML, HDF and Binary)");
  }
  if (slab) return applySlab(all, dims, *slab, what, out.values);
  return Result::success();
}

}  // namespace tetstream::xdmf
