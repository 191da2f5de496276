#!/usr/bin/env python3
# Writes a mesh as the partitioned output of a parallel run, with VTK's own writers (Debian's
# python3-vtk9), for the distributed pack's test:
#   write_pieces.py INPUT.vtu OUTDIR PIECES
# makes in OUTDIR
#   ghost.pvtu     PIECES pieces cut by VTK's piece extraction, ghost level 1 (vtkGhostType)
#   ids.pvtu       PIECES pieces, no ghosts, a GlobalIds point array
#   multi.vtu      one file with PIECES <Piece>s (as PETSc writes), no ghosts
#   broken.pvtu    ghost.pvtu's listing with one piece file that does not exist
#   lacking.pvtu   ghost.pvtu's listing whose last piece has its field under another name
import os
import sys

import vtk
from vtk.util import numpy_support as ns
import numpy as np


def parallel_writer(port, name, pieces, ghost_level):
    w = vtk.vtkXMLPUnstructuredGridWriter()
    w.SetInputConnection(port)
    w.SetFileName(name)
    w.SetNumberOfPieces(pieces)
    w.SetStartPiece(0)
    w.SetEndPiece(pieces - 1)
    w.SetGhostLevel(ghost_level)
    w.SetUseSubdirectory(True)
    w.SetDataModeToBinary()
    return w


def main():
    source, out, pieces = sys.argv[1], sys.argv[2], int(sys.argv[3])
    os.makedirs(out, exist_ok=True)
    os.chdir(out)
    r = vtk.vtkXMLUnstructuredGridReader()
    r.SetFileName(source)
    r.Update()
    grid = r.GetOutput()

    ex = vtk.vtkExtractUnstructuredGridPiece()
    ex.SetInputData(grid)
    parallel_writer(ex.GetOutputPort(), "ghost.pvtu", pieces, 1).Write()

    with_ids = vtk.vtkUnstructuredGrid()
    with_ids.DeepCopy(grid)
    gid = ns.numpy_to_vtk(np.arange(grid.GetNumberOfPoints(), dtype=np.int64), deep=True, array_type=vtk.VTK_ID_TYPE)
    gid.SetName("GlobalIds")
    with_ids.GetPointData().AddArray(gid)
    ex2 = vtk.vtkExtractUnstructuredGridPiece()
    ex2.SetInputData(with_ids)
    parallel_writer(ex2.GetOutputPort(), "ids.pvtu", pieces, 0).Write()

    multi = vtk.vtkXMLUnstructuredGridWriter()
    ex3 = vtk.vtkExtractUnstructuredGridPiece()
    ex3.SetInputData(grid)
    multi.SetInputConnection(ex3.GetOutputPort())
    multi.SetFileName("multi.vtu")
    multi.SetNumberOfPieces(pieces)
    multi.SetDataModeToBinary()
    multi.Write()

    with open("ghost.pvtu") as f:
        text = f.read()
    with open("broken.pvtu", "w") as f:
        f.write(text.replace("ghost_%d.vtu" % (pieces - 1), "missing_%d.vtu" % (pieces - 1)))

    last = vtk.vtkXMLUnstructuredGridReader()
    last.SetFileName("ghost/ghost_%d.vtu" % (pieces - 1))
    last.Update()
    renamed = vtk.vtkUnstructuredGrid()
    renamed.DeepCopy(last.GetOutput())
    renamed.GetPointData().GetArray(0).SetName("renamed")
    w = vtk.vtkXMLUnstructuredGridWriter()
    w.SetInputData(renamed)
    w.SetFileName("ghost/lacking_%d.vtu" % (pieces - 1))
    w.Write()
    with open("lacking.pvtu", "w") as f:
        f.write(text.replace("ghost_%d.vtu" % (pieces - 1), "lacking_%d.vtu" % (pieces - 1)))


main()
