"""Load time of an OpenVDB grid against the same floats as raw NIfTI, through
`build/voxlight info` (load + value range, no GL): what the VDB path adds on
top of the shared volume build. The library reads .vdb files in a helper
process (csrc/io/reader_spawn.c, `voxlight-read-oiio`); the "helper alone" row is that process's
in-process read with its output thrown away, and VOXLIGHT_BASELINE_CLI names
another `voxlight` build to time too (e.g. one from before the helper, which
read in-process). Usage: /usr/bin/python3 bench/vdb_load.py [N]"""
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
cli = os.path.join(ROOT, "build", "voxlight")
cases = [("vdb", [cli, "info", files["vdb"]]), ("nifti", [cli, "info", files["nifti"]]),
         ("vdb, helper alone", [os.path.join(ROOT, "build", "voxlight-read-oiio"), "vdb", files["vdb"],
                                "65536", str(1 << 40), "0", "0", "0", "0", ""])]
if os.environ.get("VOXLIGHT_BASELINE_CLI"):
    cases.append(("vdb, baseline CLI", [os.environ["VOXLIGHT_BASELINE_CLI"], "info", files["vdb"]]))
for name, cmd in cases:
    runs = []
    for _ in range(5):
        t = time.perf_counter()
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        runs.append(time.perf_counter() - t)
    path = files[name.split(",")[0]]
    print("%s %d^3 (%.1f MB file): best of 5 %.2f s, median %.2f s"
          % (name, n, os.path.getsize(path) / 1e6, min(runs), sorted(runs)[2]))

# What a host such as Blender sees: libvoxlight already loaded, one
# Volume.load after a warm-up, timed inside one Python process per library
# (VOXLIGHT_BASELINE_LIB: another libvoxlight.so to compare, e.g. one that read
# .vdb files in-process).
WARM = """
import sys, time
sys.path.insert(0, %r)
import conftest  # the voxlight package stub, as in the tests
from voxlight.core import native
lib = native.load_library(sys.argv[1])
native.Volume.load(sys.argv[2], lib=lib).close()
runs = []
for _ in range(5):
    t = time.perf_counter()
    native.Volume.load(sys.argv[2], lib=lib).close()
    runs.append(time.perf_counter() - t)
print("best of 5 %%.2f s, median %%.2f s" %% (min(runs), sorted(runs)[2]))
""" % os.path.join(ROOT, "tests", "python")
libs = [("library", os.path.join(ROOT, "build", "libvoxlight.so"))]
if os.environ.get("VOXLIGHT_BASELINE_LIB"):
    libs.append(("baseline library", os.environ["VOXLIGHT_BASELINE_LIB"]))
for name, lib in libs:
    out = subprocess.run([sys.executable, "-c", WARM, lib, files["vdb"]], check=True, capture_output=True, text=True)
    print("vdb %d^3, Volume.load in a warm process, %s: %s" % (n, name, out.stdout.strip()))
