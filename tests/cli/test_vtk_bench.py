"""The VTK comparison harness (bench/vtk_compare.py) that `./build.sh bench`
runs: at a tiny size it must still produce, for both volumes and both
transfer functions, a Voxlight row and a VTK row with finite errors against
the reference, covered pixels on the same frame, and the docs section.
Also checks the float64 reference itself (bench/ref_render.py) against the
library's own equations, so a wrong reference cannot pass as an error
figure. Nothing here is timed."""
import csv
import json
import math
import os
import re
import subprocess
import sys
import types
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
BENCH = ROOT / "bench"
INIA19 = "/usr/share/mricron/templates/inia19-t1-brain.nii.gz"


def test_harness_covers_both_volumes_and_transfer_functions(tmp_path):
    out, md = tmp_path / "cmp.csv", tmp_path / "cmp.md"
    cmd = ["xvfb-run", "-a", "-s", "-screen 0 640x480x24", "/usr/bin/python3", str(BENCH / "vtk_compare.py"),
           "--size", "24", "--frames", "1", "--ref-step", "0.5", "--out", str(out), "--md", str(md),
           "--json", str(tmp_path / "cmp.json"), "--cache-dir", str(tmp_path)]
    r = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr[-3000:]
    rows = list(csv.DictReader(open(out)))
    meta = json.load(open(tmp_path / "cmp.json"))
    pairs = {(row["volume"], row["tf"], row["renderer"]) for row in rows}
    assert pairs == {(v, t, k) for v in ("ch2better", "inia19") for t in ("ramp", "mri") for k in ("voxlight", "vtk")}
    for row in rows:
        for key in ("ms_median", "rmse", "psnr_db", "us_per_covered_px", "speedup_per_covered_px"):
            assert math.isfinite(float(row[key])), (row, key)
        # the frame shows the volume, and nothing is covered outside its box
        assert 0 < float(row["covered_frac"]) <= float(row["box_frac"]) < 1, row
        assert float(row["rmse"]) < 0.2, row  # same frame: an image of the wrong thing is far off
    text = md.read_text()
    assert "AutoAdjustSampleDistances" in text
    for v in ("ch2better", "inia19"):
        for t in ("ramp", "mri"):
            assert re.search(r"\| %s \| %s \| [0-9.]+%% \|" % (v, t), text), (v, t)  # the speed-up table
            m = meta["%s/%s" % (v, t)]
            assert 0 < m["visible_samples"] <= m["samples_without_skipping"], m
            assert m["voxlight_stats"]["samples"] > 0, m


def test_reference_follows_the_library_equations():
    """At the reference's own step, without jitter or early termination, the
    library's image of a float volume equals ref_render's up to float
    rounding: the reference renders the same camera, box, table, opacity
    correction, shading and compositing."""
    sys.path.insert(0, str(BENCH))
    if "voxlight" not in sys.modules:
        pkg = types.ModuleType("voxlight")
        pkg.__path__ = [str(ROOT / "plugin")]
        sys.modules["voxlight"] = pkg
    os.environ.setdefault("VOXLIGHT_LIB", str(ROOT / "build" / "libvoxlight.so"))
    from voxlight.core import native
    import ref_render
    from vtk_compare import MATERIAL, TABLES
    from vtk_peer import read_nifti

    lib = native.load_library()
    vol = native.Volume.load(INIA19, lib=lib)
    r = native.Renderer(lib=lib)
    try:
        r.set_volume(vol)
        info = vol.info
        window = (info["value_min"], info["value_max"])
        view, proj = r.default_camera(width=32, height=32, azimuth=30.0, elevation=15.0)
        dims, data = read_nifti(INIA19)
        for tf in ("ramp", "mri"):
            table = TABLES[tf]()
            p = native.make_params(width=32, height=32, view=view, proj=proj, filter="central", step=0.25,
                                   jitter=False, tf_rgba=table, window=window, material=MATERIAL,
                                   early_termination=1.0, lib=lib)
            ours = r.render(p, want_depth=False)[0]
            ref, box = ref_render.render(data, dims, np.asarray(info["affine"], float), np.asarray(view, float),
                                         np.asarray(proj, float), 32, 32, table, window, MATERIAL, 0.25)
            assert ref[..., 3].max() > 0.5 and box.any()
            assert np.abs(ours - ref).max() < 1e-3, tf
    finally:
        r.close()
        vol.close()
