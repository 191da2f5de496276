// A finite element function as legacy DOLFIN's XDMFFile.write_checkpoint stores it: an
// <Attribute Center="Other" ItemType="FiniteElementFunction" ElementFamily="CG" ElementDegree="1">
// with four DataItems, in this order: cell_dofs (the dof of each local dof of each cell),
// vector (the value of each dof), x_cell_dofs (where each cell's dofs start in cell_dofs, one
// more than the cells) and cells (the index of each cell in the grid's topology).
//
// Lagrange elements of any degree (CG, Lagrange, P, Q; DG and Discontinuous Lagrange) number a
// cell's vertex dofs first, in the order of the cell's vertices, one block of dofs per component
// of a vector or tensor function. So the value at a corner is read from the cell's first dofs:
// a continuous function gives every cell around a vertex the same value; a discontinuous one
// gives each its own, and they are averaged. Degree 0 (DG0) is one value per cell: cell data.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "io/readers.h"
#include "io/xdmf_document.h"

namespace tetstream::xdmf {

// The cells of the grid the function lives on: `cells` cells of `corners` corner vertices
// each, `nodes` ids per cell in `connectivity` (corners first), on `points` points.
struct GridCells {
  const std::vector<int64_t>* connectivity = nullptr;
  uint64_t cells = 0;
  int nodes = 0;
  int corners = 0;
  uint64_t points = 0;
};

// Reads the function of `attribute` (named `name`, `components` values per node) into a point
// field (degree >= 1) or a cell array (degree 0), appended to `fields` / `cellArrays`.
Result readFiniteElementFunction(Document& doc, pugi::xml_node attribute, const std::string& name, uint32_t components,
                                 const std::string& what, const GridCells& grid, ReadReport& report,
                                 std::vector<ScalarField>& fields, std::vector<vtkio::CellArray>& cellArrays);

}  // namespace tetstream::xdmf
