#!/usr/bin/env python3
"""Writes a tetrahedral .vtu as an XDMF spatial collection of K grids, one per rank of the run
that wrote it: each grid a run of the cells with the points they use (its own copy of the points
it shares with the next), all in one HDF5 file through h5py.

   write_grids.py MESH.vtu OUT K     (writes OUT.xdmf and OUT.h5)
"""
import os
import sys

import h5py
import meshio
import numpy as np

mesh_path, out, count = sys.argv[1], sys.argv[2], int(sys.argv[3])
m = meshio.read(mesh_path)
tets = m.cells_dict["tetra"]
h5name = os.path.basename(out) + ".h5"
grids = []
with h5py.File(out + ".h5", "w") as h:
    for k, run in enumerate(np.array_split(np.arange(len(tets)), count)):
        used, local = np.unique(tets[run], return_inverse=True)
        h[f"points{k}"] = m.points[used]
        h[f"cells{k}"] = local.reshape(-1, 4)
        arrays = ""
        for name, values in m.point_data.items():
            h[f"{name}{k}"] = values[used]
            arrays += (f'<Attribute Name="{name}" Center="Node"><DataItem Dimensions="{len(used)}" '
                       f'NumberType="Float" Precision="{values.dtype.itemsize}" Format="HDF">'
                       f'{h5name}:/{name}{k}</DataItem></Attribute>')
        grids.append(
            f'<Grid Name="rank{k}"><Topology TopologyType="Tetrahedron" NumberOfElements="{len(run)}">'
            f'<DataItem Dimensions="{len(run)} 4" NumberType="Int" Precision="8" Format="HDF">'
            f'{h5name}:/cells{k}</DataItem></Topology>'
            f'<Geometry GeometryType="XYZ"><DataItem Dimensions="{len(used)} 3" NumberType="Float" '
            f'Precision="8" Format="HDF">{h5name}:/points{k}</DataItem></Geometry>{arrays}</Grid>')
with open(out + ".xdmf", "w") as f:
    f.write('<Xdmf Version="3.0"><Domain><Grid GridType="Collection" CollectionType="Spatial">' +
            "".join(grids) + "</Grid></Domain></Xdmf>\n")
