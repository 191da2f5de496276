// An XDMF file's XML and the values of its DataItems (xdmf_reader.cpp turns the grids into a mesh).
// Layout reference: "XDMF Model and Format" (xdmf.org), XDMF 2 and 3.
//
// A DataItem's values come from its text (Format="XML"), from a dataset of an HDF5 file
// (Format="HDF", text "FILE:/path/to/dataset") or from a raw binary file (Format="Binary", text
// "FILE", with Endian, Seek and Precision). ItemType="HyperSlab" selects part of another item,
// ItemType="Function" with Function="JOIN($0, $1, ...)" interleaves items. Elements may stand for
// others: Reference="XML" (the text is a path) or Reference="/path", and <xi:include
// xpointer="xpointer(/path)"/>, within the same document (xml_path.h says which paths).
//
// Safety rules, since the XML comes from strangers:
//   - Heavy-data files are looked up in the XDMF file's folder or below it: a relative name
//     without '..' parts. Absolute names and '..' are refused (DOLFINx and meshio write plain
//     names next to the .xdmf).
//   - Declared Dimensions are checked against what is there (the text's length, the dataset's
//     shape and storage, the binary file's size) before anything is allocated.
//   - References are followed at most 8 deep, and every element the includes expand to is
//     counted against a budget, so a reference cycle or an include that includes itself ends
//     with a message.
//   - Without a folder (bytes in memory), HDF and Binary items are refused with Unsupported.
#pragma once
#include <map>
#include <memory>
#include <optional>
#include <pugixml.hpp>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "io/hdf5_file.h"
#include "status.h"

namespace tetstream::xdmf {

// The values of a DataItem and the dimensions it declares (slowest first).
template <class T>
struct Values {
  std::vector<uint64_t> dims;
  std::vector<T> values;
};

class Document {
 public:
  // `label` names the XDMF file in messages; `folder` is where its heavy-data files are
  // (nullopt: none can be read).
  Document(std::string label, std::optional<std::string> folder);

  // Parses the XML; the root must be <Xdmf>. BadMagic, Truncated or Corrupt otherwise.
  Result parse(std::string_view xml);
  pugi::xml_node root() const { return doc_.document_element(); }
  const std::string& label() const { return label_; }

  // The element `node` stands for: itself, or what its Reference points at (followed again if
  // that is a reference too). `what` starts messages.
  Result follow(pugi::xml_node node, const std::string& what, pugi::xml_node& out);
  // The element children of `parent` named `name` (every element when name is null), each
  // followed through its Reference, with <xi:include> elements replaced by what they point at.
  Result children(pugi::xml_node parent, const char* name, const std::string& what, std::vector<pugi::xml_node>& out);
  // The first DataItem child of `parent` (after includes and references); Corrupt if none.
  Result dataItem(pugi::xml_node parent, const std::string& what, pugi::xml_node& out);

  // The values of a DataItem, as doubles or as integers.
  Result numbers(pugi::xml_node item, const std::string& what, Values<double>& out);
  Result integers(pugi::xml_node item, const std::string& what, Values<int64_t>& out);

  // Rows [first, first + count) of a DataItem of `total` rows (its slowest dimension), for a
  // process that reads its share of a grid. A Uniform item whose first dimension is `total` is
  // read only there (an HDF5 hyperslab; XML and binary data are sliced once read); any other
  // item is read whole and sliced, which needs its values to be a whole number per row.
  Result numberRows(pugi::xml_node item, const std::string& what, uint64_t total, uint64_t first, uint64_t count,
                    Values<double>& out);
  Result integerRows(pugi::xml_node item, const std::string& what, uint64_t total, uint64_t first, uint64_t count,
                     Values<int64_t>& out);
  // Whether rows of `item` (of `total` rows) are read for the cost of those rows: an HDF5
  // hyperslab of a Uniform item. Other data is read whole and sliced.
  bool readsRowsAlone(pugi::xml_node item, uint64_t total);
  // A Uniform DataItem's declared Dimensions (empty for any other item, or none declared).
  std::vector<uint64_t> declaredDims(pugi::xml_node item);

  // Where data came from, for ReadReport::format: "HDF5 heavy data", "XML data", "binary data".
  const std::set<std::string>& sources() const { return sources_; }

 private:
  template <class T>
  Result read(pugi::xml_node item, const std::string& what, int depth, Values<T>& out);
  template <class T>
  Result readRows(pugi::xml_node item, const std::string& what, uint64_t total, uint64_t first, uint64_t count,
                  Values<T>& out);
  template <class T>
  Result readUniform(pugi::xml_node item, const std::string& what, const hdf5::Slab* slab, Values<T>& out);
  Result select(std::string_view path, const std::string& what, const std::vector<pugi::xml_node>*& out);
  Result childrenAt(pugi::xml_node parent, const char* name, const std::string& what, int depth,
                    std::vector<pugi::xml_node>& out);
  // The elements <xi:include> points at (named `name`, or all), followed through references.
  Result expandInclude(pugi::xml_node include, const char* name, const std::string& what, int depth,
                       std::vector<pugi::xml_node>& out);
  // The path of heavy-data file `name` under the folder, or a refusal naming the rule.
  Result heavyPath(const std::string& name, const std::string& what, std::string& path) const;
  Result hdf5File(const std::string& path, const hdf5::File*& out);
  Result spend(size_t n, const std::string& what);

  std::string label_;
  std::optional<std::string> folder_;
  std::string xml_;  // the text pugixml parsed in place
  pugi::xml_document doc_;
  std::map<std::string, std::vector<pugi::xml_node>, std::less<>> paths_;  // evaluated paths
  std::map<std::string, std::unique_ptr<hdf5::File>> files_;               // opened HDF5 files
  std::set<std::string> sources_;
  size_t budget_ = 0;     // elements handed out by children(), against kElementBudget
  size_t itemReads_ = 0;  // DataItems read, against kMaxItemReads
};

}  // namespace tetstream::xdmf
