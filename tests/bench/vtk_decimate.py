#!/usr/bin/python3
"""VTK's tetrahedral decimation, for comparison with tetstream's packer.

   vtk_decimate.py IN.vtu OUT.vtu TARGET_TETS FIELD  ->  prints {"tets", "vertices", "seconds"}

Runs vtkUnstructuredGridQuadricDecimation (VTK 9.1, Debian python3-vtk9) with the field as its
scalar, asking for the reduction that leaves TARGET_TETS tetrahedra, and times only the filter.
"""
import json
import sys
import time

import vtk

src, dst, target, field = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4]
reader = vtk.vtkXMLUnstructuredGridReader() if src.endswith(".vtu") else vtk.vtkUnstructuredGridReader()
reader.SetFileName(src)
reader.Update()
grid = reader.GetOutput()
grid.GetPointData().SetActiveScalars(field)
dec = vtk.vtkUnstructuredGridQuadricDecimation()
dec.SetInputData(grid)
dec.SetScalarsName(field)
dec.SetTargetReduction(1.0 - target / grid.GetNumberOfCells())
t0 = time.perf_counter()
dec.Update()
seconds = time.perf_counter() - t0
out = dec.GetOutput()
writer = vtk.vtkXMLUnstructuredGridWriter()
writer.SetFileName(dst)
writer.SetInputData(out)
writer.SetDataModeToAppended()
writer.EncodeAppendedDataOff()
writer.Write()
print(json.dumps({"tets": out.GetNumberOfCells(), "vertices": out.GetNumberOfPoints(), "seconds": seconds}))
