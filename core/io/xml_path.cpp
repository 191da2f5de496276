#include "io/xml_path.h"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <unordered_map>
#include <unordered_set>

namespace tetstream::xmlpath {
namespace {

constexpr size_t kMaxPath = 1024;
constexpr size_t kMaxSteps = 32;
constexpr size_t kMaxPredicates = 8;

struct Predicate {
  enum Kind { Position, Last, AttrEquals, AttrExists, SelfNames } kind = Position;
  uint64_t position = 0;
  std::string attr, value;
  std::vector<std::string> names;
};

struct Step {
  bool descendant = false;  // reached by '//'
  std::string name;         // "*" for any element
  std::vector<Predicate> predicates;
};

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '\n' || s.front() == '\r'))
    s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\n' || s.back() == '\r'))
    s.remove_suffix(1);
  return s;
}

bool isNameChar(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-' ||
         c == '.' || c == ':';
}

bool parsePredicate(std::string_view text, Predicate& p, std::string& error) {
  text = trim(text);
  if (!text.empty() && std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; })) {
    if (text.size() > 9) return error = "position " + std::string(text) + " is too large", false;
    p.kind = Predicate::Position;
    p.position = std::stoull(std::string(text));
    if (p.position == 0) return error = "positions start at 1", false;
    return true;
  }
  if (text == "last()") {
    p.kind = Predicate::Last;
    return true;
  }
  if (text.starts_with("@")) {
    size_t e = 1;
    while (e < text.size() && isNameChar(text[e])) ++e;
    p.attr = std::string(text.substr(1, e - 1));
    if (p.attr.empty()) return error = "an attribute name after '@'", false;
    std::string_view rest = trim(text.substr(e));
    if (rest.empty()) {
      p.kind = Predicate::AttrExists;
      return true;
    }
    if (rest[0] != '=') return error = "'=' after @" + p.attr, false;
    rest = trim(rest.substr(1));
    if (rest.size() < 2 || (rest[0] != '\'' && rest[0] != '"') || rest.back() != rest[0] ||
        rest.substr(1, rest.size() - 2).find(rest[0]) != std::string_view::npos)
      return error = "a quoted value after @" + p.attr + "=", false;
    p.kind = Predicate::AttrEquals;
    p.value = std::string(rest.substr(1, rest.size() - 2));
    return true;
  }
  if (text.starts_with("self::")) {
    p.kind = Predicate::SelfNames;
    while (true) {
      text = trim(text);
      if (!text.starts_with("self::")) return error = "'self::NAME' terms joined by 'or'", false;
      text.remove_prefix(6);
      size_t e = 0;
      while (e < text.size() && isNameChar(text[e])) ++e;
      if (e == 0) return error = "a name after 'self::'", false;
      p.names.emplace_back(text.substr(0, e));
      text = trim(text.substr(e));
      if (text.empty()) return true;
      if (!text.starts_with("or") || text.size() < 3 || isNameChar(text[2]))
        return error = "'or' between 'self::' terms", false;
      text.remove_prefix(2);
      if (p.names.size() > 16) return error = "too many 'self::' terms", false;
    }
  }
  return error = "predicate [" + std::string(text.substr(0, 40)) + "]", false;
}

bool parse(std::string_view path, std::vector<Step>& steps, std::string& error) {
  path = trim(path);
  if (path.size() > kMaxPath) return error = "a path of " + std::to_string(path.size()) + " characters", false;
  if (path.empty() || path[0] != '/') return error = "a relative path (an absolute one starts with '/')", false;
  size_t i = 0;
  while (i < path.size()) {
    Step s;
    if (path.substr(i, 2) == "//") {
      s.descendant = true;
      i += 2;
    } else if (path[i] == '/') {
      ++i;
    } else {
      return error = std::string("'").append(path.substr(i, 20)) + "' where a '/' was expected", false;
    }
    size_t e = i;
    if (e < path.size() && path[e] == '*')
      ++e;
    else
      while (e < path.size() && isNameChar(path[e])) ++e;
    if (e == i) return error = "a step without an element name at character " + std::to_string(i), false;
    s.name = std::string(path.substr(i, e - i));
    if (s.name.find("::") != std::string::npos) return error = "the axis in '" + s.name + "'", false;
    i = e;
    while (i < path.size() && path[i] == '[') {
      // The matching ']' outside quotes.
      size_t j = i + 1;
      char quote = 0;
      for (; j < path.size(); ++j) {
        if (quote) {
          if (path[j] == quote) quote = 0;
        } else if (path[j] == '\'' || path[j] == '"') {
          quote = path[j];
        } else if (path[j] == ']') {
          break;
        } else if (path[j] == '[') {
          return error = "a nested '['", false;
        }
      }
      if (j >= path.size()) return error = "a '[' without its ']'", false;
      Predicate p;
      if (!parsePredicate(path.substr(i + 1, j - i - 1), p, error)) return false;
      s.predicates.push_back(std::move(p));
      if (s.predicates.size() > kMaxPredicates) return error = "more than 8 predicates in a step", false;
      i = j + 1;
    }
    steps.push_back(std::move(s));
    if (steps.size() > kMaxSteps) return error = "more than 32 steps", false;
  }
  return true;
}

