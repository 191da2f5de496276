#!/usr/bin/python3
"""VTK's isosurface on a tetrahedral mesh, for comparison with `tetstream iso`.

   vtk_contour.py MESH.vtu FIELD ISOVALUE REPEAT  ->  prints {"triangles", "seconds": [..]}

Times vtkContourFilter (VTK 9.1, Debian python3-vtk9) alone, REPEAT times, on the mesh as read.
"""
import json
import sys
import time

import vtk

src, field, value, repeat = sys.argv[1], sys.argv[2], float(sys.argv[3]), int(sys.argv[4])
reader = vtk.vtkXMLUnstructuredGridReader() if src.endswith(".vtu") else vtk.vtkUnstructuredGridReader()
reader.SetFileName(src)
reader.Update()
grid = reader.GetOutput()
grid.GetPointData().SetActiveScalars(field)
seconds, triangles = [], 0
for _ in range(repeat):
    f = vtk.vtkContourFilter()
    f.SetInputData(grid)
    f.SetValue(0, value)
    f.ComputeNormalsOff()
    t0 = time.perf_counter()
    f.Update()
    seconds.append(time.perf_counter() - t0)
    triangles = f.GetOutput().GetNumberOfCells()
print(json.dumps({"triangles": triangles, "seconds": seconds}))
