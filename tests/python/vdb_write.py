"""Writes small OpenVDB files for tests with Debian's python3-openvdb
(pyopenvdb), so no test file is downloaded. Also importable inside Blender's
Python (which has no pyopenvdb): write_vdb then runs /usr/bin/python3."""

import json
import subprocess
import sys

import numpy as np

_SCRIPT = r"""
import json, sys
import numpy as np
import pyopenvdb as vdb
spec = json.loads(sys.argv[1])
grids = []
for g in spec["grids"]:
    a = np.load(g["npy"]) if g.get("npy") else None
    if g.get("vec3"):
        grid = vdb.Vec3SGrid()
        grid.fill((0, 0, 0), (3, 3, 3), (1.0, 2.0, 3.0))
    else:
        grid = vdb.FloatGrid(background=g.get("background", 0.0))
    grid.name = g["name"]
    if a is not None:
        grid.copyFromArray(a, ijk=tuple(g["ijk"]), tolerance=0)
    grid.transform = vdb.createLinearTransform(g["index_to_world_rows"])
    grids.append(grid)
vdb.write(spec["path"], grids=grids)
"""


def index_to_world(affine):
    """Our column-vector 4x4 affine -> OpenVDB's row-vector matrix rows."""
    return np.asarray(affine, np.float64).T.tolist()


def write_vdb(path, grids):
    """grids: list of dicts name, array (float32 [i, j, k] -> voxel ijk+offset),
    ijk (offset), affine (4x4 index -> world, column vectors), background,
    vec3 (True: a 4^3 vec3 grid instead). Returns path."""
    import os
    import tempfile
    tmp = tempfile.mkdtemp()
    spec = {"path": str(path), "grids": []}
    for n, g in enumerate(grids):
        entry = {"name": g["name"], "ijk": list(g.get("ijk", (0, 0, 0))),
                 "index_to_world_rows": index_to_world(g.get("affine", np.eye(4))),
                 "background": float(g.get("background", 0.0)), "vec3": bool(g.get("vec3"))}
        if g.get("array") is not None:
            npy = os.path.join(tmp, "g%d.npy" % n)
            np.save(npy, np.asarray(g["array"], np.float32))
            entry["npy"] = npy
        spec["grids"].append(entry)
    # pyopenvdb is built for Debian's python3, not for Blender's own Python.
    python = "/usr/bin/python3" if "bpy" in sys.modules else sys.executable
    subprocess.run([python, "-c", _SCRIPT, json.dumps(spec)], check=True)
    return str(path)