bool matches(const Predicate& p, pugi::xml_node n, uint64_t position, uint64_t last) {
  switch (p.kind) {
    case Predicate::Position: return position == p.position;
    case Predicate::Last: return position == last;
    case Predicate::AttrEquals: return n.attribute(p.attr.c_str()) && p.value == n.attribute(p.attr.c_str()).value();
    case Predicate::AttrExists: return bool(n.attribute(p.attr.c_str()));
    case Predicate::SelfNames:
      return std::any_of(p.names.begin(), p.names.end(), [&](const std::string& s) { return s == n.name(); });
  }
  return false;
}

}  // namespace

bool select(const pugi::xml_document& doc, std::string_view path, std::vector<pugi::xml_node>& out,
            std::string& error) {
  out.clear();
  std::vector<Step> steps;
  if (!parse(path, steps, error)) {
    error = "the reference '" + std::string(trim(path).substr(0, 80)) + "' uses " + error +
            "; tetstream follows absolute paths of '/' and '//' steps with [N], [last()], [@attr='v'] and "
            "[self::A or self::B] predicates";
    return false;
  }
  std::vector<pugi::xml_node> contexts{doc};
  std::vector<pugi::xml_node> expanded, candidates, kept;
  for (const Step& s : steps) {
    expanded.clear();
    if (s.descendant) {
      // descendant-or-self of every context, each node once: every node is visited at most once
      // per step however the contexts nest.
      std::unordered_set<const void*> seen;
      for (pugi::xml_node c : contexts) {
        if (!seen.insert(c.internal_object()).second) continue;
        expanded.push_back(c);
        for (pugi::xml_node n = c.first_child(); n;) {
          if (n.type() == pugi::node_element && seen.insert(n.internal_object()).second) {
            expanded.push_back(n);
            if (n.first_child()) {
              n = n.first_child();
              continue;
            }
          }
          while (n && n != c && !n.next_sibling()) n = n.parent();
          if (!n || n == c) break;
          n = n.next_sibling();
        }
      }
    } else {
      expanded = contexts;
    }
    contexts.clear();
    for (pugi::xml_node c : expanded) {
      candidates.clear();
      for (pugi::xml_node n = c.first_child(); n; n = n.next_sibling())
        if (n.type() == pugi::node_element && (s.name == "*" || s.name == n.name())) candidates.push_back(n);
      for (const Predicate& p : s.predicates) {
        kept.clear();
        for (size_t k = 0; k < candidates.size(); ++k)
          if (matches(p, candidates[k], k + 1, candidates.size())) kept.push_back(candidates[k]);
        candidates.swap(kept);
      }
      contexts.insert(contexts.end(), candidates.begin(), candidates.end());
    }
    if (contexts.empty()) break;
  }
  if (contexts.size() > 1) {
    // Document order: the preorder index of each element.
    std::unordered_map<const void*, size_t> order;
    size_t k = 0;
    struct Walker : pugi::xml_tree_walker {
      std::unordered_map<const void*, size_t>* order;
      size_t* k;
      bool for_each(pugi::xml_node& n) override {
        (*order)[n.internal_object()] = (*k)++;
        return true;
      }
    } walker;
    walker.order = &order;
    walker.k = &k;
    pugi::xml_node root = doc;  // a handle to the same tree
    root.traverse(walker);
    std::sort(contexts.begin(), contexts.end(), [&](pugi::xml_node a, pugi::xml_node b) {
      return order[a.internal_object()] < order[b.internal_object()];
    });
  }
  out = std::move(contexts);
  return true;
}

}  // namespace tetstream::xmlpath
