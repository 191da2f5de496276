#include "io/xdmf_function.h"

#include <cmath>
#include <cstdio>
#include <limits>

namespace tetstream::xdmf {
namespace {

bool lagrangeFamily(std::string_view f, bool& discontinuous) {
  using vtkio::iequals;
  discontinuous = iequals(f, "DG") || iequals(f, "Discontinuous Lagrange") || iequals(f, "DQ");
  return discontinuous || iequals(f, "CG") || iequals(f, "Lagrange") || iequals(f, "P") || iequals(f, "Q");
}

}  // namespace

Result readFiniteElementFunction(Document& doc, pugi::xml_node attribute, const std::string& name, uint32_t components,
                                 const std::string& what, const GridCells& grid, ReadReport& report,
                                 std::vector<ScalarField>& fields, std::vector<vtkio::CellArray>& cellArrays) {
  const std::string family = attribute.attribute("ElementFamily").value();
  bool discontinuous = false;
  if (!lagrangeFamily(family, discontinuous))
    return fail(Status::Unsupported, what + ": a finite element function of family '" + vtkio::printable(family) +
                                         "' (tetstream reads Lagrange functions: CG, DG, P, Q)");
  uint64_t degree = 0;
  if (!vtkio::parseU64(attribute.attribute("ElementDegree").value(), degree) || degree > 16)
    return fail(Status::Corrupt, what + ": ElementDegree='" +
                                     vtkio::printable(attribute.attribute("ElementDegree").value()) +
                                     "' is not a degree");
  if (!grid.connectivity)
    return fail(Status::Unsupported, what + ": a finite element function on a Mixed topology is not read");

  std::vector<pugi::xml_node> items;
  if (Result r = doc.children(attribute, "DataItem", what, items); !r) return r;
  if (items.size() != 4)
    return fail(Status::Corrupt, what + ": a finite element function has " + std::to_string(items.size()) +
                                     " DataItems, expected 4 (cell_dofs, vector, x_cell_dofs, cells)");
  Values<int64_t> cellDofs, starts, cells;
  Values<double> vector;
  if (Result r = doc.integers(items[2], what + " x_cell_dofs", starts); !r) return r;
  if (starts.values.size() != grid.cells + 1)
    return fail(Status::Corrupt, what + ": x_cell_dofs holds " + std::to_string(starts.values.size()) +
                                     " values, expected one more than the " + std::to_string(grid.cells) + " cells");
  if (Result r = doc.integers(items[3], what + " cells", cells); !r) return r;
  if (cells.values.size() != grid.cells)
    return fail(Status::Corrupt, what + ": cells holds " + std::to_string(cells.values.size()) + " values for " +
                                     std::to_string(grid.cells) + " cells");
  if (Result r = doc.integers(items[0], what + " cell_dofs", cellDofs); !r) return r;
  if (Result r = doc.numbers(items[1], what + " vector", vector); !r) return r;
  const uint64_t nDofs = cellDofs.values.size(), nValues = vector.values.size();
  if (starts.values[0] != 0 || uint64_t(starts.values.back()) != nDofs)
    return fail(Status::Corrupt, what + ": x_cell_dofs runs from " + std::to_string(starts.values[0]) + " to " +
                                     std::to_string(starts.values.back()) + ", expected 0 to the " +
                                     std::to_string(nDofs) + " cell_dofs");

  // Per vertex (or per cell, for degree 0): sum and count of the values the cells give it, per
  // component; the magnitude is taken after averaging.
  const bool perCell = degree == 0;
  const uint64_t targets = perCell ? grid.cells : grid.points;
  std::vector<double> sum(targets * components, 0.0), first(targets * components, 0.0);
  std::vector<uint32_t> count(targets, 0);
  double spread = 0, scale = 0;
  for (uint64_t k = 0; k < grid.cells; ++k) {
    const int64_t b = starts.values[k], e = starts.values[k + 1];
    if (e < b || e > int64_t(nDofs))
      return fail(Status::Corrupt, what + ": x_cell_dofs of cell " + std::to_string(k) + " (" + std::to_string(b) +
                                       ".." + std::to_string(e) + ") is outside 0.." + std::to_string(nDofs));
    const int64_t cell = cells.values[k];
    if (cell < 0 || uint64_t(cell) >= grid.cells)
      return fail(Status::OutOfRange, what + ": cells[" + std::to_string(k) + "] = " + std::to_string(cell) +
                                          " is not one of the " + std::to_string(grid.cells) + " cells");
    const uint64_t perComponent = uint64_t(e - b) / components;
    const uint64_t need = perCell ? 1 : uint64_t(grid.corners);
    if (uint64_t(e - b) % components != 0 || perComponent < need)
      return fail(Status::Corrupt, what + ": cell " + std::to_string(k) + " has " + std::to_string(e - b) +
                                       " dofs, expected at least " + std::to_string(need) + " per each of " +
                                       std::to_string(components) + " components");
    for (uint64_t i = 0; i < need; ++i) {
      const uint64_t target =
          perCell ? uint64_t(cell) : uint64_t((*grid.connectivity)[uint64_t(cell) * uint64_t(grid.nodes) + i]);
      if (target >= targets)
        return fail(Status::OutOfRange, what + ": cell " + std::to_string(cell) + " has a vertex out of range");
      for (uint32_t c = 0; c < components; ++c) {
        const int64_t dof = cellDofs.values[uint64_t(b) + c * perComponent + i];
        if (dof < 0 || uint64_t(dof) >= nValues)
          return fail(Status::OutOfRange, what + ": cell_dofs of cell " + std::to_string(k) + " names dof " +
                                              std::to_string(dof) + ", but vector holds " + std::to_string(nValues));
        const double v = vector.values[uint64_t(dof)];
        double& s = sum[target * components + c];
        if (count[target] == 0)
          first[target * components + c] = v;
        else
          spread = std::max(spread, std::fabs(v - first[target * components + c]));
        scale = std::max(scale, std::fabs(v));
        s += v;
      }
      ++count[target];
    }
  }
  std::vector<double> tuples(targets * components, std::numeric_limits<double>::quiet_NaN());
  for (uint64_t t = 0; t < targets; ++t)
    if (count[t])
      for (uint32_t c = 0; c < components; ++c) tuples[t * components + c] = sum[t * components + c] / count[t];
  const std::string fname = vtkio::fieldNameFor(name, components, report, perCell ? "cell" : "point");
  std::vector<float> scalars = vtkio::tuplesToScalars(tuples, components);
  char buf[64];
  std::snprintf(buf, sizeof buf, "%s%llu", family.c_str(), static_cast<unsigned long long>(degree));
  if (perCell) {
    cellArrays.push_back({fname, std::vector<double>(scalars.begin(), scalars.end())});
  } else {
    fields.push_back({fname, std::move(scalars)});
    if (!discontinuous && spread > 1e-9 * std::max(scale, 1.0)) {
      std::snprintf(buf + 32, 32, "%g", spread);
      report.notes.push_back("finite element function '" + name + "': the cells around a vertex give it values up to " +
                             std::string(buf + 32) + " apart (averaged), unexpected for a continuous element");
    }
  }
  report.notes.push_back("read finite element function '" + name + "' (" + std::string(buf) + ") at the " +
                         (perCell ? "cells" : "vertices") + " from its dofs");
  return Result::success();
}

}  // namespace tetstream::xdmf
