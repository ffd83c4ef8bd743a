"""Load time of an OpenVDB grid against the same floats as raw NIfTI, through
`build/voxlight info` (load + value range, no GL): what the VDB path adds on
top of the shared volume build. Usage: /usr/bin/python3 bench/vdb_load.py [N]"""
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tests", "python"))
from nifti_write import write_nifti  # noqa: E402
from vdb_write import write_vdb  # noqa: E402

n = int(sys.argv[1]) if len(sys.argv) > 1 else 256
i, j, k = np.meshgrid(*[np.linspace(-1, 1, n, dtype=np.float32)] * 3, indexing="ij")
ball = (0.01 + np.clip(1 - np.sqrt(i * i + j * j + k * k), 0, None)).astype(np.float32)
d = tempfile.mkdtemp()
files = {"vdb": write_vdb(os.path.join(d, "ball.vdb"), [{"name": "density", "array": ball}]),
         "nifti": str(write_nifti(os.path.join(d, "ball.nii"), ball, np.eye(4)))}
for name, path in files.items():
    runs = []
    for _ in range(3):
        t = time.perf_counter()
        subprocess.run([os.path.join(ROOT, "build", "voxlight"), "info", path], check=True, capture_output=True)
        runs.append(time.perf_counter() - t)
    print("%s %d^3 (%.1f MB file): best of 3 %.2f s" % (name, n, os.path.getsize(path) / 1e6, min(runs)))
