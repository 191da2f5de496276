#!/usr/bin/env python3
# Writes a mesh with its points in a shuffled order, as a solver that numbers points and cells
# each its own way writes it: a run of the cells then uses points from all over the file. One
# .vtu of appended raw data, as ParaView writes it, through VTK's own writer (Debian's
# python3-vtk9), for the distributed pack's test:
#   shuffle_points.py INPUT.vtu OUTPUT.vtu
import sys

import numpy as np
import vtk
from vtk.util import numpy_support as ns

reader = vtk.vtkXMLUnstructuredGridReader()
reader.SetFileName(sys.argv[1])
reader.Update()
grid = reader.GetOutput()
count = grid.GetNumberOfPoints()
order = np.random.default_rng(1).permutation(count)  # the file's point p is the input's order[p]
place = np.empty(count, dtype=np.int64)
place[order] = np.arange(count)

out = vtk.vtkUnstructuredGrid()
points = vtk.vtkPoints()
points.SetData(ns.numpy_to_vtk(ns.vtk_to_numpy(grid.GetPoints().GetData())[order].copy(), deep=1))
out.SetPoints(points)
cells = grid.GetCells()
offsets = ns.vtk_to_numpy(cells.GetOffsetsArray()).astype(np.int64)
connectivity = place[ns.vtk_to_numpy(cells.GetConnectivityArray()).astype(np.int64)]
array = vtk.vtkCellArray()
array.SetData(ns.numpy_to_vtk(offsets, deep=1, array_type=vtk.VTK_ID_TYPE),
              ns.numpy_to_vtk(connectivity, deep=1, array_type=vtk.VTK_ID_TYPE))
types = ns.numpy_to_vtk(ns.vtk_to_numpy(grid.GetCellTypesArray()), deep=1, array_type=vtk.VTK_UNSIGNED_CHAR)
out.SetCells(types, array)
data = grid.GetPointData()
for i in range(data.GetNumberOfArrays()):
    values = ns.numpy_to_vtk(ns.vtk_to_numpy(data.GetArray(i))[order].copy(), deep=1)
    values.SetName(data.GetArray(i).GetName())
    out.GetPointData().AddArray(values)

writer = vtk.vtkXMLUnstructuredGridWriter()
writer.SetFileName(sys.argv[2])
writer.SetInputData(out)
writer.SetDataModeToAppended()
writer.EncodeAppendedDataOff()
writer.SetCompressorTypeToNone()
writer.Write()
