// The part of XPath that XDMF files use to point at other elements of the same document
// (<xi:include xpointer="xpointer(PATH)"/>, <DataItem Reference="XML">PATH</DataItem>):
// absolute location paths of child ('/') and descendant ('//') steps, each step an element name
// (prefixes allowed) or '*', with any number of predicates:
//   [N]  [last()]  [@attr='value']  [@attr="value"]  [@attr]  [self::A or self::B ...]
// e.g. "/Xdmf/Domain/Grid[@GridType='Uniform'][1]/*[self::Topology or self::Geometry]" (DOLFINx),
// "//Grid[@Name=\"mesh\"]/*[self::Topology or self::Geometry]" (meshio).
//
// Full XPath is not evaluated on purpose: its cost on a hostile document can grow with the square
// of its size (a predicate that scans the whole document for every node), while each step here
// visits every node at most once.
#pragma once
#include <pugixml.hpp>
#include <string>
#include <string_view>
#include <vector>

namespace tetstream::xmlpath {

// Evaluates `path` against `doc`; the elements found, in document order. False with `error` set
// (what is not understood, and where) for anything outside the subset above.
bool select(const pugi::xml_document& doc, std::string_view path, std::vector<pugi::xml_node>& out, std::string& error);

}  // namespace tetstream::xmlpath
