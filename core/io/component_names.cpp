// Vectors stored as one scalar variable per component (Exodus II, CGNS): see readers.h.
#include <cmath>

#include "io/readers.h"

namespace tetstream::vtkio {

namespace {

// The stem of NAME_x / NAMEx for the component letter c ('x', 'y' or 'z', either case); empty
// when name does not end so.
std::string_view stemOf(std::string_view name, char c) {
  if (name.size() < 2) return {};
  const char last = name.back();
  if (last != c && last != char(c - 'a' + 'A')) return {};
  std::string_view stem = name.substr(0, name.size() - 1);
  if (stem.back() == '_') stem.remove_suffix(1);
  return stem;
}

}  // namespace

std::vector<ComponentTriple> componentTriples(const std::vector<std::string>& names) {
  std::vector<ComponentTriple> out;
  for (size_t i = 0; i + 2 < names.size(); ++i) {
    const std::string_view x = names[i], y = names[i + 1], z = names[i + 2];
    const std::string_view stem = stemOf(x, 'x');
    if (stem.empty() || stemOf(y, 'y') != stem || stemOf(z, 'z') != stem) continue;
    // The same spelling for all three: "vel_x, vel_y, vel_z" or "VelocityX, VelocityY, VelocityZ".
    const bool upper = x.back() == 'X';
    if ((y.back() == 'Y') != upper || (z.back() == 'Z') != upper || x.size() != y.size() || x.size() != z.size())
      continue;
    out.push_back({std::string(stem), i});
    i += 2;
  }
  return out;
}

namespace {

std::vector<std::string> namesFrom(size_t first, size_t end, auto&& nameAt) {
  std::vector<std::string> names;
  for (size_t i = first; i < end; ++i) names.push_back(nameAt(i));
  return names;
}

std::string noteFor(const std::string& name, const std::vector<std::string>& names, size_t at, const char* kind) {
  return "added '" + name + "', the magnitude of the " + kind + " (" + names[at] + ", " + names[at + 1] + ", " +
         names[at + 2] + ")";
}

}  // namespace

void addComponentMagnitudes(TetMesh& mesh, size_t firstField, ReadReport& report) {
  const std::vector<std::string> names =
      namesFrom(firstField, mesh.fields.size(), [&](size_t i) { return mesh.fields[i].name; });
  for (const ComponentTriple& t : componentTriples(names)) {
    const size_t a = firstField + t.first;
    ScalarField m;
    m.name = t.stem + "_magnitude";
    m.values.resize(mesh.fields[a].values.size());
    for (size_t v = 0; v < m.values.size(); ++v) {
      const double x = mesh.fields[a].values[v], y = mesh.fields[a + 1].values[v], z = mesh.fields[a + 2].values[v];
      m.values[v] = float(std::sqrt(x * x + y * y + z * z));
    }
    report.notes.push_back(noteFor(m.name, names, t.first, "vector"));
    addField(mesh, std::move(m), report);
  }
}

void addComponentMagnitudes(std::vector<CellArray>& arrays, size_t first, ReadReport& report) {
  const std::vector<std::string> names = namesFrom(first, arrays.size(), [&](size_t i) { return arrays[i].name; });
  for (const ComponentTriple& t : componentTriples(names)) {
    const size_t a = first + t.first;
    CellArray m;
    m.name = t.stem + "_magnitude";
    m.values.resize(arrays[a].values.size());
    for (size_t c = 0; c < m.values.size(); ++c) {
      const double x = arrays[a].values[c], y = arrays[a + 1].values[c], z = arrays[a + 2].values[c];
      m.values[c] = std::sqrt(x * x + y * y + z * z);
    }
    report.notes.push_back(noteFor(m.name, names, t.first, "cell vector"));
    arrays.push_back(std::move(m));
  }
}

}  // namespace tetstream::vtkio
