"""Writes the OpenVDB seed corpus for fuzz_vdb into the folder argv[1]
(make_seeds.c writes the other formats; a .vdb writer in C would mean
linking OpenVDB, so pyopenvdb writes these)."""

import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "python"))
from vdb_write import write_vdb  # noqa: E402

out = sys.argv[1]
os.makedirs(out, exist_ok=True)
rng = np.random.default_rng(7)
shear = np.array([[0.5, 0.1, 0, 1], [0, 0.5, 0, 2], [0, 0, 0.25, 3], [0, 0, 0, 1]])
write_vdb(os.path.join(out, "small.vdb"),
          [{"name": "density", "array": rng.random((5, 4, 3)).astype(np.float32) + 0.1, "ijk": (-3, 7, 9)}])
write_vdb(os.path.join(out, "two_grids.vdb"),
          [{"name": "vel", "vec3": True},
           {"name": "heat", "array": np.full((9, 2, 2), 3.0, np.float32), "affine": shear, "background": 1.0}])
write_vdb(os.path.join(out, "empty.vdb"), [{"name": "density"}])
