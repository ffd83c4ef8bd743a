"""Smoke run of the slicing study (voxlight-slicingbench --quick, docs/slicing.md):
every technique at every slice spacing, with its error against the analytic
reference and the popping columns at step 1."""
import csv
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
BUILD = ROOT / "build"


def test_quick_slicing_study(tmp_path):
    out = tmp_path / "slicing.csv"
    cmd = [str(BUILD / "voxlight-slicingbench"), "--quick", "--out", str(out)]
    assert subprocess.run(cmd, timeout=600).returncode == 0
    rows = list(csv.DictReader(out.open()))
    assert {(r["technique"], r["step"]) for r in rows} == {
        (t, s) for t in ("raycast", "slices2d", "slices3d") for s in ("2", "1", "0.5", "0.25")}
    for r in rows:
        assert float(r["ms"]) > 0 and 0 < float(r["rmse"]) < 1 and r["reference"] == "analytic"
    pop = {r["technique"]: float(r["pop_across_rmse"]) / float(r["pop_nearby_rmse"]) for r in rows if r["step"] == "1"}
    # the 2D stacks switch at 45 degrees: a jump well above the change of a non-switching 0.2 degrees
    assert pop["slices2d"] > 1.5 and pop["slices3d"] < 1.3, pop
